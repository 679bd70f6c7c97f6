//! A property test of the command line: argument vectors built from the real commands and
//! option names with random values (empty, NaN, `inf`, huge, negative, lists with extra
//! commas, unknown options). Every run exits 0, 1 or 2, never panics, prints one line on an
//! error (naming the option or the file at fault when the exit is 2), and writes nothing
//! unless it exits 0.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;
use std::process::Command;

use proptest::prelude::*;
use proptest::test_runner::{Config, FileFailurePersistence};

const ATOMS: [&str; 22] = [
    "", "nan", "NaN", "inf", "-inf", "1e308", "1e400", "-1", "0", "0.1", "2", "-0.3", "1e-300",
    "abc", "3:0.5", "1:", "30", "-25", "0.25", "1", "5", "+2",
];

/// A value: one atom, or a list of atoms with random extra commas.
fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        proptest::sample::select(&ATOMS[..]).prop_map(str::to_owned),
        (proptest::collection::vec(proptest::sample::select(&ATOMS[..]), 1..12), 0..4usize)
            .prop_map(|(atoms, extra)| {
                let mut s = atoms.join(",");
                match extra {
                    1 => s.push(','),
                    2 => s.insert(0, ','),
                    3 => s = s.replacen(',', ",,", 1),
                    _ => {}
                }
                s
            }),
        // The right count of plausible numbers: the command may answer.
        (1..12usize, -0.4..0.4f64).prop_map(|(n, x)| vec![format!("{x}"); n].join(",")),
    ]
}

fn robots() -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots");
    let mut v: Vec<String> = ["cdhrm5", "ua3x4", "planar-snake"]
        .iter()
        .map(|r| root.join(r).display().to_string())
        .collect();
    v.extend(["/nonexistent/robot".to_owned(), String::new()]);
    v
}

fn caspr(file: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../sinew-import/tests/data")
        .join(file)
        .display()
        .to_string()
}

/// The options of each command: (name, choices; empty choices: a random value; `None`: a flag).
fn options(command: &str) -> Vec<(&'static str, Option<Vec<String>>)> {
    let s = |v: &[&str]| Some(v.iter().map(|x| (*x).to_owned()).collect::<Vec<String>>());
    let common = vec![
        ("--robot", Some(robots())),
        ("--model", s(&["decoupled", "routed", "both", ""])),
        ("--json", None),
    ];
    let numbers = Some(Vec::new());
    let mut own = match command {
        "routing" => vec![],
        "joint" => vec![
            ("--joint", numbers.clone()),
            ("--q", numbers.clone()),
            ("--torque", numbers.clone()),
            ("--deg", None),
        ],
        "arm" => vec![
            ("--q", numbers.clone()),
            ("--wrench", numbers.clone()),
            ("--levels", numbers.clone()),
            ("--policy", s(&["least-total", "least-norm", "safest", "cheapest"])),
            ("--no-gravity", None),
            ("--deg", None),
        ],
        "sweep" => vec![
            ("--joint", numbers.clone()),
            ("--torque", numbers.clone()),
            ("--grid", s(&["2", "3", "0", "1", "1e9", "-3", "nan", "", "3,3", "1002"])),
            ("--out", s(&["out.csv", "", "missing/out.csv"])),
        ],
        "plan" => vec![
            ("--q", numbers.clone()),
            ("--wrench", numbers.clone()),
            (
                "--objective",
                s(&[
                    "stiffness-along",
                    "compliance-along",
                    "min-stiffness",
                    "volume",
                    "least-tension",
                    "sideways",
                ]),
            ),
            ("--direction", numbers.clone()),
            ("--k-min", numbers.clone()),
            ("--k-des", numbers.clone()),
            ("--margin", numbers.clone()),
            ("--budget", numbers.clone()),
            ("--joint-budget", numbers.clone()),
            ("--fixed-level", numbers.clone()),
            ("--gap", numbers.clone()),
            ("--no-gravity", None),
            ("--deg", None),
        ],
        _ => vec![],
    };
    if command == "import" {
        return vec![
            (
                "--bodies",
                Some(vec![
                    caspr("universal_bodies.xml"),
                    caspr("every_joint_bodies.xml"),
                    caspr("missing.xml"),
                    String::new(),
                ]),
            ),
            (
                "--cables",
                Some(vec![
                    caspr("universal_cables.xml"),
                    caspr("every_joint_cables.xml"),
                    caspr("universal_bodies.xml"),
                ]),
            ),
            ("--cable-set", s(&["basic", "springs", "nope", ""])),
            ("--youngs-modulus", numbers.clone()),
            ("--diameter", numbers.clone()),
            ("--free-length", numbers.clone()),
            ("--tension-limits", numbers.clone()),
            ("--name", s(&["arm", "", "a/b", "ü"])),
            ("--out", s(&["folder", "", "missing/folder"])),
        ];
    }
    own.splice(0..0, common);
    own
}

/// An argument vector: a command, each of its options with probability 3/4, sometimes an
/// unknown option or a repeated one.
fn argv() -> impl Strategy<Value = Vec<String>> {
    const COMMANDS: [&str; 6] = ["routing", "joint", "arm", "sweep", "plan", "import"];
    (
        proptest::sample::select(&COMMANDS[..]),
        proptest::collection::vec((0..4u8, value(), 0..16usize), 16),
        0..8u8,
    )
        .prop_map(|(command, draws, odd)| {
            let mut args: Vec<String> = if command == "import" {
                vec!["import".into(), "caspr".into()]
            } else {
                vec![command.into()]
            };
            for ((name, choices), (keep, random, pick)) in options(command).into_iter().zip(draws) {
                if keep == 0 {
                    continue;
                }
                match choices {
                    None => args.push(name.into()),
                    Some(c) if c.is_empty() => args.extend([name.into(), random]),
                    Some(c) => args.extend([name.into(), c[pick % c.len()].clone()]),
                }
            }
            match odd {
                0 => args.push("--bogus".into()),
                1 => args.extend(["--json".into(), "--json".into()]),
                _ => {}
            }
            args
        })
}

fn check(args: &[String]) -> Result<(), TestCaseError> {
    let cwd = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_sinew"))
        .args(args)
        .current_dir(cwd.path())
        .output()
        .unwrap();
    let (stdout, stderr) =
        (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    let code = out.status.code();
    prop_assert!(matches!(code, Some(0..=2)), "{args:?}: exit {code:?}: {stderr}");
    prop_assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    let written: Vec<_> = std::fs::read_dir(cwd.path()).unwrap().collect();
    if code == Some(0) {
        prop_assert!(!stdout.contains("NaN"), "{args:?}: {stdout}");
        if args.iter().any(|a| a == "--json") && !args.iter().any(|a| a == "--out") {
            prop_assert!(
                serde_json::from_str::<serde_json::Value>(&stdout).is_ok(),
                "{args:?}: {stdout}"
            );
        }
        return Ok(());
    }
    prop_assert!(written.is_empty(), "{args:?}: exit {code:?} wrote {written:?}");
    prop_assert!(stdout.is_empty(), "{args:?}: {stdout}");
    prop_assert_eq!(stderr.lines().count(), 1, "{:?}: {}", args, stderr);
    prop_assert!(stderr.starts_with("sinew: "), "{args:?}: {stderr}");
    if code == Some(2) {
        // The option at fault, or the file it named.
        let names = args.iter().any(|a| {
            (a.starts_with("--") && stderr.contains(a.as_str()))
                || (a.contains('/') && stderr.contains(a.as_str()))
        });
        prop_assert!(names || stderr.contains("required"), "{args:?}: names no option: {stderr}");
    }
    Ok(())
}

proptest! {
    #![proptest_config(Config {
        cases: 64,
        failure_persistence: Some(Box::new(FileFailurePersistence::Off)),
        ..Config::default()
    })]

    #[test]
    fn every_command_line_exits_0_1_or_2_with_one_line_and_writes_nothing_on_failure(args in argv()) {
        check(&args)?;
    }
}
