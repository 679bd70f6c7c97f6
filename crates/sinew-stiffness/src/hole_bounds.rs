//! A bound on every hole's rates, so that the stick load limit (`stick_limit.rs`) computes
//! along each direction only the holes that may be reached first (spec §9, #27).
//!
//! Hole `k`'s edge has the rate `ġ = a δT_{k+1} + b δT_k + d δθ_k` ([`Hole::rate_coefficients`])
//! with `δT_s = E A/ℓ_s J_s δQ` and `δθ_k = ∇θ_k δQ`. Over the DOFs `S` of its three rows,
//!
//! ```text
//! |ġ| ≤ ρ max_{i∈S}|δQ_i|,    ρ = |a| E A/ℓ_{k+1} ‖J_{k+1}‖₁ + |b| E A/ℓ_k ‖J_k‖₁ + |d| ‖∇θ_k‖₁,
//! ```
//!
//! so the edge is reached no sooner than `β / max_{i∈S}|δQ_i|` with `β = g/ρ`. Holes are
//! grouped by the first DOF their rows cover (in a chain, one group per disc), each group's
//! bound its least `β` over the largest `|δQ_i|` of its DOFs.
//!
//! Why skipping on the bound keeps the full pass's answer to the bit: a hole skipped has a
//! bound `β/m > α* (1 + SKIP_MARGIN)`, with `α*` an `α` already computed and `m` the largest
//! `|δQ_i|` over DOFs that include the hole's. In exact arithmetic `|ġ| ≤ ρ m`; the computed
//! `ġ`, `ρ` and `β` are each within a few units of rounding (1e-15 relative) of theirs, far
//! inside the margin, so the hole's computed `g/(−ġ)` would exceed `α*` and lose to it. A hole
//! that could tie is never skipped, and ties go to the first hole in the full pass's order.

use std::ops::Range;

use sinew_routing::{CableRows, DofRow};

use crate::error::StiffnessError;
use crate::holes::{Edges, Hole, HoleEvent};

/// The least `α` so far, the place in the full pass's order of its hole, and its event.
pub(crate) type Best = (f64, usize, Option<HoleEvent>);

/// Every hole's bound, grouped.
pub(crate) struct HoleBounds {
    /// Per group: the DOFs it covers, its least `β`, the hole with it, and its members.
    groups: Vec<Group>,
    /// `(β, hole)` of the holes in groups, group by group, each group's in order.
    members: Vec<(f64, usize)>,
}

/// The holes whose rows begin at one DOF.
struct Group {
    dofs: Range<usize>,
    beta: f64,
    seed: usize,
    members: Range<usize>,
}

/// How much a hole's bound must exceed the least `α` found for the hole to be skipped: far
/// above the rounding of `ġ`, `ρ` and `β` (a few 1e-16 relative each).
const SKIP_MARGIN: f64 = 1e-9;

/// A hole handed to the caller of [`HoleBounds::walk`]: its place in the order, the hole, its
/// edges, its rows `[J_{k+1}, J_k, ∇θ_k]`, and whether the hole before it on its cable was
/// handed over too (then `J_k δQ` was computed for it, as its `J_{k+1} δQ`).
pub(crate) type Visit<'r, 'a> = (usize, &'r Hole, &'r Edges, [&'r DofRow<'a>; 3], bool);

impl HoleBounds {
    /// One walk over every cable's segments (`cables`, in order; segment `k` before hole `k`,
    /// `k + 1` after it) and `holes` with them (cable by cable, hole by hole, as `holes.rs`
    /// gives them, over `n` DOFs): a hole on an edge of its band, or every hole when
    /// `exhaustive`, is handed to `visit`, in that order; every other is bounded and grouped.
    pub(crate) fn walk(
        cables: &[CableRows<'_>],
        holes: &[Hole],
        n: usize,
        exhaustive: bool,
        mut visit: impl FnMut(Visit<'_, '_>),
    ) -> Result<HoleBounds, StiffnessError> {
        let l1 = |row: &DofRow<'_>| row.values.iter().map(|v| v.abs()).sum::<f64>();
        // Per DOF: the end of the DOFs its group covers, its least β and hole, its size.
        let mut by_start = vec![(0, f64::INFINITY, usize::MAX, 0); n];
        // Per hole: the DOF its group starts at (`usize::MAX`: in no group), and its β.
        let mut placed = vec![(usize::MAX, 0.0); holes.len()];
        let mut pending = holes.iter().zip(placed.iter_mut()).enumerate();
        for (c, cable) in cables.iter().enumerate() {
            // Rows by index (a whole segment's rows, moved from one hole to the next, cost a
            // stalled copy per hole).
            let mut before = cable.jacobian(0);
            let mut carried = false;
            for s in 1..cable.len() {
                let (after, wrap) = (cable.jacobian(s), cable.wrap_gradient(s - 1)?);
                let (i, h, place) = match pending.next() {
                    Some((i, (h, place))) if (h.cable, h.hole + 1) == (c, s) => (i, h, place),
                    _ => {
                        let (expected, what) = (holes.len(), "holes (cable by cable, in order)");
                        return Err(StiffnessError::DimensionMismatch { what, expected, got: s });
                    }
                };
                let edges = h.edges();
                if exhaustive || edges.iter().any(|e| e.3) {
                    visit((i, h, &edges, [&after, &before, &wrap], carried));
                    carried = true;
                    before = after;
                    continue;
                }
                let [after_l1, before_l1, wrap_l1] = [&after, &before, &wrap].map(l1);
                let mut beta = f64::INFINITY;
                for &(_, (a, b, d), g, _) in &edges {
                    let rho = a.abs() * h.springs[1] * after_l1
                        + b.abs() * h.springs[0] * before_l1
                        + d.abs() * wrap_l1;
                    beta = beta.min(g / rho);
                }
                let rows = [&after, &before, &wrap];
                let (mut start, mut end) = (usize::MAX, 0);
                for row in rows.iter().filter(|r| !r.dofs.is_empty()) {
                    (start, end) = (start.min(row.dofs.start), end.max(row.dofs.end));
                }
                if start < n && end <= n && beta < f64::INFINITY {
                    // (No row, or no rate: `ġ = 0` in every direction, and the hole is in no
                    // group.)
                    let group = &mut by_start[start];
                    group.0 = group.0.max(end);
                    if beta < group.1 {
                        (group.1, group.2) = (beta, i);
                    }
                    group.3 += 1;
                    *place = (start, beta);
                } else if start != usize::MAX && end > n {
                    let what = "friction rows (DOFs)";
                    return Err(StiffnessError::DimensionMismatch { what, expected: n, got: end });
                }
                carried = false;
                before = after;
            }
        }
        let mut groups = Vec::new();
        let mut offsets = vec![0; n];
        let mut next = 0;
        for (s, &(end, beta, seed, size)) in by_start.iter().enumerate() {
            if size > 0 {
                offsets[s] = next;
                groups.push(Group { dofs: s..end, beta, seed, members: next..next + size });
                next += size;
            }
        }
        let mut members = vec![(0.0, 0); next];
        for (i, &(s, beta)) in placed.iter().enumerate() {
            if let Some(offset) = offsets.get_mut(s) {
                members[*offset] = (beta, i);
                *offset += 1;
            }
        }
        Ok(HoleBounds { groups, members })
    }

    /// Along the joint motion `dq`, every grouped hole that may be reached no later than
    /// `best` is handed to `exact` (which computes it and updates `best`): first the hole whose
    /// bound is least, then, group by group in order, the others not skipped on their bound.
    /// `scratch` is resized to the number of groups. The first error of `exact` ends it.
    pub(crate) fn search(
        &self,
        dq: &[f64],
        scratch: &mut Vec<(f64, f64)>,
        best: &mut Best,
        mut exact: impl FnMut(usize, &mut Best) -> Result<(), StiffnessError>,
    ) -> Result<(), StiffnessError> {
        scratch.clear();
        // Per group: its bound and the largest `|δQ_i|` over its DOFs.
        scratch.extend(self.groups.iter().map(|group| {
            let motion = dq[group.dofs.clone()].iter().fold(0.0, |m: f64, x| m.max(x.abs()));
            (group.beta / motion, motion)
        }));
        let least = (0..scratch.len()).min_by(|&a, &b| scratch[a].0.total_cmp(&scratch[b].0));
        if let Some(g) = least {
            exact(self.groups[g].seed, best)?;
        }
        for (group, &(bound, motion)) in self.groups.iter().zip(scratch.iter()) {
            if !may_reach(bound, best.0) {
                continue;
            }
            for &(beta, i) in &self.members[group.members.clone()] {
                if may_reach(beta / motion, best.0) {
                    exact(i, best)?;
                }
            }
        }
        Ok(())
    }
}

/// Whether a hole (or group) whose bound is `bound` may be reached no later than `best` (a
/// bound that is not a number is not trusted).
fn may_reach(bound: f64, best: f64) -> bool {
    bound.partial_cmp(&(best * (1.0 + SKIP_MARGIN))) != Some(std::cmp::Ordering::Greater)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use rand::Rng;
    use sinew_robot::RobotData;
    use sinew_routing::{
        FrictionData, FrictionModel, Order, RoutingData, compute_cable_geometry,
        compute_friction_geometry,
    };
    use sinew_testkit::cdhrm5;
    use sinew_testkit::config::rng;

    use super::*;
    use crate::History;
    use crate::holes::{dot, holes};

    /// The bound itself, not only the answers it leaves unchanged (`tests/stick_limit_scan.rs`):
    /// along random joint motions, every grouped hole's rate at each edge obeys
    /// `|ġ| ≤ ρ m`, that is `β |ġ| ≤ g m` with `m` the largest `|δQ_i|` over its group's DOFs,
    /// and the bound is not vacuous: for every hole, the largest `β |ġ| / (g m)` seen is near
    /// one. A `ρ` that drops a term or a factor breaks the first (a hole skipped that may be
    /// reached first, which the answers show only when that hole is the first); one that grows
    /// breaks the second (holes no longer skipped). Then [`HoleBounds::search`] along motions
    /// of every size: it must find the least `α` of all holes while handing over less than half
    /// of them (a group's or hole's bound with `m` on the wrong side of `β`, or a search that
    /// skips nothing, fails it).
    #[test]
    fn every_bound_holds_is_near_tight_and_the_search_finds_the_least_alpha() {
        for pattern in cdhrm5::MODELS {
            let (robot, routing) = cdhrm5::robot_and_routing(pattern);
            let (n, m) = (routing.dof(), routing.cable_count());
            let mut rdata = RobotData::new(&robot);
            let mut geometry = RoutingData::new(&routing);
            let (q, order) = (cdhrm5::LOADED_POSE, Order::Jacobian);
            compute_cable_geometry(&routing, &robot, &mut rdata, &mut geometry, &q, order).unwrap();
            let model = FrictionModel::new(&routing).with_friction_coefficient(0.2).unwrap();
            let mut friction = FrictionData::new(&model);
            compute_friction_geometry(&model, &routing, &geometry, &mut friction).unwrap();
            let t: Vec<f64> = (0..m).map(|c| 50.0 + 10.0 * c as f64).collect();
            let holes = holes(&model, &routing, &friction, History::Equal, &t).unwrap();
            let cables: Vec<CableRows<'_>> =
                (0..m).map(|c| friction.cable(&model, c).unwrap()).collect();
            // After `equal` every band has room: no hole is handed over unbounded.
            let bounds =
                HoleBounds::walk(&cables, &holes, n, false, |_| panic!("on an edge")).unwrap();
            assert_eq!(bounds.members.len(), holes.len(), "{pattern:?}: every hole grouped");
            let mut r = rng(17);
            // Per hole, the largest ratio over the motions.
            let mut tightest = vec![0.0_f64; holes.len()];
            for _ in 0..200 {
                let dq: Vec<f64> = (0..n).map(|_| r.random_range(-1.0..1.0)).collect();
                for group in &bounds.groups {
                    let motion =
                        dq[group.dofs.clone()].iter().fold(0.0, |a: f64, x| a.max(x.abs()));
                    for &(beta, i) in &bounds.members[group.members.clone()] {
                        let h = &holes[i];
                        let cable = &cables[h.cable];
                        let after = dot(&cable.jacobian(h.hole + 1), &dq);
                        let before = dot(&cable.jacobian(h.hole), &dq);
                        let turn = dot(&cable.wrap_gradient(h.hole).unwrap(), &dq);
                        for (edge, (a, b, d), g, _) in h.edges() {
                            let rate =
                                a * h.springs[1] * after + b * h.springs[0] * before + d * turn;
                            let ratio = beta * rate.abs() / (g * motion);
                            assert!(ratio <= 1.0 + 1e-12, "{pattern:?} {edge:?} {h:?}: {ratio}");
                            tightest[i] = tightest[i].max(ratio);
                        }
                    }
                }
            }
            let loosest = tightest.iter().fold(f64::INFINITY, |a: f64, &x| a.min(x));
            println!("{pattern:?}: per hole, the largest β|ġ|/(g m) of 200 motions ≥ {loosest:.3}");
            assert!(loosest > 0.8, "{pattern:?}: a loose bound (measured ≥ 0.969)");
            // The search: along each motion it finds the least α of all holes, handing over
            // only part of them (a search that skipped on a wrong bound misses the least α now
            // and then; one that skipped nothing hands over every hole).
            let alpha = |i: usize, dq: &[f64]| {
                let h = &holes[i];
                let cable = &cables[h.cable];
                let after = dot(&cable.jacobian(h.hole + 1), dq);
                let before = dot(&cable.jacobian(h.hole), dq);
                let turn = dot(&cable.wrap_gradient(h.hole).unwrap(), dq);
                h.edges().iter().fold(f64::INFINITY, |least, &(_, (a, b, d), g, _)| {
                    let rate = a * h.springs[1] * after + b * h.springs[0] * before + d * turn;
                    if rate < 0.0 { least.min(g / -rate) } else { least }
                })
            };
            let (mut scratch, mut handed) = (Vec::new(), 0);
            for _ in 0..200 {
                // Of every size, so that a bound with `m` on the wrong side of `β` errs.
                let size = 10.0_f64.powf(r.random_range(-2.0..2.0));
                let dq: Vec<f64> = (0..n).map(|_| size * r.random_range(-1.0..1.0)).collect();
                let mut best: Best = (f64::INFINITY, usize::MAX, None);
                bounds
                    .search(&dq, &mut scratch, &mut best, |i, best| {
                        handed += 1;
                        let a = alpha(i, &dq);
                        if a < best.0 {
                            (best.0, best.1) = (a, i);
                        }
                        Ok(())
                    })
                    .unwrap();
                let least = (0..holes.len()).map(|i| alpha(i, &dq)).fold(f64::INFINITY, f64::min);
                assert_eq!(best.0, least, "{pattern:?}: the search missed the least α");
            }
            let share = handed as f64 / (200 * holes.len()) as f64;
            println!("{pattern:?}: the search handed over {:.1} % of the holes", 100.0 * share);
            assert!(share < 0.5, "{pattern:?}: the search skips too little (measured 23 %, 6 %)");
        }
    }
}
