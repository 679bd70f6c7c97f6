//! `sinew plan` for every objective in both cable models of cdhrm5 at E4's pose: every JSON key
//! of docs/cli.md, and the numbers recomputed by the library at the tensions the command
//! returns (`K_fd`, `C_x`, the stability eigenvalue, the objective's value), the gap within
//! the asked tolerance, and the answer at least as good as the safest policy's tensions.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::process::Command;

use nalgebra::{Matrix3, Vector3, Vector6};
use serde_json::Value;
use sinew::paper::{E4_F0, E4_Q};
use sinew::routing::PatternModel;
use sinew::statics::TensionChoice;
use sinew::stiffness::{ArmStiffness, ArmStiffnessData};
use sinew_testkit::cdhrm5;

/// The keys of a `plan` document, in docs/cli.md's order.
const KEYS: [&str; 28] = [
    "command",
    "robot",
    "routing_file",
    "model",
    "gravity",
    "q",
    "wrench",
    "objective",
    "direction",
    "k_min",
    "k_des",
    "margin",
    "budget",
    "joint_budgets",
    "fixed_levels",
    "tolerance",
    "value",
    "gap",
    "lambda",
    "levels",
    "cables",
    "tensions",
    "total_tension",
    "k_fd",
    "c_x",
    "min_eigenvalue",
    "stable",
    "iterations",
];

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

fn rows(v: &Value) -> Vec<Vec<f64>> {
    v.as_array().unwrap().iter().map(numbers).collect()
}

/// The objective's value at `k_fd` / `C_x` / tensions, and whether larger is better.
fn objective(
    name: &str,
    u: Vector3<f64>,
    k: &Matrix3<f64>,
    c: &Matrix3<f64>,
    f: &[f64],
) -> (f64, bool) {
    match name {
        "stiffness-along" => ((u.transpose() * k * u)[0], true),
        "compliance-along" => ((u.transpose() * c * u)[0], false),
        "min-stiffness" => (k.symmetric_eigenvalues().min(), true),
        "volume" => (k.determinant().ln(), true),
        "least-tension" => (f.iter().sum(), false),
        other => panic!("{other}"),
    }
}

#[test]
fn every_objective_in_both_models_answers_with_keys_and_numbers_the_library_reproduces() {
    let q: Vec<String> = E4_Q.iter().map(|x| format!("{x}")).collect();
    let q = q.join(",");
    let w: Vec<String> = E4_F0.iter().map(|x| format!("{x}")).collect();
    let w = w.join(",");
    let dir = cdhrm5::dir();
    let u = Vector3::new(0.0, 0.6, 0.8);
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let arm = ArmStiffness::new(&robot, &routing).unwrap();
        let mut data = ArmStiffnessData::new(&arm);
        let f0 = Vector6::from_column_slice(&E4_F0);
        // The default tensions (levels 0) at E4 are unstable: the comparison is with the
        // safest policy's, which are stable there.
        let safest = TensionChoice::Policy(sinew::statics::TensionPolicy::Safest);
        arm.evaluate(&mut data, &E4_Q, &f0, safest).unwrap();
        let (k0, c0, f_default) = (
            data.k_fd(),
            Matrix3::from_fn(|i, j| data.compliance()[(i, j)]),
            data.tensions().to_vec(),
        );
        let name = if model == PatternModel::Decoupled { "decoupled" } else { "routed" };
        for objective_name in
            ["stiffness-along", "compliance-along", "min-stiffness", "volume", "least-tension"]
        {
            let mut args = vec![
                "plan".to_owned(),
                "--robot".into(),
                dir.display().to_string(),
                "--model".into(),
                name.into(),
                "--q".into(),
                q.clone(),
                "--wrench".into(),
                w.clone(),
                "--objective".into(),
                objective_name.into(),
                "--gap".into(),
                "1e-7".into(),
                "--json".into(),
            ];
            if objective_name.ends_with("-along") {
                args.extend(["--direction".to_owned(), "0,3,4".to_owned()]);
            }
            let out = Command::new(env!("CARGO_BIN_EXE_sinew")).args(&args).output().unwrap();
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(0), "{name} {objective_name}: {stderr}");
            let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
            let keys: Vec<&str> = doc.as_object().unwrap().keys().map(String::as_str).collect();
            assert_eq!(keys, KEYS, "{name} {objective_name}");
            assert_eq!(
                (doc["command"].as_str(), doc["model"].as_str()),
                (Some("plan"), Some(name))
            );
            assert_eq!(doc["objective"], objective_name);
            assert_eq!(doc["tolerance"].as_f64(), Some(1e-7));
            if objective_name.ends_with("-along") {
                let d = numbers(&doc["direction"]);
                assert!((Vector3::from_column_slice(&d) - u).norm() <= 1e-15, "{d:?}");
            } else {
                assert!(doc["direction"].is_null());
            }
            let tensions = numbers(&doc["tensions"]);
            assert_eq!(tensions.len(), 15);
            assert_eq!(doc["cables"].as_array().unwrap().len(), 15);
            let total = doc["total_tension"].as_f64().unwrap();
            assert!((total - tensions.iter().sum::<f64>()).abs() <= 1e-12 * total);
            // The library at the returned tensions.
            arm.evaluate(&mut data, &E4_Q, &f0, TensionChoice::Given(&tensions))
                .unwrap_or_else(|e| panic!("{name} {objective_name}: the plan's tensions: {e}"));
            let k = data.k_fd();
            let c = Matrix3::from_fn(|i, j| data.compliance()[(i, j)]);
            let k_json = rows(&doc["k_fd"]);
            let scale = k.abs().max();
            let c_scale = (0..6)
                .flat_map(|i| (0..6).map(move |j| (i, j)))
                .fold(0.0_f64, |m, (i, j)| m.max(data.compliance()[(i, j)].abs()));
            for i in 0..3 {
                for j in 0..3 {
                    assert!((k_json[i][j] - k[(i, j)]).abs() <= 1e-9 * scale, "K_fd[{i}][{j}]");
                }
            }
            let c_json = rows(&doc["c_x"]);
            for i in 0..6 {
                for j in 0..6 {
                    let (a, b) = (c_json[i][j], data.compliance()[(i, j)]);
                    assert!((a - b).abs() <= 1e-9 * c_scale, "C_x[{i}][{j}]: {a} vs {b}");
                }
            }
            let margin = data.stability_margin().unwrap();
            let eig = doc["min_eigenvalue"].as_f64().unwrap();
            assert!((eig - margin).abs() <= 1e-9 * margin.abs(), "{eig} vs {margin}");
            assert_eq!(doc["stable"], Value::Bool(eig > 0.0));
            let (value, larger) = objective(objective_name, u, &k, &c, &tensions);
            let reported = doc["value"].as_f64().unwrap();
            assert!(
                (reported - value).abs() <= 1e-9 * value.abs(),
                "{objective_name}: {reported} vs {value}"
            );
            let gap = doc["gap"].as_f64().unwrap();
            assert!(
                gap >= 0.0 && gap <= 1e-7 * value.abs() * (1.0 + 1e-9),
                "gap {gap} for {value}"
            );
            // At least as good as the default tensions (within the gap).
            let (default, _) = objective(objective_name, u, &k0, &c0, &f_default);
            let better = if larger { value >= default - gap } else { value <= default + gap };
            assert!(better, "{name} {objective_name}: {value} vs default {default}");
            println!(
                "{name} {objective_name}: value {value:.9e} (default {default:.9e}), gap {gap:.1e}, {} iterations",
                doc["iterations"]
            );
            assert!(doc["iterations"].as_u64().unwrap() >= 1);
            let levels = &doc["levels"];
            if model == PatternModel::Decoupled {
                let l = numbers(levels);
                assert_eq!(l.len(), 5);
                assert!(l.iter().all(|v| (0.0..=1.0).contains(v)), "{l:?}");
            }
            assert_eq!(numbers(&doc["lambda"]).len(), 5);
        }
    }
}
