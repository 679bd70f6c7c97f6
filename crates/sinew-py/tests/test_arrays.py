"""Arrays as numpy users pass them: every layout and dtype gives the numbers of the contiguous
float64 array, one wrench row broadcasts, nothing is written, and every bad input is an
InputError naming the argument and the shape expected."""

import numpy as np
import pytest

import sinew
from conftest import E4_F0, E4_Q
from test_pickle import BATCH, rows, same

LEVELS = [0.5] * 5


def check(arm, Q, ref, **kw):
    b = arm.evaluate_many(Q, kw.pop("wrench", E4_F0), levels=kw.pop("levels", LEVELS), **kw)
    for name in BATCH:
        same(getattr(b, name), getattr(ref, name))
    assert b.errors == ref.errors


def test_layouts(robot, arm):
    Q = rows(robot, 60)
    ref = arm.evaluate_many(Q, E4_F0, levels=LEVELS)
    check(arm, np.asfortranarray(Q), ref)
    big = np.full((120, 30), 7.0)
    big[::2, 1::3] = Q
    view = big[::2, 1::3]
    assert not view.flags.c_contiguous and not view.flags.f_contiguous
    check(arm, view, ref)
    check(arm, Q[::-1][::-1], ref)
    check(arm, Q.tolist(), ref)
    check(arm, [tuple(r) for r in Q], ref)
    frozen = Q.copy()
    frozen.setflags(write=False)
    check(arm, frozen, ref)
    # Wrench and levels too: lists, tuples, (1, 6), strided, Fortran.
    w = np.zeros((6, 3))
    w[:, 1] = E4_F0
    check(arm, Q, ref, wrench=w[:, 1])
    check(arm, Q, ref, wrench=list(E4_F0))
    check(arm, Q, ref, wrench=E4_F0[None, :])
    check(arm, Q, ref, wrench=np.asfortranarray(np.tile(E4_F0, (60, 1))))
    check(arm, Q, ref, levels=np.full(10, 0.5)[::2])


def test_dtypes_by_the_rule(robot, arm):
    # float32 widens exactly: the same as its float64 copy; integers convert.
    Q32 = rows(robot, 60).astype(np.float32)
    check(arm, Q32, arm.evaluate_many(Q32.astype(np.float64), E4_F0, levels=LEVELS))
    check(arm, Q32.astype(np.float16),
          arm.evaluate_many(Q32.astype(np.float16).astype(np.float64), E4_F0, levels=LEVELS))
    Qi = np.zeros((4, 10), dtype=np.int32)
    Qi[1, 0] = 5  # outside the limits: a failed row, as for 5.0
    ref = arm.evaluate_many(Qi.astype(np.float64), E4_F0, levels=LEVELS)
    assert ref.ok.tolist() == [True, False, True, True]
    for dtype in [np.int8, np.int64, np.uint16]:
        check(arm, Qi.astype(dtype), ref)
    check(arm, Qi.tolist(), ref)
    check(arm, Qi, ref, wrench=np.array([0, 5, 0, 0, 0, 0], dtype=np.uint8))
    check(arm, Qi, ref, levels=np.array([0.5] * 5, dtype=np.float32))
    q32 = (0.9 * E4_Q).astype(np.float32)
    one = arm.evaluate(q32, E4_F0.astype(np.int64), levels=LEVELS)
    same(one.t0, arm.evaluate(q32.astype(np.float64), E4_F0, levels=LEVELS).t0)


def test_one_wrench_row_broadcasts_and_rows_may_have_their_own(robot, arm):
    Q = rows(robot, 30)
    ref = arm.evaluate_many(Q, E4_F0, levels=LEVELS)
    check(arm, Q, ref, wrench=np.tile(E4_F0, (30, 1)))
    W = np.zeros((30, 6))
    W[:, 1] = np.linspace(0, 6, 30)
    b = arm.evaluate_many(Q, W, levels=LEVELS)
    for r in [0, 13, 29]:
        one = arm.evaluate_many(Q[r:r + 1], W[r], levels=LEVELS)
        for name in BATCH:
            same(getattr(b, name)[r], getattr(one, name)[0])
    assert not np.array_equal(b.tensions[29], ref.tensions[29])
    p = arm.plan_many(Q[:3], W[:3])
    for r in range(3):
        if p.ok[r]:
            same(p.tensions[r], arm.plan(Q[r], W[r]).tensions)


def test_nothing_is_written(robot, arm):
    Q = rows(robot, 40)
    W = np.tile(E4_F0, (40, 1))
    levels = np.full(5, 0.5)
    copies = [a.copy() for a in (Q, W, levels)]
    arm.evaluate_many(Q, W, levels=levels)
    arm.plan_many(Q[:2], W[:2])
    arm.evaluate(Q[0], W[0], levels=levels)
    for a, c in zip((Q, W, levels), copies):
        same(a, c)


@pytest.mark.parametrize("Q, match", [
    (None, r"Q: expected an array of shape \(N, 10\), got None"),
    (np.zeros((3, 4)), r"Q: expected shape \(N, 10\), got \(3, 4\)"),
    (np.zeros(10), r"Q: expected a 2-D array of shape \(N, 10\), got 1 dimensions"),
    (np.zeros((2, 3, 10)), r"Q: expected a 2-D array of shape \(N, 10\), got 3 dimensions"),
    ([[0.0] * 10, [None] * 10],
     r"Q: not an array of numbers: expected an array of shape \(N, 10\), got None in it"),
    ([[0.0] * 10, [0.0] * 9], r"Q: not an array of numbers: expected an array of shape \(N, 10\)"),
    (np.zeros((2, 10), dtype=bool), r"Q: .*booleans"),
    (np.zeros((2, 10), dtype=complex), r"Q: .*complex"),
    (np.full((2, 10), "0"), r"Q: .*strings"),
])
def test_bad_Q(arm, Q, match):
    with pytest.raises(sinew.InputError, match=match):
        arm.evaluate_many(Q)
    with pytest.raises(sinew.InputError, match=match):
        arm.plan_many(Q)


def test_bad_wrench_levels_and_q(arm):
    Q = np.zeros((5, 10))
    bad = [
        (dict(wrench=[0, np.nan, 0, 0, 0, 0]), r"wrench\[1\]: `NaN` is not a finite number"),
        (dict(wrench=np.zeros((2, 6))), r"wrench: expected shape \(6,\), \(1, 6\) or \(5, 6\).*got \(2, 6\)"),
        (dict(wrench=np.zeros(5)), r"wrench: expected shape \(6,\), \(1, 6\) or \(5, 6\).*got \(5,\)"),
        (dict(wrench=[0, None, 0, 0, 0, 0]), r"wrench: .*None"),
        (dict(wrench=np.zeros((5, 6, 1))), r"wrench: .*3 dimensions"),
        (dict(levels=[0.5, np.nan, 0.5, 0.5, 0.5]), r"levels\[1\]"),
        (dict(levels=[0.5] * 4), r"levels: expected 5 values, got 4"),
        (dict(levels=[True] * 5), r"levels: .*booleans"),
    ]
    for kw, match in bad:
        with pytest.raises(sinew.InputError, match=match):
            arm.evaluate_many(Q, **kw)
        if "wrench" in kw:
            with pytest.raises(sinew.InputError, match=match):
                arm.plan_many(Q, kw["wrench"])
    with pytest.raises(sinew.InputError, match=r"q: expected an array of shape \(10,\), got None"):
        arm.evaluate(None)
    with pytest.raises(sinew.InputError, match=r"q: .*None"):
        arm.evaluate([0.0] * 9 + [None])
    with pytest.raises(sinew.InputError, match=r"tensions: .*complex"):
        arm.evaluate(np.zeros(10), tensions=np.zeros(15, dtype=complex))
    # A NaN in a row of Q fails that row only (a map over a workspace keeps the others).
    Q[2, 4] = np.nan
    b = arm.evaluate_many(Q, E4_F0, levels=LEVELS)
    assert b.ok.tolist() == [True, True, False, True, True]
    assert b.errors[0][:2] == (2, "input") and b.errors[0][2].startswith("q: ")


def unaligned(a):
    """A copy of float64 `a` whose data sit one byte off 8-byte alignment (as a buffer that
    Dask or pickle protocol 5 hands over may)."""
    buf = np.zeros(a.size * 8 + 1, dtype=np.uint8)
    out = buf[1:].view(np.float64).reshape(a.shape)
    out[...] = a
    assert not out.flags.aligned
    return out


def test_unaligned_arrays_are_read(robot, arm):
    Q = rows(robot, 30)
    ref = arm.evaluate_many(Q, E4_F0, levels=LEVELS)
    check(arm, unaligned(Q), ref)
    check(arm, Q, ref, wrench=unaligned(E4_F0))
    check(arm, Q, ref, wrench=unaligned(np.tile(E4_F0, (30, 1))))
    check(arm, Q, ref, levels=unaligned(np.array(LEVELS)))
    one = arm.evaluate(unaligned(E4_Q), unaligned(E4_F0), levels=unaligned(np.array(LEVELS)))
    same(one.t0, arm.evaluate(E4_Q, E4_F0, levels=LEVELS).t0)
    p = arm.plan_many(unaligned(Q[:3]), unaligned(E4_F0), raise_if_all_fail=False)
    q = arm.plan_many(Q[:3], E4_F0, raise_if_all_fail=False)
    same(p.tensions, q.tensions)
