//! When tension stiffens (spec §10, conclusion (1)'s condition): the sign of a universal
//! joint's controllable stiffness per unit of its tension coordinate, in closed form at the
//! straight pose and numerically at any pose.
//!
//! # Math
//!
//! The joint's three cables hold a torque with tensions `f = f_p + λ N` (eq. 22–23; `N` the unit
//! null direction of `J_cᵀ`, every component positive under force closure, `λ` the tension
//! coordinate). The joint stiffness `K = Σ_c f_c H_c + J_cᵀ K_l J_c` (eq. 11–14, restoring sign,
//! spec §3) is affine in `λ`, and its rate is the controllable stiffness along `N`:
//!
//! ```text
//! A_i = ∂K/∂λ = Σ_c N_c H_c,        H_c = ∂²L_c/∂q²  (2 × 2, m/rad²)                    (E7.1)
//! ```
//!
//! `A_i ⪰ 0`: more tension, more stiffness (the paper's conclusion (1)); `A_i ⪯ 0`: tension
//! softens the joint; indefinite: it stiffens one direction and softens another.
//!
//! **The single cable at Q0.** Eq. 1, `T = Trans(0,0,d1) · Rot(x,q1) · Rot(y,q2) ·
//! Trans(0,0,d2)`, with the cable's hole `p = (r cos θ, r sin θ, 0)` on the proximal disc `O_i`
//! and `p' = (r cos θ, r sin θ, 0)` on the distal disc `O'_i`. With `a = d1 e_z − p` (hole to
//! joint centre) and `b = p' + d2 e_z` (joint centre to distal hole, in the distal frame), the
//! cable vector of eq. 2 is `v = a + R(q) b` and
//!
//! ```text
//! S = L² = |a|² + |b|² + 2 aᵀ R(q) b,        |a|² + |b|² = d1² + d2² + 2r²                (E7.2)
//! ```
//!
//! At `q = 0`, `aᵀ b = d1 d2 − r²`, so `L0 = d1 + d2` (the hole planes' gap, positive).
//! `∂R/∂q_k = [ω_k]×` with `ω_1 = e_x`, `ω_2 = e_y`, and `aᵀ [ω]× b = ω · (b × a)` with
//! `b × a = (d1 + d2) r (sin θ, −cos θ, 0)`, so `∂S/∂q = 2 L0 J` with `J = r (sin θ, −cos θ)` (the
//! row of eq. 3). The second derivatives: `aᵀ [ω_j]×[ω_k]× b = (a·ω_k)(ω_j·b) − (a·b)(ω_j·ω_k)`,
//!
//! ```text
//! ∂²S/∂q² = 2 [ r² sin²θ − d1 d2,   −r² sin θ cos θ ;  −r² sin θ cos θ,   r² cos²θ − d1 d2 ]
//!         = 2 (J Jᵀ − d1 d2 I)                                                           (E7.3)
//! ```
//!
//! and `H = ∂²S/(2L) − ∂S ∂Sᵀ/(4L³) = (J Jᵀ − d1 d2 I)/L0 − J Jᵀ/L0`:
//!
//! ```text
//! H_c(Q0) = −(d1 d2 / (d1 + d2)) I₂        for every cable, whatever r and θ               (E7.4)
//! ```
//!
//! **The joint at Q0.** By (E7.1) and (E7.4), with `Σ_c N_c > 0` (`√3` for three holes 120°
//! apart, where `N = (1, 1, 1)/√3`):
//!
//! ```text
//! A_i(Q0) = c (Σ_c N_c) I₂,      c = −d1 d2 / (d1 + d2)                                    (E7.5)
//! ```
//!
//! So at the straight pose, with the hole planes apart (`d1 + d2 > 0`): `A_i ≻ 0` iff
//! `d1 d2 < 0` (the joint centre outside the gap between the hole planes), `A_i = 0` iff
//! `d1 d2 = 0` (a hole plane through the joint centre: the paper's `d2 ≈ 0`, cdhrm5's fitted
//! `d2 = 0`), `A_i ≺ 0` iff `d1 d2 > 0` (holes below and above the centre). Both eigenvalues
//! are equal: `A_i(Q0)` is never indefinite, and the hole radius `r` does not enter.
//!
//! **Away from Q0 the pose matters.** `H_c(q)` gains terms of second order in `q` that the
//! closed form does not have. On the boundary `d1 d2 = 0` they decide the sign (on cdhrm5,
//! `A_i ⪰ 0` at every pose of E7's 5 × 5 grid over its workspace); with `d1 d2 > 0` they make
//! `A_i` indefinite at bent poses once `r` is large against the gap, and with `d1 d2 < 0` too
//! when the gap is narrow (numbers, not a proof: E7's table and map). [`tension_stiffness`]
//! computes `A_i` at any pose from the routing's own `H_c` and the statics' `N`; the E7 map
//! (`e7.rs`) classifies over the workspace.

use nalgebra::{Matrix2, Matrix3x2, SymmetricEigen, Vector2};

use crate::robot::{Robot, RobotData, UniformChain};
use crate::routing::{Order, PerJoint, Routing, RoutingData, RoutingSpec, compute_cable_geometry};
use crate::statics::{TensionLimits, tension_interval};
use crate::stiffness::{joint_block, stiffness_slope};

/// The hole geometry of one universal joint (eq. 1), m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HoleGeometry {
    /// From the proximal disc's hole plane to the joint centre, along the arm's axis.
    pub d1: f64,
    /// From the joint centre to the distal disc's hole plane.
    pub d2: f64,
    /// Hole circle radius, the same on both discs.
    pub radius: f64,
}

/// The sign of `A_i = Σ_c N_c H_c` (E7.1): what raising the joint's tension does to it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum TensionEffect {
    /// `A_i ⪰ 0` and not 0: more tension, more stiffness (conclusion (1)).
    Stiffens,
    /// `A_i = 0` (both eigenvalues within the tolerance): tension leaves the stiffness alone.
    Neutral,
    /// Indefinite: tension stiffens one direction and softens another.
    Indefinite,
    /// `A_i ⪯ 0` and not 0: more tension, less stiffness.
    Softens,
}

impl TensionEffect {
    /// The class of eigenvalues `[λ_min, λ_max]`, each within `tol` of 0 counted as 0.
    pub fn of_eigenvalues([lo, hi]: [f64; 2], tol: f64) -> TensionEffect {
        match (lo < -tol, hi > tol) {
            (false, false) => TensionEffect::Neutral,
            (false, true) => TensionEffect::Stiffens,
            (true, false) => TensionEffect::Softens,
            (true, true) => TensionEffect::Indefinite,
        }
    }

    /// `A_i ⪰ 0` (stiffens or neutral): conclusion (1) holds, at least weakly.
    pub fn tension_never_softens(self) -> bool {
        matches!(self, TensionEffect::Stiffens | TensionEffect::Neutral)
    }

    /// `A_i ⪯ 0` (softens or neutral).
    pub fn tension_never_stiffens(self) -> bool {
        matches!(self, TensionEffect::Softens | TensionEffect::Neutral)
    }

    /// The report's words: `A_i ≻ 0`-like symbols and what they mean.
    pub fn label(self) -> &'static str {
        match self {
            TensionEffect::Stiffens => "A ⪰ 0: tension stiffens",
            TensionEffect::Neutral => "A = 0: tension neutral",
            TensionEffect::Indefinite => "A indefinite",
            TensionEffect::Softens => "A ⪯ 0: tension softens",
        }
    }
}

/// The closed form's scalar `c = −d1 d2 / (d1 + d2)` of (E7.5), m: `A_i(Q0) = c (Σ_c N_c) I₂`.
/// `NaN` unless the hole planes are apart (`d1 + d2 > 0`).
pub fn criterion_q0(d1: f64, d2: f64) -> f64 {
    if d1 + d2 > 0.0 { -d1 * d2 / (d1 + d2) } else { f64::NAN }
}

/// The classifier at Q0 (E7.5): by the sign of `−d1 d2` alone, `d1 d2` within `tol²` (m²) of
/// 0 counted as 0 (a hole plane through the joint centre). Never indefinite, and the radius
/// does not enter. `None` unless `d1 + d2 > 0`.
pub fn classify_q0(d1: f64, d2: f64, tol: f64) -> Option<TensionEffect> {
    if d1 + d2 <= 0.0 || !(d1.is_finite() && d2.is_finite()) {
        return None;
    }
    let product = d1 * d2;
    Some(if product.abs() <= tol * tol {
        TensionEffect::Neutral
    } else if product < 0.0 {
        TensionEffect::Stiffens
    } else {
        TensionEffect::Softens
    })
}

/// The eigenvalues `[λ_min, λ_max]` of a symmetric 2 × 2 matrix.
pub fn eigenvalues(a: &Matrix2<f64>) -> [f64; 2] {
    let sym = 0.5 * (a + a.transpose());
    let e = SymmetricEigen::new(sym).eigenvalues;
    [e[0].min(e[1]), e[0].max(e[1])]
}

/// The tolerance below which an eigenvalue of `A_i` counts as 0 for a geometry, m: `1e-9` of
/// its size `r + |d1| + |d2|` (rounding in `H_c` is about `1e-16` of it).
pub fn zero_tolerance(g: &HoleGeometry) -> f64 {
    1e-9 * (g.radius + g.d1.abs() + g.d2.abs())
}

/// One joint alone with geometry `g` and the cables of `template` (a routing file of the
/// pattern form, e.g. cdhrm5's `cables.toml`): a one-joint chain of [`UniformChain`] with
/// cdhrm5's link (φ60 × 220 mm, 0.24 kg, ±π/6) and the template's first joint's cables
/// (material, limits, θ0, free length), on a hole circle of radius `g.radius` on both discs.
///
/// # Errors
/// A template without the pattern form, or a geometry the loaders refuse.
pub fn single_joint(
    template: &RoutingSpec,
    g: HoleGeometry,
) -> Result<(Robot, Routing), crate::Error> {
    let chain = UniformChain {
        name: "e7_joint".to_owned(),
        joints: 1,
        d1: g.d1,
        d2: g.d2,
        link_length: 0.22,
        link_radius: 0.03,
        total_mass: 0.24,
        limit: std::f64::consts::FRAC_PI_6,
        gravity: nalgebra::Vector3::zeros(),
    };
    let robot = chain.build()?;
    let mut spec = template.clone();
    spec.free_length = spec.free_length.as_ref().and_then(|v| v.get(0)).map(PerJoint::Uniform);
    let pattern = spec.pattern.as_mut().ok_or_else(|| crate::routing::RoutingError::Parse {
        file: "<e7 template>".to_owned(),
        message: "E7 needs a routing of the pattern form".to_owned(),
    })?;
    pattern.radius = Some(PerJoint::Uniform(g.radius));
    pattern.proximal_radius = None;
    pattern.distal_radius = None;
    pattern.proximal_discs = vec!["base_link".to_owned()];
    pattern.distal_discs = vec!["link1".to_owned()];
    pattern.cables.clear();
    let routing = Routing::new(&robot, &spec, "<e7 single joint>")?;
    Ok((robot, routing))
}

/// The geometry of joint `joint` of a robot and its pattern routing: `d1` the joint's origin
/// above its proximal disc (the URDF's `joint{i}_x`), `d1 + d2` the length at Q = 0 of its
/// first cable (both hole circles of radius `radius`, so the cable runs straight along the axis).
///
/// # Errors
/// Geometry errors; a joint without cables.
pub fn joint_geometry(
    robot: &Robot,
    routing: &Routing,
    joint: usize,
    radius: f64,
) -> Result<HoleGeometry, crate::Error> {
    let d1 = robot.joints().get(2 * joint).map_or(f64::NAN, |j| j.origin.translation.vector.z);
    let mut data = RobotData::new(robot);
    let mut g = RoutingData::new(routing);
    let q = vec![0.0; robot.dof()];
    compute_cable_geometry(routing, robot, &mut data, &mut g, &q, Order::Jacobian)?;
    let cable = routing.cables_of_joint(joint).start;
    let gap = g.lengths()?.get(cable).copied().unwrap_or(f64::NAN);
    Ok(HoleGeometry { d1, d2: gap - d1, radius })
}

/// `A_i = Σ_c N_c H_c` (E7.1) of joint 0 of a one-joint robot at angles `q`, N m/rad per N:
/// `H_c` the routing's Hessians, `N` the unit null direction of the statics' tension interval
/// (eq. 22–23, components summing to ≥ 0), and `Σ_c δf_c H_c` at `δf = N` by
/// `sinew_stiffness::stiffness_slope`.
///
/// # Errors
/// Angles the robot refuses, a rank-deficient `J_c` (no null direction).
pub fn tension_stiffness(
    robot: &Robot,
    routing: &Routing,
    q: [f64; 2],
) -> Result<Matrix2<f64>, crate::Error> {
    let mut data = RobotData::new(robot);
    let mut g = RoutingData::new(routing);
    let mut angles = vec![0.0; robot.dof()];
    angles[..2].copy_from_slice(&q);
    compute_cable_geometry(routing, robot, &mut data, &mut g, &angles, Order::Hessians)?;
    let own = routing.cables_of_joint(0);
    let j = g.jacobian()?;
    let block = Matrix3x2::from_fn(|r, c| j[(own.start + r, c)]);
    // Only the null direction is used; the limits are wide so that no torque is refused.
    let limits = TensionLimits { f_min: 0.0, f_max: f64::MAX };
    let interval = tension_interval(0, &block, &Vector2::zeros(), limits)?;
    let mut f = vec![0.0; routing.cable_count()];
    f[own.start..own.start + 3].copy_from_slice(interval.null.as_slice());
    let n = robot.dof();
    let mut slope = faer::Mat::zeros(n, n);
    stiffness_slope(routing, &g, &f, slope.as_mut())?;
    joint_block(slope.as_ref(), 0).ok_or_else(|| {
        crate::indicators::IndicatorError::NoSuchJoint { joint: 0, joints: n / 2 }.into()
    })
}
