//! The slip regimes' joint stiffness (spec §9, #27): every hole slides the same way, the pieces
//! of each cable in series, their tensions tied by the capstan ratio.
//!
//! # Derivation
//! Cable `c` (index dropped), friction segments `s = 0 … H−1`, segment 0 the free length
//! (`ℓ_0 = ℓ_free`, `J_0 = 0`); weights `w_s(Q)` of the regime (`w_0 = 1`), their gradients
//! `∇w_s = ∂w_s/∂Q` (`sinew_routing::compute_capstan_weights`). The segment tensions are
//! `T_s = T_0 w_s(Q)` and the torque is `τ = −T_0 J̃ᵀ`, `J̃ = Σ_s w_s J_s`.
//!
//! *Elasticity (the one model of every regime).* Each piece is a spring of compliance
//! `c_s = ℓ_s / (E A)` (`ℓ_s` at the pose; the free length's with the actuator held). Every
//! hole slides, so material flows between the pieces and only the cable's total material is
//! fixed: an increment `δQ` changes the pieces' lengths by `δℓ_s = J_s δQ` (`δℓ_0 = 0`) and
//! their material by `δλ_s` with `Σ_s δλ_s = 0`, while each piece's stretch follows its
//! tension, `δℓ_s − δλ_s = c_s δT_s`. Summed over the pieces:
//!
//! ```text
//! J_c δQ = Σ_s c_s δT_s = Σ_s c_s (w_s δT_0 + T_0 ∇w_s δQ)          (J_c = Σ_s J_s)
//! ⇒  ∂T_0/∂Q = (J_c − T_0 g) / C̃,     C̃ = Σ_s c_s w_s,   g = Σ_s c_s ∇w_s   (rows, 1 × dof)
//! ```
//!
//! *Stiffness.* `K = −∂τ/∂Q = J̃ᵀ ∂T_0/∂Q + T_0 ∂J̃ᵀ/∂Q`, with
//! `∂J̃ᵀ/∂Q = Σ_s (w_s H_s + J_sᵀ ∇w_s)` (entry `(i, j)`: `∂J̃_i/∂q_j`). Summed over the
//! cables and split as the frictionless `K` is:
//!
//! ```text
//! K_slip = Σ_c T_0 [ Σ_s w_s H_s + Σ_s J_sᵀ ∇w_s − J̃ᵀ g / C̃ ]   +   Σ_c J̃ᵀ J_c / C̃
//!                         (controllable: ∝ T_0)                       (inherent)
//! ```
//!
//! *Computed from the anchor back, no row `∇w_s` stored.* With `∇w_s = σμ w_s Σ_{k<s} ∇θ_k`
//! (`σμ` the regime's rate), both sums over the moving weights are sums over the holes, each
//! with a running sum of the segments beyond it:
//!
//! ```text
//! T_0 Σ_s J_sᵀ ∇w_s = Σ_k G_k ∇θ_k,   G_k = σμ T_0 Σ_{s>k} w_s J_sᵀ     (a dof column)
//! g = Σ_s c_s ∇w_s   = σμ Σ_k S_k ∇θ_k,   S_k = Σ_{s>k} c_s w_s
//! ```
//!
//! One pass from the anchor to the first hole adds each `w_s J_s` to `G` and each `c_s w_s` to
//! `S`; each hole then adds `∂θ_k/∂q_j G_k` to column `j` of `K` (contiguous) for the few DOFs
//! `j` its wrap angle depends on. Cost `O(Σ_k |wrap dofs_k| · |reach of G_k|)`.
//!
//! It is not symmetric (`J̃ ≠ J_c`, and the weights move with `Q`): the workspace reports its
//! symmetric part and the norm of its skew part. It is the stiffness for motions that keep
//! every hole sliding the same way, with the slip direction held (the weights stay those of
//! the regime); a motion that reverses a hole's slip makes it stick (spec §9's directional
//! response). At a kinked hole (`θ ≈ 0`, `sinew_routing::WRAP_KINK`) `∇θ = 0` is used (the
//! least-norm subgradient), so there `K` is one element of a set, not a derivative.
//!
//! *μ → 0⁺.* Then `w_s → 1`, `∇w_s → 0`, `J̃ → J_c`, `C̃ → (ℓ_free + L_c(Q))/(E A)`, and
//! `K_slip → Σ_c T_0 H_c + J_cᵀ E A/(ℓ_free + L_c(Q)) J_c`: eq. 14 with eq. 13's `k_c` taken at
//! the pose instead of at `Q0`. The two differ by
//! `k_c (L_c(Q0) − L_c(Q)) / (ℓ_free + L_c(Q))` relative to `k_c`: millimetres against metres on
//! cdhrm5. **At μ = 0 exactly** a cable takes today's path, eq. 13's `k_c`
//! (`sinew_routing::Cable::stiffness`), summed in today's order: with every μ = 0 the result is
//! [`crate::joint_stiffness`]'s bit for bit.

use faer::linalg::matmul::matmul;
use faer::{Accum, MatRef, Par};
use sinew_routing::{CableRows, FrictionData, FrictionModel, Routing, RoutingData, Slip};

use crate::colmajor::ColMajor;
use crate::error::StiffnessError;
use crate::friction::{
    FrictionRegime, FrictionStiffnessData, add_segment_hessians, axial_rigidity, check_weights,
};

/// The joint stiffness of the slip regime `slip` at the actuator tensions `actuator` (m, N),
/// with the slip direction held, into `out` ([`FrictionStiffnessData::stiffness`], its two
/// parts, its symmetric part and the norm of its skew part).
///
/// Needs the cable geometry with Hessians (`geometry`), and the friction geometry and the
/// capstan weights of `slip` at the same `Q` in `friction`. No allocation.
///
/// # Math
/// Module docs of `slip.rs` (the derivation):
/// `K_slip = Σ_c T_0 [Σ_s w_s H_s + Σ_s J_sᵀ ∇w_s − J̃ᵀ g / C̃] + Σ_c J̃ᵀ J_c / C̃`, with
/// `c_s = ℓ_s/(E A)`, `C̃ = Σ_s c_s w_s`, `g = Σ_s c_s ∇w_s`; a cable with μ = 0 takes today's
/// `T_0 H_c + k_c J_cᵀ J_c` (eq. 13–14). Cost `O(Σ_c Σ_s |dofs_s|² + Σ_c |dofs_c|²)`.
///
/// # Errors
/// [`StiffnessError::WrongCapstanWeights`] when `friction` holds the other regime's weights or
/// none; [`StiffnessError::DimensionMismatch`]; routing errors (among them
/// `FrictionNotComputed` for a geometry without its wrap gradients,
/// `sinew_routing::compute_friction_angles` alone).
pub fn slip_stiffness(
    model: &FrictionModel,
    routing: &Routing,
    geometry: &RoutingData,
    friction: &FrictionData,
    slip: Slip,
    actuator: &[f64],
    out: &mut FrictionStiffnessData,
) -> Result<(), StiffnessError> {
    out.start(model, routing, actuator)?;
    check_weights(friction, slip)?;
    let mu = model.friction_coefficients();
    let j_c = geometry.jacobian()?;
    // Pass 1, every cable: Σ_s T_0 w_s H_s (w_s = 1 exactly at μ = 0: today's Σ f_c H_c in its
    // order); the μ = 0 cables' k_c J_cᵀ J_c on and above the diagonal, then mirrored.
    let weight = |cable: &CableRows<'_>, s: usize| cable.weights.map_or(1.0, |w| w[s]);
    add_segment_hessians((model, routing, geometry), friction, actuator, weight, out)?;
    // The μ = 0 cables' k_c J_cᵀ J_c on and above the diagonal (eq. 13–14), mirrored below.
    for (c, cable) in routing.cables().iter().enumerate().filter(|&(c, _)| mu[c] == 0.0) {
        let k = cable.stiffness;
        for j in cable.dofs.clone() {
            let kj = k * j_c[(c, j)];
            for i in cable.dofs.start..=j {
                *out.inherent.at_mut(i, j) += kj * j_c[(c, i)];
            }
        }
    }
    out.mirror_inherent();
    // Pass 2, the cables with friction: the pieces in series. Per cable, the rows `J_c / C̃`
    // and `T_0 g / C̃` of two m × dof matrices, and `T_0 Σ_s J_sᵀ ∇w_s` straight into `K`
    // (module docs: one pass from the anchor back, with the running sums `S_k` and `G_k`);
    // then `J̃ᵀ` times each matrix (faer's product: the cables' rank-one terms summed at once).
    if mu.iter().all(|&mu| mu == 0.0) {
        out.finish(FrictionRegime::Slip(slip));
        return Ok(());
    }
    let ea = axial_rigidity(routing);
    let j_tilde = friction.effective_jacobian()?;
    out.series_elastic.as_mut_slice().fill(0.0);
    out.moving_series_t.as_mut_slice().fill(0.0);
    let n = out.dof;
    let FrictionStiffnessData { controllable, series_elastic, moving_series_t, suffix, .. } = out;
    suffix.fill(0.0);
    // Compiled with the processor's widest vectors (pulp's dispatch around the whole pass):
    // the columns' updates `K[lo..hi, j] += ∂θ_k/∂q_j G_k` are most of a slip stiffness.
    pulp::Arch::new().dispatch(SeriesPass {
        parts: (model, routing, friction, j_c),
        regime: (slip, ea, n),
        actuator,
        out: (controllable, series_elastic, moving_series_t, suffix),
    })?;
    let (elastic, moving) = (out.series_elastic.as_ref(), out.moving_series_t.as_ref().transpose());
    let (inherent, controllable) = (out.inherent.as_mut(), out.controllable.as_mut());
    matmul(inherent, Accum::Add, j_tilde.transpose(), elastic, 1.0, Par::Seq);
    matmul(controllable, Accum::Add, j_tilde.transpose(), moving, -1.0, Par::Seq);
    out.finish(FrictionRegime::Slip(slip));
    Ok(())
}

/// The arguments of pass 2 of [`slip_stiffness`] as a pulp operation.
struct SeriesPass<'a> {
    parts: (&'a FrictionModel, &'a Routing, &'a FrictionData, MatRef<'a, f64>),
    regime: (Slip, f64, usize),
    actuator: &'a [f64],
    out: (&'a mut ColMajor, &'a mut ColMajor, &'a mut ColMajor, &'a mut [f64]),
}

impl pulp::WithSimd for SeriesPass<'_> {
    type Output = Result<(), StiffnessError>;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> Self::Output {
        let SeriesPass { parts: (model, routing, friction, j_c), regime, actuator, out } = self;
        let (slip, ea, n) = regime;
        let (controllable, series_elastic, moving_series_t, suffix) = out;
        let mu = model.friction_coefficients();
        for (c, &t_0) in actuator.iter().enumerate() {
            if mu[c] == 0.0 {
                continue;
            }
            let cable = friction.cable(model, c)?;
            let Some(weights) = cable.weights else {
                return Err(StiffnessError::WrongCapstanWeights { needs: slip, computed: None });
            };
            let rate = slip.sign() * mu[c];
            // C̃ = Σ_s c_s w_s, c_s = ℓ_s / (E A), in segment order.
            let series: f64 = cable.lengths.iter().zip(weights).map(|(l, w)| l / ea * w).sum();
            // From the anchor back: before hole k, S_k = Σ_{s>k} c_s w_s and
            // G_k = σμ T_0 Σ_{s>k} w_s J_s (dense over `lo..hi`); then
            // g += σμ S_k ∇θ_k and column j of K += ∂θ_k/∂q_j G_k.
            let g = moving_series_t.col_mut(c);
            let (mut s_k, mut lo, mut hi, mut g_lo, mut g_hi) = (0.0, n, 0, n, 0);
            for k in (0..cable.len().saturating_sub(1)).rev() {
                let s = k + 1;
                s_k += cable.lengths[s] / ea * weights[s];
                let j_s = cable.jacobian(s);
                if !j_s.dofs.is_empty() {
                    let a = rate * t_0 * weights[s];
                    for (o, v) in suffix[j_s.dofs.clone()].iter_mut().zip(j_s.values) {
                        *o += a * v;
                    }
                    (lo, hi) = (lo.min(j_s.dofs.start), hi.max(j_s.dofs.end));
                }
                let theta = cable.wrap_gradient(k)?;
                if theta.dofs.is_empty() {
                    continue;
                }
                (g_lo, g_hi) = (g_lo.min(theta.dofs.start), g_hi.max(theta.dofs.end));
                let rate_s = rate * s_k;
                for (j, &d) in theta.dofs.clone().zip(theta.values) {
                    g[j] += rate_s * d;
                    if lo < hi {
                        let column = &mut controllable.col_mut(j)[lo..hi];
                        for (o, gk) in column.iter_mut().zip(&suffix[lo..hi]) {
                            *o += d * gk;
                        }
                    }
                }
            }
            if lo < hi {
                suffix[lo..hi].fill(0.0);
            }
            if g_lo < g_hi {
                for v in &mut g[g_lo..g_hi] {
                    *v *= t_0 / series;
                }
            }
            // The rows of J̃ᵀ (J_c − T_0 g) / C̃, split into its two parts.
            for j in routing.cables()[c].dofs.clone() {
                *series_elastic.at_mut(c, j) = j_c[(c, j)] / series;
            }
        }
        Ok(())
    }
}
