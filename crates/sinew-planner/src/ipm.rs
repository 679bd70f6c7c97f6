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

use crate::blocks::{Floor, base_into, compliance_block, floor_block, margin_block, push_block};
use crate::error::PlanError;
use crate::frame::Frame;
use crate::ipm_work::{IpmWork, compliance_at, floor_value, k_x_at, margin_exceeds};
use crate::problem::{Objective, PlanSettings, Requirements};
use crate::sdp::{self, End, Run, Settings};
use crate::smooth::{EndObjective, Kind};

/// How far past its target a feasibility phase goes, as a fraction of the bound's excess: a
/// start well inside the margin and the floors, not on their boundary.
const CENTRING: f64 = 0.3;

/// One plan's interior-point problem. Its phases run in an [`IpmWork`] and pass their point on
/// in its `x`.
pub(crate) struct Interior<'a> {
    pub(crate) frame: &'a Frame,
    pub(crate) objective: Objective,
    pub(crate) requirements: &'a Requirements,
    pub(crate) settings: &'a PlanSettings,
    /// Whether the work's `rotation_null` holds `R` (n × (n − 3)): when `J_r` has rank 3 and a
    /// floor block needs it.
    pub(crate) rotation_null: bool,
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

/// The last phase's end: its point is the work's `x`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Last {
    /// As [`Answer::upper`].
    pub(crate) upper: f64,
    pub(crate) iterations: usize,
}

/// The run's last iterate less its epigraph variable (the first `k`) into the work's `x`.
fn take_point(w: &mut IpmWork, k: usize) {
    w.x.clear();
    w.x.extend_from_slice(&w.run.x[..k]);
}

/// The work's `x` with an epigraph variable `t` into its `start`.
fn start_with(w: &mut IpmWork, t: f64) {
    w.start.clone_from(&w.x);
    w.start.push(t);
}

impl<'a> Interior<'a> {
    pub(crate) fn new(
        frame: &'a Frame,
        objective: Objective,
        requirements: &'a Requirements,
        settings: &'a PlanSettings,
        w: &mut IpmWork,
    ) -> Interior<'a> {
        let floors = matches!(objective, Objective::MinStiffness)
            || requirements.k_min.is_some()
            || requirements.k_des.is_some();
        w.rotation_null.clear();
        Interior {
            frame,
            objective,
            requirements,
            settings,
            rotation_null: floors
                && frame.rotation_null_basis_into(&mut w.basis, &mut w.rotation_null),
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

    /// `λ_min(A(x))`, N m/rad (one symmetric eigensolve, outside the iterations, where a
    /// phase 1 is needed).
    pub(crate) fn margin_at(&self, x: &[f64]) -> f64 {
        let n = self.frame.n;
        let mut a = vec![0.0; n * n];
        self.frame.a_at(x, &mut a);
        DMatrix::from_row_slice(n, n, &a).symmetric_eigenvalues().min()
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

    /// Phase 0: a point strictly inside the rows, near their Chebyshev centre, into `w.x`;
    /// the iterations.
    ///
    /// # Errors
    /// [`PlanError::BudgetsInfeasible`] when no point meets the rows.
    pub(crate) fn inside_rows(&self, w: &mut IpmWork) -> Result<usize, PlanError> {
        let f = self.frame;
        let k = f.vars();
        w.x.clear();
        w.x.resize(k, 0.0);
        let least = f.rhs.iter().copied().fold(f64::INFINITY, f64::min);
        if least > 1e-3 || f.rhs.is_empty() {
            return Ok(0);
        }
        // max τ s.t. G x + τ 1 ≤ h, τ ≤ 1; τ's box [τ₀ − 1, 1] holds the optimum.
        let sdp = &mut w.sdp;
        base_into(f, 1, sdp);
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
        start_with(w, tau0);
        // Until τ > 0 well inside (or the bound proves τ* ≤ 0: no point strictly inside).
        let settings = self.settings(Some(0.0), 1e-9, 1e-9);
        let run = sdp::solve(&w.sdp, None, &w.start, settings, &mut w.run);
        match run.end {
            End::Reached => {
                take_point(w, k);
                Ok(run.iterations)
            }
            End::Unreachable | End::Optimum => Err(PlanError::BudgetsInfeasible),
            _ => Err(not_converged(&run, 1e-9)),
        }
    }

    /// Phase 1: from `w.x` inside the rows, a point with margin ≥ the requirement.
    ///
    /// # Errors
    /// [`PlanError::NoStableTensions`] with the certified bound of the best margin.
    pub(crate) fn stable(&self, w: &mut IpmWork) -> Result<usize, PlanError> {
        let f = self.frame;
        let m = self.requirements.margin;
        if margin_exceeds(f, &w.x, m, &mut w.a) {
            return Ok(0);
        }
        let now = self.margin_at(&w.x);
        if now > m {
            return Ok(0);
        }
        let k = f.vars();
        base_into(f, 1, &mut w.sdp);
        push_block(&mut w.sdp, |b| margin_block(f, 0.0, 1, Some(f.a_scale), b));
        w.sdp.c[k] = 1.0;
        w.sdp.epigraph = Some((k, 0));
        start_with(w, (now - 0.05 * f.a_scale.max(now.abs())) / f.a_scale);
        let target = (m + 1e-9 * m.max(f.a_scale * 1e-6)) / f.a_scale;
        let settings = self.settings(Some(target), 1e-9, 1e-9);
        let run = sdp::solve(&w.sdp, None, &w.start, settings, &mut w.run);
        match run.end {
            End::Reached => {
                take_point(w, k);
                Ok(run.iterations)
            }
            End::Unreachable | End::Optimum => Err(self.no_stable_tensions(run.upper * f.a_scale)),
            _ => Err(not_converged(&run, 1e-9)),
        }
    }

    /// The floors of the requirements, in order (`k_min`, then `K_des`): `(K, τ)`.
    pub(crate) fn floors(&self) -> [Option<(Floor, f64, &'static str)>; 2] {
        let r = self.requirements;
        [
            r.k_min.map(|k| {
                (Floor { k: Matrix3::identity() }, k, "least stiffness λ_min(K_fd), N/m,")
            }),
            r.k_des.map(|k| (Floor { k }, 1.0, "K_fd ⪰ τ K_des, τ")),
        ]
    }

    /// A floor block `K_fd ⪰ τ K` pushed onto the work's problem.
    ///
    /// # Errors
    /// [`PlanError::NoEndStiffness`] when `J_r` has rank < 3 (no `R`).
    fn push_floor(
        &self,
        w: &mut IpmWork,
        floor: Floor,
        tau: Result<f64, f64>,
        extra: usize,
    ) -> Result<usize, PlanError> {
        if !self.rotation_null {
            return Err(PlanError::NoEndStiffness);
        }
        let (f, r, scratch) = (self.frame, &w.rotation_null, &mut w.scratch);
        Ok(push_block(&mut w.sdp, |b| floor_block(f, r, floor, tau, extra, (b, scratch))))
    }

    /// The margin (unless `lazy`) and the floors met so far as fixed blocks, with `extra`
    /// columns, pushed onto the work's problem.
    fn constraint_blocks(
        &self,
        w: &mut IpmWork,
        floors: usize,
        extra: usize,
        lazy: bool,
    ) -> Result<(), PlanError> {
        if !lazy {
            let (f, m) = (self.frame, self.requirements.margin);
            push_block(&mut w.sdp, |b| margin_block(f, m, extra, None, b));
        }
        for (floor, tau, _) in self.floors().into_iter().flatten().take(floors) {
            self.push_floor(w, floor, Ok(tau), extra)?;
        }
        Ok(())
    }

    /// Phase 1b: from a stable `w.x`, a point meeting every stiffness floor.
    ///
    /// # Errors
    /// [`PlanError::RequirementUnreachable`] with the certified bound;
    /// [`PlanError::NoEndStiffness`] when `K_x` does not exist.
    pub(crate) fn floors_met(&self, w: &mut IpmWork) -> Result<usize, PlanError> {
        let mut iterations = 0;
        let f = self.frame;
        let k = f.vars();
        for (index, (floor, tau, what)) in self.floors().into_iter().flatten().enumerate() {
            let now = floor_value(f, &w.x, &floor, &mut w.end).ok_or(PlanError::NoEndStiffness)?;
            if now > tau {
                continue;
            }
            let scale = now.abs().max(tau.abs()).max(1e-12);
            base_into(f, 1, &mut w.sdp);
            self.constraint_blocks(w, index, 1, false)?;
            let epigraph = self.push_floor(w, floor, Err(scale), 1)?;
            w.sdp.c[k] = 1.0;
            w.sdp.epigraph = Some((k, epigraph));
            start_with(w, (now - 0.05 * scale) / scale);
            let target = (tau + 1e-9 * scale) / scale;
            let settings = self.settings(Some(target), 1e-9, 1e-9);
            let run = sdp::solve(&w.sdp, None, &w.start, settings, &mut w.run);
            iterations += run.iterations;
            match run.end {
                End::Reached => take_point(w, k),
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
        Ok(iterations)
    }

    /// The last phase: the objective from `w.x` meeting every requirement, its answer into
    /// `w.x`. The returned bound is in real units of the maximised objective (`−Σ f`,
    /// `−uᵀ C u` for the minimised ones).
    ///
    /// The margin is checked lazily, as it rarely binds where the objective asks for stiffness:
    /// the phase first runs without the margin's block, and its answer stands when `A − m I ≻ 0`
    /// there (one Cholesky trial). The bound of that run holds for the plan's problem too: it
    /// bounds the optimum over a larger set (the objective is concave on its domain `A ≻ 0`,
    /// which the run never leaves: its steps are halved where they would). Otherwise the phase
    /// runs again from `x` with the block, and both runs' iterations count. Without the block
    /// an iteration is cheaper and the central path is not bent by the margin's barrier:
    /// cdhrm5's cold stiffness plans take 6–11 iterations instead of 9–13 and 40–62 % fewer
    /// instructions (docs/performance.md, session 17). A least-tension plan is where the margin
    /// binds (cdhrm5 decoupled at the default margin): there the first run is spent, 10 % more.
    ///
    /// # Errors
    /// [`PlanError::NoEndStiffness`]; [`PlanError::NotConverged`].
    pub(crate) fn optimise(
        &self,
        w: &mut IpmWork,
        max_iterations: usize,
    ) -> Result<Last, PlanError> {
        w.from.clone_from(&w.x);
        let spent = match self.optimise_blocks(w, max_iterations, true) {
            Ok(last) if margin_exceeds(self.frame, &w.x, self.requirements.margin, &mut w.a) => {
                return Ok(last);
            }
            Ok(last) => last.iterations,
            Err(PlanError::NotConverged { iterations, .. }) => iterations,
            Err(PlanError::NoEndStiffness) => 0,
            Err(other) => return Err(other),
        };
        w.x.clone_from(&w.from);
        let last = self.optimise_blocks(w, max_iterations, false)?;
        Ok(Last { iterations: last.iterations + spent, ..last })
    }

    /// [`Self::optimise`]'s run, with the margin's block unless `lazy`.
    fn optimise_blocks(
        &self,
        w: &mut IpmWork,
        max_iterations: usize,
        lazy: bool,
    ) -> Result<Last, PlanError> {
        let f = self.frame;
        let k = f.vars();
        let gap = self.settings.relative_gap;
        let mut settings = self.settings(None, gap, 1e-9);
        settings.max_iterations = max_iterations;
        let floors = self.floors().into_iter().flatten().count();
        let (run, scale) = match self.objective {
            Objective::LeastTension => {
                base_into(f, 0, &mut w.sdp);
                self.constraint_blocks(w, floors, 0, lazy)?;
                let total = f.total + f.sums.iter().zip(&w.x).map(|(a, b)| a * b).sum::<f64>();
                let scale = total.abs().max(1e-9);
                w.sdp.c0 = -f.total / scale;
                for (c, s) in w.sdp.c.iter_mut().zip(&f.sums) {
                    *c = -s / scale;
                }
                (sdp::solve(&w.sdp, None, &w.x, settings, &mut w.run), scale)
            }
            Objective::StiffnessAlong(_) | Objective::Volume => {
                base_into(f, 0, &mut w.sdp);
                self.constraint_blocks(w, floors, 0, lazy)?;
                let k_x = k_x_at(f, &w.x, &mut w.end).ok_or(PlanError::NoEndStiffness)?;
                let (kind, now) = match self.objective {
                    Objective::StiffnessAlong(u) => {
                        let v = Vector6::new(u.x, u.y, u.z, 0., 0., 0.);
                        (Kind::Along(v), v.dot(&(k_x * v)))
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
                let buffers = std::mem::take(&mut w.end);
                let mut smooth = EndObjective::reusing(f, kind, scale, buffers);
                let run = sdp::solve(&w.sdp, Some(&mut smooth), &w.x, settings, &mut w.run);
                w.end = smooth.into_buffers();
                (run, scale)
            }
            Objective::MinStiffness => {
                let floor = Floor { k: Matrix3::identity() };
                let now =
                    floor_value(f, &w.x, &floor, &mut w.end).ok_or(PlanError::NoEndStiffness)?;
                let scale = now.abs().max(1e-12);
                base_into(f, 1, &mut w.sdp);
                self.constraint_blocks(w, floors, 1, lazy)?;
                let epigraph = self.push_floor(w, floor, Err(scale), 1)?;
                w.sdp.c[k] = 1.0;
                w.sdp.epigraph = Some((k, epigraph));
                start_with(
                    w,
                    if self.warm { (1.0 - 1e-3) * now / scale } else { 0.5 * now / scale },
                );
                (sdp::solve(&w.sdp, None, &w.start, settings, &mut w.run), scale)
            }
            Objective::ComplianceAlong(u) => {
                let c = compliance_at(f, &w.x, &u, (&mut w.a, &mut w.b, &mut w.z))
                    .ok_or_else(|| self.no_stable_tensions(f64::NEG_INFINITY))?;
                let scale = c.abs().max(1e-300);
                base_into(f, 1, &mut w.sdp);
                self.constraint_blocks(w, floors, 1, lazy)?;
                let epigraph = push_block(&mut w.sdp, |b| compliance_block(f, &u, scale, b));
                w.sdp.c[k] = -1.0;
                w.sdp.epigraph = Some((k, epigraph));
                start_with(w, if self.warm { 1.0 + 1e-3 } else { 2.0 });
                (sdp::solve(&w.sdp, None, &w.start, settings, &mut w.run), scale)
            }
        };
        if run.end != End::Optimum {
            return Err(not_converged(&run, gap));
        }
        take_point(w, k);
        Ok(Last { upper: run.upper * scale, iterations: run.iterations })
    }
}

fn not_converged(run: &Run, tolerance: f64) -> PlanError {
    PlanError::NotConverged {
        iterations: run.iterations,
        gap: run.upper - run.value,
        tolerance: tolerance * run.value.abs(),
    }
}
