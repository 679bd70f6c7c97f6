//! The paper's experiments (spec §6) as data, checks and fixed-precision tables: what
//! `cargo xtask reproduce` writes and what the snapshot tests compare.
//!
//! Every number is printed at a fixed precision with `-0` normalised to `0` ([`fixed`]), so a
//! rendered table changes only when a number really changes.

mod arm;
mod claims;
mod single_joint;
mod table1;

pub use arm::{
    E4, E4_CASES, E4Case, E4Joint, claims_e4, claims_e4_end, claims_e4_joints, e4, render_e4,
    render_routed_vs_decoupled,
};
pub use claims::{Claim, claims_e1_e3, render_claims};
pub use single_joint::{
    E2_Q, E2_TORQUE, E2Point, E3_TORQUE, PAPER_TABLE_2, TABLE_2_TORQUE, Table2Row, e2, e2_csv, e3,
    e3_csv, e3_with_progress, render_table_2, rms_relative_error, table_2,
};
pub use table1::table_1;

use std::f64::consts::PI;

/// The E4 configuration (spec §6): `Q` of the 10-DOF arm, rad.
pub const E4_Q: [f64; 10] = [
    -PI / 7.0,
    -PI / 9.0,
    -PI / 9.0,
    -PI / 11.0,
    PI / 6.0,
    PI / 7.0,
    PI / 8.0,
    -PI / 15.0,
    -PI / 12.0,
    -PI / 10.0,
];

/// The E4 load: the wrench the end-effector exerts on its environment, base frame (spec §6).
pub const E4_F0: [f64; 6] = [0.0, 5.0, 0.0, 0.0, 0.0, 0.0];

/// `x` with `decimals` digits after the point, `-0.000` printed as `0.000`.
pub fn fixed(x: f64, decimals: usize) -> String {
    let s = format!("{x:.decimals$}");
    if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') {
        s[1..].to_owned()
    } else {
        s
    }
}
