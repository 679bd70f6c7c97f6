//! The interior-point plan, cold: a point inside the rows, a stable one, one meeting the
//! floors, then the objective ([`crate::ipm`]); and warm, from the previous step's tensions
//! mapped into this pose's set (module docs of `along.rs`).

use crate::active;
use crate::error::PlanError;
use crate::frame::Frame;
use crate::ipm::{Answer, Interior};
use crate::problem::{Objective, PlanSettings, Requirements};

/// The most iterations a warm start may take before the step runs cold.
pub(crate) const WARM_ITERATIONS: usize = 12;

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
    let answer = problem.optimise(&x, settings.max_iterations)?;
    Ok((answer, rows + stable + floors))
}

/// Newton steps on the mapped previous answer's active set ([`active::warm`]); where they do
/// not apply or are not certified, the last phase from the mapped previous answer (restored
/// into the interior when it is not strictly inside), capped at [`WARM_ITERATIONS`]: the
/// answer, or the iterations spent when it is refused (not restorable, not certified in time).
/// The mapped answer is `work.mapped`; the Newton steps' buffers are `work`'s.
pub(crate) fn warm(
    frame: &Frame,
    objective: Objective,
    requirements: &Requirements,
    settings: &PlanSettings,
    previous_active: Option<&[usize]>,
    work: &mut active::WarmWork,
) -> Result<Answer, usize> {
    let x = std::mem::take(&mut work.mapped);
    let newton = active::warm(frame, objective, requirements, settings, &x, previous_active, work);
    let tried = match newton {
        Ok(answer) => {
            work.mapped = x;
            return Ok(answer);
        }
        Err(steps) => steps,
    };
    let mut problem = Interior::new(frame, objective, requirements, settings);
    problem.warm = true;
    let x = problem.restored(x).ok_or(tried)?;
    match problem.optimise(&x, WARM_ITERATIONS) {
        Ok(answer) => Ok(Answer { iterations: answer.iterations + tried, ..answer }),
        Err(PlanError::NotConverged { iterations, .. }) => Err(iterations + tried),
        Err(_) => Err(WARM_ITERATIONS + tried),
    }
}
