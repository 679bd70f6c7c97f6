//! `sinew import caspr`: a CASPR model → a robot folder, written beside `--out` and renamed
//! into place, so that nothing is written to `--out` on failure.

use std::path::{Path, PathBuf};

use sinew_import::ImportOptions;

use crate::cli::CasprArgs;
use crate::error::{CliError, library_error};
use crate::input::{numbers_n, one_number};

/// Run `sinew import caspr`.
pub fn caspr(args: &CasprArgs) -> Result<(), CliError> {
    check_out(&args.out)?;
    let options = options(args)?;
    let folder = sinew_import::import_caspr_files(
        &args.bodies,
        &args.cables,
        args.operational_spaces.as_deref(),
        &options,
    )
    .map_err(CliError::input)?;

    let tmp = temporary_beside(&args.out)?;
    let written = (|| {
        folder.write_into(&tmp).map_err(CliError::input)?;
        // The folder must load as a robot before it is put in place.
        let robot = sinew::robot::load(&tmp).map_err(|e| {
            CliError::input(format!("the written URDF does not load: {}", library_error(e)))
        })?;
        let routing = sinew::routing::load(&tmp, &robot).err();
        if std::fs::read_dir(&args.out).is_ok() {
            // Empty (checked above): replaced by the new folder.
            std::fs::remove_dir(&args.out).map_err(|e| out_error(&args.out, e))?;
        }
        std::fs::rename(&tmp, &args.out).map_err(|e| out_error(&args.out, e))?;
        Ok(routing)
    })();
    let routing_error = match written {
        Ok(r) => r,
        Err(e) => {
            // Best effort: the temporary folder is ours; the error says what went wrong.
            let _ = std::fs::remove_dir_all(&tmp);
            return Err(e);
        }
    };
    for warning in &folder.warnings {
        eprintln!("sinew: warning: {warning}");
    }
    if let Some(e) = routing_error {
        // The message names the temporary folder, renamed since.
        let message = library_error(e).to_string();
        let message = message.replace(&tmp.display().to_string(), &args.out.display().to_string());
        eprintln!("sinew: warning: cables.toml does not load with this Sinew yet: {message}");
    }
    println!("wrote {}: {}", args.out.display(), folder.summary());
    Ok(())
}

fn out_error(out: &Path, e: std::io::Error) -> CliError {
    CliError::input(format!("--out {}: {e}", out.display()))
}

/// `--out` must not exist, or be an empty folder.
fn check_out(out: &Path) -> Result<(), CliError> {
    match std::fs::read_dir(out) {
        Ok(mut entries) => {
            if entries.next().is_some() {
                return Err(CliError::input(format!(
                    "--out {}: the folder exists and is not empty; give a new folder",
                    out.display()
                )));
            }
            Ok(())
        }
        Err(_) if out.exists() => {
            Err(CliError::input(format!("--out {}: exists and is not a folder", out.display())))
        }
        Err(_) => Ok(()),
    }
}

/// A new folder beside `out` (same file system, so that the final rename is atomic).
fn temporary_beside(out: &Path) -> Result<PathBuf, CliError> {
    let parent = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let stem = out.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = parent.join(format!(".{stem}.sinew-import-{}", std::process::id()));
    std::fs::create_dir(&tmp).map_err(|e| {
        CliError::input(format!("--out {}: cannot create {}: {e}", out.display(), tmp.display()))
    })?;
    Ok(tmp)
}

fn options(args: &CasprArgs) -> Result<ImportOptions, CliError> {
    let one = |option: &str, text: &Option<String>, default: f64| -> Result<f64, CliError> {
        match text {
            Some(t) => one_number(option, t),
            None => Ok(default),
        }
    };
    let name = match &args.name {
        Some(name) => name.clone(),
        None => {
            let stem = args.bodies.file_stem().map(|s| s.to_string_lossy().into_owned());
            let stem = stem.unwrap_or_default();
            stem.strip_suffix("_bodies").unwrap_or(&stem).to_owned()
        }
    };
    let tension_limits = match &args.tension_limits {
        Some(t) => {
            let v = numbers_n("--tension-limits", t, 2, "numbers (MIN,MAX)")?;
            Some([v[0], v[1]])
        }
        None => None,
    };
    Ok(ImportOptions {
        name,
        cable_set: args.cable_set.clone(),
        youngs_modulus: one(
            "--youngs-modulus",
            &args.youngs_modulus,
            sinew_import::DEFAULT_YOUNGS_MODULUS,
        )?,
        diameter: one("--diameter", &args.diameter, sinew_import::DEFAULT_DIAMETER)?,
        free_length: one("--free-length", &args.free_length, sinew_import::DEFAULT_FREE_LENGTH)?,
        tension_limits,
    })
}
