//! `ColMajor`: the dense dof × dof and 6 × dof matrices of the pipeline, in plain `Vec`s.

use std::ops::Range;

use faer::{MatMut, MatRef};

/// The symmetric mirror, the one loop of every copy of an upper triangle onto the lower one:
/// calls `copy(i, j)` for each strictly lower position `i > j` of the diagonal block `block`,
/// column by column (`j` ascending, then `i`), and the caller's `copy` sets entry `(i, j)`
/// from `(j, i)` in its own storage (a [`ColMajor`], a faer view or a fixed array).
#[inline(always)]
pub(crate) fn mirror_upper(block: Range<usize>, mut copy: impl FnMut(usize, usize)) {
    for j in block.clone() {
        for i in j + 1..block.end {
            copy(i, j);
        }
    }
}

/// A dense column-major matrix in a plain `Vec` (no padding), viewed as a faer matrix at the
/// API boundary; the structured kernels read it by slices.
#[derive(Clone)]
pub(crate) struct ColMajor {
    rows: usize,
    cols: usize,
    data: Vec<f64>,
}

impl ColMajor {
    pub(crate) fn zeros(rows: usize, cols: usize) -> ColMajor {
        ColMajor { rows, cols, data: vec![0.0; rows * cols] }
    }

    pub(crate) fn rows(&self) -> usize {
        self.rows
    }

    pub(crate) fn cols(&self) -> usize {
        self.cols
    }

    pub(crate) fn as_ref(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.data, self.rows, self.cols)
    }

    pub(crate) fn as_mut(&mut self) -> MatMut<'_, f64> {
        MatMut::from_column_major_slice_mut(&mut self.data, self.rows, self.cols)
    }

    /// The entries, column by column.
    pub(crate) fn as_slice(&self) -> &[f64] {
        &self.data
    }

    /// The entries, column by column.
    pub(crate) fn as_mut_slice(&mut self) -> &mut [f64] {
        &mut self.data
    }

    #[inline(always)]
    pub(crate) fn at(&self, i: usize, j: usize) -> f64 {
        self.data[i + j * self.rows]
    }

    #[inline(always)]
    pub(crate) fn at_mut(&mut self, i: usize, j: usize) -> &mut f64 {
        &mut self.data[i + j * self.rows]
    }

    #[inline(always)]
    pub(crate) fn col(&self, j: usize) -> &[f64] {
        &self.data[j * self.rows..(j + 1) * self.rows]
    }

    #[inline(always)]
    pub(crate) fn col_mut(&mut self, j: usize) -> &mut [f64] {
        &mut self.data[j * self.rows..(j + 1) * self.rows]
    }
}

impl std::fmt::Debug for ColMajor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.as_ref().fmt(f)
    }
}
