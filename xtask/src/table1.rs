//! Table I: the platform's parameters, read from the robot files.

use std::fmt::Write as _;
use std::path::Path;

use sinew::robot::RobotDescription;

use crate::DynResult;

/// Render Table I as a markdown table.
pub fn render(robot_dir: &Path) -> DynResult<String> {
    let description = RobotDescription::read(robot_dir)?;
    let robot = description.load_robot()?;
    let urdf = urdf_rs::read_file(&description.urdf)?;

    // Link size: the visual cylinder of the first link carrying mass.
    let mut link_size = String::from("(no cylinder in the URDF)");
    for link in &urdf.links {
        if let Some(urdf_rs::Geometry::Cylinder { radius, length }) =
            link.visual.first().map(|v| &v.geometry)
        {
            link_size = format!("φ{:.0} × {:.0}", 2000.0 * radius, 1000.0 * length);
            break;
        }
    }
    let dof = robot.dof();
    let (lower, upper) = robot
        .joints()
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, u), j| (l.min(j.lower), u.max(j.upper)));
    let limits = format!("[{}, {}]", pi_fraction(lower), pi_fraction(upper));

    let mut s = String::new();
    writeln!(s, "| Items | Value | Unit |")?;
    writeln!(s, "| --- | --- | --- |")?;
    writeln!(s, "| Single link size | {link_size} | mm |")?;
    writeln!(s, "| Total mass of manipulator | {:.2} | kg |", robot.moving_mass())?;
    if let Some(payload) = description.payload {
        writeln!(s, "| Load capability | {payload:.2} | kg |")?;
    }
    writeln!(s, "| Number of joints and degrees of freedom | {} joints/{}-DOF | |", dof / 2, dof)?;
    writeln!(s, "| Joint angle limitation | {limits} | rad |")?;
    Ok(s)
}

/// `x` as a fraction of π when it is one (π/k or −π/k), else as a number.
fn pi_fraction(x: f64) -> String {
    if x == 0.0 {
        return "0".to_owned();
    }
    let k = std::f64::consts::PI / x.abs();
    let sign = if x < 0.0 { "-" } else { "" };
    if (k - k.round()).abs() < 1e-9 { format!("{sign}π/{}", k.round()) } else { format!("{x:.4}") }
}
