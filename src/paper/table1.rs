//! Table I: the platform's parameters, read from the robot files.

use std::fmt::Write as _;
use std::path::Path;

use crate::robot::RobotDescription;

/// Table I as a markdown table, read from a robot folder (`robot.toml`, its URDF, and the
/// routing file `cables.toml` for the cable material and tension limits).
///
/// # Errors
/// A message naming the file that could not be read.
pub fn table_1(robot_dir: &Path) -> Result<String, crate::Error> {
    let description = RobotDescription::read(robot_dir)?;
    let robot = description.load_robot()?;
    let routing = crate::routing::load(robot_dir, &robot)?;
    let urdf = urdf_rs::read_file(&description.urdf).map_err(|e| crate::Error::Other {
        message: format!("{}: {e}", description.urdf.display()),
    })?;
    // Link size: the visual cylinder of the first link that has one.
    let link_size = urdf
        .links
        .iter()
        .find_map(|link| match link.visual.first().map(|v| &v.geometry) {
            Some(urdf_rs::Geometry::Cylinder { radius, length }) => {
                Some(format!("φ{:.0} × {:.0}", 2000.0 * radius, 1000.0 * length))
            }
            _ => None,
        })
        .unwrap_or_else(|| "(no cylinder in the URDF)".to_owned());
    let dof = robot.dof();
    let (lower, upper) = robot
        .joints()
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, u), j| (l.min(j.lower), u.max(j.upper)));
    let [f_min, f_max] = routing.tension_limits();
    let mut s = String::new();
    // Writing to a String cannot fail.
    let _ = writeln!(s, "| Items | Value | Unit |");
    let _ = writeln!(s, "| --- | --- | --- |");
    let _ = writeln!(s, "| Single link size | {link_size} | mm |");
    let _ = writeln!(s, "| Total mass of manipulator | {:.2} | kg |", robot.moving_mass());
    if let Some(payload) = description.payload {
        let _ = writeln!(s, "| Load capability | {payload:.2} | kg |");
    }
    let _ = writeln!(
        s,
        "| Number of joints and degrees of freedom | {} joints/{}-DOF | |",
        dof / 2,
        dof
    );
    let _ = writeln!(
        s,
        "| Joint angle limitation | [{}, {}] | rad |",
        pi_fraction(lower),
        pi_fraction(upper)
    );
    let _ = writeln!(
        s,
        "| Elastic modulus of cables E | {:.1} | GPa |",
        routing.youngs_modulus() / 1e9
    );
    let _ = writeln!(s, "| Cable tension limits | [{f_min:.0}, {f_max:.0}] | N |");
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
