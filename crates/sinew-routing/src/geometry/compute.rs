//! The per-configuration computation: lengths, `J_c` and the segment Hessians (module docs
//! of [`super`]).

use super::batch::{BatchFrames, BatchOut, SegmentPlan, rigid_length, run_batch};
use super::{Order, RoutingData};
use crate::error::{Result, RoutingError};
use crate::routing::{MIN_SEGMENT_LENGTH, Routing, Segment};
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
/// [`MIN_SEGMENT_LENGTH`] (never a NaN).
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
    let RoutingData {
        frames,
        axes,
        origins,
        lengths,
        segment_lengths,
        jacobian,
        hessians,
        v,
        g,
        batch,
        ..
    } = data;
    let mut out = Outputs { lengths, segment_lengths, jacobian, hessians, m, order };
    match &routing.plan {
        Some(plan) => batched(routing, plan, (frames, axes, origins), (v, g), batch, &mut out)?,
        None => {
            for (s, seg) in routing.segments.iter().enumerate() {
                one_segment(routing, s, seg, (frames, axes, origins), (v, g), &mut out)?;
            }
        }
    }
    data.computed = Some(order);
    Ok(())
}

/// Where the segment loop writes: the workspace's results, the number of cables (the column
/// stride of `J_c`) and the order asked for.
struct Outputs<'a> {
    lengths: &'a mut [f64],
    segment_lengths: &'a mut [f64],
    jacobian: &'a mut [f64],
    hessians: &'a mut [f64],
    m: usize,
    order: Order,
}

/// The kinematics as plain arrays: body frames, joint axes, joint origins (base frame).
type Kinematics<'a> = (&'a [[f64; 12]], &'a [[f64; 3]], &'a [[f64; 3]]);

fn degenerate(routing: &Routing, seg: &Segment, length: f64) -> RoutingError {
    let cable = routing.cables.get(seg.cable).map(|c| c.name.clone()).unwrap_or_default();
    RoutingError::DegenerateSegment { cable, segment: seg.index, length, min: MIN_SEGMENT_LENGTH }
}

/// Segment `s`: its length, and its row of `J_c` and Hessian block as `out.order` asks.
fn one_segment(
    routing: &Routing,
    s: usize,
    seg: &Segment,
    (frames, axes, origins): Kinematics<'_>,
    (v, g): (&mut [[f64; 3]], &mut [f64]),
    out: &mut Outputs<'_>,
) -> Result<()> {
    let dof = routing.dof;
    let (Some(frame_a), Some(frame_b)) =
        (frames.get(seg.proximal.body), frames.get(seg.distal.body))
    else {
        return Err(mismatch(dof));
    };
    if let Some(length) = rigid_length(seg) {
        // Both holes on one body: the length is constant, computed in the body frame.
        if length.is_nan() || length < MIN_SEGMENT_LENGTH {
            return Err(degenerate(routing, seg, length));
        }
        out.segment_lengths[s] = length;
        out.lengths[seg.cable] += length;
        return Ok(());
    }
    let o_p_a = transform(frame_a, &seg.proximal_point);
    let o_p_b = transform(frame_b, &seg.distal_point);
    let d = sub(&o_p_b, &o_p_a);
    let length = dot(&d, &d).sqrt();
    if length.is_nan() || length < MIN_SEGMENT_LENGTH {
        return Err(degenerate(routing, seg, length));
    }
    out.segment_lengths[s] = length;
    out.lengths[seg.cable] += length;
    if out.order == Order::Lengths {
        return Ok(());
    }
    let inv_length = 1.0 / length;
    let u = scale(&d, inv_length);
    let (lo, n, m) = (seg.dofs.start, seg.dofs.len(), out.m);
    let (Some(a), Some(p)) = (axes.get(lo..lo + n), origins.get(lo..lo + n)) else {
        return Err(mismatch(dof));
    };
    let Some(column) = out.jacobian.get_mut(seg.cable + lo * m..) else {
        return Err(mismatch(dof));
    };
    let hessian = if out.order < Order::Hessians {
        None
    } else {
        out.hessians.get_mut(seg.hessian_offset..seg.hessian_offset + n * n)
    };
    let parts = (&o_p_b, &d, &u, inv_length, a, p, m);
    // A segment across one universal joint (the common case) with fixed sizes.
    match n {
        1 => segment_derivatives::<1>(parts, column, hessian),
        2 => segment_derivatives::<2>(parts, column, hessian),
        _ => segment_derivatives_any(parts, (v, g), column, hessian),
    }
    Ok(())
}

/// The segment loop by batches ([`SegmentPlan`]): each batch of one or two joints computed
/// by [`run_batch`] into `scratch`, then written to the workspace's results entry by entry in
/// the plan's order (every cable's segments in routing order, as [`one_segment`] would add
/// them); batches across more joints segment by segment. The whole loop runs inside pulp's
/// dispatch (one detection per evaluation), compiled for AVX2 where the processor has it.
fn batched(
    routing: &Routing,
    plan: &SegmentPlan,
    kinematics: Kinematics<'_>,
    scratch_per_segment: (&mut [[f64; 3]], &mut [f64]),
    scratch: &mut [Vec<f64>; 6],
    out: &mut Outputs<'_>,
) -> Result<()> {
    pulp::Arch::new().dispatch(Batched {
        routing,
        plan,
        kinematics,
        scratch_per_segment,
        scratch,
        out,
    })
}

/// The arguments of [`batched`] as a pulp operation.
struct Batched<'a, 'b> {
    routing: &'a Routing,
    plan: &'a SegmentPlan,
    kinematics: Kinematics<'a>,
    scratch_per_segment: (&'a mut [[f64; 3]], &'a mut [f64]),
    scratch: &'a mut [Vec<f64>; 6],
    out: &'a mut Outputs<'b>,
}

impl pulp::WithSimd for Batched<'_, '_> {
    type Output = Result<()>;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> Result<()> {
        let Batched { routing, plan, kinematics, scratch_per_segment, scratch, out } = self;
        batched_loop(routing, plan, kinematics, scratch_per_segment, scratch, out)
    }
}

#[inline(always)]
fn batched_loop(
    routing: &Routing,
    plan: &SegmentPlan,
    (frames, axes, origins): Kinematics<'_>,
    (v, g): (&mut [[f64; 3]], &mut [f64]),
    scratch: &mut [Vec<f64>; 6],
    out: &mut Outputs<'_>,
) -> Result<()> {
    let dof = routing.dof;
    let m = out.m;
    let hessians = out.order >= Order::Hessians;
    for batch in &plan.batches {
        let joints = batch.distal - batch.proximal;
        let entries = batch.entries.clone();
        let lo = batch.proximal;
        let (Some(proximal), Some(distal), Some(a), Some(p)) = (
            frames.get(batch.proximal),
            frames.get(batch.distal),
            axes.get(lo..lo + joints),
            origins.get(lo..lo + joints),
        ) else {
            return Err(mismatch(dof));
        };
        if joints > 2 {
            for &s in &plan.segment[entries] {
                let seg = &routing.segments[s];
                one_segment(routing, s, seg, (frames, axes, origins), (&mut *v, &mut *g), out)?;
            }
            continue;
        }
        let n = entries.len();
        if joints == 0 {
            // Both holes on one body: constant lengths (the plan's; the workspace's segment
            // lengths were written when it was made), added to their cables' in order.
            let rigid = &plan.rigid_length[entries.clone()];
            match &batch.cables {
                Some(range) => add(&mut out.lengths[range.clone()], rigid),
                None => {
                    for (&c, &length) in plan.cable[entries].iter().zip(rigid) {
                        out.lengths[c] += length;
                    }
                }
            }
            continue;
        }
        let [l, g0, g1, h00, h01, h11] = scratch.each_mut().map(|v| &mut v[..n]);
        run_batch(
            &BatchFrames { proximal, distal, axes: a, origins: p },
            plan.proximal.each_ref().map(|c| &c[entries.clone()]),
            plan.distal.each_ref().map(|c| &c[entries.clone()]),
            BatchOut { length: l, g: [g0, g1], h: [h00, h01, h11] },
            joints,
            hessians,
        );
        let (segments, cables) = (&plan.segment[entries.clone()], &plan.cable[entries.clone()]);
        // One vectorisable pass (NaN fails `>=`), the culprit searched only on failure.
        if !l.iter().fold(true, |ok, &x| ok & (x >= MIN_SEGMENT_LENGTH)) {
            let i = l.iter().position(|&x| x.is_nan() || x < MIN_SEGMENT_LENGTH).unwrap_or(0);
            return Err(degenerate(routing, &routing.segments[segments[i]], l[i]));
        }
        for (&s, &length) in segments.iter().zip(l.iter()) {
            out.segment_lengths[s] = length;
        }
        let derivatives = out.order >= Order::Jacobian;
        match &batch.cables {
            // Consecutive cables: whole slices of the lengths and of J_c's columns.
            Some(range) => {
                add(&mut out.lengths[range.clone()], l);
                if derivatives {
                    let write = if plan.single_writer { set } else { add };
                    write(&mut out.jacobian[lo * m..][range.clone()], g0);
                    if joints == 2 {
                        write(&mut out.jacobian[(lo + 1) * m..][range.clone()], g1);
                    }
                }
            }
            None => {
                for i in 0..n {
                    let c = cables[i];
                    out.lengths[c] += l[i];
                    if derivatives {
                        let zero = if plan.single_writer { 0.0 } else { out.jacobian[c + lo * m] };
                        out.jacobian[c + lo * m] = zero + g0[i];
                        if joints == 2 {
                            let zero = if plan.single_writer {
                                0.0
                            } else {
                                out.jacobian[c + (lo + 1) * m]
                            };
                            out.jacobian[c + (lo + 1) * m] = zero + g1[i];
                        }
                    }
                }
            }
        }
        if hessians {
            // The batch's blocks are consecutive (the plan lays them out in its order).
            let o = plan.hessian[entries.start];
            let blocks = &mut out.hessians[o..o + n * joints * joints];
            if joints == 1 {
                blocks.copy_from_slice(h00);
            } else {
                for (i, block) in blocks.chunks_exact_mut(4).enumerate() {
                    block.copy_from_slice(&[h00[i], h01[i], h01[i], h11[i]]);
                }
            }
        }
    }
    Ok(())
}

/// What a segment's derivatives need: `o_p_B`, `d`, `u`, `1/L`, the axes and origins of its
/// joints, and the number of cables (the column stride of `J_c`).
type SegmentParts<'a> =
    (&'a [f64; 3], &'a [f64; 3], &'a [f64; 3], f64, &'a [[f64; 3]], &'a [[f64; 3]], usize);

/// A segment's row of `J_c` (added into `column`, which starts at its cable's entry of its
/// first joint) and its Hessian block (written when asked for), over `N` joints: the loops
/// of [`segment_derivatives_any`] with fixed bounds, the same operations in the same order.
#[inline(always)]
fn segment_derivatives<const N: usize>(
    (o_p_b, d, u, inv_length, axes, origins, m): SegmentParts<'_>,
    column: &mut [f64],
    hessian: Option<&mut [f64]>,
) {
    let mut v = [[0.0; 3]; N];
    let mut g = [0.0; N];
    for k in 0..N {
        let v_k = cross(&axes[k], &sub(o_p_b, &origins[k]));
        let g_k = dot(u, &v_k);
        v[k] = v_k;
        g[k] = g_k;
        column[k * m] += g_k;
    }
    let Some(block) = hessian else { return };
    let block = &mut block[..N * N];
    for k in 0..N {
        let t = cross(&v[k], d);
        let (v_k, g_k) = (v[k], g[k]);
        for i in 0..=k {
            let h = (dot(&v[i], &v_k) - g[i] * g_k + dot(&axes[i], &t)) * inv_length;
            block[i + k * N] = h;
            block[k + i * N] = h;
        }
    }
}

/// [`segment_derivatives`] for any number of joints, with the workspace's scratch.
fn segment_derivatives_any(
    (o_p_b, d, u, inv_length, axes, origins, m): SegmentParts<'_>,
    (v, g): (&mut [[f64; 3]], &mut [f64]),
    column: &mut [f64],
    hessian: Option<&mut [f64]>,
) {
    let n = axes.len();
    for k in 0..n {
        // v_k = a_k × (o_p_B − p_k) = ∂d/∂q_k,  g_k = u · v_k = ∂L/∂q_k.
        let v_k = cross(&axes[k], &sub(o_p_b, &origins[k]));
        let g_k = dot(u, &v_k);
        v[k] = v_k;
        g[k] = g_k;
        column[k * m] += g_k;
    }
    let Some(block) = hessian else { return };
    for k in 0..n {
        // d · (a_i × v_k) = a_i · (v_k × d) for i ≤ k.
        let t = cross(&v[k], d);
        let (v_k, g_k) = (v[k], g[k]);
        for i in 0..=k {
            let h = (dot(&v[i], &v_k) - g[i] * g_k + dot(&axes[i], &t)) * inv_length;
            block[i + k * n] = h;
            block[k + i * n] = h;
        }
    }
}

/// `target[i] += values[i]`.
#[inline(always)]
fn add(target: &mut [f64], values: &[f64]) {
    for (t, v) in target.iter_mut().zip(values) {
        *t += v;
    }
}

/// `target[i] = 0 + values[i]`: what `+=` on a zeroed target gives, bit for bit (`−0` becomes
/// `+0`).
#[inline(always)]
fn set(target: &mut [f64], values: &[f64]) {
    for (t, v) in target.iter_mut().zip(values) {
        *t = 0.0 + v;
    }
}

fn mismatch(dof: usize) -> RoutingError {
    RoutingError::WorkspaceMismatch { what: "robot workspace (joints)", expected: dof, got: 0 }
}

// Plain 3-vector arithmetic: the inner loops stay fast without relying on inlining of generic
// code (the test profile is opt-level 1).

#[inline(always)]
pub(super) fn transform(frame: &[f64; 12], p: &[f64; 3]) -> [f64; 3] {
    [
        frame[0] * p[0] + frame[3] * p[1] + frame[6] * p[2] + frame[9],
        frame[1] * p[0] + frame[4] * p[1] + frame[7] * p[2] + frame[10],
        frame[2] * p[0] + frame[5] * p[1] + frame[8] * p[2] + frame[11],
    ]
}

#[inline(always)]
pub(super) fn sub(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
pub(super) fn scale(a: &[f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline(always)]
pub(super) fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
pub(super) fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
