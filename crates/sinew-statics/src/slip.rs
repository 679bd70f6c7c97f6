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

use sinew_routing::{FrictionData, FrictionModel, capstan_factor};

use faer::Mat;
use nalgebra::Vector3;

use crate::actuator_interval::limit_scaling;
use crate::distribution::{CableLayout, distribute_tensions};
use crate::equilibrium::EquilibriumSet;
use crate::error::StaticsError;
use crate::interval::{TensionInterval, TensionLimits};
use crate::refusal::InfeasibleReason;

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
    for (c, (&limits, out)) in segment_limits.iter().zip(out.iter_mut()).enumerate() {
        *out = cable_actuator_limits(model, data, c, limits)?;
    }
    Ok(())
}

/// Cable `c`'s actuator-tension limits in the slip regime whose weights `data` holds,
/// `[f_min / min_s w_s, f_max / max_s w_s]` for its segment limits `limits = [f_min, f_max]`
/// (N): one cable of [`actuator_limits`]. No allocation.
///
/// # Errors
/// [`StaticsError::Routing`] before the weights or for a cable out of range;
/// [`StaticsError::EmptyActuatorInterval`].
pub fn cable_actuator_limits(
    model: &FrictionModel,
    data: &FrictionData,
    c: usize,
    limits: [f64; 2],
) -> Result<[f64; 2], StaticsError> {
    let weights = data.weights(model, c)?;
    let (lo, hi) =
        weights.iter().fold((f64::INFINITY, 0.0_f64), |(lo, hi), &w| (lo.min(w), hi.max(w)));
    let interval = [limits[0] / lo, limits[1] / hi];
    if interval[0] > interval[1] {
        return Err(StaticsError::EmptyActuatorInterval { cable: c, limits, ratio: hi / lo });
    }
    Ok(interval)
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
        // Π_k e^{σμθ_k} = e^{σμ Σ_k θ_k}: two exponentials per cable, not two per hole.
        let wrap: f64 = data.wrap_angles(model, c)?.iter().sum();
        let (pull, release) = (capstan_factor(-mu[c] * wrap), capstan_factor(mu[c] * wrap));
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

/// The actuator tensions of the slip regime whose weights `data` holds at the tension levels
/// `levels` (n, each in `[0, 1]`: 0 the least total tension on the joint's interval, 1 the
/// most), into `out` (m = 3n, N): the levels of [`crate::distribute_tensions`] with `J̃` in
/// place of `J_c` and each cable's actuator limits ([`actuator_limits`]) in place of the common
/// ones. `t0` (2n) are the equilibrium torques. At μ = 0 the answer is the frictionless one to
/// rounding. Allocates (a scaled copy of `J̃`).
///
/// # Math
/// The cables' actuator intervals `[a_c, b_c]` differ, the closed form's limits are common:
/// the closed form on the scaled `(J̃ D, t0 + J̃ᵀ β)` with the limits `[f_min, f_max]` gives
/// `g`, and `T_c = α_c g_c + β_c` (the map of [`crate::ActuatorInterval`]). An affine map keeps a segment's ends and its fractions, so
/// level `s` of `g`'s interval is level `s` of `T`'s, up to the direction: the closed form
/// orients a joint's null direction `n` by `Σ n ≥ 0`; where `Σ α n < 0` (no force closure) the
/// level is mirrored, `1 − s`, so that level 0 stays the least total actuator tension.
///
/// # Errors
/// Those of [`actuator_limits`] and [`crate::distribute_tensions`]; an
/// [`StaticsError::Infeasible`] names the joint, the torque its own cables must hold and the
/// widest of their actuator limits (a fixed tension is an actuator tension; the `λ` of
/// [`crate::InfeasibleReason::OutsideLimits`] are those of the scaled problem).
pub fn slip_levels(
    model: &FrictionModel,
    data: &FrictionData,
    (layout, limits): (&CableLayout, TensionLimits),
    segment_limits: &[[f64; 2]],
    t0: &[f64],
    levels: &[f64],
    out: &mut [f64],
) -> Result<(), StaticsError> {
    let m = model.cable_count();
    sizes(&[("actuator tensions", m, out.len())])?;
    let mut actuator = vec![[0.0; 2]; m];
    actuator_limits(model, data, segment_limits, &mut actuator)?;
    let j_tilde = data.effective_jacobian()?;
    let dof = j_tilde.ncols();
    sizes(&[("equilibrium torques T0", dof, t0.len())])?;
    let (alpha, beta): (Vec<f64>, Vec<f64>) =
        actuator.iter().map(|&a| limit_scaling(a, limits)).unzip();
    // `J̃ diag(α)` and `T0 + J̃ᵀ β`, column by column (J̃'s columns are contiguous).
    let mut scaled = Mat::<f64>::zeros(m, dof);
    let mut shifted = t0.to_vec();
    for (k, shift) in shifted.iter_mut().enumerate() {
        let column = j_tilde.col(k);
        for ((out, j), a) in scaled.col_mut(k).iter_mut().zip(column.iter()).zip(&alpha) {
            *out = j * a;
        }
        *shift += column.iter().zip(&beta).map(|(j, b)| j * b).sum::<f64>();
    }
    // Level 0 is the least total of `T`, not of `g`: where the joint's null direction in `g`
    // (oriented to a non-negative sum, as the closed form does) has a negative sum once scaled
    // by `α`, its interval runs the other way in `T`, and the level is mirrored.
    let mut mirrored = Vec::with_capacity(levels.len());
    for (i, &level) in levels.iter().enumerate() {
        if !(0.0..=1.0).contains(&level) {
            return Err(StaticsError::InvalidLevel { joint: i, level });
        }
        let rows = 3 * i..(3 * i + 3).min(m);
        let column = |k: usize| {
            let mut v = Vector3::zeros();
            for (r, c) in rows.clone().enumerate() {
                if 2 * i + k < dof {
                    v[r] = scaled[(c, 2 * i + k)];
                }
            }
            v
        };
        let mut null = column(0).cross(&column(1));
        if null.sum() < 0.0 {
            null = -null;
        }
        let in_t: f64 = rows.clone().enumerate().map(|(r, c)| alpha[c] * null[r]).sum();
        mirrored.push(if in_t < 0.0 { 1.0 - level } else { level });
    }
    let mut intervals = vec![empty_interval(limits); layout.joints()];
    let solved = distribute_tensions(
        layout,
        scaled.as_ref(),
        limits,
        &shifted,
        &mirrored,
        &mut intervals,
        out,
    );
    if let Err(StaticsError::Infeasible { joint, torque, reason, .. }) = solved {
        let own = 3 * joint..(3 * joint + 3).min(m);
        let correction =
            |k: usize| own.clone().map(|c| j_tilde[(c, 2 * joint + k)] * beta[c]).sum::<f64>();
        let reason = match reason {
            InfeasibleReason::FixedTension { cable, tension } => {
                let c = 3 * joint + cable;
                InfeasibleReason::FixedTension { cable, tension: alpha[c] * tension + beta[c] }
            }
            reason => reason,
        };
        let widest = own.clone().fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], c| {
            [lo.min(actuator[c][0]), hi.max(actuator[c][1])]
        });
        return Err(StaticsError::Infeasible {
            joint,
            torque: [torque[0] - correction(0), torque[1] - correction(1)],
            limits: widest,
            reason,
        });
    }
    solved?;
    for ((t, (a, b)), [lo, hi]) in out.iter_mut().zip(alpha.iter().zip(&beta)).zip(&actuator) {
        *t = (a * *t + b).clamp(*lo, *hi);
    }
    Ok(())
}

/// A placeholder interval for [`slip_levels`]' scratch (overwritten by the closed form).
fn empty_interval(limits: TensionLimits) -> TensionInterval {
    TensionInterval {
        joint: 0,
        particular: Vector3::zeros(),
        null: Vector3::zeros(),
        lambda_min: 0.0,
        lambda_max: 0.0,
        limits,
        limiting: [0, 0],
    }
}

fn sizes(checks: &[(&'static str, usize, usize)]) -> Result<(), StaticsError> {
    for &(what, expected, got) in checks {
        if expected != got {
            return Err(StaticsError::DimensionMismatch { what, expected, got });
        }
    }
    Ok(())
}
