//! How the tensions of a tension stage are chosen ([`TensionChoice`], with the one default of
//! every front end) and how they were ([`Chosen`]).

use crate::policy::TensionPolicy;

/// How to choose the tensions among those that balance the load.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TensionChoice<'a> {
    /// The paper's tension levels, one per joint in `[0, 1]` (0: least total tension, 1: most;
    /// spec §4), in closed form. Needs three cables per universal joint with common limits
    /// ([`crate::ArmStatics::closed_form`]).
    Levels(&'a [f64]),
    /// A named policy over the equilibrium set (any cable set).
    Policy(TensionPolicy),
    /// These tensions (m, N, routing order), checked: within their limits and balancing the
    /// load to [`crate::EQUILIBRIUM_TOLERANCE`].
    Given(&'a [f64]),
    /// The default, the one every front end uses when the user chooses nothing: every joint at
    /// tension level 0 where the closed form applies ([`crate::ArmStatics::has_levels`]), else the
    /// policy [`TensionPolicy::LeastTotal`]. Both are the least total tension of their kind.
    Default,
}

/// How the tensions of the last tension stage were chosen ([`crate::ArmStaticsData::chosen`]):
/// [`TensionChoice`] with [`TensionChoice::Default`] resolved.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Chosen {
    /// No tension stage since the last pose stage.
    Nothing,
    /// The paper's tension levels (closed form).
    Levels,
    /// A named policy over the equilibrium set.
    Policy(TensionPolicy),
    /// Given tensions, checked.
    Given,
}

impl Chosen {
    /// The name the front ends print: `levels`, the policy's name, `given`, or `none`.
    pub fn name(self) -> &'static str {
        match self {
            Chosen::Nothing => "none",
            Chosen::Levels => "levels",
            Chosen::Policy(policy) => policy.name(),
            Chosen::Given => "given",
        }
    }
}

/// Said where [`TensionChoice::Default`] fell back on the least-total policy because the
/// routing does not take the tension levels.
pub const DEFAULT_POLICY_NOTE: &str =
    "tension levels need three cables per universal joint: the tensions are the policy least-total";
