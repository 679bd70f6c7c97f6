//! Every tension policy's answer on whole arms (equilibrium sets of dimension 5 to 9) checked by
//! its optimality certificate, recomputed here from the answer's active set alone: nothing of
//! the solver's duals, nothing of the library's equilibrium set (`N`, `f_p`), only `J_c`, `T0`,
//! the limits and the tensions (nalgebra's SVD, not faer's).
//!
//! # Math
//! The three programs over `f` (m) with `J_cᵀ f = −T0` and `f_min ≤ f ≤ f_max`:
//!
//! - least total: `min 1ᵀ f`. Optimal iff multipliers `z ≥ 0` on the cables at a limit satisfy
//!   `1 − D z ∈ range(J_c)` (`D` has `+e_c` for a cable at `f_min`, `−e_c` at `f_max`); the dual
//!   objective `−μᵀ T0 + Σ_lo z f_min − Σ_hi z f_max` (`J_c μ = 1 − D z`) then equals `1ᵀ f`.
//! - least norm: `min ½|f|²`. KKT: `f − D z ∈ range(J_c)`, `z ≥ 0`.
//! - safest: `max t` with `f_min + t ≤ f ≤ f_max − t`. Optimal iff `z ≥ 0` on the cables whose
//!   distance to a limit is `t` satisfy `Σ z = 1` and `D z ∈ range(J_c)`; the dual
//!   `μᵀ T0 − Σ_lo z f_min + Σ_hi z f_max` (`J_c μ = −D z`) then equals `t`.
//!
//! `z` is found by non-negative least squares (Lawson–Hanson) on `P D z ≈ P g`, `P` the
//! projector off `range(J_c)`: a non-optimal answer leaves a residual no `z ≥ 0` removes.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use nalgebra::{DMatrix, DVector, Vector6};
use sinew_robot::{Robot, RobotData};
use sinew_routing::{Order, Routing, RoutingData, compute_cable_geometry};
use sinew_statics::{ArmStatics, StaticsError, TensionChoice, TensionPolicy};
use sinew_testkit::cdhrm5;
use sinew_testkit::random_chain::RandomChain;

/// An arm, poses and loads to certify.
struct Case {
    name: String,
    robot: Robot,
    routing: Routing,
    poses: Vec<Vec<f64>>,
    loads: Vec<Vector6<f64>>,
}

fn load(name: &str) -> (Robot, Routing) {
    let dir = cdhrm5::workspace_root().join("robots").join(name);
    let robot = sinew_robot::load(&dir).unwrap();
    let routing = sinew_routing::load(&dir, &robot).unwrap();
    (robot, routing)
}

fn cases() -> Vec<Case> {
    let mut cases = Vec::new();
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let mut poses = vec![cdhrm5::LOADED_POSE.to_vec()];
        poses.extend(sinew_testkit::config::random_qs(&robot, 25, 3));
        cases.push(Case {
            name: format!("cdhrm5 {model:?}"),
            robot,
            routing,
            poses,
            loads: vec![Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0)],
        });
    }
    let (robot, routing) = load("ua3x4");
    cases.push(Case {
        name: "ua3x4".to_owned(),
        robot,
        routing,
        poses: vec![
            vec![0.2, -0.3, 0.25, 0.1, -0.15, 0.3],
            vec![-0.45, 0.4, 0.3, -0.35, 0.2, -0.25],
        ],
        loads: vec![
            Vector6::new(0.0, 2.0, 0.0, 0.0, 0.0, 0.0),
            Vector6::new(1.0, -2.0, 0.5, 0.1, -0.1, 0.05),
        ],
    });
    let (robot, routing) = load("planar-snake");
    cases.push(Case {
        name: "planar-snake".to_owned(),
        robot,
        routing,
        poses: vec![vec![0.3, -0.2, 0.25, -0.1], vec![-0.4, 0.35, -0.3, 0.45]],
        loads: vec![
            Vector6::new(0.0, 2.0, 0.0, 0.0, 0.0, 0.0),
            Vector6::new(0.0, -3.0, 1.0, 0.2, 0.0, 0.0),
        ],
    });
    for seed in [1, 3] {
        let chain = RandomChain::new(3, seed);
        let robot = chain.robot();
        // The testkit's holes at random angles rarely surround a joint: put cable k of each
        // joint at 90° steps on every disc it passes (radius, z and skipped discs stay random),
        // so that the four pull against each other.
        let mut spec = chain.explicit_spec_with(seed, 4);
        for (c, cable) in spec.cables.iter_mut().enumerate() {
            let angle = 0.3 * seed as f64 + std::f64::consts::FRAC_PI_2 * (c % 4) as f64;
            for hole in &mut cable.holes {
                let r = hole.point[0].hypot(hole.point[1]);
                hole.point = [r * angle.cos(), r * angle.sin(), hole.point[2]];
            }
        }
        // Wide limits: the random discs' frames are turned, so the pulls rarely cancel.
        spec.tension_limits = [1.0, 2000.0];
        let routing = chain.routing(&robot, &spec);
        let poses = sinew_testkit::config::random_qs(&robot, seed + 100, 3)
            .into_iter()
            .map(|q| q.iter().map(|v| 0.3 * v).collect())
            .collect();
        cases.push(Case {
            name: chain.name.clone(),
            robot,
            routing,
            poses,
            loads: vec![Vector6::zeros(), Vector6::new(0.5, -0.5, 0.3, 0.0, 0.02, 0.0)],
        });
    }
    cases
}

/// What a policy answered at one pose and load: `J_c` (m × dof), `T0`, limits, tensions.
struct Answer {
    j: DMatrix<f64>,
    t0: DVector<f64>,
    lo: DVector<f64>,
    hi: DVector<f64>,
    f: DVector<f64>,
    dimension: usize,
}

fn answer(
    case: &Case,
    q: &[f64],
    load: &Vector6<f64>,
    policy: TensionPolicy,
) -> Result<Answer, StaticsError> {
    let statics = ArmStatics::new(&case.routing);
    let mut rdata = RobotData::new(&case.robot);
    let mut cables = RoutingData::new(&case.routing);
    compute_cable_geometry(&case.routing, &case.robot, &mut rdata, &mut cables, q, Order::Jacobian)
        .unwrap();
    let mut data = statics.data(&case.robot);
    statics.solve_with(
        &case.robot,
        &mut rdata,
        &cables,
        &mut data,
        load,
        TensionChoice::Policy(policy),
    )?;
    let jc = cables.jacobian().unwrap();
    let limits = statics.cable_limits();
    Ok(Answer {
        j: DMatrix::from_fn(jc.nrows(), jc.ncols(), |r, c| jc[(r, c)]),
        t0: DVector::from_column_slice(&data.t0),
        lo: DVector::from_iterator(limits.len(), limits.iter().map(|l| l[0])),
        hi: DVector::from_iterator(limits.len(), limits.iter().map(|l| l[1])),
        f: DVector::from_column_slice(&data.tensions),
        dimension: data.cached_equilibrium_set().unwrap().dimension(),
    })
}

/// `argmin |A x − b|` by Householder QR (nalgebra's SVD `solve` is accurate only to about
/// 1e-9 here), the SVD's when `A` has not full column rank.
fn lstsq(a: &DMatrix<f64>, b: &DVector<f64>) -> DVector<f64> {
    let qr = a.clone().qr();
    let r = qr.r();
    let full = (0..a.ncols().min(a.nrows())).all(|i| r[(i, i)].abs() > 1e-12 * r.abs().max());
    match (full && a.nrows() >= a.ncols())
        .then(|| r.solve_upper_triangular(&(qr.q().transpose() * b)))
    {
        Some(Some(x)) => x,
        _ => a.clone().svd(true, true).solve(b, 1e-14).unwrap(),
    }
}

/// Lawson–Hanson non-negative least squares: `argmin |A z − b|`, `z ≥ 0`.
fn nnls(a: &DMatrix<f64>, b: &DVector<f64>) -> DVector<f64> {
    let n = a.ncols();
    let mut x = DVector::zeros(n);
    let mut passive = vec![false; n];
    let scale = a.abs().max().max(1.0) * b.abs().max().max(1.0);
    for _ in 0..3 * n + 3 {
        let w = a.transpose() * (b - a * &x);
        let Some(j) = (0..n)
            .filter(|&j| !passive[j] && w[j] > 1e-13 * scale)
            .max_by(|&p, &q| w[p].total_cmp(&w[q]))
        else {
            break;
        };
        passive[j] = true;
        loop {
            let cols: Vec<usize> = (0..n).filter(|&j| passive[j]).collect();
            let sub = DMatrix::from_fn(a.nrows(), cols.len(), |r, c| a[(r, cols[c])]);
            let z = lstsq(&sub, b);
            if z.iter().all(|&v| v > 0.0) {
                x.fill(0.0);
                for (i, &c) in cols.iter().enumerate() {
                    x[c] = z[i];
                }
                break;
            }
            let alpha = cols
                .iter()
                .enumerate()
                .filter(|&(i, _)| z[i] <= 0.0)
                .map(|(i, &c)| x[c] / (x[c] - z[i]))
                .fold(f64::INFINITY, f64::min);
            for (i, &c) in cols.iter().enumerate() {
                x[c] += alpha * (z[i] - x[c]);
                if x[c] <= 1e-15 * scale {
                    x[c] = 0.0;
                    passive[c] = false;
                }
            }
        }
    }
    x
}

/// The certificate of `policy` at an answer: (stationarity residual relative to the gradient,
/// duality gap relative to the objective, number of active cables).
fn certificate(policy: TensionPolicy, a: &Answer) -> (f64, f64, usize) {
    let m = a.f.len();
    let svd = a.j.clone().svd(true, false);
    let u = svd.u.unwrap();
    let largest = svd.singular_values.max();
    let range: Vec<usize> = (0..svd.singular_values.len())
        .filter(|&i| svd.singular_values[i] > 1e-10 * largest)
        .collect();
    let q = DMatrix::from_fn(m, range.len(), |r, c| u[(r, range[c])]);
    let p = DMatrix::identity(m, m) - &q * q.transpose();
    let width = |c: usize| (a.hi[c] - a.lo[c]).max(1.0);
    let margin =
        (0..m).map(|c| (a.f[c] - a.lo[c]).min(a.hi[c] - a.f[c])).fold(f64::INFINITY, f64::min);
    // Active cables as (cable, +1 at f_min / −1 at f_max).
    let offset = if policy == TensionPolicy::Safest { margin } else { 0.0 };
    let mut active = Vec::new();
    for c in 0..m {
        if a.f[c] - a.lo[c] - offset <= 1e-7 * width(c) {
            active.push((c, 1.0));
        }
        if a.hi[c] - a.f[c] - offset <= 1e-7 * width(c) {
            active.push((c, -1.0));
        }
    }
    let d =
        DMatrix::from_fn(m, active.len(), |r, k| if active[k].0 == r { active[k].1 } else { 0.0 });
    let g = match policy {
        TensionPolicy::LeastTotal => DVector::from_element(m, 1.0),
        TensionPolicy::LeastNorm => a.f.clone(),
        TensionPolicy::Safest => DVector::zeros(m),
    };
    let (z, residual) = if policy == TensionPolicy::Safest {
        // P D z = 0 with Σ z = 1 (a row of weight 1: z is of order 1).
        let mut aa = DMatrix::zeros(m + 1, active.len());
        aa.view_mut((0, 0), (m, active.len())).copy_from(&(&p * &d));
        aa.row_mut(m).fill(1.0);
        let mut b = DVector::zeros(m + 1);
        b[m] = 1.0;
        let z = nnls(&aa, &b);
        let r = (&aa * &z - &b).norm();
        (z, r)
    } else {
        let pd = &p * &d;
        let z = nnls(&pd, &(&p * &g));
        let r = (&p * (&g - &d * &z)).norm() / g.norm();
        // A tie (a multiplier that is zero in exact arithmetic, e.g. a joint whose Σ f does not
        // change along its null vector) leaves NNLS a residual of the rounding's size: take
        // the unconstrained multipliers then, their negative part counted in the residual.
        let free = lstsq(&pd, &(&p * &g));
        let r_free = (&p * (&g - &d * &free)).norm() / g.norm();
        let negative = free.iter().fold(0.0_f64, |a, &v| a.max(-v)) / g.norm();
        if r_free.max(negative) < r {
            (free.map(|v| v.max(0.0)), r_free.max(negative))
        } else {
            (z, r)
        }
    };
    assert!(z.iter().all(|&v| v >= 0.0));
    let dz = &d * &z;
    // μ from J_c μ = g − D z (least squares on the range), then the dual objective.
    let (mu, primal, dual) = match policy {
        TensionPolicy::Safest => {
            let mu = lstsq(&a.j, &(-&dz));
            let bounds: f64 = active
                .iter()
                .zip(z.iter())
                .map(|(&(c, s), &zc)| if s > 0.0 { -zc * a.lo[c] } else { zc * a.hi[c] })
                .sum();
            (mu.clone(), margin, mu.dot(&a.t0) + bounds)
        }
        _ => {
            let mu = lstsq(&a.j, &(&g - &dz));
            let bounds: f64 = active
                .iter()
                .zip(z.iter())
                .map(|(&(c, s), &zc)| if s > 0.0 { zc * a.lo[c] } else { -zc * a.hi[c] })
                .sum();
            let primal =
                if policy == TensionPolicy::LeastTotal { a.f.sum() } else { a.f.norm_squared() };
            (mu.clone(), primal, -mu.dot(&a.t0) + bounds)
        }
    };
    let _ = mu;
    (residual, (primal - dual).abs() / primal.abs().max(1.0), active.len())
}

#[test]
fn every_policy_answer_carries_its_optimality_certificate_on_whole_arms() {
    let mut worst = [(0.0_f64, 0.0_f64); 3];
    let (mut dims, mut refuted) = (Vec::new(), 0);
    for case in cases() {
        let mut certified = 0;
        for q in &case.poses {
            for load in &case.loads {
                for (k, policy) in TensionPolicy::ALL.into_iter().enumerate() {
                    let a = match answer(&case, q, load, policy) {
                        Ok(a) => a,
                        Err(StaticsError::NoEquilibrium(_)) => continue,
                        Err(e) => panic!("{} {q:?} {policy:?}: {e}", case.name),
                    };
                    let (residual, gap, active) = certificate(policy, &a);
                    println!(
                        "{} {policy:?}: dim {}, {active} active, stationarity {residual:.1e}, gap {gap:.1e}",
                        case.name, a.dimension
                    );
                    worst[k] = (worst[k].0.max(residual), worst[k].1.max(gap));
                    assert!(
                        residual <= 1e-9,
                        "{} {q:?} {policy:?}: KKT residual {residual:e}",
                        case.name
                    );
                    assert!(gap <= 1e-9, "{} {q:?} {policy:?}: duality gap {gap:e}", case.name);
                    dims.push(a.dimension);
                    certified += 1;
                    // The check can fail: another policy's answer is not certified optimal
                    // for this one (unless both coincide).
                    let other = TensionPolicy::ALL[(k + 1) % 3];
                    if let Ok(b) = answer(&case, q, load, other) {
                        let (r, g, _) = certificate(policy, &b);
                        let differ = (&b.f - &a.f).abs().max() > 1e-6 * a.f.abs().max();
                        if differ {
                            assert!(
                                r > 1e-6 || g > 1e-6,
                                "{} {policy:?} certifies {other:?}'s answer",
                                case.name
                            );
                            refuted += 1;
                        }
                    }
                }
            }
        }
        assert!(certified >= 6, "{}: only {certified} answers certified", case.name);
    }
    println!("worst (stationarity, gap) per policy {worst:?}, dimensions {dims:?}");
    assert!(dims.iter().any(|&d| d >= 5), "no whole-arm set of dimension 5 or more");
    assert!(refuted >= 20, "only {refuted} other answers refuted");
}
