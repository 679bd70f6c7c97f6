//! The phases of a plan, each one call of the method ([`crate::bundle`]) on the pencil of the
//! pose: a stable start (the margin maximised until it reaches the requirement, or the proof
//! that it cannot), a start meeting the stiffness floors, then the objective.

use nalgebra::{Matrix3, Vector6};

use crate::bundle::{self, Cut, Evaluation, Linear, Outcome, Settings};
use crate::error::PlanError;
use crate::pencil::{End, Pencil};
use crate::problem::{Objective, PlanSettings, Requirements};

/// One plan's problem on the equilibrium set of its pose: the pencil `A(λ)`, the objective,
/// the requirements and the linear rows in `λ`.
pub(crate) struct Problem<'a> {
    /// `A(λ) = A_0 + Σ λ_i A_i` and `J_x`.
    pub(crate) pencil: &'a Pencil,
    /// What is optimised.
    pub(crate) objective: Objective,
    /// Margin, budgets, floors.
    pub(crate) requirements: &'a Requirements,
    /// How the phases stop.
    pub(crate) settings: &'a PlanSettings,
    /// The tension limits, budgets and held levels as rows in `λ`.
    pub(crate) linear: &'a Linear,
    /// `Σ f = total + sumsᵀ λ`: the constant.
    pub(crate) total: f64,
    /// And the gradient `Nᵀ 1`.
    pub(crate) sums: Vec<f64>,
    /// The Cholesky factor `L` of `K_des = L Lᵀ`, when a `K_des` is required.
    pub(crate) k_des_scale: Option<Matrix3<f64>>,
    /// A stiffness scale of the pencil (N m/rad), for absolute floors of the gaps.
    pub(crate) scale: f64,
}

/// The answer of the last phase: `λ`, the value, the upper bound, the iterations.
pub(crate) type Optimum = (Vec<f64>, f64, f64, usize);

impl Problem<'_> {
    fn no_stable_tensions(&self, best: f64) -> PlanError {
        PlanError::NoStableTensions {
            margin: self.requirements.margin,
            best,
            budget: self.requirements.budget.is_some(),
        }
    }

    /// Phase 1: from `start`, a point with margin ≥ the requirement, by maximising the margin
    /// (unchanged when `start` has it). Returns it and the iterations.
    ///
    /// # Errors
    /// [`PlanError::NoStableTensions`] with an upper bound of the best margin; the method's.
    pub(crate) fn stable_start(
        &self,
        start: Vec<f64>,
        k: usize,
    ) -> Result<(Vec<f64>, usize), PlanError> {
        let margin = self.requirements.margin;
        let (margin0, _) = self.pencil.margin(&start)?;
        if margin0 >= margin {
            return Ok((start, 0));
        }
        if k == 0 {
            return Err(self.no_stable_tensions(margin0));
        }
        let outcome = bundle::maximise(
            |l| {
                let (value, gradient) = self.pencil.margin(l)?;
                Ok(Evaluation {
                    objective: Some(Cut { at: l.to_vec(), value, gradient }),
                    constraints: Vec::new(),
                })
            },
            self.linear,
            &start,
            Settings {
                relative_gap: 1e-9,
                scale: self.scale,
                max_iterations: self.settings.max_iterations,
                target: Some(margin),
            },
        )?;
        match outcome {
            Outcome::Reached { lambda, iterations, .. } => Ok((lambda, iterations)),
            Outcome::Unreachable { upper } => Err(self.no_stable_tensions(upper)),
            Outcome::Optimum { value, upper, .. } if value < margin => {
                Err(self.no_stable_tensions(upper))
            }
            Outcome::Optimum { .. } => Ok((start, 0)),
            Outcome::Infeasible => Err(self.no_stable_tensions(f64::NEG_INFINITY)),
        }
    }

    /// The stiffness floors' cuts at an end (`k_min`, then `K_des`), `None` without `K_x`.
    fn floor_cuts(&self, end: &End) -> Option<Vec<(Cut, f64)>> {
        let mut cuts = Vec::new();
        if let Some(k_min) = self.requirements.k_min {
            let (value, gradient) = end.least_stiffness(self.pencil, None)?;
            cuts.push((Cut { at: Vec::new(), value, gradient }, k_min));
        }
        if let Some(l) = &self.k_des_scale {
            let (value, gradient) = end.least_stiffness(self.pencil, Some(l))?;
            cuts.push((Cut { at: Vec::new(), value, gradient }, 1.0));
        }
        Some(cuts)
    }

    /// The objective's cut and every constraint's (the margin first, then the floors) at `l`.
    fn evaluate(&self, l: &[f64]) -> Result<Evaluation, PlanError> {
        let pencil = self.pencil;
        let (m, mg) = pencil.margin(l)?;
        let mut constraints =
            vec![(Cut { at: l.to_vec(), value: m, gradient: mg }, self.requirements.margin)];
        let Some(end) = pencil.end(l) else {
            return Ok(Evaluation { objective: None, constraints });
        };
        if let Some(cuts) = self.floor_cuts(&end) {
            constraints.extend(cuts.into_iter().map(|(mut c, b)| {
                c.at = l.to_vec();
                (c, b)
            }));
        } else if self.requirements.k_min.is_some() || self.requirements.k_des.is_some() {
            return Err(PlanError::NoEndStiffness);
        }
        let value = match self.objective {
            Objective::StiffnessAlong(u) => {
                let w = Vector6::new(u.x, u.y, u.z, 0.0, 0.0, 0.0);
                end.stiffness_form(pencil, &w).ok_or(PlanError::NoEndStiffness)?
            }
            Objective::ComplianceAlong(u) => end.compliance_form(pencil, &u),
            Objective::MinStiffness => {
                end.least_stiffness(pencil, None).ok_or(PlanError::NoEndStiffness)?
            }
            Objective::Volume => end.log_volume(pencil).ok_or(PlanError::NoEndStiffness)?,
            Objective::LeastTension => {
                (-(self.total + bundle::dot(&self.sums, l)), self.sums.iter().map(|s| -s).collect())
            }
        };
        Ok(Evaluation {
            objective: Some(Cut { at: l.to_vec(), value: value.0, gradient: value.1 }),
            constraints,
        })
    }

    /// Phase 1b: from a stable `start`, a point meeting the stiffness floors (`k_min`,
    /// `K_des`), by maximising their least scaled slack (the margin kept) until it is ≥ 0.
    /// Unchanged without floors.
    ///
    /// # Errors
    /// [`PlanError::RequirementUnreachable`] with an upper bound of the best reachable;
    /// [`PlanError::NoStableTensions`]; the method's.
    pub(crate) fn floors_start(&self, start: Vec<f64>) -> Result<(Vec<f64>, usize), PlanError> {
        let requirements = self.requirements;
        if requirements.k_min.is_none() && requirements.k_des.is_none() {
            return Ok((start, 0));
        }
        let phase = bundle::maximise(
            |l| {
                let mut e = self.evaluate(l)?;
                let slack = e
                    .constraints
                    .iter()
                    .skip(1)
                    .map(|(c, b)| (c.value - b, c.gradient.clone(), b.abs().max(1.0)))
                    .min_by(|a, b| (a.0 / a.2).total_cmp(&(b.0 / b.2)));
                e.objective = match (&e.objective, slack) {
                    (Some(_), Some((s, g, n))) => Some(Cut {
                        at: l.to_vec(),
                        value: s / n,
                        gradient: g.iter().map(|x| x / n).collect(),
                    }),
                    _ => None,
                };
                e.constraints.truncate(1);
                Ok(e)
            },
            self.linear,
            &start,
            Settings {
                relative_gap: 1e-9,
                scale: 1.0,
                max_iterations: self.settings.max_iterations,
                target: Some(0.0),
            },
        )?;
        match phase {
            Outcome::Reached { lambda, iterations, .. } => Ok((lambda, iterations)),
            Outcome::Unreachable { upper } | Outcome::Optimum { upper, .. } => {
                let (what, required) = match requirements.k_min {
                    Some(k) => ("least stiffness λ_min(K_fd), N/m,", k),
                    None => ("K_fd ⪰ K_des (scaled least eigenvalue)", 1.0),
                };
                let best = match requirements.k_min {
                    Some(k) => k + upper * k.abs().max(1.0),
                    None => 1.0 + upper,
                };
                Err(PlanError::RequirementUnreachable { what, required, best })
            }
            Outcome::Infeasible => Err(self.no_stable_tensions(f64::NEG_INFINITY)),
        }
    }

    /// The last phase: the objective from a start meeting every requirement, to the settings'
    /// gap. `least_total` (the least total tension, N) scales the least-tension objective's.
    ///
    /// # Errors
    /// [`PlanError::NoStableTensions`] if the method ends elsewhere than at an optimum; the
    /// method's ([`PlanError::NotConverged`] among them).
    pub(crate) fn optimise(&self, start: &[f64], least_total: f64) -> Result<Optimum, PlanError> {
        let outcome = bundle::maximise(
            |l| self.evaluate(l),
            self.linear,
            start,
            Settings {
                relative_gap: self.settings.relative_gap,
                scale: objective_scale(self.objective, self.scale, least_total),
                max_iterations: self.settings.max_iterations,
                target: None,
            },
        )?;
        match outcome {
            Outcome::Optimum { lambda, value, upper, iterations } => {
                Ok((lambda, value, upper, iterations))
            }
            Outcome::Reached { .. } | Outcome::Unreachable { .. } | Outcome::Infeasible => {
                Err(self.no_stable_tensions(f64::NEG_INFINITY))
            }
        }
    }
}

/// A stiffness scale of the pencil (N m/rad), for absolute floors of the gaps.
pub(crate) fn pencil_scale(pencil: &Pencil) -> f64 {
    let n = pencil.a0.nrows();
    (0..n).map(|i| pencil.a0[(i, i)].abs()).fold(0.0, f64::max).max(1e-9)
}

fn objective_scale(objective: Objective, pencil_scale: f64, least_total: f64) -> f64 {
    match objective {
        Objective::LeastTension => least_total.abs().max(1.0),
        Objective::Volume => 1.0,
        _ => 1e-12 * pencil_scale.max(1.0),
    }
}
