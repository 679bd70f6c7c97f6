//! The per-block state of an interior-point run (`sdp.rs`) and the kernels that work on
//! it: the HKM product `sym(A B C)`, the Schur complement's block terms, the step lengths by
//! Cholesky trials, and the matrix step `ΔF = Σ_a Δx_a F_a`. Module docs of `sdp.rs` for the
//! math.

use crate::dense::{axpy, cholesky_whole, dot};
use crate::program::{Block, Duals, resize_pooled};

/// Per-block state of a run: the slack, its factor and inverse, the directions, scratch, and
/// per coefficient `F_a` the rows where it is not zero with the products `F_a Z` and `S⁻¹ F_a`
/// of the Schur complement (module docs). Sized once per run ([`BlockWork::reset`], in the
/// buffers of the last run); nothing per iteration.
#[derive(Debug, Default)]
pub(crate) struct BlockWork {
    pub(crate) n: usize,
    pub(crate) s: Vec<f64>,
    pub(crate) l: Vec<f64>,
    pub(crate) s_inv: Vec<f64>,
    pub(crate) ds: Vec<f64>,
    pub(crate) dz: Vec<f64>,
    pub(crate) dz_aff: Vec<f64>,
    pub(crate) ds_aff: Vec<f64>,
    pub(crate) t1: Vec<f64>,
    pub(crate) t2: Vec<f64>,
    pub(crate) product: Vec<f64>,
    pub(crate) correction: Vec<f64>,
    pub(crate) trial: Vec<f64>,
    /// Per coefficient, the rows where it is not zero (empty where the block does not depend
    /// on the variable: `Block::coefficients[a]` is `None`).
    pub(crate) supports: Vec<Vec<usize>>,
    /// Per coefficient: more than half its rows non-zero.
    pub(crate) dense: Vec<bool>,
    /// A sparse coefficient's `F_a[S_a, S_a]` (|S_a| × |S_a|).
    pub(crate) sub: Vec<Vec<f64>>,
    pub(crate) fz: Vec<Vec<f64>>,
    pub(crate) sf: Vec<Vec<f64>>,
    /// A factored block's (`Block::factors`) `R X` scratch (q × n), `R Z Rᵀ` and `R S⁻¹ Rᵀ`
    /// (q × q), and per unfactored coefficient `R (Z F_a S⁻¹) Rᵀ` (q × q).
    pub(crate) rx: Vec<f64>,
    pub(crate) rzr: Vec<f64>,
    pub(crate) rsr: Vec<f64>,
    pub(crate) rqr: Vec<Vec<f64>>,
    /// Buffers of coefficients beyond this block's count, kept ([`resize_pooled`]).
    spare: Vec<Vec<f64>>,
    spare_rows: Vec<Vec<usize>>,
}

impl BlockWork {
    /// The state of a run on `b`, in these buffers (no allocation once they have the room).
    pub(crate) fn reset(&mut self, b: &Block) {
        let n = b.n;
        self.n = n;
        for v in [
            &mut self.s,
            &mut self.l,
            &mut self.s_inv,
            &mut self.ds,
            &mut self.dz,
            &mut self.dz_aff,
            &mut self.ds_aff,
            &mut self.t1,
            &mut self.t2,
            &mut self.product,
            &mut self.correction,
            &mut self.trial,
        ] {
            sized(v, n * n);
        }
        let count = b.coefficients.len();
        resize_pooled(&mut self.supports, &mut self.spare_rows, count);
        self.dense.clear();
        for (f, rows) in b.coefficients.iter().zip(&mut self.supports) {
            rows.clear();
            if let Some(f) = f {
                rows.extend((0..n).filter(|r| f[r * n..r * n + n].iter().any(|v| *v != 0.0)));
            }
            self.dense.push(2 * rows.len() > n);
        }
        for v in [&mut self.sub, &mut self.fz, &mut self.sf, &mut self.rqr] {
            resize_pooled(v, &mut self.spare, count);
        }
        for (a, f) in b.coefficients.iter().enumerate() {
            let sub = &mut self.sub[a];
            sub.clear();
            if let Some(f) = f
                && !self.dense[a]
            {
                let rows = &self.supports[a];
                sub.extend(rows.iter().flat_map(|&r| rows.iter().map(move |&c| f[r * n + c])));
            }
        }
        // A factored block (`Block::factors`) uses its factored coefficients' `F_a Z` and
        // `S⁻¹ F_a` nowhere: the products and `R (Z F_a S⁻¹) Rᵀ` only for the others.
        let q = b.factors.as_ref().map_or(0, |f| f.q);
        for a in 0..count {
            let whole = b.coefficients[a].is_some()
                && b.factors.as_ref().is_none_or(|f| f.small.get(a).is_none_or(Option::is_none));
            sized(&mut self.fz[a], if whole { n * n } else { 0 });
            sized(&mut self.sf[a], if whole { n * n } else { 0 });
            sized(&mut self.rqr[a], if whole && b.factors.is_some() { q * q } else { 0 });
        }
        sized(&mut self.rx, q * n);
        sized(&mut self.rzr, q * q);
        sized(&mut self.rsr, q * q);
    }
}

/// `v` as `len` zeros, in its buffer.
fn sized(v: &mut Vec<f64>, len: usize) {
    v.clear();
    v.resize(len, 0.0);
}

/// `out = sym(a b c)` (all n × n, `b` and `c` symmetric), `tmp` scratch.
#[inline(always)]
pub(crate) fn sym_product(
    a: &[f64],
    b: &[f64],
    c: &[f64],
    n: usize,
    tmp: &mut [f64],
    out: &mut [f64],
) {
    crate::dense::multiply_fast(a, b, n, tmp);
    crate::dense::multiply_fast(tmp, c, n, out);
    crate::dense::symmetrise(out, n);
}

/// The largest `α ≤ 1` at 95 % of the way to the boundary of `v + α dv > 0` and of every
/// `M_j + α dM_j ≻ 0` (Cholesky trials, each stopping at its first non-positive pivot; `M_j`
/// and `dM_j` stored whole, as the run's matrices are).
///
/// A full step is tried first; where it fails, the step is shortened by 0.8 until a trial
/// passes. With `refine`, the bracket `[pass, fail]` is then bisected (geometrically) to
/// within [`REFINED`]. Stopping at the first pass wastes up to a fifth of the step, and a
/// step of 0.8 cuts `μ` only fivefold: the 50-DOF least-stiffness plan took 11 iterations so,
/// 9 with the corrector's steps refined. The predictor's steps only set the centring `σ`, and
/// refining them costs more trials than it saves (docs/performance.md, session 18).
#[inline(always)]
pub(crate) fn step_length(
    v: &[f64],
    dv: &[f64],
    blocks: &mut [BlockWork],
    matrices: impl Fn(&BlockWork) -> (&[f64], &[f64]),
    refine: bool,
) -> f64 {
    const FRACTION: f64 = 0.95;
    let mut alpha = 1.0 / FRACTION;
    for (a, d) in v.iter().zip(dv) {
        if *d < 0.0 {
            alpha = alpha.min(-a / d);
        }
    }
    let mut inside = |alpha: f64| {
        blocks.iter_mut().all(|w| {
            let mut trial = std::mem::take(&mut w.trial);
            let (m, dm) = matrices(w);
            for ((t, a), b) in trial.iter_mut().zip(m).zip(dm) {
                *t = a + alpha * b;
            }
            let ok = cholesky_whole(&mut trial, w.n, false);
            w.trial = trial;
            ok
        })
    };
    if inside(alpha) {
        return FRACTION * alpha;
    }
    let mut fail = alpha;
    for _ in 0..60 {
        alpha *= 0.8;
        if inside(alpha) {
            while refine && fail > REFINED * alpha {
                let middle = (alpha * fail).sqrt();
                if inside(middle) {
                    alpha = middle;
                } else {
                    fail = middle;
                }
            }
            return FRACTION * alpha;
        }
        fail = alpha;
    }
    0.0
}

/// The ratio to which [`step_length`] brackets the boundary: two bisections of a bracket
/// `[0.8 a, a]`.
const REFINED: f64 = 1.06;

/// The Schur complement's block terms `M_ab += tr(F_a Z F_b S⁻¹)`, upper triangle mirrored
/// (`M` is symmetric). A coefficient is *sparse* when at most half its rows are non-zero (a
/// decoupled arm's `A_i`: one 2 × 2 joint block); a symmetric `F_a` is then zero outside
/// `S_a × S_a`, `S_a` its rows, and kept as that sub-block. With `(F_a Z)` on the rows `S_a`:
///
/// - one of the pair dense, say `F_d`: `M = Σ_{r ∈ S_s} ⟨(S⁻¹ F_d)_r, (F_s Z)_r⟩`;
/// - both sparse: `M = Σ_{i ∈ S_a, l ∈ S_b} S⁻¹_li Σ_{k ∈ S_b} (F_a Z)_ik (F_b)_kl`,
///   `O(|S_a| |S_b|²)`: a handful of products for 2 × 2 joint blocks.
#[inline(always)]
pub(crate) fn add_block_schur(
    b: &Block,
    z: &[f64],
    w: &mut BlockWork,
    k: usize,
    schur: &mut [f64],
) {
    if let Some(factors) = &b.factors {
        add_factored_schur(b, factors, z, w, k, schur);
        return;
    }
    let n = b.n;
    let s_inv = &w.s_inv;
    for (a, fa) in b.coefficients.iter().enumerate() {
        let Some(fa) = fa else { continue };
        let rows = &w.supports[a];
        let (fz, sf) = (&mut w.fz[a], &mut w.sf[a]);
        if w.dense[a] {
            // Mostly dense (a routed arm's A_i): two matrix products.
            crate::dense::multiply_fast(fa, z, n, fz);
            crate::dense::multiply_fast(s_inv, fa, n, sf);
            continue;
        }
        let (sub, m) = (&w.sub[a], rows.len());
        for (i, &r) in rows.iter().enumerate() {
            let out = &mut fz[r * n..r * n + n];
            out.fill(0.0);
            for (j, &q) in rows.iter().enumerate() {
                axpy(sub[i * m + j], &z[q * n..q * n + n], out);
            }
        }
    }
    let present = |a: usize| b.coefficients.get(a).is_some_and(Option::is_some);
    for a in 0..k {
        if !present(a) {
            continue;
        }
        let rows_a = &w.supports[a];
        for bb in a..k {
            if !present(bb) {
                continue;
            }
            let rows_b = &w.supports[bb];
            let m = match (w.dense[a], w.dense[bb]) {
                (_, true) => pair_dense(n, rows_a, &w.sf[bb], &w.fz[a]),
                (true, false) => pair_dense(n, rows_b, &w.sf[a], &w.fz[bb]),
                (false, false) => {
                    let (fz, sub, mb) = (&w.fz[a], &w.sub[bb], rows_b.len());
                    let mut m = 0.0;
                    for &i in rows_a {
                        for (l, &ql) in rows_b.iter().enumerate() {
                            let mut v = 0.0;
                            for (kk, &qk) in rows_b.iter().enumerate() {
                                v += fz[i * n + qk] * sub[kk * mb + l];
                            }
                            m += s_inv[ql * n + i] * v;
                        }
                    }
                    m
                }
            };
            schur[a * k + bb] += m;
            if bb != a {
                schur[bb * k + a] += m;
            }
        }
    }
}

/// A factored block's (`Block::factors`) `W = R Z Rᵀ` into `w.rzr`, for its dual terms
/// ([`factored_dual_term`]) and its Schur terms ([`add_block_schur`], which needs it from
/// the same `Z`); nothing for another block.
#[inline(always)]
pub(crate) fn dual_congruence(b: &Block, z: &[f64], w: &mut BlockWork) {
    if let Some(factors) = &b.factors {
        congruent(&factors.basis, z, factors.q, b.n, &mut w.rx, &mut w.rzr);
    }
}

/// `⟨Z, F_a⟩ = tr(B_a W[s_a, s_a])` for a factored coefficient `F_a = R_aᵀ B_a R_a`, from
/// [`dual_congruence`]'s `W = R Z Rᵀ`: `O(|s_a|²)` instead of the n × n inner product.
/// `None` where the coefficient is not factored.
#[inline(always)]
pub(crate) fn factored_dual_term(b: &Block, w: &BlockWork, a: usize) -> Option<f64> {
    let factors = b.factors.as_ref()?;
    let (span, small) = factors.small.get(a)?.as_ref()?;
    Some(diagonal_form(span, small, &w.rzr, factors.q))
}

/// [`add_block_schur`] for a block with factored coefficients `F_a = R_aᵀ B_a R_a`
/// ([`crate::program::Factors`]). With `W = R Z Rᵀ`, `V = R S⁻¹ Rᵀ` and, per unfactored
/// coefficient `F_d`, `G_d = R (Z F_d S⁻¹) Rᵀ`:
///
/// - both factored: `tr(F_a Z F_b S⁻¹) = tr(B_a W[s_a, s_b] B_b V[s_b, s_a])`;
/// - one factored: `tr(F_a Z F_d S⁻¹) = tr(B_a G_d[s_a, s_a])`;
/// - neither: the dense products, as [`add_block_schur`] does.
///
/// `O(q n² + q² n)` once, then `O(|s|³)` per pair, instead of two n × n products per
/// coefficient.
#[inline(always)]
fn add_factored_schur(
    b: &Block,
    factors: &crate::program::Factors,
    z: &[f64],
    w: &mut BlockWork,
    k: usize,
    schur: &mut [f64],
) {
    let (n, q, r) = (b.n, factors.q, &factors.basis);
    congruent(r, &w.s_inv, q, n, &mut w.rx, &mut w.rsr);
    let small = |a: usize| factors.small.get(a).and_then(Option::as_ref);
    for (a, fa) in b.coefficients.iter().enumerate() {
        let Some(fa) = fa else { continue };
        if small(a).is_some() {
            continue;
        }
        crate::dense::multiply_fast(fa, z, n, &mut w.fz[a]);
        crate::dense::multiply_fast(&w.s_inv, fa, n, &mut w.sf[a]);
        // Z F_d S⁻¹ = (F_d Z)ᵀ S⁻¹, into t1; then R (·) Rᵀ.
        {
            use faer::{Accum, MatMut, MatRef, Par};
            let fz = MatRef::from_row_major_slice(&w.fz[a][..n * n], n, n);
            let s_inv = MatRef::from_row_major_slice(&w.s_inv[..n * n], n, n);
            let t = MatMut::from_row_major_slice_mut(&mut w.t1[..n * n], n, n);
            faer::linalg::matmul::matmul(t, Accum::Replace, fz.transpose(), s_inv, 1.0, Par::Seq);
        }
        congruent(r, &w.t1, q, n, &mut w.rx, &mut w.rqr[a]);
    }
    for a in 0..k {
        if b.coefficients.get(a).is_none_or(Option::is_none) {
            continue;
        }
        for bb in a..k {
            if b.coefficients.get(bb).is_none_or(Option::is_none) {
                continue;
            }
            let m = match (small(a), small(bb)) {
                (Some((sa, ba)), Some((sb, bbb))) => {
                    factored_pair((sa, ba), (sb, bbb), &w.rzr, &w.rsr, q)
                }
                (Some((sa, ba)), None) => diagonal_form(sa, ba, &w.rqr[bb], q),
                (None, Some((sb, bbb))) => diagonal_form(sb, bbb, &w.rqr[a], q),
                (None, None) => {
                    (0..n).map(|row| dot(&w.sf[bb][row * n..][..n], &w.fz[a][row * n..][..n])).sum()
                }
            };
            schur[a * k + bb] += m;
            if bb != a {
                schur[bb * k + a] += m;
            }
        }
    }
}

/// `out = R X Rᵀ` (R q × n, X n × n, both row-major; `rx` q × n scratch): two products by
/// faer's kernels (the blocks factored are above the fixed-size kernels' sizes).
#[inline(always)]
fn congruent(r: &[f64], x: &[f64], q: usize, n: usize, rx: &mut [f64], out: &mut [f64]) {
    use faer::linalg::matmul::matmul;
    use faer::{Accum, MatMut, MatRef, Par};
    let r = MatRef::from_row_major_slice(&r[..q * n], q, n);
    let x = MatRef::from_row_major_slice(&x[..n * n], n, n);
    let mut rx = MatMut::from_row_major_slice_mut(&mut rx[..q * n], q, n);
    matmul(rx.as_mut(), Accum::Replace, r, x, 1.0, Par::Seq);
    let out = MatMut::from_row_major_slice_mut(&mut out[..q * q], q, q);
    matmul(out, Accum::Replace, rx.as_ref(), r.transpose(), 1.0, Par::Seq);
}

/// `tr(B_a W[s_a, s_b] B_b V[s_b, s_a])` (`W`, `V` q × q).
#[inline(always)]
fn factored_pair(
    (sa, ba): (&std::ops::Range<usize>, &Vec<f64>),
    (sb, bb): (&std::ops::Range<usize>, &Vec<f64>),
    w: &[f64],
    v: &[f64],
    q: usize,
) -> f64 {
    let (ma, mb) = (sa.len(), sb.len());
    let mut total = 0.0;
    // Σ_{i,k} (B_a W[s_a, s_b])_{ik} (B_b V[s_b, s_a])_{ki}
    for i in 0..ma {
        for kk in 0..mb {
            let left: f64 =
                (0..ma).map(|j| ba[i * ma + j] * w[(sa.start + j) * q + sb.start + kk]).sum();
            let right: f64 =
                (0..mb).map(|l| bb[kk * mb + l] * v[(sb.start + l) * q + sa.start + i]).sum();
            total += left * right;
        }
    }
    total
}

/// `tr(B G[s, s]) = Σ_{i,j} B_ij G[s_j, s_i]` (`G` q × q).
#[inline(always)]
fn diagonal_form(s: &std::ops::Range<usize>, b: &[f64], g: &[f64], q: usize) -> f64 {
    let m = s.len();
    let mut total = 0.0;
    for i in 0..m {
        for j in 0..m {
            total += b[i * m + j] * g[(s.start + j) * q + s.start + i];
        }
    }
    total
}

/// `Σ_{r ∈ rows} ⟨sf_r, fz_r⟩` (rows of n).
#[inline(always)]
fn pair_dense(n: usize, rows: &[usize], sf: &[f64], fz: &[f64]) -> f64 {
    rows.iter().map(|&r| dot(&sf[r * n..r * n + n], &fz[r * n..r * n + n])).sum()
}

/// Copy each block's `Z` into its `t2` (for the dual step-length trials).
#[inline(always)]
pub(crate) fn zs(works: &mut [BlockWork], duals: &Duals) {
    for (w, z) in works.iter_mut().zip(&duals.z) {
        w.t2.copy_from_slice(z);
    }
}

/// `ΔF = Σ_a dx_a F_a` into `out`.
#[inline(always)]
pub(crate) fn matrix_step(b: &Block, dx: &[f64], out: &mut [f64]) {
    out.fill(0.0);
    for (d, fa) in dx.iter().zip(&b.coefficients) {
        if let Some(fa) = fa {
            axpy(*d, fa, out);
        }
    }
}

#[cfg(test)]
mod tests;
