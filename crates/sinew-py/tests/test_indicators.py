"""joint_range and sweep against `sinew joint --json` and `sinew sweep --json`."""

import numpy as np
import pytest

import sinew
from conftest import CDHRM5, cli, close, csv


@pytest.mark.parametrize("model", ["decoupled", "routed"])
def test_joint_range_against_the_cli(robot, model):
    routing = sinew.load_routing(robot, model)
    q, tau = [np.pi / 7, -np.pi / 9], [-1.0, 0.5]
    r = sinew.joint_range(robot, routing, 0, q, tau)
    doc = cli("joint", "--robot", str(CDHRM5), "--model", model, "--joint", "1",
              "--q", csv(q), "--torque", csv(tau))
    assert r.joint == doc["joint"] == 0
    assert r.cables == doc["cables"]
    close(r.lambda_, doc["lambda"])
    close(r.particular, doc["particular"])
    close(r.null_direction, doc["null_direction"])
    assert r.force_closure == doc["force_closure"]
    close(r.tensions, doc["tensions"])
    close(r.k_at_min, doc["k"][0])
    close(r.k_at_max, doc["k"][1])
    close(r.sigma_x, doc["sigma_x"][0])
    close(r.delta_x, doc["sigma_x"][1])
    close(r.sigma_y, doc["sigma_y"][0])
    close(r.delta_y, doc["sigma_y"][1])
    assert r.sigma_x.shape == (2,) and r.tensions.shape == (2, 3)


def test_joint_range_errors(robot, decoupled):
    with pytest.raises(sinew.InputError, match="joint 7"):
        sinew.joint_range(robot, decoupled, 7, [0, 0], [0.3, 0.3])
    with pytest.raises(sinew.InputError, match="torque"):
        sinew.joint_range(robot, decoupled, 0, [0, 0], [np.nan, 0.3])
    with pytest.raises(sinew.InfeasibleError):
        sinew.joint_range(robot, decoupled, 0, [0, 0], [300.0, 300.0])


def test_sweep_against_the_cli(robot, decoupled):
    s = sinew.sweep(robot, decoupled, 0, [0.3, 0.3], points=9)
    doc = cli("sweep", "--robot", str(CDHRM5), "--joint", "1", "--torque", "0.3,0.3", "--grid", "9")
    close(s.angles, doc["grid"]["angles"])
    for name in ["k_x_min", "k_x_max", "k_y_min", "k_y_max"]:
        ref = np.array([[np.nan if v is None else v for v in row] for row in doc[name]])
        a = getattr(s, name)
        assert a.shape == (9, 9) and a.dtype == np.float64
        assert np.array_equal(np.isnan(a), np.isnan(ref))
        close(np.nan_to_num(a), np.nan_to_num(ref))
    assert s.feasible.dtype == np.bool_ and s.feasible.sum() == doc["feasible"]


def test_sweep_errors(robot, decoupled):
    with pytest.raises(sinew.InputError, match="points"):
        sinew.sweep(robot, decoupled, 0, [0.3, 0.3], points=1)
    with pytest.raises(sinew.InputError, match="at most 1001"):
        sinew.sweep(robot, decoupled, 0, [0.3, 0.3], points=5000)


@pytest.mark.parametrize(
    "kwargs, flags",
    [
        (dict(regime="pull"), ["--regime", "pull"]),
        (dict(regime="release"), ["--regime", "release"]),
        (dict(), []),
        (dict(history="equal"), ["--history", "equal"]),
    ],
)
def test_sweep_with_friction_against_the_cli(robot, routed, kwargs, flags):
    s = sinew.sweep(robot, routed, 4, [0.5, -0.3], points=5, friction=0.2, **kwargs)
    doc = cli("sweep", "--robot", str(CDHRM5), "--model", "routed", "--joint", "5",
              "--torque", "0.5,-0.3", "--grid", "5", "--friction", "0.2", *flags)
    assert (s.regime, s.history) == (doc["friction"]["regime"], doc["friction"]["history"])
    close(s.mu, doc["friction"]["mu"])
    plain = sinew.sweep(robot, routed, 4, [0.5, -0.3], points=5)
    assert plain.regime is None and plain.mu is None
    for name in ["k_x_min", "k_x_max", "k_y_min", "k_y_max"]:
        ref = np.array([[np.nan if v is None else v for v in row] for row in doc[name]])
        a = getattr(s, name)
        assert np.array_equal(np.isnan(a), np.isnan(ref))
        close(np.nan_to_num(a), np.nan_to_num(ref))
        assert not np.allclose(np.nan_to_num(a), np.nan_to_num(getattr(plain, name)))


def test_sweep_friction_errors(robot, routed):
    with pytest.raises(sinew.InputError, match="friction"):
        sinew.sweep(robot, routed, 4, [0.5, -0.3], points=3, friction=-0.1)
    with pytest.raises(sinew.InputError, match="stick"):
        sinew.sweep(robot, routed, 4, [0.5, -0.3], points=3, regime="stick")
    with pytest.raises(sinew.InputError, match="regime"):
        sinew.sweep(robot, routed, 4, [0.5, -0.3], points=3, friction=0.1, regime="slide")
