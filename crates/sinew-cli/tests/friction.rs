//! `sinew arm --friction` (spec §9, #27) on cdhrm5 at the loaded pose: μ = 0 is the
//! frictionless document byte for byte; with μ > 0 the JSON carries the library's regime
//! numbers (`ArmStiffness::evaluate_with_friction`, the directional response, the stick load
//! limits); every bad input is one line on standard error, exit 2, nothing on standard output.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::process::{Command, Output};

use nalgebra::Vector6;
use serde_json::Value;
use sinew::routing::{FrictionModel, Slip, compute_wrap_gradients};
use sinew::statics::{TensionChoice, TensionPolicy};
use sinew::stiffness::{
    ArmStiffness, ArmStiffnessData, FrictionArmData, FrictionRegime, History, base_directions,
    directional_response, stick_load_limits,
};
use sinew_testkit::cdhrm5;

const Q: &str = "-0.45,-0.35,-0.35,-0.29,0.52,0.45,0.39,-0.21,-0.26,-0.31";

fn run(extra: &[&str]) -> Output {
    let robot = cdhrm5::dir();
    let mut args = vec!["arm", "--robot", robot.to_str().unwrap(), "--q", Q];
    args.extend(["--wrench", "0,5,0,0,0,0"]);
    args.extend(extra);
    Command::new(env!("CARGO_BIN_EXE_sinew")).args(&args).output().unwrap()
}

fn json(extra: &[&str]) -> Value {
    let out = run(extra);
    assert!(out.status.success(), "{extra:?}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

fn nums(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

fn rows(v: &Value) -> Vec<Vec<f64>> {
    v.as_array().unwrap().iter().map(nums).collect()
}

#[test]
fn mu_zero_is_the_frictionless_document_byte_for_byte() {
    let plain = run(&["--json", "--levels", "0.5,0.5,0.5,0.5,0.5"]);
    for extra in [["--friction", "0"], ["--regime", "pull"]] {
        let mut args = vec!["--json", "--levels", "0.5,0.5,0.5,0.5,0.5"];
        args.extend(extra);
        let out = run(&args);
        assert!(out.status.success());
        assert_eq!(out.stdout, plain.stdout, "{extra:?}");
    }
}

#[test]
fn the_stick_and_slip_documents_are_the_librarys_numbers() {
    let (robot, routing) = cdhrm5::robot_and_routing(sinew::routing::PatternModel::Decoupled);
    let arm = ArmStiffness::new(&robot, &routing).unwrap();
    let model = FrictionModel::new(&routing).with_friction_coefficient(0.1).unwrap();
    let q = cdhrm5::LOADED_POSE;
    let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    for (regime, flags) in [
        (FrictionRegime::Stick(History::Pull), vec!["--friction", "0.1"]),
        (FrictionRegime::Stick(History::Equal), vec!["--friction", "0.1", "--history", "equal"]),
        (FrictionRegime::Slip(Slip::Release), vec!["--friction", "0.1", "--regime", "release"]),
        (FrictionRegime::Slip(Slip::Pull), vec!["--friction", "0.1", "--regime", "pull"]),
    ] {
        // The pull row takes the paper's levels (the closed form on J̃), the others a policy.
        let by_levels = regime == FrictionRegime::Slip(Slip::Pull);
        let mut args = vec!["--json"];
        args.extend(if by_levels {
            ["--levels", "0.5,0.5,0.5,0.5,0.5"]
        } else {
            ["--policy", "safest"]
        });
        args.extend(&flags);
        let doc = json(&args);
        let mut data = ArmStiffnessData::new(&arm);
        let mut out = FrictionArmData::new(&arm, &model);
        let choice = if by_levels {
            TensionChoice::Levels(&[0.5; 5])
        } else {
            TensionChoice::Policy(TensionPolicy::Safest)
        };
        arm.evaluate_with_friction(&mut data, &mut out, (&model, regime), &q, &f0, choice).unwrap();
        assert_eq!(nums(&doc["tensions"]), out.actuator, "{flags:?}");
        let k_q = out.stiffness.stiffness().unwrap();
        let got = rows(&doc["k_q"]);
        for i in 0..10 {
            for j in 0..10 {
                assert_eq!(got[i][j], k_q[(i, j)], "{flags:?}");
            }
        }
        let c_x = rows(&doc["c_x"]);
        assert_eq!(c_x[1][1], out.end.compliance()[(1, 1)]);
        for (c, band) in out.dead_band.iter().enumerate() {
            assert_eq!(nums(&doc["dead_band"][c]), band.to_vec());
            assert_eq!(nums(&doc["segments"][c]["tensions"]), out.segments[c]);
        }
        let FrictionRegime::Stick(history) = regime else {
            assert!(doc["directional"].is_null() && doc["stick_load_limit"].is_null());
            assert!(doc["k_q_skew_norm"].as_f64().unwrap() > 0.0);
            let name = if by_levels { "pull" } else { "release" };
            assert_eq!(doc["friction"]["regime"], name);
            continue;
        };
        assert_eq!(doc["k_q_skew_norm"].as_f64().unwrap(), 0.0);
        let k_w = data.k_w().to_owned();
        let j_x = data.j_x().to_owned();
        let increment = (k_q, k_w.as_ref(), j_x.as_ref());
        let u = Vector6::new(0.0, 1.0, 0.0, 0.0, 0.0, 0.0);
        compute_wrap_gradients(&model, &mut out.friction).unwrap();
        let (f, t) = (&out.friction, &out.actuator);
        let [plus, minus] =
            directional_response(&model, &routing, f, history, t, increment, &u).unwrap();
        assert_eq!(doc["directional"]["plus"]["compliance"].as_f64().unwrap(), plus.compliance);
        assert_eq!(doc["directional"]["minus"]["stiffness"].as_f64().unwrap(), minus.stiffness);
        assert_eq!(
            doc["directional"]["plus"]["sliding"].as_array().unwrap().len(),
            plus.sliding.len()
        );
        let limits =
            stick_load_limits(&model, &routing, f, history, t, increment, &base_directions())
                .unwrap();
        let listed = doc["stick_load_limit"].as_array().unwrap();
        assert_eq!(listed.len(), 14, "12 base directions, then ±u");
        for (l, v) in limits.iter().zip(listed) {
            assert_eq!(v["magnitude"].as_f64().unwrap(), l.magnitude);
            assert_eq!(v["at_once"].as_array().unwrap().len(), l.at_once.len());
        }
        // After a pull some directions slide at once, naming their holes; after equal none does.
        let at_once = listed.iter().filter(|v| v["magnitude"].as_f64() == Some(0.0)).count();
        assert_eq!(at_once > 0, history == History::Pull, "{flags:?}");
    }
}

#[test]
fn bad_input_is_one_line_and_exit_2() {
    for (extra, says) in [
        (vec!["--friction", "-0.1"], "--friction"),
        (vec!["--friction", "nan"], "--friction"),
        (vec!["--friction", "0", "--regime", "stick"], "μ = 0"),
        (vec!["--history", "equal"], "μ = 0"),
        (vec!["--friction", "0.1", "--regime", "pull", "--history", "equal"], "--history"),
        (vec!["--friction", "0.1", "--direction", "0,0,0"], "--direction"),
        (vec!["--friction", "0.1", "--direction", "1,0"], "--direction"),
        (vec!["--friction", "0.1", "--levels", "0.5,0.5,1.5,0.5,0.5"], "level"),
    ] {
        let out = run(&extra);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {stderr}");
        assert!(out.stdout.is_empty(), "{extra:?}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{extra:?}: {stderr}");
        assert!(stderr.contains(says), "{extra:?}: {stderr}");
    }
    // No force in the load and no --direction: the stick regime's direction is missing.
    let robot = cdhrm5::dir();
    let args = ["arm", "--robot", robot.to_str().unwrap(), "--q", Q, "--friction", "0.1"];
    let out = Command::new(env!("CARGO_BIN_EXE_sinew")).args(args).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--direction: required"));
}
