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

/// One task's rows of every result buffer: the rows are written in place by the task that
/// evaluates them, so nothing is copied after the parallel loop.
struct Part<'a> {
    ok: &'a mut [bool],
    stable: &'a mut [bool],
    min_eigenvalue: &'a mut [f64],
    t0: &'a mut [f64],
    tensions: &'a mut [f64],
    c_x: &'a mut [f64],
    k_x: &'a mut [f64],
    k_fd: &'a mut [f64],
}

/// Every result buffer of a batch, borrowed (row-major, `rows ×` the width of [`Batch`]'s
/// field of the same name): a batch's own, or the caller's (`evaluate_many(out=…)`, which
/// writes into a map's shared rows). Every entry is written once by its row, a value or NaN,
/// whatever the buffer held before.
#[derive(Debug)]
pub struct Outputs<'a> {
    /// As [`Batch::ok`].
    pub ok: &'a mut [bool],
    /// As [`Batch::stable`].
    pub stable: &'a mut [bool],
    /// As [`Batch::min_eigenvalue`].
    pub min_eigenvalue: &'a mut [f64],
    /// As [`Batch::t0`].
    pub t0: &'a mut [f64],
    /// As [`Batch::tensions`].
    pub tensions: &'a mut [f64],
    /// As [`Batch::c_x`].
    pub c_x: &'a mut [f64],
    /// As [`Batch::k_x`].
    pub k_x: &'a mut [f64],
    /// As [`Batch::k_fd`].
    pub k_fd: &'a mut [f64],
}

/// Evaluate every row of `q` (rows × dof, row-major) under the load `f0`: one wrench for
/// every row (`f0.len() == 1`) or one per row (`f0.len() == rows`). In parallel on the rayon
/// pool it is called in (the global pool outside any), each task writing its rows straight
/// into the result buffers.
pub fn evaluate_many(
    arm: &ArmStiffness,
    q: &[f64],
    f0: &[Vector6<f64>],
    choice: &BatchChoice,
) -> Batch {
    let dof = arm.dof();
    let cables = arm.routing().cable_count();
    let rows = q.len().checked_div(dof).unwrap_or(0);
    // Zeroed buffers (the allocator's zeroed pages, not written twice): every entry is then
    // written once by its row, a value or NaN.
    let mut batch = Batch {
        rows,
        dof,
        cables,
        ok: vec![false; rows],
        stable: vec![false; rows],
        min_eigenvalue: vec![0.0; rows],
        t0: vec![0.0; rows * dof],
        tensions: vec![0.0; rows * cables],
        c_x: vec![0.0; rows * 36],
        k_x: vec![0.0; rows * 36],
        k_fd: vec![0.0; rows * 9],
        errors: Vec::new(),
    };
    let out = Outputs {
        ok: &mut batch.ok,
        stable: &mut batch.stable,
        min_eigenvalue: &mut batch.min_eigenvalue,
        t0: &mut batch.t0,
        tensions: &mut batch.tensions,
        c_x: &mut batch.c_x,
        k_x: &mut batch.k_x,
        k_fd: &mut batch.k_fd,
    };
    batch.errors = evaluate_into(arm, q, f0, choice, out);
    batch
}

/// [`evaluate_many`] into the caller's buffers; the `(row, kind, message)` of every failed
/// row, in row order.
///
/// # Panics
///
/// When a buffer's length is not `rows ×` its width (the caller sizes them).
pub fn evaluate_into(
    arm: &ArmStiffness,
    q: &[f64],
    f0: &[Vector6<f64>],
    choice: &BatchChoice,
    out: Outputs<'_>,
) -> Vec<(usize, ErrorKind, String)> {
    let dof = arm.dof();
    let cables = arm.routing().cable_count();
    let rows = q.len().checked_div(dof).unwrap_or(0);
    let widths = [
        (out.ok.len(), 1),
        (out.stable.len(), 1),
        (out.min_eigenvalue.len(), 1),
        (out.t0.len(), dof),
        (out.tensions.len(), cables),
        (out.c_x.len(), 36),
        (out.k_x.len(), 36),
        (out.k_fd.len(), 9),
    ];
    assert!(widths.iter().all(|&(n, w)| n == rows * w), "evaluate_into: buffers of the wrong size");
    let parts: Vec<Part<'_>> = cut(out.ok, 1, rows)
        .zip(cut(out.stable, 1, rows))
        .zip(cut(out.min_eigenvalue, 1, rows))
        .zip(cut(out.t0, dof, rows))
        .zip(cut(out.tensions, cables, rows))
        .zip(cut(out.c_x, 36, rows))
        .zip(cut(out.k_x, 36, rows))
        .zip(cut(out.k_fd, 9, rows))
        .map(|(((((((ok, stable), min_eigenvalue), t0), tensions), c_x), k_x), k_fd)| Part {
            ok,
            stable,
            min_eigenvalue,
            t0,
            tensions,
            c_x,
            k_x,
            k_fd,
        })
        .collect();
    let errors: Vec<Vec<(usize, ErrorKind, String)>> = parts
        .into_par_iter()
        .enumerate()
        .map_init(
            || ArmStiffnessData::new(arm),
            |data, (chunk, mut part)| {
                let mut errors = Vec::new();
                for r in 0..part.ok.len() {
                    let index = chunk * CHUNK + r;
                    let qr = &q[index * dof..(index + 1) * dof];
                    let f0 = wrench_of_row(f0, index);
                    if let Err((kind, message)) = row(arm, data, qr, f0, choice, &mut part, r) {
                        fail(&mut part, r, dof, cables);
                        errors.push((index, kind, message));
                    }
                }
                errors
            },
        )
        .collect();
    errors.into_iter().flatten().collect()
}

/// `buffer` (`rows × width`, row-major) cut into the tasks' blocks of [`CHUNK`] rows, one block
/// per task even when `width` is 0 (an empty slice then).
fn cut<T>(mut buffer: &mut [T], width: usize, rows: usize) -> impl Iterator<Item = &mut [T]> {
    (0..rows.div_ceil(CHUNK)).map(move |task| {
        let n = width * CHUNK.min(rows - task * CHUNK);
        let (block, rest) = std::mem::take(&mut buffer).split_at_mut(n);
        buffer = rest;
        block
    })
}

/// Row `r` of `part` as a failed row: NaN everywhere, `ok` and `stable` false.
fn fail(part: &mut Part<'_>, r: usize, dof: usize, cables: usize) {
    part.ok[r] = false;
    part.stable[r] = false;
    part.min_eigenvalue[r] = f64::NAN;
    part.t0[r * dof..(r + 1) * dof].fill(f64::NAN);
    part.tensions[r * cables..(r + 1) * cables].fill(f64::NAN);
    part.c_x[r * 36..(r + 1) * 36].fill(f64::NAN);
    part.k_x[r * 36..(r + 1) * 36].fill(f64::NAN);
    part.k_fd[r * 9..(r + 1) * 9].fill(f64::NAN);
}

/// Row `r`'s wrench: the one wrench of every row, or its own.
pub fn wrench_of_row(f0: &[Vector6<f64>], r: usize) -> &Vector6<f64> {
    if f0.len() == 1 { &f0[0] } else { &f0[r] }
}

/// One row: the arm's checks (limits, finiteness) and evaluation, written into row `r` of
/// `part`; the error's kind and message when the row fails (the caller then fills it with NaN).
fn row(
    arm: &ArmStiffness,
    data: &mut ArmStiffnessData,
    q: &[f64],
    f0: &Vector6<f64>,
    choice: &BatchChoice,
    part: &mut Part<'_>,
    r: usize,
) -> Result<(), (ErrorKind, String)> {
    let fail = |e: sinew::Error| crate::errors::message(e);
    let choice = match choice {
        BatchChoice::Levels(levels) => TensionChoice::Levels(levels),
        BatchChoice::Policy(p) => TensionChoice::Policy(*p),
        BatchChoice::Default => TensionChoice::Default,
    };
    // The arm refuses angles outside the limits and NaN in its pose stage.
    arm.evaluate_joints(data, q, f0, choice).map_err(|e| fail(e.into()))?;
    let end = arm.solve_end(data).map_err(|e| fail(e.into()))?;
    let outcome = data
        .outcome()
        .ok_or_else(|| (ErrorKind::Numerical, String::from("the evaluation left no outcome")))?;
    part.min_eigenvalue[r] = outcome.margin().map_err(|e| fail(e.into()))?;
    let (stable, full_rank) = (end.is_stable(), end.has_end_stiffness());
    part.ok[r] = true;
    part.stable[r] = stable;
    let (dof, cables) = (arm.dof(), arm.routing().cable_count());
    part.t0[r * dof..(r + 1) * dof].copy_from_slice(&data.statics.t0);
    part.tensions[r * cables..(r + 1) * cables].copy_from_slice(data.tensions());
    let (c_x, k_x, k_fd) = (
        &mut part.c_x[r * 36..][..36],
        &mut part.k_x[r * 36..][..36],
        &mut part.k_fd[r * 9..][..9],
    );
    if stable {
        let c = data.compliance();
        for i in 0..6 {
            for j in 0..6 {
                c_x[6 * i + j] = c[(i, j)];
            }
        }
    } else {
        c_x.fill(f64::NAN);
    }
    if full_rank {
        let k = data.stiffness();
        for i in 0..6 {
            for j in 0..6 {
                k_x[6 * i + j] = k[(i, j)];
            }
        }
        let k = data.k_fd();
        for i in 0..3 {
            for j in 0..3 {
                k_fd[3 * i + j] = k[(i, j)];
            }
        }
    } else {
        k_x.fill(f64::NAN);
        k_fd.fill(f64::NAN);
    }
    Ok(())
}
