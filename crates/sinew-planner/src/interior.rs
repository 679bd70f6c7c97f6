//! The interior-point plan, cold: a point inside the rows, a stable one, one meeting the
//! floors, then the objective ([`crate::ipm`]); and the state a warm start keeps.

use crate::error::PlanError;
use crate::frame::Frame;
use crate::ipm::{Answer, Interior};
use crate::problem::{Objective, PlanSettings, Requirements};
use crate::sdp::Duals;

/// What the workspace keeps of the last interior-point answer for the next plan.
#[derive(Debug, Clone)]
pub(crate) struct Warm {
    pub(crate) duals: Duals,
    pub(crate) objective: Objective,
}

/// The cold method: the answer and the iterations of the phases before the last.
///
/// # Errors
/// The phases' ([`Interior`]).
pub(crate) fn cold(
    frame: &Frame,
    objective: Objective,
    requirements: &Requirements,
    settings: &PlanSettings,
) -> Result<(Answer, usize), PlanError> {
    let problem = Interior::new(frame, objective, requirements, settings);
    let (x, rows) = problem.inside_rows()?;
    let (x, stable) = problem.stable(x)?;
    let (x, floors) = problem.floors_met(x)?;
    let answer = problem.optimise(&x, None, settings.max_iterations)?;
    Ok((answer, rows + stable + floors))
}
