//! `sinew import caspr` on the synthetic CASPR models of crates/sinew-import/tests/data: the
//! folder it writes loads with the library, and a failure writes nothing.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

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

/// Every command on imported folders: the all-universal model (three cables per joint: levels
/// and policies, joint, sweep) and the mixed one (R_X, R_Y, R_Z beside universal joints, three
/// cables for nine DOF: the arm answers with a typed infeasibility naming the joints, exit 1).
#[test]
fn every_command_runs_on_imported_folders() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("arm");
    assert!(import(&out, &[]).status.success());
    let dir = out.to_str().unwrap();
    for args in [
        vec!["routing", "--robot", dir],
        vec!["arm", "--robot", dir, "--q", "0.1,0.1,0.1,0.1", "--no-gravity"],
        vec![
            "arm",
            "--robot",
            dir,
            "--q",
            "0.1,0.1,0.1,0.1",
            "--no-gravity",
            "--policy",
            "least-norm",
        ],
        vec!["joint", "--robot", dir, "--joint", "1", "--q", "0.1,0.1", "--torque", "0.1,0.1"],
        vec!["sweep", "--robot", dir, "--joint", "1", "--torque", "0.1,0.1", "--grid", "3"],
    ] {
        // An answer: the result (exit 0), or the typed infeasibility of this synthetic model's
        // second joint, whose cables cannot all stay above f_min at zero torque (exit 1).
        let result = run(&args);
        let stderr = String::from_utf8_lossy(&result.stderr);
        let answered = result.status.success()
            || (result.status.code() == Some(1)
                && stderr.starts_with("sinew: infeasible load: ")
                && stderr.contains("joint 2")
                && stderr.lines().count() == 1);
        assert!(answered, "{args:?}: {stderr}");
    }
    let mixed = tmp.path().join("mixed");
    let (bodies, cables) = (data("every_joint_bodies.xml"), data("every_joint_cables.xml"));
    let mixed_s = mixed.display().to_string();
    let result =
        run(&["import", "caspr", "--bodies", &bodies, "--cables", &cables, "--out", &mixed_s]);
    assert!(result.status.success(), "{}", String::from_utf8_lossy(&result.stderr));
    let routing = run(&["routing", "--robot", &mixed_s, "--json"]);
    assert!(routing.status.success(), "{}", String::from_utf8_lossy(&routing.stderr));
    let doc: serde_json::Value = serde_json::from_slice(&routing.stdout).unwrap();
    let joints: Vec<u64> =
        doc["joints"].as_array().unwrap().iter().map(|j| j["joint"].as_u64().unwrap()).collect();
    assert_eq!(joints, [0, 1, 2, 3, 3, 4, 4, 5, 5], "three revolute, then three universal joints");
    let q = ["0.05"; 9].join(",");
    let arm = run(&["arm", "--robot", &mixed_s, "--q", &q]);
    assert_eq!(arm.status.code(), Some(1), "{}", String::from_utf8_lossy(&arm.stderr));
    let stderr = String::from_utf8_lossy(&arm.stderr);
    assert!(stderr.contains("no cable tensions balance the load at joints"), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    // The single-joint model is for universal arms: a clear refusal, exit 2.
    let joint =
        run(&["joint", "--robot", &mixed_s, "--joint", "1", "--q", "0.1", "--torque", "0.1"]);
    assert_eq!(joint.status.code(), Some(2), "{}", String::from_utf8_lossy(&joint.stderr));
    assert!(
        String::from_utf8_lossy(&joint.stderr)
            .contains("single-joint model needs an arm of universal joints")
    );
}
