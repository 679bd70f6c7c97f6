//! The paper's tension levels read back from tensions, and how the tensions move with a joint's
//! null-space coordinate (spec §4): the closed form's inverse and derivative, for the
//! [`ArmStatics`] of a routing with three cables per universal joint.

use nalgebra::{Vector2, Vector3, Vector6};
use sinew_robot::{Robot, RobotData};
use sinew_routing::{Order, Routing, RoutingData, compute_cable_geometry};

use crate::arm::{ArmStatics, ArmStaticsData};
use crate::error::StaticsError;
use crate::interval::{joint_block, minimum_norm_tensions, tension_interval};
use crate::refusal::InfeasibleReason;

impl ArmStatics {
    /// The paper's tension levels of balancing `tensions` (one per joint, in `[0, 1]`): where
    /// each joint's own cables sit on its feasible interval, given the tensions of the cables
    /// beyond it (routed), as [`ArmStatics::solve`] places them. Needs the closed form and a
    /// solve at the same `Q` and load (its `T0` in `data`).
    ///
    /// # Errors
    /// [`StaticsError::LevelsUnavailable`]; [`StaticsError::Infeasible`] for a joint whose
    /// interval is empty; [`StaticsError::DimensionMismatch`].
    pub fn levels_of(
        &self,
        routing_data: &RoutingData,
        data: &ArmStaticsData,
        tensions: &[f64],
    ) -> Result<Vec<f64>, StaticsError> {
        let layout = self.closed_form()?;
        let n = layout.joints();
        if tensions.len() != 3 * n {
            let got = tensions.len();
            return Err(StaticsError::DimensionMismatch { what: "tensions", expected: 3 * n, got });
        }
        let jacobian = routing_data.jacobian()?;
        let mut levels = vec![0.0; n];
        for i in 0..n {
            let mut tau = Vector2::new(data.t0[2 * i], data.t0[2 * i + 1]);
            if layout.crossing() {
                for c in 3 * (i + 1)..3 * n {
                    tau[0] += jacobian[(c, 2 * i)] * tensions[c];
                    tau[1] += jacobian[(c, 2 * i + 1)] * tensions[c];
                }
            }
            let block = joint_block(jacobian, i);
            let interval = tension_interval(i, &block, &tau, self.limits())?;
            let own = Vector3::new(tensions[3 * i], tensions[3 * i + 1], tensions[3 * i + 2]);
            let lambda = interval.null.dot(&(own - interval.particular));
            let width = interval.width();
            levels[i] = if width > 0.0 {
                ((lambda - interval.lambda_min) / width).clamp(0.0, 1.0)
            } else {
                0.0
            };
        }
        Ok(levels)
    }

    /// `∂f/∂λ_i`: how every tension changes per unit of joint `i`'s null-space coordinate,
    /// the other joints' `λ` held, balance kept (3n, into `out`). Decoupled: joint `i`'s null
    /// direction on its own cables, zero elsewhere. Routed: the distal change loads the
    /// proximal joints, whose minimum-norm tensions follow, from joint `i − 1` down to the
    /// base. The map `λ → f` is affine, so this is exact. Needs a [`ArmStatics::solve`] at
    /// the same `Q` first. No allocation.
    ///
    /// # Errors
    /// [`StaticsError::LevelsUnavailable`], [`StaticsError::NoSuchJoint`],
    /// [`StaticsError::DimensionMismatch`]; [`StaticsError::Infeasible`] for a rank-deficient
    /// proximal joint.
    pub fn tension_sensitivity(
        &self,
        routing_data: &RoutingData,
        data: &ArmStaticsData,
        joint: usize,
        out: &mut [f64],
    ) -> Result<(), StaticsError> {
        let layout = self.closed_form()?;
        let n = layout.joints();
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
        if !layout.crossing() {
            return Ok(());
        }
        let jacobian = routing_data.jacobian()?;
        for k in (0..joint).rev() {
            let mut delta_tau = Vector2::zeros();
            for c in 3 * (k + 1)..3 * n {
                delta_tau[0] += jacobian[(c, 2 * k)] * out[c];
                delta_tau[1] += jacobian[(c, 2 * k + 1)] * out[c];
            }
            let block = joint_block(jacobian, k);
            let delta = minimum_norm_tensions(&block, &delta_tau).ok_or_else(|| {
                StaticsError::Infeasible {
                    joint: k,
                    torque: [data.t0[2 * k], data.t0[2 * k + 1]],
                    limits: [self.limits().f_min, self.limits().f_max],
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
