"""Stiffness maps over whole workspaces on a Dask cluster (optional: ``pip install
"./crates/sinew-py[dask]"``, which brings ``dask[array]`` and ``distributed``).

Sinew does not schedule anything itself: ``map_evaluate`` and ``map_plan`` cut the rows of
``Q`` into chunks (``chunk`` rows each; by default about ``TASKS_PER_WORKER`` = 8 tasks per
worker and at least ``DEFAULT_CHUNK`` = 10 000 rows a task: Dask's overhead is about 2 ms per
task, 10 000 rows of cdhrm5 about 100 ms of work), ship the model once per worker (``client.scatter(arm,
broadcast=True)``: it pickles by value, the URDF, ``robot.toml`` and routing texts, never a
path), and run each chunk as one task (a numpy ``Q`` travels in the task graph, a dask ``Q``
is computed where its chunks' tasks run) calling ``evaluate_many`` / ``plan_many`` with
``threads=1`` (a worker per core then uses its core and no more). A worker lost mid-run loses
nothing: the chunks are in the task graph and Dask runs the lost ones again.

>>> import numpy as np, sinew, sinew.dask
>>> robot = sinew.load_robot("robots/cdhrm5")
>>> arm = sinew.ArmStiffness(robot, sinew.load_routing(robot))
>>> Q = np.zeros((100_000, 10)) + 0.1
>>> m = sinew.dask.map_evaluate(arm, Q, wrench=[0, 5, 0, 0, 0, 0], levels=[0.5] * 5)
>>> m.stable.mean(), m.k_fd.shape                    # doctest: +SKIP

``client`` is None (a ``distributed.LocalCluster`` of one single-threaded worker process per
core, started and closed by the call), a scheduler address (``"tcp://host:8786"``: the path
past one machine), or a ``distributed.Client``. With ``compute=False`` the fields are dask
arrays (``errors`` a ``dask.delayed`` list) and nothing runs until ``result.compute()``;
``progress=True`` shows Dask's own progress bar while it runs. A row that fails is a row of
the result (``ok`` False, NaN, its error in ``errors``); when every row fails, the first row's
error is raised, as ``evaluate_many`` does. ``fields=["ok", "stable", "k_fd"]`` keeps only
those fields (``ok`` always, and ``errors``): the workers send back only them, which is most of
a map's cost when the results are large (a full cdhrm5 row is 1.2 kB, its ``k_fd`` 72 bytes).

When every worker sees the client's ``/dev/shm`` (a ``LocalCluster``, or workers on the
client's host; checked by a token each worker reads), a computed map moves no rows through
Dask at all: ``Q`` and the result's fields live in one file there, each task reads and writes
its own rows, and only the failed rows' errors travel (``sinew._shared``). The result's arrays
are then views of that memory (the file itself is unlinked when the map returns).
``shared_memory=False`` sends everything through Dask; ``True`` requires the shared file.
"""

from __future__ import annotations

import functools
import os
from typing import Any, Optional

import numpy as np

try:
    import dask
    import dask.array as da
    import distributed
except ImportError as e:  # pragma: no cover - the message is the point
    raise ImportError(
        "sinew.dask needs dask[array] and distributed: pip install './crates/sinew-py[dask]'"
    ) from e

from . import _shared
from ._sinew import (
    ArmStiffness,
    InfeasibleError,
    InputError,
    NumericalError,
    RankDeficientError,
    UnstableError,
)

__all__ = ["DEFAULT_CHUNK", "TASKS_PER_WORKER", "MapResult", "map_evaluate", "map_plan"]

DEFAULT_CHUNK = 10_000
"""The fewest rows per task when ``chunk`` is None (Dask's overhead is about 2 ms a task, 10 000
rows of cdhrm5 about 100 ms of work)."""

TASKS_PER_WORKER = 8
"""With ``chunk`` None, the rows are cut into about this many tasks per worker (and no
fewer than ``DEFAULT_CHUNK`` rows a task): few enough that Dask's per-task cost and the
client's share of the cores stay small, enough to balance the workers, show progress and
lose little when a worker is lost."""


class MapResult:
    """The fields of ``BatchResult`` (``map_evaluate``) or ``PlanBatchResult`` (``map_plan``),
    one row per row of ``Q``: numpy arrays, or dask arrays with ``compute=False``. ``errors``
    lists ``(row, kind, message)`` of every failed row (rows of the whole ``Q``)."""

    def __init__(self, fields: dict, client: Optional["distributed.Client"] = None):
        self._names = list(fields)
        for name, value in fields.items():
            setattr(self, name, value)
        self._client = client

    def __len__(self) -> int:
        return int(self.ok.shape[0])

    def __repr__(self) -> str:
        kind = "dask" if isinstance(self.ok, da.Array) else "numpy"
        return f"sinew.dask.MapResult(rows={len(self)}, {kind}, fields={self._names})"

    def compute(self, progress: bool = False) -> "MapResult":
        """The numpy result of a ``compute=False`` map (itself when already computed)."""
        if not isinstance(self.ok, da.Array):
            return self
        client = self._client or distributed.get_client()
        values = [getattr(self, name) for name in self._names]
        futures = client.compute(values)
        if progress:
            distributed.progress(futures)
        return MapResult(dict(zip(self._names, client.gather(futures))))


def _evaluate_chunk(arm, Q, wrench, offset, names, levels=None, policy=None, out=None):
    """One task: ``evaluate_many`` on one chunk with ``threads=1``, the fields ``names`` kept
    (or written into ``out``'s arrays: then only ``written``), errors renumbered."""
    b = arm.evaluate_many(Q, wrench, levels=levels, policy=policy, threads=1,
                          raise_if_all_fail=False, out=out)
    kept = {"written": True} if out is not None else {name: getattr(b, name) for name in names}
    kept["errors"] = [(offset + r, kind, message) for r, kind, message in b.errors]
    return kept


def _plan_chunk(arm, Q, wrench, offset, names, options=None, out=None):
    """One task: ``plan_many`` on one chunk with ``threads=1``, the fields ``names`` kept,
    errors renumbered (``plan_many`` has no ``out``: the caller copies the fields into it)."""
    b = arm.plan_many(Q, wrench, threads=1, raise_if_all_fail=False, **(options or {}))
    out = {name: getattr(b, name) for name in names}
    out["errors"] = [(offset + r, kind, message) for r, kind, message in b.errors]
    return out


_EXCEPTIONS = {"input": InputError, "infeasible": InfeasibleError, "unstable": UnstableError,
               "rank-deficient": RankDeficientError}


def _all_errors(*lists):
    return [e for errors in lists for e in errors]


# Each field's trailing shape (from the model) and dtype.
_EVALUATE = {
    "ok": (lambda arm: (), np.bool_),
    "stable": (lambda arm: (), np.bool_),
    "min_eigenvalue": (lambda arm: (), np.float64),
    "t0": (lambda arm: (arm.dof,), np.float64),
    "tensions": (lambda arm: (arm.cables,), np.float64),
    "c_x": (lambda arm: (6, 6), np.float64),
    "k_x": (lambda arm: (6, 6), np.float64),
    "k_fd": (lambda arm: (3, 3), np.float64),
}
_PLAN = {
    "ok": (lambda arm: (), np.bool_),
    "value": (lambda arm: (), np.float64),
    "gap": (lambda arm: (), np.float64),
    "tensions": (lambda arm: (arm.cables,), np.float64),
    "total_tension": (lambda arm: (), np.float64),
    "levels": (lambda arm: (arm.joints,), np.float64),
    "k_fd": (lambda arm: (3, 3), np.float64),
    "c_x": (lambda arm: (6, 6), np.float64),
    "min_eigenvalue": (lambda arm: (), np.float64),
    "stable": (lambda arm: (), np.bool_),
    "iterations": (lambda arm: (), np.int64),
}


def _plan_fields(arm):
    return {k: v for k, v in _PLAN.items() if k != "levels" or arm.has_levels}


def _chosen(available: dict, fields: Any) -> dict:
    """The fields a map returns: all of ``available`` (``fields`` None) or those named, in
    the order given, ``ok`` first when it is not named (a result's length is its length)."""
    if fields is None:
        return dict(available)
    if isinstance(fields, str) or not all(isinstance(f, str) for f in fields):
        raise InputError(f"fields: expected a list of field names, got {fields!r}")
    names = list(fields)
    unknown = [f for f in names if f not in available]
    if unknown:
        raise InputError(f"fields: no field {unknown[0]!r}; the fields are {', '.join(available)}")
    if "ok" not in names:
        names.insert(0, "ok")
    return {name: available[name] for name in dict.fromkeys(names)}


def _rows(arm: ArmStiffness, Q: Any):
    """``Q`` as a numpy or dask array of shape (N, dof), checked on the client."""
    if Q is None:
        raise InputError(f"Q: expected an array of shape (N, {arm.dof}), got None")
    if not isinstance(Q, da.Array):
        try:
            Q = np.asarray(Q)
        except (TypeError, ValueError) as e:
            raise InputError(f"Q: expected an array of shape (N, {arm.dof}) of numbers ({e})") from e
    if Q.ndim != 2 or Q.shape[1] != arm.dof:
        raise InputError(f"Q: expected an array of shape (N, {arm.dof}), got {tuple(Q.shape)}")
    if Q.dtype.kind not in "fiu" and Q.shape[0]:
        # The rule of every array argument, on the client: None, booleans, complex refused.
        arm.evaluate_many(np.asarray(Q[:1]), threads=1, raise_if_all_fail=False)
    return Q


def _wrench_rows(wrench: Any, rows: int):
    """None, one wrench for every row (numpy (6,)), or a per-row (N, 6) array to chunk."""
    if wrench is None:
        return None, False
    if isinstance(wrench, da.Array):
        w = wrench
    else:
        w = np.asarray(wrench)
    if w.ndim == 2 and w.shape[0] == rows and rows != 1 and w.shape[1] == 6:
        return w, True
    if isinstance(w, da.Array):
        w = w.compute()
    if w.shape == (1, 6):
        w = w[0]
    if w.shape != (6,):
        raise InputError(
            f"wrench: expected shape (6,), (1, 6) or ({rows}, 6) (one row of Q each), got {tuple(w.shape)}"
        )
    return w, False


def _block(x, a: int, b: int):
    """Rows a:b of a numpy array (a copy: it goes into the task graph) or of a dask array
    (a lazy slice, computed where the task runs)."""
    return x[a:b] if isinstance(x, da.Array) else np.ascontiguousarray(x[a:b])


class _Session:
    """The client a map runs on; one it started (``client`` None or an address) is closed
    when the map has run, unless the result is lazy."""

    def __init__(self, client):
        self.cluster = None
        self.owned = False
        if client is None:
            n = os.cpu_count() or 1
            self.cluster = distributed.LocalCluster(
                n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None
            )
            self.client = distributed.Client(self.cluster)
            self.owned = True
        elif isinstance(client, str):
            self.client = distributed.Client(client)
            self.owned = True
        elif isinstance(client, distributed.Client):
            self.client = client
        else:
            raise InputError(
                f"client: expected None, a scheduler address or a distributed.Client, got {type(client).__name__}"
            )

    def close(self):
        if self.owned:
            self.client.close()
            if self.cluster is not None:
                self.cluster.close()


def _shared_rows(client, arm, Q, wrench, per_row, fields, rows, wanted):
    """The shared file of a map (``_shared.SharedRows``, inputs copied in) when its workers
    see the client's ``/dev/shm`` and ``wanted`` is not False; else None (``wanted`` True:
    ``InputError``)."""
    if wanted is not None and not isinstance(wanted, bool):
        raise InputError(f"shared_memory: expected None, True or False, got {wanted!r}")
    if wanted is False:
        return None
    arrays = {name: ((rows, *shape(arm)), dtype) for name, (shape, dtype) in fields.items()}
    inputs = {"in:Q": Q}
    if per_row:
        inputs["in:wrench"] = wrench
    for name, x in inputs.items():
        # A dask array is computed where its chunks' tasks run; an array numpy cannot hold
        # in a numeric buffer travels as it is.
        if isinstance(x, np.ndarray) and x.dtype.kind in "fiu":
            arrays[name] = (x.shape, x.dtype)
    _, size = _shared.plan_layout(arrays)
    why = None
    if not _shared.room_for(size):
        why = f"{_shared.DIRECTORY} is missing or has not twice the {size:,} bytes free"
    else:
        rows_file = _shared.SharedRows(arrays)
        seen = client.run(_shared.sees, rows_file.layout.path, rows_file.layout.token)
        if seen and all(seen.values()):
            for name, x in inputs.items():
                if name in arrays:
                    rows_file.views[name][...] = x
            return rows_file
        rows_file.close()
        why = "a worker does not see the client's " + _shared.DIRECTORY if seen else "no worker"
    if wanted:
        raise InputError(f"shared_memory=True: {why}")
    return None


def _run(arm, Q, wrench, chunk, client, compute, progress, task, fields, shared_memory=None):
    """Cut ``Q`` into chunks, run ``task(model, Q_chunk, wrench_chunk, offset, names)`` on
    each, and stack the fields (in a shared file when the workers see it)."""
    if not isinstance(arm, ArmStiffness):
        raise InputError(f"arm: expected a sinew.ArmStiffness, got {type(arm).__name__}")
    if chunk is not None and (not isinstance(chunk, (int, np.integer)) or isinstance(chunk, bool)
                              or chunk < 1):
        raise InputError(f"chunk: expected a number of rows ≥ 1, got {chunk!r}")
    Q = _rows(arm, Q)
    rows = int(Q.shape[0])
    wrench, per_row = _wrench_rows(wrench, rows)
    session = _Session(client)
    shared = None
    try:
        if compute:
            shared = _shared_rows(session.client, arm, Q, wrench, per_row, fields, rows,
                                  shared_memory)
        elif shared_memory:
            raise InputError("shared_memory=True: a lazy map (compute=False) keeps its rows "
                             "on the cluster")
        # The model, once per worker (it pickles by value); the tasks refer to it by key. A
        # key of its own per map (hash=False): two maps of one model in a row on one client
        # would otherwise share the key, and the first's release could drop the second's data.
        model = session.client.scatter(arm, broadcast=True, hash=False)
        names = list(fields)
        if chunk is None:
            workers = max(1, len(session.client.scheduler_info().get("workers", {})))
            chunk = max(DEFAULT_CHUNK, -(-rows // (TASKS_PER_WORKER * workers)))
        starts = list(range(0, rows, int(chunk)))
        parts = []
        for a in starts:
            b = min(a + int(chunk), rows)
            if shared is None:
                w = _block(wrench, a, b) if per_row else wrench
                parts.append((a, b, dask.delayed(task, pure=True)(model, _block(Q, a, b), w, a,
                                                                  names)))
                continue
            # Only the row range travels, with the inputs the file could not hold.
            layout = shared.layout
            q = None if "in:Q" in layout.arrays else _block(Q, a, b)
            w = (None if "in:wrench" in layout.arrays else _block(wrench, a, b)) if per_row \
                else wrench
            parts.append((a, b, dask.delayed(_shared.run_chunk, pure=True)(
                task, model, layout, a, b, q, w, per_row, names)))
        if compute:
            futures = session.client.compute([p for _, _, p in parts])
            if progress:
                distributed.progress(futures)
            # Each chunk's result fetched as soon as its task ends (while the others run) and
            # copied into its rows, then let go on the worker: no gather at the end, no
            # concatenation.
            out = ({name: shared.views[name] for name in fields} if shared is not None else
                   {name: np.empty((rows, *shape(arm)), dtype=dtype)
                    for name, (shape, dtype) in fields.items()})
            errors = [[] for _ in parts]
            chunk_of = {f.key: i for i, f in enumerate(futures)}
            for future, done in distributed.as_completed(futures, with_results=True):
                i = chunk_of[future.key]
                a, b, _ = parts[i]
                if not done.get("shared"):
                    for name in fields:
                        out[name][a:b] = done[name]
                errors[i] = done["errors"]
                future.release()
            out["errors"] = _all_errors(*errors)
            if rows and len(out["errors"]) == rows:
                # As evaluate_many / plan_many: a map whose every row failed raises.
                _, kind, message = out["errors"][0]
                raise _EXCEPTIONS.get(kind, NumericalError)(f"every row failed; row 0: {message}")
            return MapResult(out)
        out = {}
        for name, (shape, dtype) in fields.items():
            blocks = [da.from_delayed(p[name], shape=(b - a, *shape(arm)), dtype=dtype)
                      for a, b, p in parts]
            out[name] = (da.concatenate(blocks) if blocks
                         else da.zeros((0, *shape(arm)), dtype=dtype))
        out["errors"] = dask.delayed(_all_errors)(*[p["errors"] for _, _, p in parts])
        lazy = MapResult(out, session.client)
        lazy._session = session  # keeps a cluster it started alive while the result lives
        session = None
        return lazy
    finally:
        if shared is not None:
            shared.close()
        if session is not None:
            session.close()


def map_evaluate(
    arm: ArmStiffness,
    Q: Any,
    wrench: Any = None,
    levels: Any = None,
    policy: Optional[str] = None,
    chunk: Optional[int] = None,
    client: Any = None,
    compute: bool = True,
    progress: bool = False,
    fields: Optional[list] = None,
    shared_memory: Optional[bool] = None,
) -> MapResult:
    """``arm.evaluate_many(Q, wrench, levels=…, policy=…)`` on a Dask cluster, chunk by chunk
    (``threads=1`` per chunk): the same fields, bit for bit, failed rows included. ``Q`` is
    (N, dof), a numpy or dask array; ``wrench`` one (6,) for every row or (N, 6); ``fields``
    the names of ``BatchResult``'s fields to keep (None: all); ``shared_memory`` whether the
    rows go through ``/dev/shm`` instead of Dask (None: when every worker sees the client's,
    True: required, False: never; see the module's text)."""
    chosen = _chosen(_EVALUATE, fields)
    Q = _rows(arm, Q)
    if levels is not None:
        levels = np.asarray(levels, dtype=np.float64)
    # The arguments checked on the client, once, on at most one row.
    w, per_row = _wrench_rows(wrench, int(Q.shape[0]))
    arm.evaluate_many(np.zeros((0, arm.dof)), None if w is None or per_row else w,
                      levels=levels, policy=policy, threads=1)

    return _run(arm, Q, wrench, chunk, client, compute, progress,
                functools.partial(_evaluate_chunk, levels=levels, policy=policy), chosen,
                shared_memory)


def map_plan(
    arm: ArmStiffness,
    Q: Any,
    wrench: Any = None,
    chunk: Optional[int] = None,
    client: Any = None,
    compute: bool = True,
    progress: bool = False,
    fields: Optional[list] = None,
    shared_memory: Optional[bool] = None,
    **options: Any,
) -> MapResult:
    """``arm.plan_many(Q, wrench, **options)`` on a Dask cluster, chunk by chunk (``threads=1``
    per chunk): the same fields, bit for bit, failed rows included. ``options`` are
    ``plan``'s (``objective``, ``direction``, ``k_min``, ``margin``, ``budget``, …); ``fields``
    the names of ``PlanBatchResult``'s fields to keep (None: all); ``shared_memory`` as
    ``map_evaluate``'s."""
    chosen = _chosen(_plan_fields(arm), fields)
    for bad in ("threads", "raise_if_all_fail"):
        if bad in options:
            raise InputError(f"{bad}: map_plan sets it (threads=1 per chunk)")
    Q = _rows(arm, Q)
    w, per_row = _wrench_rows(wrench, int(Q.shape[0]))
    arm.plan_many(np.zeros((0, arm.dof)), None if w is None or per_row else w, threads=1,
                  **options)
    return _run(arm, Q, wrench, chunk, client, compute, progress,
                functools.partial(_plan_chunk, options=options), chosen, shared_memory)
