//! `sinew export mjcf`: the robot at a pose, its cables holding it, as a MuJoCo model.

use std::path::Path;

use nalgebra::Vector6;
use serde::Serialize;
use sinew::planner::{Planner, PlannerData};
use sinew::stiffness::{ArmStiffness, ArmStiffnessData};
use sinew_mjcf::{CableModel, MjcfOptions, Split, State};

use crate::cli::{CablesAs, MjcfArgs};
use crate::error::{CliError, library_error};
use crate::input::{levels, tension_choice};
use crate::input::{load, one_number, pose, wrench};
use crate::output::print_json;
use crate::plan_cmd::{PlanRequest, request};

/// The JSON summary of `sinew export mjcf --json`.
#[derive(Debug, Serialize)]
struct ExportOut {
    command: &'static str,
    robot: String,
    model: &'static str,
    out: String,
    cables: &'static str,
    split: bool,
    damping: f64,
    q: Vec<f64>,
    wrench: Vec<f64>,
    /// `levels`, a policy's name, or `plan:<objective>`.
    tensions_from: String,
    tensions: Vec<f64>,
}

/// Run `sinew export mjcf`.
pub fn mjcf(args: &MjcfArgs) -> Result<(), CliError> {
    let loaded = load(&args.common.robot, args.common.model, args.no_gravity)?;
    let (robot, routing) = (&loaded.robot, &loaded.routing);
    let q = pose(&args.q, args.deg, robot)?;
    let wrench = wrench(args.wrench.as_deref())?;
    let f0 = Vector6::from_column_slice(&wrench);
    let options = MjcfOptions {
        cables: match args.cables {
            CablesAs::Springs => CableModel::Springs,
            CablesAs::Motors => CableModel::Motors,
        },
        split: if args.split.is_some() { Split::Segments } else { Split::Cables },
        damping: match &args.damping {
            Some(text) => one_number("--damping", text)?,
            None => sinew_mjcf::DEFAULT_DAMPING,
        },
        ..MjcfOptions::default()
    };
    if options.split == Split::Segments && options.cables == CableModel::Motors {
        return Err(CliError::input(
            "--split segments: segments are springs; it does not go with --cables motors",
        ));
    }
    if !(options.damping.is_finite() && options.damping >= 0.0) {
        return Err(CliError::input("--damping: must be a finite number ≥ 0 (N m s/rad)"));
    }
    // The same tensions as `sinew plan` or `sinew arm` with these options (limits checked).
    let arm = ArmStiffness::new(robot, routing).map_err(library_error)?.checking_limits();
    let (tensions, tensions_from) = match args.plan {
        Some(objective) => {
            let PlanRequest { objective, requirements, settings, .. } =
                request("--plan", objective, &args.options)?;
            let planner = Planner::new(arm);
            let mut data = PlannerData::new(&planner);
            let plan = planner
                .plan(&mut data, &q, &f0, objective, &requirements, &settings)
                .map_err(library_error)?;
            (plan.tensions, format!("plan:{}", objective.name()))
        }
        None => {
            let mut data = ArmStiffnessData::new(&arm);
            arm.set_pose(&mut data, &q, &f0).map_err(library_error)?;
            let levels = levels(&args.tensions, robot.joint_count())?;
            let choice = tension_choice(levels.as_deref(), &args.tensions);
            arm.set_tensions(&mut data, choice).map_err(library_error)?;
            (data.tensions().to_vec(), data.statics.chosen().name().to_owned())
        }
    };
    let state = State {
        q: &q,
        tensions: &tensions,
        wrench: [wrench[0], wrench[1], wrench[2], wrench[3], wrench[4], wrench[5]],
        segment_tensions: None,
    };
    let text = sinew_mjcf::to_mjcf(robot, routing, &state, &options)
        .map_err(|e| CliError { kind: e.kind(), message: e.to_string() })?;
    write_atomically(&args.out, &text)?;
    if args.common.json {
        print_json(&ExportOut {
            command: "export mjcf",
            robot: robot.name().to_owned(),
            model: args.common.model.name(),
            out: args.out.display().to_string(),
            cables: match options.cables {
                CableModel::Springs => "springs",
                CableModel::Motors => "motors",
            },
            split: options.split == Split::Segments,
            damping: options.damping,
            q,
            wrench,
            tensions_from,
            tensions,
        })
    } else {
        println!(
            "wrote {} ({} cables, tensions from {tensions_from}); hold the pose with -F0 at site `tip`",
            args.out.display(),
            routing.cable_count()
        );
        Ok(())
    }
}

/// Write `text` to a temporary file beside `path`, then rename it into place: a failure
/// leaves no file (and an existing one untouched).
fn write_atomically(path: &Path, text: &str) -> Result<(), CliError> {
    let shown = path.display();
    let name = path
        .file_name()
        .ok_or_else(|| CliError::input(format!("--out: `{shown}` is not a file name")))?;
    let tmp = path.with_file_name(format!(".{}.sinew-tmp", name.to_string_lossy()));
    std::fs::write(&tmp, text)
        .map_err(|e| CliError::input(format!("--out: cannot write `{shown}`: {e}")))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        CliError::input(format!("--out: cannot write `{shown}`: {e}"))
    })
}
