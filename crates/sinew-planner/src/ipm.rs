//! The interior-point planner's phases on a [`Frame`]: a point inside the rows, a stable
//! point (the margin maximised until it is met, or the proof that it cannot be), a point
//! meeting the stiffness floors, then the objective, each a run of [`crate::sdp`] on the
//! blocks of the problem.
//!
//! # The blocks (module docs of `lib.rs` for the math)
//! - margin: `A(x) − m I ⪰ 0`;
//! - a stiffness floor `K_fd ⪰ τ K` (`K = I` for `k_min` and the least stiffness, `K_des`):
//!   `Rᵀ(A − τ J_pᵀ K J_p) R ⪰ 0`, `R` a basis of `null(J_r)` (rotation held);
//! - the compliance along `u` with rotations free, `uᵀ J_p A⁻¹ J_pᵀ u ≤ s`:
//!   `[[A, J_pᵀu], [uᵀJ_p, s]] ⪰ 0`.
//!
//! Each block is divided by a scale of its constant so that its entries are O(1).

use nalgebra::{DMatrix, Matrix3, Vector6};

use crate::blocks::{Floor, base, compliance_block, floor_block, margin_block};
use crate::error::PlanError;
use crate::frame::Frame;
use crate::problem::{Objective, PlanSettings, Requirements};
use crate::sdp::{self, Block, End, Run, Settings};
use crate::smooth::{EndObjective, Kind};

/// How far past its target a feasibility phase goes, as a fraction of the bound's excess: a
/// start well inside the margin and the floors, not on their boundary.
const CENTRING: f64 = 0.3;

/// Above this many DOFs the last phase checks the margin lazily ([`Interior::optimise`]): up to
/// it, the fixed-size kernels make the margin's block cheap.
pub(crate) const LAZY_MARGIN_DOF: usize = 16;

/// One plan's interior-point problem.
pub(crate) struct Interior<'a> {
    pub(crate) frame: &'a Frame,
    pub(crate) objective: Objective,
    pub(crate) requirements: &'a Requirements,
    pub(crate) settings: &'a PlanSettings,
    /// `R` (n × (n − 3)), when `J_r` has rank 3 and a floor block needs it (`None` when
    /// none does).
    pub(crate) rotation_null: Option<Vec<f64>>,
    /// A warm start: epigraph variables start just inside their block, not halfway.
    pub(crate) warm: bool,
}

/// The answer of the last phase in the frame's coordinates, with the real-unit bound.
#[derive(Debug, Clone)]
pub(crate) struct Answer {
    pub(crate) x: Vec<f64>,
    /// An upper bound of the objective in the plan's sense (maximised), real units.
    pub(crate) upper: f64,
    pub(crate) iterations: usize,
}

impl<'a> Interior<'a> {
    pub(crate) fn new(
        frame: &'a Frame,
        objective: Objective,
        requirements: &'a Requirements,
        settings: &'a PlanSettings,
    ) -> Interior<'a> {
        Interior {
            frame,
            objective,
            requirements,
            settings,
            rotation_null: (matches!(objective, Objective::MinStiffness)
                || requirements.k_min.is_some()
                || requirements.k_des.is_some())
            .then(|| frame.rotation_null_basis())
            .flatten(),
            warm: false,
        }
    }

    fn no_stable_tensions(&self, best: f64) -> PlanError {
        PlanError::NoStableTensions {
            margin: self.requirements.margin,
            best,
            budget: self.requirements.budget.is_some(),
        }
    }

    /// `λ_min(A(x))`, N m/rad (one symmetric eigensolve, outside the iterations).
    pub(crate) fn margin_at(&self, x: &[f64]) -> f64 {
        let n = self.frame.n;
        let mut a = vec![0.0; n * n];
        self.frame.a_at(x, &mut a);
        DMatrix::from_row_slice(n, n, &a).symmetric_eigenvalues().min()
    }

    /// Whether `λ_min(A(x)) > m`: one Cholesky trial of `A(x) − m I`.
    fn margin_exceeds(&self, x: &[f64], m: f64) -> bool {
        let n = self.frame.n;
        let mut a = vec![0.0; n * n];
        self.frame.a_at(x, &mut a);
        for i in 0..n {
            a[i * n + i] -= m;
        }
        crate::dense::cholesky(&mut a, n)
    }

    /// `K_x` at `x` (`None` where `A ⊁ 0` or `J_x` has rank < 6).
    fn k_x_at(&self, x: &[f64]) -> Option<nalgebra::Matrix6<f64>> {
        EndObjective::end_only(self.frame).end_at(x).map(|e| e.k_x)
    }

    fn settings(&self, target: Option<f64>, relative_gap: f64, scale: f64) -> Settings {
        Settings {
            relative_gap,
            scale,
            max_iterations: self.settings.max_iterations,
            target,
            centring: CENTRING,
        }
    }

    /// Phase 0: a point strictly inside the rows, near their Chebyshev centre.
    ///
    /// # Errors
    /// [`PlanError::BudgetsInfeasible`] when no point meets the rows.
    pub(crate) fn inside_rows(&self) -> Result<(Vec<f64>, usize), PlanError> {
        let f = self.frame;
        let k = f.vars();
        let x0 = vec![0.0; k];
        let least = f.rhs.iter().copied().fold(f64::INFINITY, f64::min);
        if least > 1e-3 || f.rhs.is_empty() {
            return Ok((x0, 0));
        }
        // max τ s.t. G x + τ 1 ≤ h, τ ≤ 1; τ's box [τ₀ − 1, 1] holds the optimum.
        let mut sdp = base(self.frame, 1);
        for r in 0..f.rhs.len() {
            sdp.rows[r * (k + 1) + k] = 1.0;
        }
        sdp.rows.extend(std::iter::repeat_n(0.0, k));
        sdp.rows.push(1.0);
        sdp.rhs.push(1.0);
        let tau0 = least - 1.0;
        sdp.c[k] = 1.0;
        sdp.lo[k] = tau0 - 1.0;
        sdp.hi[k] = 1.0;
        let mut start = x0;
        start.push(tau0);
        // Until τ > 0 well inside (or the bound proves τ* ≤ 0: no point strictly inside).
        let run = sdp::solve(&sdp, None, &start, self.settings(Some(0.0), 1e-9, 1e-9));
        match run.end {
            End::Reached => {
                let mut x = run.x;
                x.pop();
                Ok((x, run.iterations))
            }
            End::Unreachable | End::Optimum => Err(PlanError::BudgetsInfeasible),
            _ => Err(not_converged(&run, 1e-9)),
        }
    }

    /// Phase 1: from `x` inside the rows, a point with margin ≥ the requirement.
    ///
    /// # Errors
    /// [`PlanError::NoStableTensions`] with the certified bound of the best margin.
    pub(crate) fn stable(&self, x: Vec<f64>) -> Result<(Vec<f64>, usize), PlanError> {
        let f = self.frame;
        let m = self.requirements.margin;
        if self.margin_exceeds(&x, m) {
            return Ok((x, 0));
        }
        let now = self.margin_at(&x);
        if now > m {
            return Ok((x, 0));
        }
        let k = f.vars();
        let mut sdp = base(self.frame, 1);
        sdp.blocks.push(margin_block(self.frame, 0.0, 1, Some(f.a_scale)));
        sdp.c[k] = 1.0;
        sdp.epigraph = Some((k, 0));
        let mut start = x;
        start.push((now - 0.05 * f.a_scale.max(now.abs())) / f.a_scale);
        let target = (m + 1e-9 * m.max(f.a_scale * 1e-6)) / f.a_scale;
        let run = sdp::solve(&sdp, None, &start, self.settings(Some(target), 1e-9, 1e-9));
        match run.end {
            End::Reached => {
                let mut x = run.x;
                x.pop();
                Ok((x, run.iterations))
            }
            End::Unreachable | End::Optimum => Err(self.no_stable_tensions(run.upper * f.a_scale)),
            _ => Err(not_converged(&run, 1e-9)),
        }
    }

    /// The floors of the requirements, in order (`k_min`, then `K_des`): `(K, τ)`.
    pub(crate) fn floors(&self) -> Vec<(Floor, f64, &'static str)> {
        let mut out = Vec::new();
        if let Some(k) = self.requirements.k_min {
            out.push((Floor { k: Matrix3::identity() }, k, "least stiffness λ_min(K_fd), N/m,"));
        }
        if let Some(k) = self.requirements.k_des {
            out.push((Floor { k }, 1.0, "K_fd ⪰ τ K_des, τ"));
        }
        out
    }

    /// The margin (unless `lazy`) and the floors met so far as fixed blocks, with `extra`
    /// columns.
    fn constraint_blocks(
        &self,
        floors: usize,
        extra: usize,
        lazy: bool,
    ) -> Result<Vec<Block>, PlanError> {
        let mut blocks = Vec::new();
        if !lazy {
            blocks.push(margin_block(self.frame, self.requirements.margin, extra, None));
        }
        for (floor, tau, _) in self.floors().into_iter().take(floors) {
            blocks.push(
                floor_block(self.frame, self.rotation_null.as_ref(), floor, Ok(tau), extra)
                    .ok_or(PlanError::NoEndStiffness)?,
            );
        }
        Ok(blocks)
    }

    /// The least `τ` with `K_fd ⪰ τ K` at `x` (the generalised eigenvalue).
    pub(crate) fn floor_value(&self, x: &[f64], floor: &Floor) -> Option<f64> {
        let k_fd = self.k_x_at(x)?.fixed_view::<3, 3>(0, 0).into_owned();
        let l = floor.k.cholesky()?.l();
        let l_inv = l.try_inverse()?;
        let m = l_inv * k_fd * l_inv.transpose();
        Some(nalgebra::SymmetricEigen::new(0.5 * (m + m.transpose())).eigenvalues.min())
    }

    /// Phase 1b: from a stable `x`, a point meeting every stiffness floor.
    ///
    /// # Errors
    /// [`PlanError::RequirementUnreachable`] with the certified bound;
    /// [`PlanError::NoEndStiffness`] when `K_x` does not exist.
    pub(crate) fn floors_met(&self, mut x: Vec<f64>) -> Result<(Vec<f64>, usize), PlanError> {
        let mut iterations = 0;
        let k = self.frame.vars();
        for (index, (floor, tau, what)) in self.floors().into_iter().enumerate() {
            let now = self.floor_value(&x, &floor).ok_or(PlanError::NoEndStiffness)?;
            if now > tau {
                continue;
            }
            let scale = now.abs().max(tau.abs()).max(1e-12);
            let mut sdp = base(self.frame, 1);
            sdp.blocks = self.constraint_blocks(index, 1, false)?;
            let epigraph =
                floor_block(self.frame, self.rotation_null.as_ref(), floor, Err(scale), 1)
                    .ok_or(PlanError::NoEndStiffness)?;
            sdp.blocks.push(epigraph);
            sdp.c[k] = 1.0;
            sdp.epigraph = Some((k, sdp.blocks.len() - 1));
            let mut start = x.clone();
            start.push((now - 0.05 * scale) / scale);
            let target = (tau + 1e-9 * scale) / scale;
            let run = sdp::solve(&sdp, None, &start, self.settings(Some(target), 1e-9, 1e-9));
            iterations += run.iterations;
            match run.end {
                End::Reached => {
                    x = run.x;
                    x.pop();
                }
                End::Unreachable | End::Optimum => {
                    return Err(PlanError::RequirementUnreachable {
                        what,
                        required: tau,
                        best: run.upper * scale,
                    });
                }
                _ => return Err(not_converged(&run, 1e-9)),
            }
        }
        Ok((x, iterations))
    }

    /// The last phase: the objective from `x` meeting every requirement. The returned bound is
    /// in real units of the maximised objective (`−Σ f`, `−uᵀ C u` for the minimised ones).
    ///
    /// Above [`LAZY_MARGIN_DOF`] DOFs the margin is checked lazily, as the margin rarely binds
    /// where the objective asks for stiffness and its n × n block dominates an iteration: the
    /// phase first runs without the margin's block, and its answer stands when `A − m I ≻ 0`
    /// there (one Cholesky trial). The bound of that run holds for the plan's problem too: it
    /// bounds the optimum over a larger set (the objective is concave on its domain `A ≻ 0`,
    /// which the run never leaves: its steps are halved where they would). Otherwise the phase
    /// runs again from `x` with the block, and both runs' iterations count.
    ///
    /// # Errors
    /// [`PlanError::NoEndStiffness`]; [`PlanError::NotConverged`].
    pub(crate) fn optimise(&self, x: &[f64], max_iterations: usize) -> Result<Answer, PlanError> {
        if self.frame.n <= LAZY_MARGIN_DOF {
            return self.optimise_blocks(x, max_iterations, false);
        }
        let spent = match self.optimise_blocks(x, max_iterations, true) {
            Ok(answer) if self.margin_exceeds(&answer.x, self.requirements.margin) => {
                return Ok(answer);
            }
            Ok(answer) => answer.iterations,
            Err(PlanError::NotConverged { iterations, .. }) => iterations,
            Err(PlanError::NoEndStiffness) => 0,
            Err(other) => return Err(other),
        };
        let answer = self.optimise_blocks(x, max_iterations, false)?;
        Ok(Answer { iterations: answer.iterations + spent, ..answer })
    }

    /// [`Self::optimise`]'s run, with the margin's block unless `lazy`.
    fn optimise_blocks(
        &self,
        x: &[f64],
        max_iterations: usize,
        lazy: bool,
    ) -> Result<Answer, PlanError> {
        let f = self.frame;
        let k = f.vars();
        let gap = self.settings.relative_gap;
        let mut settings = self.settings(None, gap, 1e-9);
        settings.max_iterations = max_iterations;
        let floors = self.floors().len();
        let (run, scale) = match self.objective {
            Objective::LeastTension => {
                let mut sdp = base(self.frame, 0);
                sdp.blocks = self.constraint_blocks(floors, 0, lazy)?;
                let total = f.total + f.sums.iter().zip(x).map(|(a, b)| a * b).sum::<f64>();
                let scale = total.abs().max(1e-9);
                sdp.c0 = -f.total / scale;
                sdp.c = f.sums.iter().map(|s| -s / scale).collect();
                (sdp::solve(&sdp, None, x, settings), scale)
            }
            Objective::StiffnessAlong(_) | Objective::Volume => {
                let mut sdp = base(self.frame, 0);
                sdp.blocks = self.constraint_blocks(floors, 0, lazy)?;
                let k_x = self.k_x_at(x).ok_or(PlanError::NoEndStiffness)?;
                let (kind, now) = match self.objective {
                    Objective::StiffnessAlong(u) => {
                        let w = Vector6::new(u.x, u.y, u.z, 0., 0., 0.);
                        (Kind::Along(w), w.dot(&(k_x * w)))
                    }
                    _ => (Kind::Volume, k_x.fixed_view::<3, 3>(0, 0).determinant().ln()),
                };
                let scale = match kind {
                    Kind::Volume => now.abs().max(1.0),
                    _ => now.abs().max(1e-12),
                };
                if matches!(kind, Kind::Volume) {
                    // The gap's absolute floor: 1 in log units.
                    settings.scale = 1.0 / scale;
                }
                let mut smooth = EndObjective::new(f, kind, scale);
                (sdp::solve(&sdp, Some(&mut smooth), x, settings), scale)
            }
            Objective::MinStiffness => {
                let floor = Floor { k: Matrix3::identity() };
                let now = self.floor_value(x, &floor).ok_or(PlanError::NoEndStiffness)?;
                let scale = now.abs().max(1e-12);
                let mut sdp = base(self.frame, 1);
                sdp.blocks = self.constraint_blocks(floors, 1, lazy)?;
                sdp.blocks.push(
                    floor_block(self.frame, self.rotation_null.as_ref(), floor, Err(scale), 1)
                        .ok_or(PlanError::NoEndStiffness)?,
                );
                sdp.c[k] = 1.0;
                sdp.epigraph = Some((k, sdp.blocks.len() - 1));
                let mut start = x.to_vec();
                start.push(if self.warm { (1.0 - 1e-3) * now / scale } else { 0.5 * now / scale });
                let run = sdp::solve(&sdp, None, &start, settings);
                (run, scale)
            }
            Objective::ComplianceAlong(u) => {
                let c = self
                    .compliance_at(x, &u)
                    .ok_or_else(|| self.no_stable_tensions(f64::NEG_INFINITY))?;
                let scale = c.abs().max(1e-300);
                let mut sdp = base(self.frame, 1);
                sdp.blocks = self.constraint_blocks(floors, 1, lazy)?;
                sdp.blocks.push(compliance_block(self.frame, &u, scale));
                sdp.c[k] = -1.0;
                sdp.epigraph = Some((k, sdp.blocks.len() - 1));
                let mut start = x.to_vec();
                start.push(if self.warm { 1.0 + 1e-3 } else { 2.0 });
                (sdp::solve(&sdp, None, &start, settings), scale)
            }
        };
        if run.end != End::Optimum {
            return Err(not_converged(&run, gap));
        }
        let mut x = run.x;
        x.truncate(k);
        Ok(Answer { x, upper: run.upper * scale, iterations: run.iterations })
    }

    /// `uᵀ J_p A⁻¹ J_pᵀ u` at `x` (`None` where `A ⊁ 0`).
    fn compliance_at(&self, x: &[f64], u: &nalgebra::Vector3<f64>) -> Option<f64> {
        let n = self.frame.n;
        let mut a = vec![0.0; n * n];
        self.frame.a_at(x, &mut a);
        if !crate::dense::cholesky(&mut a, n) {
            return None;
        }
        let b: Vec<f64> =
            (0..n).map(|r| (0..3).map(|i| self.frame.j_x[i * n + r] * u[i]).sum()).collect();
        let mut z = b.clone();
        crate::dense::cholesky_solve(&a, n, &mut z);
        Some(b.iter().zip(&z).map(|(p, q)| p * q).sum())
    }
}

fn not_converged(run: &Run, tolerance: f64) -> PlanError {
    PlanError::NotConverged {
        iterations: run.iterations,
        gap: run.upper - run.value,
        tolerance: tolerance * run.value.abs(),
    }
}
