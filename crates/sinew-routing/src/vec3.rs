//! Plain 3-vector arithmetic on `[f64; 3]` and rigid frames `[R column-major, t]`: the inner
//! loops of the segment geometry (`geometry/`) and the constant lengths of the routing's
//! segment plan (`routing/plan.rs`) stay fast without relying on inlining of generic code (the
//! test profile is opt-level 1). Every function is `#[inline(always)]`, so it is compiled with
//! the vector instructions of the pulp dispatch it is called from.

/// `R p + t` for `frame = [R (column-major), t]`.
#[inline(always)]
pub(crate) fn transform(frame: &[f64; 12], p: &[f64; 3]) -> [f64; 3] {
    [
        frame[0] * p[0] + frame[3] * p[1] + frame[6] * p[2] + frame[9],
        frame[1] * p[0] + frame[4] * p[1] + frame[7] * p[2] + frame[10],
        frame[2] * p[0] + frame[5] * p[1] + frame[8] * p[2] + frame[11],
    ]
}

/// `a − b`.
#[inline(always)]
pub(crate) fn sub(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `s a`.
#[inline(always)]
pub(crate) fn scale(a: &[f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// `a · b`.
#[inline(always)]
pub(crate) fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a × b`.
#[inline(always)]
pub(crate) fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// `R v` for `frame = [R (column-major), t]`: a direction turned, not moved.
#[inline(always)]
pub(crate) fn rotate(frame: &[f64; 12], v: &[f64; 3]) -> [f64; 3] {
    [
        frame[0] * v[0] + frame[3] * v[1] + frame[6] * v[2],
        frame[1] * v[0] + frame[4] * v[1] + frame[7] * v[2],
        frame[2] * v[0] + frame[5] * v[1] + frame[8] * v[2],
    ]
}
