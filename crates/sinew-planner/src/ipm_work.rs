//! The interior-point planner's workspace (`ipm.rs`): the problem of each phase, the run's
//! buffers, the floors' scratch, the smooth objective's buffers and the phases' points, kept
//! between plans, so that a cold plan allocates only its answer once the workspace has the
//! room; and the checks of a point the phases make in it (a Cholesky trial of the margin, `K_x`,
//! a floor's value, the compliance).

use nalgebra::{Matrix6, Vector3};

use crate::blocks::{Floor, Scratch};
use crate::dense::{cholesky, cholesky_solve};
use crate::frame::Frame;
use crate::sdp::{Sdp, SolveWork};
use crate::smooth::{EndBuffers, EndObjective};

/// The buffers of the interior-point phases.
#[derive(Debug, Default)]
pub(crate) struct IpmWork {
    /// The problem of the phase running.
    pub(crate) sdp: Sdp,
    /// The run's buffers; after a run, its last iterate.
    pub(crate) run: SolveWork,
    /// The floor blocks' scratch.
    pub(crate) scratch: Scratch,
    /// The smooth objective's buffers, and those of `K_x` at a point.
    pub(crate) end: EndBuffers,
    /// `R`, a basis of `null(J_r)` (n × (n − 3)), when a floor needs it and `J_r` has rank 3
    /// (empty otherwise); the Gram–Schmidt scratch.
    pub(crate) rotation_null: Vec<f64>,
    pub(crate) basis: Vec<f64>,
    /// The phases' point (the frame's coordinates), a copy of it, and a run's start (the point
    /// with its epigraph variable).
    pub(crate) x: Vec<f64>,
    pub(crate) from: Vec<f64>,
    pub(crate) start: Vec<f64>,
    /// n × n scratch (a factor of `A(x)`), and two n-vectors.
    pub(crate) a: Vec<f64>,
    pub(crate) b: Vec<f64>,
    pub(crate) z: Vec<f64>,
}

/// `A(x) − m I` into `a` (n × n, resized).
fn shifted(frame: &Frame, x: &[f64], m: f64, a: &mut Vec<f64>) {
    let n = frame.n;
    a.clear();
    a.resize(n * n, 0.0);
    frame.a_at(x, a);
    for i in 0..n {
        a[i * n + i] -= m;
    }
}

/// Whether `λ_min(A(x)) > m`: one Cholesky trial of `A(x) − m I` (in `a`).
pub(crate) fn margin_exceeds(frame: &Frame, x: &[f64], m: f64, a: &mut Vec<f64>) -> bool {
    shifted(frame, x, m, a);
    cholesky(a, frame.n)
}

/// `K_x` at `x` (`None` where `A ⊁ 0` or `J_x` has rank < 6), in the buffers `end`.
pub(crate) fn k_x_at(frame: &Frame, x: &[f64], end: &mut EndBuffers) -> Option<Matrix6<f64>> {
    let mut objective = EndObjective::end_only(frame, std::mem::take(end));
    let k_x = objective.end_at(x).map(|e| e.k_x);
    *end = objective.into_buffers();
    k_x
}

/// The least `τ` with `K_fd ⪰ τ K` at `x` (the generalised eigenvalue).
pub(crate) fn floor_value(
    frame: &Frame,
    x: &[f64],
    floor: &Floor,
    end: &mut EndBuffers,
) -> Option<f64> {
    let k_fd = k_x_at(frame, x, end)?.fixed_view::<3, 3>(0, 0).into_owned();
    let l = floor.k.cholesky()?.l();
    let l_inv = l.try_inverse()?;
    let m = l_inv * k_fd * l_inv.transpose();
    Some(nalgebra::SymmetricEigen::new(0.5 * (m + m.transpose())).eigenvalues.min())
}

/// `uᵀ J_p A⁻¹ J_pᵀ u` at `x` (`None` where `A ⊁ 0`); `a` (n × n), `b` and `z` scratch.
pub(crate) fn compliance_at(
    frame: &Frame,
    x: &[f64],
    u: &Vector3<f64>,
    (a, b, z): (&mut Vec<f64>, &mut Vec<f64>, &mut Vec<f64>),
) -> Option<f64> {
    let n = frame.n;
    shifted(frame, x, 0.0, a);
    if !cholesky(a, n) {
        return None;
    }
    b.clear();
    b.extend((0..n).map(|r| (0..3).map(|i| frame.j_x[i * n + r] * u[i]).sum::<f64>()));
    z.clone_from(b);
    cholesky_solve(a, n, z);
    Some(b.iter().zip(z.iter()).map(|(p, q)| p * q).sum())
}
