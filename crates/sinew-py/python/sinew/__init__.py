"""Sinew: joint-to-end stiffness of cable-driven hyper-redundant manipulators.

Models and data in the spirit of Pinocchio: load a robot folder and a cable routing, build an
``ArmStiffness``, evaluate it at configurations (numpy in, numpy out, SI units). Joints and
cables are numbered from 0, as in the Rust crates; joint ``i`` of a chain of universal joints
owns ``q[2*i]`` and ``q[2*i + 1]``.

>>> import numpy as np, sinew
>>> robot = sinew.load_robot("robots/cdhrm5")
>>> arm = sinew.ArmStiffness(robot, sinew.load_routing(robot, "decoupled"))
>>> r = arm.evaluate(np.zeros(robot.dof), [0, 5, 0, 0, 0, 0])
>>> r.stable, r.k_fd.shape
(True, (3, 3))
"""

from ._sinew import (
    ArmResult,
    ArmStiffness,
    BatchResult,
    InfeasibleError,
    InputError,
    JointRange,
    NumericalError,
    PlanResult,
    RankDeficientError,
    Robot,
    Routing,
    SinewError,
    SweepResult,
    UnstableError,
    joint_range,
    load_robot,
    load_routing,
    sweep,
)

POLICIES = ("least-total", "least-norm", "safest")
OBJECTIVES = ("stiffness-along", "compliance-along", "min-stiffness", "volume", "least-tension")

__all__ = [
    "ArmResult",
    "ArmStiffness",
    "BatchResult",
    "InfeasibleError",
    "InputError",
    "JointRange",
    "NumericalError",
    "OBJECTIVES",
    "POLICIES",
    "PlanResult",
    "RankDeficientError",
    "Robot",
    "Routing",
    "SinewError",
    "SweepResult",
    "UnstableError",
    "joint_range",
    "load_robot",
    "load_routing",
    "sweep",
]

# The MuJoCo export (crate sinew-mjcf) and the cable geometry it is checked against.
from ._sinew import cable_geometry, to_mjcf  # noqa: E402

__all__ += ["cable_geometry", "to_mjcf"]
