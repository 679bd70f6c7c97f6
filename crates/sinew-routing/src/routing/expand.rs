//! The two forms of the cables in a routing file, expanded to one list of raw cables, and
//! each checked against the robot (links, joint, anchor, free length) and the material.

use nalgebra::Vector3;
use sinew_robot::Robot;

use super::friction::{
    DEFAULT_ENTRY_DIRECTION, check_coefficient, check_entry_direction, check_pattern_names,
};
use super::{Hole, MAX_HOLE_OFFSET};
use crate::error::{JointProblem, Result, RoutingError};
use crate::spec::{PatternModel, PerJoint, RoutingSpec};

/// A cable after expanding either form, before it is checked against the robot.
pub(super) struct RawCable {
    pub(super) name: String,
    /// `cable[i]` or `pattern` (for messages).
    pub(super) field: String,
    pub(super) joint: Option<usize>,
    /// An explicit free length, with its field.
    pub(super) free_length: Option<(f64, String)>,
    /// Explicit tension limits, with their field.
    pub(super) tension_limits: Option<([f64; 2], String)>,
    /// Link, point in the link frame, field naming the link.
    pub(super) holes: Vec<(String, [f64; 3], String)>,
    /// An explicit friction coefficient, with its field.
    pub(super) friction: Option<(f64, String)>,
    /// An explicit entry direction, with its field.
    pub(super) entry_direction: Option<([f64; 3], String)>,
}

/// The cross-section area from the material, checked.
pub(super) fn check_material(file: &str, spec: &RoutingSpec) -> Result<f64> {
    let material = &spec.material;
    let bad = |field, value, message| RoutingError::InvalidMaterial {
        file: file.to_owned(),
        field,
        value,
        message,
    };
    let e = material.youngs_modulus;
    if !(e.is_finite() && e > 0.0) {
        return Err(bad("material.youngs_modulus", e, "Young's modulus must be finite and > 0 Pa"));
    }
    let area = match (material.diameter, material.area) {
        (Some(_), Some(a)) => {
            return Err(bad("material.area", a, "give either diameter or area, not both"));
        }
        (None, None) => {
            return Err(bad("material.area", f64::NAN, "give the cable's diameter or area"));
        }
        (Some(d), None) => {
            if !(d.is_finite() && d > 0.0) {
                return Err(bad("material.diameter", d, "diameter must be finite and > 0 m"));
            }
            std::f64::consts::PI * d * d / 4.0
        }
        (None, Some(a)) => a,
    };
    if !(area.is_finite() && area > 0.0) {
        let field = if material.area.is_some() { "material.area" } else { "material.diameter" };
        return Err(bad(field, area, "cross-section area must be finite and > 0 m²"));
    }
    Ok(area)
}

/// Check a per-joint value list: its length and every value.
pub(super) fn check_per_joint(
    file: &str,
    field: &str,
    values: &PerJoint,
    joints: usize,
    ok: impl Fn(f64) -> bool,
    expected: &'static str,
) -> Result<()> {
    if let PerJoint::Each(list) = values
        && list.len() != joints
    {
        return Err(RoutingError::PatternSize {
            file: file.to_owned(),
            field: field.to_owned(),
            expected: joints,
            got: list.len(),
        });
    }
    for (i, &v) in values.values().iter().enumerate() {
        if !(v.is_finite() && ok(v)) {
            let field = match values {
                PerJoint::Uniform(_) => field.to_owned(),
                PerJoint::Each(_) => format!("{field}[{i}]"),
            };
            return Err(RoutingError::InvalidValue {
                file: file.to_owned(),
                cable: String::new(),
                field,
                value: v,
                expected,
            });
        }
    }
    Ok(())
}

pub(super) fn expand_pattern(
    file: &str,
    pattern: &crate::spec::Pattern,
    n: usize,
) -> Result<Vec<RawCable>> {
    for (field, list) in [
        ("pattern.proximal_discs", &pattern.proximal_discs),
        ("pattern.distal_discs", &pattern.distal_discs),
    ] {
        if list.len() != n {
            return Err(RoutingError::PatternSize {
                file: file.to_owned(),
                field: field.to_owned(),
                expected: n,
                got: list.len(),
            });
        }
    }
    let radius = |field: &str, own: &Option<PerJoint>| -> Result<PerJoint> {
        let (field, value) = match (own, &pattern.radius) {
            (Some(v), _) => (format!("pattern.{field}"), v.clone()),
            (None, Some(v)) => ("pattern.radius".to_owned(), v.clone()),
            (None, None) => {
                return Err(RoutingError::InvalidValue {
                    file: file.to_owned(),
                    cable: String::new(),
                    field: format!("pattern.{field}"),
                    value: f64::NAN,
                    expected: "give pattern.radius (or pattern.proximal_radius and pattern.distal_radius)",
                });
            }
        };
        let ok = |v: f64| v > 0.0 && v <= MAX_HOLE_OFFSET;
        check_per_joint(file, &field, &value, n, ok, "finite, > 0 m and at most 1 km")?;
        Ok(value)
    };
    let proximal_radius = radius("proximal_radius", &pattern.proximal_radius)?;
    let distal_radius = radius("distal_radius", &pattern.distal_radius)?;
    for (field, v) in
        [("pattern.theta0", pattern.theta0), ("pattern.joint_offset", pattern.joint_offset)]
    {
        if !v.is_finite() {
            return Err(RoutingError::InvalidValue {
                file: file.to_owned(),
                cable: String::new(),
                field: field.to_owned(),
                value: v,
                expected: "a finite angle in rad",
            });
        }
    }
    let hole = |disc: &[String], side: &str, radius: &PerJoint, joint: usize, theta: f64| {
        let r = radius.get(joint).unwrap_or(f64::NAN);
        (
            disc[joint].clone(),
            [r * theta.cos(), r * theta.sin(), 0.0],
            format!("pattern.{side}_discs[{joint}]"),
        )
    };
    let mut cables = Vec::with_capacity(3 * n);
    for i in 0..n {
        for k in 0..3 {
            let theta = pattern.theta0
                + std::f64::consts::TAU * k as f64 / 3.0
                + i as f64 * pattern.joint_offset;
            let mut holes = Vec::new();
            let first = match pattern.model {
                PatternModel::Decoupled => i,
                PatternModel::Routed => 0,
            };
            for j in first..i {
                holes.push(hole(&pattern.proximal_discs, "proximal", &proximal_radius, j, theta));
                holes.push(hole(&pattern.distal_discs, "distal", &distal_radius, j, theta));
            }
            holes.push(hole(&pattern.proximal_discs, "proximal", &proximal_radius, i, theta));
            holes.push(hole(&pattern.distal_discs, "distal", &distal_radius, i, theta));
            let name = format!("j{}c{}", i + 1, k + 1);
            let keys = pattern.cables.get(&name);
            let field = |key: &str| format!("pattern.cable.{name}.{key}");
            cables.push(RawCable {
                field: "pattern".to_owned(),
                joint: Some(i),
                free_length: None,
                tension_limits: None,
                holes,
                friction: keys
                    .and_then(|f| f.friction_coefficient)
                    .map(|v| (v, field("friction_coefficient"))),
                entry_direction: keys
                    .and_then(|f| f.entry_direction)
                    .map(|v| (v, field("entry_direction"))),
                name,
            });
        }
    }
    let names = cables.iter().map(|c| c.name.as_str()).collect();
    check_pattern_names(file, pattern, &names, n)?;
    Ok(cables)
}

pub(super) fn expand_explicit(cables: &[crate::spec::ExplicitCable]) -> Vec<RawCable> {
    cables
        .iter()
        .enumerate()
        .map(|(c, cable)| RawCable {
            name: cable.name.clone(),
            field: format!("cable[{c}]"),
            joint: cable.joint,
            free_length: cable.free_length.map(|v| (v, format!("cable[{c}].free_length"))),
            tension_limits: cable.tension_limits.map(|v| (v, format!("cable[{c}].tension_limits"))),
            friction: cable
                .friction_coefficient
                .map(|v| (v, format!("cable[{c}].friction_coefficient"))),
            entry_direction: cable
                .entry_direction
                .map(|v| (v, format!("cable[{c}].entry_direction"))),
            holes: cable
                .holes
                .iter()
                .enumerate()
                .map(|(h, hole)| {
                    (hole.link.clone(), hole.point, format!("cable[{c}].holes[{h}].link"))
                })
                .collect(),
        })
        .collect()
}

/// Check one cable against the robot: its joint, free length, limits and holes.
pub(super) fn check_cable(
    file: &str,
    robot: &Robot,
    spec: &RoutingSpec,
    cable: &RawCable,
) -> Result<CheckedCable> {
    let name = &cable.name;
    if cable.holes.len() < 2 {
        return Err(RoutingError::TooFewHoles {
            file: file.to_owned(),
            cable: name.clone(),
            field: format!("{}.holes", cable.field),
            holes: cable.holes.len(),
        });
    }
    let mut holes = Vec::with_capacity(cable.holes.len());
    for (link, point, field) in &cable.holes {
        if robot.link(link).is_err() {
            return Err(RoutingError::UnknownLink {
                file: file.to_owned(),
                cable: name.clone(),
                field: field.clone(),
                link: link.clone(),
            });
        }
        if let Some(&v) = point.iter().find(|v| !(v.is_finite() && v.abs() <= MAX_HOLE_OFFSET)) {
            return Err(RoutingError::InvalidValue {
                file: file.to_owned(),
                cable: name.clone(),
                field: field.replace(".link", ".point"),
                value: v,
                expected: "finite coordinates in m, within 1 km of the link's origin",
            });
        }
        let point = Vector3::from(*point);
        let body_point = robot.link_point(link, point)?;
        holes.push(Hole { link: link.clone(), point, body_point });
    }
    // At least two holes: checked above.
    let anchor = holes.last().map_or(0, |h| h.body_point.body);
    let anchor_field = cable.holes.last().map(|h| h.2.clone()).unwrap_or_default();
    let wrong = |field: String, problem: JointProblem| RoutingError::WrongJoint {
        file: file.to_owned(),
        cable: name.clone(),
        field,
        problem,
    };
    let groups = robot.joint_groups();
    let n = groups.len();
    // The joint whose revolute joints move the anchor and no further joint's do.
    let anchor_joint = anchor.checked_sub(1).and_then(|d| robot.joint_of_dof(d));
    let joint = match cable.joint {
        Some(j) => {
            let field = format!("{}.joint", cable.field);
            if j >= n {
                return Err(wrong(field, JointProblem::NoSuchJoint { joint: j, joints: n }));
            }
            if anchor_joint != Some(j) {
                let (first, last) = (groups[j].start + 1, groups[j].end);
                return Err(wrong(
                    anchor_field,
                    JointProblem::AnchorElsewhere { joint: j, anchor_body: anchor, first, last },
                ));
            }
            j
        }
        None => match anchor_joint {
            Some(j) => j,
            None => return Err(wrong(anchor_field, JointProblem::AnchorOnBase)),
        },
    };
    for (hole, raw) in holes.iter().zip(&cable.holes) {
        if hole.body_point.body > anchor {
            return Err(RoutingError::HoleOffChain {
                file: file.to_owned(),
                cable: name.clone(),
                field: raw.2.clone(),
                link: hole.link.clone(),
                body: hole.body_point.body,
                anchor_body: anchor,
            });
        }
    }
    let proximal = holes.iter().map(|h| h.body_point.body).min().unwrap_or(anchor);
    let joint_body = groups[joint].start;
    if proximal > joint_body {
        return Err(wrong(
            format!("{}.holes", cable.field),
            JointProblem::NotCrossing { joint, proximal: joint_body },
        ));
    }
    let free_length = match &cable.free_length {
        Some((v, field)) => {
            if !(v.is_finite() && *v >= 0.0) {
                return Err(RoutingError::InvalidValue {
                    file: file.to_owned(),
                    cable: name.clone(),
                    field: field.clone(),
                    value: *v,
                    expected: "finite and ≥ 0 m",
                });
            }
            *v
        }
        None => spec.free_length.as_ref().and_then(|f| f.get(joint)).unwrap_or(0.0),
    };
    let limits = match &cable.tension_limits {
        Some(([f_min, f_max], field)) => {
            let (f_min, f_max) = (*f_min, *f_max);
            if !valid_limits(f_min, f_max) {
                let value = if f_min.is_finite() && f_min >= 0.0 { f_max } else { f_min };
                return Err(RoutingError::InvalidValue {
                    file: file.to_owned(),
                    cable: name.clone(),
                    field: field.clone(),
                    value,
                    expected: "[f_min, f_max] with 0 ≤ f_min < f_max, finite, N",
                });
            }
            [f_min, f_max]
        }
        None => spec.tension_limits,
    };
    let friction_coefficient = match &cable.friction {
        Some((v, field)) => check_coefficient(file, name, field, *v)?,
        None => spec.friction_coefficient.unwrap_or(0.0),
    };
    let entry_direction = match &cable.entry_direction {
        Some((v, field)) => check_entry_direction(file, name, field, *v)?,
        None => Vector3::from(DEFAULT_ENTRY_DIRECTION),
    };
    // At least two holes (checked above): the first hole's link is known to the robot.
    let first_link = robot.link(&holes[0].link)?;
    let entry_in_body = first_link.body_m_link.rotation * entry_direction;
    Ok(CheckedCable {
        joint,
        free_length,
        limits,
        holes,
        friction_coefficient,
        entry_direction,
        entry_in_body,
    })
}

/// A cable checked against the robot.
pub(super) struct CheckedCable {
    /// The joint it drives.
    pub(super) joint: usize,
    /// Its free length, m.
    pub(super) free_length: f64,
    /// Its tension limits, N.
    pub(super) limits: [f64; 2],
    /// Its holes.
    pub(super) holes: Vec<Hole>,
    /// Its friction coefficient μ.
    pub(super) friction_coefficient: f64,
    /// Its entry direction, unit, in its first hole's link frame.
    pub(super) entry_direction: Vector3<f64>,
    /// The same in the first hole's body frame.
    pub(super) entry_in_body: Vector3<f64>,
}

/// Tension limits a cable can have: `0 ≤ f_min < f_max`, both finite.
pub(super) fn valid_limits(f_min: f64, f_max: f64) -> bool {
    f_min.is_finite() && f_max.is_finite() && f_min >= 0.0 && f_min < f_max
}
