"""plan_along: a trajectory planned step by step, warm-started, equal to plan_many's cold plans
within the gaps, the rate limit held, bad rate arguments refused."""

import numpy as np
import pytest

import sinew
from conftest import E4_F0, E4_Q


def trajectory(steps):
    # Towards zero from E4 (whose joint 3 sits at its limit) by up to 5 %, at 1 kHz.
    t = np.arange(steps) * 1e-3
    omega = 0.5 + 14.5 * np.arange(10) / 9.0
    return np.asarray(E4_Q)[None, :] * (1 - 0.05 * np.abs(np.sin(omega[None, :] * t[:, None])))


def test_plan_along_is_warm_and_equals_cold_plans_within_the_gaps(arm):
    Q = trajectory(60)
    along = arm.plan_along(Q, E4_F0, objective="stiffness-along", direction=[0, 1, 0])
    assert along.ok.all() and along.warm.shape == (60,)
    assert along.warm[1:].mean() > 0.9
    cold = arm.plan_many(Q[::10], E4_F0, objective="stiffness-along", direction=[0, 1, 0])
    assert cold.warm is None
    difference = np.abs(along.value[::10] - cold.value)
    assert (difference <= along.gap[::10] + cold.gap).all(), difference


def test_the_rate_limit_is_held_and_bad_rates_are_refused(arm):
    Q = trajectory(40)
    free = arm.plan_along(Q, E4_F0, objective="volume")
    fastest = np.abs(np.diff(free.tensions, axis=0)).max()
    limited = arm.plan_along(Q, E4_F0, objective="volume", max_rate=fastest / 1.5 / 1e-3, dt=1e-3)
    assert limited.ok.all()
    assert np.abs(np.diff(limited.tensions, axis=0)).max() <= fastest / 1.5 * (1 + 1e-9) + 1e-9
    with pytest.raises(sinew.InputError, match="max_rate and dt"):
        arm.plan_along(Q, E4_F0, max_rate=10.0)
    with pytest.raises(sinew.InputError, match="max_rate"):
        arm.plan_along(Q, E4_F0, max_rate=-1.0, dt=1e-3)
