//! The joint stiffness with friction at the holes (spec §9, #27): the regimes, the workspace
//! both regimes write ([`FrictionStiffnessData`]) and what they share. The stick regime is in
//! `stick.rs` ([`crate::stick_stiffness`]), the slip regimes in `slip.rs`
//! ([`crate::slip_stiffness`]).
//!
//! # One elastic model
//! Every piece of cable is a linear spring `E A / ℓ`: the free length (`ℓ_0 = ℓ_free`, the
//! actuator held in position, as eq. 13 assumes) and every segment (`ℓ_s(Q)`, at the pose).
//! Where a hole slides, material flows through it and the pieces on either side act in series,
//! their tensions tied by the capstan ratio; where it sticks, they act apart. Stick: every piece
//! apart (`K_stick`). Slip: every piece in series (`K_slip`).
//!
//! Both matrices are split as the frictionless `K` is: a part proportional to the actuator
//! tensions ([`FrictionStiffnessData::controllable`]) and a part free of them
//! ([`FrictionStiffnessData::inherent`]); [`FrictionStiffnessData::stiffness`] is their sum,
//! affine in the actuator tensions for a given regime (and history).

use faer::MatRef;
use sinew_routing::{CableRows, FrictionData, FrictionModel, Routing, RoutingData, Slip};

use crate::colmajor::{ColMajor, mirror_upper};
use crate::error::StiffnessError;
use crate::hessian_sums::{Weights, add_weighted_hessians};

/// How the segment tensions of a sticking cable were left (spec §9): the distribution of the
/// last slip, or equal tensions along each cable.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum History {
    /// Last pulled in: `T_s = T_0 w_s^pull` (every hole on the lower edge of its band).
    Pull,
    /// Last released: `T_s = T_0 w_s^release` (every hole on the upper edge of its band).
    Release,
    /// Equal tensions along each cable, `T_s = T_0` (after dithering, or at assembly): strictly
    /// inside every band of a bent cable.
    Equal,
}

impl History {
    /// The slip regime whose capstan weights give the segment tensions (`None` for
    /// [`History::Equal`]: every weight 1).
    pub fn slip(self) -> Option<Slip> {
        match self {
            History::Pull => Some(Slip::Pull),
            History::Release => Some(Slip::Release),
            History::Equal => None,
        }
    }
}

/// The regime of the stiffness a [`FrictionStiffnessData`] holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FrictionRegime {
    /// Every hole slides the one way ([`crate::slip_stiffness`]).
    Slip(Slip),
    /// No hole slides, the tensions left by a history ([`crate::stick_stiffness`]).
    Stick(History),
}

/// The workspace of [`crate::stick_stiffness`] and [`crate::slip_stiffness`] (Pinocchio's
/// *data*): the dof × dof results and the scratch rows, sized once by
/// [`FrictionStiffnessData::new`]; an evaluation allocates nothing.
#[derive(Debug, Clone)]
pub struct FrictionStiffnessData {
    pub(crate) dof: usize,
    pub(crate) cables: usize,
    pub(crate) regime: Option<FrictionRegime>,
    pub(crate) controllable: ColMajor,
    pub(crate) inherent: ColMajor,
    pub(crate) stiffness: ColMajor,
    pub(crate) symmetric: ColMajor,
    pub(crate) skew_norm: f64,
    /// Scratch (slip), m × dof: row `c` is `J_c / C̃_c` for a cable with friction, else 0.
    pub(crate) series_elastic: ColMajor,
    /// Scratch (slip), dof × m: column `c` is `T_0 g_c / C̃_c`, `g_c = Σ_s c_s ∂w_s/∂Q`.
    pub(crate) moving_series_t: ColMajor,
    /// Scratch, one per routing segment: its tension `T_s` (the weight of its Hessian).
    pub(crate) segment_tensions: Vec<f64>,
    /// Scratch (slip), one per DOF: the running sum `G_k = σμ T_0 Σ_{s>k} w_s J_s` of one
    /// cable (zero between cables).
    pub(crate) suffix: Vec<f64>,
}

impl FrictionStiffnessData {
    /// A workspace for the friction geometry `model` (its DOFs and cables).
    pub fn new(model: &FrictionModel) -> FrictionStiffnessData {
        let (n, m) = (model.dof(), model.cable_count());
        FrictionStiffnessData {
            dof: n,
            cables: m,
            regime: None,
            controllable: ColMajor::zeros(n, n),
            inherent: ColMajor::zeros(n, n),
            stiffness: ColMajor::zeros(n, n),
            symmetric: ColMajor::zeros(n, n),
            skew_norm: 0.0,
            series_elastic: ColMajor::zeros(m, n),
            moving_series_t: ColMajor::zeros(n, m),
            suffix: vec![0.0; n],
            segment_tensions: vec![0.0; model.routing_segment_count()],
        }
    }

    /// The regime of the last evaluation (`None` before one, or after a failed one).
    pub fn regime(&self) -> Option<FrictionRegime> {
        self.regime
    }

    /// The part of the joint stiffness proportional to the actuator tensions (dof × dof,
    /// N m/rad): `Σ_s T_s H_s` (stick; slip: with the terms of the moving weights, module docs
    /// of `slip.rs`).
    ///
    /// # Errors
    /// [`StiffnessError::StageMissing`] before an evaluation.
    pub fn controllable(&self) -> Result<MatRef<'_, f64>, StiffnessError> {
        self.computed()?;
        Ok(self.controllable.as_ref())
    }

    /// The part of the joint stiffness free of the tensions (dof × dof, N m/rad): the cable's
    /// elasticity, `Σ_s J_sᵀ (E A/ℓ_s) J_s` (stick) or `J̃_cᵀ J_c / C̃_c` (slip).
    ///
    /// # Errors
    /// As [`FrictionStiffnessData::controllable`].
    pub fn inherent(&self) -> Result<MatRef<'_, f64>, StiffnessError> {
        self.computed()?;
        Ok(self.inherent.as_ref())
    }

    /// The joint stiffness `K = −∂τ/∂Q` of the regime (dof × dof, N m/rad): controllable +
    /// inherent. Symmetric in the stick regime, not in the slip regimes.
    ///
    /// # Errors
    /// As [`FrictionStiffnessData::controllable`].
    pub fn stiffness(&self) -> Result<MatRef<'_, f64>, StiffnessError> {
        self.computed()?;
        Ok(self.stiffness.as_ref())
    }

    /// The symmetric part `(K + Kᵀ)/2` of [`FrictionStiffnessData::stiffness`].
    ///
    /// # Errors
    /// As [`FrictionStiffnessData::controllable`].
    pub fn symmetric_part(&self) -> Result<MatRef<'_, f64>, StiffnessError> {
        self.computed()?;
        Ok(self.symmetric.as_ref())
    }

    /// The Frobenius norm of the skew part `(K − Kᵀ)/2` of
    /// [`FrictionStiffnessData::stiffness`], N m/rad (0 in the stick regime).
    ///
    /// # Errors
    /// As [`FrictionStiffnessData::controllable`].
    pub fn skew_norm(&self) -> Result<f64, StiffnessError> {
        self.computed()?;
        Ok(self.skew_norm)
    }

    /// [`FrictionStiffnessData::stiffness`]'s storage (the end stage reads its columns).
    pub(crate) fn stiffness_storage(&self) -> Result<&ColMajor, StiffnessError> {
        self.computed()?;
        Ok(&self.stiffness)
    }

    fn computed(&self) -> Result<(), StiffnessError> {
        match self.regime {
            Some(_) => Ok(()),
            None => Err(StiffnessError::StageMissing {
                needs: "stick_stiffness or slip_stiffness",
                missing: "friction stiffness",
            }),
        }
    }

    /// Check every size against the model and the tensions, and clear the results.
    pub(crate) fn start(
        &mut self,
        model: &FrictionModel,
        routing: &Routing,
        tensions: &[f64],
    ) -> Result<(), StiffnessError> {
        self.regime = None;
        for (what, expected, got) in [
            ("friction stiffness workspace (joints)", routing.dof(), self.dof),
            ("friction stiffness workspace (cables)", routing.cable_count(), self.cables),
            ("friction model (joints)", routing.dof(), model.dof()),
            ("friction model (cables)", routing.cable_count(), model.cable_count()),
            ("actuator tensions", routing.cable_count(), tensions.len()),
        ] {
            if expected != got {
                return Err(StiffnessError::DimensionMismatch { what, expected, got });
            }
        }
        self.controllable.as_mut_slice().fill(0.0);
        self.inherent.as_mut_slice().fill(0.0);
        Ok(())
    }

    /// The inherent part's upper triangle copied onto its lower one.
    pub(crate) fn mirror_inherent(&mut self) {
        let inherent = &mut self.inherent;
        mirror_upper(0..self.dof, |i, j| *inherent.at_mut(i, j) = inherent.at(j, i));
    }

    /// `K = K_c + K_i`, its symmetric part and the norm of its skew part; then the regime.
    /// A stick `K` is exactly symmetric (both parts are written in symmetric pairs, module docs
    /// of `stick.rs`; its tests check `K = Kᵀ` bit for bit): its symmetric part is `K` and its
    /// skew part 0, with no pass over the pairs.
    pub(crate) fn finish(&mut self, regime: FrictionRegime) {
        let n = self.dof;
        let (c, i) = (self.controllable.as_slice(), self.inherent.as_slice());
        for ((k, c), i) in self.stiffness.as_mut_slice().iter_mut().zip(c).zip(i) {
            *k = c + i;
        }
        if let FrictionRegime::Stick(_) = regime {
            self.symmetric.as_mut_slice().copy_from_slice(self.stiffness.as_slice());
            self.skew_norm = 0.0;
            self.regime = Some(regime);
            return;
        }
        // Each pair (r, j), (j, r) once: the symmetric part's two equal entries, and the skew
        // part's two equal squares.
        let mut skew = 0.0;
        for j in 0..n {
            for r in 0..j {
                let (a, b) = (self.stiffness.at(r, j), self.stiffness.at(j, r));
                let mean = 0.5 * (a + b);
                *self.symmetric.at_mut(r, j) = mean;
                *self.symmetric.at_mut(j, r) = mean;
                skew += 2.0 * (0.5 * (a - b)).powi(2);
            }
            *self.symmetric.at_mut(j, j) = self.stiffness.at(j, j);
        }
        self.skew_norm = skew.sqrt();
        self.regime = Some(regime);
    }
}

/// `K_c = Σ_c Σ_s T_{c,s} H_{c,s}` into `out.controllable` (zeros before), with each segment's
/// tension `T_s = T_0 · weight(c, s)` (`weight(c, s)` the weight of friction segment `s ≥ 1` of
/// cable `c`). Summed as the frictionless `Σ_c f_c H_c` is (batch by batch on a batched
/// routing, else segment by segment), so that weights of exactly 1 give its bits.
pub(crate) fn add_segment_hessians(
    (model, routing, geometry): (&FrictionModel, &Routing, &RoutingData),
    friction: &FrictionData,
    actuator: &[f64],
    weight: impl Fn(&CableRows<'_>, usize) -> f64,
    out: &mut FrictionStiffnessData,
) -> Result<(), StiffnessError> {
    let FrictionStiffnessData { segment_tensions, controllable, .. } = out;
    for (c, &t_0) in actuator.iter().enumerate() {
        let cable = friction.cable(model, c)?;
        for s in 1..cable.len() {
            if let Some(t) = cable.routing_segment(s).and_then(|r| segment_tensions.get_mut(r)) {
                *t = t_0 * weight(&cable, s);
            }
        }
    }
    let hessians = geometry.segment_hessians(routing)?;
    add_weighted_hessians(routing, hessians, Weights::Segment(segment_tensions), controllable)
}

/// The capstan weights of `slip` in `friction`, checked to be that regime's.
pub(crate) fn check_weights(friction: &FrictionData, slip: Slip) -> Result<(), StiffnessError> {
    if friction.slip() != Some(slip) {
        return Err(StiffnessError::WrongCapstanWeights { needs: slip, computed: friction.slip() });
    }
    Ok(())
}

/// `E A` of the routing's cables, N.
pub(crate) fn axial_rigidity(routing: &Routing) -> f64 {
    routing.youngs_modulus() * routing.area()
}
