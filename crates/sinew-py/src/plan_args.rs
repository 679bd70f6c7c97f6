//! The planner's arguments as `ArmStiffness.plan` and `plan_many` take them (`sinew plan`'s
//! options): the objective by name, its direction, the requirements and the gap, checked.

use std::collections::BTreeMap;

use nalgebra::Vector6;
use nalgebra::{Matrix3, Vector3};
use pyo3::prelude::*;
use sinew::planner::{
    Objective, Plan, PlanError, PlanSettings, Planner, PlannerData, Requirements, StickPlanData,
};
use sinew::routing::FrictionModel;
use sinew::stiffness::History;

use crate::convert::{finite, matrix, vector};
use crate::errors::input;

/// What one plan asks for: the objective, the requirements and the settings.
#[derive(Debug, Clone)]
pub struct PlanArgs {
    /// The objective.
    pub objective: Objective,
    /// Margin, budgets, floors, fixed levels.
    pub requirements: Requirements,
    /// The relative gap at which it stops.
    pub settings: PlanSettings,
}

/// The plan's arguments checked (see `ArmStiffness.plan`).
pub fn plan_args(
    objective: &str,
    direction: Option<&Bound<'_, PyAny>>,
    k_min: Option<f64>,
    k_des: Option<&Bound<'_, PyAny>>,
    margin: f64,
    budget: Option<f64>,
    joint_budgets: Option<BTreeMap<usize, f64>>,
    fixed_levels: Option<BTreeMap<usize, f64>>,
    gap: f64,
) -> PyResult<PlanArgs> {
    let direction = match direction {
        Some(d) => {
            let u = vector(d, "direction", Some(3))?;
            let u = Vector3::new(u[0], u[1], u[2]);
            let n = u.norm();
            if !(n.is_finite() && n > 0.0) {
                return Err(input("direction: must be a finite, non-zero vector"));
            }
            Some(u / n)
        }
        None => None,
    };
    let need =
        |what: &str| direction.ok_or_else(|| input(format!("objective {what} needs a direction")));
    let objective = match objective {
        "stiffness-along" => Objective::StiffnessAlong(need("stiffness-along")?),
        "compliance-along" => Objective::ComplianceAlong(need("compliance-along")?),
        "min-stiffness" => Objective::MinStiffness,
        "volume" => Objective::Volume,
        "least-tension" => Objective::LeastTension,
        other => {
            return Err(input(format!(
                "objective: `{other}` is not one of stiffness-along, compliance-along, min-stiffness, volume, least-tension"
            )));
        }
    };
    let k_des = match k_des {
        Some(k) => {
            let (rows, v) = matrix(k, "k_des", 3)?;
            if rows != 3 {
                return Err(input(format!("k_des: expected shape (3, 3), got ({rows}, 3)")));
            }
            finite(&v, "k_des")?;
            Some(Matrix3::from_row_slice(&v))
        }
        None => None,
    };
    let requirements = Requirements {
        margin,
        budget,
        k_min,
        k_des,
        joint_budgets: joint_budgets.unwrap_or_default().into_iter().collect(),
        fixed_levels: fixed_levels.unwrap_or_default().into_iter().collect(),
    };
    let settings = PlanSettings { relative_gap: gap, ..PlanSettings::default() };
    Ok(PlanArgs { objective, requirements, settings })
}

impl PlanArgs {
    /// The plan at `q` under `f0`: frictionless, or in the stick regime after a history.
    ///
    /// # Errors
    /// The planner's.
    pub fn plan(
        &self,
        (planner, data): (&Planner, &mut PlannerData),
        stick: Option<&(FrictionModel, History)>,
        q: &[f64],
        f0: &Vector6<f64>,
    ) -> Result<Plan, PlanError> {
        let (objective, requirements, settings) =
            (self.objective, &self.requirements, &self.settings);
        match stick {
            None => planner.plan(data, q, f0, objective, requirements, settings),
            Some((model, history)) => {
                let mut out = StickPlanData::new(planner, model);
                let stage = (model, *history);
                planner.plan_in_stick(
                    data,
                    &mut out,
                    stage,
                    q,
                    f0,
                    objective,
                    requirements,
                    settings,
                )
            }
        }
    }
}
