//! Building a [`Routing`] from a parsed routing file and its robot: expanding either form of
//! the cables, checking them against the robot, and evaluating them at Q = 0.

use std::collections::HashSet;
use std::ops::Range;
use std::path::Path;

use nalgebra::Vector3;
use sinew_robot::{BodyPoint, Robot, RobotData};

use super::expand::{
    CheckedCable, check_cable, check_material, check_per_joint, expand_explicit, expand_pattern,
    valid_limits,
};
use super::friction::check_coefficient;
use super::{Cable, MIN_SEGMENT_LENGTH, ROUTING_FILE, Routing, RoutingModel, Segment, SegmentPlan};
use crate::error::{Result, RoutingError};
use crate::spec::{PatternModel, RoutingSpec};

impl Routing {
    /// Build a routing from a parsed routing file and the robot it belongs to.
    ///
    /// `source_name` names the file in messages. Checks every cable against the robot (links
    /// known and on the cable's chain, the anchor beyond the joint it drives), the material and
    /// limits, and evaluates the routing at Q = 0 to reject zero-length segments and to fix
    /// each cable's elastic length and stiffness.
    ///
    /// # Errors
    /// Every load-time variant of [`RoutingError`].
    pub fn new(robot: &Robot, spec: &RoutingSpec, source_name: &str) -> Result<Routing> {
        let file = source_name.to_owned();
        let dof = robot.dof();
        let n = robot.joint_count();
        let area = check_material(&file, spec)?;
        let [f_min, f_max] = spec.tension_limits;
        if !valid_limits(f_min, f_max) {
            return Err(RoutingError::InvalidTensionLimits { file, f_min, f_max });
        }
        let friction_coefficient = match spec.friction_coefficient {
            Some(mu) => check_coefficient(&file, "", "friction_coefficient", mu)?,
            None => 0.0,
        };
        if let Some(free) = &spec.free_length {
            check_per_joint(&file, "free_length", free, n, |v| v >= 0.0, "finite and ≥ 0 m")?;
        }

        let (model, raw) = match (&spec.pattern, spec.cables.is_empty()) {
            (Some(_), false) => {
                return Err(RoutingError::CableForm {
                    file,
                    message: "give the cables either as a [pattern] or as [[cable]] entries, not both",
                });
            }
            (None, true) => {
                return Err(RoutingError::CableForm {
                    file,
                    message: "no cables: give a [pattern] or [[cable]] entries",
                });
            }
            (Some(pattern), true) => {
                if !robot.is_universal() {
                    let robot = robot.name().to_owned();
                    return Err(RoutingError::NotUniversal { file, robot, dof });
                }
                let model = match pattern.model {
                    PatternModel::Decoupled => RoutingModel::Decoupled,
                    PatternModel::Routed => RoutingModel::Routed,
                };
                (model, expand_pattern(&file, pattern, n)?)
            }
            (None, false) => (RoutingModel::Explicit, expand_explicit(&spec.cables)),
        };

        // Check every cable against the robot, then order them by joint (stable sort).
        let mut names = HashSet::new();
        let mut checked = Vec::with_capacity(raw.len());
        for cable in raw {
            if !names.insert(cable.name.clone()) {
                return Err(RoutingError::DuplicateCable {
                    file,
                    cable: cable.name.clone(),
                    field: cable.field.clone(),
                });
            }
            let c = check_cable(&file, robot, spec, &cable)?;
            checked.push((cable, c));
        }
        checked.sort_by_key(|c| c.1.joint);

        // Evaluate at Q = 0: segment lengths, elastic lengths, stiffness.
        let mut rdata = RobotData::new(robot);
        robot.forward_kinematics(&mut rdata, &vec![0.0; dof])?;
        let mut out_cables = Vec::with_capacity(checked.len());
        let mut segments = Vec::new();
        let mut hessian_len = 0;
        let mut max_span = 0;
        for (c, (r, checked)) in checked.into_iter().enumerate() {
            let CheckedCable {
                joint,
                free_length,
                limits,
                holes,
                friction_coefficient,
                entry_direction,
                entry_in_body,
            } = checked;
            let first_segment = segments.len();
            let mut routed_length = 0.0;
            let (mut lo, mut hi) = (usize::MAX, 0);
            for s in 0..holes.len() - 1 {
                let (a, b) = (holes[s].body_point, holes[s + 1].body_point);
                let length = (world(&rdata, &b)? - world(&rdata, &a)?).norm();
                if !(length.is_finite() && length >= MIN_SEGMENT_LENGTH) {
                    return Err(RoutingError::ZeroLengthSegment {
                        file,
                        cable: r.name.clone(),
                        segment: s,
                        from: r.holes[s].2.clone(),
                        to: r.holes[s + 1].2.clone(),
                        length,
                        min: MIN_SEGMENT_LENGTH,
                    });
                }
                routed_length += length;
                let (proximal, distal) = if a.body <= b.body { (a, b) } else { (b, a) };
                let dofs = proximal.body..distal.body;
                if !dofs.is_empty() {
                    lo = lo.min(dofs.start);
                    hi = hi.max(dofs.end);
                }
                let span = dofs.len();
                segments.push(Segment {
                    cable: c,
                    index: s,
                    proximal,
                    distal,
                    dofs,
                    hessian_offset: hessian_len,
                    proximal_point: [proximal.point.x, proximal.point.y, proximal.point.z],
                    distal_point: [distal.point.x, distal.point.y, distal.point.z],
                });
                hessian_len += span * span;
                max_span = max_span.max(span);
            }
            let elastic_length = free_length + routed_length;
            let stiffness = spec.material.youngs_modulus * area / elastic_length;
            if !(stiffness.is_finite() && stiffness > 0.0) {
                return Err(RoutingError::InvalidValue {
                    file,
                    cable: r.name.clone(),
                    field: "stiffness E·A/l".to_owned(),
                    value: stiffness,
                    expected: "finite and > 0 N/m (check the material and the free length)",
                });
            }
            out_cables.push(Cable {
                name: r.name.clone(),
                joint,
                tension_limits: limits,
                holes,
                free_length,
                routed_length,
                elastic_length,
                stiffness,
                segments: first_segment..segments.len(),
                dofs: if lo < hi { lo..hi } else { 0..0 },
                friction_coefficient,
                entry_direction,
                entry_in_body,
            });
        }

        let dof_blocks = dof_blocks(dof, &out_cables);
        let groups = robot.joint_groups();
        let decoupled = out_cables.iter().all(|c| {
            let own = &groups[c.joint];
            c.dofs.start >= own.start && c.dofs.end <= own.end
        });
        let cable_limits: Vec<[f64; 2]> = out_cables.iter().map(|c| c.tension_limits).collect();
        Ok(Routing {
            dof_blocks,
            decoupled,
            source: file,
            robot: robot.name().to_owned(),
            dof,
            model,
            youngs_modulus: spec.material.youngs_modulus,
            area,
            tension_limits: spec.tension_limits,
            friction_coefficient,
            uniform_limits: cable_limits.iter().all(|l| *l == spec.tension_limits),
            cable_limits,
            joint_groups: groups.to_vec(),
            cable_joint: out_cables.iter().map(|c| c.joint).collect(),
            stiffness: out_cables.iter().map(|c| c.stiffness).collect(),
            plan: SegmentPlan::new(&mut segments, out_cables.len()),
            cables: out_cables,
            segments,
            hessian_len,
            max_span,
        })
    }

    /// Parse a routing file's text and build the routing for `robot`.
    ///
    /// # Errors
    /// [`RoutingError::Parse`] for malformed TOML, then see [`Routing::new`].
    pub fn from_toml_str(text: &str, source_name: &str, robot: &Robot) -> Result<Routing> {
        let spec = RoutingSpec::from_toml_str(text, source_name)?;
        Routing::new(robot, &spec, source_name)
    }
}

/// Load a routing for `robot` from a robot folder (its `cables.toml`) or from a routing file.
///
/// # Errors
/// [`RoutingError::Io`] when the file cannot be read, then see [`Routing::from_toml_str`].
pub fn load(path: impl AsRef<Path>, robot: &Robot) -> Result<Routing> {
    let path = path.as_ref();
    let path = if path.is_dir() { path.join(ROUTING_FILE) } else { path.to_path_buf() };
    let text = std::fs::read_to_string(&path)
        .map_err(|source| RoutingError::Io { path: path.clone(), source })?;
    Routing::from_toml_str(&text, &path.display().to_string(), robot)
}

/// [`Routing::dof_blocks`] of cables over `dof` DOFs.
fn dof_blocks(dof: usize, cables: &[Cable]) -> Vec<Range<usize>> {
    // joined[d]: DOFs d − 1 and d are in one block.
    let mut joined = vec![false; dof];
    for cable in cables {
        for d in cable.dofs.start + 1..cable.dofs.end.min(dof) {
            joined[d] = true;
        }
    }
    let mut blocks: Vec<Range<usize>> = Vec::new();
    for d in 0..dof {
        match blocks.last_mut() {
            Some(block) if joined[d] => block.end = d + 1,
            _ => blocks.push(d..d + 1),
        }
    }
    blocks
}

fn world(rdata: &RobotData, p: &BodyPoint) -> Result<Vector3<f64>> {
    let pose = rdata.body_pose(p.body).ok_or_else(|| RoutingError::WorkspaceMismatch {
        what: "robot workspace (bodies)",
        expected: p.body + 1,
        got: p.body,
    })?;
    Ok(pose.rotation * p.point + pose.translation.vector)
}
