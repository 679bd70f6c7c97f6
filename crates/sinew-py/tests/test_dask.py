"""sinew.dask on a LocalCluster of two single-threaded worker processes: the maps equal the
in-process batch calls bit for bit (failed rows included), the model is scattered once per
worker, lazy results are dask arrays, and a worker killed mid-run loses nothing."""

import glob
import mmap
import os
import signal
import threading
import time

import dask.array as da
import distributed
import numpy as np
import pytest

import sinew
import sinew.dask
from conftest import E4_F0, E4_Q
from test_pickle import BATCH, rows, same

LEVELS = [0.5] * 5
PLAN = ["ok", "value", "gap", "tensions", "total_tension", "levels", "k_fd", "c_x",
        "min_eigenvalue", "stable", "iterations"]


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
    client = distributed.Client(cluster)
    yield client
    client.close()
    cluster.close()


def workspace(robot, n, seed=5):
    """n rows: inside the limits, with failed rows (outside, NaN) spread through."""
    Q = rows(robot, n, seed)
    Q[1::997, 1] = 4.0
    Q[3::1999, 6] = np.nan
    return Q


@pytest.fixture(scope="module")
def big(robot, arm):
    """50 000 rows and their in-process batch (two tests compare with it)."""
    Q = workspace(robot, 50_000)
    return Q, arm.evaluate_many(Q, E4_F0, levels=LEVELS)


def equal(m, b, fields):
    for name in fields:
        same(getattr(m, name), getattr(b, name))
    assert m.errors == b.errors


def test_map_evaluate_equals_evaluate_many(client, big, arm):
    Q, b = big
    assert 50 < len(b.errors) < 200
    m = sinew.dask.map_evaluate(arm, Q, wrench=E4_F0, levels=LEVELS, chunk=10_000, client=client)
    assert len(m) == 50_000
    equal(m, b, BATCH)
    # A policy, a per-row wrench, a chunk that does not divide the rows, a dask Q.
    W = np.zeros((5_000, 6))
    W[:, 1] = np.linspace(0, 6, 5_000)
    b = arm.evaluate_many(Q[:5_000], W, policy="least-norm")
    m = sinew.dask.map_evaluate(arm, da.from_array(Q[:5_000], chunks=(700, 10)), wrench=W,
                                policy="least-norm", chunk=1_234, client=client)
    equal(m, b, BATCH)


def test_map_plan_equals_plan_many(client, robot, arm):
    # The 50 000 rows, failed rows spread through (outside the limits, NaN), and one
    # rank-deficient pose; five tasks of 10 000 plans.
    Q = workspace(robot, 50_000, seed=9)
    Q[17] = 0.0  # rank-deficient: typed in its row
    b = arm.plan_many(Q, E4_F0, "stiffness-along", direction=[0, 1, 0])
    kinds = {kind for _, kind, _ in b.errors}
    assert {"input", "rank-deficient"} <= kinds, kinds
    assert 35_000 < b.ok.sum() < 49_900  # most rows plan; the failed ones are rows too
    m = sinew.dask.map_plan(arm, Q, wrench=E4_F0, objective="stiffness-along",
                            direction=[0, 1, 0], chunk=10_000, client=client)
    assert len(m) == 50_000
    equal(m, b, PLAN)


def test_fields_and_maps_back_to_back(client, robot, arm):
    # Only the fields asked for come back ("ok" always), equal to the batch's; two maps of
    # one model in a row on one client (each scatters the model under a key of its own: with
    # a shared key the first's release could drop the second's model: "lost dependencies").
    Q = workspace(robot, 4_000, seed=11)
    b = arm.evaluate_many(Q, E4_F0, levels=LEVELS)
    names = ["stable", "min_eigenvalue", "k_fd"]
    for _ in range(2):
        m = sinew.dask.map_evaluate(arm, Q, wrench=E4_F0, levels=LEVELS, chunk=1_000,
                                    client=client, fields=names)
        assert m._names == ["ok"] + names + ["errors"]
        assert not hasattr(m, "c_x") and not hasattr(m, "tensions")
        equal(m, b, ["ok"] + names)
    lazy = sinew.dask.map_evaluate(arm, Q, wrench=E4_F0, levels=LEVELS, chunk=1_000,
                                   client=client, fields=["k_fd", "ok"], compute=False)
    assert lazy._names == ["k_fd", "ok", "errors"]
    equal(lazy.compute(), b, ["k_fd", "ok"])
    p = sinew.dask.map_plan(arm, Q[:200], wrench=E4_F0, objective="volume", chunk=100,
                            client=client, fields=["value", "gap"])
    bp = arm.plan_many(Q[:200], E4_F0, "volume")
    equal(p, bp, ["ok", "value", "gap"])
    for fields, match in [(["k_q"], "no field 'k_q'"), ("k_fd", "list of field names"),
                          ([3], "list of field names")]:
        with pytest.raises(sinew.InputError, match=match):
            sinew.dask.map_evaluate(arm, Q, wrench=E4_F0, levels=LEVELS, client=client,
                                    fields=fields)
    with pytest.raises(sinew.InputError, match="no field 'k_x'"):  # a plan has no K_x
        sinew.dask.map_plan(arm, Q, wrench=E4_F0, objective="volume", client=client,
                            fields=["k_x"])


def test_the_model_is_scattered_once_per_worker(client, robot, arm):
    Q = workspace(robot, 2_000)

    def models():
        return client.run(lambda dask_worker: [str(k) for k in dask_worker.data.keys()
                                               if str(k).startswith("ArmStiffness-")])

    # The models earlier maps scattered are released once their maps return (asynchronously).
    deadline = time.monotonic() + 10
    while any(models().values()) and time.monotonic() < deadline:
        time.sleep(0.05)
    lazy = sinew.dask.map_evaluate(arm, Q, wrench=E4_F0, levels=LEVELS, chunk=500,
                                   client=client, compute=False)
    held = models()
    assert len(held) == 2
    for keys in held.values():
        assert len(keys) == 1, held
    # Lazy: dask arrays of the right shapes, nothing run yet; then the numbers.
    assert isinstance(lazy.ok, da.Array) and lazy.c_x.shape == (2_000, 6, 6)
    assert lazy.tensions.chunks[0] == (500,) * 4
    done = lazy.compute()
    equal(done, arm.evaluate_many(Q, E4_F0, levels=LEVELS), BATCH)
    assert isinstance(done.k_fd, np.ndarray)


def test_a_scheduler_address_and_bad_arguments(client, robot, arm):
    Q = workspace(robot, 3_000)
    m = sinew.dask.map_evaluate(arm, Q, wrench=E4_F0, levels=LEVELS, chunk=1_000,
                                client=client.scheduler.address)
    equal(m, arm.evaluate_many(Q, E4_F0, levels=LEVELS), BATCH)
    for kw, match in [(dict(Q=None), "Q: expected an array of shape"),
                      (dict(Q=np.zeros((3, 4))), r"Q: .*\(N, 10\), got \(3, 4\)"),
                      (dict(Q=np.zeros((3, 10), dtype=complex)), "Q: .*complex"),
                      (dict(Q=Q, wrench=np.zeros((2, 6))), "wrench: expected shape"),
                      (dict(Q=Q, levels=[2.0] * 5), "levels"),
                      (dict(Q=Q, policy="cheapest"), "policy"),
                      (dict(Q=Q, chunk=0), "chunk"),
                      (dict(Q=Q, client=3), "client")]:
        with pytest.raises(sinew.InputError, match=match):
            sinew.dask.map_evaluate(arm, **{"client": client, **kw})
    with pytest.raises(sinew.InputError, match="objective"):
        sinew.dask.map_plan(arm, Q, objective="stiffest", client=client)


def test_client_none_starts_a_local_cluster(robot, arm):
    Q = workspace(robot, 1_000)
    m = sinew.dask.map_evaluate(arm, Q, wrench=E4_F0, levels=LEVELS, chunk=400)
    equal(m, arm.evaluate_many(Q, E4_F0, levels=LEVELS), BATCH)


def shared(a):
    """Whether ``a`` is a view of a memory map (the shared file of a map)."""
    while isinstance(a, np.ndarray):
        a = a.base
    return isinstance(a, mmap.mmap)


def leftovers():
    return sorted(glob.glob(os.path.join(sinew._shared.DIRECTORY, "sinew-map-*")))


def test_shared_memory_and_dask_carry_the_same_bits(client, robot, arm, monkeypatch):
    Q = workspace(robot, 6_000, seed=13)
    before = leftovers()
    b = arm.evaluate_many(Q, E4_F0, levels=LEVELS)
    W = np.zeros((6_000, 6))
    W[:, 1] = np.linspace(0, 6, 6_000)
    # A machine whose /dev/shm is small (a container's 64 MB) maps through Dask instead; every
    # map below needs under 10 MB.
    roomy = sinew._shared.room_for(10 << 20)
    if not roomy:
        with pytest.raises(sinew.InputError, match="shared_memory=True: "):
            sinew.dask.map_evaluate(arm, Q, levels=LEVELS, client=client, shared_memory=True)
    for wanted in ((None, True, False) if roomy else (None, False)):
        m = sinew.dask.map_evaluate(arm, Q, wrench=E4_F0, levels=LEVELS, chunk=1_000,
                                    client=client, shared_memory=wanted)
        equal(m, b, BATCH)
        # Through /dev/shm unless told not to: the fields are views of the map's file.
        assert all(shared(getattr(m, f)) == (wanted is not False and roomy) for f in BATCH)
        # Per-row wrenches, a Fortran-order float32 Q, a dask Q: read where they are.
        for q in (Q, np.asfortranarray(Q.astype(np.float32)), da.from_array(Q, chunks=777)):
            expected = arm.evaluate_many(q if isinstance(q, np.ndarray) else Q, W,
                                         levels=LEVELS)
            m = sinew.dask.map_evaluate(arm, q, wrench=W, levels=LEVELS, chunk=1_500,
                                        client=client, shared_memory=wanted)
            equal(m, expected, BATCH)
    p = sinew.dask.map_plan(arm, Q[:300], wrench=E4_F0, objective="volume", chunk=100,
                            client=client)
    equal(p, arm.plan_many(Q[:300], E4_F0, "volume"), PLAN)
    assert shared(p.value) == roomy
    # Nothing is left behind, after a map or after one whose every row failed.
    with pytest.raises(sinew.InputError, match="every row failed"):
        sinew.dask.map_evaluate(arm, Q[:50] + 9.0, levels=LEVELS, client=client)
    assert leftovers() == before
    # No room (or no /dev/shm): through Dask, or an error when it was required.
    monkeypatch.setattr(sinew._shared, "DIRECTORY", "/nonexistent-sinew-shm")
    m = sinew.dask.map_evaluate(arm, Q[:2_000], wrench=E4_F0, levels=LEVELS, chunk=500,
                                client=client)
    assert not shared(m.k_fd)
    equal(m, arm.evaluate_many(Q[:2_000], E4_F0, levels=LEVELS), BATCH)
    with pytest.raises(sinew.InputError, match="shared_memory=True: /nonexistent-sinew-shm"):
        sinew.dask.map_evaluate(arm, Q, levels=LEVELS, client=client, shared_memory=True)
    monkeypatch.undo()
    for kw, match in [(dict(shared_memory="yes"), "shared_memory: expected None, True"),
                      (dict(shared_memory=True, compute=False), "lazy map")]:
        with pytest.raises(sinew.InputError, match=match):
            sinew.dask.map_evaluate(arm, Q, levels=LEVELS, client=client, **kw)
    # A worker that cannot read the client's file, or reads another token, says so.
    assert not sinew._shared.sees("/nonexistent-sinew-shm/x", b"0" * 16)


def test_a_worker_killed_mid_run(client, big, arm):
    # Last in the module: its cluster loses a worker (the nanny starts another).
    Q, expected = big
    pids = client.run(os.getpid)
    victim = sorted(pids)[0]
    out = {}

    def run():
        out["map"] = sinew.dask.map_evaluate(arm, Q, wrench=E4_F0, levels=LEVELS, chunk=1_000,
                                             client=client)

    t = threading.Thread(target=run)
    t.start()
    deadline = time.monotonic() + 60
    while not client.processing().get(victim) and time.monotonic() < deadline:
        time.sleep(0.005)
    assert client.processing().get(victim), "the victim never got a task"
    os.kill(pids[victim], signal.SIGKILL)
    killed_while_running = t.is_alive()
    t.join(120)
    assert killed_while_running and not t.is_alive()
    m = out["map"]
    assert len(m) == 50_000
    equal(m, expected, BATCH)
