//! The paper's experiments (spec §6) as data, checks and fixed-precision tables: what
//! `cargo xtask reproduce` writes and what the snapshot tests compare.
//!
//! [`Report::compute`] runs every experiment once, with every parameter a named constant
//! (`experiments.rs`); `cargo xtask reproduce` writes [`Report::text_files`] and draws
//! the figures from the same [`Report`], `cargo xtask calibrate` and the tests use [`table_2`]
//! and the one check of Table II's patterns, [`table_2_patterns`].
//!
//! Every number is printed at a fixed precision with `-0` normalised to `0` ([`fixed`]), so a
//! rendered table changes only when a number really changes.

mod arm;
mod claim;
mod claims;
mod e6;
mod e7;
mod experiments;
mod patterns;
mod planning;
mod report;
mod single_joint;
mod table1;
mod tension;

pub use arm::{
    E4, E4Case, E4Joint, claims_e4, claims_e4_end, claims_e4_joints, e4, render_e4,
    render_routed_vs_decoupled,
};
pub use claim::Claim;
pub use claims::{claims_e1_e3, render_claims};
pub use e6::{
    E6, E6_FILE, E6_REGIMES, E6Row, FIG_E6_FILE, e6, e6_section, regime_label, render_e6,
};
pub use e7::{E7, E7Case, E7Cell, E7Map, e7, render_e7};
pub use experiments::{
    E2_Q, E2_SAMPLES, E2_TORQUE, E3_POINTS, E3_RANGE, E3_TORQUE, E4_CASES, E4_F0,
    E4_PAPER_BASELINE, E4_Q, E4_STABLE_BASELINE, E5_MARGIN, E5_TRADEOFF_POINTS, E6_LEVEL, E6_MU,
    E7_MIN_GAP, E7_OFF_CENTRE, E7_POINTS, E7_POSES, E7_RANGE_MM, PAPER_TABLE_2, SINGLE_JOINT,
    TABLE_2_TORQUE,
};
pub use patterns::{
    LEAST_RANGE_AWAY, MAX_RISE, MAX_RISE_OVER_MIN_MOVE, NEAR_ZERO_MAX, NEAR_ZERO_SHARE,
    WIDER_Q2_NEGATIVE, WIDER_Q2_POSITIVE, table_2_patterns,
};
pub use planning::{E5, E5Row, e5, e5_csv, render_e5};
pub use report::{
    E7_FILE, FIG_E5_FILE, FIG_E7_FILE, FIG4_FILE, FIG5_MAPS, FIG6_FILE, HeatMap, REPORT_DIR,
    ROBOT_DIR, Report,
};
pub use single_joint::{
    E2Point, Table2Row, e2, e2_csv, e3, e3_csv, e3_with_progress, render_table_2,
    rms_relative_error, table_2,
};
pub use table1::table_1;
pub use tension::{
    HoleGeometry, TensionEffect, classify_q0, criterion_q0, eigenvalues, joint_geometry,
    single_joint, tension_stiffness, zero_tolerance,
};

/// `x` with `decimals` digits after the point, `-0.000` printed as `0.000`.
pub fn fixed(x: f64, decimals: usize) -> String {
    let s = format!("{x:.decimals$}");
    if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') {
        s[1..].to_owned()
    } else {
        s
    }
}
