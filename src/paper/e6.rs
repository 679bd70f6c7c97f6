//! E6 (beyond the paper, spec §9): friction at the holes on the paper's arm at E4's pose and
//! load, decoupled and routed, for μ in [`E6_MU`]: the tension reaching the anchors, the dead
//! band, `λ_min(K_fd)` and the stiffness along the load in every regime against the
//! frictionless arm, the directional stiffness along ±(the load) after each history, the
//! stick load limit along it, and the planner's stick-regime optimum against the frictionless
//! plan at the same total tension.

use std::fmt::Write as _;

use nalgebra::{Matrix3, Vector3, Vector6};

use crate::planner::{Objective, PlanSettings, Planner, PlannerData, Requirements, StickPlanData};
use crate::robot::Robot;
use crate::routing::{FrictionModel, Routing, Slip, compute_wrap_gradients};
use crate::statics::TensionChoice;
use crate::stiffness::{
    ArmStiffness, ArmStiffnessData, EndOutcome, FrictionArmData, FrictionRegime, History,
    directional_response, stick_load_limits,
};

use super::experiments::{E4_F0, E4_Q, E6_LEVEL, E6_MU};
use super::fixed;

/// E6's report file.
pub const E6_FILE: &str = "e6_friction.md";
/// E6's figure, `λ_min(K_fd)` against μ (line plots: SVG).
pub const FIG_E6_FILE: &str = "fig_e6_friction.svg";

/// One row of E6: a model, μ, a regime and its numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct E6Row {
    /// `decoupled` or `routed`.
    pub model: String,
    /// μ at every hole.
    pub mu: f64,
    /// The regime (`None`: the frictionless arm).
    pub regime: Option<FrictionRegime>,
    /// Σ of the actuator tensions, N.
    pub total: f64,
    /// The ratio of anchor to actuator tension farthest from 1 over the cables (pull: below 1,
    /// release: above).
    pub transmission: f64,
    /// Joint by joint, the ratio of anchor to actuator tension farthest from 1 over the cables
    /// anchored there: the share of the actuator's tension that reaches the joint (empty:
    /// frictionless).
    pub reaching: Vec<f64>,
    /// The widest dead band over the cables, N.
    pub dead_band: f64,
    /// `λ_min(K_fd)` (its symmetric part), N/m; `None` when unstable or rank-deficient.
    pub lambda_min: Option<f64>,
    /// The stiffness along the load's unit force `u` with rotations free, `1/(uᵀ C_x u)`, N/m
    /// (the directional response's measure); `None` when unstable.
    pub along: Option<f64>,
    /// Stick only: the directional stiffness along `+u` and `−u`, N/m.
    pub directional: Option<[f64; 2]>,
    /// Stick only: how many holes slide along `+u` and `−u`.
    pub sliding: Option<[usize; 2]>,
    /// Stick only: the stick load limit along `+u` and `−u`, N.
    pub stick_limit: Option<[f64; 2]>,
}

/// One plan of E6: the stiffness along the load, planned in the stick regime after a history
/// with the frictionless plan's total tension as its budget.
#[derive(Debug, Clone, PartialEq)]
pub struct E6Plan {
    /// `decoupled` or `routed`.
    pub model: String,
    /// μ at every hole.
    pub mu: f64,
    /// The history the stick regime keeps.
    pub history: History,
    /// The frictionless plan's optimum `uᵀK_fd u`, N/m.
    pub frictionless: f64,
    /// Its total tension, N: the stick plan's budget.
    pub budget: f64,
    /// The stick plan's optimum, N/m.
    pub stick: f64,
    /// Its certified gap, N/m.
    pub gap: f64,
    /// Its total tension, N.
    pub total: f64,
}

/// E6: every row, both models.
#[derive(Debug, Clone, PartialEq)]
pub struct E6 {
    /// Model by model: the frictionless rows, then μ by μ the regimes.
    pub rows: Vec<E6Row>,
    /// Model by model, μ by μ: the stick plans after equal tensions and after a pull.
    pub plans: Vec<E6Plan>,
}

/// The regimes of E6, in its order.
pub const E6_REGIMES: [FrictionRegime; 5] = [
    FrictionRegime::Slip(Slip::Pull),
    FrictionRegime::Slip(Slip::Release),
    FrictionRegime::Stick(History::Pull),
    FrictionRegime::Stick(History::Release),
    FrictionRegime::Stick(History::Equal),
];

/// A regime's name in the report.
pub fn regime_label(regime: Option<FrictionRegime>) -> &'static str {
    match regime {
        None => "frictionless",
        Some(FrictionRegime::Slip(Slip::Pull)) => "slip, pull",
        Some(FrictionRegime::Slip(Slip::Release)) => "slip, release",
        Some(FrictionRegime::Stick(History::Pull)) => "stick after pull",
        Some(FrictionRegime::Stick(History::Release)) => "stick after release",
        Some(FrictionRegime::Stick(History::Equal)) => "stick after equal",
    }
}

/// Of two ratios, the one farther from 1.
fn farther(a: f64, b: f64) -> f64 {
    if (b - 1.0).abs() > (a - 1.0).abs() { b } else { a }
}

/// `λ_min` of `K_fd`'s symmetric part.
fn lambda_min(k_fd: &Matrix3<f64>) -> f64 {
    (0.5 * (k_fd + k_fd.transpose())).symmetric_eigenvalues().min()
}

/// `1/(uᵀ C_x u)` for a unit force `u`.
fn along(c_x: faer::MatRef<'_, f64>, u: &Vector3<f64>) -> f64 {
    let mut c = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            c += u[i] * c_x[(i, j)] * u[j];
        }
    }
    1.0 / c
}

/// Run E6 on `robot` with its `(name, routing)` pairs.
///
/// # Errors
/// A routing the friction model cannot take, or a failed evaluation (unstable and
/// rank-deficient are rows).
pub fn e6(robot: &Robot, routings: [(&str, &Routing); 2]) -> Result<E6, crate::Error> {
    let f0 = Vector6::from(E4_F0);
    let u3 = Vector3::new(E4_F0[0], E4_F0[1], E4_F0[2]).normalize();
    let u = Vector6::new(u3[0], u3[1], u3[2], 0.0, 0.0, 0.0);
    let levels = [E6_LEVEL; 5];
    let mut rows = Vec::new();
    let mut plans = Vec::new();
    for (name, routing) in routings {
        let arm = ArmStiffness::new(robot, routing)?;
        plans.extend(stick_plans(name, &arm, routing)?);
        let mut data = ArmStiffnessData::new(&arm);
        let choice = TensionChoice::Levels(&levels);
        arm.evaluate_joints(&mut data, &E4_Q, &f0, choice)?;
        let outcome = arm.solve_end(&mut data)?;
        let k = matches!(outcome, EndOutcome::Stiff).then(|| lambda_min(&data.k_fd()));
        let stable = !matches!(outcome, EndOutcome::Unstable { .. });
        rows.push(E6Row {
            model: name.to_owned(),
            mu: 0.0,
            regime: None,
            total: data.tensions().iter().sum(),
            transmission: 1.0,
            reaching: Vec::new(),
            dead_band: 0.0,
            lambda_min: k,
            along: stable.then(|| along(data.compliance(), &u3)),
            directional: None,
            sliding: None,
            stick_limit: None,
        });
        for &mu in E6_MU.iter().filter(|&&mu| mu > 0.0) {
            let model = FrictionModel::new(routing).with_friction_coefficient(mu)?;
            let mut out = FrictionArmData::new(&arm, &model);
            for regime in E6_REGIMES {
                let outcome = arm.evaluate_with_friction(
                    &mut data,
                    &mut out,
                    (&model, regime),
                    &E4_Q,
                    &f0,
                    choice,
                )?;
                let k = matches!(outcome, EndOutcome::Stiff).then(|| lambda_min(&out.end.k_fd()));
                let stable = !matches!(outcome, EndOutcome::Unstable { .. });
                let c = stable.then(|| along(out.end.compliance(), &u3));
                let (mut directional, mut sliding, mut stick_limit) = (None, None, None);
                if let (FrictionRegime::Stick(history), true) = (regime, stable) {
                    let k_q = out.stiffness.stiffness()?.to_owned();
                    let k_w = data.k_w().to_owned();
                    let j_x = data.j_x().to_owned();
                    let increment = (k_q.as_ref(), k_w.as_ref(), j_x.as_ref());
                    compute_wrap_gradients(&model, &mut out.friction)?;
                    let (f, t) = (&out.friction, &out.actuator);
                    let [plus, minus] =
                        directional_response(&model, routing, f, history, t, increment, &u)?;
                    directional = Some([plus.stiffness, minus.stiffness]);
                    sliding = Some([plus.sliding.len(), minus.sliding.len()]);
                    let limits =
                        stick_load_limits(&model, routing, f, history, t, increment, &[u, -u])?;
                    stick_limit = Some([limits[0].magnitude, limits[1].magnitude]);
                }
                let mut reaching = vec![1.0; robot.joint_count()];
                for ((s, t), cable) in out.segments.iter().zip(&out.actuator).zip(routing.cables())
                {
                    let ratio = s.last().copied().unwrap_or(*t) / t;
                    if let Some(r) = reaching.get_mut(cable.joint) {
                        *r = farther(*r, ratio);
                    }
                }
                let transmission = reaching.iter().copied().fold(1.0, farther);
                rows.push(E6Row {
                    model: name.to_owned(),
                    mu,
                    regime: Some(regime),
                    total: out.actuator.iter().sum(),
                    transmission,
                    reaching,
                    dead_band: out.dead_band.iter().map(|b| b[1] - b[0]).fold(0.0, f64::max),
                    lambda_min: k,
                    along: c,
                    directional,
                    sliding,
                    stick_limit,
                });
            }
        }
    }
    Ok(E6 { rows, plans })
}

/// The stiffness along E4's load, planned without friction, then in the stick regime after
/// equal tensions and after a pull for each μ > 0 with the frictionless plan's total as budget.
fn stick_plans(
    name: &str,
    arm: &ArmStiffness,
    routing: &Routing,
) -> Result<Vec<E6Plan>, crate::Error> {
    let f0 = Vector6::from(E4_F0);
    let u = Vector3::new(E4_F0[0], E4_F0[1], E4_F0[2]).normalize();
    let objective = Objective::StiffnessAlong(u);
    let planner = Planner::new(arm.clone());
    let mut data = PlannerData::new(&planner);
    let settings = PlanSettings::default();
    let free =
        planner.plan(&mut data, &E4_Q, &f0, objective, &Requirements::default(), &settings)?;
    let requirements = Requirements { budget: Some(free.total_tension), ..Requirements::default() };
    let mut out = Vec::new();
    for &mu in E6_MU.iter().filter(|&&mu| mu > 0.0) {
        let model = FrictionModel::new(routing).with_friction_coefficient(mu)?;
        let mut stick = StickPlanData::new(&planner, &model);
        for history in [History::Equal, History::Pull] {
            let plan = planner.plan_in_stick(
                &mut data,
                &mut stick,
                (&model, history),
                &E4_Q,
                &f0,
                objective,
                &requirements,
                &settings,
            )?;
            out.push(E6Plan {
                model: name.to_owned(),
                mu,
                history,
                frictionless: free.value,
                budget: free.total_tension,
                stick: plan.value,
                gap: plan.gap,
                total: plan.total_tension,
            });
        }
    }
    Ok(out)
}

/// E6 as a markdown table, one row per model, μ and regime.
pub fn render_e6(e6: &E6) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| model | μ | regime | Σ T₀ (N) | anchor/actuator farthest from 1 | widest dead band (N) | λ_min(K_fd) (N/m) | along the load, 1/(uᵀC_x u) (N/m) | directional +u / −u (N/m) | holes sliding +u / −u | stick load limit +u / −u (N) |"
    );
    let _ = writeln!(s, "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    let opt = |x: Option<f64>, d: usize| x.map_or_else(|| "unstable".to_owned(), |x| fixed(x, d));
    for r in &e6.rows {
        let pair = |x: Option<[f64; 2]>, d: usize| {
            x.map_or_else(|| "—".to_owned(), |[a, b]| format!("{} / {}", fixed(a, d), fixed(b, d)))
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.model,
            fixed(r.mu, 2),
            regime_label(r.regime),
            fixed(r.total, 1),
            fixed(r.transmission, 4),
            fixed(r.dead_band, 2),
            opt(r.lambda_min, 3),
            opt(r.along, 3),
            pair(r.directional, 3),
            r.sliding.map_or_else(|| "—".to_owned(), |[a, b]| format!("{a} / {b}")),
            pair(r.stick_limit, 4),
        );
    }
    let _ = writeln!(
        s,
        "\nThe planner's stiffness along the load (uᵀK_fd u) in the stick regime, with the frictionless plan's total tension as its budget:\n"
    );
    let _ = writeln!(
        s,
        "| model | μ | regime | frictionless plan (N/m) | budget = its Σ f (N) | stick plan (N/m) | gap (N/m) | its Σ f (N) | stick / frictionless |"
    );
    let _ = writeln!(s, "| --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    for p in &e6.plans {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            p.model,
            fixed(p.mu, 2),
            regime_label(Some(FrictionRegime::Stick(p.history))),
            fixed(p.frictionless, 3),
            fixed(p.budget, 1),
            fixed(p.stick, 1),
            fixed(p.gap, 3),
            fixed(p.total, 1),
            fixed(p.stick / p.frictionless, 2),
        );
    }
    let joints = e6.rows.iter().map(|r| r.reaching.len()).max().unwrap_or(0);
    let _ = writeln!(
        s,
        "\nThe tension reaching each joint, as a share of the actuator's (the ratio farthest from 1 over the joint's cables), in the slip regimes:\n"
    );
    let heads: String = (1..=joints).map(|i| format!(" joint {i} |")).collect();
    let _ = writeln!(s, "| model | μ | regime |{heads}");
    let _ = writeln!(s, "| --- | --- | --- |{}", " --- |".repeat(joints));
    for r in e6.rows.iter().filter(|r| matches!(r.regime, Some(FrictionRegime::Slip(_)))) {
        let cells: String = r.reaching.iter().map(|x| format!(" {} |", fixed(*x, 4))).collect();
        let _ =
            writeln!(s, "| {} | {} | {} |{cells}", r.model, fixed(r.mu, 2), regime_label(r.regime));
    }
    s
}

/// E6's section of the report's `README.md`: why μ ranges so, which tensions, what the table
/// shows and what is not built yet.
pub fn e6_section(e6: &E6) -> String {
    let mu: Vec<String> = E6_MU.iter().map(|m| fixed(*m, 2)).collect();
    let mut r = String::new();
    let _ = writeln!(
        r,
        "## E6 (beyond the paper): friction at the holes
"
    );
    let _ = writeln!(
        r,
        "The paper sets friction aside (§II.A); spec §9 models it by the capstan law at every hole. E4's pose and load, every joint at tension level {E6_LEVEL}, μ ∈ {{{}}} at every hole. The range: PTFE on steel is among the lowest-friction pairs in engineering handbooks (about 0.05–0.1), so a steel or polymer cable through PTFE-lined holes sits at 0.05–0.1; a steel cable on bare aluminium discs, lubricated, near 0.2 (dry metal pairs run higher, and would widen the dead band further).\n",
        mu.join(", ")
    );
    let _ = writeln!(
        r,
        "The tensions. Slip, pull (every hole sliding toward the actuator) and release (away from it): the segment tensions fall (rise) by e^(∓μθ) at each hole, and the levels are the paper's closed form on the effective Jacobian J̃ = Σ_s w_s J_s, each joint's interval running between the actuator tensions that keep every segment within [20, 600] N. Stick after a pull or a release keeps the tensions that history left; stick after equal keeps equal tensions along each cable, the frictionless arm's.\n"
    );
    let top = E6_MU[E6_MU.len() - 1];
    let find = |model: &str, mu: f64, regime: Option<FrictionRegime>| {
        e6.rows.iter().find(|r| r.model == model && r.mu == mu && r.regime == regime)
    };
    let pull = Some(FrictionRegime::Slip(Slip::Pull));
    let share = |x: f64| format!("{} %", fixed(100.0 * x, 0));
    let worst = |model: &str| find(model, top, pull).map_or(f64::NAN, |r| r.transmission);
    let last = find("routed", top, pull).and_then(|r| r.reaching.last().copied());
    let _ = writeln!(
        r,
        "**The decoupled model hides most of the friction.** Its cables run along the central channel and turn only at their own joint, so each wraps one bend: at μ = {} the worst joint still receives {} of its actuator's tension. The routed model's cables pass every proximal disc, and the distal joints receive much less (joint {}: {}). Both are shown; a real arm's cables are routed.\n",
        fixed(top, 2),
        share(worst("decoupled")),
        e6.rows.iter().map(|r| r.reaching.len()).max().unwrap_or(0),
        share(last.unwrap_or(f64::NAN)),
    );
    let value = |model: &str, regime, pick: fn(&E6Row) -> Option<f64>| {
        find(model, top, regime).and_then(pick).map_or_else(|| "—".to_owned(), |x| fixed(x, 1))
    };
    let equal = Some(FrictionRegime::Stick(History::Equal));
    let after_pull = Some(FrictionRegime::Stick(History::Pull));
    let frictionless = |model: &str, pick: fn(&E6Row) -> Option<f64>| {
        find(model, 0.0, None).and_then(pick).map_or_else(|| "—".to_owned(), |x| fixed(x, 1))
    };
    let _ = writeln!(
        r,
        "**Which stiffness applies when.** In stick every segment is a spring of its own (EA/ℓ_s), so the tangent K_stick is far stiffer than the frictionless arm (λ_min {} against {} N/m decoupled, {} against {} routed, after equal tensions). It holds only below the stick load limit: a few hundredths of a newton after equal tensions, and zero after a pull or a release, where every hole already sits on its band's edge. A load increment after a pull or a release makes the edge holes slide: the directional stiffness along ±u (u the load's direction) is what a loaded arm shows ({} / {} N/m along +u after a pull at μ = {}, decoupled / routed, against {} / {} frictionless along the load), and it differs between +u and −u (hysteresis). The slip K is not symmetric; its λ_min is that of its symmetric part. File: `{E6_FILE}`.\n",
        value("decoupled", equal, |r| r.lambda_min),
        frictionless("decoupled", |r| r.lambda_min),
        value("routed", equal, |r| r.lambda_min),
        frictionless("routed", |r| r.lambda_min),
        value("decoupled", after_pull, |r| r.directional.map(|d| d[0])),
        value("routed", after_pull, |r| r.directional.map(|d| d[0])),
        fixed(top, 2),
        frictionless("decoupled", |r| r.along),
        frictionless("routed", |r| r.along),
    );
    let _ = writeln!(r, "{}", render_e6(e6));
    let _ = writeln!(
        r,
        "λ_min(K_fd) against μ, one line per regime, slip and stick apart (they differ by two orders of magnitude):\n\n![E6]({FIG_E6_FILE})\n"
    );
    let ratio = |model: &str| {
        let ratios: Vec<f64> = e6
            .plans
            .iter()
            .filter(|p| p.model == model)
            .map(|p| p.stick / p.frictionless)
            .collect();
        let lo = ratios.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = ratios.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let (lo, hi) = (fixed(lo, 1), fixed(hi, 1));
        if lo == hi { format!("{lo}×") } else { format!("{lo}–{hi}×") }
    };
    let _ = writeln!(
        r,
        "**Planning in stick.** K_stick + K_W is affine in the actuator tensions and symmetric, so the planner certifies the stick regime's optimum as it does the frictionless one (`sinew plan --friction`). At the frictionless plan's total tension, the stiffest tensions along the load give {} (decoupled) and {} (routed) the frictionless optimum: the plan for an arm that holds its tensions is a different plan. A slip regime is not planned: its K is not symmetric and the end stiffness is not concave in the tensions.",
        ratio("decoupled"),
        ratio("routed"),
    );
    r
}
