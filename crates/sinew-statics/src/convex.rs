//! The crate's one caller of `clarabel` (a pure Rust interior-point LP/QP solver): its
//! settings, dense matrices to CSC, the small inequality programs of the tension policies
//! ([`crate::TensionPolicy`]) and the force-closure LP ([`crate::EquilibriumSet::force_closure`]).
//!
//! # Math
//! Every program here is `min ½ xᵀ P x + qᵀ x` subject to `A x ≤ b` (clarabel's `A x + s = b`,
//! `s ≥ 0`), with `P = I` (a QP) or `P = 0` (an LP). A solved program gives its optimum `x`; an
//! infeasible one clarabel's certificate `z ≥ 0` (one entry per row of `A`, `Aᵀ z = 0`,
//! `bᵀ z < 0`), which the policies read back as a joint motion.
//!
//! This file imports no other file of the crate but the error type and the closed form's
//! [`crate::FORCE_CLOSURE_TOLERANCE`]: the equilibrium set and the policies both call it.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use faer::MatRef;

use crate::error::{SolverStop, StaticsError};
use crate::interval::FORCE_CLOSURE_TOLERANCE;

/// A dense `rows × cols` matrix, given entry by entry by `at(row, column)`, as clarabel's
/// compressed sparse columns, built with its triplet constructor
/// ([`CscMatrix::new_from_triplets`]).
///
/// Exact zeros (`0.0` and `-0.0`) are skipped; every other entry is kept, NaN included. The
/// entries are read column by column, each column from the top, which is the order in which
/// they are stored: the same matrix as filling `colptr`, `rowval` and `nzval` by hand in that
/// order. Used by the tension policies here and by `sinew-planner`'s bundle subproblems.
pub fn dense_csc(rows: usize, cols: usize, at: impl Fn(usize, usize) -> f64) -> CscMatrix<f64> {
    let (mut row_of, mut column_of, mut value) = (Vec::new(), Vec::new(), Vec::new());
    for c in 0..cols {
        for r in 0..rows {
            let v = at(r, c);
            if v != 0.0 {
                row_of.push(r);
                column_of.push(c);
                value.push(v);
            }
        }
    }
    CscMatrix::new_from_triplets(rows, cols, row_of, column_of, value)
}

/// The solver's settings: quiet, no equilibration (the rows are unit-scaled cable tensions
/// already), otherwise clarabel's defaults.
fn settings() -> DefaultSettings<f64> {
    DefaultSettings { verbose: false, equilibrate_enable: false, ..DefaultSettings::default() }
}

/// What [`solve`] found.
pub(crate) enum Solved {
    /// The optimum `x` (solved or almost solved) and the interior-point iterations.
    Point { x: Vec<f64>, iterations: u32 },
    /// The program is (almost) primal infeasible: the certificate `z` (one entry per row of
    /// `A`).
    Infeasible { z: Vec<f64> },
}

/// `min ½ xᵀ P x + qᵀ x` subject to `A x ≤ b`, with `P = I` when `quadratic`, else `P = 0`;
/// `a` has one column per variable and `b` one entry per row.
///
/// # Errors
/// [`StaticsError::Solver`] when clarabel refuses the program or ends other than solved or
/// infeasible.
pub(crate) fn solve(
    quadratic: bool,
    q: &[f64],
    a: &CscMatrix<f64>,
    b: &[f64],
) -> Result<Solved, StaticsError> {
    let n = a.n;
    let p = if quadratic { CscMatrix::identity(n) } else { CscMatrix::zeros((n, n)) };
    let cones = [SupportedConeT::NonnegativeConeT(b.len())];
    let mut solver = DefaultSolver::new(&p, q, a, b, &cones, settings())
        .map_err(|_| StaticsError::Solver { stop: SolverStop::Setup })?;
    solver.solve();
    let solution = solver.solution;
    match solution.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => {
            Ok(Solved::Point { x: solution.x, iterations: solution.iterations })
        }
        SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
            Ok(Solved::Infeasible { z: solution.z })
        }
        status => Err(StaticsError::Solver { stop: SolverStop::from_status(status) }),
    }
}

/// Whether some strictly positive tension vector lies in the span of the orthonormal basis
/// `null` (m × k) of `null(J_cᵀ)`: maximise `t` with `N λ ≥ t`, `|λ_i| ≤ 1` (an LP in
/// `(λ, t)`); closure when `t >` [`FORCE_CLOSURE_TOLERANCE`] (with one null direction, `t` is
/// the least component of the unit direction oriented positive, the closed form's test).
/// `false` when `k = 0`.
///
/// # Errors
/// [`StaticsError::Solver`] when the LP solver fails.
pub(crate) fn force_closure(null: MatRef<'_, f64>) -> Result<bool, StaticsError> {
    let (m, k) = (null.nrows(), null.ncols());
    if k == 0 {
        return Ok(false);
    }
    let n = k + 1;
    let rows = m + 2 * k;
    let a = dense_csc(rows, n, |r, c| {
        if r < m {
            if c < k { -null[(r, c)] } else { 1.0 }
        } else if c == (r - m) % k && c < k {
            if r < m + k { 1.0 } else { -1.0 }
        } else {
            0.0
        }
    });
    let mut b = vec![0.0; rows];
    b[m..].fill(1.0);
    let mut q = vec![0.0; n];
    q[k] = -1.0;
    match solve(false, &q, &a, &b)? {
        Solved::Point { x, .. } => Ok(x[k] > FORCE_CLOSURE_TOLERANCE),
        // λ = 0, t = −1 is feasible: an infeasibility report is the solver's failure.
        Solved::Infeasible { .. } => {
            Err(StaticsError::Solver { stop: SolverStop::FalseInfeasibility })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The CSC matrix filled by hand, column by column, skipping exact zeros: what the crate
    /// and the planner built before [`dense_csc`].
    fn by_hand(rows: usize, cols: usize, at: impl Fn(usize, usize) -> f64) -> CscMatrix<f64> {
        let mut colptr = vec![0];
        let (mut rowval, mut nzval) = (Vec::new(), Vec::new());
        for c in 0..cols {
            for r in 0..rows {
                let v = at(r, c);
                if v != 0.0 {
                    rowval.push(r);
                    nzval.push(v);
                }
            }
            colptr.push(rowval.len());
        }
        CscMatrix::new(rows, cols, colptr, rowval, nzval)
    }

    #[test]
    fn dense_csc_is_the_matrix_filled_by_hand() {
        let entries = |r: usize, c: usize| match (r * 7 + c * 3) % 5 {
            0 => 0.0,
            1 => -0.0,
            k => (k as f64 - 2.5) * (1.0 + r as f64) / (1.0 + c as f64),
        };
        for (rows, cols) in [(0, 0), (0, 3), (4, 0), (1, 1), (6, 4), (9, 5), (3, 11)] {
            assert_eq!(dense_csc(rows, cols, entries), by_hand(rows, cols, entries));
        }
        assert_eq!(dense_csc(3, 2, |_, _| 0.0), CscMatrix::zeros((3, 2)));
        assert_eq!(dense_csc(4, 4, |r, c| f64::from(u8::from(r == c))), CscMatrix::identity(4));
    }

    #[test]
    fn every_clarabel_stop_has_its_own_variant_and_message() {
        use SolverStatus as S;
        let cases = [
            (S::MaxIterations, SolverStop::MaxIterations),
            (S::MaxTime, SolverStop::MaxTime),
            (S::NumericalError, SolverStop::NumericalError),
            (S::InsufficientProgress, SolverStop::InsufficientProgress),
            (S::DualInfeasible, SolverStop::Unbounded),
            (S::AlmostDualInfeasible, SolverStop::Unbounded),
            (S::Unsolved, SolverStop::NotRun),
            (S::CallbackTerminated, SolverStop::NotRun),
            (S::AlmostSolved, SolverStop::ReducedAccuracy),
            (S::PrimalInfeasible, SolverStop::FalseInfeasibility),
        ];
        for (status, stop) in cases {
            assert_eq!(SolverStop::from_status(status), stop, "{status:?}");
        }
        let messages: std::collections::BTreeSet<String> = [
            SolverStop::Setup,
            SolverStop::ReducedAccuracy,
            SolverStop::FalseInfeasibility,
            SolverStop::Unbounded,
            SolverStop::InconsistentBound,
            SolverStop::MaxIterations,
            SolverStop::MaxTime,
            SolverStop::NumericalError,
            SolverStop::InsufficientProgress,
            SolverStop::NotRun,
        ]
        .iter()
        .map(ToString::to_string)
        .collect();
        assert_eq!(messages.len(), 10, "one message per stop");
        let e = StaticsError::Solver { stop: SolverStop::MaxIterations };
        assert_eq!(
            e.to_string(),
            "the tension solver stopped without an answer: iteration limit reached"
        );
    }
}
