//! numpy in and out: checked inputs (shape, finiteness) and row-major arrays from the
//! library's matrices.

use nalgebra::{Dim, Matrix, RawStorage, Vector6};
use numpy::ndarray::Array2;
use numpy::ndarray::{Dimension, Ix1, Ix2};
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray, PyReadonlyArray2,
    PyUntypedArrayMethods,
};
use pyo3::prelude::*;

use crate::errors::input;

/// `obj` as a float64 numpy array by the conversion rule of every array argument, or an input
/// error naming `name` and the shape `expected`:
///
/// - any layout (C or Fortran order, strided views) and Python lists or tuples are read as
///   they are, and copied; the caller's array is never written;
/// - float64 is read as is; float16, float32 (exact) and longdouble (rounded) become float64;
/// - signed and unsigned integers become float64 (exact up to 2⁵³ in magnitude);
/// - `None`, booleans, complex numbers, strings and objects are refused;
/// - an array whose float64 values are not aligned in memory (as a buffer unpickled out of
///   band may be) is copied to an aligned one first.
fn as_float_array<'py>(
    obj: &Bound<'py, PyAny>,
    name: &str,
    expected: &str,
) -> PyResult<Bound<'py, PyAny>> {
    if obj.is_none() {
        return Err(input(format!("{name}: expected {expected}, got None")));
    }
    let py = obj.py();
    let numpy = py.import("numpy")?;
    let refused =
        |why: String| input(format!("{name}: not an array of numbers: expected {expected}, {why}"));
    let a = numpy
        .call_method1("asarray", (obj,))
        .map_err(|e| refused(format!("got something else ({e})")))?;
    let dtype = a.getattr("dtype")?;
    let kind: String = dtype.getattr("kind")?.extract()?;
    match kind.as_str() {
        "f" | "i" | "u" => {}
        "O" => {
            // Numbers held as Python objects convert; None (or anything else) is refused.
            let mut has_none = false;
            for x in a.getattr("flat")?.try_iter()? {
                if x?.is_none() {
                    has_none = true;
                    break;
                }
            }
            if has_none {
                return Err(refused("got None in it".to_owned()));
            }
            return aligned_copy(&numpy, &a)
                .map_err(|_| refused("got objects that are not numbers".to_owned()));
        }
        _ => {
            let what = match kind.as_str() {
                "b" => "booleans",
                "c" => "complex numbers",
                "U" | "S" => "strings",
                _ => "dtype",
            };
            return Err(refused(format!("got {what} ({dtype})")));
        }
    }
    aligned_copy(&numpy, &a)
}

/// `a` as a C-contiguous, aligned float64 array (a copy unless it already is one).
fn aligned_copy<'py>(
    numpy: &Bound<'py, PyModule>,
    a: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    numpy.call_method1("require", (a, "float64", ("C", "A")))
}

/// Whether every float64 of `a` is aligned: its data pointer and every stride.
fn aligned<D: Dimension>(a: &PyReadonlyArray<'_, f64, D>) -> bool {
    let align = align_of::<f64>();
    (a.data() as usize).is_multiple_of(align)
        && a.strides().iter().all(|s| s.unsigned_abs().is_multiple_of(align))
}

/// `obj` as a float64 array of dimension `D` that can be read in place: an aligned float64
/// array as it is, anything else by the rule of `as_float_array`. `Ok(None)` when it
/// converts but has another number of dimensions.
fn readable<'py, D: Dimension>(
    obj: &Bound<'py, PyAny>,
    name: &str,
    expected: &str,
) -> PyResult<Result<PyReadonlyArray<'py, f64, D>, Bound<'py, PyAny>>> {
    if let Ok(a) = obj.extract::<PyReadonlyArray<'py, f64, D>>()
        && aligned(&a)
    {
        return Ok(Ok(a));
    }
    let converted = as_float_array(obj, name, expected)?;
    match converted.extract::<PyReadonlyArray<'py, f64, D>>() {
        Ok(a) => Ok(Ok(a)),
        Err(_) => Ok(Err(converted)),
    }
}

/// A 1-D vector of `len` finite numbers (any sequence or array, by the rule of
/// `as_float_array`).
pub fn vector(obj: &Bound<'_, PyAny>, name: &str, len: Option<usize>) -> PyResult<Vec<f64>> {
    let expected = match len {
        Some(len) => format!("an array of shape ({len},)"),
        None => "a 1-D array".to_owned(),
    };
    let values: Vec<f64> = match readable::<Ix1>(obj, name, &expected)? {
        Ok(a) => a.as_array().iter().copied().collect(),
        Err(converted) => {
            return Err(input(format!(
                "{name}: expected {expected} (a 1-D array), got {} dimensions",
                ndim(&converted)
            )));
        }
    };
    if let Some(len) = len
        && values.len() != len
    {
        return Err(input(format!("{name}: expected {len} values, got {}", values.len())));
    }
    finite(&values, name)?;
    Ok(values)
}

/// A 2-D array, row-major, of `cols` columns (any array-like, by the rule of
/// `as_float_array`); rows are returned as they are (not checked for finiteness: the batch
/// reports bad rows).
pub fn matrix(obj: &Bound<'_, PyAny>, name: &str, cols: usize) -> PyResult<(usize, Vec<f64>)> {
    let expected = format!("an array of shape (N, {cols})");
    let read = |a: PyReadonlyArray2<'_, f64>| -> PyResult<(usize, Vec<f64>)> {
        let view = a.as_array();
        let (rows, c) = view.dim();
        if c != cols {
            return Err(input(format!("{name}: expected shape (N, {cols}), got ({rows}, {c})")));
        }
        // Logical (row-major) order whatever the layout: a copy, the caller's array untouched.
        Ok((rows, view.iter().copied().collect()))
    };
    match readable::<Ix2>(obj, name, &expected)? {
        Ok(a) => read(a),
        Err(converted) => Err(input(format!(
            "{name}: expected a 2-D array of shape (N, {cols}), got {} dimensions",
            ndim(&converted)
        ))),
    }
}

/// The load of a batch of `rows` rows: one wrench for every row (shape (6,) or (1, 6),
/// broadcast) or one per row ((rows, 6)); every value finite. `None`: no load.
pub fn wrenches(obj: Option<&Bound<'_, PyAny>>, rows: usize) -> PyResult<Vec<Vector6<f64>>> {
    let Some(obj) = obj else { return Ok(vec![Vector6::zeros()]) };
    let expected = format!("shape (6,), (1, 6) or ({rows}, 6) (one row of Q each)");
    let what = format!("an array of {expected}");
    let values: Vec<f64> = match readable::<Ix1>(obj, "wrench", &what)? {
        Ok(a) => {
            let n = a.as_array().len();
            if n != 6 {
                return Err(input(format!("wrench: expected {expected}, got ({n},)")));
            }
            a.as_array().iter().copied().collect()
        }
        Err(converted) => match readable::<Ix2>(&converted, "wrench", &what)? {
            Ok(a) => {
                let (r, c) = a.as_array().dim();
                if c != 6 || (r != 1 && r != rows) {
                    return Err(input(format!("wrench: expected {expected}, got ({r}, {c})")));
                }
                a.as_array().iter().copied().collect()
            }
            Err(converted) => {
                let dims = ndim(&converted);
                return Err(input(format!("wrench: expected {expected}, got {dims} dimensions")));
            }
        },
    };
    finite(&values, "wrench")?;
    Ok(values.chunks_exact(6).map(Vector6::from_column_slice).collect())
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
