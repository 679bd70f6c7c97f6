//! One slip regime's capstan weights and the effective cable Jacobian, from
//! the friction geometry (module docs of `crate::friction`).

use super::data::FrictionData;
use super::lanes::exp_all;
use super::model::{FrictionModel, Slip};
use crate::error::{Result, RoutingError};

/// The capstan weights of `slip` from the friction geometry in `data`
/// ([`crate::compute_friction_geometry`]): per cable `w_s`, and the effective
/// cable Jacobian `J̃_c = Σ_s w_s J_s` (m × dof). Allocates nothing; may be called for each
/// regime in turn on one geometry.
///
/// # Math
/// `w_0 = 1`, `w_s = w_{s−1} e^{σ μ θ_{s−1}}` (`σ` = [`Slip::sign`]: −1 pull, +1 release; `μ`
/// the cable's; the factors by `libm`'s `exp`, [`capstan_factor`] bit for bit),
/// `J̃_c = Σ_{s ≥ 1} w_s J_s` summed in segment order from 0. At μ = 0 every `w_s` is exactly 1 and `J̃_c` is `J_c` bit for bit.
///
/// # Errors
/// [`RoutingError::WorkspaceMismatch`] for a workspace of another model,
/// [`RoutingError::FrictionNotComputed`] before the geometry.
pub fn compute_capstan_weights(
    model: &FrictionModel,
    data: &mut FrictionData,
    slip: Slip,
) -> Result<()> {
    data.check(model)?;
    if !data.geometry {
        return Err(RoutingError::FrictionNotComputed {
            what: "friction geometry",
            call: "compute_friction_geometry",
        });
    }
    data.slip = None;
    let m = model.cables.len();
    // Each hole's capstan factor e^{σμθ_k} at once (`lanes.rs`: `libm`'s `exp` bit for bit),
    // into `weights` shifted by one (`[e]` the factor of hole e − 1); e^0 = 1 at s = 0.
    let exponents = &mut data.scratch[0];
    for (c, range) in model.cables.iter().enumerate() {
        let rate = slip.sign() * model.mu[c];
        exponents[range.start] = 0.0;
        for e in range.start + 1..range.end {
            exponents[e] = rate * data.wrap[e - 1];
        }
    }
    exp_all(exponents, &mut data.weights);
    data.effective_jacobian.fill(0.0);
    for (c, range) in model.cables.iter().enumerate() {
        let entries = &model.entries[range.clone()];
        let first = range.start;
        data.weights[first] = 1.0;
        for s in 1..entries.len() {
            let e = first + s;
            let w = data.weights[e - 1] * data.weights[e];
            data.weights[e] = w;
            let row = &entries[s].jacobian;
            let j_s = &data.jacobians[row.offset..row.offset + row.dofs.len()];
            for (i, g) in row.dofs.clone().zip(j_s) {
                data.effective_jacobian[c + i * m] += w * g;
            }
        }
    }
    data.slip = Some(slip);
    Ok(())
}

/// The capstan law's factor `e^x` for an exponent `x = σμθ` (`σ = ±1`, μ the friction
/// coefficient, θ a wrap angle or a sum of them): `libm`'s `exp` (musl's, error below 1 ulp),
/// the one [`compute_capstan_weights`] computes several holes at a time, so that a band edge
/// `e^{−μθ}` computed elsewhere is the factor the pull weights were built with, bit for bit.
pub fn capstan_factor(x: f64) -> f64 {
    libm::exp(x)
}
