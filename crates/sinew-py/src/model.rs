//! `sinew.Robot`, `sinew.Routing` and their loaders: immutable descriptions, shared by every
//! model built on them.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use nalgebra::Vector3;
use numpy::PyArray2;
use pyo3::prelude::*;
use sinew::robot::{DESCRIPTION_FILE, RobotDescription, RobotError};
use sinew::routing::{ROUTED_ROUTING_FILE, ROUTING_FILE};

use crate::convert::{vec1, vec2};
use crate::errors::{input, library};

/// A robot: a serial chain of revolute joints grouped into 1- or 2-DOF joints.
#[pyclass(module = "sinew", frozen)]
#[derive(Debug)]
pub struct Robot {
    pub(crate) inner: Arc<sinew::robot::Robot>,
    pub(crate) dir: PathBuf,
}

#[pymethods]
impl Robot {
    /// The robot's name (URDF).
    #[getter]
    fn name(&self) -> &str {
        self.inner.name()
    }

    /// The robot folder it was loaded from.
    #[getter]
    fn path(&self) -> String {
        self.dir.display().to_string()
    }

    /// Degrees of freedom: the number of revolute joints, the length of `q`.
    #[getter]
    fn dof(&self) -> usize {
        self.inner.dof()
    }

    /// The number of joints (universal joints count once): the length of `levels`.
    #[getter]
    fn joints(&self) -> usize {
        self.inner.joint_count()
    }

    /// The revolute joints' URDF names, in `q` order.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.inner.joints().iter().map(|j| j.name.clone()).collect()
    }

    /// The joints as `(start, stop)` ranges of `q` (0-based, stop exclusive).
    #[getter]
    fn joint_groups(&self) -> Vec<(usize, usize)> {
        self.inner.joint_groups().iter().map(|g| (g.start, g.end)).collect()
    }

    /// The revolute joints' unit axes in their joint frames, shape (dof, 3).
    #[getter]
    fn axes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let data = self.inner.joints().iter().flat_map(|j| [j.axis.x, j.axis.y, j.axis.z]);
        vec2(py, self.inner.dof(), 3, data.collect())
    }

    /// Joint limits `[lower, upper]` per revolute joint, rad, shape (dof, 2) (±inf when
    /// continuous).
    #[getter]
    fn limits<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let data = self.inner.joints().iter().flat_map(|j| [j.lower, j.upper]);
        vec2(py, self.inner.dof(), 2, data.collect())
    }

    /// The gravity vector, m/s², base frame.
    #[getter]
    fn gravity<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray1<f64>> {
        let g = self.inner.gravity();
        vec1(py, &[g.x, g.y, g.z])
    }

    fn __repr__(&self) -> String {
        format!(
            "sinew.Robot({:?}, dof={}, joints={}, path={:?})",
            self.inner.name(),
            self.inner.dof(),
            self.inner.joint_count(),
            self.dir.display().to_string()
        )
    }
}

/// A cable routing of a robot: the cables, their holes, stiffness and tension limits.
#[pyclass(module = "sinew", frozen)]
#[derive(Debug)]
pub struct Routing {
    pub(crate) inner: Arc<sinew::routing::Routing>,
    pub(crate) file: PathBuf,
}

#[pymethods]
impl Routing {
    /// The routing file it was read from.
    #[getter]
    fn path(&self) -> String {
        self.file.display().to_string()
    }

    /// The cables' names, in routing order (the order of every tension vector).
    #[getter]
    fn cables(&self) -> Vec<String> {
        self.inner.cables().iter().map(|c| c.name.clone()).collect()
    }

    /// The number of cables.
    #[getter]
    fn cable_count(&self) -> usize {
        self.inner.cable_count()
    }

    /// The joint (0-based) each cable ends on, in routing order.
    #[getter]
    fn cable_joints(&self) -> Vec<usize> {
        self.inner.cables().iter().map(|c| c.joint).collect()
    }

    /// Each cable's tension limits `[f_min, f_max]`, N, shape (cables, 2).
    #[getter]
    fn tension_limits<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let data = self.inner.cables().iter().flat_map(|c| c.tension_limits);
        vec2(py, self.inner.cable_count(), 2, data.collect())
    }

    /// Whether no cable crosses another joint than its own (the paper's decoupled model).
    #[getter]
    fn is_decoupled(&self) -> bool {
        self.inner.is_decoupled()
    }

    fn __repr__(&self) -> String {
        format!(
            "sinew.Routing(cables={}, decoupled={}, path={:?})",
            self.inner.cable_count(),
            self.inner.is_decoupled(),
            self.file.display().to_string()
        )
    }
}

/// Load a robot folder: `robot.toml` and the URDF it names (`gravity=False` zeroes gravity,
/// the command line's `--no-gravity`).
#[pyfunction]
#[pyo3(signature = (dir, gravity = true))]
pub fn load_robot(dir: PathBuf, gravity: bool) -> PyResult<Robot> {
    let shown = dir.display();
    if !dir.exists() {
        return Err(input(format!("robot folder `{shown}` does not exist")));
    }
    if !dir.is_dir() {
        return Err(input(format!(
            "`{shown}` is not a folder (give the robot folder holding {DESCRIPTION_FILE})"
        )));
    }
    if !dir.join(DESCRIPTION_FILE).is_file() {
        return Err(input(format!("robot folder `{shown}` has no {DESCRIPTION_FILE}")));
    }
    let description = RobotDescription::read(&dir).map_err(library)?;
    if !description.urdf.is_file() {
        return Err(input(format!(
            "robot folder `{shown}` has no URDF: {} names `{}`, which does not exist",
            description.path.display(),
            description.urdf.display()
        )));
    }
    let robot = description.load_robot().map_err(|e| match e {
        RobotError::NoSuchLink { .. } => {
            input(format!("{}: tip_link: {e}", description.path.display()))
        }
        e => library(e),
    })?;
    let robot = if gravity { robot } else { robot.with_gravity(Vector3::zeros()) };
    Ok(Robot { inner: Arc::new(robot), dir })
}

/// Load a routing of `robot`: a routing file's path, or `"decoupled"` / `"routed"` for the
/// robot folder's `cables.toml` / `cables-routed.toml`.
#[pyfunction]
#[pyo3(signature = (robot, path_or_model = "decoupled"))]
pub fn load_routing(robot: &Robot, path_or_model: &str) -> PyResult<Routing> {
    let file = match path_or_model {
        "decoupled" => robot.dir.join(ROUTING_FILE),
        "routed" => robot.dir.join(ROUTED_ROUTING_FILE),
        path => PathBuf::from(path),
    };
    if !file.is_file() && !Path::new(path_or_model).is_dir() {
        return Err(input(format!("routing file `{}` does not exist", file.display())));
    }
    let routing = sinew::routing::load(&file, &robot.inner).map_err(library)?;
    Ok(Routing { inner: Arc::new(routing), file })
}
