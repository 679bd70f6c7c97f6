//! The segments of a [`super::Routing`] batched by the pair of bodies they join
//! ([`SegmentPlan`]): model state, built once with the routing and read by the batched segment
//! loop of `geometry/batch.rs`. In the decoupled model a batch is a joint's own three cables
//! and there is no plan (see [`SegmentPlan::new`]).

use std::ops::Range;

use super::Segment;
use crate::vec3::{dot, sub};

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
