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
use sinew_routing::{HessianBatch, Routing, RoutingData, SegmentHessians};

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
        let hessians = geometry.segment_hessians(routing)?;
        match hessians.batches() {
            // Each batch's block written once (the rest of K_c is never written: zero).
            Some(batches) => {
                add_weighted_hessians_batched(routing, batches, tensions, controllable)?
            }
            None => {
                zero_blocks(layout, controllable);
                add_weighted_hessians(routing, hessians, tensions, controllable)?;
            }
        }
        // Every entry the tiles reach is written once; the others are never written (zero).
        plan.set_upper(geometry.jacobian()?, scratch, inherent)?;
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

/// `out += Σ_c f_c H_c` segment by segment, each block column by column: the sums of
/// [`RoutingData::add_weighted_hessians`] in the same order, written through column slices.
fn add_weighted_hessians(
    routing: &Routing,
    hessians: SegmentHessians<'_>,
    tensions: &[f64],
    out: &mut ColMajor,
) -> Result<(), StiffnessError> {
    if let Some(batches) = hessians.batches() {
        return add_weighted_hessians_batched(routing, batches, tensions, out);
    }
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

/// `Σ_c f_c H_c` batch by batch (routed models), each batch's diagonal block overwritten (the
/// batches cross disjoint DOFs, and no segment reaches outside its batch's block, so the
/// entries outside the blocks are never written and stay zero): a batch's segments cross the
/// same DOFs, so each entry of its block is one running sum from zero over the batch's
/// segments, kept in a register, in routing order (the sums of [`add_weighted_hessians`] on a
/// zeroed matrix, in the same order), reading the blocks and the cables in storage order.
fn add_weighted_hessians_batched<'a>(
    routing: &Routing,
    batches: impl Iterator<Item = HessianBatch<'a>>,
    tensions: &[f64],
    out: &mut ColMajor,
) -> Result<(), StiffnessError> {
    let tension_mismatch = || StiffnessError::DimensionMismatch {
        what: "tensions",
        expected: routing.cable_count(),
        got: tensions.len(),
    };
    for batch in batches {
        let (lo, n) = (batch.dofs.start, batch.dofs.len());
        if batch.blocks.len() != batch.cables.len() * n * n
            || lo + n > out.rows()
            || lo + n > out.cols()
        {
            return Err(StiffnessError::DimensionMismatch {
                what: "segment Hessian batch",
                expected: batch.cables.len() * n * n,
                got: batch.blocks.len(),
            });
        }
        if n == 2 {
            let mut acc = [0.0; 4];
            for (&c, h) in batch.cables.iter().zip(batch.blocks.chunks_exact(4)) {
                let w = *tensions.get(c).ok_or_else(tension_mismatch)?;
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
        for (&c, h) in batch.cables.iter().zip(batch.blocks.chunks_exact(n * n)) {
            let w = *tensions.get(c).ok_or_else(tension_mismatch)?;
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

/// Height of the tiles of [`InherentPlan::set_upper`]: eight rows, two AVX registers.
const LANES: usize = 8;

/// Width of the tiles of [`InherentPlan::set_upper`]: four columns, so a tile's 32
/// accumulators fill eight AVX registers and each row of `J_c` loaded serves four columns.
const COLUMNS: usize = 4;

/// What [`InherentPlan::set_upper`] needs of the routing, computed once per model: for each
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

/// The workspace of [`InherentPlan::set_upper`]: `J_c` row by row (cable `c` at
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
            weights: vec![0.0; self.stiffness.len() * COLUMNS],
        }
    }

    /// `J_cᵀ K_l J_c` on and above the diagonal into `out` (the caller mirrors it): every entry
    /// the plan can make non-zero is overwritten, the others are not touched (the caller keeps
    /// them at zero: they are zero at every configuration). In tiles of
    /// [`LANES`] rows × [`COLUMNS`] columns accumulated in registers over the cables crossing
    /// any of the tile's columns (each row of `J_c` loaded once per tile serves four columns;
    /// compiled for AVX2 where present, through pulp's dispatch): entry `(i, j)` is
    /// `Σ_c (k_c J_c[c, j]) · J_c[c, i]` summed in routing order from zero, the same sum as
    /// [`add_inherent_upper`] (the extra terms, cables that do not cross `j` or `i`, are exact
    /// zeros; Rust does not fuse the multiply and the add, so AVX2 changes no rounding).
    /// `O(Σ_j |cables crossing j| · j)`, no allocation.
    fn set_upper(
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
            ("inherent scratch", m * COLUMNS, scratch.weights.len()),
        ];
        for (what, expected, got) in sizes {
            if expected != got {
                return Err(StiffnessError::DimensionMismatch { what, expected, got });
            }
        }
        let InherentScratch { rows, weights } = scratch;
        // J_c row by row, only where a cable can be non-zero (the rest stays zero from
        // construction: J_c is exactly zero there at every configuration).
        for (i, (_, cables)) in self.columns.iter().enumerate() {
            let col = j_c.col(i);
            match col.try_as_col_major() {
                Some(col) => {
                    let col = &col.as_slice()[cables.clone()];
                    for (row, &v) in rows[cables.start * stride..].chunks_mut(stride).zip(col) {
                        row[i] = v;
                    }
                }
                None => {
                    for c in cables.clone() {
                        rows[c * stride + i] = col[c];
                    }
                }
            }
        }
        let (rows, columns, stiffness) = (&*rows, &self.columns[..], &self.stiffness[..]);
        pulp::Arch::new().dispatch(Tiles { n, stride, rows, columns, stiffness, weights, out });
        Ok(())
    }
}

/// The loop of [`InherentPlan::set_upper`] over tiles of [`LANES`] rows × [`COLUMNS`]
/// columns, as a pulp operation: `with_simd` is inlined into pulp's dispatch, so the loop is
/// compiled for AVX2 where the processor has it. `J_c` row by row (`stride` apart), the plan's
/// columns, the cables' stiffness, the weights' scratch and the output.
struct Tiles<'a> {
    n: usize,
    stride: usize,
    rows: &'a [f64],
    columns: &'a [(usize, Range<usize>)],
    stiffness: &'a [f64],
    weights: &'a mut [f64],
    out: &'a mut ColMajor,
}

impl pulp::WithSimd for Tiles<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        let Tiles { n, stride, rows, columns, stiffness, weights, out } = self;
        let mut j0 = 0;
        while j0 < n {
            let tile = COLUMNS.min(n - j0);
            // The union of the tile's cable ranges (nested or not: cables outside a
            // column's range have an exact zero there, so their weight is zero).
            let (mut lo, mut hi) = (usize::MAX, 0);
            let mut first = usize::MAX;
            for (f, cables) in &columns[j0..j0 + tile] {
                if !cables.is_empty() {
                    lo = lo.min(cables.start);
                    hi = hi.max(cables.end);
                    first = first.min(*f);
                }
            }
            if lo >= hi {
                j0 += tile;
                continue;
            }
            let rows = &rows[lo * stride..hi * stride];
            let weights = &mut weights[..(hi - lo) * COLUMNS];
            for ((w, k), row) in weights
                .chunks_exact_mut(COLUMNS)
                .zip(&stiffness[lo..hi])
                .zip(rows.chunks_exact(stride))
            {
                for t in 0..COLUMNS {
                    w[t] = if t < tile { k * row[j0 + t] } else { 0.0 };
                }
            }
            let last = j0 + tile - 1;
            let mut block = first - first % LANES;
            while block <= last {
                let mut acc = [[0.0; LANES]; COLUMNS];
                for (w, row) in weights.chunks_exact(COLUMNS).zip(rows.chunks_exact(stride)) {
                    let r = &row[block..block + LANES];
                    for t in 0..COLUMNS {
                        for l in 0..LANES {
                            acc[t][l] += w[t] * r[l];
                        }
                    }
                }
                for t in 0..tile {
                    let j = j0 + t;
                    let first_row = columns[j].0;
                    if columns[j].1.is_empty() {
                        continue;
                    }
                    let col = out.col_mut(j);
                    for l in 0..LANES {
                        let i = block + l;
                        if i >= first_row && i <= j {
                            col[i] = acc[t][l];
                        }
                    }
                }
                block += LANES;
            }
            j0 += tile;
        }
    }
}

/// Within each diagonal block `blocks`: the strict upper triangle of `inherent` copied to its
/// lower one ([`mirror_upper`] on the arm's own storage), and `K_q = K_c + K_i`, in one pass
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
