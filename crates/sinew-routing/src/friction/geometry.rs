//! The friction geometry at a configuration: every friction segment's length, direction and
//! `J_s`, every hole's wrap angle and its gradient (module docs of `crate::friction`).

use super::data::FrictionData;
use super::lanes::{atan2_all, sqrt_all};
use super::model::{Entry, FrictionModel};
use crate::error::{Result, RoutingError};
use crate::geometry::{Kinematics, RoutingData, length_derivative};
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
/// It is [`compute_friction_angles`] then [`compute_wrap_gradients`]: a caller that needs no
/// `∂θ_k/∂Q` (the stick regime's stiffness, spec §9) calls the first alone.
///
/// Allocates nothing. On error `data` holds nothing valid.
///
/// # Math
/// Module docs of `crate::friction`: `J_s[i] = u_s · (a_i × (o_p_B − p_i))` (eq. 3, the routing's
/// own formula, so `Σ_s J_s = J_c` bit for bit), `θ_k = atan2(|u_k × u_{k+1}|, u_k · u_{k+1})`,
/// `∂θ_k/∂q_i = −(∂u_k/∂q_i)·(n × u_k) + (∂u_{k+1}/∂q_i)·(n × u_{k+1})`, with
/// `∂u/∂q_i · g = (∂d/∂q_i · g) / ℓ` for `g ⊥ u`, `∂o_p/∂q_i = a_i × (o_p − p_i)` for a hole on a
/// body after joint `i`, and `∂u_0/∂q_i = a_i × u_0`. A joint that moves both ends of a
/// segment (or the entry direction) turns it rigidly, and its term is then `a_i · n` exactly,
/// not a difference of two moved ends (`Turn`). Cost `O(Σ_s |dofs_s| + Σ_k |wrap dofs_k|)`.
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
    compute_friction_angles(model, routing, routing_data, data)?;
    compute_wrap_gradients(model, data)
}

/// The friction geometry without the wrap gradients: every friction segment's length `ℓ_s`,
/// direction `u_s` and `J_s`, every hole's wrap angle `θ_k` (module docs of
/// `crate::friction`), at the configuration `routing_data` was last evaluated at. What the
/// stick regime's statics and stiffness read; [`compute_wrap_gradients`] adds `∂θ_k/∂Q` (the
/// slip regimes, the directional response and the stick load limit need them). Until then
/// [`FrictionData::wrap_gradient`] and [`FrictionData::weight_gradient`] answer
/// [`RoutingError::FrictionNotComputed`], and so does [`crate::CableRows::wrap_gradient`].
///
/// Allocates nothing. On error `data` holds nothing valid.
///
/// # Errors
/// As [`compute_friction_geometry`].
pub fn compute_friction_angles(
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
    data.gradients = false;
    data.slip = None;
    let kinematics = routing_data.kinematics();
    let segment_lengths = routing_data.segment_lengths()?;
    let j_c = routing_data.jacobian_entries().ok();
    let m = model.cables.len();
    let routing_directions = routing_data.directions();
    // Each joint's axis `a_i` and moment `m_i = a_i × p_i`, kept for the wrap gradients:
    // `(a_i × (x − p_i))·g = a_i·(x × g) − g·m_i`.
    for (i, (a, m)) in data.axes.iter_mut().zip(&mut data.moments).enumerate() {
        let (axis, origin) = joint(kinematics, i, model.dof)?;
        (*a, *m) = (*axis, cross(axis, origin));
    }
    // The body poses, kept for the wrap gradients' hole positions.
    if kinematics.0.len() != data.frames.len() {
        return Err(mismatch(model.dof));
    }
    data.frames.copy_from_slice(kinematics.0);
    // A hole in the base frame.
    let place = |entry: &Entry| match kinematics.0.get(entry.hole_body) {
        Some(frame) => Ok(transform(frame, &entry.hole_point)),
        None => Err(mismatch(model.dof)),
    };
    // The free lengths: along each cable's entry direction, turned with its first hole's body.
    for (c, range) in model.cables.iter().enumerate() {
        let first = range.start;
        let body = model.entries.get(first).map(|e| e.hole_body);
        let entry_frame =
            body.and_then(|b| kinematics.0.get(b)).ok_or_else(|| mismatch(model.dof))?;
        data.lengths[first] = model.free_length[c];
        data.directions[first] = rotate(entry_frame, &model.entry_direction[c]);
    }
    // Each other segment's length, direction and J_s. With the routing's Jacobian at hand
    // (Order::Jacobian and above) and its directions kept (`RoutingData::keep_segment_directions`),
    // a segment across joints of a cable whose segments cross distinct DOFs copies them: its
    // J_s is J_c over its DOFs, its direction the routing's (`FrictionModel::copied`, packed).
    // Either way the same operations ran on the same holes: the same bits.
    let copy = j_c.zip(routing_directions);
    if let Some((j_c, directions)) = copy {
        for s in &model.copied {
            let (Some(u), Some(&length)) =
                (directions.get(s.routing), segment_lengths.get(s.routing))
            else {
                return Err(mismatch(model.dof));
            };
            data.directions[s.entry] = *u;
            data.lengths[s.entry] = length;
            let jacobian = &mut data.jacobians[s.offset..s.offset + s.dofs];
            for (out, i) in jacobian.iter_mut().zip(s.dofs_start..) {
                *out = j_c.get(s.cable + i * m).copied().ok_or_else(|| mismatch(model.dof))?;
            }
        }
    }
    // A segment within one body: its body-frame direction turned, no J_s.
    for s in &model.turned {
        let (Some(frame), Some(&length)) =
            (kinematics.0.get(s.body), segment_lengths.get(s.routing))
        else {
            return Err(mismatch(model.dof));
        };
        data.directions[s.entry] = rotate(frame, &s.direction);
        data.lengths[s.entry] = length;
    }
    // The other segments across joints (and, without the routing's Jacobian or directions,
    // the copied ones too), from their holes by the routing's formula: J_s, and the direction
    // unless the routing kept it (turned for a segment run distal to proximal).
    let copied = model.copied.iter().map(|s| s.entry).filter(|_| copy.is_none());
    for e in model.placed.iter().copied().chain(copied) {
        let entry = &model.entries[e];
        let r = entry.routing.ok_or_else(|| mismatch(model.dof))?;
        let slot = &entry.jacobian;
        let jacobian = &mut data.jacobians[slot.offset..slot.offset + slot.dofs.len()];
        let routed = match routing_directions {
            Some(u) if !entry.jacobian.dofs.is_empty() => {
                let u = u.get(r).ok_or_else(|| mismatch(model.dof))?;
                Some(if entry.reversed { scale(u, -1.0) } else { *u })
            }
            _ => None,
        };
        // The segment's two holes, in cable order.
        let holes = [place(&model.entries[e - 1])?, place(entry)?];
        data.directions[e] = segment(routing, r, entry, kinematics, &holes, routed, jacobian)?;
        data.lengths[e] = segment_lengths[r];
    }
    // Each hole's squared sine and cosine; the anchors' (0, 1) give θ = 0.
    let [sines, cosines] = &mut data.scratch;
    let pairs = data.directions.windows(2).zip(sines.iter_mut().zip(cosines.iter_mut()));
    for (u, (sine, cosine)) in pairs {
        let w = cross(&u[0], &u[1]);
        (*sine, *cosine) = (dot(&w, &w), dot(&u[0], &u[1]));
    }
    for range in &model.cables {
        let anchor = range.end - 1;
        (sines[anchor], cosines[anchor]) = (0.0, 1.0);
    }
    // Every hole's sine (the norm of the bend, as `bend` computes it) and `atan2` at once:
    // `libm`'s `atan2` (musl's, < 1 ulp) bit for bit, several holes to a vector register
    // (`lanes.rs`).
    let [sines, cosines] = &mut data.scratch;
    sqrt_all(sines);
    atan2_all(sines, cosines, &mut data.wrap);
    for (kinked, sine) in data.kinked.iter_mut().zip(sines.iter()) {
        *kinked = *sine < WRAP_KINK;
    }
    for range in &model.cables {
        // The anchor has no wrap angle, and no kink.
        data.kinked[range.end - 1] = false;
    }
    data.geometry = true;
    Ok(())
}

/// The wrap gradients `∂θ_k/∂Q` of every hole (module docs of `crate::friction`) at the
/// configuration of the last [`compute_friction_angles`], from what that call left in `data`
/// (the holes, directions, bends and joints at that configuration), so the two always agree.
/// Does nothing when they are already computed; [`compute_friction_geometry`] is both calls.
///
/// Allocates nothing.
///
/// # Errors
/// [`RoutingError::WorkspaceMismatch`] for a workspace of another model;
/// [`RoutingError::FrictionNotComputed`] before [`compute_friction_angles`].
pub fn compute_wrap_gradients(model: &FrictionModel, data: &mut FrictionData) -> Result<()> {
    data.check(model)?;
    if !data.geometry {
        return Err(RoutingError::FrictionNotComputed {
            what: "friction geometry (for the wrap gradients)",
            call: "compute_friction_angles",
        });
    }
    if data.gradients {
        return Ok(());
    }
    // Every hole in the base frame, at the angles' configuration.
    for (position, entry) in data.positions.iter_mut().zip(&model.entries) {
        let frame = data.frames.get(entry.hole_body).ok_or_else(|| mismatch(model.dof))?;
        *position = transform(frame, &entry.hole_point);
    }
    for range in &model.cables {
        let entries = &model.entries[range.clone()];
        let first = range.start;
        for k in 0..entries.len() - 1 {
            let e = first + k;
            let (u_in, u_out) = (data.directions[e], data.directions[e + 1]);
            let slot = &entries[k].wrap;
            let gradient = &mut data.wrap_gradients[slot.offset..slot.offset + slot.dofs.len()];
            if data.kinked[e] {
                gradient.fill(0.0);
                continue;
            }
            let (w, sine) = bend(&u_in, &u_out);
            let n = scale(&w, 1.0 / sine);
            let (g_in, g_out) = (cross(&n, &u_in), cross(&n, &u_out));
            let (at, b_at) = (data.positions[e], entries[k].hole_body);
            // Incoming: the entry direction turns with hole 0's body (k = 0), else the segment
            // from hole k − 1; outgoing: the segment to hole k + 1.
            let incoming = if k == 0 {
                Turn { rigid: b_at, lone: b_at, moment: [0.0; 3], scale: 0.0 }
            } else {
                let ends = [(data.positions[e - 1], entries[k - 1].hole_body), (at, b_at)];
                Turn::of_segment(ends, &g_in, data.lengths[e])
            };
            let ends = [(at, b_at), (data.positions[e + 1], entries[k + 1].hole_body)];
            let outgoing = Turn::of_segment(ends, &g_out, data.lengths[e + 1]);
            for (out, i) in gradient.iter_mut().zip(slot.dofs.clone()) {
                let axis = data.axes.get(i).ok_or_else(|| mismatch(model.dof))?;
                let m = data.moments.get(i).ok_or_else(|| mismatch(model.dof))?;
                let turned = dot(axis, &n);
                *out = outgoing.along(i, axis, m, &g_out, turned)
                    - incoming.along(i, axis, m, &g_in, turned);
            }
        }
    }
    data.gradients = true;
    Ok(())
}

/// A hole's bend from its two directions: `u_in × u_out` and its norm, the sine of the wrap
/// angle.
#[inline]
fn bend(u_in: &[f64; 3], u_out: &[f64; 3]) -> ([f64; 3], f64) {
    let w = cross(u_in, u_out);
    (w, dot(&w, &w).sqrt())
}

/// How joint `i` turns one of a hole's two directions `u` (unit), as `(∂u/∂q_i) · g` for
/// `g = n × u` (`n` the unit normal of the hole's bend), the term `∂θ/∂q_i` takes from that side.
///
/// - A joint before every body that moves the direction (`i < rigid`) turns it rigidly:
///   `(a_i × u) · (n × u) = a_i · n` (`u ⊥ n`, `|u| = 1`), the same value on both sides of the
///   hole, so a joint before every body of the two cancels exactly.
/// - A joint between a segment's two bodies (`rigid ≤ i < lone`) moves its end on the higher
///   body alone: `±(a_i · (x × g) − g · m_i) / ℓ`, with `x` that end, `m_i = a_i × p_i`, the sign
///   `+` when it is the segment's far end (`d = x − other end`), else `−`.
/// - A joint from the higher body on moves neither end: 0.
///
/// The entry direction turns rigidly with hole 0's body (`rigid = lone` = that body).
struct Turn {
    rigid: usize,
    lone: usize,
    /// `x × g` of the end that moves alone.
    moment: [f64; 3],
    /// `±1/ℓ`.
    scale: f64,
}

impl Turn {
    /// The segment with its two ends `(position, body)` in cable order, `g = n × u` for its
    /// direction `u`, and its length.
    fn of_segment(ends: [([f64; 3], usize); 2], g: &[f64; 3], length: f64) -> Turn {
        let [(start, b_start), (end, b_end)] = ends;
        let (x, sign) = if b_end >= b_start { (end, 1.0) } else { (start, -1.0) };
        let (rigid, lone) = (b_start.min(b_end), b_start.max(b_end));
        Turn { rigid, lone, moment: cross(&x, g), scale: sign / length }
    }

    /// Its term for joint `i` (axis `a`, moment `m`), `turned = a · n`.
    #[inline]
    fn along(&self, i: usize, a: &[f64; 3], m: &[f64; 3], g: &[f64; 3], turned: f64) -> f64 {
        if i < self.rigid {
            turned
        } else if i < self.lone {
            (dot(a, &self.moment) - dot(g, m)) * self.scale
        } else {
            0.0
        }
    }
}

/// Routing segment `r`'s unit direction away from the actuator from its two holes `holes`
/// (base frame, in cable order), checked for length as the routing checks it.
fn direction(routing: &Routing, r: usize, holes: &[[f64; 3]; 2]) -> Result<[f64; 3]> {
    let d = sub(&holes[1], &holes[0]);
    let length = dot(&d, &d).sqrt();
    if length.is_nan() || length < MIN_SEGMENT_LENGTH {
        let seg = &routing.segments[r];
        return Err(RoutingError::DegenerateSegment {
            cable: routing.cables.get(seg.cable).map(|c| c.name.clone()).unwrap_or_default(),
            segment: seg.index,
            length,
            min: MIN_SEGMENT_LENGTH,
        });
    }
    Ok(scale(&d, 1.0 / length))
}

/// Friction segment `entry` (routing segment `r`): its unit direction away from the actuator
/// (`routed`, the routing's, when it has one), and `J_s` written into `jacobian` by the
/// routing's own formula (for a cable with two segments across one DOF, where `J_c` holds their
/// sum). `holes` are the segment's two holes in cable order (base frame).
fn segment(
    routing: &Routing,
    r: usize,
    entry: &Entry,
    (_, axes, origins): Kinematics<'_>,
    holes: &[[f64; 3]; 2],
    routed: Option<[f64; 3]>,
    jacobian: &mut [f64],
) -> Result<[f64; 3]> {
    let seg = &routing.segments[r];
    let u = match routed {
        Some(u) => u,
        None => direction(routing, r, holes)?,
    };
    if seg.dofs.is_empty() {
        return Ok(u);
    }
    // The routing's formula on its own orientation (proximal to distal body).
    let (o_p_b, u_seg) = if entry.reversed { (holes[0], scale(&u, -1.0)) } else { (holes[1], u) };
    let lo = seg.dofs.start;
    for (k, out) in jacobian.iter_mut().enumerate() {
        let (Some(a), Some(p)) = (axes.get(lo + k), origins.get(lo + k)) else {
            return Err(mismatch(routing.dof));
        };
        *out = length_derivative(a, p, &o_p_b, &u_seg).1;
    }
    Ok(u)
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
