"""Rows in shared memory, for a map whose workers run on the client's host (``sinew.dask``).

On one machine most of a map's cost past the evaluation itself is moving bytes: every chunk's
``Q`` goes through the task graph to a worker, and every chunk's result (858 bytes a row of
cdhrm5 with every field) comes back through the scheduler's TCP connection, is deserialised
by the client and copied into its rows. With two cores the client's share of that work is
taken from the workers.

When the workers see the client's ``/dev/shm`` (checked, not assumed: each worker reads a
random token the client wrote into the file), the client instead lays the inputs and every
field of the result out in one file there, and each task reads its rows of ``Q`` and writes
its rows of the result in place. Only the row range and the failed rows' errors travel. The
file is unlinked when the map ends (its pages live on while the result's arrays do, and go
with the last of them), and on any error. A task that runs twice (a worker lost mid-run)
writes the same bits twice.

This is the layout of the file: a 64-byte header (the token), then each array, C-contiguous,
at an offset aligned to 64 bytes.
"""

from __future__ import annotations

import mmap
import os
import secrets
import uuid
from typing import Any, Optional

import numpy as np

DIRECTORY = "/dev/shm"
"""Where the files are made: a tmpfs on Linux. Elsewhere the maps send their rows by Dask."""

_HEADER = 64


def _aligned(n: int) -> int:
    return (n + 63) // 64 * 64


class Layout:
    """Where each array lives in the file: ``name -> (offset, shape, dtype)``; small, so it
    travels with every task."""

    def __init__(self, path: str, token: bytes, arrays: dict):
        self.path = path
        self.token = token
        self.arrays = arrays
        self.size = max([_HEADER] + [off + int(np.prod(shape)) * np.dtype(dt).itemsize
                                     for off, shape, dt in arrays.values()])

    def views(self, buffer) -> dict:
        """Every array of the layout, as a numpy view of ``buffer`` (a map of the file)."""
        return {name: np.ndarray(shape, dtype=dt, buffer=buffer, offset=off)
                for name, (off, shape, dt) in self.arrays.items()}


def plan_layout(arrays: dict) -> tuple[dict, int]:
    """Offsets for ``{name: (shape, dtype)}`` after the header, and the bytes they take."""
    out = {}
    at = _HEADER
    for name, (shape, dtype) in arrays.items():
        out[name] = (at, tuple(int(s) for s in shape), np.dtype(dtype).str)
        at = _aligned(at + int(np.prod(shape)) * np.dtype(dtype).itemsize)
    return out, at


class SharedRows:
    """The client's side: the file made, mapped and filled with the inputs; ``views`` are
    its arrays. ``close`` unlinks the file (the arrays stay valid)."""

    def __init__(self, arrays: dict):
        layout, size = plan_layout(arrays)
        path = os.path.join(DIRECTORY, f"sinew-map-{uuid.uuid4().hex}")
        token = secrets.token_bytes(16)
        fd = os.open(path, os.O_CREAT | os.O_EXCL | os.O_RDWR, 0o600)
        try:
            os.ftruncate(fd, size)
            self._map = mmap.mmap(fd, size)
        except BaseException:
            os.close(fd)
            os.unlink(path)
            raise
        os.close(fd)
        self._map[:16] = token
        self.layout = Layout(path, token, layout)
        self.views = self.layout.views(self._map)

    def close(self) -> None:
        """Unlink the file: no worker can open it any more; the client's arrays live on."""
        try:
            os.unlink(self.layout.path)
        except FileNotFoundError:
            pass


def room_for(size: int) -> bool:
    """Whether ``DIRECTORY`` exists and has twice ``size`` bytes free, and 8 MB more (a full
    tmpfs would kill the worker writing into it with SIGBUS, not raise)."""
    try:
        st = os.statvfs(DIRECTORY)
    except OSError:
        return False
    return st.f_bavail * st.f_frsize >= 2 * size + (8 << 20)


def sees(path: str, token: bytes) -> bool:
    """Run on a worker: whether it opens the client's file and reads the client's token."""
    try:
        with open(path, "rb") as f:
            return f.read(16) == token
    except OSError:
        return False


def open_rows(layout: Layout) -> tuple[Any, dict]:
    """A worker's map of the file and its arrays. Raises ``RuntimeError`` (the task fails,
    with the reason) when the file is not there: a worker on another host joined the map."""
    try:
        with open(layout.path, "r+b") as f:
            buffer = mmap.mmap(f.fileno(), layout.size)
    except OSError as e:
        raise RuntimeError(
            f"sinew.dask: this worker cannot open the client's shared rows {layout.path} ({e}); "
            "pass shared_memory=False when workers join from other hosts during a map"
        ) from e
    if buffer[:16] != layout.token:
        buffer.close()
        raise RuntimeError(f"sinew.dask: {layout.path} is not this map's file")
    return buffer, layout.views(buffer)


def run_chunk(task, arm, layout: Layout, a: int, b: int, q: Optional[Any], wrench: Any,
              per_row: bool, names: list) -> dict:
    """One task on shared rows: ``Q[a:b]`` (and the wrench's rows) read from the file unless
    given, ``task`` run with rows ``a:b`` of its fields ``names`` as ``out`` (written in place
    by ``evaluate_many``; copied there otherwise); only the errors go back."""
    buffer, views = open_rows(layout)
    try:
        if q is None:
            q = views["in:Q"][a:b]
        if per_row and wrench is None:
            wrench = views["in:wrench"][a:b]
        out = {name: views[name][a:b] for name in names}
        done = task(arm, q, wrench, a, names, out=out)
        if not done.get("written"):
            for name in names:
                out[name][...] = done[name]
        return {"errors": done["errors"], "shared": True}
    finally:
        views = q = wrench = out = None
        try:
            buffer.close()
        except BufferError:  # a traceback still holds a view: the collector unmaps it
            pass
