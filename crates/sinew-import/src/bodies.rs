//! The bodies file (`<bodies_system><links><link_rigid …>`): CASPR's `BodyModelRigid.LoadXmlObj`,
//! `JointBase.LoadXmlObj` and `SystemModelBodies.LoadXmlObj`.

use nalgebra::{Matrix3, Vector3};
use roxmltree::Node;

use crate::error::{ImportError, Result};
use crate::xml::{Xml, describe, elements};

/// The joint types Sinew imports (CASPR's `JointType` names).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    /// `R_X`: revolute about x (`RevoluteX`).
    RX,
    /// `R_Y`: revolute about y.
    RY,
    /// `R_Z`: revolute about z.
    RZ,
    /// `U_XY`: about x, then about the rotated y (`UniversalXY`: `R_pe = R_x(α) R_y(β)`).
    UXY,
    /// `U_XZ`: about x, then about the rotated z.
    UXZ,
    /// `U_YZ`: about y, then about the rotated z.
    UYZ,
}

/// A coordinate axis of a link frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// x.
    X,
    /// y.
    Y,
    /// z.
    Z,
}

impl Axis {
    /// The unit vector.
    pub fn unit(self) -> [f64; 3] {
        match self {
            Axis::X => [1.0, 0.0, 0.0],
            Axis::Y => [0.0, 1.0, 0.0],
            Axis::Z => [0.0, 0.0, 1.0],
        }
    }

    /// `x`, `y` or `z`.
    pub fn name(self) -> &'static str {
        match self {
            Axis::X => "x",
            Axis::Y => "y",
            Axis::Z => "z",
        }
    }
}

impl JointKind {
    /// The type as CASPR spells it, or `None`.
    pub fn from_caspr(name: &str) -> Option<JointKind> {
        Some(match name {
            "R_X" => JointKind::RX,
            "R_Y" => JointKind::RY,
            "R_Z" => JointKind::RZ,
            "U_XY" => JointKind::UXY,
            "U_XZ" => JointKind::UXZ,
            "U_YZ" => JointKind::UYZ,
            _ => return None,
        })
    }

    /// The type as CASPR spells it.
    pub fn caspr_name(self) -> &'static str {
        match self {
            JointKind::RX => "R_X",
            JointKind::RY => "R_Y",
            JointKind::RZ => "R_Z",
            JointKind::UXY => "U_XY",
            JointKind::UXZ => "U_XZ",
            JointKind::UYZ => "U_YZ",
        }
    }

    /// The rotation axes in order: one for `R_*`, two for `U_*` (the second about the frame the
    /// first rotation made).
    pub fn axes(self) -> &'static [Axis] {
        match self {
            JointKind::RX => &[Axis::X],
            JointKind::RY => &[Axis::Y],
            JointKind::RZ => &[Axis::Z],
            JointKind::UXY => &[Axis::X, Axis::Y],
            JointKind::UXZ => &[Axis::X, Axis::Z],
            JointKind::UYZ => &[Axis::Y, Axis::Z],
        }
    }

    /// Degrees of freedom: 1 or 2.
    pub fn dof(self) -> usize {
        self.axes().len()
    }
}

/// One CASPR link (`<link_rigid>`), in its own frame: the frame of its joint, at the joint.
#[derive(Debug, Clone, PartialEq)]
pub struct Link {
    /// CASPR's `num` (1, 2, …; 0 is the base).
    pub num: usize,
    /// CASPR's `name`.
    pub name: String,
    /// The joint that moves it relative to its parent.
    pub joint: JointKind,
    /// Lower joint limit per coordinate, rad.
    pub q_min: Vec<f64>,
    /// Upper joint limit per coordinate, rad.
    pub q_max: Vec<f64>,
    /// Whether the file stated `q_min`/`q_max` (else ±π, CASPR's `q_lb`/`q_ub`).
    pub limits_stated: bool,
    /// Mass, kg.
    pub mass: f64,
    /// Centre of mass in the link frame (`<com_location>`, `r_G`), m.
    pub com: [f64; 3],
    /// Inertia about the centre of mass in the link frame's axes (`I_G`), kg m².
    pub inertia_com: [[f64; 3]; 3],
    /// The joint's position in the parent's frame (`<parent><location>`, `r_Parent`), m.
    pub parent_location: [f64; 3],
    /// The link's end point in its frame (`<end_location>`, `r_Pe`), m.
    pub end_location: [f64; 3],
}

/// Read the links of a bodies file.
pub(crate) fn read_links(xml: &Xml<'_>) -> Result<Vec<Link>> {
    let root = xml.root("bodies_system")?;
    let links_node = xml.child(root, "links")?;
    let nodes: Vec<Node<'_, '_>> = elements(links_node).collect();
    if nodes.is_empty() {
        return Err(ImportError::NoLinks { at: xml.place(links_node) });
    }
    let count = nodes.len();
    let mut links = Vec::with_capacity(count);
    for (k, node) in nodes.into_iter().enumerate() {
        if node.tag_name().name() != "link_rigid" {
            return Err(ImportError::UnexpectedElement {
                at: xml.place(node),
                element: describe(node),
                parent: "<links>".to_owned(),
                expected: "<link_rigid> (CASPR's only link type)",
            });
        }
        links.push(read_link(xml, node, k + 1, count)?);
    }
    Ok(links)
}

fn read_link(xml: &Xml<'_>, node: Node<'_, '_>, expected: usize, count: usize) -> Result<Link> {
    let num_text = xml.attribute(node, "num")?;
    if num_text.trim().parse::<usize>().ok() != Some(expected) {
        return Err(ImportError::LinkOrder {
            at: xml.place(node),
            element: describe(node),
            expected,
        });
    }
    let num = expected;
    let name = xml.attribute(node, "name")?.to_owned();

    let joint_node = xml.child(node, "joint")?;
    let type_name = xml.attribute(joint_node, "type")?;
    let joint = JointKind::from_caspr(type_name).ok_or_else(|| ImportError::UnsupportedJoint {
        at: xml.place(joint_node),
        link: num,
        name: name.clone(),
        joint_type: type_name.to_owned(),
    })?;
    let dof = joint.dof();
    let expected_limits =
        if dof == 1 { "one finite number (rad)" } else { "two finite numbers (rad)" };
    let limit = |attribute: &'static str| -> Result<Option<Vec<f64>>> {
        match joint_node.attribute(attribute) {
            Some(t) if !t.trim().is_empty() => {
                xml.numbers(joint_node, attribute, t, Some(dof), expected_limits).map(Some)
            }
            _ => Ok(None),
        }
    };
    let (q_min, q_max, limits_stated) = match (limit("q_min")?, limit("q_max")?) {
        (Some(lo), Some(hi)) => (lo, hi, true),
        (lo, hi) => (
            lo.unwrap_or_else(|| vec![-std::f64::consts::PI; dof]),
            hi.unwrap_or_else(|| vec![std::f64::consts::PI; dof]),
            false,
        ),
    };
    for (i, (&lower, &upper)) in q_min.iter().zip(&q_max).enumerate() {
        if lower > upper {
            return Err(ImportError::InvalidJointLimits {
                at: xml.place(joint_node),
                link: num,
                name,
                coordinate: i + 1,
                lower,
                upper,
            });
        }
    }

    let physical = xml.child(node, "physical")?;
    let mass = xml.child_number(physical, "mass")?;
    if mass < 0.0 {
        let mass_node = xml.child(physical, "mass")?;
        return Err(ImportError::InvalidNumber {
            at: xml.place(mass_node),
            element: describe(mass_node),
            field: "<mass>".to_owned(),
            text: crate::xml::text(mass_node).trim().to_owned(),
            expected: "a mass ≥ 0 kg",
        });
    }
    let com = xml.child_vector(physical, "com_location")?;
    let end_location = xml.child_vector(physical, "end_location")?;
    let inertia_node = xml.child(physical, "inertia")?;
    let reference = xml.attribute(inertia_node, "ref")?;
    let mut inertia = [[0.0; 3]; 3];
    for (name, i, j) in
        [("Ixx", 0, 0), ("Iyy", 1, 1), ("Izz", 2, 2), ("Ixy", 0, 1), ("Ixz", 0, 2), ("Iyz", 1, 2)]
    {
        let v = xml.child_number(inertia_node, name)?;
        inertia[i][j] = v;
        inertia[j][i] = v;
    }
    let inertia_com = match reference {
        "com" => inertia,
        // BodyModelRigid: I_G = I_O − m (r_Gᵀ r_G 𝟙 − r_G r_Gᵀ), the parallel-axis theorem.
        "joint" => about_com(inertia, mass, com),
        other => {
            return Err(ImportError::InvalidAttribute {
                at: xml.place(inertia_node),
                element: describe(inertia_node),
                attribute: "ref",
                value: other.to_owned(),
                expected: "\"com\" or \"joint\"",
            });
        }
    };

    let parent_node = xml.child(node, "parent")?;
    let (parent, _) = xml.child_index(parent_node, "num")?;
    if parent > count {
        return Err(ImportError::MissingParent {
            at: xml.place(parent_node),
            link: num,
            name,
            parent,
            links: count,
        });
    }
    if parent != num - 1 {
        return Err(ImportError::NotSerial {
            at: xml.place(parent_node),
            link: num,
            name,
            parent,
            expected: num - 1,
        });
    }
    let parent_location = xml.child_vector(parent_node, "location")?;

    Ok(Link {
        num,
        name,
        joint,
        q_min,
        q_max,
        limits_stated,
        mass,
        com,
        inertia_com,
        parent_location,
        end_location,
    })
}

/// The inertia about the centre of mass from the inertia about the joint (parallel axes).
pub(crate) fn about_com(about_joint: [[f64; 3]; 3], mass: f64, com: [f64; 3]) -> [[f64; 3]; 3] {
    let i_o = Matrix3::from_fn(|i, j| about_joint[i][j]);
    let r = Vector3::from(com);
    let i_g = i_o - mass * (Matrix3::identity() * r.dot(&r) - r * r.transpose());
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| i_g[(i, j)]))
}

#[cfg(test)]
mod tests {
    use super::JointKind;

    #[test]
    fn joint_kinds_round_trip() {
        for name in ["R_X", "R_Y", "R_Z", "U_XY", "U_XZ", "U_YZ"] {
            let kind = JointKind::from_caspr(name);
            assert_eq!(kind.map(JointKind::caspr_name), Some(name));
        }
        assert_eq!(JointKind::from_caspr("S_EULER_XYZ"), None);
    }
}
