"""ArmStiffness.evaluate against `sinew arm --json` to 1e-12, shapes, dtypes and errors."""

import numpy as np
import pytest

import sinew
from conftest import CDHRM5, E4_F0, E4_Q, UA3X4, cli, close, csv

FIELDS = ["t0", "tensions", "k_controllable", "k_inherent", "k_q", "k_w", "j_x"]


def compare(result, doc):
    for name in FIELDS:
        close(getattr(result, name), doc[name])
    assert result.stable == doc["stable"]
    close(result.min_eigenvalue, doc["min_eigenvalue"])
    for name in ["c_x", "k_x", "k_fd"]:
        close(getattr(result, name), doc[name])
    e = doc["ellipsoid"]
    if e is None:
        assert result.eigenvalues is None
    else:
        close(result.eigenvalues, e["eigenvalues"])
        close(result.directions, e["directions"])
        close(result.semi_axes, e["semi_axes"])
        close(result.condition_number, e["condition_number"])
        close(result.volume, e["volume"], 1e-10)


@pytest.mark.parametrize("model", ["decoupled", "routed"])
@pytest.mark.parametrize("levels", [[0.5] * 5, [0, 0, 1, 0, 1], [0.25] * 5])
def test_e4_against_the_cli(robot, model, levels):
    arm = sinew.ArmStiffness(robot, sinew.load_routing(robot, model))
    r = arm.evaluate(E4_Q, E4_F0, levels=levels)
    doc = cli("arm", "--robot", str(CDHRM5), "--model", model, "--q", csv(E4_Q),
              "--wrench", csv(E4_F0), "--levels", csv(levels))
    compare(r, doc)
    close(r.lambda_intervals, [iv["lambda"] for iv in doc["intervals"]])
    assert r.policy == "levels"


def test_unstable_is_a_result(arm):
    # E4 at the paper's baseline (every level 0) is unstable in the decoupled model.
    r = arm.evaluate(E4_Q, E4_F0)
    doc = cli("arm", "--robot", str(CDHRM5), "--q", csv(E4_Q), "--wrench", csv(E4_F0))
    assert r.stable is False and doc["stable"] is False
    assert r.c_x is None and r.k_x is None and r.k_fd is None
    assert r.min_eigenvalue < 0
    compare(r, doc)
    assert r.notes


@pytest.mark.parametrize("policy", ["least-total", "least-norm", "safest"])
def test_policies_against_the_cli(policy):
    robot = sinew.load_robot(UA3X4)
    arm = sinew.ArmStiffness(robot, sinew.load_routing(robot))
    q = [0.2, -0.3, 0.25, 0.1, -0.15, 0.3]
    w = [0, 2, 0, 0, 0, 0]
    r = arm.evaluate(q, w, policy=policy)
    doc = cli("arm", "--robot", str(UA3X4), "--q", csv(q), "--wrench", csv(w), "--policy", policy)
    # The convex solver's answer, polished: the same to 1e-12 as the same code's.
    compare(r, doc)
    assert r.policy == policy
    close(r.policy_objective, doc["policy_objective"])
    # Default without levels: least-total.
    assert arm.evaluate(q, w).policy == "least-total"


def test_given_tensions_reproduce(arm):
    r = arm.evaluate(E4_Q, E4_F0, levels=[0.5] * 5)
    g = arm.evaluate(E4_Q, E4_F0, tensions=r.tensions)
    assert g.policy == "given"
    close(g.k_q, r.k_q)
    close(g.c_x, r.c_x, 1e-10)


def test_shapes_and_dtypes(arm):
    r = arm.evaluate(E4_Q, E4_F0, levels=np.full(5, 0.5))
    shapes = {"q": (10,), "wrench": (6,), "t0": (10,), "tensions": (15,), "k_q": (10, 10),
              "k_w": (10, 10), "j_x": (6, 10), "c_x": (6, 6), "k_x": (6, 6), "k_fd": (3, 3),
              "eigenvalues": (3,), "directions": (3, 3), "semi_axes": (3,),
              "lambda_intervals": (5, 2)}
    for name, shape in shapes.items():
        a = getattr(r, name)
        assert isinstance(a, np.ndarray) and a.shape == shape and a.dtype == np.float64, name
    assert isinstance(r.min_eigenvalue, float) and isinstance(r.stable, bool)
    # Lists and tuples are accepted as well as arrays; int arrays are converted.
    r2 = arm.evaluate(list(E4_Q), tuple(E4_F0), levels=[0.5] * 5)
    close(r2.c_x, r.c_x, 0)
    r3 = arm.evaluate(E4_Q, np.array([0, 5, 0, 0, 0, 0], dtype=np.int64), levels=[0.5] * 5)
    close(r3.c_x, r.c_x, 0)
    # At the straight pose J_x loses rank: C_x exists, K_x does not (as the command says).
    s = arm.evaluate(np.zeros(10), levels=[0.5] * 5)
    assert s.stable and s.c_x.shape == (6, 6) and s.k_x is None and s.notes


def test_results_are_snapshots(arm):
    # Arrays are made on first read, from numbers copied when evaluate returned: a later call
    # (which reuses the model's workspace) changes nothing in an earlier result, and a second
    # read gives the same array object.
    first = arm.evaluate(E4_Q, E4_F0, levels=[0.5] * 5)
    expected = {name: np.array(getattr(arm.evaluate(E4_Q, E4_F0, levels=[0.5] * 5), name))
                for name in ["k_q", "k_w", "c_x", "k_fd", "eigenvalues", "t0"]}
    other = arm.evaluate(0.5 * E4_Q, E4_F0, levels=[1.0] * 5)
    assert not np.allclose(other.k_q, expected["k_q"])
    for name, value in expected.items():
        a = getattr(first, name)
        assert np.array_equal(a, value), name
        assert getattr(first, name) is a, name
    assert first.min_eigenvalue == arm.evaluate(E4_Q, E4_F0, levels=[0.5] * 5).min_eigenvalue
    assert first.min_eigenvalue != other.min_eigenvalue


def test_bad_input_raises(arm):
    with pytest.raises(sinew.InputError, match="q: expected 10 values, got 3"):
        arm.evaluate([0, 0, 0])
    with pytest.raises(sinew.InputError, match="1-D"):
        arm.evaluate(np.zeros((2, 10)))
    with pytest.raises(sinew.InputError, match="not a finite number"):
        arm.evaluate([np.nan] + [0] * 9)
    with pytest.raises(sinew.InputError, match="wrench"):
        arm.evaluate(np.zeros(10), [0, np.inf, 0, 0, 0, 0])
    with pytest.raises(sinew.InputError, match="wrench: expected 6"):
        arm.evaluate(np.zeros(10), [0, 1])
    with pytest.raises(sinew.InputError, match="not an array of numbers"):
        arm.evaluate(["a"] * 10)
    with pytest.raises(sinew.InputError, match="policy"):
        arm.evaluate(np.zeros(10), policy="cheapest")
    with pytest.raises(sinew.InputError, match="at most one"):
        arm.evaluate(np.zeros(10), levels=[0] * 5, policy="safest")
    with pytest.raises(sinew.InputError, match="levels"):
        arm.evaluate(np.zeros(10), levels=[2.0] * 5)
    with pytest.raises(sinew.InputError, match="outside"):
        arm.evaluate(np.full(10, 3.0))


def test_messages_are_the_clis(arm):
    q = np.full(10, 3.0)
    err = cli("arm", "--robot", str(CDHRM5), "--q", csv(q), expect=2)["stderr"]
    with pytest.raises(sinew.InputError) as e:
        arm.evaluate(q)
    # The command prints `sinew: --q: …`; Python says `q: …`.
    assert err.endswith(str(e.value)[len("q: "):])


def test_infeasible_load_raises(arm):
    w = [0, 500, 0, 0, 0, 0]
    err = cli("arm", "--robot", str(CDHRM5), "--q", csv(E4_Q), "--wrench", csv(w), expect=1)["stderr"]
    with pytest.raises(sinew.InfeasibleError, match="infeasible load") as e:
        arm.evaluate(E4_Q, w)
    assert err.endswith(str(e.value))
