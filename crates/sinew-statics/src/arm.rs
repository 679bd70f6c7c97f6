//! The arm's statics in one call: `T0`, then the tensions, for a robot and its routing (eq. 6,
//! 22–23): at the paper's tension levels in closed form (three cables per universal joint), by
//! a named policy over the equilibrium set of any cable set, or given and checked.

use std::ops::Range;

use nalgebra::{Matrix3x2, Vector2, Vector3, Vector6};
use sinew_robot::{Robot, RobotData};
use sinew_routing::{Order, Routing, RoutingData, compute_cable_geometry};

use crate::distribution::{CableLayout, distribute_tensions};
use crate::equilibrium::{EQUILIBRIUM_TOLERANCE, EquilibriumSet, norm};
use crate::error::{InfeasibleReason, StaticsError, UnsupportedRouting};
use crate::interval::{TensionInterval, TensionLimits, minimum_norm_tensions};
use crate::joint_end::{JointEndData, equilibrium_torques};
use crate::policy::{Distribution, TensionPolicy, distribute_with_policy};

/// How to choose the tensions among those that balance the load.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TensionChoice<'a> {
    /// The paper's tension levels, one per joint in `[0, 1]` (0: least total tension, 1: most;
    /// spec §4), in closed form. Needs three cables per universal joint with common limits
    /// ([`ArmStatics::closed_form`]).
    Levels(&'a [f64]),
    /// A named policy over the equilibrium set (any cable set).
    Policy(TensionPolicy),
    /// These tensions (m, N, routing order), checked: within their limits and balancing the
    /// load to [`EQUILIBRIUM_TOLERANCE`].
    Given(&'a [f64]),
}

/// What the statics of an arm needs from its routing, checked once.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmStatics {
    closed_form: Result<CableLayout, UnsupportedRouting>,
    limits: TensionLimits,
    cable_limits: Vec<[f64; 2]>,
    cable_names: Vec<String>,
    groups: Vec<Range<usize>>,
}

/// Workspace and results of [`ArmStatics::solve`], sized once.
#[derive(Debug, Clone)]
pub struct ArmStaticsData {
    joint_end: JointEndData,
    /// `T0 = T_g + J_xᵀ F0` (2n, N m).
    pub t0: Vec<f64>,
    /// Every joint's feasible tension interval (n) after a solve at levels (closed form); empty
    /// for a routing the closed form does not take.
    pub intervals: Vec<TensionInterval>,
    /// The tensions (m, N), cables in routing order.
    pub tensions: Vec<f64>,
    /// The policy's answer of the last solve by a policy (`None` after levels or given
    /// tensions).
    pub distribution: Option<Distribution>,
}

impl ArmStaticsData {
    /// The joint-end statics of the last solve: `K_W`'s generators and `J_x`, computed with
    /// `T0` in one pass ([`equilibrium_torques`]).
    pub fn joint_end(&self) -> &JointEndData {
        &self.joint_end
    }
}

impl ArmStatics {
    /// The statics of `routing`: any cable set; the closed form of the tension levels when the
    /// routing fits it (see [`CableLayout::new`]).
    pub fn new(routing: &Routing) -> ArmStatics {
        let [f_min, f_max] = routing.tension_limits();
        ArmStatics {
            closed_form: CableLayout::new(routing),
            limits: TensionLimits { f_min, f_max },
            cable_limits: routing.cable_limits().to_vec(),
            cable_names: routing.cables().iter().map(|c| c.name.clone()).collect(),
            groups: routing.joint_groups().to_vec(),
        }
    }

    /// The cable layout of the closed form (three cables per universal joint, common limits).
    ///
    /// # Errors
    /// [`StaticsError::LevelsUnavailable`] saying why the routing does not fit it.
    pub fn closed_form(&self) -> Result<&CableLayout, StaticsError> {
        self.closed_form.as_ref().map_err(|why| StaticsError::LevelsUnavailable(why.clone()))
    }

    /// Whether the tension levels apply (the closed form takes the routing).
    pub fn has_levels(&self) -> bool {
        self.closed_form.is_ok()
    }

    /// The number of joints.
    pub fn joints(&self) -> usize {
        self.groups.len()
    }

    /// The number of cables.
    pub fn cable_count(&self) -> usize {
        self.cable_limits.len()
    }

    /// The common tension limits (the routing file's).
    pub fn limits(&self) -> TensionLimits {
        self.limits
    }

    /// `[f_min, f_max]` of every cable, N.
    pub fn cable_limits(&self) -> &[[f64; 2]] {
        &self.cable_limits
    }

    /// The joints as DOF ranges.
    pub fn joint_groups(&self) -> &[Range<usize>] {
        &self.groups
    }

    /// A workspace for this arm.
    pub fn data(&self, robot: &Robot) -> ArmStaticsData {
        let n = self.closed_form.as_ref().map_or(0, CableLayout::joints);
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
            t0: vec![0.0; robot.dof()],
            intervals: (0..n).map(|joint| TensionInterval { joint, ..empty }).collect(),
            tensions: vec![0.0; self.cable_count()],
            distribution: None,
        }
    }

    /// `T0`, the intervals and the tensions at `levels`, from kinematics and a cable Jacobian
    /// already computed for the same `Q` (`robot.forward_kinematics`, then
    /// `compute_cable_geometry` with at least [`Order::Jacobian`]). No allocation.
    ///
    /// # Errors
    /// [`StaticsError::Infeasible`] naming the first joint that fails,
    /// [`StaticsError::LevelsUnavailable`], and the errors of the steps above.
    pub fn solve(
        &self,
        robot: &Robot,
        rdata: &mut RobotData,
        routing_data: &RoutingData,
        data: &mut ArmStaticsData,
        f0: &Vector6<f64>,
        levels: &[f64],
    ) -> Result<(), StaticsError> {
        self.solve_with(robot, rdata, routing_data, data, f0, TensionChoice::Levels(levels))
    }

    /// `T0` and the tensions chosen by `choice`, from kinematics and a cable Jacobian already
    /// computed for the same `Q`. Levels: no allocation. A policy: the equilibrium set and a
    /// small convex program (they allocate).
    ///
    /// # Errors
    /// Levels: as [`ArmStatics::solve`]. A policy: [`StaticsError::NoEquilibrium`] naming the
    /// joints and the joint motion along which the cables fall short. Given tensions:
    /// [`StaticsError::NotBalanced`]. And the errors of the steps above.
    pub fn solve_with(
        &self,
        robot: &Robot,
        rdata: &mut RobotData,
        routing_data: &RoutingData,
        data: &mut ArmStaticsData,
        f0: &Vector6<f64>,
        choice: TensionChoice<'_>,
    ) -> Result<(), StaticsError> {
        equilibrium_torques(robot, rdata, &mut data.joint_end, f0, &mut data.t0)?;
        data.distribution = None;
        match choice {
            TensionChoice::Levels(levels) => distribute_tensions(
                self.closed_form()?,
                routing_data.jacobian()?,
                self.limits,
                &data.t0,
                levels,
                &mut data.intervals,
                &mut data.tensions,
            ),
            TensionChoice::Policy(policy) => {
                let set = self.equilibrium_set(routing_data, data)?;
                let answer = distribute_with_policy(
                    &set,
                    policy,
                    &self.groups,
                    &self.cable_names,
                    &mut data.tensions,
                )?;
                data.distribution = Some(answer);
                Ok(())
            }
            TensionChoice::Given(tensions) => {
                self.check_balance(routing_data, &data.t0, tensions)?;
                data.tensions.copy_from_slice(tensions);
                Ok(())
            }
        }
    }

    /// The equilibrium set `f = f_p + N λ` at the last solved `Q` and load (its `T0` in
    /// `data`), with every cable's limits.
    ///
    /// # Errors
    /// As [`EquilibriumSet::new`].
    pub fn equilibrium_set(
        &self,
        routing_data: &RoutingData,
        data: &ArmStaticsData,
    ) -> Result<EquilibriumSet, StaticsError> {
        EquilibriumSet::new(routing_data.jacobian()?, &data.t0, &self.cable_limits, &self.groups)
    }

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
            let block = Matrix3x2::from_fn(|r, k| jacobian[(3 * i + r, 2 * i + k)]);
            let interval = crate::interval::tension_interval(i, &block, &tau, self.limits)?;
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

    /// Check that `tensions` are within their limits and balance `t0`.
    fn check_balance(
        &self,
        routing_data: &RoutingData,
        t0: &[f64],
        tensions: &[f64],
    ) -> Result<(), StaticsError> {
        let m = self.cable_count();
        if tensions.len() != m {
            return Err(StaticsError::DimensionMismatch {
                what: "tensions",
                expected: m,
                got: tensions.len(),
            });
        }
        for (c, (&f, [lo, hi])) in tensions.iter().zip(&self.cable_limits).enumerate() {
            if !(f.is_finite() && *lo <= f && f <= *hi) {
                let problem = format!(
                    "leave the limits: cable `{}` has {} N, outside [{}, {}] N",
                    self.cable_names[c],
                    sinew_robot::Compact(f),
                    sinew_robot::Compact(*lo),
                    sinew_robot::Compact(*hi)
                );
                return Err(StaticsError::NotBalanced { problem });
            }
        }
        let jacobian = routing_data.jacobian()?;
        let residual: Vec<f64> = (0..t0.len())
            .map(|d| t0[d] + (0..m).map(|c| jacobian[(c, d)] * tensions[c]).sum::<f64>())
            .collect();
        let scale = norm(t0).max(
            (0..t0.len())
                .map(|d| (0..m).map(|c| (jacobian[(c, d)] * tensions[c]).abs()).sum::<f64>())
                .fold(0.0, f64::max),
        );
        if norm(&residual) > EQUILIBRIUM_TOLERANCE * scale {
            let problem = format!(
                "do not balance the load: |T0 + J_cᵀ f| = {} N m, |T0| = {} N m",
                sinew_robot::Compact(norm(&residual)),
                sinew_robot::Compact(norm(t0))
            );
            return Err(StaticsError::NotBalanced { problem });
        }
        Ok(())
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
