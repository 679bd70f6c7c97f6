//! Every parameter of the paper's experiments (spec §6), one named constant each: what the
//! report, `cargo xtask calibrate` and the tests compute. The thresholds of the Table II
//! pattern check are in `patterns.rs`, the report's files in `report.rs`.

use std::f64::consts::PI;

/// The joint the single-joint experiments E1–E3 probe: joint 1 (index 0, at the base).
pub const SINGLE_JOINT: usize = 0;
/// Torque held in E1 (Table II), N m.
pub const TABLE_2_TORQUE: [f64; 2] = [0.3, 0.3];
/// Torque held in E3 (Fig. 5), N m.
pub const E3_TORQUE: [f64; 2] = [0.3, 0.3];
/// E2's joint angles (Fig. 4), rad.
pub const E2_Q: [f64; 2] = [PI / 7.0, -PI / 9.0];
/// E2's torque (Fig. 4), N m.
pub const E2_TORQUE: [f64; 2] = [-1.0, 0.5];

/// Table II as printed: `(q, [K_x min, K_x max], [K_y min, K_y max])`, N m/rad.
pub const PAPER_TABLE_2: [([f64; 2], [f64; 2], [f64; 2]); 5] = [
    ([0.0, 0.0], [1.92, 1.98], [1.85, 1.90]),
    ([PI / 6.0, PI / 6.0], [2.96, 7.94], [2.51, 10.59]),
    ([PI / 6.0, -PI / 6.0], [2.53, 18.17], [1.44, 8.18]),
    ([-PI / 6.0, PI / 6.0], [2.32, 7.50], [2.17, 10.57]),
    ([-PI / 6.0, -PI / 6.0], [1.41, 17.05], [1.37, 8.11]),
];

/// Points along E2's feasible tension segment (Fig. 4).
pub const E2_SAMPLES: usize = 41;
/// The range of both joint angles in E3 (Fig. 5), rad: the joint limits.
pub const E3_RANGE: [f64; 2] = [-PI / 6.0, PI / 6.0];
/// Points per axis of E3's grid of joint angles (Fig. 5).
pub const E3_POINTS: usize = 121;
/// The paper's tension level of the joints an E4 case does not raise: their lowest.
pub const E4_PAPER_BASELINE: f64 = 0.0;
/// The tension level of the joints an E4 case does not raise in the extra decoupled run, where
/// the decoupled arm is stable (from about 0.1).
pub const E4_STABLE_BASELINE: f64 = 0.25;

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

/// The four cases of Fig. 6: (a) every joint at the baseline level (the lowest in the paper),
/// (b) joint 3 raised to its highest, (c) joint 5 raised, (d) joints 3 and 5 raised (joints
/// numbered from 1 at the base). `true` marks a raised joint.
pub const E4_CASES: [(&str, [bool; 5]); 4] = [
    ("(a) every joint at the baseline level", [false; 5]),
    ("(b) joint 3 at its highest level", [false, false, true, false, false]),
    ("(c) joint 5 at its highest level", [false, false, false, false, true]),
    ("(d) joints 3 and 5 at their highest levels", [false, false, true, false, true]),
];

/// E5's stability margin (beyond the paper): the planned tensions keep the smallest eigenvalue
/// of `K_q + K_W` at least this, N m/rad.
pub const E5_MARGIN: f64 = 0.05;

/// Points of E5's trade-off between the tension budget and the best `λ_min(K_fd)`.
pub const E5_TRADEOFF_POINTS: usize = 9;

/// E7 (beyond the paper, spec §10): the range of both `d1` and `d2` on the map, mm.
pub const E7_RANGE_MM: [f64; 2] = [-10.0, 40.0];
/// Points per axis of E7's map (0.5 mm apart, so `d1 = 0` and `d2 = 0` are on the grid).
pub const E7_POINTS: usize = 101;
/// Poses per axis over the joint limits `[−π/6, π/6]²` where E7 classifies `A_i` (odd, so Q0
/// is one of them).
pub const E7_POSES: usize = 5;
/// The smallest gap `d1 + d2` between the hole planes on E7's map, m: below it the cables
/// cross near the joint centre and the map leaves the cell out.
pub const E7_MIN_GAP: f64 = 0.005;
/// The off-centre geometry of one of CASPR's snake models (issue #27, spec §10): holes 6.6 mm
/// below and 13.6 mm above the joint centre, `[d1, d2]`, m.
pub const E7_OFF_CENTRE: [f64; 2] = [0.0066, 0.0136];

/// E6's friction coefficients at every hole: 0 (the paper's model), then 0.05 (a steel or
/// polymer cable through PTFE-lined holes: PTFE's sliding friction on steel is among the lowest
/// of engineering materials, about 0.05–0.1 in handbook tables), 0.1 and 0.2 (a steel cable on
/// bare aluminium discs, lubricated; dry metal pairs run higher).
pub const E6_MU: [f64; 4] = [0.0, 0.05, 0.1, 0.2];
/// E6's tension level for equal tensions along each cable (every joint).
pub const E6_LEVEL: f64 = 0.5;
