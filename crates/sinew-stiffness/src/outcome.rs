//! The one evaluation outcome of the library ([`Outcome`]): stable or not, the stability
//! margin, whether `J_x` has full rank, `C_x`, `K_x`, `K_fd`, the translational stiffness and
//! the stiffness ellipsoid when they exist, each optional part computed on demand, and the
//! notes that say why a part is missing. The command line, the Python bindings and
//! `sinew::paper` print or convert it; none of them decides any of it again.

use faer::{Mat, MatRef};
use nalgebra::Matrix3;

use crate::data::{ArmStiffnessData, EndOutcome};
use crate::ellipsoid::StiffnessEllipsoid;
use crate::end::stability_margin;
use crate::error::StiffnessError;

/// The outcome of the last end stage of a workspace, read on demand
/// ([`ArmStiffnessData::outcome`]).
#[derive(Debug, Clone, Copy)]
pub struct Outcome<'a> {
    data: &'a ArmStiffnessData,
    end: EndOutcome,
}

/// Why a part of an [`Outcome`] is missing, as the front ends print it
/// ([`Outcome::notes`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OutcomeNote {
    /// `K_q + K_W` is not positive definite: no `C_x`, `K_x`, `K_fd` or ellipsoid.
    Unstable,
    /// `J_x` has rank < 6: no `K_x`, `K_fd` or ellipsoid (`C_x` exists).
    RankDeficient {
        /// Smallest over largest pivot magnitude of `C_x`'s LU factorisation.
        pivot_ratio: f64,
    },
    /// `C_x[0:3, 0:3]` is singular: no translational stiffness with rotations free.
    TranslationSingular,
    /// `K_fd` is not positive definite: the ellipsoid has no semi-axes, condition number or
    /// volume.
    IndefiniteKfd,
}

impl OutcomeNote {
    /// The note's text, naming a missing value by `null` (`"null"` in JSON, `"None"` in
    /// Python).
    pub fn text(&self, null: &str) -> String {
        match self {
            OutcomeNote::Unstable => "unstable equilibrium: K_q + K_W is not positive definite \
                 (min_eigenvalue < 0), so C_x, K_x, K_fd and the ellipsoid do not exist"
                .to_owned(),
            OutcomeNote::RankDeficient { pivot_ratio } => format!(
                "{}: k_x, k_fd and the ellipsoid are {null}",
                StiffnessError::RankDeficient { pivot_ratio: *pivot_ratio }
            ),
            OutcomeNote::TranslationSingular => format!(
                "C_x[0:3, 0:3] is singular (the end cannot translate in some direction): \
                 k_translational is {null}"
            ),
            OutcomeNote::IndefiniteKfd => format!(
                "K_fd is not positive definite: the ellipsoid's semi-axes, condition number and \
                 volume are {null}"
            ),
        }
    }
}

impl EndOutcome {
    /// The note of an end without `K_x`: unstable, or `J_x` rank-deficient.
    pub fn note(self) -> Option<OutcomeNote> {
        match self {
            EndOutcome::Stiff => None,
            EndOutcome::RankDeficient { pivot_ratio } => {
                Some(OutcomeNote::RankDeficient { pivot_ratio })
            }
            EndOutcome::Unstable { .. } => Some(OutcomeNote::Unstable),
        }
    }
}

impl ArmStiffnessData {
    /// The outcome of the last end stage ([`crate::ArmStiffness::solve_end`] or
    /// [`crate::ArmStiffness::evaluate`]); `None` when the stages since the last pose have not
    /// reached it.
    pub fn outcome(&self) -> Option<Outcome<'_>> {
        self.end_outcome().map(|end| Outcome { data: self, end })
    }
}

impl<'a> Outcome<'a> {
    /// The end stage's verdict.
    pub fn end(&self) -> EndOutcome {
        self.end
    }

    /// Whether `K_q + K_W` is positive definite.
    pub fn is_stable(&self) -> bool {
        self.end.is_stable()
    }

    /// Whether `J_x` has full rank where it was tested: stable and `K_x` exists. (An unstable
    /// arm has no `C_x` to test: `false`.)
    pub fn has_full_rank(&self) -> bool {
        self.end.has_end_stiffness()
    }

    /// The stability margin: the smallest eigenvalue of the symmetric part of `K_q + K_W`
    /// (N m/rad; positive: stable). The unstable verdict's own eigenvalue; otherwise computed
    /// now (an eigendecomposition, which allocates; not for inner loops).
    ///
    /// # Errors
    /// [`StiffnessError::Eigen`].
    pub fn margin(&self) -> Result<f64, StiffnessError> {
        if let EndOutcome::Unstable { min_eigenvalue } = self.end {
            return Ok(min_eigenvalue);
        }
        let n = self.data.k_q.rows();
        let mut k_w = Mat::<f64>::zeros(n, n);
        self.data.statics.joint_end().generators().fill_dense(k_w.as_mut())?;
        stability_margin(self.data.k_q(), k_w.as_ref())
    }

    /// `C_x` (6 × 6), when the arm is stable.
    pub fn compliance(&self) -> Option<MatRef<'a, f64>> {
        self.is_stable().then(|| self.data.compliance())
    }

    /// `K_x` (6 × 6), when it exists.
    pub fn stiffness(&self) -> Option<MatRef<'a, f64>> {
        self.has_full_rank().then(|| self.data.stiffness())
    }

    /// `K_fd = K_x[0:3, 0:3]` (eq. 21), N/m, when `K_x` exists.
    pub fn k_fd(&self) -> Option<Matrix3<f64>> {
        self.has_full_rank().then(|| self.data.k_fd())
    }

    /// `(C_x[0:3, 0:3])⁻¹`, N/m (rotations free), when the arm is stable and that block is
    /// not singular.
    pub fn translational_stiffness(&self) -> Option<Matrix3<f64>> {
        if self.is_stable() { self.data.translational_stiffness() } else { None }
    }

    /// The stiffness ellipsoid of `K_fd`, when `K_x` exists (computed now).
    ///
    /// # Errors
    /// [`StiffnessError::NonFinite`] for a `K_fd` with a NaN.
    pub fn ellipsoid(&self) -> Result<Option<StiffnessEllipsoid>, StiffnessError> {
        self.k_fd().map(|k| StiffnessEllipsoid::new(&k)).transpose()
    }

    /// Why parts are missing, in the order the front ends print them: instability or rank
    /// deficiency, a singular translational block, an indefinite `K_fd`. Computes the
    /// translational stiffness and the ellipsoid.
    ///
    /// # Errors
    /// As [`Outcome::ellipsoid`].
    pub fn notes(&self) -> Result<Vec<OutcomeNote>, StiffnessError> {
        let mut notes: Vec<OutcomeNote> = self.end.note().into_iter().collect();
        if self.is_stable() && self.translational_stiffness().is_none() {
            notes.push(OutcomeNote::TranslationSingular);
        }
        if let Some(e) = self.ellipsoid()?
            && !e.is_positive_definite()
        {
            notes.push(OutcomeNote::IndefiniteKfd);
        }
        Ok(notes)
    }
}
