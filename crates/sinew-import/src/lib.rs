//! # sinew-import
//!
//! Robots from other tools as Sinew robot folders. Today: [CASPR](https://github.com/darwinlau/CASPR)
//! (the MATLAB toolbox of cable-driven parallel robots) models, its bodies and cables XML files
//! (and optionally the operational spaces file), written as `<name>.urdf`, `robot.toml` and an
//! explicit `cables.toml` that `sinew_robot::load` and `sinew_routing::load` read.
//!
//! ```no_run
//! # fn main() -> Result<(), sinew_import::ImportError> {
//! let folder = sinew_import::import_caspr_files(
//!     "arm_bodies.xml".as_ref(),
//!     "arm_cables.xml".as_ref(),
//!     None,
//!     &sinew_import::ImportOptions::named("arm"),
//! )?;
//! for warning in &folder.warnings {
//!     eprintln!("warning: {warning}");
//! }
//! std::fs::create_dir_all("robots/arm").ok();
//! folder.write_into("robots/arm".as_ref())?;
//! # Ok(()) }
//! ```
//!
//! ## How CASPR's conventions map onto Sinew's
//!
//! Read from CASPR's source (`src/Model/…`, `data/model_config/…`); the class names are the
//! places to check.
//!
//! - **Links** (`<bodies_system><links><link_rigid num name>`, `BodyModelRigid.LoadXmlObj`,
//!   `SystemModelBodies.LoadXmlObj`): numbered 1, 2, … in file order (CASPR asserts it), link 0
//!   is the base. A link's frame is its joint frame: `SystemModelBodies.update` places body `k`
//!   at `r_OP = R_peᵀ (r_OP,parent + r_Parent + r_rel)` with `R_0k = R_0p R_pe`, so
//!   `<parent><location>` (`r_Parent`) is the joint's position in the parent's frame, and
//!   `<com_location>` (`r_G`) and `<end_location>` (`r_Pe`) are in the link's own frame, from
//!   its joint. Only serial chains import: each link's `<parent><num>` must be the link before
//!   it ([`ImportError::NotSerial`], [`ImportError::MissingParent`]).
//! - **Joints** (`JointBase.LoadXmlObj`, `RevoluteX`, `UniversalXY`, …): `R_X`, `R_Y`, `R_Z`
//!   become one URDF revolute joint at `r_Parent` about that axis; `U_XY`, `U_XZ`, `U_YZ`
//!   (`R_pe = R_first(q1) · R_second(q2)`: about the first axis, then about the rotated second
//!   one, `r_rel = 0`) become two: the first at `r_Parent` into a massless `<link>_cross`, the
//!   second with zero translation into the link. Sinew reads two consecutive revolute joints
//!   with non-parallel axes and a massless body between them as one universal joint,
//!   and a lone revolute joint as a 1-DOF joint. Every other type (`S_EULER_XYZ`, `P_*`,
//!   `PLANAR_*`, `R_AXIS`, `SPATIAL_*`, …) is [`ImportError::UnsupportedJoint`]. Limits:
//!   `q_min`/`q_max` (one value per coordinate); where the file has none, ±π (CASPR's
//!   `q_lb`/`q_ub`), said in the URDF's comments and the warnings.
//! - **Inertia** (`BodyModelRigid`): `<inertia ref="com">` is about the centre of mass;
//!   `ref="joint"` is about the joint and is converted as CASPR does,
//!   `I_G = I_O − m (r_Gᵀ r_G 𝟙 − r_G r_Gᵀ)`. The URDF gets the mass, the centre of mass as the
//!   inertial origin and `I_G`.
//! - **Gravity** (`SystemModel.GRAVITY_CONSTANT = 9.81`, `SystemModelBodies`:
//!   `G_b = R_0kᵀ [0; 0; −m g]`): `gravity = [0, 0, −9.81]` in `robot.toml`.
//! - **Tip**: with an operational spaces file, the first space with a `<link>` and an `<offset>`
//!   (`position`, `pose_euler_xyz`; `OperationalPosition.LoadXmlObj`, `r_OY = r_OP + r_y`) of
//!   the file's `default_operational_set`; without one (or with `default_operational_set=""`),
//!   the last link's `<end_location>`. A fixed joint puts the link `tip` there; it must be on the
//!   last link ([`ImportError::TipNotOnLastLink`]), as Sinew's chain cannot branch.
//! - **Cables** (`ModelConfigBase`, `SystemModelCables.LoadXmlObj`, `CableModelIdeal`,
//!   `CableModelBase.LoadSegmentsXmlObj`, `CableAttachmentPoint`): the set asked for, else the
//!   root's `default_cable_set` ([`ImportError::UnknownCableSet`] lists the ids). `cable_ideal`
//!   and `cable_linear_spring` (its `K` unused) import; pulleys and other models do not. Each
//!   `<attachment>` (`<link>`, `<location>`) becomes a hole, in order, base first as CASPR lists
//!   them; consecutive attachments are CASPR's segments, two on one link a pass-through. With
//!   `attachment_reference="joint"` the location is in the link frame; with `"com"` it is from
//!   the centre of mass (`r_GA`), and the link-frame point is `r_G + r_GA` (the base's `r_G` is
//!   0). No per-cable `joint` is written: sinew-routing takes the joint the anchor (last hole)
//!   sits beyond.
//! - **Cable limits and stiffness**: `force_min`/`force_max` give the tension limits; a negative
//!   minimum is clamped to 0 (sinew-routing needs `0 ≤ f_min < f_max`), and a zero minimum or a
//!   maximum ≥ 1e5 N is reported as a likely placeholder. When the cables' limits differ, each
//!   `[[cable]]` gets its own `tension_limits` and the top level the widest `[min, max]`.
//!   CASPR's ideal cables have no stiffness: Young's modulus, diameter and free length are
//!   [`ImportOptions`] (defaults [`DEFAULT_YOUNGS_MODULUS`], [`DEFAULT_DIAMETER`],
//!   [`DEFAULT_FREE_LENGTH`]).
//!
//! Ignored: `q_initial`, `actuated`, display settings, cable `<diameter>` (checked, unused),
//! trajectories.
//!
//! Every error is an [`ImportError`] naming the element, with the file, line and column
//! ([`ImportError::place`]).
#![deny(missing_docs)]

mod bodies;
mod cables;
mod error;
mod folder;
mod operational;
mod write;
mod xml;

use std::path::Path;

pub use bodies::{Axis, JointKind, Link};
pub use cables::{Attachment, Cable, CableSet};
pub use error::{ImportError, Place, Result};
pub use folder::{PLACEHOLDER_FORCE_MAX, RobotFolder, sanitize};
pub use operational::OperationalPoint;

/// The name of the tip link written into the URDF (`robot.toml`'s `tip_link`).
pub const TIP_LINK: &str = "tip";
/// The root link of the written URDF (CASPR's link 0).
pub const BASE_LINK: &str = "base_link";
/// The gravitational acceleration CASPR applies (`SystemModel.GRAVITY_CONSTANT`), m/s², along
/// −z of the base frame (`SystemModelBodies`: `G_b = R_0kᵀ [0; 0; −m g]`).
pub const CASPR_GRAVITY: f64 = 9.81;
/// Default Young's modulus of the cables, Pa: steel, 200 GPa.
pub const DEFAULT_YOUNGS_MODULUS: f64 = 200.0e9;
/// Default cable diameter, m: 1 mm.
pub const DEFAULT_DIAMETER: f64 = 1.0e-3;
/// Default free length from the actuator to the first hole, m: 0.5 m.
pub const DEFAULT_FREE_LENGTH: f64 = 0.5;

/// One input file: its name (for messages) and its text.
#[derive(Debug, Clone, Copy)]
pub struct Source<'a> {
    /// The file's path or another name for messages.
    pub name: &'a str,
    /// Its text.
    pub text: &'a str,
}

/// What CASPR does not say and the import needs.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportOptions {
    /// The robot's name (URDF `<robot name>`, the URDF file `<name>.urdf`); unsafe characters
    /// become `_`.
    pub name: String,
    /// The cable set's id; `None`: the file's `default_cable_set`.
    pub cable_set: Option<String>,
    /// Young's modulus `E` of every cable, Pa.
    pub youngs_modulus: f64,
    /// Cable diameter, m.
    pub diameter: f64,
    /// Free length from the actuator to the first hole, m, every cable.
    pub free_length: f64,
    /// `[f_min, f_max]`, N, for every cable instead of the file's `force_min`/`force_max`.
    pub tension_limits: Option<[f64; 2]>,
}

impl ImportOptions {
    /// The defaults with this name.
    pub fn named(name: &str) -> ImportOptions {
        ImportOptions { name: name.to_owned(), ..ImportOptions::default() }
    }
}

impl Default for ImportOptions {
    fn default() -> ImportOptions {
        ImportOptions {
            name: "caspr_robot".to_owned(),
            cable_set: None,
            youngs_modulus: DEFAULT_YOUNGS_MODULUS,
            diameter: DEFAULT_DIAMETER,
            free_length: DEFAULT_FREE_LENGTH,
            tension_limits: None,
        }
    }
}

/// A CASPR model as read: the links, the chosen cable set, the operational point.
#[derive(Debug, Clone, PartialEq)]
pub struct CasprModel {
    /// The links, base first (link `num` is `links[num − 1]`).
    pub links: Vec<Link>,
    /// The chosen cable set.
    pub cable_set: CableSet,
    /// The default operational set's point, if an operational spaces file names one.
    pub operational_point: Option<OperationalPoint>,
    /// Whether an operational spaces file was given.
    pub operational_file_given: bool,
    /// The bodies file's name.
    pub bodies_file: String,
    /// The cables file's name.
    pub cables_file: String,
}

/// Read a CASPR model: the bodies file, the cables file (set `cable_set`, or its default) and
/// optionally the operational spaces file.
///
/// # Errors
/// Every [`ImportError`] about a file, with the element's place.
pub fn read_caspr(
    bodies: Source<'_>,
    cables: Source<'_>,
    operational_spaces: Option<Source<'_>>,
    cable_set: Option<&str>,
) -> Result<CasprModel> {
    let bodies_xml = xml::Xml::parse(bodies.name, bodies.text)?;
    let links = bodies::read_links(&bodies_xml)?;
    let cables_xml = xml::Xml::parse(cables.name, cables.text)?;
    let cable_set = cables::read_cable_set(&cables_xml, &links, cable_set)?;
    let operational_point = match operational_spaces {
        Some(source) => {
            let op_xml = xml::Xml::parse(source.name, source.text)?;
            operational::read_operational_point(&op_xml, links.len())?
        }
        None => None,
    };
    Ok(CasprModel {
        links,
        cable_set,
        operational_point,
        operational_file_given: operational_spaces.is_some(),
        bodies_file: bodies.name.to_owned(),
        cables_file: cables.name.to_owned(),
    })
}

/// Read a CASPR model from texts and write its robot folder's files (in memory).
///
/// # Errors
/// Every [`ImportError`]: the files' and the options'.
pub fn import_caspr(
    bodies: Source<'_>,
    cables: Source<'_>,
    operational_spaces: Option<Source<'_>>,
    options: &ImportOptions,
) -> Result<RobotFolder> {
    let model = read_caspr(bodies, cables, operational_spaces, options.cable_set.as_deref())?;
    model.to_robot_folder(options)
}

/// [`import_caspr`] from files.
///
/// # Errors
/// [`ImportError::Io`] when a file cannot be read, then see [`import_caspr`].
pub fn import_caspr_files(
    bodies: &Path,
    cables: &Path,
    operational_spaces: Option<&Path>,
    options: &ImportOptions,
) -> Result<RobotFolder> {
    let read = |path: &Path| {
        std::fs::read_to_string(path)
            .map_err(|source| ImportError::Io { path: path.to_path_buf(), source })
    };
    let (bodies_text, cables_text) = (read(bodies)?, read(cables)?);
    let op_text = operational_spaces.map(read).transpose()?;
    let (bodies_name, cables_name) = (bodies.display().to_string(), cables.display().to_string());
    let op_name = operational_spaces.map(|p| p.display().to_string());
    import_caspr(
        Source { name: &bodies_name, text: &bodies_text },
        Source { name: &cables_name, text: &cables_text },
        op_name.as_deref().zip(op_text.as_deref()).map(|(name, text)| Source { name, text }),
        options,
    )
}

impl CasprModel {
    /// The robot folder's files for this model.
    ///
    /// # Errors
    /// [`ImportError::InvalidOption`], [`ImportError::InvalidTensionLimits`],
    /// [`ImportError::TipNotOnLastLink`].
    pub fn to_robot_folder(&self, options: &ImportOptions) -> Result<RobotFolder> {
        folder::build(self, options)
    }

    /// Sinew's DOF: one per `R_*` link, two per `U_*` link.
    pub fn dof(&self) -> usize {
        self.links.iter().map(|l| l.joint.dof()).sum()
    }
}
