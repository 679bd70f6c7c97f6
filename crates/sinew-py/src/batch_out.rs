//! `evaluate_many`'s numpy side: the batch's own buffers moved into numpy (no copy), or, with
//! `out=`, the caller's arrays written in place. `sinew.dask` passes its shared rows as `out`
//! (`sinew/_shared.py`): a worker then writes each result once, where the client reads it,
//! instead of into fresh pages it would copy afterwards.

use nalgebra::Vector6;
use numpy::{
    Element, IntoPyArray, PyArrayDyn, PyArrayMethods, PyReadwriteArrayDyn, PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sinew::stiffness::ArmStiffness;

use crate::batch::{BatchChoice, Outputs, evaluate_into};
use crate::errors::{exception, input};
use crate::pool::run;
use crate::results::BatchResult;

/// `BatchResult`'s array fields, in its order.
pub const FIELDS: [&str; 8] =
    ["ok", "stable", "min_eigenvalue", "t0", "tensions", "c_x", "k_x", "k_fd"];

/// One field's buffer: the caller's array (borrowed for writing) or the batch's own.
enum Slot<'py, T: Element> {
    Given(PyReadwriteArrayDyn<'py, T>, Bound<'py, PyAny>),
    Own(Vec<T>),
}

impl<'py, T: Element + Clone> Slot<'py, T> {
    /// `out[name]` when given (it must be a writable C-contiguous array of `dtype` and
    /// `shape`, sharing no memory with another field's), else a buffer of `fill`.
    fn new(
        given: Option<Bound<'py, PyAny>>,
        name: &str,
        shape: &[usize],
        dtype: &str,
        fill: T,
    ) -> PyResult<Self> {
        let Some(obj) = given else {
            return Ok(Slot::Own(vec![fill; shape.iter().product()]));
        };
        let bad = || {
            input(format!(
                "out[{name:?}]: expected a writable C-contiguous {dtype} array of shape {shape:?} \
                 that shares no memory with another field's"
            ))
        };
        let array = obj.cast::<PyArrayDyn<T>>().map_err(|_| bad())?;
        if array.shape() != shape || !array.is_c_contiguous() {
            return Err(bad());
        }
        let guard = array.try_readwrite().map_err(|_| bad())?;
        Ok(Slot::Given(guard, obj))
    }

    fn slice(&mut self) -> PyResult<&mut [T]> {
        match self {
            Slot::Given(guard, _) => guard.as_slice_mut().map_err(|e| input(e.to_string())),
            Slot::Own(v) => Ok(v),
        }
    }

    /// The field's numpy array: the caller's own object, or the buffer moved into numpy.
    fn into_array(self, py: Python<'py>, shape: &[usize]) -> PyResult<Py<PyAny>> {
        match self {
            Slot::Given(guard, obj) => {
                drop(guard);
                Ok(obj.unbind())
            }
            Slot::Own(v) => Ok(v.into_pyarray(py).reshape(shape.to_vec())?.into_any().unbind()),
        }
    }
}

/// Evaluate every row of `q` (rows × dof) as `evaluate_many` does, with the GIL released, on
/// `threads` threads; the fields named in `out` written into its arrays (checked first), the
/// others into the batch's own. When every row of a non-empty batch fails and
/// `raise_if_all_fail`, the first row's error instead.
pub fn evaluate_to_numpy<'py>(
    py: Python<'py>,
    arm: &ArmStiffness,
    q: &[f64],
    f0: &[Vector6<f64>],
    choice: &BatchChoice,
    threads: Option<usize>,
    out: Option<&Bound<'py, PyDict>>,
    raise_if_all_fail: bool,
) -> PyResult<BatchResult> {
    let (dof, cables) = (arm.dof(), arm.routing().cable_count());
    let rows = q.len().checked_div(dof).unwrap_or(0);
    let shapes: [Vec<usize>; 8] = [
        vec![rows],
        vec![rows],
        vec![rows],
        vec![rows, dof],
        vec![rows, cables],
        vec![rows, 6, 6],
        vec![rows, 6, 6],
        vec![rows, 3, 3],
    ];
    let mut given: [Option<Bound<'py, PyAny>>; 8] = Default::default();
    for (key, value) in out.into_iter().flat_map(|d| d.iter()) {
        let name: String = key.extract().map_err(|_| input("out: its keys are field names"))?;
        let i = FIELDS.iter().position(|f| *f == name).ok_or_else(|| {
            input(format!("out: no field {name:?}; the fields are {}", FIELDS.join(", ")))
        })?;
        given[i] = Some(value);
    }
    let [g_ok, g_stable, g_min, g_t0, g_tensions, g_c_x, g_k_x, g_k_fd] = given;
    // The batch's own buffers zeroed (the allocator's zeroed pages): every entry is written
    // once by its row anyway.
    let zero = 0.0;
    let mut ok = Slot::new(g_ok, FIELDS[0], &shapes[0], "bool", false)?;
    let mut stable = Slot::new(g_stable, FIELDS[1], &shapes[1], "bool", false)?;
    let mut min_eigenvalue = Slot::new(g_min, FIELDS[2], &shapes[2], "float64", zero)?;
    let mut t0 = Slot::new(g_t0, FIELDS[3], &shapes[3], "float64", zero)?;
    let mut tensions = Slot::new(g_tensions, FIELDS[4], &shapes[4], "float64", zero)?;
    let mut c_x = Slot::new(g_c_x, FIELDS[5], &shapes[5], "float64", zero)?;
    let mut k_x = Slot::new(g_k_x, FIELDS[6], &shapes[6], "float64", zero)?;
    let mut k_fd = Slot::new(g_k_fd, FIELDS[7], &shapes[7], "float64", zero)?;
    let buffers = Outputs {
        ok: ok.slice()?,
        stable: stable.slice()?,
        min_eigenvalue: min_eigenvalue.slice()?,
        t0: t0.slice()?,
        tensions: tensions.slice()?,
        c_x: c_x.slice()?,
        k_x: k_x.slice()?,
        k_fd: k_fd.slice()?,
    };
    let errors = py.detach(|| run(threads, || evaluate_into(arm, q, f0, choice, buffers)))?;
    if let Some((_, kind, message)) = errors.first()
        && errors.len() == rows
        && raise_if_all_fail
    {
        return Err(exception(*kind, format!("every row failed; row 0: {message}")));
    }
    Ok(BatchResult {
        ok: ok.into_array(py, &shapes[0])?,
        stable: stable.into_array(py, &shapes[1])?,
        min_eigenvalue: min_eigenvalue.into_array(py, &shapes[2])?,
        t0: t0.into_array(py, &shapes[3])?,
        tensions: tensions.into_array(py, &shapes[4])?,
        c_x: c_x.into_array(py, &shapes[5])?,
        k_x: k_x.into_array(py, &shapes[6])?,
        k_fd: k_fd.into_array(py, &shapes[7])?,
        errors: errors.into_iter().map(|(r, kind, m)| (r, kind.to_string(), m)).collect(),
    })
}
