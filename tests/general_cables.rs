//! The general cable path (issue #13, any cable set) on the two arms the closed form does not
//! take, `robots/planar-snake` (four 1-DOF joints, 9 cables, one shared by every joint) and
//! `robots/ua3x4` (three universal joints, four decoupled cables each), and against the closed
//! form on cdhrm5: balance and limits of every tension policy, each policy optimal against a
//! brute-force scan of its null space, `K_q` against finite differences, `C_x` against a
//! nonlinear Newton equilibrium, and the typed refusal of an empty equilibrium set.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::ops::Range;

use faer::{Mat, MatRef};
use nalgebra::Vector6;
use sinew::robot::{Robot, RobotData};
use sinew::routing::{
    Order, PatternModel, Routing, RoutingData, RoutingSpec, compute_cable_geometry,
};
use sinew::statics::{
    ArmStatics, EquilibriumSet, NoEquilibriumCause, StaticsError, TensionChoice, TensionPolicy,
    distribute_with_policy,
};
use sinew::stiffness::{ArmStiffness, ArmStiffnessData, StiffnessError};
use sinew_testkit::cdhrm5;
use sinew_testkit::newton::{Elastic, elastic_cable_torque};
use sinew_testkit::numeric::{H, central_difference, max_abs, rel_diff};

fn robot_dir(name: &str) -> String {
    format!("{}/robots/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn load_robot(name: &str) -> (Robot, Routing) {
    let robot = sinew::robot::load(robot_dir(name)).unwrap();
    let routing = sinew::routing::load(robot_dir(name), &robot).unwrap();
    (robot, routing)
}

/// A new arm, its poses (rad) and loads (F0, the wrench the tip exerts, base frame).
struct Case {
    name: &'static str,
    robot: Robot,
    routing: Routing,
    poses: Vec<Vec<f64>>,
    loads: Vec<Vector6<f64>>,
}

fn cases() -> Vec<Case> {
    let (robot, routing) = load_robot("planar-snake");
    let snake = Case {
        name: "planar-snake",
        robot,
        routing,
        poses: vec![vec![0.0; 4], vec![0.3, -0.2, 0.25, -0.1], vec![-0.4, 0.35, -0.3, 0.45]],
        // The tip pressing down (+y, with gravity) or up, and along the arm.
        loads: vec![
            Vector6::new(0.0, 2.0, 0.0, 0.0, 0.0, 0.0),
            Vector6::new(0.0, -3.0, 1.0, 0.2, 0.0, 0.0),
        ],
    };
    let (robot, routing) = load_robot("ua3x4");
    let ua = Case {
        name: "ua3x4",
        robot,
        routing,
        poses: vec![
            vec![0.0; 6],
            vec![0.2, -0.3, 0.25, 0.1, -0.15, 0.3],
            vec![-0.45, 0.4, 0.3, -0.35, 0.2, -0.25],
        ],
        loads: vec![
            Vector6::new(0.0, 2.0, 0.0, 0.0, 0.0, 0.0),
            Vector6::new(1.0, -2.0, 0.5, 0.1, -0.1, 0.05),
        ],
    };
    vec![snake, ua]
}

/// Kinematics and the cable Jacobian at `q`, then the statics by `choice`.
fn statics_at(
    robot: &Robot,
    routing: &Routing,
    q: &[f64],
    load: &Vector6<f64>,
    choice: TensionChoice<'_>,
) -> (ArmStatics, RoutingData, Result<sinew::statics::ArmStaticsData, StaticsError>) {
    let statics = ArmStatics::new(routing);
    let mut rdata = RobotData::new(robot);
    let mut cables = RoutingData::new(routing);
    compute_cable_geometry(routing, robot, &mut rdata, &mut cables, q, Order::Jacobian).unwrap();
    let mut data = statics.data(robot);
    let outcome =
        statics.solve_with(robot, &mut rdata, &cables, &mut data, load, choice).map(|()| data);
    (statics, cables, outcome)
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The rank of the rows `rows` of `m` (SVD, relative tolerance 1e-10).
fn row_rank(m: MatRef<'_, f64>, rows: &[usize]) -> usize {
    if rows.is_empty() || m.ncols() == 0 {
        return 0;
    }
    let sub = Mat::from_fn(rows.len(), m.ncols(), |i, j| m[(rows[i], j)]);
    let s = sub.singular_values().unwrap();
    s.iter().filter(|&&x| x > 1e-10 * s[0]).count()
}

#[test]
fn the_new_robots_have_the_joints_and_null_spaces_they_were_built_for() {
    let [snake, ua] = <[Case; 2]>::try_from(cases()).ok().unwrap();
    // No massless body between the snake's joints: four 1-DOF joints, none grouped.
    assert_eq!(snake.robot.joint_groups(), &[0..1, 1..2, 2..3, 3..4]);
    assert_eq!(ua.robot.joint_groups(), &[0..2, 2..4, 4..6]);
    let (snake_q, ua_q) = (snake.poses[1].clone(), ua.poses[1].clone());
    for (case, q, dim) in [(&snake, snake_q, 5), (&ua, ua_q, 6)] {
        // Neither fits the closed form: the levels are refused, the policies are not.
        assert!(!ArmStatics::new(&case.routing).has_levels(), "{}", case.name);
        let (statics, cables, data) = statics_at(
            &case.robot,
            &case.routing,
            &q,
            &case.loads[0],
            TensionChoice::Policy(TensionPolicy::LeastNorm),
        );
        let set = statics.equilibrium_set(&cables, &mut data.unwrap()).unwrap().clone();
        assert_eq!(set.dimension(), dim, "{}: null-space dimension", case.name);
        // Antagonistic pairs everywhere: force closed at this pose.
        assert!(set.force_closure().unwrap(), "{}: not force closed", case.name);
    }
}

#[test]
fn every_policy_balances_the_load_within_the_limits_on_the_new_robots() {
    // At every pose and load, for every policy: |T0 + J_cᵀ f| ≤ 1e-9 |T0|, every tension in
    // [f_min, f_max] exactly, and where the policy puts cables on a limit, they are on it:
    // - LeastTotal is an LP, its answer a vertex of the polytope: at least dim N cables exactly
    //   on a limit, their null-space rows of full rank dim N (they fix λ);
    // - LeastNorm: when f_p (the least-norm balancing tensions) leaves the limits, the answer
    //   has some cable exactly on a limit; when it does not, the answer is f_p itself;
    // - Safest: its objective (the least distance to a limit) is positive, and no other policy
    //   reaches a greater one.
    let mut worst_residual: f64 = 0.0;
    for case in cases() {
        for q in &case.poses {
            for load in &case.loads {
                let mut safest_margin = None;
                let mut others = Vec::new();
                for policy in TensionPolicy::ALL {
                    let (statics, cables, data) = statics_at(
                        &case.robot,
                        &case.routing,
                        q,
                        load,
                        TensionChoice::Policy(policy),
                    );
                    let data =
                        data.unwrap_or_else(|e| panic!("{} {q:?} {policy:?}: {e}", case.name));
                    let f = &data.tensions;
                    let j = cables.jacobian().unwrap();
                    let residual: Vec<f64> = (0..data.t0.len())
                        .map(|d| data.t0[d] + (0..f.len()).map(|c| j[(c, d)] * f[c]).sum::<f64>())
                        .collect();
                    let rel = norm(&residual) / norm(&data.t0);
                    worst_residual = worst_residual.max(rel);
                    // A few times the worst measured, 4.9e-15 (the library accepts 1e-9).
                    assert!(rel <= 2e-14, "{} {q:?} {policy:?}: residual {rel:e}", case.name);
                    let limits = statics.cable_limits();
                    for (c, [lo, hi]) in limits.iter().enumerate() {
                        assert!(
                            *lo <= f[c] && f[c] <= *hi,
                            "{} {q:?} {policy:?}: cable {c} at {} N",
                            case.name,
                            f[c]
                        );
                    }
                    let on_limit: Vec<usize> = (0..f.len())
                        .filter(|&c| f[c] == limits[c][0] || f[c] == limits[c][1])
                        .collect();
                    let set = data.cached_equilibrium_set().expect("the policy's set");
                    let margin = (0..f.len())
                        .map(|c| (f[c] - limits[c][0]).min(limits[c][1] - f[c]))
                        .fold(f64::INFINITY, f64::min);
                    match policy {
                        TensionPolicy::LeastTotal => {
                            assert!(
                                row_rank(set.null_basis(), &on_limit) == set.dimension(),
                                "{} {q:?}: least total not at a vertex ({on_limit:?} on a limit)",
                                case.name
                            );
                            others.push(margin);
                        }
                        TensionPolicy::LeastNorm => {
                            let p = set.particular();
                            let inside =
                                (0..p.len()).all(|c| limits[c][0] <= p[c] && p[c] <= limits[c][1]);
                            if inside {
                                assert!(rel_diff_vec(f, p) <= 1e-12, "{}: not f_p", case.name);
                            } else {
                                assert!(
                                    !on_limit.is_empty(),
                                    "{} {q:?}: least norm off the limits",
                                    case.name
                                );
                            }
                            others.push(margin);
                        }
                        TensionPolicy::Safest => {
                            assert!(margin > 0.0, "{} {q:?}: safest margin {margin}", case.name);
                            safest_margin = Some(margin);
                        }
                    }
                }
                let safest = safest_margin.unwrap();
                for m in others {
                    assert!(
                        m <= safest * (1.0 + 1e-9),
                        "{}: {m} N beats safest {safest} N",
                        case.name
                    );
                }
            }
        }
    }
    println!("worst relative equilibrium residual {worst_residual:.2e}");
}

fn rel_diff_vec(a: &[f64], b: &[f64]) -> f64 {
    let d = a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    d / b.iter().fold(0.0_f64, |m, y| m.max(y.abs()))
}

/// A small equilibrium set: the cables `cables` and DOFs `dofs` of an arm at `q` under `load`,
/// the rest of `J_c` and `T0` left out (no other cable may cross those DOFs).
fn sub_set(
    robot: &Robot,
    routing: &Routing,
    q: &[f64],
    load: &Vector6<f64>,
    cables: &[usize],
    dofs: Range<usize>,
) -> EquilibriumSet {
    let (statics, geometry, data) =
        statics_at(robot, routing, q, load, TensionChoice::Policy(TensionPolicy::LeastNorm));
    let data = data.unwrap();
    let j = geometry.jacobian().unwrap();
    // The cables left out must not act on these DOFs: T0 here is then these cables' alone.
    for c in (0..j.nrows()).filter(|c| !cables.contains(c)) {
        for d in dofs.clone() {
            assert_eq!(j[(c, d)], 0.0, "cable {c} crosses DOF {d}");
        }
    }
    let t0: Vec<f64> = data.t0[dofs.clone()].to_vec();
    let sub = Mat::from_fn(cables.len(), dofs.len(), |r, d| j[(cables[r], dofs.start + d)]);
    let limits: Vec<[f64; 2]> = cables.iter().map(|&c| statics.cable_limits()[c]).collect();
    let one_joint = 0..dofs.len();
    EquilibriumSet::new(sub.as_ref(), &t0, &limits, std::slice::from_ref(&one_joint)).unwrap()
}

/// The policy's objective at tensions `f` (minimised: the least distance to a limit enters
/// negated).
fn objective(policy: TensionPolicy, set: &EquilibriumSet, f: &[f64]) -> f64 {
    match policy {
        TensionPolicy::LeastTotal => f.iter().sum(),
        TensionPolicy::LeastNorm => norm(f),
        TensionPolicy::Safest => -(0..f.len())
            .map(|c| (f[c] - set.lower()[c]).min(set.upper()[c] - f[c]))
            .fold(f64::INFINITY, f64::min),
    }
}

/// The feasible points of a grid of `n` points per axis over the box `[lo, hi]` of `λ`: the
/// least objective found and the box of the feasible points.
fn scan(
    set: &EquilibriumSet,
    policy: TensionPolicy,
    lo: &[f64],
    hi: &[f64],
    n: usize,
) -> (f64, Vec<f64>, Vec<f64>, Vec<f64>) {
    let k = set.dimension();
    let mut f = vec![0.0; set.cable_count()];
    let (mut best, mut fmin, mut fmax) = (f64::INFINITY, hi.to_vec(), lo.to_vec());
    let mut lambda = vec![0.0; k];
    let mut argmin = vec![f64::NAN; k];
    let total = n.pow(k as u32);
    for index in 0..total {
        let mut rest = index;
        for i in 0..k {
            lambda[i] = lo[i] + (hi[i] - lo[i]) * (rest % n) as f64 / (n - 1) as f64;
            rest /= n;
        }
        set.tensions(&lambda, &mut f).unwrap();
        if (0..f.len()).all(|c| set.lower()[c] <= f[c] && f[c] <= set.upper()[c]) {
            let value = objective(policy, set, &f);
            if value < best {
                best = value;
                argmin.copy_from_slice(&lambda);
            }
            for i in 0..k {
                fmin[i] = fmin[i].min(lambda[i]);
                fmax[i] = fmax[i].max(lambda[i]);
            }
        }
    }
    (best, fmin, fmax, argmin)
}

#[test]
fn every_policy_is_optimal_against_a_brute_force_scan_of_its_null_space() {
    // Three small sets, each an arm's joint alone (its cables and DOFs, the torque the other
    // cables put on it at a full solution taken off):
    // - cdhrm5 joint 1 (decoupled): 3 cables, 2 DOF, dim 1;
    // - ua3x4 joint 1: 4 cables, 2 DOF, dim 2 (decoupled: no other cable crosses it);
    // - planar-snake joint 4: j4a, j4b and the shared cable, 1 DOF, dim 2 (no other cable
    //   crosses it).
    // A coarse grid over a box holding the polytope (|λ| ≤ |f_max| + |f_p|) finds the polytope's
    // box; a fine grid over it finds the best cell, and the same grid over ±2 of its cells
    // (spacing h): no feasible point beats the policy by more than 1e-9 relative, and the best
    // one is within the grid's resolution of it, L·h·√k with L the
    // objective's Lipschitz constant in λ (|Nᵀ1| for Σf, 1 for |f| and the least distance).
    let load = Vector6::new(0.0, 3.0, 0.0, 0.0, 0.0, 0.0);
    let (c5, c5_routing) = cdhrm5::robot_and_routing(PatternModel::Decoupled);
    let c5_q = cdhrm5::LOADED_POSE;
    let (ua, ua_routing) = load_robot("ua3x4");
    let (snake, snake_routing) = load_robot("planar-snake");
    let sets = [
        ("cdhrm5 joint 1", sub_set(&c5, &c5_routing, &c5_q, &load, &[0, 1, 2], 0..2)),
        (
            "ua3x4 joint 1",
            sub_set(
                &ua,
                &ua_routing,
                &[0.2, -0.3, 0.25, 0.1, -0.15, 0.3],
                &load,
                &[0, 1, 2, 3],
                0..2,
            ),
        ),
        (
            "planar-snake joint 4",
            sub_set(&snake, &snake_routing, &[0.3, -0.2, 0.25, -0.1], &load, &[6, 7, 8], 3..4),
        ),
    ];
    for (name, set) in &sets {
        let k = set.dimension();
        assert!(k == 1 || k == 2, "{name}: dim {k}");
        let fine = if k == 1 { 200_001 } else { 1201 };
        for policy in TensionPolicy::ALL {
            let mut f = vec![0.0; set.cable_count()];
            let answer =
                distribute_with_policy(set, policy, std::slice::from_ref(&(0..1)), &[], &mut f)
                    .unwrap();
            let mine = objective(policy, set, &f);
            let bound = norm(set.upper()) + norm(set.particular());
            let (_, lo, hi, _) = scan(set, policy, &vec![-bound; k], &vec![bound; k], 401);
            let cell = 2.0 * bound / 400.0;
            let lo: Vec<f64> = lo.iter().map(|v| v - cell).collect();
            let hi: Vec<f64> = hi.iter().map(|v| v + cell).collect();
            let (_, _, _, near) = scan(set, policy, &lo, &hi, fine);
            let h = (0..k).map(|i| (hi[i] - lo[i]) / (fine - 1) as f64).fold(0.0, f64::max);
            // Zoom: the same grid over two of its cells around its best point.
            let (lo, hi): (Vec<f64>, Vec<f64>) =
                near.iter().map(|c| (c - 2.0 * h, c + 2.0 * h)).unzip();
            let (best, _, _, _) = scan(set, policy, &lo, &hi, fine);
            let h = 4.0 * h / (fine - 1) as f64;
            let lipschitz = match policy {
                TensionPolicy::LeastTotal => {
                    let null = set.null_basis();
                    norm(
                        &(0..k)
                            .map(|i| (0..f.len()).map(|c| null[(c, i)]).sum())
                            .collect::<Vec<f64>>(),
                    )
                }
                _ => 1.0,
            };
            let resolution = lipschitz * h * (k as f64).sqrt();
            let beaten_by = (mine - best) / mine.abs();
            let gap = best - mine;
            println!(
                "{name} {policy:?}: dim {k}, objective {mine:.9}, grid best {best:.9} (h {h:.2e}, resolution {resolution:.2e}): grid better by {beaten_by:.2e} relative, worse by {gap:.2e}",
            );
            assert!(
                beaten_by <= 1e-9,
                "{name} {policy:?}: the grid beats the policy by {beaten_by:e}"
            );
            assert!(
                gap <= resolution,
                "{name} {policy:?}: policy {mine} far from the grid's best {best}"
            );
            assert!((answer.objective.abs() - mine.abs()).abs() <= 1e-9 * mine.abs());
        }
    }
}

/// `K_q`'s and `C_x`'s differences relative to `closed` (`C_x` only when the arm is stable).
fn k_q_and_c_x_diff(
    general: &ArmStiffnessData,
    closed: &ArmStiffnessData,
    stable: bool,
) -> (f64, f64) {
    let c = if stable { rel_diff(general.compliance(), closed.compliance()) } else { 0.0 };
    (rel_diff(general.k_q(), closed.k_q()), c)
}

#[test]
fn the_general_path_agrees_with_the_closed_form_on_cdhrm5() {
    let load = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    let robot = cdhrm5::robot();
    let mut poses = vec![cdhrm5::LOADED_POSE.to_vec()];
    poses.extend(sinew_testkit::config::random_qs(&robot, 13, 12));
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        let arm = ArmStiffness::new(&robot, &routing).unwrap();
        let mut closed = ArmStiffnessData::new(&arm);
        let mut general = ArmStiffnessData::new(&arm);
        let (mut compared, mut stable) = (0, 0);
        for q in &poses {
            // K_q first (defined when unstable too), then C_x where the arm is stable.
            let levels = TensionChoice::Levels(&[0.0; 5]);
            if arm.evaluate_joints(&mut closed, q, &load, levels).is_err() {
                continue; // infeasible at levels: nothing to compare
            }
            let lp = TensionChoice::Policy(TensionPolicy::LeastTotal);
            arm.evaluate_joints(&mut general, q, &load, lp).unwrap();
            compared += 1;
            let is_stable = match arm.evaluate(&mut closed, q, &load, levels) {
                Ok(()) => true,
                Err(StiffnessError::Unstable { .. }) => false,
                Err(e) => panic!("{q:?}: {e}"),
            };
            if is_stable {
                stable += 1;
            }
            match arm.evaluate(&mut general, q, &load, lp) {
                Ok(()) | Err(StiffnessError::Unstable { .. }) => {}
                Err(e) => panic!("{q:?}: {e}"),
            }
            let (fc, fg) = (closed.tensions().to_vec(), general.tensions().to_vec());
            let tension_diff = rel_diff_vec(&fg, &fc);
            let (total_c, total_g) = (fc.iter().sum::<f64>(), fg.iter().sum::<f64>());
            println!(
                "cdhrm5 {model:?}: LP vs levels 0: tensions differ by {tension_diff:.2e}, totals {total_g:.9} / {total_c:.9} N"
            );
            match model {
                PatternModel::Decoupled => {
                    // Each joint's least-total end is the LP's optimum: the same tensions.
                    assert!(
                        tension_diff <= 1e-12,
                        "decoupled: tensions differ by {tension_diff:e}"
                    );
                    let (k, c) = k_q_and_c_x_diff(&general, &closed, is_stable);
                    println!("  K_q differ by {k:.2e}, C_x by {c:.2e} (stable: {is_stable})");
                    assert!(k <= 1e-12 && c <= 1e-12, "decoupled: K_q {k:e}, C_x {c:e}");
                }
                PatternModel::Routed => {
                    // Levels 0 is each joint's least-total end given the distal tensions, so it
                    // need not be the whole arm's least total (distal tensions load the
                    // proximal joints). What held at every pose drawn: the LP's optimum IS
                    // levels 0 (tensions agree to ~1e-15), so the stronger check is asserted.
                    assert!(
                        tension_diff <= 1e-12 && total_g <= total_c * (1.0 + 1e-12),
                        "routed: tensions differ by {tension_diff:e}, LP {total_g} vs {total_c}"
                    );
                    // The general path at the closed form's tensions reproduces it.
                    let given = TensionChoice::Given(&fc);
                    match arm.evaluate(&mut general, q, &load, given) {
                        Ok(()) => assert!(is_stable, "{q:?}: stable only on the general path"),
                        Err(StiffnessError::Unstable { .. }) => assert!(!is_stable),
                        Err(e) => panic!("{q:?}: {e}"),
                    }
                    let (k, c) = k_q_and_c_x_diff(&general, &closed, is_stable);
                    println!("  given levels-0 tensions: K_q differ by {k:.2e}, C_x by {c:.2e}");
                    assert!(k <= 1e-12 && c <= 1e-12, "routed: K_q {k:e}, C_x {c:e}");
                }
            }
        }
        println!("cdhrm5 {model:?}: {compared} feasible poses compared, {stable} stable (C_x)");
        assert!(compared >= 6 && stable >= 2, "{model:?}: {compared} compared, {stable} stable");
    }
}

#[test]
fn k_q_at_policy_tensions_is_minus_the_derivative_of_the_cable_torque() {
    let mut worst_all: f64 = 0.0;
    for case in cases() {
        let arm = ArmStiffness::new(&case.robot, &case.routing).unwrap();
        let mut data = ArmStiffnessData::new(&arm);
        let mut worst: f64 = 0.0;
        for q in &case.poses {
            for policy in TensionPolicy::ALL {
                arm.evaluate_joints(&mut data, q, &case.loads[0], TensionChoice::Policy(policy))
                    .unwrap();
                let f0 = data.tensions().to_vec();
                let l0 = data.cables.lengths().unwrap().to_vec();
                let numeric = -central_difference(q, H, |q| {
                    elastic_cable_torque(&case.robot, &case.routing, q, &f0, &l0)
                });
                let k = data.k_q();
                let err = max_abs((k.to_owned() - &numeric).as_ref()) / max_abs(k).max(1.0);
                worst = worst.max(err);
            }
        }
        println!("{}: K_q vs −∂τ/∂Q worst relative error {worst:.2e}", case.name);
        worst_all = worst_all.max(worst);
        assert!(worst <= 1e-6, "{}: K_q error {worst:e}", case.name);
    }
    println!("worst {worst_all:.2e}");
}

fn mat_vec(m: MatRef<'_, f64>, v: &Vector6<f64>) -> Vector6<f64> {
    Vector6::from_fn(|i, _| (0..6).map(|j| m[(i, j)] * v[j]).sum())
}

#[test]
fn compliance_matches_the_nonlinear_equilibrium_on_the_new_robots() {
    // The symmetric probe (δx(+δw) − δx(−δw)) / 2 of a Newton solve of the elastic model
    // (sinew_testkit::newton) against C_x δw, one probe per wrench axis: 1e-3 N, 1e-4 N m, times
    // (margin / 0.6 N m/rad)² below a stability margin of 0.6 N m/rad (tests/equilibrium.rs
    // says why). The snake moves only in its plane: its out-of-plane probes (f_x, m_y, m_z)
    // have C_x δw = 0, and the solve must not move it either.
    for case in cases() {
        let arm = ArmStiffness::new(&case.robot, &case.routing).unwrap();
        let mut data = ArmStiffnessData::new(&arm);
        let (mut worst, mut checked): (f64, usize) = (0.0, 0);
        for q in &case.poses[1..] {
            for policy in [TensionPolicy::LeastNorm, TensionPolicy::Safest] {
                let load = case.loads[0];
                match arm.evaluate(&mut data, q, &load, TensionChoice::Policy(policy)) {
                    // C_x is what is compared: it exists when J_x is rank-deficient too.
                    Ok(()) | Err(StiffnessError::RankDeficient { .. }) => {}
                    Err(StiffnessError::Unstable { min_eigenvalue }) => {
                        println!("{} {q:?} {policy:?}: unstable ({min_eigenvalue:.3})", case.name);
                        continue;
                    }
                    Err(e) => panic!("{} {q:?} {policy:?}: {e}", case.name),
                }
                let margin = data.stability_margin().unwrap();
                let c_x = data.compliance().to_owned();
                let probe = (margin / 0.6).min(1.0).powi(2);
                let mut elastic =
                    Elastic::new(&case.robot, &case.routing, q, data.tensions().to_vec(), load);
                let jac = elastic.newton_matrix(q);
                let q_star = elastic.solve(q, &jac, &Vector6::zeros());
                let mut errors = Vec::new();
                let reach = {
                    let mut rd = RobotData::new(&case.robot);
                    case.robot.forward_kinematics(&mut rd, q).unwrap();
                    case.robot.point_position(&rd, &case.robot.tip_point()).unwrap().norm()
                };
                for axis in 0..6 {
                    let mut dw = Vector6::zeros();
                    dw[axis] = probe * if axis < 3 { 1e-3 } else { 1e-4 };
                    let plus = elastic.solve(q, &jac, &dw);
                    let minus = elastic.solve(q, &jac, &-dw);
                    let dx =
                        (elastic.motion(&q_star, &plus) - elastic.motion(&q_star, &minus)) / 2.0;
                    let linear = mat_vec(c_x.as_ref(), &dw);
                    if linear.norm() <= 1e-12 * max_abs(c_x.as_ref()) * dw.norm() {
                        // An out-of-plane probe of the snake: neither moves.
                        assert!(dx.norm() <= 1e-12, "{}: moved {dx:?} under {dw:?}", case.name);
                        continue;
                    }
                    // Translations over the reach L (tip distance from the base) and rotations
                    // in radians: metres and radians weighted alike, not summed raw.
                    let weigh = |v: Vector6<f64>| {
                        Vector6::from_fn(|i, _| if i < 3 { v[i] / reach } else { v[i] })
                    };
                    errors.push(weigh(dx - linear).norm() / weigh(linear).norm());
                }
                let e = errors.iter().fold(0.0_f64, |m, x| m.max(*x));
                println!(
                    "{} {q:?} {policy:?}: margin {margin:.3} N m/rad, {} probes, worst |δx − C_x δw| / |C_x δw| {e:.2e}",
                    case.name,
                    errors.len()
                );
                worst = worst.max(e);
                checked += 1;
            }
        }
        println!("{}: worst Newton error {worst:.2e} over {checked} equilibria", case.name);
        assert!(checked >= 2, "{}: only {checked} stable equilibria", case.name);
        // A few times the worst measured (snake 1.8e-6, ua3x4 4.0e-7, reach-weighted).
        assert!(worst <= 1e-5, "{}: C_x off by {worst:e}", case.name);
    }
}

fn assert_one_sentence(message: &str) {
    assert!(!message.contains('\n'), "more than a line: {message}");
    assert!(!message.contains(". "), "more than one sentence: {message}");
}

#[test]
fn a_load_beyond_the_limits_is_refused_naming_the_joint() {
    // The snake straight, F0 = 60 N along +y (the tip pressing down on a surface, which pushes
    // it up): the +y cables must pull. Joint 1 then needs 53.6 N m from its cables (all nine
    // cross it at 18 or 10 mm), which give at most 41.6 N m within [20, 600] N; joints 2–4
    // hold. The certificate names joint 1 alone, its joint motion [-1, 0, 0, 0] (T0 · δq = 53.6).
    let (robot, routing) = load_robot("planar-snake");
    let load = Vector6::new(0.0, 60.0, 0.0, 0.0, 0.0, 0.0);
    for policy in TensionPolicy::ALL {
        let (_, _, outcome) =
            statics_at(&robot, &routing, &[0.0; 4], &load, TensionChoice::Policy(policy));
        let Err(StaticsError::NoEquilibrium(why)) = outcome else {
            panic!("{policy:?}: expected NoEquilibrium, got {:?}", outcome.map(|d| d.tensions));
        };
        assert_eq!(why.joints, vec![0], "{policy:?}: {why}");
        assert!(matches!(why.cause, NoEquilibriumCause::Limits { .. }), "{policy:?}: {why}");
        let message = StaticsError::NoEquilibrium(why).to_string();
        println!("{policy:?}: {message}");
        assert!(message.contains("at joint 1:"), "{message}");
        assert_one_sentence(&message);
    }
}

#[test]
fn a_joint_without_force_closure_is_answered_when_its_segment_is_not_empty() {
    // The snake without j4b and the shared cable: joint 4 keeps only j4a (at +y), so it is not
    // force closed, and j4a alone must hold its torque. The tip pushed up by its environment
    // (F0 = +10 N along y, the tip pressing down) needs j4a at (10·0.22 − 0.24·9.81·0.11) / 0.018
    // ≈ 108 N: answered. Gravity alone needs it to push (negative tension): refused, naming
    // joint 4.
    let (robot, _) = load_robot("planar-snake");
    let text =
        std::fs::read_to_string(format!("{}/cables.toml", robot_dir("planar-snake"))).unwrap();
    let mut spec = RoutingSpec::from_toml_str(&text, "cables.toml").unwrap();
    spec.cables.retain(|c| c.name != "j4b" && c.name != "shared");
    let routing = Routing::new(&robot, &spec, "<planar-snake without j4b, shared>").unwrap();
    let j4a = routing.cables().iter().position(|c| c.name == "j4a").unwrap();
    let q = [0.0; 4];
    let push = Vector6::new(0.0, 10.0, 0.0, 0.0, 0.0, 0.0);
    for policy in TensionPolicy::ALL {
        let (_, _, outcome) =
            statics_at(&robot, &routing, &q, &push, TensionChoice::Policy(policy));
        let data = outcome.unwrap_or_else(|e| panic!("{policy:?}: {e}"));
        let set = data.cached_equilibrium_set().expect("the policy's set");
        assert!(!set.force_closure().unwrap(), "still force closed");
        let expected = (10.0 * 0.22 - 0.24 * 9.81 * 0.11) / 0.018;
        let f = data.tensions[j4a];
        println!("{policy:?}: j4a holds {f:.6} N (expected {expected:.6} N)");
        assert!((f - expected).abs() <= 1e-9 * expected, "{policy:?}: j4a {f} N");
        let (_, _, refused) =
            statics_at(&robot, &routing, &q, &Vector6::zeros(), TensionChoice::Policy(policy));
        let Err(StaticsError::NoEquilibrium(why)) = refused else {
            panic!("{policy:?}: gravity alone was answered");
        };
        assert_eq!(why.joints, vec![3], "{policy:?}: {why}");
        let message = StaticsError::NoEquilibrium(why).to_string();
        println!("{policy:?}: {message}");
        assert!(message.contains("at joint 4:"), "{message}");
        assert_one_sentence(&message);
    }
}

/// The two routing examples of docs/cli.md load as they say: four cables on one universal
/// joint (a two-dimensional equilibrium set), and a revolute joint beside a universal joint
/// with a shared cable of its own limits.
#[test]
fn the_routing_examples_of_the_cli_docs_load() {
    let doc = std::fs::read_to_string(cdhrm5::workspace_root().join("docs/cli.md")).unwrap();
    let blocks: Vec<&str> =
        doc.split("```toml\n").skip(1).map(|b| b.split("```").next().unwrap()).collect();
    let four = blocks.iter().find(|b| b.contains("\"j1d\"")).expect("the 4-cable example");
    let robot = cdhrm5::chain_robot(1);
    let routing = Routing::from_toml_str(four, "cli.md", &robot).unwrap();
    assert_eq!(routing.cable_joints(), &[0, 0, 0, 0]);
    let choice = TensionChoice::Policy(TensionPolicy::LeastNorm);
    let (statics, cables, data) =
        statics_at(&robot, &routing, &[0.1, -0.2], &Vector6::zeros(), choice);
    let set = statics.equilibrium_set(&cables, &mut data.unwrap()).unwrap().clone();
    assert_eq!(set.dimension(), 2);

    let mixed = blocks.iter().find(|b| b.contains("\"shared\"")).expect("the mixed example");
    let urdf = r#"<robot name="mixed"><link name="base_link"/>
      <joint name="r" type="revolute"><parent link="base_link"/><child link="link1"/>
        <origin xyz="0 0 0.03"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
      <link name="link1"><inertial><origin xyz="0 0 0.1"/><mass value="0.2"/>
        <inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-4"/></inertial></link>
      <joint name="link1_disc" type="fixed"><parent link="link1"/><child link="link1_distal"/><origin xyz="0 0 0.2"/></joint>
      <link name="link1_distal"/>
      <joint name="u_x" type="revolute"><parent link="link1_distal"/><child link="cross2"/>
        <origin xyz="0 0 0.03"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
      <link name="cross2"/>
      <joint name="u_y" type="revolute"><parent link="cross2"/><child link="link2"/>
        <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
      <link name="link2"/></robot>"#;
    let settings = sinew::robot::ChainSettings {
        tip_link: "link2".to_owned(),
        gravity: nalgebra::Vector3::zeros(),
    };
    let robot = Robot::from_urdf_str(urdf, "mixed.urdf", &settings).unwrap();
    assert_eq!(robot.joint_groups(), &[0..1, 1..3]);
    let routing = Routing::from_toml_str(mixed, "cli.md", &robot).unwrap();
    assert_eq!(routing.cable_joints(), &[0, 0, 1], "the shared cable drives the universal joint");
    assert_eq!(routing.cable_limits()[2], [10.0, 300.0]);
    assert_eq!(routing.cable_joint_span(2), Some(0..2), "and crosses both joints");
}
