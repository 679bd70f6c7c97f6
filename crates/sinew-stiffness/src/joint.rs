//! Joint stiffness (paper section III.A; spec §3): controllable and inherent parts.
//!
//! # Math
//! With `τ(Q) = −J_c(Q)ᵀ f(Q)` (eq. 5) and elastic cables `f = f_0 + K_l (L(Q) − L(Q_0))`
//! (eq. 13), the restoring joint stiffness is
//!
//! ```text
//! K = −∂τ/∂Q = Σ_c f_c H_c  +  J_cᵀ K_l J_c          (eq. 11/14, restoring sign)
//!              (controllable)  (inherent)
//! ```
//!
//! `H_c = ∂²L_c/∂Q²`. Both parts are symmetric. In the decoupled model `K` is block diagonal
//! with one 2 × 2 block per universal joint (`K_q = diag(K_1 … K_n)`, eq. 18); in the routed
//! model a cable's terms reach every joint it crosses and `K_q` is full. For joint `i`,
//! `K_{i,x} = K[2i, 2i]` and `K_{i,y} = K[2i+1, 2i+1]` (eq. 20).
//!
//! Each cable's terms are accumulated over its own joint range only (`Cable::dofs`), so the
//! cost is `O(Σ_c |dofs_c|²)`: linear in the number of joints when decoupled.

use std::ops::Range;

use faer::{MatMut, MatRef};
use nalgebra::Matrix2;
use sinew_routing::{Routing, RoutingData, SegmentHessians};

use crate::colmajor::{ColMajor, mirror_upper};
use crate::error::StiffnessError;
use crate::hessian_sums::{Weights, add_weighted_hessians, add_weighted_hessians_batched};
use crate::inherent::{InherentPlan, InherentScratch};
use crate::structured::{BlockLayout, MAX_BLOCK, zero_blocks};

fn check(what: &'static str, m: &MatMut<'_, f64>, n: usize) -> Result<(), StiffnessError> {
    for got in [m.nrows(), m.ncols()] {
        if got != n {
            return Err(StiffnessError::DimensionMismatch { what, expected: n, got });
        }
    }
    Ok(())
}

/// The controllable part `Σ_c f_c H_c` and the inherent part `J_cᵀ K_l J_c` of the joint
/// stiffness at the tensions `f` (N), into two dof × dof matrices (overwritten).
///
/// Needs the cable geometry with Hessians for the same `Q`. No allocation.
///
/// # Errors
/// [`StiffnessError::DimensionMismatch`], routing errors (geometry not computed).
pub fn joint_stiffness(
    routing: &Routing,
    geometry: &RoutingData,
    tensions: &[f64],
    mut controllable: MatMut<'_, f64>,
    mut inherent: MatMut<'_, f64>,
) -> Result<(), StiffnessError> {
    let n = routing.dof();
    check("controllable stiffness", &controllable, n)?;
    check("inherent stiffness", &inherent, n)?;
    if tensions.len() != routing.cable_count() {
        return Err(StiffnessError::DimensionMismatch {
            what: "tensions",
            expected: routing.cable_count(),
            got: tensions.len(),
        });
    }
    controllable.fill(0.0);
    geometry.add_weighted_hessians(routing, tensions, controllable.as_mut())?;
    inherent.fill(0.0);
    add_inherent_upper(routing, geometry, inherent.as_mut())?;
    mirror_blocks(inherent, std::iter::once(0..n));
    Ok(())
}

/// `Σ_c f_c H_c`, `J_cᵀ K_l J_c` and their sum `K_q` into three dof × dof matrices, block by
/// block of `layout` (which every cable of `routing` fits in): only the entries inside the
/// blocks are written, the caller keeps the others at zero. Small blocks
/// ([`BlockLayout::structured`]) are accumulated on the stack, segment by segment and cable by
/// cable in routing order (the sums of [`joint_stiffness`], term for term); large ones (the
/// routed model) through [`joint_stiffness`]'s own loops, the inherent part only when `current`
/// says it is not that of the pose yet. `O(Σ_c |dofs_c|²)`, no allocation.
pub(crate) fn joint_stiffness_in_blocks(
    routing: &Routing,
    geometry: &RoutingData,
    tensions: &[f64],
    layout: &BlockLayout,
    (plan, scratch, current): (&InherentPlan, &mut InherentScratch, &mut bool),
    controllable: &mut ColMajor,
    inherent: &mut ColMajor,
    k_q: &mut ColMajor,
) -> Result<(), StiffnessError> {
    let n = routing.dof();
    check("controllable stiffness", &controllable.as_mut(), n)?;
    check("inherent stiffness", &inherent.as_mut(), n)?;
    check("K_q", &k_q.as_mut(), n)?;
    if tensions.len() != routing.cable_count() {
        return Err(StiffnessError::DimensionMismatch {
            what: "tensions",
            expected: routing.cable_count(),
            got: tensions.len(),
        });
    }
    if !layout.structured() {
        let hessians = geometry.segment_hessians(routing)?;
        match hessians.batches() {
            // Each batch's block written once (the rest of K_c is never written: zero).
            Some(batches) => add_weighted_hessians_batched(
                routing,
                batches,
                Weights::Cable(tensions),
                controllable,
            )?,
            None => {
                zero_blocks(layout, controllable);
                add_weighted_hessians(routing, hessians, Weights::Cable(tensions), controllable)?;
            }
        }
        // Every entry the tiles reach is written once; the others are never written (zero).
        // It depends on the pose only: once per pose (`current`), then mirrored and summed at
        // every tension stage (the mirror copies the same upper triangle again).
        if !*current {
            plan.set_upper(geometry.jacobian()?, scratch, inherent)?;
            *current = true;
        }
        mirror_and_sum(controllable, inherent, k_q, layout.blocks());
        return Ok(());
    }
    let j_c = geometry.jacobian()?;
    let hessians = geometry.segment_hessians(routing)?;
    for (k, block) in layout.blocks().enumerate() {
        let cables = layout.cables_of(k);
        let args = (routing, hessians, j_c, tensions, cables, block.start);
        let parts = &mut (&mut *controllable, &mut *inherent, &mut *k_q);
        match block.len() {
            1 => block_stiffness::<1>(args, parts)?,
            2 => block_stiffness::<2>(args, parts)?,
            3 => block_stiffness::<3>(args, parts)?,
            4 => block_stiffness::<4>(args, parts)?,
            got => {
                return Err(StiffnessError::DimensionMismatch {
                    what: "joint stiffness block",
                    expected: MAX_BLOCK,
                    got,
                });
            }
        }
    }
    Ok(())
}

/// One `B × B` block of [`joint_stiffness_in_blocks`]: its cables' `f_c H_c` (segment by
/// segment) and `k_c J_cᵀ J_c` (each product once, both triangles), then the three matrices.
#[inline(always)]
fn block_stiffness<const B: usize>(
    (routing, hessians, j_c, tensions, cables, lo): (
        &Routing,
        SegmentHessians<'_>,
        MatRef<'_, f64>,
        &[f64],
        &[usize],
        usize,
    ),
    (controllable, inherent, k_q): &mut (&mut ColMajor, &mut ColMajor, &mut ColMajor),
) -> Result<(), StiffnessError> {
    let mut kc = [[0.0; B]; B];
    let mut ki = [[0.0; B]; B];
    let segments = routing.segments();
    for &c in cables {
        let Some(cable) = routing.cables().get(c) else { continue };
        let (f, k) = (tensions[c], cable.stiffness);
        for s in cable.segments.clone() {
            let Some(seg) = segments.get(s) else { continue };
            let (o, span) = (seg.dofs.start.wrapping_sub(lo), seg.dofs.len());
            if span == 0 || o + span > B {
                continue;
            }
            let Some(h) = hessians.get(s) else { continue };
            if span == B {
                // The common case (a segment across the whole block): fixed bounds.
                for kk in 0..B {
                    for i in 0..B {
                        kc[i][kk] += f * h[(i, kk)];
                    }
                }
            } else {
                for kk in 0..span {
                    for i in 0..span {
                        kc[o + i][o + kk] += f * h[(i, kk)];
                    }
                }
            }
        }
        let (o, span) = (cable.dofs.start.wrapping_sub(lo), cable.dofs.len());
        if span == 0 || o + span > B {
            continue;
        }
        // J_c[c, ·] over the block (exact zeros outside the cable's DOFs).
        let mut row = [0.0; B];
        for (r, v) in row.iter_mut().enumerate() {
            if r >= o && r < o + span {
                *v = j_c[(c, lo + r)];
            }
        }
        for j in 0..B {
            let kj = k * row[j];
            for i in 0..j {
                let v = kj * row[i];
                ki[i][j] += v;
                ki[j][i] += v;
            }
            ki[j][j] += kj * row[j];
        }
    }
    for cc in 0..B {
        let col = &mut controllable.col_mut(lo + cc)[lo..lo + B];
        for r in 0..B {
            col[r] = kc[r][cc];
        }
        let col = &mut inherent.col_mut(lo + cc)[lo..lo + B];
        for r in 0..B {
            col[r] = ki[r][cc];
        }
        let col = &mut k_q.col_mut(lo + cc)[lo..lo + B];
        for r in 0..B {
            col[r] = kc[r][cc] + ki[r][cc];
        }
    }
    Ok(())
}

/// `out += J_cᵀ K_l J_c` on and above the diagonal, cable by cable over each cable's joint
/// range, column by column: entry `(i, j)`, `i ≤ j`, gets `(k_c J_c[c, j]) · J_c[c, i]`. The
/// caller mirrors the result ([`mirror_upper`]) into an exactly symmetric matrix.
fn add_inherent_upper(
    routing: &Routing,
    geometry: &RoutingData,
    mut out: MatMut<'_, f64>,
) -> Result<(), StiffnessError> {
    let j_c = geometry.jacobian()?;
    for (c, cable) in routing.cables().iter().enumerate() {
        let k = cable.stiffness;
        for j in cable.dofs.clone() {
            let kj = k * j_c[(c, j)];
            for i in cable.dofs.start..=j {
                out[(i, j)] += kj * j_c[(c, i)];
            }
        }
    }
    Ok(())
}

/// Within each diagonal block `blocks`: the strict upper triangle of `inherent` copied to its
/// lower one ([`mirror_upper`] on the arm's own storage, fused), and `K_q = K_c + K_i`, in one pass
/// column by column (the lower part of column `j` of `K_i` from row `j` of the later columns,
/// then the column of `K_q` while it is in cache). The same values as mirroring, then summing.
fn mirror_and_sum(
    controllable: &ColMajor,
    inherent: &mut ColMajor,
    k_q: &mut ColMajor,
    blocks: impl Iterator<Item = Range<usize>>,
) {
    let n = inherent.rows();
    let (k_c, k_i, k_q) = (controllable.as_slice(), inherent.as_mut_slice(), k_q.as_mut_slice());
    for block in blocks {
        for j in block.clone() {
            // Entry (i, j), i > j, of K_i is (j, i): row j of the later columns.
            let (head, tail) = k_i.split_at_mut((j + 1) * n);
            let column = &mut head[j * n..];
            for (i, later) in (j + 1..block.end).zip(tail.chunks_exact(n)) {
                column[i] = later[j];
            }
            let (c, i) = (&k_c[j * n..][block.clone()], &column[block.clone()]);
            for ((q, c), i) in k_q[j * n..][block.clone()].iter_mut().zip(c).zip(i) {
                *q = c + i;
            }
        }
    }
}

fn mirror_blocks(mut out: MatMut<'_, f64>, blocks: impl Iterator<Item = Range<usize>>) {
    for block in blocks {
        mirror_upper(block, |i, j| out[(i, j)] = out[(j, i)]);
    }
}

/// `Σ_c δf_c H_c`: how the joint stiffness changes when the tensions change by `δf` (the
/// slope of the affine map tension → stiffness; the inherent part does not depend on `f`).
/// `out` is overwritten. No allocation.
///
/// With `δf` from [`sinew_statics::ArmStatics`]'s tension sensitivity of joint `i`, this is
/// `∂K/∂λ_i`: sweeps over tension levels then need no new geometry.
///
/// # Errors
/// [`StiffnessError::DimensionMismatch`], routing errors.
pub fn stiffness_slope(
    routing: &Routing,
    geometry: &RoutingData,
    delta_tensions: &[f64],
    mut out: MatMut<'_, f64>,
) -> Result<(), StiffnessError> {
    check("stiffness slope", &out, routing.dof())?;
    out.fill(0.0);
    geometry.add_weighted_hessians(routing, delta_tensions, out.as_mut())?;
    Ok(())
}

/// The 2 × 2 block of universal joint `i` in a dof × dof stiffness matrix:
/// `[[K_{i,x}, ·], [·, K_{i,y}]]`.
pub fn joint_block(k: MatRef<'_, f64>, i: usize) -> Option<Matrix2<f64>> {
    if 2 * i + 1 >= k.nrows().min(k.ncols()) {
        return None;
    }
    Some(Matrix2::from_fn(|r, c| k[(2 * i + r, 2 * i + c)]))
}
