//! `sinew arm`: the whole arm in a pose under a load (eq. 5–21).

use nalgebra::Vector6;
use serde::Serialize;
use sinew::statics::{Chosen, DEFAULT_POLICY_NOTE};
use sinew::stiffness::{ArmStiffness, ArmStiffnessData};

use crate::arm_friction::{requested, run as run_with_friction};
use crate::cli::ArmArgs;
use crate::error::{CliError, library_error};
use crate::input::{levels, load, pose, tension_choice, wrench};
use crate::output::{
    Fmt, Rows, Table, cartesian_labels, emit, faer_rows, matrix, na_rows, na_vec, print_json,
    q_labels,
};

/// The JSON document of `sinew arm`.
#[derive(Debug, Serialize)]
struct ArmOut {
    command: &'static str,
    robot: String,
    routing_file: String,
    model: &'static str,
    gravity: [f64; 3],
    q: Vec<f64>,
    wrench: Vec<f64>,
    /// `levels` (the closed form) or a policy's name.
    policy: &'static str,
    /// Null when a policy chose the tensions.
    levels: Option<Vec<f64>>,
    /// The policy's objective: Σ f (N), |f| (N) or the least distance to a limit (N); null
    /// with levels.
    policy_objective: Option<f64>,
    /// The convex solver's interior-point iterations (null with levels).
    policy_iterations: Option<u32>,
    /// Whether some strictly positive tension vector balances no load (every torque reachable
    /// with high enough tensions): a property of the pose and routing, reported.
    force_closure: bool,
    /// The dimension of the equilibrium set `f = f_p + N λ` (cables − rank of J_c).
    null_space_dimension: usize,
    cables: Vec<String>,
    t0: Vec<f64>,
    tensions: Vec<f64>,
    intervals: Vec<IntervalOut>,
    k_controllable: Rows,
    k_inherent: Rows,
    k_q: Rows,
    k_w: Rows,
    j_x: Rows,
    stable: bool,
    min_eigenvalue: f64,
    c_x: Option<Rows>,
    k_x: Option<Rows>,
    k_fd: Option<Rows>,
    k_translational: Option<Rows>,
    ellipsoid: Option<EllipsoidOut>,
    notes: Vec<String>,
}

/// One universal joint's feasible tension interval and stiffness in the arm.
#[derive(Debug, Serialize)]
struct IntervalOut {
    /// 0-based.
    joint: usize,
    /// `[λ_min, λ_max]`.
    lambda: [f64; 2],
    /// The requested level `s`.
    level: f64,
    /// `λ = λ_min + s (λ_max − λ_min)`.
    lambda_at_level: f64,
    /// The joint's own cables' tensions at `λ_min` and `λ_max`, N.
    tensions_at_ends: [Vec<f64>; 2],
    /// The joint's 2 × 2 block of `K_q`, N m/rad (`K_{i,x}`, `K_{i,y}` on the diagonal).
    k_joint: Rows,
}

/// The stiffness ellipsoid of `K_fd`.
#[derive(Debug, Serialize)]
struct EllipsoidOut {
    /// Ascending, N/m.
    eigenvalues: Vec<f64>,
    /// `directions[k]`: unit principal direction of `eigenvalues[k]` (base frame).
    directions: Rows,
    /// `1/λ_k`, m/N (null unless `K_fd` is positive definite).
    semi_axes: Option<Vec<f64>>,
    condition_number: Option<f64>,
    /// `4π/3 · Π 1/λ_k`, m³/N³.
    volume: Option<f64>,
    lambda_min: f64,
}

/// Run `sinew arm`.
pub fn run(args: &ArmArgs) -> Result<(), CliError> {
    let loaded = load(&args.common.robot, args.common.model, args.no_gravity)?;
    if let Some(friction) = requested(args.friction.asked(), &loaded.routing)? {
        return run_with_friction(args, &loaded, friction);
    }
    let (robot, routing) = (&loaded.robot, &loaded.routing);
    let joints = robot.joint_count();
    let q = pose(&args.q, args.deg, robot)?;
    let wrench = wrench(args.wrench.as_deref())?;
    let arm = ArmStiffness::new(robot, routing).map_err(library_error)?.checking_limits();
    let mut data = ArmStiffnessData::new(&arm);
    let f0 = Vector6::from_column_slice(&wrench);
    // The pose stage (angles outside the limits refused, `--q: …`), once.
    arm.set_pose(&mut data, &q, &f0).map_err(library_error)?;
    let levels = levels(&args.tensions, joints)?;
    let choice = tension_choice(levels.as_deref(), &args.tensions);
    let by_default = levels.is_none() && args.tensions.policy.is_none();
    arm.set_tensions(&mut data, choice).map_err(library_error)?;
    let chosen = data.statics.chosen();
    // The default in closed form is every joint at level 0.
    let levels = match chosen {
        Chosen::Levels => Some(levels.clone().unwrap_or_else(|| vec![0.0; joints])),
        _ => None,
    };
    let mut notes = Vec::new();
    if by_default && chosen != Chosen::Levels {
        notes.push(DEFAULT_POLICY_NOTE.to_owned());
    }
    arm.solve_end(&mut data).map_err(library_error)?;
    let outcome = data.outcome().ok_or_else(|| CliError::model("no end stage"))?;
    let stable = outcome.is_stable();
    notes.extend(outcome.notes().map_err(library_error)?.iter().map(|n| n.text("null")));
    let min_eigenvalue = outcome.margin().map_err(library_error)?;
    let c_x = outcome.compliance().map(faer_rows);
    let k_translational = outcome.translational_stiffness();
    let ellipsoid = outcome.ellipsoid().map_err(library_error)?.map(|e| EllipsoidOut {
        eigenvalues: na_vec(&e.eigenvalues),
        directions: na_rows(&e.directions.transpose()),
        semi_axes: e.semi_axes().map(|a| na_vec(&a)),
        condition_number: e.condition_number(),
        volume: e.volume(),
        lambda_min: e.lambda_min(),
    });
    let k_x = outcome.stiffness().map(faer_rows);
    let k_fd = outcome.k_fd().map(|k| na_rows(&k));
    let cables: Vec<String> = routing.cables().iter().map(|c| c.name.clone()).collect();
    let set = arm.equilibrium_set(&mut data).map_err(library_error)?;
    let force_closure = set.force_closure().map_err(library_error)?;
    let null_space_dimension = set.dimension();
    let policy_objective = data.statics.distribution.as_ref().map(|d| d.objective);
    let level_list = levels.clone().unwrap_or_default();
    let intervals = data
        .intervals()
        .iter()
        .zip(&level_list)
        .map(|(interval, &level)| {
            let (lo, hi) = interval.ends();
            IntervalOut {
                joint: interval.joint,
                lambda: [interval.lambda_min, interval.lambda_max],
                level,
                lambda_at_level: interval.lambda_at_level(level),
                tensions_at_ends: [na_vec(&lo), na_vec(&hi)],
                k_joint: data
                    .joint_stiffness(interval.joint)
                    .map(|k| na_rows(&k))
                    .unwrap_or_default(),
            }
        })
        .collect();
    let g = robot.gravity();
    let out = ArmOut {
        command: "arm",
        robot: robot.name().to_owned(),
        routing_file: loaded.routing_file.display().to_string(),
        model: args.common.model.name(),
        gravity: [g.x, g.y, g.z],
        q,
        wrench,
        policy: chosen.name(),
        levels,
        policy_objective,
        policy_iterations: data.statics.distribution.as_ref().map(|d| d.iterations),
        force_closure,
        null_space_dimension,
        cables,
        t0: data.statics.t0.clone(),
        tensions: data.tensions().to_vec(),
        intervals,
        k_controllable: faer_rows(data.k_controllable()),
        k_inherent: faer_rows(data.k_inherent()),
        k_q: faer_rows(data.k_q()),
        k_w: faer_rows(data.k_w()),
        j_x: faer_rows(data.j_x()),
        stable,
        min_eigenvalue,
        c_x,
        k_x,
        k_fd,
        k_translational: k_translational.map(|k| na_rows(&k)),
        ellipsoid,
        notes,
    };
    if args.common.json { print_json(&out) } else { emit(&render(&out, routing)) }
}

fn render(out: &ArmOut, routing: &sinew::routing::Routing) -> String {
    let mut s = String::new();
    s.push_str(&format!(
        "arm `{}` ({}: {}), gravity {} m/s²\n",
        out.robot,
        out.model,
        out.routing_file,
        Fmt::Fixed(3).list(&out.gravity)
    ));
    s.push_str(&format!("  Q  = {} rad\n", Fmt::Fixed(5).list(&out.q)));
    s.push_str(&format!(
        "  F0 = {} (N, N m; exerted by the end, base frame)\n",
        Fmt::Fixed(4).list(&out.wrench)
    ));
    match (&out.levels, out.policy_objective) {
        (Some(levels), _) => {
            s.push_str(&format!("  tension levels = {}\n", Fmt::Fixed(3).list(levels)));
        }
        (None, objective) => s.push_str(&format!(
            "  tensions by the policy {} (objective {} N)\n",
            out.policy,
            objective.map_or_else(|| "-".to_owned(), |v| Fmt::Fixed(4).num(v))
        )),
    }
    s.push_str(&format!(
        "  equilibrium set f = f_p + N λ of dimension {}; force closure: {}\n\n",
        out.null_space_dimension,
        if out.force_closure { "yes" } else { "no (reported, not required)" }
    ));
    if out.intervals.is_empty() {
        s.push_str("Cables: tensions (N) within their limits:\n");
        let mut t = Table::new(&["cable", "joint", "f", "f_min", "f_max"]).left(&[0]);
        for (c, cable) in routing.cables().iter().enumerate() {
            t.row(vec![
                out.cables[c].clone(),
                format!("{}", cable.joint + 1),
                Fmt::Fixed(3).num(out.tensions[c]),
                Fmt::Fixed(1).num(cable.tension_limits[0]),
                Fmt::Fixed(1).num(cable.tension_limits[1]),
            ]);
        }
        s.push_str(&t.render(2));
    }

    if !out.intervals.is_empty() {
        s.push_str("Joints (numbered from 1): T0 = T_g + J_xᵀ F0 (N m), feasible λ, tensions (N), K (N m/rad):\n");
    }
    let mut t = Table::new(&[
        "joint", "T0 x", "T0 y", "λ_min", "λ_max", "level", "cables", "f1", "f2", "f3", "K_x",
        "K_y",
    ])
    .left(&[6]);
    for iv in &out.intervals {
        let i = iv.joint;
        let own: Vec<usize> = routing
            .cables()
            .iter()
            .enumerate()
            .filter(|(_, c)| c.joint == i)
            .map(|(k, _)| k)
            .collect();
        let names: Vec<&str> = own.iter().map(|&k| out.cables[k].as_str()).collect();
        let mut row = vec![
            format!("{}", i + 1),
            Fmt::Fixed(4).num(out.t0[2 * i]),
            Fmt::Fixed(4).num(out.t0[2 * i + 1]),
            Fmt::Fixed(3).num(iv.lambda[0]),
            Fmt::Fixed(3).num(iv.lambda[1]),
            Fmt::Fixed(3).num(iv.level),
            names.join(","),
        ];
        for k in 0..3 {
            row.push(own.get(k).map(|&c| Fmt::Fixed(3).num(out.tensions[c])).unwrap_or_default());
        }
        let diag = |r: usize| iv.k_joint.get(r).and_then(|row| row.get(r)).copied();
        row.push(diag(0).map(|x| Fmt::Fixed(4).num(x)).unwrap_or_default());
        row.push(diag(1).map(|x| Fmt::Fixed(4).num(x)).unwrap_or_default());
        t.row(row);
    }
    if !out.intervals.is_empty() {
        s.push_str(&t.render(2));
    }
    let ql = q_labels(routing.joint_groups());
    let cl = cartesian_labels();
    s.push('\n');
    s.push_str(&matrix(
        "K_q = controllable + inherent (N m/rad):",
        &out.k_q,
        Fmt::Fixed(4),
        &ql,
        &ql,
    ));
    s.push('\n');
    s.push_str(&matrix("K_W = ∂T0/∂Q (N m/rad):", &out.k_w, Fmt::Fixed(4), &ql, &ql));
    s.push('\n');
    s.push_str(&matrix("J_x (linear rows first, base frame):", &out.j_x, Fmt::Fixed(5), &cl, &ql));
    s.push('\n');
    if out.stable {
        s.push_str(&format!(
            "Stability: STABLE, smallest eigenvalue of K_q + K_W = {} N m/rad\n\n",
            Fmt::Fixed(6).num(out.min_eigenvalue)
        ));
    } else {
        s.push_str(&format!(
            "Stability: UNSTABLE, smallest eigenvalue of K_q + K_W = {} N m/rad\n",
            Fmt::Fixed(6).num(out.min_eigenvalue)
        ));
    }
    if let Some(c_x) = &out.c_x {
        s.push_str(&matrix(
            "C_x = J_x (K_q + K_W)⁻¹ J_xᵀ (m/N, rad/(N m)):",
            c_x,
            Fmt::Sci(4),
            &cl,
            &cl,
        ));
        s.push('\n');
    }
    if let Some(k_x) = &out.k_x {
        s.push_str(&matrix("K_x = C_x⁻¹:", k_x, Fmt::Fixed(3), &cl, &cl));
        s.push('\n');
    }
    let xyz = &cl[..3];
    if let Some(k_fd) = &out.k_fd {
        s.push_str(&matrix(
            "K_fd = K_x[0:3, 0:3] (N/m, rotations held; eq. 21):",
            k_fd,
            Fmt::Fixed(3),
            xyz,
            xyz,
        ));
        s.push('\n');
    }
    if let Some(k_t) = &out.k_translational {
        s.push_str(&matrix(
            "K_t = (C_x[0:3, 0:3])⁻¹ (N/m, rotations free):",
            k_t,
            Fmt::Fixed(3),
            xyz,
            xyz,
        ));
        s.push('\n');
    }
    if let Some(e) = &out.ellipsoid {
        s.push_str("Stiffness ellipsoid of K_fd (eigenvalues ascending):\n");
        let mut t = Table::new(&["", "λ (N/m)", "1/λ (m/N)", "direction (base frame)"]);
        for k in 0..e.eigenvalues.len() {
            t.row(vec![
                format!("{}", k + 1),
                Fmt::Fixed(3).num(e.eigenvalues[k]),
                e.semi_axes
                    .as_ref()
                    .map(|a| Fmt::Sci(4).num(a[k]))
                    .unwrap_or_else(|| "-".to_owned()),
                e.directions.get(k).map(|d| Fmt::Fixed(4).list(d)).unwrap_or_default(),
            ]);
        }
        s.push_str(&t.render(2));
        let opt = |x: Option<f64>, f: Fmt| x.map(|v| f.num(v)).unwrap_or_else(|| "-".to_owned());
        s.push_str(&format!(
            "  λ_min = {} N/m, condition number = {}, volume = {} m³/N³\n",
            Fmt::Fixed(3).num(e.lambda_min),
            opt(e.condition_number, Fmt::Fixed(3)),
            opt(e.volume, Fmt::Sci(4))
        ));
    }
    for note in &out.notes {
        s.push_str(&format!("note: {note}\n"));
    }
    s
}
