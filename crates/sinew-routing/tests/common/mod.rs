//! Shared helpers of the sinew-routing tests.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use faer::{Mat, MatRef};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sinew_robot::{Robot, UniformChain};
use sinew_routing::{PatternModel, Routing, RoutingSpec};

/// The platform's folder.
pub const CDHRM5: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/cdhrm5");

/// The platform, loaded from the repository's robot files.
pub fn cdhrm5() -> Robot {
    sinew_robot::load(CDHRM5).unwrap()
}

/// The platform's routing: `cables.toml` (decoupled) or `cables-routed.toml`.
pub fn cdhrm5_routing(robot: &Robot, model: PatternModel) -> Routing {
    let file = match model {
        PatternModel::Decoupled => sinew_routing::ROUTING_FILE,
        PatternModel::Routed => sinew_routing::ROUTED_ROUTING_FILE,
    };
    sinew_routing::load(format!("{CDHRM5}/{file}"), robot).unwrap()
}

/// A generated chain of `n` universal joints (2n DOF) with the cdhrm5 pattern routing.
pub fn chain(n: usize, model: PatternModel) -> (Robot, Routing) {
    let chain = UniformChain::like_cdhrm5(n);
    let robot = chain.build().unwrap();
    let spec = RoutingSpec::for_uniform_chain(&chain, model);
    let routing = Routing::new(&robot, &spec, "<generated>").unwrap();
    (robot, routing)
}

/// The cases of the derivative and structure tests: cdhrm5 and a generated 50-joint chain,
/// decoupled and routed.
pub fn cases() -> Vec<(String, Robot, Routing)> {
    let mut cases = Vec::new();
    for model in [PatternModel::Decoupled, PatternModel::Routed] {
        let robot = cdhrm5();
        let routing = cdhrm5_routing(&robot, model);
        cases.push((format!("cdhrm5 {model:?}"), robot, routing));
        let (robot, routing) = chain(50, model);
        cases.push((format!("uniform50 {model:?}"), robot, routing));
    }
    cases
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

/// `(max |a − b|, max |a|)` over a matrix.
pub fn max_diff_and_scale(analytic: MatRef<'_, f64>, numeric: MatRef<'_, f64>) -> (f64, f64) {
    assert_eq!((analytic.nrows(), analytic.ncols()), (numeric.nrows(), numeric.ncols()));
    let mut diff: f64 = 0.0;
    let mut scale: f64 = 0.0;
    for j in 0..analytic.ncols() {
        for i in 0..analytic.nrows() {
            diff = diff.max((analytic[(i, j)] - numeric[(i, j)]).abs());
            scale = scale.max(analytic[(i, j)].abs());
        }
    }
    (diff, scale)
}

/// A dense copy.
pub fn to_mat(m: MatRef<'_, f64>) -> Mat<f64> {
    Mat::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)])
}
