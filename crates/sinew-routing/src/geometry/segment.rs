//! The segment loop one segment at a time: the reference the batched loop (`batch.rs`) is
//! tested against, the path of the decoupled model and of segments across more than two
//! joints; and what both loops share (where they write, their errors).

use super::Order;
use crate::error::{Result, RoutingError};
use crate::routing::{MIN_SEGMENT_LENGTH, Routing, Segment, rigid_length};
use crate::vec3::{cross, dot, scale, sub, transform};

/// Where the segment loop writes: the workspace's results, the number of cables (the column
/// stride of `J_c`) and the order asked for.
pub(super) struct Outputs<'a> {
    pub(super) lengths: &'a mut [f64],
    pub(super) segment_lengths: &'a mut [f64],
    /// Every segment's unit direction, when kept.
    pub(super) directions: Option<&'a mut [[f64; 3]]>,
    pub(super) jacobian: &'a mut [f64],
    pub(super) hessians: &'a mut [f64],
    pub(super) m: usize,
    pub(super) order: Order,
}

/// The kinematics as plain arrays: body frames, joint axes, joint origins (base frame).
pub(crate) type Kinematics<'a> = (&'a [[f64; 12]], &'a [[f64; 3]], &'a [[f64; 3]]);

pub(super) fn degenerate(routing: &Routing, seg: &Segment, length: f64) -> RoutingError {
    let cable = routing.cables.get(seg.cable).map(|c| c.name.clone()).unwrap_or_default();
    RoutingError::DegenerateSegment { cable, segment: seg.index, length, min: MIN_SEGMENT_LENGTH }
}

/// Segment `s`: its length, and its row of `J_c` and Hessian block as `out.order` asks.
pub(super) fn one_segment(
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
    let (o_p_b, d, length) = segment_vector(frame_a, frame_b, seg);
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
    if let Some(directions) = out.directions.as_deref_mut() {
        directions[s] = u;
    }
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
        let (v_k, g_k) = length_derivative(&axes[k], &origins[k], o_p_b, u);
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
        let (v_k, g_k) = length_derivative(&axes[k], &origins[k], o_p_b, u);
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

/// A segment across joints at the kinematics: its distal hole `o_p_B`, `d = o_p_B − o_p_A`
/// and `L = |d|` (base frame), from its two bodies' frames. The one formula of every loop that
/// needs a segment's vector (this file's, and the friction geometry's, which must give the
/// same `J_c` bit for bit).
#[inline(always)]
fn segment_vector(
    frame_a: &[f64; 12],
    frame_b: &[f64; 12],
    seg: &Segment,
) -> ([f64; 3], [f64; 3], f64) {
    let o_p_a = transform(frame_a, &seg.proximal_point);
    let o_p_b = transform(frame_b, &seg.distal_point);
    let d = sub(&o_p_b, &o_p_a);
    (o_p_b, d, dot(&d, &d).sqrt())
}

/// `v_k = a_k × (o_p_B − p_k) = ∂d/∂q_k` and `g_k = u · v_k = ∂L/∂q_k` (eq. 3) for a joint `k`
/// between a segment's two bodies, with axis `a_k` through `p_k`.
#[inline(always)]
pub(crate) fn length_derivative(
    axis: &[f64; 3],
    origin: &[f64; 3],
    o_p_b: &[f64; 3],
    u: &[f64; 3],
) -> ([f64; 3], f64) {
    let v_k = cross(axis, &sub(o_p_b, origin));
    (v_k, dot(u, &v_k))
}

pub(super) fn mismatch(dof: usize) -> RoutingError {
    RoutingError::WorkspaceMismatch { what: "robot workspace (joints)", expected: dof, got: 0 }
}
