//! `sinew joint`: one universal joint alone, its feasible tension interval and stiffness range.

use serde::Serialize;
use sinew::indicators::{Indicator, JointProbe};

use crate::cli::JointArgs;
use crate::error::{CliError, library_error};
use crate::input::{joint, load, numbers_n, to_radians};
use crate::output::{Fmt, Rows, Table, emit, na_rows, na_vec, print_json};

/// The JSON document of `sinew joint`.
#[derive(Debug, Serialize)]
struct JointOut {
    command: &'static str,
    robot: String,
    routing_file: String,
    model: &'static str,
    /// 0-based.
    joint: usize,
    /// Names of the joint's own three cables (the order of every tension vector): the only
    /// cables with tension (every other cable at zero), so the only ones in the controllable
    /// part `Σ f_c H_c`.
    cables: Vec<String>,
    /// The cables in the inherent part `J_cᵀ K_l J_c`: every cable crossing the joint (the
    /// same three when decoupled; routed, also the distal joints' cables, elastic at zero
    /// tension).
    inherent_cables: Vec<String>,
    /// The joint's two revolute joints (URDF names and unit axes): `q`, `torque` and the
    /// rows/columns of every 2 × 2 matrix are about the first then the second; `sigma_x` and
    /// `sigma_y` (the paper's names) are the first and the second axis.
    axes: [AxisOut; 2],
    q: [f64; 2],
    torque: [f64; 2],
    tension_limits: [f64; 2],
    /// `[λ_min, λ_max]`.
    lambda: [f64; 2],
    /// `f_p`, the minimum-norm tensions (N).
    particular: Vec<f64>,
    /// `n`, the unit null direction of `J_cᵀ` (components summing to ≥ 0; every component
    /// positive in force closure).
    null_direction: Vec<f64>,
    /// Whether the joint's cables are in force closure at this pose (`n` strictly positive):
    /// a property reported, not required; without it the interval may still be non-empty.
    force_closure: bool,
    /// `[f(λ_min), f(λ_max)]`, N.
    tensions: [Vec<f64>; 2],
    /// `[at λ_min, at λ_max]`, 2 × 2 each, N m/rad.
    k_controllable: [Rows; 2],
    k_inherent: [Rows; 2],
    k: [Rows; 2],
    /// `[[K_min, K_max], Δk]`, N m/rad.
    sigma_x: ([f64; 2], f64),
    sigma_y: ([f64; 2], f64),
}

/// One of a universal joint's two revolute joints.
#[derive(Debug, Serialize)]
pub struct AxisOut {
    /// The URDF joint's name.
    pub name: String,
    /// Its unit axis, in its joint frame.
    pub axis: [f64; 3],
}

/// The two axes of universal joint `i` (0-based, checked).
pub fn axes(robot: &sinew::robot::Robot, i: usize) -> [AxisOut; 2] {
    let axis = |k: usize| {
        let j = &robot.joints()[k];
        AxisOut { name: j.name.clone(), axis: [j.axis.x, j.axis.y, j.axis.z] }
    };
    [axis(2 * i), axis(2 * i + 1)]
}

fn sigma(i: Indicator) -> ([f64; 2], f64) {
    (i.range, i.delta)
}

/// Run `sinew joint`.
pub fn run(args: &JointArgs) -> Result<(), CliError> {
    let loaded = load(&args.common.robot, args.common.model, false)?;
    let (robot, routing) = (&loaded.robot, &loaded.routing);
    let i = joint(&args.joint, robot)?;
    // The library says whether the robot has this joint (and whether it has three cables).
    let mut probe = JointProbe::new(robot, routing, i).map_err(library_error)?;
    let mut q = numbers_n("--q", &args.q, 2, "angles (about the joint's first and second axis)")?;
    to_radians(&mut q, args.deg);
    let tau = numbers_n("--torque", &args.torque, 2, "torque components (T1,T2 in N m)")?;
    // Angles outside the limits are the library's to refuse (`--q: joint … outside its limits`).
    let range =
        probe.evaluate(robot, routing, [q[0], q[1]], [tau[0], tau[1]]).map_err(library_error)?;
    let names = |cables: &[usize]| -> Vec<String> {
        cables.iter().map(|&c| routing.cables()[c].name.clone()).collect()
    };
    let cables: Vec<String> = names(&probe.tensioned_cables().collect::<Vec<_>>());
    let interval = &range.interval;
    let (f_lo, f_hi) = interval.ends();
    let out = JointOut {
        command: "joint",
        robot: robot.name().to_owned(),
        routing_file: loaded.routing_file.display().to_string(),
        model: args.common.model.name(),
        joint: i,
        inherent_cables: names(probe.inherent_cables()),
        cables,
        axes: axes(robot, i),
        q: [q[0], q[1]],
        torque: [tau[0], tau[1]],
        tension_limits: routing.tension_limits(),
        lambda: [interval.lambda_min, interval.lambda_max],
        particular: na_vec(&interval.particular),
        null_direction: na_vec(&interval.null),
        force_closure: interval.force_closure(),
        tensions: [na_vec(&f_lo), na_vec(&f_hi)],
        k_controllable: [na_rows(&range.controllable[0]), na_rows(&range.controllable[1])],
        k_inherent: [na_rows(&range.inherent), na_rows(&range.inherent)],
        k: [na_rows(&range.k_at_min), na_rows(&range.k_at_max)],
        sigma_x: sigma(range.sigma_x()),
        sigma_y: sigma(range.sigma_y()),
    };
    if args.common.json { print_json(&out) } else { emit(&render(&out)) }
}

fn render(out: &JointOut) -> String {
    let mut s = String::new();
    s.push_str(&format!(
        "joint {} of `{}` alone ({}: {}), the other joints at 0\n",
        out.joint + 1,
        out.robot,
        out.model,
        out.routing_file
    ));
    s.push_str(&format!(
        "  axes: x = first `{}` {}, y = second `{}` {}\n",
        out.axes[0].name,
        Fmt::Fixed(3).list(&out.axes[0].axis),
        out.axes[1].name,
        Fmt::Fixed(3).list(&out.axes[1].axis)
    ));
    s.push_str(&format!(
        "  tension in {} only (the other cables at 0); inherent stiffness of {}\n",
        out.cables.join(", "),
        out.inherent_cables.join(", ")
    ));
    s.push_str(&format!(
        "  q = {} rad, torque = {} N m, tensions in [{}, {}] N\n\n",
        Fmt::Fixed(5).list(&out.q),
        Fmt::Fixed(4).list(&out.torque),
        out.tension_limits[0],
        out.tension_limits[1]
    ));
    if !out.force_closure {
        s.push_str(
            "  not in force closure at this pose (n has a component ≤ 0): some tension slackens as others rise\n\n",
        );
    }
    s.push_str("Feasible tensions f = f_p + λ n, λ ∈ [λ_min, λ_max] (N):\n");
    let mut header = vec!["".to_owned(), "λ".to_owned()];
    header.extend(out.cables.iter().map(|c| format!("f {c}")));
    let mut t = Table::new(&header);
    for (label, lambda, f) in [
        ("λ_min (least tension)", out.lambda[0], &out.tensions[0]),
        ("λ_max (most tension)", out.lambda[1], &out.tensions[1]),
    ] {
        let mut row = vec![label.to_owned(), Fmt::Fixed(3).num(lambda)];
        row.extend(f.iter().map(|&x| Fmt::Fixed(3).num(x)));
        t.row(row);
    }
    s.push_str(&t.render(2));
    s.push_str("\nJoint stiffness K = controllable + inherent (N m/rad, rows/columns first, second axis):\n");
    let mut t = Table::new(&["", "controllable", "", "inherent", "", "K", ""]);
    for (end, label) in ["at λ_min", "at λ_max"].iter().enumerate() {
        for r in 0..2 {
            let mut row = vec![if r == 0 { (*label).to_owned() } else { String::new() }];
            for m in [&out.k_controllable[end], &out.k_inherent[end], &out.k[end]] {
                row.extend(m[r].iter().map(|&x| Fmt::Fixed(4).num(x)));
            }
            t.row(row);
        }
    }
    s.push_str(&t.render(2));
    s.push_str("\nIndicators (eq. 20), N m/rad:\n");
    let mut t = Table::new(&["", "K min", "K max", "Δk"]);
    for (label, (range, delta)) in [("σ_x", out.sigma_x), ("σ_y", out.sigma_y)] {
        t.row(vec![
            label.to_owned(),
            Fmt::Fixed(4).num(range[0]),
            Fmt::Fixed(4).num(range[1]),
            Fmt::Fixed(4).num(delta),
        ]);
    }
    s.push_str(&t.render(2));
    s
}
