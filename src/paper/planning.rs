//! E5 (beyond the paper): planned tensions at E4's pose. The least total tension that keeps the
//! arm stable, the stiffest distributions at the total tension of the paper's case (d), beside
//! the paper's cases (a)–(d), and the trade-off between the tension budget and the best
//! `λ_min(K_fd)`, in both models (`sinew-planner`).

use nalgebra::{Vector3, Vector6};

use crate::planner::{Objective, Plan, PlanSettings, Planner, PlannerData, Requirements};
use crate::robot::Robot;
use crate::routing::Routing;
use crate::stiffness::{ArmStiffness, ArmStiffnessData, StiffnessError};

use super::experiments::{E4_CASES, E4_F0, E4_PAPER_BASELINE, E4_Q, E5_MARGIN, E5_TRADEOFF_POINTS};
use super::fixed;
use crate::statics::TensionChoice;

/// One distribution of E5: how it was chosen and what it gives.
#[derive(Debug, Clone, PartialEq)]
pub struct E5Row {
    /// How the tensions were chosen.
    pub name: String,
    /// `Σ f`, N.
    pub total: f64,
    /// `λ_min(K_q + K_W)`, N m/rad.
    pub margin: f64,
    /// `K_fd` along the load (y), N/m; `None` where unstable.
    pub k_load: Option<f64>,
    /// `λ_min(K_fd)`, N/m; `None` where unstable.
    pub k_min: Option<f64>,
    /// The planner's certified gap (in the objective's unit), `None` for the paper's cases.
    pub gap: Option<f64>,
    /// The tension levels.
    pub levels: Option<Vec<f64>>,
}

/// E5 in one model.
#[derive(Debug, Clone, PartialEq)]
pub struct E5 {
    /// `decoupled` or `routed`.
    pub model: String,
    /// The rows: the paper's cases (a)–(d), then the planned ones.
    pub rows: Vec<E5Row>,
    /// `(budget N, best λ_min(K_fd) N/m, its gap)` from the least stable total to the most
    /// tension.
    pub tradeoff: Vec<(f64, f64, f64)>,
}

/// E5 on `routing` (the model's name in `model`).
///
/// # Errors
/// Files and routings the planner cannot take; an infeasible or unreachable plan.
pub fn e5(robot: &Robot, routing: &Routing, model: &str) -> Result<E5, crate::Error> {
    let arm = ArmStiffness::new(robot, routing)?;
    let mut data = ArmStiffnessData::new(&arm);
    let f0 = Vector6::from_row_slice(&E4_F0);
    let load = Vector3::new(f0[0], f0[1], f0[2]).normalize();
    let mut rows = Vec::new();
    // One pose stage; a tension stage and the end stage per case.
    arm.set_pose(&mut data, &E4_Q, &f0)?;
    for (name, raised) in E4_CASES {
        let levels = raised.map(|r| if r { 1.0 } else { E4_PAPER_BASELINE });
        arm.set_tensions(&mut data, TensionChoice::Levels(&levels))?;
        let total = data.tensions().iter().sum();
        arm.solve_end(&mut data)?;
        let outcome = data
            .outcome()
            .ok_or(StiffnessError::StageMissing { needs: "solve_end", missing: "end stage" })?;
        let margin = outcome.margin()?;
        let (k_load, k_min) = match outcome.k_fd() {
            Some(k) if margin > 0.0 => {
                (Some(load.dot(&(k * load))), Some(k.symmetric_eigen().eigenvalues.min()))
            }
            _ => (None, None),
        };
        rows.push(E5Row {
            name: format!("paper {name}"),
            total,
            margin,
            k_load,
            k_min,
            gap: None,
            levels: Some(levels.to_vec()),
        });
    }
    let case_d = rows.last().map_or(0.0, |r| r.total);
    let planner = Planner::new(arm);
    let mut pdata = PlannerData::new(&planner);
    let settings = PlanSettings::default();
    let stable = Requirements { margin: E5_MARGIN, ..Requirements::default() };
    let at_d = Requirements { budget: Some(case_d), ..stable.clone() };
    let mut plan = |objective, requirements: &Requirements| {
        planner.plan(&mut pdata, &E4_Q, &f0, objective, requirements, &settings)
    };
    let planned = [
        (
            format!("least total tension, margin ≥ {E5_MARGIN} N m/rad"),
            plan(Objective::LeastTension, &stable)?,
        ),
        (
            "stiffest along the load, Σf ≤ Σf of (d)".to_owned(),
            plan(Objective::StiffnessAlong(load), &at_d)?,
        ),
        (
            "stiffest softest direction, Σf ≤ Σf of (d)".to_owned(),
            plan(Objective::MinStiffness, &at_d)?,
        ),
    ];
    let least_stable = planned[0].1.total_tension;
    for (name, p) in planned {
        rows.push(row(name, &p, &load));
    }
    // The most tension: every joint at level 1 where the levels apply, else the limits' top.
    let most = routing.cable_limits().iter().map(|l| l[1]).sum::<f64>();
    let mut tradeoff = Vec::new();
    for i in 0..E5_TRADEOFF_POINTS {
        let budget =
            least_stable + (most - least_stable) * i as f64 / (E5_TRADEOFF_POINTS - 1) as f64;
        let requirements = Requirements { budget: Some(budget), ..stable.clone() };
        let p = plan(Objective::MinStiffness, &requirements)?;
        tradeoff.push((budget, p.value, p.gap));
    }
    Ok(E5 { model: model.to_owned(), rows, tradeoff })
}

fn row(name: String, plan: &Plan, load: &Vector3<f64>) -> E5Row {
    let k = plan.k_fd;
    E5Row {
        name,
        total: plan.total_tension,
        margin: plan.min_eigenvalue,
        k_load: k.map(|k| load.dot(&(k * load))),
        k_min: k.map(|k| k.symmetric_eigen().eigenvalues.min()),
        gap: Some(plan.gap),
        levels: plan.levels.clone(),
    }
}

/// E5's table in one model (markdown, fixed precision).
pub fn render_e5(e5: &E5) -> String {
    let mut s = String::new();
    s.push_str("| tensions | Σf (N) | stability margin (N m/rad) | K_fd along the load (N/m) | λ_min(K_fd) (N/m) | certified gap | levels |\n");
    s.push_str("| --- | --- | --- | --- | --- | --- | --- |\n");
    let opt = |v: Option<f64>, d: usize| v.map_or_else(|| "unstable".to_owned(), |x| fixed(x, d));
    for r in &e5.rows {
        let levels = r.levels.as_ref().map_or_else(String::new, |l| {
            format!("[{}]", l.iter().map(|x| fixed(*x, 3)).collect::<Vec<_>>().join(", "))
        });
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} |\n",
            r.name,
            fixed(r.total, 1),
            fixed(r.margin, 3),
            opt(r.k_load, 2),
            opt(r.k_min, 3),
            r.gap.map_or_else(|| "—".to_owned(), |g| format!("{g:.0e}")),
            levels
        ));
    }
    s.push_str(&format!(
        "\nTrade-off: the best λ_min(K_fd) for a budget on Σf, margin ≥ {E5_MARGIN} N m/rad:\n\n| budget Σf (N) | best λ_min(K_fd) (N/m) |\n| --- | --- |\n"
    ));
    for (b, v, _) in &e5.tradeoff {
        s.push_str(&format!("| {} | {} |\n", fixed(*b, 1), fixed(*v, 3)));
    }
    s
}

/// The trade-off of every model as CSV: `model,budget_n,best_lambda_min_n_per_m,gap`.
pub fn e5_csv(runs: &[&E5]) -> String {
    let mut s = String::from("model,budget_n,best_lambda_min_n_per_m\n");
    for e in runs {
        for (b, v, _) in &e.tradeoff {
            s.push_str(&format!("{},{},{}\n", e.model, fixed(*b, 3), fixed(*v, 4)));
        }
    }
    s
}
