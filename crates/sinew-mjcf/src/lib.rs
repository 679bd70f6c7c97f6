//! A Sinew robot, its cables and chosen tensions as a MuJoCo model (MJCF text).
//!
//! [`to_mjcf`] writes one `<mujoco>` document from a [`Robot`], its [`Routing`], a pose `q`,
//! the cable tensions `f` (routing order) and the load `F0`, so that a simulator reproduces
//! Sinew's statics and stiffness at that pose:
//!
//! - `<compiler angle="radian" autolimits="true" inertiafromgeom="false"/>`, gravity from
//!   robot.toml; every length in m, angle in rad, tension in N.
//! - One `<body>` per robot body (fixed URDF links already folded in by sinew-robot), in the
//!   body's frame, with its inertial. A universal joint is two `hinge`s; MuJoCo composes the
//!   hinges of one body in order, so axes x then y give `Rx(q1)·Ry(q2)` (eq. 1). A massless
//!   body with no hole and not the tip (the cross of a universal joint) is merged into the next
//!   body: its joint becomes that body's first hinge, at the point and along the axis it has
//!   there. A massless body that carries holes or the tip keeps a body with [`MIN_MASS`] (the
//!   file says so in a comment).
//! - Hinge ranges from the joint limits (none for a continuous joint), joint damping
//!   [`MjcfOptions::damping`]; geoms (capsules along the links) with contacts off
//!   (`contype="0" conaffinity="0"`, set in `<default>`).
//! - One `<site>` per cable hole (`{cable}_h{k}`, `k` from 0 at the base) in its body's frame,
//!   and `tip` at the robot's tip point.
//! - One `<spatial>` tendon per cable through its sites in routing order, or with
//!   [`Split::Segments`] one per segment between consecutive holes (`{cable}_s{k}`).
//! - [`CableModel::Springs`]: tendon `stiffness` = `K_l = E·A / l_c` (eq. 13: `l_c` the elastic
//!   length, free length plus the routed length at `Q = 0`) and `springlength` such that the
//!   tension at the exported pose is `f`: `L_u = L_c(q) − f/K_l`, written `"0 L_u"` when
//!   `L_u ≥ 0` (a slack cable pushes nothing) and `"L_u L_u"` when negative (the decoupled
//!   model, whose tendon is only the crossing while `K_l` counts the free length: MuJoCo
//!   refuses `"0 L_u"` there, and the length never falls below a negative `L_u`, so that spring
//!   also only pulls). The segments of [`Split::Segments`] are springs `E·A/ℓ_s(q)` (spec §9's
//!   stick model) with the same tension `f`, or each with its own
//!   ([`State::segment_tensions`]: the stick regime after a pull or a release).
//! - [`CableModel::Motors`]: tendons without stiffness, `<motor tendon=… gear="-1"
//!   ctrlrange="f_min f_max"/>` (a positive ctrl with gear 1 would lengthen the tendon): the
//!   stiffness is then the controllable part `Σ f H_c` only, plus `K_W`.
//! - Sensors `tendonpos` per tendon (`{tendon}_length`) and `actuatorfrc` per motor
//!   (`{cable}_force`); a `<keyframe>` `exported` with the pose in `qpos` (and the tensions in
//!   `ctrl` for motors); `<custom>` numerics `sinew_wrench` (F0) and `sinew_tensions`.
//!
//! The load is not in the model: to hold the pose, apply `−F0` at site `tip`, in the world
//! frame (e.g. `mj_applyFT`). **Reads:** the robot, the routing, and the cable and segment
//! lengths at `q` (sinew-routing); it decides no tension.
#![deny(missing_docs)]

mod error;
mod tree;
mod write;
mod xml;

use sinew_robot::{Robot, RobotData};
use sinew_routing::{Order, Routing, RoutingData, compute_cable_geometry};

pub use error::{MjcfError, Result};
pub use tree::{MIN_INERTIA, MIN_MASS};

/// How the cables enter the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CableModel {
    /// Elastic tendons (`K_l`, the spring length giving the tension at the pose): the full
    /// joint stiffness, controllable plus inherent.
    #[default]
    Springs,
    /// Inextensible tendons pulled by motors at the tensions: the controllable part alone.
    Motors,
}

/// One tendon per cable, or one per segment between holes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Split {
    /// One tendon per cable through all its holes.
    #[default]
    Cables,
    /// One spring per segment (spec §9's stick model: no hole slides). Springs only.
    Segments,
}

/// The choices of the written model.
#[derive(Debug, Clone, PartialEq)]
pub struct MjcfOptions {
    /// Springs or motors.
    pub cables: CableModel,
    /// Tendons per cable or per segment.
    pub split: Split,
    /// Damping of every hinge, N m s/rad (≥ 0): a stated choice so a simulation settles.
    pub damping: f64,
    /// MuJoCo's time step, s (> 0).
    pub timestep: f64,
}

/// The default joint damping, N m s/rad: near critical for cdhrm5's slowest mode at E4 (about
/// 1 rad/s), so a pushed arm settles to 1e-4 of its static deflection within 12 s of simulated
/// time (measured by `crates/sinew-py/tests/test_mujoco.py`); small damping rings for minutes.
pub const DEFAULT_DAMPING: f64 = 1.0;

/// The default time step, s: stable with the default integrator (implicitfast) on the stiffest
/// joints of the repository's robots.
pub const DEFAULT_TIMESTEP: f64 = 2e-3;

impl Default for MjcfOptions {
    fn default() -> MjcfOptions {
        MjcfOptions {
            cables: CableModel::Springs,
            split: Split::Cables,
            damping: DEFAULT_DAMPING,
            timestep: DEFAULT_TIMESTEP,
        }
    }
}

/// What is exported: the pose, the tensions that hold it and the load.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State<'a> {
    /// `Q`, rad, one per revolute joint (within the limits).
    pub q: &'a [f64],
    /// `f`, N, one per cable in routing order (within each cable's limits).
    pub tensions: &'a [f64],
    /// `F0`, the wrench the tip exerts on its environment, base frame (N, N m; eq. 6).
    pub wrench: [f64; 6],
    /// With [`Split::Segments`], each segment's own tension (N, one per
    /// [`Routing::segments`] entry, in that order): the stick regime after a pull or a release
    /// (spec §9), where the tension changes at every hole. `None`: every segment carries its
    /// cable's tension (stick after equal tensions).
    pub segment_tensions: Option<&'a [f64]>,
}

/// Tensions this far outside a cable's limits (relative to `f_max`) are still accepted:
/// a solver's answer on a limit may miss it by rounding.
const LIMIT_TOLERANCE: f64 = 1e-9;

/// The MJCF document of `robot` and `routing` at `state` (module docs for every convention).
///
/// # Errors
/// [`MjcfError::Robot`] for a pose of the wrong length, non-finite or outside the limits;
/// [`MjcfError::Routing`] for a routing of another robot or a degenerate segment at `q`;
/// [`MjcfError::TensionCount`], [`MjcfError::Tension`] (non-finite or outside the cable's
/// limits; a segment's too), [`MjcfError::SegmentTensionCount`], [`MjcfError::Wrench`];
/// [`MjcfError::Option`] for a negative or non-finite damping, a non-positive time step,
/// motors with [`Split::Segments`], or segment tensions without it.
pub fn to_mjcf(
    robot: &Robot,
    routing: &Routing,
    state: &State<'_>,
    options: &MjcfOptions,
) -> Result<String> {
    robot.check_limits(state.q)?;
    routing.check_robot(robot)?;
    if state.tensions.len() != routing.cable_count() {
        return Err(MjcfError::TensionCount {
            expected: routing.cable_count(),
            got: state.tensions.len(),
        });
    }
    for ((cable, &f), &limits) in
        routing.cables().iter().zip(state.tensions).zip(routing.cable_limits())
    {
        let slack = LIMIT_TOLERANCE * limits[1].abs().max(1.0);
        if !(f.is_finite() && f >= limits[0] - slack && f <= limits[1] + slack) {
            return Err(MjcfError::Tension { cable: cable.name.clone(), tension: f, limits });
        }
    }
    if let Some(segments) = state.segment_tensions {
        check_segment_tensions(routing, segments, options)?;
    }
    if let Some((index, &value)) = state.wrench.iter().enumerate().find(|(_, w)| !w.is_finite()) {
        return Err(MjcfError::Wrench { index, value });
    }
    if !(options.damping.is_finite() && options.damping >= 0.0) {
        return Err(MjcfError::Option {
            option: "damping",
            reason: format!("{} is not a finite number ≥ 0 (N m s/rad)", options.damping),
        });
    }
    if !(options.timestep.is_finite() && options.timestep > 0.0) {
        return Err(MjcfError::Option {
            option: "timestep",
            reason: format!("{} is not a finite number > 0 (s)", options.timestep),
        });
    }
    if options.cables == CableModel::Motors && options.split == Split::Segments {
        return Err(MjcfError::Option {
            option: "split",
            reason: "segments are springs: use them with spring cables, not motors".to_owned(),
        });
    }
    let mut robot_data = RobotData::new(robot);
    let mut data = RoutingData::new(routing);
    compute_cable_geometry(routing, robot, &mut robot_data, &mut data, state.q, Order::Lengths)?;
    let at = write::AtPose { lengths: data.lengths()?, segment_lengths: data.segment_lengths()? };
    let tree = tree::bodies(robot, routing);
    Ok(write::document(robot, routing, &tree, state, &at, options))
}

/// Segment tensions need [`Split::Segments`], one per routing segment, each within its cable's
/// limits.
fn check_segment_tensions(
    routing: &Routing,
    tensions: &[f64],
    options: &MjcfOptions,
) -> Result<()> {
    if options.split != Split::Segments {
        return Err(MjcfError::Option {
            option: "segment_tensions",
            reason: "apply to one tendon per segment: use them with split segments".to_owned(),
        });
    }
    let expected = routing.segments().len();
    if tensions.len() != expected {
        return Err(MjcfError::SegmentTensionCount { expected, got: tensions.len() });
    }
    for (cable, &limits) in routing.cables().iter().zip(routing.cable_limits()) {
        let slack = LIMIT_TOLERANCE * limits[1].abs().max(1.0);
        for &t in &tensions[cable.segments.clone()] {
            if !(t.is_finite() && t >= limits[0] - slack && t <= limits[1] + slack) {
                return Err(MjcfError::Tension { cable: cable.name.clone(), tension: t, limits });
            }
        }
    }
    Ok(())
}
