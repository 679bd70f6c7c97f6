//! The paper's tables as insta snapshots (numbers at fixed precision: a snapshot changes only
//! when a number really changes; review a change with `cargo insta review`), and a check that
//! the committed report in docs/reproduction/ is what `cargo xtask reproduce` writes today.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

use sinew::paper;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn cdhrm5() -> (sinew::robot::Robot, sinew::routing::Routing) {
    let dir = root().join("robots/cdhrm5");
    let robot = sinew::robot::load(&dir).unwrap();
    let routing = sinew::routing::load(&dir, &robot).unwrap();
    (robot, routing)
}

/// The committed file must equal what the report writes now.
fn assert_committed(name: &str, fresh: &str) {
    let path: PathBuf = root().join("docs/reproduction").join(name);
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == fresh,
        "{} is stale: run `cargo xtask reproduce` and commit docs/reproduction/",
        Path::new("docs/reproduction").join(name).display()
    );
}

#[test]
fn table_1() {
    let table = paper::table_1(&root().join("robots/cdhrm5")).unwrap();
    insta::assert_snapshot!(table);
    assert_committed("table1.md", &table);
}

#[test]
fn table_2() {
    let (robot, routing) = cdhrm5();
    let rendered = paper::render_table_2(&paper::table_2(&robot, &routing).unwrap());
    insta::assert_snapshot!(rendered);
    assert_committed("table2.md", &rendered);
}

#[test]
fn fig_4_e2() {
    let (robot, routing) = cdhrm5();
    let csv = paper::e2_csv(&paper::e2(&robot, &routing, 41).unwrap());
    insta::assert_snapshot!(csv);
    assert_committed("fig4_e2.csv", &csv);
}

#[test]
fn fig_5_e3() {
    let (robot, routing) = cdhrm5();
    // The committed CSV is the full 121 × 121 grid; the snapshot a 13 × 13 one.
    assert_committed("fig5_e3.csv", &paper::e3_csv(&paper::e3(&robot, &routing, 121).unwrap()));
    insta::assert_snapshot!(paper::e3_csv(&paper::e3(&robot, &routing, 13).unwrap()));
}

#[test]
fn claims_e1_e3() {
    let (robot, routing) = cdhrm5();
    let claims = paper::claims_e1_e3(
        &paper::table_2(&robot, &routing).unwrap(),
        &paper::e2(&robot, &routing, 41).unwrap(),
        &paper::e3(&robot, &routing, 121).unwrap(),
    );
    insta::assert_snapshot!(paper::render_claims(&claims));
}

#[test]
fn snapshots_are_identical_across_runs() {
    let (robot, routing) = cdhrm5();
    let a = paper::e3_csv(&paper::e3(&robot, &routing, 31).unwrap());
    let b = paper::e3_csv(&paper::e3(&robot, &routing, 31).unwrap());
    assert_eq!(a, b, "the parallel sweep must be deterministic");
}

#[test]
fn fig_6_e4_decoupled_and_routed() {
    let (robot, routing) = cdhrm5();
    let routed = sinew::routing::load(
        root().join("robots/cdhrm5").join(sinew::routing::ROUTED_ROUTING_FILE),
        &robot,
    )
    .unwrap();
    let decoupled = paper::e4(&robot, &routing, "decoupled", 0.0).unwrap();
    let routed = paper::e4(&robot, &routed, "routed", 0.0).unwrap();
    let baseline = paper::e4(&robot, &routing, "decoupled", 0.25).unwrap();
    let rendered_b = paper::render_e4(&baseline);
    insta::assert_snapshot!("e4_decoupled_baseline", rendered_b);
    assert_committed("e4_decoupled_baseline.md", &rendered_b);
    let rendered_d = paper::render_e4(&decoupled);
    let rendered_r = paper::render_e4(&routed);
    insta::assert_snapshot!("e4_decoupled", rendered_d);
    insta::assert_snapshot!("e4_routed", rendered_r);
    insta::assert_snapshot!(
        "e4_routed_vs_decoupled",
        paper::render_routed_vs_decoupled(&decoupled, &routed)
    );
    let claims: Vec<_> = [&decoupled, &routed]
        .into_iter()
        .flat_map(paper::claims_e4_joints)
        .chain([&decoupled, &routed, &baseline].into_iter().flat_map(paper::claims_e4_end))
        .collect();
    insta::assert_snapshot!("e4_claims", paper::render_claims(&claims));
    assert_committed("e4_decoupled.md", &rendered_d);
    assert_committed("e4_routed.md", &rendered_r);
}
