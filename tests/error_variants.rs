//! Every variant of every `enum …Error` in every crate's `error.rs` is named
//! (`EnumError::Variant`) in some test, so that each error a user can meet is produced and
//! checked somewhere; the few that no test can reach stand on an allow-list with the reason.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Variants no test names, each with why.
const ALLOWED: &[(&str, &str)] = &[];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// `(file, Enum::Variant)` of every `pub enum …Error` in `text` (variants at four spaces).
fn variants(file: &str, text: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut current: Option<String> = None;
    for line in text.lines() {
        if let Some(rest) = line.strip_prefix("pub enum ") {
            let name: String =
                rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            current = name.ends_with("Error").then_some(name);
            continue;
        }
        if line.starts_with('}') {
            current = None;
            continue;
        }
        let Some(enum_name) = &current else { continue };
        let Some(rest) = line.strip_prefix("    ") else { continue };
        if rest.starts_with(char::is_uppercase) {
            let variant: String =
                rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            out.push((file.to_owned(), format!("{enum_name}::{variant}")));
        }
    }
    out
}

/// Whether `text` names `path` as a whole path (`Error::Io` is not named by `RobotError::Io`).
fn names(text: &str, path: &str) -> bool {
    let word = |c: Option<char>| c.is_some_and(|c| c.is_alphanumeric() || c == '_');
    text.match_indices(path).any(|(i, _)| {
        !word(text[..i].chars().next_back()) && !word(text[i + path.len()..].chars().next())
    })
}

#[test]
fn every_error_variant_is_named_in_some_test() {
    assert!(names("x StiffnessError::Statics(e)", "StiffnessError::Statics"));
    assert!(!names("x StiffnessError::Statics(e)", "Error::Statics"));
    assert!(!names("RobotError::IoFailure", "RobotError::Io"));
    let root = root();
    let mut sources = vec![root.join("src/error.rs")];
    let mut tests = Vec::new();
    rust_files(&root.join("tests"), &mut tests);
    rust_files(&root.join("xtask/tests"), &mut tests);
    for entry in std::fs::read_dir(root.join("crates")).unwrap() {
        let dir = entry.unwrap().path();
        if dir.join("src/error.rs").is_file() {
            sources.push(dir.join("src/error.rs"));
        }
        rust_files(&dir.join("tests"), &mut tests);
    }
    let this = Path::new(file!()).file_name().unwrap();
    let text: String = tests
        .iter()
        .filter(|p| p.file_name() != Some(this))
        .map(|p| std::fs::read_to_string(p).unwrap())
        .collect::<Vec<_>>()
        .join("\n");
    let mut all = Vec::new();
    for source in &sources {
        let rel = source.strip_prefix(&root).unwrap().display().to_string();
        all.extend(variants(&rel, &std::fs::read_to_string(source).unwrap()));
    }
    assert!(all.len() > 100, "only {} variants found: the parser is broken", all.len());
    for must in [
        "StaticsError::NoEquilibrium",
        "ImportError::EmptyCableSet",
        "PlanError::BudgetsInfeasible",
        "Error::Statics",
    ] {
        assert!(all.iter().any(|(_, v)| v == must), "{must} not found among the variants");
    }
    let allowed: BTreeSet<&str> = ALLOWED.iter().map(|(v, _)| *v).collect();
    let missing: Vec<String> = all
        .iter()
        .filter(|(_, v)| !names(&text, v) && !allowed.contains(v.as_str()))
        .map(|(f, v)| format!("{f}: {v}"))
        .collect();
    assert!(
        missing.is_empty(),
        "error variants no test names (produce each in a test, or allow-list it with a reason):\n{}",
        missing.join("\n")
    );
    // An allow-listed variant that a test now names, or that no longer exists, leaves the list.
    for (v, reason) in ALLOWED {
        assert!(!reason.is_empty(), "{v}: no reason");
        assert!(all.iter().any(|(_, x)| x == v), "{v} is allow-listed but no longer exists");
        assert!(!names(&text, v), "{v} is allow-listed but a test names it: take it off the list");
    }
    println!("{} error variants, all named in tests ({} allow-listed)", all.len(), ALLOWED.len());
}
