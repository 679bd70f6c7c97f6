//! The sweep from the tip to the base (the recursion of [`super`]'s docs): one step per block
//! of `K_q`, symmetric (`L D Lᵀ`) or general (LU), and what each block keeps for the residual
//! check.

use sinew_statics::KwGenerators;

use super::kernels::{
    add_at_b, add_at_b_upper, add_gram, dot, forward, ldlt, lu, lu_solve, mul3, mul3t, scale, sub3,
};
use super::{CHECK_WEIGHTS, MAX_BLOCK};
use crate::colmajor::{ColMajor, mirror_upper};

/// The state carried from the tip to the base (module docs): `P`, `Z`, `Z'`, `C_x`.
pub(crate) struct Sweep {
    pub(crate) p: [[f64; 3]; 3],
    pub(crate) z: [[f64; 6]; 3],
    pub(crate) z_left: [[f64; 3]; 6],
    pub(crate) c_x: [[f64; 6]; 6],
}

impl Sweep {
    pub(crate) fn new() -> Sweep {
        Sweep { p: [[0.0; 3]; 3], z: [[0.0; 6]; 3], z_left: [[0.0; 3]; 6], c_x: [[0.0; 6]; 6] }
    }
}

/// What a block keeps for the back-substitution of the residual check.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct BlockFactor {
    /// `L D Lᵀ` factors (unit lower, `D⁻¹` on the diagonal) or LU factors (unit lower, upper
    /// with reciprocal diagonal) of `Â_k`, row-major `|B_k| × |B_k|` in the leading entries.
    factor: [f64; MAX_BLOCK * MAX_BLOCK],
    /// Row permutation of the LU factorisation.
    perm: [usize; MAX_BLOCK],
    /// `w̃_j` of the block's DOFs (`ũ_j` in the symmetric case).
    pub(crate) w_tilde: [[f64; 3]; MAX_BLOCK],
    /// `Ŷ_k ω`.
    pub(crate) y_hat: [f64; MAX_BLOCK],
    /// The block `K_k` of `K_q`, row-major.
    pub(crate) k_q: [f64; MAX_BLOCK * MAX_BLOCK],
    /// `J_kᵀ ω`.
    pub(crate) y: [f64; MAX_BLOCK],
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
    pub(crate) fn matrix<const B: usize>(&self) -> ([[f64; B]; B], [usize; B]) {
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
    j_x: &[[f64; 6]],
) -> Rhs<B> {
    let mut rhs = Rhs { j: [[0.0; 6]; B], y_hat: [[0.0; 6]; B], y_w: [0.0; B], y_hat_w: [0.0; B] };
    for r in 0..B {
        let jc = &j_x[s + r];
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
pub(crate) fn step_symmetric<const B: usize>(
    st: &mut Sweep,
    s: usize,
    k_q: &ColMajor,
    gens: &KwGenerators,
    j_x: &[[f64; 6]],
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
    let p = &mut st.p;
    mirror_upper(0..3, |i, j| p[i][j] = p[j][i]);
    factor.save(&l, &[0; B], &u_t, &rhs);
    true
}

/// One block of the verdict on the symmetric part `(A + Aᵀ)/2`: generators `(u + w)/2`, blocks
/// `(K_k + K_kᵀ)/2`, pivots and `P` only.
#[inline(always)]
pub(crate) fn step_symmetric_part<const B: usize>(
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
pub(crate) fn step_general<const B: usize>(
    st: &mut Sweep,
    s: usize,
    k_q: &ColMajor,
    gens: &KwGenerators,
    j_x: &[[f64; 6]],
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
