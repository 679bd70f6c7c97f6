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
//! - with friction at the holes, the slip regimes' statics on the effective Jacobian `J̃`: the
//!   torque ([`slip_torques`]), the actuator-tension limits ([`actuator_limits`]), the
//!   equilibrium set in the actuator tensions ([`slip_equilibrium_set`]) and the dead band
//!   ([`dead_band`]) (spec §9);
//! - all of it for a robot and its routing in one call ([`ArmStatics`], [`TensionChoice`]).
//!
//! Infeasible loads are typed outcomes naming the joint — [`StaticsError::Infeasible`] with an
//! [`InfeasibleReason`] in closed form, [`StaticsError::NoEquilibrium`] on the general path —
//! never a NaN, never a panic. Force closure is reported, not required.
//!
//! # Tolerances
//!
//! Every threshold the crate decides by, one name each (the public ones are re-exported here;
//! the others are private to the file named):
//!
//! - [`JOINT_RANK_TOLERANCE`] (`1e-12`): a joint's 3 × 2 block of `J_c` has rank < 2 when
//!   `det(J_cᵀ J_c) ≤ 1e-12 (trace)²` (closed form).
//! - [`FORCE_CLOSURE_TOLERANCE`] (`1e-9`): a component of a joint's unit null direction at most
//!   this in magnitude counts as zero (closed form); the same margin decides the force-closure
//!   LP of [`EquilibriumSet::force_closure`] (`t > 1e-9`).
//! - [`SET_RANK_TOLERANCE`] (`1e-10`): a singular value of `J_c` below this fraction of the
//!   largest counts as zero (the rank of the equilibrium set).
//! - [`EQUILIBRIUM_TOLERANCE`] (`1e-9`): the relative residual `|T0 + J_cᵀ f_p| / |T0|` accepted
//!   as balance; above it the load is unreachable.
//! - `NAMED_SHARE` (`equilibrium.rs`, `0.1`): a joint or a cable is named in a
//!   [`NoEquilibrium`] when its component is at least this share of the largest.
//! - `ACTIVE_TOLERANCE` (`policy.rs`, `1e-6`): a row of a policy's program within this fraction
//!   of the bound width of its bound is active in the polish.
//! - `SNAP_FRACTION` (`policy.rs`, `1e-3`): a polished tension within this fraction of
//!   `ACTIVE_TOLERANCE` of the bound width of a limit is put exactly on it.
//! - `OUTSIDE_TOLERANCE` (`policy.rs`, `1e-7`): a policy's tension outside its limits by more
//!   than this fraction of the bound width means no tensions within the limits balance the load.
//! - `POLISH_TOLERANCE` (`policy.rs`, `1e-9`): the most a polished point may violate a row, as a
//!   fraction of the bound width, before the polish is discarded.
//! - `SHORTFALL_TOLERANCE` (`policy.rs`, `1e-9`): a certificate along one joint replaces the
//!   solver's when it falls short by more than this fraction of the largest tension limit.
//! - `NOISE_TOLERANCE` (`policy.rs`, `1e-12`): components of a certificate's joint motion below
//!   this fraction of the largest are rounding noise, set to zero.
//! - `WIDTH_FLOOR` (`policy.rs`, `1` N): the bound width the relative tolerances scale with is
//!   `max(f_max − f_min, 1 N)`.
//!
//! The interior-point solves use clarabel's default tolerances ([`convex`]).
#![deny(missing_docs)]

mod actuator_interval;
mod arm;
mod choice;
pub mod convex;
mod distribution;
mod equilibrium;
mod error;
mod interval;
mod joint_end;
mod levels;
mod policy;
mod refusal;
mod set_block;
mod slip;
mod three_cable;

pub use actuator_interval::{ActuatorInterval, actuator_interval};
pub use arm::{ArmStatics, ArmStaticsData, check_balance};
pub use choice::{Chosen, DEFAULT_POLICY_NOTE, TensionChoice};
pub use distribution::{CableLayout, distribute_tensions};
pub use equilibrium::{EQUILIBRIUM_TOLERANCE, EquilibriumSet};
pub use error::{NoEquilibrium, NoEquilibriumCause, SolverStop, StaticsError, UnsupportedRouting};
pub use interval::{
    FORCE_CLOSURE_TOLERANCE, JOINT_RANK_TOLERANCE, TensionInterval, TensionLimits,
    minimum_norm_tensions, tension_interval,
};
pub use joint_end::{
    JointEndData, KwGenerators, equilibrium_torque_derivative, equilibrium_torques,
};
pub use policy::{Distribution, TensionPolicy, distribute_with_policy};
pub use refusal::{InfeasibleReason, LevelsInfeasible, NotBalanced};
pub use set_block::SET_RANK_TOLERANCE;
pub use slip::{
    actuator_limits, cable_actuator_limits, dead_band, slip_equilibrium_set, slip_levels,
    slip_torques,
};

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
