"""Timings of the Python bindings (docs/performance.md): `evaluate` per call on cdhrm5 (E4,
levels 0.5, conversion included) and `evaluate_many` on the 10 000 configurations of
`examples/batch_loop.rs` (the Rust loop it is compared with).

Build the release module first, in its own virtualenv:
    python3 -m venv target/py-bench && target/py-bench/bin/pip install maturin numpy
    (cd crates/sinew-py && VIRTUAL_ENV=$PWD/../../target/py-bench ../../target/py-bench/bin/maturin develop --release)
    target/py-bench/bin/python crates/sinew-py/bench/bench.py
"""

import time
from pathlib import Path

import numpy as np

import sinew

ROOT = Path(__file__).resolve().parents[3]
E4_Q = np.pi * np.array([-1 / 7, -1 / 9, -1 / 9, -1 / 11, 1 / 6, 1 / 7, 1 / 8, -1 / 15, -1 / 12, -1 / 10])
E4_F0 = np.array([0.0, 5.0, 0.0, 0.0, 0.0, 0.0])


def configurations(robot, rows=10_000):
    """The linear congruential sequence of batch_loop.rs."""
    state = 12345
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]
    out = np.empty((rows, robot.dof))
    mask = (1 << 64) - 1
    for r in range(rows):
        for j in range(robot.dof):
            state = (state * 6364136223846793005 + 1442695040888963407) & mask
            u = (state >> 11) / float(1 << 53)
            out[r, j] = lo[j] + (hi[j] - lo[j]) * (0.25 + 0.5 * u)
    return out


def loop(f, calls):
    """`f()` `calls` times, each result dropped before the next call (as in a user's loop)."""
    for _ in range(calls):
        f()


def best(f, repeat):
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


robot = sinew.load_robot(ROOT / "robots" / "cdhrm5")
arm = sinew.ArmStiffness(robot, sinew.load_routing(robot, "decoupled"))
levels = np.full(5, 0.5)
calls = 20_000
for _ in range(1000):
    arm.evaluate(E4_Q, E4_F0, levels=levels)
per_call = best(lambda: loop(lambda: arm.evaluate(E4_Q, E4_F0, levels=levels), calls), 5) / calls
print(f"evaluate (cdhrm5, E4, levels): {per_call * 1e6:.2f} µs per call (best of 5 × {calls})")

# The arrays are made when first read: the same call, then reading K_fd, then every attribute.
def with_k_fd():
    return arm.evaluate(E4_Q, E4_F0, levels=levels).k_fd


ATTRIBUTES = [name for name in dir(sinew.ArmResult) if not name.startswith("_")]


def with_everything():
    r = arm.evaluate(E4_Q, E4_F0, levels=levels)
    return [getattr(r, name) for name in ATTRIBUTES]


for label, f in [("evaluate + .k_fd", with_k_fd), (f"evaluate + all {len(ATTRIBUTES)} attributes", with_everything)]:
    t = best(lambda: loop(f, calls), 5) / calls
    print(f"{label}: {t * 1e6:.2f} µs per call (best of 5 × {calls})")

Q = configurations(robot)
batch = best(lambda: arm.evaluate_many(Q, E4_F0, levels=levels), 10)
ok = int(arm.evaluate_many(Q, E4_F0, levels=levels).ok.sum())
print(f"evaluate_many: 10000 configurations in {batch * 1e3:.2f} ms (best of 10; {ok} ok), "
      f"{batch * 1e6 / 10_000:.3f} µs per row")
