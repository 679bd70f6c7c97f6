//! The warm step of re-planning by Newton steps on the previous answer's active set (issue
//! #24): the previous tensions mapped into this pose's frame, the previous plan's active rows
//! (or, when the rows are not the previous frame's, those the mapped point leaves within
//! [`ACTIVE_SLACK`] of their bound), then Newton (SQP) steps on the KKT system of
//! `max φ(x) s.t. G_W x = h_W` and, when the stability margin binds, `c(x) = δ` with
//! `c = λ_min(A(x)) − m` (`margin_row.rs`). Where a step is stationary on `W` but not
//! certified, the most violated row joins `W`, or the member with the most negative multiplier
//! leaves it. The margin joins `W` where the mapped point is within [`ACTIVE_SLACK`]` · a_scale`
//! of it, where an iterate leaves it, or where a step on the rows alone would leave the box
//! (least tension is linear: without the margin's curvature its step is unbounded). The step is
//! for the smooth objectives and least tension with no stiffness floor. Anything else (a floor,
//! a least eigenvalue that is not simple, a singular system, a bound not within the tolerance
//! after [`MAX_STEPS`] evaluations) returns to the interior-point method's warm start.
//!
//! # Math
//! At `x`, with `g = ∇φ(x)`, the Lagrangian's Hessian `H = ∇²φ(x) + η ∇²c(x) ⪯ 0` (`η ≥ 0`
//! the margin's multiplier; `∇²c ⪯ 0`) and the working set `W` (rows `G_W`, and the margin's
//! row `−∇cᵀ`), the step `d` and the multipliers `y` solve
//!
//! ```text
//! [ −H + εI   G_Wᵀ ] [ d ]   [ g                 ]
//! [  G_W      0    ] [ y ] = [ h_W − G_W x; c − δ ]
//! ```
//!
//! (`ε` a relative 10⁻⁹ of `H`'s diagonal, so that the system stays regular along a direction
//! in which `φ` is linear; with as many rows as coordinates, `x + d` is their vertex whatever
//! `ε`). The margin's target `δ > 0` keeps the answer strictly stable at a cost `η δ` of a
//! quarter of the tolerance. The bound at `x` takes `(y, η)` by least squares on
//! `G_Wᵀ y − η ∇c = g`, clipped at 0, and `Z = η v vᵀ` (`v` the margin's eigenvector):
//! `UB = φ + yᵀs + η c + Σ_a max(r_a(1 − x_a), r_a(−1 − x_a))`, `r = g − Gᵀ y + η ∇c`, valid
//! for any `y ≥ 0`, `η ≥ 0` (the bound of `program.rs`). An answer is accepted only where the
//! margin holds (one Cholesky trial of `A − m I`) and inside every row (to [`ROUNDING`]).

use std::iter::empty;

use nalgebra::Vector6;

use crate::blocks::base_into;
use crate::dense::{axpy, cholesky, dot};
use crate::frame::Frame;
use crate::ipm::Answer;
use crate::ipm_work::IpmWork;
use crate::kkt::{MARGIN, multipliers, newton, slack};
use crate::margin_row::MarginRow;
use crate::problem::{Objective, PlanSettings, Requirements};
use crate::program::{Duals, Sdp, Smooth, upper_bound};
use crate::smooth::{EndBuffers, EndObjective, Kind};

/// A row is active at the mapped point when its slack is below this (the frame's units: each
/// row's largest coefficient is 1 and `x ∈ [−1, 1]`).
pub(crate) const ACTIVE_SLACK: f64 = 1e-3;

/// The most objective evaluations (Newton steps and changes of the active set) of one warm
/// step.
pub(crate) const MAX_STEPS: usize = 8;

/// A Newton step longer than this (largest coordinate, the frame's units) leaves the box
/// `[−1, 1]`: the working set lacks a constraint.
const LONGEST: f64 = 2.0;

/// How far past a row (the frame's units) an accepted answer may lie: rounding of `G_W x = h_W`.
const ROUNDING: f64 = 1e-10;

/// A Newton step this short (largest coordinate, the frame's units) leaves `x` where it is:
/// the point is stationary on its active set.
const STATIONARY: f64 = 1e-9;

/// The buffers of the warm step, kept in the planner's workspace: a step along a trajectory
/// allocates none of them again.
#[derive(Debug, Default)]
pub(crate) struct WarmWork {
    /// The mapped previous answer `x₀` (filled by the caller).
    pub(crate) mapped: Vec<f64>,
    /// The predicted tensions that `mapped` maps (the caller's).
    pub(crate) predicted: Vec<f64>,
    /// The iterate (moved into the answer; the caller returns it).
    pub(crate) x: Vec<f64>,
    /// A forgotten plan's tensions' buffer (`PlannerData::forget`), for the next plan's.
    pub(crate) tensions: Vec<f64>,
    /// The buffers of the interior-point phases (a cold plan's, and a warm step's last phase).
    pub(crate) ipm: IpmWork,
    end: EndBuffers,
    sdp: Option<Sdp>,
    active: Vec<usize>,
    gradient: Vec<f64>,
    hessian: Vec<f64>,
    s: Vec<f64>,
    a: Vec<f64>,
    /// The KKT matrix (row-major) and its right-hand side, then `(d, y)`.
    kkt: Vec<f64>,
    rhs: Vec<f64>,
    /// Every row's multiplier, and the least-squares system of the active ones.
    y: Vec<f64>,
    gram: Vec<f64>,
    /// Rows and slacks, for [`active_rows_into`].
    pairs: Vec<(usize, f64)>,
    /// The margin's linearisation when it is in the working set, and the bound's gradient
    /// `g + η ∇c`.
    margin: MarginRow,
    bound_gradient: Vec<f64>,
}

impl WarmWork {
    /// Forget the margin's last eigenvector (its buffers kept): the next plan is then a
    /// function of its inputs alone. The forgotten plan's tensions' buffer, if any, is kept
    /// for the next plan's.
    pub(crate) fn forget(&mut self, tensions: Option<Vec<f64>>) {
        self.margin.forget();
        if let Some(tensions) = tensions {
            self.tensions = tensions;
        }
    }

    /// The scratch of [`active_rows_into`].
    pub(crate) fn pairs(&mut self) -> &mut Vec<(usize, f64)> {
        &mut self.pairs
    }
}

/// The objective of the step.
#[allow(clippy::large_enum_variant)] // one per warm step, on the stack: no allocation
enum Goal<'a> {
    Smooth(EndObjective<'a>),
    /// `−Σ f = −total − sumsᵀx` (least tension).
    Linear,
}

impl Goal<'_> {
    /// The value, the gradient and, unless `gradient_only`, the Hessian at `x` (else the
    /// Hessian is left as it was, or zero for the linear objective).
    fn evaluate(
        &mut self,
        frame: &Frame,
        x: &[f64],
        (gradient, hessian): (&mut [f64], &mut [f64]),
        gradient_only: bool,
    ) -> Option<f64> {
        match self {
            Goal::Smooth(s) => {
                s.gradient_only = gradient_only;
                s.evaluate(x, gradient, hessian)
            }
            Goal::Linear => {
                gradient.iter_mut().zip(&frame.sums).for_each(|(g, s)| *g = -s);
                hessian.fill(0.0);
                Some(-frame.total - dot(&frame.sums, x))
            }
        }
    }
}

/// The rows active at `x` (slack below [`ACTIVE_SLACK`]), tightest first, at most one per
/// free coordinate, into `out` (`pairs` a scratch): the active set a plan leaves to the next
/// step's warm start.
pub(crate) fn active_rows_into(
    frame: &Frame,
    x: &[f64],
    out: &mut Vec<usize>,
    pairs: &mut Vec<(usize, f64)>,
) {
    pairs.clear();
    pairs.extend(
        (0..frame.rhs.len()).map(|r| (r, slack(frame, x, r))).filter(|(_, s)| *s < ACTIVE_SLACK),
    );
    pairs.sort_unstable_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
    pairs.truncate(frame.vars());
    out.clear();
    out.extend(pairs.iter().map(|(r, _)| *r));
}

/// The warm answer from the mapped previous answer `x0` and the previous active set
/// `previous` (`None` when this frame's rows are not the previous frame's: then the rows
/// active at `x0`), or the evaluations spent when the step does not apply or is not
/// certified within the tolerance (module docs). The buffers are `work`'s; the answer's `x` is
/// `work.x`, moved.
pub(crate) fn warm(
    frame: &Frame,
    objective: Objective,
    requirements: &Requirements,
    settings: &PlanSettings,
    x0: &[f64],
    previous: Option<&[usize]>,
    work: &mut WarmWork,
) -> Result<Answer, usize> {
    if requirements.k_min.is_some() || requirements.k_des.is_some() {
        return Err(0);
    }
    let end = std::mem::take(&mut work.end);
    let mut goal = match objective {
        Objective::LeastTension => Goal::Linear,
        Objective::StiffnessAlong(u) => {
            let w = Vector6::new(u.x, u.y, u.z, 0.0, 0.0, 0.0);
            Goal::Smooth(EndObjective::reusing(frame, Kind::Along(w), 1.0, end))
        }
        Objective::Volume => Goal::Smooth(EndObjective::reusing(frame, Kind::Volume, 1.0, end)),
        Objective::ComplianceAlong(u) => {
            Goal::Smooth(EndObjective::reusing(frame, Kind::Compliance(u), 1.0, end))
        }
        Objective::MinStiffness => {
            Goal::Smooth(EndObjective::reusing(frame, Kind::Least, 1.0, end))
        }
    };
    let result = steps(frame, objective, requirements, settings, x0, previous, &mut goal, work);
    if let Goal::Smooth(smooth) = goal {
        work.end = smooth.into_buffers();
    }
    result
}

/// The steps of [`warm`] with its objective `goal`.
#[allow(clippy::too_many_arguments)]
fn steps(
    frame: &Frame,
    objective: Objective,
    requirements: &Requirements,
    settings: &PlanSettings,
    x0: &[f64],
    previous: Option<&[usize]>,
    goal: &mut Goal<'_>,
    work: &mut WarmWork,
) -> Result<Answer, usize> {
    let (k, n, m) = (frame.vars(), frame.n, requirements.margin);
    let sdp = work.sdp.get_or_insert_with(Sdp::default);
    base_into(frame, 0, sdp);
    match previous {
        Some(previous) => {
            work.active.clear();
            work.active.extend_from_slice(previous);
        }
        None => active_rows_into(frame, x0, &mut work.active, &mut work.pairs),
    }
    let active = &mut work.active;
    work.x.clear();
    work.x.extend_from_slice(x0);
    let x = &mut work.x;
    let sized = |v: &mut Vec<f64>, len: usize| {
        v.clear();
        v.resize(len, 0.0);
    };
    sized(&mut work.gradient, k);
    sized(&mut work.hessian, k * k);
    sized(&mut work.s, frame.rhs.len());
    sized(&mut work.a, n * n);
    let (gradient, hessian, s, a) =
        (&mut work.gradient, &mut work.hessian, &mut work.s, &mut work.a);
    let (kkt, rhs, y, gram) = (&mut work.kkt, &mut work.rhs, &mut work.y, &mut work.gram);
    let (margin, bound_gradient) = (&mut work.margin, &mut work.bound_gradient);
    let apply = |i: usize, v: &[f64], out: &mut [f64]| frame.ai_apply(i, v, out);
    // The objective's scale: its value at the first point (the gap's floor 1e-9 of it, 1 in
    // log units for the volume).
    let mut scale = None;
    // The margin's multiplier, for the Lagrangian's Hessian.
    let mut eta = 0.0;
    for step in 0..MAX_STEPS {
        let mut with_margin = active.contains(&MARGIN);
        if active.len() > k {
            return Err(step);
        }
        if active.len() == k && !with_margin {
            // As many rows as coordinates: their vertex, whatever the objective.
            if !newton(frame, x, gradient, hessian, active, None, kkt, rhs) {
                return Err(step);
            }
            x.iter_mut().zip(&rhs[..k]).for_each(|(xa, da)| *xa += da);
        }
        frame.a_at(x, a);
        if with_margin && !margin.linearise(a, n, k, apply) {
            return Err(step);
        }
        // The margin must hold: one Cholesky trial. At the mapped point, a margin within
        // ACTIVE_SLACK of binding joins the working set.
        let near = if step == 0 && !with_margin { ACTIVE_SLACK * frame.a_scale } else { 0.0 };
        for i in 0..n {
            a[i * n + i] -= m + near;
        }
        let mut inside = cholesky(a, n);
        if !inside && !with_margin {
            // At the mapped point the margin takes the loosest row's place in a full set.
            if k == 0 || (active.len() >= k && near == 0.0) {
                return Err(step);
            }
            active.truncate(k - 1);
            active.push(MARGIN);
            with_margin = true;
            frame.a_at(x, a);
            if !margin.linearise(a, n, k, apply) {
                return Err(step);
            }
            inside = near > 0.0 && margin.rho > m && {
                for i in 0..n {
                    a[i * n + i] -= m;
                }
                cholesky(a, n)
            };
        }
        // The value and gradient first: they decide the certificate, which most warm steps
        // meet at their first point; the Hessian only where a Newton step follows.
        let value = goal.evaluate(frame, x, (gradient, hessian), true).ok_or(step)?;
        let (scale, floor) = *scale.get_or_insert_with(|| match objective {
            Objective::Volume => (value.abs().max(1.0), 1.0 / value.abs().max(1.0)),
            _ => (value.abs().max(1e-12), 1e-9),
        });
        let value = value / scale;
        gradient.iter_mut().chain(hessian.iter_mut()).for_each(|v| *v /= scale);
        let tolerance = settings.relative_gap * value.abs().max(floor);
        sdp.slacks(x, s);
        // The most violated row, if any.
        let violated = s
            .iter()
            .enumerate()
            .fold((None, -ROUNDING), |best, (r, &v)| if v < best.1 { (Some(r), v) } else { best })
            .0;
        let c_gradient = with_margin.then_some(&margin.gradient[..]);
        if violated.is_none() || with_margin {
            eta = multipliers(frame, gradient, active, c_gradient, y, gram);
        }
        if violated.is_none() && inside {
            // The bound with Z = η v vᵀ (module docs of `margin_row.rs`).
            let (mut bound_value, c) = (value, margin.rho - m);
            bound_gradient.clone_from(gradient);
            if with_margin {
                bound_value += eta * c;
                axpy(eta, &margin.gradient, bound_gradient);
            }
            let duals = Duals { y: std::mem::take(y), ..Duals::default() };
            let none = |_, _| None;
            let upper = upper_bound(sdp, x, bound_value, bound_gradient, s, empty(), &duals, none);
            *y = duals.y;
            if upper - value <= tolerance {
                let x = std::mem::take(x);
                return Ok(Answer { x, upper: upper * scale, iterations: step + 1 });
            }
        }
        // Not certified: the Hessian at x (and the gradient again, the same to the bit).
        goal.evaluate(frame, x, (gradient, hessian), false).ok_or(step)?;
        gradient.iter_mut().chain(hessian.iter_mut()).for_each(|v| *v /= scale);
        // The Lagrangian's Hessian, and the margin's target: `c = δ` inside it by a quarter of
        // the tolerance's worth of objective (`η δ`), so that the answer is strictly stable.
        let margin_row = with_margin.then(|| {
            axpy(eta, &margin.hessian, hessian);
            let delta = (0.25 * tolerance / eta.max(f64::MIN_POSITIVE))
                .clamp(1e-10 * frame.a_scale, 1e-6 * frame.a_scale);
            (&margin.gradient[..], margin.rho - m - delta)
        });
        if !newton(frame, x, gradient, hessian, active, margin_row, kkt, rhs) {
            return Err(step + 1);
        }
        let (d, multipliers) = rhs.split_at(k);
        let length = d.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        if length > LONGEST && !with_margin && active.len() < k {
            // A step out of the box: the objective has too little curvature on W (least
            // tension is linear), and the margin, the one curved constraint, must bind.
            active.push(MARGIN);
            continue;
        }
        if let Some(i) = active.iter().position(|r| *r == MARGIN) {
            eta = multipliers[i].max(0.0);
        }
        if d.iter().fold(0.0_f64, |m, v| m.max(v.abs())) > STATIONARY {
            x.iter_mut().zip(d).for_each(|(xa, da)| *xa += da);
            continue;
        }
        // Stationary on W and not certified: a violated row joins W, else the row (or the
        // margin) with the most negative multiplier leaves it.
        match violated {
            Some(r) if active.len() < k => active.push(r),
            Some(_) => return Err(step + 1),
            None => {
                let (i, least) = multipliers
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
