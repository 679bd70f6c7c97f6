"""The MuJoCo export checked by MuJoCo itself (crate sinew-mjcf; issue 26): the file compiles
with no warning, holds the pose with the exported tensions, its tendons are Sinew's cables
(lengths and J_c), its static compliance is Sinew's C_x (springs: K_q + K_W; motors: the
controllable part + K_W), it settles where C_x says and drifts away where Sinew says unstable.
Robots: cdhrm5 in both models (E4 and seeded random stable poses), ua3x4, planar-snake."""

import numpy as np
import pytest

import sinew
from conftest import CDHRM5, E4_F0, E4_Q, ROOT, UA3X4

mujoco = pytest.importorskip("mujoco")
from mjsim import Exported  # noqa: E402

SNAKE = ROOT / "robots" / "planar-snake"


def random_stable(arm, robot, seed, count, f0, **choice):
    """`count` seeded poses within 80 % of the limits where Sinew's tensions are feasible and
    K_q + K_W stable."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < count:
        q = rng.uniform(-0.8, 0.8, robot.dof) * np.pi / 6
        try:
            r = arm.evaluate(q, f0, **choice)
        except sinew.InfeasibleError:
            continue
        if r.stable:
            out.append((q, r))
    return out


def cases():
    """(name, robot, routing, q, result): every robot and pose the checks run on."""
    out = []
    robot = sinew.load_robot(CDHRM5)
    for model in ("decoupled", "routed"):
        routing = sinew.load_routing(robot, model)
        arm = sinew.ArmStiffness(robot, routing)
        for levels in ([0.5] * 5, [0.0, 0.0, 1.0, 0.0, 1.0]):
            out.append((f"cdhrm5-{model}-E4-{levels}", robot, routing, E4_Q, arm.evaluate(E4_Q, E4_F0, levels=levels)))
        for k, (q, r) in enumerate(random_stable(arm, robot, 26, 2, E4_F0, levels=[0.7] * 5)):
            out.append((f"cdhrm5-{model}-random{k}", robot, routing, q, r))
    for folder, q in ((UA3X4, [0.2, -0.3, 0.25, 0.1, -0.15, 0.3]), (SNAKE, [0.2, -0.3, 0.25, 0.1])):
        robot = sinew.load_robot(folder)
        routing = sinew.load_routing(robot, "decoupled")
        arm = sinew.ArmStiffness(robot, routing)
        f0 = np.array([0.0, 2.0, 0.0, 0.0, 0.0, 0.0])
        out.append((f"{robot.name}-readme", robot, routing, np.array(q), arm.evaluate(q, f0, policy="safest")))
        for k, (q, r) in enumerate(random_stable(arm, robot, 26, 1, f0, policy="safest")):
            out.append((f"{robot.name}-random{k}", robot, routing, q, r))
    return out


CASES = cases()
IDS = [c[0] for c in CASES]


def export(case, cables="springs"):
    _, robot, routing, q, r = case
    return Exported(sinew.to_mjcf(robot, routing, q, r.tensions, r.wrench, cables=cables))


@pytest.mark.parametrize("case", CASES, ids=IDS)
@pytest.mark.parametrize("cables", ["springs", "motors"])
def test_compiles_without_warning_and_holds_the_pose(case, cables, capfd):
    sim = export(case, cables)
    out, err = capfd.readouterr()
    assert "WARNING" not in out + err, out + err
    assert all(w.number == 0 for w in sim.data.warning), [w.number for w in sim.data.warning]
    gravity = np.linalg.norm(sim.gravity_torque())
    residual = np.linalg.norm(sim.residual(sim.q0))
    assert residual <= 1e-9 * gravity, (residual, gravity)


@pytest.mark.parametrize("case", CASES, ids=IDS)
def test_tendons_are_the_cables(case):
    _, robot, routing, q, _ = case
    sim = export(case)
    lengths, j_c = sinew.cable_geometry(robot, routing, q)
    ten_length, ten_j = sim.tendon(q)
    assert np.max(np.abs(ten_length - lengths)) <= 1e-12
    assert np.max(np.abs(ten_j - j_c)) <= 1e-12


def rel(measured, expected):
    """Largest column error relative to the largest column, force and moment columns apart."""
    out = 0.0
    for cols in (slice(0, 3), slice(3, 6)):
        scale = np.max(np.linalg.norm(expected[:, cols], axis=0))
        out = max(out, np.max(np.linalg.norm(measured[:, cols] - expected[:, cols], axis=0)) / scale)
    return out


@pytest.mark.parametrize("case", CASES, ids=IDS)
def test_compliance_is_c_x(case):
    r = case[4]
    assert r.stable
    c = export(case).compliance()
    assert rel(c, r.c_x) <= 1e-6, rel(c, r.c_x)


@pytest.mark.parametrize("case", CASES, ids=IDS)
def test_motors_give_the_controllable_part_alone(case):
    r = case[4]
    j = r.j_x
    expected = j @ np.linalg.solve(r.k_controllable + r.k_w, j.T)
    c = export(case, "motors").compliance()
    assert rel(c, expected) <= 1e-6, rel(c, expected)
    # and not the springs' answer (the inherent part is large on these cables)
    assert rel(c, r.c_x) > 1e-2
