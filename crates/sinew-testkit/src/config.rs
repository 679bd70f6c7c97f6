//! Seeded configurations: every test run sees the same ones.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sinew_robot::Robot;

/// A seeded generator (ChaCha8).
pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// A configuration drawn uniformly within the joint limits.
///
/// # Panics
/// When a joint has no finite limits (a continuous joint): there is no uniform draw.
pub fn random_q(robot: &Robot, rng: &mut impl Rng) -> Vec<f64> {
    robot.joints().iter().map(|j| rng.random_range(j.lower..=j.upper)).collect()
}

/// `count` configurations drawn uniformly within the joint limits from a generator seeded
/// with `seed`.
pub fn random_qs(robot: &Robot, seed: u64, count: usize) -> Vec<Vec<f64>> {
    let mut rng = rng(seed);
    (0..count).map(|_| random_q(robot, &mut rng)).collect()
}

/// A configuration within `±spread` (rad, uniform) of `centre`: the pose is an argument, so
/// that each experiment's pose keeps its one owner (the E4 pose: `sinew::paper::E4_Q`).
pub fn near(centre: &[f64], spread: f64, rng: &mut impl Rng) -> Vec<f64> {
    centre.iter().map(|c| c + rng.random_range(-spread..spread)).collect()
}
