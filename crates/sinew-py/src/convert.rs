//! numpy in and out: checked inputs (shape, finiteness) and row-major arrays from the
//! library's matrices.

use nalgebra::{Dim, Matrix, RawStorage};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::errors::input;

/// `obj` as a float64 numpy array (no copy when it already is one), or an input error naming
/// `name`.
fn as_float_array<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Bound<'py, PyAny>> {
    let py = obj.py();
    let numpy = py.import("numpy")?;
    numpy
        .call_method1("ascontiguousarray", (obj, "float64"))
        .map_err(|e| input(format!("{name}: not an array of numbers ({e})")))
}

/// A 1-D vector of `len` finite numbers (any sequence or array convertible to float64).
pub fn vector(obj: &Bound<'_, PyAny>, name: &str, len: Option<usize>) -> PyResult<Vec<f64>> {
    let values: Vec<f64> = if let Ok(a) = obj.extract::<PyReadonlyArray1<'_, f64>>() {
        a.as_array().iter().copied().collect()
    } else {
        let converted = as_float_array(obj, name)?;
        let a = converted.extract::<PyReadonlyArray1<'_, f64>>().map_err(|_| {
            input(format!("{name}: expected a 1-D array, got {} dimensions", ndim(&converted)))
        })?;
        a.as_array().iter().copied().collect()
    };
    if let Some(len) = len
        && values.len() != len
    {
        return Err(input(format!("{name}: expected {len} values, got {}", values.len())));
    }
    finite(&values, name)?;
    Ok(values)
}

/// A 2-D array, row-major, of `cols` columns (any array-like convertible to float64); rows
/// are returned as they are (not checked for finiteness: the batch reports bad rows).
pub fn matrix(obj: &Bound<'_, PyAny>, name: &str, cols: usize) -> PyResult<(usize, Vec<f64>)> {
    let read = |a: PyReadonlyArray2<'_, f64>| -> PyResult<(usize, Vec<f64>)> {
        let view = a.as_array();
        let (rows, c) = view.dim();
        if c != cols {
            return Err(input(format!("{name}: expected shape (N, {cols}), got ({rows}, {c})")));
        }
        Ok((rows, view.iter().copied().collect()))
    };
    if let Ok(a) = obj.extract::<PyReadonlyArray2<'_, f64>>() {
        return read(a);
    }
    let converted = as_float_array(obj, name)?;
    match converted.extract::<PyReadonlyArray2<'_, f64>>() {
        Ok(a) => read(a),
        Err(_) => Err(input(format!(
            "{name}: expected a 2-D array of shape (N, {cols}), got {} dimensions",
            ndim(&converted)
        ))),
    }
}

fn ndim(obj: &Bound<'_, PyAny>) -> String {
    obj.getattr("ndim").and_then(|n| n.extract::<usize>()).map_or("?".to_owned(), |n| n.to_string())
}

/// Every value finite, or an input error naming the first that is not.
pub fn finite(values: &[f64], name: &str) -> PyResult<()> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(k) => Err(input(format!("{name}[{k}]: `{}` is not a finite number", values[k]))),
        None => Ok(()),
    }
}

/// A 1-D array.
pub fn vec1<'py>(py: Python<'py>, v: &[f64]) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, v)
}

/// A 2-D array from a row-major buffer (`data.len() == rows * cols`).
pub fn vec2<'py>(
    py: Python<'py>,
    rows: usize,
    cols: usize,
    data: Vec<f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let a = Array2::from_shape_vec((rows, cols), data)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py))
}

/// A nalgebra matrix as a 2-D array.
pub fn na2<'py, R: Dim, C: Dim, S: RawStorage<f64, R, C>>(
    py: Python<'py>,
    m: &Matrix<f64, R, C, S>,
) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_fn((m.nrows(), m.ncols()), |(i, j)| m[(i, j)]).into_pyarray(py)
}

/// Reshape a flat array into `shape` (a view, no copy).
pub fn reshape<'py>(a: Bound<'py, PyArray1<f64>>, shape: &[usize]) -> PyResult<Bound<'py, PyAny>> {
    Ok(a.reshape(shape.to_vec())?.into_any())
}
