//! The stability margin as an active constraint of the warm step's Newton steps (issue #24):
//! `c(x) = λ_min(A(x)) − m ≥ 0` linearised at `x`, with its gradient and Hessian, where the
//! least eigenvalue is simple. `active.rs` puts it in the working set beside the active rows
//! when the margin binds, as it does for least tension under load.
//!
//! # Math
//! With `A(x) = A₀ + Σ_a x_a A_a` and `v` the unit eigenvector of the simple least eigenvalue
//! `λ₁` (`A v = λ₁ v`), first- and second-order perturbation theory give
//!
//! ```text
//! ∂c/∂x_a = vᵀ A_a v,
//! ∂²c/∂x_a∂x_b = −2 (A_a v)ᵀ (A − λ₁ I)⁺ (A_b v),
//! ```
//!
//! (`A` is affine in `x`, so no second derivative of `A` enters; `∇²c ⪯ 0`, `λ_min` is
//! concave). The pseudo-inverse acts on `w_a = A_a v − (vᵀ A_a v) v ⊥ v` through the regular
//! `B = A − λ₁ I + γ v vᵀ` (`γ > 0`), whose inverse agrees with `(A − λ₁ I)⁺` on `v⊥`: one
//! Cholesky factorisation and a solve per coordinate, no eigendecomposition.
//!
//! The eigenpair comes from [`LeastEigen`] (Cholesky trials and inverse iteration), whose vector
//! is accurate to about `√(10⁻¹⁰)` of the gap. That error enters `vᵀ A_a v` to first order, so
//! the vector is refined by one Newton step on the eigenproblem with the same factor `B`:
//! `v ← v − P B⁻¹ (A v − ρ v)`, `ρ = vᵀ A v`, `P` the projection onto `v⊥`, which squares its
//! error. A least eigenvalue that is not simple (no factor `B`, or a vector that does not
//! converge) is refused: `c` is not differentiable there.
//!
//! The certificate of `program.rs` takes `Z = η v vᵀ` for the margin's multiplier `η ≥ 0`:
//! `⟨Z, A − m I⟩ = η (vᵀ A v − m)` and `A*(Z)_a = η vᵀ A_a v`, exact for whatever unit `v` is
//! used, so the bound holds even where `v` is not an eigenvector; it is tight where it is.

use crate::dense::{cholesky, cholesky_solve, dot};
use crate::least::{LeastEigen, rayleigh_residual};

/// The residual `‖A v − ρ v‖` (of `max |a_ij|`) above which the refined vector is refused.
const RESIDUAL: f64 = 1e-9;

/// The margin's linearisation at the last [`MarginRow::linearise`], with its buffers (no
/// allocation once sized).
#[derive(Debug, Default)]
pub(crate) struct MarginRow {
    least: LeastEigen,
    /// `B = A − ρ I + γ v vᵀ`, then its factor.
    shifted: Vec<f64>,
    /// The unit vector `v`.
    pub(crate) v: Vec<f64>,
    /// `ρ = vᵀ A v`, the least eigenvalue to rounding.
    pub(crate) rho: f64,
    /// `∇c` (k).
    pub(crate) gradient: Vec<f64>,
    /// `∇²c` (k × k, row-major).
    pub(crate) hessian: Vec<f64>,
    /// Per coordinate `A_a v`, then `w_a`, then `B⁻¹ w_a` (k × n).
    w: Vec<f64>,
    u: Vec<f64>,
    r: Vec<f64>,
}

impl MarginRow {
    /// Forget the last vector, as an independent plan must (its buffers kept).
    pub(crate) fn forget(&mut self) {
        self.least.forget();
    }

    /// Linearise `λ_min(A)` at `a = A(x)` (n × n, row-major, symmetric), `apply(i, v, out)`
    /// writing `A_i v` into `out` for each of the `k` coordinates: `ρ`, `v`, `∇c` and `∇²c`
    /// into `self`. `false` where the least eigenvalue is not simple or `a` is not finite.
    pub(crate) fn linearise(
        &mut self,
        a: &[f64],
        n: usize,
        k: usize,
        apply: impl Fn(usize, &[f64], &mut [f64]),
    ) -> bool {
        let Some(rho) = self.least.least(a, n, None) else { return false };
        let scale = a[..n * n].iter().fold(0.0_f64, |m, v| m.max(v.abs())).max(f64::MIN_POSITIVE);
        self.v.clear();
        self.v.extend_from_slice(self.least.vector());
        let norm = dot(&self.v, &self.v).sqrt();
        self.v.iter_mut().for_each(|x| *x /= norm);
        self.shifted.clear();
        self.shifted.extend_from_slice(&a[..n * n]);
        for i in 0..n {
            for j in 0..n {
                self.shifted[i * n + j] += scale * self.v[i] * self.v[j];
            }
            self.shifted[i * n + i] -= rho;
        }
        // A gap below 1e-10 of the scale is a repeated eigenvalue to rounding.
        if !cholesky(&mut self.shifted, n)
            || (0..n).any(|i| self.shifted[i * n + i].powi(2) < 1e-10 * scale)
        {
            return false;
        }
        // One Newton step on the eigenvector: v ← v − P B⁻¹ (A v − ρ v).
        self.r.clear();
        self.r.resize(n, 0.0);
        let rho = self.residual(a, n);
        cholesky_solve(&self.shifted, n, &mut self.r);
        let along = dot(&self.r, &self.v);
        for (v, t) in self.v.iter_mut().zip(&self.r) {
            *v -= t - along * *v;
        }
        let norm = dot(&self.v, &self.v).sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            return false;
        }
        self.v.iter_mut().for_each(|x| *x /= norm);
        self.rho = self.residual(a, n);
        if !(dot(&self.r, &self.r).sqrt() <= RESIDUAL * scale && (rho - self.rho).abs() <= scale) {
            return false;
        }
        // ∇c_a = vᵀ A_a v, w_a = A_a v − (∇c_a) v, u_a = B⁻¹ w_a, ∇²c_ab = −2 w_aᵀ u_b.
        self.gradient.clear();
        self.w.clear();
        self.w.resize(k * n, 0.0);
        for (i, w) in self.w.chunks_exact_mut(n).enumerate() {
            apply(i, &self.v, w);
            let g = dot(w, &self.v);
            w.iter_mut().zip(&self.v).for_each(|(w, v)| *w -= g * v);
            self.gradient.push(g);
        }
        self.u.clone_from(&self.w);
        for u in self.u.chunks_exact_mut(n) {
            cholesky_solve(&self.shifted, n, u);
        }
        self.hessian.clear();
        self.hessian.resize(k * k, 0.0);
        for i in 0..k {
            for j in i..k {
                let h = -(dot(&self.w[i * n..][..n], &self.u[j * n..][..n])
                    + dot(&self.w[j * n..][..n], &self.u[i * n..][..n]));
                self.hessian[i * k + j] = h;
                self.hessian[j * k + i] = h;
            }
        }
        true
    }

    /// `ρ = vᵀ A v` and `r = A v − ρ v` into `self.r`.
    fn residual(&mut self, a: &[f64], n: usize) -> f64 {
        rayleigh_residual(a, n, &self.v, &mut self.r)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use nalgebra::DMatrix;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::MarginRow;

    /// A random symmetric n × n, row-major.
    fn symmetric(rng: &mut ChaCha8Rng, n: usize, scale: f64) -> Vec<f64> {
        let m = DMatrix::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
        let m = (&m + m.transpose()) * (0.5 * scale);
        m.transpose().iter().copied().collect()
    }

    /// `λ_min(A(x))` by nalgebra's symmetric eigensolver.
    fn least(a0: &[f64], ai: &[Vec<f64>], x: &[f64], n: usize) -> f64 {
        let mut a = a0.to_vec();
        for (xa, m) in x.iter().zip(ai) {
            a.iter_mut().zip(m).for_each(|(e, f)| *e += xa * f);
        }
        DMatrix::from_row_slice(n, n, &a).symmetric_eigenvalues().min()
    }

    /// The gradient and Hessian of `λ_min(A(x))` against central differences of an
    /// eigensolver's value, at random pencils with a simple least eigenvalue; the value is the
    /// eigensolver's, and `∇²c ⪯ 0`.
    #[test]
    fn the_derivatives_are_central_differences_of_the_least_eigenvalue() {
        let mut rng = ChaCha8Rng::seed_from_u64(31);
        let mut row = MarginRow::default();
        let (mut worst_g, mut worst_h): (f64, f64) = (0.0, 0.0);
        for case in 0..60 {
            let n = 2 + case % 11;
            let k = 1 + case % 6;
            let a0 = symmetric(&mut rng, n, 1.0);
            let ai: Vec<Vec<f64>> = (0..k).map(|_| symmetric(&mut rng, n, 0.3)).collect();
            let x: Vec<f64> = (0..k).map(|_| rng.random_range(-1.0..1.0)).collect();
            let mut a = a0.clone();
            for (xa, m) in x.iter().zip(&ai) {
                a.iter_mut().zip(m).for_each(|(e, f)| *e += xa * f);
            }
            let apply = |i: usize, v: &[f64], out: &mut [f64]| {
                for (o, r) in out.iter_mut().zip(ai[i].chunks_exact(n)) {
                    *o = r.iter().zip(v).map(|(p, q)| p * q).sum();
                }
            };
            assert!(row.linearise(&a, n, k, apply), "case {case}");
            let reference = least(&a0, &ai, &x, n);
            assert!((row.rho - reference).abs() <= 1e-12, "case {case}: {} {reference}", row.rho);
            let h = 1e-4;
            let at = |shift: &[(usize, f64)]| {
                let mut y = x.clone();
                shift.iter().for_each(|(i, d)| y[*i] += d);
                least(&a0, &ai, &y, n)
            };
            for i in 0..k {
                let fd = (at(&[(i, h)]) - at(&[(i, -h)])) / (2.0 * h);
                worst_g = worst_g.max((fd - row.gradient[i]).abs());
                assert!((fd - row.gradient[i]).abs() <= 3e-8, "case {case}: ∂{i} {fd}");
                for j in 0..k {
                    let fd =
                        (at(&[(i, h), (j, h)]) - at(&[(i, h), (j, -h)]) - at(&[(i, -h), (j, h)])
                            + at(&[(i, -h), (j, -h)]))
                            / (4.0 * h * h);
                    let got = row.hessian[i * k + j];
                    worst_h = worst_h.max((fd - got).abs() / got.abs().max(1.0));
                    assert!((fd - got).abs() <= 2e-6 * got.abs().max(1.0), "case {case}: ∂{i}∂{j}");
                }
            }
            let hessian = DMatrix::from_row_slice(k, k, &row.hessian);
            assert!(hessian.symmetric_eigenvalues().max() <= 1e-12, "case {case}: not concave");
        }
        eprintln!("worst gradient error {worst_g:.1e}, Hessian {worst_h:.1e}");
    }

    /// A repeated least eigenvalue (not differentiable) is refused, and so is a matrix with a
    /// NaN.
    #[test]
    fn a_repeated_least_eigenvalue_is_refused() {
        let mut row = MarginRow::default();
        let a = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 2.0];
        assert!(!row.linearise(&a, 3, 1, |_, _, out: &mut [f64]| out.fill(0.0)));
        let a = [1.0, f64::NAN, f64::NAN, 1.0];
        assert!(!row.linearise(&a, 2, 1, |_, _, out: &mut [f64]| out.fill(0.0)));
    }
}
