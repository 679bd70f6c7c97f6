//! Tension distribution over the equilibrium set of any cable set: the named policies, solved
//! as small convex programs in the set's coordinates `λ` with `clarabel` (pure Rust LP/QP), then
//! polished on their active set so that balance holds to rounding and the limits exactly.
//!
//! # Math
//! On `f = f_p + N λ` ([`crate::EquilibriumSet`], `N` orthonormal, `f_p ⊥ N`), with the limits
//! as the rows `N λ ≤ f_max − f_p` and `−N λ ≤ f_p − f_min`:
//!
//! - [`TensionPolicy::LeastTotal`]: minimise `Σ f = Σ f_p + (Nᵀ 1)ᵀ λ` (LP);
//! - [`TensionPolicy::LeastNorm`]: minimise `|f|² = |f_p|² + |λ|²` (QP);
//! - [`TensionPolicy::Safest`]: maximise the least distance to a limit, `t` with
//!   `f_min + t ≤ f ≤ f_max − t` (LP in `(λ, t)`): the tensions farthest from both limits.
//!
//! The interior-point answer is accurate to the solver's tolerance (about `1e-8` relative).
//! The polish takes the rows within `1e-6 (f_max − f_min)` ([`ACTIVE_TOLERANCE`]) of their bound
//! as active and solves them exactly: for the QP `λ = N_A⁺ (b_A − f_p,A)` (the least `|λ|` on
//! the active rows, its optimum given the active set), for the LPs the projection of the answer
//! onto the active rows (the vertex itself when they fix it). A polish that would leave a row
//! violated (by more than [`POLISH_TOLERANCE`]) is discarded. A load no tensions balance gets
//! the solver's certificate of infeasibility read back as a joint motion `δq`
//! ([`NoEquilibriumCause::Limits`]): along it the load needs more torque than the cables give
//! within their limits. The programs are solved in [`crate::convex`].

use std::ops::Range;

use faer::Mat;

use crate::convex::{Solved, dense_csc, solve};
use crate::equilibrium::{EquilibriumSet, NAMED_SHARE, joints_along, norm};
use crate::error::{NoEquilibrium, NoEquilibriumCause, StaticsError};

/// A named way to choose the tensions among all that balance the load.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TensionPolicy {
    /// Least total tension `Σ f` (LP).
    LeastTotal,
    /// Least 2-norm `|f|` (QP).
    LeastNorm,
    /// Farthest from the limits: the greatest least distance of a tension to `f_min` or
    /// `f_max` (LP).
    Safest,
}

impl TensionPolicy {
    /// Every policy, in the order the docs list them.
    pub const ALL: [TensionPolicy; 3] =
        [TensionPolicy::LeastTotal, TensionPolicy::LeastNorm, TensionPolicy::Safest];

    /// The name the command line and the JSON use (`least-total`, `least-norm`, `safest`).
    pub fn name(self) -> &'static str {
        match self {
            TensionPolicy::LeastTotal => "least-total",
            TensionPolicy::LeastNorm => "least-norm",
            TensionPolicy::Safest => "safest",
        }
    }
}

/// The answer of a policy ([`distribute_with_policy`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Distribution {
    /// The policy.
    pub policy: TensionPolicy,
    /// The coordinates `λ` of the tensions in the set.
    pub lambda: Vec<f64>,
    /// The policy's objective at the answer: `Σ f` (N), `|f|` (N), or the least distance to a
    /// limit (N).
    pub objective: f64,
    /// The interior-point iterations (0 when the set is a single point).
    pub iterations: u32,
}

/// Rows within this fraction of their cable's bound width (see [`WIDTH_FLOOR`]) of their bound
/// are active in the polish.
const ACTIVE_TOLERANCE: f64 = 1e-6;

/// A polished tension within this fraction of [`ACTIVE_TOLERANCE`] (so `1e-9` of the bound
/// width) of a limit is put exactly on it.
const SNAP_FRACTION: f64 = 1e-3;

/// A tension outside its limits by more than this fraction of the bound width, after the
/// polish, means no point of the set is within them: the load is refused with a certificate.
const OUTSIDE_TOLERANCE: f64 = 1e-7;

/// A polished point may leave a row violated by at most this fraction of the bound width;
/// beyond, the polish is discarded and the solver's answer kept.
const POLISH_TOLERANCE: f64 = 1e-9;

/// A certificate along one joint (or one DOF) replaces the solver's only when its shortfall
/// per newton of cable weight exceeds this fraction of the largest tension limit.
const SHORTFALL_TOLERANCE: f64 = 1e-9;

/// Components of a certificate's joint motion below this fraction of the largest are rounding
/// noise (about `1e-16` from the other joints' blocks) and are set to zero.
const NOISE_TOLERANCE: f64 = 1e-12;

/// The least bound width, N, that the relative tolerances above scale with:
/// `max(f_max − f_min, WIDTH_FLOOR)`.
const WIDTH_FLOOR: f64 = 1.0;

/// The tensions of `policy` on `set` (into `tensions`, m, N). `groups` (the joints as DOF
/// ranges) and `names` (the cables) name what is at fault in an infeasibility.
///
/// # Errors
/// [`StaticsError::NoEquilibrium`] when no tensions within the limits balance the load, with
/// the joint motion along which they fall short; [`StaticsError::Solver`] when the solver
/// fails; [`StaticsError::DimensionMismatch`].
pub fn distribute_with_policy(
    set: &EquilibriumSet,
    policy: TensionPolicy,
    groups: &[Range<usize>],
    names: &[String],
    tensions: &mut [f64],
) -> Result<Distribution, StaticsError> {
    let (m, k) = (set.cable_count(), set.dimension());
    if tensions.len() != m {
        return Err(StaticsError::DimensionMismatch {
            what: "tensions",
            expected: m,
            got: tensions.len(),
        });
    }
    let program = Program::new(set, policy);
    // A set of dimension 0 is one point (f = f_p): no program, no polish (the safest
    // program's margin variable would be polished on an empty answer).
    let (x, iterations) = if k == 0 {
        (Vec::new(), 0)
    } else {
        match program.solve()? {
            Solved::Point { x, iterations } => (program.polish(x), iterations),
            Solved::Infeasible { z, .. } => {
                return Err(limits_certificate(
                    set,
                    &program.certificate_weights(&z),
                    groups,
                    names,
                ));
            }
        }
    };
    let lambda = x[..k].to_vec();
    set.tensions(&lambda, tensions)?;
    let (lower, upper) = (set.lower(), set.upper());
    // Off the limits by more than rounding: no point of the set is within them.
    let worst = (0..m)
        .map(|c| (lower[c] - tensions[c]).max(tensions[c] - upper[c]) / width(set, c))
        .fold(f64::NEG_INFINITY, f64::max);
    if worst > OUTSIDE_TOLERANCE {
        let c = (0..m)
            .max_by(|&a, &b| {
                let over = |c: usize| (lower[c] - tensions[c]).max(tensions[c] - upper[c]);
                over(a).total_cmp(&over(b))
            })
            .unwrap_or(0);
        let mut w = vec![0.0; m];
        w[c] = if tensions[c] > upper[c] { 1.0 } else { -1.0 };
        if k > 0 {
            // The set is not a point, yet its best point is outside: read the certificate of
            // the least-total program, which is infeasible then.
            if let Ok(Solved::Infeasible { z, .. }) =
                Program::new(set, TensionPolicy::LeastTotal).solve()
            {
                let weights = Program::new(set, TensionPolicy::LeastTotal).certificate_weights(&z);
                return Err(limits_certificate(set, &weights, groups, names));
            }
        }
        return Err(limits_certificate(set, &w, groups, names));
    }
    for c in 0..m {
        let f = tensions[c].clamp(lower[c], upper[c]);
        let tol = ACTIVE_TOLERANCE * width(set, c);
        tensions[c] = if (f - lower[c]).abs() <= tol * SNAP_FRACTION {
            lower[c]
        } else if (upper[c] - f).abs() <= tol * SNAP_FRACTION {
            upper[c]
        } else {
            f
        };
    }
    let objective = match policy {
        TensionPolicy::LeastTotal => tensions.iter().sum(),
        TensionPolicy::LeastNorm => norm(tensions),
        TensionPolicy::Safest => (0..m)
            .map(|c| (tensions[c] - lower[c]).min(upper[c] - tensions[c]))
            .fold(f64::INFINITY, f64::min),
    };
    Ok(Distribution { policy, lambda, objective, iterations })
}

/// The bound width of cable `c`, floored at [`WIDTH_FLOOR`].
fn width(set: &EquilibriumSet, c: usize) -> f64 {
    (set.upper()[c] - set.lower()[c]).max(WIDTH_FLOOR)
}

/// A policy's program in `x = λ` (or `(λ, t)` for [`TensionPolicy::Safest`]): minimise
/// `½ xᵀ P x + qᵀ x` subject to `G x ≤ h`, `G = [N; −N]` (plus a column of ones for `t`),
/// `h = [f_max − f_p; f_p − f_min]`.
struct Program {
    policy: TensionPolicy,
    /// Number of variables.
    n: usize,
    /// `G`, dense, row-major (2m × n).
    g: Vec<f64>,
    h: Vec<f64>,
    q: Vec<f64>,
    /// The bound width of each row's cable (for the active tolerance).
    row_width: Vec<f64>,
}

impl Program {
    fn new(set: &EquilibriumSet, policy: TensionPolicy) -> Program {
        let (m, k) = (set.cable_count(), set.dimension());
        let null = set.null_basis();
        let n = if policy == TensionPolicy::Safest { k + 1 } else { k };
        let mut g = vec![0.0; 2 * m * n];
        let mut h = vec![0.0; 2 * m];
        let mut row_width = vec![0.0; 2 * m];
        let p = set.particular();
        for c in 0..m {
            for i in 0..k {
                g[c * n + i] = null[(c, i)];
                g[(m + c) * n + i] = -null[(c, i)];
            }
            if policy == TensionPolicy::Safest {
                g[c * n + k] = 1.0;
                g[(m + c) * n + k] = 1.0;
            }
            h[c] = set.upper()[c] - p[c];
            h[m + c] = p[c] - set.lower()[c];
            row_width[c] = width(set, c);
            row_width[m + c] = width(set, c);
        }
        let q = match policy {
            TensionPolicy::LeastTotal => {
                (0..k).map(|i| (0..m).map(|c| null[(c, i)]).sum()).collect()
            }
            TensionPolicy::LeastNorm => vec![0.0; k],
            TensionPolicy::Safest => {
                let mut q = vec![0.0; n];
                q[k] = -1.0;
                q
            }
        };
        Program { policy, n, g, h, q, row_width }
    }

    fn rows(&self) -> usize {
        self.h.len()
    }

    fn solve(&self) -> Result<Solved, StaticsError> {
        let n = self.n;
        let a = dense_csc(self.rows(), n, |r, c| self.g[r * n + c]);
        solve(self.policy == TensionPolicy::LeastNorm, &self.q, &a, &self.h)
    }

    /// The cable weights `w = z_upper − z_lower` of a certificate of infeasibility `z` (2m).
    fn certificate_weights(&self, z: &[f64]) -> Vec<f64> {
        let m = self.rows() / 2;
        (0..m)
            .map(|c| z.get(c).copied().unwrap_or(0.0) - z.get(m + c).copied().unwrap_or(0.0))
            .collect()
    }

    /// The answer polished on its active rows (see the module docs); `x` unchanged when the
    /// polish would violate a row.
    fn polish(&self, x: Vec<f64>) -> Vec<f64> {
        let n = self.n;
        if n == 0 {
            return x;
        }
        let slack =
            |x: &[f64], r: usize| self.h[r] - (0..n).map(|c| self.g[r * n + c] * x[c]).sum::<f64>();
        let active: Vec<usize> = (0..self.rows())
            .filter(|&r| slack(&x, r) <= ACTIVE_TOLERANCE * self.row_width[r])
            .collect();
        let feasible = |x: &[f64]| {
            (0..self.rows()).all(|r| slack(x, r) >= -POLISH_TOLERANCE * self.row_width[r])
        };
        if active.is_empty() {
            // The QP's optimum with no active row is λ = 0 (f = f_p); an LP's stays.
            let zero = vec![0.0; n];
            return if self.policy == TensionPolicy::LeastNorm && feasible(&zero) {
                zero
            } else {
                x
            };
        }
        let g_active = Mat::from_fn(active.len(), n, |i, c| self.g[active[i] * n + c]);
        let Ok(svd) = g_active.svd() else { return x };
        let pinv = svd.pseudoinverse();
        // LeastNorm: the least |λ| on the active rows; LPs: x projected onto them.
        let base: Vec<f64> =
            if self.policy == TensionPolicy::LeastNorm { vec![0.0; n] } else { x.clone() };
        let defect: Vec<f64> = active.iter().map(|&r| slack(&base, r)).collect();
        let polished: Vec<f64> = (0..n)
            .map(|c| base[c] + (0..active.len()).map(|i| pinv[(c, i)] * defect[i]).sum::<f64>())
            .collect();
        if feasible(&polished) { polished } else { x }
    }
}

/// A certificate `w` (cable weights, in the range of `J_c`) read back as the joint motion
/// along which the cables fall short.
fn limits_certificate(
    set: &EquilibriumSet,
    w: &[f64],
    groups: &[Range<usize>],
    names: &[String],
) -> StaticsError {
    let m = set.cable_count();
    let (lower, upper, p) = (set.lower(), set.upper(), set.particular());
    let mut w = w.to_vec();
    // Σ_c w_c f_c is the same for every balancing f: the load's demand along w.
    let demand = |w: &[f64]| (0..m).map(|c| w[c] * p[c]).sum::<f64>();
    let top = |w: &[f64]| {
        (0..m).map(|c| w[c] * if w[c] > 0.0 { upper[c] } else { lower[c] }).sum::<f64>()
    };
    let bottom = |w: &[f64]| {
        (0..m).map(|c| w[c] * if w[c] > 0.0 { lower[c] } else { upper[c] }).sum::<f64>()
    };
    // The solver's certificate is one of many, often a mix of joints; a certificate along one
    // joint alone names just that joint: take the one that falls shortest by the most, per
    // newton of cable weight, when there is one. Candidates: each joint's part of the solver's
    // joint motion and each of its DOFs alone.
    let shortfall = |w: &[f64]| (demand(w) - top(w)).max(bottom(w) - demand(w)) / norm(w);
    let direction = set.joint_motion(&w);
    let mut best: Option<(f64, Vec<f64>)> = None;
    for g in groups {
        let part: Vec<f64> =
            (0..direction.len()).map(|d| if g.contains(&d) { direction[d] } else { 0.0 }).collect();
        let axes = g.clone().map(|d| (0..direction.len()).map(|i| f64::from(i == d)).collect());
        for dq in std::iter::once(part).chain(axes) {
            let candidate = set.cable_motion(&dq);
            if norm(&candidate) == 0.0 {
                continue;
            }
            let by = shortfall(&candidate);
            let scale = (0..m).map(|c| upper[c].abs().max(lower[c].abs())).fold(0.0, f64::max);
            if by > SHORTFALL_TOLERANCE * scale && best.as_ref().is_none_or(|(b, _)| by > *b) {
                best = Some((by, candidate));
            }
        }
    }
    if let Some((_, single)) = best {
        w = single;
    }
    if demand(&w) < bottom(&w) {
        w.iter_mut().for_each(|v| *v = -*v);
    }
    let mut direction = set.joint_motion(&w);
    let scale = direction.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
    if scale > 0.0 {
        // Rounding noise (~1e-16) in the other joints' components would read as motion.
        direction
            .iter_mut()
            .for_each(|v| *v = if v.abs() <= NOISE_TOLERANCE * scale { 0.0 } else { *v / scale });
        w.iter_mut().for_each(|v| *v /= scale);
    }
    let largest = w.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
    let named = |sign: f64| -> Vec<String> {
        (0..m)
            .filter(|&c| sign * w[c] >= NAMED_SHARE * largest && largest > 0.0)
            .map(|c| names.get(c).cloned().unwrap_or_else(|| format!("#{}", c + 1)))
            .collect()
    };
    // `w · f = (J_cᵀ f) · δq` is minus the cables' torque `τ = −J_cᵀ f` along `δq`: the
    // numbers above are the cables' torque along `−δq`, which is the joint motion reported
    // (the sign of `T0`, as `NoEquilibriumCause::Unreachable` reports it).
    direction.iter_mut().for_each(|v| *v = if *v == 0.0 { 0.0 } else { -*v });
    StaticsError::NoEquilibrium(Box::new(NoEquilibrium {
        joints: joints_along(&direction, groups),
        cause: NoEquilibriumCause::Limits {
            needed: demand(&w),
            range: [bottom(&w), top(&w)],
            at_max: named(1.0),
            at_min: named(-1.0),
            direction,
        },
    }))
}
