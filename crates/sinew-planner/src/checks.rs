//! Unit checks of the interior-point method's parts on cdhrm5's pencils: the smooth
//! objectives' gradients and Hessians against central differences (and `H ⪯ 0`), the
//! certificate's soundness for random multipliers, the method on a problem solved by hand, and
//! the frame's compact coefficients against the pencil.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{DMatrix, Vector6};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sinew_routing::PatternModel;
use sinew_statics::TensionChoice;
use sinew_stiffness::{ArmStiffness, ArmStiffnessData};
use sinew_testkit::cdhrm5;

use crate::blocks::{base, margin_block, push_block};
use crate::frame::Frame;
use crate::program::{Block, Duals, End, Sdp, Settings, Smooth, bound_at};
use crate::rows::linear_rows;
use crate::sdp;
use crate::smooth::{EndObjective, Kind};

fn frame(model: PatternModel) -> Frame {
    let (robot, routing) = cdhrm5::robot_and_routing(model);
    let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    fill(&robot, &routing, &cdhrm5::LOADED_POSE, &f0, &mut crate::pencil::Pencil::empty())
}

/// `pencil` filled at `q` under `f0` (levels ½, the equilibrium set's), and its frame.
fn fill(
    robot: &sinew_robot::Robot,
    routing: &sinew_routing::Routing,
    q: &[f64],
    f0: &Vector6<f64>,
    pencil: &mut crate::pencil::Pencil,
) -> Frame {
    let arm = ArmStiffness::new(robot, routing).unwrap();
    let mut sd = ArmStiffnessData::new(&arm);
    arm.set_pose(&mut sd, q, f0).unwrap();
    let set = arm.equilibrium_set(&mut sd).unwrap().clone();
    arm.set_tensions(&mut sd, TensionChoice::Levels(&vec![0.5; set.dimension()])).unwrap();
    pencil.fill(&arm, &mut sd, &set).unwrap();
    Frame::new(pencil, &set, &linear_rows(&set, None, &[]).merged(), &[])
}

/// The frame of a 12-joint weightless chain (24 DOFs) under a small tip force.
fn chain12() -> Frame {
    let (robot, routing) = cdhrm5::chain(12, PatternModel::Decoupled);
    let robot = robot.with_gravity(nalgebra::Vector3::zeros());
    let q: Vec<f64> = (0..24).map(|i| 0.1 * ((i as f64) * 1.3).sin()).collect();
    let f0 = Vector6::new(0.0, 0.1, 0.05, 0.0, 0.0, 0.0);
    fill(&robot, &routing, &q, &f0, &mut crate::pencil::Pencil::empty())
}

/// Random points strictly inside the rows with `A(x) ≻ margin I`.
fn stable_points(f: &Frame, margin: f64, count: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let sdp = {
        let mut s = base(f, 0);
        push_block(&mut s, |b| margin_block(f, margin, 0, None, b));
        s
    };
    let mut out = Vec::new();
    // Bounded: a broken frame (no stable point) fails the test instead of hanging it.
    for _ in 0..100_000 {
        if out.len() == count {
            break;
        }
        let x: Vec<f64> = (0..f.vars()).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut s = vec![0.0; sdp.rhs.len()];
        sdp.slacks(&x, &mut s);
        let mut a = vec![0.0; sdp.blocks[0].n.pow(2)];
        sdp.blocks[0].at(&x, &mut a);
        if s.iter().all(|v| *v > 0.0) && crate::dense::cholesky(&mut a, sdp.blocks[0].n) {
            out.push(x);
        }
    }
    assert_eq!(out.len(), count, "stable points found in 100 000 draws");
    out
}

fn evaluate(objective: &mut EndObjective<'_>, x: &[f64]) -> (f64, Vec<f64>, Vec<f64>) {
    let k = x.len();
    let (mut g, mut h) = (vec![0.0; k], vec![0.0; k * k]);
    let v = objective.evaluate(x, &mut g, &mut h).unwrap();
    (v, g, h)
}

/// A warm step's first evaluation (`gradient_only`) gives the full evaluation's value and
/// gradient to the bit and leaves the Hessian as it was: one that stopped before the gradient
/// was complete, or scaled or wrote the Hessian, fails.
#[test]
fn a_gradient_only_evaluation_is_the_full_one_without_the_hessian() {
    for model in cdhrm5::MODELS {
        let f = frame(model);
        let k = f.vars();
        let u = nalgebra::Vector3::new(0.6, 0.0, 0.8);
        let w = Vector6::new(0.0, 0.6, 0.8, 0.0, 0.0, 0.0);
        for kind in [Kind::Along(w), Kind::Volume, Kind::Compliance(u), Kind::Least] {
            let mut objective = EndObjective::new(&f, kind, 3.0);
            for x in stable_points(&f, 1e-3, 3, 9) {
                let (v, g, h) = evaluate(&mut objective, &x);
                assert!(h.iter().any(|e| *e != 0.0));
                objective.gradient_only = true;
                let (mut g_only, mut h_kept) = (vec![0.0; k], vec![7.0; k * k]);
                let v_only = objective.evaluate(&x, &mut g_only, &mut h_kept).unwrap();
                objective.gradient_only = false;
                assert_eq!(v_only.to_bits(), v.to_bits(), "{model:?} {kind:?}");
                assert!(g_only.iter().zip(&g).all(|(a, b)| a.to_bits() == b.to_bits()));
                assert!(h_kept.iter().all(|e| *e == 7.0), "{model:?} {kind:?}: Hessian written");
            }
        }
    }
}

#[test]
fn smooth_gradients_and_hessians_match_central_differences_and_are_concave() {
    for model in cdhrm5::MODELS {
        let f = frame(model);
        let k = f.vars();
        let kinds = [
            Kind::Along(Vector6::new(0.0, 0.6, 0.8, 0.0, 0.0, 0.0)),
            Kind::Volume,
            Kind::Compliance(nalgebra::Vector3::new(0.6, 0.0, 0.8)),
            Kind::Least,
        ];
        for kind in kinds {
            let mut objective = EndObjective::new(&f, kind, 1.0);
            let (mut worst_g, mut worst_h) = (0.0_f64, 0.0_f64);
            for x in stable_points(&f, 1e-3, 6, 7) {
                let (_, g, h) = evaluate(&mut objective, &x);
                let step = 1e-5;
                for a in 0..k {
                    let (mut up, mut down) = (x.clone(), x.clone());
                    up[a] += step;
                    down[a] -= step;
                    let (vu, gu, _) = evaluate(&mut objective, &up);
                    let (vd, gd, _) = evaluate(&mut objective, &down);
                    let fd = (vu - vd) / (2.0 * step);
                    let scale = g.iter().fold(0.0_f64, |m, v| m.max(v.abs())).max(1e-12);
                    worst_g = worst_g.max((fd - g[a]).abs() / scale);
                    let h_scale = h.iter().fold(0.0_f64, |m, v| m.max(v.abs())).max(1e-12);
                    for b in 0..k {
                        let fd = (gu[b] - gd[b]) / (2.0 * step);
                        worst_h = worst_h.max((fd - h[a * k + b]).abs() / h_scale);
                    }
                }
                let eig = DMatrix::from_row_slice(k, k, &h).symmetric_eigenvalues();
                let h_scale = h.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
                assert!(eig.max() <= 1e-10 * h_scale, "{model:?}: H has eigenvalue {}", eig.max());
            }
            println!(
                "{model:?} {kind:?}: gradient error {worst_g:.1e}, Hessian error {worst_h:.1e}"
            );
            // Measured: ≤ 1.3e-8 (gradient) and 2.8e-8 (Hessian) relative to the largest entry.
            assert!(worst_g <= 5e-8, "{model:?}: gradient error {worst_g:e}");
            assert!(worst_h <= 1e-7, "{model:?}: Hessian error {worst_h:e}");
        }
    }
}

/// Random `y ≥ 0` and `Z ⪰ 0` for `sdp`.
fn random_duals(sdp: &Sdp, rng: &mut ChaCha8Rng) -> Duals {
    let y = sdp.rhs.iter().map(|_| rng.random_range(0.0..1.0_f64).powi(3)).collect();
    let z = sdp
        .blocks
        .iter()
        .map(|b| {
            let n = b.n;
            let r: Vec<f64> = (0..n * 2).map(|_| rng.random_range(-1.0..1.0)).collect();
            let mut z = vec![0.0; n * n];
            for i in 0..n {
                for j in 0..n {
                    z[i * n + j] = 0.1 * (0..2).map(|c| r[i * 2 + c] * r[j * 2 + c]).sum::<f64>();
                }
            }
            z
        })
        .collect();
    Duals { y, z, ..Duals::default() }
}

#[test]
fn the_certificate_bounds_every_sampled_feasible_value_for_random_multipliers() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for model in cdhrm5::MODELS {
        let f = frame(model);
        let mut sdp = base(&f, 0);
        push_block(&mut sdp, |b| margin_block(&f, 1e-3, 0, None, b));
        let points = stable_points(&f, 1e-3, 400, 3);
        let w = Vector6::new(0.0, 1.0, 0.0, 0.0, 0.0, 0.0);
        let mut objective = EndObjective::new(&f, Kind::Along(w), 1.0);
        // Least tension (linear) and the stiffness along y (smooth).
        let linear = |x: &[f64]| -(f.total + f.sums.iter().zip(x).map(|(a, b)| a * b).sum::<f64>());
        for trial in 0..20 {
            let centre = &points[trial];
            let duals = random_duals(&sdp, &mut rng);
            let upper = bound_at(
                &sdp,
                centre,
                linear(centre),
                &f.sums.iter().map(|s| -s).collect::<Vec<_>>(),
                &duals,
            )
            .unwrap();
            let (v, g, _) = evaluate(&mut objective, centre);
            let upper_smooth = bound_at(&sdp, centre, v, &g, &duals).unwrap();
            assert!(upper.is_finite() && upper_smooth.is_finite());
            for x in &points {
                assert!(
                    linear(x) <= upper + 1e-9 * upper.abs(),
                    "{model:?}: {} > {upper}",
                    linear(x)
                );
                let (v, _, _) = evaluate(&mut objective, x);
                assert!(
                    v <= upper_smooth + 1e-9 * upper_smooth.abs(),
                    "{model:?}: {v} > {upper_smooth}"
                );
            }
        }
    }
}

#[test]
fn the_method_finds_a_hand_solved_optimum_and_certifies_it() {
    // max t s.t. diag(1 + x, 1 − x) − t I ⪰ 0, −1 ≤ x ≤ 1 (rows): t* = 1 at x = 0.
    let block = Block {
        n: 2,
        constant: vec![1.0, 0.0, 0.0, 1.0],
        coefficients: vec![Some(vec![1.0, 0.0, 0.0, -1.0]), Some(vec![-1.0, 0.0, 0.0, -1.0])],
        factors: None,
        ..Block::default()
    };
    let sdp = Sdp {
        c0: 0.0,
        c: vec![0.0, 1.0],
        rows: vec![1.0, 0.0, -1.0, 0.0],
        rhs: vec![1.0, 1.0],
        blocks: vec![block],
        lo: vec![-1.0, f64::NEG_INFINITY],
        hi: vec![1.0, f64::INFINITY],
        epigraph: Some((1, 0)),
        ..Sdp::default()
    };
    let settings = Settings {
        relative_gap: 1e-10,
        scale: 1.0,
        max_iterations: 50,
        target: None,
        centring: 0.0,
    };
    let mut work = sdp::SolveWork::default();
    let run = sdp::solve(&sdp, None, &[0.7, -2.0], settings, &mut work);
    assert_eq!(run.end, End::Optimum);
    assert!((work.x[0]).abs() <= 1e-8 && (run.value - 1.0).abs() <= 1e-9, "{:?}", work.x);
    assert!(run.upper >= 1.0 - 1e-12 && run.upper - run.value <= 1e-10);
}

/// The frame keeps each `∂A/∂x_a` as its square over the coefficient's span: `A(x)` from it is
/// the pencil's `A(λ(x))` (symmetrised, every entry), in both models, and the form `vᵀ A_a v`
/// and the dense copy agree with it. A span cut short, or a square placed at the wrong
/// origin, fails it.
#[test]
fn the_frames_compact_coefficients_are_the_pencils() {
    let mut rng = ChaCha8Rng::seed_from_u64(23);
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
        let mut pencil = crate::pencil::Pencil::empty();
        let f = fill(&robot, &routing, &cdhrm5::LOADED_POSE, &f0, &mut pencil);
        let n = f.n;
        for _ in 0..5 {
            let x: Vec<f64> = (0..f.vars()).map(|_| rng.random_range(-1.0..1.0)).collect();
            let mut a = vec![0.0; n * n];
            f.a_at(&x, &mut a);
            let expected = pencil.at(&f.lambda(&x));
            let size = (0..n).map(|i| expected[(i, i)].abs()).fold(0.0, f64::max);
            for r in 0..n {
                for c in 0..n {
                    let d = (a[r * n + c] - expected[(r, c)]).abs();
                    assert!(d <= 1e-12 * size, "{model:?}: A({r}, {c}) off by {d:e}");
                }
            }
            let v: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            for a in 0..f.vars() {
                let dense = f.ai_dense(a, 1.0);
                let form: f64 = (0..n)
                    .map(|r| v[r] * (0..n).map(|c| dense[r * n + c] * v[c]).sum::<f64>())
                    .sum();
                assert!((f.ai_form(a, &v) - form).abs() <= 1e-12 * (1.0 + form.abs()));
            }
        }
        println!("{model:?}: spans {:?}", f.spans);
    }
}

/// A pencil refilled in its own buffers (the planner's workspace keeps one between plans) is
/// the pencil filled afresh: the routed arm's `A_i` span the DOFs from the base, the decoupled
/// arm's one joint each, so zeroing the new spans instead of the old leaves the routed
/// entries behind and fails this.
#[test]
fn a_refilled_pencil_is_a_fresh_one() {
    let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    let fill_model = |model: PatternModel, pencil: &mut crate::pencil::Pencil| {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        fill(&robot, &routing, &cdhrm5::LOADED_POSE, &f0, pencil);
    };
    let mut reused = crate::pencil::Pencil::empty();
    fill_model(PatternModel::Routed, &mut reused);
    fill_model(PatternModel::Decoupled, &mut reused);
    let mut fresh = crate::pencil::Pencil::empty();
    fill_model(PatternModel::Decoupled, &mut fresh);
    assert_eq!(reused.ai.len(), fresh.ai.len());
    for (i, (a, b)) in reused.ai.iter().zip(&fresh.ai).enumerate() {
        assert!(a == b, "A_{i} differs after a refill");
    }
    assert!(reused.a0 == fresh.a0 && reused.spans == fresh.spans);
}

/// The Schur terms of a stiffness floor's block from its factored coefficients
/// (`R_aᵀ B_a R_a`: `block_work::add_factored_schur`) are those of its dense ones, for random
/// `Z ⪰ 0` and the block's own `S⁻¹`, with and without an epigraph coefficient (factored and
/// unfactored pairs), and so are its dual terms `⟨Z, F_a⟩` (`block_work::factored_dual_term`).
/// A wrong entry of `G_d`, `W` or `V` (its diagonal only, another joint's rows) fails it.
#[test]
fn a_floors_factored_schur_terms_are_its_dense_ones() {
    use crate::block_work::{BlockWork, add_block_schur, dual_congruence, factored_dual_term};
    use crate::blocks::{Floor, Scratch, floor_block};
    // 24 DOFs, a 21 × 21 floor, above the fixed-size kernels (below them it is not factored).
    let f = chain12();
    let r = f.rotation_null_basis().unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let x = stable_points(&f, 0.0, 1, 5).remove(0);
    let k = nalgebra::Matrix3::new(2.0, 0.3, 0.1, 0.3, 1.0, 0.2, 0.1, 0.2, 1.5);
    for tau in [Ok(0.5), Err(2.0)] {
        let mut factored = Block::default();
        floor_block(&f, &r, Floor { k }, tau, 1, (&mut factored, &mut Scratch::default()));
        assert!(factored.factors.as_ref().unwrap().small[..f.vars()].iter().all(Option::is_some));
        let dense = Block { factors: None, ..factored.clone() };
        let n = factored.n;
        let mut xs = x.clone();
        xs.push(0.1);
        let b = DMatrix::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
        let z_m = &b * b.transpose() + DMatrix::identity(n, n) * 0.1;
        let z: Vec<f64> = (0..n * n).map(|e| z_m[(e / n, e % n)]).collect();
        let schur = |block: &Block| {
            let mut w = BlockWork::default();
            w.reset(block);
            let mut s = vec![0.0; n * n];
            block.at(&xs, &mut s);
            let s_m = DMatrix::from_fn(n, n, |i, j| s[i * n + j]);
            let s_inv = s_m.try_inverse().unwrap();
            w.s_inv = (0..n * n).map(|e| s_inv[(e / n, e % n)]).collect();
            let kk = f.vars() + 1;
            let mut out = vec![0.0; kk * kk];
            dual_congruence(block, &z, &mut w);
            add_block_schur(block, &z, &mut w, kk, &mut out);
            for (a, fa) in block.coefficients.iter().enumerate() {
                let Some(fa) = fa else { continue };
                let known = factored_dual_term(block, &w, a);
                assert_eq!(known.is_some(), block.factors.is_some(), "{tau:?}: coefficient {a}");
                let dense = crate::dense::inner(fa, &z);
                let error = (known.unwrap_or(dense) - dense).abs();
                assert!(
                    error <= 1e-12 * (1.0 + dense.abs()),
                    "{tau:?}: ⟨Z, F_{a}⟩ off by {error:e}"
                );
            }
            out
        };
        let (a, d) = (schur(&factored), schur(&dense));
        let size = d.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for (e, (u, v)) in a.iter().zip(&d).enumerate() {
            assert!((u - v).abs() <= 1e-11 * size, "{tau:?}: entry {e}: {u} against {v}");
        }
    }
}

/// The margin's linearisation on both cdhrm5 frames (the frame's `A_a v` by spans) against
/// central differences of an eigensolver's least eigenvalue of `A(x)`.
#[test]
fn the_margin_row_is_the_least_eigenvalue_of_the_frames_pencil() {
    let least = |f: &Frame, x: &[f64]| {
        let mut a = vec![0.0; f.n * f.n];
        f.a_at(x, &mut a);
        DMatrix::from_row_slice(f.n, f.n, &a).symmetric_eigenvalues().min()
    };
    let mut row = crate::margin_row::MarginRow::default();
    for model in cdhrm5::MODELS {
        let f = frame(model);
        let (n, k) = (f.n, f.vars());
        let mut worst: f64 = 0.0;
        for x in stable_points(&f, 1e-3, 5, 17) {
            let mut a = vec![0.0; n * n];
            f.a_at(&x, &mut a);
            assert!(row.linearise(&a, n, k, |i, v, out| f.ai_apply(i, v, out)), "{model:?}");
            assert!((row.rho - least(&f, &x)).abs() <= 1e-12 * f.a_scale, "{model:?}");
            let scale = row.gradient.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            for i in 0..k {
                let h = 1e-6;
                let (mut up, mut down) = (x.clone(), x.clone());
                up[i] += h;
                down[i] -= h;
                let fd = (least(&f, &up) - least(&f, &down)) / (2.0 * h);
                worst = worst.max((fd - row.gradient[i]).abs() / scale);
            }
        }
        println!("{model:?}: margin gradient error {worst:.1e}");
        assert!(worst <= 5e-8, "{model:?}: margin gradient error {worst:e}");
    }
}

/// The basis `R` of `null(J_r)` on both cdhrm5 frames and the 24-DOF chain: orthonormal and
/// annihilated by `J_r` to rounding; refused when `J_r` loses rank (one rotation row a
/// combination of the other two, or zero). A reflection applied in the wrong order, or one
/// missing, fails the first; a wrong rank test fails the second.
#[test]
fn the_rotation_null_basis_is_orthonormal_and_in_the_null_space() {
    for mut f in cdhrm5::MODELS.into_iter().map(frame).chain([chain12()]) {
        let (n, p) = (f.n, f.n - 3);
        let r = DMatrix::from_row_slice(n, p, &f.rotation_null_basis().unwrap());
        let j_r = DMatrix::from_row_slice(3, n, &f.j_x[3 * n..6 * n]);
        let orthonormal = (r.transpose() * &r - DMatrix::identity(p, p)).abs().max();
        let null = (&j_r * &r).abs().max() / j_r.abs().max();
        assert!(orthonormal <= 1e-14 && null <= 1e-14, "n = {n}: {orthonormal:e}, {null:e}");
        let row: Vec<f64> =
            (0..n).map(|c| 0.3 * f.j_x[3 * n + c] - 2.0 * f.j_x[4 * n + c]).collect();
        f.j_x[5 * n..6 * n].copy_from_slice(&row);
        assert!(f.rotation_null_basis().is_none(), "n = {n}: rank 2 accepted");
        f.j_x[3 * n..4 * n].fill(0.0);
        assert!(f.rotation_null_basis().is_none(), "n = {n}: a zero row accepted");
    }
}
