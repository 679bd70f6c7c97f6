//! The paper's claims about E1–E3 (spec §6), checked numerically.

use std::fmt::Write as _;

use crate::indicators::SweepMaps;

// `pub`: `super::claims::Claim` stays a path to it.
pub use super::claim::Claim;
use super::fixed;
use super::patterns::table_2_patterns;
use super::single_joint::{E2Point, Table2Row};

/// Render claims as a markdown list.
pub fn render_claims(claims: &[Claim]) -> String {
    let mut s = String::new();
    for c in claims {
        let _ = writeln!(s, "- **{}** — {}. {}", c.verdict(), c.claim, c.evidence);
    }
    s
}

/// Check the claims of E1 (Table II, through [`table_2_patterns`]), E2 (Fig. 4) and E3 (Fig. 5).
pub fn claims_e1_e3(table: &[Table2Row], e2: &[E2Point], e3: &SweepMaps) -> Vec<Claim> {
    // E1: the patterns of Table II, with the thresholds shared by calibration and tests.
    let mut claims = table_2_patterns(table);

    // E2: tensions and stiffness rise together, linearly. The tensions' linearity holds by
    // construction (f = f_p + λ n, λ affine in the level); the stiffness's is checked against
    // direct evaluations from the tensions in tests/reproduction.rs.
    if let (Some(first), Some(last)) = (e2.first(), e2.last()) {
        let rising = e2.windows(2).all(|w| {
            (0..3).all(|k| w[1].tensions[k] > w[0].tensions[k])
                && w[1].k_x > w[0].k_x
                && w[1].k_y > w[0].k_y
        });
        // Linear: the midpoint is the mean of the ends.
        let mid = &e2[e2.len() / 2];
        let linear = (0..3).all(|k| {
            let expected = first.tensions[k] + mid.level * (last.tensions[k] - first.tensions[k]);
            (mid.tensions[k] - expected).abs() <= 1e-9 * last.tensions[k].abs().max(1.0)
        });
        claims.push(Claim::checked(
            "E2: as one cable's tension rises, the other two rise linearly, and so does the joint stiffness",
            rising && linear,
            format!(
                "ours: f from [{}, {}, {}] N to [{}, {}, {}] N (linear in the level by construction, f = f_p + λ n); K_x from {} to {}, K_y from {} to {} N m/rad",
                fixed(first.tensions[0], 1),
                fixed(first.tensions[1], 1),
                fixed(first.tensions[2], 1),
                fixed(last.tensions[0], 1),
                fixed(last.tensions[1], 1),
                fixed(last.tensions[2], 1),
                fixed(first.k_x, 2),
                fixed(last.k_x, 2),
                fixed(first.k_y, 2),
                fixed(last.k_y, 2)
            ),
        ));
    }

    // E3: larger |q| mainly raises the maximum, widening the range.
    let n = e3.grid.points;
    let centre = e3.cell(n / 2, n / 2).copied();
    let corners: Vec<_> = [(0, 0), (0, n - 1), (n - 1, 0), (n - 1, n - 1)]
        .iter()
        .filter_map(|&(a, b)| e3.cell(a, b).copied())
        .collect();
    if let (Some(c), false) = (centre, corners.is_empty()) {
        let mean = |f: &dyn Fn(&crate::indicators::SweepCell) -> f64| {
            corners.iter().map(f).sum::<f64>() / corners.len() as f64
        };
        let rise_max =
            mean(&|k| k.k_x.range[1] + k.k_y.range[1]) - (c.k_x.range[1] + c.k_y.range[1]);
        let rise_min =
            mean(&|k| k.k_x.range[0] + k.k_y.range[0]) - (c.k_x.range[0] + c.k_y.range[0]);
        claims.push(Claim::checked(
            "E3: larger |q1|, |q2| mainly raise the maximum stiffness and so widen the range",
            rise_max > 0.0 && rise_max > rise_min.abs(),
            format!(
                "ours, corners of the grid against its centre (K_x + K_y): the maximum rises by {} N m/rad, the minimum changes by {} N m/rad",
                fixed(rise_max, 2),
                fixed(rise_min, 2)
            ),
        ));
    }
    // E3: sign of q2 decides which axis has the wider range, over the whole map.
    let mut sums = [[0.0_f64; 2]; 2]; // [q2 < 0, q2 > 0] × [count where Δk_x > Δk_y, count]
    for a in 0..n {
        for b in 0..n {
            let q2 = e3.grid.angle(b);
            if q2 == 0.0 {
                continue;
            }
            if let Some(c) = e3.cell(a, b) {
                let side = usize::from(q2 > 0.0);
                sums[side][1] += 1.0;
                if c.k_x.delta > c.k_y.delta {
                    sums[side][0] += 1.0;
                }
            }
        }
    }
    let share_x_neg = if sums[0][1] > 0.0 { sums[0][0] / sums[0][1] } else { 0.0 };
    let share_y_pos = if sums[1][1] > 0.0 { 1.0 - sums[1][0] / sums[1][1] } else { 0.0 };
    claims.push(Claim::checked(
            "E3: over the map, q2 < 0 gives K_x the wider range and q2 > 0 gives K_y the wider range",
            share_x_neg > 0.5 && share_y_pos > 0.5,
            format!(
            "ours: Δk_x > Δk_y at {} % of the feasible points with q2 < 0; Δk_y > Δk_x at {} % of those with q2 > 0",
            fixed(100.0 * share_x_neg, 1),
            fixed(100.0 * share_y_pos, 1)
        ),
    ));
    claims
}
