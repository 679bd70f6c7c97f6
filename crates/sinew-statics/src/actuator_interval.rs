//! One joint's interval of actuator tensions when its cables' limits differ (spec §9, #27): in
//! a slip distribution (or a stick one left by it) each cable's actuator tension must keep every
//! segment within the cable's limits, so each cable has limits of its own
//! ([`crate::actuator_limits`]), where the closed form (eq. 22–23) takes common ones.

use nalgebra::{Matrix3x2, Vector2, Vector3};

use crate::error::StaticsError;
use crate::interval::{TensionInterval, TensionLimits, tension_interval};
use crate::refusal::InfeasibleReason;

/// The affine map `T = α g + β` from the common limits `limits` onto the actuator limits
/// `actuator = [a, b]` ([`ActuatorInterval`]): `(α, β)`.
pub(crate) fn limit_scaling(actuator: [f64; 2], limits: TensionLimits) -> (f64, f64) {
    let alpha = (actuator[1] - actuator[0]) / (limits.f_max - limits.f_min);
    (alpha, actuator[0] - alpha * limits.f_min)
}

/// One joint's feasible actuator tensions for cables with limits of their own:
/// `T(λ) = α ∘ g(λ) + β` over the scaled closed form's interval.
///
/// # Math
/// Cable `c` of the joint, actuator limits `[a_c, b_c]`, common limits `[f_min, f_max]`. With
///
/// ```text
/// T_c = α_c g_c + β_c,   α_c = (b_c − a_c)/(f_max − f_min),   β_c = a_c − α_c f_min
/// ```
///
/// `T_c ∈ [a_c, b_c] ⇔ g_c ∈ [f_min, f_max]`, and `τ + J̃ᵀ T = 0 ⇔ τ' + (J̃ D)ᵀ g = 0` with
/// `D = diag α`, `τ' = τ + J̃ᵀ β`: the closed form on `(J̃ D, τ')` with the common limits gives
/// the interval of `g`, and `T = α ∘ g + β` maps it onto the actuator tensions (an affine map
/// keeps a segment's ends). When `Σ α_c n_c < 0` (`n` the scaled null direction, oriented by
/// `Σ n ≥ 0`) the total actuator tension falls along `λ`, and the ends swap. With every
/// `[a_c, b_c] = [f_min, f_max]` (μ = 0) `α = 1`, `β = 0` and everything is the closed form's
/// bit for bit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActuatorInterval {
    /// The interval of the normalised tensions `g ∈ [f_min, f_max]` (eq. 22–23 on `J̃ D` with
    /// the common limits).
    pub scaled: TensionInterval,
    /// `α_c`, the scale of each cable's map (≥ 0).
    pub alpha: Vector3<f64>,
    /// `β_c`, the offset of each cable's map, N.
    pub beta: Vector3<f64>,
    /// The cables' actuator limits `[a_c, b_c]`, N.
    pub limits: [[f64; 2]; 3],
}

impl ActuatorInterval {
    /// The actuator tensions at `λ` of the scaled interval, N: `α ∘ g(λ) + β`, within each
    /// cable's actuator limits (a tension off them by rounding only is put on them).
    pub fn tensions(&self, lambda: f64) -> Vector3<f64> {
        let g = self.scaled.tensions(lambda);
        Vector3::from_fn(|c, _| {
            let [lo, hi] = self.limits[c];
            (self.alpha[c] * g[c] + self.beta[c]).clamp(lo, hi)
        })
    }

    /// The actuator tensions at the least and at the most total actuator tension, N: the
    /// scaled interval's ends, swapped when the total falls along `λ` (`Σ α_c n_c < 0`).
    pub fn ends(&self) -> (Vector3<f64>, Vector3<f64>) {
        let (low, high) =
            (self.tensions(self.scaled.lambda_min), self.tensions(self.scaled.lambda_max));
        if self.alpha.dot(&self.scaled.null) < 0.0 { (high, low) } else { (low, high) }
    }
}

/// The feasible actuator tensions of joint `joint` holding the torque `tau` (`τ = −J̃ᵀ T`) with
/// its 3 × 2 block `block` of the effective cable Jacobian `J̃` (rows: its cables, the first of
/// them `first_cable` in the routing) and their actuator limits `actuator`
/// ([`crate::actuator_limits`]; [`ActuatorInterval`]). `limits` are the cables' own (segment) limits, the
/// common limits of the normalised tensions. `O(1)`, no allocation.
///
/// # Errors
/// Those of [`tension_interval`], with the torque the caller asked for, the widest of the
/// cables' actuator limits, and a fixed tension as an actuator tension;
/// [`StaticsError::EmptyActuatorInterval`] when a cable's actuator limits are empty or not
/// finite (its ratio that of actuator limits from [`crate::actuator_limits`] with `limits`).
pub fn actuator_interval(
    (joint, first_cable): (usize, usize),
    block: &Matrix3x2<f64>,
    tau: &Vector2<f64>,
    limits: TensionLimits,
    actuator: [[f64; 2]; 3],
) -> Result<ActuatorInterval, StaticsError> {
    let mut alpha = Vector3::zeros();
    let mut beta = Vector3::zeros();
    for (c, [lo, hi]) in actuator.into_iter().enumerate() {
        if !(lo <= hi && lo.is_finite() && hi.is_finite()) {
            return Err(StaticsError::EmptyActuatorInterval {
                cable: first_cable + c,
                limits: [limits.f_min, limits.f_max],
                ratio: (lo / hi) * (limits.f_max / limits.f_min),
            });
        }
        (alpha[c], beta[c]) = limit_scaling([lo, hi], limits);
    }
    let scaled_block = Matrix3x2::from_fn(|r, k| block[(r, k)] * alpha[r]);
    let shifted = tau + block.transpose() * beta;
    let scaled = tension_interval(joint, &scaled_block, &shifted, limits).map_err(|e| match e {
        StaticsError::Infeasible { joint, reason, .. } => {
            let reason = match reason {
                InfeasibleReason::FixedTension { cable, tension } => {
                    let t = alpha[cable.min(2)] * tension + beta[cable.min(2)];
                    InfeasibleReason::FixedTension { cable, tension: t }
                }
                reason => reason,
            };
            let widest = actuator.iter().fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], l| {
                [lo.min(l[0]), hi.max(l[1])]
            });
            StaticsError::Infeasible { joint, torque: [tau[0], tau[1]], limits: widest, reason }
        }
        e => e,
    })?;
    Ok(ActuatorInterval { scaled, alpha, beta, limits: actuator })
}
