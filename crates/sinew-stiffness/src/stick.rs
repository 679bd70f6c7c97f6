//! The stick regime's joint stiffness (spec §9, #27): no hole slides, each segment a spring of
//! its own.

use sinew_routing::{CableRows, FrictionData, FrictionModel, Routing, RoutingData};

use crate::error::StiffnessError;
use crate::friction::{
    FrictionRegime, FrictionStiffnessData, History, add_segment_hessians, axial_rigidity,
    check_weights,
};

/// The joint stiffness of the stick regime after `history`, at the actuator tensions
/// `actuator` (m, N), into `out` ([`FrictionStiffnessData::stiffness`], its two parts, its
/// symmetric part; the skew norm is 0 up to rounding).
///
/// Needs the cable geometry with Hessians (`geometry`), the friction geometry at the same `Q`
/// and, for a [`History::Pull`] or [`History::Release`], that regime's capstan weights in
/// `friction` ([`sinew_routing::compute_capstan_weights`]). No allocation.
///
/// # Math
/// No hole slides: each piece of cable keeps its material, so each is a spring of its own,
/// `k_s = E A / ℓ_s(Q)` (the free length, `J_0 = 0`, no longer adds compliance). The segment
/// tensions are those the history left, `T_s = T_0 w_s` (`w_s` the pull or release weights at
/// the pose, or 1 for [`History::Equal`]); `τ = −Σ_s T_s J_sᵀ`, and with `δT_s = k_s J_s δQ`:
///
/// ```text
/// K_stick = Σ_c [ Σ_s T_{c,s} H_{c,s}  +  Σ_s J_{c,s}ᵀ (E A / ℓ_{c,s}(Q)) J_{c,s} ]
///              (controllable)            (inherent)
/// ```
///
/// symmetric (both sums are, and the inherent part is accumulated on one triangle and mirrored),
/// affine in the actuator tensions for a given history. At equal tensions it is ⪰ the
/// frictionless `K` with the cable's spring `E A/(ℓ_free + L_c(Q))`, by Cauchy–Schwarz:
/// `(J_c δQ)² = (Σ_s √c_s · √k_s J_s δQ)² ≤ (Σ_s c_s)(Σ_s k_s (J_s δQ)²)`, `c_s = 1/k_s`,
/// the free length's `c_0 = ℓ_free/(E A)` included. It is the tangent while every hole stays
/// inside its band (spec §9: below the stick load limit).
///
/// # Errors
/// [`StiffnessError::StickWithoutFriction`] for a cable with μ = 0 (no band: it cannot stick);
/// [`StiffnessError::WrongCapstanWeights`] when `friction` holds the other regime's weights (or
/// none) for a pull or release history; [`StiffnessError::DimensionMismatch`]; routing errors
/// (geometry not computed, workspaces of another routing).
pub fn stick_stiffness(
    model: &FrictionModel,
    routing: &Routing,
    geometry: &RoutingData,
    friction: &FrictionData,
    history: History,
    actuator: &[f64],
    out: &mut FrictionStiffnessData,
) -> Result<(), StiffnessError> {
    out.start(model, routing, actuator)?;
    if let Some(cable) = model.friction_coefficients().iter().position(|&mu| mu <= 0.0) {
        return Err(StiffnessError::StickWithoutFriction { cable });
    }
    if let Some(slip) = history.slip() {
        check_weights(friction, slip)?;
    }
    let ea = axial_rigidity(routing);
    let weight = |cable: &CableRows<'_>, s: usize| match (history, cable.weights) {
        (History::Pull | History::Release, Some(w)) => w[s],
        _ => 1.0,
    };
    add_segment_hessians((model, routing, geometry), friction, actuator, weight, out)?;
    for c in 0..actuator.len() {
        let cable = friction.cable(model, c)?;
        for s in 1..cable.len() {
            // J_sᵀ k_s J_s on and above the diagonal (mirrored below once every cable is in).
            let j_s = cable.jacobian(s);
            let k_s = ea / cable.lengths[s];
            let (lo, v) = (j_s.dofs.start, j_s.values);
            let inherent = &mut out.inherent;
            match *v {
                [] => {}
                // A segment across one universal joint (the common case), unrolled: the same
                // products, added in the same order.
                [v0, v1] => {
                    let (k0, k1) = (k_s * v0, k_s * v1);
                    *inherent.at_mut(lo, lo) += k0 * v0;
                    *inherent.at_mut(lo, lo + 1) += k1 * v0;
                    *inherent.at_mut(lo + 1, lo + 1) += k1 * v1;
                }
                _ => {
                    for (jj, j) in j_s.dofs.clone().enumerate() {
                        let kj = k_s * v[jj];
                        for (ii, i) in j_s.dofs.clone().enumerate().take(jj + 1) {
                            *inherent.at_mut(i, j) += kj * v[ii];
                        }
                    }
                }
            }
        }
    }
    out.mirror_inherent();
    out.finish(FrictionRegime::Stick(history));
    Ok(())
}
