//! A certified maximiser of a concave function over a polytope with concave constraints: the
//! level bundle method, its subproblems solved with clarabel (LP for the bound, QP for the
//! step).
//!
//! # Math
//! Maximise a concave `φ(λ)` subject to `G λ ≤ h` and concave constraints `ψ_j(λ) ≥ b_j`. Every
//! evaluation at a point `λ_k` gives supergradient cuts `φ(λ) ≤ φ(λ_k) + g_kᵀ(λ − λ_k)` and
//! `ψ_j(λ) ≤ ψ_j(λ_k) + h_kᵀ(λ − λ_k)`, valid everywhere by concavity. So
//!
//! ```text
//! UB = max { t : t ≤ φ_k + g_kᵀ(λ − λ_k) ∀k,  ψ_jk + h_jkᵀ(λ − λ_jk) ≥ b_j ∀j,k,  G λ ≤ h }
//! ```
//!
//! (an LP) is an upper bound of the optimum, and the best `φ` at a point meeting every
//! constraint (`LB`) a lower bound: `UB − LB` certifies how far the answer is from the true
//! optimum. The next point is the projection of the best one onto the level set of the cuts at
//! `ℓ = LB + κ (UB − LB)` (a QP); the method stops when the gap is at most the tolerance
//! (Lemaréchal, Nemirovskii and Nesterov's level method, with constraints by their cuts). An
//! infeasible LP proves that no point meets the constraints.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use sinew_statics::SolverStop;
use sinew_statics::convex::dense_csc;

use crate::error::PlanError;

/// A linear over-estimator `value + gradientᵀ(λ − at)` of a concave function.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Cut {
    pub(crate) at: Vec<f64>,
    pub(crate) value: f64,
    pub(crate) gradient: Vec<f64>,
}

impl Cut {
    /// `value − gradientᵀ at`: the cut is `gradientᵀ λ + offset`.
    fn offset(&self) -> f64 {
        self.value - dot(&self.gradient, &self.at)
    }
}

/// What one evaluation tells: the objective's cut where it is defined, each constraint's cut
/// with its bound.
#[derive(Debug, Clone)]
pub(crate) struct Evaluation {
    pub(crate) objective: Option<Cut>,
    pub(crate) constraints: Vec<(Cut, f64)>,
}

impl Evaluation {
    /// Whether every constraint holds at the point (and the objective is defined).
    pub(crate) fn feasible(&self) -> bool {
        self.objective.is_some() && self.constraints.iter().all(|(c, b)| c.value >= *b)
    }
}

/// The linear part: `rows[r] · λ ≤ rhs[r]`.
#[derive(Debug, Clone)]
pub(crate) struct Linear {
    /// Coordinates per row.
    k: usize,
    /// The rows `a`, row-major (rows × k).
    rows: Vec<f64>,
    pub(crate) rhs: Vec<f64>,
}

impl Linear {
    /// No rows, in `k` coordinates, with room for `capacity` rows.
    pub(crate) fn new(k: usize, capacity: usize) -> Linear {
        Linear { k, rows: Vec::with_capacity(k * capacity), rhs: Vec::with_capacity(capacity) }
    }

    /// No rows, in `k` coordinates, with room for `capacity` rows (this one's buffers kept).
    pub(crate) fn clear(&mut self, k: usize, capacity: usize) {
        self.k = k;
        self.rows.clear();
        self.rows.reserve(k * capacity);
        self.rhs.clear();
        self.rhs.reserve(capacity);
    }

    /// Adds the row `a·x ≤ rhs` (`a` of `k` coordinates).
    pub(crate) fn push(&mut self, a: impl IntoIterator<Item = f64>, rhs: f64) {
        let before = self.rows.len();
        self.rows.extend(a);
        debug_assert_eq!(self.rows.len(), before + self.k);
        self.rhs.push(rhs);
    }

    /// The rows' `a`, in order.
    pub(crate) fn rows(&self) -> impl Iterator<Item = &[f64]> + '_ {
        (0..self.rhs.len()).map(|r| &self.rows[r * self.k..(r + 1) * self.k])
    }

    /// The same polytope with parallel rows merged (the tightest kept): in the decoupled model
    /// each cable's two limit rows bound the one coordinate of its joint, so three cables'
    /// six rows become two.
    pub(crate) fn merged(&self) -> Linear {
        let mut out = Linear::new(self.k, self.rhs.len());
        self.merged_into(&mut out, &mut Vec::new());
        out
    }

    /// [`Linear::merged`] into `out`'s buffers, with `keys` a scratch.
    pub(crate) fn merged_into(&self, out: &mut Linear, keys: &mut Vec<usize>) {
        let k = self.k;
        out.clear(k, self.rhs.len());
        // Each kept row's first coordinate above `KEY` (rows scaled to a largest entry of 1):
        // only rows with the same key are compared in full. Rows within 1e-12 of each other
        // share it unless an entry lies within 1e-12 of `KEY`, and then they are both kept,
        // which leaves the polytope as it is.
        const KEY: f64 = 1e-6;
        keys.clear();
        for (row, rhs) in self.rows().zip(&self.rhs) {
            let scale = row.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
            if scale == 0.0 {
                // 0 ≤ rhs: keep it (an infeasible one proves infeasibility).
                out.push(row.iter().copied(), *rhs);
                keys.push(usize::MAX);
                continue;
            }
            let b = rhs / scale;
            let key = row.iter().position(|v| v.abs() > KEY * scale).unwrap_or(k);
            let same = keys.iter().enumerate().position(|(i, kr)| {
                *kr == key
                    && out.rows[i * k..(i + 1) * k]
                        .iter()
                        .zip(row)
                        .all(|(x, y)| (x - y / scale).abs() <= 1e-12)
            });
            match same {
                Some(i) => out.rhs[i] = out.rhs[i].min(b),
                None => {
                    out.push(row.iter().map(|v| v / scale), b);
                    keys.push(key);
                }
            }
        }
    }

    /// Whether `x` meets every row (to `1e-9` of the row's scale).
    pub(crate) fn satisfied(&self, x: &[f64]) -> bool {
        self.rows().zip(&self.rhs).all(|(row, rhs)| {
            let scale = rhs.abs().max(row.iter().fold(0.0_f64, |a, v| a.max(v.abs()))).max(1.0);
            dot(row, x) <= rhs + 1e-9 * scale
        })
    }
}

/// A point meeting the linear rows (the LP with no cut), `None` when there is none.
pub(crate) fn feasible_point(k: usize, linear: &Linear) -> Result<Option<Vec<f64>>, PlanError> {
    Ok(upper_bound(k, &[], &[], linear)?.map(|(_, x)| x))
}

/// How a run ended.
#[derive(Debug, Clone)]
pub(crate) enum Outcome {
    /// The best point, its value, the certified gap `UB − LB`, the iterations.
    Optimum { lambda: Vec<f64>, value: f64, upper: f64, iterations: usize },
    /// No point meets the constraints (the LP with their cuts is infeasible).
    Infeasible,
    /// A point reached `target` (early stop of a feasibility phase).
    Reached { lambda: Vec<f64>, iterations: usize },
    /// `UB < target`: the target is out of reach; `upper` bounds the optimum.
    Unreachable { upper: f64 },
}

/// Settings of a run.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Settings {
    /// Stop at `UB − LB ≤ relative_gap · max(|LB|, scale)`.
    pub(crate) relative_gap: f64,
    /// Absolute floor of the gap's scale (the objective's unit).
    pub(crate) scale: f64,
    pub(crate) max_iterations: usize,
    /// Stop as soon as a feasible point reaches this value (a feasibility phase), or when
    /// the bound proves it cannot be reached.
    pub(crate) target: Option<f64>,
}

/// Maximise over `linear` and the constraints' cuts, from the feasible point `start`.
pub(crate) fn maximise(
    mut evaluate: impl FnMut(&[f64]) -> Result<Evaluation, PlanError>,
    linear: &Linear,
    start: &[f64],
    settings: Settings,
) -> Result<Outcome, PlanError> {
    let k = start.len();
    let mut objective_cuts: Vec<Cut> = Vec::new();
    let mut constraint_cuts: Vec<(Cut, f64)> = Vec::new();
    let mut best: Option<(Vec<f64>, f64)> = None;
    let mut centre = start.to_vec();
    let mut last_bound: Option<(f64, Vec<f64>)> = None;
    let first = evaluate(start)?;
    record(&first, start, linear, &mut objective_cuts, &mut constraint_cuts, &mut best);
    for iteration in 1..=settings.max_iterations {
        if let (Some(target), Some((lambda, value))) = (settings.target, &best)
            && *value >= target
        {
            return Ok(Outcome::Reached { lambda: lambda.clone(), iterations: iteration - 1 });
        }
        // A bound LP solved only to reduced accuracy: the last bound still holds (cuts only
        // add), and the step goes on from the level set.
        let bound = match upper_bound(k, &objective_cuts, &constraint_cuts, linear) {
            Err(PlanError::Solver { .. }) if last_bound.is_some() => last_bound.clone(),
            bound => bound?,
        };
        let Some((upper, upper_point)) = bound else {
            return Ok(Outcome::Infeasible);
        };
        last_bound = Some((upper, upper_point.clone()));
        if let Some(target) = settings.target
            && upper < target
        {
            return Ok(Outcome::Unreachable { upper });
        }
        let next = match &best {
            Some((lambda, value)) => {
                let gap = upper - value;
                if gap < -1e-9 * value.abs().max(settings.scale) {
                    // A bound below a feasible value: the LP's answer is not to be trusted.
                    return Err(PlanError::Solver { stop: SolverStop::InconsistentBound });
                }
                if gap <= settings.relative_gap * value.abs().max(settings.scale) {
                    return Ok(Outcome::Optimum {
                        lambda: lambda.clone(),
                        value: *value,
                        upper,
                        iterations: iteration,
                    });
                }
                centre.clone_from(lambda);
                let level = value + 0.5 * gap;
                project(&centre, level, &objective_cuts, &constraint_cuts, linear)?
                    .unwrap_or(upper_point)
            }
            // No feasible point yet: go where the model is best.
            None => upper_point,
        };
        let evaluation = evaluate(&next)?;
        record(&evaluation, &next, linear, &mut objective_cuts, &mut constraint_cuts, &mut best);
    }
    let Some((lambda, value)) = best else {
        return Ok(Outcome::Infeasible);
    };
    let upper =
        upper_bound(k, &objective_cuts, &constraint_cuts, linear)?.map_or(value, |(u, _)| u);
    let tolerance = settings.relative_gap * value.abs().max(settings.scale);
    if upper - value <= tolerance {
        Ok(Outcome::Optimum { lambda, value, upper, iterations: settings.max_iterations })
    } else {
        Err(PlanError::NotConverged {
            iterations: settings.max_iterations,
            gap: upper - value,
            tolerance,
        })
    }
}

fn record(
    evaluation: &Evaluation,
    at: &[f64],
    linear: &Linear,
    objective_cuts: &mut Vec<Cut>,
    constraint_cuts: &mut Vec<(Cut, f64)>,
    best: &mut Option<(Vec<f64>, f64)>,
) {
    if let Some(cut) = &evaluation.objective {
        objective_cuts.push(cut.clone());
    }
    constraint_cuts.extend(evaluation.constraints.iter().cloned());
    if evaluation.feasible() && linear.satisfied(at) {
        let value = evaluation.objective.as_ref().map_or(f64::NEG_INFINITY, |c| c.value);
        if best.as_ref().is_none_or(|(_, b)| value > *b) {
            *best = Some((at.to_vec(), value));
        }
    }
}

/// The LP bound: `max t` over the cuts and the linear rows; `None` when infeasible. Without an
/// objective cut yet, `t` is bounded by 0 (the LP then only tests feasibility).
fn upper_bound(
    k: usize,
    objective_cuts: &[Cut],
    constraint_cuts: &[(Cut, f64)],
    linear: &Linear,
) -> Result<Option<(f64, Vec<f64>)>, PlanError> {
    // Variables (λ, t); rows a·x ≤ b.
    let mut rows: Vec<(Vec<f64>, f64)> = Vec::new();
    for cut in objective_cuts {
        // t − gᵀλ ≤ offset
        let mut a: Vec<f64> = cut.gradient.iter().map(|g| -g).collect();
        a.push(1.0);
        rows.push((a, cut.offset()));
    }
    if objective_cuts.is_empty() {
        let mut a = vec![0.0; k];
        a.push(1.0);
        rows.push((a, 0.0));
    }
    push_constraints(&mut rows, constraint_cuts, linear, 1);
    let mut q = vec![0.0; k + 1];
    q[k] = -1.0;
    match solve(k + 1, false, &q, &rows)? {
        Some(x) => Ok(Some((x[k], x[..k].to_vec()))),
        None => Ok(None),
    }
}

/// The level step: the point nearest `centre` where every objective cut is at least `level`.
fn project(
    centre: &[f64],
    level: f64,
    objective_cuts: &[Cut],
    constraint_cuts: &[(Cut, f64)],
    linear: &Linear,
) -> Result<Option<Vec<f64>>, PlanError> {
    let k = centre.len();
    let mut rows: Vec<(Vec<f64>, f64)> = Vec::new();
    for cut in objective_cuts {
        // −gᵀλ ≤ offset − level
        rows.push((cut.gradient.iter().map(|g| -g).collect(), cut.offset() - level));
    }
    push_constraints(&mut rows, constraint_cuts, linear, 0);
    // ½|λ − c|² = ½λᵀλ − cᵀλ + const.
    let q: Vec<f64> = centre.iter().map(|c| -c).collect();
    solve(k, true, &q, &rows)
}

/// Constraint cuts `ψ + hᵀ(λ − at) ≥ b` as `−hᵀλ ≤ offset − b`, then the linear rows; `extra`
/// zero columns after λ.
fn push_constraints(
    rows: &mut Vec<(Vec<f64>, f64)>,
    constraint_cuts: &[(Cut, f64)],
    linear: &Linear,
    extra: usize,
) {
    for (cut, bound) in constraint_cuts {
        let mut a: Vec<f64> = cut.gradient.iter().map(|h| -h).collect();
        a.extend(std::iter::repeat_n(0.0, extra));
        rows.push((a, cut.offset() - bound));
    }
    for (row, rhs) in linear.rows().zip(&linear.rhs) {
        let mut a = row.to_vec();
        a.extend(std::iter::repeat_n(0.0, extra));
        rows.push((a, *rhs));
    }
}

/// `min ½ xᵀ P x + qᵀ x` (P = I when `quadratic`, else 0) subject to `a·x ≤ b` for every row;
/// `None` when infeasible.
fn solve(
    n: usize,
    quadratic: bool,
    q: &[f64],
    rows: &[(Vec<f64>, f64)],
) -> Result<Option<Vec<f64>>, PlanError> {
    let p = if quadratic { CscMatrix::identity(n) } else { CscMatrix::zeros((n, n)) };
    let m = rows.len();
    // The LP equilibrated (x = D x̃, each column and then each row of A D scaled to a largest
    // entry of 1): its cuts mix λ ~ 10³ N with gradients ~ 10⁻⁵, and unscaled, clarabel's
    // answer can fall below a feasible value by 10⁻⁴ relative. The QP keeps its metric.
    let column_scale: Vec<f64> = (0..n)
        .map(|c| {
            let largest = rows.iter().fold(0.0_f64, |a, (r, _)| a.max(r[c].abs()));
            if quadratic || largest == 0.0 { 1.0 } else { 1.0 / largest }
        })
        .collect();
    let row_scale: Vec<f64> = rows
        .iter()
        .map(|(r, _)| {
            let largest =
                r.iter().zip(&column_scale).fold(0.0_f64, |a, (v, d)| a.max((v * d).abs()));
            if quadratic || largest == 0.0 { 1.0 } else { 1.0 / largest }
        })
        .collect();
    let a = dense_csc(m, n, |r, c| rows[r].0[c] * column_scale[c] * row_scale[r]);
    let b: Vec<f64> = rows.iter().zip(&row_scale).map(|((_, b), s)| b * s).collect();
    let q: Vec<f64> = q.iter().zip(&column_scale).map(|(v, d)| v * d).collect();
    let cones = [SupportedConeT::NonnegativeConeT(m)];
    let settings = DefaultSettings {
        verbose: false,
        tol_gap_abs: 1e-10,
        tol_gap_rel: 1e-10,
        tol_feas: 1e-10,
        ..DefaultSettings::default()
    };
    let mut solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings)
        .map_err(|_| PlanError::Solver { stop: SolverStop::Setup })?;
    solver.solve();
    match solver.solution.status {
        // An LP answer only to reduced accuracy is no bound (its value can be 10⁻³ low).
        SolverStatus::AlmostSolved if !quadratic => {
            Err(PlanError::Solver { stop: SolverStop::ReducedAccuracy })
        }
        SolverStatus::Solved | SolverStatus::AlmostSolved => {
            Ok(Some(solver.solution.x.iter().zip(&column_scale).map(|(x, d)| x * d).collect()))
        }
        SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => Ok(None),
        status => Err(PlanError::Solver { stop: SolverStop::from_status(status) }),
    }
}

pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
