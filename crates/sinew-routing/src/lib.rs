//! # sinew-routing
//!
//! Cable routing geometry (spec §2): a cable is a polyline through holes fixed on the robot's
//! discs, ending at an anchor on the disc that it drives. From a routing file beside the URDF
//! (`robots/<robot>/cables.toml`, format in [`spec`]) this crate builds an immutable
//! [`Routing`] and, for a configuration `Q`, computes into a reusable [`RoutingData`]:
//!
//! - every cable's length `L_c(Q)` (eq. 2),
//! - the cable Jacobian `J_c = ∂L/∂Q`, m × dof (eq. 3),
//! - each cable's Hessian `H_c = ∂²L_c/∂Q²` and the weighted sum `Σ_c f_c H_c` (the
//!   controllable stiffness of spec §3),
//!
//! all analytic and without allocation (Pinocchio's model/data split), and the cable stiffness
//! `K_l = diag(E·A / l_c)` (eq. 13).
//!
//! Two routing models share one code path: **decoupled** (each cable crosses only the joint it
//! drives; `J_c` block diagonal) and **routed** (each cable also passes through its holes on
//! every proximal disc; `J_c` block lower-triangular). The file gives the cables hole by hole
//! or as a per-joint pattern; both expand to the same [`Routing`].
//!
//! ```no_run
//! # fn main() -> Result<(), sinew_routing::RoutingError> {
//! use sinew_routing::{Order, RoutingData, compute_cable_geometry};
//! let robot = sinew_robot::load("robots/cdhrm5")?;
//! let routing = sinew_routing::load("robots/cdhrm5", &robot)?; // robots/cdhrm5/cables.toml
//! let mut robot_data = sinew_robot::RobotData::new(&robot);
//! let mut data = RoutingData::new(&routing);
//! let q = vec![0.1; robot.dof()];
//! compute_cable_geometry(&routing, &robot, &mut robot_data, &mut data, &q, Order::Hessians)?;
//! let lengths = data.lengths()?; // m
//! let j_c = data.jacobian()?; // m × dof
//! let f = vec![50.0; routing.cable_count()];
//! let mut k_controllable = faer::Mat::<f64>::zeros(robot.dof(), robot.dof());
//! data.add_weighted_hessians(&routing, &f, k_controllable.as_mut())?; // Σ f_c H_c
//! # let _ = (lengths, j_c);
//! # Ok(()) }
//! ```
//!
//! Friction at the holes (spec §9, geometry only): each cable's μ and entry direction come from
//! the routing file (default μ = 0); [`FrictionModel`] and its workspace [`FrictionData`] give
//! every segment's length `ℓ_s`, `J_s` and `H_s`, the wrap angle `θ` at every hole and its
//! gradient ([`compute_friction_geometry`]), and the `pull`/`release` capstan weights `w_s`,
//! `∂w_s/∂Q` and the effective Jacobian `J̃_c = Σ_s w_s J_s` ([`compute_capstan_weights`]). At
//! μ = 0 the weights are exactly 1 and `J̃_c` is `J_c` bit for bit.
//!
//! Conventions: SI units (m, rad, Pa, N); universal joint `i` (0-based) is the revolute pair
//! `2i` (about x), `2i + 1` (about y); cables are ordered by the universal joint they drive.
//!
//! **Invariant:** nothing in this crate mutates a [`Routing`] after it is built; every
//! per-configuration function writes only into a [`RoutingData`] or a caller's buffer.
#![deny(missing_docs)]

mod error;
mod friction;
mod geometry;
mod routing;
pub mod spec;
mod vec3;

pub use error::{JointProblem, Result, RoutingError};
pub use friction::{
    CableRows, DofRow, FrictionData, FrictionModel, SegmentRows, Slip, WRAP_KINK, WeightGradient,
    capstan_factor, compute_capstan_weights, compute_friction_angles, compute_friction_geometry,
    compute_wrap_gradients,
};
pub use geometry::{
    HessianBatch, Order, RoutingData, SegmentHessians, compute_cable_geometry,
    compute_cable_geometry_from_kinematics,
};
pub use routing::{
    Cable, CableView, Hole, HoleView, MAX_HOLE_OFFSET, MIN_SEGMENT_LENGTH, ROUTED_ROUTING_FILE,
    ROUTING_FILE, Routing, RoutingModel, RoutingView, Segment, load, routing_file,
};
pub use spec::{
    CableFriction, ExplicitCable, HoleSpec, Material, Pattern, PatternModel, PerJoint, RoutingSpec,
};
