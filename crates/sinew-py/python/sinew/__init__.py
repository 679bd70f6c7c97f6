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

Every object pickles by value (the URDF, ``robot.toml`` and routing texts, never a path), and
the batch calls (``evaluate_many``, ``plan_many``, ``sweep``) take ``threads=``; ``sinew.dask``
(optional: ``pip install "./crates/sinew-py[dask]"``) runs them chunk by chunk on a Dask
cluster.

Array arguments follow one rule: C or Fortran order, strided views, lists and tuples are read
as given (and copied: no argument is ever written); float16/float32 are widened to float64
exactly, integers converted (exact up to 2**53); None, booleans, complex numbers and strings
raise ``InputError`` naming the argument and the shape expected, as do a wrong shape and a NaN
in ``q``, ``wrench``, ``levels`` or ``tensions``. A NaN in a row of ``Q`` fails that row only
(``ok`` False, its error in ``errors``).
"""

from ._sinew import (
    ArmResult,
    ArmStiffness,
    BatchResult,
    FrictionResult,
    InfeasibleError,
    InputError,
    JointRange,
    NumericalError,
    PlanBatchResult,
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
    "FrictionResult",
    "InfeasibleError",
    "InputError",
    "JointRange",
    "NumericalError",
    "OBJECTIVES",
    "POLICIES",
    "PlanBatchResult",
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
