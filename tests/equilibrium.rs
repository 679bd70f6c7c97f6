//! The end compliance against a nonlinear equilibrium solve (spec §5), which needs no
//! derivative of the library: apply a small wrench `δw` to the end-effector, find the new
//! equilibrium `Q` of the elastic cables, gravity and the load by Newton's method (with a
//! finite-difference Jacobian of the residual), and compare the end-effector's displacement and
//! rotation with `C_x δw`. Criterion: `|δx_nonlinear − C_x δw| ≤ 1 % · |C_x δw|`.
//!
//! The arm is soft (a 0.01 N force moves the tip by millimetres to centimetres), so the
//! nonlinear response to `+δw` alone carries a second-order part of about 1 %. The probe is
//! therefore the symmetric one, `(δx(+δw) − δx(−δw)) / 2`, whose error is of second order in
//! `δw`; the one-sided error is printed as well. `one_sided_error_is_first_order` checks that
//! the one-sided error shrinks in proportion to `δw`, i.e. that `C_x` is the exact derivative.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use faer::linalg::solvers::Solve;
use nalgebra::{Vector3, Vector6};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sinew::robot::{Robot, RobotData};
use sinew::routing::{Order, Routing, RoutingData, compute_cable_geometry};
use sinew::stiffness::{ArmStiffness, ArmStiffnessData};

const ROBOT_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/robots/cdhrm5");

use sinew::paper::E4_Q;

/// Everything the nonlinear model needs, frozen at the reference equilibrium.
struct Elastic<'a> {
    robot: &'a Robot,
    routing: &'a Routing,
    /// Tensions at the reference configuration, N.
    f0: Vec<f64>,
    /// Cable lengths at the reference configuration, m.
    l0: Vec<f64>,
    /// Wrench the end-effector exerts on its environment at the reference, base frame.
    load: Vector6<f64>,
}

impl Elastic<'_> {
    /// `R(Q) = −J_c(Q)ᵀ f(Q) − T_g(Q) − J_x(Q)ᵀ (F0 − δw)`, zero at equilibrium; `δw` is the
    /// wrench applied to the end-effector; `f(Q) = f0 + K_l (L(Q) − L0)`.
    fn residual(&self, q: &[f64], dw: &Vector6<f64>) -> Vec<f64> {
        let n = self.robot.dof();
        let mut rdata = RobotData::new(self.robot);
        let mut g = RoutingData::new(self.routing);
        compute_cable_geometry(self.routing, self.robot, &mut rdata, &mut g, q, Order::Jacobian)
            .unwrap();
        let (l, j_c, k) =
            (g.lengths().unwrap(), g.jacobian().unwrap(), self.routing.cable_stiffness());
        let f: Vec<f64> = (0..l.len()).map(|c| self.f0[c] + k[c] * (l[c] - self.l0[c])).collect();
        let mut t_g = vec![0.0; n];
        self.robot.gravity_torque(&mut rdata, &mut t_g).unwrap();
        let mut t_load = vec![0.0; n];
        self.robot
            .wrench_torque(&rdata, &self.robot.tip_point(), &(self.load - dw), &mut t_load)
            .unwrap();
        (0..n)
            .map(|d| -(0..f.len()).map(|c| j_c[(c, d)] * f[c]).sum::<f64>() - t_g[d] - t_load[d])
            .collect()
    }

    /// Newton's method from `q0`, with a central-difference Jacobian of the residual.
    fn solve(&self, q0: &[f64], dw: &Vector6<f64>) -> Vec<f64> {
        let n = q0.len();
        let mut q = q0.to_vec();
        for _ in 0..50 {
            let r = self.residual(&q, dw);
            let norm = r.iter().map(|x| x * x).sum::<f64>().sqrt();
            // Round-off in J_cᵀ f (tensions of hundreds of newtons) is ~1e-13 N m.
            if norm < 1e-10 {
                return q;
            }
            let h = 1e-7;
            let mut jac = Mat::<f64>::zeros(n, n);
            for i in 0..n {
                let mut qp = q.clone();
                let mut qm = q.clone();
                qp[i] += h;
                qm[i] -= h;
                let (rp, rm) = (self.residual(&qp, dw), self.residual(&qm, dw));
                for j in 0..n {
                    jac[(j, i)] = (rp[j] - rm[j]) / (2.0 * h);
                }
            }
            let rhs = Mat::from_fn(n, 1, |i, _| -r[i]);
            let step = jac.partial_piv_lu().solve(rhs);
            // Backtracking: halve the step until the residual decreases.
            let mut t = 1.0;
            loop {
                let trial: Vec<f64> = (0..n).map(|i| q[i] + t * step[(i, 0)]).collect();
                let r_trial = self.residual(&trial, dw);
                if r_trial.iter().map(|x| x * x).sum::<f64>().sqrt() < norm || t < 1e-6 {
                    q = trial;
                    break;
                }
                t *= 0.5;
            }
        }
        let r = self.residual(&q, dw);
        panic!(
            "Newton did not converge: residual {:.3e} at {q:?} (from {q0:?}, δw {dw:?})",
            r.iter().map(|x| x * x).sum::<f64>().sqrt()
        );
    }

    /// End-effector displacement and rotation vector from `q0` to `q`, base frame.
    fn motion(&self, q0: &[f64], q: &[f64]) -> Vector6<f64> {
        let mut data = RobotData::new(self.robot);
        self.robot.forward_kinematics(&mut data, q0).unwrap();
        let a = self.robot.tip_pose(&data).unwrap();
        self.robot.forward_kinematics(&mut data, q).unwrap();
        let b = self.robot.tip_pose(&data).unwrap();
        let dp = b.translation.vector - a.translation.vector;
        let dr = (b.rotation * a.rotation.inverse()).scaled_axis();
        Vector6::new(dp[0], dp[1], dp[2], dr[0], dr[1], dr[2])
    }
}

/// The errors of one equilibrium over the six probe wrenches: `(symmetric, one-sided)`.
struct Errors {
    symmetric: f64,
    one_sided: f64,
}

/// Checks one equilibrium with probes `scale · (0.01 N along each axis, 0.001 N m about each
/// axis)`; `None` when it is infeasible, unstable, or stable by less than `margin` N m/rad.
fn check(
    robot: &Robot,
    routing: &Routing,
    q0: &[f64],
    load: &Vector6<f64>,
    levels: &[f64],
    margin: f64,
    scale: f64,
) -> Option<Errors> {
    let model = ArmStiffness::new(robot, routing).unwrap();
    let mut data = ArmStiffnessData::new(&model);
    model.evaluate_compliance(&mut data, q0, load, levels).ok()?;
    if data.stability_margin().unwrap() < margin {
        return None;
    }
    let c_x = data.compliance().to_owned();
    let elastic = Elastic {
        robot,
        routing,
        f0: data.tensions().to_vec(),
        l0: data.cables.lengths().unwrap().to_vec(),
        load: *load,
    };
    let mut errors = Errors { symmetric: 0.0, one_sided: 0.0 };
    for k in 0..6 {
        let mut dw = Vector6::zeros();
        dw[k] = scale * if k < 3 { 0.01 } else { 0.001 };
        let plus = elastic.motion(q0, &elastic.solve(q0, &dw));
        let minus = elastic.motion(q0, &elastic.solve(q0, &-dw));
        let linear = Vector6::from_fn(|i, _| (0..6).map(|j| c_x[(i, j)] * dw[j]).sum());
        let symmetric = (plus - minus) / 2.0;
        errors.symmetric = errors.symmetric.max((symmetric - linear).norm() / linear.norm());
        errors.one_sided = errors.one_sided.max((plus - linear).norm() / linear.norm());
    }
    Some(errors)
}

fn setups() -> Vec<(&'static str, Robot, Routing)> {
    let robot = sinew::robot::load(ROBOT_DIR).unwrap();
    [sinew::routing::ROUTING_FILE, sinew::routing::ROUTED_ROUTING_FILE]
        .into_iter()
        .map(|file| {
            let routing = sinew::routing::load(format!("{ROBOT_DIR}/{file}"), &robot).unwrap();
            (file, robot.clone(), routing)
        })
        .collect()
}

#[test]
fn compliance_matches_the_nonlinear_equilibrium_at_e4() {
    let load = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    for (name, robot, routing) in setups() {
        let mut checked = 0;
        for level in [0.0, 0.25, 0.5, 0.75, 1.0] {
            let Some(e) = check(&robot, &routing, &E4_Q, &load, &[level; 5], 0.0, 1.0) else {
                println!("{name}: E4 at level {level} is infeasible or unstable; not checked");
                continue;
            };
            checked += 1;
            println!(
                "{name}: E4 level {level}: error {:.2e} (one-sided {:.2e})",
                e.symmetric, e.one_sided
            );
            assert!(
                e.symmetric <= 0.01,
                "{name}: E4 level {level}: C_x δw off by {:.3} %",
                100.0 * e.symmetric
            );
        }
        assert!(checked >= 3, "{name}: E4 stable at only {checked} of 5 levels");
    }
}

#[test]
fn compliance_matches_the_nonlinear_equilibrium_at_random_stable_configurations() {
    for (name, robot, routing) in setups() {
        let mut rng = ChaCha8Rng::seed_from_u64(71);
        let (mut checked, mut tried, mut worst, mut worst_one_sided) = (0, 0, 0.0_f64, 0.0_f64);
        while checked < 20 {
            tried += 1;
            assert!(tried < 5000, "{name}: too few feasible stable configurations");
            let q: Vec<f64> =
                robot.joints().iter().map(|j| rng.random_range(j.lower..=j.upper)).collect();
            let load = Vector6::new(
                rng.random_range(-2.0..2.0),
                rng.random_range(-2.0..2.0),
                rng.random_range(-2.0..2.0),
                0.0,
                0.0,
                0.0,
            );
            let levels: Vec<f64> = (0..5).map(|_| rng.random_range(0.0..1.0)).collect();
            // Stable with a margin of 0.6 N m/rad: 0.01 N at the ~1.2 m tip is 0.012 N m, which
            // turns such a joint by ~0.02 rad. Closer to the stability limit 0.01 N is no longer
            // a small load (Newton then finds the arm snapping to another equilibrium). With the
            // calibrated geometry (joint centre on the distal disc) one of these draws, at a
            // margin of 0.53 N m/rad, is off by 3.6 % at 0.01 N but by 0.03 % at 0.001 N: second
            // order in the probe, i.e. C_x exact and 0.01 N no longer small there.
            if let Some(e) = check(&robot, &routing, &q, &load, &levels, 0.6, 1.0) {
                worst = worst.max(e.symmetric);
                worst_one_sided = worst_one_sided.max(e.one_sided);
                checked += 1;
            }
        }
        println!(
            "{name}: 20 random stable equilibria ({tried} tried): worst error {worst:.2e} (one-sided {worst_one_sided:.2e})"
        );
        assert!(worst <= 0.01, "{name}: C_x δw off by {:.3} %", 100.0 * worst);
    }
}

#[test]
fn one_sided_error_is_first_order() {
    // Ten times smaller probes, ten times smaller one-sided error: C_x is the exact derivative.
    let load = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    for (name, robot, routing) in setups() {
        let big = check(&robot, &routing, &E4_Q, &load, &[0.5; 5], 0.0, 1.0).unwrap();
        let small = check(&robot, &routing, &E4_Q, &load, &[0.5; 5], 0.0, 0.1).unwrap();
        let ratio = big.one_sided / small.one_sided;
        println!(
            "{name}: one-sided error {:.2e} → {:.2e} (ratio {ratio:.2})",
            big.one_sided, small.one_sided
        );
        assert!((ratio - 10.0).abs() < 1.0, "{name}: one-sided error ratio {ratio}");
    }
}

#[test]
fn the_reference_is_an_equilibrium_of_the_nonlinear_model_with_gravity() {
    // The residual vanishes at the reference (the statics balanced T0 there), and it does not
    // once gravity is taken away: the nonlinear model does carry gravity.
    let (_, robot, routing) = setups().remove(0);
    let model = ArmStiffness::new(&robot, &routing).unwrap();
    let mut data = ArmStiffnessData::new(&model);
    let load = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
    model.evaluate_compliance(&mut data, &E4_Q, &load, &[0.5; 5]).unwrap();
    let (f0, l0) = (data.tensions().to_vec(), data.cables.lengths().unwrap().to_vec());
    let with = Elastic { robot: &robot, routing: &routing, f0: f0.clone(), l0: l0.clone(), load };
    let r = with.residual(&E4_Q, &Vector6::zeros());
    assert!(r.iter().all(|x| x.abs() <= 1e-9), "residual at the reference: {r:?}");
    let weightless = robot.with_gravity(Vector3::zeros());
    let without = Elastic { robot: &weightless, routing: &routing, f0, l0, load };
    let r = without.residual(&E4_Q, &Vector6::zeros());
    assert!(r.iter().any(|x| x.abs() > 0.1), "gravity changed nothing: {r:?}");
}
