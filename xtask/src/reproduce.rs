//! `cargo xtask reproduce`: every table and figure of the paper from `robots/cdhrm5`, written
//! to `docs/reproduction/`. With `--check` it writes them to `target/reproduce-check/` instead
//! and fails unless every file equals the committed one (the SVGs included, which the snapshot
//! tests do not cover).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use sinew::paper;

use crate::{DynResult, plots};

/// Grid of Fig. 5 (points per axis).
const FIG5_POINTS: usize = 121;
/// The baseline tension level of E4's extra run (the decoupled arm is stable from about 0.1).
const STABLE_BASELINE: f64 = 0.25;
/// Points along E2's segment.
const E2_SAMPLES: usize = 41;

/// Which number of a sweep cell a heat map shows.
type CellValue = fn(&sinew::indicators::SweepCell) -> f64;

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

/// Where the report is committed, relative to the workspace root.
const REPORT_DIR: &str = "docs/reproduction";

/// `cargo xtask reproduce [--check]`.
pub fn run(root: &Path, args: &[String]) -> DynResult<()> {
    let check = match args {
        [] => false,
        [flag] if flag == "--check" => true,
        _ => return Err(format!("reproduce takes no arguments but --check, got {args:?}").into()),
    };
    let dir = if check { root.join("target/reproduce-check") } else { root.join(REPORT_DIR) };
    let written = write_report(root, dir)?;
    if check {
        let stale: Vec<String> = written
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
        if !stale.is_empty() {
            return Err(format!(
                "stale or missing: {}; run `cargo xtask reproduce` and commit {REPORT_DIR}/",
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
    let robot_dir = root.join("robots/cdhrm5");
    let mut out = Output { dir, written: Vec::new() };
    std::fs::create_dir_all(&out.dir)?;

    let started = Instant::now();
    let robot = sinew::robot::load(&robot_dir)?;
    let routing = sinew::routing::load(&robot_dir, &robot)?;
    let table_1 = paper::table_1(&robot_dir)?;
    let table_2 = paper::table_2(&robot, &routing)?;
    let e2 = paper::e2(&robot, &routing, E2_SAMPLES)?;
    let e3 = paper::e3(&robot, &routing, FIG5_POINTS)?;
    let claims = paper::claims_e1_e3(&table_2, &e2, &e3);
    let routed = sinew::routing::load(robot_dir.join(sinew::routing::ROUTED_ROUTING_FILE), &robot)?;
    let e4 = [
        paper::e4(&robot, &routing, "decoupled", 0.0)?,
        paper::e4(&robot, &routed, "routed", 0.0)?,
        paper::e4(&robot, &routing, "decoupled", STABLE_BASELINE)?,
    ];
    let claims_e4: Vec<_> = e4[..2]
        .iter()
        .flat_map(paper::claims_e4_joints)
        .chain(e4.iter().flat_map(paper::claims_e4_end))
        .collect();
    let comparison = paper::render_routed_vs_decoupled(&e4[0], &e4[1]);
    let computed = started.elapsed();

    out.write("table1.md", &table_1)?;
    out.write("table2.md", &paper::render_table_2(&table_2))?;
    out.write("fig4_e2.csv", &paper::e2_csv(&e2))?;
    out.write("fig5_e3.csv", &paper::e3_csv(&e3))?;
    plots::fig4(&e2, &out.path("fig4_e2.svg"))?;
    let maps: [(&str, &str, CellValue); 4] = [
        ("fig5_kx_min.svg", "(a) minimum of K_x over the feasible tensions", |c| c.k_x.range[0]),
        ("fig5_kx_max.svg", "(b) maximum of K_x over the feasible tensions", |c| c.k_x.range[1]),
        ("fig5_ky_min.svg", "(c) minimum of K_y over the feasible tensions", |c| c.k_y.range[0]),
        ("fig5_ky_max.svg", "(d) maximum of K_y over the feasible tensions", |c| c.k_y.range[1]),
    ];
    for (name, title, value) in maps {
        plots::heat_map(&e3, title, value, &out.path(name))?;
    }

    let mut report = String::new();
    writeln!(report, "# Reproduction of the paper on `robots/cdhrm5`\n")?;
    writeln!(
        report,
        "Written by `cargo xtask reproduce`; do not edit by hand. The same tables are"
    )?;
    writeln!(
        report,
        "snapshot-tested by `cargo test` (`tests/reproduction.rs`). The robot's unstated"
    )?;
    writeln!(report, "parameters and why they were chosen: `robots/cdhrm5/README.md`.\n")?;
    writeln!(report, "## Table I: the platform\n\n{table_1}")?;
    writeln!(report, "## Table II (E1): joint stiffness at the angle limits\n")?;
    writeln!(
        report,
        "Joint 1, τ = [0.3, 0.3] N m, f ∈ [20, 600] N; ranges over the feasible tensions, N m/rad. The unstated single-joint geometry (hole radius, θ0, d1, d2, cable stiffness) is fitted to this table by `cargo xtask calibrate` (spec §7; values and bounds in `robots/cdhrm5/README.md`).\n"
    )?;
    writeln!(report, "{}", paper::render_table_2(&table_2))?;
    writeln!(report, "## Fig. 4 (E2): tensions and stiffness along the feasible segment\n")?;
    writeln!(report, "q = [π/7, −π/9] rad, τ = [−1, 0.5] N m. Data: `fig4_e2.csv`.\n")?;
    writeln!(report, "![Fig. 4](fig4_e2.svg)\n")?;
    writeln!(report, "## Fig. 5 (E3): limits of the joint stiffness over the joint angles\n")?;
    writeln!(
        report,
        "τ = [0.3, 0.3] N m, q1, q2 ∈ [−π/6, π/6] on a {FIG5_POINTS} × {FIG5_POINTS} grid ({} of {} points feasible; grey: infeasible). Data: `fig5_e3.csv`.\n",
        e3.feasible(),
        FIG5_POINTS * FIG5_POINTS
    )?;
    writeln!(report, "| | minimum | maximum |\n| --- | --- | --- |")?;
    writeln!(report, "| K_x | ![](fig5_kx_min.svg) | ![](fig5_kx_max.svg) |")?;
    writeln!(report, "| K_y | ![](fig5_ky_min.svg) | ![](fig5_ky_max.svg) |\n")?;
    writeln!(report, "## The paper's claims on E1–E3\n\n{}", paper::render_claims(&claims))?;
    writeln!(
        report,
        "## Fig. 6 (E4): end stiffness under different joint stiffness distributions\n"
    )?;
    writeln!(
        report,
        "Q = [−π/7, −π/9, −π/9, −π/11, π/6, π/7, π/8, −π/15, −π/12, −π/10] rad, F0 = [0, 5, 0, 0, 0, 0] (N, N m; the wrench the tip exerts, base frame), gravity on (mounting: `robots/cdhrm5/README.md`). Tension levels: 0 = least total tension on the joint's feasible interval, 1 = most. Stability margin: smallest eigenvalue of K_q + K_W.\n"
    )?;
    let titles = [
        ("e4_decoupled.md", "Decoupled (the paper's model)"),
        ("e4_routed.md", "Routed"),
        ("e4_decoupled_baseline.md", "Decoupled, the other joints at a stable baseline level"),
    ];
    for (model, (file, title)) in e4.iter().zip(titles) {
        let rendered = paper::render_e4(model);
        out.write(file, &rendered)?;
        writeln!(report, "### {title}\n\n{rendered}")?;
    }
    writeln!(
        report,
        "The last run is not the paper's: with every other joint at its lowest level the decoupled arm is unstable in cases (a)–(c), so the comparison is repeated with the joints that are not raised at level {STABLE_BASELINE}, where the arm is stable, to check conclusion (3) at all.\n"
    )?;
    plots::fig6(&[&e4[0], &e4[2], &e4[1]], &out.path("fig6_e4.svg"))?;
    writeln!(
        report,
        "Deformation ellipsoids `{{K_fd⁻¹ F : |F| = 1 N}}` of the cases that are feasible and stable:\n\n![Fig. 6](fig6_e4.svg)\n"
    )?;
    writeln!(report, "## Routed beside decoupled (beyond the paper)\n\n{comparison}")?;
    writeln!(report, "## The paper's conclusions on E4\n\n{}", paper::render_claims(&claims_e4))?;
    out.write("README.md", &report)?;

    println!(
        "computed E1–E4 in {:.2} s (Fig. 5 grid {FIG5_POINTS} × {FIG5_POINTS})",
        computed.as_secs_f64()
    );
    for c in claims.iter().chain(&claims_e4) {
        println!("  {}: {}", c.verdict(), c.claim);
    }
    println!("wrote:");
    for path in &out.written {
        println!("  {}", path.strip_prefix(root).unwrap_or(path).display());
    }
    Ok(out.written)
}
