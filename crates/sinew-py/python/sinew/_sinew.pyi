"""Type stubs of the extension module ``sinew._sinew`` (re-exported by ``sinew``).

Units are SI (m, rad, N, N m); joints, cables and rows are numbered from 0; every array is
float64 unless marked bool.

Arrays in: C or Fortran order, strided views, lists and tuples are read as given and copied
(no argument is ever written); float16/float32 widen to float64 exactly, integers convert
(exact up to 2**53); None, booleans, complex numbers and strings raise InputError naming the
argument and the shape expected. A NaN in a row of ``Q`` fails that row only.

``threads``: the batch calls run on a rayon pool of exactly that many threads (never rayon's
global pool), or on every core when None; the GIL is released while they run.

Pickling: Robot, Routing and ArmStiffness pickle by value (the URDF, robot.toml and routing
file texts; never a path) and evaluate bit for bit like the original when unpickled.
"""

from collections.abc import Mapping
from os import PathLike
from typing import Any, Literal, Optional, Union

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
F64 = npt.NDArray[np.float64]
Bool = npt.NDArray[np.bool_]
Policy = Literal["least-total", "least-norm", "safest"]
Regime = Literal["pull", "release", "stick"]
History = Literal["pull", "release", "equal"]
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
    """K_q + K_W is not positive definite: raised by ``evaluate(..., require_stiffness=True)``
    (without it, evaluate returns stable=False, as ``sinew arm`` does)."""

class RankDeficientError(SinewError):
    """J_x has rank < 6: raised by ``plan`` (an objective needs K_x; ``sinew plan`` exits 1)
    and by ``evaluate(..., require_stiffness=True)`` (without it, k_x is None)."""

class NumericalError(SinewError):
    """The computation failed."""

class Robot:
    """A robot folder loaded: a serial chain of revolute joints grouped into joints."""

    @classmethod
    def from_texts(cls, urdf: str, description: str, gravity: bool = True) -> Robot:
        """The robot of a URDF text and a ``robot.toml`` text (nothing read from disk)."""
    @property
    def urdf(self) -> str:
        """The URDF's text."""
    @property
    def description(self) -> str:
        """The text of ``robot.toml``."""
    @property
    def name(self) -> str: ...
    @property
    def path(self) -> Optional[str]:
        """The folder it was loaded from; None when built from texts (unpickled)."""
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

    @classmethod
    def from_text(cls, robot: Robot, text: str, name: str = "cables.toml") -> Routing:
        """The routing of a routing file's text for ``robot``."""
    @property
    def robot(self) -> Robot: ...
    @property
    def text(self) -> str:
        """The routing file's text."""
    @property
    def path(self) -> Optional[str]:
        """The file it was read from; None when built from a text (unpickled)."""
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

class FrictionResult:
    """One evaluation with friction at the holes (``sinew arm --friction --json``'s numbers)."""

    mu: F64
    regime: Regime
    history: Optional[History]
    q: F64
    wrench: F64
    t0: F64
    tensions: F64
    segments: list[dict[str, Any]]
    dead_band: F64
    k_q: F64
    k_q_skew_norm: float
    k_w: F64
    j_x: F64
    stable: bool
    min_eigenvalue: float
    c_x: Optional[F64]
    k_x: Optional[F64]
    k_fd: Optional[F64]
    directional: Optional[dict[str, Any]]
    stick_load_limit: Optional[list[dict[str, Any]]]
    notes: list[str]

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

class PlanBatchResult:
    """Stacked results of ``plan_many``: row r is ``Q[r]``; failed rows are NaN."""

    objective: str
    ok: Bool
    value: F64
    gap: F64
    tensions: F64
    """(N, cables)."""
    total_tension: F64
    levels: Optional[F64]
    """(N, joints), None when the routing has no levels."""
    k_fd: F64
    """(N, 3, 3), NaN where J_x has rank < 6."""
    c_x: F64
    """(N, 6, 6)."""
    min_eigenvalue: F64
    stable: Bool
    iterations: npt.NDArray[np.int64]
    errors: list[tuple[int, str, str]]
    warm: Optional[npt.NDArray[np.bool_]]
    """``plan_along`` only: whether each step's warm-started answer was accepted."""
    """``(row, kind, message)`` of each failed row."""
    def __len__(self) -> int: ...

class ArmStiffness:
    """The model ``Q → K_x`` of a robot and a routing, with its workspace."""

    def __init__(self, robot: Robot, routing: Routing) -> None: ...
    @property
    def robot(self) -> Robot: ...
    @property
    def routing(self) -> Routing: ...
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
        require_stiffness: bool = False,
        friction: Optional[float] = None,
        regime: Optional[Regime] = None,
        history: Optional[History] = None,
        direction: Optional[ArrayLike] = None,
    ) -> Union[ArmResult, FrictionResult]:
        """Evaluate at ``q`` under ``wrench``; at most one of levels, policy, tensions.
        ``require_stiffness``: raise UnstableError / RankDeficientError instead of None.
        With friction at the holes (``friction`` μ > 0, or the routing file's): a
        ``FrictionResult`` in ``regime`` (default stick) after ``history`` (default pull);
        ``direction`` (3,) the directional response's force (default the load's)."""
    def evaluate_many(
        self,
        Q: ArrayLike,
        wrench: Optional[ArrayLike] = None,
        levels: Optional[ArrayLike] = None,
        policy: Optional[Policy] = None,
        threads: Optional[int] = None,
        raise_if_all_fail: bool = True,
        out: Optional[dict[str, np.ndarray]] = None,
    ) -> BatchResult:
        """Every row of ``Q`` (N, dof) in parallel under ``wrench`` ((6,) for every row, or
        (N, 6)); raises only when every row fails (and ``raise_if_all_fail``). ``out`` maps
        field names to writable C-contiguous arrays of the result's shapes (bool for ``ok``
        and ``stable``, float64 else), written in place and returned as those fields."""
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
        friction: Optional[float] = None,
        regime: Optional[Literal["stick", "pull", "release"]] = None,
        history: Optional[Literal["pull", "release", "equal"]] = None,
    ) -> PlanResult:
        """The tensions that optimise the end stiffness (``sinew plan``); with ``friction``,
        in the stick regime after ``history`` (``sinew plan --friction``; the slip regimes are
        refused)."""
    def plan_many(
        self,
        Q: ArrayLike,
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
        threads: Optional[int] = None,
        raise_if_all_fail: bool = True,
    ) -> PlanBatchResult:
        """``plan`` at every row of ``Q`` (N, dof) in parallel; a typed failure per row."""
    def plan_along(
        self,
        Q: ArrayLike,
        wrench: Optional[ArrayLike] = None,
        objective: PlanObjective = "min-stiffness",
        direction: Optional[ArrayLike] = None,
        k_min: Optional[float] = None,
        k_des: Optional[ArrayLike] = None,
        margin: float = 1e-3,
        budget: Optional[float] = None,
        joint_budgets: Optional[Mapping[int, float]] = None,
        gap: float = 1e-6,
        max_rate: Optional[float] = None,
        dt: Optional[float] = None,
    ) -> PlanBatchResult:
        """One certified plan per row of ``Q`` (N, dof), in order, each warm-started from the
        step before (``warm``); ``max_rate`` (N/s) with ``dt`` (s) bounds each cable's change
        per step. A failed step is NaN in its row and the next starts cold."""

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
    regime: Optional[Regime]
    history: Optional[History]
    mu: Optional[F64]

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
    threads: Optional[int] = None,
    friction: Optional[float] = None,
    regime: Optional[Regime] = None,
    history: Optional[History] = None,
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
    segment_tensions: Optional[list[ArrayLike]] = None,
) -> str:
    """The MJCF text of the robot at ``q`` held by ``tensions`` (N, routing order); ``cables``
    "springs" or "motors", ``split="segments"`` for one spring per segment, and with it
    ``segment_tensions`` (per cable, actuator to anchor, as ``FrictionResult.segments``) for
    each segment's own tension. Apply ``-wrench`` at site ``tip`` to hold the pose."""
    ...
def cable_geometry(robot: Robot, routing: Routing, q: ArrayLike) -> tuple[F64, F64]:
    """``(lengths, j_c)`` at ``q``: the cable lengths (m) and ``J_c = dL/dQ`` (cables x dof)."""
    ...
