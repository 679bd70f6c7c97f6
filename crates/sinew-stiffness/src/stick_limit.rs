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
use crate::friction::{History, axial_rigidity, check_weights};

/// A hole is on an edge of its band when `g ≤ EDGE_TOLERANCE · (T_k + T_{k+1})`: a pull or
/// release distribution puts every hole on an edge up to the rounding of `e^{±μθ}` products
/// (1e-16 relative), and no band a real arm has is this narrow.
pub const EDGE_TOLERANCE: f64 = 1e-12;

/// An edge's rate `ġ` is taken as 0 (the increment neither approaches nor leaves the edge)
/// when `|ġ| ≤ RATE_TOLERANCE ·` the sum of its terms' magnitudes: cancellation, as at a hole
/// inside one body, whose segments keep their lengths and angle.
pub const RATE_TOLERANCE: f64 = 1e-10;

/// Which edge of a hole's capstan band `T_k e^{−μθ} ≤ T_{k+1} ≤ T_k e^{+μθ}`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BandEdge {
    /// `T_{k+1} = T_k e^{−μθ_k}`: the cable slides toward the actuator (as in pull).
    Lower,
    /// `T_{k+1} = T_k e^{+μθ_k}`: the cable slides away from the actuator (as in release).
    Upper,
}

/// A hole reaching an edge of its band.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct HoleEvent {
    /// The cable (routing order, 0-based).
    pub cable: usize,
    /// The hole, 0-based along the cable from the actuator (between friction segments `hole`
    /// and `hole + 1`; the anchor has none).
    pub hole: usize,
    /// The edge it reaches.
    pub edge: BandEdge,
    /// Whether the hole is at the kink `θ ≈ 0` (module docs: its band has no width there).
    pub kinked: bool,
}

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
/// `K_stick + K_W`, then one solve per direction (module docs for the math).
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
    if let Some(cable) = model.friction_coefficients().iter().position(|&mu| mu <= 0.0) {
        return Err(StiffnessError::StickWithoutFriction { cable });
    }
    if let Some(slip) = history.slip() {
        check_weights(friction, slip)?;
    }
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
    let mut out = Vec::with_capacity(directions.len());
    for u in directions {
        let rhs = Mat::from_fn(n, 1, |i, _| (0..6).map(|r| j_x[(r, i)] * u[r]).sum::<f64>());
        let dq = lu.solve(rhs);
        let dq: Vec<f64> = (0..n).map(|i| dq[(i, 0)]).collect();
        out.push(along(model, routing, friction, history, actuator, u, dq)?);
    }
    Ok(out)
}

/// The limit along `u`, given its joint motion `dq` per unit `α`.
fn along(
    model: &FrictionModel,
    routing: &Routing,
    friction: &FrictionData,
    history: History,
    actuator: &[f64],
    u: &Vector6<f64>,
    dq: Vec<f64>,
) -> Result<StickLoadLimit, StiffnessError> {
    let ea = axial_rigidity(routing);
    let mu = model.friction_coefficients();
    let mut best = (f64::INFINITY, None);
    let mut at_once = Vec::new();
    for (c, &t_0) in actuator.iter().enumerate() {
        let lengths = friction.lengths(model, c)?;
        let weights = match history {
            History::Equal => None,
            History::Pull | History::Release => Some(friction.weights(model, c)?),
        };
        let tension = |s: usize| weights.map_or(t_0, |w| t_0 * w[s]);
        // δT_s per unit α: the segment's spring times its stretch; the free length's is 0.
        let rate = |s: usize| -> Result<f64, StiffnessError> {
            if s == 0 {
                return Ok(0.0);
            }
            let j_s = friction.segment_jacobian(model, c, s)?;
            let stretch: f64 = j_s.values.iter().zip(j_s.dofs).map(|(v, d)| v * dq[d]).sum();
            Ok(ea / lengths[s] * stretch)
        };
        let (angles, kinked) = (friction.wrap_angles(model, c)?, friction.kinked(model, c)?);
        for (k, (&theta, &kinked)) in angles.iter().zip(kinked).enumerate() {
            let grad = friction.wrap_gradient(model, c, k)?;
            let dtheta: f64 = grad.values.iter().zip(grad.dofs).map(|(v, d)| v * dq[d]).sum();
            let (t_k, t_next) = (tension(k), tension(k + 1));
            let (dt_k, dt_next) = (rate(k)?, rate(k + 1)?);
            let (lo, hi) = ((-mu[c] * theta).exp(), (mu[c] * theta).exp());
            let turn = mu[c] * t_k * dtheta;
            let edges = [
                (BandEdge::Lower, t_next - t_k * lo, dt_next - lo * (dt_k - turn), lo),
                (BandEdge::Upper, t_k * hi - t_next, hi * (dt_k + turn) - dt_next, hi),
            ];
            for (edge, g, dg, e) in edges {
                let terms = dt_next.abs() + e * (dt_k.abs() + turn.abs());
                if dg >= -RATE_TOLERANCE * terms {
                    continue;
                }
                let event = HoleEvent { cable: c, hole: k, edge, kinked };
                if g <= EDGE_TOLERANCE * (t_k + t_next) {
                    at_once.push(event);
                } else if g / -dg < best.0 {
                    best = (g / -dg, Some(event));
                }
            }
        }
    }
    let (magnitude, first) = match at_once.first() {
        Some(&event) => (0.0, Some(event)),
        None => best,
    };
    Ok(StickLoadLimit { direction: *u, magnitude, first, at_once, joint_motion: dq })
}
