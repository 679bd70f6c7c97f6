//! The structured end solve of the decoupled model: `C_x = J_x (K_q + K_W)⁻¹ J_xᵀ` (eq. 19)
//! and the stability verdict in `O(dof)`, without forming or factorising a dof × dof matrix.
//!
//! # Math
//! Shapes: `n = dof`; the DOFs fall into consecutive blocks `B_0 … B_{N−1}` over which `K_q` is
//! block diagonal (`|B_k| = 2`, one universal joint, in the decoupled model; at most
//! [`MAX_BLOCK`]). `a_j` is joint `j`'s unit axis (base frame). `K_W = ∂T0/∂Q` (eq. 9) is
//! semiseparable, each entry a dot product of the proximal joint's axis and a generator of the
//! distal joint (the generators of [`sinew_statics::KwGenerators`], computed with `T0` and
//! `J_x` in one pass by [`sinew_statics::equilibrium_torques`]):
//!
//! ```text
//! A = K_q + K_W                                         (n × n)
//! K_q = diag(K_0, …, K_{N−1})                           (eq. 18, blocks |B_k| × |B_k|)
//! K_W[j, i] = a_i · w_j   (i ≤ j),    K_W[j, i] = a_j · u_i   (i > j)          (1)
//! u_k = g × (a_k × r_k) + v_k × f,    w_k = u_k + a_k × m,    v_k = a_k × (p − p_k)
//! J_x[:, k] = [v_k; a_k]                                (6 × n)
//! ```
//!
//! (`F0 = [f; m]`, `r_k` the mass moment of the bodies joint `k` moves, `p` the tip; the load
//! terms and `J_x`'s column vanish for joints at or beyond the tip's body.) Between an earlier
//! set of DOFs `R` and a later block `B` the coupling has rank ≤ 3 in each triangle:
//! `A[R, B] = A_Rᵀ U_B` and `A[B, R] = W_Bᵀ A_R` (`A_R = [a_i]` 3 × |R|, `U_B = [u_j]` and
//! `W_B = [w_j]` 3 × |B|).
//!
//! **Elimination from the tip** (a block `U D L` factorisation, organised like the
//! articulated-body recursion). Eliminating the last block `B` leaves the Schur complement
//! `A[R, R] − A_Rᵀ (U_B Â_B⁻¹ W_Bᵀ) A_R`: the form (1) again, less `a_iᵀ P a_j` for a 3 × 3
//! matrix `P`. Carrying `P` to the base, block `k` sees the generators `ũ_j = u_j − P a_j`,
//! `w̃_j = w_j − Pᵀ a_j` and the pivot block `Â_k`; the right-hand side `J_xᵀ` and the left
//! factor `J_x` are reduced the same way through the 3 × 6 and 6 × 3 accumulators `Z`, `Z'`:
//!
//! ```text
//! P = 0 (3 × 3), Z = 0 (3 × 6), Z' = 0 (6 × 3), C_x = 0 (6 × 6)
//! for k = N−1 down to 0, with j, i ∈ B_k:
//!     ũ_j = u_j − P a_j,    w̃_j = w_j − Pᵀ a_j                                    (3)
//!     Â_k[j, i] = K_q[j, i] + (a_i · w̃_j  if i ≤ j,  a_j · ũ_i  if i > j)   (|B_k| × |B_k|)
//!     Ŷ_k = J_kᵀ − A_kᵀ Z       (|B_k| × 6, J_k = J_x[:, B_k])
//!     Ĵ_k = J_k − Z' A_k        (6 × |B_k|)
//!     C_x += Ĵ_k Â_k⁻¹ Ŷ_k                                                      (eq. 19)
//!     Z += Ũ_k Â_k⁻¹ Ŷ_k,   Z' += Ĵ_k Â_k⁻¹ W̃_kᵀ,   P += Ũ_k Â_k⁻¹ W̃_kᵀ         (3 × 3)
//! ```
//!
//! With `A = M diag(Â_k) M'` (`M` unit block upper, `M'` unit block lower triangular),
//! `C_x = (J_x M'⁻¹) diag(Â_k)⁻¹ (M⁻¹ J_xᵀ)`, and `Ĵ_k`, `Ŷ_k` are the block columns and rows
//! of the two outer factors.
//!
//! **Symmetric case** (`m = 0`: `w = u`, `A = Aᵀ`; `Ĵ_k = Ŷ_kᵀ`, `Z' = Zᵀ`, `M' = Mᵀ`).
//! `Â_k = L_k D_k L_kᵀ` (2 × 2, `L_k` unit lower triangular); with `G_k = L_k⁻¹ Ŷ_k` (B × 6)
//! and `E_k = L_k⁻¹ Ũ_kᵀ` (B × 3) the three updates are blocks of one positive semidefinite
//! Gram matrix:
//!
//! ```text
//! [ P  Z  ]      [ E_kᵀ ]
//! [ Zᵀ C_x]  +=  [ G_kᵀ ] D_k⁻¹ [ E_k  G_k ]                                     (9 × 9)
//! ```
//!
//! so `C_x` is symmetric by construction. By Sylvester's law of inertia `A = M diag(Â_k) Mᵀ` is
//! positive definite exactly when every `Â_k` is, i.e. when every pivot of the `D_k` is
//! positive: the verdict of the dense Cholesky of `K_q + K_W`.
//!
//! **Non-symmetric case** (a moment in `F0`). Stability is that of the symmetric part
//! `H = (A + Aᵀ)/2`, which has the form (1) with `½(u + w)` for both generators and the blocks
//! `½(K_k + K_kᵀ)`: a first sweep (pivots and `P` only) decides it. When `H ≻ 0`, every Schur
//! complement of `A` has a positive definite symmetric part, so every `Â_k` is nonsingular; the
//! second sweep is the recursion above with a partially pivoted LU of each `Â_k`.
//!
//! **Robustness.** For `A ≻ 0` the recursion is block `LDLᵀ` without pivoting, which is
//! backward stable for positive definite matrices; the generator form adds the products `P a_j`
//! and `A_kᵀ Z`, whose rounding is bounded by `‖P‖` and `‖Z‖`. These are of the size of the
//! entries of `A` and `J_x` along the axes (`A_Rᵀ P A_R ⪯ A[R, R]`, and `|Z_ic| ≤ (P_ii C_cc)^½`
//! by the Gram form) but not in a direction no remaining axis has (a nearly straight arm of
//! universal joints leaves the chain's axis unseen). So every result is checked a posteriori:
//! for one combined right-hand side `y = J_xᵀ ω` (fixed weights `ω`), `x` is back-substituted
//! from the stored block factors, from the base,
//!
//! ```text
//! x_k = Â_k⁻¹ (Ŷ_k ω − W̃_kᵀ σ),    σ = Σ_{i before B_k} a_i x_i
//! ```
//!
//! and the residual `r = A x − y` is formed from the original generators and `K_q` by (1):
//! `r_j = (K_k x_k)_j + w_j · Σ_{i ≤ j} a_i x_i + a_j · Σ_{i > j} u_i x_i − y_j` (one pass,
//! `O(n)`). Unless the backward error
//! `‖r‖∞ / ((max|K_q| + max(|u|, |w|)) ‖x‖₁ + ‖y‖∞) ≤ RESIDUAL_TOLERANCE` (`1e-12`; a stable
//! solve gives ~`1e-17`), the caller uses the dense path; so it does for an indefinite pivot
//! block (the dense path then reports the smallest eigenvalue) and any non-finite number.
//!
//! Cost: `O(n)`, about 100 flops per DOF for the sweep and 25 for the check, no allocation.

/// Runs `step::<B>` for a block of `b` DOFs.
macro_rules! dispatch {
    ($b:expr, $step:ident ($($arg:expr),*)) => {
        match $b {
            1 => $step::<1>($($arg),*),
            2 => $step::<2>($($arg),*),
            3 => $step::<3>($($arg),*),
            4 => $step::<4>($($arg),*),
            _ => false,
        }
    };
}

mod check;
mod kernels;
mod layout;
mod sweep;

use sinew_statics::KwGenerators;

pub(crate) use kernels::{lu, lu_solve};
pub(crate) use layout::{BlockLayout, MAX_BLOCK, zero_blocks};

use crate::colmajor::{ColMajor, mirror_upper};
use check::check;
use sweep::{BlockFactor, Sweep, step_general, step_symmetric, step_symmetric_part};

/// Bound on the backward error of the structured solve (see the module docs); a stable solve
/// gives about `1e-16`.
pub(crate) const RESIDUAL_TOLERANCE: f64 = 1e-12;

/// The weights `ω` of the combined right-hand side `y = J_xᵀ ω` of the residual check: all six
/// rows of `J_x`, none with a special weight.
const CHECK_WEIGHTS: [f64; 6] = [1.0, 0.9, 0.8, 0.7, 0.6, 0.5];

/// Outcome of the structured solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Structured {
    /// `C_x` computed and checked.
    Done,
    /// A pivot block of `K_q + K_W` (or of its symmetric part) is not positive definite.
    NotPositiveDefinite,
    /// The residual check failed, a number is not finite, or the shapes do not match: use the
    /// dense path.
    Rejected,
}

/// Workspace of the structured solve, sized once.
#[derive(Debug, Clone)]
pub(crate) struct StructuredData {
    pub(crate) factors: Vec<BlockFactor>,
    /// The residual rows of the check, less their distal part (n).
    pub(crate) x: Vec<f64>,
    /// `C_x` (6 × 6, row-major).
    pub(crate) c_x: [[f64; 6]; 6],
    /// Last backward error of the check (diagnostics and tests).
    pub(crate) backward_error: f64,
}

impl StructuredData {
    pub(crate) fn new(layout: &BlockLayout) -> StructuredData {
        StructuredData {
            factors: vec![BlockFactor::default(); layout.count()],
            x: vec![0.0; layout.dof()],
            c_x: [[0.0; 6]; 6],
            backward_error: f64::NAN,
        }
    }
}

/// `C_x` (eq. 19) and the stability verdict by the structured recursion (module docs), into
/// `data.c_x`. `k_q`: n × n, block diagonal over `layout` (entries outside the blocks are not
/// read); `j_x`: the n columns of `J_x`.
pub(crate) fn compliance(
    layout: &BlockLayout,
    k_q: &ColMajor,
    gens: &KwGenerators,
    j_x: &[[f64; 6]],
    data: &mut StructuredData,
) -> Structured {
    let n = layout.dof();
    data.backward_error = f64::NAN;
    if !layout.structured()
        || (k_q.rows(), k_q.cols()) != (n, n)
        || j_x.len() != n
        || gens.len() != n
        || data.x.len() != n
        || data.factors.len() != layout.count()
    {
        return Structured::Rejected;
    }
    if !gens.is_symmetric() {
        let mut p = [[0.0; 3]; 3];
        for block in layout.blocks().rev() {
            if !dispatch!(block.len(), step_symmetric_part(&mut p, block.start, k_q, gens)) {
                return Structured::NotPositiveDefinite;
            }
        }
    }
    let mut sweep = Sweep::new();
    for (block, factor) in layout.blocks().zip(data.factors.iter_mut()).rev() {
        let s = block.start;
        let ok = if gens.is_symmetric() {
            dispatch!(block.len(), step_symmetric(&mut sweep, s, k_q, gens, j_x, factor))
        } else {
            dispatch!(block.len(), step_general(&mut sweep, s, k_q, gens, j_x, factor))
        };
        if !ok {
            return Structured::NotPositiveDefinite;
        }
    }
    if gens.is_symmetric() {
        let c_x = &mut sweep.c_x;
        mirror_upper(0..6, |i, j| c_x[i][j] = c_x[j][i]);
    }
    data.c_x = sweep.c_x;
    let accepted = check(layout, gens, data);
    let finite = data.c_x.iter().flatten().all(|v| v.is_finite());
    if accepted && finite { Structured::Done } else { Structured::Rejected }
}
