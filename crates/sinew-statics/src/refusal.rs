//! Why the statics refuse, with the numbers: why a joint's cables cannot hold its torque
//! ([`InfeasibleReason`]), what is wrong with given tensions ([`NotBalanced`]), and a refusal
//! of the tension levels that the levels caused ([`LevelsInfeasible`]); each prints its
//! message. The payloads of [`crate::StaticsError`].

use sinew_robot::Compact;

/// Why a joint's cables cannot hold its torque.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum InfeasibleReason {
    /// The joint's cable Jacobian block has rank < 2: the cables cannot produce some torque.
    RankDeficient,
    /// The null space of `J_cᵀ` has no strictly positive direction (lost force closure) and
    /// that alone decides nothing: kept for callers that require force closure. The solvers of
    /// this crate report force closure as a property instead
    /// ([`crate::TensionInterval::force_closure`]) and answer whenever tensions within the
    /// limits exist.
    NoForceClosure {
        /// Unit null direction of `J_cᵀ`.
        null: [f64; 3],
    },
    /// Cable `cable` (0, 1 or 2 of the joint) cannot change its tension without unbalancing
    /// the joint (its null-direction component is zero), and the tension it must keep is
    /// outside the limits.
    FixedTension {
        /// The cable, 0-based within the joint.
        cable: usize,
        /// The tension it must keep, N.
        tension: f64,
    },
    /// Every balancing tension vector leaves some cable outside `[f_min, f_max]`: the limits
    /// would need `λ ≥ lambda_min` and `λ ≤ lambda_max` with `lambda_min > lambda_max`.
    OutsideLimits {
        /// Least `λ` that keeps every cable at or above `f_min`.
        lambda_min: f64,
        /// Greatest `λ` that keeps every cable at or below `f_max`.
        lambda_max: f64,
    },
}

impl std::fmt::Display for InfeasibleReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            InfeasibleReason::RankDeficient => write!(f, "its cable Jacobian has rank < 2"),
            InfeasibleReason::NoForceClosure { null } => write!(
                f,
                "its cables have lost force closure (null direction [{}, {}, {}] is not positive)",
                Compact(null[0]),
                Compact(null[1]),
                Compact(null[2])
            ),
            InfeasibleReason::FixedTension { cable, tension } => write!(
                f,
                "its cable {} must keep the tension {} N, outside the limits, whatever the others do",
                cable + 1,
                Compact(*tension)
            ),
            InfeasibleReason::OutsideLimits { lambda_min, lambda_max } => write!(
                f,
                "no tensions within the limits hold the torque (λ ≥ {} and λ ≤ {})",
                Compact(*lambda_min),
                Compact(*lambda_max)
            ),
        }
    }
}

/// What is wrong with given tensions ([`crate::StaticsError::NotBalanced`]).
#[derive(Debug, Clone, PartialEq)]
pub enum NotBalanced {
    /// A tension outside its cable's limits (or not finite).
    OutsideLimits {
        /// The cable's name.
        cable: String,
        /// Its tension, N.
        tension: f64,
        /// Its `[f_min, f_max]`, N.
        limits: [f64; 2],
    },
    /// The tensions leave a torque unbalanced: `|T0 + J_cᵀ f|` above
    /// [`crate::EQUILIBRIUM_TOLERANCE`] of the torques' scale.
    Residual {
        /// `|T0 + J_cᵀ f|`, N m.
        residual: f64,
        /// `|T0|`, N m.
        t0: f64,
    },
}

impl std::fmt::Display for NotBalanced {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NotBalanced::OutsideLimits { cable, tension, limits } => write!(
                f,
                "leave the limits: cable `{cable}` has {} N, outside [{}, {}] N",
                Compact(*tension),
                Compact(limits[0]),
                Compact(limits[1])
            ),
            NotBalanced::Residual { residual, t0 } => write!(
                f,
                "do not balance the load: |T0 + J_cᵀ f| = {} N m, |T0| = {} N m",
                Compact(*residual),
                Compact(*t0)
            ),
        }
    }
}

/// A refusal of the tension levels that the levels caused ([`crate::StaticsError::LevelsInfeasible`]):
/// in the routed model the closed form fixes the distal joints' tensions first, at their levels,
/// and those tensions load the proximal joints.
#[derive(Debug, Clone, PartialEq)]
pub struct LevelsInfeasible {
    /// The joint that cannot hold its torque (0-based; the message counts from 1).
    pub joint: usize,
    /// The torque its own cables must hold, N m (the load's and the distal cables').
    pub torque: [f64; 2],
    /// `[f_min, f_max]`, N.
    pub limits: [f64; 2],
    /// Why its own cables cannot hold it.
    pub reason: InfeasibleReason,
    /// The distal joints whose levels did it (0-based), each with the torque its cables add
    /// at `joint`, N m.
    pub distal: Vec<(usize, [f64; 2])>,
    /// A policy that holds the same load within the limits.
    pub policy: crate::TensionPolicy,
}

impl std::fmt::Display for LevelsInfeasible {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let joints: Vec<String> = self.distal.iter().map(|(j, _)| (j + 1).to_string()).collect();
        let added = self.distal.iter().fold([0.0; 2], |a, (_, t)| [a[0] + t[0], a[1] + t[1]]);
        write!(
            f,
            "joint {} cannot hold torque [{}, {}] N m with tensions in [{}, {}] N at these tension levels: {}; \
             the levels of joint{} {} fixed their cables' tensions first, and those add [{}, {}] N m at joint {}. \
             Tensions within the limits do balance this load: choose a tension policy instead of levels \
             (e.g. {}: `--policy {}` on the command line, `policy=\"{}\"` in Python)",
            self.joint + 1,
            Compact(self.torque[0]),
            Compact(self.torque[1]),
            Compact(self.limits[0]),
            Compact(self.limits[1]),
            self.reason,
            if joints.len() == 1 { "" } else { "s" },
            joints.join(", "),
            Compact(added[0]),
            Compact(added[1]),
            self.joint + 1,
            self.policy.name(),
            self.policy.name(),
            self.policy.name(),
        )
    }
}
