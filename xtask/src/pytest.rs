//! `cargo xtask test [--locked]`: every test of the project in one command. `cargo test
//! --workspace`, then the Python bindings: a virtualenv in `target/py-venv` (made once; pip
//! installs maturin, numpy and pytest into it), `maturin develop` (the dev profile, so it
//! reuses what `cargo test` just built) and pytest on `crates/sinew-py/tests`. pytest's "no
//! tests collected" (exit 5) fails like any other non-zero exit.

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use crate::DynResult;

/// What pip installs into the virtualenv: the build tool and the tests' dependencies only.
const PYTHON_PACKAGES: [&str; 3] = ["maturin>=1.9,<2", "numpy", "pytest"];

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
    let venv = root.join("target").join("py-venv");
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
    println!("== maturin develop (dev profile) in crates/sinew-py");
    status(
        Command::new(bin.join("maturin"))
            .current_dir(root.join("crates").join("sinew-py"))
            .args(["develop", "--quiet"])
            .args(lock)
            .env("VIRTUAL_ENV", &venv)
            .env("PATH", &path)
            .env_remove("CONDA_PREFIX"),
    )?;
    println!("== pytest crates/sinew-py/tests");
    // The `sinew` binary the tests compare with: the one `cargo test` built.
    status(
        Command::new(&python)
            .current_dir(root)
            .args(["-m", "pytest", "-q", "crates/sinew-py/tests"])
            .env("SINEW_BIN", root.join("target").join("debug").join("sinew"))
            .env("PATH", &path),
    )?;
    println!("== the Python step took {:.1} s", start.elapsed().as_secs_f64());
    Ok(())
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
