//! Joint stiffness (paper section III.A; spec §3): controllable and inherent parts.
//!
//! # Math
//! With `τ(Q) = −J_c(Q)ᵀ f(Q)` (eq. 5) and elastic cables `f = f_0 + K_l (L(Q) − L(Q_0))`
//! (eq. 13), the restoring joint stiffness is
//!
//! ```text
//! K = −∂τ/∂Q = Σ_c f_c H_c  +  J_cᵀ K_l J_c          (eq. 11/14, restoring sign)
//!              (controllable)  (inherent)
//! ```
//!
//! `H_c = ∂²L_c/∂Q²`. Both parts are symmetric. In the decoupled model `K` is block diagonal
//! with one 2 × 2 block per universal joint (`K_q = diag(K_1 … K_n)`, eq. 18); in the routed
//! model a cable's terms reach every joint it crosses and `K_q` is full. For joint `i`,
//! `K_{i,x} = K[2i, 2i]` and `K_{i,y} = K[2i+1, 2i+1]` (eq. 20).
//!
//! Each cable's terms are accumulated over its own joint range only (`Cable::dofs`), so the
//! cost is `O(Σ_c |dofs_c|²)`: linear in the number of joints when decoupled.

use faer::MatMut;
use nalgebra::Matrix2;
use sinew_routing::{Routing, RoutingData};

use crate::error::StiffnessError;

fn check(what: &'static str, m: &MatMut<'_, f64>, n: usize) -> Result<(), StiffnessError> {
    for got in [m.nrows(), m.ncols()] {
        if got != n {
            return Err(StiffnessError::DimensionMismatch { what, expected: n, got });
        }
    }
    Ok(())
}

/// The controllable part `Σ_c f_c H_c` and the inherent part `J_cᵀ K_l J_c` of the joint
/// stiffness at the tensions `f` (N), into two dof × dof matrices (overwritten).
///
/// Needs the cable geometry with Hessians for the same `Q`. No allocation.
///
/// # Errors
/// [`StiffnessError::DimensionMismatch`], routing errors (geometry not computed).
pub fn joint_stiffness(
    routing: &Routing,
    geometry: &RoutingData,
    tensions: &[f64],
    mut controllable: MatMut<'_, f64>,
    mut inherent: MatMut<'_, f64>,
) -> Result<(), StiffnessError> {
    let n = routing.dof();
    check("controllable stiffness", &controllable, n)?;
    check("inherent stiffness", &inherent, n)?;
    if tensions.len() != routing.cable_count() {
        return Err(StiffnessError::DimensionMismatch {
            what: "tensions",
            expected: routing.cable_count(),
            got: tensions.len(),
        });
    }
    controllable.fill(0.0);
    geometry.add_weighted_hessians(routing, tensions, controllable.as_mut())?;
    inherent.fill(0.0);
    add_inherent(routing, geometry, inherent.as_mut())?;
    Ok(())
}

/// `out += J_cᵀ K_l J_c`, cable by cable over each cable's joint range.
fn add_inherent(
    routing: &Routing,
    geometry: &RoutingData,
    mut out: MatMut<'_, f64>,
) -> Result<(), StiffnessError> {
    let j_c = geometry.jacobian()?;
    for (c, cable) in routing.cables().iter().enumerate() {
        let k = cable.stiffness;
        for j in cable.dofs.clone() {
            let kj = k * j_c[(c, j)];
            for i in cable.dofs.clone() {
                out[(i, j)] += kj * j_c[(c, i)];
            }
        }
    }
    Ok(())
}

/// `Σ_c δf_c H_c`: how the joint stiffness changes when the tensions change by `δf` (the
/// slope of the affine map tension → stiffness; the inherent part does not depend on `f`).
/// `out` is overwritten. No allocation.
///
/// With `δf` from [`sinew_statics::ArmStatics`]'s tension sensitivity of joint `i`, this is
/// `∂K/∂λ_i`: sweeps over tension levels then need no new geometry.
///
/// # Errors
/// [`StiffnessError::DimensionMismatch`], routing errors.
pub fn stiffness_slope(
    routing: &Routing,
    geometry: &RoutingData,
    delta_tensions: &[f64],
    mut out: MatMut<'_, f64>,
) -> Result<(), StiffnessError> {
    check("stiffness slope", &out, routing.dof())?;
    out.fill(0.0);
    geometry.add_weighted_hessians(routing, delta_tensions, out.as_mut())?;
    Ok(())
}

/// The 2 × 2 block of universal joint `i` in a dof × dof stiffness matrix:
/// `[[K_{i,x}, ·], [·, K_{i,y}]]`.
pub fn joint_block(k: faer::MatRef<'_, f64>, i: usize) -> Option<Matrix2<f64>> {
    if 2 * i + 1 >= k.nrows().min(k.ncols()) {
        return None;
    }
    Some(Matrix2::from_fn(|r, c| k[(2 * i + r, 2 * i + c)]))
}
