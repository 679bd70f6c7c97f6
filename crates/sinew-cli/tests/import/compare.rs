//! Comparing the JSON of the `sinew` commands with numbers computed in the test.

use nalgebra::DMatrix;
use serde_json::Value;

pub fn numbers(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

pub fn matrix(v: &Value) -> DMatrix<f64> {
    let rows: Vec<Vec<f64>> = v.as_array().unwrap().iter().map(numbers).collect();
    DMatrix::from_fn(rows.len(), rows[0].len(), |r, c| rows[r][c])
}

/// Entry by entry within `rel` of the largest entry of `want`.
pub fn close(what: &str, got: &DMatrix<f64>, want: &DMatrix<f64>, rel: f64) {
    assert_eq!(got.shape(), want.shape(), "{what}");
    let tol = rel * want.amax().max(f64::MIN_POSITIVE);
    let worst = (got - want).amax();
    assert!(worst <= tol, "{what}: off by {worst:e} (tolerance {tol:e})\n got {got}\nwant {want}");
}

pub fn close_v(what: &str, got: &Value, want: &[f64], rel: f64) {
    let got = numbers(got);
    close(
        what,
        &DMatrix::from_row_slice(1, got.len(), &got),
        &DMatrix::from_row_slice(1, want.len(), want),
        rel,
    );
}

pub fn sub(m: &DMatrix<f64>, r: std::ops::Range<usize>, c: std::ops::Range<usize>) -> DMatrix<f64> {
    m.view((r.start, c.start), (r.len(), c.len())).into_owned()
}
