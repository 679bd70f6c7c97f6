//! A wrench increment after a history, with friction at the holes (spec §9, #27): the stick
//! load limit and the directional response, against a nonlinear model built from library
//! *values* only. Every piece of cable is a spring `E A/ℓ_s` frozen at the pose with the
//! tensions the history left; gravity and the load `F0 − δw` complete the potential
//! (`sinew_testkit::newton::Potential`), solved by Newton's method.
//!
//! - **Stick load limit:** at 0.98 times the limit every hole is inside its band; at 1.02 times
//!   the hole the library names is past the edge it names, and that edge's rate (`−g/α`)
//!   matches the central difference of the model's `g` (3e-6: the bracket alone does not see
//!   the band's motion `μ T δθ`, small next to the springs). After a pull, along a direction
//!   whose limit is 0, a small increment pushes each hole named past its edge.
//! - **Directional response:** the linear system of a sliding set is the stick response with no
//!   hole and the pull slip regime's (`K_slip`, derived apart) with every hole; along ±(the
//!   load), the nonlinear model with the holes the library says slide free to pass cable at
//!   their edge moves the tip by `ε · compliance` to first order, with those holes passing cable
//!   toward the actuator and every other hole inside its band.
//!
//! What the model reads from the library: segment lengths and wrap angles (values, at any `Q`),
//! poses, masses, and at the reference the tensions, `K_stick`, `K_W` and `J_x` (only to
//! compute what is checked; Newton's matrices are central differences of the residual). A
//! wrong `δT_s`, `∇θ`, band edge, flux or sign therefore shows here.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use faer::linalg::solvers::Solve;
use nalgebra::{Rotation3, Vector6};
use sinew_robot::{Robot, RobotData};
use sinew_routing::{
    FrictionData, FrictionModel, Order, PatternModel, Routing, RoutingData, Slip,
    compute_cable_geometry, compute_capstan_weights, compute_friction_geometry,
};
use sinew_statics::{TensionChoice, TensionPolicy, distribute_with_policy, slip_equilibrium_set};
use sinew_stiffness::{
    ArmStiffness, ArmStiffnessData, BandEdge, DirectionalResponse, FrictionStiffnessData, History,
    HoleEvent, Increment, StickLoadLimit, StiffnessError, base_directions, directional_response,
    sliding_response, slip_stiffness, stick_load_limits, stick_stiffness,
};
use sinew_testkit::cdhrm5;
use sinew_testkit::newton::{Potential, Values};

const MU: f64 = 0.1;
/// E4's load: 5 N along +y at the tip (base frame).
const F0: [f64; 6] = [0.0, 5.0, 0.0, 0.0, 0.0, 0.0];

/// The friction geometry at `q` (lengths, directions, wrap angles), weights of `slip` if any.
fn friction_at(
    robot: &Robot,
    routing: &Routing,
    model: &FrictionModel,
    q: &[f64],
    slip: Option<Slip>,
) -> (RoutingData, FrictionData) {
    let mut rdata = RobotData::new(robot);
    let mut geometry = RoutingData::new(routing);
    compute_cable_geometry(routing, robot, &mut rdata, &mut geometry, q, Order::Hessians).unwrap();
    let mut friction = FrictionData::new(model);
    compute_friction_geometry(model, routing, &geometry, &mut friction).unwrap();
    if let Some(slip) = slip {
        compute_capstan_weights(model, &mut friction, slip).unwrap();
    }
    (geometry, friction)
}

/// The stick model frozen at the reference: per cable, each segment's length, tension and
/// spring there.
struct Stick<'a> {
    robot: &'a Robot,
    routing: &'a Routing,
    model: &'a FrictionModel,
    values: Values<'a>,
    load: Vector6<f64>,
    /// Per cable and segment: `(ℓ_s, T_s, E A/ℓ_s)` at the reference.
    frozen: Vec<Vec<(f64, f64, f64)>>,
    /// Per cable and segment: the unstretched length gained since the reference, `δm_s`
    /// (0 while every hole sticks; [`Stick::set_flux`]).
    material: Vec<Vec<f64>>,
}

impl<'a> Stick<'a> {
    fn new(
        robot: &'a Robot,
        routing: &'a Routing,
        model: &'a FrictionModel,
        q: &[f64],
        segment_tensions: &[Vec<f64>],
    ) -> Stick<'a> {
        let (_, friction) = friction_at(robot, routing, model, q, None);
        let ea = routing.youngs_modulus() * routing.area();
        let frozen = segment_tensions
            .iter()
            .enumerate()
            .map(|(c, t)| {
                let l = friction.lengths(model, c).unwrap();
                l.iter().zip(t).map(|(&l, &t)| (l, t, ea / l)).collect()
            })
            .collect();
        let values = Values::new(robot, routing);
        let material = segment_tensions.iter().map(|t| vec![0.0; t.len()]).collect();
        Stick { robot, routing, model, values, load: Vector6::from(F0), frozen, material }
    }

    /// Cable `phi[i]` passed through hole `sliding[i] = (cable, hole)` (away from the
    /// actuator): `δm_s = φ_{s−1} − φ_s`.
    fn set_flux(&mut self, sliding: &[(usize, usize)], phi: &[f64]) {
        for m in &mut self.material {
            m.fill(0.0);
        }
        for (&(c, k), &f) in sliding.iter().zip(phi) {
            self.material[c][k] -= f;
            self.material[c][k + 1] += f;
        }
    }

    /// Per cable: every segment's tension and every hole's wrap angle at `q`.
    fn state(&self, q: &[f64]) -> Vec<(Vec<f64>, Vec<f64>)> {
        let (_, friction) = friction_at(self.robot, self.routing, self.model, q, None);
        self.frozen
            .iter()
            .enumerate()
            .map(|(c, frozen)| {
                let l = friction.lengths(self.model, c).unwrap();
                let t = frozen
                    .iter()
                    .zip(l)
                    .zip(&self.material[c])
                    .map(|((&(l0, t0, k), &l), m)| t0 + k * (l - l0 - m))
                    .collect();
                (t, friction.wrap_angles(self.model, c).unwrap().to_vec())
            })
            .collect()
    }

    /// `g⁻` and `g⁺` of every hole at `q`, cable by cable: `(cable, hole, g⁻, g⁺, scale)`.
    fn bands(&self, q: &[f64]) -> Vec<(usize, usize, f64, f64, f64)> {
        let mut out = Vec::new();
        for (c, (t, theta)) in self.state(q).into_iter().enumerate() {
            for (k, &theta) in theta.iter().enumerate() {
                let (lo, hi) = ((-MU * theta).exp(), (MU * theta).exp());
                out.push((c, k, t[k + 1] - t[k] * lo, t[k] * hi - t[k + 1], t[k] + t[k + 1]));
            }
        }
        out
    }
}

impl Potential for Stick<'_> {
    fn load(&self) -> Vector6<f64> {
        self.load
    }

    fn energy(&mut self, q: &[f64], dw: &Vector6<f64>) -> (f64, Rotation3<f64>) {
        let force = (self.load - dw).fixed_rows::<3>(0).into_owned();
        let (_, tip, gravity) = self.values.at(q);
        let (tip, mut v) = (tip, gravity + force.dot(&tip.translation.vector));
        let (_, friction) = friction_at(self.robot, self.routing, self.model, q, None);
        for (c, frozen) in self.frozen.iter().enumerate() {
            let l = friction.lengths(self.model, c).unwrap();
            for ((&(l0, t0, k), &l), m) in frozen.iter().zip(l).zip(&self.material[c]) {
                let d = l - l0 - m;
                v += t0 * d + 0.5 * k * d * d;
            }
        }
        (v, tip.rotation)
    }
}

/// Everything at the reference for one routing model and history.
struct Setup {
    robot: Robot,
    routing: Routing,
    model: FrictionModel,
    actuator: Vec<f64>,
    segments: Vec<Vec<f64>>,
    limits: Vec<StickLoadLimit>,
    friction: FrictionData,
    geometry: RoutingData,
    k_stick: Mat<f64>,
    k_w: Mat<f64>,
    j_x: Mat<f64>,
}

impl Setup {
    fn increment(&self) -> Increment<'_> {
        (self.k_stick.as_ref(), self.k_w.as_ref(), self.j_x.as_ref())
    }
}

fn setup(pattern: PatternModel, history: History) -> Setup {
    let (robot, routing) = cdhrm5::robot_and_routing(pattern);
    let model = FrictionModel::new(&routing).with_friction_coefficient(MU).unwrap();
    let q = cdhrm5::LOADED_POSE;
    let f0 = Vector6::from(F0);
    let arm = ArmStiffness::new(&robot, &routing).unwrap();
    let mut data = ArmStiffnessData::new(&arm);
    arm.evaluate_joints(&mut data, &q, &f0, TensionChoice::Levels(&[0.5; 5])).unwrap();
    let (geometry, friction) = friction_at(&robot, &routing, &model, &q, history.slip());
    // Actuator tensions that balance the load with the history's segment tensions: equal along
    // each cable (the frictionless statics), or the pull distribution (the slip statics on J̃).
    let actuator = match history {
        History::Equal => data.tensions().to_vec(),
        _ => {
            let statics = arm.statics();
            let set = slip_equilibrium_set(
                &model,
                &friction,
                &data.statics.t0,
                statics.cable_limits(),
                statics.joint_groups(),
            )
            .unwrap();
            let names: Vec<String> = routing.cables().iter().map(|c| c.name.clone()).collect();
            let mut t = vec![0.0; routing.cable_count()];
            distribute_with_policy(
                &set,
                TensionPolicy::Safest,
                statics.joint_groups(),
                &names,
                &mut t,
            )
            .unwrap();
            t
        }
    };
    let segments: Vec<Vec<f64>> = (0..routing.cable_count())
        .map(|c| {
            let h = friction.lengths(&model, c).unwrap().len();
            match history {
                History::Equal => vec![actuator[c]; h],
                _ => friction.weights(&model, c).unwrap().iter().map(|w| actuator[c] * w).collect(),
            }
        })
        .collect();
    let mut stick = FrictionStiffnessData::new(&model);
    stick_stiffness(&model, &routing, &geometry, &friction, history, &actuator, &mut stick)
        .unwrap();
    let k_w = data.k_w().to_owned();
    let j_x = data.j_x().to_owned();
    let limits = stick_load_limits(
        &model,
        &routing,
        &friction,
        history,
        &actuator,
        (stick.stiffness().unwrap(), k_w.as_ref(), j_x.as_ref()),
        &base_directions(),
    )
    .unwrap();
    let k_stick = stick.stiffness().unwrap().to_owned();
    Setup {
        robot,
        routing,
        model,
        actuator,
        segments,
        limits,
        friction,
        geometry,
        k_stick,
        k_w,
        j_x,
    }
}

/// The least `g / scale` over every hole and edge, and that of one hole's edge.
fn least_and_named(
    bands: &[(usize, usize, f64, f64, f64)],
    c: usize,
    k: usize,
    edge: BandEdge,
) -> (f64, f64) {
    let least = bands.iter().map(|b| b.2.min(b.3) / b.4).fold(f64::INFINITY, f64::min);
    let b = bands.iter().find(|b| b.0 == c && b.1 == k).unwrap();
    let named = match edge {
        BandEdge::Lower => b.2 / b.4,
        BandEdge::Upper => b.3 / b.4,
    };
    (least, named)
}

#[test]
fn from_equal_tensions_the_limit_is_positive_and_right_on_both_sides() {
    for pattern in cdhrm5::MODELS {
        let s = setup(pattern, History::Equal);
        let q = cdhrm5::LOADED_POSE;
        let mut stick = Stick::new(&s.robot, &s.routing, &s.model, &q, &s.segments);
        // The reference is an equilibrium of the nonlinear model (the library's statics, signs
        // and tensions agree with it): Newton does not move.
        let jac = stick.newton_matrix(&q);
        let rest = stick.solve(&q, &jac, &Vector6::zeros());
        let moved = rest.iter().zip(&q).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(moved < 1e-9, "{pattern:?}: the reference is not an equilibrium ({moved:.1e} rad)");
        for limit in &s.limits {
            let u = limit.direction;
            assert!(limit.at_once.is_empty(), "{pattern:?} {u:?}: {:?}", limit.at_once);
            let first = limit.first.expect("some edge is approached");
            let alpha = limit.magnitude;
            assert!(alpha > 0.0 && alpha.is_finite(), "{pattern:?} {u:?}: {alpha}");
            assert!(!first.kinked);
            let below = stick.solve(&q, &jac, &(0.98 * alpha * u));
            let below = stick.bands(&below);
            let above = stick.solve(&q, &jac, &(1.02 * alpha * u));
            let above = stick.bands(&above);
            let (least_below, _) = least_and_named(&below, first.cable, first.hole, first.edge);
            let (_, named_above) = least_and_named(&above, first.cable, first.hole, first.edge);
            println!(
                "{pattern:?} u = {:?}: limit {alpha:.4} (cable {}, hole {}, {:?}); least band room \
                 at 0.98×: {least_below:.2e}, the named edge at 1.02×: {named_above:.2e}",
                u.as_slice(),
                first.cable,
                first.hole,
                first.edge
            );
            assert!(least_below > 0.0, "{pattern:?} {u:?}: a band is broken below the limit");
            assert!(named_above < 0.0, "{pattern:?} {u:?}: the named edge holds above the limit");
            // The named edge's rate ġ = −g/α (the limit is g/(−ġ)) against the central
            // difference of the nonlinear model's g along u: the band's motion (μ T δθ) counts
            // in it, not only the segments' stretch.
            let raw = |bands: &[(usize, usize, f64, f64, f64)]| {
                let b = bands.iter().find(|b| (b.0, b.1) == (first.cable, first.hole)).unwrap();
                if first.edge == BandEdge::Lower { b.2 } else { b.3 }
            };
            let step = 1e-3 * alpha;
            let (plus, minus) =
                (stick.solve(&q, &jac, &(step * u)), stick.solve(&q, &jac, &(-step * u)));
            let (plus, minus) = (raw(&stick.bands(&plus)), raw(&stick.bands(&minus)));
            let g0 = raw(&stick.bands(&q));
            let (slope, predicted) = ((plus - minus) / (2.0 * step), -g0 / alpha);
            let error = (slope / predicted - 1.0).abs();
            println!(
                "{pattern:?} u = {:?}: ġ {predicted:.6e}, central difference {slope:.6e} ({error:.1e})",
                u.as_slice()
            );
            assert!(error <= RATE_CHECK, "{pattern:?} {u:?}: ġ {predicted} against {slope}");
        }
    }
}

/// The relative error allowed between the stick load limit's edge rate and the central
/// difference of the nonlinear model (measured: at most 6.8e-7 over both models and the twelve
/// base directions).
const RATE_CHECK: f64 = 3e-6;

#[test]
fn after_a_pull_the_holes_pushed_over_their_edge_slide_at_once() {
    for pattern in cdhrm5::MODELS {
        let s = setup(pattern, History::Pull);
        let q = cdhrm5::LOADED_POSE;
        let mut stick = Stick::new(&s.robot, &s.routing, &s.model, &q, &s.segments);
        let jac = stick.newton_matrix(&q);
        // Every hole of a pulled cable sits on its lower edge.
        for b in stick.bands(&q) {
            assert!(b.2.abs() <= 1e-12 * b.4, "{pattern:?}: hole {b:?} is not on its lower edge");
        }
        let zero: Vec<&StickLoadLimit> = s.limits.iter().filter(|l| l.magnitude == 0.0).collect();
        assert!(!zero.is_empty(), "{pattern:?}: no direction slides at once after a pull");
        for limit in &s.limits {
            let u = limit.direction;
            if limit.magnitude > 0.0 {
                assert!(limit.at_once.is_empty());
                continue;
            }
            // 0.01 N (or N m) along u: far above Newton's floor, far below any band's width.
            let moved = stick.solve(&q, &jac, &(0.01 * u));
            let bands = stick.bands(&moved);
            for e in &limit.at_once {
                assert_eq!(e.edge, BandEdge::Lower, "{pattern:?} {u:?}: {e:?}");
                let (_, named) = least_and_named(&bands, e.cable, e.hole, e.edge);
                assert!(named < 0.0, "{pattern:?} {u:?}: {e:?} holds ({named:.1e})");
            }
            // And the holes not named stay on their edge or move inside it.
            for b in &bands {
                let named = limit.at_once.iter().any(|e| e.cable == b.0 && e.hole == b.1);
                assert!(named || b.2 >= -1e-9 * b.4, "{pattern:?} {u:?}: hole {b:?} not named");
            }
            println!(
                "{pattern:?} u = {:?}: {} holes slide at once",
                u.as_slice(),
                limit.at_once.len()
            );
        }
        assert!(s.actuator.iter().all(|t| *t > 0.0));
    }
}

#[test]
fn bad_input_is_refused() {
    let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Routed);
    let q = cdhrm5::LOADED_POSE;
    let n = routing.dof();
    let eye = Mat::<f64>::identity(n, n);
    let zero = Mat::<f64>::zeros(n, n);
    let j_x = Mat::<f64>::from_fn(6, n, |i, j| if i == j { 1.0 } else { 0.0 });
    let t = vec![100.0; routing.cable_count()];
    let model = FrictionModel::new(&routing).with_friction_coefficient(MU).unwrap();
    let (_, friction) = friction_at(&robot, &routing, &model, &q, None);
    let call = |model: &FrictionModel, history, k: &Mat<f64>, u: Vector6<f64>| {
        stick_load_limits(
            model,
            &routing,
            &friction,
            history,
            &t,
            (k.as_ref(), zero.as_ref(), j_x.as_ref()),
            &[u],
        )
        .map(|_| ())
        .map_err(Box::new)
    };
    let u = Vector6::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    assert!(call(&model, History::Equal, &eye, u).is_ok());
    for bad in [Vector6::zeros(), Vector6::new(f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0)] {
        let e = call(&model, History::Equal, &eye, bad).unwrap_err();
        assert!(matches!(*e, StiffnessError::InvalidWrenchDirection { .. }), "{e}");
    }
    let unstable = Mat::<f64>::from_fn(n, n, |i, j| match (i == j, i) {
        (true, 3) => -2.0,
        (true, _) => 1.0,
        _ => 0.0,
    });
    match *call(&model, History::Equal, &unstable, u).unwrap_err() {
        StiffnessError::Unstable { min_eigenvalue } => assert_eq!(min_eigenvalue, -2.0),
        e => panic!("{e}"),
    }
    // Unstable along (1, …, 1) only: I − 1.1 · 11ᵀ/n, least eigenvalue −0.1 (a symmetric part
    // formed as 0.5 + (K + Kᵀ) instead of 0.5 (K + Kᵀ) adds 0.5 · 11ᵀ and hides it).
    let ones = Mat::<f64>::from_fn(n, n, |i, j| f64::from(u8::from(i == j)) - 1.1 / n as f64);
    match *call(&model, History::Equal, &ones, u).unwrap_err() {
        StiffnessError::Unstable { min_eigenvalue } => {
            assert!((min_eigenvalue + 0.1).abs() < 1e-12, "{min_eigenvalue}")
        }
        e => panic!("{e}"),
    }
    // Pull without the pull weights; μ = 0 (no band to stick in).
    let e = call(&model, History::Pull, &eye, u).unwrap_err();
    assert!(matches!(*e, StiffnessError::WrongCapstanWeights { .. }), "{e}");
    let frictionless = FrictionModel::new(&routing);
    let e = call(&frictionless, History::Equal, &eye, u).unwrap_err();
    assert!(matches!(*e, StiffnessError::StickWithoutFriction { cable: 0 }), "{e}");
}

/// `(K + K_W)⁻¹ J_xᵀ u`.
fn response(k: &Mat<f64>, k_w: &Mat<f64>, j_x: &Mat<f64>, u: &Vector6<f64>) -> Vec<f64> {
    let n = k.nrows();
    let a = Mat::from_fn(n, n, |i, j| k[(i, j)] + k_w[(i, j)]);
    let rhs = Mat::from_fn(n, 1, |i, _| (0..6).map(|r| j_x[(r, i)] * u[r]).sum::<f64>());
    let x = a.partial_piv_lu().solve(rhs);
    (0..n).map(|i| x[(i, 0)]).collect()
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let d = a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    d / b.iter().map(|x| x.abs()).fold(0.0, f64::max)
}

#[test]
fn the_sliding_system_is_stick_with_no_hole_and_slip_with_every_hole() {
    // No hole sliding: the stick regime's response. Every hole sliding at its lower edge after
    // a pull: the pull slip regime's, whose K_slip is derived apart (slip.rs) and checked
    // against the central difference of a nonlinear torque (tests/friction.rs).
    for pattern in cdhrm5::MODELS {
        let s = setup(pattern, History::Pull);
        let mut slip = FrictionStiffnessData::new(&s.model);
        let args = (&s.model, &s.routing, &s.geometry, &s.friction);
        slip_stiffness(args.0, args.1, args.2, args.3, Slip::Pull, &s.actuator, &mut slip).unwrap();
        let k_slip = slip.stiffness().unwrap().to_owned();
        let every: Vec<HoleEvent> = (0..s.routing.cable_count())
            .flat_map(|c| {
                let n = s.friction.wrap_angles(&s.model, c).unwrap().len();
                (0..n).map(move |k| HoleEvent {
                    cable: c,
                    hole: k,
                    edge: BandEdge::Lower,
                    kinked: false,
                })
            })
            .collect();
        let mut worst = [0.0_f64; 2];
        for u in base_directions() {
            let call = |sliding: &[HoleEvent]| {
                let h = History::Pull;
                let (m, r, f, t) = (&s.model, &s.routing, &s.friction, &s.actuator);
                sliding_response(m, r, f, h, t, s.increment(), &u, sliding).unwrap()
            };
            let (dq, flux) = call(&[]);
            assert!(flux.is_empty());
            worst[0] = worst[0].max(rel_diff(&dq, &response(&s.k_stick, &s.k_w, &s.j_x, &u)));
            let (dq, flux) = call(&every);
            worst[1] = worst[1].max(rel_diff(&dq, &response(&k_slip, &s.k_w, &s.j_x, &u)));
            assert_eq!(flux.len(), every.len());
        }
        println!(
            "{pattern:?}: |δQ − δQ_stick| {:.1e}, |δQ − δQ_slip| {:.1e} (relative)",
            worst[0], worst[1]
        );
        assert!(worst[0] <= 1e-12, "{pattern:?}: stick {:.1e}", worst[0]);
        assert!(worst[1] <= 1e-8, "{pattern:?}: slip {:.1e}", worst[1]);
    }
}

#[test]
fn the_directional_response_is_consistent_and_shows_hysteresis() {
    for pattern in cdhrm5::MODELS {
        // From equal tensions no hole is on an edge: both directions are the stick response.
        let s = setup(pattern, History::Equal);
        for u in base_directions() {
            let (m, r, f, t) = (&s.model, &s.routing, &s.friction, &s.actuator);
            let [plus, minus] =
                directional_response(m, r, f, History::Equal, t, s.increment(), &u).unwrap();
            let dq = response(&s.k_stick, &s.k_w, &s.j_x, &u);
            assert!(plus.sliding.is_empty() && minus.sliding.is_empty());
            assert_eq!(plus.passes, 1);
            assert!(rel_diff(&plus.joint_motion, &dq) <= 1e-12);
            assert!((plus.compliance - minus.compliance).abs() <= 1e-12 * plus.compliance);
        }
        // After a pull: some holes slide, the way their edge allows; every hole that sticks
        // stays inside its band and every one that slides keeps to its edge, recomputed here
        // from δQ and the fluxes (δT_s = k_s (J_s δQ − φ_{s−1} + φ_s)); sliding only softens.
        let s = setup(pattern, History::Pull);
        let mut hysteresis = 0.0_f64;
        for u in base_directions().into_iter().step_by(2) {
            let (m, r, f, t) = (&s.model, &s.routing, &s.friction, &s.actuator);
            let both = directional_response(m, r, f, History::Pull, t, s.increment(), &u).unwrap();
            let stick_compliance = {
                let dq = response(&s.k_stick, &s.k_w, &s.j_x, &u);
                (0..6)
                    .map(|r| u[r] * (0..10).map(|i| s.j_x[(r, i)] * dq[i]).sum::<f64>())
                    .sum::<f64>()
            };
            for one in &both {
                assert!(
                    !one.sliding.is_empty(),
                    "{pattern:?} {u:?}: a pull leaves every hole on an edge"
                );
                // Reported cable by cable, hole by hole, as documented.
                let order: Vec<(usize, usize)> =
                    one.sliding.iter().map(|e| (e.cable, e.hole)).collect();
                assert!(order.windows(2).all(|w| w[0] < w[1]), "{pattern:?} {u:?}: {order:?}");
                for (e, f) in one.sliding.iter().zip(&one.flux) {
                    assert_eq!(e.edge, BandEdge::Lower);
                    assert!(
                        *f <= 0.0,
                        "{pattern:?}: {e:?} slides away from the actuator ({f:.1e})"
                    );
                }
                assert!(
                    one.compliance >= stick_compliance * (1.0 - 1e-12),
                    "{pattern:?}: stiffer than stick"
                );
                assert!((one.stiffness * one.compliance - 1.0).abs() < 1e-15);
                check_bands(&s, one);
            }
            hysteresis = hysteresis
                .max((both[0].compliance - both[1].compliance).abs() / both[0].compliance);
            println!(
                "{pattern:?} u = {:?}: compliance +u {:.4e} ({} sliding, {} passes), −u {:.4e} ({} sliding); stick {:.4e}",
                u.as_slice(),
                both[0].compliance,
                both[0].sliding.len(),
                both[0].passes,
                both[1].compliance,
                both[1].sliding.len(),
                stick_compliance
            );
        }
        assert!(hysteresis > 1e-3, "{pattern:?}: ±u give the same compliance ({hysteresis:.1e})");
        // After a release every hole is on its upper edge: those that slide, slide away from
        // the actuator (cargo mutants: the upper edge's flux sign taken as the lower one's went
        // unnoticed while only pull was tested), and sliding only softens.
        let s = setup(pattern, History::Release);
        for u in base_directions().into_iter().step_by(2) {
            let (m, r, f, t) = (&s.model, &s.routing, &s.friction, &s.actuator);
            let both =
                directional_response(m, r, f, History::Release, t, s.increment(), &u).unwrap();
            let dq = response(&s.k_stick, &s.k_w, &s.j_x, &u);
            let stick_compliance: f64 =
                (0..6).map(|r| u[r] * (0..10).map(|i| s.j_x[(r, i)] * dq[i]).sum::<f64>()).sum();
            for one in &both {
                assert!(!one.sliding.is_empty(), "{pattern:?} {u:?}: every hole on an edge");
                for (e, f) in one.sliding.iter().zip(&one.flux) {
                    assert_eq!(e.edge, BandEdge::Upper);
                    assert!(*f >= 0.0, "{pattern:?}: {e:?} slides toward the actuator ({f:.1e})");
                }
                assert!(one.compliance >= stick_compliance * (1.0 - 1e-12), "{pattern:?}");
            }
        }
    }
}

/// Every hole's lower-edge rate `ġ⁻` under the response, from its `δQ` and fluxes: 0 where the
/// hole slides, ≥ 0 where it sticks (after a pull every hole is on its lower edge).
fn check_bands(s: &Setup, one: &DirectionalResponse) {
    let ea = s.routing.youngs_modulus() * s.routing.area();
    let dot = |row: sinew_routing::DofRow<'_>| {
        row.values.iter().zip(row.dofs).map(|(v, d)| v * one.joint_motion[d]).sum::<f64>()
    };
    for c in 0..s.routing.cable_count() {
        let l = s.friction.lengths(&s.model, c).unwrap();
        let theta = s.friction.wrap_angles(&s.model, c).unwrap();
        let phi = |k: usize| {
            one.sliding
                .iter()
                .zip(&one.flux)
                .find(|(e, _)| (e.cable, e.hole) == (c, k))
                .map_or(0.0, |(_, f)| *f)
        };
        let rate = |s_: usize| {
            let stretch = if s_ == 0 {
                0.0
            } else {
                dot(s.friction.segment_jacobian(&s.model, c, s_).unwrap())
            };
            let gained = if s_ == 0 { 0.0 } else { phi(s_ - 1) } - phi(s_);
            ea / l[s_] * (stretch - gained)
        };
        for k in 0..theta.len() {
            let (t_k, lo) = (s.segments[c][k], (-MU * theta[k]).exp());
            let dtheta = dot(s.friction.wrap_gradient(&s.model, c, k).unwrap());
            let (dt_k, dt_next) = (rate(k), rate(k + 1));
            let g = dt_next - lo * (dt_k - MU * t_k * dtheta);
            let terms = dt_next.abs() + lo * (dt_k.abs() + (MU * t_k * dtheta).abs());
            let slides = one.sliding.iter().any(|e| (e.cable, e.hole) == (c, k));
            if slides {
                assert!(
                    g.abs() <= 1e-9 * terms.max(1e-300),
                    "cable {c} hole {k}: slides off its edge ({g:.1e})"
                );
            } else {
                assert!(
                    g >= -1e-9 * terms,
                    "cable {c} hole {k}: pushed over its edge ({g:.1e}) but sticks"
                );
            }
        }
    }
}

/// The equilibrium under `dw` with the holes `sliding` (each at its lower edge) free to pass
/// cable and every other hole sticking: Newton's method on `(Q, φ)`, the residual the energy's
/// gradient in `Q` and each sliding hole's edge `T_{k+1} − T_k e^{−μθ_k}` (values only), its
/// matrix a central difference at the reference (a chord method).
fn solve_sliding(
    stick: &mut Stick<'_>,
    q0: &[f64],
    sliding: &[(usize, usize)],
    dw: &Vector6<f64>,
) -> (Vec<f64>, Vec<f64>) {
    let (n, p) = (q0.len(), sliding.len());
    let residual = |stick: &mut Stick<'_>, z: &[f64]| -> Vec<f64> {
        stick.set_flux(sliding, &z[n..]);
        let mut r = Potential::residual(stick, &z[..n], dw);
        let state = stick.state(&z[..n]);
        for &(c, k) in sliding {
            let (t, theta) = &state[c];
            r.push(t[k + 1] - t[k] * (-MU * theta[k]).exp());
        }
        r
    };
    let z0: Vec<f64> = q0.iter().copied().chain(std::iter::repeat_n(0.0, p)).collect();
    let mut jac = Mat::<f64>::zeros(n + p, n + p);
    for j in 0..n + p {
        let h = if j < n { 1e-5 } else { 1e-8 };
        let mut z = z0.clone();
        z[j] += h;
        let rp = residual(stick, &z);
        z[j] -= 2.0 * h;
        let rm = residual(stick, &z);
        for i in 0..n + p {
            jac[(i, j)] = (rp[i] - rm[i]) / (2.0 * h);
        }
    }
    let lu = jac.partial_piv_lu();
    let mut z = z0;
    for _ in 0..60 {
        let r = residual(stick, &z);
        let norm = r.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm < 1e-11 {
            break;
        }
        let step = lu.solve(Mat::from_fn(n + p, 1, |i, _| -r[i]));
        for (i, x) in z.iter_mut().enumerate() {
            *x += step[(i, 0)];
        }
    }
    stick.set_flux(sliding, &z[n..]);
    (z[..n].to_vec(), z[n..].to_vec())
}

#[test]
fn the_directional_compliance_is_the_nonlinear_models_with_its_holes_sliding() {
    // Along the load (+y) and against it, after a pull: the nonlinear model, with the holes the
    // library says slide free to pass cable at their edge and the others sticking, moves the
    // tip by `ε (compliance) u` to first order in ε.
    let u = Vector6::new(0.0, 1.0, 0.0, 0.0, 0.0, 0.0);
    let q = cdhrm5::LOADED_POSE;
    for pattern in cdhrm5::MODELS {
        let s = setup(pattern, History::Pull);
        let (m, r, f, t) = (&s.model, &s.routing, &s.friction, &s.actuator);
        let both = directional_response(m, r, f, History::Pull, t, s.increment(), &u).unwrap();
        let mut stick = Stick::new(&s.robot, &s.routing, &s.model, &q, &s.segments);
        let mut values = Values::new(&s.robot, &s.routing);
        for one in &both {
            let sliding: Vec<(usize, usize)> =
                one.sliding.iter().map(|e| (e.cable, e.hole)).collect();
            let mut errors = Vec::new();
            for eps in [1e-2, 1e-3] {
                let (q_eps, phi) = solve_sliding(&mut stick, &q, &sliding, &(eps * one.direction));
                let motion = values.motion(&q, &q_eps);
                let compliance = one.direction.dot(&motion) / eps;
                errors.push((compliance - one.compliance).abs() / one.compliance);
                // The nonlinear solution is consistent: sliding holes pass cable toward the
                // actuator, and the others stay inside their bands.
                for (e, (f, f_lib)) in sliding.iter().zip(phi.iter().zip(&one.flux)) {
                    assert!(*f < 0.0, "{pattern:?} {e:?}: flux {f:.2e}");
                    assert!((f / eps - f_lib).abs() <= 0.05 * f_lib.abs(), "{pattern:?} {e:?}");
                }
                for b in stick.bands(&q_eps) {
                    let slides = sliding.contains(&(b.0, b.1));
                    assert!(slides || b.2 >= -1e-9 * b.4, "{pattern:?}: hole {b:?} pushed over");
                }
            }
            println!(
                "{pattern:?} {:?}: compliance {:.6e} ({} sliding); nonlinear at ε = 1e-2, 1e-3: relative error {:.1e}, {:.1e}",
                one.direction.as_slice(),
                one.compliance,
                sliding.len(),
                errors[0],
                errors[1]
            );
            assert!(errors[1] <= 5e-5, "{pattern:?}: {errors:?}"); // measured ≤ 1.0e-5
            assert!(
                errors[1] <= 0.2 * errors[0] + 1e-6,
                "{pattern:?}: not first order: {errors:?}"
            );
        }
    }
}
