//! The routed model's inherent stiffness `J_cᵀ K_l J_c` (eq. 14) by a staircase kernel: the
//! cables crossing each tile of 8 × 4 entries only, one triangle, in AVX2 registers where the
//! processor has them (pulp's runtime dispatch). The same sums in the same order as
//! [`crate::joint_stiffness`]'s loop.

use std::ops::Range;

use faer::MatRef;
use sinew_routing::Routing;

use crate::colmajor::ColMajor;
use crate::error::StiffnessError;

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
    pub(crate) fn set_upper(
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
