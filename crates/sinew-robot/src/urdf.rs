//! URDF → [`Robot`]: parse with urdf-rs, then check and fold the tree into a serial chain.
//!
//! What is read: links (`<inertial>`: origin, mass, inertia), joints (type, origin, parent,
//! child, axis, limits). What is ignored: visual and collision geometry, materials, transmissions,
//! dynamics, mimic and safety-controller tags, and Gazebo extensions.
//!
//! Fixed joints are folded into their parent body (masses, centres of mass and inertias are
//! combined); `continuous` joints are revolute joints without limits; `prismatic`, `planar`,
//! `floating` and `spherical` joints are an [`RobotError::UnsupportedJoint`].

use std::collections::HashMap;

use nalgebra::{IsometryMatrix3, Matrix3, Rotation3, Translation3, Unit, Vector3};

use crate::error::{Result, RobotError};
use crate::model::{Body, ChainSettings, Joint, LinkPlacement, Robot};

fn pose(p: &urdf_rs::Pose) -> IsometryMatrix3<f64> {
    let rotation = Rotation3::from_euler_angles(p.rpy[0], p.rpy[1], p.rpy[2]);
    IsometryMatrix3::from_parts(Translation3::new(p.xyz[0], p.xyz[1], p.xyz[2]), rotation)
}

/// The largest magnitude a URDF number may have (m, rad, kg, kg m²). Beyond it no arm is
/// described, and products of such numbers (a torque: mass × gravity × lever arm) overflow to
/// infinity: `1e308` in an origin once loaded and gave an infinite gravity torque.
pub(crate) const MAX_MAGNITUDE: f64 = 1e9;

fn all_finite(values: &[f64]) -> bool {
    values.iter().all(|v| v.is_finite() && v.abs() <= MAX_MAGNITUDE)
}

impl Robot {
    /// Build a robot from URDF text.
    ///
    /// `source_name` names the text in error messages (a path, or `<string>`).
    ///
    /// # Errors
    /// Every malformed input is a distinct [`RobotError`] naming the element at fault.
    pub fn from_urdf_str(text: &str, source_name: &str, settings: &ChainSettings) -> Result<Robot> {
        let urdf = urdf_rs::read_from_string(text).map_err(|e| RobotError::InvalidUrdf {
            source_name: source_name.to_owned(),
            message: e.to_string(),
        })?;
        Robot::from_urdf(&urdf, source_name, settings)
    }

    /// Build a robot from a parsed URDF.
    ///
    /// # Errors
    /// Every malformed input is a distinct [`RobotError`] naming the element at fault.
    pub fn from_urdf(
        urdf: &urdf_rs::Robot,
        source_name: &str,
        settings: &ChainSettings,
    ) -> Result<Robot> {
        Builder { urdf, source: source_name }.build(settings)
    }
}

/// One link's inertial, expressed in its body's frame.
#[derive(Clone)]
struct MassPart {
    mass: f64,
    com: Vector3<f64>,
    inertia: Matrix3<f64>,
}

struct Builder<'a> {
    urdf: &'a urdf_rs::Robot,
    source: &'a str,
}

impl Builder<'_> {
    fn non_finite(&self, element: String, field: &str) -> RobotError {
        RobotError::NonFinite {
            source_name: self.source.to_owned(),
            element,
            field: field.to_owned(),
        }
    }

    fn check_numbers(&self) -> Result<()> {
        for link in &self.urdf.links {
            let inertial = &link.inertial;
            let mass = inertial.mass.value;
            if !mass.is_finite() || !(0.0..=MAX_MAGNITUDE).contains(&mass) {
                return Err(RobotError::InvalidMass {
                    source_name: self.source.to_owned(),
                    link: link.name.clone(),
                    mass,
                });
            }
            if !all_finite(&inertial.origin.xyz.0) || !all_finite(&inertial.origin.rpy.0) {
                return Err(self.non_finite(format!("link `{}` inertial", link.name), "origin"));
            }
            let i = &inertial.inertia;
            if !all_finite(&[i.ixx, i.ixy, i.ixz, i.iyy, i.iyz, i.izz]) {
                return Err(self.non_finite(format!("link `{}` inertial", link.name), "inertia"));
            }
        }
        for joint in &self.urdf.joints {
            if !all_finite(&joint.origin.xyz.0) || !all_finite(&joint.origin.rpy.0) {
                return Err(self.non_finite(format!("joint `{}`", joint.name), "origin"));
            }
            if !all_finite(&joint.axis.xyz.0) {
                return Err(self.non_finite(format!("joint `{}`", joint.name), "axis"));
            }
        }
        Ok(())
    }

    fn build(&self, settings: &ChainSettings) -> Result<Robot> {
        let urdf = self.urdf;
        let source_name = || self.source.to_owned();
        self.check_numbers()?;

        // Link names → indices, unique.
        let mut link_index: HashMap<&str, usize> = HashMap::new();
        for (i, link) in urdf.links.iter().enumerate() {
            if link_index.insert(link.name.as_str(), i).is_some() {
                return Err(RobotError::DuplicateLink {
                    source_name: source_name(),
                    link: link.name.clone(),
                });
            }
        }
        let mut joint_names: HashMap<&str, ()> = HashMap::new();
        for joint in &urdf.joints {
            if joint_names.insert(joint.name.as_str(), ()).is_some() {
                return Err(RobotError::DuplicateJoint {
                    source_name: source_name(),
                    joint: joint.name.clone(),
                });
            }
        }

        // Parent/child structure.
        let n_links = urdf.links.len();
        let mut parent_joint: Vec<Option<usize>> = vec![None; n_links];
        let mut child_joints: Vec<Vec<usize>> = vec![Vec::new(); n_links];
        let mut joint_child: Vec<usize> = Vec::with_capacity(urdf.joints.len());
        for (j, joint) in urdf.joints.iter().enumerate() {
            let find = |name: &str| {
                link_index.get(name).copied().ok_or_else(|| RobotError::UnknownLink {
                    source_name: source_name(),
                    joint: joint.name.clone(),
                    link: name.to_owned(),
                })
            };
            let parent = find(&joint.parent.link)?;
            let child = find(&joint.child.link)?;
            if parent == child || parent_joint[child].is_some() {
                return Err(RobotError::KinematicLoop {
                    source_name: source_name(),
                    link: joint.child.link.clone(),
                });
            }
            parent_joint[child] = Some(j);
            child_joints[parent].push(j);
            joint_child.push(child);
        }
        let mut roots = (0..n_links).filter(|&l| parent_joint[l].is_none());
        let Some(root) = roots.next() else {
            // Every link has a parent: the joints close a loop.
            let link = urdf.links.first().map(|l| l.name.clone()).unwrap_or_default();
            return Err(RobotError::KinematicLoop { source_name: source_name(), link });
        };
        if let Some(second) = roots.next() {
            return Err(RobotError::MultipleRoots {
                source_name: source_name(),
                first: urdf.links[root].name.clone(),
                second: urdf.links[second].name.clone(),
            });
        }

        // Depth-first order from the root; links not reached sit on a loop.
        let mut order = Vec::with_capacity(n_links);
        let mut stack = vec![root];
        while let Some(l) = stack.pop() {
            order.push(l);
            stack.extend(child_joints[l].iter().rev().map(|&j| joint_child[j]));
        }
        if order.len() != n_links {
            let mut reached = vec![false; n_links];
            for &l in &order {
                reached[l] = true;
            }
            let link = (0..n_links).find(|&l| !reached[l]).map(|l| urdf.links[l].name.clone());
            return Err(RobotError::KinematicLoop {
                source_name: source_name(),
                link: link.unwrap_or_default(),
            });
        }

        // Joint types; which subtrees hold a movable joint.
        let mut movable = vec![false; urdf.joints.len()];
        for (j, joint) in urdf.joints.iter().enumerate() {
            use urdf_rs::JointType as T;
            movable[j] = match joint.joint_type {
                T::Revolute | T::Continuous => true,
                T::Fixed => false,
                T::Prismatic | T::Floating | T::Planar | T::Spherical => {
                    return Err(RobotError::UnsupportedJoint {
                        source_name: source_name(),
                        joint: joint.name.clone(),
                        kind: format!("{:?}", joint.joint_type).to_lowercase(),
                    });
                }
            };
        }
        let mut subtree_movable = vec![false; n_links];
        for &l in order.iter().rev() {
            subtree_movable[l] =
                child_joints[l].iter().any(|&j| movable[j] || subtree_movable[joint_child[j]]);
        }
        for &l in &order {
            let branches = child_joints[l]
                .iter()
                .filter(|&&j| movable[j] || subtree_movable[joint_child[j]])
                .count();
            if branches > 1 {
                return Err(RobotError::BranchingChain {
                    source_name: source_name(),
                    link: urdf.links[l].name.clone(),
                });
            }
        }

        // Walk the tree: place every link on a body, create a joint per revolute joint.
        let mut placement: Vec<Option<(usize, IsometryMatrix3<f64>)>> = vec![None; n_links];
        placement[root] = Some((0, IsometryMatrix3::identity()));
        let mut joints = Vec::new();
        let mut body_link = vec![root];
        for &l in &order {
            let Some((body, body_m_link)) = placement[l] else { continue };
            for &j in &child_joints[l] {
                let joint = &urdf.joints[j];
                let origin = body_m_link * pose(&joint.origin);
                let child = joint_child[j];
                if !movable[j] {
                    placement[child] = Some((body, origin));
                    continue;
                }
                let axis = Vector3::new(joint.axis.xyz[0], joint.axis.xyz[1], joint.axis.xyz[2]);
                let Some(axis) = Unit::try_new(axis, 1e-12) else {
                    return Err(RobotError::ZeroAxis {
                        source_name: source_name(),
                        joint: joint.name.clone(),
                    });
                };
                let (lower, upper) = match joint.joint_type {
                    urdf_rs::JointType::Continuous => (f64::NEG_INFINITY, f64::INFINITY),
                    _ => (joint.limit.lower, joint.limit.upper),
                };
                if lower.is_nan() || upper.is_nan() || lower >= upper {
                    return Err(RobotError::InvalidLimits {
                        source_name: source_name(),
                        joint: joint.name.clone(),
                        lower,
                        upper,
                    });
                }
                joints.push(Joint { name: joint.name.clone(), origin, axis, lower, upper });
                placement[child] = Some((joints.len(), IsometryMatrix3::identity()));
                body_link.push(child);
            }
        }
        if joints.is_empty() {
            return Err(RobotError::NoJoints { source_name: source_name() });
        }

        // Fold masses into bodies (parallel-axis theorem, body axes).
        let mut bodies: Vec<Body> = body_link
            .iter()
            .map(|&l| Body {
                name: urdf.links[l].name.clone(),
                mass: 0.0,
                com: Vector3::zeros(),
                inertia: Matrix3::zeros(),
            })
            .collect();
        let mut parts: Vec<Vec<MassPart>> = vec![Vec::new(); bodies.len()];
        let mut links = Vec::with_capacity(n_links);
        for &l in &order {
            let Some((body, body_m_link)) = placement[l] else { continue };
            let link = &urdf.links[l];
            links.push(LinkPlacement { name: link.name.clone(), body, body_m_link });
            let inertial = &link.inertial;
            let body_m_com = body_m_link * pose(&inertial.origin);
            let i = &inertial.inertia;
            let local = Matrix3::new(i.ixx, i.ixy, i.ixz, i.ixy, i.iyy, i.iyz, i.ixz, i.iyz, i.izz);
            let r = body_m_com.rotation.matrix();
            parts[body].push(MassPart {
                mass: inertial.mass.value,
                com: body_m_com.translation.vector,
                inertia: r * local * r.transpose(),
            });
        }
        for (body, parts) in bodies.iter_mut().zip(&parts) {
            let mass: f64 = parts.iter().map(|p| p.mass).sum();
            if mass > 0.0 {
                body.mass = mass;
                body.com = parts.iter().map(|p| p.mass * p.com).sum::<Vector3<f64>>() / mass;
                body.inertia = parts
                    .iter()
                    .map(|p| {
                        let d = p.com - body.com;
                        p.inertia
                            + p.mass * (Matrix3::identity() * d.norm_squared() - d * d.transpose())
                    })
                    .sum();
            }
        }

        let mut subtree_mass = vec![0.0; joints.len()];
        let mut acc = 0.0;
        for j in (0..joints.len()).rev() {
            acc += bodies[j + 1].mass;
            subtree_mass[j] = acc;
        }

        let joint_groups = crate::model::group_joints(&joints, &bodies);
        let mut dof_joint = vec![0; joints.len()];
        for (g, group) in joint_groups.iter().enumerate() {
            dof_joint[group.clone()].fill(g);
        }
        let name = urdf.name.clone();
        let tip = links.iter().find(|p| p.name == settings.tip_link).cloned().ok_or_else(|| {
            RobotError::NoSuchLink { robot: name.clone(), link: settings.tip_link.clone() }
        })?;
        Ok(Robot {
            name,
            source: source_name(),
            bodies,
            joints,
            links,
            gravity: settings.gravity,
            tip,
            subtree_mass,
            joint_groups,
            dof_joint,
        })
    }
}
