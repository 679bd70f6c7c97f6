"""Robots and routings: properties against `sinew routing --json` and the files."""

import numpy as np
import pytest

import sinew
from conftest import CDHRM5, ROOT, UA3X4, cli, close


def test_robot_properties(robot):
    assert robot.dof == 10
    assert robot.joints == 5
    assert robot.joint_groups == [(2 * i, 2 * i + 2) for i in range(5)]
    assert len(robot.joint_names) == 10
    assert robot.limits.shape == (10, 2) and robot.limits.dtype == np.float64
    assert np.all(robot.limits[:, 0] < robot.limits[:, 1])
    assert robot.axes.shape == (10, 3)
    assert robot.gravity.shape == (3,)
    assert "cdhrm5" in repr(robot)


def test_routings_against_the_cli(robot, decoupled, routed):
    for model, routing in [("decoupled", decoupled), ("routed", routed)]:
        doc = cli("routing", "--robot", str(CDHRM5), "--model", model)
        names = [c["name"] for c in doc["cables"]]
        assert routing.cables == names
        assert routing.cable_count == 15
        assert routing.tension_limits.shape == (15, 2)
    assert decoupled.is_decoupled and not routed.is_decoupled
    assert sinew.load_routing(robot, str(CDHRM5 / "cables.toml")).cables == decoupled.cables


def test_no_gravity():
    assert np.all(sinew.load_robot(CDHRM5, gravity=False).gravity == 0.0)


def test_unknown_files_raise_input_errors(robot, tmp_path):
    with pytest.raises(sinew.InputError, match="does not exist"):
        sinew.load_robot(ROOT / "robots" / "no-such-robot")
    with pytest.raises(sinew.InputError, match="robot.toml"):
        sinew.load_robot(tmp_path)
    with pytest.raises(sinew.InputError, match="does not exist"):
        sinew.load_routing(robot, str(tmp_path / "nope.toml"))
    bad = tmp_path / "bad.toml"
    bad.write_text("this is = not [ a routing")
    with pytest.raises(sinew.InputError):
        sinew.load_routing(robot, str(bad))
    # Every error is a SinewError.
    assert issubclass(sinew.InputError, sinew.SinewError)
    for e in [sinew.InfeasibleError, sinew.UnstableError, sinew.RankDeficientError, sinew.NumericalError]:
        assert issubclass(e, sinew.SinewError)


def test_any_cable_set_robot():
    robot = sinew.load_robot(UA3X4)
    routing = sinew.load_routing(robot, "decoupled")
    arm = sinew.ArmStiffness(robot, routing)
    assert not arm.has_levels
    assert arm.cables == routing.cable_count == 12
