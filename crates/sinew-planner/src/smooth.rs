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
//! Both Hessians are `⪯ 0` (Gram forms with `P ⪰ 0`): the objectives are concave, as
//! `wᵀ K_x w = min { δqᵀ A δq : J_x δq = w }` is a minimum of affine functions of `x`.

use nalgebra::{Matrix3, Matrix6, Vector6};
use sinew_stiffness::compliance_inverse;

use crate::dense::{cholesky, cholesky_solve};
use crate::frame::Frame;
use crate::sdp::Smooth;

/// Which smooth objective.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Kind {
    /// `wᵀ K_x w` with `w = (u, 0)`.
    Along(Vector6<f64>),
    /// `log det K_fd`.
    Volume,
}

/// A smooth objective on a frame, divided by `scale`.
pub(crate) struct EndObjective<'a> {
    pub(crate) frame: &'a Frame,
    pub(crate) kind: Kind,
    pub(crate) scale: f64,
    a: Vec<f64>,
    y: Vec<f64>,
    column: Vec<f64>,
}

/// `K_x` at `x` (the factor of `A` and `Y = A⁻¹ J_xᵀ` stay in the objective's buffers).
pub(crate) struct EndAt {
    pub(crate) k_x: Matrix6<f64>,
}

impl<'a> EndObjective<'a> {
    pub(crate) fn new(frame: &'a Frame, kind: Kind, scale: f64) -> EndObjective<'a> {
        let n = frame.n;
        EndObjective {
            frame,
            kind,
            scale,
            a: vec![0.0; n * n],
            y: vec![0.0; n * 6],
            column: vec![0.0; n],
        }
    }

    /// Factor `A(x)` and form `Y`, `C_x`, `K_x`; `None` where `A` is not positive definite or
    /// `J_x` has rank < 6.
    pub(crate) fn end_at(&mut self, x: &[f64]) -> Option<EndAt> {
        let n = self.frame.n;
        self.frame.a_at(x, &mut self.a);
        if !cholesky(&mut self.a, n) {
            return None;
        }
        for j in 0..6 {
            self.column.copy_from_slice(&self.frame.j_x[j * n..j * n + n]);
            cholesky_solve(&self.a, n, &mut self.column);
            for d in 0..n {
                self.y[d * 6 + j] = self.column[d];
            }
        }
        let j_x = &self.frame.j_x;
        let c_x = Matrix6::from_fn(|r, c| (0..n).map(|d| j_x[r * n + d] * self.y[d * 6 + c]).sum());
        let c_x = 0.5 * (c_x + c_x.transpose());
        let k_x = compliance_inverse(&c_x).ok()?;
        Some(EndAt { k_x: 0.5 * (k_x + k_x.transpose()) })
    }

    /// `P v` for the factor in `self.a` (after [`Self::end_at`]).
    fn p_times(&self, k_x: &Matrix6<f64>, v: &[f64], out: &mut [f64]) {
        let n = self.frame.n;
        out.copy_from_slice(v);
        cholesky_solve(&self.a, n, out);
        let ytv = Vector6::from_fn(|j, _| (0..n).map(|d| self.y[d * 6 + j] * v[d]).sum());
        let kv = k_x * ytv;
        for (d, o) in out.iter_mut().enumerate() {
            *o -= (0..6).map(|j| self.y[d * 6 + j] * kv[j]).sum::<f64>();
        }
    }

    /// `Y K_x M` for a 6 × c matrix `M` given by columns: n × c row-major.
    fn v_times(&self, k_x: &Matrix6<f64>, columns: &[Vector6<f64>]) -> Vec<f64> {
        let n = self.frame.n;
        let c = columns.len();
        let mut out = vec![0.0; n * c];
        for (j, m) in columns.iter().enumerate() {
            let km = k_x * m;
            for d in 0..n {
                out[d * c + j] = (0..6).map(|i| self.y[d * 6 + i] * km[i]).sum();
            }
        }
        out
    }

    /// `A_a z` for every free coordinate, each z a column of the n × c matrix `zs`: per
    /// coordinate n × c row-major.
    fn pencil_times(&self, zs: &[f64], c: usize) -> Vec<Vec<f64>> {
        let n = self.frame.n;
        self.frame
            .ai
            .iter()
            .map(|a| {
                let mut out = vec![0.0; n * c];
                for r in 0..n {
                    for p in 0..n {
                        let v = a[r * n + p];
                        if v == 0.0 {
                            continue;
                        }
                        for j in 0..c {
                            out[r * c + j] += v * zs[p * c + j];
                        }
                    }
                }
                out
            })
            .collect()
    }

    /// The value, gradient and Hessian (unscaled) with `zs` the n × c matrix of the method
    /// (`z` or `U`) and the 3 × 3 `G_a` terms when `volume`.
    fn forms(
        &self,
        k_x: &Matrix6<f64>,
        zs: &[f64],
        c: usize,
        volume: bool,
        gradient: &mut [f64],
        hessian: &mut [f64],
    ) {
        let n = self.frame.n;
        let k = self.frame.vars();
        let az = self.pencil_times(zs, c);
        // G_a = zsᵀ A_a zs (c × c); gradient = tr G_a.
        let g: Vec<Vec<f64>> = az
            .iter()
            .map(|a| {
                let mut m = vec![0.0; c * c];
                for i in 0..c {
                    for j in 0..c {
                        m[i * c + j] = (0..n).map(|d| zs[d * c + i] * a[d * c + j]).sum();
                    }
                }
                m
            })
            .collect();
        for a in 0..k {
            gradient[a] = (0..c).map(|i| g[a][i * c + i]).sum();
        }
        // P A_b z, column by column.
        let mut column = vec![0.0; n];
        let mut p_out = vec![0.0; n];
        let pa: Vec<Vec<f64>> = az
            .iter()
            .map(|a| {
                let mut out = vec![0.0; n * c];
                for j in 0..c {
                    for d in 0..n {
                        column[d] = a[d * c + j];
                    }
                    self.p_times(k_x, &column, &mut p_out);
                    for d in 0..n {
                        out[d * c + j] = p_out[d];
                    }
                }
                out
            })
            .collect();
        for a in 0..k {
            for b in 0..k {
                let cross: f64 = az[a].iter().zip(&pa[b]).map(|(x, y)| x * y).sum();
                let gg: f64 =
                    if volume { g[a].iter().zip(&g[b]).map(|(x, y)| x * y).sum() } else { 0.0 };
                hessian[a * k + b] = -2.0 * cross - gg;
            }
        }
        crate::dense::symmetrise(hessian, k);
    }
}

impl Smooth for EndObjective<'_> {
    fn evaluate(&mut self, x: &[f64], gradient: &mut [f64], hessian: &mut [f64]) -> Option<f64> {
        let end = self.end_at(x)?;
        let k_x = end.k_x;
        let value = match self.kind {
            Kind::Along(w) => {
                let z = self.v_times(&k_x, &[w]);
                self.forms(&k_x, &z, 1, false, gradient, hessian);
                w.dot(&(k_x * w))
            }
            Kind::Volume => {
                let k_fd: Matrix3<f64> = k_x.fixed_view::<3, 3>(0, 0).into_owned();
                let l = k_fd.cholesky()?.l();
                let l_inv_t = l.try_inverse()?.transpose();
                // U = Y K_x [I₃; 0] L⁻ᵀ.
                let columns: Vec<Vector6<f64>> = (0..3)
                    .map(|a| Vector6::from_fn(|r, _| if r < 3 { l_inv_t[(r, a)] } else { 0.0 }))
                    .collect();
                let u = self.v_times(&k_x, &columns);
                self.forms(&k_x, &u, 3, true, gradient, hessian);
                2.0 * (0..3).map(|i| l[(i, i)].ln()).sum::<f64>()
            }
        };
        let s = 1.0 / self.scale;
        gradient.iter_mut().for_each(|g| *g *= s);
        hessian.iter_mut().for_each(|h| *h *= s);
        value.is_finite().then_some(value * s)
    }
}
