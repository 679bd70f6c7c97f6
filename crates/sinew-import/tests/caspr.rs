//! Synthetic CASPR models (tests/data, written for these tests) imported and loaded back with
//! `sinew_robot::load` and `sinew_routing::load`: DOF, axes, masses, centres of mass, inertias
//! and forward kinematics against CASPR's own composition of its joint rotations.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use approx::assert_relative_eq;
use nalgebra::{Matrix3, Rotation3, Vector3};
use sinew_import::{ImportOptions, JointKind, RobotFolder, Source, import_caspr};
use sinew_robot::{Robot, RobotData};
use tempfile::TempDir;

fn data(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(file)
}

fn read(file: &str) -> String {
    std::fs::read_to_string(data(file)).unwrap()
}

fn import(bodies: &str, cables: &str, op: Option<&str>, options: &ImportOptions) -> RobotFolder {
    let (b, c) = (read(bodies), read(cables));
    let o = op.map(read);
    import_caspr(
        Source { name: bodies, text: &b },
        Source { name: cables, text: &c },
        o.as_deref().map(|text| Source { name: "op.xml", text }),
        options,
    )
    .unwrap()
}

fn write(folder: &RobotFolder) -> TempDir {
    let dir = tempfile::tempdir().unwrap();
    folder.write_into(dir.path()).unwrap();
    dir
}

/// CASPR's rotation of a joint (`RevoluteX.RelRotationMatrix`, `UniversalXY`: `R_01 · R_12`).
fn caspr_rotation(kind: JointKind, q: &[f64]) -> Rotation3<f64> {
    let r = |axis: sinew_import::Axis, angle: f64| {
        Rotation3::from_axis_angle(
            &nalgebra::Unit::new_normalize(Vector3::from(axis.unit())),
            angle,
        )
    };
    kind.axes().iter().zip(q).fold(Rotation3::identity(), |acc, (&a, &angle)| acc * r(a, angle))
}

/// The tip by CASPR's kinematics (`SystemModelBodies.update`): `R_0k = R_0p R_pe`, the joint
/// at the parent's joint plus `R_0p r_Parent`, the tip at the last joint plus `R_0k r_Pe`.
fn caspr_tip(links: &[(JointKind, [f64; 3])], end: [f64; 3], q: &[f64]) -> Vector3<f64> {
    let (mut rot, mut pos, mut i) = (Rotation3::identity(), Vector3::zeros(), 0);
    for &(kind, location) in links {
        pos += rot * Vector3::from(location);
        rot *= caspr_rotation(kind, &q[i..i + kind.dof()]);
        i += kind.dof();
    }
    pos + rot * Vector3::from(end)
}

fn tip_position(robot: &Robot, q: &[f64]) -> Vector3<f64> {
    let mut data = RobotData::new(robot);
    robot.forward_kinematics(&mut data, q).unwrap();
    robot.point_position(&data, &robot.tip_point()).unwrap()
}

#[test]
fn every_joint_type_loads_with_caspr_axes_limits_and_inertials() {
    let folder = import(
        "every_joint_bodies.xml",
        "every_joint_cables.xml",
        None,
        &ImportOptions::named("ej"),
    );
    assert_eq!((folder.links, folder.dof, folder.universal_joints, folder.cables), (6, 9, 3, 3));
    assert_eq!(folder.urdf_file, "ej.urdf");
    let dir = write(&folder);
    let robot = sinew_robot::load(dir.path()).unwrap();
    assert_eq!(robot.dof(), 9);
    assert_eq!(robot.gravity(), Vector3::new(0.0, 0.0, -9.81));

    let axes: Vec<[f64; 3]> =
        robot.joints().iter().map(|j| [j.axis.x, j.axis.y, j.axis.z]).collect();
    let (x, y, z) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
    assert_eq!(axes, vec![x, y, z, x, y, x, z, y, z]);
    let names: Vec<&str> = robot.joints().iter().map(|j| j.name.as_str()).collect();
    assert_eq!(
        names,
        ["rx_x", "ry_y", "rz_z", "uxy_x", "uxy_y", "uxz_x", "uxz_z", "uyz_y", "uyz_z"]
    );
    let limits: Vec<[f64; 2]> = robot.joints().iter().map(|j| [j.lower, j.upper]).collect();
    let pi = std::f64::consts::PI;
    assert_eq!(
        limits,
        vec![
            [-1.5, 1.5],
            [-1.2, 1.3],
            [-pi, pi], // R_Z states no limits
            [-0.5, 0.5],
            [-0.6, 0.6],
            [-0.7, 0.7],
            [-0.8, 0.8],
            [-0.9, 0.9],
            [-1.0, 1.0]
        ]
    );
    assert!(folder.warnings.iter().any(|w| w.contains("link(s) 3 state no q_min/q_max")));
    assert!(folder.urdf.contains("no q_min/q_max in the CASPR file: limits ±π"));
    // The second joint of a universal joint has zero translation; cross links are massless.
    for j in [4, 6, 8] {
        assert_eq!(robot.joints()[j].origin.translation.vector, Vector3::zeros());
        assert_eq!(robot.bodies()[j].mass, 0.0, "cross body of joint {j}");
    }
    assert_eq!(robot.joints()[3].origin.translation.vector, Vector3::new(0.0, 0.02, 0.09));

    // Masses and centres of mass, body by body (bodies 1.. are the joints' children).
    let body_of_link = [1, 2, 3, 5, 7, 9];
    let masses = [0.5, 0.4, 0.3, 0.25, 0.2, 0.15];
    let coms = [[0.01, 0.02, 0.05], [0.0, 0.01, 0.06], [0.02, 0.0, 0.04], [0.0, 0.0, 0.05]];
    for (k, &b) in body_of_link.iter().enumerate() {
        let body = &robot.bodies()[b];
        let expected_mass = masses[k];
        assert_relative_eq!(body.mass, expected_mass, epsilon = 1e-15);
        if k < coms.len() {
            assert_relative_eq!(body.com, Vector3::from(coms[k]), epsilon = 1e-15);
        }
    }
    // ref="com" as written; ref="joint" moved to the centre of mass (parallel axes).
    let i_rx = Matrix3::new(0.001, 0.0001, 0.0, 0.0001, 0.002, 0.0, 0.0, 0.0, 0.0005);
    assert_relative_eq!(robot.bodies()[1].inertia, i_rx, epsilon = 1e-15);
    let i_o = Matrix3::new(0.003, 0.0, 0.0002, 0.0, 0.004, 0.0, 0.0002, 0.0, 0.0006);
    let r = Vector3::new(0.0, 0.01, 0.06);
    let i_g = i_o - 0.4 * (Matrix3::identity() * r.dot(&r) - r * r.transpose());
    assert_relative_eq!(robot.bodies()[2].inertia, i_g, epsilon = 1e-15);
    // By hand: I_xx = 0.003 − 0.4 (0.01² + 0.06²), I_yz = 0 + 0.4 · 0.01 · 0.06.
    assert_relative_eq!(i_g[(0, 0)], 0.003 - 0.4 * 0.0037, epsilon = 1e-15);
    assert_relative_eq!(i_g[(1, 2)], 0.4 * 0.0006, epsilon = 1e-15);
}

#[test]
fn forward_kinematics_equals_caspr_composition_for_every_joint_type() {
    let folder = import(
        "every_joint_bodies.xml",
        "every_joint_cables.xml",
        None,
        &ImportOptions::named("ej"),
    );
    let dir = write(&folder);
    let robot = sinew_robot::load(dir.path()).unwrap();
    let links = [
        (JointKind::RX, [0.0, 0.0, 0.02]),
        (JointKind::RY, [0.0, 0.0, 0.1]),
        (JointKind::RZ, [0.01, 0.0, 0.12]),
        (JointKind::UXY, [0.0, 0.02, 0.09]),
        (JointKind::UXZ, [0.0, 0.0, 0.1]),
        (JointKind::UYZ, [0.0, 0.0, 0.1]),
    ];
    let end = [0.0, 0.01, 0.08];
    for q in [
        [0.0; 9],
        [0.3, -0.4, 0.5, 0.2, -0.3, 0.6, -0.7, 0.8, -0.9],
        [-1.1, 0.9, -2.0, -0.45, 0.55, -0.65, 0.75, -0.85, 0.95],
    ] {
        let expected = caspr_tip(&links, end, &q);
        assert_relative_eq!(tip_position(&robot, &q), expected, epsilon = 1e-14);
    }
}

#[test]
fn two_revolute_links_tip_by_hand() {
    // R_X at z = 0.1 then R_Y at z = 0.2 of link 1, tip 0.3 along z of link 2.
    let link = |num: usize, kind: &str, location: &str, end: &str| {
        format!(
            r#"<link_rigid num="{num}" name="l{num}"><joint type="{kind}" q_min="-3" q_max="3"/>
<physical><mass>1</mass><com_location>0 0 0.1</com_location><end_location>{end}</end_location>
<inertia ref="com"><Ixx>0.01</Ixx><Iyy>0.01</Iyy><Izz>0.001</Izz><Ixy>0</Ixy><Ixz>0</Ixz><Iyz>0</Iyz></inertia></physical>
<parent><num>{}</num><location>{location}</location></parent></link_rigid>"#,
            num - 1
        )
    };
    let bodies = format!(
        "<bodies_system><links>{}{}</links></bodies_system>",
        link(1, "R_X", "0 0 0.1", "0 0 0.2"),
        link(2, "R_Y", "0 0 0.2", "0 0 0.3")
    );
    let cables = r#"<cables default_cable_set="s"><cable_set id="s">
<cable_ideal name="c" attachment_reference="joint"><properties><force_min>1</force_min><force_max>10</force_max></properties>
<attachments><attachment><link>0</link><location>0.01 0 0</location></attachment>
<attachment><link>2</link><location>0.01 0 0.1</location></attachment></attachments></cable_ideal>
</cable_set></cables>"#;
    let folder = import_caspr(
        Source { name: "b", text: &bodies },
        Source { name: "c", text: cables },
        None,
        &ImportOptions::named("two"),
    )
    .unwrap();
    let dir = write(&folder);
    let robot = sinew_robot::load(dir.path()).unwrap();
    assert_eq!(robot.dof(), 2);
    let h = std::f64::consts::FRAC_PI_2;
    // Rot_y(90°) (0, 0, 0.3) = (0.3, 0, 0); plus (0, 0, 0.2): (0.3, 0, 0.2);
    // Rot_x(90°) of it = (0.3, −0.2, 0); plus (0, 0, 0.1).
    assert_relative_eq!(
        tip_position(&robot, &[h, h]),
        Vector3::new(0.3, -0.2, 0.1),
        epsilon = 1e-15
    );
    assert_relative_eq!(tip_position(&robot, &[0.0, 0.0]), Vector3::new(0.0, 0.0, 0.6));
    // Two 1-DOF joints with masses: Sinew reads them as two joints, no warning about it.
    assert_eq!(robot.joint_count(), 2);
    assert!(
        !folder.warnings.iter().any(|w| w.contains("universal joint")),
        "{:?}",
        folder.warnings
    );
}

#[test]
fn all_universal_arm_loads_robot_and_routing() {
    let folder =
        import("universal_bodies.xml", "universal_cables.xml", None, &ImportOptions::named("uu"));
    assert!(folder.warnings.is_empty(), "{:?}", folder.warnings);
    assert!(!folder.cables_toml.contains("joint ="), "no per-cable joint field");
    let dir = write(&folder);
    let robot = sinew_robot::load(dir.path()).unwrap();
    assert_eq!(robot.dof(), 4);
    let routing = sinew_routing::load(dir.path(), &robot).unwrap();
    assert_eq!(routing.tension_limits(), [5.0, 300.0]);
    let view = routing.view();
    assert_eq!(view.cables.len(), 6);
    let a1 = view.cables.iter().find(|c| c.name == "a1").unwrap();
    assert_eq!(a1.joint, 0);
    assert_eq!(a1.holes.len(), 2);
    assert_eq!(a1.free_length, sinew_import::DEFAULT_FREE_LENGTH);
    // b1: base, the pass-through pair on link 1 (both kept), the anchor on link 2; attachment
    // reference "com": each point is its link's com (link 1: z 0.05, link 2: z 0.04) plus the
    // location.
    let b1 = view.cables.iter().find(|c| c.name == "b1").unwrap();
    assert_eq!(b1.joint, 1);
    let links: Vec<&str> = b1.holes.iter().map(|h| h.link).collect();
    assert_eq!(links, ["base_link", "base_side", "base_side", "tip_side"]);
    assert_relative_eq!(b1.holes[1].point[2], 0.05 + 0.01, epsilon = 1e-15);
    assert_relative_eq!(b1.holes[2].point[2], 0.05 + 0.05, epsilon = 1e-15);
    assert_relative_eq!(b1.holes[3].point[2], 0.04 + 0.03, epsilon = 1e-15);
    assert_relative_eq!(b1.holes[0].point[2], 0.0, epsilon = 1e-15);
    // E A / l with the default material: 200 GPa, 1 mm.
    let area = std::f64::consts::PI * 0.25e-6;
    assert_relative_eq!(a1.stiffness, 200.0e9 * area / a1.elastic_length, max_relative = 1e-12);
}

#[test]
fn operational_space_gives_the_tip() {
    let folder = import(
        "universal_bodies.xml",
        "universal_cables.xml",
        Some("universal_operational_spaces.xml"),
        &ImportOptions::named("uu"),
    );
    let dir = write(&folder);
    let robot = sinew_robot::load(dir.path()).unwrap();
    assert_eq!(robot.tip().name, "tip");
    let links = [(JointKind::UXY, [0.0, 0.0, 0.03]), (JointKind::UXZ, [0.0, 0.0, 0.13])];
    let q = [0.2, -0.3, 0.4, 0.5];
    assert_relative_eq!(
        tip_position(&robot, &q),
        caspr_tip(&links, [0.01, 0.0, 0.12], &q),
        epsilon = 1e-14
    );
    assert!(folder.robot_toml.contains("operational space `tool` of set `tip_position`"));
    // Without the file: the last link's end location.
    let plain =
        import("universal_bodies.xml", "universal_cables.xml", None, &ImportOptions::named("uu"));
    let robot = sinew_robot::load(write(&plain).path()).unwrap();
    assert_relative_eq!(
        tip_position(&robot, &q),
        caspr_tip(&links, [0.0, 0.0, 0.09], &q),
        epsilon = 1e-14
    );
}

#[test]
fn cable_sets_by_id_and_by_default() {
    let options =
        ImportOptions { cable_set: Some("mixed_limits".to_owned()), ..ImportOptions::named("uu") };
    let mixed = import("universal_bodies.xml", "universal_cables.xml", None, &options);
    assert!(mixed.cables_toml.contains("cable set `mixed_limits`"));
    assert!(!mixed.cables_toml.contains("default_cable_set"));
    // Per-cable limits differ: each cable has its own, the top level is the widest.
    assert!(mixed.cables_toml.contains("tension_limits = [2.0, 450.0]\n"));
    for (i, name) in ["a1", "a2", "a3", "b1", "b2", "b3"].iter().enumerate() {
        let block = mixed
            .cables_toml
            .split("[[cable]]")
            .find(|b| b.contains(&format!("\"{name}\"")))
            .unwrap();
        let expected =
            format!("tension_limits = [{:?}, {:?}]", 2.0 + i as f64, 200.0 + 50.0 * i as f64);
        assert!(block.contains(&expected), "{name}: {block}");
    }
    assert!(mixed.warnings.iter().any(|w| w.contains("force limits differ")));

    let default =
        import("universal_bodies.xml", "universal_cables.xml", None, &ImportOptions::named("uu"));
    assert!(default.cables_toml.contains("cable set `basic` (the file's default_cable_set)"));
    assert_eq!(
        default.cables_toml.matches("tension_limits").count(),
        2,
        "top level only (and a comment)"
    );

    let springs =
        ImportOptions { cable_set: Some("springs".to_owned()), ..ImportOptions::named("uu") };
    let springs = import("universal_bodies.xml", "universal_cables.xml", None, &springs);
    assert!(springs.warnings.iter().any(|w| w.contains("stiffness K ignored")));
}

#[test]
fn options_set_material_free_length_and_limits() {
    let options = ImportOptions {
        youngs_modulus: 12.5e9,
        diameter: 0.5e-3,
        free_length: 2.0,
        tension_limits: Some([10.0, 80.0]),
        ..ImportOptions::named("uu")
    };
    let folder = import("universal_bodies.xml", "universal_cables.xml", None, &options);
    let dir = write(&folder);
    let robot = sinew_robot::load(dir.path()).unwrap();
    let routing = sinew_routing::load(dir.path(), &robot).unwrap();
    let view = routing.view();
    assert_eq!(view.tension_limits, [10.0, 80.0]);
    assert_eq!(view.youngs_modulus, 12.5e9);
    assert_relative_eq!(view.area, std::f64::consts::PI * 0.0625e-6, max_relative = 1e-15);
    assert!(view.cables.iter().all(|c| c.free_length == 2.0));
    assert!(folder.warnings.iter().any(|w| w.contains("replace the file's force_min/force_max")));
}

#[test]
fn placeholder_and_negative_limits_are_clamped_and_reported() {
    let text = read("universal_cables.xml")
        .replace("<force_min>5</force_min>", "<force_min>-1</force_min>")
        .replace("<force_max>300</force_max>", "<force_max>1e6</force_max>");
    let bodies = read("universal_bodies.xml");
    let folder = import_caspr(
        Source { name: "b", text: &bodies },
        Source { name: "c", text: &text },
        None,
        &ImportOptions::named("uu"),
    )
    .unwrap();
    assert!(folder.cables_toml.contains("tension_limits = [0.0, 1000000.0]"));
    assert!(folder.warnings.iter().any(|w| w.contains("force_min < 0 clamped to 0 N")));
    assert!(folder.warnings.iter().any(|w| w.contains("placeholder rather than a rating")));
    let dir = write(&folder);
    let robot = sinew_robot::load(dir.path()).unwrap();
    sinew_routing::load(dir.path(), &robot).unwrap();
}

#[test]
fn a_cable_listed_tip_first_is_written_base_first() {
    let base = "<link>0</link>\n          <location>0.019107 0.00591 0</location>";
    let link = "<link>1</link>\n          <location>0.019107 0.00591 0.1</location>";
    let text = read("universal_cables.xml")
        .replacen(base, "@", 1)
        .replacen(link, base, 1)
        .replacen("@", link, 1);
    let bodies = read("universal_bodies.xml");
    let folder = import_caspr(
        Source { name: "b", text: &bodies },
        Source { name: "c", text: &text },
        None,
        &ImportOptions::named("uu"),
    )
    .unwrap();
    assert!(folder.warnings.iter().any(|w| w.contains("a1: attachments listed from the tip")));
    let dir = write(&folder);
    let robot = sinew_robot::load(dir.path()).unwrap();
    let routing = sinew_routing::load(dir.path(), &robot).unwrap();
    let a1 = routing.view().cables.into_iter().find(|c| c.name == "a1").unwrap();
    let links: Vec<&str> = a1.holes.iter().map(|h| h.link).collect();
    assert_eq!(links, ["base_link", "base_side"]);
}

#[test]
fn names_with_quotes_backslashes_and_newlines_round_trip() {
    // In XML, `&quot;` is a quote and `&#10;` a newline an attribute keeps.
    let bodies =
        read("universal_bodies.xml").replace(r#"name="base_side""#, r#"name="a&quot;b\c""#);
    let set = r#"s&quot;\&#10;--x"#;
    let cables = read("universal_cables.xml")
        .replacen(r#"<cable_ideal name="a1""#, r#"<cable_ideal name="a&quot;b\c&#10;d""#, 1)
        .replace(r#"default_cable_set="basic""#, &format!(r#"default_cable_set="{set}""#))
        .replacen(r#"<cable_set id="basic">"#, &format!(r#"<cable_set id="{set}">"#), 1);
    let folder = import_caspr(
        Source { name: "b\"\\\n--.xml", text: &bodies },
        Source { name: "c\"\\\r\n.xml", text: &cables },
        None,
        &ImportOptions::named("r\"b\\c"),
    )
    .unwrap();
    // The robot's and the links' names are made URDF-safe (`sanitize`) and the renaming is
    // reported; a cable keeps its name as CASPR gives it.
    assert_eq!((folder.name.as_str(), folder.urdf_file.as_str()), ("r_b_c", "r_b_c.urdf"));
    assert!(
        folder.warnings.iter().any(|w| w.contains("`a\"b\\c` → `a_b_c`")),
        "{:?}",
        folder.warnings
    );
    let dir = write(&folder);
    let robot = sinew_robot::load(dir.path()).unwrap();
    assert_eq!(robot.joints()[0].name, "a_b_c_x");
    let routing = sinew_routing::load(dir.path(), &robot).unwrap();
    let name = "a\"b\\c\nd";
    let c = routing.cable_index(name).unwrap();
    assert_eq!(routing.cables()[c].name, name);
    let view = routing.view();
    let links: Vec<&str> = view.cables[c].holes.iter().map(|h| h.link).collect();
    assert_eq!(links, ["base_link", "a_b_c"]);
    // The file names and the set's id stay inside their one-line comments.
    assert!(folder.cables_toml.contains("cable set `s\"\\ - -x` (the file's default_cable_set)"));
    assert!(folder.robot_toml.starts_with(
        "# Imported from CASPR by `sinew import caspr` (sinew-import): bodies b\"\\ - -.xml.\n"
    ));
}
