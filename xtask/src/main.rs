//! `cargo xtask <command>`: project automation.
//!
//! - `reproduce [--check]`: every table and figure of the paper, from the robot files in
//!   `robots/`; `--check` fails when the committed `docs/reproduction/` is stale.
//! - `gen-chain`: write the URDF of a uniform chain of universal joints.
//! - `test [--locked]`: `cargo test --workspace`, then the Python bindings' pytest suite.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

mod calibrate;
mod plots;
mod pytest;
mod reproduce;

type DynResult<T> = Result<T, Box<dyn std::error::Error>>;

const USAGE: &str = "usage: cargo xtask <command>

commands:
  reproduce [--check]             every table and figure of the paper (robots/cdhrm5) into docs/reproduction/;
                                  --check: write them under target/ and fail if the committed ones differ
  gen-chain --joints N --out FILE [--name NAME] [--d1 M] [--d2 M] [--link-length M]
            [--link-radius M] [--mass-per-link KG] [--limit RAD]
                                  write the URDF of a uniform chain of universal joints
  test [--locked]                 every test: cargo test --workspace, then the Python bindings (a virtualenv in
                                  target/py-venv, pip install maturin numpy pytest, maturin develop, pytest)
  calibrate [--check]             fit the unstated joint geometry to Table II and write it into robots/cdhrm5";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.first().map(String::as_str) {
        Some("reproduce") => reproduce::run(&project_root(), &args[1..]),
        Some("gen-chain") => gen_chain(&args[1..]),
        Some("calibrate") => calibrate::run(&args[1..]),
        Some("test") => pytest::run(&project_root(), &args[1..]),
        Some("-h" | "--help") | None => {
            println!("{USAGE}");
            Ok(())
        }
        Some(other) => Err(format!("unknown command `{other}`\n\n{USAGE}").into()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask: {e}");
            ExitCode::FAILURE
        }
    }
}

/// The workspace root (xtask lives one level below it).
fn project_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().map(Path::to_path_buf).unwrap_or_default()
}

fn gen_chain(args: &[String]) -> DynResult<()> {
    let mut joints = None;
    let mut out = None;
    let mut chain = sinew_testkit::cdhrm5::uniform_chain(1);
    let mut mass_per_link = None;
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        let value = it.next().ok_or_else(|| format!("{flag} needs a value"))?;
        let number = || -> DynResult<f64> {
            value.parse::<f64>().map_err(|e| format!("{flag} {value}: {e}").into())
        };
        match flag.as_str() {
            "--joints" => joints = Some(value.parse::<usize>()?),
            "--out" => out = Some(PathBuf::from(value)),
            "--name" => chain.name = value.clone(),
            "--d1" => chain.d1 = number()?,
            "--d2" => chain.d2 = number()?,
            "--link-length" => chain.link_length = number()?,
            "--link-radius" => chain.link_radius = number()?,
            "--mass-per-link" => mass_per_link = Some(number()?),
            "--limit" => chain.limit = number()?,
            _ => return Err(format!("unknown option {flag}\n\n{USAGE}").into()),
        }
    }
    let joints = joints.ok_or("--joints N is required")?;
    let out = out.ok_or("--out FILE is required")?;
    chain.joints = joints;
    chain.total_mass = mass_per_link.unwrap_or(0.24) * joints as f64;
    if chain.name == "uniform1" {
        chain.name = format!("uniform{joints}");
    }
    // Check that the chain loads before writing it.
    chain.build()?;
    std::fs::write(&out, chain.to_urdf())?;
    println!("wrote {} ({} universal joints, {} DOF)", out.display(), joints, 2 * joints);
    Ok(())
}
