//! The immutable routing: every cable as an ordered list of holes on the robot's bodies, checked
//! against the robot and expanded from either form of the file.

use std::collections::HashSet;
use std::ops::Range;
use std::path::Path;

use faer::MatMut;
use nalgebra::Vector3;
use serde::Serialize;
use sinew_robot::{BodyPoint, Robot, RobotData};

use crate::error::{Result, RoutingError};
use crate::spec::{PatternModel, PerJoint, RoutingSpec};

/// The name of the routing file inside a robot folder.
pub const ROUTING_FILE: &str = "cables.toml";

/// The least segment length accepted, m: shorter segments (at Q = 0 when loading, at any
/// configuration when evaluating) have no well-defined direction and are errors.
pub const MIN_SEGMENT_LENGTH: f64 = 1e-6;

/// How the routing was given.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum RoutingModel {
    /// Pattern form, each cable crossing only its own joint (spec §2, the paper's model).
    Decoupled,
    /// Pattern form, each cable also passing through every proximal disc (spec §2).
    Routed,
    /// Explicit form: cables given hole by hole.
    Explicit,
}

/// A hole: a point fixed in a link's frame, and the same point on the link's body.
#[derive(Debug, Clone, PartialEq)]
pub struct Hole {
    /// URDF link name.
    pub link: String,
    /// Coordinates in the link frame, m.
    pub point: Vector3<f64>,
    /// The same point on the body the link is folded into.
    pub body_point: BodyPoint,
}

/// A cable: a polyline through its holes, ending at its anchor (the last hole).
#[derive(Debug, Clone, PartialEq)]
pub struct Cable {
    /// Unique name (pattern cables: `j{i+1}c{k+1}`).
    pub name: String,
    /// The universal joint it drives, 0-based (revolute joints `2·joint`, `2·joint + 1`).
    pub joint: usize,
    /// Holes from the base to the anchor.
    pub holes: Vec<Hole>,
    /// Free length from the actuator, m.
    pub free_length: f64,
    /// Routed length at Q = 0, m.
    pub routed_length: f64,
    /// Elastic length `l_c = free_length + routed_length`, m.
    pub elastic_length: f64,
    /// Axial stiffness `k_c = E·A / l_c`, N/m (eq. 13).
    pub stiffness: f64,
    /// Its segments in [`Routing::segments`].
    pub segments: Range<usize>,
    /// The revolute joints its length depends on (empty only if it never crosses a joint,
    /// which loading rejects): `J_c[c, j]` is exactly zero outside this range.
    pub dofs: Range<usize>,
}

/// A straight segment between two consecutive holes of a cable.
///
/// Its length depends only on the revolute joints `dofs = A..B` between its proximal body `A`
/// and its distal body `B`: joints before `A` move both ends rigidly, joints from `B` on move
/// neither. Segments within one body (`A = B`) have a constant length and no derivative.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// The cable it belongs to.
    pub cable: usize,
    /// Its index within the cable: it joins holes `index` and `index + 1`.
    pub index: usize,
    /// The end on the lower-numbered body.
    pub proximal: BodyPoint,
    /// The end on the higher-numbered body.
    pub distal: BodyPoint,
    /// The revolute joints its length depends on.
    pub dofs: Range<usize>,
    /// Offset of its `|dofs| × |dofs|` Hessian block in the flat storage of the workspace.
    pub(crate) hessian_offset: usize,
    /// `proximal.point` as an array (for the inner loops).
    pub(crate) proximal_point: [f64; 3],
    /// `distal.point` as an array.
    pub(crate) distal_point: [f64; 3],
}

/// The immutable routing of a robot's cables (Pinocchio's *model* for cables).
///
/// Built once from a routing file and the [`Robot`] it belongs to ([`load`],
/// [`Routing::from_toml_str`], [`Routing::new`]); every per-configuration algorithm takes
/// `&Routing`, the robot, a [`sinew_robot::RobotData`] and a reusable [`crate::RoutingData`].
///
/// Cables are ordered by the universal joint they drive (stable: file order within a joint).
#[derive(Debug, Clone, PartialEq)]
pub struct Routing {
    pub(crate) source: String,
    pub(crate) robot: String,
    pub(crate) dof: usize,
    pub(crate) model: RoutingModel,
    pub(crate) youngs_modulus: f64,
    pub(crate) area: f64,
    pub(crate) tension_limits: [f64; 2],
    pub(crate) cables: Vec<Cable>,
    pub(crate) segments: Vec<Segment>,
    pub(crate) cable_joint: Vec<usize>,
    pub(crate) stiffness: Vec<f64>,
    /// Total size of the segments' Hessian blocks.
    pub(crate) hessian_len: usize,
    /// Largest `|dofs|` of a segment.
    pub(crate) max_span: usize,
    /// [`Routing::dof_blocks`].
    pub(crate) dof_blocks: Vec<Range<usize>>,
    /// [`Routing::is_decoupled`].
    pub(crate) decoupled: bool,
}

/// A cable after expanding either form, before it is checked against the robot.
struct RawCable {
    name: String,
    /// `cable[i]` or `pattern` (for messages).
    field: String,
    joint: Option<usize>,
    /// An explicit free length, with its field.
    free_length: Option<(f64, String)>,
    /// Link, point in the link frame, field naming the link.
    holes: Vec<(String, [f64; 3], String)>,
}

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
        if !dof.is_multiple_of(2) {
            return Err(RoutingError::NotUniversal { file, robot: robot.name().to_owned(), dof });
        }
        let n = dof / 2;
        let area = check_material(&file, spec)?;
        let [f_min, f_max] = spec.tension_limits;
        if !(f_min.is_finite() && f_max.is_finite() && f_min >= 0.0 && f_min < f_max) {
            return Err(RoutingError::InvalidTensionLimits { file, f_min, f_max });
        }
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
            let (joint, free_length, holes) = check_cable(&file, robot, spec, &cable, n)?;
            checked.push((cable, joint, free_length, holes));
        }
        checked.sort_by_key(|c| c.1);

        // Evaluate at Q = 0: segment lengths, elastic lengths, stiffness.
        let mut rdata = RobotData::new(robot);
        robot.forward_kinematics(&mut rdata, &vec![0.0; dof])?;
        let mut out_cables = Vec::with_capacity(checked.len());
        let mut segments = Vec::new();
        let mut hessian_len = 0;
        let mut max_span = 0;
        for (c, (r, joint, free_length, holes)) in checked.into_iter().enumerate() {
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
                holes,
                free_length,
                routed_length,
                elastic_length,
                stiffness,
                segments: first_segment..segments.len(),
                dofs: if lo < hi { lo..hi } else { 0..0 },
            });
        }

        let dof_blocks = dof_blocks(dof, &out_cables);
        let decoupled = out_cables
            .iter()
            .all(|c| c.dofs.start >= 2 * c.joint && c.dofs.end <= 2 * c.joint + 2);
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
            cable_joint: out_cables.iter().map(|c| c.joint).collect(),
            stiffness: out_cables.iter().map(|c| c.stiffness).collect(),
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

    /// The file the routing was read from (`<string>` or a generated name otherwise).
    pub fn source(&self) -> &str {
        &self.source
    }

    /// The name of the robot the routing was built for.
    pub fn robot_name(&self) -> &str {
        &self.robot
    }

    /// Number of revolute joints of that robot (the columns of `J_c`).
    pub fn dof(&self) -> usize {
        self.dof
    }

    /// Number of cables `m` (the rows of `J_c`).
    pub fn cable_count(&self) -> usize {
        self.cables.len()
    }

    /// How the routing was given.
    pub fn model(&self) -> RoutingModel {
        self.model
    }

    /// Young's modulus `E` of the cables, Pa.
    pub fn youngs_modulus(&self) -> f64 {
        self.youngs_modulus
    }

    /// Cross-section area `A` of the cables, m².
    pub fn area(&self) -> f64 {
        self.area
    }

    /// `[f_min, f_max]`, N, for every cable.
    pub fn tension_limits(&self) -> [f64; 2] {
        self.tension_limits
    }

    /// The cables, ordered by joint.
    pub fn cables(&self) -> &[Cable] {
        &self.cables
    }

    /// Every segment of every cable, cable by cable.
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// The universal joint each cable drives (`cable_joints()[c]`, 0-based, non-decreasing).
    pub fn cable_joints(&self) -> &[usize] {
        &self.cable_joint
    }

    /// Each cable's axial stiffness `k_c = E·A / l_c`, N/m: the diagonal of `K_l` (eq. 13).
    pub fn cable_stiffness(&self) -> &[f64] {
        &self.stiffness
    }

    /// The cables that drive universal joint `joint`: a range of [`Routing::cables`] (they are
    /// ordered by joint), empty for a joint no cable drives. `O(log m)`, no allocation.
    pub fn cables_of_joint(&self, joint: usize) -> Range<usize> {
        let lo = self.cable_joint.partition_point(|&j| j < joint);
        let hi = self.cable_joint.partition_point(|&j| j <= joint);
        lo..hi
    }

    /// The universal joints whose DOFs cable `c`'s length depends on (the 2-DOF blocks of `J_c`
    /// it spans): `J_c[c, d]` is exactly zero unless `d / 2` is in this range. `None` for no such
    /// cable.
    pub fn cable_joint_span(&self, c: usize) -> Option<Range<usize>> {
        let dofs = &self.cables.get(c)?.dofs;
        Some(dofs.start / 2..dofs.end.div_ceil(2))
    }

    /// Whether every cable changes length with the DOFs of the joint it drives only (the
    /// decoupled model): `J_c` and the joint stiffness are then block diagonal, one 2 × 2 block
    /// per universal joint at most.
    pub fn is_decoupled(&self) -> bool {
        self.decoupled
    }

    /// The DOF blocks of the routing: the finest partition of `0..dof` into consecutive ranges
    /// that no cable's DOFs straddle, so that the joint stiffness `Σ f_c H_c + J_cᵀ K_l J_c` is
    /// block diagonal over them with exact zeros elsewhere. Decoupled: one block per universal
    /// joint; routed: one block of every DOF a cable of the last joint crosses.
    pub fn dof_blocks(&self) -> &[Range<usize>] {
        &self.dof_blocks
    }

    /// Index of a cable by name.
    pub fn cable_index(&self, name: &str) -> Option<usize> {
        self.cables.iter().position(|c| c.name == name)
    }

    /// Write `K_l = diag(E·A / l_c)` (m × m, N/m) into `out`.
    ///
    /// # Math
    /// Eq. 13: `f_c = f_c0 + k_c (L_c(Q) − L_c(Q0))`, `k_c = E·A / l_c`, `l_c` the elastic length
    /// (free length plus routed length at Q = 0).
    ///
    /// # Errors
    /// [`RoutingError::DimensionMismatch`] unless `out` is m × m.
    pub fn fill_stiffness_matrix(&self, mut out: MatMut<'_, f64>) -> Result<()> {
        let m = self.cables.len();
        check_shape("cable stiffness matrix K_l", out.nrows(), out.ncols(), m, m)?;
        out.fill(0.0);
        for (c, k) in self.stiffness.iter().enumerate() {
            out[(c, c)] = *k;
        }
        Ok(())
    }

    /// Check that the routing was built for `robot` (same name and number of joints).
    ///
    /// # Errors
    /// [`RoutingError::RobotMismatch`].
    pub fn check_robot(&self, robot: &Robot) -> Result<()> {
        if robot.dof() != self.dof || robot.name() != self.robot {
            return Err(RoutingError::RobotMismatch {
                routing_robot: self.robot.clone(),
                routing_dof: self.dof,
                robot: robot.name().to_owned(),
                dof: robot.dof(),
            });
        }
        Ok(())
    }

    /// The expanded routing (every cable's holes as link + point in the link frame, its joint,
    /// stiffness and limits) as pretty-printed JSON, for inspection and other tools. The same
    /// document as `serde::Serialize` for [`Routing`].
    ///
    /// # Errors
    /// [`RoutingError::Serialize`] (not expected: every number is finite).
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string_pretty(self)
            .map_err(|e| RoutingError::Serialize { message: e.to_string() })
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

pub(crate) fn check_shape(
    what: &'static str,
    rows: usize,
    cols: usize,
    want_rows: usize,
    want_cols: usize,
) -> Result<()> {
    if rows != want_rows {
        return Err(RoutingError::DimensionMismatch { what, expected: want_rows, got: rows });
    }
    if cols != want_cols {
        return Err(RoutingError::DimensionMismatch { what, expected: want_cols, got: cols });
    }
    Ok(())
}

fn world(rdata: &RobotData, p: &BodyPoint) -> Result<Vector3<f64>> {
    let pose = rdata.body_pose(p.body).ok_or_else(|| RoutingError::WorkspaceMismatch {
        what: "robot workspace (bodies)",
        expected: p.body + 1,
        got: p.body,
    })?;
    Ok(pose.rotation * p.point + pose.translation.vector)
}

/// The cross-section area from the material, checked.
fn check_material(file: &str, spec: &RoutingSpec) -> Result<f64> {
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
fn check_per_joint(
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

fn expand_pattern(file: &str, pattern: &crate::spec::Pattern, n: usize) -> Result<Vec<RawCable>> {
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
        check_per_joint(file, &field, &value, n, |v| v > 0.0, "finite and > 0 m")?;
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
            cables.push(RawCable {
                name: format!("j{}c{}", i + 1, k + 1),
                field: "pattern".to_owned(),
                joint: Some(i),
                free_length: None,
                holes,
            });
        }
    }
    Ok(cables)
}

fn expand_explicit(cables: &[crate::spec::ExplicitCable]) -> Vec<RawCable> {
    cables
        .iter()
        .enumerate()
        .map(|(c, cable)| RawCable {
            name: cable.name.clone(),
            field: format!("cable[{c}]"),
            joint: cable.joint,
            free_length: cable.free_length.map(|v| (v, format!("cable[{c}].free_length"))),
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

/// Check one cable against the robot: (joint, free length, holes).
fn check_cable(
    file: &str,
    robot: &Robot,
    spec: &RoutingSpec,
    cable: &RawCable,
    n: usize,
) -> Result<(usize, f64, Vec<Hole>)> {
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
        if let Some(&v) = point.iter().find(|v| !v.is_finite()) {
            return Err(RoutingError::InvalidValue {
                file: file.to_owned(),
                cable: name.clone(),
                field: field.replace(".link", ".point"),
                value: v,
                expected: "finite coordinates in m",
            });
        }
        let point = Vector3::from(*point);
        let body_point = robot.link_point(link, point)?;
        holes.push(Hole { link: link.clone(), point, body_point });
    }
    // At least two holes: checked above.
    let anchor = holes.last().map_or(0, |h| h.body_point.body);
    let anchor_field = cable.holes.last().map(|h| h.2.clone()).unwrap_or_default();
    let wrong = |field: String, message: String| RoutingError::WrongJoint {
        file: file.to_owned(),
        cable: name.clone(),
        field,
        message,
    };
    let joint = match cable.joint {
        Some(j) => {
            let field = format!("{}.joint", cable.field);
            if j >= n {
                return Err(wrong(
                    field,
                    format!("joint {j} does not exist: the robot has universal joints 0..{n}"),
                ));
            }
            if anchor == 0 || (anchor - 1) / 2 != j {
                return Err(wrong(
                    anchor_field,
                    format!(
                        "the anchor is on body {anchor}, but a cable driving joint {j} must end on body {} or {} (moved by joint {j} and no further joint)",
                        2 * j + 1,
                        2 * j + 2
                    ),
                ));
            }
            j
        }
        None => {
            if anchor == 0 {
                return Err(wrong(
                    anchor_field,
                    "the anchor is on the base body: the cable drives no joint".to_owned(),
                ));
            }
            (anchor - 1) / 2
        }
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
    if proximal > 2 * joint {
        return Err(wrong(
            format!("{}.holes", cable.field),
            format!(
                "no hole lies proximal to joint {joint} (on a body ≤ {}): the cable does not cross the joint it drives",
                2 * joint
            ),
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
    Ok((joint, free_length, holes))
}

// ---------------------------------------------------------------------------------------------
// The expanded view, for printing.

#[derive(Serialize)]
struct RoutingView<'a> {
    robot: &'a str,
    source: &'a str,
    model: RoutingModel,
    youngs_modulus: f64,
    area: f64,
    tension_limits: [f64; 2],
    cables: Vec<CableView<'a>>,
}

#[derive(Serialize)]
struct CableView<'a> {
    name: &'a str,
    joint: usize,
    free_length: f64,
    routed_length: f64,
    elastic_length: f64,
    stiffness: f64,
    f_min: f64,
    f_max: f64,
    holes: Vec<HoleView<'a>>,
}

#[derive(Serialize)]
struct HoleView<'a> {
    link: &'a str,
    point: [f64; 3],
}

/// The expanded routing: `robot`, `source`, `model`, `youngs_modulus` (Pa), `area` (m²),
/// `tension_limits` (N) and `cables`, each with `name`, `joint` (0-based), `free_length`,
/// `routed_length` (at Q = 0), `elastic_length` (m), `stiffness` (E·A/l, N/m), `f_min`, `f_max`
/// (N) and `holes` as `{link, point}` (point in the link frame, m), base first.
impl Serialize for Routing {
    fn serialize<S: serde::Serializer>(
        &self,
        serializer: S,
    ) -> std::result::Result<S::Ok, S::Error> {
        let [f_min, f_max] = self.tension_limits;
        RoutingView {
            robot: &self.robot,
            source: &self.source,
            model: self.model,
            youngs_modulus: self.youngs_modulus,
            area: self.area,
            tension_limits: self.tension_limits,
            cables: self
                .cables
                .iter()
                .map(|c| CableView {
                    name: &c.name,
                    joint: c.joint,
                    free_length: c.free_length,
                    routed_length: c.routed_length,
                    elastic_length: c.elastic_length,
                    stiffness: c.stiffness,
                    f_min,
                    f_max,
                    holes: c
                        .holes
                        .iter()
                        .map(|h| HoleView {
                            link: &h.link,
                            point: [h.point.x, h.point.y, h.point.z],
                        })
                        .collect(),
                })
                .collect(),
        }
        .serialize(serializer)
    }
}
