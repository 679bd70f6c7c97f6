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
//! already on an edge (`g ≤` [`EDGE_TOLERANCE`] `· (T_k + T_{k+1})`, as after a
//! [`History::Pull`] or [`History::Release`]) that the increment pushes outward slides at once:
//! the limit is 0 and every such hole is named ([`StickLoadLimit::at_once`]). From
//! [`History::Equal`] every band of a bent cable has room on both sides and the limit is
//! positive in every direction.
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
use crate::holes::{BandEdge, Hole, HoleEvent, dot, holes};

/// A hole is on an edge of its band when `g ≤ EDGE_TOLERANCE · (T_k + T_{k+1})`: a pull or
/// release distribution puts every hole on an edge up to the rounding of `e^{±μθ}` products
/// (1e-16 relative), and no band a real arm has is this narrow.
pub const EDGE_TOLERANCE: f64 = 1e-12;

/// An edge's rate `ġ` is taken as 0 (the increment neither approaches nor leaves the edge)
/// when `|ġ| ≤ RATE_TOLERANCE ·` the sum of its terms' magnitudes: cancellation, as at a hole
/// inside one body, whose segments keep their lengths and angle.
pub const RATE_TOLERANCE: f64 = 1e-10;

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
/// `K_stick + K_W`, one solve with a right-hand side per direction, and one pass over the
/// holes for every direction (module docs for the math).
///
/// # Errors
/// [`StiffnessError::StickWithoutFriction`] for a cable with μ = 0;
/// [`StiffnessError::WrongCapstanWeights`]; [`StiffnessError::InvalidWrenchDirection`] for a
/// zero or non-finite direction; [`StiffnessError::Unstable`] when `K_stick + K_W` is not
/// positive definite; [`StiffnessError::DimensionMismatch`]; routing errors.
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
    // Every direction's joint motion in one solve with as many right-hand sides, then one pass
    // over the holes for them all.
    let rhs = Mat::from_fn(n, directions.len(), |i, j| {
        (0..6).map(|r| j_x[(r, i)] * directions[j][r]).sum::<f64>()
    });
    let dq = lu.solve(rhs);
    along(model, friction, &holes, directions, dq.as_ref())
}

/// The limit along each of `directions`, given their joint motions per unit `α` (the columns
/// of `dq`, n × directions): one pass over the holes for every direction, each hole's
/// coefficients read once and each segment's stretch `J_s δQ` computed once per direction (it
/// is the stretch after one hole and before the next).
fn along(
    model: &FrictionModel,
    friction: &FrictionData,
    holes: &[Hole],
    directions: &[Vector6<f64>],
    dq: MatRef<'_, f64>,
) -> Result<Vec<StickLoadLimit>, StiffnessError> {
    let n = dq.nrows();
    let mut out: Vec<StickLoadLimit> = directions
        .iter()
        .enumerate()
        .map(|(j, u)| StickLoadLimit {
            direction: *u,
            magnitude: f64::INFINITY,
            first: None,
            at_once: Vec::new(),
            joint_motion: (0..n).map(|i| dq[(i, j)]).collect(),
        })
        .collect();
    // Each direction's stretch of the segment before the current hole.
    let mut stretch = vec![0.0; directions.len()];
    // The holes come cable by cable, hole by hole ([`holes`]): walk each cable's segments
    // (read once per cable) in step, segment `k` before hole `k` and `k + 1` after it.
    let mut pending = holes.iter();
    for c in 0..model.cable_count() {
        let mut segments = friction.segments(model, c)?.enumerate();
        let Some((_, mut before)) = segments.next() else {
            continue;
        };
        // The free length does not stretch (the actuator holds its end).
        stretch.fill(0.0);
        for (s, after) in segments {
            let h = match pending.next() {
                Some(h) if (h.cable, h.hole + 1) == (c, s) => h,
                _ => {
                    let expected = holes.len();
                    let what = "holes (cable by cable, in order)";
                    return Err(StiffnessError::DimensionMismatch { what, expected, got: s });
                }
            };
            let edges = [BandEdge::Lower, BandEdge::Upper].map(|edge| {
                let g = h.room(edge);
                (edge, h.rate_coefficients(edge), g, g <= EDGE_TOLERANCE * h.scale())
            });
            for (limit, stretch) in out.iter_mut().zip(stretch.iter_mut()) {
                let dq = &limit.joint_motion;
                // δT per unit α of the two segments: spring times stretch.
                let dt_k = h.springs[0] * *stretch;
                *stretch = dot(&after.jacobian, dq);
                let dt_next = h.springs[1] * *stretch;
                let dtheta = dot(&before.wrap_gradient, dq);
                for &(edge, (a, b, d), g, at_edge) in &edges {
                    let dg = a * dt_next + b * dt_k + d * dtheta;
                    let terms = (a * dt_next).abs() + (b * dt_k).abs() + (d * dtheta).abs();
                    if dg >= -RATE_TOLERANCE * terms {
                        continue;
                    }
                    if at_edge {
                        limit.at_once.push(h.event(edge));
                    } else if g / -dg < limit.magnitude {
                        limit.magnitude = g / -dg;
                        limit.first = Some(h.event(edge));
                    }
                }
            }
            before = after;
        }
    }
    for limit in &mut out {
        if let Some(&event) = limit.at_once.first() {
            (limit.magnitude, limit.first) = (0.0, Some(event));
        }
    }
    Ok(out)
}
