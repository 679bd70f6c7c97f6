//! The pipeline `Q → K_x` with friction at the holes (spec §9, #27): the arm's pose stage, then
//! the friction geometry, the actuator tensions by the regime's statics, the regime's joint
//! stiffness and the end stage on it. What `sinew arm --friction` reports.
//!
//! # The tensions of a regime
//! - **Stick after `equal`**: equal tensions along each cable balance the load exactly as the
//!   frictionless statics say (`τ = −J_cᵀ f`): the arm's own tension stage chooses them (levels,
//!   a policy, given tensions or the default), and they are the actuator tensions.
//! - **Slip (pull or release), and stick after pull or release**: the segment tensions are
//!   `T_0 w_s`, so the actuator tensions `T_0` balance the load through `J̃`
//!   (`sinew_statics::slip_equilibrium_set`, with the actuator limits that keep every segment
//!   within the cable's limits): a policy over that set ([`TensionChoice::Default`]: least
//!   total), the paper's tension levels on each joint's interval of actuator tensions
//!   (`sinew_statics::slip_levels`: the closed form on `J̃` with each cable's actuator limits),
//!   or given actuator tensions checked against it.
//!
//! The end stage is the arm's dense one, with `K_W` from its generators (the same numbers as
//! [`crate::end_stiffness`] on the dense `K_W`, bit for bit): a slip `K` is not symmetric, and a
//! routed stick `K` is not block structured. A stick `K` is exactly symmetric, which the end
//! stage is told, so with a symmetric `K_W` only its lower triangle is formed.

use nalgebra::Vector6;
use sinew_routing::{
    FrictionData, FrictionModel, compute_capstan_weights, compute_friction_angles,
    compute_friction_geometry,
};
use sinew_statics::{
    TensionChoice, TensionPolicy, actuator_limits, check_balance, dead_band,
    distribute_with_policy, slip_equilibrium_set, slip_levels,
};

use crate::arm::ArmStiffness;
use crate::data::{ArmStiffnessData, EndOutcome};
use crate::end::{end_compliance_generated, stability_margin};
use crate::end_data::EndStiffnessData;
use crate::error::StiffnessError;
use crate::friction::{FrictionRegime, FrictionStiffnessData};
use crate::slip::slip_stiffness;
use crate::stick::stick_stiffness;

/// The workspace of [`ArmStiffness::evaluate_with_friction`] beside the arm's own
/// ([`ArmStiffnessData`]): the friction geometry, the regime's joint stiffness, its end, and
/// the tensions along every cable.
#[derive(Debug)]
pub struct FrictionArmData {
    /// The friction geometry at the pose (segments, wrap angles), with the regime's weights.
    pub friction: FrictionData,
    /// The regime's joint stiffness `K_q` (and its parts, symmetric part, skew norm).
    pub stiffness: FrictionStiffnessData,
    /// `C_x`, `K_x` of the regime.
    pub end: EndStiffnessData,
    /// The actuator tensions `T_{c,0}` (m, N).
    pub actuator: Vec<f64>,
    /// Per cable, the segment tensions from the actuator to the anchor (N).
    pub segments: Vec<Vec<f64>>,
    /// Per cable, the dead band `[T₀^release, T₀^pull]` of its anchor tension (N).
    pub dead_band: Vec<[f64; 2]>,
    /// Per cable, the anchor tension the dead band is computed for (N).
    anchor: Vec<f64>,
    /// The end's verdict (`None` before an evaluation).
    pub outcome: Option<EndOutcome>,
}

impl FrictionArmData {
    /// A workspace for `arm` with the friction geometry `model`.
    pub fn new(arm: &ArmStiffness, model: &FrictionModel) -> FrictionArmData {
        let m = model.cable_count();
        FrictionArmData {
            friction: FrictionData::new(model),
            stiffness: FrictionStiffnessData::new(model),
            end: EndStiffnessData::new(arm.dof()),
            actuator: vec![0.0; m],
            segments: vec![Vec::new(); m],
            dead_band: vec![[0.0; 2]; m],
            anchor: vec![0.0; m],
            outcome: None,
        }
    }

    /// The stability margin of the last evaluation: the smallest eigenvalue of the symmetric
    /// part of `K_q + K_W` (N m/rad; positive: stable), `data` the arm's workspace of that
    /// evaluation (its `K_W`). Computed on demand, as [`ArmStiffnessData::stability_margin`]
    /// (an eigen-decomposition; allocates): an evaluation's outcome already says stable or not.
    ///
    /// # Errors
    /// [`StiffnessError::StageMissing`] before an evaluation; [`StiffnessError::Eigen`].
    pub fn stability_margin(&self, data: &mut ArmStiffnessData) -> Result<f64, StiffnessError> {
        stability_margin(self.stiffness.stiffness()?, data.k_w())
    }
}

impl ArmStiffness {
    /// The pipeline with friction at the holes in `regime` (module docs): the pose stage at `Q`
    /// under `F0`, the friction geometry, the actuator tensions by `choice`, the regime's `K_q`,
    /// then `C_x` and `K_x`. The arm's own workspace `data` holds the pose (and, after `equal`,
    /// the frictionless tension stage). Unstable and rank-deficient are outcomes.
    ///
    /// In the stick regime `out.friction` holds the friction geometry without the wrap
    /// gradients, which nothing in it reads (`sinew_routing::compute_friction_angles`); call
    /// `sinew_routing::compute_wrap_gradients(model, &mut out.friction)` before
    /// [`crate::directional_response`] or [`crate::stick_load_limits`] on it.
    ///
    /// It turns on `data.cables`' kept segment directions
    /// (`sinew_routing::RoutingData::keep_segment_directions`), which the friction geometry reads;
    /// a frictionless [`ArmStiffness::evaluate`] on the same workspace then keeps them too (about
    /// 5 % more instructions) until turned off there.
    ///
    /// # Errors
    /// Those of the pose stage, the statics, [`crate::stick_stiffness`] (μ = 0 in
    /// the stick regime) and [`crate::slip_stiffness`]; numerical failures of the end stage.
    pub fn evaluate_with_friction(
        &self,
        data: &mut ArmStiffnessData,
        out: &mut FrictionArmData,
        (model, regime): (&FrictionModel, FrictionRegime),
        q: &[f64],
        f0: &Vector6<f64>,
        choice: TensionChoice<'_>,
    ) -> Result<EndOutcome, StiffnessError> {
        out.outcome = None;
        // The friction geometry reads the routing's segment directions.
        data.cables.keep_segment_directions(true);
        self.set_pose(data, q, f0)?;
        let routing = self.routing();
        // The stick regime's tensions and stiffness read no wrap gradient: the directional
        // response and the stick load limit, which do, are asked for after
        // `sinew_routing::compute_wrap_gradients`.
        match regime {
            FrictionRegime::Slip(_) => {
                compute_friction_geometry(model, routing, &data.cables, &mut out.friction)?
            }
            FrictionRegime::Stick(_) => {
                compute_friction_angles(model, routing, &data.cables, &mut out.friction)?
            }
        }
        let slip = match regime {
            FrictionRegime::Slip(slip) => Some(slip),
            FrictionRegime::Stick(history) => history.slip(),
        };
        match slip {
            None => {
                self.set_tensions(data, choice)?;
                out.actuator.copy_from_slice(data.tensions());
            }
            Some(slip) => {
                compute_capstan_weights(model, &mut out.friction, slip)?;
                self.slip_tensions(data, out, model, choice)?;
            }
        }
        for (c, segments) in out.segments.iter_mut().enumerate() {
            let t_0 = out.actuator[c];
            segments.clear();
            match slip {
                None => segments.resize(out.friction.lengths(model, c)?.len(), t_0),
                Some(_) => segments.extend(out.friction.weights(model, c)?.iter().map(|w| t_0 * w)),
            }
        }
        for (a, s) in out.anchor.iter_mut().zip(&out.segments) {
            *a = s.last().copied().unwrap_or(0.0);
        }
        dead_band(model, &out.friction, &out.anchor, &mut out.dead_band)?;
        let geometry = &data.cables;
        match regime {
            FrictionRegime::Slip(slip) => {
                let (f, t, k) = (&out.friction, &out.actuator, &mut out.stiffness);
                slip_stiffness(model, routing, geometry, f, slip, t, k)?
            }
            FrictionRegime::Stick(history) => {
                let (f, t, k) = (&out.friction, &out.actuator, &mut out.stiffness);
                stick_stiffness(model, routing, geometry, f, history, t, k)?
            }
        }
        // The arm's dense end stage (`end_compliance_generated`: `K_W` from its generators,
        // the same sums as `end_stiffness` with the dense `K_W`); a stick `K_q` is exactly
        // symmetric, a slip one is not.
        let joint_end = data.statics.joint_end();
        let k_q = (out.stiffness.stiffness_storage()?, matches!(regime, FrictionRegime::Stick(_)));
        let stable =
            end_compliance_generated(k_q, joint_end.generators(), joint_end.j_x(), &mut out.end)?;
        let outcome = if !stable {
            // Not positive definite: the smallest eigenvalue, from the dense K_W.
            data.fill_k_w();
            let min_eigenvalue = stability_margin(k_q.0.as_ref(), data.k_w_filled.as_ref())?;
            EndOutcome::Unstable { min_eigenvalue }
        } else {
            match out.end.invert_compliance() {
                Ok(()) => EndOutcome::Stiff,
                Err(StiffnessError::RankDeficient { pivot_ratio }) => {
                    EndOutcome::RankDeficient { pivot_ratio }
                }
                Err(e) => return Err(e),
            }
        };
        out.outcome = Some(outcome);
        Ok(outcome)
    }

    /// The actuator tensions of a pull or release distribution (module docs), into
    /// `out.actuator`.
    fn slip_tensions(
        &self,
        data: &ArmStiffnessData,
        out: &mut FrictionArmData,
        model: &FrictionModel,
        choice: TensionChoice<'_>,
    ) -> Result<(), StiffnessError> {
        let statics = self.statics();
        let names = statics.cable_names();
        let policy = match choice {
            TensionChoice::Levels(levels) => {
                let closed_form = (statics.closed_form()?, statics.limits());
                let (t0, limits) = (&data.statics.t0, statics.cable_limits());
                let out_t = &mut out.actuator;
                slip_levels(model, &out.friction, closed_form, limits, t0, levels, out_t)?;
                return Ok(());
            }
            TensionChoice::Given(tensions) => {
                let mut limits = vec![[0.0; 2]; model.cable_count()];
                actuator_limits(model, &out.friction, statics.cable_limits(), &mut limits)?;
                let j_tilde = out.friction.effective_jacobian()?;
                check_balance(j_tilde, &data.statics.t0, &limits, names, tensions)?;
                out.actuator.copy_from_slice(tensions);
                return Ok(());
            }
            TensionChoice::Policy(policy) => policy,
            TensionChoice::Default => TensionPolicy::LeastTotal,
        };
        let set = slip_equilibrium_set(
            model,
            &out.friction,
            &data.statics.t0,
            statics.cable_limits(),
            statics.joint_groups(),
        )?;
        distribute_with_policy(&set, policy, statics.joint_groups(), names, &mut out.actuator)?;
        Ok(())
    }
}
