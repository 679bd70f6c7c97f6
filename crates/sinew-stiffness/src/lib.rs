//! # sinew-stiffness
//!
//! Joint stiffness and end stiffness of a cable-driven hyper-redundant manipulator (paper
//! section III; spec §3, §5):
//!
//! - joint stiffness `K = Σ f_c H_c + J_cᵀ K_l J_c` ([`joint_stiffness`]), its slope in the
//!   tensions ([`stiffness_slope`]) and per-joint 2 × 2 blocks ([`joint_block`]);
//! - end compliance and stiffness `C_x = J_x (K_q + K_W)⁻¹ J_xᵀ`, `K_x = C_x⁻¹`
//!   ([`end_compliance`], [`end_stiffness`]), with unstable equilibria and rank-deficient
//!   Jacobians as typed outcomes;
//! - with friction at the holes (spec §9): the stick regime's `K_stick` ([`stick_stiffness`])
//!   and the slip regimes' `K = −∂τ/∂Q` with the slip direction held ([`slip_stiffness`]),
//!   into a [`FrictionStiffnessData`];
//! - the whole pipeline `Q → K_x` for a robot and its routing: the model [`ArmStiffness`] and
//!   its workspace [`ArmStiffnessData`].
//!
//! The pipeline runs in stages on a workspace ([`ArmStiffness::set_pose`],
//! [`ArmStiffness::set_tensions`], [`ArmStiffness::solve_end`]; [`ArmStiffness::evaluate`] in
//! one call), and its one evaluation outcome is [`ArmStiffnessData::outcome`].
//!
//! # Tolerances
//! Every threshold of the crate, named once:
//! - [`END_RANK_TOLERANCE`] (`1e-10`): a pivot of `C_x`'s 6 × 6 LU below this fraction of the
//!   largest means `J_x` has rank < 6 ([`has_full_rank`], the one test of it, which the
//!   planner uses too); the same fraction of the singular values of `C_x[0:3, 0:3]` decides
//!   that the translational stiffness with rotations free does not exist.
//! - `RESIDUAL_TOLERANCE` (`structured/mod.rs`, `1e-12`): the backward error above which the
//!   structured `O(dof)` solve is not trusted and the dense reference runs instead.
//! - Positive definiteness of `K_q + K_W` has no threshold: a Cholesky pivot that is not
//!   strictly positive (or NaN) is unstable.
#![deny(missing_docs)]

mod arm;
mod cholesky;
mod colmajor;
mod data;
mod directional;
mod ellipsoid;
mod end;
mod end_data;
mod error;
mod friction;
mod friction_arm;
mod hessian_sums;
mod hole_bounds;
mod holes;
mod inherent;
mod joint;
mod lu;
mod outcome;
mod slip;
mod stick;
mod stick_limit;
mod structured;

pub use arm::ArmStiffness;
pub use cholesky::cholesky_lower_in_place;
pub use data::{ArmStiffnessData, EndOutcome, EndSolver};
pub use directional::{DirectionalResponse, Increment, directional_response, sliding_response};
pub use ellipsoid::StiffnessEllipsoid;
pub use end::{end_compliance, end_stiffness, stability_margin};
pub use end_data::{END_RANK_TOLERANCE, EndStiffnessData, compliance_inverse, has_full_rank};
pub use error::StiffnessError;
pub use friction::{FrictionRegime, FrictionStiffnessData, History};
pub use friction_arm::FrictionArmData;
pub use holes::{BandEdge, EDGE_TOLERANCE, HoleEvent, RATE_TOLERANCE};
pub use joint::{joint_block, joint_stiffness, stiffness_slope};
pub use outcome::{Outcome, OutcomeNote};
pub use slip::slip_stiffness;
pub use stick::stick_stiffness;
pub use stick_limit::{StickLoadLimit, base_directions, stick_load_limits};
