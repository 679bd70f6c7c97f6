"""Where a shared-rows map's time goes beyond the ideal (docs/performance.md, issue #28): the
same 62 500-row chunk of cdhrm5 (decoupled, E4's load, levels 0.5) timed alone in this process,
then each of a 10**6-row map's 16 tasks timed inside its worker (wall and CPU time), the client
process's CPU time during the map, and the set-up of the shared file.

Build the release module first, as scale.py says, then:
    target/py-bench/bin/python crates/sinew-py/bench/map_tasks.py
"""

import functools
import os
import time
from pathlib import Path

import distributed
import numpy as np

import sinew
import sinew._shared
import sinew.dask

ROOT = Path(__file__).resolve().parents[3]
E4_F0 = np.array([0.0, 5.0, 0.0, 0.0, 0.0, 0.0])
LEVELS = np.array([0.5] * 5)
ROWS, CHUNK = 1_000_000, 62_500


def timed(task, arm, layout, a, b, names):
    """One task of the map, as ``_shared.run_chunk`` runs it, timed where it runs."""
    t, c = time.perf_counter(), time.process_time()
    sinew._shared.run_chunk(task, arm, layout, a, b, None, E4_F0, False, names)
    return time.perf_counter() - t, time.process_time() - c, os.getpid()


def main():
    robot = sinew.load_robot(ROOT / "robots" / "cdhrm5")
    arm = sinew.ArmStiffness(robot, sinew.load_routing(robot, "decoupled"))
    rng = np.random.default_rng(1)
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]
    Q = lo + (hi - lo) * rng.random((ROWS, robot.dof))
    alone = []
    for a in range(0, 4 * CHUNK, CHUNK):
        t = time.perf_counter()
        arm.evaluate_many(Q[a:a + CHUNK], E4_F0, levels=LEVELS, threads=1)
        alone.append(time.perf_counter() - t)
    print(f"one {CHUNK}-row chunk in this process: {min(alone) * 1e3:.0f}–{max(alone) * 1e3:.0f} ms")
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
    client = distributed.Client(cluster)
    fields = sinew.dask._EVALUATE
    task = functools.partial(sinew.dask._evaluate_chunk, levels=LEVELS, policy=None)
    try:
        for _ in range(2):
            t, c = time.perf_counter(), time.process_time()
            shared = sinew.dask._shared_rows(client, arm, Q, E4_F0, False, fields, ROWS, True)
            setup = time.perf_counter() - t
            model = client.scatter(arm, broadcast=True, hash=False)
            futures = [client.submit(timed, task, model, shared.layout, a, a + CHUNK,
                                     list(fields), pure=False) for a in range(0, ROWS, CHUNK)]
            done = client.gather(futures)
            wall, cpu = time.perf_counter() - t, time.process_time() - c
            shared.close()
            shared = None
            walls = np.array([d[0] for d in done])
            cpus = np.array([d[1] for d in done])
            print(f"map: {wall:.3f} s; shared file set up in {setup * 1e3:.0f} ms; client CPU "
                  f"{cpu:.2f} s; a task in its worker: {walls.mean() * 1e3:.0f} ms wall, "
                  f"{cpus.mean() * 1e3:.0f} ms CPU (mean of {len(done)})")
    finally:
        client.close()
        cluster.close()


if __name__ == "__main__":
    main()
