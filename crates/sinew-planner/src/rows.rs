//! The linear rows of a plan in the coordinates `λ` of the equilibrium set: the tension limits,
//! the total and per-joint budgets, and the joints held at a level.

use sinew_statics::EquilibriumSet;

use crate::bundle::Linear;
use crate::error::PlanError;

/// `Nᵀ 1`: how the total tension changes per unit of each `λ`.
pub(crate) fn column_sums(set: &EquilibriumSet) -> impl Iterator<Item = f64> + '_ {
    let null = set.null_basis();
    (0..set.dimension()).map(move |i| (0..set.cable_count()).map(|c| null[(c, i)]).sum())
}

/// The limits `f_min ≤ f_p + N λ ≤ f_max`, the budget `Σ f ≤ B` and the per-joint budgets
/// `Σ_{c ∈ cables} f_c ≤ B_j` as rows in `λ`.
pub(crate) fn linear_rows(
    set: &EquilibriumSet,
    budget: Option<f64>,
    joint_budgets: &[(std::ops::Range<usize>, f64)],
) -> Linear {
    let mut linear = Linear::new(0, 0);
    linear_rows_into(set, budget, joint_budgets, &mut linear);
    linear
}

/// [`linear_rows`] into `linear`'s buffers (its rows replaced).
pub(crate) fn linear_rows_into(
    set: &EquilibriumSet,
    budget: Option<f64>,
    joint_budgets: &[(std::ops::Range<usize>, f64)],
    linear: &mut Linear,
) {
    let null = set.null_basis();
    let (m, k) = (set.cable_count(), set.dimension());
    let p = set.particular();
    // Room for the limits, the budgets and the rate rows a trajectory adds.
    linear.clear(k, 4 * m + 1 + joint_budgets.len());
    for c in 0..m {
        linear.push((0..k).map(|i| null[(c, i)]), set.upper()[c] - p[c]);
        linear.push((0..k).map(|i| -null[(c, i)]), p[c] - set.lower()[c]);
    }
    if let Some(b) = budget {
        linear.push(column_sums(set), b - p.iter().sum::<f64>());
    }
    for (cables, b) in joint_budgets {
        let row = (0..k).map(|i| cables.clone().map(|c| null[(c, i)]).sum());
        linear.push(row, b - cables.clone().map(|c| p[c]).sum::<f64>());
    }
}

/// A joint held at a level: its cables and their tensions there.
pub(crate) type HeldTensions = (std::ops::Range<usize>, Vec<f64>);

/// Each held joint's null coordinate (the one column of `N` on its cables, decoupled) and the
/// value that gives its tensions: `(coordinate, value)`.
pub(crate) fn held_coordinates(
    set: &EquilibriumSet,
    fixed: &[(std::ops::Range<usize>, Vec<f64>)],
) -> Vec<(usize, f64)> {
    let null = set.null_basis();
    let k = set.dimension();
    let p = set.particular();
    fixed
        .iter()
        .filter_map(|(cables, target)| {
            let column = (0..k).find(|&i| cables.clone().any(|c| null[(c, i)].abs() > 0.5))?;
            let value =
                cables.clone().zip(target).map(|(c, t)| null[(c, column)] * (t - p[c])).sum();
            Some((column, value))
        })
        .collect()
}

/// Hold each fixed joint's own tensions ([`held_coordinates`]) as two rows a rounding apart
/// (the bundle method's form; the interior-point method removes the coordinate instead).
pub(crate) fn fix_rows(
    set: &EquilibriumSet,
    fixed: &[(std::ops::Range<usize>, Vec<f64>)],
    linear: &mut Linear,
) {
    let k = set.dimension();
    for (column, value) in held_coordinates(set, fixed) {
        let tol = 1e-9 * (1.0 + value.abs());
        let unit = |sign: f64| (0..k).map(move |i| if i == column { sign } else { 0.0 });
        linear.push(unit(1.0), value + tol);
        linear.push(unit(-1.0), tol - value);
    }
}

/// The rate limit `|f − f_prev| ≤ change` per cable as rows in `λ`.
pub(crate) fn rate_rows(set: &EquilibriumSet, previous: &[f64], change: f64, linear: &mut Linear) {
    let null = set.null_basis();
    let k = set.dimension();
    let p = set.particular();
    for (c, f) in previous.iter().enumerate().take(set.cable_count()) {
        linear.push((0..k).map(|i| null[(c, i)]), f + change - p[c]);
        linear.push((0..k).map(|i| -null[(c, i)]), p[c] - (f - change));
    }
}

/// The warm start's tensions from the last plan's, `last`, and, where that plan was a step
/// along the same trajectory, the tensions of the plan before it, `before`: the linear
/// prediction `2 f_k − f_{k−1}`
/// within the tension limits (into `out`), whose error along a smooth trajectory is second
/// order in the time step where the last tensions' is first order; `last` itself without
/// `before`.
pub(crate) fn predicted<'a>(
    set: &EquilibriumSet,
    last: &'a [f64],
    before: Option<&[f64]>,
    out: &'a mut Vec<f64>,
) -> &'a [f64] {
    let Some(before) = before.filter(|b| b.len() == last.len()) else { return last };
    out.clear();
    out.extend(last.iter().zip(before).map(|(f, b)| 2.0 * f - b));
    for (f, (lo, hi)) in out.iter_mut().zip(set.lower().iter().zip(set.upper())) {
        *f = f.clamp(*lo, *hi);
    }
    out
}

/// With a rate limit, rows that no point meets are the limit's doing (or the budgets').
pub(crate) fn rate_error(error: PlanError, limited: bool) -> PlanError {
    match error {
        PlanError::BudgetsInfeasible if limited => PlanError::RateLimitInfeasible,
        e => e,
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use nalgebra::Vector6;
    use sinew_routing::PatternModel;
    use sinew_stiffness::{ArmStiffness, ArmStiffnessData};
    use sinew_testkit::cdhrm5;

    use super::predicted;

    #[test]
    fn the_prediction_is_the_linear_extrapolation_within_the_limits() {
        let (robot, routing) = cdhrm5::robot_and_routing(PatternModel::Routed);
        let arm = ArmStiffness::new(&robot, &routing).unwrap();
        let mut sd = ArmStiffnessData::new(&arm);
        let f0 = Vector6::new(0.0, 5.0, 0.0, 0.0, 0.0, 0.0);
        arm.set_pose(&mut sd, &cdhrm5::LOADED_POSE, &f0).unwrap();
        let set = arm.equilibrium_set(&mut sd).unwrap();
        let (lower, upper) = (set.lower(), set.upper());
        let m = set.cable_count();
        // Inside the limits, except cable 0 driven above its upper one and cable 1 below its
        // lower one.
        let middle = |c: usize| 0.5 * (lower[c] + upper[c]);
        let last: Vec<f64> = (0..m).map(|c| middle(c) + 0.01 * c as f64).collect();
        let mut before: Vec<f64> = (0..m).map(|c| middle(c) - 0.02 * c as f64).collect();
        before[0] = last[0] - upper[0];
        before[1] = last[1] + upper[1];
        let mut out = Vec::new();
        let got = predicted(set, &last, Some(&before), &mut out).to_vec();
        assert_eq!(got[0], upper[0]);
        assert_eq!(got[1], lower[1]);
        for c in 2..m {
            assert_eq!(got[c], 2.0 * last[c] - before[c], "cable {c}");
            assert!(got[c] > last[c], "cable {c}: along the motion");
        }
        // Without the tensions before (or with another arm's), the last ones.
        assert_eq!(predicted(set, &last, None, &mut out), &last[..]);
        assert_eq!(predicted(set, &last, Some(&before[1..]), &mut out), &last[..]);
    }
}
