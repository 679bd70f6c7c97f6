//! # sinew-statics
//!
//! The statics of a cable-driven hyper-redundant manipulator (paper section II, IV.A):
//!
//! - cable-joint statics (eq. 5): `τ = −J_cᵀ f` ([`cable_torques`]);
//! - the feasible tension interval of a 3-cable, 2-DOF joint in closed form (eq. 22–23,
//!   [`tension_interval`]) and over a whole arm, decoupled or routed ([`distribute_tensions`]);
//! - joint-end statics (eq. 6–9): `T0 = T_g + J_xᵀ F0` ([`equilibrium_torques`]), and in the
//!   same pass `J_x` and `K_W = ∂T0/∂Q` as its `O(dof)` generators ([`KwGenerators`], the one
//!   owner of `∂T0/∂Q`; dense: [`equilibrium_torque_derivative`]);
//! - for any cable set (any number of cables, shared cables, 1-DOF and 2-DOF joints): the
//!   equilibrium set `f = f_p + N λ` and its polytope ([`EquilibriumSet`]), and the named
//!   tension policies over it ([`TensionPolicy`]: least total tension, least 2-norm, farthest
//!   from the limits), solved with clarabel;
//! - all of it for a robot and its routing in one call ([`ArmStatics`], [`TensionChoice`]).
//!
//! Infeasible loads are typed outcomes naming the joint — [`StaticsError::Infeasible`] with an
//! [`InfeasibleReason`] in closed form, [`StaticsError::NoEquilibrium`] on the general path —
//! never a NaN, never a panic. Force closure is reported, not required.
#![deny(missing_docs)]

mod arm;
pub mod convex;
mod distribution;
mod equilibrium;
mod error;
mod interval;
mod joint_end;
mod policy;

pub use arm::{ArmStatics, ArmStaticsData, TensionChoice};
pub use distribution::{CableLayout, distribute_tensions};
pub use equilibrium::{EQUILIBRIUM_TOLERANCE, EquilibriumSet, SET_RANK_TOLERANCE};
pub use error::{
    InfeasibleReason, NoEquilibrium, NoEquilibriumCause, StaticsError, UnsupportedRouting,
};
pub use interval::{
    FORCE_CLOSURE_TOLERANCE, RANK_TOLERANCE, TensionInterval, TensionLimits, minimum_norm_tensions,
    tension_interval,
};
pub use joint_end::{
    JointEndData, KwGenerators, equilibrium_torque_derivative, equilibrium_torques,
};
pub use policy::{Distribution, TensionPolicy, distribute_with_policy};

use faer::MatRef;

/// Cable-joint statics (eq. 5): `τ = −J_cᵀ f`, the generalized force the cables put on the
/// joints (N m). `tau` has length dof, `tensions` length m. No allocation.
///
/// # Errors
/// [`StaticsError::DimensionMismatch`].
pub fn cable_torques(
    jacobian: MatRef<'_, f64>,
    tensions: &[f64],
    tau: &mut [f64],
) -> Result<(), StaticsError> {
    if tensions.len() != jacobian.nrows() {
        return Err(StaticsError::DimensionMismatch {
            what: "tensions",
            expected: jacobian.nrows(),
            got: tensions.len(),
        });
    }
    if tau.len() != jacobian.ncols() {
        return Err(StaticsError::DimensionMismatch {
            what: "cable torques",
            expected: jacobian.ncols(),
            got: tau.len(),
        });
    }
    for (j, t) in tau.iter_mut().enumerate() {
        *t = -(0..tensions.len()).map(|c| jacobian[(c, j)] * tensions[c]).sum::<f64>();
    }
    Ok(())
}
