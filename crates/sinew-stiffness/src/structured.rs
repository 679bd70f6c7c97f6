//! The structured end solve of the decoupled model: `C_x = J_x (K_q + K_W)⁻¹ J_xᵀ` (eq. 19)
//! and the stability verdict in `O(dof)`, without forming or factorising a dof × dof matrix.
//!
//! # Math
//! Shapes: `n = dof`; the DOFs fall into consecutive blocks `B_0 … B_{N−1}` over which `K_q` is
//! block diagonal (`|B_k| = 2`, one universal joint, in the decoupled model; at most
//! [`MAX_BLOCK`]). `a_j` is joint `j`'s unit axis (base frame). `K_W = ∂T0/∂Q` (eq. 9) is
//! semiseparable, each entry a dot product of the proximal joint's axis and a generator of the
//! distal joint (sinew-robot's `gravity_torque_derivative_generators`,
//! `wrench_torque_derivative_generators`):
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

use std::ops::Range;

use faer::{MatMut, MatRef};
use nalgebra::{Vector3, Vector6};
use sinew_robot::{Robot, RobotData};
use sinew_routing::Routing;

use crate::error::StiffnessError;

/// The largest block of `K_q` the structured solve handles (a universal joint is 2).
pub(crate) const MAX_BLOCK: usize = 4;

/// Bound on the backward error of the structured solve (see the module docs); a stable solve
/// gives about `1e-16`.
pub(crate) const RESIDUAL_TOLERANCE: f64 = 1e-12;

/// The weights `ω` of the combined right-hand side `y = J_xᵀ ω` of the residual check: all six
/// rows of `J_x`, none with a special weight.
const CHECK_WEIGHTS: [f64; 6] = [1.0, 0.9, 0.8, 0.7, 0.6, 0.5];

/// A dense column-major matrix in a plain `Vec` (no padding), viewed as a faer matrix at the
/// API boundary; the structured kernels read it by slices.
#[derive(Clone)]
pub(crate) struct ColMajor {
    rows: usize,
    cols: usize,
    data: Vec<f64>,
}

impl ColMajor {
    pub(crate) fn zeros(rows: usize, cols: usize) -> ColMajor {
        ColMajor { rows, cols, data: vec![0.0; rows * cols] }
    }

    pub(crate) fn rows(&self) -> usize {
        self.rows
    }

    pub(crate) fn cols(&self) -> usize {
        self.cols
    }

    pub(crate) fn as_ref(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.data, self.rows, self.cols)
    }

    pub(crate) fn as_mut(&mut self) -> MatMut<'_, f64> {
        MatMut::from_column_major_slice_mut(&mut self.data, self.rows, self.cols)
    }

    #[inline(always)]
    pub(crate) fn at(&self, i: usize, j: usize) -> f64 {
        self.data[i + j * self.rows]
    }

    #[inline(always)]
    pub(crate) fn at_mut(&mut self, i: usize, j: usize) -> &mut f64 {
        &mut self.data[i + j * self.rows]
    }

    #[inline(always)]
    pub(crate) fn col(&self, j: usize) -> &[f64] {
        &self.data[j * self.rows..(j + 1) * self.rows]
    }

    #[inline(always)]
    pub(crate) fn col_mut(&mut self, j: usize) -> &mut [f64] {
        &mut self.data[j * self.rows..(j + 1) * self.rows]
    }
}

impl std::fmt::Debug for ColMajor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.as_ref().fmt(f)
    }
}

/// Consecutive blocks of DOFs over which `K_q` is block diagonal: no cable's DOFs straddle two
/// blocks (`J_c` and the Hessians are exactly zero outside each cable's range).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BlockLayout {
    dof: usize,
    /// Block `k` is `starts[k]..starts[k + 1]`.
    starts: Vec<usize>,
    /// `block_of[d]`: the block of DOF `d`.
    block_of: Vec<usize>,
    /// The block of every cable (`usize::MAX` for a cable that crosses no joint).
    cable_block: Vec<usize>,
    /// The cables of block `k`, in routing order: `cables[cable_starts[k]..cable_starts[k + 1]]`.
    cables: Vec<usize>,
    cable_starts: Vec<usize>,
    max_block: usize,
}

impl BlockLayout {
    pub(crate) fn new(routing: &Routing) -> BlockLayout {
        let n = routing.dof();
        // joined[d]: DOFs d − 1 and d are in one block.
        let mut joined = vec![false; n];
        for cable in routing.cables() {
            for d in cable.dofs.start + 1..cable.dofs.end.min(n) {
                joined[d] = true;
            }
        }
        let mut starts = Vec::with_capacity(n + 1);
        let mut block_of = vec![0; n];
        for d in 0..n {
            if d == 0 || !joined[d] {
                starts.push(d);
            }
            block_of[d] = starts.len() - 1;
        }
        starts.push(n);
        let max_block = starts.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(0);
        let cable_block: Vec<usize> = routing
            .cables()
            .iter()
            .map(|c| if c.dofs.is_empty() { usize::MAX } else { block_of[c.dofs.start.min(n - 1)] })
            .collect();
        let blocks = starts.len() - 1;
        let mut cables = Vec::with_capacity(cable_block.len());
        let mut cable_starts = Vec::with_capacity(blocks + 1);
        for k in 0..blocks {
            cable_starts.push(cables.len());
            cables.extend((0..cable_block.len()).filter(|&c| cable_block[c] == k));
        }
        cable_starts.push(cables.len());
        BlockLayout { dof: n, starts, block_of, cable_block, cables, cable_starts, max_block }
    }

    /// Whether `routing` is one this layout describes: same DOFs and cables, every cable
    /// inside its block.
    pub(crate) fn fits(&self, routing: &Routing) -> bool {
        routing.dof() == self.dof
            && routing.cable_count() == self.cable_block.len()
            && routing.cables().iter().zip(&self.cable_block).all(|(c, &block)| {
                if c.dofs.is_empty() {
                    block == usize::MAX
                } else {
                    c.dofs.end <= self.dof
                        && self.block_of[c.dofs.start] == block
                        && self.block_of[c.dofs.end - 1] == block
                }
            })
    }

    /// Whether the structured solve applies (every block at most [`MAX_BLOCK`]).
    pub(crate) fn structured(&self) -> bool {
        self.max_block <= MAX_BLOCK
    }

    pub(crate) fn blocks(
        &self,
    ) -> impl DoubleEndedIterator<Item = Range<usize>> + ExactSizeIterator + '_ {
        self.starts.windows(2).map(|w| w[0]..w[1])
    }

    /// The cables of block `k`, in routing order.
    pub(crate) fn cables_of(&self, k: usize) -> &[usize] {
        match (self.cable_starts.get(k), self.cable_starts.get(k + 1)) {
            (Some(&lo), Some(&hi)) => &self.cables[lo..hi],
            _ => &[],
        }
    }

    fn count(&self) -> usize {
        self.starts.len() - 1
    }
}

/// The generators of `K_W = ∂T0/∂Q` (module docs): `K_W[j, i] = a_i · w_j` for `i ≤ j`,
/// `a_j · u_i` for `i > j`, one `[a_j, u_j, w_j]` per joint.
#[derive(Debug, Clone)]
pub(crate) struct KwGenerators {
    /// `[a_j, u_j, w_j]`, base frame.
    joints: Vec<[[f64; 3]; 3]>,
    /// `w = u` exactly (no moment in `F0`): `K_W` is symmetric.
    symmetric: bool,
    gravity: Vec<Vector3<f64>>,
    velocity: Vec<Vector3<f64>>,
}

impl KwGenerators {
    pub(crate) fn new(n: usize) -> KwGenerators {
        KwGenerators {
            joints: vec![[[0.0; 3]; 3]; n],
            symmetric: true,
            gravity: vec![Vector3::zeros(); n],
            velocity: vec![Vector3::zeros(); n],
        }
    }

    /// The generators at the configuration of `rdata` (forward kinematics done) for the load
    /// `f0 = [f; m]` (base frame), and the end-effector Jacobian `J_x` (6 × n) on the way:
    ///
    /// ```text
    /// u_k = g × (a_k × r_k) + v_k × f,   w_k = u_k + a_k × m,   J_x[:, k] = [v_k; a_k]
    /// ```
    ///
    /// for the joints `k < b` that move the tip (its body `b`; the load terms and the column
    /// vanish for the others), with sinew-robot's gravity generators and partial velocities
    /// `v_k = a_k × (p − p_k)`: the sums of [`Robot::gravity_torque_derivative_generators`] and
    /// [`Robot::wrench_torque_derivative_generators`], and the values of
    /// [`Robot::point_jacobian`], in one pass. `O(n)`, no allocation.
    pub(crate) fn compute(
        &mut self,
        robot: &Robot,
        rdata: &mut RobotData,
        f0: &Vector6<f64>,
        j_x: &mut ColMajor,
    ) -> Result<(), StiffnessError> {
        let n = robot.dof();
        for (what, expected, got) in [
            ("K_W generators", self.joints.len(), n),
            ("J_x (columns)", j_x.cols(), n),
            ("J_x (rows)", j_x.rows(), 6),
        ] {
            if expected != got {
                return Err(StiffnessError::DimensionMismatch { what, expected, got });
            }
        }
        let tip = robot.tip_point();
        robot.gravity_torque_derivative_generators(rdata, &mut self.gravity)?;
        robot.point_partial_velocities(rdata, &tip, &mut self.velocity)?;
        let f = Vector3::new(f0[0], f0[1], f0[2]);
        let m = Vector3::new(f0[3], f0[4], f0[5]);
        self.symmetric = m == Vector3::zeros();
        let b = tip.body.min(n);
        for (k, out) in self.joints.iter_mut().enumerate() {
            let a = rdata.joint_axis(k).copied().unwrap_or_else(Vector3::zeros);
            let g = self.gravity[k];
            let (u, w, column) = if k < b {
                let v = self.velocity[k];
                let load = v.cross(&f);
                let u = g + load;
                let w = if self.symmetric { u } else { g + (load + a.cross(&m)) };
                (u, w, [v.x, v.y, v.z, a.x, a.y, a.z])
            } else {
                (g, g, [0.0; 6])
            };
            *out = [a.into(), u.into(), w.into()];
            j_x.col_mut(k).copy_from_slice(&column);
        }
        Ok(())
    }

    #[inline(always)]
    fn a(&self, k: usize) -> [f64; 3] {
        self.joints[k][0]
    }

    #[inline(always)]
    fn u(&self, k: usize) -> [f64; 3] {
        self.joints[k][1]
    }

    #[inline(always)]
    fn w(&self, k: usize) -> [f64; 3] {
        self.joints[k][2]
    }

    fn len(&self) -> usize {
        self.joints.len()
    }

    /// `K_W` (n × n) from the generators, column by column. `O(n²)`.
    pub(crate) fn fill_dense(&self, k_w: &mut ColMajor) {
        for i in 0..self.len() {
            let (a_i, u_i) = (self.a(i), self.u(i));
            let col = k_w.col_mut(i);
            let (above, below) = col.split_at_mut(i);
            // Rows j < i: a_j · u_i.
            for (out, g) in above.iter_mut().zip(&self.joints) {
                *out = dot(g[0], u_i);
            }
            // Rows j ≥ i: a_i · w_j.
            for (out, g) in below.iter_mut().zip(&self.joints[i..]) {
                *out = dot(a_i, g[2]);
            }
        }
    }
}

/// What a block keeps for the back-substitution of the residual check.
#[derive(Debug, Clone, Copy, Default)]
struct BlockFactor {
    /// `L D Lᵀ` factors (unit lower, `D⁻¹` on the diagonal) or LU factors (unit lower, upper
    /// with reciprocal diagonal) of `Â_k`, row-major `|B_k| × |B_k|` in the leading entries.
    factor: [f64; MAX_BLOCK * MAX_BLOCK],
    /// Row permutation of the LU factorisation.
    perm: [usize; MAX_BLOCK],
    /// `w̃_j` of the block's DOFs (`ũ_j` in the symmetric case).
    w_tilde: [[f64; 3]; MAX_BLOCK],
    /// `Ŷ_k ω`.
    y_hat: [f64; MAX_BLOCK],
    /// The block `K_k` of `K_q`, row-major.
    k_q: [f64; MAX_BLOCK * MAX_BLOCK],
    /// `J_kᵀ ω`.
    y: [f64; MAX_BLOCK],
}

impl BlockFactor {
    #[inline(always)]
    fn save<const B: usize>(
        &mut self,
        m: &[[f64; B]; B],
        perm: &[usize; B],
        w_tilde: &[[f64; 3]; B],
        rhs: &Rhs<B>,
    ) {
        for r in 0..B {
            for c in 0..B {
                self.factor[r * B + c] = m[r][c];
            }
            self.perm[r] = perm[r];
            self.w_tilde[r] = w_tilde[r];
            self.y_hat[r] = rhs.y_hat_w[r];
            self.y[r] = rhs.y_w[r];
        }
    }

    /// Store the block `K_k` of `K_q` and return it.
    #[inline(always)]
    fn save_k_q<const B: usize>(&mut self, s: usize, k_q: &ColMajor) -> [[f64; B]; B] {
        let mut k = [[0.0; B]; B];
        for c in 0..B {
            for r in 0..B {
                k[r][c] = k_q.at(s + r, s + c);
                self.k_q[r * B + c] = k[r][c];
            }
        }
        k
    }

    #[inline(always)]
    fn matrix<const B: usize>(&self) -> ([[f64; B]; B], [usize; B]) {
        let mut m = [[0.0; B]; B];
        let mut perm = [0; B];
        for r in 0..B {
            for c in 0..B {
                m[r][c] = self.factor[r * B + c];
            }
            perm[r] = self.perm[r];
        }
        (m, perm)
    }
}

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
    factors: Vec<BlockFactor>,
    /// The residual rows of the check, less their distal part (n).
    x: Vec<f64>,
    /// `C_x` (6 × 6, row-major).
    pub(crate) c_x: [[f64; 6]; 6],
    /// Last backward error of the check (diagnostics and tests).
    pub(crate) backward_error: f64,
}

impl StructuredData {
    pub(crate) fn new(layout: &BlockLayout) -> StructuredData {
        StructuredData {
            factors: vec![BlockFactor::default(); layout.count()],
            x: vec![0.0; layout.dof],
            c_x: [[0.0; 6]; 6],
            backward_error: f64::NAN,
        }
    }
}

#[inline(always)]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `p · a` for a row-major 3 × 3 `p`.
#[inline(always)]
fn mul3(p: &[[f64; 3]; 3], a: [f64; 3]) -> [f64; 3] {
    [dot(p[0], a), dot(p[1], a), dot(p[2], a)]
}

/// `pᵀ · a`.
#[inline(always)]
fn mul3t(p: &[[f64; 3]; 3], a: [f64; 3]) -> [f64; 3] {
    [
        p[0][0] * a[0] + p[1][0] * a[1] + p[2][0] * a[2],
        p[0][1] * a[0] + p[1][1] * a[1] + p[2][1] * a[2],
        p[0][2] * a[0] + p[1][2] * a[1] + p[2][2] * a[2],
    ]
}

#[inline(always)]
fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// In-place `Â = L D Lᵀ` of the lower triangle of a block (`L` unit lower triangular below the
/// diagonal, `D⁻¹` on the diagonal); `false` unless every pivot `d_r` is positive (NaN
/// included). For a symmetric block this is Cholesky without its square roots:
/// `d_r = (L_chol)_rr²`, and the block is positive definite exactly when every `d_r > 0`.
#[inline(always)]
fn ldlt<const B: usize>(m: &mut [[f64; B]; B]) -> bool {
    let mut d = [0.0; B];
    for c in 0..B {
        // m[c][k] (k < c) holds L_ck; ld[k] = L_ck d_k.
        let mut ld = [0.0; B];
        let mut pivot = m[c][c];
        for k in 0..c {
            ld[k] = m[c][k] * d[k];
            pivot -= m[c][k] * ld[k];
        }
        // Written so that NaN is not positive.
        let positive = pivot > 0.0;
        if !positive {
            return false;
        }
        d[c] = pivot;
        let inv = 1.0 / pivot;
        m[c][c] = inv;
        for r in c + 1..B {
            let mut s = m[r][c];
            for k in 0..c {
                s -= m[r][k] * ld[k];
            }
            m[r][c] = s * inv;
        }
    }
    true
}

/// `V ← L⁻¹ V` for the rows `V[r]` (length `N`) of a `B × N` matrix, `L` unit lower triangular
/// (from [`ldlt`]).
#[inline(always)]
fn forward<const B: usize, const N: usize>(l: &[[f64; B]; B], v: &mut [[f64; N]; B]) {
    for r in 1..B {
        for k in 0..r {
            let f = l[r][k];
            let vk = v[k];
            for (x, y) in v[r].iter_mut().zip(vk) {
                *x -= f * y;
            }
        }
    }
}

/// `V ← D⁻¹ V` (from [`ldlt`]).
#[inline(always)]
fn scale<const B: usize, const N: usize>(l: &[[f64; B]; B], v: &mut [[f64; N]; B]) {
    for r in 0..B {
        let inv = l[r][r];
        for x in v[r].iter_mut() {
            *x *= inv;
        }
    }
}

/// `V ← L⁻ᵀ V`.
#[inline(always)]
fn backward<const B: usize, const N: usize>(l: &[[f64; B]; B], v: &mut [[f64; N]; B]) {
    for r in (0..B.saturating_sub(1)).rev() {
        for k in r + 1..B {
            let f = l[k][r];
            let vk = v[k];
            for (x, y) in v[r].iter_mut().zip(vk) {
                *x -= f * y;
            }
        }
    }
}

/// `S += Σ_r d_r⁻¹ V[r] V[r]ᵀ` on the upper triangle of `S` (`N × N`), the symmetric update
/// `Vᵀ D⁻¹ V` of [`ldlt`].
#[inline(always)]
fn add_gram<const B: usize, const N: usize>(
    l: &[[f64; B]; B],
    v: &[[f64; N]; B],
    s: &mut [[f64; N]; N],
) {
    let mut dv = *v;
    scale(l, &mut dv);
    add_at_b_upper(s, &dv, v);
}

/// `acc += Aᵀ B` for `A` (`K × M`) and `B` (`K × N`), row-major arrays: the rank-`K` updates
/// of the sweeps.
#[inline(always)]
fn add_at_b<const K: usize, const M: usize, const N: usize>(
    acc: &mut [[f64; N]; M],
    a: &[[f64; M]; K],
    b: &[[f64; N]; K],
) {
    for (p, acc_row) in acc.iter_mut().enumerate() {
        for (q, acc_pq) in acc_row.iter_mut().enumerate() {
            let mut sum = 0.0;
            for r in 0..K {
                sum += a[r][p] * b[r][q];
            }
            *acc_pq += sum;
        }
    }
}

/// [`add_at_b`] on and above the diagonal only (`M = N`), for updates known to be symmetric.
#[inline(always)]
fn add_at_b_upper<const K: usize, const N: usize>(
    acc: &mut [[f64; N]; N],
    a: &[[f64; N]; K],
    b: &[[f64; N]; K],
) {
    for p in 0..N {
        for q in p..N {
            let mut sum = 0.0;
            for r in 0..K {
                sum += a[r][p] * b[r][q];
            }
            acc[p][q] += sum;
        }
    }
}

/// In-place LU with partial pivoting of a block (`P Â = L U`, `L` unit lower, the diagonal of
/// `U` stored as its reciprocal); `false` for a zero or non-finite pivot.
#[inline(always)]
fn lu<const B: usize>(m: &mut [[f64; B]; B], perm: &mut [usize; B]) -> bool {
    for (r, p) in perm.iter_mut().enumerate() {
        *p = r;
    }
    for c in 0..B {
        let mut best = c;
        for r in c + 1..B {
            if m[r][c].abs() > m[best][c].abs() {
                best = r;
            }
        }
        if best != c {
            m.swap(best, c);
            perm.swap(best, c);
        }
        let pivot = m[c][c];
        if !(pivot != 0.0 && pivot.is_finite()) {
            return false;
        }
        let inv = 1.0 / pivot;
        m[c][c] = inv;
        for r in c + 1..B {
            let f = m[r][c] * inv;
            m[r][c] = f;
            for k in c + 1..B {
                m[r][k] -= f * m[c][k];
            }
        }
    }
    true
}

/// `V ← Â⁻¹ V` from the LU factors, for the rows `V[r]` of a `B × N` matrix.
#[inline(always)]
fn lu_solve<const B: usize, const N: usize>(
    m: &[[f64; B]; B],
    perm: &[usize; B],
    v: &mut [[f64; N]; B],
) {
    let mut t = [[0.0; N]; B];
    for r in 0..B {
        t[r] = v[perm[r]];
        for k in 0..r {
            let f = m[r][k];
            let tk = t[k];
            for (x, y) in t[r].iter_mut().zip(tk) {
                *x -= f * y;
            }
        }
    }
    for r in (0..B).rev() {
        for k in r + 1..B {
            let f = m[r][k];
            let tk = t[k];
            for (x, y) in t[r].iter_mut().zip(tk) {
                *x -= f * y;
            }
        }
        let inv = m[r][r];
        for x in t[r].iter_mut() {
            *x *= inv;
        }
    }
    *v = t;
}

/// The state carried from the tip to the base (module docs): `P`, `Z`, `Z'`, `C_x`.
struct Sweep {
    p: [[f64; 3]; 3],
    z: [[f64; 6]; 3],
    z_left: [[f64; 3]; 6],
    c_x: [[f64; 6]; 6],
}

impl Sweep {
    fn new() -> Sweep {
        Sweep { p: [[0.0; 3]; 3], z: [[0.0; 6]; 3], z_left: [[0.0; 3]; 6], c_x: [[0.0; 6]; 6] }
    }
}

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

/// `C_x` (eq. 19) and the stability verdict by the structured recursion (module docs), into
/// `data.c_x`. `k_q`: n × n, block diagonal over `layout` (entries outside the blocks are not
/// read); `j_x`: 6 × n.
pub(crate) fn compliance(
    layout: &BlockLayout,
    k_q: &ColMajor,
    gens: &KwGenerators,
    j_x: &ColMajor,
    data: &mut StructuredData,
) -> Structured {
    let n = layout.dof;
    data.backward_error = f64::NAN;
    if !layout.structured()
        || (k_q.rows(), k_q.cols()) != (n, n)
        || (j_x.rows(), j_x.cols()) != (6, n)
        || gens.len() != n
        || data.x.len() != n
        || data.factors.len() != layout.count()
    {
        return Structured::Rejected;
    }
    if !gens.symmetric {
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
        let ok = if gens.symmetric {
            dispatch!(block.len(), step_symmetric(&mut sweep, s, k_q, gens, j_x, factor))
        } else {
            dispatch!(block.len(), step_general(&mut sweep, s, k_q, gens, j_x, factor))
        };
        if !ok {
            return Structured::NotPositiveDefinite;
        }
    }
    if gens.symmetric {
        for p in 0..6 {
            for q in 0..p {
                sweep.c_x[p][q] = sweep.c_x[q][p];
            }
        }
    }
    data.c_x = sweep.c_x;
    let accepted = check(layout, gens, data);
    let finite = data.c_x.iter().flatten().all(|v| v.is_finite());
    if accepted && finite { Structured::Done } else { Structured::Rejected }
}

/// The generators and the axes of a block: `(a_j, u_j − P a_j)`.
#[inline(always)]
fn block_generators<const B: usize>(
    p: &[[f64; 3]; 3],
    s: usize,
    gens: &KwGenerators,
) -> ([[f64; 3]; B], [[f64; 3]; B]) {
    let mut a = [[0.0; 3]; B];
    let mut u_t = [[0.0; 3]; B];
    for r in 0..B {
        a[r] = gens.a(s + r);
        u_t[r] = sub3(gens.u(s + r), mul3(p, a[r]));
    }
    (a, u_t)
}

/// The right-hand side of a block: `J_kᵀ` (rows), `Ŷ_k = J_kᵀ − A_kᵀ Z` (rows), and both
/// times `ω` for the residual check.
struct Rhs<const B: usize> {
    j: [[f64; 6]; B],
    y_hat: [[f64; 6]; B],
    y_w: [f64; B],
    y_hat_w: [f64; B],
}

#[inline(always)]
fn reduced_rhs<const B: usize>(
    z: &[[f64; 6]; 3],
    a: &[[f64; 3]; B],
    s: usize,
    j_x: &ColMajor,
) -> Rhs<B> {
    let mut rhs = Rhs { j: [[0.0; 6]; B], y_hat: [[0.0; 6]; B], y_w: [0.0; B], y_hat_w: [0.0; B] };
    for r in 0..B {
        let jc = j_x.col(s + r);
        for col in 0..6 {
            let j = jc[col];
            let v = j - (a[r][0] * z[0][col] + a[r][1] * z[1][col] + a[r][2] * z[2][col]);
            rhs.j[r][col] = j;
            rhs.y_hat[r][col] = v;
            rhs.y_w[r] += CHECK_WEIGHTS[col] * j;
            rhs.y_hat_w[r] += CHECK_WEIGHTS[col] * v;
        }
    }
    rhs
}

/// One block of the symmetric sweep (`w = u`): Cholesky of `Â_k`, then the updates of `C_x`,
/// `Z` and `P` as symmetric products.
#[inline(always)]
fn step_symmetric<const B: usize>(
    st: &mut Sweep,
    s: usize,
    k_q: &ColMajor,
    gens: &KwGenerators,
    j_x: &ColMajor,
    factor: &mut BlockFactor,
) -> bool {
    let (a, u_t) = block_generators::<B>(&st.p, s, gens);
    let kq = factor.save_k_q::<B>(s, k_q);
    let mut l = [[0.0; B]; B];
    for c in 0..B {
        for r in c..B {
            l[r][c] = kq[r][c] + dot(a[c], u_t[r]);
        }
    }
    if !ldlt(&mut l) {
        return false;
    }
    // With G = L⁻¹ Ŷ_k (B × 6) and E = L⁻¹ Ũ_kᵀ (B × 3), the three updates are blocks of one
    // Gram matrix [E G]ᵀ D⁻¹ [E G]: C_x += Gᵀ D⁻¹ G (upper triangle), Z += Eᵀ D⁻¹ G,
    // P += Eᵀ D⁻¹ E (upper triangle, then mirrored).
    let rhs = reduced_rhs::<B>(&st.z, &a, s, j_x);
    let mut g = rhs.y_hat;
    forward(&l, &mut g);
    let mut e = u_t;
    forward(&l, &mut e);
    let mut dg = g;
    scale(&l, &mut dg);
    let mut de = e;
    scale(&l, &mut de);
    add_at_b_upper(&mut st.c_x, &dg, &g);
    add_at_b(&mut st.z, &de, &g);
    add_at_b_upper(&mut st.p, &de, &e);
    for p in 0..3 {
        for q in p + 1..3 {
            st.p[q][p] = st.p[p][q];
        }
    }
    factor.save(&l, &[0; B], &u_t, &rhs);
    true
}

/// One block of the verdict on the symmetric part `(A + Aᵀ)/2`: generators `(u + w)/2`, blocks
/// `(K_k + K_kᵀ)/2`, pivots and `P` only.
#[inline(always)]
fn step_symmetric_part<const B: usize>(
    p: &mut [[f64; 3]; 3],
    s: usize,
    k_q: &ColMajor,
    gens: &KwGenerators,
) -> bool {
    let mut a = [[0.0; 3]; B];
    let mut v_t = [[0.0; 3]; B];
    for r in 0..B {
        let j = s + r;
        let (u, w) = (gens.u(j), gens.w(j));
        let v = [0.5 * (u[0] + w[0]), 0.5 * (u[1] + w[1]), 0.5 * (u[2] + w[2])];
        a[r] = gens.a(j);
        v_t[r] = sub3(v, mul3(p, a[r]));
    }
    let mut l = [[0.0; B]; B];
    for c in 0..B {
        for r in c..B {
            let sym = 0.5 * (k_q.at(s + r, s + c) + k_q.at(s + c, s + r));
            l[r][c] = sym + dot(a[c], v_t[r]);
        }
    }
    if !ldlt(&mut l) {
        return false;
    }
    let mut e = v_t;
    forward(&l, &mut e);
    add_gram(&l, &e, p);
    for i in 0..3 {
        for k in 0..i {
            p[i][k] = p[k][i];
        }
    }
    true
}

/// One block of the general sweep (`w ≠ u`): LU of `Â_k` with partial pivoting, then the
/// updates of `C_x`, `Z`, `Z'` and `P`.
#[inline(always)]
fn step_general<const B: usize>(
    st: &mut Sweep,
    s: usize,
    k_q: &ColMajor,
    gens: &KwGenerators,
    j_x: &ColMajor,
    factor: &mut BlockFactor,
) -> bool {
    let (a, u_t) = block_generators::<B>(&st.p, s, gens);
    let mut w_t = [[0.0; 3]; B];
    for r in 0..B {
        w_t[r] = sub3(gens.w(s + r), mul3t(&st.p, a[r]));
    }
    let kq = factor.save_k_q::<B>(s, k_q);
    let mut m = [[0.0; B]; B];
    for c in 0..B {
        for r in 0..B {
            let kw = if c <= r { dot(a[c], w_t[r]) } else { dot(a[r], u_t[c]) };
            m[r][c] = kq[r][c] + kw;
        }
    }
    let mut perm = [0; B];
    if !lu(&mut m, &mut perm) {
        return false;
    }
    // Ĵ_k = J_k − Z' A_k (rows of its transpose), H = Â_k⁻¹ Ŷ_k, F = Â_k⁻¹ W̃_kᵀ.
    let rhs = reduced_rhs::<B>(&st.z, &a, s, j_x);
    let mut h = rhs.y_hat;
    let mut j_hat = [[0.0; 6]; B];
    for r in 0..B {
        for col in 0..6 {
            j_hat[r][col] = rhs.j[r][col] - dot(st.z_left[col], a[r]);
        }
    }
    lu_solve(&m, &perm, &mut h);
    let mut f = w_t;
    lu_solve(&m, &perm, &mut f);
    add_at_b(&mut st.c_x, &j_hat, &h);
    add_at_b(&mut st.z, &u_t, &h);
    add_at_b(&mut st.z_left, &j_hat, &f);
    add_at_b(&mut st.p, &u_t, &f);
    factor.save(&m, &perm, &w_t, &rhs);
    true
}

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
fn check(layout: &BlockLayout, gens: &KwGenerators, data: &mut StructuredData) -> bool {
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
        dispatch!(block.len(), check_block(factor, gens.symmetric, start, gens, &mut acc, rho));
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

/// Zero the entries of `m` inside the blocks of `layout`.
pub(crate) fn zero_blocks(layout: &BlockLayout, m: &mut ColMajor) {
    for block in layout.blocks() {
        for c in block.clone() {
            m.col_mut(c)[block.clone()].fill(0.0);
        }
    }
}
