//! docs/ARCHITECTURE.md cannot drift from the tree: every `crates/*` folder has a section of
//! the code map, every section names a folder that exists, and every path the document names
//! (a backticked `a/b/...` rooted at a top-level folder, or a backticked `file.rs` inside a
//! crate's section) exists.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Top-level folders a backticked path may start with.
const ROOTS: [&str; 9] =
    ["crates/", "docs/", "robots/", "xtask/", "src/", "tests/", "scripts/", ".ci/", "examples/"];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn architecture() -> String {
    let path = root().join("docs/ARCHITECTURE.md");
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The backticked spans of a line.
fn backticked(line: &str) -> impl Iterator<Item = &str> {
    line.split('`').skip(1).step_by(2)
}

/// `### `crates/name`` headings of the code map, in order.
fn crate_sections(doc: &str) -> Vec<String> {
    doc.lines()
        .filter_map(|l| l.strip_prefix("### `crates/"))
        .filter_map(|rest| rest.split('`').next())
        .map(|name| name.trim_end_matches('/').to_owned())
        .collect()
}

fn contains_file(dir: &Path, name: &str) -> bool {
    let Ok(entries) = std::fs::read_dir(dir) else { return false };
    entries.flatten().any(|e| {
        let path = e.path();
        if path.is_dir() {
            path.file_name().is_none_or(|n| n != "target") && contains_file(&path, name)
        } else {
            path.file_name().is_some_and(|n| n == name)
        }
    })
}

#[test]
fn every_crate_has_a_section_and_every_section_a_crate() {
    let doc = architecture();
    let sections: BTreeSet<String> = crate_sections(&doc).into_iter().collect();
    let crates: BTreeSet<String> = std::fs::read_dir(root().join("crates"))
        .expect("crates/ exists")
        .flatten()
        .filter(|e| e.path().join("Cargo.toml").is_file())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    let missing: Vec<_> = crates.difference(&sections).collect();
    let stale: Vec<_> = sections.difference(&crates).collect();
    assert!(missing.is_empty(), "crates without a `### `crates/…`` section: {missing:?}");
    assert!(stale.is_empty(), "sections for crates that do not exist: {stale:?}");
}

#[test]
fn every_path_the_document_names_exists() {
    let doc = architecture();
    let mut section: Option<PathBuf> = None;
    let mut missing = Vec::new();
    let mut checked = 0;
    for line in doc.lines() {
        if line.starts_with("## ") || line.starts_with("### ") {
            section = backticked(line)
                .next()
                .filter(|p| p.starts_with("crates/") || *p == "xtask" || *p == "src/")
                .map(|p| root().join(p));
        }
        for span in backticked(line) {
            let span = span.trim_end_matches(['.', ',', ':']);
            if span.contains(' ') || span.contains('*') || span.contains('<') {
                continue;
            }
            if ROOTS.iter().any(|r| span.starts_with(r)) {
                checked += 1;
                if !root().join(span).exists() {
                    missing.push(span.to_owned());
                }
            } else if span.ends_with(".rs") && !span.contains('/') {
                checked += 1;
                let found = match &section {
                    Some(dir) => contains_file(dir, span),
                    None => contains_file(&root(), span),
                };
                if !found {
                    missing.push(format!("{span} (in section {section:?})"));
                }
            }
        }
    }
    assert!(checked >= 20, "only {checked} paths found: is the document's format still parsed?");
    assert!(missing.is_empty(), "docs/ARCHITECTURE.md names paths that do not exist: {missing:?}");
}

/// The rows of the dependency table under the bird's-eye view: `| `crate` | `dep`, `dep` |`.
fn drawn_dependencies(doc: &str) -> std::collections::BTreeMap<String, BTreeSet<String>> {
    let start = doc.find("<!-- dependencies -->").expect("the dependency table's marker");
    let end = doc[start..].find("<!-- /dependencies -->").expect("its end marker") + start;
    doc[start..end]
        .lines()
        .filter(|l| l.starts_with("| `"))
        .map(|l| {
            let cells: Vec<&str> = l.split('|').collect();
            let name = backticked(cells[1]).next().unwrap_or_default().to_owned();
            let deps = backticked(cells[2]).map(str::to_owned).collect();
            (name, deps)
        })
        .collect()
}

/// The normal (not dev, not build) dependencies on the workspace's own crates of the package
/// whose manifest is `path`.
fn normal_sinew_dependencies(path: &Path) -> (String, BTreeSet<String>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let manifest: toml::Table = text.parse().unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let name = manifest["package"]["name"].as_str().expect("a package name").to_owned();
    let deps = manifest
        .get("dependencies")
        .and_then(|d| d.as_table())
        .map(|d| d.keys().filter(|k| k.starts_with("sinew")).cloned().collect())
        .unwrap_or_default();
    (name, deps)
}

#[test]
fn every_dependency_between_our_crates_is_drawn_and_every_drawn_one_exists() {
    let drawn = drawn_dependencies(&architecture());
    let mut manifests: Vec<PathBuf> = std::fs::read_dir(root().join("crates"))
        .expect("crates/ exists")
        .flatten()
        .map(|e| e.path().join("Cargo.toml"))
        .filter(|p| p.is_file())
        .collect();
    manifests.push(root().join("xtask/Cargo.toml"));
    manifests.push(root().join("Cargo.toml"));
    let mut problems = Vec::new();
    for manifest in &manifests {
        let (name, deps) = normal_sinew_dependencies(manifest);
        let Some(allowed) = drawn.get(&name) else {
            problems.push(format!("{name}: no row in the dependency table"));
            continue;
        };
        for d in deps.difference(allowed) {
            problems.push(format!("{name} depends on {d}, which the table does not draw"));
        }
        for d in allowed.difference(&deps) {
            problems.push(format!("the table draws {name} → {d}, which Cargo.toml does not have"));
        }
        if name != "xtask" && deps.contains("sinew-testkit") {
            problems.push(format!("{name}: sinew-testkit is dev-only"));
        }
    }
    assert_eq!(drawn.len(), manifests.len(), "rows for packages that do not exist: {drawn:?}");
    assert!(problems.is_empty(), "{problems:#?}");
}
