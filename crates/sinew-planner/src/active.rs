//! The warm step of re-planning by Newton steps on the previous answer's active set (issue
//! #24): the previous tensions mapped into this pose's frame, the previous plan's active rows
//! (or, when the rows are not the previous frame's, those the mapped point leaves within
//! [`ACTIVE_SLACK`] of their bound), then Newton steps on the KKT system of
//! `max φ(x) s.t. G_W x = h_W`. Where a step is stationary on `W` but not certified, the most
//! violated row joins `W`, or the row with the most negative multiplier leaves it. The answer
//! is certified by the bound of `program.rs` with the active rows' multipliers and `Z = 0`: the
//! step is for the smooth objectives and least tension with the margin not active and no
//! stiffness floor. Anything else (an active margin, a floor, a singular system, a bound not
//! within the tolerance after [`MAX_STEPS`] evaluations) returns to the interior-point
//! method's warm start.
//!
//! # Math
//! At `x`, with `g = ∇φ(x)`, `H = ∇²φ(x) ⪯ 0` and the active rows `W`, the step `d` and the
//! multipliers `y` of the rows solve
//!
//! ```text
//! [ −H + εI   G_Wᵀ ] [ d ]   [ g           ]
//! [  G_W      0    ] [ y ] = [ h_W − G_W x ]
//! ```
//!
//! (`ε` a relative 10⁻⁹ of `H`'s diagonal, so that the system stays regular along a direction
//! in which `φ` is linear; with as many rows as coordinates, `x + d` is their vertex whatever
//! `ε`). The bound at `x` takes `y` by least squares on `G_Wᵀ y = g`, clipped at 0:
//! `UB = φ + yᵀs + Σ_a max(r_a(1 − x_a), r_a(−1 − x_a))`, `r = g − G_Wᵀ y`, valid for any
//! `y ≥ 0` (the margin's multiplier is 0, so the margin only needs to hold, which one Cholesky
//! trial checks). An answer is accepted only inside every row (to [`ROUNDING`]).

use nalgebra::Vector6;

use crate::blocks::base_into;
use crate::dense::{cholesky, cholesky_solve, dot};
use crate::frame::Frame;
use crate::ipm::Answer;
use crate::problem::{Objective, PlanSettings, Requirements};
use crate::program::{Duals, Sdp, Smooth, upper_bound};
use crate::smooth::{EndBuffers, EndObjective, Kind};

/// A row is active at the mapped point when its slack is below this (the frame's units: each
/// row's largest coefficient is 1 and `x ∈ [−1, 1]`).
pub(crate) const ACTIVE_SLACK: f64 = 1e-3;

/// The most objective evaluations (Newton steps and changes of the active set) of one warm
/// step.
pub(crate) const MAX_STEPS: usize = 6;

/// How far past a row (the frame's units) an accepted answer may lie: rounding of `G_W x = h_W`.
const ROUNDING: f64 = 1e-10;

/// A Newton step this short (largest coordinate, the frame's units) leaves `x` where it is:
/// the point is stationary on its active set.
const STATIONARY: f64 = 1e-9;

/// The buffers of the warm step, kept in the planner's workspace: a step along a trajectory
/// allocates none of them again.
#[derive(Debug, Default)]
pub(crate) struct WarmWork {
    /// The mapped previous answer `x₀` (filled by the caller).
    pub(crate) mapped: Vec<f64>,
    /// The iterate (moved into the answer; the caller returns it).
    pub(crate) x: Vec<f64>,
    end: EndBuffers,
    sdp: Option<Sdp>,
    active: Vec<usize>,
    gradient: Vec<f64>,
    hessian: Vec<f64>,
    s: Vec<f64>,
    a: Vec<f64>,
    /// The KKT matrix (row-major) and its right-hand side, then `(d, y)`.
    kkt: Vec<f64>,
    rhs: Vec<f64>,
    /// Every row's multiplier, and the least-squares system of the active ones.
    y: Vec<f64>,
    gram: Vec<f64>,
    /// Rows and slacks, for [`active_rows_into`].
    pairs: Vec<(usize, f64)>,
}

impl WarmWork {
    /// The scratch of [`active_rows_into`].
    pub(crate) fn pairs(&mut self) -> &mut Vec<(usize, f64)> {
        &mut self.pairs
    }
}

/// The objective of the step.
#[allow(clippy::large_enum_variant)] // one per warm step, on the stack: no allocation
enum Goal<'a> {
    Smooth(EndObjective<'a>),
    /// `−Σ f = −total − sumsᵀx` (least tension).
    Linear,
}

impl Goal<'_> {
    fn evaluate(
        &mut self,
        frame: &Frame,
        x: &[f64],
        gradient: &mut [f64],
        hessian: &mut [f64],
    ) -> Option<f64> {
        match self {
            Goal::Smooth(s) => s.evaluate(x, gradient, hessian),
            Goal::Linear => {
                gradient.iter_mut().zip(&frame.sums).for_each(|(g, s)| *g = -s);
                hessian.fill(0.0);
                Some(-frame.total - dot(&frame.sums, x))
            }
        }
    }
}

/// The rows active at `x` (slack below [`ACTIVE_SLACK`]), tightest first, at most one per
/// free coordinate, into `out` (`pairs` a scratch): the active set a plan leaves to the next
/// step's warm start.
pub(crate) fn active_rows_into(
    frame: &Frame,
    x: &[f64],
    out: &mut Vec<usize>,
    pairs: &mut Vec<(usize, f64)>,
) {
    pairs.clear();
    pairs.extend(
        (0..frame.rhs.len()).map(|r| (r, slack(frame, x, r))).filter(|(_, s)| *s < ACTIVE_SLACK),
    );
    pairs.sort_unstable_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
    pairs.truncate(frame.vars());
    out.clear();
    out.extend(pairs.iter().map(|(r, _)| *r));
}

/// `h_r − G_r x`.
fn slack(frame: &Frame, x: &[f64], r: usize) -> f64 {
    let k = frame.vars();
    frame.rhs[r] - frame.rows[r * k..r * k + k].iter().zip(x).map(|(a, b)| a * b).sum::<f64>()
}

/// The warm answer from the mapped previous answer `x0` and the previous active set
/// `previous` (`None` when this frame's rows are not the previous frame's: then the rows
/// active at `x0`), or the evaluations spent when the step does not apply or is not
/// certified within the tolerance (module docs). The buffers are `work`'s; the answer's `x` is
/// `work.x`, moved.
pub(crate) fn warm(
    frame: &Frame,
    objective: Objective,
    requirements: &Requirements,
    settings: &PlanSettings,
    x0: &[f64],
    previous: Option<&[usize]>,
    work: &mut WarmWork,
) -> Result<Answer, usize> {
    if requirements.k_min.is_some() || requirements.k_des.is_some() {
        return Err(0);
    }
    let end = std::mem::take(&mut work.end);
    let mut goal = match objective {
        Objective::LeastTension => Goal::Linear,
        Objective::StiffnessAlong(u) => {
            let w = Vector6::new(u.x, u.y, u.z, 0.0, 0.0, 0.0);
            Goal::Smooth(EndObjective::reusing(frame, Kind::Along(w), 1.0, end))
        }
        Objective::Volume => Goal::Smooth(EndObjective::reusing(frame, Kind::Volume, 1.0, end)),
        Objective::MinStiffness | Objective::ComplianceAlong(_) => {
            work.end = end;
            return Err(0);
        }
    };
    let result = steps(frame, objective, requirements, settings, x0, previous, &mut goal, work);
    if let Goal::Smooth(smooth) = goal {
        work.end = smooth.into_buffers();
    }
    result
}

/// The steps of [`warm`] with its objective `goal`.
#[allow(clippy::too_many_arguments)]
fn steps(
    frame: &Frame,
    objective: Objective,
    requirements: &Requirements,
    settings: &PlanSettings,
    x0: &[f64],
    previous: Option<&[usize]>,
    goal: &mut Goal<'_>,
    work: &mut WarmWork,
) -> Result<Answer, usize> {
    let (k, n) = (frame.vars(), frame.n);
    let sdp = work.sdp.get_or_insert_with(Sdp::default);
    base_into(frame, 0, sdp);
    match previous {
        Some(previous) => {
            work.active.clear();
            work.active.extend_from_slice(previous);
        }
        None => active_rows_into(frame, x0, &mut work.active, &mut work.pairs),
    }
    let active = &mut work.active;
    work.x.clear();
    work.x.extend_from_slice(x0);
    let x = &mut work.x;
    let sized = |v: &mut Vec<f64>, len: usize| {
        v.clear();
        v.resize(len, 0.0);
    };
    sized(&mut work.gradient, k);
    sized(&mut work.hessian, k * k);
    sized(&mut work.s, frame.rhs.len());
    sized(&mut work.a, n * n);
    let (gradient, hessian, s, a) =
        (&mut work.gradient, &mut work.hessian, &mut work.s, &mut work.a);
    let (kkt, rhs, y, gram) = (&mut work.kkt, &mut work.rhs, &mut work.y, &mut work.gram);
    // The objective's scale: its value at the first point (the gap's floor 1e-9 of it, 1 in
    // log units for the volume).
    let mut scale = None;
    for step in 0..MAX_STEPS {
        if active.len() > k {
            return Err(step);
        }
        if active.len() == k {
            // As many rows as coordinates: their vertex, whatever the objective.
            if !newton(frame, x, gradient, hessian, active, kkt, rhs) {
                return Err(step);
            }
            x.iter_mut().zip(&rhs[..k]).for_each(|(xa, da)| *xa += da);
        }
        // The margin must hold (its multiplier is 0): one Cholesky trial.
        frame.a_at(x, a);
        for i in 0..n {
            a[i * n + i] -= requirements.margin;
        }
        if !cholesky(a, n) {
            return Err(step);
        }
        let value = goal.evaluate(frame, x, gradient, hessian).ok_or(step)?;
        let (scale, floor) = *scale.get_or_insert_with(|| match objective {
            Objective::Volume => (value.abs().max(1.0), 1.0 / value.abs().max(1.0)),
            _ => (value.abs().max(1e-12), 1e-9),
        });
        let value = value / scale;
        gradient.iter_mut().chain(hessian.iter_mut()).for_each(|v| *v /= scale);
        sdp.slacks(x, s);
        // The most violated row, if any.
        let violated = s
            .iter()
            .enumerate()
            .fold((None, -ROUNDING), |best, (r, &v)| if v < best.1 { (Some(r), v) } else { best })
            .0;
        if violated.is_none() {
            multipliers(frame, gradient, active, y, gram);
            let duals = Duals { y: std::mem::take(y), z: Vec::new() };
            let upper = upper_bound(sdp, x, value, gradient, s, std::iter::empty(), &duals);
            *y = duals.y;
            if upper - value <= settings.relative_gap * value.abs().max(floor) {
                let x = std::mem::take(x);
                return Ok(Answer { x, upper: upper * scale, iterations: step + 1 });
            }
        }
        if !newton(frame, x, gradient, hessian, active, kkt, rhs) {
            return Err(step + 1);
        }
        let (d, multipliers) = rhs.split_at(k);
        if d.iter().fold(0.0_f64, |m, v| m.max(v.abs())) > STATIONARY {
            x.iter_mut().zip(d).for_each(|(xa, da)| *xa += da);
            continue;
        }
        // Stationary on W and not certified: a violated row joins W, else the row with the
        // most negative multiplier leaves it.
        match violated {
            Some(r) if active.len() < k => active.push(r),
            Some(_) => return Err(step + 1),
            None => {
                let (i, least) = multipliers
                    .iter()
                    .enumerate()
                    .fold((0, 0.0), |best, (i, &v)| if v < best.1 { (i, v) } else { best });
                if least >= 0.0 {
                    return Err(step + 1);
                }
                active.remove(i);
            }
        }
    }
    Err(MAX_STEPS)
}

/// The Newton step `d` and the active rows' multipliers `y` (module docs) into `rhs` as
/// `(d, y)`, the KKT matrix in `kkt`; `false` when the system is singular.
fn newton(
    frame: &Frame,
    x: &[f64],
    gradient: &[f64],
    hessian: &[f64],
    active: &[usize],
    kkt: &mut Vec<f64>,
    rhs: &mut Vec<f64>,
) -> bool {
    let k = frame.vars();
    let p = active.len();
    let size = k + p;
    let largest = (0..k).map(|a| hessian[a * k + a].abs()).fold(0.0, f64::max);
    let epsilon = 1e-9 * largest.max(1e-3);
    kkt.clear();
    kkt.resize(size * size, 0.0);
    rhs.clear();
    rhs.resize(size, 0.0);
    for a in 0..k {
        for b in 0..k {
            kkt[a * size + b] = -hessian[a * k + b];
        }
        kkt[a * size + a] += epsilon;
        rhs[a] = gradient[a];
    }
    for (i, &r) in active.iter().enumerate() {
        let row = &frame.rows[r * k..r * k + k];
        for (a, v) in row.iter().enumerate() {
            kkt[(k + i) * size + a] = *v;
            kkt[a * size + k + i] = *v;
        }
        rhs[k + i] = slack(frame, x, r);
    }
    lu_solve(kkt, size, rhs) && rhs.iter().all(|v| v.is_finite())
}

/// `A⁻¹ b` into `b` by Gaussian elimination with partial pivoting (`a` n × n row-major,
/// overwritten); `false` when a pivot is zero (`a` singular).
fn lu_solve(a: &mut [f64], n: usize, b: &mut [f64]) -> bool {
    for c in 0..n {
        let pivot =
            (c..n).fold(c, |p, r| if a[r * n + c].abs() > a[p * n + c].abs() { r } else { p });
        if a[pivot * n + c] == 0.0 {
            return false;
        }
        if pivot != c {
            for j in 0..n {
                a.swap(pivot * n + j, c * n + j);
            }
            b.swap(pivot, c);
        }
        let d = a[c * n + c];
        for r in c + 1..n {
            let f = a[r * n + c] / d;
            if f == 0.0 {
                continue;
            }
            for j in c + 1..n {
                a[r * n + j] -= f * a[c * n + j];
            }
            b[r] -= f * b[c];
        }
    }
    for c in (0..n).rev() {
        let tail: f64 = (c + 1..n).map(|j| a[c * n + j] * b[j]).sum();
        b[c] = (b[c] - tail) / a[c * n + c];
    }
    true
}

/// Every row's multiplier for the bound into `y`: the active rows' by least squares on
/// `G_Wᵀ y = g`, clipped at 0, the others' 0 (`gram` a scratch).
fn multipliers(
    frame: &Frame,
    gradient: &[f64],
    active: &[usize],
    y: &mut Vec<f64>,
    gram: &mut Vec<f64>,
) {
    let k = frame.vars();
    let (p, rows) = (active.len(), frame.rhs.len());
    y.clear();
    y.resize(rows + p, 0.0);
    if p > 0 {
        let row = |i: usize| &frame.rows[active[i] * k..active[i] * k + k];
        gram.clear();
        gram.extend((0..p * p).map(|e| dot(row(e / p), row(e % p))));
        let (every, solved) = y.split_at_mut(rows);
        for (i, v) in solved.iter_mut().enumerate() {
            *v = dot(row(i), gradient);
        }
        if cholesky(gram, p) {
            cholesky_solve(gram, p, solved);
            for (&r, v) in active.iter().zip(solved.iter()) {
                every[r] = v.max(0.0);
            }
        }
    }
    y.truncate(rows);
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use nalgebra::{DMatrix, DVector};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::lu_solve;

    /// The KKT solve against nalgebra's LU: random systems of the warm step's shape
    /// `[[−H + εI, Gᵀ], [G, 0]]` (a zero block on the diagonal, so that the elimination must
    /// pivot), with `ε` as small as the least-tension step's; a singular system is refused.
    #[test]
    fn the_kkt_solve_is_the_lu_of_nalgebra() {
        let mut rng = ChaCha8Rng::seed_from_u64(12);
        let mut worst: f64 = 0.0;
        for case in 0..200 {
            let k = 1 + case % 6;
            let p = case % (k + 1);
            let size = k + p;
            let epsilon = [1e-12, 1e-3, 1.0][case % 3];
            let mut a = DMatrix::<f64>::zeros(size, size);
            let h = DMatrix::from_fn(k, k, |_, _| rng.random_range(-1.0..1.0));
            let h = &h * h.transpose();
            for i in 0..k {
                for j in 0..k {
                    a[(i, j)] = h[(i, j)] * if epsilon < 1e-6 { 0.0 } else { 1.0 };
                }
                a[(i, i)] += epsilon;
            }
            for r in 0..p {
                for c in 0..k {
                    let v = rng.random_range(-1.0..1.0);
                    a[(k + r, c)] = v;
                    a[(c, k + r)] = v;
                }
            }
            let b = DVector::from_fn(size, |_, _| rng.random_range(-1.0..1.0));
            let reference = a.clone().lu().solve(&b).unwrap();
            let mut rows: Vec<f64> = a.transpose().iter().copied().collect();
            let mut x: Vec<f64> = b.iter().copied().collect();
            assert!(lu_solve(&mut rows, size, &mut x), "case {case}");
            let scale = reference.amax().max(1.0);
            let residual = (&a * DVector::from_column_slice(&x) - &b).amax();
            for (got, want) in x.iter().zip(reference.iter()) {
                worst = worst.max((got - want).abs() / scale);
            }
            assert!(residual <= 1e-9 * scale, "case {case}: residual {residual:e}");
        }
        assert!(worst <= 1e-6, "worst difference from nalgebra's LU {worst:e}");
        // Singular: two equal rows; and a zero matrix.
        let mut singular = vec![1.0, 2.0, 1.0, 2.0];
        assert!(!lu_solve(&mut singular, 2, &mut [1.0, 1.0]));
        assert!(!lu_solve(&mut [0.0; 9], 3, &mut [1.0; 3]));
    }
}
