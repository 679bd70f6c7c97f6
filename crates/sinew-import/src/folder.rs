//! A CASPR model → a Sinew robot folder: the importer's decisions (the names, the tip, the
//! tension limits, the order of each cable's holes, every warning) and the [`RobotFolder`] they
//! make. The files' text is written by `write/` from these decisions.

use std::collections::HashSet;
use std::path::Path;

use crate::bodies::Link;
use crate::cables::Cable;
use crate::error::{ImportError, Result};
use crate::write::Tip;
use crate::write::toml_files::{CableToml, CablesToml, RobotToml};
use crate::write::urdf::write_urdf;
use crate::{BASE_LINK, CasprModel, ImportOptions, TIP_LINK};

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
    let robot_toml = RobotToml {
        bodies_file: &model.bodies_file,
        urdf_file: &urdf_file,
        tip_link: TIP_LINK,
        tip: &tip,
    }
    .text();
    let cables_toml = cables_toml(model, options, &names, &limits).text();
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

/// What `cables.toml` says: the options' material and free length, the decided limits, and
/// each cable's holes base first (a cable listed tip first reversed) on the links' URDF names.
fn cables_toml<'a>(
    model: &'a CasprModel,
    options: &ImportOptions,
    names: &'a [String],
    limits: &Limits,
) -> CablesToml<'a> {
    let set = &model.cable_set;
    let cables = set
        .cables
        .iter()
        .enumerate()
        .map(|(k, cable)| {
            let mut holes: Vec<_> =
                cable.attachments.iter().map(|a| (names[a.link].as_str(), a.point)).collect();
            if reversed(cable) {
                holes.reverse();
            }
            CableToml {
                name: &cable.name,
                tension_limits: limits.per_cable.as_ref().map(|each| each[k]),
                holes,
            }
        })
        .collect();
    CablesToml {
        cables_file: &model.cables_file,
        cable_set: &set.id,
        default_set: set.is_default,
        youngs_modulus: options.youngs_modulus,
        diameter: options.diameter,
        free_length: options.free_length,
        tension_limits: limits.common,
        cables,
    }
}

#[cfg(test)]
mod tests {
    use super::sanitize;

    #[test]
    fn names_are_made_safe() {
        assert_eq!(sanitize(" a b/c "), "a_b_c");
        assert_eq!(sanitize("a\"b\\c\nd"), "a_b_c_d");
    }
}
