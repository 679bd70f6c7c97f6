//! `sinew import caspr` on the synthetic CASPR models of crates/sinew-import/tests/data: the
//! folder it writes loads with the library, a failure writes nothing, and every command on it
//! gives the numbers of the model rebuilt from the XML (tests/import/model.rs).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use nalgebra::DVector;
use serde_json::{Value, json};

#[path = "import/compare.rs"]
mod compare;
#[path = "import/model.rs"]
mod model;

use compare::{close, close_v, matrix, numbers, sub};

fn data(file: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../sinew-import/tests/data")
        .join(file)
        .display()
        .to_string()
}

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sinew")).args(args).output().expect("the sinew binary runs")
}

fn import(out: &Path, extra: &[&str]) -> Output {
    let (bodies, cables) = (data("universal_bodies.xml"), data("universal_cables.xml"));
    let out = out.display().to_string();
    let mut args = vec!["import", "caspr", "--bodies", &bodies, "--cables", &cables, "--out", &out];
    args.extend_from_slice(extra);
    run(&args)
}

fn entries(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    v.sort();
    v
}

#[test]
fn imports_a_model_that_the_library_and_the_routing_command_load() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("arm");
    let result = import(&out, &["--free-length", "1.5", "--tension-limits", "10,90"]);
    let (stdout, stderr) =
        (String::from_utf8_lossy(&result.stdout), String::from_utf8_lossy(&result.stderr));
    assert!(result.status.success(), "{stderr}");
    // The name comes from the bodies file; the summary is one line.
    assert_eq!(
        stdout.trim(),
        format!(
            "wrote {}: universal: 2 links (2 universal joints), 4 DOF, 6 cables",
            out.display()
        )
    );
    assert!(
        stderr.contains("sinew: warning: tension limits [10, 90] N from the options"),
        "{stderr}"
    );
    let names: Vec<_> = entries(&out)
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["cables.toml", "robot.toml", "universal.urdf"]);
    // Nothing else beside it: the temporary folder was renamed.
    assert_eq!(entries(tmp.path()), std::slice::from_ref(&out));

    let robot = sinew::robot::load(&out).unwrap();
    assert_eq!(robot.dof(), 4);
    let routing = sinew::routing::load(&out, &robot).unwrap();
    assert_eq!(routing.tension_limits(), [10.0, 90.0]);
    let json = run(&["routing", "--robot", out.to_str().unwrap(), "--json"]);
    assert!(json.status.success(), "{}", String::from_utf8_lossy(&json.stderr));

    // An existing empty folder is filled; a non-empty one is refused (exit 2).
    let empty = tmp.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    assert!(import(&empty, &["--name", "again"]).status.success());
    assert!(empty.join("again.urdf").is_file());
    let refused = import(&out, &[]);
    assert_eq!(refused.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(stderr.contains("exists and is not empty"), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
}

#[test]
fn a_failed_import_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("arm");
    for (extra, message) in [
        (
            &["--cable-set", "nope"][..],
            "no <cable_set id=\"nope\">: the file has `basic`, `mixed_limits`, `springs`",
        ),
        (&["--diameter", "-1"][..], "diameter = -1: expected finite and > 0"),
        (&["--tension-limits", "1"][..], "--tension-limits: expected 2 numbers"),
    ] {
        let result = import(&out, extra);
        assert_eq!(result.status.code(), Some(2), "{extra:?}");
        let stderr = String::from_utf8_lossy(&result.stderr);
        assert!(stderr.starts_with("sinew: ") && stderr.contains(message), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(result.stdout.is_empty());
        assert!(entries(tmp.path()).is_empty(), "{extra:?}: {:?}", entries(tmp.path()));
    }
    // A file error names the place.
    let bad = tmp.path().join("bad_bodies.xml");
    std::fs::write(&bad, "<bodies_system>\n  <links/>\n</bodies_system>\n").unwrap();
    let (bad_s, cables) = (bad.display().to_string(), data("universal_cables.xml"));
    let out_s = out.display().to_string();
    let result =
        run(&["import", "caspr", "--bodies", &bad_s, "--cables", &cables, "--out", &out_s]);
    assert_eq!(result.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(stderr.contains(&format!("{bad_s}:2:3: <links> holds no <link_rigid>")), "{stderr}");
    assert_eq!(entries(tmp.path()), [bad]);
}

// Every command on imported folders, against the synthetic model rebuilt from the XML's numbers
// (tests/import/model.rs). Successes: exit 0, nothing on stderr, the JSON's numbers. Failures:
// the exit code, one exact line on stderr, nothing on stdout.

fn imported(tmp: &Path) -> String {
    let out = tmp.join("arm");
    let result = import(&out, &[]);
    assert!(result.status.success(), "{}", String::from_utf8_lossy(&result.stderr));
    out.display().to_string()
}

/// Runs a command that must succeed; its standard output.
fn ok(args: &[&str]) -> String {
    let result = run(args);
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert_eq!(result.status.code(), Some(0), "{args:?}: {stderr}");
    assert!(stderr.is_empty(), "{args:?}: {stderr}");
    String::from_utf8(result.stdout).unwrap()
}

fn json(args: &[&str]) -> Value {
    let mut args = args.to_vec();
    args.push("--json");
    serde_json::from_str(&ok(&args)).unwrap()
}

/// Runs a command that must fail with `code`; its one line of standard error.
fn fails(args: &[&str], code: i32) -> String {
    let result = run(args);
    let stderr = String::from_utf8(result.stderr).unwrap();
    assert_eq!(result.status.code(), Some(code), "{args:?}: {stderr}");
    assert!(result.stdout.is_empty(), "{args:?}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    stderr.trim_end().to_owned()
}

#[test]
fn routing_reports_the_cables_as_imported() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = imported(tmp.path());
    let doc = json(&["routing", "--robot", &dir]);
    assert_eq!(doc["model"], "explicit");
    assert_eq!(numbers(&doc["tension_limits"]), model::LIMITS);
    assert_eq!(numbers(&doc["gravity"]), model::GRAVITY);
    let area = std::f64::consts::PI * 0.25e-6;
    assert!((doc["area"].as_f64().unwrap() - area).abs() < 1e-20, "{}", doc["area"]);
    let table = ok(&["routing", "--robot", &dir]);
    let links = ["base_link", "base_side", "tip_side"];
    let cables = doc["cables"].as_array().unwrap();
    assert_eq!(cables.len(), 6);
    for (got, (name, holes)) in cables.iter().zip(model::cables()) {
        assert_eq!(got["name"], name);
        // The joint a cable drives is its last hole's: a* joint 0, b* joint 1.
        assert_eq!(got["joint"], holes.last().unwrap().0 - 1, "{name}");
        let got_holes = got["holes"].as_array().unwrap();
        assert_eq!(got_holes.len(), holes.len(), "{name}");
        for (h, &(link, point)) in got_holes.iter().zip(&holes) {
            assert_eq!(h["link"], links[link], "{name}");
            close_v(name, &h["point"], &point, 1e-15);
        }
        // k = E A / (0.5 m + routed length at Q = 0): 0.13 m for a*, 0.09 + 0.04 + 0.10 for b*.
        let routed = model::length(&holes, &[0.0; 4]).0;
        let k = model::stiffness(&holes);
        close_v(
            name,
            &json!([got["routed_length"], got["elastic_length"], got["stiffness"]]),
            &[routed, 0.5 + routed, k],
            1e-12,
        );
        assert!(table.contains(&format!("{k:.2}")), "{name}: {k:.2} not in\n{table}");
    }
}

#[test]
fn joint_and_sweep_hold_the_torque_the_geometry_says() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = imported(tmp.path());
    let torque = DVector::from_vec(vec![0.1, 0.1]);
    // Joint 1 at (q1, q2), joint 2 at 0: its cables a1..a3 hold the torque; the inherent
    // stiffness counts all six cables (b1..b3 cross joint 1 too, at zero tension).
    let expect = |q1: f64, q2: f64| {
        let q = [q1, q2, 0.0, 0.0];
        let interval = model::Interval::new(&model::block(&q, 0..3, 0..2), &torque);
        let ends = interval.lambda.map(|l| {
            let mut f = interval.tensions(l).as_slice().to_vec();
            f.extend([0.0; 3]);
            let (kc, ki) = model::joint_stiffness(&q, &f);
            (f, sub(&kc, 0..2, 0..2), sub(&ki, 0..2, 0..2))
        });
        (interval, ends)
    };
    let doc =
        json(&["joint", "--robot", &dir, "--joint", "1", "--q", "0.1,0.1", "--torque", "0.1,0.1"]);
    let (interval, ends) = expect(0.1, 0.1);
    assert_eq!(doc["inherent_cables"], json!(["a1", "a2", "a3", "b1", "b2", "b3"]));
    close_v("lambda", &doc["lambda"], &interval.lambda, 1e-9);
    close_v("particular", &doc["particular"], interval.particular.as_slice(), 1e-9);
    close_v("null", &doc["null_direction"], interval.null.as_slice(), 1e-9);
    assert_eq!(doc["force_closure"], true);
    let mut sigma = [[f64::INFINITY, f64::NEG_INFINITY]; 2];
    for (e, (f, kc, ki)) in ends.iter().enumerate() {
        close_v("tensions", &doc["tensions"][e], &f[..3], 1e-9);
        close("k_controllable", &matrix(&doc["k_controllable"][e]), kc, 1e-8);
        close("k_inherent", &matrix(&doc["k_inherent"][e]), ki, 1e-9);
        close("k", &matrix(&doc["k"][e]), &(kc + ki), 1e-9);
        for a in 0..2 {
            sigma[a] = [
                sigma[a][0].min(kc[(a, a)] + ki[(a, a)]),
                sigma[a][1].max(kc[(a, a)] + ki[(a, a)]),
            ];
        }
    }
    // One cable at each limit: a2 at 5 N, then at 300 N (the least and the most tension).
    assert_eq!(numbers(&doc["tensions"][0])[1], 5.0);
    assert_eq!(numbers(&doc["tensions"][1])[1], 300.0);
    let table =
        ok(&["joint", "--robot", &dir, "--joint", "1", "--q", "0.1,0.1", "--torque", "0.1,0.1"]);
    for (key, name, [lo, hi]) in [("sigma_x", "σ_x", sigma[0]), ("sigma_y", "σ_y", sigma[1])] {
        close_v(
            key,
            &json!([doc[key][0][0], doc[key][0][1], doc[key][1]]),
            &[lo, hi, hi - lo],
            1e-9,
        );
        let row = format!("{name}  {lo:.4}  {hi:.4}  {:.4}", hi - lo);
        assert!(table.contains(&row), "{row} not in\n{table}");
    }

    // The sweep over the limits ±0.6 at 3 × 3 points: only q = 0 holds the torque (at ±0.6
    // some tension would have to leave [5, 300] N), with the joint command's ranges there.
    let args = ["sweep", "--robot", &dir, "--joint", "1", "--torque", "0.1,0.1", "--grid", "3"];
    let doc = json(&args);
    let angles = [-0.6, 0.0, 0.6];
    assert_eq!(numbers(&doc["grid"]["angles"]), angles);
    let mut feasible = 0;
    for (r, q1) in angles.iter().enumerate() {
        for (c, q2) in angles.iter().enumerate() {
            let (interval, ends) = expect(*q1, *q2);
            let cell = |key: &str| &doc[key][r][c];
            if interval.lambda[0] > interval.lambda[1] {
                assert!(cell("k_x_min").is_null() && cell("k_y_max").is_null(), "({q1}, {q2})");
                continue;
            }
            feasible += 1;
            let k: Vec<[f64; 2]> = ends
                .iter()
                .map(|(_, kc, ki)| [kc[(0, 0)] + ki[(0, 0)], kc[(1, 1)] + ki[(1, 1)]])
                .collect();
            let got = json!([cell("k_x_min"), cell("k_x_max"), cell("k_y_min"), cell("k_y_max")]);
            let want = [
                k[0][0].min(k[1][0]),
                k[0][0].max(k[1][0]),
                k[0][1].min(k[1][1]),
                k[0][1].max(k[1][1]),
            ];
            close_v("sweep", &got, &want, 1e-9);
        }
    }
    assert_eq!((feasible, doc["feasible"].as_u64()), (1, Some(1)));
    assert!(ok(&args).contains("feasible: 1 of 9 points"));
}

#[test]
fn arm_balances_gravity_and_a_force_as_the_geometry_says() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = imported(tmp.path());
    let q = [0.2, 0.1, -0.15, 0.005];
    let base =
        ["arm", "--robot", &dir, "--q", "0.2,0.1,-0.15,0.005", "--wrench", "0.5,-1,0.3,0,0,0"];
    let doc = json(&base);
    let (t0, kw) = model::load(&q, [0.5, -1.0, 0.3], true);
    close_v("t0", &doc["t0"], t0.as_slice(), 1e-9);
    close("k_w", &matrix(&doc["k_w"]), &kw, 1e-9);
    // Level 0, tip to base: b1..b3 hold joint 2's T0 at their least; a1..a3 hold joint 1's T0
    // plus the torque that b1..b3 (crossing joint 1) put on it, at their least.
    let joint2 = model::Interval::new(&model::block(&q, 3..6, 2..4), &t0.rows(2, 2).into_owned());
    let fb = joint2.tensions(joint2.lambda[0]);
    let carried = t0.rows(0, 2) + model::block(&q, 3..6, 0..2) * &fb;
    let joint1 = model::Interval::new(&model::block(&q, 0..3, 0..2), &carried);
    let fa = joint1.tensions(joint1.lambda[0]);
    let f: Vec<f64> = fa.iter().chain(fb.iter()).copied().collect();
    close_v("tensions", &doc["tensions"], &f, 1e-9);
    for (i, interval) in [joint1, joint2].iter().enumerate() {
        close_v("lambda", &doc["intervals"][i]["lambda"], &interval.lambda, 1e-9);
        for e in 0..2 {
            let ends = interval.tensions(interval.lambda[e]);
            close_v("ends", &doc["intervals"][i]["tensions_at_ends"][e], ends.as_slice(), 1e-9);
        }
    }
    let (kc, ki) = model::joint_stiffness(&q, &f);
    let kq = &kc + &ki;
    close("k_controllable", &matrix(&doc["k_controllable"]), &kc, 1e-8);
    close("k_inherent", &matrix(&doc["k_inherent"]), &ki, 1e-9);
    close("k_q", &matrix(&doc["k_q"]), &kq, 1e-9);
    close("k_joint", &matrix(&doc["intervals"][1]["k_joint"]), &sub(&kq, 2..4, 2..4), 1e-9);
    let jx = model::tip_jacobian(&q);
    close("j_x", &matrix(&doc["j_x"]), &jx, 1e-12);
    let a = &kq + &kw;
    let smallest = a.clone().symmetric_eigen().eigenvalues.min();
    assert!(smallest > 0.0 && doc["stable"] == true);
    close_v("min_eigenvalue", &json!([doc["min_eigenvalue"]]), &[smallest], 1e-8);
    let cx = &jx * a.try_inverse().unwrap() * jx.transpose();
    close("c_x", &matrix(&doc["c_x"]), &cx, 1e-9);
    let kt = sub(&cx, 0..3, 0..3).try_inverse().unwrap();
    close("k_translational", &matrix(&doc["k_translational"]), &kt, 1e-6);
    // Four DOF move the tip in four of six directions: C_x is singular, K_x does not exist.
    assert!(doc["k_x"].is_null() && doc["k_fd"].is_null() && doc["ellipsoid"].is_null());
    let notes = doc["notes"].as_array().unwrap();
    assert!(notes.len() == 1 && notes[0].as_str().unwrap().contains("rank < 6"), "{notes:?}");
    let table = ok(&base);
    assert!(
        table.contains(&format!("smallest eigenvalue of K_q + K_W = {smallest:.6} N m/rad")),
        "{table}"
    );

    // The least 2-norm policy, against an enumeration of the active sets: the same tensions
    // (in force closure, f_p ⟂ null(J_cᵀ): lowering every λ lowers the norm and the total).
    let mut args = base.to_vec();
    args.extend(["--policy", "least-norm"]);
    let doc = json(&args);
    let f = model::least_norm(&q, &t0);
    close_v("least-norm", &doc["tensions"], f.as_slice(), 1e-7);
    close_v("objective", &json!([doc["policy_objective"]]), &[f.norm()], 1e-7);
    assert_eq!(doc["policy"], "least-norm");
}

#[test]
fn arm_refuses_a_twist_that_no_tensions_hold() {
    // At Q = 0.1 (4 DOF), no load: b1..b3 must give joint 2 zero torque, but their null
    // direction has mixed signs, so some would have to go below f_min = 5 N.
    let tmp = tempfile::tempdir().unwrap();
    let dir = imported(tmp.path());
    let q = [0.1; 4];
    let a2 = model::block(&q, 3..6, 2..4);
    let interval = model::Interval::new(&a2, &DVector::zeros(2));
    let [lo, hi] = interval.lambda;
    assert!(lo > 0.0 && hi < 0.0, "{lo} {hi}");
    let base = ["arm", "--robot", &dir, "--q", "0.1,0.1,0.1,0.1", "--no-gravity"];
    assert_eq!(
        fails(&base, 1),
        format!(
            "sinew: infeasible load: joint 2 cannot hold torque [0, 0] N m with tensions in \
             [5, 300] N: no tensions within the limits hold the torque (λ ≥ {lo:.3} and λ ≤ {hi:.3})"
        )
    );
    // A policy's certificate: along the joint motion d, the cables' torque −J_cᵀ f · d (the
    // sign of T0) has only a range, over f ∈ [5, 300]³, that misses the 0 N m the load needs.
    // Checked against the geometry's J_c: `along` is J_c (−d), the cables' weights.
    let mut args = base.to_vec();
    args.extend(["--policy", "least-norm"]);
    let line = fails(&args, 1);
    let head = "sinew: infeasible load: no tensions within the limits balance the load at joint 2: \
                along the joint motion [";
    let rest = line.strip_prefix(head).unwrap_or_else(|| panic!("{line}"));
    let (d, rest) =
        rest.split_once("] the load needs 0 N m from the cables, which give only [").unwrap();
    let (range, rest) = rest.split_once("] N m within their limits; ").unwrap();
    let parse = |s: &str| -> Vec<f64> { s.split(", ").map(|x| x.parse().unwrap()).collect() };
    let (d, range) = (parse(d), parse(range));
    assert_eq!(d[..2], [0.0, 0.0], "{line}");
    assert_eq!(d.iter().fold(0.0_f64, |m, x| m.max(x.abs())), 1.0, "largest component 1: {line}");
    let along: Vec<f64> = (0..3).map(|c| -(a2[(0, c)] * d[2] + a2[(1, c)] * d[3])).collect();
    let [min, max] = [5.0, 300.0]
        .map(|up| along.iter().map(|&x| x * if x > 0.0 { up } else { 305.0 - up }).sum::<f64>());
    let near = |got: f64, want: f64| (got / want - 1.0).abs() < 1e-4;
    assert!(max < 0.0 && near(range[0], min) && near(range[1], max), "{line}: [{min}, {max}]");
    // Every J_c · d < 0: closer to 0 only below f_min. The message names the cables that carry
    // at least a tenth of the largest share: b1 and b3, not b2 (J_c · d 9.5 % of b3's).
    let largest = along.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    assert!(along.iter().all(|x| *x < 0.0), "{along:?}");
    assert!(along[0].abs() > 0.1 * largest && along[1].abs() < 0.1 * largest, "{along:?}");
    assert_eq!(rest, "b1, b3 at f_min (raise those limits or lighten the load)");
}

/// The mixed model (R_X, R_Y, R_Z beside three universal joints, three cables for nine DOF):
/// no cable crosses joints 4 to 6, so the arm has no answer (exit 1) and the single-joint
/// model refuses it (exit 2).
#[test]
fn the_mixed_model_has_no_answer_and_no_single_joint() {
    let tmp = tempfile::tempdir().unwrap();
    let mixed = tmp.path().join("mixed");
    let (bodies, cables) = (data("every_joint_bodies.xml"), data("every_joint_cables.xml"));
    let mixed_s = mixed.display().to_string();
    let result =
        run(&["import", "caspr", "--bodies", &bodies, "--cables", &cables, "--out", &mixed_s]);
    assert!(result.status.success(), "{}", String::from_utf8_lossy(&result.stderr));
    let doc = json(&["routing", "--robot", &mixed_s]);
    let joints: Vec<u64> =
        doc["joints"].as_array().unwrap().iter().map(|j| j["joint"].as_u64().unwrap()).collect();
    assert_eq!(joints, [0, 1, 2, 3, 3, 4, 4, 5, 5], "three revolute, then three universal joints");
    let q = ["0.05"; 9].join(",");
    let line = fails(&["arm", "--robot", &mixed_s, "--q", &q], 1);
    let head = "sinew: infeasible load: no cable tensions balance the load at joints 4, 5: the \
                cables exert no torque along the joint motion [";
    let rest = line.strip_prefix(head).unwrap_or_else(|| panic!("{line}"));
    let (d, torque) = rest.split_once("], where the load needs ").unwrap();
    let d: Vec<f64> = d.split(", ").map(|x| x.parse().unwrap()).collect();
    // Unit, and the cables hold joints 1 to 3 (three cables, three DOF): nothing left there.
    assert_eq!(d.len(), 9);
    assert!((d.iter().map(|x| x * x).sum::<f64>() - 1.0).abs() < 1e-4, "{line}");
    assert!(d[..3].iter().all(|x| x.abs() < 1e-9), "{line}");
    assert!(torque.strip_suffix(" N m").unwrap().parse::<f64>().unwrap() > 0.0, "{line}");
    assert_eq!(
        fails(&["joint", "--robot", &mixed_s, "--joint", "1", "--q", "0.1", "--torque", "0.1"], 2),
        "sinew: --joint 1: joint 1 has 1 revolute joint(s); the single-joint model needs an arm \
         of universal joints (any arm: `sinew arm --policy`)"
    );
}
