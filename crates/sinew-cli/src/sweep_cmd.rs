//! `sinew sweep`: a joint's stiffness range over a grid of its two angles (Fig. 5).

use std::io::Write;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use sinew::indicators::{AngleGrid, JointProbe, SweepCell, SweepMaps, sweep_probe};
use sinew::robot::Compact;

use crate::arm_friction::{FrictionOut, requested};
use crate::cli::SweepArgs;
use crate::error::{CliError, library_error};
use crate::input::{joint, load, numbers_n};
use crate::joint_cmd::{AxisOut, axes};
use crate::output::{Fmt, Table, emit, print_json};

/// The most grid points per axis `sinew sweep` accepts: 1001² ≈ 10⁶ points. Time, memory and
/// output grow as N² (about 100 bytes of JSON or table text per point and map), so a larger
/// grid takes minutes to hours and gigabytes; 100 000 points per axis would be 10¹⁰ points.
pub const MAX_GRID_POINTS: usize = 1001;

/// The JSON document of `sinew sweep`.
#[derive(Debug, Serialize)]
struct SweepOut {
    command: &'static str,
    robot: String,
    routing_file: String,
    model: &'static str,
    /// 0-based.
    joint: usize,
    /// The joint's two revolute joints: q1 (rows) about the first, q2 (columns) about the
    /// second; `k_x_*` and `k_y_*` (the paper's names) are the stiffness about the first and
    /// the second axis.
    axes: [AxisOut; 2],
    torque: [f64; 2],
    tension_limits: [f64; 2],
    grid: GridOut,
    /// Number of grid points where the torque can be held.
    feasible: usize,
    /// `points × points`, `[a][b]` at `q = [angles[a], angles[b]]`; null where infeasible.
    k_x_min: Vec<Vec<Option<f64>>>,
    k_x_max: Vec<Vec<Option<f64>>>,
    k_y_min: Vec<Vec<Option<f64>>>,
    k_y_max: Vec<Vec<Option<f64>>>,
    /// The CSV file written, if any.
    csv: Option<String>,
    /// Friction at the holes (spec §9), when modelled (absent without, so that a frictionless
    /// sweep's document is unchanged): the regime's actuator tensions and joint stiffness.
    #[serde(skip_serializing_if = "Option::is_none")]
    friction: Option<FrictionOut>,
}

/// The angle grid, the same on both axes.
#[derive(Debug, Serialize)]
struct GridOut {
    lower: f64,
    upper: f64,
    points: usize,
    angles: Vec<f64>,
}

/// Run `sinew sweep`.
pub fn run(args: &SweepArgs) -> Result<(), CliError> {
    let loaded = load(&args.common.robot, args.common.model, false)?;
    let (robot, routing) = (&loaded.robot, &loaded.routing);
    // Friction at the holes when the routing file or --friction gives some μ > 0 (spec §9).
    let friction = requested(args.friction.asked(), routing)?;
    let i = joint(&args.joint, robot)?;
    let tau = numbers_n("--torque", &args.torque, 2, "torque components (T1,T2 in N m)")?;
    let points: usize = args.grid.trim().parse().map_err(|_| {
        CliError::input(format!("--grid: `{}` is not a whole number of points", args.grid.trim()))
    })?;
    if points > MAX_GRID_POINTS {
        return Err(CliError::input(format!(
            "--grid {points}: at most {MAX_GRID_POINTS} points per axis; the sweep's time, memory and output grow as N² ({} points asked for)",
            Compact((points as f64).powi(2))
        )));
    }
    // The library says whether the robot has this joint (and whether it has three cables);
    // too few points and an empty range are its to refuse too.
    let mut probe = JointProbe::new(robot, routing, i).map_err(library_error)?;
    if let Some((model, regime)) = &friction {
        probe = probe.with_friction(routing, model.clone(), *regime).map_err(library_error)?;
    }
    // Both axes share one grid: the range the joint's first and second axes both allow.
    let (jx, jy) = (&robot.joints()[2 * i], &robot.joints()[2 * i + 1]);
    let (lower, upper) = (jx.lower.max(jy.lower), jx.upper.min(jy.upper));
    let grid = AngleGrid { lower, upper, points };
    let cannot_write = |path: &std::path::Path, e: std::io::Error| {
        CliError::input(format!("--out: cannot write `{}`: {e}", path.display()))
    };
    // Open the CSV file first: a bad path fails before the sweep, not after it.
    let csv_file = match &args.out {
        Some(path) => Some((path, std::fs::File::create(path).map_err(|e| cannot_write(path, e))?)),
        None => None,
    };
    let bar = progress_bar(points.saturating_mul(points));
    let maps = sweep_probe(&probe, robot, routing, [tau[0], tau[1]], grid, &|done, _| {
        bar.set_position(done as u64)
    });
    bar.finish_and_clear();
    let maps = maps.map_err(library_error)?;
    if let Some((path, mut file)) = csv_file {
        file.write_all(sinew::paper::e3_csv(&maps).as_bytes())
            .map_err(|e| cannot_write(path, e))?;
    }
    let map = |f: fn(&SweepCell) -> f64| -> Vec<Vec<Option<f64>>> {
        (0..points).map(|a| (0..points).map(|b| maps.cell(a, b).map(f)).collect()).collect()
    };
    let out = SweepOut {
        command: "sweep",
        robot: robot.name().to_owned(),
        routing_file: loaded.routing_file.display().to_string(),
        model: args.common.model.name(),
        joint: i,
        axes: axes(robot, i),
        torque: [tau[0], tau[1]],
        tension_limits: routing.tension_limits(),
        grid: GridOut {
            lower,
            upper,
            points,
            angles: (0..points).map(|k| grid.angle(k)).collect(),
        },
        feasible: maps.feasible(),
        k_x_min: map(|c| c.k_x.range[0]),
        k_x_max: map(|c| c.k_x.range[1]),
        k_y_min: map(|c| c.k_y.range[0]),
        k_y_max: map(|c| c.k_y.range[1]),
        csv: args.out.as_ref().map(|p| p.display().to_string()),
        friction: friction.map(|(model, regime)| FrictionOut::new(&model, regime)),
    };
    if args.common.json { print_json(&out) } else { emit(&render(&out, &maps, args.out.is_none())) }
}

/// A progress bar on standard error, drawn only when it is a terminal.
fn progress_bar(total: usize) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(total as u64), ProgressDrawTarget::stderr());
    if let Ok(style) =
        ProgressStyle::with_template("sweep {bar:40} {pos}/{len} points ({eta} left)")
    {
        bar.set_style(style);
    }
    bar
}

fn render(out: &SweepOut, maps: &SweepMaps, with_maps: bool) -> String {
    let mut s = String::new();
    let n = out.grid.points;
    s.push_str(&format!(
        "sweep of joint {} of `{}` ({}: {}), the other joints at 0\n",
        out.joint + 1,
        out.robot,
        out.model,
        out.routing_file
    ));
    if let Some(f) = &out.friction {
        s.push_str(&format!(
            "  friction at the holes: {}; tensions are actuator tensions, each within the limits that keep every segment in [{}, {}] N\n",
            f.describe(),
            out.tension_limits[0],
            out.tension_limits[1]
        ));
    }
    s.push_str(&format!(
        "  torque = {} N m, tensions in [{}, {}] N\n  grid: {n} × {n} points, q1 and q2 from {} to {} rad\n  feasible: {} of {} points\n",
        Fmt::Fixed(4).list(&out.torque),
        out.tension_limits[0],
        out.tension_limits[1],
        Fmt::Fixed(5).num(out.grid.lower),
        Fmt::Fixed(5).num(out.grid.upper),
        out.feasible,
        n * n
    ));
    s.push_str(&format!(
        "  axes: q1, K_x about the first `{}` {}; q2, K_y about the second `{}` {}\n",
        out.axes[0].name,
        Fmt::Fixed(3).list(&out.axes[0].axis),
        out.axes[1].name,
        Fmt::Fixed(3).list(&out.axes[1].axis)
    ));
    let extremes = |m: &Vec<Vec<Option<f64>>>| {
        let values = m.iter().flatten().flatten().copied();
        values.fold(None, |acc: Option<(f64, f64)>, v| {
            Some(acc.map_or((v, v), |(lo, hi)| (lo.min(v), hi.max(v))))
        })
    };
    let mut t = Table::new(&["map (N m/rad)", "smallest", "largest"]);
    for (name, m) in [
        ("K_x min", &out.k_x_min),
        ("K_x max", &out.k_x_max),
        ("K_y min", &out.k_y_min),
        ("K_y max", &out.k_y_max),
    ] {
        let (lo, hi) = extremes(m)
            .map(|(lo, hi)| (Fmt::Fixed(4).num(lo), Fmt::Fixed(4).num(hi)))
            .unwrap_or_else(|| ("-".to_owned(), "-".to_owned()));
        t.row(vec![name.to_owned(), lo, hi]);
    }
    s.push('\n');
    s.push_str(&t.render(2));
    if let Some(path) = &out.csv {
        s.push_str(&format!("\nwrote {path} ({} rows)\n", n * n));
    }
    if !with_maps {
        return s;
    }
    let mut header = vec!["q1 \\ q2".to_owned()];
    header.extend(out.grid.angles.iter().map(|&a| Fmt::Fixed(4).num(a)));
    for (name, f) in [
        ("K_x min", (|c: &SweepCell| c.k_x.range[0]) as fn(&SweepCell) -> f64),
        ("K_x max", |c: &SweepCell| c.k_x.range[1]),
        ("K_y min", |c: &SweepCell| c.k_y.range[0]),
        ("K_y max", |c: &SweepCell| c.k_y.range[1]),
    ] {
        s.push_str(&format!("\n{name} (N m/rad; rows q1, columns q2, rad; - infeasible):\n"));
        let mut t = Table::new(&header);
        for a in 0..n {
            let mut row = vec![Fmt::Fixed(4).num(out.grid.angles[a])];
            row.extend((0..n).map(|b| {
                maps.cell(a, b).map(|c| Fmt::Fixed(4).num(f(c))).unwrap_or_else(|| "-".to_owned())
            }));
            t.row(row);
        }
        s.push_str(&t.render(2));
    }
    s
}
