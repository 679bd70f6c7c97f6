//! `sinew export mjcf`: the file is the library's `sinew_mjcf::to_mjcf` with the tensions the
//! library chooses for the same options (levels, policy, plan), and every bad input gives one
//! line, exit 2 or 1, and no file.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use nalgebra::{Vector3, Vector6};
use sinew::paper::{E4_F0, E4_Q};
use sinew::planner::{Objective, PlanSettings, Planner, PlannerData, Requirements};
use sinew::statics::{TensionChoice, TensionPolicy};
use sinew::stiffness::{ArmStiffness, ArmStiffnessData};
use sinew_mjcf::{CableModel, MjcfOptions, Split, State, to_mjcf};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sinew")).args(args).output().expect("the sinew binary runs")
}

fn robot_dir(name: &str) -> PathBuf {
    sinew_testkit::cdhrm5::workspace_root().join("robots").join(name)
}

fn csv(values: &[f64]) -> String {
    values.iter().map(|v| format!("{v:?}")).collect::<Vec<_>>().join(",")
}

fn load(name: &str, file: &str) -> (sinew::robot::Robot, sinew::routing::Routing) {
    let robot = sinew::robot::load(robot_dir(name)).unwrap();
    let routing = sinew::routing::load(robot_dir(name).join(file), &robot).unwrap();
    (robot, routing)
}

fn state<'a>(q: &'a [f64], f: &'a [f64], w: &Vector6<f64>) -> State<'a> {
    State { q, tensions: f, wrench: [w[0], w[1], w[2], w[3], w[4], w[5]], segment_tensions: None }
}

fn written(out: &Output, path: &Path) -> String {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    std::fs::read_to_string(path).unwrap()
}

#[test]
fn levels_write_the_library_model_with_the_library_tensions() {
    let tmp = tempfile::tempdir().unwrap();
    let (robot, routing) = load("cdhrm5", "cables-routed.toml");
    let levels = [0.0, 0.0, 1.0, 0.0, 1.0];
    let e4_f0 = Vector6::from_column_slice(&E4_F0);
    let arm = ArmStiffness::new(&robot, &routing).unwrap();
    let mut data = ArmStiffnessData::new(&arm);
    arm.set_pose(&mut data, &E4_Q, &e4_f0).unwrap();
    arm.set_tensions(&mut data, TensionChoice::Levels(&levels)).unwrap();
    for (cables, split, model) in [
        ("springs", None, MjcfOptions::default()),
        ("motors", None, MjcfOptions { cables: CableModel::Motors, ..MjcfOptions::default() }),
        (
            "springs",
            Some("segments"),
            MjcfOptions { split: Split::Segments, ..MjcfOptions::default() },
        ),
    ] {
        let path = tmp.path().join(format!("{cables}-{split:?}.xml"));
        let dir = robot_dir("cdhrm5");
        let mut args = vec![
            "export",
            "mjcf",
            "--robot",
            dir.to_str().unwrap(),
            "--model",
            "routed",
            "--cables",
            cables,
            "--out",
            path.to_str().unwrap(),
        ];
        let (q, w, l) = (csv(&E4_Q), csv(&E4_F0), csv(&levels));
        args.extend(["--q", &q, "--wrench", &w, "--levels", &l]);
        if let Some(split) = split {
            args.extend(["--split", split]);
        }
        let text = written(&run(&args), &path);
        let expect =
            to_mjcf(&robot, &routing, &state(&E4_Q, data.tensions(), &e4_f0), &model).unwrap();
        assert_eq!(text, expect, "{cables} {split:?}");
    }
}

#[test]
fn a_policy_and_a_plan_choose_as_sinew_arm_and_sinew_plan_do() {
    let tmp = tempfile::tempdir().unwrap();
    let (robot, routing) = load("ua3x4", "cables.toml");
    let q = [0.2, -0.3, 0.25, 0.1, -0.15, 0.3];
    let f0 = Vector6::new(0.0, 2.0, 0.0, 0.0, 0.0, 0.0);
    let arm = ArmStiffness::new(&robot, &routing).unwrap();
    let mut data = ArmStiffnessData::new(&arm);
    arm.set_pose(&mut data, &q, &f0).unwrap();
    arm.set_tensions(&mut data, TensionChoice::Policy(TensionPolicy::Safest)).unwrap();
    let path = tmp.path().join("safest.xml");
    let dir = robot_dir("ua3x4");
    let (qs, ws) = (csv(&q), csv(f0.as_slice()));
    let base = ["export", "mjcf", "--robot", dir.to_str().unwrap(), "--q", &qs, "--wrench", &ws];
    let mut args = base.to_vec();
    args.extend(["--policy", "safest", "--out", path.to_str().unwrap(), "--damping", "0.2"]);
    let text = written(&run(&args), &path);
    let options = MjcfOptions { damping: 0.2, ..MjcfOptions::default() };
    assert_eq!(
        text,
        to_mjcf(&robot, &routing, &state(&q, data.tensions(), &f0), &options).unwrap()
    );

    let planner = Planner::new(ArmStiffness::new(&robot, &routing).unwrap().checking_limits());
    let mut pd = PlannerData::new(&planner);
    let objective = Objective::StiffnessAlong(Vector3::new(0.0, 1.0, 0.0));
    let plan = planner
        .plan(&mut pd, &q, &f0, objective, &Requirements::default(), &PlanSettings::default())
        .unwrap();
    let path = tmp.path().join("plan.xml");
    let mut args = base.to_vec();
    args.extend([
        "--plan",
        "stiffness-along",
        "--direction",
        "0,2,0",
        "--json",
        "--out",
        path.to_str().unwrap(),
    ]);
    let out = run(&args);
    let text = written(&out, &path);
    assert_eq!(
        text,
        to_mjcf(&robot, &routing, &state(&q, &plan.tensions, &f0), &MjcfOptions::default())
            .unwrap()
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["tensions_from"], "plan:stiffness-along");
    assert_eq!(doc["tensions"].as_array().unwrap().len(), 12);
}

#[test]
fn bad_input_is_one_line_exit_2_or_1_and_no_file() {
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("never.xml");
    let out_path = path.to_str().unwrap();
    let dir = robot_dir("cdhrm5");
    let robot = dir.to_str().unwrap();
    let e4 = csv(&E4_Q);
    let mut outside = E4_Q;
    outside[0] = -0.6;
    let outside = csv(&outside);
    let cases: [(Vec<&str>, u8, &str); 6] = [
        (vec!["--q", &e4, "--bogus", "1"], 2, "--bogus"),
        (vec!["--q", &outside], 2, "--q"),
        (vec!["--q", &e4, "--wrench", "0,500,0,0,0,0"], 1, "infeasible"),
        (vec!["--q", &e4, "--cables", "motors", "--split", "segments"], 2, "--split"),
        (vec!["--q", &e4, "--levels", "0,0,0,0,0", "--plan", "volume"], 2, "--plan"),
        (vec!["--q", &e4, "--damping", "-1"], 2, "--damping"),
    ];
    for (extra, code, needle) in cases {
        let mut args = vec!["export", "mjcf", "--robot", robot, "--out", out_path];
        args.extend(extra.iter().copied());
        let out = run(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(i32::from(code)), "{extra:?}: {stderr}");
        assert!(stderr.contains(needle), "{extra:?}: {stderr}");
        // clap's own usage errors (unknown option, conflicting options) print a usage hint.
        if !["--bogus", "--plan"].contains(&needle) {
            assert_eq!(stderr.trim().lines().count(), 1, "{extra:?}: {stderr}");
        }
        assert!(!path.exists(), "{extra:?} wrote a file");
        assert_eq!(std::fs::read_dir(tmp.path()).unwrap().count(), 0, "{extra:?} left a file");
    }
}
