//! The interior-point method's problem: linear rows and linear matrix inequalities on `x`, a
//! concave objective, the multipliers, how a run stops and ends; and the certificate, which
//! bounds the optimum from any strictly feasible point and any multipliers.
//!
//! # Math
//! Maximise `φ(x) = c₀ + cᵀx + ψ(x)` (`ψ` smooth and concave, or absent) subject to
//! `s = h − G x ≥ 0` (multipliers `y`) and `S_j = F_j(x) = F_j0 + Σ_a x_a F_ja ⪰ 0`
//! (multipliers `Z_j`).
//!
//! **Certificate.** For any `y ≥ 0`, `Z ⪰ 0`, the Lagrangian
//! `L(x) = φ(x) + yᵀ(h − Gx) + Σ⟨Z_j, F_j(x)⟩` is concave and `≥ φ` on the feasible set, so with
//! `r = ∇L(x̄) = ∇φ(x̄) − Gᵀy + F*(Z)` and a box `[lo, hi]` that holds an optimum,
//!
//! ```text
//! UB = φ(x̄) + yᵀs + Σ⟨Z_j, S_j⟩ + Σ_a max(r_a (hi_a − x̄_a), r_a (lo_a − x̄_a))  ≥  max φ.
//! ```
//!
//! An epigraph variable `t` (unbounded, in one block only, not in a row) has its block's `Z`
//! scaled so that `r_t = 0` exactly. Nothing in the bound depends on how `y` and `Z` were found.

#[cfg(test)]
use crate::dense::cholesky;
use crate::dense::inner;

/// One matrix inequality `F(x) = F_0 + Σ_a x_a F_a ⪰ 0` (each n × n, row-major, symmetric).
#[derive(Debug, Clone, Default)]
pub(crate) struct Block {
    pub(crate) n: usize,
    pub(crate) constant: Vec<f64>,
    /// One per variable; `None` where the block does not depend on it.
    pub(crate) coefficients: Vec<Option<Vec<f64>>>,
    /// The same coefficients as congruences of small blocks, where the block has them (a
    /// stiffness floor of the decoupled model); only the Schur terms read them.
    pub(crate) factors: Option<Factors>,
    /// The buffers of earlier coefficients, for [`Block::fresh`].
    pub(crate) spare: Vec<Vec<f64>>,
}

/// Coefficients `F_a = R_aᵀ B_a R_a`, `R_a` the rows `span_a` of a basis `R` (q × n,
/// row-major) and `B_a` symmetric, |span_a| × |span_a|: a floor's `Rᵀ A_a R` with `A_a` one
/// joint's 2 × 2 block, or the epigraph's `Pᵀ B P` on three rows `P = J_p R` appended below
/// the DOFs' (so `q` is the DOFs plus 3). With them the Schur terms need `R Z Rᵀ` and
/// `R S⁻¹ Rᵀ` once an iteration, not two n × n products per coefficient (`block_work.rs`).
#[derive(Debug, Clone)]
pub(crate) struct Factors {
    pub(crate) basis: Vec<f64>,
    pub(crate) q: usize,
    /// Per coefficient: `(span_a, B_a)`, or `None` where it is not factored (used whole).
    pub(crate) small: Vec<Option<(std::ops::Range<usize>, Vec<f64>)>>,
}

impl Block {
    /// The block emptied for `count` variables, n × n, its constant zero: every coefficient
    /// `None`, their buffers kept for [`Block::fresh`] (so that refilling a block of the same
    /// shape allocates nothing).
    pub(crate) fn recycle(&mut self, n: usize, count: usize) {
        self.n = n;
        self.constant.clear();
        self.constant.resize(n * n, 0.0);
        self.spare.extend(self.coefficients.drain(..).flatten());
        self.coefficients.resize(count, None);
        self.factors = None;
    }

    /// A zero buffer of `len` entries, an earlier coefficient's where there is one.
    pub(crate) fn fresh(&mut self, len: usize) -> Vec<f64> {
        let mut v = self.spare.pop().unwrap_or_default();
        v.clear();
        v.resize(len, 0.0);
        v
    }

    /// `F(x)` into `out`.
    pub(crate) fn at(&self, x: &[f64], out: &mut [f64]) {
        out.copy_from_slice(&self.constant);
        for (xa, fa) in x.iter().zip(&self.coefficients) {
            if let Some(fa) = fa {
                for (o, f) in out.iter_mut().zip(fa) {
                    *o += xa * f;
                }
            }
        }
    }
}

/// The problem: maximise `c₀ + cᵀx + ψ(x)` over rows and blocks; `[lo, hi]` bounds an optimum.
#[derive(Debug, Clone, Default)]
pub(crate) struct Sdp {
    pub(crate) c0: f64,
    pub(crate) c: Vec<f64>,
    /// `G`, rows × vars, row-major.
    pub(crate) rows: Vec<f64>,
    pub(crate) rhs: Vec<f64>,
    pub(crate) blocks: Vec<Block>,
    pub(crate) lo: Vec<f64>,
    pub(crate) hi: Vec<f64>,
    /// `(variable, block)` of an epigraph variable.
    pub(crate) epigraph: Option<(usize, usize)>,
    /// Earlier blocks, for [`Sdp::next_block`].
    pub(crate) spare: Vec<Block>,
}

impl Sdp {
    /// Every block moved to the spares (their buffers kept), the epigraph removed.
    pub(crate) fn clear_blocks(&mut self) {
        // Last first: the next `next_block` returns the earlier first block.
        while let Some(b) = self.blocks.pop() {
            self.spare.push(b);
        }
        self.epigraph = None;
    }

    /// A block to fill ([`Block::recycle`]) and push: an earlier one where there is one.
    pub(crate) fn next_block(&mut self) -> Block {
        self.spare.pop().unwrap_or_default()
    }

    pub(crate) fn vars(&self) -> usize {
        self.c.len()
    }

    pub(crate) fn row_count(&self) -> usize {
        self.rhs.len()
    }

    /// `h − G x` into `s`.
    pub(crate) fn slacks(&self, x: &[f64], s: &mut [f64]) {
        let k = self.vars();
        for (r, si) in s.iter_mut().enumerate() {
            let g = &self.rows[r * k..r * k + k];
            *si = self.rhs[r] - g.iter().zip(x).map(|(a, b)| a * b).sum::<f64>();
        }
    }
}

/// A smooth concave part `ψ` of the objective.
pub(crate) trait Smooth {
    /// `ψ(x)`, its gradient and its Hessian (vars × vars, ⪯ 0); `None` outside its domain.
    fn evaluate(&mut self, x: &[f64], gradient: &mut [f64], hessian: &mut [f64]) -> Option<f64>;
}

/// How a run stops.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Settings {
    /// Stop at `UB − φ ≤ relative_gap · max(|φ|, scale)`.
    pub(crate) relative_gap: f64,
    pub(crate) scale: f64,
    pub(crate) max_iterations: usize,
    /// Stop as soon as `φ ≥ target` (a feasibility phase) and `φ − target` is at least
    /// `centring` of `UB − target` (so that the point is well inside, not on the target's
    /// boundary), or at the optimum when it is above the target; or when `UB < target`.
    pub(crate) target: Option<f64>,
    pub(crate) centring: f64,
}

/// The multipliers `y` (rows) and `Z_j` (blocks).
#[derive(Debug, Clone, Default)]
pub(crate) struct Duals {
    pub(crate) y: Vec<f64>,
    pub(crate) z: Vec<Vec<f64>>,
    /// Earlier blocks' `Z` buffers ([`resize_pooled`]).
    pub(crate) spare: Vec<Vec<f64>>,
}

/// How a run ended: the last iterate's value, its certified bound, the iterations (the iterate
/// itself is the run's workspace's, `SolveWork::x` in `sdp.rs`).
#[derive(Debug, Clone)]
pub(crate) struct Run {
    pub(crate) value: f64,
    pub(crate) upper: f64,
    pub(crate) iterations: usize,
    pub(crate) end: End,
}

/// Why a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum End {
    /// The gap closed.
    Optimum,
    /// `φ ≥ target`.
    Reached,
    /// `UB < target`.
    Unreachable,
    /// The iterations ran out.
    NotConverged,
    /// The iterate left the interior or the objective's domain (numerical breakdown).
    Breakdown,
}

/// The certified upper bound at `x` with `(y, Z)` (module docs), given the slacks `s` and the
/// blocks' values `S_j` (row-major). `known(a, j)` is `⟨Z_j, F_ja⟩` where the caller has it
/// at less cost than the n × n inner product (a factored block's `tr(B_a (R Z Rᵀ)[s_a, s_a])`,
/// `block_work.rs`), else `None`. Inlined into the run, so that its inner products get the
/// run's vector instructions (`sdp.rs`).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn upper_bound<'m>(
    sdp: &Sdp,
    x: &[f64],
    value: f64,
    gradient: &[f64],
    s: &[f64],
    slack_matrices: impl Iterator<Item = &'m [f64]>,
    duals: &Duals,
    known: impl Fn(usize, usize) -> Option<f64>,
) -> f64 {
    let k = sdp.vars();
    let dual_term = |a: usize, j: usize, z: &[f64]| -> f64 {
        sdp.blocks[j].coefficients[a]
            .as_ref()
            .map_or(0.0, |f| known(a, j).unwrap_or_else(|| inner(f, z)))
    };
    // The epigraph block's scale κ (every other block's is 1).
    let mut epigraph = None;
    if let Some((t, j)) = sdp.epigraph {
        let d = dual_term(t, j, &duals.z[j]);
        let kappa = -gradient[t] / d;
        if !(kappa.is_finite() && kappa > 0.0) {
            return f64::INFINITY;
        }
        epigraph = Some((j, kappa));
    }
    let scale = |j: usize| match epigraph {
        Some((e, kappa)) if e == j => kappa,
        _ => 1.0,
    };
    let mut bound = value + duals.y.iter().zip(s).map(|(a, b)| a * b).sum::<f64>();
    for (j, m) in slack_matrices.enumerate() {
        bound += scale(j) * inner(&duals.z[j], m);
    }
    for a in 0..k {
        if sdp.epigraph.is_some_and(|(t, _)| t == a) {
            continue;
        }
        let mut r = gradient[a];
        for (row, y) in duals.y.iter().enumerate() {
            r -= sdp.rows[row * k + a] * y;
        }
        for j in 0..sdp.blocks.len() {
            r += scale(j) * dual_term(a, j, &duals.z[j]);
        }
        if r == 0.0 {
            continue;
        }
        let term = (r * (sdp.hi[a] - x[a])).max(r * (sdp.lo[a] - x[a]));
        if !term.is_finite() {
            return f64::INFINITY;
        }
        bound += term;
    }
    bound
}

/// The certified bound at a strictly feasible `x` with any `y ≥ 0`, `Z ⪰ 0` (module docs),
/// given `φ(x)` and `∇φ(x)`; `None` when `x` is not strictly feasible.
#[cfg(test)]
pub(crate) fn bound_at(
    sdp: &Sdp,
    x: &[f64],
    value: f64,
    gradient: &[f64],
    duals: &Duals,
) -> Option<f64> {
    let mut s = vec![0.0; sdp.row_count()];
    sdp.slacks(x, &mut s);
    let matrices: Vec<Vec<f64>> = sdp
        .blocks
        .iter()
        .map(|b| {
            let mut m = vec![0.0; b.n * b.n];
            b.at(x, &mut m);
            m
        })
        .collect();
    let inside = s.iter().all(|v| *v >= 0.0)
        && sdp.blocks.iter().zip(&matrices).all(|(b, m)| cholesky(&mut m.clone(), b.n));
    let refs = matrices.iter().map(Vec::as_slice);
    inside.then(|| upper_bound(sdp, x, value, gradient, &s, refs, duals, |_, _| None))
}

/// Multipliers on the central path at `x`, `y = μ/s`, `Z_j = μ S_j⁻¹`, with `μ` the
/// least-squares fit of stationarity `∇φ + μ (−Gᵀ(1/s) + F*(S⁻¹)) = 0` (floored at a small
/// positive value), into `duals` (its buffers reused). `s_inverse(j)` is `S_j⁻¹`; `b` and
/// `g` are scratch of the variables' length. An epigraph block gets its own `μ_t`, the one
/// that makes the epigraph variable's stationarity exact (`∂φ/∂t + μ_t ⟨F_t, S⁻¹⟩ = 0`); the
/// fit is then over the other coordinates.
#[allow(clippy::too_many_arguments)]
pub(crate) fn centred_duals<'w>(
    sdp: &Sdp,
    gradient: &[f64],
    s: &[f64],
    s_inverse: impl Fn(usize) -> &'w [f64],
    value: f64,
    scale: f64,
    (b, g): (&mut [f64], &mut [f64]),
    duals: &mut Duals,
) {
    let k = sdp.vars();
    let mut own = None;
    if let Some((t, j)) = sdp.epigraph {
        let d = sdp.blocks[j].coefficients[t].as_ref().map_or(0.0, |f| inner(f, s_inverse(j)));
        let mu_t = -gradient[t] / d;
        if mu_t.is_finite() && mu_t > 0.0 {
            own = Some((j, mu_t));
        }
    }
    let own_of = |j: usize| own.and_then(|(e, mu_t)| (e == j).then_some(mu_t));
    b.fill(0.0);
    g.copy_from_slice(gradient);
    for (r, sr) in s.iter().enumerate() {
        for a in 0..k {
            b[a] -= sdp.rows[r * k + a] / sr;
        }
    }
    for (j, blk) in sdp.blocks.iter().enumerate() {
        let w = s_inverse(j);
        for a in 0..k {
            if let Some(fa) = &blk.coefficients[a] {
                match own_of(j) {
                    Some(mu_t) => g[a] += mu_t * inner(fa, w),
                    None => b[a] += inner(fa, w),
                }
            }
        }
    }
    if let Some((t, _)) = sdp.epigraph {
        b[t] = 0.0;
        g[t] = 0.0;
    }
    let bb: f64 = b.iter().map(|v| v * v).sum();
    let gb: f64 = b.iter().zip(g.iter()).map(|(x, y)| x * y).sum();
    let nu = (s.len() + sdp.blocks.iter().map(|b| b.n).sum::<usize>()) as f64;
    let floor = 1e-3 * value.abs().max(scale) / nu.max(1.0);
    let mu = if bb > 0.0 { (-gb / bb).max(floor) } else { floor };
    duals.y.clear();
    duals.y.extend(s.iter().map(|v| mu / v));
    resize_pooled(&mut duals.z, &mut duals.spare, sdp.blocks.len());
    for (j, z) in duals.z.iter_mut().enumerate() {
        let m = own_of(j).unwrap_or(mu);
        z.clear();
        z.extend(s_inverse(j).iter().map(|v| m * v));
    }
}

/// `v` to `len` entries: those cut go to `spare`, those added come from it (or are new), so
/// that a buffer keeps its place and its room from one run to the next.
pub(crate) fn resize_pooled<T: Default>(v: &mut Vec<T>, spare: &mut Vec<T>, len: usize) {
    while v.len() > len {
        spare.extend(v.pop());
    }
    while v.len() < len {
        v.push(spare.pop().unwrap_or_default());
    }
}
