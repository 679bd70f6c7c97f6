//! Re-planning along a trajectory: one plan per step, each warm-started from the previous
//! step's answer, optionally with a bound on each cable's rate of tension change.
//!
//! # Warm start
//! The previous tensions are mapped into the new pose's equilibrium set through the tensions,
//! `λ' = N'ᵀ(f_prev − f_p')`, so a change of basis of `N` does not matter. Where the previous
//! step followed another, `f_prev` is the linear prediction `2 f_k − f_{k−1}` within the tension
//! limits (`rows::predicted`): along a smooth trajectory its error is second order in the time
//! step, the last tensions' first order (on the bench's routed trajectory: one cold step per
//! 100 instead of three, and for the volume 66 Newton steps over 198 warm steps instead of
//! 118). From there, Newton
//! steps on the previous plan's active rows (module docs of `active.rs`: the smooth objectives
//! and least tension, with the margin not active and no floor). Where those do not apply or are
//! not certified: when the point is strictly inside the new constraints (else it is moved by
//! one least-norm step onto the linearised violated constraints: the restoration step), the
//! last phase runs from it with multipliers centred there (`μ` by least squares) and a small
//! iteration cap. An answer is accepted only with its certificate within the tolerance;
//! otherwise the step runs cold.

use nalgebra::Vector6;

/// One step of a trajectory: the pose and the end's force (base frame, no moment).
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// The joint angles, rad.
    pub q: Vec<f64>,
    /// The wrench at the end (its moment must be zero), N.
    pub f0: Vector6<f64>,
}

/// A bound on the rate of tension change: `|f_k − f_{k−1}| ≤ max_rate · dt` per cable.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateLimit {
    /// The largest rate of change of any cable's tension, N/s.
    pub max_rate: f64,
    /// The time step between two steps, s.
    pub dt: f64,
}

impl RateLimit {
    /// The largest change per step, N.
    pub fn max_change(&self) -> f64 {
        self.max_rate * self.dt
    }
}

/// What one step of [`crate::Planner::plan_along`] gave.
#[derive(Debug)]
pub struct AlongStep {
    /// The plan, or why the step has none (the next step then starts cold).
    pub plan: Result<crate::Plan, crate::PlanError>,
    /// Whether the warm path's answer was accepted (certified within the tolerance).
    pub warm: bool,
    /// Iterations of the method at this step (the warm attempt's included).
    pub iterations: usize,
}

impl crate::Planner {
    /// Plans along a trajectory: one certified plan per step, each warm-started from the
    /// previous step's answer (module docs), with `rate` bounding every cable's change per step.
    /// A step without a plan is typed in its row ([`AlongStep::plan`]); the next starts cold.
    ///
    /// # Errors
    /// [`crate::PlanError::InvalidInput`] for a rate or time step that is not finite and
    /// positive (then no step is planned).
    pub fn plan_along(
        &self,
        data: &mut crate::PlannerData,
        steps: &[Step],
        objective: crate::Objective,
        requirements: &crate::Requirements,
        settings: &crate::PlanSettings,
        rate: Option<RateLimit>,
    ) -> Result<Vec<AlongStep>, crate::PlanError> {
        check_rate(rate)?;
        data.forget();
        let mut out = Vec::with_capacity(steps.len());
        for step in steps {
            out.push(self.replan(data, step, objective, requirements, settings, rate)?);
        }
        Ok(out)
    }

    /// One step of re-planning in a control loop, where the poses come one at a time: the
    /// plan at `step`, warm-started from the tensions of the last plan made in `data` (by
    /// [`Self::plan`], [`Self::plan_along`] or `replan`) as the steps of [`Self::plan_along`]
    /// are, with `rate` bounding each cable's change from them. With no last plan (a new
    /// workspace, or a last step that had none) the step runs cold. [`Self::plan`] at a
    /// trajectory's first step and then `replan` at each of the others give the plans
    /// [`Self::plan_along`] gives.
    ///
    /// # Errors
    /// [`crate::PlanError::InvalidInput`] for a rate or time step that is not finite and
    /// positive (then the step is not planned).
    pub fn replan(
        &self,
        data: &mut crate::PlannerData,
        step: &Step,
        objective: crate::Objective,
        requirements: &crate::Requirements,
        settings: &crate::PlanSettings,
        rate: Option<RateLimit>,
    ) -> Result<AlongStep, crate::PlanError> {
        check_rate(rate)?;
        let change = rate.map(|r| r.max_change());
        let result =
            self.plan_step(data, &step.q, &step.f0, objective, requirements, settings, change);
        Ok(match result {
            Ok((plan, warm, iterations)) => AlongStep { plan: Ok(plan), warm, iterations },
            // A step without a plan: the next starts cold.
            Err(e) => {
                data.previous = None;
                AlongStep { plan: Err(e), warm: false, iterations: 0 }
            }
        })
    }
}

/// A rate limit's rate and time step are finite and positive.
fn check_rate(rate: Option<RateLimit>) -> Result<(), crate::PlanError> {
    use crate::{InputProblem, PlanError};
    if let Some(r) = rate {
        for (what, v) in [("max_rate", r.max_rate), ("dt", r.dt)] {
            if !(v.is_finite() && v > 0.0) {
                let problem = InputProblem::NotPositive { unit: "", reason: "" };
                return Err(PlanError::InvalidInput { what, problem });
            }
        }
    }
    Ok(())
}
