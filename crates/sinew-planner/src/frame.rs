//! The interior-point method's coordinates: the equilibrium set's `λ` shifted to the centre of
//! its closed-form box and scaled by the box's half-widths (`λ = λ_c + W x`, `x ∈ [−1, 1]`),
//! joints held at a level removed, the pencil and the rows in those coordinates, and the basis
//! `R` of `null(J_r)` for the stiffness blocks.
//!
//! # Math
//! With `N` orthonormal, every balancing `f = f_p + N λ` has `λ = Nᵀ(f − f_p)`, so over
//! `f_min ≤ f ≤ f_max` each `λ_i` lies in `[Σ_c min(N_ci a_c, N_ci b_c), Σ_c max(…)]`,
//! `a = f_min − f_p`, `b = f_max − f_p`: a box that holds the whole polytope, hence every
//! optimum (the certificate's `[lo, hi]`). Scaling `x` to it and each matrix block by its
//! diagonal makes the method's numbers O(1) (`λ ~ 10² N`, `A_i ~ 10⁻² N m/rad per N`).

use std::ops::Range;

use sinew_statics::EquilibriumSet;

use crate::bundle::Linear;
use crate::dense::mirror_lower;
use crate::pencil::Pencil;

/// The pencil, the rows and the box in the scaled coordinates `x`.
#[derive(Debug, Clone)]
pub(crate) struct Frame {
    /// Degrees of freedom.
    pub(crate) n: usize,
    /// `λ`'s index of each free coordinate.
    pub(crate) free: Vec<usize>,
    /// `λ` at `x = 0` (held coordinates at their values).
    pub(crate) base: Vec<f64>,
    /// The half-width of each free coordinate's box.
    pub(crate) width: Vec<f64>,
    /// `A(x = 0)`, n × n row-major, N m/rad.
    pub(crate) a0: Vec<f64>,
    /// `∂A/∂x_a = w_a A_i`, one per free coordinate, stored as its square over `spans[a]`
    /// (row-major, `|span|²` entries; zero outside it).
    pub(crate) ai: Vec<Vec<f64>>,
    /// The rows and columns where each `∂A/∂x_a` can be non-zero ([`Pencil::spans`]): a
    /// decoupled joint's 2 × 2 block, a routed cable's DOFs from the base to its anchor.
    pub(crate) spans: Vec<Range<usize>>,
    /// A stiffness scale of the pencil (its largest diagonal entry at `x = 0`), N m/rad.
    pub(crate) a_scale: f64,
    /// `J_x`, 6 × n row-major.
    pub(crate) j_x: Vec<f64>,
    /// The rows `G x ≤ h`, each scaled to a largest coefficient of 1 (rows × free).
    pub(crate) rows: Vec<f64>,
    pub(crate) rhs: Vec<f64>,
    /// `Σ f = total + sumsᵀ x`, N.
    pub(crate) total: f64,
    pub(crate) sums: Vec<f64>,
    /// Scratch of [`Frame::fill`]: the box of `λ` (then `Nᵀ 1` in `lo`).
    lo: Vec<f64>,
    hi: Vec<f64>,
}

/// The closed-form box of `λ` over the tension limits into `(lo, hi)`.
pub(crate) fn lambda_box(set: &EquilibriumSet, lo: &mut Vec<f64>, hi: &mut Vec<f64>) {
    let null = set.null_basis();
    let p = set.particular();
    lo.clear();
    lo.resize(set.dimension(), 0.0);
    hi.clear();
    hi.resize(set.dimension(), 0.0);
    for i in 0..set.dimension() {
        for c in 0..set.cable_count() {
            let a = null[(c, i)] * (set.lower()[c] - p[c]);
            let b = null[(c, i)] * (set.upper()[c] - p[c]);
            lo[i] += a.min(b);
            hi[i] += a.max(b);
        }
    }
}

/// The symmetric part of the pencil's matrix `a` (`a[(r, c)]` is entry `r` of column `c`),
/// scaled by `scale`, over the rows and columns `span` where the matrix can be non-zero (a
/// decoupled `A_i` is one 2 × 2 joint block: `Pencil::spans`), added into the lower triangle
/// of `out`, row-major, a square of side `side` whose first row and column are `origin`'s
/// ([`mirror_lower`] completes it once every term is in).
///
/// Entry `(r, c)`, `r ≥ c`, gains `0.5 s a[(r, c)]`, then `0.5 s a[(c, r)]`. The plain double
/// loop, which adds `0.5 s a[(r, c)]` at both `(r, c)` and `(c, r)` column by column, adds the
/// same two terms in the same order to both entries. So the result is that loop's, bit for bit.
fn add_symmetric(
    a: &faer::Mat<f64>,
    span: Range<usize>,
    scale: f64,
    out: &mut [f64],
    side: usize,
    origin: usize,
) {
    let half = 0.5 * scale;
    for c in span.clone() {
        let column = &a.col_as_slice(c)[c..span.end];
        let row = &mut out[(c - origin) * side..];
        for ((k, lower), r) in column.iter().enumerate().zip(c..span.end) {
            let upper = a.col_as_slice(r)[c];
            let o = &mut row[k * side + (c - origin)];
            *o = (*o + half * lower) + half * upper;
        }
    }
}

impl Frame {
    /// A frame with no buffers yet ([`Frame::fill`] sizes them).
    pub(crate) fn empty() -> Frame {
        Frame {
            n: 0,
            free: Vec::new(),
            base: Vec::new(),
            width: Vec::new(),
            a0: Vec::new(),
            ai: Vec::new(),
            spans: Vec::new(),
            a_scale: 1.0,
            j_x: Vec::new(),
            rows: Vec::new(),
            rhs: Vec::new(),
            total: 0.0,
            sums: Vec::new(),
            lo: Vec::new(),
            hi: Vec::new(),
        }
    }

    /// The frame of `pencil` on `set` with the rows `linear` (in `λ`) and the coordinates
    /// `held` fixed at their values.
    pub(crate) fn new(
        pencil: &Pencil,
        set: &EquilibriumSet,
        linear: &Linear,
        held: &[(usize, f64)],
    ) -> Frame {
        let mut frame = Frame::empty();
        frame.fill(pencil, set, linear, held);
        frame
    }

    /// [`Frame::new`] into this frame's buffers (a plan's frame is kept in its workspace:
    /// re-planning along a trajectory allocates none of it again).
    pub(crate) fn fill(
        &mut self,
        pencil: &Pencil,
        set: &EquilibriumSet,
        linear: &Linear,
        held: &[(usize, f64)],
    ) {
        let n = pencil.a0.nrows();
        self.n = n;
        let (lo, hi) = (&mut self.lo, &mut self.hi);
        lambda_box(set, lo, hi);
        let base = &mut self.base;
        base.clear();
        base.extend(lo.iter().zip(hi.iter()).map(|(a, b)| 0.5 * (a + b)));
        self.free.clear();
        self.width.clear();
        for i in 0..set.dimension() {
            if let Some(&(_, v)) = held.iter().find(|(c, _)| *c == i) {
                base[i] = v;
                continue;
            }
            let w = 0.5 * (hi[i] - lo[i]);
            if w > 1e-12 * (1.0 + base[i].abs()) {
                self.free.push(i);
                self.width.push(w);
            }
        }
        let span = |i: usize| pencil.spans.get(i).cloned().unwrap_or(0..n);
        self.a0.clear();
        self.a0.resize(n * n, 0.0);
        add_symmetric(&pencil.a0, 0..n, 1.0, &mut self.a0, n, 0);
        for (i, (l, a)) in base.iter().zip(&pencil.ai).enumerate() {
            if *l != 0.0 {
                add_symmetric(a, span(i), *l, &mut self.a0, n, 0);
            }
        }
        mirror_lower(&mut self.a0, n);
        self.spans.clear();
        self.spans.extend(self.free.iter().map(|&i| span(i)));
        self.ai.truncate(self.free.len());
        self.ai.resize_with(self.free.len(), Vec::new);
        for (((&i, w), span), out) in
            self.free.iter().zip(&self.width).zip(&self.spans).zip(&mut self.ai)
        {
            let side = span.len();
            out.clear();
            out.resize(side * side, 0.0);
            add_symmetric(&pencil.ai[i], span.clone(), *w, out, side, span.start);
            mirror_lower(out, side);
        }
        self.a_scale = (0..n).map(|i| self.a0[i * n + i].abs()).fold(0.0, f64::max).max(1e-12);
        self.j_x.clear();
        for r in 0..6 {
            self.j_x.extend((0..n).map(|c| pencil.j_x[(r, c)]));
        }
        let k = self.free.len();
        let (rows, rhs) = (&mut self.rows, &mut self.rhs);
        rows.clear();
        rhs.clear();
        for (row, h) in linear.rows().zip(&linear.rhs) {
            let shift: f64 = row.iter().zip(base.iter()).map(|(a, b)| a * b).sum();
            let start = rows.len();
            rows.extend(self.free.iter().zip(&self.width).map(|(&i, w)| row[i] * w));
            let g = &mut rows[start..];
            let scale = g.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
            if scale <= 1e-14 * row.iter().fold(0.0_f64, |a, v| a.max(v.abs())).max(1e-300) {
                // A row on held coordinates only: a constant, checked by the caller's start.
                rows.truncate(start);
                continue;
            }
            g.iter_mut().for_each(|v| *v /= scale);
            rhs.push((h - shift) / scale);
        }
        // Σ f = Σ f_p + (Nᵀ1)ᵀ λ (`Nᵀ1` into `lo`, no longer needed).
        let column_sums = &mut self.lo;
        column_sums.clear();
        column_sums.extend(crate::rows::column_sums(set));
        self.total = set.particular().iter().sum::<f64>()
            + column_sums.iter().zip(base.iter()).map(|(a, b)| a * b).sum::<f64>();
        self.sums.clear();
        self.sums.extend(self.free.iter().zip(&self.width).map(|(&i, w)| column_sums[i] * w));
        debug_assert_eq!(self.rows.len(), self.rhs.len() * k);
    }

    /// Free coordinates.
    pub(crate) fn vars(&self) -> usize {
        self.free.len()
    }

    /// `λ` of `x`.
    pub(crate) fn lambda(&self, x: &[f64]) -> Vec<f64> {
        let mut l = self.base.clone();
        for ((&i, w), v) in self.free.iter().zip(&self.width).zip(x) {
            l[i] += w * v;
        }
        l
    }

    /// `x` of the tensions `f` (the held coordinates ignored) into `out`: `λ = Nᵀ(f − f_p)`
    /// ([`EquilibriumSet::coordinates`]), then `x_a = (λ_i − λ_c,i) / w_i`.
    pub(crate) fn x_of_tensions(&self, set: &EquilibriumSet, f: &[f64], out: &mut Vec<f64>) {
        let (null, p) = (set.null_basis(), set.particular());
        let m = set.cable_count().min(f.len());
        out.clear();
        out.extend(self.free.iter().zip(&self.width).map(|(&i, w)| {
            let lambda: f64 = (0..m).map(|c| null[(c, i)] * (f[c] - p[c])).sum();
            (lambda - self.base[i]) / w
        }));
    }

    /// `A(x)` into `out` (n × n).
    pub(crate) fn a_at(&self, x: &[f64], out: &mut [f64]) {
        out.copy_from_slice(&self.a0);
        for (a, v) in x.iter().enumerate() {
            self.add_ai(a, *v, out, self.n);
        }
    }

    /// `out += scale · ∂A/∂x_a` on the leading n × n of the row-major `out` of side `side`.
    pub(crate) fn add_ai(&self, a: usize, scale: f64, out: &mut [f64], side: usize) {
        let span = self.spans[a].clone();
        let w = span.len();
        for (r, row) in span.clone().zip(self.ai[a].chunks_exact(w.max(1))) {
            let out = &mut out[r * side + span.start..r * side + span.end];
            for (o, e) in out.iter_mut().zip(row) {
                *o += scale * e;
            }
        }
    }

    /// `scale · ∂A/∂x_a`, n × n row-major.
    #[cfg(test)]
    pub(crate) fn ai_dense(&self, a: usize, scale: f64) -> Vec<f64> {
        let mut out = vec![0.0; self.n * self.n];
        self.add_ai(a, scale, &mut out, self.n);
        out
    }

    /// `vᵀ (∂A/∂x_a) v`.
    pub(crate) fn ai_form(&self, a: usize, v: &[f64]) -> f64 {
        let span = self.spans[a].clone();
        let w = span.len();
        let v = &v[span.clone()];
        self.ai[a]
            .chunks_exact(w.max(1))
            .zip(v)
            .map(|(row, vr)| vr * row.iter().zip(v).map(|(e, vc)| e * vc).sum::<f64>())
            .sum()
    }

    /// `out = (∂A/∂x_a) v` (n).
    pub(crate) fn ai_apply(&self, a: usize, v: &[f64], out: &mut [f64]) {
        let span = self.spans[a].clone();
        let w = span.len();
        out.fill(0.0);
        for (o, row) in out[span.clone()].iter_mut().zip(self.ai[a].chunks_exact(w.max(1))) {
            *o = row.iter().zip(&v[span.clone()]).map(|(e, vc)| e * vc).sum();
        }
    }

    /// `R`: an orthonormal basis of `null(J_r)` (n × (n − 3), row-major), the last n − 3
    /// columns of `Q = H₀ H₁ H₂`, the Householder reflections that triangularise `J_rᵀ`
    /// (n × 3); `None` when `J_r` has rank < 3 (a column's part on and below the diagonal,
    /// once reflected, is at most 1e-9 of its norm).
    #[cfg(test)]
    pub(crate) fn rotation_null_basis(&self) -> Option<Vec<f64>> {
        let (mut basis, mut out) = (Vec::new(), Vec::new());
        self.rotation_null_basis_into(&mut basis, &mut out).then_some(out)
    }

    /// [`Self::rotation_null_basis`] into `out`, `basis` scratch (both reused): whether there
    /// is one. `O(n²)`: three reflections applied to the n − 3 unit columns.
    pub(crate) fn rotation_null_basis_into(
        &self,
        basis: &mut Vec<f64>,
        out: &mut Vec<f64>,
    ) -> bool {
        use crate::dense::{axpy, dot};
        let n = self.n;
        out.clear();
        if n < 6 {
            return false;
        }
        let p = n - 3;
        // The columns of J_rᵀ (n each), then the reflections' vectors v_j (zero above row j),
        // then a row of p.
        basis.clear();
        basis.extend_from_slice(&self.j_x[3 * n..6 * n]);
        basis.resize(6 * n + p, 0.0);
        let (columns, rest) = basis.split_at_mut(3 * n);
        let (vectors, w) = rest.split_at_mut(3 * n);
        let mut betas = [0.0; 3];
        for j in 0..3 {
            let (done, later) = columns.split_at_mut((j + 1) * n);
            let column = &done[j * n..];
            let (scale, alpha) =
                (dot(column, column).sqrt(), dot(&column[j..], &column[j..]).sqrt());
            if !(alpha > 1e-9 * scale && alpha.is_finite()) {
                return false;
            }
            let v = &mut vectors[j * n..j * n + n];
            v[j..].copy_from_slice(&column[j..]);
            v[j] += if column[j] >= 0.0 { alpha } else { -alpha };
            betas[j] = 2.0 / dot(&v[j..], &v[j..]);
            for c in later.chunks_exact_mut(n) {
                let d = betas[j] * dot(&v[j..], &c[j..]);
                axpy(-d, &v[j..], &mut c[j..]);
            }
        }
        // Q E, E the unit columns 3..n: H₂, then H₁, then H₀, each `X −= β v (vᵀ X)`.
        out.resize(n * p, 0.0);
        for c in 0..p {
            out[(c + 3) * p + c] = 1.0;
        }
        for j in (0..3).rev() {
            let v = &vectors[j * n..j * n + n];
            w.fill(0.0);
            for r in j..n {
                axpy(v[r], &out[r * p..r * p + p], w);
            }
            for r in j..n {
                axpy(-betas[j] * v[r], w, &mut out[r * p..r * p + p]);
            }
        }
        true
    }
}

/// `Rᵀ M R` (M n × n symmetric, R n × p, both row-major) into `out` (p × p), symmetric, by
/// two of faer's products (`t`, n × p, scratch).
pub(crate) fn congruence(
    m: &[f64],
    r: &[f64],
    (n, p): (usize, usize),
    t: &mut Vec<f64>,
    out: &mut [f64],
) {
    use faer::{Accum, MatMut, MatRef, Par};
    t.clear();
    t.resize(n * p, 0.0);
    let (m, r) = (
        MatRef::from_row_major_slice(&m[..n * n], n, n),
        MatRef::from_row_major_slice(&r[..n * p], n, p),
    );
    faer::linalg::matmul::matmul(
        MatMut::from_row_major_slice_mut(t, n, p),
        Accum::Replace,
        m,
        r,
        1.0,
        Par::Seq,
    );
    let t = MatRef::from_row_major_slice(t, n, p);
    let o = MatMut::from_row_major_slice_mut(&mut out[..p * p], p, p);
    faer::linalg::matmul::matmul(o, Accum::Replace, r.transpose(), t, 1.0, Par::Seq);
    crate::dense::symmetrise(out, p);
}

/// `out += Rᵀ (scale · M) R` for an `M` that is zero outside `span × span` (`m` its square
/// there, row-major; a decoupled `A_i` is one 2 × 2 joint block), R n × p row-major, `out`
/// p × p and symmetric afterwards: `Σ_{i ∈ span} R_iᵀ t_i`, `t_i = Σ_{j ∈ span} scale m_ij R_j`
/// (`t` p scratch), `O(|span| p²)` instead of a dense congruence's `O(n p²)`.
pub(crate) fn span_congruence(
    (m, span, scale): (&[f64], Range<usize>, f64),
    r: &[f64],
    p: usize,
    t: &mut Vec<f64>,
    out: &mut [f64],
) {
    let w = span.len();
    for (i, row) in span.clone().zip(m.chunks_exact(w.max(1))) {
        t.clear();
        t.resize(p, 0.0);
        for (j, v) in span.clone().zip(row) {
            if *v != 0.0 {
                crate::dense::axpy(scale * v, &r[j * p..j * p + p], t);
            }
        }
        for (a, ra) in r[i * p..i * p + p].iter().enumerate() {
            if *ra != 0.0 {
                crate::dense::axpy(*ra, t, &mut out[a * p..a * p + p]);
            }
        }
    }
    crate::dense::symmetrise(out, p);
}
