//! E7 (spec §10, #27): the closed-form classifier of `A_i = Σ_c N_c H_c` at Q0
//! (`src/paper/tension.rs`, E7.5) against the eigenvalues the routing and the statics compute,
//! over a grid of hole geometries; the routing's `A_i` against second differences of the cable
//! lengths; and the signs that a wrong classifier (e.g. a sign error in d2) would get wrong.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

use nalgebra::Matrix2;
use sinew::paper::{
    self, HoleGeometry, TensionEffect, classify_q0, criterion_q0, eigenvalues, single_joint,
    tension_stiffness, zero_tolerance,
};
use sinew::routing::{Order, RoutingData, RoutingSpec, compute_cable_geometry};

fn template() -> RoutingSpec {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("robots/cdhrm5/cables.toml");
    RoutingSpec::from_toml_str(&std::fs::read_to_string(&path).unwrap(), "cables.toml").unwrap()
}

fn a_at(g: HoleGeometry, q: [f64; 2]) -> Matrix2<f64> {
    let (robot, routing) = single_joint(&template(), g).unwrap();
    tension_stiffness(&robot, &routing, q).unwrap()
}

/// At Q0, over d1, d2 ∈ [−12, 42] mm (3 mm apart, gap ≥ 3 mm) and r ∈ {5, 12, 20.61, 30} mm:
/// the closed form's class equals the numbers' at every point off the boundary d1·d2 = 0, both
/// eigenvalues equal `c·ΣN = −d1·d2/(d1 + d2)·√3` (N = (1, 1, 1)/√3 for holes 120° apart), and on
/// the boundary both are ~0.
#[test]
fn the_closed_form_classifies_every_geometry_as_the_numbers_do() {
    let (mut points, mut boundary, mut worst) = (0, 0, 0.0_f64);
    let mut seen = std::collections::BTreeSet::new();
    for r_mm in [5.0, 12.0, 20.61, 30.0] {
        for i in 0..19 {
            for j in 0..19 {
                let (d1, d2) =
                    ((-12.0 + 3.0 * f64::from(i)) * 1e-3, (-12.0 + 3.0 * f64::from(j)) * 1e-3);
                if d1 + d2 <= 0.0 {
                    assert_eq!(classify_q0(d1, d2, 1e-9), None);
                }
                if d1 + d2 < 3e-3 {
                    continue;
                }
                let g = HoleGeometry { d1, d2, radius: r_mm * 1e-3 };
                let e = eigenvalues(&a_at(g, [0.0, 0.0]));
                let tol = zero_tolerance(&g);
                let expected = criterion_q0(d1, d2) * 3f64.sqrt();
                for x in e {
                    worst = worst.max((x - expected).abs());
                    assert!((x - expected).abs() <= 1e-12, "{g:?}: {e:?} against {expected:e}");
                }
                let closed = classify_q0(d1, d2, tol).unwrap();
                let numbers = TensionEffect::of_eigenvalues(e, tol);
                if d1 * d2 == 0.0 {
                    boundary += 1;
                    assert!(e[0].abs() <= tol && e[1].abs() <= tol, "{g:?}: {e:?}");
                    assert_eq!(closed, TensionEffect::Neutral);
                } else {
                    assert_eq!(closed, numbers, "{g:?}: eigenvalues {e:?}");
                    assert_ne!(closed, TensionEffect::Indefinite);
                }
                seen.insert(closed);
                points += 1;
            }
        }
    }
    println!("{points} geometries ({boundary} on the boundary), worst |λ − c√3| = {worst:.1e} m");
    assert!(points > 1000 && boundary >= 40);
    // The grid covers every class the closed form has.
    let all = [TensionEffect::Stiffens, TensionEffect::Neutral, TensionEffect::Softens];
    assert_eq!(seen.into_iter().collect::<Vec<_>>(), all);
}

/// Named geometries with their values (mm): a classifier with d2's sign flipped, or one that
/// asks for d2 = 0 alone, or that uses d1 + d2, gets one of these wrong.
#[test]
fn the_signs_of_named_geometries() {
    let r = 0.02061;
    let cases = [
        // (d1, d2, c = −d1 d2/(d1 + d2) in mm, class)
        (30.0, 0.0, 0.0, TensionEffect::Neutral),
        (0.0, 30.0, 0.0, TensionEffect::Neutral),
        (6.6, 13.6, -4.443_564, TensionEffect::Softens),
        (15.0, 15.0, -7.5, TensionEffect::Softens),
        (30.0, 5.0, -4.285_714, TensionEffect::Softens),
        (30.0, -5.0, 6.0, TensionEffect::Stiffens),
        (-5.0, 30.0, 6.0, TensionEffect::Stiffens),
        (-5.0, 10.0, 10.0, TensionEffect::Stiffens),
    ];
    for (d1, d2, c_mm, class) in cases {
        let g = HoleGeometry { d1: d1 * 1e-3, d2: d2 * 1e-3, radius: r };
        let c = criterion_q0(g.d1, g.d2);
        assert!((1e3 * c - c_mm).abs() <= 1e-6, "({d1}, {d2}): c = {} mm", 1e3 * c);
        assert_eq!(classify_q0(g.d1, g.d2, zero_tolerance(&g)), Some(class), "({d1}, {d2})");
        let e = eigenvalues(&a_at(g, [0.0, 0.0]));
        assert_eq!(TensionEffect::of_eigenvalues(e, zero_tolerance(&g)), class, "({d1}, {d2})");
    }
    // No gap between the hole planes: no answer.
    assert_eq!(classify_q0(0.01, -0.01, 1e-9), None);
    assert!(criterion_q0(-0.02, 0.01).is_nan());
}

/// `A_i` from the routing's analytic `H_c` against central second differences of the cable
/// lengths `L_c(q)` weighted by the same `N`, at Q0 and at bent poses, on three geometries.
#[test]
fn the_routings_a_matches_second_differences_of_the_lengths() {
    let geometries = [
        HoleGeometry { d1: 0.03, d2: 0.0, radius: 0.02061 },
        HoleGeometry { d1: 0.0066, d2: 0.0136, radius: 0.02061 },
        HoleGeometry { d1: 0.035, d2: -0.005, radius: 0.012 },
    ];
    let mut worst = 0.0_f64;
    for g in geometries {
        let (robot, routing) = single_joint(&template(), g).unwrap();
        for q in [[0.0, 0.0], [0.3, -0.2], [-0.5, 0.45]] {
            let a = tension_stiffness(&robot, &routing, q).unwrap();
            let mut data = sinew::robot::RobotData::new(&robot);
            let mut geo = RoutingData::new(&routing);
            let mut lengths = |q: [f64; 2]| -> Vec<f64> {
                compute_cable_geometry(&routing, &robot, &mut data, &mut geo, &q, Order::Jacobian)
                    .unwrap();
                geo.lengths().unwrap().to_vec()
            };
            // N: the unit null direction of J_cᵀ, from central first differences.
            let h1 = 1e-6;
            let col = |k: usize, l: &mut dyn FnMut([f64; 2]) -> Vec<f64>| {
                let (mut p, mut m) = (q, q);
                p[k] += h1;
                m[k] -= h1;
                let (lp, lm) = (l(p), l(m));
                nalgebra::Vector3::from_fn(|c, _| (lp[c] - lm[c]) / (2.0 * h1))
            };
            let (c0, c1) = (col(0, &mut lengths), col(1, &mut lengths));
            let mut n = c0.cross(&c1).normalize();
            if n.sum() < 0.0 {
                n = -n;
            }
            let h = 1e-4;
            let weighted = |l: Vec<f64>| (0..3).map(|c| n[c] * l[c]).sum::<f64>();
            let mut fd = Matrix2::zeros();
            for i in 0..2 {
                for j in 0..2 {
                    let mut at = |si: f64, sj: f64| {
                        let mut p = q;
                        p[i] += si * h;
                        p[j] += sj * h;
                        weighted(lengths(p))
                    };
                    fd[(i, j)] = (at(1.0, 1.0) - at(1.0, -1.0) - at(-1.0, 1.0) + at(-1.0, -1.0))
                        / (4.0 * h * h);
                }
            }
            let err = (a - fd).amax() / a.amax().max(1e-3);
            worst = worst.max(err);
            assert!(err <= 1e-5, "{g:?} at {q:?}: {a} against {fd}");
        }
    }
    println!("worst relative difference, analytic A against second differences: {worst:.1e}");
}

/// The report's E7: cdhrm5 is read from its files (d1 = 30 mm, d2 = 0), the off-centre
/// geometry softens at Q0 with K falling as tension rises, and becomes indefinite at a bent
/// pose; the claim's verdict follows the numbers.
#[test]
fn the_reports_cases() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let robot = sinew::robot::load(root.join(paper::ROBOT_DIR)).unwrap();
    let routing = sinew::routing::load(root.join(paper::ROBOT_DIR), &robot).unwrap();
    let e7 = paper::e7(&robot, &routing, &template()).unwrap();
    let (cdhrm5, off) = (&e7.cases[0], &e7.cases[1]);
    assert!((cdhrm5.geometry.d1 - 0.03).abs() < 1e-12 && cdhrm5.geometry.d2.abs() < 1e-12);
    assert_eq!(cdhrm5.closed_form, Some(TensionEffect::Neutral));
    assert_eq!(cdhrm5.cell.workspace_class, TensionEffect::Stiffens);
    assert!(cdhrm5.cell.workspace[0] >= -1e-12 && cdhrm5.cell.workspace[1] > 0.02);
    // Flat at Q0, as Table II's first row.
    assert!((cdhrm5.k_x[1] - cdhrm5.k_x[0]).abs() < 1e-9);
    assert_eq!(off.closed_form, Some(TensionEffect::Softens));
    assert_eq!(off.cell.workspace_class, TensionEffect::Indefinite);
    assert!((off.cell.q0[0] + 4.443_564e-3 * 3f64.sqrt()).abs() < 1e-8, "{:?}", off.cell.q0);
    assert!(off.k_x[1] < off.k_x[0] - 1.0 && off.k_y[1] < off.k_y[0] - 1.0, "{:?}", off.k_x);
    let (agree, total) = e7.map.closed_form_agreement();
    assert_eq!(agree, total);
    assert!(e7.claim.checkable && e7.claim.holds, "{}", e7.claim.evidence);
}
