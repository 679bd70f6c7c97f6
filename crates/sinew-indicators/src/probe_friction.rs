//! A joint probed with friction at the holes (spec §9, #27): the single-joint model
//! ([`crate::JointProbe`]) with the regime's statics and joint stiffness in place of the
//! frictionless ones.
//!
//! # Math
//! The joint's three cables hold the torque through their segment tensions, every other cable
//! at zero tension, as without friction. In a slip regime, and in stick after a pull or a
//! release, the segment tensions are `T_0 w_s` (the capstan weights at the pose), so the
//! actuator tensions `T_0` hold `τ = −J̃ᵀ T_0` on the joint's 3 × 2 block of `J̃`, each within
//! its cable's actuator limits (every segment within the cable's limits;
//! `sinew_statics::cable_actuator_limits`): the closed form on scaled tensions
//! (`sinew_statics::actuator_interval`). In stick after `equal` the tensions are equal along
//! each cable and the interval is the frictionless one. The joint stiffness is the regime's
//! (`sinew_stiffness::slip_stiffness`, `sinew_stiffness::stick_stiffness`) restricted to the
//! joint's 2 × 2 block; it is affine in the actuator tensions at a pose (the weights do not
//! depend on them), so its diagonal ranges between its values at the interval's two ends
//! (eq. 20). A slip stiffness is not symmetric; the indicators read its diagonal. At μ = 0 a
//! slip regime gives the frictionless probe's numbers bit for bit.

use nalgebra::{Matrix3x2, Vector2};
use sinew_routing::{
    FrictionData, FrictionModel, Routing, RoutingData, RoutingError, compute_capstan_weights,
    compute_friction_angles, compute_friction_geometry,
};
use sinew_statics::{TensionLimits, actuator_interval, cable_actuator_limits, tension_interval};
use sinew_stiffness::{
    FrictionRegime, FrictionStiffnessData, StiffnessError, joint_block, slip_stiffness,
    stick_stiffness,
};

use crate::error::IndicatorError;
use crate::range::JointStiffnessRange;

/// The friction model, regime and workspaces of a probe.
#[derive(Debug, Clone)]
pub(crate) struct ProbeFriction {
    pub(crate) model: FrictionModel,
    pub(crate) regime: FrictionRegime,
    data: FrictionData,
    stiffness: FrictionStiffnessData,
}

impl ProbeFriction {
    /// The friction `model` of `routing` in `regime`.
    ///
    /// # Errors
    /// [`IndicatorError::Routing`] ([`RoutingError::WorkspaceMismatch`]) for a model of
    /// another routing; [`IndicatorError::Stiffness`]
    /// ([`StiffnessError::StickWithoutFriction`]) for the stick regime with a cable at μ = 0.
    pub(crate) fn new(
        routing: &Routing,
        model: FrictionModel,
        regime: FrictionRegime,
    ) -> Result<ProbeFriction, IndicatorError> {
        for (what, expected, got) in [
            ("friction model's cables", routing.cable_count(), model.cable_count()),
            ("friction model's DOF", routing.dof(), model.dof()),
        ] {
            if expected != got {
                return Err(RoutingError::WorkspaceMismatch { what, expected, got }.into());
            }
        }
        if let FrictionRegime::Stick(_) = regime {
            let mu = model.friction_coefficients();
            if let Some(cable) = mu.iter().position(|&mu| mu <= 0.0) {
                return Err(StiffnessError::StickWithoutFriction { cable }.into());
            }
        }
        Ok(ProbeFriction {
            data: FrictionData::new(&model),
            stiffness: FrictionStiffnessData::new(&model),
            model,
            regime,
        })
    }

    /// The range of joint `joint` (its cables from `first` on) holding `tau`, with the cable
    /// geometry `cables` (with Hessians) at the pose; `tensions` (m) is scratch. No allocation.
    pub(crate) fn evaluate(
        &mut self,
        routing: &Routing,
        cables: &RoutingData,
        (joint, first): (usize, usize),
        tau: &Vector2<f64>,
        tensions: &mut [f64],
    ) -> Result<JointStiffnessRange, IndicatorError> {
        let (model, data) = (&self.model, &mut self.data);
        // The stick regime reads no wrap gradient (`compute_friction_angles` alone).
        match self.regime {
            FrictionRegime::Slip(_) => compute_friction_geometry(model, routing, cables, data)?,
            FrictionRegime::Stick(_) => compute_friction_angles(model, routing, cables, data)?,
        }
        let [f_min, f_max] = routing.tension_limits();
        let limits = TensionLimits { f_min, f_max };
        let slip = match self.regime {
            FrictionRegime::Slip(slip) => Some(slip),
            FrictionRegime::Stick(history) => history.slip(),
        };
        let (interval, ends) = match slip {
            None => {
                let j = cables.jacobian()?;
                let block = Matrix3x2::from_fn(|r, k| j[(first + r, 2 * joint + k)]);
                let interval = tension_interval(joint, &block, tau, limits)?;
                let (low, high) = interval.ends();
                (interval, [low, high])
            }
            Some(slip) => {
                compute_capstan_weights(model, data, slip)?;
                let own = routing.cable_limits();
                let mut actuator = [[0.0; 2]; 3];
                for (r, a) in actuator.iter_mut().enumerate() {
                    let c = first + r;
                    let segment = own.get(c).copied().unwrap_or([f_min, f_max]);
                    *a = cable_actuator_limits(model, data, c, segment)?;
                }
                let j = data.effective_jacobian()?;
                let block = Matrix3x2::from_fn(|r, k| j[(first + r, 2 * joint + k)]);
                let interval = actuator_interval((joint, first), &block, tau, limits, actuator)?;
                let (low, high) = interval.ends();
                (interval.scaled, [low, high])
            }
        };
        let mut k = [nalgebra::Matrix2::zeros(); 2];
        let mut controllable = [nalgebra::Matrix2::zeros(); 2];
        let mut inherent = nalgebra::Matrix2::zeros();
        for end in 0..2 {
            tensions.fill(0.0);
            tensions[first..first + 3].copy_from_slice(ends[end].as_slice());
            let (data, out) = (&self.data, &mut self.stiffness);
            match self.regime {
                FrictionRegime::Slip(slip) => {
                    slip_stiffness(model, routing, cables, data, slip, tensions, out)?
                }
                FrictionRegime::Stick(history) => {
                    stick_stiffness(model, routing, cables, data, history, tensions, out)?
                }
            }
            let no_joint = || IndicatorError::NoSuchJoint { joint, joints: routing.dof() / 2 };
            let kc = joint_block(out.controllable()?, joint).ok_or_else(no_joint)?;
            let ki = joint_block(out.inherent()?, joint).ok_or_else(no_joint)?;
            (controllable[end], inherent, k[end]) = (kc, ki, kc + ki);
        }
        Ok(JointStiffnessRange {
            interval,
            tensions: ends,
            k_at_min: k[0],
            k_at_max: k[1],
            controllable,
            inherent,
        })
    }
}
