//! Error measures and central differences: how the tests check every analytic derivative
//! (against central differences with step [`H`], each test bounding each robot at a few times
//! the error it measured, docs/ARCHITECTURE.md).

use faer::{Mat, MatRef};

/// Step of the central differences: balances truncation (h²) against round-off (ε/h).
pub const H: f64 = 1e-6;

/// `max |m_ij|` (0 for an empty matrix).
pub fn max_abs(m: MatRef<'_, f64>) -> f64 {
    let mut x: f64 = 0.0;
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            x = x.max(m[(i, j)].abs());
        }
    }
    x
}

/// `(max |a − b|, max |a|)` over two matrices of the same shape.
///
/// # Panics
/// When the shapes differ.
pub fn max_diff_and_scale(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> (f64, f64) {
    assert_eq!((a.nrows(), a.ncols()), (b.nrows(), b.ncols()), "shapes differ");
    let mut diff: f64 = 0.0;
    let mut scale: f64 = 0.0;
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            diff = diff.max((a[(i, j)] - b[(i, j)]).abs());
            scale = scale.max(a[(i, j)].abs());
        }
    }
    (diff, scale)
}

/// `max |a − b| / max(1, max |a|)`: the error relative to the analytic value `a`'s scale (an
/// absolute floor of 1 in the quantity's SI unit keeps entries that are zero from dividing).
///
/// # Panics
/// When the shapes differ.
pub fn rel_err(analytic: MatRef<'_, f64>, numeric: MatRef<'_, f64>) -> f64 {
    let (diff, scale) = max_diff_and_scale(analytic, numeric);
    diff / scale.max(1.0)
}

/// `max |a − b| / max |b|`, relative to the reference `b` (0 when the two are equal, so two
/// zero matrices compare equal).
///
/// # Panics
/// When the shapes differ.
pub fn rel_diff(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> f64 {
    let (diff, _) = max_diff_and_scale(a, b);
    if diff == 0.0 { 0.0 } else { diff / max_abs(b) }
}

/// A dense copy.
pub fn to_mat(m: MatRef<'_, f64>) -> Mat<f64> {
    Mat::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)])
}

/// A column vector as a one-column matrix.
pub fn column(v: &[f64]) -> Mat<f64> {
    Mat::from_fn(v.len(), 1, |i, _| v[i])
}

/// `(q + h e_i, q − h e_i)`: the two points of a central difference along coordinate `i`.
///
/// # Panics
/// When `i ≥ q.len()`.
pub fn perturbed(q: &[f64], i: usize, h: f64) -> (Vec<f64>, Vec<f64>) {
    let mut plus = q.to_vec();
    let mut minus = q.to_vec();
    plus[i] += h;
    minus[i] -= h;
    (plus, minus)
}

/// The central-difference Jacobian of `f` at `q`: column `i` is
/// `(f(q + h e_i) − f(q − h e_i)) / 2h`, `f` giving as many values at every point.
///
/// # Panics
/// When `f` gives a different number of values at two points.
pub fn central_difference(q: &[f64], h: f64, mut f: impl FnMut(&[f64]) -> Vec<f64>) -> Mat<f64> {
    let mut out = Mat::zeros(0, q.len());
    for i in 0..q.len() {
        let (plus, minus) = perturbed(q, i, h);
        let (fp, fm) = (f(&plus), f(&minus));
        assert_eq!(fp.len(), fm.len(), "f gives {} and {} values", fp.len(), fm.len());
        if i == 0 {
            out = Mat::zeros(fp.len(), q.len());
        }
        for r in 0..fp.len() {
            out[(r, i)] = (fp[r] - fm[r]) / (2.0 * h);
        }
    }
    out
}

/// The points of an `n`-per-axis grid (`n ≥ 2`) over the cube of half-width `half` around
/// `centre`, the last axis varying fastest: brute-force searches over a few coordinates.
pub fn grid_points(centre: &[f64], half: f64, n: usize) -> Vec<Vec<f64>> {
    let mut points: Vec<Vec<f64>> = vec![Vec::new()];
    for c in centre {
        let axis: Vec<f64> =
            (0..n).map(|i| c - half + 2.0 * half * i as f64 / (n - 1) as f64).collect();
        points = points
            .iter()
            .flat_map(|p| axis.iter().map(move |&a| [p.as_slice(), &[a]].concat()))
            .collect();
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn central_differences_of_a_quadratic_are_exact_to_round_off() {
        // f(q) = [q0² + q1, q0·q1]: J = [[2 q0, 1], [q1, q0]]; central differences of a
        // quadratic have no truncation error.
        let q = [0.3, -0.7];
        let numeric = central_difference(&q, H, |q| vec![q[0] * q[0] + q[1], q[0] * q[1]]);
        let expected = Mat::from_fn(2, 2, |r, c| [[2.0 * q[0], 1.0], [q[1], q[0]]][r][c]);
        assert!(rel_err(expected.as_ref(), numeric.as_ref()) <= 1e-9);
    }

    #[test]
    fn the_two_relative_errors_differ_only_in_their_scale() {
        let a = column(&[0.5, -0.25]);
        let b = column(&[0.5, -0.5]);
        assert_eq!(max_diff_and_scale(a.as_ref(), b.as_ref()), (0.25, 0.5));
        // Floor 1 on the analytic scale; relative to the reference's largest entry.
        assert_eq!(rel_err(a.as_ref(), b.as_ref()), 0.25);
        assert_eq!(rel_diff(a.as_ref(), b.as_ref()), 0.5);
        assert_eq!(rel_diff(a.as_ref(), a.as_ref()), 0.0);
        assert_eq!(perturbed(&[1.0, 2.0], 1, 0.5), (vec![1.0, 2.5], vec![1.0, 1.5]));
    }
}
