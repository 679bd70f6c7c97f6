//! `sinew plan`: the tensions that optimise the end stiffness, certified by a gap.

use nalgebra::{Matrix3, Vector3, Vector6};
use serde::Serialize;
use sinew::planner::{
    DEFAULT_GAP, DEFAULT_MARGIN, Objective, PlanSettings, Planner, PlannerData, Requirements,
    StickPlanData,
};
use sinew::routing::{FrictionModel, Routing};
use sinew::stiffness::{ArmStiffness, FrictionRegime, History};

use crate::arm_friction::{history_name, requested};

use crate::cli::{PlanArgs, PlanObjective, PlanOptions};
use crate::error::{CliError, library_error};
use crate::input::{load, numbers_n, one_number, pose, wrench};
use crate::output::{Fmt, Rows, Table, cartesian_labels, emit, matrix, na_rows, print_json};

/// The JSON document of `sinew plan`.
#[derive(Debug, Serialize)]
struct PlanOut {
    command: &'static str,
    robot: String,
    routing_file: String,
    model: &'static str,
    gravity: [f64; 3],
    q: Vec<f64>,
    wrench: Vec<f64>,
    objective: &'static str,
    /// The unit direction of stiffness-along / compliance-along.
    direction: Option<[f64; 3]>,
    k_min: Option<f64>,
    k_des: Option<Rows>,
    margin: f64,
    budget: Option<f64>,
    /// `[[joint (0-based), N], …]`.
    joint_budgets: Vec<(usize, f64)>,
    /// `[[joint (0-based), level], …]`.
    fixed_levels: Vec<(usize, f64)>,
    /// The relative gap asked for.
    tolerance: f64,
    value: f64,
    gap: f64,
    lambda: Vec<f64>,
    levels: Option<Vec<f64>>,
    cables: Vec<String>,
    tensions: Vec<f64>,
    total_tension: f64,
    k_fd: Option<Rows>,
    c_x: Rows,
    min_eigenvalue: f64,
    stable: bool,
    iterations: usize,
    /// The stick regime's model and history, when the plan has friction (absent without, so
    /// that a frictionless plan's document is unchanged).
    #[serde(skip_serializing_if = "Option::is_none")]
    friction: Option<PlanFriction>,
}

/// `friction` of a plan in the stick regime.
#[derive(Debug, Serialize)]
struct PlanFriction {
    /// μ of each cable.
    mu: Vec<f64>,
    regime: &'static str,
    history: &'static str,
}

/// The stick regime's plan, when friction is asked for (`None`: the frictionless plan).
///
/// # Errors
/// A slip regime (not planned: its stiffness is not symmetric, the end stiffness not concave
/// in the tensions); those of [`requested`].
fn stick_requested(
    args: &PlanArgs,
    routing: &Routing,
) -> Result<Option<(FrictionModel, History)>, CliError> {
    match requested(args.friction.asked(), routing)? {
        None => Ok(None),
        Some((_, FrictionRegime::Slip(_))) => Err(CliError::input(
            "--regime pull|release: a slip regime is not planned (its K_q is not symmetric and the end stiffness is not concave in the tensions); plan in --regime stick",
        )),
        Some((model, FrictionRegime::Stick(history))) => Ok(Some((model, history))),
    }
}

/// `J:X` pairs, joints numbered from 1 on the command line, 0-based in the library.
fn joint_pairs(
    option: &str,
    texts: &[String],
    expected: &str,
) -> Result<Vec<(usize, f64)>, CliError> {
    texts
        .iter()
        .map(|text| {
            let parsed = text.split_once(':').and_then(|(j, x)| {
                Some((j.trim().parse::<usize>().ok()?, x.trim().parse::<f64>().ok()?))
            });
            match parsed {
                Some((j, x)) if j >= 1 => Ok((j - 1, x)),
                _ => Err(CliError::input(format!("{option} {text}: expected {expected}"))),
            }
        })
        .collect()
}

/// What a plan is asked: the objective and its direction, the requirements, the gap.
#[derive(Debug)]
pub struct PlanRequest {
    /// The objective (with its unit direction).
    pub objective: Objective,
    /// `--direction`, normalised.
    pub direction: Option<Vector3<f64>>,
    /// Margin, budgets, floors, held levels.
    pub requirements: Requirements,
    /// `--gap`.
    pub tolerance: f64,
    /// The settings with that gap.
    pub settings: PlanSettings,
}

/// The plan `objective` and `options` ask for, every number checked as `sinew plan` does.
///
/// `flag` is the option that named the objective (`--objective`, or `--plan` for the export).
pub fn request(
    flag: &str,
    objective: PlanObjective,
    options: &PlanOptions,
) -> Result<PlanRequest, CliError> {
    let direction = match &options.direction {
        Some(text) => {
            let u = numbers_n("--direction", text, 3, "components (UX,UY,UZ)")?;
            let u = Vector3::new(u[0], u[1], u[2]);
            let n = u.norm();
            if !(n.is_finite() && n > 0.0) {
                return Err(CliError::input("--direction: must be a finite, non-zero vector"));
            }
            Some(u / n)
        }
        None => None,
    };
    let need_direction = |what: &str| {
        direction.ok_or_else(|| CliError::input(format!("{flag} {what} needs --direction")))
    };
    let objective = match objective {
        PlanObjective::StiffnessAlong => {
            Objective::StiffnessAlong(need_direction("stiffness-along")?)
        }
        PlanObjective::ComplianceAlong => {
            Objective::ComplianceAlong(need_direction("compliance-along")?)
        }
        PlanObjective::MinStiffness => Objective::MinStiffness,
        PlanObjective::Volume => Objective::Volume,
        PlanObjective::LeastTension => Objective::LeastTension,
    };
    let k_des = match &options.k_des {
        Some(text) => {
            let k = numbers_n("--k-des", text, 9, "entries (K11,...,K33, row by row)")?;
            Some(Matrix3::from_row_slice(&k))
        }
        None => None,
    };
    let joint_budgets = joint_pairs(
        "--joint-budget",
        &options.joint_budget,
        "J:N, a joint numbered from 1 and a total tension in N",
    )?;
    let fixed_levels = joint_pairs(
        "--fixed-level",
        &options.fixed_level,
        "J:S, a joint numbered from 1 and a level in [0, 1]",
    )?;
    let requirements = Requirements {
        joint_budgets,
        fixed_levels,
        margin: options
            .margin
            .as_deref()
            .map(|t| one_number("--margin", t))
            .transpose()?
            .unwrap_or(DEFAULT_MARGIN),
        budget: options.budget.as_deref().map(|t| one_number("--budget", t)).transpose()?,
        k_min: options.k_min.as_deref().map(|t| one_number("--k-min", t)).transpose()?,
        k_des,
    };
    let tolerance = match &options.gap {
        Some(text) => one_number("--gap", text)?,
        None => DEFAULT_GAP,
    };
    let settings = PlanSettings { relative_gap: tolerance, ..PlanSettings::default() };
    Ok(PlanRequest { objective, direction, requirements, tolerance, settings })
}

/// Run `sinew plan`.
pub fn run(args: &PlanArgs) -> Result<(), CliError> {
    let loaded = load(&args.common.robot, args.common.model, args.no_gravity)?;
    let (robot, routing) = (&loaded.robot, &loaded.routing);
    // (clap requires --q without --trajectory; main.rs sends --trajectory elsewhere.)
    let q = pose(args.q.as_deref().unwrap_or_default(), args.deg, robot)?;
    let wrench = wrench(args.wrench.as_deref())?;
    let PlanRequest { objective, direction, requirements, tolerance, settings } =
        request("--objective", args.objective, &args.options)?;
    // The planner's one pose stage refuses angles outside the limits (`--q: …`).
    let arm = ArmStiffness::new(robot, routing).map_err(library_error)?.checking_limits();
    let planner = Planner::new(arm);
    let mut data = PlannerData::new(&planner);
    let f0 = Vector6::from_column_slice(&wrench);
    let friction = stick_requested(args, routing)?;
    let plan = match &friction {
        None => planner.plan(&mut data, &q, &f0, objective, &requirements, &settings),
        Some((model, history)) => {
            let mut stick = StickPlanData::new(&planner, model);
            let stage = (model, *history);
            planner.plan_in_stick(
                &mut data,
                &mut stick,
                stage,
                &q,
                &f0,
                objective,
                &requirements,
                &settings,
            )
        }
    }
    .map_err(library_error)?;
    let g = robot.gravity();
    let out = PlanOut {
        command: "plan",
        robot: robot.name().to_owned(),
        routing_file: loaded.routing_file.display().to_string(),
        model: args.common.model.name(),
        gravity: [g.x, g.y, g.z],
        q,
        wrench,
        objective: objective.name(),
        direction: direction.map(|u| [u.x, u.y, u.z]),
        k_min: requirements.k_min,
        k_des: requirements.k_des.map(|k| na_rows(&k)),
        margin: requirements.margin,
        budget: requirements.budget,
        joint_budgets: requirements.joint_budgets.clone(),
        fixed_levels: requirements.fixed_levels.clone(),
        tolerance,
        value: plan.value,
        gap: plan.gap,
        lambda: plan.lambda.clone(),
        levels: plan.levels.clone(),
        cables: routing.cables().iter().map(|c| c.name.clone()).collect(),
        tensions: plan.tensions.clone(),
        total_tension: plan.total_tension,
        k_fd: plan.k_fd.map(|k| na_rows(&k)),
        c_x: na_rows(&plan.c_x),
        min_eigenvalue: plan.min_eigenvalue,
        stable: plan.min_eigenvalue > 0.0,
        iterations: plan.iterations,
        friction: friction.map(|(model, history)| PlanFriction {
            mu: model.friction_coefficients().to_vec(),
            regime: "stick",
            history: history_name(history),
        }),
    };
    if args.common.json { print_json(&out) } else { emit(&render(&out)) }
}

fn unit(objective: &str) -> &'static str {
    match objective {
        "stiffness-along" | "min-stiffness" => "N/m",
        "compliance-along" => "m/N",
        "least-tension" => "N",
        _ => "(ln of (N/m)³)",
    }
}

fn render(out: &PlanOut) -> String {
    let mut s = String::new();
    s.push_str(&format!(
        "plan for `{}` ({}: {}), gravity {} m/s²\n",
        out.robot,
        out.model,
        out.routing_file,
        Fmt::Fixed(3).list(&out.gravity)
    ));
    s.push_str(&format!("  Q  = {} rad\n", Fmt::Fixed(5).list(&out.q)));
    s.push_str(&format!("  F0 = {} (N, N m)\n", Fmt::Fixed(4).list(&out.wrench)));
    let mut asked = format!("  objective {}", out.objective);
    if let Some(u) = out.direction {
        asked.push_str(&format!(" along {}", Fmt::Fixed(4).list(&u)));
    }
    asked.push_str(&format!("; margin ≥ {} N m/rad", Fmt::Sci(3).num(out.margin)));
    if let Some(b) = out.budget {
        asked.push_str(&format!(", Σf ≤ {} N", Fmt::Fixed(3).num(b)));
    }
    if let Some(k) = out.k_min {
        asked.push_str(&format!(", λ_min(K_fd) ≥ {} N/m", Fmt::Fixed(3).num(k)));
    }
    if out.k_des.is_some() {
        asked.push_str(", K_fd ⪰ K_des");
    }
    s.push_str(&asked);
    s.push('\n');
    if let Some(f) = &out.friction {
        s.push_str(&format!(
            "  friction at the holes: {} after {}, μ = {}\n",
            f.regime,
            f.history,
            Fmt::Fixed(3).list(&f.mu)
        ));
    }
    s.push('\n');
    s.push_str(&format!(
        "Optimum: {} {} (certified: within {} of the true optimum; {} iterations)\n",
        Fmt::Sci(8).num(out.value),
        unit(out.objective),
        Fmt::Sci(2).num(out.gap),
        out.iterations
    ));
    s.push_str(&format!(
        "  total tension {} N, smallest eigenvalue of K_q + K_W {} N m/rad\n",
        Fmt::Fixed(3).num(out.total_tension),
        Fmt::Fixed(6).num(out.min_eigenvalue)
    ));
    if let Some(levels) = &out.levels {
        s.push_str(&format!("  tension levels = {}\n", Fmt::Fixed(4).list(levels)));
    }
    s.push('\n');
    let mut t = Table::new(&["cable", "f (N)"]).left(&[0]);
    for (name, f) in out.cables.iter().zip(&out.tensions) {
        t.row(vec![name.clone(), Fmt::Fixed(3).num(*f)]);
    }
    s.push_str(&t.render(2));
    let cl = cartesian_labels();
    if let Some(k_fd) = &out.k_fd {
        s.push('\n');
        let xyz = &cl[..3];
        s.push_str(&matrix("K_fd = K_x[0:3, 0:3] (N/m):", k_fd, Fmt::Fixed(3), xyz, xyz));
    }
    s.push('\n');
    s.push_str(&matrix("C_x (m/N, rad/(N m)):", &out.c_x, Fmt::Sci(4), &cl, &cl));
    s
}
