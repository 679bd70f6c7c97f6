//! The feasible tension interval of one 3-cable, 2-DOF joint, in closed form (eq. 22–23).
//!
//! # Math
//! The joint's cables hold a torque `τ` (2) when `τ + J_cᵀ f = 0` (eq. 23, `P`), with `J_c`
//! the 3 × 2 block of the cable Jacobian (rows: the joint's cables, columns: its two DOF).
//! `P` is the line `f = f_p + λ n` with
//!
//! ```text
//! f_p = −J_c (J_cᵀ J_c)⁻¹ τ          (the minimum-norm solution)
//! n   = J_c[:,0] × J_c[:,1] / |…|    (spans null(J_cᵀ), oriented so that n > 0)
//! ```
//!
//! `n` is oriented so that its components sum to `≥ 0`: the total tension then rises with `λ`,
//! and `λ_min` is the end of least total tension (level `s = 0`), `λ_max` that of most
//! (`s = 1`). `Ω ∩ P` (eq. 22) is the interval of `λ` where every cable is within its limits:
//! cable `k` bounds `λ` from below by `(f_min − f_p,k)/n_k` when `n_k > 0` (by
//! `(f_max − f_p,k)/n_k` when `n_k < 0`) and from above by the other limit.
//!
//! The cables are in *force closure* when `n` is strictly positive: every tension rises with
//! `λ`, so any torque is held with tensions high enough. Force closure is a property of the
//! pose and the routing, reported ([`TensionInterval::force_closure`]), not required: without
//! it the interval may still be non-empty (a cable with `n_k < 0` slackens as the others
//! tighten), and a cable with `n_k = 0` keeps the tension `f_p,k` whatever `λ`.

use faer::MatRef;
use nalgebra::{Matrix3x2, Vector2, Vector3};

use crate::error::StaticsError;
use crate::refusal::InfeasibleReason;

/// A component of the (unit) null direction below this in magnitude counts as zero: that cable's
/// tension cannot be changed without losing balance, and the joint is not in force closure.
pub const FORCE_CLOSURE_TOLERANCE: f64 = 1e-9;

/// `det(J_cᵀ J_c)` below this fraction of `(trace)²` counts as a rank-deficient cable Jacobian.
pub const JOINT_RANK_TOLERANCE: f64 = 1e-12;

/// Tension limits of a joint's cables, N.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TensionLimits {
    /// Least tension, N (cables must stay taut).
    pub f_min: f64,
    /// Greatest tension, N.
    pub f_max: f64,
}

/// The feasible set `Λ = Ω ∩ P` of one joint: `f(λ) = f_p + λ n`, `λ ∈ [λ_min, λ_max]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TensionInterval {
    /// Universal joint index (0-based).
    pub joint: usize,
    /// The minimum-norm tensions that hold the torque, `f_p` (N; may lie outside the limits).
    pub particular: Vector3<f64>,
    /// Unit null direction of `J_cᵀ`, its components summing to `≥ 0` (every component
    /// positive when the joint is in force closure).
    pub null: Vector3<f64>,
    /// Lower end of the interval (least total tension).
    pub lambda_min: f64,
    /// Upper end of the interval (most total tension).
    pub lambda_max: f64,
    /// The tension limits the interval was clipped to.
    pub limits: TensionLimits,
    /// The cable (0, 1 or 2) on a limit at `λ_min`, and the one on a limit at `λ_max`: at the
    /// ends they are set exactly on it ([`TensionInterval::tensions`]). In force closure these
    /// are `f_min` at `λ_min` and `f_max` at `λ_max`; a cable with `n_k < 0` meets the other
    /// limit.
    pub limiting: [usize; 2],
}

impl TensionInterval {
    /// Tensions at a point `λ` of the line `P`, N. Inside the interval every tension is within
    /// `[f_min, f_max]` exactly (a tension off its limit by rounding only is put on it), and at
    /// `λ_min` (`λ_max`) the limiting cable is exactly at `f_min` (`f_max`).
    pub fn tensions(&self, lambda: f64) -> Vector3<f64> {
        let mut f = self.particular + lambda * self.null;
        let TensionLimits { f_min, f_max } = self.limits;
        if (self.lambda_min..=self.lambda_max).contains(&lambda) {
            for v in f.iter_mut() {
                *v = v.clamp(f_min, f_max);
            }
            if lambda == self.lambda_min {
                let k = self.limiting[0].min(2);
                f[k] = if self.null[k] > 0.0 { f_min } else { f_max };
            }
            if lambda == self.lambda_max {
                let k = self.limiting[1].min(2);
                f[k] = if self.null[k] > 0.0 { f_max } else { f_min };
            }
        }
        f
    }

    /// Whether the joint's cables are in force closure: the null direction strictly positive
    /// (above [`FORCE_CLOSURE_TOLERANCE`]), so every tension rises with `λ`.
    pub fn force_closure(&self) -> bool {
        self.null.min() > FORCE_CLOSURE_TOLERANCE
    }

    /// `λ` at tension level `s ∈ [0, 1]` (0: least total tension, 1: most; both ends exactly).
    pub fn lambda_at_level(&self, s: f64) -> f64 {
        if s == 1.0 {
            self.lambda_max
        } else {
            self.lambda_min + s * (self.lambda_max - self.lambda_min)
        }
    }

    /// Tensions at tension level `s ∈ [0, 1]`, N.
    pub fn tensions_at_level(&self, s: f64) -> Vector3<f64> {
        self.tensions(self.lambda_at_level(s))
    }

    /// Tensions at both ends, `(at λ_min, at λ_max)`, N.
    pub fn ends(&self) -> (Vector3<f64>, Vector3<f64>) {
        (self.tensions(self.lambda_min), self.tensions(self.lambda_max))
    }

    /// Width of the interval, `λ_max − λ_min` (≥ 0).
    pub fn width(&self) -> f64 {
        self.lambda_max - self.lambda_min
    }
}

/// Joint `joint`'s 3 × 2 block of the cable Jacobian `jacobian` (3n × 2n, three cables per
/// universal joint in joint order): rows `3 joint..3 joint + 3` (its cables), columns
/// `2 joint..2 joint + 2` (its two DOF), the `jacobian` argument of [`tension_interval`] and
/// [`minimum_norm_tensions`].
///
/// # Panics
/// When the block is outside `jacobian` (the callers have checked its shape).
#[inline]
pub(crate) fn joint_block(jacobian: MatRef<'_, f64>, joint: usize) -> Matrix3x2<f64> {
    Matrix3x2::from_fn(|r, k| jacobian[(3 * joint + r, 2 * joint + k)])
}

/// `f_p = −J_c (J_cᵀ J_c)⁻¹ τ`: the minimum-norm tensions with `τ + J_cᵀ f_p = 0` (eq. 23),
/// `None` when the 3 × 2 block has rank < 2 (see [`JOINT_RANK_TOLERANCE`]).
pub fn minimum_norm_tensions(
    jacobian: &Matrix3x2<f64>,
    tau: &Vector2<f64>,
) -> Option<Vector3<f64>> {
    let jtj = jacobian.transpose() * jacobian;
    let det = jtj[(0, 0)] * jtj[(1, 1)] - jtj[(0, 1)] * jtj[(1, 0)];
    let trace = jtj[(0, 0)] + jtj[(1, 1)];
    // Written so that a NaN determinant also counts as rank-deficient.
    let full_rank = det > JOINT_RANK_TOLERANCE * trace * trace;
    if !full_rank {
        return None;
    }
    // (JᵀJ)⁻¹ τ by the 2 × 2 adjugate.
    let y = Vector2::new(
        jtj[(1, 1)] * tau[0] - jtj[(0, 1)] * tau[1],
        -jtj[(1, 0)] * tau[0] + jtj[(0, 0)] * tau[1],
    ) / det;
    Some(-(jacobian * y))
}

/// The feasible tension interval of joint `joint` for the torque `tau` (eq. 22–23).
///
/// `jacobian` is the joint's 3 × 2 block of `J_c` (rows: its cables, columns: its two DOF);
/// `tau` the torque its cables must hold (`τ = −J_cᵀ f`). `O(1)`, no allocation.
///
/// # Errors
/// [`StaticsError::Infeasible`] naming the joint and the reason: a rank-deficient `J_c`, a
/// cable whose tension is fixed outside its limits, or a torque that no tensions within the
/// limits hold. Lost force closure alone is not an error ([`TensionInterval::force_closure`]).
pub fn tension_interval(
    joint: usize,
    jacobian: &Matrix3x2<f64>,
    tau: &Vector2<f64>,
    limits: TensionLimits,
) -> Result<TensionInterval, StaticsError> {
    let infeasible = |reason| StaticsError::Infeasible {
        joint,
        torque: [tau[0], tau[1]],
        limits: [limits.f_min, limits.f_max],
        reason,
    };
    if !(tau[0].is_finite() && tau[1].is_finite()) {
        return Err(StaticsError::NonFiniteTorque { joint, torque: [tau[0], tau[1]] });
    }
    let Some(particular) = minimum_norm_tensions(jacobian, tau) else {
        return Err(infeasible(InfeasibleReason::RankDeficient));
    };
    let c0: Vector3<f64> = jacobian.column(0).into_owned();
    let c1: Vector3<f64> = jacobian.column(1).into_owned();
    let mut null = c0.cross(&c1);
    null /= null.norm();
    if null.sum() < 0.0 {
        null = -null;
    }
    let mut lambda_min = f64::NEG_INFINITY;
    let mut lambda_max = f64::INFINITY;
    let mut limiting = [0, 0];
    // Where each cable reaches each limit along the null space: all six quotients at once (the
    // divisions side by side, in vector instructions), then chosen by the sign of `null[k]`.
    let at_min: [f64; 3] = std::array::from_fn(|k| (limits.f_min - particular[k]) / null[k]);
    let at_max: [f64; 3] = std::array::from_fn(|k| (limits.f_max - particular[k]) / null[k]);
    for k in 0..3 {
        if null[k].abs() <= FORCE_CLOSURE_TOLERANCE {
            // The tension of cable k is f_p,k whatever λ: it must be within the limits.
            if !(limits.f_min..=limits.f_max).contains(&particular[k]) {
                let tension = particular[k];
                return Err(infeasible(InfeasibleReason::FixedTension { cable: k, tension }));
            }
            continue;
        }
        let (lo, hi) = if null[k] > 0.0 { (at_min[k], at_max[k]) } else { (at_max[k], at_min[k]) };
        if lo > lambda_min {
            (lambda_min, limiting[0]) = (lo, k);
        }
        if hi < lambda_max {
            (lambda_max, limiting[1]) = (hi, k);
        }
    }
    if lambda_min > lambda_max {
        return Err(infeasible(InfeasibleReason::OutsideLimits { lambda_min, lambda_max }));
    }
    Ok(TensionInterval { joint, particular, null, lambda_min, lambda_max, limits, limiting })
}
