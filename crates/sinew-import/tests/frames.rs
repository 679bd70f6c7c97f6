//! Every link frame and every attachment point of an imported CASPR model, in the base frame,
//! against CASPR's own composition of its joint rotations (`SystemModelBodies.update`,
//! re-implemented here): each joint type the importer accepts (R_X, R_Y, R_Z, U_XY, U_XZ,
//! U_YZ) in the synthetic model tests/data/every_joint_bodies.xml, and cables written here
//! with an attachment on every link, in both attachment references, to 1e-14.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use nalgebra::{Rotation3, Unit, Vector3};
use sinew_import::{ImportError, ImportOptions, JointKind, Source, import_caspr};
use sinew_robot::RobotData;

/// The model's links: joint type, `<parent><location>`, `<com_location>` (every_joint_bodies.xml).
const LINKS: [(JointKind, [f64; 3], [f64; 3]); 6] = [
    (JointKind::RX, [0.0, 0.0, 0.02], [0.01, 0.02, 0.05]),
    (JointKind::RY, [0.0, 0.0, 0.1], [0.0, 0.01, 0.06]),
    (JointKind::RZ, [0.01, 0.0, 0.12], [0.02, 0.0, 0.04]),
    (JointKind::UXY, [0.0, 0.02, 0.09], [0.0, 0.0, 0.05]),
    (JointKind::UXZ, [0.0, 0.0, 0.1], [0.01, 0.0, 0.05]),
    (JointKind::UYZ, [0.0, 0.0, 0.1], [0.0, 0.0, 0.04]),
];
const NAMES: [&str; 6] = ["rx", "ry", "rz", "uxy", "uxz", "uyz"];

/// CASPR's frames of links 0..=6 at `q`: `R_0k = R_0p R_k(q_k)`, the origin at the parent's
/// origin plus `R_0p r_Parent`.
fn caspr_frames(q: &[f64]) -> Vec<(Rotation3<f64>, Vector3<f64>)> {
    let mut frames = vec![(Rotation3::identity(), Vector3::zeros())];
    let mut i = 0;
    for (kind, location, _) in LINKS {
        let (rot, pos) = *frames.last().unwrap();
        let joint = kind.axes().iter().zip(&q[i..i + kind.dof()]).fold(
            Rotation3::identity(),
            |acc, (axis, &angle)| {
                acc * Rotation3::from_axis_angle(
                    &Unit::new_normalize(Vector3::from(axis.unit())),
                    angle,
                )
            },
        );
        i += kind.dof();
        frames.push((rot * joint, pos + rot * Vector3::from(location)));
    }
    frames
}

/// One cable per moving link k: from the base through every link before k to its anchor on k,
/// odd k in the joint reference, even k in the com one. (link, location) per attachment.
fn cable_attachments(k: usize) -> Vec<(usize, [f64; 3])> {
    let theta = k as f64;
    let mut points = vec![(0, [0.02 * theta.cos(), 0.02 * theta.sin(), 0.0])];
    for l in 1..=k {
        let z = if l == k { 0.07 } else { 0.03 };
        points.push((l, [0.015 * (theta + l as f64).cos(), -0.012 * (theta - l as f64).sin(), z]));
    }
    points
}

fn cables_xml() -> String {
    let mut text = String::from("<cables default_cable_set=\"all\">\n  <cable_set id=\"all\">\n");
    for k in 1..=6 {
        let reference = if k % 2 == 1 { "joint" } else { "com" };
        text += &format!(
            "    <cable_ideal name=\"k{k}\" attachment_reference=\"{reference}\">\n      <properties><force_min>2</force_min><force_max>90</force_max></properties>\n      <attachments>\n"
        );
        for (link, p) in cable_attachments(k) {
            text += &format!(
                "        <attachment><link>{link}</link><location>{:e} {:e} {:e}</location></attachment>\n",
                p[0], p[1], p[2]
            );
        }
        text += "      </attachments>\n    </cable_ideal>\n";
    }
    text + "  </cable_set>\n</cables>\n"
}

fn bodies_xml() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/every_joint_bodies.xml");
    std::fs::read_to_string(path).unwrap()
}

#[test]
fn every_link_frame_and_attachment_is_caspr_s_in_the_base_frame() {
    let folder = import_caspr(
        Source { name: "every_joint_bodies.xml", text: &bodies_xml() },
        Source { name: "all.xml", text: &cables_xml() },
        None,
        &ImportOptions::named("ej"),
    )
    .unwrap();
    assert_eq!(folder.cables, 6);
    let dir = tempfile::tempdir().unwrap();
    folder.write_into(dir.path()).unwrap();
    let robot = sinew_robot::load(dir.path()).unwrap();
    let routing = sinew_routing::load(dir.path(), &robot).unwrap();
    assert_eq!(routing.cable_limits(), &[[2.0, 90.0]; 6]);
    let view = routing.view();
    let mut data = RobotData::new(&robot);
    let (mut worst_frame, mut worst_point): (f64, f64) = (0.0, 0.0);
    for q in [
        [0.0; 9],
        [0.3, -0.4, 0.5, 0.2, -0.3, 0.6, -0.7, 0.8, -0.9],
        [-1.1, 0.9, -2.0, -0.45, 0.55, -0.65, 0.75, -0.85, 0.95],
    ] {
        robot.forward_kinematics(&mut data, &q).unwrap();
        let frames = caspr_frames(&q);
        // Every link frame: the URDF link of CASPR link k (base_link for 0).
        for (k, (rot, pos)) in frames.iter().enumerate() {
            let name = if k == 0 { "base_link" } else { NAMES[k - 1] };
            let placement = robot.link(name).unwrap();
            let pose = data.body_pose(placement.body).unwrap() * placement.body_m_link;
            let dr = (pose.rotation.matrix() - rot.matrix()).abs().max();
            let dp = (pose.translation.vector - pos).abs().max();
            assert!(
                dr <= 1e-14 && dp <= 1e-14,
                "{q:?} link {name}: rotation {dr:e}, origin {dp:e}"
            );
            worst_frame = worst_frame.max(dr).max(dp);
        }
        // Every attachment: r_A (joint) or r_G + r_A (com) in link k's frame.
        for k in 1..=6 {
            let cable = view.cables.iter().find(|c| c.name == format!("k{k}")).unwrap();
            let expected = cable_attachments(k);
            assert_eq!(cable.holes.len(), expected.len(), "k{k}");
            for (hole, (link, r)) in cable.holes.iter().zip(expected) {
                let mut r = Vector3::from(r);
                if k % 2 == 0 && link > 0 {
                    r += Vector3::from(LINKS[link - 1].2);
                }
                let (rot, pos) = frames[link];
                let point = robot.link_point(hole.link, Vector3::from(hole.point)).unwrap();
                let got = robot.point_position(&data, &point).unwrap();
                let d = (got - (pos + rot * r)).abs().max();
                assert!(d <= 1e-14, "{q:?} k{k} hole on link {link}: off by {d:e}");
                worst_point = worst_point.max(d);
            }
        }
    }
    println!("worst link frame difference {worst_frame:.1e}, attachment {worst_point:.1e} m");
}

#[test]
fn joint_types_the_importer_does_not_take_are_refused_by_name() {
    for kind in ["FIXED", "R_XY", "U_XX", "r_x", ""] {
        let text = bodies_xml().replacen("type=\"R_X\"", &format!("type=\"{kind}\""), 1);
        let e = import_caspr(
            Source { name: "b.xml", text: &text },
            Source { name: "all.xml", text: &cables_xml() },
            None,
            &ImportOptions::named("ej"),
        )
        .unwrap_err();
        match &e {
            ImportError::UnsupportedJoint { joint_type, link: 1, .. } if !kind.is_empty() => {
                assert_eq!(joint_type, kind);
                assert!(
                    e.to_string().contains(&format!("`{kind}`")) || e.to_string().contains(kind),
                    "{e}"
                );
            }
            ImportError::MissingAttribute { attribute: "type", .. } if kind.is_empty() => {}
            other => panic!("{kind}: {other:?}"),
        }
        assert_eq!(e.place().map(|p| p.line), Some(7), "{e}");
    }
}
