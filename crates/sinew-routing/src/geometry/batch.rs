//! The segment loop of [`super::compute_cable_geometry_from_kinematics`] batched by the pair of
//! bodies a segment joins: every segment of a batch crosses the same joints and transforms its
//! holes by the same two frames, so the batch is one loop over plain arrays of hole
//! coordinates (structure of arrays) that the compiler vectorises, run with the widest vector
//! instructions the processor has (pulp's runtime dispatch around the whole loop, in
//! `compute.rs`: AVX2 on x86-64 when present, the baseline SSE2 otherwise). The operations and their order are those of the per-segment
//! code, and Rust never fuses a multiply and an add, so the results are the same bit for bit;
//! only the memory layout and the vector width change.
//!
//! The routed model is where this pays: the segments across joint `j` are the segments of
//! every cable of joint `j` and beyond (three per joint in the pattern, so 150 on average in a
//! 200-DOF arm). In the decoupled model a batch is a joint's own three cables and the plain
//! loop is kept (see [`SegmentPlan::new`]).

use std::ops::Range;

use super::compute::{cross, dot, scale, sub, transform};
use crate::routing::Segment;

/// The least mean number of segments per batch for which the batched loop is used: below it
/// (the decoupled model: three) the per-segment loop is as fast.
const MIN_MEAN_BATCH: usize = 4;

/// Segments grouped by the bodies they join, in an order that keeps every cable's segments in
/// their routing order (so each cable's length and row of `J_c` are summed in the same order
/// as the per-segment loop). Immutable, part of the [`crate::Routing`].
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SegmentPlan {
    /// The batches in processing order.
    pub(crate) batches: Vec<Batch>,
    /// Segment index of each entry (batch by batch).
    pub(crate) segment: Vec<usize>,
    /// Its cable.
    pub(crate) cable: Vec<usize>,
    /// The offset of its Hessian block in the workspace.
    pub(crate) hessian: Vec<usize>,
    /// Proximal hole on its body, `x`, `y`, `z` of every entry.
    pub(crate) proximal: [Vec<f64>; 3],
    /// Distal hole on its body.
    pub(crate) distal: [Vec<f64>; 3],
    /// The constant length of each entry whose holes are on one body (zero for the others),
    /// computed in the body frame as the segment-by-segment loop does.
    pub(crate) rigid_length: Vec<f64>,
    /// The longest batch (the size of the workspace's scratch).
    pub(crate) longest: usize,
    /// Whether every entry of `J_c` has at most one segment (and no batch crosses more than
    /// two joints): the batched loop then writes each entry once instead of adding into a
    /// zeroed `J_c`, and the entries no segment reaches stay zero from the workspace's
    /// construction.
    pub(crate) single_writer: bool,
    /// Whether no two batches cross the same joint (then every entry of `Σ f_c H_c` is summed
    /// within one batch, in the same order batch by batch as segment by segment).
    pub(crate) disjoint: bool,
}

/// One batch: the entries `entries` join body `proximal` to body `distal` across `dofs`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Batch {
    /// Its entries in the plan's arrays.
    pub(crate) entries: Range<usize>,
    /// The lower-numbered body.
    pub(crate) proximal: usize,
    /// The higher-numbered body.
    pub(crate) distal: usize,
    /// Its entries' cables when they are consecutive (`cable[e] = start + e − entries.start`):
    /// its results are then written to `J_c` and the lengths as slices.
    pub(crate) cables: Option<Range<usize>>,
}

impl SegmentPlan {
    /// The plan of `segments` (cables' segments consecutive, in routing order), or `None` when
    /// batching does not pay (fewer than [`MIN_MEAN_BATCH`] segments per batch on average) or
    /// would change the order in which a cable's segments are summed. With a plan, the
    /// segments' Hessian blocks are laid out in the plan's order (their `hessian_offset`), so
    /// that a batch's blocks are consecutive.
    pub(crate) fn new(segments: &mut [Segment], cables: usize) -> Option<SegmentPlan> {
        let mut keys: Vec<(usize, usize)> =
            segments.iter().map(|s| (s.proximal.body, s.distal.body)).collect();
        keys.sort_unstable();
        keys.dedup();
        if keys.is_empty() || segments.len() < MIN_MEAN_BATCH * keys.len() {
            return None;
        }
        let mut order: Vec<usize> = (0..segments.len()).collect();
        // By batch, then by segment index within a batch.
        order.sort_by_key(|&s| (segments[s].proximal.body, segments[s].distal.body, s));
        // Every cable's segments must come in increasing index (the per-segment loop's order).
        let mut last = vec![None::<usize>; cables];
        for &s in &order {
            let c = segments[s].cable;
            let slot = last.get_mut(c)?;
            if slot.is_some_and(|prev| prev >= s) {
                return None;
            }
            *slot = Some(s);
        }
        let mut batches: Vec<Batch> = Vec::with_capacity(keys.len());
        for (e, &s) in order.iter().enumerate() {
            let key = (segments[s].proximal.body, segments[s].distal.body);
            match batches.last_mut() {
                Some(b) if (b.proximal, b.distal) == key => b.entries.end = e + 1,
                _ => batches.push(Batch {
                    entries: e..e + 1,
                    proximal: key.0,
                    distal: key.1,
                    cables: None,
                }),
            }
        }
        let mut offset = 0;
        for &s in &order {
            let seg = &mut segments[s];
            seg.hessian_offset = offset;
            offset += seg.dofs.len() * seg.dofs.len();
        }
        let mut covered =
            vec![None::<usize>; segments.iter().map(|s| s.dofs.end).max().unwrap_or(0)];
        let mut disjoint = true;
        for (b, batch) in batches.iter_mut().enumerate() {
            let first = segments[order[batch.entries.start]].cable;
            let consecutive = order[batch.entries.clone()]
                .iter()
                .enumerate()
                .all(|(i, &s)| segments[s].cable == first + i);
            batch.cables = consecutive.then(|| first..first + batch.entries.len());
            for slot in &mut covered[batch.proximal..batch.distal] {
                disjoint &= slot.is_none_or(|other| other == b);
                *slot = Some(b);
            }
        }
        let coordinate = |k: usize, distal: bool| -> Vec<f64> {
            order
                .iter()
                .map(|&s| {
                    let seg = &segments[s];
                    if distal { seg.distal_point[k] } else { seg.proximal_point[k] }
                })
                .collect()
        };
        let longest = batches.iter().map(|b| b.entries.len()).max().unwrap_or(0);
        let dof = segments.iter().map(|s| s.dofs.end).max().unwrap_or(0);
        let mut written = vec![false; cables * dof];
        let mut single_writer = batches.iter().all(|b| b.distal - b.proximal <= 2);
        for seg in segments.iter() {
            for k in seg.dofs.clone() {
                let slot = &mut written[seg.cable * dof + k];
                single_writer &= !*slot;
                *slot = true;
            }
        }
        Some(SegmentPlan {
            batches,
            proximal: [coordinate(0, false), coordinate(1, false), coordinate(2, false)],
            distal: [coordinate(0, true), coordinate(1, true), coordinate(2, true)],
            cable: order.iter().map(|&s| segments[s].cable).collect(),
            rigid_length: order
                .iter()
                .map(|&s| rigid_length(&segments[s]).unwrap_or(0.0))
                .collect(),
            hessian: order.iter().map(|&s| segments[s].hessian_offset).collect(),
            segment: order,
            longest,
            single_writer,
            disjoint,
        })
    }
}

/// The constant length of a segment whose holes are on one body, in the body frame (the
/// formula of the segment-by-segment loop); `None` for a segment across joints.
pub(crate) fn rigid_length(seg: &Segment) -> Option<f64> {
    seg.dofs.is_empty().then(|| {
        let d = sub(&seg.distal_point, &seg.proximal_point);
        dot(&d, &d).sqrt()
    })
}

/// A batch's frames and joints: the proximal and distal body poses (`[R column-major, t]`)
/// and the axes and origins of the joints crossed (one or two).
pub(crate) struct BatchFrames<'a> {
    pub(crate) proximal: &'a [f64; 12],
    pub(crate) distal: &'a [f64; 12],
    pub(crate) axes: &'a [[f64; 3]],
    pub(crate) origins: &'a [[f64; 3]],
}

/// A batch's results, one entry per segment: the length, `∂L/∂q` over its joints (`g[0..n]`)
/// and the Hessian's upper triangle (`h[0]` = (0,0), `h[1]` = (0,1), `h[2]` = (1,1)).
pub(crate) struct BatchOut<'a> {
    pub(crate) length: &'a mut [f64],
    pub(crate) g: [&'a mut [f64]; 2],
    pub(crate) h: [&'a mut [f64]; 3],
}

/// The batch's lengths and their derivatives, for one or two joints (`joints` ∈ {1, 2}; the
/// caller takes longer segments one by one, and segments within one body from the plan). `hessians`: whether the Hessians are wanted.
/// Inlined into the caller's pulp dispatch, so compiled with its vector instructions.
#[inline(always)]
pub(crate) fn run_batch(
    frames: &BatchFrames<'_>,
    proximal: [&[f64]; 3],
    distal: [&[f64]; 3],
    out: BatchOut<'_>,
    joints: usize,
    hessians: bool,
) {
    match (joints, hessians) {
        (1, false) => kernel::<1, false>(frames, proximal, distal, out),
        (1, true) => kernel::<1, true>(frames, proximal, distal, out),
        (2, false) => kernel::<2, false>(frames, proximal, distal, out),
        (2, true) => kernel::<2, true>(frames, proximal, distal, out),
        _ => {}
    }
}

/// The per-segment computation of `compute.rs` (`transform`, `segment_derivatives::<N>`) over
/// a batch, the same operations in the same order, one loop per batch.
#[inline(always)]
fn kernel<const N: usize, const H: bool>(
    frames: &BatchFrames<'_>,
    proximal: [&[f64]; 3],
    distal: [&[f64]; 3],
    out: BatchOut<'_>,
) {
    let n = out.length.len();
    let (fa, fb) = (frames.proximal, frames.distal);
    let [ax, ay, az] = proximal.map(|c| &c[..n]);
    let [bx, by, bz] = distal.map(|c| &c[..n]);
    let BatchOut { length, g: [g0, g1], h: [h00, h01, h11] } = out;
    let (g0, g1, h00, h01, h11) =
        (&mut g0[..n], &mut g1[..n], &mut h00[..n], &mut h01[..n], &mut h11[..n]);
    let axis = |k: usize| frames.axes.get(k).copied().unwrap_or([0.0; 3]);
    let origin = |k: usize| frames.origins.get(k).copied().unwrap_or([0.0; 3]);
    let (a0, a1, p0, p1) = (axis(0), axis(1), origin(0), origin(1));
    for i in 0..n {
        let pa = transform(fa, &[ax[i], ay[i], az[i]]);
        let pb = transform(fb, &[bx[i], by[i], bz[i]]);
        let d = sub(&pb, &pa);
        let l = dot(&d, &d).sqrt();
        length[i] = l;
        let inv_length = 1.0 / l;
        let u = scale(&d, inv_length);
        let v0 = cross(&a0, &sub(&pb, &p0));
        let q0 = dot(&u, &v0);
        g0[i] = q0;
        if N == 1 {
            if H {
                let t = cross(&v0, &d);
                h00[i] = (dot(&v0, &v0) - q0 * q0 + dot(&a0, &t)) * inv_length;
            }
            continue;
        }
        let v1 = cross(&a1, &sub(&pb, &p1));
        let q1 = dot(&u, &v1);
        g1[i] = q1;
        if H {
            let t0 = cross(&v0, &d);
            h00[i] = (dot(&v0, &v0) - q0 * q0 + dot(&a0, &t0)) * inv_length;
            let t1 = cross(&v1, &d);
            h01[i] = (dot(&v0, &v1) - q0 * q1 + dot(&a0, &t1)) * inv_length;
            h11[i] = (dot(&v1, &v1) - q1 * q1 + dot(&a1, &t1)) * inv_length;
        }
    }
}
