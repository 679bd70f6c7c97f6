//! `sinew plan --trajectory`: the rows of a CSV trajectory planned step by step, CSV and JSON
//! out, each step's value equal to `sinew plan` at that pose within the two gaps, the rate
//! limit held, and bad files and rates refused with one line and exit 2.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;
use sinew::paper::{E4_F0, E4_Q};

fn robot() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots/cdhrm5")
}

fn sinew(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sinew")).args(args).output().unwrap()
}

fn csv(values: &[f64]) -> String {
    values.iter().map(|v| format!("{v}")).collect::<Vec<_>>().join(",")
}

/// 20 steps at 1 kHz near E4, the wrench on each row.
fn trajectory_file(name: &str) -> (PathBuf, Vec<Vec<f64>>) {
    let dir = std::env::temp_dir().join(format!("sinew-trajectory-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("steps.csv");
    let mut text =
        String::from("# q1..q10, FX..MZ\nq1,q2,q3,q4,q5,q6,q7,q8,q9,q10,fx,fy,fz,mx,my,mz\n");
    let mut poses = Vec::new();
    for k in 0..20 {
        // Towards zero from E4 (whose joint 3 sits at its limit), up to 5 %.
        let q: Vec<f64> = (0..10)
            .map(|j| {
                let omega = 0.5 + 14.5 * j as f64 / 9.0;
                E4_Q[j] * (1.0 - 0.05 * (omega * k as f64 * 1e-3).sin().abs())
            })
            .collect();
        text.push_str(&format!("{},{}\n", csv(&q), csv(&E4_F0)));
        poses.push(q);
    }
    std::fs::write(&path, text).unwrap();
    (path, poses)
}

#[test]
fn a_trajectory_is_planned_step_by_step_as_single_plans_would_be() {
    let (path, poses) = trajectory_file("json");
    let robot = robot();
    let (robot, path) = (robot.to_str().unwrap(), path.to_str().unwrap());
    let out =
        sinew(&["plan", "--robot", robot, "--trajectory", path, "--objective", "volume", "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
    let steps = doc["steps"].as_array().unwrap();
    assert_eq!(steps.len(), 20);
    assert!(doc["warm_steps"].as_u64().unwrap() >= 15, "{}", doc["warm_steps"]);
    for k in [0, 9, 19] {
        let step = &steps[k];
        assert_eq!(step["ok"], true);
        let single = sinew(&[
            "plan",
            "--robot",
            robot,
            "--q",
            &csv(&poses[k]),
            "--wrench",
            &csv(&E4_F0),
            "--objective",
            "volume",
            "--json",
        ]);
        let single: Value = serde_json::from_slice(&single.stdout).unwrap();
        let (a, b) = (step["value"].as_f64().unwrap(), single["value"].as_f64().unwrap());
        let gaps = step["gap"].as_f64().unwrap() + single["gap"].as_f64().unwrap();
        assert!((a - b).abs() <= gaps, "step {k}: {a} vs {b}");
    }
    // CSV: a header and one line per step, the cables' tensions in routing order.
    let out = sinew(&["plan", "--robot", robot, "--trajectory", path, "--objective", "volume"]);
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 21);
    assert!(
        lines[0].starts_with("step,ok,warm,iterations,value,gap,total_tension,min_eigenvalue,f_")
    );
    assert_eq!(lines[0].split(',').count(), lines[1].split(',').count());
}

#[test]
fn the_rate_limit_holds_and_bad_input_is_refused() {
    let (path, _) = trajectory_file("rate");
    let robot = robot();
    let (robot, path_s) = (robot.to_str().unwrap(), path.to_str().unwrap());
    let out = sinew(&[
        "plan",
        "--robot",
        robot,
        "--trajectory",
        path_s,
        "--objective",
        "volume",
        "--rate",
        "500",
        "--dt",
        "0.001",
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
    let tensions: Vec<Vec<f64>> = doc["steps"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|s| {
            s["tensions"].as_array().map(|t| t.iter().map(|v| v.as_f64().unwrap()).collect())
        })
        .collect();
    assert!(tensions.len() >= 2);
    for pair in tensions.windows(2) {
        let change = pair[0].iter().zip(&pair[1]).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(change <= 0.5 * (1.0 + 1e-9) + 1e-9, "change {change} N");
    }
    for (args, names) in [
        (vec!["--rate", "-5", "--dt", "0.001"], "--rate"),
        (vec!["--rate", "5", "--dt", "0,1"], "--dt"),
    ] {
        let mut all =
            vec!["plan", "--robot", robot, "--trajectory", path_s, "--objective", "volume"];
        all.extend(args);
        let out = sinew(&all);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
        assert!(stderr.contains(names), "{stderr}");
    }
    let bad = path.with_file_name("bad.csv");
    std::fs::write(&bad, "q\n0.1,0.2\n").unwrap();
    let out = sinew(&[
        "plan",
        "--robot",
        robot,
        "--trajectory",
        bad.to_str().unwrap(),
        "--objective",
        "volume",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("bad.csv:2") && stderr.contains("expected 10"), "{stderr}");
}
