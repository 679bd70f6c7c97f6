//! The friction geometry (spec §9) against central differences and against the frictionless
//! geometry it must reproduce.
//!
//! Criterion for each derivative, per case over its configurations: `max |analytic − FD| ≤
//! tol · max |analytic|` (h = 1e-6), `tol` at a few times the worst error measured (beside each
//! bound; `--nocapture` prints them). Cases: cdhrm5 in both routing files (the decoupled
//! cables enter on a moving disc; the routed cables run through rigid segments along the
//! links), seeded random-geometry chains with pattern and explicit routings whose cables carry
//! random entry directions, and cables that run back toward the base (a segment whose routing
//! ends are swapped; a first segment that does, where the entry direction's turning enters
//! `∂θ_0`).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use sinew_robot::{Robot, RobotData};
use sinew_routing::{
    CableFriction, FrictionData, FrictionModel, Order, PatternModel, Routing, RoutingData, Slip,
    compute_cable_geometry, compute_capstan_weights, compute_friction_angles,
    compute_friction_geometry, compute_wrap_gradients,
};
use sinew_testkit::cdhrm5;
use sinew_testkit::config::{random_q, random_qs, rng};
use sinew_testkit::numeric::H;
use sinew_testkit::random_chain::RandomChain;

use rand::Rng;

/// Everything at one configuration: the routing workspace and the friction workspace.
struct At {
    routing_data: RoutingData,
    data: FrictionData,
}

fn evaluate(robot: &Robot, routing: &Routing, model: &FrictionModel, q: &[f64], slip: Slip) -> At {
    let mut rdata = RobotData::new(robot);
    let mut routing_data = RoutingData::new(routing);
    compute_cable_geometry(routing, robot, &mut rdata, &mut routing_data, q, Order::Hessians)
        .unwrap();
    let mut data = FrictionData::new(model);
    compute_friction_geometry(model, routing, &routing_data, &mut data).unwrap();
    compute_capstan_weights(model, &mut data, slip).unwrap();
    At { routing_data, data }
}

/// [`cases`]' tolerances for the random chains.
const RANDOM_TOL: [f64; 6] = [1e-8, 3e-9, 6e-9, 5e-9, 5e-9, 1e-8];

/// A random unit-ish direction within 60° of +z (a cable arriving roughly along the arm).
fn random_entry(rng: &mut impl Rng) -> [f64; 3] {
    [rng.random_range(-0.8..0.8), rng.random_range(-0.8..0.8), rng.random_range(0.5..2.0)]
}

/// The derivative cases: name, robot, routing, tolerances `[J_s, H_s, ∂θ, ∂w, ∂J̃, J̃]` at a
/// few times the worst measured (cdhrm5: 5.1e-9, 2.6e-9, 5.8e-9, 5.7e-9, 3.1e-9, 8.7e-9;
/// random chains: at most 2.6e-9, 6.3e-10, 1.7e-9, 1.4e-9, 1.2e-9, 3.2e-9).
fn cases() -> Vec<(String, Robot, Routing, [f64; 6])> {
    let mut out = Vec::new();
    for model in cdhrm5::MODELS {
        let (robot, routing) = cdhrm5::robot_and_routing(model);
        out.push((
            format!("cdhrm5 {model:?}"),
            robot,
            routing,
            [2e-8, 1e-8, 2e-8, 2e-8, 1e-8, 3e-8],
        ));
    }
    for seed in [3, 4] {
        let chain = RandomChain::new(3, seed);
        let robot = chain.robot();
        let mut entries = rng(100 + seed);
        for model in cdhrm5::MODELS {
            let mut spec = chain.pattern_spec(model);
            if let Some(pattern) = spec.pattern.as_mut() {
                for i in 0..chain.joints {
                    let friction = CableFriction {
                        entry_direction: Some(random_entry(&mut entries)),
                        ..Default::default()
                    };
                    pattern.cables.insert(format!("j{}c2", i + 1), friction);
                }
            }
            let routing = chain.routing(&robot, &spec);
            out.push((format!("{} {model:?}", chain.name), robot.clone(), routing, RANDOM_TOL));
        }
        let mut spec = chain.explicit_spec(seed);
        for cable in &mut spec.cables {
            cable.entry_direction = Some(random_entry(&mut entries));
        }
        let routing = chain.routing(&robot, &spec);
        out.push((format!("{} explicit", chain.name), robot, routing, RANDOM_TOL));
    }
    // Two cables that run back toward the base (link2 → link1), one of them from its first
    // segment (`RandomChain::turning_back_cables`).
    let chain = RandomChain::new(2, 5);
    let robot = chain.robot();
    let mut spec = chain.explicit_spec(5);
    spec.cables.extend(RandomChain::turning_back_cables());
    let routing = chain.routing(&robot, &spec);
    let zigzag = &routing.cables()[routing.cable_index("zigzag").unwrap()];
    assert!(zigzag.holes[1].body_point.body > zigzag.holes[2].body_point.body);
    out.push(("zigzag".to_owned(), robot, routing, RANDOM_TOL));
    out
}

/// Worst `max |a − fd|` and `max |a|` of one quantity over a case.
#[derive(Default)]
struct Worst {
    diff: f64,
    scale: f64,
}

impl Worst {
    fn add(&mut self, analytic: f64, fd: f64) {
        self.diff = self.diff.max((analytic - fd).abs());
        self.scale = self.scale.max(analytic.abs());
    }
    fn check(&self, case: &str, what: &str, tol: f64) {
        let rel = self.diff / self.scale;
        println!("{case}: {what}: worst |analytic − FD| / max |analytic| = {rel:.2e}");
        assert!(self.scale > 0.0, "{case}: {what} is zero everywhere: nothing checked");
        assert!(rel <= tol, "{case}: {what}: {rel:.2e} > {tol:.0e}");
    }
}

#[test]
fn segment_wrap_and_weight_derivatives_match_central_differences() {
    for (case, robot, routing, [j_tol, h_tol, theta_tol, w_tol, d_jt_tol, jt_tol]) in cases() {
        let model = FrictionModel::new(&routing).with_friction_coefficient(0.2).unwrap();
        let (dof, m) = (robot.dof(), routing.cable_count());
        let mut worst: [Worst; 6] = Default::default();
        let mut checked_angles = 0;
        for (n, q) in random_qs(&robot, 11, 8).iter().enumerate() {
            let slip = if n % 2 == 0 { Slip::Pull } else { Slip::Release };
            let at = evaluate(&robot, &routing, &model, q, slip);
            let d = &at.data;
            for i in 0..dof {
                let (mut plus, mut minus) = (q.clone(), q.clone());
                plus[i] += H;
                minus[i] -= H;
                let p = evaluate(&robot, &routing, &model, &plus, slip);
                let mm = evaluate(&robot, &routing, &model, &minus, slip);
                let fd = |a: f64, b: f64| (a - b) / (2.0 * H);
                for c in 0..m {
                    let segments = model.segment_count(c).unwrap();
                    let (lp, lm) =
                        (p.data.lengths(&model, c).unwrap(), mm.data.lengths(&model, c).unwrap());
                    let (wp, wm) =
                        (p.data.weights(&model, c).unwrap(), mm.data.weights(&model, c).unwrap());
                    let weights = d.weights(&model, c).unwrap();
                    // J̃ as the gradient of Σ_s w_s(q) ℓ_s at frozen weights.
                    let weighted =
                        |l: &[f64]| l.iter().zip(weights).skip(1).map(|(l, w)| l * w).sum::<f64>();
                    let jt = d.effective_jacobian().unwrap()[(c, i)];
                    worst[5].add(jt, fd(weighted(lp), weighted(lm)));
                    // ∂J̃_c/∂q_i = Σ_s (∂w_s/∂q_i J_s + w_s H_s[:, i]): the whole column, what a
                    // slip stiffness T_0 ∂J̃ᵀ/∂Q is made of.
                    let mut d_jt = vec![0.0; dof];
                    for s in 0..segments {
                        let j_s = d.segment_jacobian(&model, c, s).unwrap();
                        worst[0].add(j_s.get(i), fd(lp[s], lm[s]));
                        let dw = d.weight_gradient(&model, c, s).unwrap().get(i);
                        worst[3].add(dw, fd(wp[s], wm[s]));
                        for k in j_s.dofs.clone() {
                            d_jt[k] += dw * j_s.get(k);
                        }
                        // H_s's column i against the difference of J_s.
                        let Some((dofs, h)) =
                            model.segment_hessian(&routing, &at.routing_data, c, s).unwrap()
                        else {
                            continue;
                        };
                        if !dofs.contains(&i) {
                            continue;
                        }
                        let (jp, jm) = (
                            p.data.segment_jacobian(&model, c, s).unwrap(),
                            mm.data.segment_jacobian(&model, c, s).unwrap(),
                        );
                        for (r, k) in dofs.clone().enumerate() {
                            let h_ki = h[(r, i - dofs.start)];
                            worst[1].add(h_ki, fd(jp.get(k), jm.get(k)));
                            d_jt[k] += weights[s] * h_ki;
                        }
                    }
                    let (jt_p, jt_m) = (
                        p.data.effective_jacobian().unwrap(),
                        mm.data.effective_jacobian().unwrap(),
                    );
                    for k in 0..dof {
                        worst[4].add(d_jt[k], fd(jt_p[(c, k)], jt_m[(c, k)]));
                    }
                    let angles = d.wrap_angles(&model, c).unwrap();
                    let (ap, am) = (
                        p.data.wrap_angles(&model, c).unwrap(),
                        mm.data.wrap_angles(&model, c).unwrap(),
                    );
                    for k in 0..angles.len() {
                        // Away from the kink only: θ ≫ h |∇θ|.
                        if angles[k] > 1e-3 && angles[k] < 3.0 {
                            worst[2].add(
                                d.wrap_gradient(&model, c, k).unwrap().get(i),
                                fd(ap[k], am[k]),
                            );
                            checked_angles += 1;
                        }
                    }
                }
            }
        }
        assert!(checked_angles > 0, "{case}: no wrap angle away from 0");
        worst[0].check(&case, "J_s", j_tol);
        worst[1].check(&case, "H_s", h_tol);
        worst[2].check(&case, "∂θ/∂Q", theta_tol);
        worst[3].check(&case, "∂w/∂Q", w_tol);
        worst[4].check(&case, "∂J̃/∂Q", d_jt_tol);
        worst[5].check(&case, "J̃ = ∇ Σ w ℓ at frozen w", jt_tol);
    }
}

#[test]
fn segment_rows_sum_to_j_c_and_mu_zero_is_the_frictionless_jacobian_bit_for_bit() {
    let mut routings: Vec<(String, Robot, Routing)> = cases()
        .into_iter()
        .flat_map(|(name, robot, routing, _)| {
            let unbatched = routing.unbatched();
            [
                (name.clone(), robot.clone(), routing),
                (format!("{name} unbatched"), robot, unbatched),
            ]
        })
        .collect();
    routings.extend(cdhrm5::cases(20));
    for (case, robot, routing) in routings {
        let (dof, m) = (robot.dof(), routing.cable_count());
        let frictionless = FrictionModel::new(&routing);
        let rough = FrictionModel::new(&routing).with_friction_coefficient(0.3).unwrap();
        for q in random_qs(&robot, 5, 3) {
            for slip in [Slip::Pull, Slip::Release] {
                let at = evaluate(&robot, &routing, &frictionless, &q, slip);
                let j_c = at.routing_data.jacobian().unwrap();
                let j_t = at.data.effective_jacobian().unwrap();
                for c in 0..m {
                    assert!(at.data.weights(&frictionless, c).unwrap().iter().all(|&w| w == 1.0));
                    for s in 0..frictionless.segment_count(c).unwrap() {
                        let g = at.data.weight_gradient(&frictionless, c, s).unwrap();
                        assert!(g.values.iter().all(|&v| v == 0.0), "{case}: ∂w ≠ 0 at μ = 0");
                    }
                    for i in 0..dof {
                        assert_eq!(
                            j_t[(c, i)].to_bits(),
                            j_c[(c, i)].to_bits(),
                            "{case}: J̃[{c},{i}]"
                        );
                    }
                }
                // With friction, the unweighted sum Σ_s J_s is still J_c bit for bit.
                let at = evaluate(&robot, &routing, &rough, &q, slip);
                let j_c = at.routing_data.jacobian().unwrap();
                for c in 0..m {
                    let mut row = vec![0.0; dof];
                    for s in 0..rough.segment_count(c).unwrap() {
                        let j_s = at.data.segment_jacobian(&rough, c, s).unwrap();
                        for (k, v) in j_s.dofs.clone().zip(j_s.values) {
                            row[k] += v;
                        }
                    }
                    for i in 0..dof {
                        assert_eq!(
                            row[i].to_bits(),
                            j_c[(c, i)].to_bits(),
                            "{case}: Σ J_s [{c},{i}]"
                        );
                    }
                    // Segment 0 is the free length, with no row.
                    assert_eq!(
                        at.data.lengths(&rough, c).unwrap()[0],
                        routing.cables()[c].free_length
                    );
                    assert!(at.data.segment_jacobian(&rough, c, 0).unwrap().values.is_empty());
                }
            }
        }
    }
}

#[test]
fn a_straight_cdhrm5_has_no_wrap_and_pull_weights_fall_distally_elsewhere() {
    for model_kind in [PatternModel::Decoupled, PatternModel::Routed] {
        let (robot, routing) = cdhrm5::robot_and_routing(model_kind);
        let model = FrictionModel::new(&routing).with_friction_coefficient(0.2).unwrap();
        let at = evaluate(&robot, &routing, &model, &vec![0.0; robot.dof()], Slip::Pull);
        for c in 0..routing.cable_count() {
            let holes = routing.cables()[c].holes.len();
            let angles = at.data.wrap_angles(&model, c).unwrap();
            assert_eq!(angles.len(), holes - 1);
            // Every hole of a cable sits at the same angle on its disc and the entry is +z: the
            // cable runs straight along the arm, exactly.
            assert!(angles.iter().all(|&t| t == 0.0), "{model_kind:?} cable {c}: {angles:?}");
            assert!(at.data.kinked(&model, c).unwrap().iter().all(|&k| k));
            assert!(at.data.weights(&model, c).unwrap().iter().all(|&w| w == 1.0));
            for k in 0..holes - 1 {
                let g = at.data.wrap_gradient(&model, c, k).unwrap();
                assert!(g.values.iter().all(|&v| v == 0.0), "the kink's gradient is 0");
            }
        }
        // Bent within the limits (±π/6 per axis): every hole turns the cable, by less than a
        // radian, and each pull weight is the one before times e^{−μθ}.
        let mut rng = rng(9);
        let q = random_q(&robot, &mut rng);
        let at = evaluate(&robot, &routing, &model, &q, Slip::Pull);
        for c in 0..routing.cable_count() {
            let (angles, weights) =
                (at.data.wrap_angles(&model, c).unwrap(), at.data.weights(&model, c).unwrap());
            assert_eq!(weights[0], 1.0);
            for (k, &theta) in angles.iter().enumerate() {
                assert!(
                    theta > 1e-3 && theta < 1.0,
                    "{model_kind:?} cable {c} hole {k}: θ = {theta}"
                );
                let ratio = weights[k + 1] / weights[k];
                assert!((ratio - (-0.2 * theta).exp()).abs() <= 1e-15, "ratio {ratio}");
            }
        }
    }
}

// The ways the friction geometry gets each segment's `J_s` and direction. With the
// routing's Jacobian at hand (`Order::Jacobian` and above), a cable whose segments cross
// distinct DOFs reads `J_s` from `J_c`, and, when the routing keeps its segment directions
// (`keep_segment_directions`), every segment across joints takes its direction from the
// routing's (turned for a segment run distal to proximal); otherwise (`Order::Lengths`, or two
// segments of one cable across one DOF: the zigzag case) the routing's formula runs again per
// segment, from the holes. All must give the same rows and directions bit for bit, and
// everything computed from them too: a copy from the wrong row, column or segment, a segment
// turned the wrong way, or a stale row fails here.

fn geometry(
    robot: &Robot,
    routing: &Routing,
    model: &FrictionModel,
    q: &[f64],
    (order, keep_directions): (Order, bool),
) -> FrictionData {
    let mut rdata = RobotData::new(robot);
    let mut routing_data = RoutingData::new(routing);
    routing_data.keep_segment_directions(keep_directions);
    compute_cable_geometry(routing, robot, &mut rdata, &mut routing_data, q, order).unwrap();
    let mut data = FrictionData::new(model);
    compute_friction_geometry(model, routing, &routing_data, &mut data).unwrap();
    data
}

fn bits(values: &[f64]) -> Vec<u64> {
    values.iter().map(|v| v.to_bits()).collect()
}

#[test]
fn j_s_read_from_j_c_is_the_routing_formula_bit_for_bit() {
    for (case, robot, routing, _) in cases() {
        let model = FrictionModel::new(&routing).with_friction_coefficient(0.2).unwrap();
        for q in random_qs(&robot, 3, 7) {
            let formula = geometry(&robot, &routing, &model, &q, (Order::Lengths, true));
            for keep in [true, false] {
                let copied = geometry(&robot, &routing, &model, &q, (Order::Hessians, keep));
                for c in 0..model.cable_count() {
                    let h = model.segment_count(c).unwrap();
                    for s in 0..h {
                        let (a, b) = (
                            formula.segment_jacobian(&model, c, s).unwrap(),
                            copied.segment_jacobian(&model, c, s).unwrap(),
                        );
                        assert_eq!(a.dofs, b.dofs, "{case}: J_s dofs, cable {c} segment {s}");
                        assert_eq!(
                            bits(a.values),
                            bits(b.values),
                            "{case}: J_s, cable {c} segment {s}"
                        );
                    }
                    for k in 0..h - 1 {
                        let (a, b) = (
                            formula.wrap_gradient(&model, c, k).unwrap(),
                            copied.wrap_gradient(&model, c, k).unwrap(),
                        );
                        assert_eq!(
                            bits(a.values),
                            bits(b.values),
                            "{case}: ∂θ, cable {c} hole {k}"
                        );
                    }
                    let pairs = [
                        (formula.lengths(&model, c).unwrap(), copied.lengths(&model, c).unwrap()),
                        (
                            formula.wrap_angles(&model, c).unwrap(),
                            copied.wrap_angles(&model, c).unwrap(),
                        ),
                    ];
                    for (a, b) in pairs {
                        assert_eq!(bits(a), bits(b), "{case}: lengths or wrap angles, cable {c}");
                    }
                    let (a, b) = (
                        formula.directions(&model, c).unwrap(),
                        copied.directions(&model, c).unwrap(),
                    );
                    let (a, b) = (a.as_flattened(), b.as_flattened());
                    assert_eq!(bits(a), bits(b), "{case}: directions, cable {c}");
                }
            }
        }
    }
}

#[test]
fn the_cable_view_reads_the_rows_of_the_accessors() {
    for (case, robot, routing, _) in cases().into_iter().take(4) {
        let model = FrictionModel::new(&routing).with_friction_coefficient(0.2).unwrap();
        let q = random_qs(&robot, 1, 11).remove(0);
        let mut data = geometry(&robot, &routing, &model, &q, (Order::Hessians, true));
        let view = data.cable(&model, 0).unwrap();
        assert!(view.weights.is_none(), "{case}: weights before they are computed");
        compute_capstan_weights(&model, &mut data, Slip::Release).unwrap();
        for c in 0..model.cable_count() {
            let view = data.cable(&model, c).unwrap();
            let h = model.segment_count(c).unwrap();
            assert_eq!(view.len(), h, "{case}");
            assert_eq!(view.lengths, data.lengths(&model, c).unwrap(), "{case}");
            assert_eq!(view.weights.unwrap(), data.weights(&model, c).unwrap(), "{case}");
            assert_eq!(&view.wrap[..h - 1], data.wrap_angles(&model, c).unwrap(), "{case}");
            for s in 0..h {
                assert_eq!(view.jacobian(s), data.segment_jacobian(&model, c, s).unwrap());
                assert_eq!(view.routing_segment(s), model.routing_segment(c, s), "{case}");
                if s + 1 < h {
                    let row = data.wrap_gradient(&model, c, s).unwrap();
                    assert_eq!(view.wrap_gradient(s).unwrap(), row, "{case}");
                }
            }
            // Past the end: empty rows, no segment.
            assert!(view.jacobian(h).values.is_empty());
            assert!(view.wrap_gradient(h).unwrap().values.is_empty());
            assert_eq!(view.routing_segment(h), None);
        }
        assert!(data.cable(&model, model.cable_count()).is_err(), "{case}: no such cable");
    }
}

#[test]
fn the_angles_then_the_wrap_gradients_are_the_whole_geometry_bit_for_bit() {
    for (case, robot, routing, _) in cases() {
        let model = FrictionModel::new(&routing).with_friction_coefficient(0.2).unwrap();
        let qs = random_qs(&robot, 2, 17);
        let (mut rdata, mut routing_data) = (RobotData::new(&robot), RoutingData::new(&routing));
        let mut at = |q: &[f64], routing_data: &mut RoutingData| {
            compute_cable_geometry(&routing, &robot, &mut rdata, routing_data, q, Order::Hessians)
                .unwrap();
        };
        let mut split = FrictionData::new(&model);
        assert!(compute_wrap_gradients(&model, &mut split).is_err(), "{case}: before the angles");
        // The whole geometry at one pose, then the angles alone at another: the first pose's
        // gradients are no longer offered.
        at(&qs[0], &mut routing_data);
        compute_friction_geometry(&model, &routing, &routing_data, &mut split).unwrap();
        assert!(split.check_wrap_gradients().is_ok(), "{case}");
        at(&qs[1], &mut routing_data);
        let mut whole = FrictionData::new(&model);
        compute_friction_geometry(&model, &routing, &routing_data, &mut whole).unwrap();
        compute_friction_angles(&model, &routing, &routing_data, &mut split).unwrap();
        assert!(split.check_wrap_gradients().is_err(), "{case}: stale gradients offered");
        assert!(split.wrap_gradient(&model, 0, 0).is_err(), "{case}");
        assert!(split.cable(&model, 0).unwrap().wrap_gradient(0).is_err(), "{case}");
        assert!(split.segments(&model, 0).unwrap().all(|s| s.wrap_gradient.is_none()), "{case}");
        compute_capstan_weights(&model, &mut split, Slip::Pull).unwrap();
        compute_capstan_weights(&model, &mut whole, Slip::Pull).unwrap();
        assert!(split.weight_gradient(&model, 0, 1).is_err(), "{case}");
        for c in 0..model.cable_count() {
            let (a, b) = (&split, &whole);
            assert_eq!(bits(a.lengths(&model, c).unwrap()), bits(b.lengths(&model, c).unwrap()));
            assert_eq!(bits(a.weights(&model, c).unwrap()), bits(b.weights(&model, c).unwrap()));
            let angles = |d: &FrictionData| bits(d.wrap_angles(&model, c).unwrap());
            assert_eq!(angles(a), angles(b), "{case}: cable {c}");
            assert_eq!(a.kinked(&model, c).unwrap(), b.kinked(&model, c).unwrap(), "{case}");
            let directions = |d: &FrictionData| d.directions(&model, c).unwrap().concat();
            assert_eq!(bits(&directions(a)), bits(&directions(b)), "{case}: cable {c}");
            for s in 0..model.segment_count(c).unwrap() {
                let row = |d: &FrictionData| bits(d.segment_jacobian(&model, c, s).unwrap().values);
                assert_eq!(row(a), row(b), "{case}: cable {c}, segment {s}");
            }
        }
        // Then the gradients, from what the angles left: the whole geometry's, to the bit.
        compute_wrap_gradients(&model, &mut split).unwrap();
        let wrap_rows = whole.wrap_gradient(&model, 0, 0).unwrap().values.len();
        assert!(wrap_rows > 0, "{case}: a wrap row to compare");
        for c in 0..model.cable_count() {
            for k in 0..model.segment_count(c).unwrap() - 1 {
                let row = |d: &FrictionData| bits(d.wrap_gradient(&model, c, k).unwrap().values);
                assert_eq!(row(&split), row(&whole), "{case}: cable {c}, hole {k}");
                let weight =
                    |d: &FrictionData| bits(&d.weight_gradient(&model, c, k + 1).unwrap().values);
                assert_eq!(weight(&split), weight(&whole), "{case}: cable {c}, hole {k}");
            }
        }
    }
}
