//! The whole reproduction report, computed once: every experiment's parameters as named
//! constants, every table, data set and claim in [`Report`], and the report's text files.
//! `cargo xtask reproduce` writes these files and draws the figures from the same `Report`;
//! the snapshot tests compare them.

use std::fmt::Write as _;
use std::path::Path;

use crate::indicators::{SweepCell, SweepMaps};
use crate::robot::Robot;
use crate::routing::Routing;

use super::arm::{E4, claims_e4_end, claims_e4_joints, e4, render_e4, render_routed_vs_decoupled};
use super::claims::{Claim, claims_e1_e3, render_claims};
use super::e6::{E6, E6_FILE, e6, e6_section, render_e6};
use super::e7::{E7, e7, render_e7};
use super::experiments::{E2_SAMPLES, E3_POINTS, E4_PAPER_BASELINE, E4_STABLE_BASELINE, E5_MARGIN};
use super::planning::{E5, e5, e5_csv, render_e5};
use super::single_joint::{
    E2Point, Table2Row, e2, e2_csv, e3_csv, e3_with_progress, render_table_2, table_2,
};
use super::table1::table_1;

/// The robot folder of the report, relative to the workspace root.
pub const ROBOT_DIR: &str = "robots/cdhrm5";
/// Where the report is committed, relative to the workspace root.
pub const REPORT_DIR: &str = "docs/reproduction";

/// Fig. 4's file (line plots: SVG).
pub const FIG4_FILE: &str = "fig4_e2.svg";
/// Fig. 6's file (line plots: SVG).
pub const FIG6_FILE: &str = "fig6_e4.svg";
/// E5's trade-off figure (line plots: SVG).
pub const FIG_E5_FILE: &str = "fig_e5_tradeoff.svg";
/// E7's map of the sign of the controllable stiffness over `d1`, `d2` (a raster image: PNG).
pub const FIG_E7_FILE: &str = "fig_e7_tension_stiffens.png";
/// E7's report file.
pub const E7_FILE: &str = "e7_tension_stiffens.md";

/// One heat map of Fig. 5: its file, its title and the number of a sweep cell it shows.
#[derive(Debug, Clone, Copy)]
pub struct HeatMap {
    /// File name in the report (a raster image: PNG).
    pub file: &'static str,
    /// Title drawn above the map.
    pub title: &'static str,
    /// The value shown, N m/rad.
    pub value: fn(&SweepCell) -> f64,
}

/// The four heat maps of Fig. 5: the minimum and the maximum of `K_x` and of `K_y` over the
/// feasible tensions.
pub const FIG5_MAPS: [HeatMap; 4] = [
    HeatMap {
        file: "fig5_kx_min.png",
        title: "(a) minimum of K_x over the feasible tensions",
        value: |c| c.k_x.range[0],
    },
    HeatMap {
        file: "fig5_kx_max.png",
        title: "(b) maximum of K_x over the feasible tensions",
        value: |c| c.k_x.range[1],
    },
    HeatMap {
        file: "fig5_ky_min.png",
        title: "(c) minimum of K_y over the feasible tensions",
        value: |c| c.k_y.range[0],
    },
    HeatMap {
        file: "fig5_ky_max.png",
        title: "(d) maximum of K_y over the feasible tensions",
        value: |c| c.k_y.range[1],
    },
];

/// Every result of the report on one robot folder.
#[derive(Debug, Clone)]
pub struct Report {
    /// The robot.
    pub robot: Robot,
    /// Its default (decoupled) routing.
    pub routing: Routing,
    /// Its routed routing ([`crate::routing::ROUTED_ROUTING_FILE`]).
    pub routed: Routing,
    /// Table I, rendered (markdown).
    pub table_1: String,
    /// Table II (E1), ours beside the paper's.
    pub table_2: Vec<Table2Row>,
    /// E2 (Fig. 4): [`E2_SAMPLES`] points along the feasible segment.
    pub e2: Vec<E2Point>,
    /// E3 (Fig. 5): the [`E3_POINTS`] × [`E3_POINTS`] sweep.
    pub e3: SweepMaps,
    /// The claims of E1–E3.
    pub claims_e1_e3: Vec<Claim>,
    /// E4, the paper's decoupled model at the paper's baseline.
    pub e4_decoupled: E4,
    /// E4, the routed model at the paper's baseline.
    pub e4_routed: E4,
    /// E4, the decoupled model at [`E4_STABLE_BASELINE`].
    pub e4_stable: E4,
    /// The conclusions (1)–(3) on E4: (1) and (2) for the decoupled and the routed runs, (3)
    /// for every run.
    pub claims_e4: Vec<Claim>,
    /// E5 (beyond the paper), the decoupled model: planned tensions at E4's pose.
    pub e5_decoupled: E5,
    /// E5, the routed model.
    pub e5_routed: E5,
    /// E6 (beyond the paper): friction at the holes, decoupled and routed.
    pub e6: E6,
    /// E7 (beyond the paper): when tension stiffens, on joint 1's hole geometry.
    pub e7: E7,
}

/// The E4 runs with their report file and heading, in the report's order.
const E4_RUNS: [(&str, &str); 3] = [
    ("e4_decoupled.md", "Decoupled (the paper's model)"),
    ("e4_routed.md", "Routed"),
    ("e4_decoupled_baseline.md", "Decoupled, the other joints at a stable baseline level"),
];

impl Report {
    /// Compute every table, data set and claim from a robot folder (`robot.toml`, its URDF,
    /// [`crate::routing::ROUTING_FILE`] and [`crate::routing::ROUTED_ROUTING_FILE`]).
    ///
    /// # Errors
    /// A file that cannot be read or a routing the experiments cannot handle; infeasible or
    /// unstable E4 cases are results, not errors.
    pub fn compute(robot_dir: &Path) -> Result<Report, crate::Error> {
        Report::compute_with_progress(robot_dir, &|_, _| {})
    }

    /// [`Report::compute`], reporting the Fig. 5 sweep's `progress(done, total)` as it goes
    /// (`cargo xtask reproduce` draws it as a progress bar on a terminal).
    ///
    /// # Errors
    /// As [`Report::compute`].
    pub fn compute_with_progress(
        robot_dir: &Path,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<Report, crate::Error> {
        let robot = crate::robot::load(robot_dir)?;
        let routing = crate::routing::load(robot_dir, &robot)?;
        let routed =
            crate::routing::load(robot_dir.join(crate::routing::ROUTED_ROUTING_FILE), &robot)?;
        let table_1 = table_1(robot_dir)?;
        let table_2 = table_2(&robot, &routing)?;
        let e2 = e2(&robot, &routing, E2_SAMPLES)?;
        let e3 = e3_with_progress(&robot, &routing, E3_POINTS, progress)?;
        let claims_e1_e3 = claims_e1_e3(&table_2, &e2, &e3);
        let e4_decoupled = e4(&robot, &routing, "decoupled", E4_PAPER_BASELINE)?;
        let e4_routed = e4(&robot, &routed, "routed", E4_PAPER_BASELINE)?;
        let e4_stable = e4(&robot, &routing, "decoupled", E4_STABLE_BASELINE)?;
        let claims_e4 = [&e4_decoupled, &e4_routed]
            .into_iter()
            .flat_map(claims_e4_joints)
            .chain([&e4_decoupled, &e4_routed, &e4_stable].into_iter().flat_map(claims_e4_end))
            .collect();
        let e5_decoupled = e5(&robot, &routing, "decoupled")?;
        let e5_routed = e5(&robot, &routed, "routed")?;
        let e6 = e6(&robot, [("decoupled", &routing), ("routed", &routed)])?;
        let routing_file = robot_dir.join(crate::routing::ROUTING_FILE);
        let text = std::fs::read_to_string(&routing_file).map_err(|source| {
            crate::routing::RoutingError::Io { path: routing_file.clone(), source }
        })?;
        let template =
            crate::routing::RoutingSpec::from_toml_str(&text, &routing_file.display().to_string())?;
        let e7 = e7(&robot, &routing, &template)?;
        Ok(Report {
            robot,
            routing,
            routed,
            table_1,
            table_2,
            e2,
            e3,
            claims_e1_e3,
            e4_decoupled,
            e4_routed,
            e4_stable,
            claims_e4,
            e5_decoupled,
            e5_routed,
            e6,
            e7,
        })
    }

    /// The E4 runs in the report's order: decoupled, routed, decoupled at the stable baseline.
    pub fn e4_runs(&self) -> [&E4; 3] {
        [&self.e4_decoupled, &self.e4_routed, &self.e4_stable]
    }

    /// Every claim of the report, E1–E3, E4, then E7's.
    pub fn claims(&self) -> impl Iterator<Item = &Claim> {
        self.claims_e1_e3.iter().chain(&self.claims_e4).chain(std::iter::once(&self.e7.claim))
    }

    /// The report's text files, `(name in REPORT_DIR, content)`: the tables, the CSV data,
    /// the E4 tables and `README.md` (which shows the figures [`FIG4_FILE`], [`FIG5_MAPS`] and
    /// [`FIG6_FILE`]).
    pub fn text_files(&self) -> Vec<(&'static str, String)> {
        let mut files = vec![
            ("table1.md", self.table_1.clone()),
            ("table2.md", render_table_2(&self.table_2)),
            ("fig4_e2.csv", e2_csv(&self.e2)),
            ("fig5_e3.csv", e3_csv(&self.e3)),
        ];
        for ((file, _), run) in E4_RUNS.iter().zip(self.e4_runs()) {
            files.push((file, render_e4(run)));
        }
        files.push(("e5_decoupled.md", render_e5(&self.e5_decoupled)));
        files.push(("e5_routed.md", render_e5(&self.e5_routed)));
        files.push(("e5_tradeoff.csv", e5_csv(&[&self.e5_decoupled, &self.e5_routed])));
        files.push((E6_FILE, render_e6(&self.e6)));
        files.push((E7_FILE, render_e7(&self.e7)));
        files.push(("README.md", self.readme()));
        files
    }

    /// The report's `README.md`.
    pub fn readme(&self) -> String {
        let mut r = String::new();
        // Writing to a String cannot fail.
        let _ = self.write_readme(&mut r);
        r
    }

    fn write_readme(&self, r: &mut String) -> std::fmt::Result {
        let table_1 = &self.table_1;
        writeln!(r, "# Reproduction of the paper on `{ROBOT_DIR}`\n")?;
        writeln!(
            r,
            "Written by `cargo xtask reproduce`; do not edit by hand. The same tables are"
        )?;
        writeln!(
            r,
            "snapshot-tested by `cargo test` (`tests/reproduction.rs`). The robot's unstated"
        )?;
        writeln!(r, "parameters and why they were chosen: `{ROBOT_DIR}/README.md`.\n")?;
        writeln!(r, "## Table I: the platform\n\n{table_1}")?;
        writeln!(r, "## Table II (E1): joint stiffness at the angle limits\n")?;
        writeln!(
            r,
            "Joint 1, τ = [0.3, 0.3] N m, f ∈ [20, 600] N; ranges over the feasible tensions, N m/rad. The unstated single-joint geometry (hole radius, θ0, d1, d2, cable stiffness) is fitted to this table by `cargo xtask calibrate` (spec §7; values and bounds in `{ROBOT_DIR}/README.md`).\n"
        )?;
        writeln!(r, "{}", render_table_2(&self.table_2))?;
        writeln!(r, "## Fig. 4 (E2): tensions and stiffness along the feasible segment\n")?;
        writeln!(r, "q = [π/7, −π/9] rad, τ = [−1, 0.5] N m. Data: `fig4_e2.csv`.\n")?;
        writeln!(r, "![Fig. 4]({FIG4_FILE})\n")?;
        writeln!(r, "## Fig. 5 (E3): limits of the joint stiffness over the joint angles\n")?;
        writeln!(
            r,
            "τ = [0.3, 0.3] N m, q1, q2 ∈ [−π/6, π/6] on a {E3_POINTS} × {E3_POINTS} grid ({} of {} points feasible; grey: infeasible). Data: `fig5_e3.csv`.\n",
            self.e3.feasible(),
            E3_POINTS * E3_POINTS
        )?;
        let [kx_min, kx_max, ky_min, ky_max] = FIG5_MAPS.map(|m| m.file);
        writeln!(r, "| | minimum | maximum |\n| --- | --- | --- |")?;
        writeln!(r, "| K_x | ![]({kx_min}) | ![]({kx_max}) |")?;
        writeln!(r, "| K_y | ![]({ky_min}) | ![]({ky_max}) |\n")?;
        writeln!(r, "## The paper's claims on E1–E3\n\n{}", render_claims(&self.claims_e1_e3))?;
        writeln!(
            r,
            "## Fig. 6 (E4): end stiffness under different joint stiffness distributions\n"
        )?;
        writeln!(
            r,
            "Q = [−π/7, −π/9, −π/9, −π/11, π/6, π/7, π/8, −π/15, −π/12, −π/10] rad, F0 = [0, 5, 0, 0, 0, 0] (N, N m; the wrench the tip exerts, base frame), gravity on (mounting: `{ROBOT_DIR}/README.md`). Tension levels: 0 = least total tension on the joint's feasible interval, 1 = most. Stability margin: smallest eigenvalue of K_q + K_W.\n"
        )?;
        for ((_, title), run) in E4_RUNS.iter().zip(self.e4_runs()) {
            writeln!(r, "### {title}\n\n{}", render_e4(run))?;
        }
        writeln!(
            r,
            "The last run is not the paper's: with every other joint at its lowest level the decoupled arm is unstable in cases (a)–(c), so the comparison is repeated with the joints that are not raised at level {E4_STABLE_BASELINE}, where the arm is stable, to check conclusion (3) at all.\n"
        )?;
        writeln!(
            r,
            "Deformation ellipsoids `{{K_fd⁻¹ F : |F| = 1 N}}` of the cases that are feasible and stable:\n\n![Fig. 6]({FIG6_FILE})\n"
        )?;
        writeln!(
            r,
            "## Routed beside decoupled (beyond the paper)\n\n{}",
            render_routed_vs_decoupled(&self.e4_decoupled, &self.e4_routed)
        )?;
        writeln!(r, "## The paper's conclusions on E4\n\n{}", render_claims(&self.claims_e4))?;
        writeln!(r, "## E5 (beyond the paper): planned tensions at E4's pose\n")?;
        writeln!(
            r,
            "The paper chooses tension levels by hand; `sinew-planner` chooses the tensions that optimise the end stiffness, with equilibrium exact, every tension in [20, 600] N and the arm stable (smallest eigenvalue of K_q + K_W ≥ {E5_MARGIN} N m/rad), each answer certified by a gap (the true optimum is at most that much better). Same pose and load as E4; the paper's cases (a)–(d) with the other joints at their lowest level, for comparison. \"Σf of (d)\": the planned rows may use no more total tension than case (d).\n"
        )?;
        writeln!(r, "### Decoupled\n\n{}", render_e5(&self.e5_decoupled))?;
        writeln!(r, "### Routed\n\n{}", render_e5(&self.e5_routed))?;
        writeln!(
            r,
            "The best λ_min(K_fd) against the tension budget (data: `e5_tradeoff.csv`):\n\n![E5 trade-off]({FIG_E5_FILE})\n"
        )?;
        writeln!(r, "{}", e6_section(&self.e6))?;
        self.write_e7(r)
    }

    fn write_e7(&self, r: &mut String) -> std::fmt::Result {
        writeln!(r, "## E7 (beyond the paper): when tension stiffens\n")?;
        writeln!(
            r,
            "Conclusion (1), \"the greater the cable tension, the greater the joint stiffness\", is a property of the hole geometry. Along the joint's tension coordinate λ (f = f_p + λ N, eq. 22–23) the joint stiffness changes at the rate A_i = Σ_c N_c H_c (H_c = ∂²L_c/∂q², spec §10). At the straight pose Q0 every cable's Hessian is −d1·d2/(d1 + d2)·I, whatever the hole radius r and angle, so"
        )?;
        writeln!(r, "\n    A_i(Q0) = −d1·d2/(d1 + d2) · (Σ_c N_c) · I₂\n")?;
        writeln!(
            r,
            "(derivation: `src/paper/tension.rs`): tension stiffens the straight joint iff d1·d2 < 0 (the joint centre outside the gap between the hole planes), leaves it alone iff d1·d2 = 0 (a hole plane through the centre: the paper's d2 ≈ 0, cdhrm5's fitted d2 = 0), and softens it iff d1·d2 > 0 (holes below and above the centre). At Q0 A_i is never indefinite; away from it the pose and r matter, so the map classifies A_i over the workspace too. The off-centre geometry is CASPR's snake's hole planes (6.6 mm below, 13.6 mm above the centre) with cdhrm5's cables and hole radius: the rest of that model (its radius, cables, pose and load) is not in this repository, so its 81.7 → 75.8 N m/rad is not reproduced here, only its sign. Joint 1 alone, the other joints straight; K at Q0 holds τ = [0.3, 0.3] N m with f ∈ [20, 600] N. File: `{E7_FILE}`.\n"
        )?;
        writeln!(r, "{}", render_e7(&self.e7))?;
        writeln!(
            r,
            "Sign of A_i over the workspace, d2 against d1 at cdhrm5's r; the closed form's boundary at Q0 (d1 = 0, d2 = 0) dashed, the gap d1 + d2 below the map's minimum in grey:\n\n![E7 map]({FIG_E7_FILE})"
        )
    }
}
