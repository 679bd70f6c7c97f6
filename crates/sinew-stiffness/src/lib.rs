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
//! - the whole pipeline `Q → K_x` for a robot and its routing: the model [`ArmStiffness`] and
//!   its workspace [`ArmStiffnessData`].
#![deny(missing_docs)]

mod arm;
mod cholesky;
mod colmajor;
mod data;
mod ellipsoid;
mod end;
mod end_data;
mod error;
mod inherent;
mod joint;
mod outcome;
mod structured;

pub use arm::ArmStiffness;
pub use data::{ArmStiffnessData, EndOutcome, EndSolver};
pub use ellipsoid::StiffnessEllipsoid;
pub use end::{end_compliance, end_stiffness, stability_margin};
pub use end_data::{END_RANK_TOLERANCE, EndStiffnessData, compliance_inverse, has_full_rank};
pub use error::StiffnessError;
pub use joint::{joint_block, joint_stiffness, stiffness_slope};
pub use outcome::{Outcome, OutcomeNote};
