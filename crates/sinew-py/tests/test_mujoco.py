"""The MuJoCo export checked by MuJoCo itself (crate sinew-mjcf; issue 26): the file compiles
with no warning, holds the pose with the exported tensions, its tendons are Sinew's cables
(lengths and J_c), its static compliance is Sinew's C_x (springs: K_q + K_W; motors: the
controllable part + K_W), it settles where C_x says and drifts away where Sinew says unstable.
Robots: cdhrm5 in both models (E4 and seeded random stable poses), ua3x4, planar-snake."""

import numpy as np
import pytest

import sinew
from conftest import CDHRM5, E4_F0, E4_Q, ROOT, UA3X4

from mjsim import Exported

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
    """The case exported; `cables="segments"`: springs, one per segment (the stick model)."""
    _, robot, routing, q, r = case
    split = "segments" if cables == "segments" else None
    cables = "springs" if cables == "segments" else cables
    return Exported(sinew.to_mjcf(robot, routing, q, r.tensions, r.wrench, cables=cables, split=split))


@pytest.mark.parametrize("case", CASES, ids=IDS)
@pytest.mark.parametrize("cables", ["springs", "motors", "segments"])
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


SETTLE = [c for c in CASES if c[0].endswith(("E4-[0.5, 0.5, 0.5, 0.5, 0.5]", "readme"))]


@pytest.mark.parametrize("case", SETTLE, ids=[c[0] for c in SETTLE])
def test_a_pushed_arm_settles_where_c_x_says(case):
    """12 s of simulated time (the file's time step and damping), the tip load −F0 + δw applied
    every step: the deflection is C_x δw within 1e-3 (δw small enough that the static response
    is linear to ~1e-4 on the softest arm)."""
    r = case[4]
    sim = export(case)
    push = np.array([0.0, 5e-4, 0.0, 0.0, 0.0, 0.0])
    q, _ = sim.simulate(push, 12.0)
    dx = sim.deflection(q)
    expected = r.c_x @ push
    assert np.linalg.norm(dx - expected) <= 1e-3 * np.linalg.norm(expected)
    assert np.max(np.abs(sim.data.qvel)) <= 1e-3 * np.max(np.abs(q - sim.q0))  # at rest (1/s)


def test_stability_verdict_unstable_drifts_stable_does_not():
    """A compressive tip load at a nearly straight pose: Sinew says unstable (λ_min(K_q + K_W)
    < 0) and the simulated arm leaves the pose from a 1e-6 rad nudge; at E4 (stable) the same
    nudge dies out. Both poses are equilibria of the exported model."""
    robot = sinew.load_robot(CDHRM5)
    routing = sinew.load_routing(robot, "decoupled")
    arm = sinew.ArmStiffness(robot, routing)
    nudge = 1e-6 * np.random.default_rng(26).standard_normal(robot.dof)
    q = np.full(robot.dof, 0.05)
    unstable = arm.evaluate(q, [0, 0, 2.0, 0, 0, 0], levels=[0.0] * 5)
    assert not unstable.stable and unstable.min_eigenvalue < -1.0
    stable = arm.evaluate(E4_Q, E4_F0, levels=[0.5] * 5)
    assert stable.stable
    drift = {}
    for name, q, r in (("unstable", q, unstable), ("stable", E4_Q, stable)):
        sim = Exported(sinew.to_mjcf(robot, routing, q, r.tensions, r.wrench))
        assert np.linalg.norm(sim.residual(sim.q0)) <= 1e-9 * np.linalg.norm(sim.gravity_torque())
        _, drift[name] = sim.simulate(np.zeros(6), 4.0, perturb=nudge)
    size = np.max(np.abs(nudge))
    # 4 s: the unstable arm has left by a thousand times the nudge (exponential growth under
    # the default damping), the stable one never strays beyond twice it.
    assert drift["unstable"] > 300 * size, (drift, size)
    assert drift["stable"] < 2 * size, (drift, size)


STICK = [c for c in CASES if c[0].startswith("cdhrm5")]


@pytest.mark.parametrize("case", STICK, ids=[c[0] for c in STICK])
def test_segment_springs_are_the_stick_regime(case):
    """Spec §9's stick model after equal tensions, K_stick = Σ T H_s + Σ J_sᵀ (EA/ℓ_s) J_s,
    against MuJoCo with one spring tendon per segment (its own rest length and EA/ℓ_s): the
    static compliance is Sinew's stick C_x, and not the frictionless one."""
    name, robot, routing, q, r = case
    arm = sinew.ArmStiffness(robot, routing)
    stick = arm.evaluate(q, r.wrench, tensions=r.tensions, friction=0.1, history="equal")
    np.testing.assert_array_equal(stick.tensions, r.tensions)
    assert stick.stable
    c = export(case, "segments").compliance()
    assert rel(c, stick.c_x) <= 1e-10, rel(c, stick.c_x)  # measured 1.6e-11 to 3.1e-11
    assert rel(c, r.c_x) > 0.5  # far stiffer than the cables as single springs


@pytest.mark.parametrize("case", STICK, ids=[c[0] for c in STICK])
@pytest.mark.parametrize("history", ["pull", "release"])
def test_segment_springs_with_their_own_tensions_are_the_stick_regime_after_a_history(case, history):
    """After a pull or a release the tension changes at every hole (the capstan law): each
    segment's spring exported with its own tension holds the pose, and MuJoCo's static
    compliance is Sinew's stick C_x after that history."""
    name, robot, routing, q, r = case
    arm = sinew.ArmStiffness(robot, routing)
    stick = arm.evaluate(q, r.wrench, policy="safest", friction=0.1, regime="stick", history=history)
    assert stick.stable
    per_segment = [s["tensions"] for s in stick.segments]
    assert any(np.ptp(t) > 1e-3 * t[0] for t in per_segment), "the tensions change along the cables"
    xml = sinew.to_mjcf(robot, routing, q, stick.tensions, stick.wrench, split="segments",
                        segment_tensions=per_segment)
    sim = Exported(xml)
    assert np.linalg.norm(sim.residual(sim.q0)) <= 1e-9 * np.linalg.norm(sim.gravity_torque())
    c = sim.compliance()
    assert rel(c, stick.c_x) <= 1e-10, rel(c, stick.c_x)


def test_segment_tensions_are_checked():
    _, robot, routing, q, r = STICK[0]
    per_cable = [np.full(len(s["tensions"]), t) for s, t in zip(
        sinew.ArmStiffness(robot, routing).evaluate(q, r.wrench, tensions=r.tensions, friction=0.1,
                                                     history="equal").segments, r.tensions)]
    with pytest.raises(sinew.InputError, match="segment_tensions"):
        sinew.to_mjcf(robot, routing, q, r.tensions, r.wrench, split="segments", segment_tensions=per_cable[1:])
    with pytest.raises(sinew.InputError, match="segment_tensions of cable"):
        sinew.to_mjcf(robot, routing, q, r.tensions, r.wrench, split="segments",
                      segment_tensions=[t[1:] for t in per_cable])
    with pytest.raises(sinew.InputError, match="segment_tensions"):
        sinew.to_mjcf(robot, routing, q, r.tensions, r.wrench, segment_tensions=per_cable)
    # Equal tensions along each cable give the file of no segment tensions.
    plain = sinew.to_mjcf(robot, routing, q, r.tensions, r.wrench, split="segments")
    same = sinew.to_mjcf(robot, routing, q, r.tensions, r.wrench, split="segments", segment_tensions=per_cable)
    assert same == plain
