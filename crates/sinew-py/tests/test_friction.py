"""Friction at the holes from Python (spec §9, issue 27): `ArmStiffness.evaluate(…, friction=,
regime=, history=, direction=)` answers what `sinew arm --friction … --json` prints, as numpy
arrays, in every regime and both models; μ = 0 is the frictionless `ArmResult`; every bad
argument is an `InputError` naming it."""

import numpy as np
import pytest

import sinew
from conftest import CDHRM5, E4_F0, E4_Q, cli, close, csv

LEVELS = [0.5] * 5
REGIMES = [
    ("pull", None),
    ("release", None),
    ("stick", "pull"),
    ("stick", "release"),
    ("stick", "equal"),
]


def flags(regime, history):
    out = ["--friction", "0.1", "--regime", regime]
    return out + (["--history", history] if history else [])


@pytest.mark.parametrize("model", ["decoupled", "routed"])
@pytest.mark.parametrize("regime,history", REGIMES)
def test_every_regime_against_the_cli(robot, model, regime, history):
    arm = sinew.ArmStiffness(robot, sinew.load_routing(robot, model))
    r = arm.evaluate(E4_Q, E4_F0, levels=LEVELS, friction=0.1, regime=regime, history=history)
    assert isinstance(r, sinew.FrictionResult)
    doc = cli("arm", "--robot", str(CDHRM5), "--model", model, "--q", csv(E4_Q),
              "--wrench", csv(E4_F0), "--levels", csv(LEVELS), *flags(regime, history))
    assert (r.regime, r.history) == (doc["friction"]["regime"], doc["friction"]["history"])
    close(r.mu, doc["friction"]["mu"])
    for name in ("t0", "tensions", "dead_band", "k_q", "k_w", "j_x", "c_x", "k_x", "k_fd"):
        close(getattr(r, name), doc[name])
    assert r.stable == doc["stable"]
    assert r.min_eigenvalue == pytest.approx(doc["min_eigenvalue"], rel=1e-12)
    assert r.k_q_skew_norm == pytest.approx(doc["k_q_skew_norm"], rel=1e-12, abs=0.0)
    for got, want in zip(r.segments, doc["segments"]):
        assert got["cable"] == want["cable"]
        for key in ("tensions", "wrap_angles", "lengths"):
            close(got[key], want[key])
    if regime != "stick":
        assert r.directional is None and r.stick_load_limit is None
        assert r.k_q_skew_norm > 0.0
        return
    assert r.k_q_skew_norm == 0.0
    np.testing.assert_allclose(r.k_q, r.k_q.T, rtol=0, atol=1e-9 * np.abs(r.k_q).max())
    close(r.directional["direction"], doc["directional"]["direction"])
    for sign in ("plus", "minus"):
        got, want = r.directional[sign], doc["directional"][sign]
        assert got["stiffness"] == pytest.approx(want["stiffness"], rel=1e-12)
        assert got["compliance"] * got["stiffness"] == pytest.approx(1.0, rel=1e-12)
        assert [s[:3] for s in got["sliding"]] == [(h["cable"], h["hole"], h["edge"]) for h in want["sliding"]]
    assert len(r.stick_load_limit) == len(doc["stick_load_limit"]) == 14
    for got, want in zip(r.stick_load_limit, doc["stick_load_limit"]):
        close(got["direction"], want["direction"])
        if want["magnitude"] is None:
            assert got["magnitude"] is None
        else:
            assert got["magnitude"] == pytest.approx(want["magnitude"], rel=1e-12, abs=1e-15)
        assert len(got["at_once"]) == len(want["at_once"])
    # After a pull or a release every hole is on an edge: the load limit along ±u is 0 and
    # holes slide; after equal tensions nothing slides and ±u agree.
    along = r.stick_load_limit[-2:]
    if history == "equal":
        assert all(l["magnitude"] > 0.0 for l in along)
        assert r.directional["plus"]["sliding"] == r.directional["minus"]["sliding"] == []
        assert r.directional["plus"]["stiffness"] == pytest.approx(r.directional["minus"]["stiffness"], rel=1e-9)
    else:
        assert all(l["magnitude"] == 0.0 for l in along)
        assert r.directional["plus"]["sliding"] and r.directional["minus"]["sliding"]


def test_mu_zero_is_the_frictionless_result(arm):
    plain = arm.evaluate(E4_Q, E4_F0, levels=LEVELS)
    for kwargs in ({"friction": 0.0}, {"friction": 0.0, "regime": "pull"}):
        r = arm.evaluate(E4_Q, E4_F0, levels=LEVELS, **kwargs)
        assert isinstance(r, sinew.ArmResult)
        np.testing.assert_array_equal(r.tensions, plain.tensions)
        np.testing.assert_array_equal(r.c_x, plain.c_x)


def test_stick_after_equal_keeps_the_frictionless_tensions_and_stiffens(arm):
    plain = arm.evaluate(E4_Q, E4_F0, levels=LEVELS)
    r = arm.evaluate(E4_Q, E4_F0, levels=LEVELS, friction=0.1, history="equal")
    np.testing.assert_array_equal(r.tensions, plain.tensions)
    for seg, t in zip(r.segments, plain.tensions):
        assert np.all(seg["tensions"] == t)
    # K_stick − K (frictionless) is the segment springs' extra: positive semidefinite.
    extra = 0.5 * (r.k_q + r.k_q.T) - plain.k_q
    assert np.linalg.eigvalsh(extra).min() >= -1e-9 * np.abs(extra).max()
    assert np.linalg.eigvalsh(r.k_fd).min() > 30 * np.linalg.eigvalsh(plain.k_fd).min()


def test_a_direction_of_the_users(arm):
    r = arm.evaluate(E4_Q, E4_F0, levels=LEVELS, friction=0.1, direction=[0.0, 0.0, 2.0])
    np.testing.assert_array_equal(r.directional["direction"], [0.0, 0.0, 1.0])
    # No force in the load: the direction must be given.
    with pytest.raises(sinew.InputError, match="direction"):
        arm.evaluate(E4_Q, np.zeros(6), levels=LEVELS, friction=0.1)


@pytest.mark.parametrize(
    "kwargs,says",
    [
        ({"friction": -0.1}, "friction"),
        ({"friction": float("nan")}, "friction"),
        ({"friction": 0.1, "regime": "slide"}, "regime"),
        ({"friction": 0.1, "history": "push"}, "history"),
        ({"friction": 0.1, "regime": "pull", "history": "equal"}, "history"),
        ({"friction": 0.0, "regime": "stick"}, "μ > 0"),
        ({"history": "equal"}, "μ > 0"),
        ({"friction": 0.1, "direction": [0.0, 0.0, 0.0]}, "direction"),
        ({"friction": 0.1, "direction": [1.0, 0.0]}, "direction"),
        ({"direction": [1.0, 0.0, 0.0]}, "direction"),
        ({"friction": 0.1, "levels": [0.5, 0.5, 1.5, 0.5, 0.5]}, "level"),
    ],
)
def test_bad_arguments_are_input_errors(arm, kwargs, says):
    kwargs = {"levels": LEVELS, **kwargs}
    with pytest.raises(sinew.InputError, match=says):
        arm.evaluate(E4_Q, E4_F0, **kwargs)


def test_require_stiffness_raises_in_a_regime_too(arm):
    """At the lowest levels the frictionless arm buckles under E4's load; slipping holes
    (pull) leave it unstable too, and `require_stiffness` raises as for the frictionless arm."""
    r = arm.evaluate(E4_Q, E4_F0, levels=[0.0] * 5, friction=0.1, regime="pull")
    assert not r.stable and r.c_x is None and r.k_fd is None
    with pytest.raises(sinew.UnstableError):
        arm.evaluate(E4_Q, E4_F0, levels=[0.0] * 5, friction=0.1, regime="pull", require_stiffness=True)


@pytest.mark.parametrize("model", ["decoupled", "routed"])
@pytest.mark.parametrize("history", ["pull", "equal"])
def test_a_stick_plan_is_the_clis(robot, model, history):
    arm = sinew.ArmStiffness(robot, sinew.load_routing(robot, model))
    p = arm.plan(E4_Q, E4_F0, objective="stiffness-along", direction=[0, 1, 0],
                 friction=0.1, history=history)
    doc = cli("plan", "--robot", str(CDHRM5), "--model", model, "--q", csv(E4_Q),
              "--wrench", csv(E4_F0), "--objective", "stiffness-along", "--direction", "0,1,0",
              "--friction", "0.1", "--history", history)
    assert doc["friction"] == {"mu": [0.1] * len(doc["cables"]), "regime": "stick", "history": history}
    assert p.value == doc["value"] and p.gap == doc["gap"]
    close(p.tensions, doc["tensions"])
    assert p.min_eigenvalue == pytest.approx(doc["min_eigenvalue"], rel=1e-12)
    free = arm.plan(E4_Q, E4_F0, objective="stiffness-along", direction=[0, 1, 0])
    assert p.value > 10 * free.value
    same = arm.plan(E4_Q, E4_F0, objective="stiffness-along", direction=[0, 1, 0], friction=0.0)
    assert same.value == free.value
    close(same.tensions, free.tensions)


def test_a_slip_regime_is_not_planned(robot):
    arm = sinew.ArmStiffness(robot, sinew.load_routing(robot, "decoupled"))
    for regime in ("pull", "release"):
        with pytest.raises(sinew.InputError, match="slip regime is not planned"):
            arm.plan(E4_Q, E4_F0, friction=0.1, regime=regime)
    with pytest.raises(sinew.InputError, match="μ > 0"):
        arm.plan(E4_Q, E4_F0, regime="stick")
