//! What a joint probe returns: one joint's stiffness over its feasible tension interval, and
//! the paper's indicators of it (eq. 20).

use nalgebra::{Matrix2, Vector3};
use sinew_statics::TensionInterval;

/// The range of one stiffness component over the feasible tensions, and its width (eq. 20).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Indicator {
    /// `[K^min, K^max]`, N m/rad.
    pub range: [f64; 2],
    /// `Δk = K^max − K^min`, N m/rad.
    pub delta: f64,
}

impl Indicator {
    fn from_ends(a: f64, b: f64) -> Indicator {
        let range = [a.min(b), a.max(b)];
        Indicator { range, delta: range[1] - range[0] }
    }
}

/// One joint's stiffness over its feasible tension interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointStiffnessRange {
    /// The feasible tension interval of the joint's three cables. With friction at the holes
    /// after a pull or a release (a slip regime, or stick after one), the cables' actuator
    /// limits differ, and this is the interval of their normalised tensions
    /// (`sinew_statics::ActuatorInterval::scaled`); [`JointStiffnessRange::tensions`] are the
    /// actuator tensions at its ends.
    pub interval: TensionInterval,
    /// The three cables' (actuator) tensions at the least and at the most total tension, N:
    /// where `k_at_min` and `k_at_max` are taken.
    pub tensions: [Vector3<f64>; 2],
    /// Joint stiffness at the least total tension (`λ_min` without friction), 2 × 2, N m/rad.
    pub k_at_min: Matrix2<f64>,
    /// Joint stiffness at the most total tension (`λ_max` without friction), 2 × 2, N m/rad.
    pub k_at_max: Matrix2<f64>,
    /// The controllable part at both ends (`Σ f_c H_c` over the joint's own three cables,
    /// [`crate::JointProbe::tensioned_cables`]; with friction, the regime's part proportional
    /// to the tensions), N m/rad.
    pub controllable: [Matrix2<f64>; 2],
    /// The inherent part (`J_cᵀ K_l J_c` over every cable crossing the joint,
    /// [`crate::JointProbe::inherent_cables`]; with friction, the regime's part independent of
    /// the tensions; the same at both ends), N m/rad.
    pub inherent: Matrix2<f64>,
}

impl JointStiffnessRange {
    /// `σ_{i,x}`: the range of `K_{i,x}` and its width (eq. 20).
    pub fn sigma_x(&self) -> Indicator {
        Indicator::from_ends(self.k_at_min[(0, 0)], self.k_at_max[(0, 0)])
    }

    /// `σ_{i,y}`: the range of `K_{i,y}` and its width (eq. 20).
    pub fn sigma_y(&self) -> Indicator {
        Indicator::from_ends(self.k_at_min[(1, 1)], self.k_at_max[(1, 1)])
    }

    /// The joint stiffness at tension level `s ∈ [0, 1]` (affine in `λ`, and in the actuator
    /// tensions with friction).
    pub fn at_level(&self, s: f64) -> Matrix2<f64> {
        self.k_at_min + s * (self.k_at_max - self.k_at_min)
    }
}
