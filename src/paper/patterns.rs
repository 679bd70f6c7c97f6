//! The qualitative patterns of Table II (E1, spec §6), checked once, with one set of
//! thresholds: for the report's claims, `cargo xtask calibrate` and the calibration tests.
//!
//! Every threshold also holds for the paper's own numbers (in brackets below), so a pattern
//! that fails says our model departs from the paper, not that the threshold is too tight.

use std::fmt::Write as _;

use super::claim::Claim;
use super::fixed;
use super::single_joint::Table2Row;

/// At `q = [0, 0]` each range `Δk` is at most this share of the smallest range at the other
/// angles [paper: 0.06 / 4.98 = 1.2 %].
pub const NEAR_ZERO_SHARE: f64 = 0.05;
/// At `q = [0, 0]` each range `Δk` is below this, N m/rad [paper: 0.06].
pub const NEAR_ZERO_MAX: f64 = 0.1;
/// At the other four angles every range exceeds this, N m/rad [paper: ≥ 4.98].
pub const LEAST_RANGE_AWAY: f64 = 4.0;
/// `q2 < 0`: `Δk_x` exceeds `Δk_y` by this factor [paper: 15.64 / 6.74 = 2.3].
pub const WIDER_Q2_NEGATIVE: f64 = 2.0;
/// `q2 > 0`: `Δk_y` exceeds `Δk_x` by this factor [paper: 8.08 / 4.98 = 1.6].
pub const WIDER_Q2_POSITIVE: f64 = 1.5;
/// Away from `q = 0` the maximum of each axis rises by more than this many times the amount
/// the minimum moves [paper: ≥ 5.7].
pub const MAX_RISE_OVER_MIN_MOVE: f64 = 3.0;
/// … and by more than this, N m/rad [paper: ≥ 5.5].
pub const MAX_RISE: f64 = 3.0;

/// The four patterns of Table II in `rows` (any order; the row at `q = [0, 0]` is the
/// reference): a near-zero range at `q = 0`, `K_x` wider when `q2 < 0`, `K_y` wider when
/// `q2 > 0`, and larger `|q|` raising mainly the maximum. Each is a [`Claim`] with its numbers.
pub fn table_2_patterns(rows: &[Table2Row]) -> Vec<Claim> {
    let is_zero = |r: &&Table2Row| r.q == [0.0, 0.0];
    let zero = rows.iter().find(is_zero);
    let others: Vec<&Table2Row> = rows.iter().filter(|r| !is_zero(r)).collect();
    let mut claims = Vec::new();

    let c = format!(
        "E1: at q = [0, 0] the stiffness range is near zero (paper: Δk_x = 0.06, Δk_y = 0.05 N m/rad; checked: below {NEAR_ZERO_MAX} N m/rad and {} % of the smallest range at the other angles, which exceeds {LEAST_RANGE_AWAY} N m/rad)",
        100.0 * NEAR_ZERO_SHARE
    );
    match zero {
        Some(zero) if !others.is_empty() => {
            let d = zero.ours_delta();
            let least = others.iter().flat_map(|r| r.ours_delta()).fold(f64::INFINITY, f64::min);
            let holds = least > LEAST_RANGE_AWAY
                && d.iter().all(|&d| d <= NEAR_ZERO_SHARE * least && d < NEAR_ZERO_MAX);
            claims.push(Claim::checked(
                c,
                holds,
                format!(
                    "ours: Δk_x = {}, Δk_y = {} N m/rad; the smallest range at the other four angles is {} N m/rad",
                    fixed(d[0], 3),
                    fixed(d[1], 3),
                    fixed(least, 3)
                ),
            ));
        }
        _ => claims.push(Claim::unchecked(c, "Table II has no row at q = [0, 0] and others")),
    }

    // q2 < 0 → K_x wider; q2 > 0 → K_y wider.
    for (sign, axis_name, wider, factor) in
        [(-1.0, "K_x", 0usize, WIDER_Q2_NEGATIVE), (1.0, "K_y", 1usize, WIDER_Q2_POSITIVE)]
    {
        let (this, other) = (["Δk_x", "Δk_y"][wider], ["Δk_x", "Δk_y"][1 - wider]);
        let c = format!(
            "E1/E3: when q2 {} 0, {axis_name} has the wider range (Table II; checked: {this} > {factor} {other})",
            if sign < 0.0 { "<" } else { ">" }
        );
        let side: Vec<&Table2Row> = rows.iter().filter(|r| r.q[1] * sign > 0.0).collect();
        let holds = !side.is_empty()
            && side.iter().all(|r| r.ours_delta()[wider] > factor * r.ours_delta()[1 - wider]);
        let mut evidence = String::from("ours (Δk_x, Δk_y):");
        for r in &side {
            let d = r.ours_delta();
            let _ = write!(
                evidence,
                " q = [{}, {}]: ({}, {});",
                fixed(r.q[0], 3),
                fixed(r.q[1], 3),
                fixed(d[0], 2),
                fixed(d[1], 2)
            );
        }
        claims.push(Claim::checked(c, holds, evidence));
    }

    let c = format!(
        "E1: larger |q| mainly raises the maximum stiffness (Table II; checked: at each other angle, on each axis, the maximum rises above q = [0, 0]'s by more than {MAX_RISE} N m/rad and by more than {MAX_RISE_OVER_MIN_MOVE} times the amount the minimum moves)"
    );
    match zero {
        Some(zero) if !others.is_empty() => {
            let mut holds = true;
            let mut evidence = String::from("ours (rise of the maximum, move of the minimum):");
            for r in &others {
                let mut parts = Vec::new();
                for axis in 0..2 {
                    let up = r.ours[axis][1] - zero.ours[axis][1];
                    let moved = (r.ours[axis][0] - zero.ours[axis][0]).abs();
                    holds &= up > MAX_RISE && up > MAX_RISE_OVER_MIN_MOVE * moved;
                    parts.push(format!(
                        "{} ({}, {})",
                        ["K_x", "K_y"][axis],
                        fixed(up, 2),
                        fixed(moved, 2)
                    ));
                }
                let _ = write!(
                    evidence,
                    " q = [{}, {}]: {};",
                    fixed(r.q[0], 3),
                    fixed(r.q[1], 3),
                    parts.join(", ")
                );
            }
            claims.push(Claim::checked(c, holds, evidence));
        }
        _ => claims.push(Claim::unchecked(c, "Table II has no row at q = [0, 0] and others")),
    }
    claims
}
