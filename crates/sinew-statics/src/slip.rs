//! The statics of the slip regimes (spec §9, #27): with friction at the holes and every hole
//! sliding one way ([`Slip::Pull`] or [`Slip::Release`]), the segment tensions are the actuator
//! tension times the capstan weights, and the statics is §4's on the effective cable Jacobian.
//!
//! # Math
//! Cable `c`, friction segments `s = 0 … H−1` (0 the free length; `crate`-external conventions
//! in `sinew_routing::friction` and docs/ARCHITECTURE.md, "Friction at the holes"):
//!
//! ```text
//! T_{c,s} = T_{c,0} w_{c,s}(Q)                      (w_{c,0} = 1)
//! τ = −Σ_c Σ_s T_{c,s} J_{c,s}ᵀ = −Σ_c T_{c,0} J̃_cᵀ,    J̃_c = Σ_s w_{c,s} J_{c,s}   (m × dof)
//! f_min ≤ T_{c,0} w_{c,s} ≤ f_max  ∀ s   ⇔   f_min / min_s w_{c,s} ≤ T_{c,0} ≤ f_max / max_s w_{c,s}
//! ```
//!
//! So the equilibrium set `T_0 = f_p + N λ`, the policies and the levels of the frictionless
//! statics apply unchanged with `J̃` in place of `J_c` and these actuator limits in place of the
//! cable limits ([`slip_equilibrium_set`]): the unknowns are the actuator tensions `T_{c,0}`.
//!
//! **Dead band.** The anchor carries `T_{c,H−1} = T_{c,0} w_{c,H−1}`. For a given anchor
//! tension `T_a`, the pull distribution needs the actuator at `T_a / w^pull_{H−1}` (the most:
//! `w^pull ≤ 1`), the release distribution at `T_a / w^release_{H−1}` (the least); between the
//! two every hole can stick and the anchor tension does not move ([`dead_band`]):
//!
//! ```text
//! [T₀^release, T₀^pull] = [T_a e^{−μΘ_c}, T_a e^{+μΘ_c}],   Θ_c = Σ_k θ_{c,k}
//! ```
//!
//! (computed as `T_a / Π_k e^{σμθ_k}`, the product in the order of
//! `sinew_routing::compute_capstan_weights`, so that an end of the band reproduces that regime's
//! anchor tension to rounding). At μ = 0 every weight is exactly 1: `J̃ = J_c`, the actuator
//! limits are the cable limits and the dead band is the point `T_a`, all bit for bit.

use std::ops::Range;

use sinew_routing::{FrictionData, FrictionModel};

use crate::equilibrium::EquilibriumSet;
use crate::error::StaticsError;

/// The joint torque of the slip regime whose weights `data` holds
/// ([`sinew_routing::compute_capstan_weights`]): `τ = −Σ_c T_{c,0} J̃_cᵀ` (dof, N m) for the
/// actuator tensions `actuator` (m, N). At μ = 0 it is [`crate::cable_torques`] on `J_c` bit
/// for bit. No allocation.
///
/// # Errors
/// [`StaticsError::Routing`] before the weights; [`StaticsError::DimensionMismatch`].
pub fn slip_torques(
    data: &FrictionData,
    actuator: &[f64],
    tau: &mut [f64],
) -> Result<(), StaticsError> {
    crate::cable_torques(data.effective_jacobian()?, actuator, tau)
}

/// The actuator-tension limits of the slip regime whose weights `data` holds: for each cable,
/// `[f_min / min_s w_s, f_max / max_s w_s]`, the actuator tensions that keep every segment's
/// tension `T_0 w_s` within the cable's limits `segment_limits[c] = [f_min, f_max]` (N), into
/// `out` (m). No allocation.
///
/// # Errors
/// [`StaticsError::DimensionMismatch`]; [`StaticsError::Routing`] before the weights;
/// [`StaticsError::EmptyActuatorInterval`] when no actuator tension keeps every segment within
/// the limits (the capstan ratio along the cable exceeds `f_max / f_min`).
pub fn actuator_limits(
    model: &FrictionModel,
    data: &FrictionData,
    segment_limits: &[[f64; 2]],
    out: &mut [[f64; 2]],
) -> Result<(), StaticsError> {
    let m = model.cable_count();
    sizes(&[
        ("segment tension limits", m, segment_limits.len()),
        ("actuator limits", m, out.len()),
    ])?;
    for (c, (limits, out)) in segment_limits.iter().zip(out.iter_mut()).enumerate() {
        let weights = data.weights(model, c)?;
        let (lo, hi) =
            weights.iter().fold((f64::INFINITY, 0.0_f64), |(lo, hi), &w| (lo.min(w), hi.max(w)));
        let interval = [limits[0] / lo, limits[1] / hi];
        if interval[0] > interval[1] {
            return Err(StaticsError::EmptyActuatorInterval {
                cable: c,
                limits: *limits,
                ratio: hi / lo,
            });
        }
        *out = interval;
    }
    Ok(())
}

/// The dead band of every cable (spec §9): for the anchor tensions `anchor` (m, N), the
/// interval `[T₀^release, T₀^pull]` of actuator tension over which the anchor tension stays
/// `anchor[c]`, into `out` (m, N). Needs the friction geometry only (the wrap angles), not a
/// regime's weights. No allocation.
///
/// # Math
/// `T₀^σ = T_a / Π_{k<H−1} e^{σμθ_k}`: the actuator tension whose slip distribution `σ` has the
/// anchor at `T_a` (module docs).
///
/// # Errors
/// [`StaticsError::DimensionMismatch`]; [`StaticsError::Routing`] before the friction
/// geometry.
pub fn dead_band(
    model: &FrictionModel,
    data: &FrictionData,
    anchor: &[f64],
    out: &mut [[f64; 2]],
) -> Result<(), StaticsError> {
    let m = model.cable_count();
    sizes(&[("anchor tensions", m, anchor.len()), ("dead band", m, out.len())])?;
    let mu = model.friction_coefficients();
    for (c, (&t_a, out)) in anchor.iter().zip(out.iter_mut()).enumerate() {
        let (mut pull, mut release) = (1.0, 1.0);
        for &theta in data.wrap_angles(model, c)? {
            pull *= (-mu[c] * theta).exp();
            release *= (mu[c] * theta).exp();
        }
        *out = [t_a / release, t_a / pull];
    }
    Ok(())
}

/// The equilibrium set of the actuator tensions in the slip regime whose weights `data` holds:
/// [`EquilibriumSet::new`] on `J̃` with the actuator limits of [`actuator_limits`] (the cables'
/// `segment_limits`), under the equilibrium torques `t0`. The tension policies
/// ([`crate::distribute_with_policy`]) then choose actuator tensions; each segment carries
/// `T_0 w_s`. At μ = 0 it equals the frictionless set on `J_c` exactly. Allocates (as
/// [`EquilibriumSet::new`] does).
///
/// # Errors
/// Those of [`actuator_limits`] and [`EquilibriumSet::new`].
pub fn slip_equilibrium_set(
    model: &FrictionModel,
    data: &FrictionData,
    t0: &[f64],
    segment_limits: &[[f64; 2]],
    groups: &[Range<usize>],
) -> Result<EquilibriumSet, StaticsError> {
    let mut limits = vec![[0.0; 2]; model.cable_count()];
    actuator_limits(model, data, segment_limits, &mut limits)?;
    EquilibriumSet::new(data.effective_jacobian()?, t0, &limits, groups)
}

fn sizes(checks: &[(&'static str, usize, usize)]) -> Result<(), StaticsError> {
    for &(what, expected, got) in checks {
        if expected != got {
            return Err(StaticsError::DimensionMismatch { what, expected, got });
        }
    }
    Ok(())
}
