//! Rendering the model: the decisions of `tree.rs` and the checked state of `lib.rs` as MJCF
//! text.

use std::fmt::Write as _;

use sinew_robot::Robot;
use sinew_routing::Routing;

use crate::tree::{MIN_INERTIA, MIN_MASS, MjBody, full_inertia};
use crate::xml::{attr, comment, frame, num, nums, vec3};
use crate::{CableModel, MjcfOptions, Split, State};

/// The lengths at the exported pose that the writer needs.
#[derive(Debug)]
pub(crate) struct AtPose<'a> {
    /// `L_c(q)`, m, per cable.
    pub lengths: &'a [f64],
    /// `ℓ_s(q)`, m, per segment ([`Routing::segments`]).
    pub segment_lengths: &'a [f64],
}

/// One tendon: its name, sites, stiffness and spring length (springs) and the tension it
/// carries at the pose.
struct Tendon {
    name: String,
    sites: Vec<String>,
    spring: Option<(f64, f64)>,
    tension: f64,
}

/// A spring of stiffness `k` whose tension at length `l` is `f`: `L_u = l − f/k`, written
/// `"0 L_u"` (no force below `L_u`: a slack cable pushes nothing) when `L_u ≥ 0`, else
/// `"L_u L_u"` (MuJoCo refuses a dead band `[0, L_u]` with `L_u < 0`; a length never falls
/// below a negative `L_u`, so that spring only pulls too). `-1` exactly is MuJoCo's "compute
/// at qpos_spring": the next float below is written instead.
pub(crate) fn spring_length(l: f64, f: f64, k: f64) -> [f64; 2] {
    let mut rest = l - f / k;
    if rest == -1.0 {
        rest = f64::from_bits((-1.0f64).to_bits() + 1);
    }
    if rest >= 0.0 { [0.0, rest] } else { [rest, rest] }
}

fn site_name(cable: &str, hole: usize) -> String {
    format!("{cable}_h{hole}")
}

fn tendons(routing: &Routing, state: &State<'_>, at: &AtPose<'_>, o: &MjcfOptions) -> Vec<Tendon> {
    let mut out = Vec::new();
    for (c, cable) in routing.cables().iter().enumerate() {
        let f = state.tensions[c];
        let sites: Vec<String> =
            (0..cable.holes.len()).map(|h| site_name(&cable.name, h)).collect();
        match (o.cables, o.split) {
            (CableModel::Motors, _) => {
                out.push(Tendon { name: cable.name.clone(), sites, spring: None, tension: f })
            }
            (CableModel::Springs, Split::Cables) => out.push(Tendon {
                name: cable.name.clone(),
                sites,
                spring: Some((cable.stiffness, at.lengths[c])),
                tension: f,
            }),
            (CableModel::Springs, Split::Segments) => {
                // E·A of this cable (k_c l_c, eq. 13), each segment a spring E·A/ℓ_s(q).
                let ea = cable.stiffness * cable.elastic_length;
                for s in cable.segments.clone() {
                    let i = routing.segments()[s].index;
                    let l = at.segment_lengths[s];
                    out.push(Tendon {
                        name: format!("{}_s{i}", cable.name),
                        sites: vec![sites[i].clone(), sites[i + 1].clone()],
                        spring: Some((ea / l, l)),
                        tension: state.segment_tensions.map_or(f, |t| t[s]),
                    });
                }
            }
        }
    }
    out
}

/// The whole file.
pub(crate) fn document(
    robot: &Robot,
    routing: &Routing,
    tree: &[MjBody],
    state: &State<'_>,
    at: &AtPose<'_>,
    o: &MjcfOptions,
) -> String {
    let mut s = String::new();
    let g = robot.gravity();
    let model = match o.cables {
        CableModel::Springs => match o.split {
            Split::Cables => "springs (one tendon per cable)",
            Split::Segments => "springs, one tendon per segment between holes (stick model)",
        },
        CableModel::Motors => "motors (tendons without stiffness, driven by the tensions)",
    };
    let _ = writeln!(s, "<mujoco model=\"{}\">", attr(robot.name()));
    for line in [
        format!("Written by sinew-mjcf from robot `{}` ({}), routing {}.", robot.name(), robot.source(), routing.source()),
        format!("Cables: {model}."),
        format!("Exported pose q (rad) = {}; tensions (N, routing order) = {}.", nums(state.q), nums(state.tensions)),
        format!("F0 (the wrench the tip exerts, base frame, N and N m) = {}: apply -F0 at site `tip` (mj_applyFT, world frame) to hold the pose.", nums(&state.wrench)),
        "Spring cables: stiffness = K_l = E A / l_c (l_c the elastic length: free length plus routed length at Q = 0, eq. 13); springlength L_u = L_c(q) - f/K_l so the tension at the exported pose is f.".to_owned(),
        format!("Joint damping {} N m s/rad on every hinge (a stated choice so a simulation settles; not part of the stiffness model).", num(o.damping)),
    ] {
        let _ = writeln!(s, "  {}", comment(&line));
    }
    let _ =
        writeln!(s, "  <compiler angle=\"radian\" autolimits=\"true\" inertiafromgeom=\"false\"/>");
    let _ = writeln!(
        s,
        "  <option gravity=\"{}\" timestep=\"{}\" integrator=\"implicitfast\"/>",
        vec3(&g),
        num(o.timestep)
    );
    let _ = writeln!(s, "  <default>");
    let _ = writeln!(s, "    <geom contype=\"0\" conaffinity=\"0\" rgba=\"0.7 0.7 0.75 1\"/>");
    let _ = writeln!(s, "    <site size=\"0.002\" rgba=\"0.9 0.3 0.2 1\"/>");
    let _ = writeln!(s, "    <tendon width=\"0.001\" rgba=\"0.2 0.4 0.9 1\"/>");
    let _ = writeln!(s, "  </default>");
    let _ = writeln!(s, "  <worldbody>");
    sites(&mut s, robot, routing, 0, 2);
    for (depth, mj) in tree.iter().enumerate() {
        open_body(&mut s, robot, tree, depth, mj, o);
        sites(&mut s, robot, routing, mj.body, depth + 3);
    }
    for depth in (0..tree.len()).rev() {
        let _ = writeln!(s, "{}</body>", "  ".repeat(depth + 2));
    }
    let _ = writeln!(s, "  </worldbody>");
    let tendons = tendons(routing, state, at, o);
    let _ = writeln!(s, "  <tendon>");
    for t in &tendons {
        let spring = match t.spring {
            Some((k, l)) => {
                let [lo, hi] = spring_length(l, t.tension, k);
                let _ = writeln!(
                    s,
                    "    {}",
                    comment(&format!(
                        "{}: f = {} N at length {} m, K = {} N/m",
                        t.name,
                        num(t.tension),
                        num(l),
                        num(k)
                    ))
                );
                format!(" stiffness=\"{}\" springlength=\"{}\"", num(k), nums(&[lo, hi]))
            }
            None => String::new(),
        };
        let _ = writeln!(s, "    <spatial name=\"{}\"{spring}>", attr(&t.name));
        for site in &t.sites {
            let _ = writeln!(s, "      <site site=\"{}\"/>", attr(site));
        }
        let _ = writeln!(s, "    </spatial>");
    }
    let _ = writeln!(s, "  </tendon>");
    if o.cables == CableModel::Motors {
        let _ = writeln!(
            s,
            "  {}",
            comment("gear -1: a positive ctrl pulls (shortens the tendon) with that tension, N.")
        );
        let _ = writeln!(s, "  <actuator>");
        for (c, cable) in routing.cables().iter().enumerate() {
            let [lo, hi] = routing.cable_limits()[c];
            let _ = writeln!(
                s,
                "    <motor name=\"{}\" tendon=\"{}\" gear=\"-1\" ctrlrange=\"{}\"/>",
                attr(&format!("{}_motor", cable.name)),
                attr(&cable.name),
                nums(&[lo, hi])
            );
        }
        let _ = writeln!(s, "  </actuator>");
    }
    let _ = writeln!(s, "  <sensor>");
    for t in &tendons {
        let _ = writeln!(
            s,
            "    <tendonpos name=\"{}\" tendon=\"{}\"/>",
            attr(&format!("{}_length", t.name)),
            attr(&t.name)
        );
    }
    if o.cables == CableModel::Motors {
        for cable in routing.cables() {
            let _ = writeln!(
                s,
                "    <actuatorfrc name=\"{}\" actuator=\"{}\"/>",
                attr(&format!("{}_force", cable.name)),
                attr(&format!("{}_motor", cable.name))
            );
        }
    }
    let _ = writeln!(s, "  </sensor>");
    let _ = writeln!(s, "  <custom>");
    let _ = writeln!(s, "    <numeric name=\"sinew_wrench\" data=\"{}\"/>", nums(&state.wrench));
    let _ = writeln!(s, "    <numeric name=\"sinew_tensions\" data=\"{}\"/>", nums(state.tensions));
    let _ = writeln!(s, "  </custom>");
    let _ = writeln!(s, "  <keyframe>");
    let ctrl = match o.cables {
        CableModel::Motors => format!(" ctrl=\"{}\"", nums(state.tensions)),
        CableModel::Springs => String::new(),
    };
    let _ = writeln!(s, "    <key name=\"exported\" qpos=\"{}\"{ctrl}/>", nums(state.q));
    let _ = writeln!(s, "  </keyframe>");
    let _ = writeln!(s, "</mujoco>");
    s
}

/// `<body …>` with its inertial, hinges and a capsule to the next body (or the tip).
fn open_body(
    s: &mut String,
    robot: &Robot,
    tree: &[MjBody],
    depth: usize,
    mj: &MjBody,
    o: &MjcfOptions,
) {
    let pad = "  ".repeat(depth + 2);
    let inner = "  ".repeat(depth + 3);
    let b = &robot.bodies()[mj.body];
    let _ = writeln!(s, "{pad}<body name=\"{}\"{}>", attr(&b.name), frame(&mj.parent_m_body));
    if !mj.merged.is_empty() {
        let names: Vec<&str> = mj.merged.iter().map(|&m| robot.bodies()[m].name.as_str()).collect();
        let line = format!(
            "the massless link(s) {} (no hole, no tip) merged into this body: their joint is the first hinge",
            names.join(", ")
        );
        let _ = writeln!(s, "{inner}{}", comment(&line));
    }
    if mj.min_mass {
        let line = format!(
            "massless in the URDF but carries holes or the tip: given {} kg, {} kg m², the least MuJoCo accepts with margin (mjMINVAL = 1e-15)",
            num(MIN_MASS),
            num(MIN_INERTIA)
        );
        let _ = writeln!(s, "{inner}{}", comment(&line));
        let _ = writeln!(
            s,
            "{inner}<inertial pos=\"0 0 0\" mass=\"{}\" diaginertia=\"{}\"/>",
            num(MIN_MASS),
            nums(&[MIN_INERTIA; 3])
        );
    } else {
        let _ = writeln!(
            s,
            "{inner}<inertial pos=\"{}\" mass=\"{}\" fullinertia=\"{}\"/>",
            vec3(&b.com),
            num(b.mass),
            nums(&full_inertia(&b.inertia))
        );
    }
    for h in &mj.hinges {
        let j = &robot.joints()[h.joint];
        let range = if j.lower.is_finite() && j.upper.is_finite() {
            format!(" range=\"{}\"", nums(&[j.lower, j.upper]))
        } else {
            String::new()
        };
        let pos = if h.pos == nalgebra::Vector3::zeros() {
            String::new()
        } else {
            format!(" pos=\"{}\"", vec3(&h.pos))
        };
        let _ = writeln!(
            s,
            "{inner}<joint name=\"{}\" type=\"hinge\"{pos} axis=\"{}\"{range} damping=\"{}\"/>",
            attr(&j.name),
            vec3(&h.axis),
            num(o.damping)
        );
    }
    // A capsule along the link, to the next body's first hinge (or to the tip): to see it.
    let end = match tree.get(depth + 1) {
        Some(next) => {
            next.parent_m_body
                * nalgebra::Point3::from(
                    next.hinges.first().map_or_else(nalgebra::Vector3::zeros, |h| h.pos),
                )
        }
        None => nalgebra::Point3::from(robot.tip_point().point),
    };
    let length = end.coords.norm();
    if length > 1e-9 {
        let radius = (0.08 * length).clamp(1e-3, 0.03);
        let _ = writeln!(
            s,
            "{inner}<geom type=\"capsule\" fromto=\"0 0 0 {}\" size=\"{}\" mass=\"0\"/>",
            vec3(&end.coords),
            num(radius)
        );
    } else {
        let _ = writeln!(s, "{inner}<geom type=\"sphere\" size=\"0.005\" mass=\"0\"/>");
    }
}

/// The sites on robot body `body`: one per hole of every cable, and the tip.
fn sites(s: &mut String, robot: &Robot, routing: &Routing, body: usize, depth: usize) {
    let pad = "  ".repeat(depth);
    for cable in routing.cables() {
        for (h, hole) in cable.holes.iter().enumerate() {
            if hole.body_point.body == body {
                let _ = writeln!(
                    s,
                    "{pad}<site name=\"{}\" pos=\"{}\"/>",
                    attr(&site_name(&cable.name, h)),
                    vec3(&hole.body_point.point)
                );
            }
        }
    }
    let tip = robot.tip_point();
    if tip.body == body {
        let _ = writeln!(s, "{pad}<site name=\"tip\" pos=\"{}\"/>", vec3(&tip.point));
    }
}

#[cfg(test)]
mod tests {
    use super::spring_length;

    #[test]
    fn the_spring_length_gives_the_tension_and_never_pushes() {
        // L_u = 0.03 − 20/3027 > 0: the dead band [0, L_u].
        let [lo, hi] = spring_length(0.03, 20.0, 3027.0);
        assert_eq!(lo, 0.0);
        assert!((3027.0 * (0.03 - hi) - 20.0).abs() < 1e-12);
        // 300 N on the same crossing: L_u < 0, written L_u L_u.
        let [lo, hi] = spring_length(0.03, 300.0, 3027.0);
        assert!(lo < 0.0 && lo == hi);
        assert!((3027.0 * (0.03 - hi) - 300.0).abs() < 1e-12);
        // Exactly −1 is MuJoCo's "compute it": the next float below instead.
        let [lo, hi] = spring_length(1.0, 2.0, 1.0);
        assert!(lo == hi && lo < -1.0 && lo > -1.0 - 1e-15);
    }
}
