# %% [markdown]
# # Plan the stiffest tensions at E4, export them to MuJoCo, push the tip
#
# Notebook-style (`# %%` cells). Needs the `sinew` package (`pip install ./crates/sinew-py`),
# numpy and the `mujoco` package (`pip install mujoco`).
# Run from the repository root: `python examples/python/simulate_plan.py`.
#
# Sinew plans the tensions that make the arm stiffest along the load (y) at the paper's E4
# pose, `sinew.to_mjcf` writes the robot with its cables as springs holding that pose, and
# MuJoCo simulates it: the tip is pushed by a small extra force along each axis (the load
# −F0 + δF applied at site `tip` every step, world frame), the arm settles under the joint
# damping, and the measured deflection is printed beside Sinew's `C_x δF`.

# %%
import tempfile
from pathlib import Path

import mujoco
import numpy as np

import sinew

ROOT = Path(__file__).resolve().parents[2]
robot = sinew.load_robot(ROOT / "robots" / "cdhrm5")
routing = sinew.load_routing(robot, "decoupled")
arm = sinew.ArmStiffness(robot, routing)

E4_Q = np.pi * np.array([-1 / 7, -1 / 9, -1 / 9, -1 / 11, 1 / 6, 1 / 7, 1 / 8, -1 / 15, -1 / 12, -1 / 10])
E4_F0 = np.array([0.0, 5.0, 0.0, 0.0, 0.0, 0.0])

# %% [markdown]
# ## The plan and the model

# %%
plan = arm.plan(E4_Q, E4_F0, "stiffness-along", direction=[0, 1, 0])
print(f"stiffness along y: {plan.value:.2f} N/m (certified within {plan.gap:.1e}), total tension {plan.total_tension:.1f} N")
xml = sinew.to_mjcf(robot, routing, E4_Q, plan.tensions, E4_F0)
out = Path(tempfile.gettempdir()) / "e4_plan.xml"
out.write_text(xml)
model = mujoco.MjModel.from_xml_string(xml)
data = mujoco.MjData(model)
tip = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "tip")
body = model.site_bodyid[tip]
print(f"wrote {out}: {model.nbody - 1} bodies, {model.nv} hinges, {model.ntendon} spring tendons")

# %% [markdown]
# ## Push the tip and let it settle
#
# 12 s of simulated time with the file's damping (1 N m s/rad per hinge) settles E4 to about
# 1e-4 of the static deflection. The pushes are small (0.5 mN) so the response is linear.

# %%
def settle(push, seconds=12.0):
    mujoco.mj_resetDataKeyframe(model, data, 0)
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_LIMIT  # Sinew's model has no limits
    mujoco.mj_forward(model, data)
    wrench = -E4_F0 + push
    for _ in range(int(seconds / model.opt.timestep)):
        data.qfrc_applied[:] = 0.0
        mujoco.mj_applyFT(model, data, wrench[:3].copy(), wrench[3:].copy(),
                          data.site_xpos[tip].copy(), body, data.qfrc_applied)
        mujoco.mj_step(model, data)
    return data.site_xpos[tip].copy()


rest = settle(np.zeros(6))
print("\npush (N)      measured deflection (m)                 C_x δF (m)                             rel. error")
for axis, name in enumerate("xyz"):
    push = np.zeros(6)
    push[axis] = 5e-4
    measured = settle(push) - rest
    predicted = (plan.c_x @ push)[:3]
    err = np.linalg.norm(measured - predicted) / np.linalg.norm(predicted)
    print(f"δF_{name} = 5e-4   {np.array2string(measured, precision=4)}   {np.array2string(predicted, precision=4)}   {err:.1e}")
