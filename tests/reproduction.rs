//! The paper's tables as insta snapshots (numbers at fixed precision: a snapshot changes only
//! when a number really changes; review a change with `cargo insta review`), and a check that
//! the committed report in docs/reproduction/ is what `cargo xtask reproduce` writes today.
//! Everything comes from one [`paper::Report`], the one `cargo xtask reproduce` writes.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use sinew::paper;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The report, computed once for every test of this file.
fn report() -> &'static paper::Report {
    static REPORT: OnceLock<paper::Report> = OnceLock::new();
    REPORT.get_or_init(|| paper::Report::compute(&root().join(paper::ROBOT_DIR)).unwrap())
}

/// The committed file must equal what the report writes now.
fn assert_committed(name: &str, fresh: &str) {
    let path: PathBuf = root().join(paper::REPORT_DIR).join(name);
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == fresh,
        "{} is stale: run `cargo xtask reproduce` and commit docs/reproduction/",
        Path::new(paper::REPORT_DIR).join(name).display()
    );
}

#[test]
fn table_1() {
    let table = &report().table_1;
    insta::assert_snapshot!(table);
    assert_committed("table1.md", table);
    // Table I read directly equals the report's.
    assert_eq!(&paper::table_1(&root().join(paper::ROBOT_DIR)).unwrap(), table);
}

#[test]
fn table_2() {
    let rendered = paper::render_table_2(&report().table_2);
    insta::assert_snapshot!(rendered);
    assert_committed("table2.md", &rendered);
}

#[test]
fn fig_4_e2() {
    let csv = paper::e2_csv(&report().e2);
    insta::assert_snapshot!(csv);
    assert_committed("fig4_e2.csv", &csv);
}

#[test]
fn fig_5_e3() {
    let r = report();
    // The committed CSV is the full 121 × 121 grid; the snapshot a 13 × 13 one.
    assert_eq!(r.e3.grid.points, 121);
    assert_committed("fig5_e3.csv", &paper::e3_csv(&r.e3));
    insta::assert_snapshot!(paper::e3_csv(&paper::e3(&r.robot, &r.routing, 13).unwrap()));
}

#[test]
fn claims_e1_e3() {
    insta::assert_snapshot!(paper::render_claims(&report().claims_e1_e3));
}

#[test]
fn snapshots_are_identical_across_runs() {
    let r = report();
    let a = paper::e3_csv(&paper::e3(&r.robot, &r.routing, 31).unwrap());
    let b = paper::e3_csv(&paper::e3(&r.robot, &r.routing, 31).unwrap());
    assert_eq!(a, b, "the parallel sweep must be deterministic");
}

#[test]
fn fig_6_e4_decoupled_and_routed() {
    let r = report();
    assert_eq!(r.e4_stable.baseline, 0.25);
    let rendered_b = paper::render_e4(&r.e4_stable);
    insta::assert_snapshot!("e4_decoupled_baseline", rendered_b);
    assert_committed("e4_decoupled_baseline.md", &rendered_b);
    let rendered_d = paper::render_e4(&r.e4_decoupled);
    let rendered_r = paper::render_e4(&r.e4_routed);
    insta::assert_snapshot!("e4_decoupled", rendered_d);
    insta::assert_snapshot!("e4_routed", rendered_r);
    insta::assert_snapshot!(
        "e4_routed_vs_decoupled",
        paper::render_routed_vs_decoupled(&r.e4_decoupled, &r.e4_routed)
    );
    insta::assert_snapshot!("e4_claims", paper::render_claims(&r.claims_e4));
    assert_committed("e4_decoupled.md", &rendered_d);
    assert_committed("e4_routed.md", &rendered_r);
}

/// Every text file of the report (README.md included) is committed as written; the figures
/// are compared by `cargo xtask reproduce --check` (run by .ci/run).
#[test]
fn every_text_file_of_the_report_is_committed() {
    let files = report().text_files();
    assert!(files.iter().any(|(name, _)| *name == "README.md"));
    for (name, text) in &files {
        assert_committed(name, text);
    }
}
