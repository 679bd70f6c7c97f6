//! The smooth end-stiffness objectives of the interior-point method, with their analytic
//! gradients and Hessians in the frame's coordinates `x`.
//!
//! # Math
//! With `A = A(x)`, `Y = A⁻¹ J_xᵀ`, `C_x = J_x Y`, `K_x = C_x⁻¹` and the constrained inverse
//! `P = A⁻¹ − Y K_x Yᵀ ⪰ 0` (`∂_a K_x = Vᵀ A_a V` with `V = Y K_x`, `∂_a V = −P A_a V`):
//!
//! - `φ = wᵀ K_x w`, `z = V w`: `∂_a φ = zᵀ A_a z`, `∂_ab φ = −2 (A_a z)ᵀ P (A_b z)`;
//! - `φ = log det K_fd`, `K_fd = K_x[0:3, 0:3] = L Lᵀ`, `U = V[:, 0:3] L⁻ᵀ`,
//!   `G_a = Uᵀ A_a U`: `∂_a φ = tr G_a`, `∂_ab φ = −⟨G_a, G_b⟩ − 2 ⟨A_a U, P A_b U⟩`.
//!
//! With `A = L Lᵀ`, the Hessians' cross terms are `(A_a z)ᵀ P (A_b z) = w_aᵀ w_b − t_aᵀ K_x t_b`,
//! `w_a = L⁻¹ A_a z` (a forward substitution from the first row where `A_a` is not zero) and
//! `t_a = Yᵀ A_a z`: no full solve per coefficient.
//!
//! - `φ = −wᵀ A⁻¹ w`, `w = J_pᵀ u` (the compliance along `u`, rotations free), `z = A⁻¹ w`:
//!   `∂_a φ = zᵀ A_a z`, `∂_ab φ = −2 (A_a z)ᵀ A⁻¹ (A_b z) = −2 w_aᵀ w_b`.
//!
//! - `φ = λ_min(K_fd)` where it is simple, `K_fd = E Λ Eᵀ` (`e₁` least), `Z = V[:, 0:3] E`,
//!   `G_a = Zᵀ A_a Z`: `∂_a φ = G_a[0, 0]`, `∂_ab φ = −2 (A_a z₁)ᵀ P (A_b z₁) +
//!   2 Σ_{j>1} G_a[0, j] G_b[0, j] / (λ₁ − λ_j)` (second-order perturbation of an eigenvalue).
//!
//! All four Hessians are `⪯ 0` (Gram forms with `P ⪰ 0`): the objectives are concave, as
//! `wᵀ K_x w = min { δqᵀ A δq : J_x δq = w }` is a minimum of affine functions of `x`.

use nalgebra::{Matrix3, Matrix6, Vector6};
use sinew_stiffness::compliance_inverse;

use crate::dense::{axpy, cholesky, cholesky_solve, dot, forward_solve_from};
use crate::frame::Frame;
use crate::sdp::Smooth;

/// Which smooth objective.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Kind {
    /// `wᵀ K_x w` with `w = (u, 0)`.
    Along(Vector6<f64>),
    /// `log det K_fd`.
    Volume,
    /// `−uᵀ C_x[0:3, 0:3] u = −wᵀ A⁻¹ w`, `w = J_pᵀ u`: the compliance along `u` with the
    /// rotations free, negated (module docs).
    Compliance(nalgebra::Vector3<f64>),
    /// `λ_min(K_fd)`, the least stiffness with the rotations held, where it is simple.
    Least,
}

/// Which Hessian [`EndObjective::forms`] assembles from its vectors `z_j`.
#[derive(Debug, Clone, Copy)]
enum Form {
    /// `wᵀ K_x w`: one vector.
    Along,
    /// `log det K_fd`: three, with `−⟨G_a, G_b⟩`.
    Volume,
    /// `−wᵀ A⁻¹ w`: one, `P = A⁻¹`.
    Compliance,
    /// `λ_min(K_fd)`: three (the eigenvectors of `K_fd`, least first), the cross terms of the
    /// first only, with `2 Σ_j G_a[0, j] G_b[0, j] / (λ₁ − λ_j)`; the gaps `λ₁ − λ_j`.
    Least([f64; 2]),
}

/// A smooth objective on a frame, divided by `scale`, with the buffers of its evaluations
/// (allocated once: an evaluation allocates nothing). Vectors of length n are stored one after
/// another (`Yᵀ` as 6 rows, `z_j`, `A_a z_j`, `P A_a z_j`), so that every product is a dot
/// product or an update of contiguous slices.
pub(crate) struct EndObjective<'a> {
    pub(crate) frame: &'a Frame,
    pub(crate) kind: Kind,
    pub(crate) scale: f64,
    /// Evaluate the value and the gradient only, the Hessian left as it was (a warm step's
    /// first evaluation, which most often certifies the point without a Newton step).
    pub(crate) gradient_only: bool,
    b: EndBuffers,
}

/// The buffers of an [`EndObjective`], kept between objectives ([`EndObjective::reusing`]).
#[derive(Debug, Default)]
pub(crate) struct EndBuffers {
    /// The Cholesky factor of `A(x)`.
    a: Vec<f64>,
    /// `Yᵀ = J_x A⁻¹` (6 × n).
    yt: Vec<f64>,
    /// The rows of each `A_a` that can be non-zero (the frame's spans).
    supports: Vec<std::ops::Range<usize>>,
    /// `z_j` (c × n).
    zs: Vec<f64>,
    /// `A_a z_j` and `L⁻¹ A_a z_j` (k × c × n).
    az: Vec<f64>,
    la: Vec<f64>,
    /// `Yᵀ A_a z_j` and `K_x Yᵀ A_a z_j` (k × c × 6).
    ta: Vec<f64>,
    kta: Vec<f64>,
    /// `G_a = zsᵀ A_a zs` (k × c × c).
    g: Vec<f64>,
}

/// `K_x` at `x` (the factor of `A` and `Y = A⁻¹ J_xᵀ` stay in the objective's buffers).
pub(crate) struct EndAt {
    pub(crate) k_x: Matrix6<f64>,
}

impl<'a> EndObjective<'a> {
    #[cfg(test)]
    pub(crate) fn new(frame: &'a Frame, kind: Kind, scale: f64) -> EndObjective<'a> {
        Self::reusing(frame, kind, scale, EndBuffers::default())
    }

    /// For [`Self::end_at`] only (`K_x` at a point, no derivatives), in the buffers of an
    /// earlier objective.
    pub(crate) fn end_only(frame: &'a Frame, buffers: EndBuffers) -> EndObjective<'a> {
        Self::in_buffers(frame, Kind::Volume, 1.0, 0, buffers)
    }

    /// A smooth objective in the buffers of an earlier objective ([`Self::into_buffers`]):
    /// no allocation once they have the room.
    pub(crate) fn reusing(
        frame: &'a Frame,
        kind: Kind,
        scale: f64,
        buffers: EndBuffers,
    ) -> EndObjective<'a> {
        let columns = match kind {
            Kind::Along(_) | Kind::Compliance(_) => 1,
            Kind::Volume | Kind::Least => 3,
        };
        Self::in_buffers(frame, kind, scale, columns, buffers)
    }

    /// The buffers, for a later objective ([`Self::reusing`]).
    pub(crate) fn into_buffers(self) -> EndBuffers {
        self.b
    }

    fn in_buffers(
        frame: &'a Frame,
        kind: Kind,
        scale: f64,
        c: usize,
        mut b: EndBuffers,
    ) -> EndObjective<'a> {
        let (n, k) = (frame.n, frame.vars());
        let k = if c == 0 { 0 } else { k };
        let sized = |v: &mut Vec<f64>, len: usize| {
            v.clear();
            v.resize(len, 0.0);
        };
        sized(&mut b.a, n * n);
        sized(&mut b.yt, 6 * n);
        b.supports.clone_from(&frame.spans);
        sized(&mut b.zs, c * n);
        sized(&mut b.az, k * c * n);
        sized(&mut b.la, k * c * n);
        sized(&mut b.ta, k * c * 6);
        sized(&mut b.kta, k * c * 6);
        sized(&mut b.g, k * c * c);
        EndObjective { frame, kind, scale, gradient_only: false, b }
    }

    /// Factor `A(x)` and form `Y`, `C_x`, `K_x`; `None` where `A` is not positive definite or
    /// `J_x` has rank < 6.
    #[inline(always)]
    pub(crate) fn end_at(&mut self, x: &[f64]) -> Option<EndAt> {
        let n = self.frame.n;
        self.frame.a_at(x, &mut self.b.a);
        if !cholesky(&mut self.b.a, n) {
            return None;
        }
        let j_x = &self.frame.j_x;
        self.b.yt.copy_from_slice(&j_x[..6 * n]);
        for row in self.b.yt.chunks_exact_mut(n) {
            cholesky_solve(&self.b.a, n, row);
        }
        let c_x =
            Matrix6::from_fn(|r, c| dot(&j_x[r * n..r * n + n], &self.b.yt[c * n..c * n + n]));
        let c_x = 0.5 * (c_x + c_x.transpose());
        let k_x = compliance_inverse(&c_x).ok()?;
        Some(EndAt { k_x: 0.5 * (k_x + k_x.transpose()) })
    }

    /// `z_j = Y K_x m_j` for the 6-vectors `columns` into `self.b.zs`.
    #[inline(always)]
    fn v_times(&mut self, k_x: &Matrix6<f64>, columns: &[Vector6<f64>]) {
        let n = self.frame.n;
        for (m, z) in columns.iter().zip(self.b.zs.chunks_exact_mut(n)) {
            let km = k_x * m;
            z.fill(0.0);
            for (i, row) in self.b.yt.chunks_exact(n).enumerate() {
                axpy(km[i], row, z);
            }
        }
    }

    /// The gradient and Hessian (unscaled) of `form` with the `c` vectors `z_j` in
    /// `self.b.zs` (module docs): `P = A⁻¹` instead of the constrained inverse for the
    /// compliance, the `c × c` terms `G_a = Zᵀ A_a Z` for the volume and the least stiffness.
    #[inline(always)]
    fn forms(
        &mut self,
        k_x: &Matrix6<f64>,
        c: usize,
        form: Form,
        gradient: &mut [f64],
        hessian: &mut [f64],
    ) {
        let constrained = !matches!(form, Form::Compliance);
        // The vectors whose cross terms enter (the least stiffness: its eigenvector's only).
        let crossed = if matches!(form, Form::Least(_)) { 1 } else { c };
        let n = self.frame.n;
        let k = self.frame.vars();
        let zs = &self.b.zs[..c * n];
        // A_a z_j over the rows where A_a is not zero (A_a symmetric: rows against z).
        for (a, (ai, rows)) in self.frame.ai.iter().zip(&self.b.supports).enumerate() {
            for (j, z) in zs.chunks_exact(n).enumerate() {
                let out = &mut self.b.az[(a * c + j) * n..(a * c + j + 1) * n];
                out.fill(0.0);
                let w = rows.len();
                for (r, row) in rows.clone().zip(ai.chunks_exact(w.max(1))) {
                    out[r] = dot(row, &z[rows.clone()]);
                }
            }
        }
        // G_a = zsᵀ A_a zs (c × c); gradient = tr G_a.
        for a in 0..k {
            let mut trace = 0.0;
            for i in 0..c {
                for j in 0..c {
                    let rows = self.b.supports[a].clone();
                    let z = &zs[i * n..i * n + n][rows.clone()];
                    let v = dot(z, &self.b.az[(a * c + j) * n..][..n][rows]);
                    self.b.g[a * c * c + i * c + j] = v;
                    if i == j && (i == 0 || !matches!(form, Form::Least(_))) {
                        trace += v;
                    }
                }
            }
            gradient[a] = trace;
        }
        if self.gradient_only {
            return;
        }
        // L⁻¹ A_a z_j from the span's first row, and Yᵀ A_a z_j over the span.
        for (a, rows) in self.b.supports.iter().enumerate() {
            for j in 0..crossed {
                let at = (a * c + j) * n;
                let (az, la) = (&self.b.az[at..at + n], &mut self.b.la[at..at + n]);
                la.copy_from_slice(az);
                forward_solve_from(&self.b.a, n, la, rows.start.min(n));
                if !constrained {
                    continue;
                }
                let t = Vector6::from_fn(|i, _| {
                    dot(&self.b.yt[i * n..i * n + n][rows.clone()], &az[rows.clone()])
                });
                self.b.ta[(a * c + j) * 6..][..6].copy_from_slice(t.as_slice());
                self.b.kta[(a * c + j) * 6..][..6].copy_from_slice((k_x * t).as_slice());
            }
        }
        for a in 0..k {
            for b in a..k {
                let from = self.b.supports[a].start.max(self.b.supports[b].start).min(n);
                let mut cross = 0.0;
                for j in 0..crossed {
                    let (ra, rb) = ((a * c + j) * n, (b * c + j) * n);
                    cross += dot(&self.b.la[ra + from..ra + n], &self.b.la[rb + from..rb + n]);
                    if !constrained {
                        continue;
                    }
                    cross -= dot(
                        &self.b.ta[(a * c + j) * 6..][..6],
                        &self.b.kta[(b * c + j) * 6..][..6],
                    );
                }
                let (ga, gb) = (&self.b.g[a * c * c..][..c * c], &self.b.g[b * c * c..][..c * c]);
                let gg = match form {
                    Form::Volume => dot(ga, gb),
                    Form::Least(gaps) => {
                        -2.0 * (1..c).map(|j| ga[j] * gb[j] / gaps[j - 1]).sum::<f64>()
                    }
                    Form::Along | Form::Compliance => 0.0,
                };
                hessian[a * k + b] = -2.0 * cross - gg;
                hessian[b * k + a] = -2.0 * cross - gg;
            }
        }
    }
}

impl Smooth for EndObjective<'_> {
    /// Compiled once per instruction set and dispatched by pulp, as the method's own loop is
    /// (`sdp.rs`): the objective is called through `dyn Smooth`, outside that loop's dispatch,
    /// and its substitutions and dot products are the larger part of an iteration above 16 DOF.
    fn evaluate(&mut self, x: &[f64], gradient: &mut [f64], hessian: &mut [f64]) -> Option<f64> {
        pulp::Arch::new().dispatch(Evaluate { objective: self, x, gradient, hessian })
    }
}

/// [`EndObjective`]'s evaluation as a pulp operation.
struct Evaluate<'o, 'a, 'v> {
    objective: &'o mut EndObjective<'a>,
    x: &'v [f64],
    gradient: &'v mut [f64],
    hessian: &'v mut [f64],
}

impl pulp::WithSimd for Evaluate<'_, '_, '_> {
    type Output = Option<f64>;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> Option<f64> {
        self.objective.evaluate_body(self.x, self.gradient, self.hessian)
    }
}

impl EndObjective<'_> {
    #[inline(always)]
    fn evaluate_body(
        &mut self,
        x: &[f64],
        gradient: &mut [f64],
        hessian: &mut [f64],
    ) -> Option<f64> {
        let end = self.end_at(x)?;
        let k_x = end.k_x;
        let value = match self.kind {
            Kind::Along(w) => {
                self.v_times(&k_x, &[w]);
                self.forms(&k_x, 1, Form::Along, gradient, hessian);
                w.dot(&(k_x * w))
            }
            Kind::Volume => {
                let k_fd: Matrix3<f64> = k_x.fixed_view::<3, 3>(0, 0).into_owned();
                let l = k_fd.cholesky()?.l();
                let l_inv_t = l.try_inverse()?.transpose();
                // U = Y K_x [I₃; 0] L⁻ᵀ.
                let columns: [Vector6<f64>; 3] = std::array::from_fn(|a| {
                    Vector6::from_fn(|r, _| if r < 3 { l_inv_t[(r, a)] } else { 0.0 })
                });
                self.v_times(&k_x, &columns);
                self.forms(&k_x, 3, Form::Volume, gradient, hessian);
                2.0 * (0..3).map(|i| l[(i, i)].ln()).sum::<f64>()
            }
            Kind::Compliance(u) => {
                // z = A⁻¹ J_pᵀ u from the rows of Yᵀ = J_x A⁻¹; φ = −(J_pᵀ u)ᵀ z.
                let n = self.frame.n;
                let z = &mut self.b.zs[..n];
                z.fill(0.0);
                for (i, row) in self.b.yt.chunks_exact(n).take(3).enumerate() {
                    axpy(u[i], row, z);
                }
                let j_x = &self.frame.j_x;
                let value: f64 = (0..3).map(|i| -u[i] * dot(&j_x[i * n..i * n + n], z)).sum();
                self.forms(&k_x, 1, Form::Compliance, gradient, hessian);
                value
            }
            Kind::Least => {
                let k_fd: Matrix3<f64> = k_x.fixed_view::<3, 3>(0, 0).into_owned();
                let eigen = k_fd.symmetric_eigen();
                let mut order = [0, 1, 2];
                order.sort_by(|i, j| eigen.eigenvalues[*i].total_cmp(&eigen.eigenvalues[*j]));
                let lambda = order.map(|i| eigen.eigenvalues[i]);
                let gaps = [lambda[0] - lambda[1], lambda[0] - lambda[2]];
                // A least eigenvalue within 1e-9 of the next is repeated to rounding: there
                // `λ_min` has no gradient.
                if gaps.iter().any(|g| g.is_nan() || *g >= -1e-9 * lambda[2].abs()) {
                    return None;
                }
                let columns: [Vector6<f64>; 3] = std::array::from_fn(|j| {
                    Vector6::from_fn(
                        |r, _| if r < 3 { eigen.eigenvectors[(r, order[j])] } else { 0.0 },
                    )
                });
                self.v_times(&k_x, &columns);
                self.forms(&k_x, 3, Form::Least(gaps), gradient, hessian);
                lambda[0]
            }
        };
        let s = 1.0 / self.scale;
        gradient.iter_mut().for_each(|g| *g *= s);
        if !self.gradient_only {
            hessian.iter_mut().for_each(|h| *h *= s);
        }
        value.is_finite().then_some(value * s)
    }
}
