//! `sinew joint`: one universal joint alone, its feasible tension interval and stiffness range.

use serde::Serialize;
use sinew::indicators::{Indicator, JointProbe};

use crate::cli::JointArgs;
use crate::error::{CliError, model_error};
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
    /// Names of the joint's three cables (the order of every tension vector).
    cables: Vec<String>,
    q: [f64; 2],
    torque: [f64; 2],
    tension_limits: [f64; 2],
    /// `[λ_min, λ_max]`.
    lambda: [f64; 2],
    /// `f_p`, the minimum-norm tensions (N).
    particular: Vec<f64>,
    /// `n`, the unit null direction of `J_cᵀ` (every component positive).
    null_direction: Vec<f64>,
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

fn sigma(i: Indicator) -> ([f64; 2], f64) {
    (i.range, i.delta)
}

/// Run `sinew joint`.
pub fn run(args: &JointArgs) -> Result<(), CliError> {
    let loaded = load(&args.common.robot, args.common.model, false)?;
    let (robot, routing) = (&loaded.robot, &loaded.routing);
    let i = joint(&args.joint, robot)?;
    let mut q = numbers_n("--q", &args.q, 2, "angles (the joint's q_x,q_y)")?;
    to_radians(&mut q, args.deg);
    let tau = numbers_n("--torque", &args.torque, 2, "torque components (T1,T2 in N m)")?;
    // The other joints stay at zero: check the full configuration for a clear message.
    let mut full = vec![0.0; robot.dof()];
    full[2 * i] = q[0];
    full[2 * i + 1] = q[1];
    crate::input::check_limits(robot, &full)?;
    let mut probe = JointProbe::new(robot, routing, i).map_err(CliError::input)?;
    let range =
        probe.evaluate(robot, routing, [q[0], q[1]], [tau[0], tau[1]]).map_err(model_error)?;
    let cables: Vec<String> =
        routing.cables().iter().filter(|c| c.joint == i).map(|c| c.name.clone()).collect();
    let interval = &range.interval;
    let (f_lo, f_hi) = interval.ends();
    let out = JointOut {
        command: "joint",
        robot: robot.name().to_owned(),
        routing_file: loaded.routing_file.display().to_string(),
        model: args.common.model.name(),
        joint: i,
        cables,
        q: [q[0], q[1]],
        torque: [tau[0], tau[1]],
        tension_limits: routing.tension_limits(),
        lambda: [interval.lambda_min, interval.lambda_max],
        particular: na_vec(&interval.particular),
        null_direction: na_vec(&interval.null),
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
        "joint {} of `{}` alone ({}: {}), the other joints at 0 with slack cables\n",
        out.joint + 1,
        out.robot,
        out.model,
        out.routing_file
    ));
    s.push_str(&format!(
        "  q = {} rad, torque = {} N m, tensions in [{}, {}] N\n\n",
        Fmt::Fixed(5).list(&out.q),
        Fmt::Fixed(4).list(&out.torque),
        out.tension_limits[0],
        out.tension_limits[1]
    ));
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
    s.push_str("\nJoint stiffness K = controllable + inherent (N m/rad, rows/columns x, y):\n");
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
