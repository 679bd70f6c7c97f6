//! The per-configuration computation: lengths, `J_c` and the segment Hessians (module docs
//! of [`super`]), segment by segment (`segment.rs`) or batch by batch (`batch.rs`).

use super::batch::batched;
use super::segment::{Outputs, mismatch, one_segment};
use super::{Order, RoutingData};
use crate::error::{Result, RoutingError};
use crate::routing::Routing;
use sinew_robot::{Robot, RobotData};

/// Forward kinematics at `q`, then [`compute_cable_geometry_from_kinematics`]: the cable
/// lengths, and up to `order` the cable Jacobian and the cables' Hessians, into `data`.
///
/// # Math
/// See [`compute_cable_geometry_from_kinematics`]: eq. 2–3; shapes `L` m, `J_c` m × dof,
/// `H_c` dof × dof.
///
/// # Errors
/// [`RoutingError::RobotMismatch`], [`RoutingError::WorkspaceMismatch`],
/// [`RoutingError::Robot`] for a wrong or non-finite `q`, [`RoutingError::DegenerateSegment`].
pub fn compute_cable_geometry(
    routing: &Routing,
    robot: &Robot,
    robot_data: &mut RobotData,
    data: &mut RoutingData,
    q: &[f64],
    order: Order,
) -> Result<()> {
    routing.check_robot(robot)?;
    data.computed = None;
    robot.forward_kinematics(robot_data, q)?;
    compute_cable_geometry_from_kinematics(routing, robot, robot_data, data, order)
}

/// The cable lengths, and up to `order` the cable Jacobian and the cables' Hessians, from
/// forward kinematics already computed in `robot_data` (by `robot.forward_kinematics`; this
/// function cannot tell which `Q` that was).
///
/// Allocates nothing. On error `data` holds nothing valid ([`RoutingData::computed`] is `None`).
///
/// # Math
/// Frames: `o_` is the base frame. Joint `j` has the unit axis `a_j` through the point `p_j`.
/// A segment joins a hole `o_p_A` on body `A` to a hole `o_p_B` on body `B > A`:
/// `d = o_p_B − o_p_A`, `L = |d|`, `u = d / L` (both holes on one body: `L` is constant,
/// computed in the body frame). Joints before `A` move both holes rigidly and
/// joints from `B` on move neither, so `L` depends only on `q_A … q_{B−1}`. For `i, k` in that
/// range, with `v_i = a_i × (o_p_B − p_i) = ∂d/∂q_i` and `∂²d/∂q_i∂q_k = a_min × v_max`:
///
/// ```text
/// ∂L/∂q_i       = u · v_i                                                   (eq. 3)
/// ∂²L/∂q_i∂q_k  = ( v_i · v_k − (u · v_i)(u · v_k) + d · (a_min × v_max) ) / L
/// ```
///
/// A cable's length is the sum of its segments' (eq. 2 for one joint); its row of `J_c`
/// (m × dof) and its Hessian (dof × dof) are the sums of theirs, with exact zeros outside each
/// segment's joints. Cost `O(dof + Σ_s |dofs_s|²)`.
///
/// # Errors
/// [`RoutingError::RobotMismatch`], [`RoutingError::WorkspaceMismatch`],
/// [`RoutingError::DegenerateSegment`] when a segment is shorter than
/// [`crate::MIN_SEGMENT_LENGTH`] (never a NaN).
pub fn compute_cable_geometry_from_kinematics(
    routing: &Routing,
    robot: &Robot,
    robot_data: &RobotData,
    data: &mut RoutingData,
    order: Order,
) -> Result<()> {
    routing.check_robot(robot)?;
    data.check(routing)?;
    data.computed = None;
    let dof = routing.dof;
    if robot_data.joint_axis(dof.saturating_sub(1)).is_none()
        || robot_data.joint_axis(dof).is_some()
        || robot_data.body_pose(dof).is_none()
    {
        let got = (0..).take_while(|&j| robot_data.joint_axis(j).is_some()).count();
        return Err(RoutingError::WorkspaceMismatch {
            what: "robot workspace (joints)",
            expected: dof,
            got,
        });
    }
    // The kinematics as plain arrays (base frame), once per evaluation.
    for b in 0..=dof {
        let (Some(pose), Some(frame)) = (robot_data.body_pose(b), data.frames.get_mut(b)) else {
            return Err(mismatch(dof));
        };
        // Column-major rotation, then the translation.
        frame[..9].copy_from_slice(pose.rotation.matrix().as_slice());
        frame[9..].copy_from_slice(pose.translation.vector.as_slice());
    }
    for j in 0..dof {
        let (Some(a), Some(p)) = (robot_data.joint_axis(j), robot_data.joint_origin(j)) else {
            return Err(mismatch(dof));
        };
        data.axes[j] = [a[0], a[1], a[2]];
        data.origins[j] = [p[0], p[1], p[2]];
    }

    data.lengths.fill(0.0);
    // With a plan whose every entry of J_c has at most one segment, each entry is written
    // once (`0 + g`, as `+=` on zero would give) and the others are never written: no fill.
    let single_writer = routing.plan.as_ref().is_some_and(|p| p.single_writer);
    if order >= Order::Jacobian && !single_writer {
        data.jacobian.fill(0.0);
    }
    let m = data.cables;
    let keep_directions = data.keep_directions && order >= Order::Jacobian;
    data.directions_kept = false;
    let RoutingData {
        frames,
        axes,
        origins,
        lengths,
        segment_lengths,
        directions,
        jacobian,
        hessians,
        v,
        g,
        batch,
        ..
    } = data;
    let directions = keep_directions.then_some(&mut directions[..]);
    let mut out = Outputs { lengths, segment_lengths, directions, jacobian, hessians, m, order };
    match &routing.plan {
        Some(plan) => batched(routing, plan, (frames, axes, origins), (v, g), batch, &mut out)?,
        None => {
            for (s, seg) in routing.segments.iter().enumerate() {
                one_segment(routing, s, seg, (frames, axes, origins), (v, g), &mut out)?;
            }
        }
    }
    data.computed = Some(order);
    data.directions_kept = keep_directions;
    Ok(())
}
