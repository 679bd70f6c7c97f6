//! The arm's statics for a robot and its routing (eq. 6, 22–23), in two stages: the pose
//! stage ([`ArmStatics::set_pose`]: `T0`, `K_W`'s generators and `J_x` for a pose and a load),
//! then any number of tension stages ([`ArmStatics::set_tensions`]): at the paper's tension
//! levels in closed form (three cables per universal joint), by a named policy over the
//! equilibrium set of any cable set (the set computed once per pose and kept), or given and
//! checked.

use std::ops::Range;

use nalgebra::{Vector3, Vector6};
use sinew_robot::{Robot, RobotData};
use sinew_routing::{Routing, RoutingData};

use crate::choice::{Chosen, TensionChoice};
use crate::distribution::{CableLayout, distribute_tensions};
use crate::equilibrium::{EQUILIBRIUM_TOLERANCE, EquilibriumSet, norm};
use crate::error::{StaticsError, UnsupportedRouting};
use crate::interval::{TensionInterval, TensionLimits};
use crate::joint_end::{JointEndData, equilibrium_torques};
use crate::policy::{Distribution, TensionPolicy, distribute_with_policy};
use crate::refusal::{LevelsInfeasible, NotBalanced};

/// What the statics of an arm needs from its routing, checked once.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmStatics {
    closed_form: Result<CableLayout, UnsupportedRouting>,
    limits: TensionLimits,
    cable_limits: Vec<[f64; 2]>,
    cable_names: Vec<String>,
    groups: Vec<Range<usize>>,
    /// Level 0 for every joint: [`TensionChoice::Default`] with the closed form.
    lowest_levels: Vec<f64>,
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
    /// The equilibrium set at the pose, once a policy or [`ArmStatics::equilibrium_set`] asked
    /// for it (`set_current`; every pose stage clears it, and the next set is rebuilt in this
    /// one's buffers).
    set: Option<EquilibriumSet>,
    set_current: bool,
    /// How the tensions of the last tension stage were chosen.
    chosen: Chosen,
    /// Whether a pose stage has run (`T0`, the generators and `J_x` are those of a pose).
    posed: bool,
}

impl ArmStaticsData {
    /// The joint-end statics of the last solve: `K_W`'s generators and `J_x`, computed with
    /// `T0` in one pass ([`equilibrium_torques`]).
    pub fn joint_end(&self) -> &JointEndData {
        &self.joint_end
    }

    /// How the tensions of the last tension stage were chosen ([`Chosen::Nothing`] before one).
    pub fn chosen(&self) -> Chosen {
        self.chosen
    }

    /// The equilibrium set of the current pose if it was already computed (by a policy or by
    /// [`ArmStatics::equilibrium_set`]).
    pub fn cached_equilibrium_set(&self) -> Option<&EquilibriumSet> {
        self.current_set()
    }

    /// The set if it is the current pose's.
    fn current_set(&self) -> Option<&EquilibriumSet> {
        self.set.as_ref().filter(|_| self.set_current)
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
            lowest_levels: vec![0.0; routing.joint_count()],
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

    /// Every cable's name, routing order (what the refusals name).
    pub fn cable_names(&self) -> &[String] {
        &self.cable_names
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
            set: None,
            set_current: false,
            chosen: Chosen::Nothing,
            posed: false,
        }
    }

    /// `T0`, the intervals and the tensions at `levels`, from kinematics and a cable Jacobian
    /// already computed for the same `Q` (`robot.forward_kinematics`, then
    /// `compute_cable_geometry` with at least [`sinew_routing::Order::Jacobian`]): the pose
    /// stage, then one tension stage. No allocation.
    ///
    /// # Errors
    /// As [`ArmStatics::set_pose`] and [`ArmStatics::set_tensions`].
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

    /// [`ArmStatics::set_pose`], then [`ArmStatics::set_tensions`] with `choice`.
    ///
    /// # Errors
    /// As those two.
    pub fn solve_with(
        &self,
        robot: &Robot,
        rdata: &mut RobotData,
        routing_data: &RoutingData,
        data: &mut ArmStaticsData,
        f0: &Vector6<f64>,
        choice: TensionChoice<'_>,
    ) -> Result<(), StaticsError> {
        self.set_pose(robot, rdata, data, f0)?;
        self.set_tensions(routing_data, data, choice)
    }

    /// The pose stage: `T0 = T_g + J_xᵀ F0`, `K_W`'s generators and `J_x` in one pass
    /// ([`equilibrium_torques`]) from kinematics already computed for the pose. Forgets the
    /// previous pose's equilibrium set and tensions' provenance. No allocation.
    ///
    /// # Errors
    /// Those of [`equilibrium_torques`] (a non-finite wrench, a workspace of another robot).
    pub fn set_pose(
        &self,
        robot: &Robot,
        rdata: &mut RobotData,
        data: &mut ArmStaticsData,
        f0: &Vector6<f64>,
    ) -> Result<(), StaticsError> {
        data.posed = false;
        data.set_current = false;
        data.distribution = None;
        data.chosen = Chosen::Nothing;
        equilibrium_torques(robot, rdata, &mut data.joint_end, f0, &mut data.t0)?;
        data.posed = true;
        Ok(())
    }

    /// A tension stage at the pose of the last [`ArmStatics::set_pose`] (whose cable Jacobian
    /// is `routing_data`'s): the tensions chosen by `choice`. Levels: closed form, no
    /// allocation. A policy: a small convex program over the equilibrium set, which is
    /// computed at the first policy of a pose and kept (they allocate). Given: checked.
    ///
    /// # Errors
    /// [`StaticsError::NoPose`] before a pose stage. Levels: [`StaticsError::Infeasible`]
    /// naming the first joint that fails, or [`StaticsError::LevelsInfeasible`] when the
    /// distal joints' levels overloaded it and tensions within the limits do balance the load
    /// (a policy holds it); [`StaticsError::LevelsUnavailable`]; [`StaticsError::InvalidLevel`].
    /// A policy: [`StaticsError::NoEquilibrium`] naming the joints and the joint motion along
    /// which the cables fall short. Given tensions: [`StaticsError::NotBalanced`].
    pub fn set_tensions(
        &self,
        routing_data: &RoutingData,
        data: &mut ArmStaticsData,
        choice: TensionChoice<'_>,
    ) -> Result<(), StaticsError> {
        if !data.posed {
            return Err(StaticsError::NoPose);
        }
        data.distribution = None;
        data.chosen = Chosen::Nothing;
        let choice = match choice {
            TensionChoice::Default if self.has_levels() => {
                TensionChoice::Levels(&self.lowest_levels)
            }
            TensionChoice::Default => TensionChoice::Policy(TensionPolicy::LeastTotal),
            choice => choice,
        };
        match choice {
            TensionChoice::Levels(levels) => {
                let solved = distribute_tensions(
                    self.closed_form()?,
                    routing_data.jacobian()?,
                    self.limits,
                    &data.t0,
                    levels,
                    &mut data.intervals,
                    &mut data.tensions,
                );
                if let Err(e) = solved {
                    return Err(self.levels_refusal(routing_data, data, e));
                }
                data.chosen = Chosen::Levels;
                Ok(())
            }
            TensionChoice::Policy(policy) => {
                self.cache_equilibrium_set(routing_data, data)?;
                // Current: the line above computed it for this pose.
                let Some(set) = data.set.as_ref() else {
                    return Err(StaticsError::NoPose);
                };
                let answer = distribute_with_policy(
                    set,
                    policy,
                    &self.groups,
                    &self.cable_names,
                    &mut data.tensions,
                )?;
                data.distribution = Some(answer);
                data.chosen = Chosen::Policy(policy);
                Ok(())
            }
            TensionChoice::Given(tensions) => {
                self.check_balance(routing_data, &data.t0, tensions)?;
                data.tensions.copy_from_slice(tensions);
                data.chosen = Chosen::Given;
                Ok(())
            }
            TensionChoice::Default => Err(StaticsError::NoPose),
        }
    }

    /// An infeasibility at levels, said as the levels' when they caused it: in the routed
    /// model the distal joints' tensions are fixed first, and when they overload a proximal
    /// joint while some tensions within the limits balance the load (a policy holds it), the
    /// error names the distal joints and suggests a policy. Other errors pass unchanged.
    fn levels_refusal(
        &self,
        routing_data: &RoutingData,
        data: &mut ArmStaticsData,
        error: StaticsError,
    ) -> StaticsError {
        let StaticsError::Infeasible { joint, torque, limits, reason } = error else {
            return error;
        };
        let infeasible = StaticsError::Infeasible { joint, torque, limits, reason };
        let Ok(layout) = self.closed_form() else { return infeasible };
        let Ok(jacobian) = routing_data.jacobian() else { return infeasible };
        let n = layout.joints();
        if !layout.crossing() || joint + 1 >= n {
            return infeasible;
        }
        // What each distal joint's cables add at the joint (the tensions its level fixed).
        let distal: Vec<(usize, [f64; 2])> = (joint + 1..n)
            .map(|j| {
                let mut tau = [0.0; 2];
                for c in 3 * j..3 * j + 3 {
                    tau[0] += jacobian[(c, 2 * joint)] * data.tensions[c];
                    tau[1] += jacobian[(c, 2 * joint + 1)] * data.tensions[c];
                }
                (j, tau)
            })
            .filter(|(_, tau)| tau[0] != 0.0 || tau[1] != 0.0)
            .collect();
        if distal.is_empty() || self.cache_equilibrium_set(routing_data, data).is_err() {
            return infeasible;
        }
        let Some(set) = data.current_set() else { return infeasible };
        let mut scratch = vec![0.0; self.cable_count()];
        let policy = TensionPolicy::Safest;
        if distribute_with_policy(set, policy, &self.groups, &self.cable_names, &mut scratch)
            .is_err()
        {
            return infeasible;
        }
        StaticsError::LevelsInfeasible(Box::new(LevelsInfeasible {
            joint,
            torque,
            limits,
            reason,
            distal,
            policy,
        }))
    }

    /// Compute the equilibrium set of the pose into `data` unless it is there.
    fn cache_equilibrium_set(
        &self,
        routing_data: &RoutingData,
        data: &mut ArmStaticsData,
    ) -> Result<(), StaticsError> {
        if !data.posed {
            return Err(StaticsError::NoPose);
        }
        if !data.set_current {
            let (jacobian, t0) = (routing_data.jacobian()?, &data.t0);
            let (limits, groups) = (&self.cable_limits, &self.groups);
            match data.set.as_mut() {
                Some(set) => set.rebuild(jacobian, t0, limits, groups)?,
                None => data.set = Some(EquilibriumSet::new(jacobian, t0, limits, groups)?),
            }
            data.set_current = true;
        }
        Ok(())
    }

    /// The equilibrium set `f = f_p + N λ` at the last pose (its `T0` in `data`), with every
    /// cable's limits: computed at its first use after the pose stage (in the last pose's
    /// buffers: [`EquilibriumSet::rebuild`]), then kept in `data` for every later tension stage
    /// of the pose.
    ///
    /// # Errors
    /// [`StaticsError::NoPose`]; as [`EquilibriumSet::new`].
    pub fn equilibrium_set<'d>(
        &self,
        routing_data: &RoutingData,
        data: &'d mut ArmStaticsData,
    ) -> Result<&'d EquilibriumSet, StaticsError> {
        self.cache_equilibrium_set(routing_data, data)?;
        data.current_set().ok_or(StaticsError::NoPose)
    }

    /// [`check_balance`] on `J_c` and the cable limits.
    fn check_balance(
        &self,
        routing_data: &RoutingData,
        t0: &[f64],
        tensions: &[f64],
    ) -> Result<(), StaticsError> {
        let jacobian = routing_data.jacobian()?;
        check_balance(jacobian, t0, &self.cable_limits, &self.cable_names, tensions)
    }
}

/// Whether the given `tensions` (m, N) are within `limits` (per cable) and balance the
/// equilibrium torques `t0` through `jacobian` (m × dof: `J_c`, or a slip regime's `J̃_c` for
/// actuator tensions): `|T0 + Jᵀ f| ≤` [`EQUILIBRIUM_TOLERANCE`] times the larger of `|T0|` and
/// the largest `Σ_c |J_cd f_c|`. `names` name the cables.
///
/// # Errors
/// [`StaticsError::DimensionMismatch`]; [`StaticsError::NotBalanced`] (outside a limit, naming
/// the cable, or the residual).
pub fn check_balance(
    jacobian: faer::MatRef<'_, f64>,
    t0: &[f64],
    limits: &[[f64; 2]],
    names: &[String],
    tensions: &[f64],
) -> Result<(), StaticsError> {
    let m = limits.len();
    if tensions.len() != m || jacobian.nrows() != m {
        let got = if tensions.len() != m { tensions.len() } else { jacobian.nrows() };
        return Err(StaticsError::DimensionMismatch { what: "tensions", expected: m, got });
    }
    for (c, (&f, [lo, hi])) in tensions.iter().zip(limits).enumerate() {
        if !(f.is_finite() && *lo <= f && f <= *hi) {
            return Err(StaticsError::NotBalanced(NotBalanced::OutsideLimits {
                cable: names.get(c).cloned().unwrap_or_else(|| format!("cable {c}")),
                tension: f,
                limits: [*lo, *hi],
            }));
        }
    }
    // |T0 + Jᵀ f| and the largest Σ_c |J_cd f_c|, one DOF at a time (no allocation: a
    // planner's answer is checked by this at every step).
    let (mut squares, mut largest) = (0.0_f64, 0.0_f64);
    for (d, t) in t0.iter().enumerate() {
        let (mut r, mut size) = (*t, 0.0);
        for (c, f) in tensions.iter().enumerate() {
            r += jacobian[(c, d)] * f;
            size += (jacobian[(c, d)] * f).abs();
        }
        squares += r * r;
        largest = largest.max(size);
    }
    let residual = squares.sqrt();
    if residual > EQUILIBRIUM_TOLERANCE * norm(t0).max(largest) {
        return Err(StaticsError::NotBalanced(NotBalanced::Residual { residual, t0: norm(t0) }));
    }
    Ok(())
}
