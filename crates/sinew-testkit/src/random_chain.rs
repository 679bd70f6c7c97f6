//! Seeded random-geometry chains: what the derivative tests see besides the axis-aligned
//! cdhrm5 and [`sinew_robot::UniformChain`] (every `rpy = 0`, axes along x and y, centres of
//! mass on the link axis).
//!
//! [`RandomChain::new`] draws a serial chain of `2·joints` revolute joints, paired into
//! universal joints as the routing expects (`base_link` → `cross{i}` → `pivot{i}` → `link{i}`
//! → `link{i}_distal`, the last one `end_effector`), with random joint origins (rpy over the
//! whole circle, xyz offsets), random unit axes (the two of a pair not parallel), random fixed
//! joints, masses, centres of mass and full inertia tensors (principal moments satisfying the
//! triangle inequality, turned by a random rotation and a random inertial `rpy`), and gravity
//! along a random direction. The `cross{i}` links (between the two revolutes of a pair) are
//! massless, as on a real universal joint; the `pivot{i}` links carry a second inertial that
//! the loader folds into `link{i}`'s body.
//!
//! The chain keeps its joints ([`RandomChain::joints`]), so that [`RandomChain::link_poses`]
//! computes every link frame's pose from the URDF's own numbers, independently of sinew-robot.
//! [`RandomChain::pattern_spec`] and [`RandomChain::explicit_spec`] give it cables.

use std::collections::HashMap;
use std::f64::consts::PI;
use std::fmt::Write as _;

use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, Unit, UnitQuaternion, Vector3};
use rand::Rng;
use sinew_robot::{ChainSettings, Robot};
use sinew_routing::{
    ExplicitCable, HoleSpec, Material, Pattern, PatternModel, PerJoint, Routing, RoutingSpec,
};

use crate::cdhrm5::{DIAMETER, TENSION_LIMITS, YOUNGS_MODULUS};
use crate::config::rng;

/// One URDF joint of a [`RandomChain`], as written in its URDF.
#[derive(Debug, Clone, PartialEq)]
pub struct RandomJoint {
    /// Joint name.
    pub name: String,
    /// Parent link.
    pub parent: String,
    /// Child link.
    pub child: String,
    /// `<origin xyz>`, m.
    pub xyz: [f64; 3],
    /// `<origin rpy>`, rad.
    pub rpy: [f64; 3],
    /// The unit axis of a revolute joint (`None`: fixed).
    pub axis: Option<[f64; 3]>,
    /// `[lower, upper]` of a revolute joint, rad.
    pub limits: [f64; 2],
}

/// A seeded random-geometry chain of universal joints (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct RandomChain {
    /// Robot name, `random{joints}s{seed}`.
    pub name: String,
    /// Number of universal joints (`2·joints` revolute joints).
    pub joints: usize,
    /// Gravity in the base frame, m/s² (|g| = 9.81, random direction).
    pub gravity: Vector3<f64>,
    /// Every URDF joint, base first (revolute and fixed).
    pub urdf_joints: Vec<RandomJoint>,
    /// The URDF text.
    pub urdf: String,
}

fn uniform3(rng: &mut impl Rng, lo: [f64; 3], hi: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|k| rng.random_range(lo[k]..=hi[k]))
}

fn random_rpy(rng: &mut impl Rng) -> [f64; 3] {
    [rng.random_range(-PI..PI), rng.random_range(-PI / 2.0..PI / 2.0), rng.random_range(-PI..PI)]
}

fn random_unit(rng: &mut impl Rng) -> Vector3<f64> {
    loop {
        let v = Vector3::from_fn(|_, _| rng.random_range(-1.0..1.0));
        let n = v.norm();
        if (0.2..=1.0).contains(&n) {
            return v / n;
        }
    }
}

/// A rotation from URDF `rpy` (fixed axes x, y, z: `Rz(y)·Ry(p)·Rx(r)`).
pub fn rpy_rotation(rpy: [f64; 3]) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), rpy[2])
        * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), rpy[1])
        * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), rpy[0])
}

/// A revolute joint with a random `rpy` and limits.
fn revolute(
    rng: &mut impl Rng,
    name: String,
    parent: String,
    child: String,
    xyz: [f64; 3],
    axis: Vector3<f64>,
) -> RandomJoint {
    let lower = -rng.random_range(0.3..0.6);
    let upper = rng.random_range(0.3..0.6);
    RandomJoint {
        name,
        parent,
        child,
        xyz,
        rpy: random_rpy(rng),
        axis: Some([axis.x, axis.y, axis.z]),
        limits: [lower, upper],
    }
}

/// A hole on `link` at a random angle on a circle of radius 15–25 mm, `z` within ±(1–5) mm.
fn random_hole(link: String, rng: &mut impl Rng) -> HoleSpec {
    let radius = rng.random_range(0.015..0.025);
    let theta = rng.random_range(0.0..std::f64::consts::TAU);
    let z = rng.random_range(0.001..0.005) * if rng.random_bool(0.5) { 1.0 } else { -1.0 };
    HoleSpec { link, point: [radius * theta.cos(), radius * theta.sin(), z] }
}

/// `<inertial>` text: mass, a random centre of mass and a full random inertia tensor.
fn inertial(rng: &mut impl Rng, mass: f64, com_lo: [f64; 3], com_hi: [f64; 3]) -> String {
    let com = uniform3(rng, com_lo, com_hi);
    let rpy = random_rpy(rng);
    // Principal moments in [1, 2]·scale satisfy the triangle inequality; a random rotation
    // gives every product of inertia.
    let scale = mass * 4e-3;
    let d = Matrix3::from_diagonal(&Vector3::from_fn(|_, _| scale * rng.random_range(1.0..2.0)));
    let r = Rotation3::from_axis_angle(
        &Unit::new_normalize(random_unit(rng)),
        rng.random_range(0.0..PI),
    );
    let i = r.matrix() * d * r.matrix().transpose();
    format!(
        r#"<inertial><origin xyz="{} {} {}" rpy="{} {} {}"/><mass value="{mass}"/><inertia ixx="{}" ixy="{}" ixz="{}" iyy="{}" iyz="{}" izz="{}"/></inertial>"#,
        com[0],
        com[1],
        com[2],
        rpy[0],
        rpy[1],
        rpy[2],
        i[(0, 0)],
        i[(0, 1)],
        i[(0, 2)],
        i[(1, 1)],
        i[(1, 2)],
        i[(2, 2)],
    )
}

impl RandomChain {
    /// Draw a chain of `joints` universal joints from a generator seeded with `seed`.
    pub fn new(joints: usize, seed: u64) -> RandomChain {
        let mut rng = rng(seed);
        let name = format!("random{joints}s{seed}");
        let mut urdf_joints = Vec::new();
        let mut links = vec![r#"  <link name="base_link"/>"#.to_owned()];
        for i in 1..=joints {
            let parent =
                if i == 1 { "base_link".to_owned() } else { format!("link{}_distal", i - 1) };
            let xyz = uniform3(&mut rng, [-0.01, -0.01, 0.02], [0.01, 0.01, 0.05]);
            let a = random_unit(&mut rng);
            urdf_joints.push(revolute(
                &mut rng,
                format!("joint{i}_a"),
                parent,
                format!("cross{i}"),
                xyz,
                a,
            ));
            // The second axis: random, at least 30° away from the first (in the base's view the
            // rpy of the second joint turns it, so draw until the turned axis is clear of a).
            let xyz = uniform3(&mut rng, [-0.005; 3], [0.005; 3]);
            let joint_b = loop {
                let b = random_unit(&mut rng);
                let j = revolute(
                    &mut rng,
                    format!("joint{i}_b"),
                    format!("cross{i}"),
                    format!("pivot{i}"),
                    xyz,
                    b,
                );
                let turned = rpy_rotation(j.rpy) * b;
                if turned.cross(&a).norm() >= 0.5 {
                    break j;
                }
            };
            urdf_joints.push(joint_b);
            links.push(format!(r#"  <link name="cross{i}"/>"#));
            let pivot_mass = rng.random_range(0.01..0.05);
            links.push(format!(
                "  <link name=\"pivot{i}\">{}</link>",
                inertial(&mut rng, pivot_mass, [-0.01; 3], [0.01; 3])
            ));
            let xyz = uniform3(&mut rng, [-0.01, -0.01, 0.0], [0.01, 0.01, 0.02]);
            urdf_joints.push(RandomJoint {
                name: format!("joint{i}_fixed"),
                parent: format!("pivot{i}"),
                child: format!("link{i}"),
                xyz,
                rpy: random_rpy(&mut rng),
                axis: None,
                limits: [0.0, 0.0],
            });
            let mass = rng.random_range(0.1..0.5);
            links.push(format!(
                "  <link name=\"link{i}\">{}</link>",
                inertial(&mut rng, mass, [-0.02, -0.02, 0.05], [0.02, 0.02, 0.15])
            ));
            let child =
                if i < joints { format!("link{i}_distal") } else { "end_effector".to_owned() };
            links.push(format!(r#"  <link name="{child}"/>"#));
            let xyz = uniform3(&mut rng, [-0.01, -0.01, 0.15], [0.01, 0.01, 0.25]);
            urdf_joints.push(RandomJoint {
                name: format!("link{i}_disc"),
                parent: format!("link{i}"),
                child,
                xyz,
                rpy: random_rpy(&mut rng),
                axis: None,
                limits: [0.0, 0.0],
            });
        }
        let gravity = random_unit(&mut rng) * 9.81;
        let mut urdf = String::new();
        let _ = writeln!(urdf, r#"<?xml version="1.0"?>"#);
        let _ = writeln!(urdf, r#"<robot name="{name}">"#);
        for link in &links {
            let _ = writeln!(urdf, "{link}");
        }
        for j in &urdf_joints {
            let kind = if j.axis.is_some() { "revolute" } else { "fixed" };
            let _ = writeln!(urdf, r#"  <joint name="{}" type="{kind}">"#, j.name);
            let _ =
                writeln!(urdf, r#"    <parent link="{}"/><child link="{}"/>"#, j.parent, j.child);
            let _ = writeln!(
                urdf,
                r#"    <origin xyz="{} {} {}" rpy="{} {} {}"/>"#,
                j.xyz[0], j.xyz[1], j.xyz[2], j.rpy[0], j.rpy[1], j.rpy[2]
            );
            if let Some(axis) = j.axis {
                let _ = writeln!(urdf, r#"    <axis xyz="{} {} {}"/>"#, axis[0], axis[1], axis[2]);
                let _ = writeln!(
                    urdf,
                    r#"    <limit lower="{}" upper="{}" effort="100" velocity="1"/>"#,
                    j.limits[0], j.limits[1]
                );
            }
            let _ = writeln!(urdf, "  </joint>");
        }
        let _ = writeln!(urdf, "</robot>");
        RandomChain { name, joints, gravity, urdf_joints, urdf }
    }

    /// Tip link `end_effector` and the chain's gravity.
    pub fn settings(&self) -> ChainSettings {
        ChainSettings { tip_link: "end_effector".to_owned(), gravity: self.gravity }
    }

    /// The chain loaded through sinew-robot's URDF loader.
    ///
    /// # Panics
    /// When the loader rejects it (the message names the chain and the error).
    pub fn robot(&self) -> Robot {
        Robot::from_urdf_str(&self.urdf, &format!("<{}>", self.name), &self.settings())
            .unwrap_or_else(|e| panic!("{}: {e}", self.name))
    }

    /// The pose in the base frame of every link at `q` (one angle per revolute joint, base
    /// first), from the URDF's numbers alone: `pose(child) = pose(parent) · origin · Rot(axis, q)`
    /// (no sinew-robot code).
    ///
    /// # Panics
    /// When `q` does not have one angle per revolute joint.
    pub fn link_poses(&self, q: &[f64]) -> HashMap<String, Isometry3<f64>> {
        let mut poses = HashMap::new();
        poses.insert("base_link".to_owned(), Isometry3::identity());
        let mut k = 0;
        for j in &self.urdf_joints {
            let parent = poses[&j.parent];
            let origin = Isometry3::from_parts(
                Translation3::new(j.xyz[0], j.xyz[1], j.xyz[2]),
                rpy_rotation(j.rpy),
            );
            let motion = match j.axis {
                Some(axis) => {
                    let angle = q[k];
                    k += 1;
                    UnitQuaternion::from_axis_angle(
                        &Unit::new_normalize(Vector3::from(axis)),
                        angle,
                    )
                }
                None => UnitQuaternion::identity(),
            };
            poses.insert(
                j.child.clone(),
                parent * origin * Isometry3::from_parts(Translation3::identity(), motion),
            );
        }
        assert_eq!(k, q.len(), "{}: {} angles for {k} revolute joints", self.name, q.len());
        poses
    }

    fn common_spec(&self, free_length: PerJoint) -> RoutingSpec {
        RoutingSpec {
            tension_limits: TENSION_LIMITS,
            free_length: Some(free_length),
            material: Material {
                youngs_modulus: YOUNGS_MODULUS,
                diameter: Some(DIAMETER),
                area: None,
            },
            friction_coefficient: None,
            pattern: None,
            cables: Vec::new(),
        }
    }

    /// The cdhrm5-like pattern routing of `model` on this chain's discs (`base_link` /
    /// `link{i-1}_distal` proximal, `link{i}` distal; holes at z = 0 in those random frames).
    pub fn pattern_spec(&self, model: PatternModel) -> RoutingSpec {
        let n = self.joints;
        RoutingSpec {
            pattern: Some(Pattern {
                model,
                radius: Some(PerJoint::Uniform(0.02)),
                proximal_radius: None,
                distal_radius: None,
                theta0: 0.1,
                joint_offset: std::f64::consts::TAU / 15.0,
                proximal_discs: crate::cdhrm5::proximal_discs(n),
                distal_discs: crate::cdhrm5::distal_discs(n),
                cables: Default::default(),
            }),
            ..self.common_spec(PerJoint::Uniform(3.0))
        }
    }

    /// An explicit routing (the hole-by-hole form) that the pattern cannot give, seeded with
    /// `seed`: three cables per universal joint; cable `k` of joint `i` starts on `base_link`,
    /// then, for every joint `j < i`, passes through a hole on `cross{j+1}` (the massless link
    /// between the two revolutes of the pair), on `link{j+1}` and on `link{j+1}_distal`, each
    /// kept with probability 1/2 (so segments skip discs and cross up to every joint before
    /// the anchor), and ends at its anchor on `link{i+1}`. Every hole has a random z
    /// (±5 mm, never 0) on a circle of radius 15–25 mm.
    pub fn explicit_spec(&self, seed: u64) -> RoutingSpec {
        self.explicit_spec_with(seed, 3)
    }

    /// [`RandomChain::explicit_spec`] with `per_joint` cables per universal joint (3 gives the
    /// same routing): four or more make the equilibrium set of each joint two-dimensional or
    /// more, the sets the tension policies choose in.
    pub fn explicit_spec_with(&self, seed: u64, per_joint: usize) -> RoutingSpec {
        let mut rng = rng(seed);
        let mut cables = Vec::new();
        for i in 0..self.joints {
            for k in 0..per_joint {
                let mut holes = vec![random_hole("base_link".to_owned(), &mut rng)];
                for j in 1..=i {
                    for link in [format!("cross{j}"), format!("link{j}"), format!("link{j}_distal")]
                    {
                        if rng.random_bool(0.5) {
                            holes.push(random_hole(link, &mut rng));
                        }
                    }
                }
                holes.push(random_hole(format!("link{}", i + 1), &mut rng));
                cables.push(ExplicitCable {
                    name: format!("x{}c{}", i + 1, k + 1),
                    joint: None,
                    free_length: None,
                    tension_limits: None,
                    friction_coefficient: None,
                    entry_direction: None,
                    holes,
                });
            }
        }
        RoutingSpec { cables, ..self.common_spec(PerJoint::Uniform(3.0)) }
    }

    /// Two explicit cables that run back toward the base, for a chain of two or more joints
    /// (the friction tests' cases where two segments of one cable cross one DOF):
    /// - `zigzag` (entry direction given): base → `link2` → `link1` → `link2`, its middle
    ///   segment's routing ends swapped against the cable's direction;
    /// - `backward`: `link2` → `link1` → `link2`, its first segment run back toward the base,
    ///   the one case where the entry direction's own turning reaches `∂θ_0/∂Q` (before the
    ///   first segment's lower body it turns both directions rigidly and cancels).
    pub fn turning_back_cables() -> [ExplicitCable; 2] {
        let hole = |link: &str, point: [f64; 3]| HoleSpec { link: link.to_owned(), point };
        let cable = |name: &str, entry_direction: [f64; 3], holes: Vec<HoleSpec>| ExplicitCable {
            name: name.to_owned(),
            joint: None,
            free_length: None,
            tension_limits: None,
            friction_coefficient: None,
            entry_direction: Some(entry_direction),
            holes,
        };
        let (up, back, down) = (
            hole("link2", [0.0, 0.02, -0.002]),
            hole("link1", [-0.02, 0.0, 0.003]),
            hole("link2", [0.0, -0.02, 0.002]),
        );
        let zigzag =
            vec![hole("base_link", [0.02, 0.0, 0.001]), up.clone(), back.clone(), down.clone()];
        [
            cable("zigzag", [0.3, -0.2, 1.0], zigzag),
            cable("backward", [-0.2, 0.1, -1.0], vec![up, back, down]),
        ]
    }

    /// The routing of `spec` on [`RandomChain::robot`].
    ///
    /// # Panics
    /// When the routing does not load (the message names the chain and the error).
    pub fn routing(&self, robot: &Robot, spec: &RoutingSpec) -> Routing {
        Routing::new(robot, spec, &format!("<{} cables>", self.name))
            .unwrap_or_else(|e| panic!("{}: {e}", self.name))
    }
}
