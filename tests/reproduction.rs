//! The paper's tables as insta snapshots (numbers at fixed precision: a snapshot changes only
//! when a number really changes; review a change with `cargo insta review`), and a check that
//! the committed report in docs/reproduction/ is what `cargo xtask reproduce` writes today.
//! Everything comes from one [`paper::Report`], the one `cargo xtask reproduce` writes.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use sinew::paper;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The report, computed once for every test of this file.
fn report() -> &'static paper::Report {
    static REPORT: OnceLock<paper::Report> = OnceLock::new();
    REPORT.get_or_init(|| paper::Report::compute(&root().join(paper::ROBOT_DIR)).unwrap())
}

/// The committed file must equal what the report writes now.
fn assert_committed(name: &str, fresh: &str) {
    let path: PathBuf = root().join(paper::REPORT_DIR).join(name);
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == fresh,
        "{} is stale: run `cargo xtask reproduce` and commit docs/reproduction/",
        Path::new(paper::REPORT_DIR).join(name).display()
    );
}

#[test]
fn table_1() {
    let table = &report().table_1;
    insta::assert_snapshot!(table);
    assert_committed("table1.md", table);
    // Table I read directly equals the report's.
    assert_eq!(&paper::table_1(&root().join(paper::ROBOT_DIR)).unwrap(), table);
}

/// Table I's values (paper §V) from the loaded robot, routing and URDF, not from the rendered
/// text: the snapshot above only echoes the robot files.
#[test]
fn table_1_values_are_the_papers() {
    let r = report();
    let dir = root().join(paper::ROBOT_DIR);
    let description = sinew::robot::RobotDescription::read(&dir).unwrap();
    // Single link size φ60 × 220 mm: five cylinder links, each that size.
    let urdf = urdf_rs::read_file(&description.urdf).unwrap();
    let cylinders: Vec<(f64, f64)> = urdf
        .links
        .iter()
        .flat_map(|link| &link.visual)
        .filter_map(|v| match v.geometry {
            urdf_rs::Geometry::Cylinder { radius, length } => Some((radius, length)),
            _ => None,
        })
        .collect();
    assert_eq!(cylinders.len(), 5, "{cylinders:?}");
    for (radius, length) in cylinders {
        assert!((2.0 * radius - 0.060).abs() <= 1e-12 && (length - 0.220).abs() <= 1e-12);
    }
    // Total mass 1.2 kg; load capability 0.8 kg.
    assert!((r.robot.moving_mass() - 1.2).abs() <= 1e-12, "{} kg", r.robot.moving_mass());
    assert_eq!(description.payload, Some(0.8));
    // 5 universal joints, 10 DOF: pairs of orthogonal axes.
    assert_eq!(r.robot.dof(), 10);
    assert_eq!(r.robot.joints().len(), 10);
    for pair in r.robot.joints().chunks(2) {
        assert!(
            pair[0].axis.dot(&pair[1].axis).abs() <= 1e-12,
            "{} {}",
            pair[0].name,
            pair[1].name
        );
    }
    // Every joint limited to [−π/6, π/6].
    for joint in r.robot.joints() {
        let sixth = std::f64::consts::FRAC_PI_6;
        assert!((joint.lower + sixth).abs() <= 1e-12, "{}: {}", joint.name, joint.lower);
        assert!((joint.upper - sixth).abs() <= 1e-12, "{}: {}", joint.name, joint.upper);
    }
    // Cables: E = 12.5 GPa, f ∈ [20, 600] N; three per joint.
    assert_eq!(r.routing.youngs_modulus(), 12.5e9);
    assert_eq!(r.routing.tension_limits(), [20.0, 600.0]);
    assert_eq!(r.routing.cable_count(), 15);
}

#[test]
fn table_2() {
    let rendered = paper::render_table_2(&report().table_2);
    insta::assert_snapshot!(rendered);
    assert_committed("table2.md", &rendered);
}

#[test]
fn fig_4_e2() {
    let csv = paper::e2_csv(&report().e2);
    insta::assert_snapshot!(csv);
    assert_committed("fig4_e2.csv", &csv);
}

/// Joint 1's stiffness block `K_q[0..2, 0..2]` at `E2_Q` recomputed from the three tensions
/// alone (spec §3: `Σ f_c H_c + J_cᵀ K_l J_c`), and the torque those tensions hold.
fn e2_direct(tensions: [f64; 3]) -> (nalgebra::Matrix2<f64>, nalgebra::Vector2<f64>) {
    use sinew::routing::{Order, RoutingData, compute_cable_geometry};
    let r = report();
    let n = r.robot.dof();
    let mut q = vec![0.0; n];
    q[2 * paper::SINGLE_JOINT..2 * paper::SINGLE_JOINT + 2].copy_from_slice(&paper::E2_Q);
    let mut rdata = sinew::robot::RobotData::new(&r.robot);
    let mut g = RoutingData::new(&r.routing);
    compute_cable_geometry(&r.routing, &r.robot, &mut rdata, &mut g, &q, Order::Hessians).unwrap();
    let mut f = vec![0.0; r.routing.cable_count()];
    f[3 * paper::SINGLE_JOINT..3 * paper::SINGLE_JOINT + 3].copy_from_slice(&tensions);
    let (mut kc, mut ki) = (faer::Mat::zeros(n, n), faer::Mat::zeros(n, n));
    sinew::stiffness::joint_stiffness(&r.routing, &g, &f, kc.as_mut(), ki.as_mut()).unwrap();
    let k = &kc + &ki;
    let d = 2 * paper::SINGLE_JOINT;
    let j = g.jacobian().unwrap();
    let tau = nalgebra::Vector2::from_fn(|col, _| {
        -(0..3).map(|c| j[(3 * paper::SINGLE_JOINT + c, d + col)] * tensions[c]).sum::<f64>()
    });
    (nalgebra::Matrix2::from_fn(|a, b| k[(d + a, d + b)]), tau)
}

/// E2's "the other two tensions rise linearly" is true by construction (`f = f_p + λ n`);
/// the stiffness half is not: `K` recomputed from the tensions at every sampled level must
/// equal the report's value and lie on the line through the two direct end evaluations.
#[test]
fn e2_stiffness_is_affine_in_the_level_by_direct_evaluation() {
    let e2 = &report().e2;
    assert_eq!(e2.len(), paper::E2_SAMPLES);
    let (k_first, _) = e2_direct(e2[0].tensions);
    let (k_last, _) = e2_direct(e2[e2.len() - 1].tensions);
    let (mut worst_report, mut worst_line, mut worst_torque) = (0.0_f64, 0.0_f64, 0.0_f64);
    for p in e2 {
        let (k, tau) = e2_direct(p.tensions);
        // The tensions hold E2's torque.
        let torque_err = (tau - nalgebra::Vector2::from(paper::E2_TORQUE)).norm();
        worst_torque = worst_torque.max(torque_err);
        // Measured worst 3.2e-15 N m.
        assert!(torque_err <= 2e-14, "level {}: τ off by {torque_err:e} N m", p.level);
        // The report's K_x, K_y are the direct ones.
        let report_err = ((p.k_x - k[(0, 0)]).abs()).max((p.k_y - k[(1, 1)]).abs()) / k.amax();
        worst_report = worst_report.max(report_err);
        // The direct K on the line between the direct ends.
        let line = k_first + (k_last - k_first) * p.level;
        let line_err = (k - line).amax() / k.amax();
        worst_line = worst_line.max(line_err);
        // Measured worst 2.7e-16 for both.
        assert!(report_err <= 2e-15, "level {}: report's K off by {report_err:e}", p.level);
        assert!(line_err <= 2e-15, "level {}: K off the line by {line_err:e}", p.level);
    }
    println!(
        "E2: worst |τ − τ_E2| {worst_torque:.2e} N m, report vs direct K {worst_report:.2e}, \
         direct K vs line {worst_line:.2e}"
    );
    // And it rises: K_x, K_y both stiffer at the top of the segment.
    assert!(k_last[(0, 0)] > k_first[(0, 0)] + 1.0 && k_last[(1, 1)] > k_first[(1, 1)] + 1.0);
}

#[test]
fn fig_5_e3() {
    let r = report();
    // The committed CSV is the full 121 × 121 grid; the snapshot a 13 × 13 one.
    assert_eq!(r.e3.grid.points, 121);
    assert_committed("fig5_e3.csv", &paper::e3_csv(&r.e3));
    insta::assert_snapshot!(paper::e3_csv(&paper::e3(&r.robot, &r.routing, 13).unwrap()));
}

#[test]
fn claims_e1_e3() {
    insta::assert_snapshot!(paper::render_claims(&report().claims_e1_e3));
}

#[test]
fn snapshots_are_identical_across_runs() {
    let r = report();
    let a = paper::e3_csv(&paper::e3(&r.robot, &r.routing, 31).unwrap());
    let b = paper::e3_csv(&paper::e3(&r.robot, &r.routing, 31).unwrap());
    assert_eq!(a, b, "the parallel sweep must be deterministic");
}

#[test]
fn fig_6_e4_decoupled_and_routed() {
    let r = report();
    assert_eq!(r.e4_stable.baseline, 0.25);
    let rendered_b = paper::render_e4(&r.e4_stable);
    insta::assert_snapshot!("e4_decoupled_baseline", rendered_b);
    assert_committed("e4_decoupled_baseline.md", &rendered_b);
    let rendered_d = paper::render_e4(&r.e4_decoupled);
    let rendered_r = paper::render_e4(&r.e4_routed);
    insta::assert_snapshot!("e4_decoupled", rendered_d);
    insta::assert_snapshot!("e4_routed", rendered_r);
    insta::assert_snapshot!(
        "e4_routed_vs_decoupled",
        paper::render_routed_vs_decoupled(&r.e4_decoupled, &r.e4_routed)
    );
    insta::assert_snapshot!("e4_claims", paper::render_claims(&r.claims_e4));
    assert_committed("e4_decoupled.md", &rendered_d);
    assert_committed("e4_routed.md", &rendered_r);
}

/// Every text file of the report (README.md included) is committed as written; the figures
/// are compared by `cargo xtask reproduce --check` (run by .ci/run).
#[test]
fn every_text_file_of_the_report_is_committed() {
    let files = report().text_files();
    assert!(files.iter().any(|(name, _)| *name == "README.md"));
    for (name, text) in &files {
        assert_committed(name, text);
    }
}

/// E5 (beyond the paper): the planner at E4's pose. Besides the snapshots, what the section
/// claims: the least stable total tension is below the paper's case (d) (the decoupled paper
/// baseline (a) is unstable, the planned one is not); at (d)'s total the planned rows are at
/// least as stiff as (d) in their objective; the trade-off never falls as the budget grows.
#[test]
fn e5_planned_tensions() {
    let r = report();
    for e5 in [&r.e5_decoupled, &r.e5_routed] {
        let rendered = paper::render_e5(e5);
        insta::assert_snapshot!(format!("e5_{}", e5.model), rendered);
        assert_committed(&format!("e5_{}.md", e5.model), &rendered);
        let [a, _, _, d, least, along, softest] = e5.rows.as_slice() else {
            panic!("seven rows: {:?}", e5.rows);
        };
        assert!(least.margin >= paper::E5_MARGIN * (1.0 - 1e-9), "{}", e5.model);
        assert!(least.total <= d.total, "{}", e5.model);
        if a.margin < 0.0 {
            assert!(least.total > a.total, "{}: stability costs tension", e5.model);
        }
        let slack = |row: &paper::E5Row| row.gap.unwrap_or(0.0) + 1e-9;
        assert!(along.k_load.unwrap() >= d.k_load.unwrap() - slack(along), "{}", e5.model);
        assert!(softest.k_min.unwrap() >= d.k_min.unwrap() - slack(softest), "{}", e5.model);
        assert!(along.total <= d.total * (1.0 + 1e-12) && softest.total <= d.total * (1.0 + 1e-12));
        for w in e5.tradeoff.windows(2) {
            assert!(w[1].1 >= w[0].1 - w[0].2 - w[1].2 - 1e-9, "{}: {:?}", e5.model, e5.tradeoff);
        }
    }
    insta::assert_snapshot!("e5_tradeoff", paper::e5_csv(&[&r.e5_decoupled, &r.e5_routed]));
}

/// E7 (beyond the paper, #27): when tension stiffens. The table and the claim as a snapshot;
/// the closed form against the numbers is `tests/tension_stiffens.rs`.
#[test]
fn e7_tension_stiffens() {
    let r = report();
    let rendered = paper::render_e7(&r.e7);
    insta::assert_snapshot!("e7_tension_stiffens", rendered);
    assert_committed(paper::E7_FILE, &rendered);
    // The claim is in the report's list, and its verdict is the numbers'.
    assert!(r.claims().any(|c| c == &r.e7.claim));
    assert_eq!(r.e7.claim.verdict(), "holds", "{}", r.e7.claim.evidence);
    // Every point of the map: the closed form at Q0 classifies it as the numbers do, and where
    // the holes do not straddle the centre over a gap at least as wide as the hole radius,
    // tension never softens anywhere in the workspace.
    let (agree, total) = r.e7.map.closed_form_agreement();
    let n = r.e7.map.axis.len();
    let axis = &r.e7.map.axis;
    let wide = (0..n * n).filter(|k| axis[k / n] + axis[k % n] >= paper::E7_MIN_GAP).count();
    // Every point with the gap computed, and classified alike.
    assert_eq!((agree, total), (wide, wide));
    assert_eq!(wide, 8910);
    for a in 0..n {
        for b in 0..n {
            let (d1, d2) = (r.e7.map.axis[a], r.e7.map.axis[b]);
            if let Some(c) = r.e7.map.cell(a, b) {
                if d1 * d2 <= 0.0 && d1 + d2 >= r.e7.map.radius {
                    assert_eq!(c.workspace_class, paper::TensionEffect::Stiffens, "({d1}, {d2})");
                }
                if d1 * d2 > 0.0 {
                    assert_ne!(c.workspace_class, paper::TensionEffect::Stiffens, "({d1}, {d2})");
                }
            }
        }
    }
}

/// E6 (beyond the paper, #27): friction at the holes. The tables as a snapshot; what their
/// numbers must satisfy is `tests/e6_friction.rs`.
#[test]
fn e6_friction() {
    let r = report();
    let rendered = paper::render_e6(&r.e6);
    insta::assert_snapshot!("e6_friction", rendered);
    assert_committed(paper::E6_FILE, &rendered);
    assert!(r.readme().contains(&rendered), "the README shows E6's tables");
}
