//! `cargo xtask reproduce`: every table and figure of the paper from `robots/cdhrm5`, written
//! to `docs/reproduction/`. Everything is computed once by [`sinew::paper::Report`]; this file
//! writes its text files and draws its figures. With `--check` it writes them to
//! `target/reproduce-check/` instead and fails unless every file equals the committed one (the
//! figures included, which the snapshot tests do not cover) and no committed file is left that
//! the report no longer writes.

use std::path::{Path, PathBuf};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use sinew::paper::{self, REPORT_DIR, Report};

use crate::{DynResult, plots};

/// A progress bar for Fig. 5's sweep on standard error (drawn only on a terminal).
fn sweep_bar(total: usize) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(total as u64), ProgressDrawTarget::stderr());
    if let Ok(style) =
        ProgressStyle::with_template("fig. 5 sweep {bar:40} {pos}/{len} points ({eta} left)")
    {
        bar.set_style(style);
    }
    bar
}

struct Output {
    dir: PathBuf,
    written: Vec<PathBuf>,
}

impl Output {
    fn write(&mut self, name: &str, text: &str) -> DynResult<()> {
        let path = self.dir.join(name);
        std::fs::write(&path, text)?;
        self.written.push(path);
        Ok(())
    }

    fn path(&mut self, name: &str) -> PathBuf {
        let path = self.dir.join(name);
        self.written.push(path.clone());
        path
    }
}

/// `cargo xtask reproduce [--check]`.
pub fn run(root: &Path, args: &[String]) -> DynResult<()> {
    let check = match args {
        [] => false,
        [flag] if flag == "--check" => true,
        _ => return Err(format!("reproduce takes no arguments but --check, got {args:?}").into()),
    };
    let dir = if check { root.join("target/reproduce-check") } else { root.join(REPORT_DIR) };
    if check {
        // Start empty, so that a file the report no longer writes is not compared by mistake.
        let _ = std::fs::remove_dir_all(&dir);
    }
    let written = write_report(root, dir)?;
    let names: Vec<_> = written.iter().filter_map(|p| p.file_name()).collect();
    // The committed files that the report no longer writes (e.g. figures in another format).
    let mut extra = Vec::new();
    for entry in std::fs::read_dir(root.join(REPORT_DIR))? {
        let path = entry?.path();
        if path.file_name().is_some_and(|name| !names.contains(&name)) {
            extra.push(path);
        }
    }
    if !check {
        // docs/reproduction/ is generated: it holds the report and nothing else.
        for path in &extra {
            std::fs::remove_file(path)?;
            println!("removed {}", path.strip_prefix(root).unwrap_or(path).display());
        }
    } else {
        let mut stale: Vec<String> = written
            .iter()
            .filter_map(|fresh| {
                let name = fresh.file_name()?;
                let committed = root.join(REPORT_DIR).join(name);
                let same = matches!(
                    (std::fs::read(fresh), std::fs::read(&committed)),
                    (Ok(a), Ok(b)) if a == b
                );
                (!same).then(|| format!("{REPORT_DIR}/{}", name.to_string_lossy()))
            })
            .collect();
        for path in &extra {
            let name = path.file_name().map(|n| n.to_string_lossy()).unwrap_or_default();
            stale.push(format!("{REPORT_DIR}/{name} (no longer written)"));
        }
        if !stale.is_empty() {
            return Err(format!(
                "stale, missing or extra: {}; run `cargo xtask reproduce` and commit {REPORT_DIR}/",
                stale.join(", ")
            )
            .into());
        }
        println!("{REPORT_DIR}/ is up to date ({} files compared)", written.len());
    }
    Ok(())
}

/// Compute everything and write the report into `dir`; returns the files written.
fn write_report(root: &Path, dir: PathBuf) -> DynResult<Vec<PathBuf>> {
    let mut out = Output { dir, written: Vec::new() };
    std::fs::create_dir_all(&out.dir)?;

    let started = Instant::now();
    let bar = sweep_bar(paper::E3_POINTS * paper::E3_POINTS);
    let report = Report::compute_with_progress(&root.join(paper::ROBOT_DIR), &|done, _| {
        bar.set_position(done as u64)
    });
    bar.finish_and_clear();
    let report = report?;
    let computed = started.elapsed();

    for (name, text) in report.text_files() {
        out.write(name, &text)?;
    }
    plots::fig4(&report.e2, &out.path(paper::FIG4_FILE))?;
    for map in paper::FIG5_MAPS {
        plots::heat_map(&report.e3, map.title, map.value, &out.path(map.file))?;
    }
    plots::fig6(
        &[&report.e4_decoupled, &report.e4_stable, &report.e4_routed],
        &out.path(paper::FIG6_FILE),
    )?;
    plots::fig_e5(&[&report.e5_decoupled, &report.e5_routed], &out.path(paper::FIG_E5_FILE))?;
    plots::fig_e6(&report.e6, &out.path(paper::FIG_E6_FILE))?;
    plots::fig_e7(&report.e7, &out.path(paper::FIG_E7_FILE))?;

    println!(
        "computed E1–E7 in {:.2} s (Fig. 5 grid {n} × {n})",
        computed.as_secs_f64(),
        n = paper::E3_POINTS
    );
    for c in report.claims() {
        println!("  {}: {}", c.verdict(), c.claim);
    }
    println!("wrote:");
    for path in &out.written {
        println!("  {}", path.strip_prefix(root).unwrap_or(path).display());
    }
    Ok(out.written)
}
