//! The single-joint experiments: Table II (E1), Fig. 4 (E2) and Fig. 5 (E3), on joint 1 of a
//! robot with its routing (spec §6).

use std::fmt::Write as _;

use crate::indicators::{AngleGrid, IndicatorError, JointProbe, SweepMaps, sweep_joint};
use crate::robot::Robot;
use crate::routing::Routing;

use super::experiments::{
    E2_Q, E2_TORQUE, E3_RANGE, E3_TORQUE, PAPER_TABLE_2, SINGLE_JOINT, TABLE_2_TORQUE,
};
use super::fixed;

/// One row of Table II: ours beside the paper's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Table2Row {
    /// Joint angles, rad.
    pub q: [f64; 2],
    /// Ours: `[[K_x min, K_x max], [K_y min, K_y max]]`, N m/rad.
    pub ours: [[f64; 2]; 2],
    /// The paper's, same layout.
    pub paper: [[f64; 2]; 2],
}

impl Table2Row {
    /// `Δk_x`, `Δk_y` of ours.
    pub fn ours_delta(&self) -> [f64; 2] {
        [self.ours[0][1] - self.ours[0][0], self.ours[1][1] - self.ours[1][0]]
    }

    /// `Δk_x`, `Δk_y` of the paper.
    pub fn paper_delta(&self) -> [f64; 2] {
        [self.paper[0][1] - self.paper[0][0], self.paper[1][1] - self.paper[1][0]]
    }

    /// The relative errors `(ours − paper) / paper` of the four interval ends:
    /// `[K_x min, K_x max, K_y min, K_y max]`.
    pub fn relative_errors(&self) -> [f64; 4] {
        let e = |axis: usize, end: usize| {
            (self.ours[axis][end] - self.paper[axis][end]) / self.paper[axis][end]
        };
        [e(0, 0), e(0, 1), e(1, 0), e(1, 1)]
    }
}

/// Table II (E1) on joint 1 (index 0) of `robot` with `routing`.
///
/// # Errors
/// An infeasible configuration or a geometry error.
pub fn table_2(robot: &Robot, routing: &Routing) -> Result<Vec<Table2Row>, IndicatorError> {
    let mut probe = JointProbe::new(robot, routing, SINGLE_JOINT)?;
    PAPER_TABLE_2
        .iter()
        .map(|&(q, kx, ky)| {
            let range = probe.evaluate(robot, routing, q, TABLE_2_TORQUE)?;
            Ok(Table2Row {
                q,
                ours: [range.sigma_x().range, range.sigma_y().range],
                paper: [kx, ky],
            })
        })
        .collect()
}

/// RMS relative error of ours against the paper over the 20 interval ends.
pub fn rms_relative_error(rows: &[Table2Row]) -> f64 {
    let errors: Vec<f64> = rows.iter().flat_map(Table2Row::relative_errors).collect();
    if errors.is_empty() {
        0.0
    } else {
        (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt()
    }
}

fn q_label(q: [f64; 2]) -> String {
    let part = |x: f64| {
        if x == 0.0 {
            "0".to_owned()
        } else if x > 0.0 {
            "π/6".to_owned()
        } else {
            "−π/6".to_owned()
        }
    };
    format!("[{}, {}]", part(q[0]), part(q[1]))
}

/// Table II as markdown: ours, the paper's, and the relative error of each interval end.
pub fn render_table_2(rows: &[Table2Row]) -> String {
    let mut s = String::new();
    let range = |r: [f64; 2]| format!("[{}, {}]", fixed(r[0], 2), fixed(r[1], 2));
    let err = |ours: [f64; 2], paper: [f64; 2]| {
        format!(
            "{} %, {} %",
            fixed(100.0 * (ours[0] - paper[0]) / paper[0], 1),
            fixed(100.0 * (ours[1] - paper[1]) / paper[1], 1)
        )
    };
    let _ = writeln!(
        s,
        "| q | K_x ours | K_x paper | error | Δk_x ours / paper | K_y ours | K_y paper | error | Δk_y ours / paper |"
    );
    let _ = writeln!(s, "| --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    for row in rows {
        let (od, pd) = (row.ours_delta(), row.paper_delta());
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} / {} | {} | {} | {} | {} / {} |",
            q_label(row.q),
            range(row.ours[0]),
            range(row.paper[0]),
            err(row.ours[0], row.paper[0]),
            fixed(od[0], 2),
            fixed(pd[0], 2),
            range(row.ours[1]),
            range(row.paper[1]),
            err(row.ours[1], row.paper[1]),
            fixed(od[1], 2),
            fixed(pd[1], 2),
        );
    }
    let _ = writeln!(
        s,
        "\nRMS relative error over the 20 interval ends: {} %",
        fixed(100.0 * rms_relative_error(rows), 1)
    );
    s
}

/// One point of E2's feasible tension segment (Fig. 4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct E2Point {
    /// Tension level `s ∈ [0, 1]`.
    pub level: f64,
    /// The three tensions, N.
    pub tensions: [f64; 3],
    /// `K_x`, N m/rad.
    pub k_x: f64,
    /// `K_y`, N m/rad.
    pub k_y: f64,
}

/// E2 (Fig. 4): `samples` points along joint 1's feasible tension segment at `q = [π/7, −π/9]`
/// holding `τ = [−1, 0.5]` N m.
///
/// # Errors
/// An infeasible torque or a geometry error.
pub fn e2(
    robot: &Robot,
    routing: &Routing,
    samples: usize,
) -> Result<Vec<E2Point>, IndicatorError> {
    let mut probe = JointProbe::new(robot, routing, SINGLE_JOINT)?;
    let range = probe.evaluate(robot, routing, E2_Q, E2_TORQUE)?;
    let samples = samples.max(2);
    Ok((0..samples)
        .map(|k| {
            let level = k as f64 / (samples - 1) as f64;
            let f = range.interval.tensions_at_level(level);
            let kq = range.at_level(level);
            E2Point { level, tensions: [f[0], f[1], f[2]], k_x: kq[(0, 0)], k_y: kq[(1, 1)] }
        })
        .collect())
}

/// E2 as CSV: `level,f1,f2,f3,k_x,k_y` (N, N m/rad).
pub fn e2_csv(points: &[E2Point]) -> String {
    let mut s = String::from("level,f1_N,f2_N,f3_N,k_x_Nm_per_rad,k_y_Nm_per_rad\n");
    for p in points {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{}",
            fixed(p.level, 3),
            fixed(p.tensions[0], 3),
            fixed(p.tensions[1], 3),
            fixed(p.tensions[2], 3),
            fixed(p.k_x, 4),
            fixed(p.k_y, 4)
        );
    }
    s
}

/// E3 (Fig. 5): joint 1's indicators over `points × points` angles in `[−π/6, π/6]²`
/// holding `τ = [0.3, 0.3]` N m.
///
/// # Errors
/// Geometry errors (infeasible points are `None` in the maps).
pub fn e3(robot: &Robot, routing: &Routing, points: usize) -> Result<SweepMaps, IndicatorError> {
    e3_with_progress(robot, routing, points, &|_, _| {})
}

/// [`e3`], reporting `progress(done, total)` points as the sweep goes (see
/// [`sweep_joint`]; `cargo xtask reproduce` draws it as a progress bar).
///
/// # Errors
/// As [`e3`].
pub fn e3_with_progress(
    robot: &Robot,
    routing: &Routing,
    points: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<SweepMaps, IndicatorError> {
    sweep_joint(
        robot,
        routing,
        SINGLE_JOINT,
        E3_TORQUE,
        AngleGrid { lower: E3_RANGE[0], upper: E3_RANGE[1], points },
        progress,
    )
}

/// E3 as CSV: `q1,q2,k_x_min,k_x_max,k_y_min,k_y_max`; infeasible points have empty fields.
pub fn e3_csv(maps: &SweepMaps) -> String {
    let n = maps.grid.points;
    let mut s = String::from("q1_rad,q2_rad,k_x_min,k_x_max,k_y_min,k_y_max\n");
    for a in 0..n {
        for b in 0..n {
            let (q1, q2) = (fixed(maps.grid.angle(a), 5), fixed(maps.grid.angle(b), 5));
            match maps.cell(a, b) {
                Some(c) => {
                    let _ = writeln!(
                        s,
                        "{q1},{q2},{},{},{},{}",
                        fixed(c.k_x.range[0], 4),
                        fixed(c.k_x.range[1], 4),
                        fixed(c.k_y.range[0], 4),
                        fixed(c.k_y.range[1], 4)
                    );
                }
                None => {
                    let _ = writeln!(s, "{q1},{q2},,,,");
                }
            }
        }
    }
    s
}
