//! The `sinew` binary on cdhrm5: its JSON equals the library's numbers, `--deg` equals
//! radians, and every bad input gives one line on standard error and a non-zero exit.
//!
//! Each test copies `robots/cdhrm5` into a temporary folder first, so that the binary and the
//! library read the same files even while the robot's values are being recalibrated.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;
use std::process::{Command, Output};

use faer::MatRef;
use nalgebra::{Matrix2, Matrix3, Vector3, Vector6};
use serde_json::Value;
use sinew::indicators::{AngleGrid, JointProbe, StiffnessEllipsoid, sweep_joint};
use sinew::paper::{E4_F0, E4_Q, e3_csv};
use sinew::robot::{Robot, RobotDescription};
use sinew::routing::Routing;
use sinew::statics::TensionChoice;
use sinew::stiffness::{ArmStiffness, ArmStiffnessData, StiffnessError};
use tempfile::TempDir;

/// A private copy of cdhrm5, loaded through the library.
struct Fixture {
    dir: TempDir,
    robot: Robot,
    routing: Routing,
    routed: Routing,
}

impl Fixture {
    fn new() -> Fixture {
        let dir = tempfile::tempdir().unwrap();
        for entry in std::fs::read_dir(sinew_testkit::cdhrm5::dir()).unwrap() {
            let entry = entry.unwrap();
            if entry.file_type().unwrap().is_file() {
                std::fs::copy(entry.path(), dir.path().join(entry.file_name())).unwrap();
            }
        }
        let robot = sinew::robot::load(dir.path()).unwrap();
        let routing =
            sinew::routing::load(dir.path().join(sinew::routing::ROUTING_FILE), &robot).unwrap();
        let routed =
            sinew::routing::load(dir.path().join(sinew::routing::ROUTED_ROUTING_FILE), &robot)
                .unwrap();
        Fixture { dir, robot, routing, routed }
    }

    fn path(&self) -> &str {
        self.dir.path().to_str().unwrap()
    }
}

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sinew"))
        .args(args)
        .env("RUST_BACKTRACE", "1")
        .output()
        .expect("the sinew binary runs")
}

/// Run, expect success, parse standard output as JSON.
fn json(args: &[&str]) -> Value {
    let out = run(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "sinew {args:?} failed: {stderr}");
    serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("sinew {args:?}: stdout is not JSON ({e})"))
}

fn list(xs: &[f64]) -> String {
    // `{}` prints the shortest text that reads back to the same f64.
    xs.iter().map(|x| format!("{x}")).collect::<Vec<_>>().join(",")
}

fn close(a: f64, b: f64) -> bool {
    a == b || (a - b).abs() <= 1e-12 * a.abs().max(b.abs())
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("{v} is not a number"))
}

fn assert_num(v: &Value, expected: f64, what: &str) {
    let got = num(v);
    assert!(close(got, expected), "{what}: JSON {got} vs library {expected}");
}

fn assert_vec(v: &Value, expected: &[f64], what: &str) {
    let items = v.as_array().unwrap_or_else(|| panic!("{what}: {v} is not an array"));
    assert_eq!(items.len(), expected.len(), "{what}: length");
    for (k, (item, &e)) in items.iter().zip(expected).enumerate() {
        assert_num(item, e, &format!("{what}[{k}]"));
    }
}

fn assert_rows(v: &Value, rows: usize, cols: usize, at: impl Fn(usize, usize) -> f64, what: &str) {
    let items = v.as_array().unwrap_or_else(|| panic!("{what}: {v} is not an array of rows"));
    assert_eq!(items.len(), rows, "{what}: rows");
    for (i, row) in items.iter().enumerate() {
        let row = row.as_array().unwrap_or_else(|| panic!("{what}[{i}] is not a row"));
        assert_eq!(row.len(), cols, "{what}[{i}]: columns");
        for (j, x) in row.iter().enumerate() {
            assert_num(x, at(i, j), &format!("{what}[{i}][{j}]"));
        }
    }
}

fn assert_faer(v: &Value, m: MatRef<'_, f64>, what: &str) {
    assert_rows(v, m.nrows(), m.ncols(), |i, j| m[(i, j)], what);
}

fn assert_m2(v: &Value, m: &Matrix2<f64>, what: &str) {
    assert_rows(v, 2, 2, |i, j| m[(i, j)], what);
}

fn assert_m3(v: &Value, m: &Matrix3<f64>, what: &str) {
    assert_rows(v, 3, 3, |i, j| m[(i, j)], what);
}

// ---------------------------------------------------------------------------------------------
// routing

fn check_routing(fx: &Fixture, model: &str, routing: &Routing) {
    let doc = json(&["routing", "--robot", fx.path(), "--model", model, "--json"]);
    let description = RobotDescription::read(fx.dir.path()).unwrap();
    assert_eq!(doc["command"], "routing");
    assert_eq!(doc["urdf"], description.urdf.display().to_string());
    assert_eq!(doc["tip_link"], description.settings.tip_link);
    let g = fx.robot.gravity();
    assert_vec(&doc["gravity"], &[g.x, g.y, g.z], "gravity");
    assert_eq!(doc["model"], model);
    assert_vec(&doc["tension_limits"], &routing.tension_limits(), "tension_limits");
    assert_num(&doc["youngs_modulus"], routing.youngs_modulus(), "youngs_modulus");
    assert_num(&doc["area"], routing.area(), "area");
    let joints = doc["joints"].as_array().unwrap();
    assert_eq!(joints.len(), fx.robot.dof());
    for (k, (j, lib)) in joints.iter().zip(fx.robot.joints()).enumerate() {
        assert_eq!(j["index"], k);
        assert_eq!(j["name"], lib.name.as_str());
        assert_eq!(j["joint"], k / 2);
        assert_eq!(j["axis_index"], k % 2);
        assert_vec(&j["axis"], &[lib.axis.x, lib.axis.y, lib.axis.z], "axis");
        assert_num(&j["lower"], lib.lower, "lower");
        assert_num(&j["upper"], lib.upper, "upper");
    }
    let cables = doc["cables"].as_array().unwrap();
    assert_eq!(cables.len(), routing.cable_count());
    let [f_min, f_max] = routing.tension_limits();
    for (c, lib) in cables.iter().zip(routing.cables()) {
        assert_eq!(c["name"], lib.name.as_str());
        assert_eq!(c["joint"], lib.joint, "cable {}: 0-based joint", lib.name);
        assert_num(&c["stiffness"], lib.stiffness, "stiffness");
        assert_num(&c["elastic_length"], lib.elastic_length, "elastic_length");
        assert_num(&c["free_length"], lib.free_length, "free_length");
        assert_num(&c["routed_length"], lib.routed_length, "routed_length");
        assert_num(&c["f_min"], f_min, "f_min");
        assert_num(&c["f_max"], f_max, "f_max");
        let holes = c["holes"].as_array().unwrap();
        assert_eq!(holes.len(), lib.holes.len(), "cable {}: holes", lib.name);
        for (h, lh) in holes.iter().zip(&lib.holes) {
            assert_eq!(h["link"], lh.link.as_str());
            assert_vec(&h["point"], lh.point.as_slice(), "hole point");
        }
    }
}

#[test]
fn routing_json_equals_the_library_in_both_models() {
    let fx = Fixture::new();
    check_routing(&fx, "decoupled", &fx.routing);
    check_routing(&fx, "routed", &fx.routed);
    // The routed model really is the other file: more holes per distal cable.
    let last = fx.routed.cables().last().unwrap();
    assert!(last.holes.len() > fx.routing.cables().last().unwrap().holes.len());
}

// ---------------------------------------------------------------------------------------------
// joint

fn check_joint(fx: &Fixture, joint: usize, q: [f64; 2], tau: [f64; 2]) {
    check_joint_in(fx, "decoupled", joint, q, tau);
}

/// The fixture's routing of a model (`decoupled` or `routed`).
fn routing_of<'a>(fx: &'a Fixture, model: &str) -> &'a Routing {
    if model == "routed" { &fx.routed } else { &fx.routing }
}

/// `sinew joint … --model <model> --json` against the library's probe on that model's routing;
/// returns the document.
fn check_joint_in(fx: &Fixture, model: &str, joint: usize, q: [f64; 2], tau: [f64; 2]) -> Value {
    let number = (joint + 1).to_string();
    let (qs, ts) = (list(&q), list(&tau));
    let args = ["joint", "--robot", fx.path(), "--joint", &number, "--q", &qs, "--torque", &ts];
    let doc = json(&[&args[..], &["--model", model, "--json"]].concat());
    let routing = routing_of(fx, model);
    let mut probe = JointProbe::new(&fx.robot, routing, joint).unwrap();
    let range = probe.evaluate(&fx.robot, routing, q, tau).unwrap();
    assert_eq!(doc["command"], "joint");
    assert_eq!(doc["model"], model);
    assert_eq!(doc["joint"], joint, "JSON joint is 0-based");
    assert_vec(&doc["q"], &q, "q");
    assert_vec(&doc["torque"], &tau, "torque");
    let iv = &range.interval;
    assert_vec(&doc["lambda"], &[iv.lambda_min, iv.lambda_max], "lambda");
    let (lo, hi) = iv.ends();
    assert_vec(&doc["tensions"][0], lo.as_slice(), "tensions at λ_min");
    assert_vec(&doc["tensions"][1], hi.as_slice(), "tensions at λ_max");
    assert_vec(&doc["particular"], iv.particular.as_slice(), "particular");
    assert_vec(&doc["null_direction"], iv.null.as_slice(), "null_direction");
    assert_m2(&doc["k_controllable"][0], &range.controllable[0], "k_controllable at min");
    assert_m2(&doc["k_controllable"][1], &range.controllable[1], "k_controllable at max");
    assert_m2(&doc["k_inherent"][0], &range.inherent, "k_inherent at min");
    assert_m2(&doc["k_inherent"][1], &range.inherent, "k_inherent at max");
    assert_m2(&doc["k"][0], &range.k_at_min, "k at min");
    assert_m2(&doc["k"][1], &range.k_at_max, "k at max");
    for (key, sigma) in [("sigma_x", range.sigma_x()), ("sigma_y", range.sigma_y())] {
        assert_vec(&doc[key][0], &sigma.range, key);
        assert_num(&doc[key][1], sigma.delta, key);
    }
    let names: Vec<&str> =
        routing.cables().iter().filter(|c| c.joint == joint).map(|c| c.name.as_str()).collect();
    assert_eq!(doc["cables"], serde_json::json!(names));
    doc
}

#[test]
fn joint_json_equals_the_library() {
    let fx = Fixture::new();
    let pi6 = std::f64::consts::FRAC_PI_6;
    check_joint(&fx, 0, [pi6, pi6], [0.3, 0.3]);
    check_joint(&fx, 0, [0.3, -0.2], [0.3, 0.3]);
    check_joint(&fx, 2, [-0.25, 0.1], [-0.5, 0.2]);
}

#[test]
fn joint_routed_equals_the_library_and_differs_from_decoupled() {
    let fx = Fixture::new();
    let (q, tau) = ([-0.25, 0.1], [-0.5, 0.2]);
    let routed = check_joint_in(&fx, "routed", 2, q, tau);
    check_joint_in(&fx, "routed", 4, [0.3, -0.2], [0.3, 0.3]);
    // `--model routed` is not ignored: joint 3's cables pass joints 1 and 2 there.
    let decoupled = check_joint_in(&fx, "decoupled", 2, q, tau);
    assert_ne!(routed["k"], decoupled["k"]);
}

#[test]
fn joint_deg_equals_radians() {
    let fx = Fixture::new();
    let base = ["joint", "--robot", fx.path(), "--joint", "2", "--torque", "0.3,0.3", "--json"];
    let deg = json(&[&base[..], &["--q", "20,-10", "--deg"]].concat());
    let q = list(&[20f64.to_radians(), (-10f64).to_radians()]);
    let rad = json(&[&base[..], &["--q", &q]].concat());
    assert_eq!(deg, rad);
}

// ---------------------------------------------------------------------------------------------
// arm

/// The library's evaluation of the arm, and its outcome.
fn library_arm(
    robot: &Robot,
    routing: &Routing,
    q: &[f64],
    f0: &[f64; 6],
    levels: &[f64],
) -> (ArmStiffnessData, Result<(), StiffnessError>) {
    let arm = ArmStiffness::new(robot, routing).unwrap();
    let mut data = ArmStiffnessData::new(&arm);
    let outcome =
        arm.evaluate(&mut data, q, &Vector6::from_column_slice(f0), TensionChoice::Levels(levels));
    (data, outcome)
}

fn check_arm(doc: &Value, data: &mut ArmStiffnessData, outcome: &Result<(), StiffnessError>) {
    assert_eq!(doc["command"], "arm");
    assert_vec(&doc["t0"], &data.statics.t0, "t0");
    assert_vec(&doc["tensions"], data.tensions(), "tensions");
    assert_faer(&doc["k_q"], data.k_q(), "k_q");
    assert_faer(&doc["k_w"], data.k_w(), "k_w");
    assert_faer(&doc["k_controllable"], data.k_controllable(), "k_controllable");
    assert_faer(&doc["k_inherent"], data.k_inherent(), "k_inherent");
    assert_faer(&doc["j_x"], data.j_x(), "j_x");
    let margin = data.stability_margin().unwrap();
    assert_num(&doc["min_eigenvalue"], margin, "min_eigenvalue");
    for (k, (iv, lib)) in
        doc["intervals"].as_array().unwrap().iter().zip(data.intervals()).enumerate()
    {
        assert_eq!(iv["joint"], k);
        assert_vec(&iv["lambda"], &[lib.lambda_min, lib.lambda_max], "interval lambda");
        assert_m2(&iv["k_joint"], &data.joint_stiffness(k).unwrap(), "k_joint");
    }
    match outcome {
        Ok(()) => {
            assert_eq!(doc["stable"], true);
            assert_faer(&doc["c_x"], data.compliance(), "c_x");
            assert_faer(&doc["k_x"], data.stiffness(), "k_x");
            assert_m3(&doc["k_fd"], &data.k_fd(), "k_fd");
            assert_m3(&doc["k_translational"], &data.translational_stiffness().unwrap(), "k_t");
            let e = StiffnessEllipsoid::new(&data.k_fd()).unwrap();
            let el = &doc["ellipsoid"];
            assert_vec(&el["eigenvalues"], e.eigenvalues.as_slice(), "eigenvalues");
            assert_rows(&el["directions"], 3, 3, |k, i| e.directions[(i, k)], "directions");
            assert_num(&el["lambda_min"], e.lambda_min(), "lambda_min");
            match e.semi_axes() {
                Some(a) => assert_vec(&el["semi_axes"], a.as_slice(), "semi_axes"),
                None => assert!(el["semi_axes"].is_null()),
            }
            match e.condition_number() {
                Some(c) => assert_num(&el["condition_number"], c, "condition_number"),
                None => assert!(el["condition_number"].is_null()),
            }
            match e.volume() {
                Some(v) => assert_num(&el["volume"], v, "volume"),
                None => assert!(el["volume"].is_null()),
            }
        }
        Err(StiffnessError::Unstable { min_eigenvalue }) => {
            assert_eq!(doc["stable"], false);
            assert_num(&doc["min_eigenvalue"], *min_eigenvalue, "min_eigenvalue (unstable)");
            for key in ["c_x", "k_x", "k_fd", "k_translational", "ellipsoid"] {
                assert!(doc[key].is_null(), "{key} is null when unstable");
            }
        }
        Err(StiffnessError::RankDeficient { .. }) => {
            assert_eq!(doc["stable"], true);
            assert_faer(&doc["c_x"], data.compliance(), "c_x");
            for key in ["k_x", "k_fd", "ellipsoid"] {
                assert!(doc[key].is_null(), "{key} is null when J_x is rank-deficient");
            }
            assert!(doc["notes"].to_string().contains("rank"), "a note says why");
            if !doc["k_translational"].is_null() {
                let k_t = data.translational_stiffness().unwrap();
                assert_m3(&doc["k_translational"], &k_t, "k_translational");
            }
        }
        Err(e) => panic!("unexpected library error: {e}"),
    }
}

#[test]
fn arm_json_equals_the_library_at_e4() {
    let fx = Fixture::new();
    let levels = [0.5; 5];
    let (q, f0, s) = (list(&E4_Q), list(&E4_F0), list(&levels));
    let doc =
        json(&["arm", "--robot", fx.path(), "--q", &q, "--wrench", &f0, "--levels", &s, "--json"]);
    let (mut data, outcome) = library_arm(&fx.robot, &fx.routing, &E4_Q, &E4_F0, &levels);
    check_arm(&doc, &mut data, &outcome);
    assert_vec(&doc["q"], &E4_Q, "q");
    assert_vec(&doc["wrench"], &E4_F0, "wrench");
    assert_vec(&doc["levels"], &levels, "levels");
}

#[test]
fn arm_defaults_routed_and_no_gravity_equal_the_library() {
    let fx = Fixture::new();
    let q = list(&E4_Q);
    // Defaults: zero wrench, every level 0, gravity on, decoupled.
    let doc = json(&["arm", "--robot", fx.path(), "--q", &q, "--json"]);
    let (mut data, outcome) = library_arm(&fx.robot, &fx.routing, &E4_Q, &[0.0; 6], &[0.0; 5]);
    check_arm(&doc, &mut data, &outcome);
    // Routed, gravity off, a load and mixed levels.
    let levels = [0.2, 0.4, 1.0, 0.0, 0.7];
    let (f0, s) = ([0.0, 2.0, 0.0, 0.0, 0.0, 0.1], list(&levels));
    let wrench = list(&f0);
    let doc = json(&[
        "arm",
        "--robot",
        fx.path(),
        "--q",
        &q,
        "--wrench",
        &wrench,
        "--levels",
        &s,
        "--model",
        "routed",
        "--no-gravity",
        "--json",
    ]);
    let weightless = fx.robot.with_gravity(Vector3::zeros());
    let (mut data, outcome) = library_arm(&weightless, &fx.routed, &E4_Q, &f0, &levels);
    check_arm(&doc, &mut data, &outcome);
    assert_vec(&doc["gravity"], &[0.0; 3], "gravity");
    assert_eq!(doc["model"], "routed");
}

#[test]
fn arm_deg_equals_radians() {
    let fx = Fixture::new();
    let deg = [-25.0, -20.0, -20.0, -15.0, 30.0, 25.0, 20.0, -10.0, -15.0, -20.0];
    let rad: Vec<f64> = deg.iter().map(|d: &f64| d.to_radians()).collect();
    let base = ["arm", "--robot", fx.path(), "--wrench", "0,5,0,0,0,0", "--json"];
    let a = json(&[&base[..], &["--q", &list(&deg), "--deg"]].concat());
    let b = json(&[&base[..], &["--q", &list(&rad)]].concat());
    assert_eq!(a, b);
}

#[test]
fn an_unstable_equilibrium_is_a_result_with_null_end_stiffness() {
    // Straight arm, no gravity, the end pushing along its own axis (+z) with 50 N: the
    // environment compresses the arm and it buckles (K_W ≈ −F·l per joint ≫ K_q).
    let fx = Fixture::new();
    let weightless = fx.robot.with_gravity(Vector3::zeros());
    let q = [0.0; 10];
    let f0 = [0.0, 0.0, 50.0, 0.0, 0.0, 0.0];
    let (mut data, outcome) = library_arm(&weightless, &fx.routing, &q, &f0, &[0.0; 5]);
    assert!(
        matches!(outcome, Err(StiffnessError::Unstable { .. })),
        "precondition: the library finds this load unstable ({outcome:?})"
    );
    let (qs, fs) = (list(&q), list(&f0));
    let args = ["arm", "--robot", fx.path(), "--q", &qs, "--wrench", &fs, "--no-gravity"];
    let doc = json(&[&args[..], &["--json"]].concat());
    check_arm(&doc, &mut data, &outcome);
    assert!(num(&doc["min_eigenvalue"]) < 0.0);
    // The tables say so too, with exit 0.
    let out = run(&args);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("UNSTABLE"), "{text}");
}

#[test]
fn a_rank_deficient_jacobian_reports_the_compliance_only() {
    // Straight arm pulled along its axis: stable, but J_x has no z row at Q = 0.
    let fx = Fixture::new();
    let weightless = fx.robot.with_gravity(Vector3::zeros());
    let q = [0.0; 10];
    let f0 = [0.0, 0.0, -50.0, 0.0, 0.0, 0.0];
    let (mut data, outcome) = library_arm(&weightless, &fx.routing, &q, &f0, &[0.0; 5]);
    assert!(
        matches!(outcome, Err(StiffnessError::RankDeficient { .. })),
        "precondition: rank-deficient J_x ({outcome:?})"
    );
    let (qs, fs) = (list(&q), list(&f0));
    let doc =
        json(&["arm", "--robot", fx.path(), "--q", &qs, "--wrench", &fs, "--no-gravity", "--json"]);
    check_arm(&doc, &mut data, &outcome);
}

// ---------------------------------------------------------------------------------------------
// sweep

#[test]
fn sweep_json_and_csv_equal_the_library() {
    let fx = Fixture::new();
    check_sweep(&fx, "decoupled", 0, [0.3, 0.3]);
}

#[test]
fn sweep_routed_equals_the_library() {
    let fx = Fixture::new();
    check_sweep(&fx, "routed", 2, [-0.5, 0.2]);
}

/// `sinew sweep … --model <model> --grid 5 --out maps.csv --json` against the library's sweep
/// on that model's routing: the JSON maps and the CSV file.
fn check_sweep(fx: &Fixture, model: &str, joint: usize, tau: [f64; 2]) {
    let csv = fx.dir.path().join(format!("maps-{model}.csv"));
    let csv_arg = csv.to_str().unwrap();
    let (number, ts) = ((joint + 1).to_string(), list(&tau));
    let doc = json(&[
        "sweep",
        "--robot",
        fx.path(),
        "--model",
        model,
        "--joint",
        &number,
        "--torque",
        &ts,
        "--grid",
        "5",
        "--out",
        csv_arg,
        "--json",
    ]);
    let x = &fx.robot.joints()[2 * joint];
    let grid = AngleGrid { lower: x.lower, upper: x.upper, points: 5 };
    let routing = routing_of(fx, model);
    let maps = sweep_joint(&fx.robot, routing, joint, tau, grid, &|_, _| {}).unwrap();
    assert!(maps.feasible() > 0, "{model}: nothing to compare");
    assert_eq!(doc["model"], model);
    assert_eq!(doc["joint"], joint);
    assert_eq!(doc["grid"]["points"], 5);
    let angles: Vec<f64> = (0..5).map(|k| grid.angle(k)).collect();
    assert_vec(&doc["grid"]["angles"], &angles, "angles");
    assert_eq!(doc["feasible"], maps.feasible());
    for a in 0..5 {
        for b in 0..5 {
            let cell = maps.cell(a, b);
            for (key, value) in [
                ("k_x_min", cell.map(|c| c.k_x.range[0])),
                ("k_x_max", cell.map(|c| c.k_x.range[1])),
                ("k_y_min", cell.map(|c| c.k_y.range[0])),
                ("k_y_max", cell.map(|c| c.k_y.range[1])),
            ] {
                let v = &doc[key][a][b];
                match value {
                    Some(x) => assert_num(v, x, &format!("{key}[{a}][{b}]")),
                    None => assert!(v.is_null(), "{key}[{a}][{b}] null where infeasible"),
                }
            }
        }
    }
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), e3_csv(&maps));
}

#[test]
fn sweep_marks_infeasible_points_null() {
    // A torque that only part of the grid can hold (6 of 9 points; 6 N m held all 9, so the
    // old case checked no null): nulls, not errors, beside numbers.
    let fx = Fixture::new();
    let doc = json(&[
        "sweep",
        "--robot",
        fx.path(),
        "--joint",
        "2",
        "--torque",
        "10,0",
        "--grid",
        "3",
        "--json",
    ]);
    let x = &fx.robot.joints()[2];
    let grid = AngleGrid { lower: x.lower, upper: x.upper, points: 3 };
    let maps = sweep_joint(&fx.robot, &fx.routing, 1, [10.0, 0.0], grid, &|_, _| {}).unwrap();
    assert_eq!(doc["feasible"], maps.feasible());
    // Mixed: both kinds present, or the check below proves nothing.
    assert!(0 < maps.feasible() && maps.feasible() < 9, "{} of 9 feasible", maps.feasible());
    for key in ["k_x_min", "k_x_max", "k_y_min", "k_y_max"] {
        for a in 0..3 {
            for b in 0..3 {
                let v = &doc[key][a][b];
                match maps.cell(a, b) {
                    Some(_) => assert!(v.is_f64(), "{key}[{a}][{b}] a number where feasible"),
                    None => assert!(v.is_null(), "{key}[{a}][{b}] null where infeasible"),
                }
            }
        }
    }
}

#[test]
fn sweep_out_without_json_writes_the_csv_and_prints_tables() {
    let fx = Fixture::new();
    let csv = fx.dir.path().join("tables.csv");
    let csv_arg = csv.to_str().unwrap();
    let args = [
        "sweep",
        "--robot",
        fx.path(),
        "--joint",
        "1",
        "--torque",
        "0.3,0.3",
        "--grid",
        "4",
        "--out",
        csv_arg,
    ];
    let out = run(&args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(serde_json::from_str::<Value>(&text).is_err(), "tables, not JSON:\n{text}");
    assert!(text.contains(&format!("wrote {csv_arg} (16 rows)")), "{text}");
    assert!(text.contains("K_x max"), "{text}");
    // With --out the per-point maps go to the file, not to the terminal.
    assert!(!text.contains("rows q1, columns q2"), "{text}");
    let x = &fx.robot.joints()[0];
    let grid = AngleGrid { lower: x.lower, upper: x.upper, points: 4 };
    let maps = sweep_joint(&fx.robot, &fx.routing, 0, [0.3, 0.3], grid, &|_, _| {}).unwrap();
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), e3_csv(&maps));
}

// ---------------------------------------------------------------------------------------------
// tables

#[test]
fn every_command_prints_tables_by_default() {
    let fx = Fixture::new();
    let q = list(&E4_Q);
    for (args, expect) in [
        (vec!["routing", "--robot", fx.path()], "j1c1"),
        (
            vec![
                "joint",
                "--robot",
                fx.path(),
                "--joint",
                "1",
                "--q",
                "0.3,-0.2",
                "--torque",
                "0.3,0.3",
            ],
            "σ_x",
        ),
        (vec!["arm", "--robot", fx.path(), "--q", &q, "--wrench", "0,5,0,0,0,0"], "K_q"),
        (
            vec![
                "sweep",
                "--robot",
                fx.path(),
                "--joint",
                "1",
                "--torque",
                "0.3,0.3",
                "--grid",
                "3",
            ],
            "K_x max",
        ),
    ] {
        let out = run(&args);
        assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
        let text = String::from_utf8(out.stdout).unwrap();
        assert!(text.contains(expect), "{args:?} prints {expect}:\n{text}");
        assert!(serde_json::from_str::<Value>(&text).is_err(), "tables, not JSON");
    }
}

// ---------------------------------------------------------------------------------------------
// bad input

/// Expect a failure with this exit code and one line on standard error, `sinew: …`,
/// containing every `needle`; nothing on standard output; no panic.
fn assert_fails(args: &[&str], code: i32, needles: &[&str]) {
    let out = run(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "sinew {args:?}: exit code; stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "sinew {args:?} panicked: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "sinew {args:?}: one line, got: {stderr}");
    assert!(stderr.starts_with("sinew: "), "sinew {args:?}: {stderr}");
    for needle in needles {
        assert!(stderr.contains(needle), "sinew {args:?}: `{needle}` missing from: {stderr}");
    }
    assert!(out.stdout.is_empty(), "sinew {args:?}: nothing on stdout");
}

#[test]
fn a_wrong_count_of_numbers_is_named() {
    let fx = Fixture::new();
    let r = fx.path();
    assert_fails(&["arm", "--robot", r, "--q", "0.1,0.2"], 2, &["--q", "expected 10", "got 2"]);
    assert_fails(
        &["joint", "--robot", r, "--joint", "1", "--q", "0.1", "--torque", "0,0"],
        2,
        &["--q", "expected 2", "got 1"],
    );
    let q = list(&E4_Q);
    assert_fails(&["arm", "--robot", r, "--q", &q, "--wrench", "0,5"], 2, &["--wrench", "6"]);
    assert_fails(&["arm", "--robot", r, "--q", &q, "--levels", "0,1"], 2, &["--levels", "5"]);
    assert_fails(
        &["sweep", "--robot", r, "--joint", "1", "--torque", "0.3", "--grid", "3"],
        2,
        &["--torque", "expected 2"],
    );
}

#[test]
fn an_unknown_joint_is_named() {
    let fx = Fixture::new();
    let r = fx.path();
    for joint in ["9", "0", "-1"] {
        assert_fails(
            &["joint", "--robot", r, "--joint", joint, "--q", "0,0", "--torque", "0,0"],
            2,
            &["--joint", joint, "5 universal joints"],
        );
    }
    assert_fails(
        &["sweep", "--robot", r, "--joint", "9", "--torque", "0.3,0.3", "--grid", "3"],
        2,
        &["--joint 9", "5 universal joints"],
    );
    assert_fails(
        &["joint", "--robot", r, "--joint", "x", "--q", "0,0", "--torque", "0,0"],
        2,
        &["--joint", "`x`"],
    );
}

#[test]
fn a_robot_folder_without_its_files_is_named() {
    let q = list(&[0.0; 10]);
    // robot.toml naming a URDF that is not there.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("robot.toml"),
        "urdf = \"missing.urdf\"\ntip_link = \"end_effector\"\ngravity = [0.0, 9.81, 0.0]\n",
    )
    .unwrap();
    let d = dir.path().to_str().unwrap();
    assert_fails(&["arm", "--robot", d, "--q", &q], 2, &["no URDF", "missing.urdf"]);
    assert_fails(&["routing", "--robot", d], 2, &["no URDF", "missing.urdf"]);
    // No robot.toml at all.
    let empty = tempfile::tempdir().unwrap();
    let e = empty.path().to_str().unwrap();
    assert_fails(&["routing", "--robot", e], 2, &["no robot.toml", e]);
    assert_fails(
        &["joint", "--robot", e, "--joint", "1", "--q", "0,0", "--torque", "0,0"],
        2,
        &["no robot.toml"],
    );
    // No folder.
    let gone = empty.path().join("nowhere");
    let g = gone.to_str().unwrap();
    assert_fails(&["routing", "--robot", g], 2, &["does not exist", g]);
    // A folder without the routing file of the model asked for.
    let fx = Fixture::new();
    std::fs::remove_file(fx.dir.path().join(sinew::routing::ROUTED_ROUTING_FILE)).unwrap();
    assert_fails(
        &["routing", "--robot", fx.path(), "--model", "routed"],
        2,
        &[sinew::routing::ROUTED_ROUTING_FILE],
    );
}

#[test]
fn a_malformed_routing_file_is_one_line_with_exit_2() {
    let fx = Fixture::new();
    let r = fx.path();
    let q = list(&[0.0; 10]);
    // Not TOML: the parser's multi-line report folds into one line naming the file.
    std::fs::write(fx.dir.path().join("cables.toml"), "tension_limits = [20.0, 600.0\n[material\n")
        .unwrap();
    for args in [
        vec!["routing", "--robot", r],
        vec!["arm", "--robot", r, "--q", &q],
        vec!["joint", "--robot", r, "--joint", "1", "--q", "0,0", "--torque", "0,0"],
        vec!["sweep", "--robot", r, "--joint", "1", "--torque", "0,0", "--grid", "3"],
    ] {
        assert_fails(&args, 2, &["cables.toml", "invalid routing file"]);
    }
    // Valid TOML, an invalid value: named by its field.
    std::fs::write(
        fx.dir.path().join("cables-routed.toml"),
        std::fs::read_to_string(sinew_testkit::cdhrm5::dir().join("cables-routed.toml"))
            .unwrap()
            .replacen("tension_limits = [20.0, 600.0]", "tension_limits = [600.0, 20.0]", 1),
    )
    .unwrap();
    assert_fails(
        &["routing", "--robot", r, "--model", "routed"],
        2,
        &["cables-routed.toml", "tension_limits"],
    );
}

#[test]
fn an_infeasible_load_is_named_with_exit_1() {
    let fx = Fixture::new();
    let q = list(&E4_Q);
    assert_fails(
        &["arm", "--robot", fx.path(), "--q", &q, "--wrench", "0,100,0,0,0,0"],
        1,
        &["infeasible load", "joint", "cannot hold torque"],
    );
    assert_fails(
        &["arm", "--robot", fx.path(), "--q", &q, "--wrench", "0,100,0,0,0,0", "--json"],
        1,
        &["infeasible load"],
    );
    assert_fails(
        &["joint", "--robot", fx.path(), "--joint", "1", "--q", "0,0", "--torque", "50,0"],
        1,
        &["infeasible load", "joint 1"],
    );
}

#[test]
fn an_angle_outside_the_limits_is_named() {
    let fx = Fixture::new();
    let r = fx.path();
    let mut q = E4_Q;
    q[4] = 1.0;
    let qs = list(&q);
    assert_fails(&["arm", "--robot", r, "--q", &qs], 2, &["joint3_x", "outside its limits"]);
    assert_fails(
        &["joint", "--robot", r, "--joint", "2", "--q", "0,40", "--deg", "--torque", "0,0"],
        2,
        &["joint2_y", "outside its limits"],
    );
}

#[test]
fn other_bad_values_are_named() {
    let fx = Fixture::new();
    let r = fx.path();
    let q = list(&E4_Q);
    assert_fails(&["arm", "--robot", r, "--q", "a,b"], 2, &["--q", "`a` is not a number"]);
    assert_fails(&["arm", "--robot", r, "--q", &q, "--wrench", "0,NaN,0,0,0,0"], 2, &["finite"]);
    assert_fails(
        &["arm", "--robot", r, "--q", &q, "--levels", "0,0,1.5,0,0"],
        2,
        &["--levels", "joint 3", "[0, 1]"],
    );
    assert_fails(
        &["sweep", "--robot", r, "--joint", "1", "--torque", "0.3,0.3", "--grid", "1"],
        2,
        &["--grid"],
    );
    let bad = Path::new(r).join("no-such-folder").join("maps.csv");
    assert_fails(
        &[
            "sweep",
            "--robot",
            r,
            "--joint",
            "1",
            "--torque",
            "0.3,0.3",
            "--grid",
            "3",
            "--out",
            bad.to_str().unwrap(),
        ],
        2,
        &["--out", "maps.csv"],
    );
}

#[test]
fn usage_errors_are_clap_errors_with_exit_2() {
    let out = run(&["arm", "--robot", "x"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("--q") && !stderr.contains("panicked"), "{stderr}");
    let out = run(&["routing", "--robot", "x", "--model", "tangled"]);
    assert_eq!(out.status.code(), Some(2));
    let out = run(&["--help"]);
    assert!(out.status.success());
}

// ---------------------------------------------------------------------------------------------
// what a new user trips on

#[test]
fn an_absurd_grid_is_refused_with_exit_2_before_sweeping() {
    let fx = Fixture::new();
    let r = fx.path();
    let started = std::time::Instant::now();
    assert_fails(
        &["sweep", "--robot", r, "--joint", "1", "--torque", "0.3,0.3", "--grid", "100000"],
        2,
        &["--grid 100000", "at most 1001 points per axis", "N²", "1e10 points"],
    );
    assert!(started.elapsed().as_secs() < 30, "refused at once, not after sweeping");
    // The largest grid accepted is the documented one.
    assert_fails(
        &["sweep", "--robot", r, "--joint", "1", "--torque", "0.3,0.3", "--grid", "1002"],
        2,
        &["--grid 1002", "at most 1001"],
    );
    // Too few points: the library's check speaks, named by the option.
    assert_fails(
        &["sweep", "--robot", r, "--joint", "1", "--torque", "0.3,0.3", "--grid", "1"],
        2,
        &["--grid 1", "need at least 2"],
    );
}

#[test]
fn the_library_names_an_unknown_joint_for_the_command() {
    let fx = Fixture::new();
    let r = fx.path();
    // The library's NoSuchJoint, prefixed by the option it came from.
    assert_fails(
        &["joint", "--robot", r, "--joint", "6", "--q", "0,0", "--torque", "0,0"],
        2,
        &["--joint 6: joint 6 does not exist", "5 universal joints"],
    );
    // A level outside [0, 1]: the library's InvalidLevel, exit 2.
    let q = list(&E4_Q);
    assert_fails(
        &["arm", "--robot", r, "--q", &q, "--levels", "0,0,0,0,-0.5"],
        2,
        &["--levels: joint 5", "tension level -0.5", "[0, 1]"],
    );
    // An angle outside the limits: the library's OutOfLimits, numbers compact.
    assert_fails(
        &["joint", "--robot", r, "--joint", "2", "--q", "0,1", "--torque", "0,0"],
        2,
        &["--q: joint `joint2_y`", "angle 1 rad", "[-0.5236, 0.5236]"],
    );
}

#[test]
fn a_huge_infeasible_load_prints_compact_numbers_with_exit_1() {
    let fx = Fixture::new();
    let r = fx.path();
    for args in [
        vec!["joint", "--robot", r, "--joint", "1", "--q", "0,0", "--torque", "1e300,0"],
        vec!["arm", "--robot", r, "--q", "0,0,0,0,0,0,0,0,0,0", "--wrench", "0,1e300,0,0,0,0"],
    ] {
        let out = run(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(stderr.starts_with("sinew: infeasible load: joint"), "{args:?}: {stderr}");
        assert!(
            stderr.len() < 400,
            "{args:?}: a short message, got {} bytes: {stderr}",
            stderr.len()
        );
        let longest_number =
            stderr.split(|c: char| !c.is_ascii_digit()).map(str::len).max().unwrap_or(0);
        assert!(longest_number <= 6, "{args:?}: no long number: {stderr}");
    }
}

#[test]
fn joint_names_the_cables_it_counts_in_both_models() {
    let fx = Fixture::new();
    for (model, routing) in [("decoupled", &fx.routing), ("routed", &fx.routed)] {
        let args = [
            "joint",
            "--robot",
            fx.path(),
            "--model",
            model,
            "--joint",
            "1",
            "--q",
            "0.2,-0.1",
            "--torque",
            "0.3,0.3",
        ];
        let doc = json(&[&args[..], &["--json"]].concat());
        let probe = JointProbe::new(&fx.robot, routing, 0).unwrap();
        let name = |c: usize| routing.cables()[c].name.clone();
        let own: Vec<String> = probe.tensioned_cables().map(name).collect();
        let inherent: Vec<String> = probe.inherent_cables().iter().map(|&c| name(c)).collect();
        assert_eq!(doc["cables"], serde_json::json!(own), "{model}");
        assert_eq!(doc["inherent_cables"], serde_json::json!(inherent), "{model}");
        // Every cable crossing joint 1 is counted, and only those.
        let crossing: Vec<String> = routing
            .cables()
            .iter()
            .filter(|c| c.dofs.start <= 1 && c.dofs.end > 0)
            .map(|c| c.name.clone())
            .collect();
        assert_eq!(inherent, crossing, "{model}");
        if model == "decoupled" {
            assert_eq!(inherent, own, "decoupled: the joint's own cables only");
        } else {
            assert_eq!(
                inherent.len(),
                routing.cable_count(),
                "routed: every cable crosses joint 1"
            );
        }
        let text = String::from_utf8(run(&args).stdout).unwrap();
        assert!(
            text.contains(&format!("tension in {} only", own.join(", ")))
                && text.contains(&format!("inherent stiffness of {}", inherent.join(", "))),
            "{model}: the table says what it counts:\n{text}"
        );
    }
}

#[test]
fn any_universal_joint_axes_load_and_are_named() {
    // joint2_y turned to another unit axis: the second universal joint is no longer "x then y".
    let with_second_axis = |axis: &str| {
        let fx = Fixture::new();
        let urdf = fx.dir.path().join("cdhrm5.urdf");
        let text = std::fs::read_to_string(&urdf).unwrap();
        let at = text.find("<joint name=\"joint2_y\"").unwrap();
        let old = "<axis xyz=\"0 1 0\"/>";
        let axis_at = at + text[at..].find(old).unwrap();
        let mut edited = text.clone();
        edited.replace_range(axis_at..axis_at + old.len(), &format!("<axis xyz=\"{axis}\"/>"));
        std::fs::write(&urdf, edited).unwrap();
        fx
    };
    // An oblique axis in the disc plane: loads, computes, and is named.
    let fx = with_second_axis("0.6 0.8 0");
    let robot = sinew::robot::load(fx.dir.path()).unwrap();
    let routing =
        sinew::routing::load(fx.dir.path().join(sinew::routing::ROUTING_FILE), &robot).unwrap();
    let args =
        ["joint", "--robot", fx.path(), "--joint", "2", "--q", "0.1,-0.2", "--torque", "0.3,0.3"];
    let doc = json(&[&args[..], &["--json"]].concat());
    assert_eq!(doc["axes"][0]["name"], "joint2_x");
    assert_vec(&doc["axes"][0]["axis"], &[1.0, 0.0, 0.0], "first axis");
    assert_eq!(doc["axes"][1]["name"], "joint2_y");
    assert_vec(&doc["axes"][1]["axis"], &[0.6, 0.8, 0.0], "second axis");
    // The numbers are the library's for these axes.
    let mut probe = JointProbe::new(&robot, &routing, 1).unwrap();
    let range = probe.evaluate(&robot, &routing, [0.1, -0.2], [0.3, 0.3]).unwrap();
    assert_m2(&doc["k"][0], &range.k_at_min, "k at min");
    assert_m2(&doc["k"][1], &range.k_at_max, "k at max");
    let table = String::from_utf8(run(&args).stdout).unwrap();
    assert!(
        table.contains("second `joint2_y` [0.600, 0.800, 0.000]"),
        "the table names the second axis:\n{table}"
    );
    let sweep = json(&[
        "sweep",
        "--robot",
        fx.path(),
        "--joint",
        "2",
        "--torque",
        "0.3,0.3",
        "--grid",
        "3",
        "--json",
    ]);
    assert_vec(&sweep["axes"][1]["axis"], &[0.6, 0.8, 0.0], "sweep's second axis");
    // x then z: loads and computes. The cables are not in force closure about z at this pose,
    // but tensions within the limits still hold the torque: an answer (exit 0) that says so,
    // not a refusal.
    let fx = with_second_axis("0 0 1");
    let routing = json(&["routing", "--robot", fx.path(), "--json"]);
    assert_vec(&routing["joints"][3]["axis"], &[0.0, 0.0, 1.0], "x then z loads");
    let args =
        ["joint", "--robot", fx.path(), "--joint", "2", "--q", "0.1,-0.2", "--torque", "0.3,0.3"];
    let doc = json(&[&args[..], &["--json"]].concat());
    assert_eq!(doc["force_closure"], false, "{doc}");
    let lambda = doc["lambda"].as_array().unwrap();
    assert!(lambda[0].as_f64().unwrap() <= lambda[1].as_f64().unwrap(), "non-empty: {doc}");
    for f in
        doc["tensions"][0].as_array().unwrap().iter().chain(doc["tensions"][1].as_array().unwrap())
    {
        let f = f.as_f64().unwrap();
        assert!((20.0..=600.0).contains(&f), "within the limits: {doc}");
    }
    let table = String::from_utf8(run(&args).stdout).unwrap();
    assert!(table.contains("not in force closure"), "{table}");
}

// ---------------------------------------------------------------------------------------------
// tension policies (any cable set)

#[test]
fn arm_takes_a_tension_policy() {
    let fx = Fixture::new();
    let q = list(&E4_Q);
    let base = ["arm", "--robot", fx.path(), "--q", &q, "--wrench", "0,5,0,0,0,0", "--json"];
    let levels = json(&base);
    assert_eq!(levels["policy"], "levels");
    assert_eq!(levels["force_closure"], true);
    assert_eq!(levels["null_space_dimension"], 5);
    assert!(levels["policy_objective"].is_null());
    let total = |doc: &Value| {
        doc["tensions"].as_array().unwrap().iter().map(|f| f.as_f64().unwrap()).sum::<f64>()
    };
    for (policy, objective_of) in [
        ("least-total", total as fn(&Value) -> f64),
        ("least-norm", |doc: &Value| {
            doc["tensions"]
                .as_array()
                .unwrap()
                .iter()
                .map(|f| f.as_f64().unwrap().powi(2))
                .sum::<f64>()
                .sqrt()
        }),
        ("safest", |doc: &Value| {
            doc["tensions"]
                .as_array()
                .unwrap()
                .iter()
                .map(|f| f.as_f64().unwrap())
                .map(|f| (f - 20.0).min(600.0 - f))
                .fold(f64::INFINITY, f64::min)
        }),
    ] {
        let doc = json(&[&base[..], &["--policy", policy]].concat());
        assert_eq!(doc["policy"], policy);
        assert!(doc["levels"].is_null() && doc["intervals"].as_array().unwrap().is_empty());
        let objective = doc["policy_objective"].as_f64().unwrap();
        assert!(
            (objective - objective_of(&doc)).abs() <= 1e-9 * objective.abs().max(1.0),
            "{policy}: {objective}"
        );
        for f in doc["tensions"].as_array().unwrap() {
            let f = f.as_f64().unwrap();
            assert!((20.0..=600.0).contains(&f), "{policy}: {f}");
        }
    }
    // Decoupled: each joint's least-total end is its level 0, so the LP's total is the levels'.
    let lp = json(&[&base[..], &["--policy", "least-total"]].concat());
    assert!(
        (total(&lp) - total(&levels)).abs() <= 1e-9 * total(&levels),
        "{} vs {}",
        total(&lp),
        total(&levels)
    );
    // The table says which policy chose the tensions, and lists the cables.
    let args =
        ["arm", "--robot", fx.path(), "--q", &q, "--wrench", "0,5,0,0,0,0", "--policy", "safest"];
    let table = String::from_utf8(run(&args).stdout).unwrap();
    assert!(table.contains("tensions by the policy safest"), "{table}");
    assert!(table.contains("force closure: yes"), "{table}");
    // --levels and --policy exclude each other: a usage error, exit 2.
    let out = run(&[&args[..], &["--levels", "0,0,0,0,0"]].concat());
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn an_infeasible_load_under_a_policy_names_the_joint_and_the_motion() {
    let fx = Fixture::new();
    let q = list(&E4_Q);
    assert_fails(
        &[
            "arm",
            "--robot",
            fx.path(),
            "--q",
            &q,
            "--wrench",
            "0,400,0,0,0,0",
            "--policy",
            "least-norm",
        ],
        1,
        &[
            "infeasible load",
            "no tensions within the limits balance the load at joint",
            "along the joint motion",
            "at f_max",
        ],
    );
}

/// Every command on the robots beyond the paper's pattern: a planar snake of 1-DOF joints with
/// a shared cable, and a universal arm with four cables per joint. `routing` and `arm` answer
/// (the tensions by a policy, least-total by default); the single-joint model (`joint`,
/// `sweep`), which is the paper's three cables on a universal joint, refuses with one line and
/// exit 2.
#[test]
fn every_command_runs_on_the_general_robots() {
    let root = sinew_testkit::cdhrm5::workspace_root();
    for (robot, q, joint_q) in [
        ("planar-snake", "0.3,-0.2,0.25,-0.1", "0.1"),
        ("ua3x4", "0.2,-0.3,0.25,0.1,-0.15,0.3", "0.1,0.1"),
    ] {
        let dir = root.join("robots").join(robot);
        let dir = dir.to_str().unwrap();
        let routing = json(&["routing", "--robot", dir, "--json"]);
        assert_eq!(routing["model"], "explicit");
        let default = json(&["arm", "--robot", dir, "--q", q, "--wrench", "0,2,0,0,0,0", "--json"]);
        assert_eq!(default["policy"], "least-total", "{robot}");
        assert!(
            default["notes"]
                .as_array()
                .unwrap()
                .iter()
                .any(|n| n.as_str().unwrap().contains("tension levels need"))
        );
        for policy in ["least-total", "least-norm", "safest"] {
            let doc = json(&[
                "arm",
                "--robot",
                dir,
                "--q",
                q,
                "--wrench",
                "0,2,0,0,0,0",
                "--policy",
                policy,
                "--json",
            ]);
            assert_eq!(doc["stable"], true, "{robot} {policy}");
            assert!(doc["c_x"].is_array(), "{robot} {policy}");
            assert_eq!(doc["force_closure"], true, "{robot} {policy}");
        }
        assert_fails(
            &[
                "arm",
                "--robot",
                dir,
                "--q",
                q,
                "--levels",
                &vec!["0"; if robot == "ua3x4" { 3 } else { 4 }].join(","),
            ],
            2,
            &["tension levels need three cables per universal joint"],
        );
        let refusal =
            if robot == "ua3x4" { "cables of its own" } else { "needs an arm of universal joints" };
        assert_fails(
            &["joint", "--robot", dir, "--joint", "1", "--q", joint_q, "--torque", joint_q],
            2,
            &[refusal],
        );
    }
}

// ---------------------------------------------------------------------------------------------
// sinew plan

#[test]
fn plan_answers_with_a_certificate_and_its_levels_reproduce_the_arm() {
    let fx = Fixture::new();
    let q = list(&E4_Q);
    let base = ["plan", "--robot", fx.path(), "--q", &q, "--wrench", "0,5,0,0,0,0", "--json"];
    let doc =
        json(&[&base[..], &["--objective", "stiffness-along", "--direction", "0,2,0"]].concat());
    for key in [
        "objective",
        "value",
        "gap",
        "lambda",
        "levels",
        "tensions",
        "total_tension",
        "k_fd",
        "c_x",
        "min_eigenvalue",
        "stable",
        "iterations",
        "q",
        "wrench",
        "direction",
        "margin",
    ] {
        assert!(doc.get(key).is_some(), "key {key} missing: {doc}");
    }
    assert_eq!(doc["objective"], "stiffness-along");
    assert_vec(&doc["direction"], &[0.0, 1.0, 0.0], "direction normalised");
    let value = doc["value"].as_f64().unwrap();
    let gap = doc["gap"].as_f64().unwrap();
    assert!(gap >= 0.0 && gap <= 1e-6 * value, "gap {gap} for {value}");
    assert_eq!(doc["stable"], true);
    // `sinew arm` at the returned levels gives the same K_fd.
    let levels: Vec<f64> =
        doc["levels"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    let s = list(&levels);
    let arm = json(&[
        "arm",
        "--robot",
        fx.path(),
        "--q",
        &q,
        "--wrench",
        "0,5,0,0,0,0",
        "--levels",
        &s,
        "--json",
    ]);
    let (a, b) = (&arm["k_fd"], &doc["k_fd"]);
    for r in 0..3 {
        for c in 0..3 {
            let (x, y) = (a[r][c].as_f64().unwrap(), b[r][c].as_f64().unwrap());
            assert!((x - y).abs() <= 1e-8 * value, "K_fd[{r}][{c}]: arm {x}, plan {y}");
        }
    }
    assert!((arm["k_fd"][1][1].as_f64().unwrap() - value).abs() <= 1e-8 * value);
    // Tables by default.
    let table = String::from_utf8(
        run(&base[..base.len() - 1]
            .iter()
            .copied()
            .chain(["--objective", "volume"])
            .collect::<Vec<_>>())
        .stdout,
    )
    .unwrap();
    assert!(table.contains("certified: within"), "{table}");
}

#[test]
fn plan_refuses_bad_input_and_reports_the_unreachable() {
    let fx = Fixture::new();
    let q = list(&E4_Q);
    let base = ["plan", "--robot", fx.path(), "--q", &q];
    let with = |extra: &[&'static str]| -> Vec<String> {
        base.iter().map(|s| s.to_string()).chain(extra.iter().map(|s| s.to_string())).collect()
    };
    for (extra, code, needles) in [
        (vec!["--objective", "sideways"], 2, vec!["sideways"]),
        (vec!["--objective", "stiffness-along", "--direction", "0,0,0"], 2, vec!["--direction"]),
        (vec!["--objective", "stiffness-along"], 2, vec!["needs --direction"]),
        (
            vec!["--objective", "least-tension", "--k-des", "1,2,0,0,1,0,0,0,1"],
            2,
            vec!["--k-des", "symmetric positive definite"],
        ),
        (
            vec!["--objective", "volume", "--wrench", "0,5,0,0.1,0,0"],
            2,
            vec!["--wrench", "moment", "not symmetric"],
        ),
        (vec!["--objective", "volume", "--budget=-5"], 2, vec!["--budget"]),
        (vec!["--objective", "volume", "--margin=-1"], 2, vec!["--margin"]),
        (vec!["--objective", "volume", "--budget", "50"], 1, vec!["infeasible", "budget"]),
        (
            vec!["--objective", "least-tension", "--k-min", "1e6"],
            1,
            vec!["infeasible", "exceeds the best reachable"],
        ),
    ] {
        let args = with(&extra);
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = run(&refs);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(code), "{extra:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        if code == 1 || !needles.contains(&"sideways") {
            assert_eq!(stderr.lines().count(), 1, "{extra:?}: {stderr}");
        }
        for n in needles {
            assert!(stderr.contains(n), "{extra:?}: `{n}` missing in {stderr}");
        }
    }
}

#[test]
fn levels_that_overload_a_proximal_joint_say_so_and_suggest_a_policy() {
    // Routed, E4's pose, every joint at level 1: the closed form fixes joints 4 and 5 first,
    // and their cables overload joint 3; the safest policy holds the same load.
    let q = "-25.714,-20,-20,-16.364,30,25.714,22.5,-12,-15,-18";
    let base = ["arm", "--robot", CDHRM5_DIR, "--model", "routed", "--deg", "--q", q];
    let with = |extra: &[&'static str]| {
        let mut args = base.to_vec();
        args.extend_from_slice(&["--wrench", "0,5,0,0,0,0"]);
        args.extend_from_slice(extra);
        args
    };
    assert_fails(
        &with(&["--levels", "1,1,1,1,1"]),
        1,
        &[
            "joint 3 cannot hold torque",
            "at these tension levels",
            "the levels of joints 4, 5 fixed their cables' tensions first",
            "choose a tension policy",
            "--policy safest",
        ],
    );
    let held = json(&with(&["--policy", "safest", "--json"]));
    assert_eq!(held["policy"], "safest");
    let [lo, hi] = [20.0, 600.0];
    for f in held["tensions"].as_array().unwrap() {
        let f = f.as_f64().unwrap();
        assert!(lo < f && f < hi, "{f} N within the limits");
    }
}

#[test]
fn an_option_of_one_number_refuses_a_list() {
    let q = "-25.714,-20,-20,-16.364,30,25.714,22.5,-12,-15,-18";
    let plan = ["plan", "--robot", CDHRM5_DIR, "--deg", "--q", q, "--wrench", "0,5,0,0,0,0"];
    for (option, value, says) in [
        ("--gap", "1e-3,5", "expected 1 number, got 2"),
        ("--margin", "1e-3,1", "expected 1 number, got 2"),
        ("--budget", "900,", "`` is not a number"),
        ("--k-min", "2 3", "is not a number"),
    ] {
        let mut args = plan.to_vec();
        args.extend_from_slice(&["--objective", "volume", option, value]);
        assert_fails(&args, 2, &[option, says]);
    }
}

/// The embedded robot folder.
const CDHRM5_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/cdhrm5");
