//! `sinew plan --trajectory FILE.csv`: one certified plan per step of a trajectory, each
//! warm-started from the one before ([`sinew::planner::Planner::plan_along`]), optionally with a
//! bound on each cable's rate of tension change (`--rate N/s --dt s`). The rows come out as
//! CSV, or as one JSON document with `--json`. A step without a plan is typed in its row.

use std::path::Path;

use nalgebra::Vector6;
use serde::Serialize;
use sinew::planner::{Planner, PlannerData, RateLimit, Step};
use sinew::stiffness::ArmStiffness;

use crate::arm_friction::requested;
use crate::cli::PlanArgs;
use crate::error::{CliError, library_error};
use crate::input::{load, one_number, to_radians, wrench};
use crate::output::{emit, print_json};
use crate::plan_cmd::{PlanRequest, request};

/// One step's row.
#[derive(Debug, Serialize)]
struct StepOut {
    step: usize,
    ok: bool,
    warm: bool,
    iterations: usize,
    value: Option<f64>,
    gap: Option<f64>,
    total_tension: Option<f64>,
    min_eigenvalue: Option<f64>,
    tensions: Option<Vec<f64>>,
    error: Option<String>,
}

/// The JSON document.
#[derive(Debug, Serialize)]
struct TrajectoryOut {
    command: &'static str,
    robot: String,
    model: &'static str,
    objective: &'static str,
    trajectory: String,
    rate: Option<f64>,
    dt: Option<f64>,
    cables: Vec<String>,
    warm_steps: usize,
    steps: Vec<StepOut>,
}

/// The steps of the CSV file: per line the `dof` angles, then optionally six F0 components.
fn read_steps(path: &Path, dof: usize, deg: bool, f0: &[f64]) -> Result<Vec<Step>, CliError> {
    let shown = path.display();
    let text = std::fs::read_to_string(path)
        .map_err(|e| CliError::input(format!("--trajectory {shown}: cannot read it: {e}")))?;
    let mut steps = Vec::new();
    let mut header_allowed = true;
    for (number, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let values: Result<Vec<f64>, _> =
            line.split(',').map(|v| v.trim().parse::<f64>()).collect();
        let values = match values {
            Ok(v) => v,
            Err(_) if header_allowed => {
                header_allowed = false;
                continue;
            }
            Err(_) => {
                return Err(CliError::input(format!(
                    "--trajectory {shown}:{}: `{line}` is not a row of numbers",
                    number + 1
                )));
            }
        };
        header_allowed = false;
        if !(values.len() == dof || values.len() == dof + 6)
            || !values.iter().all(|v| v.is_finite())
        {
            return Err(CliError::input(format!(
                "--trajectory {shown}:{}: expected {dof} finite angles, optionally then 6 wrench components (FX,FY,FZ,MX,MY,MZ); got {} values",
                number + 1,
                values.len()
            )));
        }
        let mut q = values[..dof].to_vec();
        to_radians(&mut q, deg);
        let w = if values.len() == dof + 6 { &values[dof..] } else { f0 };
        steps.push(Step { q, f0: Vector6::from_column_slice(w) });
    }
    if steps.is_empty() {
        return Err(CliError::input(format!("--trajectory {shown}: no step in the file")));
    }
    Ok(steps)
}

/// Run `sinew plan --trajectory`.
pub fn run(args: &PlanArgs) -> Result<(), CliError> {
    let loaded = load(&args.common.robot, args.common.model, args.no_gravity)?;
    let (robot, routing) = (&loaded.robot, &loaded.routing);
    let path = args.trajectory.as_deref().unwrap_or(Path::new(""));
    let f0 = wrench(args.wrench.as_deref())?;
    let steps = read_steps(path, robot.dof(), args.deg, &f0)?;
    let PlanRequest { objective, requirements, settings, .. } =
        request("--objective", args.objective, &args.options)?;
    if requested(args.friction.asked(), routing)?.is_some() {
        return Err(CliError::input(
            "--trajectory: plans without friction at the holes; plan in the stick regime one pose at a time (--q), or give --friction 0",
        ));
    }
    let rate = match (&args.rate, &args.dt) {
        (Some(rate), Some(dt)) => {
            Some(RateLimit { max_rate: one_number("--rate", rate)?, dt: one_number("--dt", dt)? })
        }
        _ => None,
    };
    let arm = ArmStiffness::new(robot, routing).map_err(library_error)?.checking_limits();
    let planner = Planner::new(arm);
    let mut data = PlannerData::new(&planner);
    let along = planner
        .plan_along(&mut data, &steps, objective, &requirements, &settings, rate)
        .map_err(|e| match e {
            sinew::planner::PlanError::InvalidInput { what: "max_rate", .. } => {
                CliError::input("--rate: must be finite and > 0 (N/s)")
            }
            sinew::planner::PlanError::InvalidInput { what: "dt", .. } => {
                CliError::input("--dt: must be finite and > 0 (s)")
            }
            e => library_error(e),
        })?;
    if along.iter().all(|s| s.plan.is_err()) {
        let mut along = along;
        if let Some(Err(e)) = along.drain(..).next().map(|s| s.plan) {
            return Err(library_error(e));
        }
        return Err(CliError::input("--trajectory: no step in the file"));
    }
    let rows: Vec<StepOut> = along
        .into_iter()
        .enumerate()
        .map(|(step, s)| match s.plan {
            Ok(p) => StepOut {
                step,
                ok: true,
                warm: s.warm,
                iterations: s.iterations,
                value: Some(p.value),
                gap: Some(p.gap),
                total_tension: Some(p.total_tension),
                min_eigenvalue: Some(p.min_eigenvalue),
                tensions: Some(p.tensions),
                error: None,
            },
            Err(e) => StepOut {
                step,
                ok: false,
                warm: false,
                iterations: s.iterations,
                value: None,
                gap: None,
                total_tension: None,
                min_eigenvalue: None,
                tensions: None,
                error: Some(library_error(e).one_line()),
            },
        })
        .collect();
    let cables: Vec<String> = routing.cables().iter().map(|c| c.name.clone()).collect();
    if args.common.json {
        return print_json(&TrajectoryOut {
            command: "plan --trajectory",
            robot: robot.name().to_owned(),
            model: args.common.model.name(),
            objective: objective.name(),
            trajectory: path.display().to_string(),
            rate: rate.map(|r| r.max_rate),
            dt: rate.map(|r| r.dt),
            warm_steps: rows.iter().filter(|r| r.warm).count(),
            cables,
            steps: rows,
        });
    }
    emit(&csv(&cables, &rows))
}

/// The rows as CSV: one header line, then one line per step (empty fields where it failed).
fn csv(cables: &[String], rows: &[StepOut]) -> String {
    let mut out = String::from("step,ok,warm,iterations,value,gap,total_tension,min_eigenvalue");
    for c in cables {
        out.push_str(&format!(",f_{c}"));
    }
    out.push_str(",error\n");
    let number = |v: Option<f64>| v.map(|v| format!("{v:e}")).unwrap_or_default();
    for r in rows {
        out.push_str(&format!(
            "{},{},{},{},{},{},{},{}",
            r.step,
            r.ok,
            r.warm,
            r.iterations,
            number(r.value),
            number(r.gap),
            number(r.total_tension),
            number(r.min_eigenvalue)
        ));
        for i in 0..cables.len() {
            out.push_str(&format!(",{}", number(r.tensions.as_ref().map(|t| t[i]))));
        }
        let error = r.error.as_deref().unwrap_or("").replace('"', "'");
        out.push_str(&format!(",\"{error}\"\n"));
    }
    out
}
