//! The joint stiffness as an affine function of the equilibrium set's coordinates, and the end
//! stiffness functions of it with their supergradients.
//!
//! # Math
//! On `f = f_p + N λ` the controllable stiffness `Σ_c f_c H_c` is linear in `f` and the inherent
//! part `J_cᵀ K_l J_c` does not depend on it, so
//! `A(λ) = K_q(λ) + K_W = A_0 + Σ_i λ_i A_i` with `A_0 = J_cᵀ K_l J_c + Σ_c f_p,c H_c + K_W` and
//! `A_i = Σ_c N_ci H_c`. Where `A ≻ 0`, `C_x = J_x A⁻¹ J_xᵀ` and `K_x = C_x⁻¹`, and
//! `wᵀ K_x w = min { δqᵀ A δq : J_x δq = w }` is concave in `λ`, with supergradient
//! `∂/∂λ_i = zᵀ A_i z`, `z = A⁻¹ J_xᵀ K_x w` (the minimiser). Likewise `−uᵀ C_x u` with
//! `z = A⁻¹ J_xᵀ u`, `λ_min(K_fd)` (its eigenvector's `w`), `log det K_fd`
//! (`Σ_a y_aᵀ A_i y_a`, `Y = A⁻¹ J_xᵀ K_x[:, 0:3] L⁻ᵀ`, `L Lᵀ = K_fd`) and the stability
//! margin `λ_min(A)` (its eigenvector `v`: `vᵀ A_i v`).

use faer::linalg::solvers::Solve;
use faer::{Mat, MatRef, Side};
use nalgebra::{Matrix3, Matrix6, SymmetricEigen, Vector3, Vector6};

use sinew_routing::{FrictionData, FrictionModel};
use sinew_statics::EquilibriumSet;
use sinew_stiffness::{
    ArmStiffness, ArmStiffnessData, FrictionStiffnessData, History, compliance_inverse,
    stick_stiffness,
};

use crate::error::PlanError;

/// `A(λ) = A_0 + Σ λ_i A_i` with `J_x`, at one pose and load.
#[derive(Debug, Clone)]
pub(crate) struct Pencil {
    pub(crate) a0: Mat<f64>,
    pub(crate) ai: Vec<Mat<f64>>,
    pub(crate) j_x: Mat<f64>,
    /// Scratch: one column of `N` as cable weights.
    pub(crate) weights: Vec<f64>,
    /// Scratch: `K_W`.
    pub(crate) k_w: Mat<f64>,
    /// The DOFs `A_i` can be non-zero on (rows and columns): the union of the cables' DOFs
    /// that `N`'s column `i` weighs (`A_i = Σ_c N_ci H_c`, and `H_c` lives on cable `c`'s
    /// DOFs; so does its stick stiffness). A decoupled `A_i` is one joint's 2 × 2 block.
    pub(crate) spans: Vec<std::ops::Range<usize>>,
    /// Whether the `A_i` may be non-zero outside their spans: after the stick regime's fill
    /// (which writes them whole) or one that did not complete.
    whole: bool,
}

/// The end quantities at a point where `A ≻ 0`.
pub(crate) struct End {
    /// `A⁻¹ J_xᵀ` (dof × 6).
    y: Mat<f64>,
    pub(crate) c_x: Matrix6<f64>,
    /// `None` when `C_x` is singular (`J_x` rank-deficient).
    pub(crate) k_x: Option<Matrix6<f64>>,
}

impl Pencil {
    /// `A_0` and the `A_i` of `arm` at the pose of `sd` (after a tension stage there: `K_i` and
    /// `K_W`), into this pencil's buffers (a plan's pencil is kept in its workspace:
    /// re-planning along a trajectory allocates none of it again).
    pub(crate) fn fill(
        &mut self,
        arm: &ArmStiffness,
        sd: &mut ArmStiffnessData,
        set: &EquilibriumSet,
    ) -> Result<(), PlanError> {
        let routing = arm.routing();
        let dof = arm.dof();
        self.size(dof, set.dimension());
        // Σ_c f_p,c H_c and every A_i = Σ_c N_ci H_c in one pass over the segments' Hessians
        // (each entry summed in segment order, as `add_weighted_hessians` does), then K_i + K_W
        // entry by entry.
        // Each cable's weights in A_0 and in every A_i (`f_p,c`, then row c of N), read once:
        // a cable has several segments.
        let (null, particular) = (set.null_basis(), set.particular());
        let targets = set.dimension() + 1;
        self.weights.clear();
        for (c, &p) in particular.iter().enumerate() {
            self.weights.push(p);
            self.weights.extend((0..targets - 1).map(|i| null[(c, i)]));
        }
        for (seg, h) in sd.cables.segment_hessians(routing)?.iter() {
            let (lo, n, c) = (seg.dofs.start, seg.dofs.len(), seg.cable);
            let Some(weights) = self.weights.get(c * targets..(c + 1) * targets) else {
                continue;
            };
            if n == 0 || h.len() != n * n {
                continue;
            }
            let matrices = std::iter::once(&mut self.a0).chain(self.ai.iter_mut());
            for (a, &w) in matrices.zip(weights) {
                add_block(a, lo, n, h, w);
            }
        }
        self.k_w.copy_from(sd.k_w());
        let k_inherent = sd.k_inherent();
        for c in 0..dof {
            let (a0, k_w) = (self.a0.col_as_slice_mut(c), self.k_w.col_as_slice(c));
            for ((a, w), k) in a0.iter_mut().zip(k_w).zip(k_inherent.col(c).iter()) {
                *a += k + w;
            }
        }
        self.copy_j_x(sd.j_x());
        self.fill_spans(arm, set);
        self.whole = false;
        Ok(())
    }

    /// The pencil of the stick regime after `history` (spec §9): `A(λ) = K_stick(f_p + N λ) +
    /// K_W`, affine in the actuator tensions because the segment tensions are theirs times the
    /// history's weights (`T_s = T_0 w_s`) and the segment springs do not depend on them:
    /// `A_0 = K_stick(f_p) + K_W` and `A_i` the controllable part at the tensions `N e_i`
    /// ([`sinew_stiffness::stick_stiffness`], which takes any real tensions). `set` is the
    /// equilibrium set of the regime's statics (through `J̃` after a pull or a release) and
    /// `friction` the friction geometry at the pose of `sd`, with the history's weights.
    pub(crate) fn fill_stick(
        &mut self,
        arm: &ArmStiffness,
        sd: &mut ArmStiffnessData,
        (model, friction, history): (&FrictionModel, &FrictionData, History),
        set: &EquilibriumSet,
        scratch: &mut FrictionStiffnessData,
    ) -> Result<(), PlanError> {
        let routing = arm.routing();
        let dof = arm.dof();
        self.size(dof, set.dimension());
        let geometry = &sd.cables;
        stick_stiffness(model, routing, geometry, friction, history, set.particular(), scratch)?;
        self.a0.copy_from(scratch.stiffness()?);
        let null = set.null_basis();
        self.weights.resize(set.cable_count(), 0.0);
        for (i, a) in self.ai.iter_mut().enumerate() {
            for (c, w) in self.weights.iter_mut().enumerate() {
                *w = null[(c, i)];
            }
            stick_stiffness(model, routing, geometry, friction, history, &self.weights, scratch)?;
            a.copy_from(scratch.controllable()?);
        }
        self.k_w.copy_from(sd.k_w());
        for c in 0..dof {
            for r in 0..dof {
                self.a0[(r, c)] += self.k_w[(r, c)];
            }
        }
        self.copy_j_x(sd.j_x());
        self.fill_spans(arm, set);
        Ok(())
    }

    /// `A_0`, `K_W` and `k` coefficients of `dof × dof`, zero. An `A_i` of the last fill of the
    /// same size is zeroed over its span only, where that fill wrote it (the cables' Hessians
    /// live on their DOFs): a 200-DOF chain's 100 coefficients would otherwise be 32 MB of
    /// stores per plan.
    /// [`Pencil::spans`] of `set`'s null basis over `arm`'s cables.
    fn fill_spans(&mut self, arm: &ArmStiffness, set: &EquilibriumSet) {
        let (cables, null) = (arm.routing().cables(), set.null_basis());
        self.spans.clear();
        for i in 0..set.dimension() {
            let span = (0..set.cable_count().min(cables.len()))
                .filter(|&c| null[(c, i)] != 0.0)
                .map(|c| &cables[c].dofs)
                .fold(None, |acc: Option<std::ops::Range<usize>>, d| match acc {
                    None => Some(d.clone()),
                    Some(a) => Some(a.start.min(d.start)..a.end.max(d.end)),
                });
            self.spans.push(span.unwrap_or(0..0));
        }
    }

    fn size(&mut self, dof: usize, k: usize) {
        let reset = |a: &mut Mat<f64>| {
            if a.nrows() == dof && a.ncols() == dof {
                a.fill(0.0);
            } else {
                *a = Mat::zeros(dof, dof);
            }
        };
        reset(&mut self.a0);
        reset(&mut self.k_w);
        self.ai.truncate(k);
        for (i, a) in self.ai.iter_mut().enumerate() {
            match self.spans.get(i) {
                Some(span) if !self.whole && a.nrows() == dof && a.ncols() == dof => {
                    for c in span.clone() {
                        a.col_as_slice_mut(c)[span.clone()].fill(0.0);
                    }
                }
                _ => reset(a),
            }
        }
        self.ai.resize_with(k, || Mat::zeros(dof, dof));
        // Until a fill completes, where it writes is not known.
        self.whole = true;
    }

    fn copy_j_x(&mut self, j_x: MatRef<'_, f64>) {
        if self.j_x.nrows() == j_x.nrows() && self.j_x.ncols() == j_x.ncols() {
            self.j_x.copy_from(j_x);
        } else {
            self.j_x = j_x.to_owned();
        }
    }

    /// A pencil with no buffers yet ([`Pencil::fill`] sizes them).
    pub(crate) fn empty() -> Pencil {
        Pencil {
            a0: Mat::zeros(0, 0),
            ai: Vec::new(),
            j_x: Mat::zeros(0, 0),
            weights: Vec::new(),
            k_w: Mat::zeros(0, 0),
            spans: Vec::new(),
            whole: true,
        }
    }

    /// `A(λ)`, symmetrised.
    pub(crate) fn at(&self, lambda: &[f64]) -> Mat<f64> {
        let n = self.a0.nrows();
        Mat::from_fn(n, n, |r, c| {
            let mut v = 0.5 * (self.a0[(r, c)] + self.a0[(c, r)]);
            for (l, a) in lambda.iter().zip(&self.ai) {
                v += l * 0.5 * (a[(r, c)] + a[(c, r)]);
            }
            v
        })
    }

    /// `(zᵀ A_i z)_i`.
    pub(crate) fn forms(&self, z: MatRef<'_, f64>) -> Vec<f64> {
        let n = z.nrows();
        self.ai
            .iter()
            .map(|a| {
                let mut s = 0.0;
                for col in 0..z.ncols() {
                    for r in 0..n {
                        let zr = z[(r, col)];
                        if zr == 0.0 {
                            continue;
                        }
                        for c in 0..n {
                            s += zr * a[(r, c)] * z[(c, col)];
                        }
                    }
                }
                s
            })
            .collect()
    }

    /// The stability margin `λ_min(A(λ))` and its supergradient.
    pub(crate) fn margin(&self, lambda: &[f64]) -> Result<(f64, Vec<f64>), PlanError> {
        let a = self.at(lambda);
        let eigen = a
            .self_adjoint_eigen(Side::Lower)
            .map_err(|_| PlanError::Numerical { what: "eigendecomposition of K_q + K_W" })?;
        let value = eigen.S().column_vector()[0];
        let v = eigen.U().subcols(0, 1);
        Ok((value, self.forms(v)))
    }

    /// `C_x` and `K_x` at `λ`, `None` where `A(λ)` is not positive definite.
    pub(crate) fn end(&self, lambda: &[f64]) -> Option<End> {
        let a = self.at(lambda);
        let llt = a.llt(Side::Lower).ok()?;
        let y = llt.solve(self.j_x.transpose());
        let c_x = Matrix6::from_fn(|r, c| {
            (0..y.nrows()).map(|d| self.j_x[(r, d)] * y[(d, c)]).sum::<f64>()
        });
        let c_x = 0.5 * (c_x + c_x.transpose());
        // K_x only where J_x has full rank: the pipeline's one test of it, on C_x.
        let k_x = compliance_inverse(&c_x).ok().map(|k| 0.5 * (k + k.transpose()));
        if !c_x.iter().all(|v| v.is_finite()) {
            return None;
        }
        Some(End { y, c_x, k_x })
    }
}

impl End {
    /// `K_fd = K_x[0:3, 0:3]`.
    pub(crate) fn k_fd(&self) -> Option<Matrix3<f64>> {
        self.k_x.map(|k| k.fixed_view::<3, 3>(0, 0).into_owned())
    }

    /// `wᵀ K_x w` and its gradient in `λ`.
    pub(crate) fn stiffness_form(
        &self,
        pencil: &Pencil,
        w: &Vector6<f64>,
    ) -> Option<(f64, Vec<f64>)> {
        let k_x = self.k_x?;
        let kw = k_x * w;
        let z =
            Mat::from_fn(self.y.nrows(), 1, |d, _| (0..6).map(|j| self.y[(d, j)] * kw[j]).sum());
        Some((w.dot(&kw), pencil.forms(z.as_ref())))
    }

    /// `−uᵀ C_x[0:3, 0:3] u` (the compliance along `u` with rotations free, negated) and its
    /// gradient.
    pub(crate) fn compliance_form(&self, pencil: &Pencil, u: &Vector3<f64>) -> (f64, Vec<f64>) {
        let z = Mat::from_fn(self.y.nrows(), 1, |d, _| (0..3).map(|j| self.y[(d, j)] * u[j]).sum());
        let c = self.c_x.fixed_view::<3, 3>(0, 0).into_owned();
        (-(u.dot(&(c * u))), pencil.forms(z.as_ref()))
    }

    /// `λ_min(K_fd)` (of `S⁻¹ K_fd S⁻ᵀ` when `scale = S` is given) and its supergradient.
    pub(crate) fn least_stiffness(
        &self,
        pencil: &Pencil,
        scale: Option<&Matrix3<f64>>,
    ) -> Option<(f64, Vec<f64>)> {
        let k_fd = self.k_fd()?;
        let (m, back) = match scale {
            Some(s) => {
                let s_inv = s.try_inverse()?;
                (s_inv * k_fd * s_inv.transpose(), s_inv.transpose())
            }
            None => (k_fd, Matrix3::identity()),
        };
        let eigen = SymmetricEigen::new(0.5 * (m + m.transpose()));
        let i = eigen.eigenvalues.imin();
        let v = back * eigen.eigenvectors.column(i).into_owned();
        let w = Vector6::new(v.x, v.y, v.z, 0.0, 0.0, 0.0);
        let (_, gradient) = self.stiffness_form(pencil, &w)?;
        Some((eigen.eigenvalues[i], gradient))
    }

    /// `log det K_fd` and its gradient.
    pub(crate) fn log_volume(&self, pencil: &Pencil) -> Option<(f64, Vec<f64>)> {
        let k_x = self.k_x?;
        let k_fd = self.k_fd()?;
        let l = k_fd.cholesky()?.l();
        let l_inv_t = l.try_inverse()?.transpose();
        // Y = A⁻¹ J_xᵀ K_x[:, 0:3] L⁻ᵀ (dof × 3).
        let k3 = k_x.fixed_view::<6, 3>(0, 0).into_owned() * l_inv_t;
        let z = Mat::from_fn(self.y.nrows(), 3, |d, a| {
            (0..6).map(|j| self.y[(d, j)] * k3[(j, a)]).sum()
        });
        let value = 2.0 * (0..3).map(|i| l[(i, i)].ln()).sum::<f64>();
        Some((value, pencil.forms(z.as_ref())))
    }
}

/// `out[lo.., lo..] += w · h` for a segment's Hessian block `h` (n × n, column-major), column
/// slice by column slice (`n ≥ 1`); nothing for `w = 0` (a cable outside a null column).
fn add_block(out: &mut Mat<f64>, lo: usize, n: usize, h: &[f64], w: f64) {
    if w == 0.0 {
        return;
    }
    if let ([h00, h10, h01, h11], 2) = (h, n) {
        // A joint's 2 × 2 block (every routed and decoupled segment of the pattern): the same
        // sums without the loops.
        let col = &mut out.col_as_slice_mut(lo)[lo..lo + 2];
        col[0] += w * h00;
        col[1] += w * h10;
        let col = &mut out.col_as_slice_mut(lo + 1)[lo..lo + 2];
        col[0] += w * h01;
        col[1] += w * h11;
        return;
    }
    for (k, h) in h.chunks_exact(n).enumerate() {
        let col = &mut out.col_as_slice_mut(lo + k)[lo..lo + n];
        for (v, h) in col.iter_mut().zip(h) {
            *v += w * h;
        }
    }
}
