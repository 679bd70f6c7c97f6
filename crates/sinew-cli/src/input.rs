//! Reading what the user gives: the robot folder and the comma-separated numbers.

use std::path::{Path, PathBuf};

use nalgebra::Vector3;
use sinew::robot::{DESCRIPTION_FILE, Robot, RobotDescription, RobotError};
use sinew::routing::Routing;

use sinew::statics::TensionChoice;

use crate::cli::{Model, TensionArgs};
use crate::error::{CliError, library_error};

/// A robot folder, loaded: its description, the robot and the routing of the chosen model.
#[derive(Debug)]
pub struct Loaded {
    /// `robot.toml`, read.
    pub description: RobotDescription,
    /// The robot (gravity zeroed when asked).
    pub robot: Robot,
    /// The routing of the chosen model.
    pub routing: Routing,
    /// The routing file read.
    pub routing_file: PathBuf,
}

/// Load a robot folder: `robot.toml`, its URDF, and `cables.toml` or `cables-routed.toml`.
///
/// Every missing piece is an input error naming the folder and the file.
pub fn load(dir: &Path, model: Model, no_gravity: bool) -> Result<Loaded, CliError> {
    let shown = dir.display();
    if !dir.exists() {
        return Err(CliError::input(format!("--robot: robot folder `{shown}` does not exist")));
    }
    if !dir.is_dir() {
        return Err(CliError::input(format!(
            "--robot: `{shown}` is not a folder (give the robot folder holding {DESCRIPTION_FILE})"
        )));
    }
    if !dir.join(DESCRIPTION_FILE).is_file() {
        return Err(CliError::input(format!(
            "--robot: robot folder `{shown}` has no {DESCRIPTION_FILE}"
        )));
    }
    let description = RobotDescription::read(dir).map_err(library_error)?;
    if !description.urdf.is_file() {
        return Err(CliError::input(format!(
            "--robot: robot folder `{shown}` has no URDF: {} names `{}`, which does not exist",
            description.path.display(),
            description.urdf.display()
        )));
    }
    let robot = description.load_robot().map_err(|e| match e {
        // The only link robot.toml names is the tip: say where it comes from.
        RobotError::NoSuchLink { .. } => {
            CliError::input(format!("{}: tip_link: {e}", description.path.display()))
        }
        e => library_error(e),
    })?;
    let routing_file = dir.join(model.file_name());
    if !routing_file.is_file() {
        return Err(CliError::input(format!(
            "--model {}: robot folder `{shown}` has no {}",
            model.name(),
            model.file_name()
        )));
    }
    let routing = sinew::routing::load(&routing_file, &robot).map_err(library_error)?;
    let robot = if no_gravity { robot.with_gravity(Vector3::zeros()) } else { robot };
    Ok(Loaded { description, robot, routing, routing_file })
}

/// Comma-separated finite numbers, e.g. `0.1,-0.2, 3e-1`.
pub fn numbers(option: &str, text: &str) -> Result<Vec<f64>, CliError> {
    if text.trim().is_empty() {
        return Err(CliError::input(format!("{option}: no numbers given")));
    }
    text.split(',')
        .map(|item| {
            let item = item.trim();
            match item.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                Ok(_) => Err(CliError::input(format!("{option}: `{item}` is not a finite number"))),
                Err(_) => Err(CliError::input(format!("{option}: `{item}` is not a number"))),
            }
        })
        .collect()
}

/// Exactly `count` comma-separated numbers; `what` says what they are (for the message).
pub fn numbers_n(option: &str, text: &str, count: usize, what: &str) -> Result<Vec<f64>, CliError> {
    let values = numbers(option, text)?;
    if values.len() != count {
        return Err(CliError::input(format!(
            "{option}: expected {count} {what}, got {}",
            values.len()
        )));
    }
    Ok(values)
}

/// Exactly one number: an option that takes one value refuses a list (`--gap 1e-3,5`).
pub fn one_number(option: &str, text: &str) -> Result<f64, CliError> {
    Ok(numbers_n(option, text, 1, "number")?[0])
}

/// A 1-based universal joint number of the command line, as the 0-based index. Only the
/// command line's numbering is checked here (a whole number from 1); whether the robot has
/// that joint is the library's to say (`--joint N: joint N does not exist …`).
pub fn joint(text: &str, robot: &Robot) -> Result<usize, CliError> {
    let joints = robot.dof() / 2;
    let number: i64 = text.trim().parse().map_err(|_| {
        CliError::input(format!("--joint: `{}` is not a joint number (1 to {joints})", text.trim()))
    })?;
    if number < 1 {
        return Err(CliError::input(format!(
            "--joint {number}: no such joint; the robot `{}` has {joints} universal joints, numbered 1 to {joints} from the base",
            robot.name()
        )));
    }
    usize::try_from(number - 1).map_err(|_| CliError::input(format!("--joint {number}: too large")))
}

/// Angles to radians.
pub fn to_radians(values: &mut [f64], deg: bool) {
    if deg {
        for v in values {
            *v = v.to_radians();
        }
    }
}

/// `--q`: one angle per revolute joint (degrees with `--deg`), in radians.
pub fn pose(text: &str, deg: bool, robot: &Robot) -> Result<Vec<f64>, CliError> {
    let (dof, joints) = (robot.dof(), robot.joint_count());
    let what = format!("angles (one per revolute joint, {joints} joints)");
    let mut q = numbers_n("--q", text, dof, &what)?;
    to_radians(&mut q, deg);
    Ok(q)
}

/// `--wrench`: six components, zero when not given.
pub fn wrench(text: Option<&str>) -> Result<Vec<f64>, CliError> {
    match text {
        Some(text) => numbers_n("--wrench", text, 6, "wrench components (FX,FY,FZ,MX,MY,MZ)"),
        None => Ok(vec![0.0; 6]),
    }
}

/// `--levels`, one per joint, if given. Levels outside [0, 1] are the library's to refuse
/// (`--levels: joint i: …`).
pub fn levels(args: &TensionArgs, joints: usize) -> Result<Option<Vec<f64>>, CliError> {
    let what = format!("tension levels (one per joint, {joints} joints)");
    args.levels.as_deref().map(|text| numbers_n("--levels", text, joints, &what)).transpose()
}

/// The tensions the options choose: `--levels` (as parsed by [`levels`]), `--policy`, or the
/// default.
pub fn tension_choice<'a>(levels: Option<&'a [f64]>, args: &TensionArgs) -> TensionChoice<'a> {
    match (levels, args.policy) {
        (Some(levels), _) => TensionChoice::Levels(levels),
        (None, Some(policy)) => TensionChoice::Policy(policy.tension_policy()),
        (None, None) => TensionChoice::Default,
    }
}
