//! `sinew.to_mjcf` (the MuJoCo model of a robot at a pose with its tensions, as text) and
//! `sinew.cable_geometry` (the cable lengths and `J_c` at a pose: what a simulator's tendons
//! are compared with).

use pyo3::prelude::*;
use sinew::robot::RobotData;
use sinew::routing::{Order, RoutingData, compute_cable_geometry};
use sinew_mjcf::{CableModel, MjcfOptions, Split, State};

use crate::convert::{vec1, vec2, vector};
use crate::errors::{exception, input, library};
use crate::model::{Robot, Routing};

/// The MJCF text of `robot` with `routing` at pose `q`, its cables holding it with `tensions`
/// (N, routing order) under the load `wrench` (F0, the wrench the tip exerts, base frame).
///
/// `cables`: "springs" (tendon stiffness K_l = E A / l_c and a spring length giving each
/// tension at the pose) or "motors" (tendons without stiffness pulled by motors, gear -1,
/// ctrl = the tensions in the keyframe `exported`). `split="segments"`: one spring per
/// segment between holes (springs only); with it, `segment_tensions` gives each segment its
/// own tension: per cable, the tensions from the actuator to the anchor (the free length
/// first, as `FrictionResult.segments[c]["tensions"]`: the stick regime after a pull or a
/// release). `damping`: every hinge's damping, N m s/rad.
/// The load is not in the model: apply -F0 at site `tip`. Conventions: crate sinew-mjcf.
#[pyfunction]
#[pyo3(signature = (robot, routing, q, tensions, wrench=None, *, cables="springs", split=None, damping=sinew_mjcf::DEFAULT_DAMPING, segment_tensions=None))]
#[allow(clippy::too_many_arguments)]
pub fn to_mjcf(
    robot: &Robot,
    routing: &Routing,
    q: &Bound<'_, PyAny>,
    tensions: &Bound<'_, PyAny>,
    wrench: Option<&Bound<'_, PyAny>>,
    cables: &str,
    split: Option<&str>,
    damping: f64,
    segment_tensions: Option<Vec<Bound<'_, PyAny>>>,
) -> PyResult<String> {
    let q = vector(q, "q", Some(robot.inner.dof()))?;
    let tensions = vector(tensions, "tensions", Some(routing.inner.cable_count()))?;
    let w = match wrench {
        Some(w) => vector(w, "wrench", Some(6))?,
        None => vec![0.0; 6],
    };
    let cables = match cables {
        "springs" => CableModel::Springs,
        "motors" => CableModel::Motors,
        other => return Err(input(format!("cables: `{other}` is not springs or motors"))),
    };
    let split = match split {
        None => Split::Cables,
        Some("segments") => Split::Segments,
        Some(other) => return Err(input(format!("split: `{other}` is not segments"))),
    };
    let options = MjcfOptions { cables, split, damping, ..MjcfOptions::default() };
    let segments = match segment_tensions {
        Some(per_cable) => Some(flat_segment_tensions(&routing.inner, &per_cable)?),
        None => None,
    };
    let state = State {
        q: &q,
        tensions: &tensions,
        wrench: [w[0], w[1], w[2], w[3], w[4], w[5]],
        segment_tensions: segments.as_deref(),
    };
    sinew_mjcf::to_mjcf(&robot.inner, &routing.inner, &state, &options).map_err(|e| match e {
        sinew_mjcf::MjcfError::Robot(e) => library(e),
        sinew_mjcf::MjcfError::Routing(e) => library(e),
        e => exception(e.kind(), e.to_string()),
    })
}

/// Per cable the tensions from the actuator to the anchor (free length first) as one tension
/// per routing segment, in the routing's segment order.
fn flat_segment_tensions(
    routing: &sinew::routing::Routing,
    per_cable: &[Bound<'_, PyAny>],
) -> PyResult<Vec<f64>> {
    let cables = routing.cables();
    if per_cable.len() != cables.len() {
        return Err(input(format!(
            "segment_tensions: expected {} arrays (one per cable), got {}",
            cables.len(),
            per_cable.len()
        )));
    }
    let mut out = vec![0.0; routing.segments().len()];
    for (cable, given) in cables.iter().zip(per_cable) {
        let n = cable.segments.len();
        let name = format!("segment_tensions of cable `{}`", cable.name);
        let t = vector(given, &name, Some(n + 1))?;
        out[cable.segments.clone()].copy_from_slice(&t[1..]);
    }
    Ok(out)
}

/// The cable lengths `L_c(q)` (m, routing order) and the cable Jacobian `J_c = ∂L/∂Q`
/// (cables × dof, eq. 2–3) at pose `q`, as `(lengths, j_c)`.
#[pyfunction]
pub fn cable_geometry<'py>(
    py: Python<'py>,
    robot: &Robot,
    routing: &Routing,
    q: &Bound<'py, PyAny>,
) -> PyResult<(Py<PyAny>, Py<PyAny>)> {
    let (robot, routing) = (&robot.inner, &routing.inner);
    let q = vector(q, "q", Some(robot.dof()))?;
    let mut robot_data = RobotData::new(robot);
    let mut data = RoutingData::new(routing);
    compute_cable_geometry(routing, robot, &mut robot_data, &mut data, &q, Order::Jacobian)
        .map_err(library)?;
    let lengths = vec1(py, data.lengths().map_err(library)?).into_any().unbind();
    let j = data.jacobian().map_err(library)?;
    let (m, n) = (j.nrows(), j.ncols());
    let rows: Vec<f64> = (0..m).flat_map(|r| (0..n).map(move |c| j[(r, c)])).collect();
    Ok((lengths, vec2(py, m, n, rows)?.into_any().unbind()))
}
