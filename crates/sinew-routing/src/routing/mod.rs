//! The immutable routing: every cable as an ordered list of holes on the robot's bodies, and
//! the structure the other crates derive their layouts from (which cables a joint owns, which
//! joints a cable spans, the DOF blocks, decoupled or not). Built from the file in `build.rs`
//! (the cables expanded and checked in `expand.rs`, the segments batched for the geometry in
//! `plan.rs`); the serialisable view in `view.rs`.

mod build;
mod expand;
mod friction;
mod plan;
mod view;

use std::ops::Range;

use faer::MatMut;
use nalgebra::Vector3;
use serde::Serialize;
use sinew_robot::{BodyPoint, Robot};

use crate::error::{Result, RoutingError};
use crate::spec::PatternModel;

pub use build::load;
pub(crate) use plan::{SegmentPlan, rigid_length};
pub use view::{CableView, HoleView, RoutingView};

/// The routing file of the decoupled model inside a robot folder (the default of [`load`]).
pub const ROUTING_FILE: &str = "cables.toml";

/// The routing file of the routed model inside a robot folder.
pub const ROUTED_ROUTING_FILE: &str = "cables-routed.toml";

/// The routing file of a pattern model inside a robot folder: [`ROUTING_FILE`] or
/// [`ROUTED_ROUTING_FILE`].
pub fn routing_file(model: PatternModel) -> &'static str {
    match model {
        PatternModel::Decoupled => ROUTING_FILE,
        PatternModel::Routed => ROUTED_ROUTING_FILE,
    }
}

/// The least segment length accepted, m: shorter segments (at Q = 0 when loading, at any
/// configuration when evaluating) have no well-defined direction and are errors.
pub const MIN_SEGMENT_LENGTH: f64 = 1e-6;

/// The farthest a hole may lie from its link's origin, m (each coordinate): a disc of a
/// manipulator is centimetres across. A hole at 1e308 m loads as finite but overflows the
/// cable Hessians' products of lever arms, so it is an input error, not a NaN later.
pub const MAX_HOLE_OFFSET: f64 = 1e3;

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
    /// The joint it drives, 0-based ([`Robot::joint_groups`]; on a universal arm revolute
    /// joints `2·joint`, `2·joint + 1`): the joint that moves its anchor and no further joint
    /// does.
    pub joint: usize,
    /// `[f_min, f_max]`, N.
    pub tension_limits: [f64; 2],
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
    /// Its friction coefficient μ at every hole (spec §9), ≥ 0: the file's per-cable value, else
    /// the routing-wide one ([`Routing::friction_coefficient`]), else 0.
    pub friction_coefficient: f64,
    /// The direction along which its free length arrives at its first hole (going away from
    /// the actuator), unit, in the frame of the first hole's link (the frame of
    /// `holes[0].point`); default `+z` of that link. The wrap angle at the first hole is
    /// measured from it (`crate::friction`).
    pub entry_direction: Vector3<f64>,
    /// [`Cable::entry_direction`] in the frame of the first hole's body (`holes[0].body_point`).
    pub(crate) entry_in_body: Vector3<f64>,
}

impl Cable {
    /// [`Cable::entry_direction`] in the frame of the body carrying the first hole
    /// (`holes[0].body_point.body`), unit: the link's rotation in its body applied to it.
    pub fn entry_direction_in_body(&self) -> Vector3<f64> {
        self.entry_in_body
    }
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
    pub(crate) friction_coefficient: f64,
    pub(crate) cable_limits: Vec<[f64; 2]>,
    pub(crate) uniform_limits: bool,
    pub(crate) joint_groups: Vec<Range<usize>>,
    pub(crate) cables: Vec<Cable>,
    pub(crate) segments: Vec<Segment>,
    /// The segments batched by the bodies they join, when that pays (routed models).
    pub(crate) plan: Option<SegmentPlan>,
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

impl Routing {
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

    /// `[f_min, f_max]`, N: the file's limits, those of every cable that does not set its own
    /// ([`Routing::cable_limits`]).
    pub fn tension_limits(&self) -> [f64; 2] {
        self.tension_limits
    }

    /// The routing-wide friction coefficient μ (spec §9): the file's `friction_coefficient`,
    /// 0 when absent; each cable's own is [`Cable::friction_coefficient`].
    pub fn friction_coefficient(&self) -> f64 {
        self.friction_coefficient
    }

    /// Whether some cable has friction (μ > 0). Without, the friction geometry's weights are
    /// all exactly 1 and its effective Jacobian is `J_c` bit for bit.
    pub fn has_friction(&self) -> bool {
        self.cables.iter().any(|c| c.friction_coefficient > 0.0)
    }

    /// `[f_min, f_max]` of each cable, N (routing order).
    pub fn cable_limits(&self) -> &[[f64; 2]] {
        &self.cable_limits
    }

    /// Whether every cable has the file's limits [`Routing::tension_limits`].
    pub fn has_uniform_limits(&self) -> bool {
        self.uniform_limits
    }

    /// The robot's joints as ranges of its revolute joints ([`Robot::joint_groups`]).
    pub fn joint_groups(&self) -> &[Range<usize>] {
        &self.joint_groups
    }

    /// The number of joints of the robot ([`Robot::joint_count`]).
    pub fn joint_count(&self) -> usize {
        self.joint_groups.len()
    }

    /// The cables, ordered by joint.
    pub fn cables(&self) -> &[Cable] {
        &self.cables
    }

    /// Whether the geometry runs batched: segments grouped by the bodies they join, one
    /// vectorised loop per group (routed models, where a joint is crossed by many cables), or
    /// segment by segment (the decoupled model). Both give the same numbers bit for bit.
    pub fn is_batched(&self) -> bool {
        self.plan.is_some()
    }

    /// This routing with the segment-by-segment loop: the reference the batched loop is
    /// tested against (the results are the same bit for bit, only slower).
    pub fn unbatched(&self) -> Routing {
        Routing { plan: None, ..self.clone() }
    }

    /// Every segment of every cable, cable by cable.
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// The joint each cable drives (`cable_joints()[c]`, 0-based, non-decreasing).
    pub fn cable_joints(&self) -> &[usize] {
        &self.cable_joint
    }

    /// Each cable's axial stiffness `k_c = E·A / l_c`, N/m: the diagonal of `K_l` (eq. 13).
    pub fn cable_stiffness(&self) -> &[f64] {
        &self.stiffness
    }

    /// The cables that drive joint `joint`: a range of [`Routing::cables`] (they are
    /// ordered by joint), empty for a joint no cable drives. `O(log m)`, no allocation.
    pub fn cables_of_joint(&self, joint: usize) -> Range<usize> {
        let lo = self.cable_joint.partition_point(|&j| j < joint);
        let hi = self.cable_joint.partition_point(|&j| j <= joint);
        lo..hi
    }

    /// The joints whose DOFs cable `c`'s length depends on (the joint blocks of `J_c` it
    /// spans): `J_c[c, d]` is exactly zero unless `d` belongs to a joint in this range. `None`
    /// for no such cable.
    pub fn cable_joint_span(&self, c: usize) -> Option<Range<usize>> {
        let dofs = &self.cables.get(c)?.dofs;
        if dofs.is_empty() {
            return Some(0..0);
        }
        let of = |d: usize| self.joint_groups.iter().position(|g| g.contains(&d));
        Some(of(dofs.start)?..of(dofs.end - 1)? + 1)
    }

    /// Whether every cable changes length with the DOFs of the joint it drives only (the
    /// decoupled model): `J_c` and the joint stiffness are then block diagonal, one block per
    /// joint at most (2 × 2 for a universal joint).
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
