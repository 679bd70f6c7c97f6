//! The joint stiffness indicator (eq. 20): one joint's stiffness over its feasible tension
//! interval.
//!
//! # Math
//! For universal joint `i` at angles `q = [q_i1, q_i2]` holding the torque `τ` with its three
//! cables, the feasible tensions are `f(λ) = f_p + λ n`, `λ ∈ [λ_min, λ_max]` (eq. 22–23), and
//! the joint stiffness `K(λ) = Σ_c f_c(λ) H_c + J_cᵀ K_l J_c` is affine in `λ`. So
//! `K_{i,x} = K[0,0]` and `K_{i,y} = K[1,1]` (eq. 20) range between their values at the two
//! ends of the interval, and
//!
//! ```text
//! σ_{i,x} = [K_{i,x}, Δk_{i,x}]ᵀ,  K_{i,x} ∈ [K^min, K^max],  Δk_{i,x} = K^max − K^min   (eq. 20)
//! ```
//!
//! This is the paper's single-joint model: the joint's own three cables hold the torque, the
//! other joints are at the angles given (zero by default). Exactly what it counts:
//!
//! - **tension** (the controllable part `Σ f_c H_c`): the joint's own three cables only
//!   ([`JointProbe::tensioned_cables`]); every other cable is at zero tension;
//! - **inherent** part `J_cᵀ K_l J_c`: every cable crossing the joint
//!   ([`JointProbe::inherent_cables`]), as elastic members at zero tension. In the decoupled
//!   routing these are the same three cables; in the routed model the distal joints' cables
//!   cross the joint too and add their inherent stiffness, but not their tension's (their
//!   tensions come from the whole arm's statics: `sinew_stiffness::ArmStiffness` accounts for
//!   them).
//!
//! The two angles, torque components and stiffness axes are about the universal joint's first
//! and second revolute joints (`Q[2i]`, `Q[2i+1]`), whatever their URDF axes; the paper's
//! `x` and `y` name the first and the second.

use std::ops::Range;

use faer::Mat;
use nalgebra::{Matrix2, Matrix3x2, Vector2};
use sinew_robot::{Robot, RobotData};
use sinew_routing::{FrictionModel, Order, Routing, RoutingData, compute_cable_geometry};
use sinew_statics::{TensionLimits, tension_interval};
use sinew_stiffness::{FrictionRegime, joint_block, joint_stiffness};

use crate::error::IndicatorError;
use crate::probe_friction::ProbeFriction;
use crate::range::JointStiffnessRange;

/// A single joint of an arm, probed alone (Pinocchio-style model/data: this is the data, built
/// once for a robot and routing, reused for every evaluation).
#[derive(Debug, Clone)]
pub struct JointProbe {
    joint: usize,
    /// Index of the first of the joint's three cables (cables are ordered by joint).
    first_cable: usize,
    /// Every cable crossing the joint (its length depends on `Q[2i]` or `Q[2i+1]`).
    crossing: Vec<usize>,
    limits: TensionLimits,
    q: Vec<f64>,
    tensions: Vec<f64>,
    robot_data: RobotData,
    cables: RoutingData,
    controllable: Mat<f64>,
    inherent: Mat<f64>,
    /// Friction at the holes ([`JointProbe::with_friction`]); `None`: the paper's model.
    friction: Option<ProbeFriction>,
}

impl JointProbe {
    /// A probe of universal joint `joint` (0-based), the other joints at zero.
    ///
    /// # Errors
    /// [`IndicatorError::NoSuchJoint`]; [`IndicatorError::NotThreeCables`] when the joint does
    /// not have exactly three cables of its own.
    pub fn new(
        robot: &Robot,
        routing: &Routing,
        joint: usize,
    ) -> Result<JointProbe, IndicatorError> {
        let joints = robot.joint_count();
        if joint >= joints {
            return Err(IndicatorError::NoSuchJoint { joint, joints });
        }
        let groups = robot.joint_groups();
        if !robot.is_universal() {
            // Name the joint asked for when it is the one at fault, else the first that is.
            let j = if groups[joint].len() == 2 {
                groups.iter().position(|g| g.len() != 2).unwrap_or(joint)
            } else {
                joint
            };
            return Err(IndicatorError::NotUniversal { joint: j, dofs: groups[j].len() });
        }
        let own = routing.cables_of_joint(joint);
        let first_cable = own.start;
        let common = routing.tension_limits();
        let own_limits = routing.cable_limits().get(own.clone()).unwrap_or(&[]);
        if own.len() != 3 || own_limits.iter().any(|l| *l != common) {
            return Err(IndicatorError::NotThreeCables { joint, cables: own.len() });
        }
        let [f_min, f_max] = routing.tension_limits();
        let n = robot.dof();
        let crossing = (0..routing.cable_count())
            .filter(|&c| routing.cable_joint_span(c).is_some_and(|span| span.contains(&joint)))
            .collect();
        Ok(JointProbe {
            joint,
            first_cable,
            crossing,
            limits: TensionLimits { f_min, f_max },
            q: vec![0.0; n],
            tensions: vec![0.0; routing.cable_count()],
            robot_data: RobotData::new(robot),
            cables: RoutingData::new(routing),
            controllable: Mat::zeros(n, n),
            inherent: Mat::zeros(n, n),
            friction: None,
        })
    }

    /// The same probe with friction at the holes (spec §9): the friction `model` of the
    /// routing (μ per cable) in `regime`. Its statics and joint stiffness are then the regime's
    /// (the joint's three cables hold the torque through their segment tensions; in a slip
    /// regime or after a pull or a release, the interval is that of their actuator tensions,
    /// each within the actuator limits that keep every segment within the cable's limits).
    /// With μ = 0 everywhere a slip regime gives the frictionless numbers bit for bit.
    ///
    /// # Errors
    /// [`IndicatorError::Routing`] for a model of another routing;
    /// [`IndicatorError::Stiffness`] for the stick regime with a cable at μ = 0 (no band to
    /// stick in).
    pub fn with_friction(
        mut self,
        routing: &Routing,
        model: FrictionModel,
        regime: FrictionRegime,
    ) -> Result<JointProbe, IndicatorError> {
        self.friction = Some(ProbeFriction::new(routing, model, regime)?);
        Ok(self)
    }

    /// The friction model and regime of the probe, `None` for the paper's frictionless model.
    pub fn friction(&self) -> Option<(&FrictionModel, FrictionRegime)> {
        self.friction.as_ref().map(|f| (&f.model, f.regime))
    }

    /// The probed joint (0-based).
    pub fn joint(&self) -> usize {
        self.joint
    }

    /// The cables with tension (indices in the routing): the joint's own three. Only they
    /// enter the controllable part `Σ f_c H_c`; every other cable is at zero tension.
    pub fn tensioned_cables(&self) -> Range<usize> {
        self.first_cable..self.first_cable + 3
    }

    /// The cables whose inherent stiffness `J_cᵀ K_l J_c` is counted (indices in the routing,
    /// ascending): every cable crossing the joint. The own three when decoupled; routed, also
    /// the distal joints' cables.
    pub fn inherent_cables(&self) -> &[usize] {
        &self.crossing
    }

    /// Set the angles of the other joints (length dof; the probed joint's entries are
    /// overwritten by each evaluation).
    ///
    /// # Errors
    /// [`IndicatorError::Robot`] for a wrong length.
    pub fn set_configuration(&mut self, q: &[f64]) -> Result<(), IndicatorError> {
        if q.len() != self.q.len() {
            return Err(sinew_robot::RobotError::DimensionMismatch {
                what: "joint configuration Q",
                expected: self.q.len(),
                got: q.len(),
            }
            .into());
        }
        self.q.copy_from_slice(q);
        Ok(())
    }

    /// The joint's stiffness over its feasible interval at angles `q` holding torque `tau`
    /// (eq. 20, 22–23); with friction ([`JointProbe::with_friction`]), the regime's. No
    /// allocation.
    ///
    /// # Errors
    /// Angles outside the joint limits ([`IndicatorError::Robot`]); an infeasible torque
    /// ([`IndicatorError::Statics`]); geometry errors.
    pub fn evaluate(
        &mut self,
        robot: &Robot,
        routing: &Routing,
        q: [f64; 2],
        tau: [f64; 2],
    ) -> Result<JointStiffnessRange, IndicatorError> {
        let i = self.joint;
        self.q[2 * i] = q[0];
        self.q[2 * i + 1] = q[1];
        robot.check_limits(&self.q)?;
        compute_cable_geometry(
            routing,
            robot,
            &mut self.robot_data,
            &mut self.cables,
            &self.q,
            Order::Hessians,
        )?;
        let first = self.first_cable;
        let tau = Vector2::new(tau[0], tau[1]);
        if let Some(friction) = &mut self.friction {
            let joint = (i, first);
            return friction.evaluate(routing, &self.cables, joint, &tau, &mut self.tensions);
        }
        let j = self.cables.jacobian()?;
        let block = Matrix3x2::from_fn(|r, c| j[(first + r, 2 * i + c)]);
        let interval = tension_interval(i, &block, &tau, self.limits)?;
        let mut ends = [Matrix2::zeros(); 2];
        let mut controllable = [Matrix2::zeros(); 2];
        let mut inherent = Matrix2::zeros();
        let (low, high) = interval.ends();
        for (end, f) in [low, high].into_iter().enumerate() {
            self.tensions.fill(0.0);
            self.tensions[first..first + 3].copy_from_slice(f.as_slice());
            joint_stiffness(
                routing,
                &self.cables,
                &self.tensions,
                self.controllable.as_mut(),
                self.inherent.as_mut(),
            )?;
            let kc = joint_block(self.controllable.as_ref(), i)
                .ok_or_else(|| IndicatorError::NoSuchJoint { joint: i, joints: robot.dof() / 2 })?;
            let ki = joint_block(self.inherent.as_ref(), i)
                .ok_or_else(|| IndicatorError::NoSuchJoint { joint: i, joints: robot.dof() / 2 })?;
            controllable[end] = kc;
            inherent = ki;
            ends[end] = kc + ki;
        }
        Ok(JointStiffnessRange {
            interval,
            tensions: [low, high],
            k_at_min: ends[0],
            k_at_max: ends[1],
            controllable,
            inherent,
        })
    }
}
