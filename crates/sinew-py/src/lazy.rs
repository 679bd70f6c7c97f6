//! Results whose numpy arrays are made when they are first read: `evaluate` copies the
//! workspace's numbers into plain buffers (a few hundred floats for cdhrm5) and returns; each
//! attribute becomes a numpy array on its first access and the same array afterwards.

use faer::MatRef;
use nalgebra::{Dim, Matrix, RawStorage};
use numpy::{PyArray, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;

/// A float64 array kept as a row-major buffer until Python reads it.
pub struct LazyArray {
    shape: Vec<usize>,
    values: Vec<f64>,
    array: PyOnceLock<Py<PyAny>>,
}

impl LazyArray {
    /// A 1-D array of `values`.
    pub fn vector(values: &[f64]) -> LazyArray {
        LazyArray::new(vec![values.len()], values.to_vec())
    }

    /// A 2-D array of a faer matrix.
    pub fn faer(m: MatRef<'_, f64>) -> LazyArray {
        let (rows, cols) = (m.nrows(), m.ncols());
        let mut values = Vec::with_capacity(rows * cols);
        for i in 0..rows {
            values.extend((0..cols).map(|j| m[(i, j)]));
        }
        LazyArray::new(vec![rows, cols], values)
    }

    /// A 2-D array of a nalgebra matrix.
    pub fn nalgebra<R: Dim, C: Dim, S: RawStorage<f64, R, C>>(
        m: &Matrix<f64, R, C, S>,
    ) -> LazyArray {
        let (rows, cols) = (m.nrows(), m.ncols());
        let mut values = Vec::with_capacity(rows * cols);
        for i in 0..rows {
            values.extend((0..cols).map(|j| m[(i, j)]));
        }
        LazyArray::new(vec![rows, cols], values)
    }

    /// A row-major buffer of `shape`.
    pub fn new(shape: Vec<usize>, values: Vec<f64>) -> LazyArray {
        debug_assert_eq!(shape.iter().product::<usize>(), values.len());
        LazyArray { shape, values, array: PyOnceLock::new() }
    }

    /// The numbers, row-major.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The numpy array (made on the first call, the same object afterwards).
    pub fn get(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let array = self.array.get_or_try_init(py, || -> PyResult<Py<PyAny>> {
            let flat = PyArray::from_slice(py, &self.values);
            Ok(flat.reshape(self.shape.clone())?.into_any().unbind())
        })?;
        Ok(array.clone_ref(py))
    }
}

impl std::fmt::Debug for LazyArray {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LazyArray")
            .field("shape", &self.shape)
            .field("values", &self.values)
            .finish()
    }
}

/// An optional [`LazyArray`] read as an array or None.
pub fn optional(py: Python<'_>, a: Option<&LazyArray>) -> PyResult<Option<Py<PyAny>>> {
    a.map(|a| a.get(py)).transpose()
}
