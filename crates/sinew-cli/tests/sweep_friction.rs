//! `sinew sweep` with friction at the holes (spec §9, #27): μ = 0 is the frictionless document
//! byte for byte; with μ > 0 (from `--friction` or the routing file) the maps are the library's
//! probe with friction (`JointProbe::with_friction`, `sweep_probe`) and the document says the
//! regime; bad input is one line, exit 2, and nothing written.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;
use std::process::{Command, Output};

use serde_json::Value;
use sinew::indicators::{AngleGrid, JointProbe, sweep_probe};
use sinew::routing::{FrictionModel, PatternModel, Slip};
use sinew::stiffness::{FrictionRegime, History};
use sinew_testkit::cdhrm5;

fn sweep(dir: &Path, extra: &[&str]) -> Output {
    let args = ["sweep", "--robot", dir.to_str().unwrap(), "--model", "routed", "--joint", "5"];
    let grid = ["--torque", "0.5,-0.3", "--grid", "3"];
    Command::new(env!("CARGO_BIN_EXE_sinew")).args(args).args(grid).args(extra).output().unwrap()
}

fn json(dir: &Path, extra: &[&str]) -> Value {
    let mut args = extra.to_vec();
    args.push("--json");
    let out = sweep(dir, &args);
    assert!(out.status.success(), "{extra:?}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The library's maps of joint 5 (0-based 4) of the routed cdhrm5 with friction μ in `regime`.
fn library(mu: f64, regime: FrictionRegime) -> Vec<[Option<f64>; 4]> {
    let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Routed);
    let model = FrictionModel::new(&routing).with_friction_coefficient(mu).unwrap();
    let probe = JointProbe::new(&robot, &routing, 4).unwrap();
    let probe = probe.with_friction(&routing, model, regime).unwrap();
    let (jx, jy) = (&robot.joints()[8], &robot.joints()[9]);
    let grid =
        AngleGrid { lower: jx.lower.max(jy.lower), upper: jx.upper.min(jy.upper), points: 3 };
    let maps = sweep_probe(&probe, &robot, &routing, [0.5, -0.3], grid, &|_, _| ()).unwrap();
    maps.cells
        .iter()
        .map(|c| {
            let c = c.as_ref();
            [
                c.map(|c| c.k_x.range[0]),
                c.map(|c| c.k_x.range[1]),
                c.map(|c| c.k_y.range[0]),
                c.map(|c| c.k_y.range[1]),
            ]
        })
        .collect()
}

fn assert_maps(doc: &Value, expected: &[[Option<f64>; 4]], what: &str) {
    let mut checked = 0;
    for (k, key) in ["k_x_min", "k_x_max", "k_y_min", "k_y_max"].into_iter().enumerate() {
        for a in 0..3 {
            for b in 0..3 {
                let got = doc[key][a][b].as_f64();
                let want = expected[3 * a + b][k];
                match (got, want) {
                    (Some(g), Some(w)) => {
                        assert!(
                            (g - w).abs() <= 1e-12 * w.abs(),
                            "{what} {key}[{a}][{b}]: {g} vs {w}"
                        );
                        checked += 1;
                    }
                    (None, None) => {}
                    _ => panic!("{what} {key}[{a}][{b}]: {got:?} vs {want:?}"),
                }
            }
        }
    }
    assert!(checked >= 30, "{what}: {checked} cells compared");
}

#[test]
fn mu_zero_is_the_frictionless_sweep_byte_for_byte() {
    let dir = cdhrm5::dir();
    let plain = sweep(&dir, &["--json"]);
    for extra in [["--friction", "0"], ["--regime", "pull"]] {
        let mut args = extra.to_vec();
        args.push("--json");
        let out = sweep(&dir, &args);
        assert!(out.status.success());
        assert_eq!(out.stdout, plain.stdout, "{extra:?}");
    }
    let doc: Value = serde_json::from_slice(&plain.stdout).unwrap();
    assert!(doc.get("friction").is_none(), "a frictionless document has no `friction`");
}

#[test]
fn with_friction_the_maps_are_the_probes_with_friction() {
    let dir = cdhrm5::dir();
    let plain = json(&dir, &[]);
    for (args, regime, name, history) in [
        (vec!["--regime", "pull"], FrictionRegime::Slip(Slip::Pull), "pull", None),
        (vec!["--regime", "release"], FrictionRegime::Slip(Slip::Release), "release", None),
        (vec![], FrictionRegime::Stick(History::Pull), "stick", Some("pull")),
        (vec!["--history", "equal"], FrictionRegime::Stick(History::Equal), "stick", Some("equal")),
    ] {
        let mut args = args.clone();
        args.extend(["--friction", "0.2"]);
        let doc = json(&dir, &args);
        assert_eq!(doc["friction"]["regime"], name, "{args:?}");
        assert_eq!(doc["friction"]["history"].as_str(), history, "{args:?}");
        let mu = doc["friction"]["mu"].as_array().unwrap();
        assert_eq!(mu.len(), 15);
        assert!(mu.iter().all(|m| m.as_f64() == Some(0.2)));
        assert_maps(&doc, &library(0.2, regime), &format!("{args:?}"));
        assert_ne!(doc["k_x_max"], plain["k_x_max"], "{args:?}: friction changes the map");
    }
}

#[test]
fn the_routing_files_mu_turns_friction_on_and_bad_input_writes_nothing() {
    let dir = std::env::temp_dir().join(format!("sinew-sweep-friction-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for entry in std::fs::read_dir(cdhrm5::dir()).unwrap() {
        let path = entry.unwrap().path();
        std::fs::copy(&path, dir.join(path.file_name().unwrap())).unwrap();
    }
    let cables = dir.join("cables-routed.toml");
    let text = std::fs::read_to_string(&cables).unwrap();
    std::fs::write(&cables, format!("friction_coefficient = 0.2\n{text}")).unwrap();
    // The default with friction: stick after a pull, as `sinew arm`.
    let doc = json(&dir, &[]);
    assert_eq!(
        (doc["friction"]["regime"].as_str(), doc["friction"]["history"].as_str()),
        (Some("stick"), Some("pull"))
    );
    assert_maps(&doc, &library(0.2, FrictionRegime::Stick(History::Pull)), "routing file");
    let csv = dir.join("maps.csv");
    for bad in [
        vec!["--friction", "-0.1"],
        vec!["--friction", "NaN"],
        vec!["--friction", "0", "--regime", "stick"],
        vec!["--regime", "pull", "--history", "equal"],
    ] {
        let mut args = bad.clone();
        args.extend(["--out", csv.to_str().unwrap()]);
        let out = sweep(&dir, &args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{bad:?}: {stderr}");
        assert!(out.stdout.is_empty(), "{bad:?}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{bad:?}: {stderr}");
        assert!(stderr.contains("--friction") || stderr.contains("--history"), "{bad:?}: {stderr}");
        assert!(!csv.exists(), "{bad:?}: nothing written");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
