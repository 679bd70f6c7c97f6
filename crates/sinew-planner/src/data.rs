//! The planner's workspace ([`PlannerData`]): the stiffness pipeline's, and the buffers a plan
//! reuses from the last (its set, pencil, rows, frame, the interior-point phases' and the warm
//! step's), so that a plan allocates only its answer once they have the room.

use sinew_statics::EquilibriumSet;
use sinew_stiffness::{ArmStiffness, ArmStiffnessData};

use crate::active;
use crate::bundle::Linear;
use crate::error::PlanError;
use crate::frame::Frame;
use crate::least::LeastEigen;
use crate::pencil::Pencil;

/// The planner's workspace.
#[derive(Debug)]
pub struct PlannerData {
    pub(crate) stiffness: ArmStiffnessData,
    /// The last plan's tensions, for a rate limit and a warm start along a trajectory.
    pub(crate) previous: Option<Vec<f64>>,
    /// The tensions of the plan before the last, where the last was a step after it along a
    /// trajectory (the flag; the buffer is kept either way): with the last, the warm start's
    /// predicted tensions `2 f_k − f_{k−1}` (module docs of `along.rs`).
    pub(crate) before: (bool, Vec<f64>),
    /// The last interior-point plan's active rows, with the number of rows of its frame (the
    /// warm start's first active set when this frame has as many).
    pub(crate) active: Option<(usize, Vec<usize>)>,
    /// The last plan's pencil, its buffers reused by the next.
    pub(crate) pencil: Option<Pencil>,
    /// The answer's `sym(K_q + K_W)` (row-major) and its least eigenvalue's workspace.
    pub(crate) margin: (Vec<f64>, LeastEigen),
    /// The last plan's equilibrium set: the next pose's is copied into its buffers.
    pub(crate) set: Option<EquilibriumSet>,
    /// The last interior-point plan's frame, its buffers reused by the next.
    pub(crate) frame: Option<Frame>,
    /// The last plan's rows in `λ`, merged, and the merge's scratch.
    pub(crate) rows: Option<(Linear, Linear, Vec<usize>)>,
    /// The warm step's buffers, with the interior-point phases'.
    pub(crate) warm: active::WarmWork,
}

/// The buffers a plan takes out of its workspace while it runs.
pub(crate) type Taken = (Frame, active::WarmWork, Pencil, (Linear, Linear, Vec<usize>));

impl PlannerData {
    /// A workspace for a planner of `arm`.
    pub(crate) fn for_arm(arm: &ArmStiffness) -> PlannerData {
        PlannerData {
            stiffness: ArmStiffnessData::new(arm),
            previous: None,
            before: (false, Vec::new()),
            active: None,
            pencil: None,
            margin: (Vec::new(), LeastEigen::default()),
            set: None,
            frame: None,
            rows: None,
            warm: active::WarmWork::default(),
        }
    }

    /// Forget the previous plan (its tensions and the margin's last eigenvector): the next
    /// plan is cold and depends on its own arguments only.
    pub(crate) fn forget(&mut self) {
        self.margin.1.forget();
        self.before.0 = false;
        self.warm.forget(self.previous.take());
    }

    /// The buffers of a plan that ends in an error back into the workspace, with its set, so
    /// that the next plan finds them: the error.
    pub(crate) fn keep(
        &mut self,
        (frame, warm, pencil, rows): Taken,
        set: EquilibriumSet,
        error: PlanError,
    ) -> PlanError {
        self.frame = Some(frame);
        self.warm = warm;
        self.pencil = Some(pencil);
        self.rows = Some(rows);
        self.set = Some(set);
        error
    }

    /// The stiffness workspace of the last plan (the arm evaluated at its tensions; its
    /// [`ArmStiffnessData::pose_stages`] counts the pose stages the plans have run).
    pub fn stiffness(&self) -> &ArmStiffnessData {
        &self.stiffness
    }
}
