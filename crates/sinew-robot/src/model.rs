//! The immutable robot description: a serial chain of revolute joints built once from a URDF.

use std::ops::Range;

use nalgebra::{IsometryMatrix3, Matrix3, Point3, Unit, Vector3};

use crate::error::{Result, RobotError};

/// A rigid body of the chain: the child of one revolute joint together with every link that is
/// attached to it through fixed joints (the root body has no parent joint).
///
/// Frame: the body frame is the frame of the URDF link that is the revolute joint's child.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// URDF name of the link whose frame is the body frame.
    pub name: String,
    /// Total mass of the folded links, kg.
    pub mass: f64,
    /// Centre of mass in the body frame, m (zero when the body is massless).
    pub com: Vector3<f64>,
    /// Inertia about the centre of mass, body axes, kg m².
    pub inertia: Matrix3<f64>,
}

/// A revolute joint of the chain. Joint `j` moves body `j + 1` relative to body `j`.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// URDF name.
    pub name: String,
    /// Pose of the joint frame in the parent body frame (`parent_M_joint`), fixed joints folded in.
    pub origin: IsometryMatrix3<f64>,
    /// Unit rotation axis in the joint frame.
    pub axis: Unit<Vector3<f64>>,
    /// Lower limit, rad (`-inf` for a continuous joint).
    pub lower: f64,
    /// Upper limit, rad (`+inf` for a continuous joint).
    pub upper: f64,
}

/// A point fixed on a body, given in that body's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyPoint {
    /// Body index: 0 is the root, `j + 1` the child of joint `j`.
    pub body: usize,
    /// Coordinates in the body frame, m.
    pub point: Vector3<f64>,
}

/// Where a URDF link sits on the chain: its body and its pose in the body frame.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkPlacement {
    /// URDF link name.
    pub name: String,
    /// Body index the link is folded into.
    pub body: usize,
    /// Pose of the link frame in the body frame (`body_M_link`).
    pub body_m_link: IsometryMatrix3<f64>,
}

/// The immutable description of a serial chain of revolute joints (Pinocchio's *model*).
///
/// Built once (from a URDF through [`crate::load`], or from [`Robot::from_urdf`]); every
/// per-configuration algorithm takes `&Robot`, a reusable [`crate::RobotData`] and `Q`.
///
/// Conventions (spec §1, §5): `Q` lists the revolute joints from the base to the tip; the base
/// frame is the root link's frame; the gravity vector (m/s²) is expressed in the base frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Robot {
    pub(crate) name: String,
    pub(crate) source: String,
    pub(crate) bodies: Vec<Body>,
    pub(crate) joints: Vec<Joint>,
    pub(crate) links: Vec<LinkPlacement>,
    pub(crate) gravity: Vector3<f64>,
    pub(crate) tip: LinkPlacement,
    /// `subtree_mass[j]`: total mass of the bodies moved by joint `j` (bodies `j + 1 ..`).
    pub(crate) subtree_mass: Vec<f64>,
    /// [`Robot::joint_groups`].
    pub(crate) joint_groups: Vec<Range<usize>>,
    /// `dof_joint[d]`: the arm joint that revolute joint `d` belongs to.
    pub(crate) dof_joint: Vec<usize>,
}

/// The arm's joints as groups of revolute joints (see [`Robot::joint_groups`]): revolute joint
/// `k` and `k + 1` form one universal joint when the body between them is massless (the cross
/// of a universal joint: no inertial, no attached link with mass) and their axes are not
/// parallel; any other revolute joint is a 1-DOF joint of its own. Greedy from the base. The
/// axes need not intersect (a universal joint with offset axes is still one joint).
pub(crate) fn group_joints(joints: &[Joint], bodies: &[Body]) -> Vec<Range<usize>> {
    let mut groups = Vec::new();
    let mut k = 0;
    while k < joints.len() {
        let pairs = k + 1 < joints.len() && {
            let next = &joints[k + 1];
            let between = &bodies[k + 1];
            let second_axis = next.origin.rotation * next.axis.into_inner();
            between.mass <= 0.0 && joints[k].axis.cross(&second_axis).norm() > 1e-9
        };
        let len = if pairs { 2 } else { 1 };
        groups.push(k..k + len);
        k += len;
    }
    groups
}

/// The part of a robot description that URDF does not carry.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainSettings {
    /// The link whose frame is the end-effector frame (its origin is the end-effector point).
    pub tip_link: String,
    /// Gravitational acceleration in the base frame, m/s².
    pub gravity: Vector3<f64>,
}

impl Robot {
    /// The robot's name (URDF `<robot name>`).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The file the robot was read from (`<string>` when built from text).
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Number of revolute joints, the length of `Q`.
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    /// The arm's joints, base first, each as the range of its revolute joints in `Q`: `k..k + 2`
    /// for a universal joint (two consecutive revolute joints with non-parallel axes and a
    /// massless cross between them, as a URDF writes a universal joint), `k..k + 1` for a lone
    /// revolute joint. Tension levels, cable ownership and the per-joint outputs are counted
    /// in these joints. The paper's arms are all universal (`2n` DOF, joint `i` owning
    /// `q[2i]`, `q[2i + 1]`).
    pub fn joint_groups(&self) -> &[Range<usize>] {
        &self.joint_groups
    }

    /// The number of arm joints ([`Robot::joint_groups`]).
    pub fn joint_count(&self) -> usize {
        self.joint_groups.len()
    }

    /// The arm joint revolute joint `dof` belongs to, `None` past the last one.
    pub fn joint_of_dof(&self, dof: usize) -> Option<usize> {
        self.dof_joint.get(dof).copied()
    }

    /// Whether every arm joint is a 2-DOF universal joint (the paper's arms).
    pub fn is_universal(&self) -> bool {
        self.joint_groups.iter().all(|g| g.len() == 2)
    }

    /// The revolute joints from base to tip.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// The bodies: index 0 is the root, `j + 1` the child of joint `j`.
    pub fn bodies(&self) -> &[Body] {
        &self.bodies
    }

    /// Every URDF link with the body it belongs to.
    pub fn links(&self) -> &[LinkPlacement] {
        &self.links
    }

    /// Gravitational acceleration in the base frame, m/s².
    pub fn gravity(&self) -> Vector3<f64> {
        self.gravity
    }

    /// The same robot under another gravity vector (base frame, m/s²), e.g. zero to study the
    /// load alone.
    pub fn with_gravity(&self, gravity: Vector3<f64>) -> Robot {
        Robot { gravity, ..self.clone() }
    }

    /// Total mass of the moving bodies (every body but the root), kg.
    pub fn moving_mass(&self) -> f64 {
        self.bodies.iter().skip(1).map(|b| b.mass).sum()
    }

    /// The end-effector link and where it sits.
    pub fn tip(&self) -> &LinkPlacement {
        &self.tip
    }

    /// The end-effector point (the tip link's origin) as a body point.
    pub fn tip_point(&self) -> BodyPoint {
        BodyPoint { body: self.tip.body, point: self.tip.body_m_link.translation.vector }
    }

    /// Index of a revolute joint by name.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// Where a URDF link sits on the chain.
    ///
    /// # Errors
    /// [`RobotError::NoSuchLink`] when the robot has no link of that name.
    pub fn link(&self, name: &str) -> Result<&LinkPlacement> {
        self.links.iter().find(|l| l.name == name).ok_or_else(|| RobotError::NoSuchLink {
            robot: self.name.clone(),
            link: name.to_owned(),
        })
    }

    /// A point given in a URDF link's frame, as a point on its body.
    ///
    /// # Errors
    /// [`RobotError::NoSuchLink`] when the robot has no link of that name.
    pub fn link_point(&self, link: &str, point_in_link: Vector3<f64>) -> Result<BodyPoint> {
        let placement = self.link(link)?;
        let point = placement.body_m_link * Point3::from(point_in_link);
        Ok(BodyPoint { body: placement.body, point: point.coords })
    }

    /// Check `Q` against the joint limits.
    ///
    /// # Errors
    /// [`RobotError::DimensionMismatch`] for a wrong length, [`RobotError::NonFiniteAngle`] for a
    /// NaN or infinite angle, [`RobotError::OutOfLimits`] for the first joint outside its limits.
    pub fn check_limits(&self, q: &[f64]) -> Result<()> {
        self.check_configuration(q)?;
        for (joint, &value) in self.joints.iter().zip(q) {
            if value < joint.lower || value > joint.upper {
                return Err(RobotError::OutOfLimits {
                    joint: joint.name.clone(),
                    position: value,
                    lower: joint.lower,
                    upper: joint.upper,
                });
            }
        }
        Ok(())
    }

    /// Check the length of `Q` and that every angle is finite.
    ///
    /// # Errors
    /// [`RobotError::DimensionMismatch`] or [`RobotError::NonFiniteAngle`].
    pub fn check_configuration(&self, q: &[f64]) -> Result<()> {
        if q.len() != self.dof() {
            return Err(RobotError::DimensionMismatch {
                what: "joint configuration Q",
                expected: self.dof(),
                got: q.len(),
            });
        }
        for (joint, &value) in self.joints.iter().zip(q) {
            if !value.is_finite() {
                return Err(RobotError::NonFiniteAngle { joint: joint.name.clone(), value });
            }
        }
        Ok(())
    }

    /// Check that a body point refers to a body of this robot.
    pub(crate) fn check_body(&self, body: usize) -> Result<()> {
        if body >= self.bodies.len() {
            return Err(RobotError::NoSuchBody { body, bodies: self.bodies.len() });
        }
        Ok(())
    }
}
