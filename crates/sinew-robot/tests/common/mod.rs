//! Shared helpers of the sinew-robot tests.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use faer::{Mat, MatRef};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sinew_robot::{Robot, UniformChain};

/// The platform, loaded from the repository's robot files.
pub fn cdhrm5() -> Robot {
    sinew_robot::load(concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/cdhrm5")).unwrap()
}

/// A generated chain of `n` universal joints (2n DOF).
pub fn chain(n: usize) -> Robot {
    UniformChain::like_cdhrm5(n).build().unwrap()
}

/// The robots the derivative tests run on: cdhrm5 and a generated 50-joint chain.
pub fn test_robots() -> Vec<(&'static str, Robot)> {
    vec![("cdhrm5", cdhrm5()), ("uniform50", chain(50))]
}

/// A seeded generator: every test run sees the same configurations.
pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// A configuration drawn uniformly within the joint limits.
pub fn random_q(robot: &Robot, rng: &mut ChaCha8Rng) -> Vec<f64> {
    robot.joints().iter().map(|j| rng.random_range(j.lower..=j.upper)).collect()
}

/// Step of the central differences: balances truncation (h²) against round-off (ε/h).
pub const H: f64 = 1e-6;

/// Relative tolerance of analytic derivatives against central differences.
pub const RTOL: f64 = 1e-6;

/// `max |a − b| / max(1, max |a|)`: the error relative to the analytic value's scale (an
/// absolute floor of 1 in the quantity's SI unit keeps entries that are zero from dividing).
pub fn rel_err(analytic: MatRef<'_, f64>, numeric: MatRef<'_, f64>) -> f64 {
    assert_eq!((analytic.nrows(), analytic.ncols()), (numeric.nrows(), numeric.ncols()));
    let mut diff: f64 = 0.0;
    let mut scale: f64 = 1.0;
    for j in 0..analytic.ncols() {
        for i in 0..analytic.nrows() {
            diff = diff.max((analytic[(i, j)] - numeric[(i, j)]).abs());
            scale = scale.max(analytic[(i, j)].abs());
        }
    }
    diff / scale
}

/// A column vector as a one-column faer matrix.
pub fn column(v: &[f64]) -> Mat<f64> {
    Mat::from_fn(v.len(), 1, |i, _| v[i])
}
