//! Sweeps of a joint's stiffness indicators over a grid of its two angles (the paper's Fig. 5),
//! in parallel over the grid (rayon). Progress is reported to a callback; drawing it (a
//! progress bar, a log line) is the caller's business.

use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;
use sinew_robot::Robot;
use sinew_routing::Routing;

use crate::error::IndicatorError;
use crate::joint::JointProbe;
use crate::range::Indicator;

/// A square grid of joint angles: `points` values from `lower` to `upper` on each axis, rad.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AngleGrid {
    /// First angle, rad.
    pub lower: f64,
    /// Last angle, rad.
    pub upper: f64,
    /// Points per axis (≥ 2).
    pub points: usize,
}

impl AngleGrid {
    /// The least number of points per axis (the two ends of the range).
    pub const MIN_POINTS: usize = 2;

    /// The `k`-th angle of the grid, rad.
    pub fn angle(&self, k: usize) -> f64 {
        self.lower + (self.upper - self.lower) * k as f64 / (self.points - 1) as f64
    }

    fn check(&self) -> Result<(), IndicatorError> {
        if self.points < Self::MIN_POINTS {
            return Err(IndicatorError::GridTooSmall {
                points: self.points,
                min: Self::MIN_POINTS,
            });
        }
        if !(self.lower.is_finite() && self.upper.is_finite() && self.lower < self.upper) {
            return Err(IndicatorError::GridRange { lower: self.lower, upper: self.upper });
        }
        Ok(())
    }
}

/// The indicators at one grid point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepCell {
    /// `σ_x`: range and width of `K_{i,x}`.
    pub k_x: Indicator,
    /// `σ_y`: range and width of `K_{i,y}`.
    pub k_y: Indicator,
}

/// The result of a sweep: `cells[a * points + b]` is at `q = [angle(a), angle(b)]`; `None`
/// where the torque cannot be held within the tension limits.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepMaps {
    /// The probed joint (0-based).
    pub joint: usize,
    /// The torque held, N m.
    pub torque: [f64; 2],
    /// The grid (the same on both axes).
    pub grid: AngleGrid,
    /// Row-major cells, `q_1` along rows, `q_2` along columns.
    pub cells: Vec<Option<SweepCell>>,
}

impl SweepMaps {
    /// The cell at grid indices `(a, b)`, i.e. `q = [angle(a), angle(b)]`.
    pub fn cell(&self, a: usize, b: usize) -> Option<&SweepCell> {
        self.cells.get(a * self.grid.points + b).and_then(Option::as_ref)
    }

    /// Number of grid points where the torque can be held.
    pub fn feasible(&self) -> usize {
        self.cells.iter().filter(|c| c.is_some()).count()
    }
}

/// Sweep joint `joint`'s indicators over `grid × grid` for the torque `tau` (Fig. 5), the
/// other joints at zero: [`sweep_probe`] with [`JointProbe::new`]'s probe.
///
/// # Errors
/// [`IndicatorError::NoSuchJoint`], [`IndicatorError::NotThreeCables`],
/// [`IndicatorError::NotUniversal`], and those of [`sweep_probe`].
pub fn sweep_joint(
    robot: &Robot,
    routing: &Routing,
    joint: usize,
    tau: [f64; 2],
    grid: AngleGrid,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<SweepMaps, IndicatorError> {
    grid.check()?;
    sweep_probe(&JointProbe::new(robot, routing, joint)?, robot, routing, tau, grid, progress)
}

/// Sweep the indicators of `probe`'s joint over `grid × grid` for the torque `tau` (Fig. 5),
/// with the probe's other joint angles and friction ([`JointProbe::with_friction`]).
///
/// Parallel over the grid's rows; each thread reuses a clone of `probe`. After each row,
/// `progress(done, total)` is called with the number of points done so far and the total
/// (`points²`), from whichever thread finished the row (pass `&|_, _| {}` for none).
/// Infeasible points are `None`; other errors (angles outside the limits, bad geometry) stop
/// the sweep.
///
/// # Errors
/// [`IndicatorError::GridTooSmall`], [`IndicatorError::GridRange`], and the first
/// non-infeasibility error of a point.
pub fn sweep_probe(
    probe: &JointProbe,
    robot: &Robot,
    routing: &Routing,
    tau: [f64; 2],
    grid: AngleGrid,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<SweepMaps, IndicatorError> {
    grid.check()?;
    let (joint, n) = (probe.joint(), grid.points);
    let done = AtomicUsize::new(0);
    let rows: Result<Vec<Vec<Option<SweepCell>>>, IndicatorError> = (0..n)
        .into_par_iter()
        .map_init(
            || probe.clone(),
            |probe, a| {
                let mut row = Vec::with_capacity(n);
                for b in 0..n {
                    let q = [grid.angle(a), grid.angle(b)];
                    let cell = match probe.evaluate(robot, routing, q, tau) {
                        Ok(range) => Some(SweepCell { k_x: range.sigma_x(), k_y: range.sigma_y() }),
                        Err(e) if e.is_infeasible() => None,
                        Err(e) => return Err(e),
                    };
                    row.push(cell);
                }
                progress(done.fetch_add(n, Ordering::Relaxed) + n, n * n);
                Ok(row)
            },
        )
        .collect();
    Ok(SweepMaps { joint, torque: tau, grid, cells: rows?.into_iter().flatten().collect() })
}
