//! A CASPR model → the three files of a Sinew robot folder: the URDF, `robot.toml` and the
//! explicit `cables.toml`.

use std::collections::HashSet;
use std::fmt::Write as _;
use std::path::Path;

use crate::bodies::Link;
use crate::cables::Cable;
use crate::error::{ImportError, Result};
use crate::{CasprModel, ImportOptions};

/// The name of the tip link written into the URDF (`robot.toml`'s `tip_link`).
pub const TIP_LINK: &str = "tip";
/// The root link of the written URDF (CASPR's link 0).
pub const BASE_LINK: &str = "base_link";
/// The gravitational acceleration CASPR applies (`SystemModel.GRAVITY_CONSTANT`), m/s², along
/// −z of the base frame (`SystemModelBodies`: `G_b = R_0kᵀ [0; 0; −m g]`).
pub const CASPR_GRAVITY: f64 = 9.81;
/// A `force_max` at or above this (N) is reported as a placeholder rather than a cable's rating.
pub const PLACEHOLDER_FORCE_MAX: f64 = 1.0e5;

/// The written robot folder, in memory.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotFolder {
    /// The robot's name (URDF `<robot name>`).
    pub name: String,
    /// The URDF's file name, `<name>.urdf`.
    pub urdf_file: String,
    /// The URDF text.
    pub urdf: String,
    /// `robot.toml`.
    pub robot_toml: String,
    /// `cables.toml` (explicit form).
    pub cables_toml: String,
    /// What the import changed, assumed or could not carry over, one message each.
    pub warnings: Vec<String>,
    /// CASPR links imported.
    pub links: usize,
    /// Revolute joints written (Sinew's DOF).
    pub dof: usize,
    /// Universal joints among the links.
    pub universal_joints: usize,
    /// Cables written.
    pub cables: usize,
}

impl RobotFolder {
    /// Write the three files into the existing folder `dir`.
    ///
    /// # Errors
    /// [`ImportError::Io`] naming the file that could not be written.
    pub fn write_into(&self, dir: &Path) -> Result<()> {
        for (file, text) in [
            (self.urdf_file.as_str(), &self.urdf),
            ("robot.toml", &self.robot_toml),
            ("cables.toml", &self.cables_toml),
        ] {
            let path = dir.join(file);
            std::fs::write(&path, text).map_err(|source| ImportError::Io { path, source })?;
        }
        Ok(())
    }

    /// One line: links, DOF, cables.
    pub fn summary(&self) -> String {
        format!(
            "{}: {} links ({} universal joints), {} DOF, {} cables",
            self.name, self.links, self.universal_joints, self.dof, self.cables
        )
    }
}

/// A name safe in URDF, TOML and file names: letters, digits, `_`, `-`, `.`; others become `_`.
pub fn sanitize(name: &str) -> String {
    name.trim()
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.') { c } else { '_' })
        .collect()
}

/// Build the folder's files from a model read by [`crate::read_caspr`].
pub(crate) fn build(model: &CasprModel, options: &ImportOptions) -> Result<RobotFolder> {
    check_options(options)?;
    let mut warnings = Vec::new();
    let name = match sanitize(&options.name) {
        n if n.is_empty() => "caspr_robot".to_owned(),
        n => n,
    };
    let names = link_names(&model.links, &mut warnings);
    let tip = tip(model, &mut warnings)?;
    let limits = tension_limits(&model.cable_set.cables, options, &mut warnings)?;
    joint_group_warnings(&model.links, &mut warnings);

    let missing_limits: Vec<String> =
        model.links.iter().filter(|l| !l.limits_stated).map(|l| l.num.to_string()).collect();
    if !missing_limits.is_empty() {
        warnings.push(format!(
            "link(s) {} state no q_min/q_max: joint limits ±π written (CASPR's q_lb/q_ub)",
            names_list(&missing_limits.iter().map(String::as_str).collect::<Vec<_>>())
        ));
    }
    let springs: Vec<&str> = model
        .cable_set
        .cables
        .iter()
        .filter(|c| c.kind == "cable_linear_spring")
        .map(|c| c.name.as_str())
        .collect();
    if !springs.is_empty() {
        warnings.push(format!(
            "cable(s) {}: <cable_linear_spring> stiffness K ignored: Sinew's cable stiffness is E·A/l from the material and lengths",
            names_list(&springs)
        ));
    }
    let reversed: Vec<&str> =
        model.cable_set.cables.iter().filter(|c| reversed(c)).map(|c| c.name.as_str()).collect();
    if !reversed.is_empty() {
        warnings.push(format!(
            "cable(s) {}: attachments listed from the tip towards the base: written base first (the same polyline; sinew-routing anchors a cable at its last hole)",
            names_list(&reversed)
        ));
    }
    let on_base: Vec<&str> = model
        .cable_set
        .cables
        .iter()
        .filter(|c| c.attachments.iter().all(|a| a.link == 0))
        .map(|c| c.name.as_str())
        .collect();
    if !on_base.is_empty() {
        warnings.push(format!(
            "cable(s) {} lie on the base (link 0) only: sinew-routing needs each cable's anchor on a moving link",
            names_list(&on_base)
        ));
    }

    let dof: usize = model.links.iter().map(|l| l.joint.dof()).sum();
    let universal_joints = model.links.iter().filter(|l| l.joint.dof() == 2).count();

    let urdf_file = format!("{name}.urdf");
    let urdf = write_urdf(model, &name, &names, &tip);
    let robot_toml = write_robot_toml(model, &urdf_file, &tip);
    let cables_toml = write_cables_toml(model, options, &names, &limits);
    Ok(RobotFolder {
        name,
        urdf_file,
        urdf,
        robot_toml,
        cables_toml,
        warnings,
        links: model.links.len(),
        dof,
        universal_joints,
        cables: model.cable_set.cables.len(),
    })
}

fn check_options(options: &ImportOptions) -> Result<()> {
    let positive = |option, value: f64| {
        if value.is_finite() && value > 0.0 {
            Ok(())
        } else {
            Err(ImportError::InvalidOption { option, value, expected: "finite and > 0" })
        }
    };
    positive("youngs_modulus", options.youngs_modulus)?;
    positive("diameter", options.diameter)?;
    if !(options.free_length.is_finite() && options.free_length >= 0.0) {
        return Err(ImportError::InvalidOption {
            option: "free_length",
            value: options.free_length,
            expected: "finite and ≥ 0 m",
        });
    }
    if let Some([lo, hi]) = options.tension_limits {
        if !(lo.is_finite() && lo >= 0.0) {
            return Err(ImportError::InvalidOption {
                option: "tension_limits (min)",
                value: lo,
                expected: "finite and ≥ 0 N (sinew-routing: 0 ≤ f_min < f_max)",
            });
        }
        if !(hi.is_finite() && hi > lo) {
            return Err(ImportError::InvalidOption {
                option: "tension_limits (max)",
                value: hi,
                expected: "finite and > the min (sinew-routing: 0 ≤ f_min < f_max)",
            });
        }
    }
    Ok(())
}

/// URDF link names, index 0 the base: each CASPR name made safe, unique, and distinct from the
/// names the import adds (`base_link`, `tip`, `<link>_cross`); else `link<num>`.
fn link_names(links: &[Link], warnings: &mut Vec<String>) -> Vec<String> {
    let mut used: HashSet<String> = [BASE_LINK, TIP_LINK].into_iter().map(str::to_owned).collect();
    let mut names = vec![BASE_LINK.to_owned()];
    let mut renamed: Vec<String> = Vec::new();
    for link in links {
        let wanted = sanitize(&link.name);
        let mut name = wanted.clone();
        let free = |n: &str, used: &HashSet<String>| {
            !n.is_empty() && !used.contains(n) && !used.contains(&format!("{n}_cross"))
        };
        if !free(&name, &used) {
            name = format!("link{}", link.num);
            let mut k = 2;
            while !free(&name, &used) {
                name = format!("link{}_{k}", link.num);
                k += 1;
            }
        }
        if name != link.name {
            renamed.push(format!("`{}` → `{name}`", link.name));
        }
        used.insert(name.clone());
        used.insert(format!("{name}_cross"));
        names.push(name);
    }
    if !renamed.is_empty() {
        warnings.push(format!(
            "link names made URDF-safe and unique: {}",
            names_list(&renamed.iter().map(String::as_str).collect::<Vec<_>>())
        ));
    }
    names
}

/// Whether a cable's attachments run from the tip towards the base (its first attachment on a
/// later link than its last): such a cable is written reversed, base first.
fn reversed(cable: &Cable) -> bool {
    match (cable.attachments.first(), cable.attachments.last()) {
        (Some(first), Some(last)) => first.link > last.link,
        _ => false,
    }
}

/// At most six names, then how many more.
fn names_list(names: &[&str]) -> String {
    const SHOWN: usize = 6;
    let mut out = names.iter().take(SHOWN).copied().collect::<Vec<_>>().join(", ");
    if names.len() > SHOWN {
        out.push_str(&format!(" and {} more", names.len() - SHOWN));
    }
    out
}

/// Where the tip sits: (link number, point in its frame, what it is).
struct Tip {
    link: usize,
    point: [f64; 3],
    what: String,
}

fn tip(model: &CasprModel, warnings: &mut Vec<String>) -> Result<Tip> {
    let last = model.links.len();
    match &model.operational_point {
        Some(op) => {
            if op.link != last {
                return Err(ImportError::TipNotOnLastLink {
                    at: op.place.clone(),
                    link: op.link,
                    last,
                });
            }
            if op.ignored > 0 {
                warnings.push(format!(
                    "operational set `{}`: the tip is its first point, `{}`; {} other space(s) ignored",
                    op.set, op.name, op.ignored
                ));
            }
            Ok(Tip {
                link: op.link,
                point: op.offset,
                what: format!("operational space `{}` of set `{}` (its <offset>)", op.name, op.set),
            })
        }
        None => {
            let link = &model.links[last - 1];
            if model.operational_file_given {
                warnings.push(
                    "the operational spaces file names no default_operational_set: the tip is the last link's <end_location>"
                        .to_owned(),
                );
            }
            Ok(Tip {
                link: last,
                point: link.end_location,
                what: format!("the <end_location> of the last link, {} `{}`", link.num, link.name),
            })
        }
    }
}

/// The limits written: the top-level `[min, max]` and, when cables differ, each cable's.
struct Limits {
    common: [f64; 2],
    per_cable: Option<Vec<[f64; 2]>>,
}

fn tension_limits(
    cables: &[Cable],
    options: &ImportOptions,
    warnings: &mut Vec<String>,
) -> Result<Limits> {
    if let Some(common) = options.tension_limits {
        let differ = cables.iter().any(|c| [c.force_min, c.force_max] != common);
        if differ {
            warnings.push(format!(
                "tension limits [{}, {}] N from the options replace the file's force_min/force_max",
                common[0], common[1]
            ));
        }
        return Ok(Limits { common, per_cable: None });
    }
    let mut clamped = Vec::new();
    let mut zero = Vec::new();
    let mut placeholder = Vec::new();
    let mut each = Vec::with_capacity(cables.len());
    for c in cables {
        if c.force_min >= c.force_max {
            return Err(ImportError::InvalidTensionLimits {
                at: c.properties.clone(),
                cable: c.name.clone(),
                f_min: c.force_min,
                f_max: c.force_max,
            });
        }
        let mut lo = c.force_min;
        if lo < 0.0 {
            clamped.push(c.name.as_str());
            lo = 0.0;
        } else if lo == 0.0 {
            zero.push(c.name.as_str());
        }
        if c.force_max >= PLACEHOLDER_FORCE_MAX {
            placeholder.push(c.name.as_str());
        }
        each.push([lo, c.force_max]);
    }
    if !clamped.is_empty() {
        warnings.push(format!(
            "cable(s) {}: force_min < 0 clamped to 0 N (sinew-routing needs 0 ≤ f_min < f_max; a cable cannot push)",
            names_list(&clamped)
        ));
    }
    if !zero.is_empty() {
        warnings.push(format!(
            "cable(s) {}: force_min = 0 N, a placeholder? The tension distribution may then slacken cables; give --tension-limits for a real minimum",
            names_list(&zero)
        ));
    }
    if !placeholder.is_empty() {
        warnings.push(format!(
            "cable(s) {}: force_max ≥ {PLACEHOLDER_FORCE_MAX:e} N, a placeholder rather than a rating? Give --tension-limits for the cables' real limits",
            names_list(&placeholder)
        ));
    }
    let first = each[0];
    if each.iter().all(|l| *l == first) {
        return Ok(Limits { common: first, per_cable: None });
    }
    let lo = each.iter().map(|l| l[0]).fold(f64::INFINITY, f64::min);
    let hi = each.iter().map(|l| l[1]).fold(f64::NEG_INFINITY, f64::max);
    warnings.push(format!(
        "the cables' force limits differ: written per cable (`tension_limits` in each [[cable]], a field sinew-routing is gaining; older versions refuse the file) and [{lo}, {hi}] N, the widest, at the top level"
    ));
    Ok(Limits { common: [lo, hi], per_cable: Some(each) })
}

/// Sinew reads two consecutive revolute joints with a massless body between them and
/// non-parallel axes as one universal joint (`sinew_robot::Robot::joint_groups`): say when two
/// CASPR `R_*` links will be read so.
fn joint_group_warnings(links: &[Link], warnings: &mut Vec<String>) {
    for pair in links.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        if a.joint.dof() == 1
            && b.joint.dof() == 1
            && a.mass == 0.0
            && a.joint.axes()[0] != b.joint.axes()[0]
        {
            warnings.push(format!(
                "links {} and {}: two revolute joints with a massless link between: Sinew reads them as one universal joint",
                a.num, b.num
            ));
        }
    }
}

/// `{}` of an f64: the shortest text that reads back to the same number.
fn n(v: f64) -> String {
    // -0 prints as 0.
    if v == 0.0 { "0".to_owned() } else { format!("{v}") }
}

fn xyz(v: [f64; 3]) -> String {
    format!("{} {} {}", n(v[0]), n(v[1]), n(v[2]))
}

/// A float as TOML reads it (always with a `.` or an exponent).
fn t(v: f64) -> String {
    if v == 0.0 { "0.0".to_owned() } else { format!("{v:?}") }
}

fn toml_vec(v: &[f64]) -> String {
    format!("[{}]", v.iter().map(|&x| t(x)).collect::<Vec<_>>().join(", "))
}

/// A TOML basic string.
fn toml_str(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => {
                let _ = write!(out, "\\u{:04X}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// Text safe inside an XML comment (no `--`) or a TOML comment (one line).
fn comment(s: &str) -> String {
    s.replace("--", "- -").replace(['\n', '\r'], " ")
}

/// Text safe in an XML attribute.
fn attr(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

fn write_urdf(model: &CasprModel, name: &str, names: &[String], tip: &Tip) -> String {
    let mut u = String::new();
    let _ = writeln!(u, "<?xml version=\"1.0\"?>");
    let _ = writeln!(
        u,
        "<!-- Imported from CASPR by `sinew import caspr` (sinew-import): bodies {}, cable set `{}`.",
        comment(&model.bodies_file),
        comment(&model.cable_set.id)
    );
    let _ = writeln!(
        u,
        "     Each CASPR link is its joint frame: R_* is one revolute joint at <parent><location>, U_* two"
    );
    let _ = writeln!(
        u,
        "     (the first axis into the massless `<link>_cross`, the second with zero translation). Inertias"
    );
    let _ = writeln!(
        u,
        "     are about the centre of mass (ref=\"joint\" converted by the parallel-axis theorem). Joint limits"
    );
    let _ = writeln!(
        u,
        "     are CASPR's q_min/q_max, or ±π where the file states none. effort and velocity are unused by Sinew. -->"
    );
    let _ = writeln!(u, "<robot name=\"{}\">", attr(name));
    let _ = writeln!(u, "  <link name=\"{BASE_LINK}\"/>");
    for link in &model.links {
        let me = &names[link.num];
        let parent = &names[link.num - 1];
        let _ = writeln!(u);
        let _ = writeln!(
            u,
            "  <!-- CASPR link {} `{}`: {} -->",
            link.num,
            comment(&link.name),
            link.joint.caspr_name()
        );
        if !link.limits_stated {
            let _ = writeln!(u, "  <!-- no q_min/q_max in the CASPR file: limits ±π -->");
        }
        let axes = link.joint.axes();
        for (i, axis) in axes.iter().enumerate() {
            let (from, to, origin) = match (axes.len(), i) {
                (1, _) => (parent.clone(), me.clone(), link.parent_location),
                (_, 0) => (parent.clone(), format!("{me}_cross"), link.parent_location),
                _ => (format!("{me}_cross"), me.clone(), [0.0; 3]),
            };
            let _ =
                writeln!(u, "  <joint name=\"{}_{}\" type=\"revolute\">", attr(me), axis.name());
            let _ = writeln!(
                u,
                "    <parent link=\"{}\"/><child link=\"{}\"/>",
                attr(&from),
                attr(&to)
            );
            let _ = writeln!(
                u,
                "    <origin xyz=\"{}\" rpy=\"0 0 0\"/><axis xyz=\"{}\"/>",
                xyz(origin),
                xyz(axis.unit())
            );
            let _ = writeln!(
                u,
                "    <limit lower=\"{}\" upper=\"{}\" effort=\"0\" velocity=\"0\"/>",
                n(link.q_min[i]),
                n(link.q_max[i])
            );
            let _ = writeln!(u, "  </joint>");
            if axes.len() == 2 && i == 0 {
                let _ = writeln!(u, "  <link name=\"{}_cross\"/>", attr(me));
            }
        }
        if link.mass == 0.0 && link.inertia_com == [[0.0; 3]; 3] {
            let _ = writeln!(u, "  <link name=\"{}\"/>", attr(me));
        } else {
            let i = link.inertia_com;
            let _ = writeln!(u, "  <link name=\"{}\">", attr(me));
            let _ = writeln!(u, "    <inertial>");
            let _ = writeln!(u, "      <origin xyz=\"{}\" rpy=\"0 0 0\"/>", xyz(link.com));
            let _ = writeln!(u, "      <mass value=\"{}\"/>", n(link.mass));
            let _ = writeln!(
                u,
                "      <inertia ixx=\"{}\" ixy=\"{}\" ixz=\"{}\" iyy=\"{}\" iyz=\"{}\" izz=\"{}\"/>",
                n(i[0][0]),
                n(i[0][1]),
                n(i[0][2]),
                n(i[1][1]),
                n(i[1][2]),
                n(i[2][2])
            );
            let _ = writeln!(u, "    </inertial>");
            let _ = writeln!(u, "  </link>");
        }
    }
    let _ = writeln!(u);
    let _ = writeln!(u, "  <!-- The tip: {} -->", comment(&tip.what));
    let _ = writeln!(u, "  <joint name=\"tip_joint\" type=\"fixed\">");
    let _ = writeln!(
        u,
        "    <parent link=\"{}\"/><child link=\"{TIP_LINK}\"/>",
        attr(&names[tip.link])
    );
    let _ = writeln!(u, "    <origin xyz=\"{}\" rpy=\"0 0 0\"/>", xyz(tip.point));
    let _ = writeln!(u, "  </joint>");
    let _ = writeln!(u, "  <link name=\"{TIP_LINK}\"/>");
    let _ = writeln!(u, "</robot>");
    u
}

fn write_robot_toml(model: &CasprModel, urdf_file: &str, tip: &Tip) -> String {
    let mut r = String::new();
    let _ = writeln!(
        r,
        "# Imported from CASPR by `sinew import caspr` (sinew-import): bodies {}.",
        comment(&model.bodies_file)
    );
    let _ = writeln!(r, "urdf = {}", toml_str(urdf_file));
    let _ = writeln!(r, "# The tip: {}.", comment(&tip.what));
    let _ = writeln!(r, "tip_link = {}", toml_str(TIP_LINK));
    let _ = writeln!(
        r,
        "# CASPR's gravity: -m g along z of the base frame, g = {CASPR_GRAVITY} m/s² (SystemModel.GRAVITY_CONSTANT)."
    );
    let _ = writeln!(r, "gravity = {}", toml_vec(&[0.0, 0.0, -CASPR_GRAVITY]));
    r
}

fn write_cables_toml(
    model: &CasprModel,
    options: &ImportOptions,
    names: &[String],
    limits: &Limits,
) -> String {
    let mut c = String::new();
    let set = &model.cable_set;
    let _ = writeln!(
        c,
        "# Imported from CASPR by `sinew import caspr` (sinew-import): cables {}, cable set `{}`{}.",
        comment(&model.cables_file),
        comment(&set.id),
        if set.is_default { " (the file's default_cable_set)" } else { "" }
    );
    let _ = writeln!(
        c,
        "# Each cable's holes are its CASPR attachments in order, as points in the link frame (the joint"
    );
    let _ = writeln!(
        c,
        "# frame; attachment_reference=\"com\" offsets converted by adding the link's <com_location>)."
    );
    let _ = writeln!(
        c,
        "# CASPR's ideal cables have no stiffness: the material and the free length are the import's"
    );
    let _ = writeln!(
        c,
        "# options (defaults: E = 200 GPa steel, d = 1 mm, free length 0.5 m); here E = {} Pa, d = {} m,",
        t(options.youngs_modulus),
        t(options.diameter)
    );
    let _ = writeln!(c, "# free length {} m.", t(options.free_length));
    match &limits.per_cable {
        None => {
            let _ = writeln!(c, "# tension_limits: force_min (clamped to ≥ 0) and force_max, N.");
        }
        Some(_) => {
            let _ = writeln!(
                c,
                "# The cables' force limits differ: each [[cable]] has its own tension_limits; the top-level value is"
            );
            let _ = writeln!(c, "# the widest [min of force_min, max of force_max], N.");
        }
    }
    let _ = writeln!(c, "tension_limits = {}", toml_vec(&limits.common));
    let _ = writeln!(c, "free_length = {}", t(options.free_length));
    let _ = writeln!(c);
    let _ = writeln!(c, "[material]");
    let _ = writeln!(c, "youngs_modulus = {}", t(options.youngs_modulus));
    let _ = writeln!(c, "diameter = {}", t(options.diameter));
    for (k, cable) in set.cables.iter().enumerate() {
        let _ = writeln!(c);
        let _ = writeln!(c, "[[cable]]");
        let _ = writeln!(c, "name = {}", toml_str(&cable.name));
        if let Some(each) = &limits.per_cable {
            let _ = writeln!(c, "tension_limits = {}", toml_vec(&each[k]));
        }
        let _ = writeln!(c, "holes = [");
        let mut holes: Vec<_> = cable.attachments.iter().collect();
        if reversed(cable) {
            holes.reverse();
        }
        for a in holes {
            let _ = writeln!(
                c,
                "  {{ link = {}, point = {} }},",
                toml_str(&names[a.link]),
                toml_vec(&a.point)
            );
        }
        let _ = writeln!(c, "]");
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::JointKind;

    #[test]
    fn names_are_made_safe() {
        assert_eq!(sanitize(" a b/c "), "a_b_c");
        assert_eq!(toml_str("a\"b\\c"), "\"a\\\"b\\\\c\"");
        assert_eq!(t(2.0e11), "200000000000.0");
        assert_eq!(t(1.0e-7), "1e-7");
        assert_eq!(n(-0.0), "0");
        assert_eq!(comment("a--b"), "a- -b");
    }

    #[test]
    fn joint_kinds_round_trip() {
        for name in ["R_X", "R_Y", "R_Z", "U_XY", "U_XZ", "U_YZ"] {
            let kind = JointKind::from_caspr(name);
            assert_eq!(kind.map(JointKind::caspr_name), Some(name));
        }
        assert_eq!(JointKind::from_caspr("S_EULER_XYZ"), None);
    }
}
