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
use faer::{Accum, Par};
use sinew_routing::{FrictionData, FrictionModel, Routing, RoutingData, Slip};

use crate::error::StiffnessError;
use crate::friction::{
    FrictionRegime, FrictionStiffnessData, add_segment_hessian, axial_rigidity, check_weights,
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
/// none; [`StiffnessError::DimensionMismatch`]; routing errors.
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
    let hessians = (routing, &geometry.segment_hessians(routing)?);
    for (c, &t_0) in actuator.iter().enumerate() {
        for segment in friction.segments(model, c)?.skip(1) {
            let w = segment.weight.unwrap_or(1.0);
            add_segment_hessian(hessians, &segment, t_0 * w, &mut out.controllable)?;
        }
        if mu[c] == 0.0 {
            let cable = &routing.cables()[c];
            let k = cable.stiffness;
            for j in cable.dofs.clone() {
                let kj = k * j_c[(c, j)];
                for i in cable.dofs.start..=j {
                    *out.inherent.at_mut(i, j) += kj * j_c[(c, i)];
                }
            }
        }
    }
    out.mirror_inherent();
    // Pass 2, the cables with friction: the pieces in series. Per cable, the rows
    // `J_c / C̃` and `T_0 g / C̃` of two m × dof matrices, and `T_0 Σ_s J_sᵀ ∇w_s` transposed
    // (each `∇w_s` a contiguous row: one axpy per DOF of `J_s`); then `J̃ᵀ` times each matrix
    // (faer's product: the cables' rank-one terms `J̃_cᵀ (…)` summed at once).
    if mu.iter().all(|&mu| mu == 0.0) {
        out.finish(FrictionRegime::Slip(slip));
        return Ok(());
    }
    let ea = axial_rigidity(routing);
    let j_tilde = friction.effective_jacobian()?;
    out.series_elastic.as_mut_slice().fill(0.0);
    out.moving_series_t.as_mut_slice().fill(0.0);
    out.moving_transposed.as_mut_slice().fill(0.0);
    for (c, &t_0) in actuator.iter().enumerate() {
        if mu[c] == 0.0 {
            continue;
        }
        // g = Σ_s c_s ∇w_s accumulates in column c of the transposed scratch (contiguous).
        let (mut series, mut reach) = (0.0, 0..0);
        for segment in friction.segments(model, c)? {
            let (Some(w), Some(grad_w)) = (segment.weight, segment.weight_gradient) else {
                let computed = friction.slip();
                return Err(StiffnessError::WrongCapstanWeights { needs: slip, computed });
            };
            let c_s = segment.length / ea;
            series += c_s * w;
            let g = &mut out.moving_series_t.col_mut(c)[grad_w.dofs.clone()];
            for (o, v) in g.iter_mut().zip(grad_w.values) {
                *o += c_s * v;
            }
            // T_0 J_sᵀ ∇w_s, transposed: column i of the scratch += T_0 J_s[i] ∇w_s.
            let j_s = segment.jacobian;
            for (v, i) in j_s.values.iter().zip(j_s.dofs.clone()) {
                let tv = t_0 * v;
                let column = &mut out.moving_transposed.col_mut(i)[grad_w.dofs.clone()];
                for (o, g) in column.iter_mut().zip(grad_w.values) {
                    *o += tv * g;
                }
            }
            reach = grad_w.dofs;
        }
        // The rows of J̃ᵀ (J_c − T_0 g) / C̃, split into its two parts.
        for j in routing.cables()[c].dofs.clone() {
            *out.series_elastic.at_mut(c, j) = j_c[(c, j)] / series;
        }
        for v in &mut out.moving_series_t.col_mut(c)[reach] {
            *v *= t_0 / series;
        }
    }
    let (elastic, moving) = (out.series_elastic.as_ref(), out.moving_series_t.as_ref().transpose());
    let (inherent, controllable) = (out.inherent.as_mut(), out.controllable.as_mut());
    matmul(inherent, Accum::Add, j_tilde.transpose(), elastic, 1.0, Par::Seq);
    matmul(controllable, Accum::Add, j_tilde.transpose(), moving, -1.0, Par::Seq);
    let n = out.dof;
    for j in 0..n {
        for i in 0..n {
            *out.controllable.at_mut(i, j) += out.moving_transposed.at(j, i);
        }
    }
    out.finish(FrictionRegime::Slip(slip));
    Ok(())
}
