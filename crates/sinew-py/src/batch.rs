//! The batch kernel of `ArmStiffness.evaluate_many`, in plain Rust (no Python types): many
//! configurations in parallel (rayon), one workspace per thread, results written in place
//! into row-major buffers. `examples/batch_loop.rs` times it alone, the reference for the
//! Python call's overhead.

use nalgebra::Vector6;
use rayon::prelude::*;
use sinew::ErrorKind;
use sinew::statics::{TensionChoice, TensionPolicy};
use sinew::stiffness::{ArmStiffness, ArmStiffnessData};

/// How every row's tensions are chosen.
#[derive(Debug, Clone, PartialEq)]
pub enum BatchChoice {
    /// The paper's levels, the same for every row (one per joint).
    Levels(Vec<f64>),
    /// A policy over the equilibrium set.
    Policy(TensionPolicy),
    /// The library's default ([`TensionChoice::Default`]).
    Default,
}

/// The results of a batch, row-major; a failed row is NaN everywhere, `ok` false and its
/// error in `errors`; an unstable row is `ok`, not `stable`, NaN in `c_x`, `k_x`, `k_fd`.
#[derive(Debug, Clone, PartialEq)]
pub struct Batch {
    /// Rows.
    pub rows: usize,
    /// Degrees of freedom.
    pub dof: usize,
    /// Cables.
    pub cables: usize,
    /// Whether the row evaluated (statics solved; stable or not).
    pub ok: Vec<bool>,
    /// Whether `K_q + K_W` is positive definite.
    pub stable: Vec<bool>,
    /// `λ_min` of the symmetric part of `K_q + K_W` (rows × 1).
    pub min_eigenvalue: Vec<f64>,
    /// `T0` (rows × dof).
    pub t0: Vec<f64>,
    /// Tensions (rows × cables).
    pub tensions: Vec<f64>,
    /// `C_x` (rows × 36).
    pub c_x: Vec<f64>,
    /// `K_x` (rows × 36; NaN when `J_x` is rank-deficient).
    pub k_x: Vec<f64>,
    /// `K_fd` (rows × 9).
    pub k_fd: Vec<f64>,
    /// `(row, kind, message)` of every failed row, in row order.
    pub errors: Vec<(usize, ErrorKind, String)>,
}

/// Rows per parallel task.
const CHUNK: usize = 32;

/// Per-row scalars and the 6 × 6 / 3 × 3 results, written in place.
#[derive(Debug, Clone)]
struct Fixed {
    ok: bool,
    stable: bool,
    min_eigenvalue: f64,
    c_x: [f64; 36],
    k_x: [f64; 36],
    k_fd: [f64; 9],
    error: Option<(ErrorKind, String)>,
}

impl Fixed {
    fn nan() -> Fixed {
        Fixed {
            ok: false,
            stable: false,
            min_eigenvalue: f64::NAN,
            c_x: [f64::NAN; 36],
            k_x: [f64::NAN; 36],
            k_fd: [f64::NAN; 9],
            error: None,
        }
    }
}

/// Evaluate every row of `q` (rows × dof, row-major) under the load `f0`: one wrench for
/// every row (`f0.len() == 1`) or one per row (`f0.len() == rows`). In parallel on the rayon
/// pool it is called in (the global pool outside any).
pub fn evaluate_many(
    arm: &ArmStiffness,
    q: &[f64],
    f0: &[Vector6<f64>],
    choice: &BatchChoice,
) -> Batch {
    let dof = arm.dof();
    let cables = arm.routing().cable_count();
    let rows = q.len().checked_div(dof).unwrap_or(0);
    let mut fixed = vec![Fixed::nan(); rows];
    let mut t0 = vec![f64::NAN; rows * dof];
    let mut tensions = vec![f64::NAN; rows * cables];
    fixed
        .par_chunks_mut(CHUNK)
        .zip(t0.par_chunks_mut(CHUNK * dof.max(1)))
        .zip(tensions.par_chunks_mut(CHUNK * cables.max(1)))
        .zip(q.par_chunks(CHUNK * dof.max(1)))
        .enumerate()
        .for_each_init(
            || ArmStiffnessData::new(arm),
            |data, (chunk, (((fixed, t0), tensions), q))| {
                for (r, out) in fixed.iter_mut().enumerate() {
                    let qr = &q[r * dof..(r + 1) * dof];
                    let f0 = wrench_of_row(f0, chunk * CHUNK + r);
                    row(arm, data, qr, f0, choice, out);
                    if out.ok {
                        t0[r * dof..(r + 1) * dof].copy_from_slice(&data.statics.t0);
                        tensions[r * cables..(r + 1) * cables].copy_from_slice(data.tensions());
                    }
                }
            },
        );
    let mut batch = Batch {
        rows,
        dof,
        cables,
        ok: Vec::with_capacity(rows),
        stable: Vec::with_capacity(rows),
        min_eigenvalue: Vec::with_capacity(rows),
        t0,
        tensions,
        c_x: Vec::with_capacity(rows * 36),
        k_x: Vec::with_capacity(rows * 36),
        k_fd: Vec::with_capacity(rows * 9),
        errors: Vec::new(),
    };
    for (r, f) in fixed.into_iter().enumerate() {
        batch.ok.push(f.ok);
        batch.stable.push(f.stable);
        batch.min_eigenvalue.push(f.min_eigenvalue);
        batch.c_x.extend_from_slice(&f.c_x);
        batch.k_x.extend_from_slice(&f.k_x);
        batch.k_fd.extend_from_slice(&f.k_fd);
        if let Some((kind, message)) = f.error {
            batch.errors.push((r, kind, message));
        }
    }
    batch
}

/// Row `r`'s wrench: the one wrench of every row, or its own.
pub fn wrench_of_row(f0: &[Vector6<f64>], r: usize) -> &Vector6<f64> {
    if f0.len() == 1 { &f0[0] } else { &f0[r] }
}

/// One row: the arm's checks (limits, finiteness) and evaluation, into `out`.
fn row(
    arm: &ArmStiffness,
    data: &mut ArmStiffnessData,
    q: &[f64],
    f0: &Vector6<f64>,
    choice: &BatchChoice,
    out: &mut Fixed,
) {
    let fail = |out: &mut Fixed, e: sinew::Error| {
        out.error = Some(crate::errors::message(e));
    };
    let choice = match choice {
        BatchChoice::Levels(levels) => TensionChoice::Levels(levels),
        BatchChoice::Policy(p) => TensionChoice::Policy(*p),
        BatchChoice::Default => TensionChoice::Default,
    };
    // The arm refuses angles outside the limits and NaN in its pose stage.
    if let Err(e) = arm.evaluate_joints(data, q, f0, choice) {
        return fail(out, e.into());
    }
    let end = match arm.solve_end(data) {
        Ok(end) => end,
        Err(e) => return fail(out, e.into()),
    };
    let Some(outcome) = data.outcome() else { return };
    match outcome.margin() {
        Ok(m) => out.min_eigenvalue = m,
        Err(e) => return fail(out, e.into()),
    }
    let (stable, full_rank) = (end.is_stable(), end.has_end_stiffness());
    out.ok = true;
    out.stable = stable;
    if stable {
        let c = data.compliance();
        for i in 0..6 {
            for j in 0..6 {
                out.c_x[6 * i + j] = c[(i, j)];
            }
        }
    }
    if full_rank {
        let k = data.stiffness();
        for i in 0..6 {
            for j in 0..6 {
                out.k_x[6 * i + j] = k[(i, j)];
            }
        }
        let k_fd = data.k_fd();
        for i in 0..3 {
            for j in 0..3 {
                out.k_fd[3 * i + j] = k_fd[(i, j)];
            }
        }
    }
}
