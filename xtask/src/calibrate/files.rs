//! The files the calibration reads and writes: the five-joint URDF and the two routing files of
//! `robots/cdhrm5` for a geometry, and the comparison of the committed files with the fit.

use std::path::Path;

use sinew::robot::UniformChain;
use sinew::routing::{PerJoint, Routing, RoutingSpec};

use super::model::{Geometry, LINK, chain, ea};
use crate::DynResult;

/// `cargo xtask calibrate --check` tolerances: lengths (m), θ0 (rad), relative k.
const CHECK_LENGTH: f64 = 5e-5;
const CHECK_ANGLE: f64 = 1e-3;
const CHECK_STIFFNESS: f64 = 1e-3;

/// The five-joint files for geometry `g`: the URDF and the two routing files.
fn file_texts(g: &Geometry) -> DynResult<[(&'static str, String); 3]> {
    let chain = UniformChain { name: "cdhrm5".to_owned(), ..chain(g, 5) };
    chain.build()?;
    let free = g.free_length(ea());
    let pitch = g.d1 + g.d2 + LINK;
    let per_joint: Vec<String> = (0..5).map(|i| fmt_num(free + i as f64 * pitch, 4)).collect();
    let values = Values {
        radius: fmt_num(g.rho_p, 5),
        radius_mm: format!("{:.2}", 1e3 * g.rho_p),
        rim_mm: format!("{:.1}", 30.0 - 1e3 * g.rho_p),
        theta0: fmt_num(g.theta0, 5),
        theta0_deg: format!("{:.2}", g.theta0.to_degrees()),
        free: fmt_num(free, 4),
        per_joint: per_joint.join(", "),
        stiffness: format!("{:.0}", g.stiffness),
        elastic: format!("{:.4}", ea() / g.stiffness),
        gap_mm: format!("{:.0}", 1e3 * (g.d1 + g.d2)),
        pitch: format!("{:.2}", pitch),
    };
    Ok([
        ("cdhrm5.urdf", chain.to_urdf()),
        (sinew::routing::ROUTING_FILE, decoupled_toml(&values)),
        (sinew::routing::ROUTED_ROUTING_FILE, routed_toml(&values)),
    ])
}

pub(super) fn write_files(dir: &Path, g: &Geometry) -> DynResult<()> {
    for (name, text) in file_texts(g)? {
        std::fs::write(dir.join(name), text)?;
    }
    Ok(())
}

/// The differences between the committed files and geometry `g` beyond the check tolerances.
pub(super) fn compare_with_files(dir: &Path, g: &Geometry) -> DynResult<Vec<String>> {
    let mut out = Vec::new();
    let robot = sinew::robot::load(dir)?;
    let d1 = robot.joints().first().map_or(f64::NAN, |j| j.origin.translation.z);
    let d2 = robot.link("link1")?.body_m_link.translation.z;
    let mut compare = |what: &str, file: f64, fit: f64, tol: f64, relative: bool| {
        let diff = if relative { (file - fit).abs() / fit.abs() } else { (file - fit).abs() };
        if diff.is_nan() || diff > tol {
            out.push(format!("  {what}: files {file:.6}, fit {fit:.6}"));
        }
    };
    compare("d1 (cdhrm5.urdf)", d1, g.d1, CHECK_LENGTH, false);
    compare("d2 (cdhrm5.urdf)", d2, g.d2, CHECK_LENGTH, false);
    for file in [sinew::routing::ROUTING_FILE, sinew::routing::ROUTED_ROUTING_FILE] {
        let text = std::fs::read_to_string(dir.join(file))?;
        let spec = RoutingSpec::from_toml_str(&text, file)?;
        let pattern = spec.pattern.as_ref().ok_or_else(|| format!("{file}: no [pattern]"))?;
        let radius = |r: &Option<PerJoint>| r.as_ref().and_then(|r| r.get(0));
        let rho_p = radius(&pattern.proximal_radius).or(radius(&pattern.radius));
        let rho_d = radius(&pattern.distal_radius).or(radius(&pattern.radius));
        compare(
            &format!("proximal radius ({file})"),
            rho_p.unwrap_or(f64::NAN),
            g.rho_p,
            CHECK_LENGTH,
            false,
        );
        compare(
            &format!("distal radius ({file})"),
            rho_d.unwrap_or(f64::NAN),
            g.rho_d,
            CHECK_LENGTH,
            false,
        );
        compare(&format!("theta0 ({file})"), pattern.theta0, g.theta0, CHECK_ANGLE, false);
        let routing = Routing::new(&robot, &spec, file)?;
        let k = routing.cable_stiffness().first().copied().unwrap_or(f64::NAN);
        compare(
            &format!("joint-1 cable stiffness ({file})"),
            k,
            g.stiffness,
            CHECK_STIFFNESS,
            true,
        );
    }
    Ok(out)
}

/// `x` rounded to `decimals`, printed without trailing zeros (at least one decimal).
fn fmt_num(x: f64, decimals: usize) -> String {
    let s = format!("{x:.decimals$}");
    let s = s.trim_end_matches('0');
    let s = if s.ends_with('.') { format!("{s}0") } else { s.to_owned() };
    if s == "-0.0" { "0.0".to_owned() } else { s }
}

/// The fitted values as the routing files print them.
struct Values {
    radius: String,
    radius_mm: String,
    rim_mm: String,
    theta0: String,
    theta0_deg: String,
    free: String,
    per_joint: String,
    stiffness: String,
    elastic: String,
    gap_mm: String,
    pitch: String,
}

fn decoupled_toml(v: &Values) -> String {
    format!(
        r#"# Cable routing of cdhrm5, the paper's platform: 15 cables, 3 per universal joint, in the
# paper's DECOUPLED model (spec §2: each cable's length counts only its crossing of the joint
# it drives; proximal crossings run through the central channel). The routed variant is
# cables-routed.toml beside this file. Format: crates/sinew-routing/src/spec.rs. SI units.
#
# Table I states E and the tension limits; everything else is chosen here and explained in
# README.md ("Cable routing"). The hole radius, theta0 and the free length are fitted to Table II
# (spec §7) by `cargo xtask calibrate`, which writes them here; `cargo xtask calibrate --check`
# tells whether this file still holds what the fit gives.

# Section IV of the paper: every cable tension stays in [20, 600] N.
tension_limits = [20.0, 600.0]

# Elastic length l_c = free_length + routed length at Q = 0 (eq. 13: k_c = E·A / l_c).
# Free length from the actuator to the base disc: {free} m, fitted to Table II: joint 1's cables
# have l_c = {elastic} m and k = E·A/l_c = {stiffness} N/m. It lumps the cable run to a remote
# actuation unit and any compliance in series.
# Decoupled: the routed length is only the {gap_mm} mm crossing of the cable's own joint, so the
# free length of joint i (0-based) adds the central channel through the i links before it,
# i · (d1 + d2 + link) = i · {pitch} m. Every cable then has the same elastic length as in the
# routed variant.
free_length = [{per_joint}]

[material]
# Table I: elastic modulus of the cables.
youngs_modulus = 12.5e9
# Not stated: a 1 mm cable (A = 0.785 mm²). At the 600 N limit it carries 764 MPa, within a
# steel wire rope's or braided polymer line's strength; E·A = 9817 N.
diameter = 1.0e-3

[pattern]
model = "decoupled"
# Hole circle radius on every disc: {radius_mm} mm, fitted to Table II; inside the φ60 mm link
# ({rim_mm} mm from the rim, room for the hole, its bushing and a central channel).
radius = {radius}
# Cable k (0, 1, 2) of joint i (0-based) at θ = theta0 + 120°·k + i·joint_offset.
# theta0 = {theta0_deg}°, fitted to Table II (modulo 120°: cable 1 of joint 1 near +x);
# joint_offset = 24° = 360°/15, so the 15 cables use 15 distinct, evenly spaced holes on each disc.
theta0 = {theta0}
joint_offset = 0.41887902047863906
# The disc links of each universal joint, base first: O_i (distal disc of link i-1, the base
# disc for joint 1) and O'_i (proximal disc of link i). Names of the generated URDF.
proximal_discs = ["base_link", "link1_distal", "link2_distal", "link3_distal", "link4_distal"]
distal_discs = ["link1", "link2", "link3", "link4", "link5"]
"#,
        free = v.free,
        elastic = v.elastic,
        stiffness = v.stiffness,
        gap_mm = v.gap_mm,
        pitch = v.pitch,
        per_joint = v.per_joint,
        radius_mm = v.radius_mm,
        rim_mm = v.rim_mm,
        radius = v.radius,
        theta0_deg = v.theta0_deg,
        theta0 = v.theta0,
    )
}

fn routed_toml(v: &Values) -> String {
    format!(
        r#"# Cable routing of cdhrm5 in the ROUTED model (spec §2): the cable of joint i starts at its hole
# on the base disc and passes through its holes (same angle) on the distal and proximal discs
# of every joint before i, ending at its anchor on the distal disc of joint i. Its tension then
# also loads every proximal joint (J_c block lower-triangular). Same cables, holes and material
# as cables.toml (the decoupled default); see README.md ("Cable routing") for the values. The
# hole radius, theta0 and the free length are fitted to Table II by `cargo xtask calibrate`.

tension_limits = [20.0, 600.0]

# Elastic length l_c = free_length + routed length at Q = 0. Here the routed length already
# holds the run along the proximal links ({pitch} m per link), so one free length serves every
# cable: the same {free} m from the actuator to the base disc as cables.toml, and the same
# elastic lengths at Q = 0.
free_length = {free}

[material]
youngs_modulus = 12.5e9
diameter = 1.0e-3

[pattern]
model = "routed"
radius = {radius}
theta0 = {theta0}
joint_offset = 0.41887902047863906
proximal_discs = ["base_link", "link1_distal", "link2_distal", "link3_distal", "link4_distal"]
distal_discs = ["link1", "link2", "link3", "link4", "link5"]
"#,
        pitch = v.pitch,
        free = v.free,
        radius = v.radius,
        theta0 = v.theta0,
    )
}
