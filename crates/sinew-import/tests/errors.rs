//! Bad CASPR files: each a typed error naming the element, at the line and column where that
//! element starts (counted by hand in the texts below).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use sinew_import::{ImportError, ImportOptions, Place, Source, import_caspr, read_caspr};

/// A one-link bodies file; `joint`, `mass` and `parent` are spliced into lines 3, 5 and 8.
fn bodies(joint: &str, mass: &str, parent: &str) -> String {
    format!(
        r#"<bodies_system>
  <links>
    <link_rigid num="1" name="arm"><joint type="{joint}" q_min="-1 -1" q_max="1 1"/>
      <physical>
        <mass>{mass}</mass><com_location>0 0 0.05</com_location><end_location>0 0 0.1</end_location>
        <inertia ref="com"><Ixx>1e-3</Ixx><Iyy>1e-3</Iyy><Izz>1e-4</Izz><Ixy>0</Ixy><Ixz>0</Ixz><Iyz>0</Iyz></inertia>
      </physical>
      <parent><num>{parent}</num><location>0 0 0</location></parent>
    </link_rigid>
  </links>
</bodies_system>
"#
    )
}

const CABLES: &str = r#"<cables default_cable_set="one">
  <cable_set id="one">
    <cable_ideal name="c" attachment_reference="joint">
      <properties><force_min>1</force_min><force_max>100</force_max></properties>
      <attachments>
        <attachment><link>0</link><location>0.01 0 0</location></attachment>
        <attachment><link>1</link><location>0.01 0 0.1</location></attachment>
      </attachments>
    </cable_ideal>
  </cable_set>
  <cable_set id="two">
    <cable_ideal name="c" attachment_reference="joint">
      <properties><force_min>1</force_min><force_max>100</force_max></properties>
      <attachments><attachment><link>0</link><location>0 0 0</location></attachment></attachments>
    </cable_ideal>
  </cable_set>
</cables>
"#;

fn run(bodies: &str, cables: &str, set: Option<&str>) -> ImportError {
    let options = ImportOptions { cable_set: set.map(str::to_owned), ..ImportOptions::named("t") };
    import_caspr(
        Source { name: "b.xml", text: bodies },
        Source { name: "c.xml", text: cables },
        None,
        &options,
    )
    .unwrap_err()
}

fn at(e: &ImportError) -> (&str, u32, u32) {
    let Place { file, line, column } = e.place().unwrap_or_else(|| panic!("no place: {e}"));
    (file.as_str(), *line, *column)
}

#[test]
fn the_good_file_imports() {
    import_caspr(
        Source { name: "b.xml", text: &bodies("U_XY", "0.2", "0") },
        Source { name: "c.xml", text: CABLES },
        None,
        &ImportOptions::named("t"),
    )
    .unwrap();
}

#[test]
fn spherical_and_unknown_joint_types_name_the_link() {
    for kind in ["S_EULER_XYZ", "S", "Q_X"] {
        let e = run(&bodies(kind, "0.2", "0"), CABLES, None);
        match &e {
            ImportError::UnsupportedJoint { link, name, joint_type, .. } => {
                assert_eq!((*link, name.as_str(), joint_type.as_str()), (1, "arm", kind));
            }
            other => panic!("{other:?}"),
        }
        // `<joint` on line 3, after `    <link_rigid num="1" name="arm">` (35 characters).
        assert_eq!(at(&e), ("b.xml", 3, 36));
        let message = e.to_string();
        assert!(message.starts_with("b.xml:3:36: link 1 `arm`: joint type"), "{message}");
    }
}

#[test]
fn a_missing_parent_and_a_tree_are_errors() {
    let e = run(&bodies("U_XY", "0.2", "4"), CABLES, None);
    assert!(matches!(&e, ImportError::MissingParent { link: 1, parent: 4, links: 1, .. }), "{e:?}");
    assert_eq!(at(&e), ("b.xml", 8, 7));
    // Its own number (the last link's) is a link that exists, but not the previous one.
    let e = run(&bodies("U_XY", "0.2", "1"), CABLES, None);
    assert!(matches!(&e, ImportError::NotSerial { link: 1, parent: 1, expected: 0, .. }), "{e:?}");

    // Link 2 hangs from the base: not the previous link.
    let two = bodies("U_XY", "0.2", "0").replace(
        "  </links>",
        r#"    <link_rigid num="2" name="side"><joint type="R_X"/>
      <physical><mass>0.1</mass><com_location>0 0 0</com_location><end_location>0 0 0</end_location>
        <inertia ref="joint"><Ixx>0</Ixx><Iyy>0</Iyy><Izz>0</Izz><Ixy>0</Ixy><Ixz>0</Ixz><Iyz>0</Iyz></inertia></physical>
      <parent><num>0</num><location>0 0 0</location></parent>
    </link_rigid>
  </links>"#,
    );
    let e = run(&two, CABLES, None);
    match &e {
        ImportError::NotSerial { link, name, parent, expected, .. } => {
            assert_eq!((*link, name.as_str(), *parent, *expected), (2, "side", 0, 1));
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(at(&e), ("b.xml", 13, 7));
}

#[test]
fn nan_and_malformed_numbers_name_the_element() {
    let e = run(&bodies("U_XY", "NaN", "0"), CABLES, None);
    match &e {
        ImportError::InvalidNumber { field, text, .. } => {
            assert_eq!((field.as_str(), text.as_str()), ("<mass>", "NaN"));
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(at(&e), ("b.xml", 5, 9));

    let e = run(&bodies("U_XY", "0.2 0.3", "0"), CABLES, None);
    assert!(matches!(&e, ImportError::InvalidNumber { .. }), "{e:?}");
    assert_eq!(at(&e), ("b.xml", 5, 9));

    // Two limits per coordinate pair for a 1-DOF joint: q_min of the <joint>.
    let e = run(&bodies("R_Y", "0.2", "0"), CABLES, None);
    match &e {
        ImportError::InvalidNumber { field, text, .. } => {
            assert_eq!((field.as_str(), text.as_str()), ("q_min", "-1 -1"));
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(at(&e), ("b.xml", 3, 36));
}

#[test]
fn missing_elements_and_attributes_name_the_parent() {
    let no_inertia = bodies("U_XY", "0.2", "0").replace(
        r#"<inertia ref="com"><Ixx>1e-3</Ixx><Iyy>1e-3</Iyy><Izz>1e-4</Izz><Ixy>0</Ixy><Ixz>0</Ixz><Iyz>0</Iyz></inertia>"#,
        "",
    );
    let e = run(&no_inertia, CABLES, None);
    match &e {
        ImportError::MissingElement { parent, element, .. } => {
            assert_eq!((parent.as_str(), *element), ("<physical>", "inertia"));
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(at(&e), ("b.xml", 4, 7));

    let no_ref = bodies("U_XY", "0.2", "0").replace(r#"<inertia ref="com">"#, "<inertia>");
    let e = run(&no_ref, CABLES, None);
    assert!(matches!(&e, ImportError::MissingAttribute { attribute: "ref", .. }), "{e:?}");
    assert_eq!(at(&e), ("b.xml", 6, 9));

    let bad_ref = bodies("U_XY", "0.2", "0").replace(r#"ref="com""#, r#"ref="world""#);
    let e = run(&bad_ref, CABLES, None);
    assert!(matches!(&e, ImportError::InvalidAttribute { attribute: "ref", .. }), "{e:?}");

    let e = run("<robot/>", CABLES, None);
    assert!(matches!(&e, ImportError::UnexpectedRoot { expected: "bodies_system", .. }), "{e:?}");
    assert_eq!(at(&e), ("b.xml", 1, 1));

    let e = run("<bodies_system><links>", CABLES, None);
    assert!(matches!(&e, ImportError::Xml { .. }), "{e:?}");
    assert_eq!(at(&e).0, "b.xml");
}

#[test]
fn unknown_cable_set_lists_the_known_ids() {
    let e = run(&bodies("U_XY", "0.2", "0"), CABLES, Some("three"));
    match &e {
        ImportError::UnknownCableSet { id, known, .. } => {
            assert_eq!(id, "three");
            assert_eq!(known, &["one", "two"]);
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(at(&e), ("c.xml", 1, 1));
    assert!(e.to_string().contains("the file has `one`, `two`"), "{e}");

    let no_default = CABLES.replace(r#" default_cable_set="one""#, "");
    let e = run(&bodies("U_XY", "0.2", "0"), &no_default, None);
    assert!(matches!(&e, ImportError::MissingAttribute { attribute: "default_cable_set", .. }));
}

#[test]
fn bad_cables_name_the_cable() {
    // Set `two`: one attachment.
    let e = run(&bodies("U_XY", "0.2", "0"), CABLES, Some("two"));
    match &e {
        ImportError::TooFewAttachments { cable, count, .. } => {
            assert_eq!((cable.as_str(), *count), ("c", 1));
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(at(&e), ("c.xml", 14, 7));

    let far = CABLES.replace("<link>1</link>", "<link>5</link>");
    let e = run(&bodies("U_XY", "0.2", "0"), &far, None);
    assert!(matches!(&e, ImportError::UnknownAttachmentLink { link: 5, links: 1, .. }), "{e:?}");
    assert_eq!(at(&e), ("c.xml", 7, 21));

    let pulley = CABLES.replacen("<attachment>", "<base_rotating_pulley>", 1).replacen(
        "</attachment>",
        "</base_rotating_pulley>",
        1,
    );
    let e = run(&bodies("U_XY", "0.2", "0"), &pulley, None);
    assert!(matches!(&e, ImportError::UnsupportedAttachment { .. }), "{e:?}");
    assert_eq!(at(&e), ("c.xml", 6, 9));

    let vsd = CABLES.replacen("cable_ideal", "cable_vsd_torsion_spring", 2);
    let e = run(&bodies("U_XY", "0.2", "0"), &vsd, None);
    assert!(matches!(&e, ImportError::UnsupportedCable { .. }), "{e:?}");
    assert_eq!(at(&e), ("c.xml", 3, 5));

    let inverted = CABLES.replacen("<force_min>1</force_min>", "<force_min>200</force_min>", 1);
    let e = run(&bodies("U_XY", "0.2", "0"), &inverted, None);
    assert!(
        matches!(&e, ImportError::InvalidTensionLimits { f_min: 200.0, f_max: 100.0, .. }),
        "{e:?}"
    );
    assert_eq!(at(&e), ("c.xml", 4, 7));

    let reference =
        CABLES.replacen(r#"attachment_reference="joint""#, r#"attachment_reference="tip""#, 1);
    let e = run(&bodies("U_XY", "0.2", "0"), &reference, None);
    assert!(matches!(&e, ImportError::InvalidAttribute { attribute: "attachment_reference", .. }));
}

#[test]
fn bad_options_are_typed() {
    let options = ImportOptions { diameter: -1.0, ..ImportOptions::named("t") };
    let e = import_caspr(
        Source { name: "b.xml", text: &bodies("U_XY", "0.2", "0") },
        Source { name: "c.xml", text: CABLES },
        None,
        &options,
    )
    .unwrap_err();
    assert!(matches!(e, ImportError::InvalidOption { option: "diameter", .. }), "{e:?}");
    assert!(e.place().is_none());
}

#[test]
fn operational_point_off_the_last_link_is_an_error() {
    let op = r#"<operational_spaces default_operational_set="p">
  <operational_set id="p">
    <position marker_id="1" name="p"><link>0</link><offset>0 0 0</offset></position>
  </operational_set>
</operational_spaces>"#;
    let e = import_caspr(
        Source { name: "b.xml", text: &bodies("U_XY", "0.2", "0") },
        Source { name: "c.xml", text: CABLES },
        Some(Source { name: "o.xml", text: op }),
        &ImportOptions::named("t"),
    )
    .unwrap_err();
    assert!(matches!(e, ImportError::TipNotOnLastLink { link: 0, last: 1, .. }), "{e:?}");
    assert_eq!(at(&e), ("o.xml", 3, 38));

    let unknown = op.replace(r#"default_operational_set="p""#, r#"default_operational_set="q""#);
    let e = import_caspr(
        Source { name: "b.xml", text: &bodies("U_XY", "0.2", "0") },
        Source { name: "c.xml", text: CABLES },
        Some(Source { name: "o.xml", text: &unknown }),
        &ImportOptions::named("t"),
    )
    .unwrap_err();
    assert!(matches!(e, ImportError::UnknownOperationalSet { .. }), "{e:?}");
}

/// `e`'s message starts with `file:line:column:` and names `element`.
fn assert_names(e: &ImportError, place: (&str, u32, u32), element: &str) {
    assert_eq!(at(e), place, "{e}");
    let message = e.to_string();
    let (file, line, column) = place;
    assert!(message.starts_with(&format!("{file}:{line}:{column}: ")), "{message}");
    assert!(message.contains(element), "{message} does not name {element}");
    assert!(!message.contains('\n'), "{message}");
}

#[test]
fn an_empty_links_element_is_refused_at_links() {
    let e = run("<bodies_system>\n  <links>\n  </links>\n</bodies_system>\n", CABLES, None);
    assert!(matches!(e, ImportError::NoLinks { .. }), "{e:?}");
    assert_names(&e, ("b.xml", 2, 3), "<links>");
}

#[test]
fn a_link_of_another_kind_is_refused_naming_it() {
    let soft = bodies("U_XY", "0.2", "0").replace("link_rigid", "link_soft");
    let e = run(&soft, CABLES, None);
    match &e {
        ImportError::UnexpectedElement { element, parent, .. } => {
            assert_eq!(
                (element.as_str(), parent.as_str()),
                (r#"<link_soft num="1" name="arm">"#, "<links>")
            );
        }
        other => panic!("{other:?}"),
    }
    assert_names(&e, ("b.xml", 3, 5), "<link_soft num=\"1\" name=\"arm\">");
}

#[test]
fn links_numbered_out_of_file_order_are_refused() {
    for num in ["2", "0", "one"] {
        let wrong = bodies("U_XY", "0.2", "0").replace(r#"num="1""#, &format!(r#"num="{num}""#));
        let e = run(&wrong, CABLES, None);
        assert!(matches!(e, ImportError::LinkOrder { expected: 1, .. }), "{num}: {e:?}");
        assert_names(&e, ("b.xml", 3, 5), &format!(r#"<link_rigid num="{num}" name="arm">"#));
        assert!(e.to_string().contains("num should be 1"), "{e}");
    }
}

#[test]
fn joint_limits_the_wrong_way_round_name_the_coordinate() {
    let inverted = bodies("U_XY", "0.2", "0").replace(r#"q_max="1 1""#, r#"q_max="1 -2""#);
    let e = run(&inverted, CABLES, None);
    match &e {
        ImportError::InvalidJointLimits { link, name, coordinate, lower, upper, .. } => {
            assert_eq!((*link, name.as_str(), *coordinate), (1, "arm", 2));
            assert_eq!((*lower, *upper), (-1.0, -2.0));
        }
        other => panic!("{other:?}"),
    }
    assert_names(&e, ("b.xml", 3, 36), "`arm`");
}

#[test]
fn an_empty_cable_set_is_refused_naming_its_id() {
    let empty = CABLES.replace("</cables>", "  <cable_set id=\"empty\"></cable_set>\n</cables>");
    let e = run(&bodies("U_XY", "0.2", "0"), &empty, Some("empty"));
    match &e {
        ImportError::EmptyCableSet { id, .. } => assert_eq!(id, "empty"),
        other => panic!("{other:?}"),
    }
    assert_names(&e, ("c.xml", 17, 3), "`empty`");
}

#[test]
fn two_cables_of_one_name_are_refused_at_the_second() {
    // The cable of set `one` (lines 3–9) twice: the copy starts on line 10.
    let lines: Vec<&str> = CABLES.lines().collect();
    let cable = lines[2..9].join("\n");
    let twice = CABLES.replacen("  </cable_set>", &format!("{cable}\n  </cable_set>"), 1);
    let e = run(&bodies("U_XY", "0.2", "0"), &twice, None);
    match &e {
        ImportError::DuplicateCable { cable, .. } => assert_eq!(cable, "c"),
        other => panic!("{other:?}"),
    }
    assert_names(&e, ("c.xml", 10, 5), "`c`");
}

#[test]
fn an_operational_set_without_a_point_is_refused() {
    let op = "<operational_spaces default_operational_set=\"p\">\n  <operational_set id=\"p\">\n    <orientation_euler_xyz name=\"o\"/>\n  </operational_set>\n</operational_spaces>";
    let e = import_caspr(
        Source { name: "b.xml", text: &bodies("U_XY", "0.2", "0") },
        Source { name: "c.xml", text: CABLES },
        Some(Source { name: "o.xml", text: op }),
        &ImportOptions::named("t"),
    )
    .unwrap_err();
    match &e {
        ImportError::NoOperationalPoint { id, .. } => assert_eq!(id, "p"),
        other => panic!("{other:?}"),
    }
    assert_names(&e, ("o.xml", 2, 3), "`p`");
}

#[test]
fn a_file_that_cannot_be_read_or_written_is_named() {
    let dir = std::env::temp_dir().join(format!("sinew-import-io-{}", std::process::id()));
    let missing = dir.join("missing-bodies.xml");
    let e = sinew_import::import_caspr_files(&missing, &missing, None, &ImportOptions::named("t"))
        .unwrap_err();
    match &e {
        ImportError::Io { path, .. } => assert_eq!(path, &missing),
        other => panic!("{other:?}"),
    }
    assert!(e.to_string().contains("missing-bodies.xml"), "{e}");
    assert!(e.place().is_none());
    // Writing into a folder that does not exist names the first file.
    let folder = import_caspr(
        Source { name: "b.xml", text: &bodies("U_XY", "0.2", "0") },
        Source { name: "c.xml", text: CABLES },
        None,
        &ImportOptions::named("t"),
    )
    .unwrap();
    let e = folder.write_into(&dir.join("not-there")).unwrap_err();
    let ImportError::Io { path, .. } = &e else { panic!("{e:?}") };
    assert!(path.starts_with(dir.join("not-there")), "{e}");
}

fn read(bodies: &str) -> Result<sinew_import::CasprModel, ImportError> {
    read_caspr(
        Source { name: "b.xml", text: bodies },
        Source { name: "c.xml", text: CABLES },
        None,
        None,
    )
}

#[test]
fn limits_say_how_many_numbers_a_joint_of_one_or_two_coordinates_takes() {
    // R_Y with "-1 -1": one number expected; U_XY with "-1": two.
    let e = read(&bodies("R_Y", "0.2", "0")).unwrap_err();
    assert!(
        matches!(&e, ImportError::InvalidNumber { expected: "one finite number (rad)", .. }),
        "{e:?}"
    );
    let one = bodies("U_XY", "0.2", "0").replace(r#"q_min="-1 -1""#, r#"q_min="-1""#);
    let e = read(&one).unwrap_err();
    match &e {
        ImportError::InvalidNumber { field, text, expected, .. } => {
            assert_eq!((field.as_str(), text.as_str()), ("q_min", "-1"));
            assert_eq!(*expected, "two finite numbers (rad)");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn blank_limits_are_absent_and_equal_limits_are_a_locked_joint() {
    // A blank q_min / q_max is no limit: ±π, and the limits are marked as not stated.
    let blank = bodies("U_XY", "0.2", "0")
        .replace(r#"q_min="-1 -1""#, r#"q_min="  ""#)
        .replace(r#"q_max="1 1""#, r#"q_max="""#);
    let link = &read(&blank).unwrap().links[0];
    let pi = std::f64::consts::PI;
    assert_eq!((link.q_min.as_slice(), link.q_max.as_slice()), (&[-pi, -pi][..], &[pi, pi][..]));
    assert!(!link.limits_stated);
    // Stated limits are kept as written; lower = upper (a locked coordinate) is not inverted.
    let locked = bodies("U_XY", "0.2", "0").replace(r#"q_max="1 1""#, r#"q_max="1 -1""#);
    let link = &read(&locked).unwrap().links[0];
    assert_eq!(
        (link.q_min.as_slice(), link.q_max.as_slice()),
        (&[-1.0, -1.0][..], &[1.0, -1.0][..])
    );
    assert!(link.limits_stated);
}

#[test]
fn a_negative_mass_is_refused_and_a_massless_link_is_not() {
    let e = read(&bodies("U_XY", "-0.1", "0")).unwrap_err();
    match &e {
        ImportError::InvalidNumber { field, text, expected, .. } => {
            assert_eq!(
                (field.as_str(), text.as_str(), *expected),
                ("<mass>", "-0.1", "a mass ≥ 0 kg")
            );
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(at(&e), ("b.xml", 5, 9));
    assert_eq!(read(&bodies("U_XY", "0", "0")).unwrap().links[0].mass, 0.0);
}
