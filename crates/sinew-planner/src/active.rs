//! The warm step of re-planning by Newton steps on the previous answer's active set (issue
//! #24): the previous tensions mapped into this pose's frame, the previous plan's active rows
//! (or, when the rows are not the previous frame's, those the mapped point leaves within
//! [`ACTIVE_SLACK`] of their bound), then Newton steps on the KKT system of
//! `max φ(x) s.t. G_W x = h_W`. Where a step is stationary on `W` but not certified, the most
//! violated row joins `W`, or the row with the most negative multiplier leaves it. The answer
//! is certified by the bound of `program.rs` with the active rows' multipliers and `Z = 0`: the
//! step is for the smooth objectives and least tension with the margin not active and no
//! stiffness floor. Anything else (an active margin, a floor, a singular system, a bound not
//! within the tolerance after [`MAX_STEPS`] evaluations) returns to the interior-point
//! method's warm start.
//!
//! # Math
//! At `x`, with `g = ∇φ(x)`, `H = ∇²φ(x) ⪯ 0` and the active rows `W`, the step `d` and the
//! multipliers `y` of the rows solve
//!
//! ```text
//! [ −H + εI   G_Wᵀ ] [ d ]   [ g           ]
//! [  G_W      0    ] [ y ] = [ h_W − G_W x ]
//! ```
//!
//! (`ε` a relative 10⁻⁹ of `H`'s diagonal, so that the system stays regular along a direction
//! in which `φ` is linear; with as many rows as coordinates, `x + d` is their vertex whatever
//! `ε`). The bound at `x` takes `y` by least squares on `G_Wᵀ y = g`, clipped at 0:
//! `UB = φ + yᵀs + Σ_a max(r_a(1 − x_a), r_a(−1 − x_a))`, `r = g − G_Wᵀ y`, valid for any
//! `y ≥ 0` (the margin's multiplier is 0, so the margin only needs to hold, which one Cholesky
//! trial checks). An answer is accepted only inside every row (to [`ROUNDING`]).

use nalgebra::{DMatrix, DVector, Vector6};

use crate::blocks::base;
use crate::dense::cholesky;
use crate::frame::Frame;
use crate::ipm::Answer;
use crate::problem::{Objective, PlanSettings, Requirements};
use crate::program::{Duals, Smooth, upper_bound};
use crate::smooth::{EndObjective, Kind};

/// A row is active at the mapped point when its slack is below this (the frame's units: each
/// row's largest coefficient is 1 and `x ∈ [−1, 1]`).
pub(crate) const ACTIVE_SLACK: f64 = 1e-3;

/// The most objective evaluations (Newton steps and changes of the active set) of one warm
/// step.
pub(crate) const MAX_STEPS: usize = 6;

/// How far past a row (the frame's units) an accepted answer may lie: rounding of `G_W x = h_W`.
const ROUNDING: f64 = 1e-10;

/// A Newton step this short (largest coordinate, the frame's units) leaves `x` where it is:
/// the point is stationary on its active set.
const STATIONARY: f64 = 1e-9;

/// The objective of the step.
enum Goal<'a> {
    Smooth(Box<EndObjective<'a>>),
    /// `c₀ + cᵀx`.
    Linear(f64, Vec<f64>),
}

impl Goal<'_> {
    fn evaluate(&mut self, x: &[f64], gradient: &mut [f64], hessian: &mut [f64]) -> Option<f64> {
        match self {
            Goal::Smooth(s) => s.evaluate(x, gradient, hessian),
            Goal::Linear(c0, c) => {
                gradient.copy_from_slice(c);
                hessian.fill(0.0);
                Some(*c0 + c.iter().zip(x).map(|(a, b)| a * b).sum::<f64>())
            }
        }
    }
}

/// The rows active at `x` (slack below [`ACTIVE_SLACK`]), tightest first, at most one per
/// free coordinate: the active set a plan leaves to the next step's warm start.
pub(crate) fn active_rows(frame: &Frame, x: &[f64]) -> Vec<usize> {
    let k = frame.vars();
    let mut rows: Vec<(usize, f64)> = (0..frame.rhs.len())
        .map(|r| (r, slack(frame, x, r)))
        .filter(|(_, s)| *s < ACTIVE_SLACK)
        .collect();
    rows.sort_by(|a, b| a.1.total_cmp(&b.1));
    rows.truncate(k);
    rows.into_iter().map(|(r, _)| r).collect()
}

/// `h_r − G_r x`.
fn slack(frame: &Frame, x: &[f64], r: usize) -> f64 {
    let k = frame.vars();
    frame.rhs[r] - frame.rows[r * k..r * k + k].iter().zip(x).map(|(a, b)| a * b).sum::<f64>()
}

/// The warm answer from the mapped previous answer `x0` and the previous active set
/// `previous` (`None` when this frame's rows are not the previous frame's: then the rows
/// active at `x0`), or the evaluations spent when the step does not apply or is not
/// certified within the tolerance (module docs).
pub(crate) fn warm(
    frame: &Frame,
    objective: Objective,
    requirements: &Requirements,
    settings: &PlanSettings,
    x0: &[f64],
    previous: Option<&[usize]>,
) -> Result<Answer, usize> {
    if requirements.k_min.is_some() || requirements.k_des.is_some() {
        return Err(0);
    }
    let k = frame.vars();
    let mut goal = match objective {
        Objective::LeastTension => {
            Goal::Linear(-frame.total, frame.sums.iter().map(|s| -s).collect())
        }
        Objective::StiffnessAlong(u) => {
            let w = Vector6::new(u.x, u.y, u.z, 0.0, 0.0, 0.0);
            Goal::Smooth(Box::new(EndObjective::new(frame, Kind::Along(w), 1.0)))
        }
        Objective::Volume => Goal::Smooth(Box::new(EndObjective::new(frame, Kind::Volume, 1.0))),
        Objective::MinStiffness | Objective::ComplianceAlong(_) => return Err(0),
    };
    let sdp = base(frame, 0);
    let rows = frame.rhs.len();
    let mut active = match previous {
        Some(previous) => previous.to_vec(),
        None => active_rows(frame, x0),
    };
    let mut x = x0.to_vec();
    let (mut gradient, mut hessian) = (vec![0.0; k], vec![0.0; k * k]);
    let mut s = vec![0.0; rows];
    let mut a = vec![0.0; frame.n * frame.n];
    // The objective's scale: its value at the first point (the gap's floor 1e-9 of it, 1 in
    // log units for the volume).
    let mut scale = None;
    for step in 0..MAX_STEPS {
        if active.len() > k {
            return Err(step);
        }
        if active.len() == k {
            // As many rows as coordinates: their vertex, whatever the objective.
            let d = newton(frame, &x, &gradient, &hessian, &active).ok_or(step)?.0;
            x.iter_mut().zip(&d).for_each(|(xa, da)| *xa += da);
        }
        // The margin must hold (its multiplier is 0): one Cholesky trial.
        frame.a_at(&x, &mut a);
        for i in 0..frame.n {
            a[i * frame.n + i] -= requirements.margin;
        }
        if !cholesky(&mut a, frame.n) {
            return Err(step);
        }
        let value = goal.evaluate(&x, &mut gradient, &mut hessian).ok_or(step)?;
        let (scale, floor) = *scale.get_or_insert_with(|| match objective {
            Objective::Volume => (value.abs().max(1.0), 1.0 / value.abs().max(1.0)),
            _ => (value.abs().max(1e-12), 1e-9),
        });
        let value = value / scale;
        gradient.iter_mut().chain(hessian.iter_mut()).for_each(|v| *v /= scale);
        sdp.slacks(&x, &mut s);
        // The most violated row, if any.
        let violated = s
            .iter()
            .enumerate()
            .fold((None, -ROUNDING), |best, (r, &v)| if v < best.1 { (Some(r), v) } else { best })
            .0;
        if violated.is_none() {
            let duals = Duals { y: multipliers(frame, &gradient, &active), z: Vec::new() };
            let upper = upper_bound(&sdp, &x, value, &gradient, &s, std::iter::empty(), &duals);
            if upper - value <= settings.relative_gap * value.abs().max(floor) {
                return Ok(Answer { x, upper: upper * scale, iterations: step + 1 });
            }
        }
        let (d, y) = newton(frame, &x, &gradient, &hessian, &active).ok_or(step + 1)?;
        if d.iter().fold(0.0_f64, |m, v| m.max(v.abs())) > STATIONARY {
            x.iter_mut().zip(&d).for_each(|(xa, da)| *xa += da);
            continue;
        }
        // Stationary on W and not certified: a violated row joins W, else the row with the
        // most negative multiplier leaves it.
        match violated {
            Some(r) if active.len() < k => active.push(r),
            Some(_) => return Err(step + 1),
            None => {
                let (i, least) = y
                    .iter()
                    .enumerate()
                    .fold((0, 0.0), |best, (i, &v)| if v < best.1 { (i, v) } else { best });
                if least >= 0.0 {
                    return Err(step + 1);
                }
                active.remove(i);
            }
        }
    }
    Err(MAX_STEPS)
}

/// The Newton step `d` and the active rows' multipliers `y` (module docs); `None` when the
/// system is singular.
fn newton(
    frame: &Frame,
    x: &[f64],
    gradient: &[f64],
    hessian: &[f64],
    active: &[usize],
) -> Option<(Vec<f64>, Vec<f64>)> {
    let k = frame.vars();
    let p = active.len();
    let largest = (0..k).map(|a| hessian[a * k + a].abs()).fold(0.0, f64::max);
    let epsilon = 1e-9 * largest.max(1e-3);
    let mut kkt = DMatrix::zeros(k + p, k + p);
    let mut rhs = DVector::zeros(k + p);
    for a in 0..k {
        for b in 0..k {
            kkt[(a, b)] = -hessian[a * k + b];
        }
        kkt[(a, a)] += epsilon;
        rhs[a] = gradient[a];
    }
    for (i, &r) in active.iter().enumerate() {
        let row = &frame.rows[r * k..r * k + k];
        for (a, v) in row.iter().enumerate() {
            kkt[(k + i, a)] = *v;
            kkt[(a, k + i)] = *v;
        }
        rhs[k + i] = slack(frame, x, r);
    }
    let solution = kkt.lu().solve(&rhs)?;
    if !solution.iter().all(|v| v.is_finite()) {
        return None;
    }
    let d = solution.rows(0, k).iter().copied().collect();
    Some((d, solution.rows(k, p).iter().copied().collect()))
}

/// Every row's multiplier for the bound: the active rows' by least squares on `G_Wᵀ y = g`,
/// clipped at 0, the others' 0.
fn multipliers(frame: &Frame, gradient: &[f64], active: &[usize]) -> Vec<f64> {
    let k = frame.vars();
    let mut y = vec![0.0; frame.rhs.len()];
    if active.is_empty() {
        return y;
    }
    let g = DMatrix::from_fn(active.len(), k, |i, a| frame.rows[active[i] * k + a]);
    let gram = &g * g.transpose();
    if let Some(c) = gram.cholesky() {
        let solved = c.solve(&(&g * DVector::from_column_slice(gradient)));
        for (&r, v) in active.iter().zip(solved.iter()) {
            y[r] = v.max(0.0);
        }
    }
    y
}
