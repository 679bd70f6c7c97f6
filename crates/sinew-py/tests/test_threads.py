"""threads=: a pool of that size (never the global one), one core for threads=1, the same
numbers whatever the count, and the GIL released (two Python threads evaluate at once)."""

import os
import threading
import time

import numpy as np
import pytest

import sinew
from sinew import _sinew
from conftest import E4_F0
from test_pickle import BATCH, rows, same


def test_the_pool_has_the_threads_asked_for():
    # rayon's own count, read inside the pool the call runs on.
    assert _sinew._pool_threads(1) == 1
    assert _sinew._pool_threads(3) == 3
    expected = int(os.environ.get("RAYON_NUM_THREADS", 0)) or os.cpu_count()
    assert _sinew._pool_threads() == expected
    for bad in [0, -1]:
        with pytest.raises(sinew.InputError, match="threads"):
            _sinew._pool_threads(bad)


def test_every_thread_count_gives_the_same_numbers(robot, arm, decoupled):
    Q = rows(robot, 300)
    ref = arm.evaluate_many(Q, E4_F0, levels=[0.5] * 5)
    for threads in [1, 2, 3]:
        b = arm.evaluate_many(Q, E4_F0, levels=[0.5] * 5, threads=threads)
        for name in BATCH:
            same(getattr(b, name), getattr(ref, name))
        assert b.errors == ref.errors
    p1 = arm.plan_many(Q[:8], E4_F0, threads=1)
    p2 = arm.plan_many(Q[:8], E4_F0, threads=2)
    for name in ["ok", "value", "tensions", "c_x", "iterations"]:
        same(getattr(p1, name), getattr(p2, name))
    s1 = sinew.sweep(robot, decoupled, 0, [0.3, 0.3], points=11, threads=1)
    s = sinew.sweep(robot, decoupled, 0, [0.3, 0.3], points=11)
    for name in ["feasible", "k_x_min", "k_y_max"]:
        same(getattr(s1, name), getattr(s, name))
    for call in [lambda: arm.evaluate_many(Q, threads=0), lambda: arm.plan_many(Q, threads=-2),
                 lambda: sinew.sweep(robot, decoupled, 0, [0.3, 0.3], threads=0)]:
        with pytest.raises(sinew.InputError, match="threads"):
            call()


def test_threads_1_uses_one_core(robot, arm):
    # CPU time over wall time of a long batch: about 1 on one thread (a loose bound: the
    # machine is shared), where the global pool would use every core.
    Q = np.tile(rows(robot, 1000), (20, 1))
    arm.evaluate_many(Q[:1000], E4_F0, levels=[0.5] * 5, threads=1)
    wall, cpu = time.perf_counter(), time.process_time()
    arm.evaluate_many(Q, E4_F0, levels=[0.5] * 5, threads=1)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    assert wall > 0.05, wall
    assert cpu / wall < 1.3, (cpu, wall)


def test_two_python_threads_evaluate_at_once(robot, arm):
    Q = np.tile(rows(robot, 1000), (8, 1))
    expected = arm.evaluate_many(Q, E4_F0, levels=[0.5] * 5, threads=1)
    start = threading.Barrier(2)
    spans, results = [None, None], [None, None]

    def work(k):
        start.wait()
        t = time.perf_counter()
        results[k] = arm.evaluate_many(Q, E4_F0, levels=[0.5] * 5, threads=1)
        spans[k] = (t, time.perf_counter())

    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    # With the GIL held for the call, the second call could only begin once the first had
    # returned; released, each begins before the other ends.
    assert max(s[0] for s in spans) < min(s[1] for s in spans), spans
    for r in results:
        for name in BATCH:
            same(getattr(r, name), getattr(expected, name))
        assert r.errors == expected.errors
