"""Type stubs of the extension module ``sinew._sinew`` (re-exported by ``sinew``).

Units are SI (m, rad, N, N m); joints, cables and rows are numbered from 0; every array is
float64 unless marked bool.
"""

from collections.abc import Mapping
from os import PathLike
from typing import Literal, Optional, Union

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
F64 = npt.NDArray[np.float64]
Bool = npt.NDArray[np.bool_]
Policy = Literal["least-total", "least-norm", "safest"]
PlanObjective = Literal[
    "stiffness-along", "compliance-along", "min-stiffness", "volume", "least-tension"
]

class SinewError(Exception):
    """Base class of every error Sinew raises."""

class InputError(SinewError):
    """Wrong input: a file, a shape, a non-finite number, an angle outside its limits."""

class InfeasibleError(SinewError):
    """The cables cannot hold the load within their limits; a plan's requirements unreachable."""

class UnstableError(SinewError):
    """K_q + K_W is not positive definite (raised by the planner; evaluate returns stable=False)."""

class RankDeficientError(SinewError):
    """J_x has rank < 6."""

class NumericalError(SinewError):
    """The computation failed."""

class Robot:
    """A robot folder loaded: a serial chain of revolute joints grouped into joints."""

    @property
    def name(self) -> str: ...
    @property
    def path(self) -> str: ...
    @property
    def dof(self) -> int:
        """Revolute joints: the length of ``q``."""
    @property
    def joints(self) -> int:
        """Joints (a universal joint counts once): the length of ``levels``."""
    @property
    def joint_names(self) -> list[str]: ...
    @property
    def joint_groups(self) -> list[tuple[int, int]]:
        """Each joint's ``(start, stop)`` range of ``q``."""
    @property
    def axes(self) -> F64:
        """(dof, 3) unit axes in the joint frames."""
    @property
    def limits(self) -> F64:
        """(dof, 2) ``[lower, upper]``, rad."""
    @property
    def gravity(self) -> F64:
        """(3,) m/s², base frame."""

class Routing:
    """A cable routing of a robot."""

    @property
    def path(self) -> str: ...
    @property
    def cables(self) -> list[str]:
        """Cable names in routing order (the order of every tension vector)."""
    @property
    def cable_count(self) -> int: ...
    @property
    def cable_joints(self) -> list[int]:
        """The joint each cable ends on."""
    @property
    def tension_limits(self) -> F64:
        """(cables, 2) ``[f_min, f_max]``, N."""
    @property
    def is_decoupled(self) -> bool: ...

def load_robot(dir: Union[str, PathLike[str]], gravity: bool = True) -> Robot:
    """Load a robot folder (``robot.toml`` and its URDF); ``gravity=False`` zeroes gravity."""

def load_routing(robot: Robot, path_or_model: str = "decoupled") -> Routing:
    """A routing file's path, or ``"decoupled"``/``"routed"`` (``cables.toml``/``cables-routed.toml``)."""

class ArmResult:
    """One evaluation of the arm (``sinew arm --json``'s numbers). Its numbers are copied when
    ``evaluate`` returns; each array is made on its first read (then the same object)."""

    q: F64
    wrench: F64
    policy: str
    """``"levels"``, ``"given"`` or the policy's name."""
    levels: Optional[F64]
    policy_objective: Optional[float]
    t0: F64
    """(dof,) ``T0 = T_g + J_xᵀ F0``, N m."""
    tensions: F64
    """(cables,) N."""
    lambda_intervals: Optional[F64]
    """(joints, 2) ``[λ_min, λ_max]`` with levels."""
    k_controllable: F64
    k_inherent: F64
    k_q: F64
    """(dof, dof) N m/rad."""
    k_w: F64
    j_x: F64
    """(6, dof), linear rows first, base frame."""
    stable: bool
    min_eigenvalue: float
    c_x: Optional[F64]
    """(6, 6), None when unstable."""
    k_x: Optional[F64]
    k_fd: Optional[F64]
    """(3, 3) N/m (eq. 21)."""
    eigenvalues: Optional[F64]
    """(3,) of K_fd, ascending."""
    directions: Optional[F64]
    """(3, 3): row k is the unit direction of eigenvalues[k]."""
    semi_axes: Optional[F64]
    condition_number: Optional[float]
    volume: Optional[float]
    notes: list[str]

class BatchResult:
    """Stacked results of ``evaluate_many``: row r is ``Q[r]``; failed rows are NaN."""

    ok: Bool
    stable: Bool
    min_eigenvalue: F64
    t0: F64
    """(N, dof)."""
    tensions: F64
    """(N, cables)."""
    c_x: F64
    """(N, 6, 6)."""
    k_x: F64
    k_fd: F64
    """(N, 3, 3)."""
    errors: list[tuple[int, str, str]]
    """``(row, kind, message)`` of each failed row."""
    def __len__(self) -> int: ...

class PlanResult:
    """A certified plan (``sinew plan --json``'s numbers)."""

    objective: str
    value: float
    gap: float
    lambda_: F64
    levels: Optional[F64]
    tensions: F64
    total_tension: float
    k_fd: Optional[F64]
    c_x: F64
    min_eigenvalue: float
    stable: bool
    iterations: int

class ArmStiffness:
    """The model ``Q → K_x`` of a robot and a routing, with its workspace."""

    def __init__(self, robot: Robot, routing: Routing) -> None: ...
    @property
    def dof(self) -> int: ...
    @property
    def joints(self) -> int: ...
    @property
    def cables(self) -> int: ...
    @property
    def has_levels(self) -> bool: ...
    def evaluate(
        self,
        q: ArrayLike,
        wrench: Optional[ArrayLike] = None,
        levels: Optional[ArrayLike] = None,
        policy: Optional[Policy] = None,
        tensions: Optional[ArrayLike] = None,
    ) -> ArmResult:
        """Evaluate at ``q`` under ``wrench``; at most one of levels, policy, tensions."""
    def evaluate_many(
        self,
        Q: ArrayLike,
        wrench: Optional[ArrayLike] = None,
        levels: Optional[ArrayLike] = None,
        policy: Optional[Policy] = None,
    ) -> BatchResult:
        """Every row of ``Q`` (N, dof) in parallel; raises only when every row fails."""
    def plan(
        self,
        q: ArrayLike,
        wrench: Optional[ArrayLike] = None,
        objective: PlanObjective = "min-stiffness",
        direction: Optional[ArrayLike] = None,
        k_min: Optional[float] = None,
        k_des: Optional[ArrayLike] = None,
        margin: float = 1e-3,
        budget: Optional[float] = None,
        joint_budgets: Optional[Mapping[int, float]] = None,
        fixed_levels: Optional[Mapping[int, float]] = None,
        gap: float = 1e-6,
    ) -> PlanResult:
        """The tensions that optimise the end stiffness (``sinew plan``)."""

class JointRange:
    """One universal joint alone over its feasible tension interval (``sinew joint``)."""

    joint: int
    cables: list[str]
    q: F64
    torque: F64
    lambda_: F64
    particular: F64
    null_direction: F64
    force_closure: bool
    tensions: F64
    """(2, 3): at λ_min, at λ_max."""
    k_at_min: F64
    k_at_max: F64
    k_inherent: F64
    sigma_x: F64
    """``[K_x min, K_x max]`` (eq. 20)."""
    sigma_y: F64
    delta_x: float
    delta_y: float

class SweepResult:
    """Fig. 5 maps: ``k_x_min[a, b]`` at ``q = [angles[a], angles[b]]``, NaN where infeasible."""

    joint: int
    torque: F64
    angles: F64
    feasible: Bool
    k_x_min: F64
    k_x_max: F64
    k_y_min: F64
    k_y_max: F64

def joint_range(
    robot: Robot, routing: Routing, joint: int, q: ArrayLike, torque: ArrayLike
) -> JointRange: ...
def sweep(
    robot: Robot,
    routing: Routing,
    joint: int,
    torque: ArrayLike,
    points: int = 41,
    lower: Optional[float] = None,
    upper: Optional[float] = None,
) -> SweepResult: ...
def to_mjcf(
    robot: Robot,
    routing: Routing,
    q: ArrayLike,
    tensions: ArrayLike,
    wrench: Optional[ArrayLike] = None,
    *,
    cables: str = "springs",
    split: Optional[str] = None,
    damping: float = 1.0,
) -> str:
    """The MJCF text of the robot at ``q`` held by ``tensions`` (N, routing order); ``cables``
    "springs" or "motors", ``split="segments"`` for one spring per segment. Apply ``-wrench``
    at site ``tip`` to hold the pose."""
    ...
def cable_geometry(robot: Robot, routing: Routing, q: ArrayLike) -> tuple[F64, F64]:
    """``(lengths, j_c)`` at ``q``: the cable lengths (m) and ``J_c = dL/dQ`` (cables x dof)."""
    ...
