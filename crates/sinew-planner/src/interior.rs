//! The interior-point plan, cold: a point inside the rows, a stable one, one meeting the
//! floors, then the objective ([`crate::ipm`]); and warm, from the previous step's tensions
//! mapped into this pose's set (module docs of `along.rs`).

use crate::active;
use crate::error::PlanError;
use crate::frame::Frame;
use crate::ipm::{Answer, Interior, Last};
use crate::problem::{Objective, PlanSettings, Requirements};

/// The most iterations a warm start may take before the step runs cold.
pub(crate) const WARM_ITERATIONS: usize = 12;

/// The cold method: the answer (its `x` in the buffer `work.x`, moved) and the iterations of
/// the phases before the last, in `work`'s buffers.
///
/// # Errors
/// The phases' ([`Interior`]).
pub(crate) fn cold(
    frame: &Frame,
    objective: Objective,
    requirements: &Requirements,
    settings: &PlanSettings,
    work: &mut active::WarmWork,
) -> Result<(Answer, usize), PlanError> {
    let w = &mut work.ipm;
    let problem = Interior::new(frame, objective, requirements, settings, w);
    let rows = problem.inside_rows(w)?;
    let stable = problem.stable(w)?;
    let floors = problem.floors_met(w)?;
    let last = problem.optimise(w, settings.max_iterations)?;
    Ok((answer(work, last), rows + stable + floors))
}

/// The answer of the last phase, its `x` moved out of `work.x` (refilled from the phases').
fn answer(work: &mut active::WarmWork, last: Last) -> Answer {
    let mut x = std::mem::take(&mut work.x);
    x.clone_from(&work.ipm.x);
    Answer { x, upper: last.upper, iterations: last.iterations }
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
    let w = &mut work.ipm;
    let mut problem = Interior::new(frame, objective, requirements, settings, w);
    problem.warm = true;
    let restored = problem.restored(&x, w);
    work.mapped = x;
    if !restored {
        return Err(tried);
    }
    match problem.optimise(&mut work.ipm, WARM_ITERATIONS) {
        Ok(last) => {
            let answer = answer(work, last);
            Ok(Answer { iterations: answer.iterations + tried, ..answer })
        }
        Err(PlanError::NotConverged { iterations, .. }) => Err(iterations + tried),
        Err(_) => Err(WARM_ITERATIONS + tried),
    }
}
