//! The routing file, `cables.toml`, as Rust types: what the file says, before it is checked
//! against a robot and expanded into a [`crate::Routing`].
//!
//! SI units everywhere: m, rad, Pa, m², N. Two forms give the cables; a file uses exactly one.
//!
//! **Per-joint pattern** (three cables per universal joint):
//!
//! ```toml
//! tension_limits = [20.0, 600.0]         # N, [f_min, f_max], every cable
//! free_length = 3.0                      # m: one value, or one per universal joint
//!
//! [material]
//! youngs_modulus = 12.5e9                # Pa
//! diameter = 1.0e-3                      # m (or `area = …` in m²)
//!
//! [pattern]
//! model = "decoupled"                    # or "routed"
//! radius = 0.022                         # m: hole circle on every disc (one value or one per joint)
//! # proximal_radius = …, distal_radius = … override `radius` per side
//! theta0 = 1.5707963267948966            # rad, angle of cable 1 of joint 0
//! joint_offset = 0.41887902047863906     # rad, added per joint (2π/15: 15 distinct holes)
//! proximal_discs = ["base_link", "link1_distal"]   # one per universal joint, base first
//! distal_discs = ["link1", "link2"]
//! ```
//!
//! Cable `k` (0, 1, 2) of universal joint `i` (0-based) is named `j{i+1}c{k+1}`; its holes sit
//! at `(ρ cos θ, ρ sin θ, 0)` in the disc frames, `θ = theta0 + 2πk/3 + i·joint_offset`.
//! Decoupled: two holes, the proximal disc of joint `i`, then the anchor on its distal disc.
//! Routed: the hole on the proximal disc of joint 0, then the distal and proximal discs of every
//! joint before `i`, then the anchor on the distal disc of joint `i` (spec §2).
//!
//! **Explicit** (each cable an ordered list of holes, base first, the last one its anchor):
//!
//! ```toml
//! [[cable]]
//! name = "a"
//! joint = 0                              # optional: the joint it drives (0-based); default the
//!                                        # joint that moves its anchor (and no further joint does)
//! free_length = 3.1                      # optional: overrides the top-level value
//! tension_limits = [10.0, 400.0]         # optional: overrides the top-level limits, N
//! holes = [
//!   { link = "base_link", point = [0.022, 0.0, 0.0] },
//!   { link = "link1", point = [0.022, 0.0, 0.0] },
//! ]
//! ```
//!
//! The explicit form takes any cable set: any number of cables per joint, cables that cross
//! several joints (shared), and robots whose joints are 1-DOF revolute joints beside 2-DOF
//! universal ones ([`sinew_robot::Robot::joint_groups`]). The pattern form needs an arm of
//! universal joints. Four cables on one universal joint (two antagonistic pairs, 90° apart;
//! the tensions then have a 2-dimensional equilibrium set per joint, chosen by a policy):
//!
//! ```toml
//! [[cable]]
//! name = "j1a"
//! holes = [{ link = "base_link", point = [0.02, 0.0, 0.0] }, { link = "link1", point = [0.02, 0.0, 0.0] }]
//! [[cable]]
//! name = "j1b"
//! holes = [{ link = "base_link", point = [0.0, 0.02, 0.0] }, { link = "link1", point = [0.0, 0.02, 0.0] }]
//! [[cable]]
//! name = "j1c"
//! holes = [{ link = "base_link", point = [-0.02, 0.0, 0.0] }, { link = "link1", point = [-0.02, 0.0, 0.0] }]
//! [[cable]]
//! name = "j1d"
//! holes = [{ link = "base_link", point = [0.0, -0.02, 0.0] }, { link = "link1", point = [0.0, -0.02, 0.0] }]
//! ```
//!
//! A revolute joint (`link1`, about x) followed by a universal joint (`link2`): two cables
//! drive the revolute joint, and a shared cable runs through `link1`'s discs to anchor on
//! `link2`, so it loads both joints (its `joint` is the universal joint, which moves its
//! anchor):
//!
//! ```toml
//! [[cable]]
//! name = "r_up"
//! holes = [{ link = "base_link", point = [0.0, 0.02, 0.0] }, { link = "link1", point = [0.0, 0.02, 0.0] }]
//! [[cable]]
//! name = "r_down"
//! holes = [{ link = "base_link", point = [0.0, -0.02, 0.0] }, { link = "link1", point = [0.0, -0.02, 0.0] }]
//! [[cable]]
//! name = "shared"
//! tension_limits = [10.0, 300.0]
//! holes = [
//!   { link = "base_link", point = [0.015, 0.015, 0.0] },
//!   { link = "link1", point = [0.015, 0.015, 0.0] },
//!   { link = "link1_distal", point = [0.015, 0.015, 0.0] },
//!   { link = "link2", point = [0.015, 0.015, 0.0] },
//! ]
//! ```
//!
//! The elastic length of a cable is `l_c = free_length + L_c(Q = 0)` (the free length from the
//! actuator plus the routed length), its stiffness `k_c = E·A / l_c` (eq. 13).
//!
//! **Friction at the holes** (spec §9; optional, either form). Absent, every cable has μ = 0 and
//! the numbers are the frictionless model's, bit for bit.
//!
//! ```toml
//! friction_coefficient = 0.1             # μ at every hole of every cable, ≥ 0 (default 0)
//!
//! [[cable]]                              # explicit form: per-cable keys
//! name = "a"
//! friction_coefficient = 0.15            # optional: this cable's μ, overrides the top-level one
//! entry_direction = [0.0, 0.1, 1.0]      # optional: see below (any length > 0; normalised)
//! holes = [ … ]
//!
//! [pattern.cable.j2c1]                   # pattern form: per-cable keys, by the cable's name
//! friction_coefficient = 0.2
//! entry_direction = [0.0, 0.0, 1.0]
//! ```
//!
//! `entry_direction` is the direction along which the free length arrives at the cable's first
//! hole, going away from the actuator, in the frame of the first hole's link (the frame its
//! `point` is given in); the wrap angle at the first hole is measured from it. Default `+z` of
//! that link: the arm's axis on a disc, so that a straight arm has no wrap there. In the pattern
//! form the first hole is on the base disc (routed: the cable arrives from below) or on the
//! proximal disc of the cable's joint (decoupled: it arrives along the central channel). A
//! negative or non-finite μ, an entry direction of zero length or with a non-finite coordinate,
//! and a `[pattern.cable.NAME]` for a cable the pattern does not have are errors naming the file,
//! the cable and the key. Conventions of the friction geometry: `docs/ARCHITECTURE.md`
//! ("Friction at the holes: conventions").

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// A value given once for every universal joint, or one per joint (base first).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum PerJoint {
    /// The same value for every joint.
    Uniform(f64),
    /// One value per universal joint.
    Each(Vec<f64>),
}

impl PerJoint {
    /// The value for joint `i`, if there is one.
    pub fn get(&self, i: usize) -> Option<f64> {
        match self {
            PerJoint::Uniform(v) => Some(*v),
            PerJoint::Each(values) => values.get(i).copied(),
        }
    }

    /// Every value given (one for [`PerJoint::Uniform`]).
    pub fn values(&self) -> &[f64] {
        match self {
            PerJoint::Uniform(v) => std::slice::from_ref(v),
            PerJoint::Each(values) => values,
        }
    }
}

/// The cable material, common to every cable.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Young's modulus `E`, Pa.
    pub youngs_modulus: f64,
    /// Cable diameter, m (give exactly one of `diameter` and `area`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diameter: Option<f64>,
    /// Cross-section area `A`, m².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub area: Option<f64>,
}

/// How the pattern's cables run (spec §2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PatternModel {
    /// Each cable crosses only the joint it drives (the paper's model): `J_c` block diagonal.
    Decoupled,
    /// Each cable also passes through its holes on every proximal disc: `J_c` block
    /// lower-triangular.
    Routed,
}

/// The per-joint pattern: three cables per universal joint, holes on circles on the discs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pattern {
    /// Decoupled or routed.
    pub model: PatternModel,
    /// Radius ρ of the hole circle on every disc, m (default of the two below).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<PerJoint>,
    /// Radius on the proximal disc of each joint, m (overrides `radius`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub proximal_radius: Option<PerJoint>,
    /// Radius on the distal disc of each joint, m (overrides `radius`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub distal_radius: Option<PerJoint>,
    /// Angle of cable 1 of joint 0 in the disc frames, rad (about z, from x).
    #[serde(default)]
    pub theta0: f64,
    /// Angle added per joint, rad, so that the cables of different joints use different holes.
    #[serde(default)]
    pub joint_offset: f64,
    /// The proximal disc link of each universal joint (frame `O_i`), base first.
    pub proximal_discs: Vec<String>,
    /// The distal disc link of each universal joint (frame `O'_i`), base first.
    pub distal_discs: Vec<String>,
    /// Per-cable friction keys by cable name (`[pattern.cable.j1c2]`): each names a cable of
    /// the pattern.
    #[serde(default, rename = "cable", skip_serializing_if = "BTreeMap::is_empty")]
    pub cables: BTreeMap<String, CableFriction>,
}

/// The friction keys of one cable of the pattern form (`[pattern.cable.NAME]`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CableFriction {
    /// This cable's friction coefficient μ (≥ 0); default the file's `friction_coefficient`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_coefficient: Option<f64>,
    /// The free length's direction at the first hole, in that hole's link frame (module docs);
    /// default `[0, 0, 1]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub entry_direction: Option<[f64; 3]>,
}

/// One hole of an explicit cable: a point fixed in a link's frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HoleSpec {
    /// URDF link name.
    pub link: String,
    /// Coordinates in the link frame, m.
    pub point: [f64; 3],
}

/// A cable given hole by hole.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExplicitCable {
    /// Unique name.
    pub name: String,
    /// The joint it drives (0-based, [`sinew_robot::Robot::joint_groups`]); default the joint
    /// whose revolute joints move its anchor and no further joint's do (`(anchor body − 1) / 2`
    /// on a universal arm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joint: Option<usize>,
    /// Free length from the actuator, m; default the file's `free_length` for its joint.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub free_length: Option<f64>,
    /// `[f_min, f_max]` of this cable, N; default the file's `tension_limits`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tension_limits: Option<[f64; 2]>,
    /// This cable's friction coefficient μ (≥ 0); default the file's `friction_coefficient`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_coefficient: Option<f64>,
    /// The free length's direction at the first hole, in that hole's link frame (module docs);
    /// default `[0, 0, 1]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub entry_direction: Option<[f64; 3]>,
    /// The holes from the base to the anchor (the last one).
    pub holes: Vec<HoleSpec>,
}

/// A whole routing file (`cables.toml`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoutingSpec {
    /// `[f_min, f_max]`, N, for every cable.
    pub tension_limits: [f64; 2],
    /// Free length from the actuator, m: one value or one per universal joint (the cable's
    /// joint picks it). Default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub free_length: Option<PerJoint>,
    /// The cable material.
    pub material: Material,
    /// The friction coefficient μ at every hole (spec §9), ≥ 0, of every cable that does not
    /// give its own; default 0 (no friction).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_coefficient: Option<f64>,
    /// The per-joint pattern form.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pattern: Option<Pattern>,
    /// The explicit form (`[[cable]]` tables).
    #[serde(default, rename = "cable", skip_serializing_if = "Vec::is_empty")]
    pub cables: Vec<ExplicitCable>,
}

impl RoutingSpec {
    /// Parse the text of a routing file (no check against a robot yet).
    ///
    /// # Errors
    /// [`crate::RoutingError::Parse`] naming `source_name`.
    pub fn from_toml_str(text: &str, source_name: &str) -> crate::Result<RoutingSpec> {
        toml::from_str(text).map_err(|e| crate::RoutingError::Parse {
            file: source_name.to_owned(),
            message: e.to_string(),
        })
    }
}
