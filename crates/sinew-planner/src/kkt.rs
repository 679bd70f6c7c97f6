//! The KKT systems of the warm step's Newton steps (`active.rs`), solved without allocation:
//! Gaussian elimination with partial pivoting (Golub and Van Loan, Alg. 3.4.1). The systems
//! are symmetric but indefinite, with a zero block on the diagonal, so a Cholesky
//! factorisation does not apply and the row exchanges are needed. The systems themselves
//! (module docs of `active.rs`): the Newton step on a working set of rows and the margin, and
//! the least-squares multipliers of the bound.

use crate::dense::{cholesky, cholesky_solve, dot};
use crate::frame::Frame;

/// The margin's entry in a working set (the rows' are their indices).
pub(crate) const MARGIN: usize = usize::MAX;

/// `h_r − G_r x`.
pub(crate) fn slack(frame: &Frame, x: &[f64], r: usize) -> f64 {
    let k = frame.vars();
    frame.rhs[r] - frame.rows[r * k..r * k + k].iter().zip(x).map(|(a, b)| a * b).sum::<f64>()
}

/// The Newton step `d` and the working set's multipliers `y` (module docs) into `rhs` as
/// `(d, y)`, the KKT matrix in `kkt`; the margin, when in the set ([`MARGIN`]), is the row
/// `−∇c` with its slack `c − δ`. `false` when the system is singular.
#[allow(clippy::too_many_arguments)]
pub(crate) fn newton(
    frame: &Frame,
    x: &[f64],
    gradient: &[f64],
    hessian: &[f64],
    active: &[usize],
    margin: Option<(&[f64], f64)>,
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
        let (row, slack, sign) = match (r, margin) {
            (MARGIN, Some((c_gradient, slack))) => (c_gradient, slack, -1.0),
            (MARGIN, None) => return false,
            _ => (&frame.rows[r * k..r * k + k], slack(frame, x, r), 1.0),
        };
        for (a, v) in row.iter().enumerate() {
            kkt[(k + i) * size + a] = sign * v;
            kkt[a * size + k + i] = sign * v;
        }
        rhs[k + i] = slack;
    }
    lu_solve(kkt, size, rhs) && rhs.iter().all(|v| v.is_finite())
}

/// Every row's multiplier for the bound into `y` and the margin's, returned: the working
/// set's by least squares on `G_Wᵀ y = g` (the margin's column `−∇c`, `c_gradient`, when it
/// is in the set), clipped at 0, the others' 0 (`gram` a scratch).
pub(crate) fn multipliers(
    frame: &Frame,
    gradient: &[f64],
    active: &[usize],
    c_gradient: Option<&[f64]>,
    y: &mut Vec<f64>,
    gram: &mut Vec<f64>,
) -> f64 {
    let k = frame.vars();
    let (p, rows) = (active.len(), frame.rhs.len());
    y.clear();
    y.resize(rows + p, 0.0);
    let mut eta = 0.0;
    if p > 0 {
        let column = |i: usize| match (active[i], c_gradient) {
            // Without `c_gradient` (not in the set) the margin's column is empty.
            (MARGIN, c) => (c.unwrap_or(&[]), -1.0),
            (r, _) => (&frame.rows[r * k..r * k + k], 1.0),
        };
        let product = |i: usize, j: usize| {
            let ((a, sa), (b, sb)) = (column(i), column(j));
            sa * sb * dot(a, b)
        };
        gram.clear();
        gram.extend((0..p * p).map(|e| product(e / p, e % p)));
        let (every, solved) = y.split_at_mut(rows);
        for (i, v) in solved.iter_mut().enumerate() {
            let (a, sa) = column(i);
            *v = sa * dot(a, gradient);
        }
        if cholesky(gram, p) {
            cholesky_solve(gram, p, solved);
            for (&r, v) in active.iter().zip(solved.iter()) {
                match r {
                    MARGIN => eta = v.max(0.0),
                    r => every[r] = v.max(0.0),
                }
            }
        }
    }
    y.truncate(rows);
    eta
}
/// `A⁻¹ b` into `b` by Gaussian elimination with partial pivoting (`a` n × n row-major,
/// overwritten); `false` when a pivot is zero (`a` singular).
pub(crate) fn lu_solve(a: &mut [f64], n: usize, b: &mut [f64]) -> bool {
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
