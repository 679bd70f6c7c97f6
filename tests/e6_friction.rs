//! E6 (beyond the paper, #27): what friction at the holes must do to the paper's arm, checked
//! on the report's own numbers. The capstan law fixes how the tension reaching each joint
//! scales with μ and how pull and release mirror each other; the stick regimes must stiffen the
//! arm, hold only below their load limit, and show hysteresis after a pull or a release.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use sinew::paper::{self, E6Row};
use sinew::routing::Slip;
use sinew::stiffness::{FrictionRegime, History};
use sinew_testkit::cdhrm5;

fn rows() -> Vec<E6Row> {
    let dir = cdhrm5::dir();
    let robot = sinew::robot::load(&dir).unwrap();
    let routing = sinew::routing::load(&dir, &robot).unwrap();
    let routed =
        sinew::routing::load(dir.join(sinew::routing::ROUTED_ROUTING_FILE), &robot).unwrap();
    paper::e6(&robot, [("decoupled", &routing), ("routed", &routed)]).unwrap().rows
}

fn find<'a>(rows: &'a [E6Row], model: &str, mu: f64, regime: Option<FrictionRegime>) -> &'a E6Row {
    rows.iter().find(|r| r.model == model && r.mu == mu && r.regime == regime).unwrap()
}

const PULL: Option<FrictionRegime> = Some(FrictionRegime::Slip(Slip::Pull));
const RELEASE: Option<FrictionRegime> = Some(FrictionRegime::Slip(Slip::Release));

#[test]
fn the_tension_reaching_each_joint_follows_the_capstan_law() {
    let rows = rows();
    let mus: Vec<f64> = paper::E6_MU.into_iter().filter(|&m| m > 0.0).collect();
    for model in ["decoupled", "routed"] {
        // The wrap angles are the pose's, not μ's: ln(share)/μ is one number per joint.
        let first = &find(&rows, model, mus[0], PULL).reaching;
        for &mu in &mus {
            let pull = &find(&rows, model, mu, PULL).reaching;
            let release = &find(&rows, model, mu, RELEASE).reaching;
            for (j, ((p, r), p0)) in pull.iter().zip(release).zip(first).enumerate() {
                let angle = -p.ln() / mu;
                assert!(angle > 0.0, "{model} μ = {mu}: joint {}", j + 1);
                assert!((angle - (-p0.ln() / mus[0])).abs() <= 1e-9 * angle, "{model} {mu} {j}");
                // Release multiplies where pull divides: the same cable, e^(+μΘ).
                assert!((p * r - 1.0).abs() <= 1e-12, "{model} μ = {mu}: joint {}", j + 1);
            }
        }
    }
    // The routed cables pass every proximal disc: the distal joints receive less than any
    // joint of the decoupled model, and less the farther out they sit.
    let top = mus[mus.len() - 1];
    let decoupled = find(&rows, "decoupled", top, PULL);
    let routed = &find(&rows, "routed", top, PULL).reaching;
    assert!(routed.windows(2).all(|w| w[1] < w[0]), "{routed:?}");
    assert!(routed[routed.len() - 1] < 0.8 * decoupled.transmission);
}

#[test]
fn stick_stiffens_the_arm_only_below_its_load_limit() {
    let rows = rows();
    let mus: Vec<f64> = paper::E6_MU.into_iter().filter(|&m| m > 0.0).collect();
    let equal = Some(FrictionRegime::Stick(History::Equal));
    for model in ["decoupled", "routed"] {
        let frictionless = find(&rows, model, 0.0, None);
        let (k0, along0) = (frictionless.lambda_min.unwrap(), frictionless.along.unwrap());
        for &mu in &mus {
            // After equal tensions: every segment a spring of its own, far stiffer; no hole at
            // an edge, so ±u agree with the tangent and nothing slides below the limit.
            let e = find(&rows, model, mu, equal);
            assert!(e.lambda_min.unwrap() > 30.0 * k0, "{model} μ = {mu}");
            let [plus, minus] = e.directional.unwrap();
            assert!((plus - e.along.unwrap()).abs() <= 1e-9 * plus, "{model} μ = {mu}");
            assert!((minus - plus).abs() <= 1e-9 * plus, "{model} μ = {mu}");
            assert_eq!(e.sliding, Some([0, 0]), "{model} μ = {mu}");
            let [lp, lm] = e.stick_limit.unwrap();
            assert!(lp > 0.0 && lm > 0.0 && lp < 0.1 && lm < 0.1, "{model} μ = {mu}: {lp} {lm}");
            // The band grows with μ: e^(μθ) − 1 ≈ μθ, so the limit about doubles with μ.
            if mu < 0.15 {
                let [dp, _] = find(&rows, model, 2.0 * mu, equal).stick_limit.unwrap();
                assert!((dp / lp - 2.0).abs() < 0.1, "{model} μ = {mu}: {lp} → {dp}");
            }
            // After a pull or a release every hole is on an edge: no load is held in stick,
            // some holes slide either way, and the two signs differ (hysteresis), between the
            // frictionless arm and the stick tangent.
            for history in [History::Pull, History::Release] {
                let h = find(&rows, model, mu, Some(FrictionRegime::Stick(history)));
                assert_eq!(h.stick_limit, Some([0.0, 0.0]), "{model} μ = {mu} {history:?}");
                let [sp, sm] = h.sliding.unwrap();
                assert!(sp > 0 && sm > 0, "{model} μ = {mu} {history:?}");
                let [plus, minus] = h.directional.unwrap();
                assert!((plus - minus).abs() > 1e-4 * plus, "{model} μ = {mu} {history:?}");
                for d in [plus, minus] {
                    assert!(along0 < d && d < h.along.unwrap(), "{model} μ = {mu} {history:?}");
                }
            }
        }
    }
}

/// The planner's stick optimum along the load: certified, within the frictionless plan's total
/// tension, far above the frictionless optimum (K_stick ⪰ K after equal tensions), and after
/// equal tensions the same for every μ (μ only sets the bands' widths, not K_stick).
#[test]
fn the_stick_plans_beat_the_frictionless_plan_within_its_total_tension() {
    let dir = cdhrm5::dir();
    let robot = sinew::robot::load(&dir).unwrap();
    let routing = sinew::routing::load(&dir, &robot).unwrap();
    let routed =
        sinew::routing::load(dir.join(sinew::routing::ROUTED_ROUTING_FILE), &robot).unwrap();
    let plans = paper::e6(&robot, [("decoupled", &routing), ("routed", &routed)]).unwrap().plans;
    assert_eq!(plans.len(), 2 * 3 * 2);
    for p in &plans {
        let case = format!("{} μ = {} {:?}", p.model, p.mu, p.history);
        assert!(p.gap >= 0.0 && p.gap <= 2e-6 * p.stick, "{case}: gap {}", p.gap);
        assert!(p.total <= p.budget * (1.0 + 1e-9), "{case}: {} > {}", p.total, p.budget);
        assert!(p.stick > 10.0 * p.frictionless, "{case}: {} vs {}", p.stick, p.frictionless);
        if p.history == History::Equal {
            let first = plans.iter().find(|q| q.model == p.model && q.history == History::Equal);
            let first = first.unwrap().stick;
            assert!((p.stick - first).abs() <= 1e-6 * first, "{case}: {} vs {first}", p.stick);
        }
    }
}
