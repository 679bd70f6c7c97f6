"""evaluate_many: each row equals evaluate's, bad rows are flagged, 10 000 configurations."""

import numpy as np
import pytest

import sinew
from conftest import E4_F0, E4_Q, close


def random_q(robot, n, seed=7):
    rng = np.random.default_rng(seed)
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]
    return lo + (hi - lo) * rng.random((n, robot.dof)) * 0.5 + (hi - lo) * 0.25


def test_rows_equal_evaluate(robot, arm):
    Q = random_q(robot, 40)
    Q[0] = E4_Q
    b = arm.evaluate_many(Q, E4_F0, levels=[0.5] * 5)
    assert len(b) == 40
    for r in range(40):
        if not b.ok[r]:
            with pytest.raises(sinew.SinewError):
                arm.evaluate(Q[r], E4_F0, levels=[0.5] * 5)
            continue
        one = arm.evaluate(Q[r], E4_F0, levels=[0.5] * 5)
        assert b.stable[r] == one.stable
        close(b.t0[r], one.t0, 0)
        close(b.tensions[r], one.tensions, 0)
        close(b.min_eigenvalue[r], one.min_eigenvalue, 0)
        if one.stable:
            close(b.c_x[r], one.c_x, 0)
            close(b.k_fd[r], one.k_fd, 0)
        else:
            assert np.all(np.isnan(b.c_x[r]))


def test_bad_rows_are_flagged(robot, arm):
    Q = np.zeros((4, 10))
    Q[1, 3] = np.nan
    Q[2, 0] = 3.0
    b = arm.evaluate_many(Q, E4_F0, levels=[0.5] * 5)
    assert b.ok.tolist() == [True, False, False, True]
    assert [e[0] for e in b.errors] == [1, 2]
    assert [e[1] for e in b.errors] == ["input", "input"]
    assert b.errors[1][2].startswith("q: ")
    assert np.all(np.isnan(b.t0[1])) and np.all(np.isnan(b.c_x[2]))


def test_every_field_of_failed_and_rank_deficient_rows(arm):
    # The buffers start zeroed and each row writes every entry once: a field a failed row left
    # unwritten would read 0.0 here, not NaN.
    Q = np.zeros((5, 10))
    Q[1, 3] = np.nan
    Q[2, 0] = 3.0
    Q[3] = E4_Q
    Q[4] = E4_Q
    b = arm.evaluate_many(Q, E4_F0, levels=[0.5] * 5)
    floats = ["min_eigenvalue", "t0", "tensions", "c_x", "k_x", "k_fd"]
    for r in (1, 2):
        assert not b.ok[r] and not b.stable[r]
        for name in floats:
            assert np.all(np.isnan(getattr(b, name)[r])), (r, name)
    # Row 0, the straight arm: evaluated and stable, J_x rank-deficient: C_x finite, K_x and
    # K_fd NaN, as evaluate(...) gives None for them.
    one = arm.evaluate(Q[0], E4_F0, levels=[0.5] * 5)
    assert b.ok[0] and b.stable[0] == one.stable
    assert one.k_x is None
    assert np.all(np.isfinite(b.c_x[0])) and np.all(np.isnan(b.k_x[0]))
    assert np.all(np.isnan(b.k_fd[0]))
    close(b.t0[0], one.t0, 0)
    # Rows 3 and 4, the same pose: every entry finite and equal, written by the same code.
    for name in floats:
        a = getattr(b, name)
        assert np.all(np.isfinite(a[3])), name
        assert a[3].tobytes() == a[4].tobytes(), name


def test_all_bad_rows_raise(arm):
    with pytest.raises(sinew.InputError, match="every row failed"):
        arm.evaluate_many(np.full((3, 10), 3.0))
    with pytest.raises(sinew.InfeasibleError, match="every row failed"):
        arm.evaluate_many(np.tile(E4_Q, (2, 1)), [0, 500, 0, 0, 0, 0])
    with pytest.raises(sinew.InputError, match=r"shape \(N, 10\)"):
        arm.evaluate_many(np.zeros((3, 4)))
    with pytest.raises(sinew.InputError, match="2-D"):
        arm.evaluate_many(np.zeros(10))


def test_empty_batch(arm):
    b = arm.evaluate_many(np.zeros((0, 10)))
    assert b.t0.shape == (0, 10) and b.c_x.shape == (0, 6, 6) and b.errors == []


def test_ten_thousand_configurations(robot, arm):
    Q = random_q(robot, 10_000, seed=11)
    b = arm.evaluate_many(Q, E4_F0, levels=[0.5] * 5)
    n = 10_000
    assert b.ok.shape == (n,) and b.ok.dtype == np.bool_ and b.stable.dtype == np.bool_
    assert b.t0.shape == (n, 10) and b.tensions.shape == (n, 15)
    assert b.c_x.shape == (n, 6, 6) and b.k_x.shape == (n, 6, 6) and b.k_fd.shape == (n, 3, 3)
    assert b.min_eigenvalue.shape == (n,) and b.min_eigenvalue.dtype == np.float64
    assert len(b.errors) == int((~b.ok).sum())
    assert np.isfinite(b.c_x[b.stable]).all()
    # Spot-check rows against evaluate.
    for r in [0, 4999, 9999]:
        if b.ok[r]:
            close(b.tensions[r], arm.evaluate(Q[r], E4_F0, levels=[0.5] * 5).tensions, 0)


def test_policy_batch():
    from conftest import UA3X4
    robot = sinew.load_robot(UA3X4)
    arm = sinew.ArmStiffness(robot, sinew.load_routing(robot))
    Q = np.array([[0.2, -0.3, 0.25, 0.1, -0.15, 0.3], [0.0] * 6])
    b = arm.evaluate_many(Q, [0, 2, 0, 0, 0, 0], policy="safest")
    for r in range(2):
        close(b.tensions[r], arm.evaluate(Q[r], [0, 2, 0, 0, 0, 0], policy="safest").tensions, 0)


def test_out_writes_the_fields_in_place(robot, arm):
    # out= (what sinew.dask's shared rows use): the given arrays are the result's, written
    # bit for bit as the batch's own, failed rows included, whatever they held before.
    from test_pickle import BATCH, rows, same

    Q = rows(robot, 300, seed=21)
    b = arm.evaluate_many(Q, E4_F0, levels=[0.5] * 5)
    assert len(b.errors) == 3
    for names in (BATCH, ["k_fd", "ok"], ["stable", "t0", "c_x"]):
        out = {n: np.full_like(getattr(b, n), True if n in ("ok", "stable") else 7.0)
               for n in names}
        o = arm.evaluate_many(Q, E4_F0, levels=[0.5] * 5, out=out)
        for n in BATCH:
            same(getattr(o, n), getattr(b, n))
            assert (getattr(o, n) is out.get(n)) == (n in names)
        assert o.errors == b.errors
    # Rows of a bigger C-contiguous array: a view is written, the rest untouched.
    big = np.zeros((400, 3, 3))
    arm.evaluate_many(Q, E4_F0, levels=[0.5] * 5, out={"k_fd": big[50:350]})
    same(big[50:350], b.k_fd)
    assert not big[:50].any() and not big[350:].any()
    k = np.zeros((300, 3, 3))
    for out, match in [
        ({"k_q": k}, 'out: no field "k_q"'),
        ({3: k}, "out: its keys are field names"),
        ({"k_fd": np.zeros((300, 9))}, r"out\[\"k_fd\"\]: .*shape \[300, 3, 3\]"),
        ({"k_fd": np.zeros((300, 3, 3), dtype=np.float32)}, r"out\[\"k_fd\"\]: .*float64"),
        ({"k_fd": np.zeros((300, 3, 3), order="F")}, "C-contiguous"),
        ({"k_fd": np.zeros((600, 3, 3))[::2]}, "C-contiguous"),
        ({"ok": np.zeros(300)}, r"out\[\"ok\"\]: .*bool"),
        ({"k_fd": np.zeros((300, 3, 3)).copy(), "t0": None}, r"out\[\"t0\"\]"),
        ({"c_x": np.zeros((300, 6, 6)), "k_x": "the same"}, r"out\[\"k_x\"\]"),
    ]:
        with pytest.raises(sinew.InputError, match=match):
            arm.evaluate_many(Q, E4_F0, levels=[0.5] * 5, out=out)
    frozen = np.zeros((300, 3, 3))
    frozen.flags.writeable = False
    shared = np.zeros((300, 6, 6))
    for out in ({"k_fd": frozen}, {"c_x": shared, "k_x": shared}):
        with pytest.raises(sinew.InputError, match="writable C-contiguous .* shares no memory"):
            arm.evaluate_many(Q, E4_F0, levels=[0.5] * 5, out=out)
