//! `cargo xtask test [--locked]`: every test of the project in one command. `cargo test
//! --workspace`, then the Python bindings: a virtualenv in `target/py-venv` (made once; pip
//! installs numpy, pytest, mujoco, dask[array] and distributed into it), the package assembled in
//! `target/py-pkg/sinew` from `crates/sinew-py/python/sinew` and the extension module `cargo
//! test` has just built (the `sinew-py` cdylib, `target/debug/deps/lib_sinew.so`: its example
//! links the library, so the workspace build makes it with the workspace's features and
//! nothing is compiled again), and pytest on `crates/sinew-py/tests` with that folder first on
//! `PYTHONPATH`. pytest's "no tests collected" (exit 5) fails like any other non-zero exit.
//! `target` is `$CARGO_TARGET_DIR` when it is set (where `cargo test` then builds), else the
//! workspace's `target/`. (Users install the package with `pip install ./crates/sinew-py` or
//! `maturin develop`; building it with maturin here would compile the dependencies again with
//! maturin's feature set, about two minutes of CI.)

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use crate::DynResult;

/// What pip installs into the virtualenv: the tests' dependencies only (mujoco: the exported
/// MJCF models are checked by the simulator, `crates/sinew-py/tests/test_mujoco.py`; dask's for
/// the `sinew.dask` tests: a two-worker LocalCluster). Dask through its `distributed` extra,
/// which pins distributed to dask's own version: asked for separately, pip once took dask
/// 2026.11.0 before its distributed was published and paired it with distributed 2021.4.1,
/// which does not import.
const PYTHON_PACKAGES: [&str; 4] = ["numpy", "pytest", "mujoco", "dask[array,distributed]"];

/// Cargo's target folder: `$CARGO_TARGET_DIR` (relative to the workspace) or `target/`.
fn target_dir(root: &Path) -> std::path::PathBuf {
    match std::env::var_os("CARGO_TARGET_DIR") {
        Some(dir) if !dir.is_empty() => root.join(dir),
        _ => root.join("target"),
    }
}

pub fn run(root: &Path, args: &[String]) -> DynResult<()> {
    let mut locked = false;
    for arg in args {
        match arg.as_str() {
            "--locked" => locked = true,
            other => return Err(format!("test: unknown option `{other}` (only --locked)").into()),
        }
    }
    let lock: &[&str] = if locked { &["--locked"] } else { &[] };
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());

    println!("== cargo test --workspace {}", lock.join(" "));
    status(Command::new(&cargo).current_dir(root).args(["test", "--workspace"]).args(lock))?;

    let start = Instant::now();
    let target = target_dir(root);
    let venv = target.join("py-venv");
    let bin = venv.join("bin");
    if !bin.join("python").is_file() {
        println!("== python3 -m venv {}", venv.display());
        status(Command::new("python3").args(["-m", "venv"]).arg(&venv))?;
    }
    let python = bin.join("python");
    println!("== pip install {}", PYTHON_PACKAGES.join(" "));
    status(
        Command::new(&python)
            .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check"])
            .args(PYTHON_PACKAGES),
    )?;
    // The virtualenv's tools first on PATH, as if it were activated.
    let path = std::env::var_os("PATH").unwrap_or_default();
    let mut paths = vec![bin.clone()];
    paths.extend(std::env::split_paths(&path));
    let path = std::env::join_paths(paths)?;
    let package = assemble_package(root, &target)?;
    println!("== pytest crates/sinew-py/tests");
    // The `sinew` binary the tests compare with: the one `cargo test` built.
    status(
        Command::new(&python)
            .current_dir(root)
            .args(["-m", "pytest", "-q", "crates/sinew-py/tests"])
            .env("SINEW_BIN", target.join("debug").join("sinew"))
            .env("PYTHONPATH", &package)
            .env("PATH", &path),
    )?;
    println!("== the Python step took {:.1} s", start.elapsed().as_secs_f64());
    Ok(())
}

/// `target/py-pkg`: the Python package `sinew` (the sources of `crates/sinew-py/python/sinew`
/// and the extension module `_sinew` that `cargo test --workspace` built), made afresh.
fn assemble_package(root: &Path, target: &Path) -> DynResult<std::path::PathBuf> {
    let built = target.join("debug").join("deps").join(format!(
        "{}_sinew{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    ));
    if !built.is_file() {
        return Err(format!(
            "{}: the sinew-py extension module is missing (cargo test --workspace builds it for its example)",
            built.display()
        )
        .into());
    }
    let out = target.join("py-pkg");
    let package = out.join("sinew");
    if package.exists() {
        std::fs::remove_dir_all(&package)?;
    }
    std::fs::create_dir_all(&package)?;
    let sources = root.join("crates").join("sinew-py").join("python").join("sinew");
    for entry in std::fs::read_dir(&sources)? {
        let path = entry?.path();
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        // The package's own files; not a module a local `maturin develop` left there.
        if path.is_file() && !name.ends_with(".so") && !name.ends_with(".pyd") {
            std::fs::copy(&path, package.join(&name))?;
        }
    }
    std::fs::copy(&built, package.join("_sinew.so"))?;
    println!("== the package: {} (extension module from {})", package.display(), built.display());
    Ok(out)
}

/// Run `command`; an error naming it unless it exits with 0 (pytest's 5, "no tests collected",
/// included).
fn status(command: &mut Command) -> DynResult<()> {
    let shown = format!("{command:?}");
    let status = command.status().map_err(|e| format!("cannot run {shown}: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        let why = match status.code() {
            Some(5) if shown.contains("pytest") => " (pytest collected no tests)".to_owned(),
            Some(code) => format!(" (exit code {code})"),
            None => " (killed by a signal)".to_owned(),
        };
        Err(format!("{shown} failed{why}").into())
    }
}
