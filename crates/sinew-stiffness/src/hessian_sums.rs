//! The weighted sums of the segments' Hessians, `Σ_s w_s H_s` (eq. 14's `Σ_c f_c H_c`, and the
//! friction regimes' `Σ_s T_s H_s`): segment by segment, or batch by batch on a batched routing
//! (routed models), each entry summed in routing order.

use sinew_routing::{HessianBatch, Routing, SegmentHessians};

use crate::colmajor::ColMajor;
use crate::error::StiffnessError;

/// The weight of each segment's Hessian in a sum `Σ w H`: its cable's tension (`Σ_c f_c H_c`,
/// eq. 14) or one per segment (the friction regimes' segment tensions `T_s`).
#[derive(Debug, Clone, Copy)]
pub(crate) enum Weights<'a> {
    /// `w = f_c` of the segment's cable (one per cable).
    Cable(&'a [f64]),
    /// `w = T_s`, one per segment of [`Routing::segments`].
    Segment(&'a [f64]),
}

impl Weights<'_> {
    /// The weight of segment `s` of cable `c`.
    #[inline(always)]
    fn get(&self, c: usize, s: usize) -> Option<f64> {
        match self {
            Weights::Cable(w) => w.get(c).copied(),
            Weights::Segment(w) => w.get(s).copied(),
        }
    }

    fn mismatch(&self, routing: &Routing) -> StiffnessError {
        let (what, expected, got) = match self {
            Weights::Cable(w) => ("tensions", routing.cable_count(), w.len()),
            Weights::Segment(w) => ("segment tensions", routing.segments().len(), w.len()),
        };
        StiffnessError::DimensionMismatch { what, expected, got }
    }
}

/// `out += Σ_s w_s H_s` segment by segment, each block column by column: the sums of
/// [`sinew_routing::RoutingData::add_weighted_hessians`] in the same order (with `w_s = f_c`), written through
/// column slices. Batched routings go batch by batch ([`add_weighted_hessians_batched`]: each
/// block overwritten, so `out` must hold zeros there).
pub(crate) fn add_weighted_hessians(
    routing: &Routing,
    hessians: SegmentHessians<'_>,
    weights: Weights<'_>,
    out: &mut ColMajor,
) -> Result<(), StiffnessError> {
    if let Some(batches) = hessians.batches() {
        return add_weighted_hessians_batched(routing, batches, weights, out);
    }
    for (s, (seg, h)) in hessians.iter().enumerate() {
        let (lo, n) = (seg.dofs.start, seg.dofs.len());
        if n == 0 {
            continue;
        }
        let Some(w) = weights.get(seg.cable, s) else {
            return Err(weights.mismatch(routing));
        };
        if h.len() != n * n || lo + n > out.rows() || lo + n > out.cols() {
            return Err(StiffnessError::DimensionMismatch {
                what: "segment Hessian",
                expected: n * n,
                got: s,
            });
        }
        if let [h00, h10, h01, h11] = *h {
            // A segment across one universal joint (every routed segment): fixed bounds.
            let col = &mut out.col_mut(lo)[lo..lo + 2];
            col[0] += w * h00;
            col[1] += w * h10;
            let col = &mut out.col_mut(lo + 1)[lo..lo + 2];
            col[0] += w * h01;
            col[1] += w * h11;
            continue;
        }
        for (k, h) in h.chunks_exact(n).enumerate() {
            let col = &mut out.col_mut(lo + k)[lo..lo + n];
            for (v, h) in col.iter_mut().zip(h) {
                *v += w * h;
            }
        }
    }
    Ok(())
}

/// `Σ_c f_c H_c` batch by batch (routed models), each batch's diagonal block overwritten (the
/// batches cross disjoint DOFs, and no segment reaches outside its batch's block, so the
/// entries outside the blocks are never written and stay zero): a batch's segments cross the
/// same DOFs, so each entry of its block is one running sum from zero over the batch's
/// segments, kept in a register, in routing order (the sums of [`add_weighted_hessians`] on a
/// zeroed matrix, in the same order), reading the blocks and the cables in storage order.
pub(crate) fn add_weighted_hessians_batched<'a>(
    routing: &Routing,
    batches: impl Iterator<Item = HessianBatch<'a>>,
    weights: Weights<'_>,
    out: &mut ColMajor,
) -> Result<(), StiffnessError> {
    let mismatch = || weights.mismatch(routing);
    // One loop per kind of weight, so the inner loops read the weights directly.
    match weights {
        Weights::Cable(w) => batched(batches, |c, _| w.get(c).copied(), mismatch, out),
        Weights::Segment(w) => batched(batches, |_, s| w.get(s).copied(), mismatch, out),
    }
}

/// [`add_weighted_hessians_batched`] with the weight of segment `s` of cable `c` from
/// `weight(c, s)`.
#[inline(always)]
fn batched<'a>(
    batches: impl Iterator<Item = HessianBatch<'a>>,
    weight: impl Fn(usize, usize) -> Option<f64>,
    mismatch: impl Fn() -> StiffnessError,
    out: &mut ColMajor,
) -> Result<(), StiffnessError> {
    for batch in batches {
        let (lo, n) = (batch.dofs.start, batch.dofs.len());
        if batch.blocks.len() != batch.cables.len() * n * n
            || batch.segments.len() != batch.cables.len()
            || lo + n > out.rows()
            || lo + n > out.cols()
        {
            return Err(StiffnessError::DimensionMismatch {
                what: "segment Hessian batch",
                expected: batch.cables.len() * n * n,
                got: batch.blocks.len(),
            });
        }
        let entries = batch.cables.iter().zip(batch.segments);
        if n == 2 {
            let mut acc = [0.0; 4];
            for ((&c, &r), h) in entries.zip(batch.blocks.chunks_exact(4)) {
                let w = weight(c, r).ok_or_else(&mismatch)?;
                for t in 0..4 {
                    acc[t] += w * h[t];
                }
            }
            out.col_mut(lo)[lo..lo + 2].copy_from_slice(&acc[..2]);
            out.col_mut(lo + 1)[lo..lo + 2].copy_from_slice(&acc[2..]);
            continue;
        }
        for k in lo..lo + n {
            out.col_mut(k)[lo..lo + n].fill(0.0);
        }
        for ((&c, &r), h) in entries.zip(batch.blocks.chunks_exact(n * n)) {
            let w = weight(c, r).ok_or_else(&mismatch)?;
            for (k, h) in h.chunks_exact(n).enumerate() {
                let col = &mut out.col_mut(lo + k)[lo..lo + n];
                for (v, h) in col.iter_mut().zip(h) {
                    *v += w * h;
                }
            }
        }
    }
    Ok(())
}
