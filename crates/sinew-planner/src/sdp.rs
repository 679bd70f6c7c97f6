//! A small primal–dual interior-point method for the problems of [`crate::program`], with
//! Mehrotra's predictor–corrector and the HKM direction, certified at every iterate by
//! [`crate::program::upper_bound`].
//!
//! # Math
//! With `μ = (sᵀy + Σ⟨S_j, Z_j⟩)/ν`, `ν = rows + Σ n_j`, the Newton step towards the central
//! point `s∘y = σμ`, `S Z = σμ I` (symmetrised as HKM does:
//! `ΔZ = σμ S⁻¹ − Z − sym(Z ΔS S⁻¹)`) reduces to the Schur system
//!
//! ```text
//! (−∇²ψ + Gᵀ diag(y/s) G + Σ_j M_j) Δx = ∇φ − σμ Gᵀ(1/s) + σμ F*(S⁻¹),
//! (M_j)_ab = tr(F_ja Z_j F_jb S_j⁻¹),   F*(W)_a = Σ_j ⟨F_ja, W_j⟩,
//! ```
//!
//! solved by Cholesky. The predictor takes `σ = 0`; `σ = (μ_aff/μ)³` and the second-order
//! terms `Δs∘Δy` and `sym(ΔZ ΔS S⁻¹)` of the predictor enter the corrector (Mehrotra). Step
//! lengths are found by Cholesky trials, 95 % of the way to the boundary (the corrector's
//! bracketed to within 6 %, `block_work::step_length`). The primal iterate
//! stays strictly feasible (every phase starts from such a point), so `s` and `S` are functions
//! of `x`.

use crate::block_work::{
    BlockWork, add_block_schur, dual_congruence, factored_dual_term, matrix_step, step_length,
    sym_product, zs,
};
use crate::dense::{axpy, cholesky, cholesky_inverse, cholesky_solve, cholesky_whole, dot, inner};
pub(crate) use crate::program::{Block, Duals, End, Run, Sdp, Settings, Smooth};
use crate::program::{centred_duals, resize_pooled, upper_bound};

/// How often a step that leaves the smooth objective's domain is halved before the run
/// breaks down.
const MAX_HALVINGS: usize = 30;

/// The vectors of a run (rows, variables), sized once per run.
#[derive(Debug, Default)]
struct Vectors {
    s: Vec<f64>,
    gradient: Vec<f64>,
    smooth_gradient: Vec<f64>,
    hessian: Vec<f64>,
    schur: Vec<f64>,
    factored: Vec<f64>,
    dx: Vec<f64>,
    dx_aff: Vec<f64>,
    ds_row: Vec<f64>,
    dy: Vec<f64>,
    ds_aff_row: Vec<f64>,
    dy_aff: Vec<f64>,
    /// `x` before the last step.
    previous: Vec<f64>,
    /// The centring's scratch ([`centred_duals`]).
    centring: (Vec<f64>, Vec<f64>),
}

impl Vectors {
    fn size(&mut self, k: usize, p: usize) {
        for (v, len) in [
            (&mut self.s, p),
            (&mut self.gradient, k),
            (&mut self.smooth_gradient, k),
            (&mut self.hessian, k * k),
            (&mut self.schur, k * k),
            (&mut self.factored, k * k),
            (&mut self.dx, k),
            (&mut self.dx_aff, k),
            (&mut self.ds_row, p),
            (&mut self.dy, p),
            (&mut self.ds_aff_row, p),
            (&mut self.dy_aff, p),
            (&mut self.previous, k),
            (&mut self.centring.0, k),
            (&mut self.centring.1, k),
        ] {
            v.clear();
            v.resize(len, 0.0);
        }
    }
}

/// A run's workspace, kept between runs: once its buffers have the room of a problem, a run
/// on a problem of that shape allocates nothing. After a run, `x` is its last iterate.
#[derive(Debug, Default)]
pub(crate) struct SolveWork {
    /// The last iterate (the start where the run broke down).
    pub(crate) x: Vec<f64>,
    v: Vectors,
    works: Vec<BlockWork>,
    spare: Vec<BlockWork>,
    duals: Duals,
}

/// Run the method from the strictly feasible `x0`, with multipliers centred there.
///
/// The whole run is compiled once per instruction set and dispatched at run time by pulp
/// (AVX2 and FMA where the processor has them): its kernels are small dense loops over rows
/// of 5–20 entries, which the wider vectors serve. The arithmetic is the same on every path
/// up to the rounding of fused multiply–adds.
pub(crate) fn solve(
    sdp: &Sdp,
    smooth: Option<&mut dyn Smooth>,
    x0: &[f64],
    settings: Settings,
    work: &mut SolveWork,
) -> Run {
    pulp::Arch::new().dispatch(Solve { sdp, smooth, x0, settings, work })
}

/// The arguments of [`solve`] as a pulp operation.
struct Solve<'a, 'b> {
    sdp: &'a Sdp,
    smooth: Option<&'a mut (dyn Smooth + 'b)>,
    x0: &'a [f64],
    settings: Settings,
    work: &'a mut SolveWork,
}

impl pulp::WithSimd for Solve<'_, '_> {
    type Output = Run;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> Run {
        solve_body(self.sdp, self.smooth, self.x0, self.settings, self.work)
    }
}

#[inline(always)]
fn solve_body<'s>(
    sdp: &Sdp,
    mut smooth: Option<&mut (dyn Smooth + 's)>,
    x0: &[f64],
    settings: Settings,
    work: &mut SolveWork,
) -> Run {
    let k = sdp.vars();
    let p = sdp.row_count();
    let nu = (p + sdp.blocks.iter().map(|b| b.n).sum::<usize>()) as f64;
    let SolveWork { x, v, works, spare, duals } = work;
    resize_pooled(works, spare, sdp.blocks.len());
    for (w, b) in works.iter_mut().zip(&sdp.blocks) {
        w.reset(b);
    }
    v.size(k, p);
    x.clear();
    x.extend_from_slice(x0);
    let mut best: Option<(f64, f64)> = None;
    let run = |value, upper, iterations, end| Run { value, upper, iterations, end };
    // The last primal step's length: where the step leaves the smooth objective's domain
    // (which no block bounds when the margin is checked lazily, `ipm.rs`), it is halved.
    let mut last_step: Option<f64> = None;
    for iteration in 0..=settings.max_iterations {
        let mut halvings = 0;
        let (value, interior) = loop {
            // The slacks, their factors and inverses, the objective.
            sdp.slacks(x, &mut v.s);
            let mut interior = v.s.iter().all(|s| *s > 0.0);
            for (b, w) in sdp.blocks.iter().zip(works.iter_mut()) {
                b.at(x, &mut w.s);
                w.l.copy_from_slice(&w.s);
                interior &= cholesky_whole(&mut w.l, b.n, true);
                if interior {
                    cholesky_inverse(&w.l, b.n, &mut w.s_inv, &mut w.t1);
                }
            }
            v.gradient.copy_from_slice(&sdp.c);
            v.hessian.fill(0.0);
            let mut value = sdp.c0 + dot(&sdp.c, x);
            if let Some(smooth) = smooth.as_deref_mut() {
                match smooth.evaluate(x, &mut v.smooth_gradient, &mut v.hessian) {
                    Some(psi) => {
                        value += psi;
                        axpy(1.0, &v.smooth_gradient, &mut v.gradient);
                    }
                    None => interior = false,
                }
            }
            match last_step {
                Some(alpha) if !interior && halvings < MAX_HALVINGS => {
                    halvings += 1;
                    last_step = Some(0.5 * alpha);
                    x.copy_from_slice(&v.previous);
                    axpy(0.5 * alpha, &v.dx, x);
                }
                _ => break (value, interior),
            }
        };
        if !interior {
            let (value, upper) = best.unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
            x.copy_from_slice(x0);
            return run(value, upper, iteration, End::Breakdown);
        }
        if iteration == 0 {
            let inverses = |j: usize| works[j].s_inv.as_slice();
            let (b, g) = (&mut v.centring.0, &mut v.centring.1);
            let (gradient, s) = (&v.gradient, &v.s);
            centred_duals(sdp, gradient, s, inverses, value, settings.scale, (b, g), duals);
        }
        let s = &v.s;
        let mu = (dot(&duals.y, s)
            + works.iter().zip(&duals.z).map(|(w, z)| inner(z, &w.s)).sum::<f64>())
            / nu.max(1.0);
        // A factored block's `R Z Rᵀ`: its dual terms here, its Schur terms below.
        for ((b, w), z) in sdp.blocks.iter().zip(works.iter_mut()).zip(&duals.z) {
            dual_congruence(b, z, w);
        }
        let upper = {
            let matrices = works.iter().map(|w| w.s.as_slice());
            let known = |a: usize, j: usize| factored_dual_term(&sdp.blocks[j], &works[j], a);
            upper_bound(sdp, x, value, &v.gradient, s, matrices, duals, known)
        };
        best = Some((value, upper));
        if let Some(target) = settings.target {
            let converged =
                upper - value <= settings.relative_gap * value.abs().max(settings.scale);
            if value > target
                && (value - target >= settings.centring * (upper - target) || converged)
            {
                return run(value, upper, iteration, End::Reached);
            }
            if upper < target {
                return run(value, upper, iteration, End::Unreachable);
            }
        }
        if upper - value <= settings.relative_gap * value.abs().max(settings.scale) {
            return run(value, upper, iteration, End::Optimum);
        }
        if iteration == settings.max_iterations || p + works.len() == 0 {
            return run(value, upper, iteration, End::NotConverged);
        }
        // The Schur complement.
        for (e, h) in v.schur.iter_mut().zip(&v.hessian) {
            *e = -h;
        }
        for r in 0..p {
            let g = &sdp.rows[r * k..r * k + k];
            let d = duals.y[r] / s[r];
            for a in 0..k {
                if g[a] != 0.0 {
                    axpy(d * g[a], g, &mut v.schur[a * k..a * k + k]);
                }
            }
        }
        for ((b, w), z) in sdp.blocks.iter().zip(works.iter_mut()).zip(&duals.z) {
            add_block_schur(b, z, w, k, &mut v.schur);
        }
        crate::dense::symmetrise(&mut v.schur, k);
        let trace: f64 = (0..k).map(|a| v.schur[a * k + a].abs()).sum::<f64>().max(1e-300);
        v.factored.copy_from_slice(&v.schur);
        if !cholesky(&mut v.factored, k) {
            v.factored.copy_from_slice(&v.schur);
            for a in 0..k {
                v.factored[a * k + a] += 1e-12 * trace;
            }
            if !cholesky(&mut v.factored, k) {
                return run(value, upper, iteration, End::Breakdown);
            }
        }
        // Predictor (σ = 0).
        v.dx_aff.copy_from_slice(&v.gradient);
        cholesky_solve(&v.factored, k, &mut v.dx_aff);
        directions(sdp, s, duals, &v.dx_aff, 0.0, &mut v.ds_aff_row, &mut v.dy_aff);
        for ((b, w), z) in sdp.blocks.iter().zip(works.iter_mut()).zip(&duals.z) {
            matrix_step(b, &v.dx_aff, &mut w.ds_aff);
            // ΔZ = −Z − sym(Z ΔS S⁻¹).
            sym_product(z, &w.ds_aff, &w.s_inv, b.n, &mut w.t1, &mut w.product);
            for ((d, zz), o) in w.dz_aff.iter_mut().zip(z).zip(&w.product) {
                *d = -zz - o;
            }
        }
        let alpha_p = step_length(s, &v.ds_aff_row, works, |w| (&w.s, &w.ds_aff), false);
        zs(works, duals);
        let alpha_d = step_length(&duals.y, &v.dy_aff, works, |w| (&w.t2, &w.dz_aff), false);
        let mut mu_aff = 0.0;
        for r in 0..p {
            mu_aff += (s[r] + alpha_p * v.ds_aff_row[r]) * (duals.y[r] + alpha_d * v.dy_aff[r]);
        }
        for (w, z) in works.iter().zip(&duals.z) {
            for e in 0..w.s.len() {
                mu_aff += (w.s[e] + alpha_p * w.ds_aff[e]) * (z[e] + alpha_d * w.dz_aff[e]);
            }
        }
        mu_aff /= nu;
        let sigma = (mu_aff / mu).clamp(0.0, 1.0).powi(3);
        let sigma_mu = sigma * mu;
        // Corrector: the right-hand side with the second-order terms.
        v.dx.copy_from_slice(&v.gradient);
        for r in 0..p {
            let coefficient = (sigma_mu - v.ds_aff_row[r] * v.dy_aff[r]) / s[r];
            axpy(-coefficient, &sdp.rows[r * k..r * k + k], &mut v.dx);
        }
        for (b, w) in sdp.blocks.iter().zip(works.iter_mut()) {
            // W = σμ S⁻¹ − sym(ΔZ_aff ΔS_aff S⁻¹).
            sym_product(&w.dz_aff, &w.ds_aff, &w.s_inv, b.n, &mut w.t1, &mut w.product);
            for ((c, si), o) in w.correction.iter_mut().zip(&w.s_inv).zip(&w.product) {
                *c = sigma_mu * si - o;
            }
            for (a, fa) in b.coefficients.iter().enumerate() {
                if let Some(fa) = fa {
                    v.dx[a] += inner(fa, &w.correction);
                }
            }
        }
        cholesky_solve(&v.factored, k, &mut v.dx);
        directions(sdp, s, duals, &v.dx, sigma_mu, &mut v.ds_row, &mut v.dy);
        for r in 0..p {
            v.dy[r] -= v.ds_aff_row[r] * v.dy_aff[r] / s[r];
        }
        for ((b, w), z) in sdp.blocks.iter().zip(works.iter_mut()).zip(&duals.z) {
            matrix_step(b, &v.dx, &mut w.ds);
            sym_product(z, &w.ds, &w.s_inv, b.n, &mut w.t1, &mut w.product);
            for e in 0..w.dz.len() {
                w.dz[e] = w.correction[e] - z[e] - w.product[e];
            }
        }
        let alpha_p = step_length(s, &v.ds_row, works, |w| (&w.s, &w.ds), true);
        zs(works, duals);
        let alpha_d = step_length(&duals.y, &v.dy, works, |w| (&w.t2, &w.dz), true);
        v.previous.copy_from_slice(x);
        last_step = Some(alpha_p);
        axpy(alpha_p, &v.dx, x);
        axpy(alpha_d, &v.dy, &mut duals.y);
        for (z, w) in duals.z.iter_mut().zip(works.iter()) {
            axpy(alpha_d, &w.dz, z);
            crate::dense::symmetrise(z, w.n);
        }
    }
    unreachable!("the loop returns at its last iteration")
}

/// The row parts of a direction: `Δs = −G Δx`, `Δy = σμ/s − y − (y/s)∘Δs`.
#[inline(always)]
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
        ds[r] = -dot(g, dx);
        dy[r] = sigma_mu / s[r] - duals.y[r] - duals.y[r] / s[r] * ds[r];
    }
}
