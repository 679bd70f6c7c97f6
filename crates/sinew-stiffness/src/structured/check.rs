//! The a-posteriori residual check of the structured solve ([`super`]'s docs, Robustness).

use sinew_statics::KwGenerators;

use super::kernels::{backward, dot, forward, lu_solve, scale};
use super::layout::BlockLayout;
use super::sweep::BlockFactor;
use super::{RESIDUAL_TOLERANCE, StructuredData};

/// Accumulators of the residual check.
struct Residual {
    /// `σ = Σ a_i x_i` and `μ = Σ u_i x_i` over the DOFs done.
    sigma: [f64; 3],
    mu: [f64; 3],
    kq_max: f64,
    gen_max2: f64,
    x_sum: f64,
    y_max: f64,
}

/// One block of the check, from the base: back substitution
/// `x_k = Â_k⁻¹ (ŷ_k − W̃_kᵀ σ)`, then for each DOF `j` of the block the residual without its
/// distal part, `ρ_j = (K_k x_k)_j + w_j · σ_j − a_j · μ_j − y_j` (`σ_j`, `μ_j` summed over
/// `i ≤ j`), stored in `rho[j]`; the whole residual is `r_j = ρ_j + a_j · μ_n`.
#[inline(always)]
fn check_block<const B: usize>(
    factor: &BlockFactor,
    symmetric: bool,
    start: usize,
    gens: &KwGenerators,
    acc: &mut Residual,
    rho: &mut [f64],
) -> bool {
    let mut v = [[0.0; 1]; B];
    for r in 0..B {
        v[r][0] = factor.y_hat[r] - dot(factor.w_tilde[r], acc.sigma);
    }
    let (m, perm) = factor.matrix::<B>();
    if symmetric {
        forward(&m, &mut v);
        scale(&m, &mut v);
        backward(&m, &mut v);
    } else {
        lu_solve(&m, &perm, &mut v);
    }
    for r in 0..B {
        let j = start + r;
        let x = v[r][0];
        let (a, u, w) = (gens.a(j), gens.u(j), gens.w(j));
        for c in 0..3 {
            acc.sigma[c] += a[c] * x;
            acc.mu[c] += u[c] * x;
        }
        let mut kx = 0.0;
        for c in 0..B {
            let k = factor.k_q[r * B + c];
            kx += k * v[c][0];
            acc.kq_max = acc.kq_max.max(k.abs());
        }
        let y = factor.y[r];
        rho[j] = kx + dot(w, acc.sigma) - dot(a, acc.mu) - y;
        acc.gen_max2 = acc.gen_max2.max(dot(u, u)).max(dot(w, w));
        acc.x_sum += x.abs();
        acc.y_max = acc.y_max.max(y.abs());
    }
    true
}

/// The a-posteriori check (module docs): back-substitute `x = A⁻¹ J_xᵀ ω` from the stored
/// factors, form `r = A x − J_xᵀ ω` from the original generators and `K_q`, and accept the
/// solve when its backward error is below [`RESIDUAL_TOLERANCE`]. One pass from the base
/// (`r_j` less its distal part `a_j · Σ_{i > j} u_i x_i`, written as `a_j · (μ_n − μ_j)`), then
/// `r_j = ρ_j + a_j · μ_n`.
pub(crate) fn check(layout: &BlockLayout, gens: &KwGenerators, data: &mut StructuredData) -> bool {
    let mut acc = Residual {
        sigma: [0.0; 3],
        mu: [0.0; 3],
        kq_max: 0.0,
        gen_max2: 0.0,
        x_sum: 0.0,
        y_max: 0.0,
    };
    let rho = &mut data.x;
    for (block, factor) in layout.blocks().zip(&data.factors) {
        let start = block.start;
        dispatch!(
            block.len(),
            check_block(factor, gens.is_symmetric(), start, gens, &mut acc, rho)
        );
    }
    let mut r_max: f64 = 0.0;
    for (j, rho_j) in rho.iter().enumerate() {
        r_max = r_max.max((rho_j + dot(gens.a(j), acc.mu)).abs());
    }
    let scale = (acc.kq_max + acc.gen_max2.sqrt()) * acc.x_sum + acc.y_max;
    data.backward_error = r_max / scale;
    // Written so that NaN is rejected.
    r_max <= RESIDUAL_TOLERANCE * scale
}
