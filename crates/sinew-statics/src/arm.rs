//! The arm's statics in one call: `T0`, every joint's tension interval, the tensions at given
//! levels (eq. 6, 22–23), for a robot and its routing.

use nalgebra::{Matrix3x2, Vector2, Vector3, Vector6};
use sinew_robot::{Robot, RobotData};
use sinew_routing::{Order, Routing, RoutingData, compute_cable_geometry};

use crate::distribution::{CableLayout, distribute_tensions};
use crate::error::{InfeasibleReason, StaticsError};
use crate::interval::{TensionInterval, TensionLimits, minimum_norm_tensions};
use crate::joint_end::{JointEndData, equilibrium_torques};

/// What the statics of an arm needs from its routing, checked once.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmStatics {
    layout: CableLayout,
    limits: TensionLimits,
}

/// Workspace and results of [`ArmStatics::solve`], sized once.
#[derive(Debug, Clone)]
pub struct ArmStaticsData {
    joint_end: JointEndData,
    /// `T0 = T_g + J_xᵀ F0` (2n, N m).
    pub t0: Vec<f64>,
    /// Every joint's feasible tension interval (n).
    pub intervals: Vec<TensionInterval>,
    /// The tensions at the requested levels (3n, N), cables in routing order.
    pub tensions: Vec<f64>,
}

impl ArmStaticsData {
    /// The joint-end statics of the last solve: `K_W`'s generators and `J_x`, computed with
    /// `T0` in one pass ([`equilibrium_torques`]).
    pub fn joint_end(&self) -> &JointEndData {
        &self.joint_end
    }
}

impl ArmStatics {
    /// Check the routing against the solver (see [`CableLayout::new`]).
    ///
    /// # Errors
    /// [`StaticsError::UnsupportedRouting`].
    pub fn new(routing: &Routing) -> Result<ArmStatics, StaticsError> {
        let [f_min, f_max] = routing.tension_limits();
        Ok(ArmStatics {
            layout: CableLayout::new(routing)?,
            limits: TensionLimits { f_min, f_max },
        })
    }

    /// The cable layout.
    pub fn layout(&self) -> &CableLayout {
        &self.layout
    }

    /// The tension limits of every cable.
    pub fn limits(&self) -> TensionLimits {
        self.limits
    }

    /// A workspace for this arm.
    pub fn data(&self, robot: &Robot) -> ArmStaticsData {
        let n = self.layout.joints();
        let empty = TensionInterval {
            joint: 0,
            particular: Vector3::zeros(),
            null: Vector3::zeros(),
            lambda_min: 0.0,
            lambda_max: 0.0,
            limits: self.limits,
            limiting: [0, 0],
        };
        ArmStaticsData {
            joint_end: JointEndData::new(robot),
            t0: vec![0.0; 2 * n],
            intervals: (0..n).map(|joint| TensionInterval { joint, ..empty }).collect(),
            tensions: vec![0.0; 3 * n],
        }
    }

    /// `T0`, the intervals and the tensions at `levels`, from kinematics and a cable Jacobian
    /// already computed for the same `Q` (`robot.forward_kinematics`, then
    /// `compute_cable_geometry` with at least [`Order::Jacobian`]). No allocation.
    ///
    /// # Errors
    /// [`StaticsError::Infeasible`] naming the first joint that fails, and the errors of the
    /// steps above.
    pub fn solve(
        &self,
        robot: &Robot,
        rdata: &mut RobotData,
        routing_data: &RoutingData,
        data: &mut ArmStaticsData,
        f0: &Vector6<f64>,
        levels: &[f64],
    ) -> Result<(), StaticsError> {
        equilibrium_torques(robot, rdata, &mut data.joint_end, f0, &mut data.t0)?;
        distribute_tensions(
            &self.layout,
            routing_data.jacobian()?,
            self.limits,
            &data.t0,
            levels,
            &mut data.intervals,
            &mut data.tensions,
        )
    }

    /// `∂f/∂λ_i`: how every tension changes per unit of joint `i`'s null-space coordinate,
    /// the other joints' `λ` held, balance kept (3n, into `out`). Decoupled: joint `i`'s null
    /// direction on its own cables, zero elsewhere. Routed: the distal change loads the
    /// proximal joints, whose minimum-norm tensions follow, from joint `i − 1` down to the
    /// base. The map `λ → f` is affine, so this is exact. Needs a [`ArmStatics::solve`] at
    /// the same `Q` first. No allocation.
    ///
    /// # Errors
    /// [`StaticsError::NoSuchJoint`], [`StaticsError::DimensionMismatch`];
    /// [`StaticsError::Infeasible`] for a rank-deficient proximal joint.
    pub fn tension_sensitivity(
        &self,
        routing_data: &RoutingData,
        data: &ArmStaticsData,
        joint: usize,
        out: &mut [f64],
    ) -> Result<(), StaticsError> {
        let n = self.layout.joints();
        if joint >= n {
            return Err(StaticsError::NoSuchJoint { joint, joints: n });
        }
        if out.len() != 3 * n {
            return Err(StaticsError::DimensionMismatch {
                what: "tension sensitivity",
                expected: 3 * n,
                got: out.len(),
            });
        }
        out.fill(0.0);
        out[3 * joint..3 * joint + 3].copy_from_slice(data.intervals[joint].null.as_slice());
        if !self.layout.crossing() {
            return Ok(());
        }
        let jacobian = routing_data.jacobian()?;
        for k in (0..joint).rev() {
            let mut delta_tau = Vector2::zeros();
            for c in 3 * (k + 1)..3 * n {
                delta_tau[0] += jacobian[(c, 2 * k)] * out[c];
                delta_tau[1] += jacobian[(c, 2 * k + 1)] * out[c];
            }
            let block = Matrix3x2::from_fn(|r, col| jacobian[(3 * k + r, 2 * k + col)]);
            let delta = minimum_norm_tensions(&block, &delta_tau).ok_or_else(|| {
                StaticsError::Infeasible {
                    joint: k,
                    torque: [data.t0[2 * k], data.t0[2 * k + 1]],
                    limits: [self.limits.f_min, self.limits.f_max],
                    reason: InfeasibleReason::RankDeficient,
                }
            })?;
            out[3 * k..3 * k + 3].copy_from_slice(delta.as_slice());
        }
        Ok(())
    }

    /// [`ArmStatics::solve`] at `Q`: forward kinematics and the cable Jacobian first.
    ///
    /// # Errors
    /// As [`ArmStatics::solve`], plus robot and routing errors for `Q`.
    pub fn solve_at(
        &self,
        robot: &Robot,
        routing: &Routing,
        rdata: &mut RobotData,
        routing_data: &mut RoutingData,
        data: &mut ArmStaticsData,
        q: &[f64],
        f0: &Vector6<f64>,
        levels: &[f64],
    ) -> Result<(), StaticsError> {
        compute_cable_geometry(routing, robot, rdata, routing_data, q, Order::Jacobian)?;
        self.solve(robot, rdata, routing_data, data, f0, levels)
    }
}
