"""Shared fixtures: the repository's robots and the `sinew` command (its JSON is the reference)."""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import sinew

ROOT = Path(__file__).resolve().parents[3]
CDHRM5 = ROOT / "robots" / "cdhrm5"
UA3X4 = ROOT / "robots" / "ua3x4"
# The E4 pose and load of the paper (src/paper/experiments.rs: E4_Q, E4_F0).
E4_Q = np.pi * np.array([-1 / 7, -1 / 9, -1 / 9, -1 / 11, 1 / 6, 1 / 7, 1 / 8, -1 / 15, -1 / 12, -1 / 10])
E4_F0 = np.array([0.0, 5.0, 0.0, 0.0, 0.0, 0.0])
TOL = 1e-12


def sinew_bin() -> Path:
    """The `sinew` binary `cargo test --workspace` built (or $SINEW_BIN)."""
    path = Path(os.environ.get("SINEW_BIN", ROOT / "target" / "debug" / "sinew"))
    if not path.is_file():
        pytest.fail(f"{path} not found: run `cargo build -p sinew-cli` (cargo xtask test does)")
    return path


def cli(*args: str, expect: int = 0) -> dict:
    """Run `sinew ARGS --json` and return its JSON document (or stderr when it fails)."""
    done = subprocess.run(
        [str(sinew_bin()), *args, "--json"], capture_output=True, text=True, cwd=ROOT
    )
    assert done.returncode == expect, done.stderr
    return json.loads(done.stdout) if expect == 0 else {"stderr": done.stderr.strip()}


def csv(values) -> str:
    return ",".join(repr(float(v)) for v in np.ravel(values))


def close(a, b, tol: float = TOL) -> None:
    """`a` equals the JSON value `b` (None ↔ None) to `tol` relative to the largest entry."""
    if b is None:
        assert a is None
        return
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    assert a.shape == b.shape, (a.shape, b.shape)
    scale = max(1.0, float(np.max(np.abs(b))) if b.size else 1.0)
    assert np.max(np.abs(a - b), initial=0.0) <= tol * scale, np.max(np.abs(a - b))


@pytest.fixture(scope="session")
def robot() -> sinew.Robot:
    return sinew.load_robot(CDHRM5)


@pytest.fixture(scope="session")
def decoupled(robot) -> sinew.Routing:
    return sinew.load_routing(robot, "decoupled")


@pytest.fixture(scope="session")
def routed(robot) -> sinew.Routing:
    return sinew.load_routing(robot, "routed")


@pytest.fixture(scope="session")
def arm(robot, decoupled) -> sinew.ArmStiffness:
    return sinew.ArmStiffness(robot, decoupled)
