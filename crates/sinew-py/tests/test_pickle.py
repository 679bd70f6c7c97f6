"""Pickling by value: every class round-trips to an object that evaluates bit for bit like the
original, in this interpreter and in a fresh one with the robot folder deleted."""

import copy
import pickle
import shutil
import subprocess
import sys

import numpy as np
import pytest

import sinew
from conftest import CDHRM5, E4_F0, E4_Q, UA3X4


def rows(robot, n=200, seed=3):
    """Seeded rows inside the limits, two outside them and one NaN (failed rows)."""
    rng = np.random.default_rng(seed)
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]
    Q = lo + (hi - lo) * (0.1 + 0.8 * rng.random((n, robot.dof)))
    Q[5, 0] = hi[0] + 0.1
    Q[7, 3] = lo[3] - 0.1
    Q[11, 2] = np.nan
    return Q


def same(a, b):
    """Bit for bit (NaNs included), shapes and dtypes too."""
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape and a.dtype == b.dtype, (a.shape, b.shape, a.dtype, b.dtype)
    assert a.tobytes() == b.tobytes()


BATCH = ["ok", "stable", "min_eigenvalue", "t0", "tensions", "c_x", "k_x", "k_fd"]
ONE = ["t0", "tensions", "k_q", "k_w", "j_x", "c_x", "k_x", "k_fd", "eigenvalues"]


def same_arm(a, b, robot):
    Q = rows(robot)
    x, y = a.evaluate_many(Q, E4_F0, levels=[0.5] * 5), b.evaluate_many(Q, E4_F0, levels=[0.5] * 5)
    for name in BATCH:
        same(getattr(x, name), getattr(y, name))
    assert x.errors == y.errors and len(x.errors) == 3
    r, s = a.evaluate(E4_Q, E4_F0, levels=[0.5] * 5), b.evaluate(E4_Q, E4_F0, levels=[0.5] * 5)
    for name in ONE:
        same(getattr(r, name), getattr(s, name))
    assert r.min_eigenvalue == s.min_eigenvalue
    p = a.plan_many(Q[:4], E4_F0, "stiffness-along", direction=[0, 1, 0], raise_if_all_fail=False)
    q = b.plan_many(Q[:4], E4_F0, "stiffness-along", direction=[0, 1, 0], raise_if_all_fail=False)
    for name in ["ok", "value", "tensions", "c_x", "iterations"]:
        same(getattr(p, name), getattr(q, name))
    assert p.errors == q.errors


@pytest.mark.parametrize("model", ["decoupled", "routed"])
def test_every_class_round_trips(robot, model):
    routing = sinew.load_routing(robot, model)
    arm = sinew.ArmStiffness(robot, routing)
    # The model straight, and rebuilt from its robot and routing pickled apart.
    r2 = pickle.loads(pickle.dumps(robot))
    c2 = pickle.loads(pickle.dumps(routing))
    a2 = pickle.loads(pickle.dumps(arm))
    assert isinstance(r2, sinew.Robot) and isinstance(c2, sinew.Routing)
    assert isinstance(a2, sinew.ArmStiffness)
    assert r2.path is None and c2.path is None and robot.path is not None
    assert (r2.dof, r2.joint_names, r2.name) == (robot.dof, robot.joint_names, robot.name)
    same(r2.limits, robot.limits)
    same(r2.gravity, robot.gravity)
    assert c2.cables == routing.cables and c2.is_decoupled == routing.is_decoupled
    same(c2.tension_limits, routing.tension_limits)
    same_arm(arm, a2, robot)
    same_arm(arm, sinew.ArmStiffness(r2, c2), robot)
    same_arm(arm, copy.deepcopy(arm), robot)
    # Every protocol, and the routing's robot travels with it.
    for protocol in range(2, pickle.HIGHEST_PROTOCOL + 1):
        same_arm(arm, pickle.loads(pickle.dumps(arm, protocol)), robot)
    assert c2.robot.dof == robot.dof


def test_the_pickle_holds_texts_not_paths(robot, decoupled, arm):
    blob = pickle.dumps(arm)
    assert str(CDHRM5).encode() not in blob and b"robots/cdhrm5" not in blob
    assert robot.urdf.encode() in blob and decoupled.text.encode() in blob
    assert robot.description.encode() in blob
    # The texts are the files'.
    assert robot.urdf == (CDHRM5 / "cdhrm5.urdf").read_text()
    assert decoupled.text == (CDHRM5 / "cables.toml").read_text()
    # One robot in the pickle, shared by the routing and the arm.
    assert blob.count(robot.urdf.encode()) == 1


def test_no_gravity_and_any_cable_set_round_trip():
    robot = sinew.load_robot(CDHRM5, gravity=False)
    r2 = pickle.loads(pickle.dumps(robot))
    assert np.all(r2.gravity == 0.0)
    arm = sinew.ArmStiffness(robot, sinew.load_routing(robot))
    same_arm(arm, pickle.loads(pickle.dumps(arm)), robot)
    ua = sinew.load_robot(UA3X4)
    ua_arm = sinew.ArmStiffness(ua, sinew.load_routing(ua))
    copy_ = pickle.loads(pickle.dumps(ua_arm))
    Q = np.array([[0.2, -0.3, 0.25, 0.1, -0.15, 0.3], [0.0] * 6])
    x = ua_arm.evaluate_many(Q, [0, 2, 0, 0, 0, 0], policy="safest")
    y = copy_.evaluate_many(Q, [0, 2, 0, 0, 0, 0], policy="safest")
    for name in BATCH:
        same(getattr(x, name), getattr(y, name))


def test_from_texts_errors(robot):
    with pytest.raises(sinew.InputError, match="description"):
        sinew.Robot.from_texts(robot.urdf, "this is = not [ toml")
    with pytest.raises(sinew.InputError):
        sinew.Robot.from_texts("<robot", robot.description)
    with pytest.raises(sinew.InputError):
        sinew.Routing.from_text(robot, "model = 3")
    # An unpickled robot has no folder: "decoupled" cannot name a file of it.
    r2 = pickle.loads(pickle.dumps(robot))
    with pytest.raises(sinew.InputError, match="built from texts"):
        sinew.load_routing(r2, "decoupled")


FRESH = """
import pickle, sys
import numpy as np
arm = pickle.load(open(sys.argv[1], "rb"))
Q = np.load(sys.argv[2])
b = arm.evaluate_many(Q, [0, 5, 0, 0, 0, 0], levels=[0.5] * 5)
p = arm.plan_many(Q[:6], [0, 5, 0, 0, 0, 0], "min-stiffness", threads=1)
np.savez(sys.argv[3], **{n: getattr(b, n) for n in %r}, plan=p.tensions, value=p.value)
pickle.dump((b.errors, p.errors), open(sys.argv[3] + ".errors", "wb"))
""" % (BATCH,)


def test_a_fresh_interpreter_without_the_robot_folder(tmp_path):
    folder = tmp_path / "cdhrm5"
    shutil.copytree(CDHRM5, folder)
    robot = sinew.load_robot(folder)
    arm = sinew.ArmStiffness(robot, sinew.load_routing(robot, "routed"))
    (tmp_path / "arm.pickle").write_bytes(pickle.dumps(arm))
    Q = rows(robot)
    np.save(tmp_path / "q.npy", Q)
    shutil.rmtree(folder)
    (tmp_path / "fresh.py").write_text(FRESH)
    out = tmp_path / "out.npz"
    done = subprocess.run([sys.executable, str(tmp_path / "fresh.py"), str(tmp_path / "arm.pickle"),
                           str(tmp_path / "q.npy"), str(out)], cwd=tmp_path, capture_output=True,
                          text=True)
    assert done.returncode == 0, done.stderr
    there = np.load(out)
    b = arm.evaluate_many(Q, [0, 5, 0, 0, 0, 0], levels=[0.5] * 5)
    p = arm.plan_many(Q[:6], [0, 5, 0, 0, 0, 0], "min-stiffness", threads=1)
    for name in BATCH:
        same(there[name], getattr(b, name))
    same(there["plan"], p.tensions)
    same(there["value"], p.value)
    errors, plan_errors = pickle.loads((tmp_path / "out.npz.errors").read_bytes())
    assert [tuple(e) for e in errors] == b.errors and [tuple(e) for e in plan_errors] == p.errors
    assert 5 in [e[0] for e in plan_errors]
