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

use crate::colmajor::ColMajor;
use crate::error::StiffnessError;
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
    mirror_upper(inherent, std::iter::once(0..n));
    Ok(())
}

/// `Σ_c f_c H_c`, `J_cᵀ K_l J_c` and their sum `K_q` into three dof × dof matrices, block by
/// block of `layout` (which every cable of `routing` fits in): only the entries inside the
/// blocks are written, the caller keeps the others at zero. Small blocks
/// ([`BlockLayout::structured`]) are accumulated on the stack, segment by segment and cable by
/// cable in routing order (the sums of [`joint_stiffness`], term for term); large ones (the
/// routed model) through [`joint_stiffness`]'s own loops. `O(Σ_c |dofs_c|²)`, no allocation.
pub(crate) fn joint_stiffness_in_blocks(
    routing: &Routing,
    geometry: &RoutingData,
    tensions: &[f64],
    layout: &BlockLayout,
    (plan, scratch): (&InherentPlan, &mut InherentScratch),
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
        zero_blocks(layout, controllable);
        add_weighted_hessians(
            routing,
            geometry.segment_hessians(routing)?,
            tensions,
            controllable,
        )?;
        zero_blocks(layout, inherent);
        plan.add_upper(geometry.jacobian()?, scratch, inherent)?;
        mirror_upper(inherent.as_mut(), layout.blocks());
        for block in layout.blocks() {
            for j in block.clone() {
                for i in block.clone() {
                    *k_q.at_mut(i, j) = controllable.at(i, j) + inherent.at(i, j);
                }
            }
        }
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

/// `out += Σ_c f_c H_c` segment by segment, each block column by column: the sums of
/// [`RoutingData::add_weighted_hessians`] in the same order, written through column slices.
fn add_weighted_hessians(
    routing: &Routing,
    hessians: SegmentHessians<'_>,
    tensions: &[f64],
    out: &mut ColMajor,
) -> Result<(), StiffnessError> {
    for (s, (seg, h)) in hessians.iter().enumerate() {
        let (lo, n) = (seg.dofs.start, seg.dofs.len());
        if n == 0 {
            continue;
        }
        let Some(&w) = tensions.get(seg.cable) else {
            return Err(StiffnessError::DimensionMismatch {
                what: "tensions",
                expected: routing.cable_count(),
                got: tensions.len(),
            });
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

/// Width of the row blocks of [`InherentPlan::add_upper`]: eight `f64` accumulators, two AVX
/// registers.
const LANES: usize = 8;

/// What [`InherentPlan::add_upper`] needs of the routing, computed once per model: for each
/// column `j` of `J_cᵀ K_l J_c`, the cables whose rows of `J_c` can be non-zero there and the
/// first row they reach; and every cable's `k_c`.
///
/// Routed, cable `c` spans its joint and every joint before it, so the cables crossing DOF `j`
/// are those of joint `⌊j/2⌋` on (a contiguous range: cables are ordered by joint) and they all
/// start at DOF 0: `J_c` is a staircase.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct InherentPlan {
    dof: usize,
    /// Row stride of [`InherentScratch::rows`]: `dof` rounded up to [`LANES`].
    stride: usize,
    /// Column `j`: the first row `i` with a non-zero term, and the range of cables (routing
    /// order) bounding those whose DOFs contain `j` (cables inside that do not contribute
    /// exact zeros).
    columns: Vec<(usize, Range<usize>)>,
    stiffness: Vec<f64>,
}

/// The workspace of [`InherentPlan::add_upper`]: `J_c` row by row (cable `c` at
/// `rows[c · stride ..]`, zero-padded), and one column of `K_l J_c`.
#[derive(Debug, Clone)]
pub(crate) struct InherentScratch {
    rows: Vec<f64>,
    weights: Vec<f64>,
}

impl InherentPlan {
    pub(crate) fn new(routing: &Routing) -> InherentPlan {
        let dof = routing.dof();
        let stride = dof.div_ceil(LANES) * LANES;
        let columns = (0..dof)
            .map(|j| {
                let mut first_row = j;
                let (mut lo, mut hi) = (usize::MAX, 0);
                for (c, cable) in routing.cables().iter().enumerate() {
                    if cable.dofs.contains(&j) {
                        first_row = first_row.min(cable.dofs.start);
                        lo = lo.min(c);
                        hi = c + 1;
                    }
                }
                (first_row, if lo < hi { lo..hi } else { 0..0 })
            })
            .collect();
        let stiffness = routing.cables().iter().map(|c| c.stiffness).collect();
        InherentPlan { dof, stride, columns, stiffness }
    }

    pub(crate) fn scratch(&self) -> InherentScratch {
        InherentScratch {
            rows: vec![0.0; self.stiffness.len() * self.stride],
            weights: vec![0.0; self.stiffness.len()],
        }
    }

    /// `out += J_cᵀ K_l J_c` on and above the diagonal (the caller mirrors it), column `j` over
    /// the cables crossing DOF `j` only, rows in blocks of [`LANES`] accumulated in registers
    /// over the cables: entry `(i, j)` is `Σ_c (k_c J_c[c, j]) · J_c[c, i]` summed in routing
    /// order from zero, the same sum as [`add_inherent_upper`] (the extra terms are exact
    /// zeros). `O(Σ_j |cables crossing j| · j)`, no allocation.
    fn add_upper(
        &self,
        j_c: MatRef<'_, f64>,
        scratch: &mut InherentScratch,
        out: &mut ColMajor,
    ) -> Result<(), StiffnessError> {
        let (m, n, stride) = (self.stiffness.len(), self.dof, self.stride);
        let sizes = [
            ("inherent stiffness", n, out.cols()),
            ("cable Jacobian", m, j_c.nrows()),
            ("cable Jacobian", n, j_c.ncols()),
            ("inherent scratch", m * stride, scratch.rows.len()),
            ("inherent scratch", m, scratch.weights.len()),
        ];
        for (what, expected, got) in sizes {
            if expected != got {
                return Err(StiffnessError::DimensionMismatch { what, expected, got });
            }
        }
        let InherentScratch { rows, weights } = scratch;
        for (c, row) in rows.chunks_exact_mut(stride).enumerate() {
            for (i, v) in row[..n].iter_mut().enumerate() {
                *v = j_c[(c, i)];
            }
        }
        for (j, (first_row, cables)) in self.columns.iter().enumerate() {
            let rows = &rows[cables.start * stride..cables.end * stride];
            let (weights, stiffness) =
                (&mut weights[cables.clone()], &self.stiffness[cables.clone()]);
            for ((w, k), row) in weights.iter_mut().zip(stiffness).zip(rows.chunks_exact(stride)) {
                *w = k * row[j];
            }
            let col = &mut out.col_mut(j)[..=j];
            let mut block = first_row - first_row % LANES;
            while block <= j {
                let mut acc = [0.0; LANES];
                for (&w, row) in weights.iter().zip(rows.chunks_exact(stride)) {
                    let r = &row[block..block + LANES];
                    for t in 0..LANES {
                        acc[t] += w * r[t];
                    }
                }
                for t in 0..LANES {
                    let i = block + t;
                    if i >= *first_row && i <= j {
                        col[i] += acc[t];
                    }
                }
                block += LANES;
            }
        }
        Ok(())
    }
}

/// Copy the strict upper triangle of each diagonal block `blocks` of `out` to its lower one.
fn mirror_upper(mut out: MatMut<'_, f64>, blocks: impl Iterator<Item = Range<usize>>) {
    for block in blocks {
        for j in block.clone() {
            for i in j + 1..block.end {
                out[(i, j)] = out[(j, i)];
            }
        }
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
