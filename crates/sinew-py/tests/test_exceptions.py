"""UnstableError and RankDeficientError where the docstrings say, matching the command's
verdict; plan_many's typed failure per row."""

import numpy as np
import pytest

import sinew
from conftest import CDHRM5, E4_F0, E4_Q, cli, csv
from test_pickle import rows, same


def test_unstable_error_where_the_command_says_unstable(arm):
    # E4 at the paper's baseline (every level 0) is unstable in the decoupled model.
    doc = cli("arm", "--robot", str(CDHRM5), "--q", csv(E4_Q), "--wrench", csv(E4_F0))
    assert doc["stable"] is False
    with pytest.raises(sinew.UnstableError) as e:
        arm.evaluate(E4_Q, E4_F0, require_stiffness=True)
    assert not isinstance(e.value, sinew.RankDeficientError)
    # The message carries the command's smallest eigenvalue.
    assert f"{doc['min_eigenvalue']:.3}"[:4] in str(e.value).replace("−", "-"), (str(e.value), doc)
    # Without it: a result, as the command's.
    assert arm.evaluate(E4_Q, E4_F0).stable is False
    # A stable pose raises nothing.
    doc = cli("arm", "--robot", str(CDHRM5), "--q", csv(E4_Q), "--wrench", csv(E4_F0),
              "--levels", csv([0.5] * 5))
    assert doc["stable"] is True and doc["k_x"] is not None
    assert arm.evaluate(E4_Q, E4_F0, levels=[0.5] * 5, require_stiffness=True).stable


def test_rank_deficient_error_where_the_command_says_so(arm):
    q = np.zeros(10)
    # `sinew arm`: C_x exists, K_x does not (a result); `sinew plan`: no answer, exit 1.
    doc = cli("arm", "--robot", str(CDHRM5), "--q", csv(q), "--levels", csv([0.5] * 5))
    assert doc["stable"] is True and doc["k_x"] is None and doc["c_x"] is not None
    with pytest.raises(sinew.RankDeficientError):
        arm.evaluate(q, levels=[0.5] * 5, require_stiffness=True)
    assert arm.evaluate(q, levels=[0.5] * 5).k_x is None
    err = cli("plan", "--robot", str(CDHRM5), "--q", csv(q), "--wrench", csv(E4_F0),
              "--objective", "min-stiffness", expect=1)["stderr"]
    with pytest.raises(sinew.RankDeficientError) as e:
        arm.plan(q, E4_F0)
    assert err.endswith(str(e.value)), (err, str(e.value))
    # plan_many: the same failure, typed, in its row; the other rows planned.
    Q = np.array([E4_Q, q, E4_Q])
    p = arm.plan_many(Q, E4_F0)
    assert p.ok.tolist() == [True, False, True]
    assert p.errors == [(1, "rank-deficient", str(e.value))]
    assert np.isnan(p.tensions[1]).all() and p.iterations[1] == 0
    with pytest.raises(sinew.RankDeficientError, match="every row failed"):
        arm.plan_many(np.zeros((2, 10)), E4_F0)
    assert len(arm.plan_many(np.zeros((2, 10)), E4_F0, raise_if_all_fail=False).errors) == 2


def test_plan_many_rows_are_plan(robot, arm):
    Q = rows(robot, 12)
    Q[0] = E4_Q
    p = arm.plan_many(Q, E4_F0, "stiffness-along", direction=[0, 1, 0])
    assert len(p) == 12 and p.objective == "stiffness-along"
    assert p.tensions.shape == (12, 15) and p.levels.shape == (12, 5)
    assert p.c_x.shape == (12, 6, 6) and p.k_fd.shape == (12, 3, 3)
    assert p.iterations.dtype == np.int64 and p.ok.dtype == np.bool_
    assert p.ok[0] and not p.ok[5] and not p.ok[7] and not p.ok[11]
    errors = {row: (kind, message) for row, kind, message in p.errors}
    assert sorted(errors) == [r for r in range(12) if not p.ok[r]]
    classes = {"input": sinew.InputError, "infeasible": sinew.InfeasibleError,
               "rank-deficient": sinew.RankDeficientError}
    for r in range(12):
        if not p.ok[r]:
            kind, message = errors[r]
            with pytest.raises(classes[kind]) as e:
                arm.plan(Q[r], E4_F0, "stiffness-along", direction=[0, 1, 0])
            # plan checks a NaN itself before the planner's pose stage does (its own words).
            if np.isfinite(Q[r]).all():
                assert str(e.value) == message
            continue
        one = arm.plan(Q[r], E4_F0, "stiffness-along", direction=[0, 1, 0])
        assert p.value[r] == one.value and p.gap[r] == one.gap
        same(p.tensions[r], one.tensions)
        same(p.levels[r], one.levels)
        same(p.c_x[r], one.c_x)
        same(p.k_fd[r], one.k_fd)
        assert p.min_eigenvalue[r] == one.min_eigenvalue and p.stable[r] == one.stable
        assert p.iterations[r] == one.iterations
    kinds = {kind for _, kind, _ in p.errors}
    assert "input" in kinds
    # Bad arguments are raised before any row runs.
    with pytest.raises(sinew.InputError, match="direction"):
        arm.plan_many(Q, E4_F0, "stiffness-along")
    with pytest.raises(sinew.InputError, match="objective"):
        arm.plan_many(Q, E4_F0, "stiffest")
