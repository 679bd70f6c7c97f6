//! A small primal–dual interior-point method for a concave objective under linear rows and
//! linear matrix inequalities, with Mehrotra's predictor–corrector and the HKM direction, and
//! the method-independent certificate of every iterate.
//!
//! # Math
//! Maximise `φ(x) = c₀ + cᵀx + ψ(x)` (`ψ` smooth and concave, or absent) subject to
//! `s = h − G x ≥ 0` (multipliers `y`) and `S_j = F_j(x) = F_j0 + Σ_a x_a F_ja ⪰ 0`
//! (multipliers `Z_j`). With `μ = (sᵀy + Σ⟨S_j, Z_j⟩)/ν`, `ν = rows + Σ n_j`, the Newton
//! step towards the central point `s∘y = σμ`, `S Z = σμ I` (symmetrised as HKM does:
//! `ΔZ = σμ S⁻¹ − Z − sym(Z ΔS S⁻¹)`) reduces to the Schur system
//!
//! ```text
//! (−∇²ψ + Gᵀ diag(y/s) G + Σ_j M_j) Δx = ∇φ − σμ Gᵀ(1/s) + σμ F*(S⁻¹),
//! (M_j)_ab = tr(F_ja Z_j F_jb S_j⁻¹),   F*(W)_a = Σ_j ⟨F_ja, W_j⟩,
//! ```
//!
//! solved by Cholesky. The predictor takes `σ = 0`; `σ = (μ_aff/μ)³` and the second-order
//! terms `Δs∘Δy` and `sym(ΔZ ΔS S⁻¹)` of the predictor enter the corrector (Mehrotra). Step
//! lengths are found by Cholesky trials, 95 % of the way to the boundary. The primal iterate
//! stays strictly feasible (every phase starts from such a point), so `s` and `S` are functions
//! of `x`.
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

use crate::dense::{cholesky, cholesky_inverse, cholesky_solve, inner, multiply};

/// One matrix inequality `F(x) = F_0 + Σ_a x_a F_a ⪰ 0` (each n × n, row-major, symmetric).
#[derive(Debug, Clone)]
pub(crate) struct Block {
    pub(crate) n: usize,
    pub(crate) constant: Vec<f64>,
    /// One per variable; `None` where the block does not depend on it.
    pub(crate) coefficients: Vec<Option<Vec<f64>>>,
}

impl Block {
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
#[derive(Debug, Clone)]
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
}

impl Sdp {
    pub(crate) fn vars(&self) -> usize {
        self.c.len()
    }

    fn row_count(&self) -> usize {
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
}

/// How a run ended: the last iterate, its value, its certified bound, the iterations.
#[derive(Debug, Clone)]
pub(crate) struct Run {
    pub(crate) x: Vec<f64>,
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

/// Per-block state of an iteration.
struct BlockWork {
    s: Vec<f64>,
    l: Vec<f64>,
    s_inv: Vec<f64>,
    ds: Vec<f64>,
    dz: Vec<f64>,
    dz_aff: Vec<f64>,
    ds_aff: Vec<f64>,
    t1: Vec<f64>,
    t2: Vec<f64>,
    trial: Vec<f64>,
}

impl BlockWork {
    fn new(n: usize) -> BlockWork {
        let z = || vec![0.0; n * n];
        BlockWork {
            s: z(),
            l: z(),
            s_inv: z(),
            ds: z(),
            dz: z(),
            dz_aff: z(),
            ds_aff: z(),
            t1: z(),
            t2: z(),
            trial: z(),
        }
    }
}

/// `out = sym(a b c)` (all n × n), `tmp` scratch.
fn sym_product(a: &[f64], b: &[f64], c: &[f64], n: usize, tmp: &mut [f64], out: &mut [f64]) {
    multiply(a, b, n, tmp);
    multiply(tmp, c, n, out);
    crate::dense::symmetrise(out, n);
}

/// The largest `α ≤ 1` at 95 % of the way to the boundary of `v + α dv > 0` and of every
/// `M_j + α dM_j ≻ 0` (Cholesky trials).
fn step_length(
    v: &[f64],
    dv: &[f64],
    blocks: &mut [BlockWork],
    sizes: &[usize],
    matrices: impl Fn(&BlockWork) -> (&[f64], &[f64]),
) -> f64 {
    const FRACTION: f64 = 0.95;
    let mut alpha = 1.0 / FRACTION;
    for (a, d) in v.iter().zip(dv) {
        if *d < 0.0 {
            alpha = alpha.min(-a / d);
        }
    }
    for _ in 0..60 {
        let ok = (0..blocks.len()).all(|j| {
            let n = sizes[j];
            let w = &mut blocks[j];
            let (m, dm) = matrices(w);
            let trial: Vec<f64> = m.iter().zip(dm).map(|(a, b)| a + alpha * b).collect();
            w.trial.copy_from_slice(&trial);
            cholesky(&mut w.trial, n)
        });
        if ok {
            return FRACTION * alpha;
        }
        alpha *= 0.8;
    }
    0.0
}

/// The certified upper bound at `x` with `(y, Z)` (module docs); `z_scale` out: the factor of
/// the epigraph block's `Z`.
fn upper_bound(
    sdp: &Sdp,
    x: &[f64],
    value: f64,
    gradient: &[f64],
    s: &[f64],
    works: &[BlockWork],
    duals: &Duals,
) -> f64 {
    let k = sdp.vars();
    let mut scales = vec![1.0; sdp.blocks.len()];
    let dual_term = |a: usize, j: usize, z: &[f64]| -> f64 {
        sdp.blocks[j].coefficients[a].as_ref().map_or(0.0, |f| inner(f, z))
    };
    if let Some((t, j)) = sdp.epigraph {
        let d = dual_term(t, j, &duals.z[j]);
        let kappa = -gradient[t] / d;
        if !(kappa.is_finite() && kappa > 0.0) {
            return f64::INFINITY;
        }
        scales[j] = kappa;
    }
    let mut bound = value + duals.y.iter().zip(s).map(|(a, b)| a * b).sum::<f64>();
    for (j, w) in works.iter().enumerate() {
        bound += scales[j] * inner(&duals.z[j], &w.s);
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
            r += scales[j] * dual_term(a, j, &duals.z[j]);
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
    let mut works: Vec<BlockWork> = sdp.blocks.iter().map(|b| BlockWork::new(b.n)).collect();
    for (b, w) in sdp.blocks.iter().zip(works.iter_mut()) {
        b.at(x, &mut w.s);
    }
    s.iter().all(|v| *v >= 0.0).then(|| upper_bound(sdp, x, value, gradient, &s, &works, duals))
}

/// Run the method from the strictly feasible `x0`, with multipliers centred there.
pub(crate) fn solve(
    sdp: &Sdp,
    mut smooth: Option<&mut dyn Smooth>,
    x0: &[f64],
    settings: Settings,
) -> Run {
    let k = sdp.vars();
    let p = sdp.row_count();
    let sizes: Vec<usize> = sdp.blocks.iter().map(|b| b.n).collect();
    let nu = (p + sizes.iter().sum::<usize>()) as f64;
    let mut works: Vec<BlockWork> = sizes.iter().map(|&n| BlockWork::new(n)).collect();
    let mut x = x0.to_vec();
    let mut s = vec![0.0; p];
    let mut gradient = vec![0.0; k];
    let mut hessian = vec![0.0; k * k];
    let mut schur = vec![0.0; k * k];
    let mut column = vec![0.0; sizes.iter().copied().max().unwrap_or(0).max(k)];
    let (mut dx, mut dx_aff) = (vec![0.0; k], vec![0.0; k]);
    let (mut ds_row, mut dy, mut ds_aff_row, mut dy_aff) =
        (vec![0.0; p], vec![0.0; p], vec![0.0; p], vec![0.0; p]);
    let mut duals = Duals::default();
    // The rows where each coefficient is not zero, and per coefficient `F_a Z` and `S⁻¹ F_a`.
    let supports: Vec<Vec<Option<Vec<usize>>>> = sdp
        .blocks
        .iter()
        .map(|b| {
            let n = b.n;
            b.coefficients
                .iter()
                .map(|f| {
                    f.as_ref().map(|f| {
                        (0..n).filter(|r| f[r * n..r * n + n].iter().any(|v| *v != 0.0)).collect()
                    })
                })
                .collect()
        })
        .collect();
    let mut products: Vec<Vec<(Vec<f64>, Vec<f64>)>> = sdp
        .blocks
        .iter()
        .map(|b| {
            b.coefficients
                .iter()
                .map(|f| match f {
                    Some(_) => (vec![0.0; b.n * b.n], vec![0.0; b.n * b.n]),
                    None => (Vec::new(), Vec::new()),
                })
                .collect()
        })
        .collect();
    let mut best: Option<(f64, f64)> = None;
    let run = |x: Vec<f64>, value, upper, iterations, end| Run { x, value, upper, iterations, end };
    for iteration in 0..=settings.max_iterations {
        // The slacks, their factors and inverses, the objective.
        sdp.slacks(&x, &mut s);
        let mut interior = s.iter().all(|v| *v > 0.0);
        for (b, w) in sdp.blocks.iter().zip(works.iter_mut()) {
            b.at(&x, &mut w.s);
            w.l.copy_from_slice(&w.s);
            interior &= cholesky(&mut w.l, b.n);
            if interior {
                cholesky_inverse(&w.l, b.n, &mut w.s_inv, &mut column);
            }
        }
        gradient.copy_from_slice(&sdp.c);
        hessian.fill(0.0);
        let mut value = sdp.c0 + sdp.c.iter().zip(&x).map(|(a, b)| a * b).sum::<f64>();
        if let Some(smooth) = smooth.as_deref_mut() {
            let mut g = vec![0.0; k];
            match smooth.evaluate(&x, &mut g, &mut hessian) {
                Some(v) => {
                    value += v;
                    for (a, b) in gradient.iter_mut().zip(&g) {
                        *a += b;
                    }
                }
                None => interior = false,
            }
        }
        if !interior {
            let (value, upper) = best.unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
            return run(x0.to_vec(), value, upper, iteration, End::Breakdown);
        }
        if iteration == 0 {
            duals = centred_duals(sdp, &gradient, &s, &works, value, settings.scale);
        }
        let mu = (duals.y.iter().zip(&s).map(|(a, b)| a * b).sum::<f64>()
            + works.iter().zip(&duals.z).map(|(w, z)| inner(z, &w.s)).sum::<f64>())
            / nu.max(1.0);
        let upper = upper_bound(sdp, &x, value, &gradient, &s, &works, &duals);
        best = Some((value, upper));
        if let Some(target) = settings.target {
            let converged =
                upper - value <= settings.relative_gap * value.abs().max(settings.scale);
            if value > target
                && (value - target >= settings.centring * (upper - target) || converged)
            {
                return run(x, value, upper, iteration, End::Reached);
            }
            if upper < target {
                return run(x, value, upper, iteration, End::Unreachable);
            }
        }
        if upper - value <= settings.relative_gap * value.abs().max(settings.scale) {
            return run(x, value, upper, iteration, End::Optimum);
        }
        if iteration == settings.max_iterations || p + works.len() == 0 {
            return run(x, value, upper, iteration, End::NotConverged);
        }
        // The Schur complement.
        for (e, h) in schur.iter_mut().zip(&hessian) {
            *e = -h;
        }
        for r in 0..p {
            let g = &sdp.rows[r * k..r * k + k];
            let d = duals.y[r] / s[r];
            for a in 0..k {
                if g[a] == 0.0 {
                    continue;
                }
                for b in 0..k {
                    schur[a * k + b] += d * g[a] * g[b];
                }
            }
        }
        // M_ab = tr(F_a Z F_b S⁻¹) = ⟨S⁻¹ F_b, F_a Z⟩ over the rows where F_a is not zero:
        // each A_i is made of a few 2 × 2 joint blocks, so this costs O(k² n) for them.
        for (j, b) in sdp.blocks.iter().enumerate() {
            let n = b.n;
            let (z, s_inv) = (&duals.z[j], &works[j].s_inv);
            for (a, fa) in b.coefficients.iter().enumerate() {
                let (Some(fa), Some(rows)) = (fa, &supports[j][a]) else { continue };
                let (fz, sf) = &mut products[j][a];
                fz.fill(0.0);
                sf.fill(0.0);
                for &r in rows {
                    for q in 0..n {
                        let v = fa[r * n + q];
                        if v != 0.0 {
                            for c in 0..n {
                                fz[r * n + c] += v * z[q * n + c];
                            }
                        }
                    }
                }
                for r in 0..n {
                    for &q in rows {
                        let v = s_inv[r * n + q];
                        for c in 0..n {
                            sf[r * n + c] += v * fa[q * n + c];
                        }
                    }
                }
            }
            for a in 0..k {
                let Some(rows) = &supports[j][a] else { continue };
                for bb in 0..k {
                    if supports[j][bb].is_none() {
                        continue;
                    }
                    let (fz, sf) = (&products[j][a].0, &products[j][bb].1);
                    let mut m = 0.0;
                    for &r in rows {
                        m += inner(&sf[r * n..r * n + n], &fz[r * n..r * n + n]);
                    }
                    schur[a * k + bb] += m;
                }
            }
        }
        crate::dense::symmetrise(&mut schur, k);
        let trace: f64 = (0..k).map(|a| schur[a * k + a].abs()).sum::<f64>().max(1e-300);
        let mut factored = schur.clone();
        if !cholesky(&mut factored, k) {
            factored.copy_from_slice(&schur);
            for a in 0..k {
                factored[a * k + a] += 1e-12 * trace;
            }
            if !cholesky(&mut factored, k) {
                return run(x, value, upper, iteration, End::Breakdown);
            }
        }
        // Predictor (σ = 0).
        dx_aff.copy_from_slice(&gradient);
        cholesky_solve(&factored, k, &mut dx_aff);
        directions(sdp, &s, &duals, &dx_aff, 0.0, &mut ds_aff_row, &mut dy_aff);
        for (j, b) in sdp.blocks.iter().enumerate() {
            let w = &mut works[j];
            matrix_step(b, &dx_aff, &mut w.ds_aff);
            let (ds, z, s_inv, n) = (&w.ds_aff, &duals.z[j], &w.s_inv, b.n);
            // ΔZ = −Z − sym(Z ΔS S⁻¹).
            let mut out = vec![0.0; n * n];
            sym_product(z, ds, s_inv, n, &mut w.t1, &mut out);
            for ((d, zz), o) in w.dz_aff.iter_mut().zip(z).zip(&out) {
                *d = -zz - o;
            }
        }
        let alpha_p = step_length(&s, &ds_aff_row, &mut works, &sizes, |w| (&w.s, &w.ds_aff));
        zs(&mut works, &duals);
        let alpha_d = step_length(&duals.y, &dy_aff, &mut works, &sizes, |w| (&w.t2, &w.dz_aff));
        let mut mu_aff = 0.0;
        for r in 0..p {
            mu_aff += (s[r] + alpha_p * ds_aff_row[r]) * (duals.y[r] + alpha_d * dy_aff[r]);
        }
        for (j, w) in works.iter().enumerate() {
            let z = &duals.z[j];
            for e in 0..w.s.len() {
                mu_aff += (w.s[e] + alpha_p * w.ds_aff[e]) * (z[e] + alpha_d * w.dz_aff[e]);
            }
        }
        mu_aff /= nu;
        let sigma = (mu_aff / mu).clamp(0.0, 1.0).powi(3);
        let sigma_mu = sigma * mu;
        // Corrector: the right-hand side with the second-order terms.
        dx.copy_from_slice(&gradient);
        for r in 0..p {
            let coefficient = (sigma_mu - ds_aff_row[r] * dy_aff[r]) / s[r];
            for a in 0..k {
                dx[a] -= sdp.rows[r * k + a] * coefficient;
            }
        }
        let mut corrections: Vec<Vec<f64>> = Vec::with_capacity(works.len());
        for (j, b) in sdp.blocks.iter().enumerate() {
            let n = b.n;
            let w = &mut works[j];
            // W = σμ S⁻¹ − sym(ΔZ_aff ΔS_aff S⁻¹).
            let mut second = vec![0.0; n * n];
            sym_product(&w.dz_aff, &w.ds_aff, &w.s_inv, n, &mut w.t1, &mut second);
            let correction: Vec<f64> =
                w.s_inv.iter().zip(&second).map(|(si, c)| sigma_mu * si - c).collect();
            for a in 0..k {
                if let Some(fa) = &b.coefficients[a] {
                    dx[a] += inner(fa, &correction);
                }
            }
            corrections.push(correction);
        }
        cholesky_solve(&factored, k, &mut dx);
        directions(sdp, &s, &duals, &dx, sigma_mu, &mut ds_row, &mut dy);
        for r in 0..p {
            dy[r] -= ds_aff_row[r] * dy_aff[r] / s[r];
        }
        for (j, b) in sdp.blocks.iter().enumerate() {
            let w = &mut works[j];
            matrix_step(b, &dx, &mut w.ds);
            let n = b.n;
            let mut out = vec![0.0; n * n];
            sym_product(&duals.z[j], &w.ds, &w.s_inv, n, &mut w.t1, &mut out);
            for e in 0..n * n {
                w.dz[e] = corrections[j][e] - duals.z[j][e] - out[e];
            }
        }
        let alpha_p = step_length(&s, &ds_row, &mut works, &sizes, |w| (&w.s, &w.ds));
        zs(&mut works, &duals);
        let alpha_d = step_length(&duals.y, &dy, &mut works, &sizes, |w| (&w.t2, &w.dz));
        for (xa, d) in x.iter_mut().zip(&dx) {
            *xa += alpha_p * d;
        }
        for (ya, d) in duals.y.iter_mut().zip(&dy) {
            *ya += alpha_d * d;
        }
        for (z, w) in duals.z.iter_mut().zip(&works) {
            for (ze, d) in z.iter_mut().zip(&w.dz) {
                *ze += alpha_d * d;
            }
            crate::dense::symmetrise(z, w.s.len().isqrt());
        }
    }
    unreachable!("the loop returns at its last iteration")
}

/// Copy each block's `Z` into its `t2` (for the dual step-length trials).
fn zs(works: &mut [BlockWork], duals: &Duals) {
    for (w, z) in works.iter_mut().zip(&duals.z) {
        w.t2.copy_from_slice(z);
    }
}

/// `ΔF = Σ_a dx_a F_a` into `out`.
fn matrix_step(b: &Block, dx: &[f64], out: &mut [f64]) {
    out.fill(0.0);
    for (d, fa) in dx.iter().zip(&b.coefficients) {
        if let Some(fa) = fa {
            for (o, f) in out.iter_mut().zip(fa) {
                *o += d * f;
            }
        }
    }
}

/// The row parts of a direction: `Δs = −G Δx`, `Δy = σμ/s − y − (y/s)∘Δs`.
fn directions(
    sdp: &Sdp,
    s: &[f64],
    duals: &Duals,
    dx: &[f64],
    sigma_mu: f64,
    ds: &mut [f64],
    dy: &mut [f64],
) {
    let k = sdp.vars();
    for r in 0..s.len() {
        let g = &sdp.rows[r * k..r * k + k];
        ds[r] = -g.iter().zip(dx).map(|(a, b)| a * b).sum::<f64>();
        dy[r] = sigma_mu / s[r] - duals.y[r] - duals.y[r] / s[r] * ds[r];
    }
}

/// Multipliers on the central path at `x`, `y = μ/s`, `Z_j = μ S_j⁻¹`, with `μ` the
/// least-squares fit of stationarity `∇φ + μ (−Gᵀ(1/s) + F*(S⁻¹)) = 0` (floored at a small
/// positive value). An epigraph block gets its own `μ_t`, the one that makes the epigraph
/// variable's stationarity exact (`∂φ/∂t + μ_t ⟨F_t, S⁻¹⟩ = 0`); the fit is then over the
/// other coordinates.
fn centred_duals(
    sdp: &Sdp,
    gradient: &[f64],
    s: &[f64],
    works: &[BlockWork],
    value: f64,
    scale: f64,
) -> Duals {
    let k = sdp.vars();
    let mut own = vec![None; works.len()];
    if let Some((t, j)) = sdp.epigraph {
        let d = sdp.blocks[j].coefficients[t].as_ref().map_or(0.0, |f| inner(f, &works[j].s_inv));
        let mu_t = -gradient[t] / d;
        if mu_t.is_finite() && mu_t > 0.0 {
            own[j] = Some(mu_t);
        }
    }
    let mut b = vec![0.0; k];
    let mut g = gradient.to_vec();
    for (r, sr) in s.iter().enumerate() {
        for a in 0..k {
            b[a] -= sdp.rows[r * k + a] / sr;
        }
    }
    for (j, (blk, w)) in sdp.blocks.iter().zip(works).enumerate() {
        for a in 0..k {
            if let Some(fa) = &blk.coefficients[a] {
                match own[j] {
                    Some(mu_t) => g[a] += mu_t * inner(fa, &w.s_inv),
                    None => b[a] += inner(fa, &w.s_inv),
                }
            }
        }
    }
    if let Some((t, _)) = sdp.epigraph {
        b[t] = 0.0;
        g[t] = 0.0;
    }
    let bb: f64 = b.iter().map(|v| v * v).sum();
    let gb: f64 = b.iter().zip(&g).map(|(x, y)| x * y).sum();
    let nu = (s.len() + works.iter().map(|w| w.s.len().isqrt()).sum::<usize>()) as f64;
    let floor = 1e-3 * value.abs().max(scale) / nu.max(1.0);
    let mu = if bb > 0.0 { (-gb / bb).max(floor) } else { floor };
    Duals {
        y: s.iter().map(|v| mu / v).collect(),
        z: works
            .iter()
            .zip(&own)
            .map(|(w, o)| w.s_inv.iter().map(|v| o.unwrap_or(mu) * v).collect())
            .collect(),
    }
}
