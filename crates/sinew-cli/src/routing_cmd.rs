//! `sinew routing`: the expanded cable routing and the robot's joints.

use serde::Serialize;
use sinew::routing::{RoutingModel, RoutingView};

use crate::cli::RoutingArgs;
use crate::error::CliError;
use crate::input::{Loaded, load};
use crate::output::{Fmt, Table, emit, print_json};

/// The JSON document of `sinew routing`: the robot's files and joints, then the library's
/// view of the routing ([`sinew::routing::Routing::view`], flattened: `robot`, `source`,
/// `model`, `youngs_modulus`, `area`, `tension_limits`, `cables`).
#[derive(Debug, Serialize)]
struct RoutingOut<'a> {
    command: &'static str,
    robot_dir: String,
    urdf: String,
    tip_link: &'a str,
    gravity: [f64; 3],
    routing_file: String,
    joints: Vec<JointOut<'a>>,
    #[serde(flatten)]
    routing: RoutingView<'a>,
}

/// A revolute joint.
#[derive(Debug, Serialize)]
struct JointOut<'a> {
    /// Index in Q, 0-based.
    index: usize,
    name: &'a str,
    /// The arm joint it belongs to (a universal joint or a 1-DOF joint), 0-based.
    universal_joint: usize,
    /// Its place in that joint, from 1; 0 for a 1-DOF joint (the table's `q` names).
    #[serde(skip)]
    position: usize,
    /// Unit axis in the joint frame.
    axis: [f64; 3],
    lower: f64,
    upper: f64,
}

/// Run `sinew routing`.
pub fn run(args: &RoutingArgs) -> Result<(), CliError> {
    let loaded = load(&args.common.robot, args.common.model, false)?;
    let out = document(&loaded);
    if args.common.json { print_json(&out) } else { emit(&render(&out)) }
}

fn document(loaded: &Loaded) -> RoutingOut<'_> {
    let Loaded { description, robot, routing, routing_file } = loaded;
    let g = robot.gravity();
    RoutingOut {
        command: "routing",
        robot_dir: description.dir.display().to_string(),
        urdf: description.urdf.display().to_string(),
        tip_link: &description.settings.tip_link,
        gravity: [g.x, g.y, g.z],
        routing_file: routing_file.display().to_string(),
        joints: robot
            .joints()
            .iter()
            .enumerate()
            .map(|(index, j)| JointOut {
                index,
                name: &j.name,
                // The arm joint (robot.joint_groups(): a universal pair or a 1-DOF joint), not
                // index / 2: a chain of 1-DOF joints is not one of pairs.
                universal_joint: robot.joint_of_dof(index).unwrap_or(index),
                position: robot
                    .joint_groups()
                    .iter()
                    .find(|g| g.contains(&index))
                    .map_or(0, |g| if g.len() == 1 { 0 } else { index - g.start + 1 }),
                axis: [j.axis.x, j.axis.y, j.axis.z],
                lower: j.lower,
                upper: j.upper,
            })
            .collect(),
        routing: routing.view(),
    }
}

fn render(out: &RoutingOut<'_>) -> String {
    let mut s = String::new();
    let model = match out.routing.model {
        RoutingModel::Decoupled => "decoupled",
        RoutingModel::Routed => "routed",
        RoutingModel::Explicit => "explicit (hole by hole)",
    };
    s.push_str(&format!(
        "robot `{}`: {}\n  tip link `{}`, gravity {} m/s² (base frame)\n",
        out.routing.robot,
        out.urdf,
        out.tip_link,
        Fmt::Fixed(3).list(&out.gravity)
    ));
    s.push_str(&format!(
        "routing: {} ({model}), {} cables\n  E = {} Pa, A = {} m², tensions in [{}, {}] N\n\n",
        out.routing_file,
        out.routing.cables.len(),
        Fmt::Sci(4).num(out.routing.youngs_modulus),
        Fmt::Sci(4).num(out.routing.area),
        out.routing.tension_limits[0],
        out.routing.tension_limits[1]
    ));
    s.push_str("Revolute joints, base first (arm joints numbered from 1: universal or 1-DOF), limits in rad:\n");
    let mut joints = Table::new(&["q", "name", "joint", "axis", "lower", "upper"]).left(&[1]);
    for j in &out.joints {
        joints.row(vec![
            if j.position == 0 {
                format!("q{}", j.universal_joint + 1)
            } else {
                format!("q{}{}", j.universal_joint + 1, j.position)
            },
            j.name.to_owned(),
            format!("{}", j.universal_joint + 1),
            Fmt::Fixed(3).list(&j.axis),
            Fmt::Fixed(5).num(j.lower),
            Fmt::Fixed(5).num(j.upper),
        ]);
    }
    s.push_str(&joints.render(2));
    s.push_str(
        "\nCables (joint numbered from 1; holes base first, points in m in the hole's link frame):\n",
    );
    let mut cables =
        Table::new(&["cable", "joint", "k = EA/l (N/m)", "l (m)", "hole", "link", "x", "y", "z"])
            .left(&[5]);
    for c in &out.routing.cables {
        for (k, h) in c.holes.iter().enumerate() {
            let mut cells = if k == 0 {
                vec![
                    c.name.to_owned(),
                    format!("{}", c.joint + 1),
                    Fmt::Fixed(2).num(c.stiffness),
                    Fmt::Fixed(4).num(c.elastic_length),
                ]
            } else {
                vec![String::new(); 4]
            };
            cells.push(format!("{}", k + 1));
            cells.push(h.link.to_owned());
            cells.extend(h.point.iter().map(|&x| Fmt::Fixed(6).num(x)));
            cables.row(cells);
        }
    }
    s.push_str(&cables.render(2));
    s
}
