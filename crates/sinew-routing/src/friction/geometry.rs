//! The friction geometry at a configuration: every friction segment's length, direction and
//! `J_s`, every hole's wrap angle and its gradient (module docs of `crate::friction`).

use super::data::FrictionData;
use super::model::{Entry, FrictionModel};
use crate::error::{Result, RoutingError};
use crate::geometry::{Kinematics, RoutingData, length_derivative, segment_vector};
use crate::routing::{MIN_SEGMENT_LENGTH, Routing};
use crate::vec3::{cross, dot, rotate, scale, sub, transform};

/// Below this `|u_k × u_{k+1}|` (the sine of the wrap angle) a hole is at the kink of `θ`
/// (θ within about 1e-12 rad of 0, or of π): its angle is kept exact and its gradient is 0, the
/// least-norm subgradient (module docs of `crate::friction`). Far above rounding (1e-16), far
/// below any wrap a real arm has.
pub const WRAP_KINK: f64 = 1e-12;

/// The friction geometry at the configuration `routing_data` was last evaluated at: per cable,
/// every friction segment's length `ℓ_s`, direction `u_s` and Jacobian row `J_s`, and every
/// hole's wrap angle `θ_k` and its gradient `∂θ_k/∂Q`, into `data`. Any regime's weights must
/// be computed again after it ([`crate::compute_capstan_weights`]).
///
/// Allocates nothing. On error `data` holds nothing valid.
///
/// # Math
/// Module docs of `crate::friction`: `J_s[i] = u_s · (a_i × (o_p_B − p_i))` (eq. 3, the routing's
/// own formula, so `Σ_s J_s = J_c` bit for bit), `θ_k = atan2(|u_k × u_{k+1}|, u_k · u_{k+1})`,
/// `∂θ_k/∂q_i = −(∂u_k/∂q_i)·(n × u_k) + (∂u_{k+1}/∂q_i)·(n × u_{k+1})`, with
/// `∂u/∂q_i · g = (∂d/∂q_i · g) / ℓ` for `g ⊥ u`, `∂o_p/∂q_i = a_i × (o_p − p_i)` for a hole on a
/// body after joint `i`, and `∂u_0/∂q_i = a_i × u_0`. Cost `O(Σ_s |dofs_s| + Σ_k |wrap dofs_k|)`.
///
/// # Errors
/// [`RoutingError::WorkspaceMismatch`] for a model, routing workspace or friction workspace of
/// another routing; [`RoutingError::NotComputed`] before `routing_data` was evaluated;
/// [`RoutingError::DegenerateSegment`] for a segment shorter than [`crate::MIN_SEGMENT_LENGTH`].
pub fn compute_friction_geometry(
    model: &FrictionModel,
    routing: &Routing,
    routing_data: &RoutingData,
    data: &mut FrictionData,
) -> Result<()> {
    model.check(routing)?;
    routing_data.check(routing)?;
    data.check(model)?;
    routing_data.need(crate::Order::Lengths, "routing geometry (for the friction geometry)")?;
    data.geometry = false;
    data.slip = None;
    let kinematics = routing_data.kinematics();
    let segment_lengths = routing_data.segment_lengths()?;
    for (c, range) in model.cables.iter().enumerate() {
        let entries = &model.entries[range.clone()];
        let first = range.start;
        // Hole positions, then each segment's length, direction and J_s.
        for (s, entry) in entries.iter().enumerate() {
            let frame = kinematics.0.get(entry.hole_body).ok_or_else(|| mismatch(model.dof))?;
            data.positions[first + s] = transform(frame, &entry.hole_point);
        }
        let entry_frame =
            kinematics.0.get(entries[0].hole_body).ok_or_else(|| mismatch(model.dof))?;
        data.lengths[first] = model.free_length[c];
        data.directions[first] = rotate(entry_frame, &model.entry_direction[c]);
        for (s, entry) in entries.iter().enumerate().skip(1) {
            let r = entry.routing.ok_or_else(|| mismatch(model.dof))?;
            let length = segment_lengths[r];
            let u = segment(routing, r, entry, kinematics, &data.positions[first + s - 1..], {
                let slot = &entry.jacobian;
                &mut data.jacobians[slot.offset..slot.offset + slot.dofs.len()]
            })?;
            data.lengths[first + s] = length;
            data.directions[first + s] = u;
        }
        // Wrap angles at every hole but the anchor.
        for k in 0..entries.len() - 1 {
            let e = first + k;
            let (u_in, u_out) = (data.directions[e], data.directions[e + 1]);
            let w = cross(&u_in, &u_out);
            let sine = dot(&w, &w).sqrt();
            data.wrap[e] = sine.atan2(dot(&u_in, &u_out));
            data.kinked[e] = sine < WRAP_KINK;
            let slot = &entries[k].wrap;
            let gradient = &mut data.wrap_gradients[slot.offset..slot.offset + slot.dofs.len()];
            if data.kinked[e] {
                gradient.fill(0.0);
                continue;
            }
            let n = scale(&w, 1.0 / sine);
            let (g_in, g_out) = (cross(&n, &u_in), cross(&n, &u_out));
            let holes = &data.positions[if k == 0 { e } else { e - 1 }..=e + 1];
            let bodies = [entries[k.saturating_sub(1)].hole_body, entries[k].hole_body];
            let ends = Ends { holes, bodies, out_body: entries[k + 1].hole_body, first: k == 0 };
            let lengths = (data.lengths[e], data.lengths[e + 1]);
            for (j, i) in slot.dofs.clone().enumerate() {
                let (axis, origin) = joint(kinematics, i, model.dof)?;
                let incoming = if k == 0 {
                    // The entry direction turns with hole 0's body.
                    if i < entries[0].hole_body { dot(&cross(axis, &u_in), &g_in) } else { 0.0 }
                } else {
                    dot(&ends.in_motion(axis, origin, i), &g_in) / lengths.0
                };
                let outgoing = dot(&ends.out_motion(axis, origin, i), &g_out) / lengths.1;
                gradient[j] = outgoing - incoming;
            }
        }
        data.wrap[first + entries.len() - 1] = 0.0;
        data.kinked[first + entries.len() - 1] = false;
    }
    data.geometry = true;
    Ok(())
}

/// Friction segment `entry` (routing segment `r`): its unit direction away from the actuator,
/// and `J_s` written into `jacobian`. `holes` starts at the segment's first hole (base frame).
fn segment(
    routing: &Routing,
    r: usize,
    entry: &Entry,
    (frames, axes, origins): Kinematics<'_>,
    holes: &[[f64; 3]],
    jacobian: &mut [f64],
) -> Result<[f64; 3]> {
    let seg = &routing.segments[r];
    let dof = routing.dof;
    let degenerate = |length: f64| RoutingError::DegenerateSegment {
        cable: routing.cables.get(seg.cable).map(|c| c.name.clone()).unwrap_or_default(),
        segment: seg.index,
        length,
        min: MIN_SEGMENT_LENGTH,
    };
    if seg.dofs.is_empty() {
        // Within one body: a constant length, a direction that turns with the body.
        let d = sub(&holes[1], &holes[0]);
        let length = dot(&d, &d).sqrt();
        if length.is_nan() || length < MIN_SEGMENT_LENGTH {
            return Err(degenerate(length));
        }
        return Ok(scale(&d, 1.0 / length));
    }
    let (Some(frame_a), Some(frame_b)) =
        (frames.get(seg.proximal.body), frames.get(seg.distal.body))
    else {
        return Err(mismatch(dof));
    };
    // The routing's own formula for the segment (proximal body to distal body), so that J_s is
    // its share of J_c bit for bit; turned to point away from the actuator after.
    let (o_p_b, d, length) = segment_vector(frame_a, frame_b, seg);
    if length.is_nan() || length < MIN_SEGMENT_LENGTH {
        return Err(degenerate(length));
    }
    let u = scale(&d, 1.0 / length);
    let lo = seg.dofs.start;
    for (k, out) in jacobian.iter_mut().enumerate() {
        let (Some(a), Some(p)) = (axes.get(lo + k), origins.get(lo + k)) else {
            return Err(mismatch(dof));
        };
        *out = length_derivative(a, p, &o_p_b, &u).1;
    }
    Ok(if entry.reversed { scale(&u, -1.0) } else { u })
}

/// The three holes around hole `k` (base frame) and what moves them, for `∂d/∂q_i` of the
/// segments arriving at (`d_in = hole_k − hole_{k−1}`) and leaving (`d_out = hole_{k+1} −
/// hole_k`) hole `k`.
struct Ends<'a> {
    /// Holes `k − 1, k, k + 1` (`k, k + 1` when `first`).
    holes: &'a [[f64; 3]],
    /// Bodies of holes `k − 1` and `k` (both hole 0's when `first`).
    bodies: [usize; 2],
    /// Body of hole `k + 1`.
    out_body: usize,
    /// Whether `k = 0` (no segment arrives: the entry direction does).
    first: bool,
}

impl Ends<'_> {
    /// `∂d_in/∂q_i` (not used when `first`).
    fn in_motion(&self, axis: &[f64; 3], origin: &[f64; 3], i: usize) -> [f64; 3] {
        let (before, at) = (&self.holes[0], &self.holes[1]);
        sub(
            &motion(axis, origin, i, at, self.bodies[1]),
            &motion(axis, origin, i, before, self.bodies[0]),
        )
    }

    /// `∂d_out/∂q_i`.
    fn out_motion(&self, axis: &[f64; 3], origin: &[f64; 3], i: usize) -> [f64; 3] {
        let at = usize::from(!self.first);
        let (hole, next) = (&self.holes[at], &self.holes[at + 1]);
        sub(
            &motion(axis, origin, i, next, self.out_body),
            &motion(axis, origin, i, hole, self.bodies[1]),
        )
    }
}

/// `∂o_p/∂q_i = a_i × (o_p − p_i)` for a hole on `body` (0 unless joint `i` moves it: `i < body`).
fn motion(axis: &[f64; 3], origin: &[f64; 3], i: usize, hole: &[f64; 3], body: usize) -> [f64; 3] {
    if i < body { cross(axis, &sub(hole, origin)) } else { [0.0; 3] }
}

/// Joint `i`'s axis and origin (base frame).
fn joint<'a>(
    (_, axes, origins): Kinematics<'a>,
    i: usize,
    dof: usize,
) -> Result<(&'a [f64; 3], &'a [f64; 3])> {
    match (axes.get(i), origins.get(i)) {
        (Some(a), Some(p)) => Ok((a, p)),
        _ => Err(mismatch(dof)),
    }
}

fn mismatch(dof: usize) -> RoutingError {
    RoutingError::WorkspaceMismatch { what: "routing workspace (joints)", expected: dof, got: 0 }
}
