//! The stick load limit (spec §9, #27): how large a wrench increment the arm takes in the
//! stick regime before a hole changes state.
//!
//! # Math
//! In the stick regime every hole holds its cable, each segment a spring of its own
//! ([`crate::stick_stiffness`]). A wrench `δw = α u` applied to the end-effector (base frame,
//! linear rows first: `δx = C_x δw`, spec §5) moves the joints by
//! `δQ = α (K_stick + K_W)⁻¹ J_xᵀ u` and each segment's tension by `δT_s = α (E A/ℓ_s) J_s δQ/α`
//! (the free length's `J_0 = 0`: the actuator tension does not move). Hole `k` of a cable (0-based,
//! between segments `k` and `k + 1`, [`sinew_routing::FrictionData::wrap_angles`]) holds while
//! both edges of its capstan band do:
//!
//! ```text
//! lower:  g⁻ = T_{k+1} − T_k e^{−μθ_k} ≥ 0      (reached: the cable slides toward the actuator)
//! upper:  g⁺ = T_k e^{+μθ_k} − T_{k+1} ≥ 0      (reached: it slides away from the actuator)
//! ġ⁻ = δT_{k+1} − e^{−μθ_k} (δT_k − μ T_k δθ_k)      ġ⁺ = e^{+μθ_k} (δT_k + μ T_k δθ_k) − δT_{k+1}
//! ```
//!
//! per unit `α`, with `δθ_k = ∇θ_k · δQ`: the band moves with the pose, and that counts. An
//! edge the increment approaches (`ġ < 0`) is reached at `α = g / (−ġ)`; the stick load limit
//! along `u` is the least such `α` over every hole and edge, to first order in `α`. A hole
//! already on an edge (`g ≤` [`EDGE_TOLERANCE`](crate::EDGE_TOLERANCE) `· (T_k + T_{k+1})`,
//! as after a [`History::Pull`] or [`History::Release`]) that the increment pushes outward
//! slides at once: the limit is 0 and every such hole is named ([`StickLoadLimit::at_once`]).
//! From [`History::Equal`] every band of a bent cable has room on both sides and the limit is
//! positive in every direction.
//!
//! # Cost
//! The answer needs the least `α` over every hole, but not every hole's `α`: each hole's rates
//! are bounded once by `|ġ| ≤ ρ max_{i∈S}|δQ_i|` (`S` the DOFs of its rows,
//! `ρ = |a| E A/ℓ_{k+1} ‖J_{k+1}‖₁ + |b| E A/ℓ_k ‖J_k‖₁ + |d| ‖∇θ_k‖₁`), and along a direction
//! a hole whose bound `g/(ρ max|δQ_i|)` exceeds an `α` already found is skipped. After
//! [`History::Equal`] an extra direction then costs less than one solve of `K_stick + K_W`
//! (docs/performance.md, `scripts/stick-limit-instructions`). After a pull or release every
//! hole is on an edge and each direction names the holes it pushes over theirs, about half of
//! them: there a direction costs a pass over the holes, shared with its mirror `−u`.
//!
//! At a kinked hole (`θ ≈ 0`, [`sinew_routing::FrictionData::kinked`]) the band has no width and
//! `θ`'s gradient is taken as 0: the one-sided growth of `θ` there (`δθ ≥ 0` whichever way the
//! joints move) is not modelled, so such a hole is reported at once as soon as the tensions on
//! either side move apart ([`HoleEvent::kinked`] says so).

use faer::linalg::solvers::Solve;
use faer::{Mat, MatRef, Side};
use nalgebra::Vector6;
use sinew_routing::{FrictionData, FrictionModel, Routing};

use crate::end::stability_margin;
use crate::error::StiffnessError;
use crate::friction::History;
use crate::hole_bounds::{Best, HoleBounds};
use crate::holes::{Edges, Hole, HoleEvent, RATE_TOLERANCE, dot, holes};

/// The stick load limit along one direction.
#[derive(Debug, Clone, PartialEq)]
pub struct StickLoadLimit {
    /// The direction `u` as given (base frame, force then moment).
    pub direction: Vector6<f64>,
    /// The largest `α ≥ 0` (in units of `u`: N for a unit force, N m for a unit moment) for
    /// which the wrench increment `α u` leaves every hole inside its band, to first order;
    /// `f64::INFINITY` when no edge is approached.
    pub magnitude: f64,
    /// The hole and edge reached first (`None` when none is).
    pub first: Option<HoleEvent>,
    /// The holes already on an edge that the increment pushes over it (then `magnitude` is 0),
    /// cable by cable, hole by hole.
    pub at_once: Vec<HoleEvent>,
    /// `δQ` per unit `α`: `(K_stick + K_W)⁻¹ J_xᵀ u` (rad).
    pub joint_motion: Vec<f64>,
}

/// The twelve base directions: `+e_i` then `−e_i` for the force along x, y, z, then the
/// moment about x, y, z.
pub fn base_directions() -> [Vector6<f64>; 12] {
    std::array::from_fn(|k| {
        let mut u = Vector6::zeros();
        u[k / 2] = if k % 2 == 0 { 1.0 } else { -1.0 };
        u
    })
}

/// The stick load limit along each of `directions`, after `history`, at the actuator tensions
/// `actuator` (m, N): `k_stick` the stick regime's joint stiffness at those tensions
/// ([`crate::stick_stiffness`], dof × dof), `k_w` the load's (`K_W`), `j_x` the end-effector
/// Jacobian (6 × dof), `friction` the friction geometry at the pose (with the history's
/// capstan weights for [`History::Pull`] and [`History::Release`]). One factorisation of
/// `K_stick + K_W`, one solve with a right-hand side per direction (none for a direction that
/// is the negation of an earlier one: its joint motion and rates are that one's, negated), and
/// one walk over the holes for every direction. Holes on an edge of their band are computed
/// along every direction; the others are bounded once, and along each direction only those
/// that may be reached first are computed, with the same answer to the bit as computing them
/// all (module docs for the math).
///
/// # Errors
/// [`StiffnessError::StickWithoutFriction`] for a cable with μ = 0;
/// [`StiffnessError::WrongCapstanWeights`]; [`StiffnessError::InvalidWrenchDirection`] for a
/// zero or non-finite direction; [`StiffnessError::Unstable`] when `K_stick + K_W` is not
/// positive definite; [`StiffnessError::DimensionMismatch`]; routing errors (among them
/// `FrictionNotComputed` for a geometry without its wrap gradients, as
/// [`crate::ArmStiffness::evaluate_with_friction`] leaves it in the stick regime:
/// `sinew_routing::compute_wrap_gradients` adds them).
pub fn stick_load_limits(
    model: &FrictionModel,
    routing: &Routing,
    friction: &FrictionData,
    history: History,
    actuator: &[f64],
    (k_stick, k_w, j_x): (MatRef<'_, f64>, MatRef<'_, f64>, MatRef<'_, f64>),
    directions: &[Vector6<f64>],
) -> Result<Vec<StickLoadLimit>, StiffnessError> {
    let n = routing.dof();
    for (what, expected, got) in [
        ("K_stick", n, k_stick.nrows()),
        ("K_stick", n, k_stick.ncols()),
        ("K_W", n, k_w.nrows()),
        ("K_W", n, k_w.ncols()),
        ("J_x (rows)", 6, j_x.nrows()),
        ("J_x (columns)", n, j_x.ncols()),
        ("actuator tensions", routing.cable_count(), actuator.len()),
        ("friction model (cables)", routing.cable_count(), model.cable_count()),
    ] {
        if expected != got {
            return Err(StiffnessError::DimensionMismatch { what, expected, got });
        }
    }
    let holes = holes(model, routing, friction, history, actuator)?;
    if let Some(u) = directions.iter().find(|u| !u.iter().all(|x| x.is_finite()) || u.norm() == 0.0)
    {
        return Err(StiffnessError::InvalidWrenchDirection { direction: (*u).into() });
    }
    let k = Mat::from_fn(n, n, |i, j| k_stick[(i, j)] + k_w[(i, j)]);
    let symmetric = Mat::from_fn(n, n, |i, j| 0.5 * (k[(i, j)] + k[(j, i)]));
    if symmetric.llt(Side::Lower).is_err() {
        return Err(StiffnessError::Unstable { min_eigenvalue: stability_margin(k_stick, k_w)? });
    }
    let lu = k.partial_piv_lu();
    // A direction that is the negation of an earlier one (as `±e_i` are) is that one's mirror:
    // its joint motion and every rate are the negated ones, exactly (rounding is symmetric), so
    // neither is computed twice. The others' joint motions in one solve with as many
    // right-hand sides, then one walk over the holes for them all.
    let pairs = mirror_pairs(directions);
    let rhs = Mat::from_fn(n, pairs.len(), |i, p| {
        (0..6).map(|r| j_x[(r, i)] * directions[pairs[p].0][r]).sum::<f64>()
    });
    let dq = lu.solve(rhs);
    along(model, friction, &holes, directions, &pairs, dq.as_ref())
}

/// The directions to compute, each with its mirror if one follows it: `(j, Some(k))` when
/// `directions[k] = −directions[j]`, `k > j` the first such not yet taken. Every direction is in
/// one pair, once.
fn mirror_pairs(directions: &[Vector6<f64>]) -> Vec<(usize, Option<usize>)> {
    let mut taken = vec![false; directions.len()];
    let mut pairs = Vec::with_capacity(directions.len());
    for (j, u) in directions.iter().enumerate() {
        if taken[j] {
            continue;
        }
        let mirror = (j + 1..directions.len()).find(|&k| !taken[k] && directions[k] == -u);
        if let Some(k) = mirror {
            taken[k] = true;
        }
        pairs.push((j, mirror));
    }
    pairs
}

/// The limit along each of `directions`, given the joint motions per unit `α` of each pair
/// of [`mirror_pairs`] (the columns of `dq`, n × pairs).
///
/// Every hole is checked, but most without computing their rates ([`HoleBounds`]: a bound
/// `g/(ρ max_{i∈S}|δQ_i|)` on when each is reached); the answer is the full pass's to the bit:
/// the same least `α`, and among equal ones the first hole and edge in its order (cable by
/// cable, hole by hole, lower edge first). Holes on an edge are computed along every direction,
/// in that order, since every one pushed over its edge is named.
fn along(
    model: &FrictionModel,
    friction: &FrictionData,
    holes: &[Hole],
    directions: &[Vector6<f64>],
    pairs: &[(usize, Option<usize>)],
    dq: MatRef<'_, f64>,
) -> Result<Vec<StickLoadLimit>, StiffnessError> {
    let n = dq.nrows();
    let mut out: Vec<StickLoadLimit> = directions
        .iter()
        .map(|u| StickLoadLimit {
            direction: *u,
            magnitude: f64::INFINITY,
            first: None,
            at_once: Vec::new(),
            joint_motion: Vec::new(),
        })
        .collect();
    for (p, &(j, mirror)) in pairs.iter().enumerate() {
        out[j].joint_motion = (0..n).map(|i| dq[(i, p)]).collect();
        if let Some(k) = mirror {
            out[k].joint_motion = (0..n).map(|i| -dq[(i, p)]).collect();
        }
    }
    // Per direction: the least `α` so far, with its hole's place in the full pass's order and
    // its event.
    let mut best: Vec<Best> = vec![(f64::INFINITY, usize::MAX, None); directions.len()];
    // The holes on an edge (every hole, along one pair of directions) hole by hole, every
    // direction for each, as the full pass: a segment's stretch `J_s δQ` computed once when it
    // is after one such hole and before the next, and a mirror's rates negated.
    let mut stretch = vec![0.0; pairs.len()];
    let exhaustive = pairs.len() == 1;
    // Each cable's rows, the workspace checked once: for the walk, then the holes skipped in it.
    friction.check_wrap_gradients()?;
    let cables = (0..model.cable_count())
        .map(|c| friction.cable(model, c))
        .collect::<Result<Vec<_>, _>>()?;
    let bounds = HoleBounds::walk(&cables, holes, n, exhaustive, |visit| {
        let (i, h, edges, [after, before, wrap], carried) = visit;
        for (&(j, mirror), stretch) in pairs.iter().zip(&mut stretch) {
            let dq = &out[j].joint_motion;
            let first = if carried { *stretch } else { dot(before, dq) };
            *stretch = dot(after, dq);
            let rates = [h.springs[1] * *stretch, h.springs[0] * first, dot(wrap, dq)];
            check(h, i, edges, rates, &mut best[j], &mut out[j].at_once);
            if let Some(k) = mirror {
                let rates = rates.map(|r| -r);
                check(h, i, edges, rates, &mut best[k], &mut out[k].at_once);
            }
        }
    })?;
    // The other holes, along each direction on which none of those slides at once.
    let mut scratch = Vec::new();
    for (limit, best) in out.iter_mut().zip(&mut best) {
        if limit.at_once.is_empty() {
            let (dq, at_once) = (&limit.joint_motion, &mut limit.at_once);
            bounds.search(dq, &mut scratch, best, |i, best| {
                let (h, rows) = (&holes[i], &cables[holes[i].cable]);
                let rates = [
                    h.springs[1] * dot(&rows.jacobian(h.hole + 1), dq),
                    h.springs[0] * dot(&rows.jacobian(h.hole), dq),
                    dot(&rows.wrap_gradient(h.hole)?, dq),
                ];
                check(h, i, &h.edges(), rates, best, at_once);
                Ok(())
            })?;
        }
        (limit.magnitude, limit.first) = match limit.at_once.first() {
            Some(&event) => (0.0, Some(event)),
            None => (best.0, best.2),
        };
    }
    Ok(out)
}

/// Hole `h` (place `i` in the full pass's order) under the rates `[δT_{k+1}, δT_k, δθ_k]` per
/// unit `α` (spring times stretch for the two segments; the free length's row is empty, and
/// the band's motion): each edge the increment approaches is pushed to `at_once` if the hole is
/// on it, else `best` is replaced if it is reached sooner (or as soon, by an earlier hole).
fn check(
    h: &Hole,
    i: usize,
    edges: &Edges,
    [dt_next, dt_k, dtheta]: [f64; 3],
    best: &mut Best,
    at_once: &mut Vec<HoleEvent>,
) {
    for &(edge, (a, b, d), g, on_edge) in edges {
        let dg = a * dt_next + b * dt_k + d * dtheta;
        let terms = (a * dt_next).abs() + (b * dt_k).abs() + (d * dtheta).abs();
        if dg >= -RATE_TOLERANCE * terms {
            continue;
        }
        if on_edge {
            at_once.push(h.event(edge));
        } else {
            let alpha = g / -dg;
            if alpha < best.0 || (alpha == best.0 && i < best.1) {
                *best = (alpha, i, Some(h.event(edge)));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The documented order: `+e_i` then `−e_i`, force x, y, z, then moment x, y, z.
    #[test]
    fn base_directions_are_in_their_documented_order() {
        let base = base_directions();
        for (k, u) in base.iter().enumerate() {
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            let expected = Vector6::from_fn(|i, _| if i == k / 2 { sign } else { 0.0 });
            assert_eq!(*u, expected, "direction {k}");
        }
    }

    /// Each direction is paired with the first later exact negation not yet taken, so that the
    /// base directions cost six solves, and a repeated direction is computed on its own.
    #[test]
    fn mirror_pairs_take_each_negation_once() {
        let pairs = mirror_pairs(&base_directions());
        let expected: Vec<_> = (0..6).map(|i| (2 * i, Some(2 * i + 1))).collect();
        assert_eq!(pairs, expected);
        let u = Vector6::new(0.3, 1.0, -0.2, 0.0, 0.0, 0.1);
        assert_eq!(mirror_pairs(&[u, -u, -u, u]), vec![(0, Some(1)), (2, Some(3))]);
        assert_eq!(mirror_pairs(&[u, -u, -u]), vec![(0, Some(1)), (2, None)]);
        assert_eq!(
            mirror_pairs(&[u, 0.5 * u, -(1.0 + 1e-15) * u]),
            vec![(0, None), (1, None), (2, None)]
        );
    }
}
