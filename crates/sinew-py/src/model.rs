//! `sinew.Robot`, `sinew.Routing` and their loaders: immutable descriptions, shared by every
//! model built on them. Each keeps the texts it was built from (the URDF and `robot.toml`;
//! the routing file) and pickles as them, never as a path: a copy unpickled on a machine
//! without the robot folder (a Dask worker) is built from the same texts by the same code,
//! and evaluates bit for bit like the original.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use nalgebra::Vector3;
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyType;
use sinew::robot::{DESCRIPTION_FILE, RobotDescription, RobotError};
use sinew::routing::{ROUTED_ROUTING_FILE, ROUTING_FILE};

use crate::convert::{vec1, vec2};
use crate::errors::{input, library};

/// A robot: a serial chain of revolute joints grouped into 1- or 2-DOF joints.
#[pyclass(module = "sinew", frozen)]
#[derive(Debug)]
pub struct Robot {
    pub(crate) inner: Arc<sinew::robot::Robot>,
    /// The folder it was loaded from; None when built from texts (unpickled).
    pub(crate) dir: Option<PathBuf>,
    /// What it was built from.
    texts: RobotTexts,
}

/// What `Routing` pickles as: `Routing.from_text` and its arguments.
type RoutingReduced = (Py<PyAny>, (Py<Robot>, String, String));

/// The texts a robot is built from: what it pickles as.
#[derive(Debug, Clone)]
struct RobotTexts {
    urdf: String,
    description: String,
    gravity: bool,
}

impl Robot {
    /// The robot of a `robot.toml` text and a URDF text (nothing read from disk); the URDF is
    /// named in messages by the file name `robot.toml` gives it.
    fn from_texts(urdf: String, description: String, gravity: bool) -> PyResult<Robot> {
        let parsed = RobotDescription::from_toml_str(&description, DESCRIPTION_FILE)
            .map_err(|e| input(format!("description: {e}")))?;
        let name = parsed.urdf.display().to_string();
        let robot = sinew::robot::Robot::from_urdf_str(&urdf, &name, &parsed.settings).map_err(
            |e| match e {
                RobotError::NoSuchLink { .. } => {
                    input(format!("{DESCRIPTION_FILE}: tip_link: {e}"))
                }
                e => library(e),
            },
        )?;
        let robot = if gravity { robot } else { robot.with_gravity(Vector3::zeros()) };
        Ok(Robot {
            inner: Arc::new(robot),
            dir: None,
            texts: RobotTexts { urdf, description, gravity },
        })
    }
}

#[pymethods]
impl Robot {
    /// A robot from the texts of its URDF and its `robot.toml` (whose `urdf` entry then only
    /// names the URDF in messages); `gravity=False` zeroes gravity. What a pickled robot is
    /// rebuilt with.
    #[classmethod]
    #[pyo3(name = "from_texts", signature = (urdf, description, gravity = true))]
    fn py_from_texts(
        _class: &Bound<'_, PyType>,
        urdf: String,
        description: String,
        gravity: bool,
    ) -> PyResult<Robot> {
        Robot::from_texts(urdf, description, gravity)
    }

    /// Pickling by value: `Robot.from_texts(urdf, description, gravity)`, the files' texts.
    fn __reduce__(&self, py: Python<'_>) -> PyResult<(Py<PyAny>, (String, String, bool))> {
        let build = py.get_type::<Robot>().getattr("from_texts")?.unbind();
        let t = &self.texts;
        Ok((build, (t.urdf.clone(), t.description.clone(), t.gravity)))
    }

    /// The URDF's text.
    #[getter]
    fn urdf(&self) -> &str {
        &self.texts.urdf
    }

    /// The text of `robot.toml`.
    #[getter]
    fn description(&self) -> &str {
        &self.texts.description
    }

    /// The robot's name (URDF).
    #[getter]
    fn name(&self) -> &str {
        self.inner.name()
    }

    /// The robot folder it was loaded from, or None when built from texts (unpickled).
    #[getter]
    fn path(&self) -> Option<String> {
        self.dir.as_ref().map(|d| d.display().to_string())
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
            self.path()
        )
    }
}

/// A cable routing of a robot: the cables, their holes, stiffness and tension limits.
#[pyclass(module = "sinew", frozen)]
#[derive(Debug)]
pub struct Routing {
    pub(crate) inner: Arc<sinew::routing::Routing>,
    /// The file it was read from; None when built from a text (unpickled).
    pub(crate) file: Option<PathBuf>,
    /// The robot it was built for, the routing file's text and the name messages give it:
    /// what it pickles as.
    robot: Py<Robot>,
    text: String,
    name: String,
}

impl Routing {
    /// The routing of `text` for `robot`, named `name` in messages.
    fn from_text(robot: &Bound<'_, Robot>, text: String, name: String) -> PyResult<Routing> {
        let routing = sinew::routing::Routing::from_toml_str(&text, &name, &robot.get().inner)
            .map_err(library)?;
        Ok(Routing {
            inner: Arc::new(routing),
            file: None,
            robot: robot.clone().unbind(),
            text,
            name,
        })
    }
}

#[pymethods]
impl Routing {
    /// The routing of a routing file's text for `robot` (`name` names it in messages). What
    /// a pickled routing is rebuilt with.
    #[classmethod]
    #[pyo3(name = "from_text", signature = (robot, text, name = "cables.toml".to_owned()))]
    fn py_from_text(
        _class: &Bound<'_, PyType>,
        robot: &Bound<'_, Robot>,
        text: String,
        name: String,
    ) -> PyResult<Routing> {
        Routing::from_text(robot, text, name)
    }

    /// Pickling by value: `Routing.from_text(robot, text, name)`, the robot pickled as its
    /// texts and the routing file's text.
    fn __reduce__(&self, py: Python<'_>) -> PyResult<RoutingReduced> {
        let build = py.get_type::<Routing>().getattr("from_text")?.unbind();
        // The file's name only: a folder of the client's disk means nothing on a worker.
        let name = Path::new(&self.name)
            .file_name()
            .map_or_else(|| self.name.clone(), |n| n.to_string_lossy().into_owned());
        Ok((build, (self.robot.clone_ref(py), self.text.clone(), name)))
    }

    /// The robot it was built for.
    #[getter]
    fn robot(&self, py: Python<'_>) -> Py<Robot> {
        self.robot.clone_ref(py)
    }

    /// The routing file's text.
    #[getter]
    fn text(&self) -> &str {
        &self.text
    }

    /// The routing file it was read from, or None when built from a text (unpickled).
    #[getter]
    fn path(&self) -> Option<String> {
        self.file.as_ref().map(|f| f.display().to_string())
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
            self.path()
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
    let description_text = read_text(&description.path)?;
    if !description.urdf.is_file() {
        return Err(input(format!(
            "robot folder `{shown}` has no URDF: {} names `{}`, which does not exist",
            description.path.display(),
            description.urdf.display()
        )));
    }
    let urdf = read_text(&description.urdf)?;
    let name = description.urdf.display().to_string();
    let robot = sinew::robot::Robot::from_urdf_str(&urdf, &name, &description.settings).map_err(
        |e| match e {
            RobotError::NoSuchLink { .. } => {
                input(format!("{}: tip_link: {e}", description.path.display()))
            }
            e => library(e),
        },
    )?;
    let robot = if gravity { robot } else { robot.with_gravity(Vector3::zeros()) };
    let texts = RobotTexts { urdf, description: description_text, gravity };
    Ok(Robot { inner: Arc::new(robot), dir: Some(dir), texts })
}

/// A file's text, or the library's I/O error naming it.
fn read_text(path: &Path) -> PyResult<String> {
    std::fs::read_to_string(path)
        .map_err(|source| library(RobotError::Io { path: path.to_path_buf(), source }))
}

/// Load a routing of `robot`: a routing file's path, or `"decoupled"` / `"routed"` for the
/// robot folder's `cables.toml` / `cables-routed.toml`.
#[pyfunction]
#[pyo3(signature = (robot, path_or_model = "decoupled"))]
pub fn load_routing(robot: &Bound<'_, Robot>, path_or_model: &str) -> PyResult<Routing> {
    let in_folder = |name: &str| match &robot.get().dir {
        Some(dir) => Ok(dir.join(name)),
        None => Err(input(format!(
            "path_or_model: `{path_or_model}` names a file of the robot folder, and this robot was built from texts (unpickled): give the routing file's path, or use Routing.from_text"
        ))),
    };
    let file = match path_or_model {
        "decoupled" => in_folder(ROUTING_FILE)?,
        "routed" => in_folder(ROUTED_ROUTING_FILE)?,
        path if Path::new(path).is_dir() => Path::new(path).join(ROUTING_FILE),
        path => PathBuf::from(path),
    };
    if !file.is_file() {
        return Err(input(format!("routing file `{}` does not exist", file.display())));
    }
    let text = std::fs::read_to_string(&file).map_err(|source| {
        library(sinew::routing::RoutingError::Io { path: file.clone(), source })
    })?;
    let mut routing = Routing::from_text(robot, text, file.display().to_string())?;
    routing.file = Some(file);
    Ok(routing)
}
