//! The arm's statics in one call: `T0`, every joint's tension interval, the tensions at given
//! levels (eq. 6, 22–23), for a robot and its routing.

use nalgebra::{Vector3, Vector6};
use sinew_robot::{Robot, RobotData};
use sinew_routing::{Order, Routing, RoutingData, compute_cable_geometry};

use crate::distribution::{CableLayout, distribute_tensions};
use crate::error::StaticsError;
use crate::interval::{TensionInterval, TensionLimits};
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
