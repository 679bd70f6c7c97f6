//! The segment loop of [`super::compute_cable_geometry_from_kinematics`] batched by the pair of
//! bodies a segment joins ([`crate::routing::SegmentPlan`]): every segment of a batch crosses
//! the same joints and transforms its holes by the same two frames, so the batch is one loop
//! over plain arrays of hole coordinates (structure of arrays) that the compiler vectorises,
//! run with the widest vector instructions the processor has (pulp's runtime dispatch around
//! the whole loop, [`batched`]: AVX2 on x86-64 when present, the baseline SSE2 otherwise). The
//! operations and their order are those of the per-segment code (`segment.rs`), and Rust never
//! fuses a multiply and an add, so the results are the same bit for bit; only the memory
//! layout and the vector width change.
//!
//! The routed model is where this pays: the segments across joint `j` are the segments of
//! every cable of joint `j` and beyond (three per joint in the pattern, so 150 on average in a
//! 200-DOF arm). In the decoupled model a batch is a joint's own three cables and the plain
//! loop is kept (the routing has no plan).

use super::Order;
use super::segment::{Kinematics, Outputs, degenerate, mismatch, one_segment};
use crate::error::Result;
use crate::routing::{MIN_SEGMENT_LENGTH, Routing, SegmentPlan};
use crate::vec3::{cross, dot, scale, sub, transform};

/// The segment loop by batches ([`SegmentPlan`]): each batch of one or two joints computed
/// by [`run_batch`] into `scratch`, then written to the workspace's results entry by entry in
/// the plan's order (every cable's segments in routing order, as [`one_segment`] would add
/// them); batches across more joints segment by segment. The whole loop runs inside pulp's
/// dispatch (one detection per evaluation), compiled for AVX2 where the processor has it.
pub(super) fn batched(
    routing: &Routing,
    plan: &SegmentPlan,
    kinematics: Kinematics<'_>,
    scratch_per_segment: (&mut [[f64; 3]], &mut [f64]),
    scratch: &mut [Vec<f64>; 9],
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
    scratch: &'a mut [Vec<f64>; 9],
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
    scratch: &mut [Vec<f64>; 9],
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
        let [l, g0, g1, h00, h01, h11, ux, uy, uz] = scratch.each_mut().map(|v| &mut v[..n]);
        run_batch(
            &BatchFrames { proximal, distal, axes: a, origins: p },
            plan.proximal.each_ref().map(|c| &c[entries.clone()]),
            plan.distal.each_ref().map(|c| &c[entries.clone()]),
            BatchOut { length: l, g: [g0, g1], h: [h00, h01, h11], u: [ux, uy, uz] },
            joints,
            (hessians, out.directions.is_some()),
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
        if let Some(directions) = out.directions.as_deref_mut() {
            for (i, &s) in segments.iter().enumerate() {
                directions[s] = [ux[i], uy[i], uz[i]];
            }
        }
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

/// A batch's frames and joints: the proximal and distal body poses (`[R column-major, t]`)
/// and the axes and origins of the joints crossed (one or two).
pub(crate) struct BatchFrames<'a> {
    pub(crate) proximal: &'a [f64; 12],
    pub(crate) distal: &'a [f64; 12],
    pub(crate) axes: &'a [[f64; 3]],
    pub(crate) origins: &'a [[f64; 3]],
}

/// A batch's results, one entry per segment: the length, `∂L/∂q` over its joints (`g[0..n]`),
/// the Hessian's upper triangle (`h[0]` = (0,0), `h[1]` = (0,1), `h[2]` = (1,1)) and the unit
/// direction `u` by coordinate.
pub(crate) struct BatchOut<'a> {
    pub(crate) length: &'a mut [f64],
    pub(crate) g: [&'a mut [f64]; 2],
    pub(crate) h: [&'a mut [f64]; 3],
    pub(crate) u: [&'a mut [f64]; 3],
}

/// The batch's lengths and their derivatives, for one or two joints (`joints` ∈ {1, 2}; the
/// caller takes longer segments one by one, and segments within one body from the plan).
/// `hessians`, `directions`: whether the Hessians and the unit directions are wanted.
/// Inlined into the caller's pulp dispatch, so compiled with its vector instructions.
#[inline(always)]
pub(crate) fn run_batch(
    frames: &BatchFrames<'_>,
    proximal: [&[f64]; 3],
    distal: [&[f64]; 3],
    out: BatchOut<'_>,
    joints: usize,
    (hessians, directions): (bool, bool),
) {
    match (joints, hessians, directions) {
        (1, false, false) => kernel::<1, false, false>(frames, proximal, distal, out),
        (1, false, true) => kernel::<1, false, true>(frames, proximal, distal, out),
        (1, true, false) => kernel::<1, true, false>(frames, proximal, distal, out),
        (1, true, true) => kernel::<1, true, true>(frames, proximal, distal, out),
        (2, false, false) => kernel::<2, false, false>(frames, proximal, distal, out),
        (2, false, true) => kernel::<2, false, true>(frames, proximal, distal, out),
        (2, true, false) => kernel::<2, true, false>(frames, proximal, distal, out),
        (2, true, true) => kernel::<2, true, true>(frames, proximal, distal, out),
        _ => {}
    }
}

/// The per-segment computation of `segment.rs` (`transform`, `segment_derivatives::<N>`) over
/// a batch, the same operations in the same order, one loop per batch.
#[inline(always)]
fn kernel<const N: usize, const H: bool, const D: bool>(
    frames: &BatchFrames<'_>,
    proximal: [&[f64]; 3],
    distal: [&[f64]; 3],
    out: BatchOut<'_>,
) {
    let n = out.length.len();
    let (fa, fb) = (frames.proximal, frames.distal);
    let [ax, ay, az] = proximal.map(|c| &c[..n]);
    let [bx, by, bz] = distal.map(|c| &c[..n]);
    let BatchOut { length, g: [g0, g1], h: [h00, h01, h11], u: [ux, uy, uz] } = out;
    let (g0, g1, h00, h01, h11) =
        (&mut g0[..n], &mut g1[..n], &mut h00[..n], &mut h01[..n], &mut h11[..n]);
    let (ux, uy, uz) = (&mut ux[..n], &mut uy[..n], &mut uz[..n]);
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
        if D {
            (ux[i], uy[i], uz[i]) = (u[0], u[1], u[2]);
        }
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
