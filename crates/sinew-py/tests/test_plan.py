"""ArmStiffness.plan against `sinew plan --json` (same objectives and requirements)."""

import numpy as np
import pytest

import sinew
from conftest import CDHRM5, E4_F0, E4_Q, cli, close, csv  # noqa: F401


@pytest.mark.parametrize(
    "objective, extra, py",
    [
        ("min-stiffness", [], {}),
        ("stiffness-along", ["--direction", "0,1,0"], {"direction": [0, 1, 0]}),
        ("least-tension", ["--margin", "0.05"], {"margin": 0.05}),
    ],
)
def test_plan_against_the_cli(arm, objective, extra, py):
    r = arm.plan(E4_Q, E4_F0, objective, **py)
    doc = cli("plan", "--robot", str(CDHRM5), "--q", csv(E4_Q), "--wrench", csv(E4_F0),
              "--objective", objective, *extra)
    assert r.objective == doc["objective"]
    for name in ["value", "gap", "tensions", "total_tension", "k_fd", "c_x", "min_eigenvalue", "levels"]:
        close(getattr(r, name), doc[name], 1e-10)
    close(r.lambda_, doc["lambda"], 1e-10)
    assert r.iterations == doc["iterations"]
    assert r.stable == doc["stable"]
    assert r.tensions.shape == (15,) and r.c_x.shape == (6, 6)


def test_plan_requirements(arm, decoupled):
    r = arm.plan(E4_Q, E4_F0, "least-tension", k_min=5.0)
    assert np.linalg.eigvalsh(r.k_fd)[0] >= 5.0 * (1 - 1e-6)
    assert r.min_eigenvalue >= 1e-3 * (1 - 1e-6)
    # A joint budget above the plan's own spending changes nothing; the planner's error otherwise.
    spent = r.tensions[np.array(decoupled.cable_joints) == 0].sum()
    again = arm.plan(E4_Q, E4_F0, "least-tension", k_min=5.0, joint_budgets={0: spent + 1.0})
    close(again.total_tension, r.total_tension, 1e-6)
    with pytest.raises(sinew.InfeasibleError, match="per-joint budgets"):
        arm.plan(E4_Q, E4_F0, "least-tension", joint_budgets={4: 1.0})


def test_plan_errors(arm):
    with pytest.raises(sinew.InputError, match="direction"):
        arm.plan(E4_Q, E4_F0, "stiffness-along")
    with pytest.raises(sinew.InputError, match="objective"):
        arm.plan(E4_Q, E4_F0, "stiffest")
    with pytest.raises(sinew.InfeasibleError):
        arm.plan(E4_Q, E4_F0, "min-stiffness", budget=1.0)
    with pytest.raises(sinew.InputError, match="wrench"):
        arm.plan(E4_Q, [0, 5, 0, 1, 0, 0])


def test_plan_fixed_levels_against_the_cli(arm):
    r = arm.plan(E4_Q, E4_F0, "min-stiffness", fixed_levels={2: 0.25})
    doc = cli("plan", "--robot", str(CDHRM5), "--q", csv(E4_Q), "--wrench", csv(E4_F0),
              "--objective", "min-stiffness", "--fixed-level", "3:0.25")
    close(r.value, doc["value"], 1e-10)
    close(r.levels, doc["levels"], 1e-10)
    assert abs(r.levels[2] - 0.25) <= 1e-6
