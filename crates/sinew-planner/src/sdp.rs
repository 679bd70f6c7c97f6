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
//! lengths are found by Cholesky trials, 95 % of the way to the boundary. The primal iterate
//! stays strictly feasible (every phase starts from such a point), so `s` and `S` are functions
//! of `x`.

use crate::dense::{cholesky, cholesky_inverse, cholesky_solve, inner, multiply};
pub(crate) use crate::program::{Block, Duals, End, Run, Sdp, Settings, Smooth};
use crate::program::{centred_duals, upper_bound};

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
            let inverses: Vec<&[f64]> = works.iter().map(|w| w.s_inv.as_slice()).collect();
            duals = centred_duals(sdp, &gradient, &s, &inverses, value, settings.scale);
        }
        let mu = (duals.y.iter().zip(&s).map(|(a, b)| a * b).sum::<f64>()
            + works.iter().zip(&duals.z).map(|(w, z)| inner(z, &w.s)).sum::<f64>())
            / nu.max(1.0);
        let matrices: Vec<&[f64]> = works.iter().map(|w| w.s.as_slice()).collect();
        let upper = upper_bound(sdp, &x, value, &gradient, &s, &matrices, &duals);
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
