//! The directional response after a history (spec §9, #27): the end's compliance along `+u`
//! and along `−u`, each hole on an edge of its band sticking or sliding as the increment drives
//! it. After a pull or release every hole sits on an edge, so the two directions differ:
//! hysteresis.
//!
//! # Math
//! One elastic model (module docs of `friction.rs`): every piece of cable is a spring
//! `k_s = E A/ℓ_s` (segment 0 the free length, the actuator held). Let `φ_k` be the cable that
//! passes through hole `k` per unit increment (m, positive away from the actuator); segment `s`
//! gains `δm_s = φ_{s−1} − φ_s` of unstretched length (`φ_{−1} = 0` at the actuator, and no flux
//! at the anchor), so `δT_s = k_s (J_s δQ − δm_s)`. A sticking hole has `φ_k = 0`; a hole
//! sliding at an edge keeps its tensions on that edge, `ġ = 0` (`holes.rs`). With the
//! equilibrium of the increment `δw = α u` on the end-effector (spec §5's sign):
//!
//! ```text
//! (K_stick + K_W) δQ + Σ_{k∈S} (k_k J_k − k_{k+1} J_{k+1})ᵀ φ_k = J_xᵀ u        (n rows)
//! a_k δT_{k+1} + b_k δT_k + d_k ∇θ_k · δQ = 0                       k ∈ S     (|S| rows)
//! ```
//!
//! per unit `α`: a square linear system in `(δQ, φ_S)` for a set `S` of sliding holes
//! ([`sliding_response`]). `S = ∅` is the stick regime; every hole sliding at its lower edge
//! after a pull is the pull slip regime (the system then reproduces `K_slip`, tested).
//!
//! **Which holes slide** is a small complementarity problem over the holes on an edge: a hole in
//! `S` must slide the way its edge allows (`φ ≤ 0` at the lower edge, toward the actuator;
//! `φ ≥ 0` at the upper one), and a hole on an edge outside `S` must not be pushed over it
//! (`ġ ≥ 0`). [`directional_response`] solves it exactly by an active-set pass: start from
//! `S = ∅`; while some hole in `S` slides the wrong way, drop the first one; else while some
//! edge hole outside `S` is pushed over its edge, add the first one; stop when neither happens
//! (the result is then consistent, and checked). It fails with
//! [`StiffnessError::NoConsistentSliding`] when the passes cycle, and with
//! [`StiffnessError::UnstableSliding`] when the consistent set's joint stiffness (the Schur
//! complement of the system on `δQ`) is not positive definite.
//!
//! The response is `uᵀ δx / α = uᵀ J_x δQ` (the end's compliance along `u`: m/N for a unit
//! force) and its inverse.

use faer::linalg::solvers::Solve;
use faer::{Mat, MatRef, Side};
use nalgebra::Vector6;
use sinew_routing::{FrictionData, FrictionModel, Routing};

use crate::error::StiffnessError;
use crate::friction::History;
use crate::holes::{BandEdge, Hole, HoleEvent, dot, holes};
use crate::holes::{EDGE_TOLERANCE, RATE_TOLERANCE};

/// The response along one signed direction.
#[derive(Debug, Clone, PartialEq)]
pub struct DirectionalResponse {
    /// The direction (`u` or `−u`), base frame, force then moment.
    pub direction: Vector6<f64>,
    /// `uᵀ δx` per unit `α`: the end's compliance along the direction (m/N for a unit force).
    pub compliance: f64,
    /// `1 / compliance` (N/m for a unit force).
    pub stiffness: f64,
    /// The holes that slide, with their edge, cable by cable, hole by hole.
    pub sliding: Vec<HoleEvent>,
    /// Per sliding hole, the cable passing through it per unit `α` (m, away from the actuator
    /// positive).
    pub flux: Vec<f64>,
    /// `δQ` per unit `α` (rad).
    pub joint_motion: Vec<f64>,
    /// Active-set passes taken (one linear solve each).
    pub passes: usize,
}

/// The matrices of the increment: `K_stick`, `K_W` (dof × dof), `J_x` (6 × dof).
pub type Increment<'a> = (MatRef<'a, f64>, MatRef<'a, f64>, MatRef<'a, f64>);

/// `(δQ, φ)` per unit `α` for the increment `α u` with the holes of `sliding` sliding at their
/// edges and every other hole sticking (module docs). `k_stick` is the stick regime's joint
/// stiffness after `history` at `actuator` ([`crate::stick_stiffness`]).
///
/// # Errors
/// Those of [`crate::stick_load_limits`]; [`StiffnessError::NoConsistentSliding`] when the
/// system is singular (one hole named twice, or the two edges of one hole).
pub fn sliding_response(
    model: &FrictionModel,
    routing: &Routing,
    friction: &FrictionData,
    history: History,
    actuator: &[f64],
    increment: Increment<'_>,
    u: &Vector6<f64>,
    sliding: &[HoleEvent],
) -> Result<(Vec<f64>, Vec<f64>), StiffnessError> {
    let holes = holes(model, routing, friction, history, actuator)?;
    let system = System::new(model, friction, &holes, increment, sliding)?;
    system.solve(u)
}

/// The response along `u` and along `−u` after `history` at `actuator` (module docs).
///
/// # Errors
/// Those of [`crate::stick_load_limits`]; [`StiffnessError::NoConsistentSliding`],
/// [`StiffnessError::UnstableSliding`].
pub fn directional_response(
    model: &FrictionModel,
    routing: &Routing,
    friction: &FrictionData,
    history: History,
    actuator: &[f64],
    increment: Increment<'_>,
    u: &Vector6<f64>,
) -> Result<[DirectionalResponse; 2], StiffnessError> {
    if !u.iter().all(|x| x.is_finite()) || u.norm() == 0.0 {
        return Err(StiffnessError::InvalidWrenchDirection { direction: (*u).into() });
    }
    let holes = holes(model, routing, friction, history, actuator)?;
    let on_edge: Vec<(usize, BandEdge)> = (0..holes.len())
        .flat_map(|i| [(i, BandEdge::Lower), (i, BandEdge::Upper)])
        .filter(|&(i, edge)| holes[i].room(edge) <= EDGE_TOLERANCE * holes[i].scale())
        .collect();
    let mut out = Vec::with_capacity(2);
    for direction in [*u, -u] {
        out.push(one_way(model, friction, &holes, increment, &on_edge, direction)?);
    }
    let [plus, minus]: [DirectionalResponse; 2] =
        out.try_into().map_err(|_| StiffnessError::NoConsistentSliding { passes: 0 })?;
    Ok([plus, minus])
}

/// The active-set pass along one signed direction.
fn one_way(
    model: &FrictionModel,
    friction: &FrictionData,
    holes: &[Hole],
    increment: Increment<'_>,
    on_edge: &[(usize, BandEdge)],
    u: Vector6<f64>,
) -> Result<DirectionalResponse, StiffnessError> {
    let mut sliding: Vec<(usize, BandEdge)> = Vec::new();
    let max_passes = 2 * on_edge.len() + 2;
    for passes in 1..=max_passes {
        let events: Vec<HoleEvent> = sliding.iter().map(|&(i, e)| holes[i].event(e)).collect();
        let system = System::new(model, friction, holes, increment, &events)?;
        let (dq, flux) = system.solve(&u)?;
        let scale = flux.iter().fold(0.0_f64, |m, f| m.max(f.abs()));
        // A hole sliding the wrong way sticks; else an edge hole pushed over its edge slides.
        let wrong = sliding
            .iter()
            .zip(&flux)
            .position(|(&(_, edge), f)| edge.flux_sign() * f < -1e-12 * scale);
        if let Some(k) = wrong {
            sliding.remove(k);
            continue;
        }
        let mut pushed = None;
        for &(i, edge) in on_edge {
            let taken = sliding.iter().any(|&(j, _)| j == i);
            if !taken && system.edge_rate(&holes[i], edge, &dq, &flux)? < 0.0 {
                pushed = Some((i, edge));
                break;
            }
        }
        if let Some(p) = pushed {
            let at = sliding.partition_point(|&(j, _)| j < p.0);
            sliding.insert(at, p);
            continue;
        }
        system.check_stable()?;
        let compliance: f64 = (0..6)
            .map(|r| u[r] * (0..dq.len()).map(|i| increment.2[(r, i)] * dq[i]).sum::<f64>())
            .sum();
        return Ok(DirectionalResponse {
            direction: u,
            compliance,
            stiffness: 1.0 / compliance,
            sliding: events,
            flux,
            joint_motion: dq,
            passes,
        });
    }
    Err(StiffnessError::NoConsistentSliding { passes: max_passes })
}

/// The square system of one sliding set, assembled and factorised.
struct System<'a> {
    model: &'a FrictionModel,
    friction: &'a FrictionData,
    /// The sliding holes: `(cable, hole)` and their column `n + i`.
    sliding: Vec<(usize, usize)>,
    n: usize,
    lu: faer::linalg::solvers::PartialPivLu<f64>,
    j_x: MatRef<'a, f64>,
}

impl<'a> System<'a> {
    fn new(
        model: &'a FrictionModel,
        friction: &'a FrictionData,
        holes: &[Hole],
        (k_stick, k_w, j_x): Increment<'a>,
        sliding: &[HoleEvent],
    ) -> Result<System<'a>, StiffnessError> {
        let n = k_stick.nrows();
        for (what, expected, got) in [
            ("K_stick", n, k_stick.ncols()),
            ("K_W", n, k_w.nrows()),
            ("K_W", n, k_w.ncols()),
            ("J_x (rows)", 6, j_x.nrows()),
            ("J_x (columns)", n, j_x.ncols()),
            ("friction model (joints)", n, model.dof()),
        ] {
            if expected != got {
                return Err(StiffnessError::DimensionMismatch { what, expected, got });
            }
        }
        let p = sliding.len();
        let mut a = Mat::zeros(n + p, n + p);
        for j in 0..n {
            for i in 0..n {
                a[(i, j)] = k_stick[(i, j)] + k_w[(i, j)];
            }
        }
        let keys: Vec<(usize, usize)> = sliding.iter().map(|e| (e.cable, e.hole)).collect();
        let column = |c: usize, k: usize| keys.iter().position(|&key| key == (c, k));
        for (i, e) in sliding.iter().enumerate() {
            let h = holes
                .iter()
                .find(|h| h.cable == e.cable && h.hole == e.hole)
                .ok_or(StiffnessError::NoConsistentSliding { passes: 0 })?;
            let [k_k, k_next] = h.springs;
            // Column n + i: (k_k J_k − k_{k+1} J_{k+1})ᵀ in the equilibrium rows.
            for (s, spring, sign) in [(e.hole, k_k, 1.0), (e.hole + 1, k_next, -1.0)] {
                if s > 0 {
                    let j_s = friction.segment_jacobian(model, e.cable, s)?;
                    for (v, d) in j_s.values.iter().zip(j_s.dofs) {
                        a[(d, n + i)] += sign * spring * v;
                    }
                }
            }
            // Row n + i: ġ = a δT_{k+1} + b δT_k + d ∇θ·δQ = 0, δT_s = k_s (J_s δQ − δm_s).
            let (ca, cb, cd) = h.rate_coefficients(e.edge);
            for (s, spring, weight) in [(e.hole + 1, k_next, ca), (e.hole, k_k, cb)] {
                if s > 0 {
                    let j_s = friction.segment_jacobian(model, e.cable, s)?;
                    for (v, d) in j_s.values.iter().zip(j_s.dofs) {
                        a[(n + i, d)] += weight * spring * v;
                    }
                }
                // −k_s δm_s = −k_s (φ_{s−1} − φ_s).
                if let Some(col) = s.checked_sub(1).and_then(|k| column(e.cable, k)) {
                    a[(n + i, n + col)] -= weight * spring;
                }
                if let Some(col) = column(e.cable, s) {
                    a[(n + i, n + col)] += weight * spring;
                }
            }
            let grad = friction.wrap_gradient(model, e.cable, e.hole)?;
            for (v, d) in grad.values.iter().zip(grad.dofs) {
                a[(n + i, d)] += cd * v;
            }
        }
        let lu = a.partial_piv_lu();
        Ok(System { model, friction, sliding: keys, n, lu, j_x })
    }

    /// `(δQ, φ)` per unit `α` along `u`.
    fn solve(&self, u: &Vector6<f64>) -> Result<(Vec<f64>, Vec<f64>), StiffnessError> {
        let (n, p) = (self.n, self.sliding.len());
        let rhs = Mat::from_fn(n + p, 1, |i, _| {
            if i < n { (0..6).map(|r| self.j_x[(r, i)] * u[r]).sum::<f64>() } else { 0.0 }
        });
        let x = self.lu.solve(rhs);
        if !(0..n + p).all(|i| x[(i, 0)].is_finite()) {
            return Err(StiffnessError::NoConsistentSliding { passes: 0 });
        }
        Ok(((0..n).map(|i| x[(i, 0)]).collect(), (n..n + p).map(|i| x[(i, 0)]).collect()))
    }

    /// `δT_s` of cable `c` for the solution `(dq, flux)`.
    fn tension_rate(
        &self,
        (c, s, spring): (usize, usize, f64),
        dq: &[f64],
        flux: &[f64],
    ) -> Result<f64, StiffnessError> {
        let stretch =
            if s > 0 { dot(&self.friction.segment_jacobian(self.model, c, s)?, dq) } else { 0.0 };
        let phi =
            |k: usize| self.sliding.iter().position(|&key| key == (c, k)).map_or(0.0, |i| flux[i]);
        let gained = s.checked_sub(1).map_or(0.0, phi) - phi(s);
        Ok(spring * (stretch - gained))
    }

    /// `ġ` of `hole` at `edge` for the solution, 0 within [`RATE_TOLERANCE`] of its terms.
    fn edge_rate(
        &self,
        hole: &Hole,
        edge: BandEdge,
        dq: &[f64],
        flux: &[f64],
    ) -> Result<f64, StiffnessError> {
        let (a, b, d) = hole.rate_coefficients(edge);
        let dt_next = self.tension_rate((hole.cable, hole.hole + 1, hole.springs[1]), dq, flux)?;
        let dt_k = self.tension_rate((hole.cable, hole.hole, hole.springs[0]), dq, flux)?;
        let dtheta = dot(&self.friction.wrap_gradient(self.model, hole.cable, hole.hole)?, dq);
        let rate = a * dt_next + b * dt_k + d * dtheta;
        let terms = (a * dt_next).abs() + (b * dt_k).abs() + (d * dtheta).abs();
        Ok(if rate.abs() <= RATE_TOLERANCE * terms { 0.0 } else { rate })
    }

    /// The joint stiffness with the sliding holes free, `K_eff` (the inverse of `A⁻¹`'s
    /// leading block), must have a positive definite symmetric part.
    fn check_stable(&self) -> Result<(), StiffnessError> {
        let (n, p) = (self.n, self.sliding.len());
        if p == 0 {
            return Ok(());
        }
        let inverse =
            self.lu.solve(Mat::<f64>::from_fn(n + p, n, |i, j| if i == j { 1.0 } else { 0.0 }));
        let block = Mat::from_fn(n, n, |i, j| inverse[(i, j)]);
        let k_eff = block.partial_piv_lu().solve(Mat::<f64>::identity(n, n));
        let sym = Mat::from_fn(n, n, |i, j| 0.5 * (k_eff[(i, j)] + k_eff[(j, i)]));
        if sym.llt(Side::Lower).is_ok() {
            return Ok(());
        }
        let least = sym
            .self_adjoint_eigenvalues(Side::Lower)
            .map_err(|_| StiffnessError::Eigen)?
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        Err(StiffnessError::UnstableSliding { holes: p, min_eigenvalue: least })
    }
}
