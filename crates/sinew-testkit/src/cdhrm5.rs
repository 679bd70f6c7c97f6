//! The cdhrm5 platform: its files in `robots/cdhrm5` (paths resolved from the workspace root,
//! whatever the crate under test), and the generated uniform chains that share its link and
//! cable pattern (benchmarks, scaling tests, `cargo xtask calibrate` and `gen-chain`).
//!
//! The pattern constants below are those `cargo xtask calibrate` fitted to Table II and wrote
//! into `robots/cdhrm5` (its README says why); sinew-routing's `tests/structure.rs` checks that
//! the files and [`chain_routing_spec`] agree, so a recalibration that forgets one of them fails
//! `cargo test`. They live here, not in the library crates: the library knows no robot.

use std::f64::consts::{FRAC_PI_6, TAU};
use std::path::{Path, PathBuf};

use nalgebra::Vector3;
use sinew_robot::{Robot, UniformChain};
use sinew_routing::{Material, Pattern, PatternModel, PerJoint, Routing, RoutingSpec};

/// Hole radius of the cdhrm5 pattern, m (fitted to Table II).
pub const HOLE_RADIUS: f64 = 0.02061;
/// Angle of cable 1 of joint 0 of the cdhrm5 pattern, rad (fitted to Table II, near +x).
pub const THETA0: f64 = 0.01379;
/// Angular offset per joint of the cdhrm5 pattern, rad: 2π/15, 15 evenly spaced holes.
pub const JOINT_OFFSET: f64 = TAU / 15.0;
/// Free length of the cdhrm5 cables from the actuator to the base disc, m (fitted to Table II).
pub const FREE_LENGTH: f64 = 3.2128;
/// Young's modulus of the cdhrm5 cables, Pa (Table I).
pub const YOUNGS_MODULUS: f64 = 12.5e9;
/// Cable diameter of cdhrm5, m.
pub const DIAMETER: f64 = 1.0e-3;
/// Tension limits of cdhrm5, N (Table I / section IV).
pub const TENSION_LIMITS: [f64; 2] = [20.0, 600.0];
/// Distance from a disc to the joint centre (`d1`) and from the centre to the next disc
/// (`d2`) of cdhrm5, m (eq. 1; fitted to Table II).
pub const D1_D2: (f64, f64) = (0.03, 0.0);

/// A loaded pose of cdhrm5, rad: under gravity and 5 N along +y at the tip, every joint's
/// tensions are feasible and `K_q + K_W` is stable, decoupled and routed. It is the E4 pose
/// rounded to 0.01 rad, for the tests below the facade that need a loaded pose, not the
/// experiment: E4 itself has one owner, `sinew::paper::E4_Q` (see the crate docs).
pub const LOADED_POSE: [f64; 10] =
    [-0.45, -0.35, -0.35, -0.29, 0.52, 0.45, 0.39, -0.21, -0.26, -0.31];

/// Both cable models, in the order the tests run them.
pub const MODELS: [PatternModel; 2] = [PatternModel::Decoupled, PatternModel::Routed];

/// The poses of a smooth trajectory about [`LOADED_POSE`] sampled every `dt` seconds:
/// `q_j(t) = q0_j + 0.2 sin(ω_j t + φ j)`, `ω_j` from 0.5 to 15 rad/s (joint speeds up to
/// 0.1–3 rad/s). The planner's re-planning bench, profile and tests share it.
pub fn swaying_poses(steps: usize, dt: f64, phase: f64) -> Vec<Vec<f64>> {
    (0..steps)
        .map(|k| {
            let t = k as f64 * dt;
            (0..10)
                .map(|j| {
                    let omega = 0.5 + 14.5 * j as f64 / 9.0;
                    LOADED_POSE[j] + 0.2 * (omega * t + phase * j as f64).sin()
                })
                .collect()
        })
        .collect()
}

/// The workspace root (this crate lives in `crates/sinew-testkit`).
pub fn workspace_root() -> PathBuf {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    manifest.parent().and_then(Path::parent).unwrap_or(manifest).to_path_buf()
}

/// The platform's folder, `robots/cdhrm5`.
pub fn dir() -> PathBuf {
    workspace_root().join("robots").join("cdhrm5")
}

/// The routing file of a cable model ([`sinew_routing::routing_file`]).
pub fn routing_file(model: PatternModel) -> &'static str {
    sinew_routing::routing_file(model)
}

/// The platform, loaded from the repository's robot files.
///
/// # Panics
/// When the files do not load (the message names the folder and the error).
pub fn robot() -> Robot {
    let dir = dir();
    sinew_robot::load(&dir).unwrap_or_else(|e| panic!("loading {}: {e}", dir.display()))
}

/// The platform's routing of `model` for `robot` (cdhrm5, or a copy of it with other gravity).
///
/// # Panics
/// When the file does not load (the message names it and the error).
pub fn routing(robot: &Robot, model: PatternModel) -> Routing {
    let path = dir().join(routing_file(model));
    sinew_routing::load(&path, robot).unwrap_or_else(|e| panic!("loading {}: {e}", path.display()))
}

/// The platform and its routing of `model`.
pub fn robot_and_routing(model: PatternModel) -> (Robot, Routing) {
    let robot = robot();
    let routing = routing(&robot, model);
    (robot, routing)
}

/// A chain of `joints` universal joints with the platform's link (φ60 × 220 mm), 0.24 kg per
/// link, ±π/6 limits, d1 = 30 mm, d2 = 0 (fitted to Table II) and a horizontal mounting
/// (gravity along +y): the values of `robots/cdhrm5` (its README says why).
pub fn uniform_chain(joints: usize) -> UniformChain {
    UniformChain {
        name: format!("uniform{joints}"),
        joints,
        d1: D1_D2.0,
        d2: D1_D2.1,
        link_length: 0.22,
        link_radius: 0.03,
        total_mass: 0.24 * joints as f64,
        limit: FRAC_PI_6,
        gravity: Vector3::new(0.0, 9.81, 0.0),
    }
}

/// The cdhrm5 routing (the values of `robots/cdhrm5/cables.toml`) for a chain generated by
/// [`UniformChain`]: three cables per joint on the disc links that the generator names
/// (`base_link` / `link{i-1}_distal` proximal, `link{i}` distal).
///
/// Free lengths: in the decoupled model a cable's routed length is only its crossing of its
/// own joint, so the free length of joint `i` (0-based) adds the central channel through the
/// `i` links before it, `i · (d1 + d2 + link_length)`; in the routed model the routed length
/// already holds that run, so the free length is the same for all. Both give every cable the
/// same elastic length at Q = 0 as the other model.
pub fn chain_routing_spec(chain: &UniformChain, model: PatternModel) -> RoutingSpec {
    let n = chain.joints;
    let pitch = chain.d1 + chain.d2 + chain.link_length;
    let free_length = match model {
        PatternModel::Decoupled => {
            PerJoint::Each((0..n).map(|i| FREE_LENGTH + i as f64 * pitch).collect())
        }
        PatternModel::Routed => PerJoint::Uniform(FREE_LENGTH),
    };
    RoutingSpec {
        tension_limits: TENSION_LIMITS,
        free_length: Some(free_length),
        material: Material { youngs_modulus: YOUNGS_MODULUS, diameter: Some(DIAMETER), area: None },
        friction_coefficient: None,
        pattern: Some(Pattern {
            model,
            radius: Some(PerJoint::Uniform(HOLE_RADIUS)),
            proximal_radius: None,
            distal_radius: None,
            theta0: THETA0,
            joint_offset: JOINT_OFFSET,
            proximal_discs: proximal_discs(n),
            distal_discs: distal_discs(n),
            cables: Default::default(),
        }),
        cables: Vec::new(),
    }
}

/// The robot of [`uniform_chain`]`(joints)`.
///
/// # Panics
/// For `joints == 0` (the loader's `NoJoints`).
pub fn chain_robot(joints: usize) -> Robot {
    uniform_chain(joints).build().unwrap_or_else(|e| panic!("uniform{joints}: {e}"))
}

/// A generated chain of `joints` universal joints (2·`joints` DOF) with the cdhrm5 pattern
/// routing of `model` ([`chain_routing_spec`]).
///
/// # Panics
/// For `joints == 0`.
pub fn chain(joints: usize, model: PatternModel) -> (Robot, Routing) {
    let chain = uniform_chain(joints);
    let robot = chain_robot(joints);
    let routing = Routing::new(&robot, &chain_routing_spec(&chain, model), "<generated>")
        .unwrap_or_else(|e| panic!("uniform{joints} {model:?}: {e}"));
    (robot, routing)
}

/// The usual cases of the structure and derivative tests: cdhrm5 and a generated chain of
/// `joints` universal joints, decoupled then routed, named `cdhrm5 Decoupled`,
/// `uniform50 Routed`, …
pub fn cases(joints: usize) -> Vec<(String, Robot, Routing)> {
    let mut cases = Vec::new();
    for model in MODELS {
        let (robot, routing) = robot_and_routing(model);
        cases.push((format!("cdhrm5 {model:?}"), robot, routing));
        let (robot, routing) = chain(joints, model);
        cases.push((format!("uniform{joints} {model:?}"), robot, routing));
    }
    cases
}

/// The proximal disc of each of `n` universal joints in the cdhrm5 link naming (also the
/// generated chains'): `base_link`, then `link{i}_distal`.
pub fn proximal_discs(n: usize) -> Vec<String> {
    (1..=n)
        .map(|i| if i == 1 { "base_link".to_owned() } else { format!("link{}_distal", i - 1) })
        .collect()
}

/// The distal disc of each of `n` universal joints in the cdhrm5 link naming: `link{i}`.
pub fn distal_discs(n: usize) -> Vec<String> {
    (1..=n).map(|i| format!("link{i}")).collect()
}
