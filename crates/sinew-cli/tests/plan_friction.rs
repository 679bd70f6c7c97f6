//! `sinew plan --friction` (spec §9, #27) on cdhrm5 at the loaded pose: a plan in the stick
//! regime is the library's (`Planner::plan_in_stick`), μ = 0 is the frictionless document byte
//! for byte, and what is not planned (a slip regime, stick at μ = 0, friction along a
//! trajectory) is one line on standard error, exit 2, nothing on standard output.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::process::{Command, Output};

use nalgebra::{Vector3, Vector6};
use serde_json::Value;
use sinew::planner::{Objective, PlanSettings, Planner, PlannerData, Requirements, StickPlanData};
use sinew::routing::FrictionModel;
use sinew::stiffness::{ArmStiffness, History};
use sinew_testkit::cdhrm5;

const Q: &str = "-0.45,-0.35,-0.35,-0.29,0.52,0.45,0.39,-0.21,-0.26,-0.31";

fn run(extra: &[&str]) -> Output {
    let robot = cdhrm5::dir();
    let mut args = vec!["plan", "--robot", robot.to_str().unwrap(), "--q", Q];
    args.extend(["--wrench", "0,5,0,0,0,0", "--objective", "stiffness-along"]);
    args.extend(["--direction", "0,1,0"]);
    args.extend(extra);
    Command::new(env!("CARGO_BIN_EXE_sinew")).args(&args).output().unwrap()
}

fn nums(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

#[test]
fn a_stick_plan_is_the_librarys_and_mu_zero_is_the_frictionless_plan() {
    let plain = run(&["--json"]);
    assert!(plain.status.success());
    let zero = run(&["--json", "--friction", "0"]);
    assert_eq!(zero.stdout, plain.stdout, "μ = 0 must be the frictionless plan byte for byte");
    let (robot, routing) = cdhrm5::robot_and_routing(sinew::routing::PatternModel::Decoupled);
    let planner = Planner::new(ArmStiffness::new(&robot, &routing).unwrap());
    let model = FrictionModel::new(&routing).with_friction_coefficient(0.1).unwrap();
    let mut data = PlannerData::new(&planner);
    let mut stick = StickPlanData::new(&planner, &model);
    let q: Vec<f64> = Q.split(',').map(|x| x.parse().unwrap()).collect();
    let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    for (history, word) in [(History::Pull, "pull"), (History::Equal, "equal")] {
        let out = run(&["--json", "--friction", "0.1", "--history", word]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(doc["friction"]["regime"], "stick");
        assert_eq!(doc["friction"]["history"], word);
        assert_eq!(nums(&doc["friction"]["mu"]), vec![0.1; 15]);
        let plan = planner
            .plan_in_stick(
                &mut data,
                &mut stick,
                (&model, history),
                &q,
                &f0,
                Objective::StiffnessAlong(Vector3::y()),
                &Requirements::default(),
                &PlanSettings::default(),
            )
            .unwrap();
        assert_eq!(doc["value"].as_f64().unwrap(), plan.value, "{word}");
        assert_eq!(nums(&doc["tensions"]), plan.tensions, "{word}");
        assert_eq!(doc["min_eigenvalue"].as_f64().unwrap(), plan.min_eigenvalue, "{word}");
        // Far stiffer than the frictionless plan: the free length no longer counts.
        let free: Value = serde_json::from_slice(&plain.stdout).unwrap();
        assert!(plan.value > 10.0 * free["value"].as_f64().unwrap(), "{word}");
    }
    // The text names the regime.
    let text = run(&["--friction", "0.1"]);
    assert!(
        String::from_utf8_lossy(&text.stdout).contains("friction at the holes: stick after pull")
    );
}

#[test]
fn what_is_not_planned_is_one_line_and_exit_2() {
    for (extra, says) in [
        (vec!["--friction", "0.1", "--regime", "pull"], "slip regime is not planned"),
        (vec!["--friction", "0.1", "--regime", "release"], "slip regime is not planned"),
        (vec!["--friction", "0", "--regime", "stick"], "μ = 0"),
        (vec!["--friction", "-1"], "--friction"),
        (vec!["--friction", "0.1", "--fixed-level", "1:0.5"], "stick regime"),
    ] {
        let out = run(&extra);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {stderr}");
        assert!(out.stdout.is_empty(), "{extra:?}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{extra:?}: {stderr}");
        assert!(stderr.contains(says), "{extra:?}: {stderr}");
    }
    // Along a trajectory: not offered (one pose at a time).
    let dir = std::env::temp_dir().join(format!("sinew-plan-friction-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("steps.csv");
    std::fs::write(&csv, format!("{Q}\n{Q}\n")).unwrap();
    let robot = cdhrm5::dir();
    let args = [
        "plan",
        "--robot",
        robot.to_str().unwrap(),
        "--trajectory",
        csv.to_str().unwrap(),
        "--wrench",
        "0,5,0,0,0,0",
        "--objective",
        "min-stiffness",
        "--friction",
        "0.1",
    ];
    let out = Command::new(env!("CARGO_BIN_EXE_sinew")).args(args).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(out.stdout.is_empty() && stderr.contains("--trajectory"), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}
