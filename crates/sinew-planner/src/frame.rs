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
}

/// The closed-form box of `λ` over the tension limits: `(lo, hi)`.
pub(crate) fn lambda_box(set: &EquilibriumSet) -> (Vec<f64>, Vec<f64>) {
    let null = set.null_basis();
    let p = set.particular();
    let (mut lo, mut hi) = (vec![0.0; set.dimension()], vec![0.0; set.dimension()]);
    for i in 0..set.dimension() {
        for c in 0..set.cable_count() {
            let a = null[(c, i)] * (set.lower()[c] - p[c]);
            let b = null[(c, i)] * (set.upper()[c] - p[c]);
            lo[i] += a.min(b);
            hi[i] += a.max(b);
        }
    }
    (lo, hi)
}

impl Frame {
    /// The frame of `pencil` on `set` with the rows `linear` (in `λ`) and the coordinates
    /// `held` fixed at their values.
    pub(crate) fn new(
        pencil: &Pencil,
        set: &EquilibriumSet,
        linear: &Linear,
        held: &[(usize, f64)],
    ) -> Frame {
        let n = pencil.a0.nrows();
        let (lo, hi) = lambda_box(set);
        let mut base: Vec<f64> = lo.iter().zip(&hi).map(|(a, b)| 0.5 * (a + b)).collect();
        let mut free = Vec::new();
        let mut width = Vec::new();
        for i in 0..set.dimension() {
            if let Some(&(_, v)) = held.iter().find(|(c, _)| *c == i) {
                base[i] = v;
                continue;
            }
            let w = 0.5 * (hi[i] - lo[i]);
            if w > 1e-12 * (1.0 + base[i].abs()) {
                free.push(i);
                width.push(w);
            }
        }
        // The symmetric parts, row-major, from the pencil's columns (`a[(r, c)]` is entry `r`
        // of column `c`) over the rows and columns `span` where the matrix can be non-zero
        // (a decoupled `A_i` is one 2 × 2 joint block: `Pencil::spans`), into `out`, a square
        // of side `side` whose first row and column are `origin`'s.
        let symmetric = |a: &faer::Mat<f64>,
                         span: Range<usize>,
                         scale: f64,
                         out: &mut [f64],
                         side: usize,
                         origin: usize| {
            for c in span.clone() {
                for (r, v) in a.col_as_slice(c)[span.clone()].iter().enumerate() {
                    let (r, c) = (r + span.start - origin, c - origin);
                    out[r * side + c] += 0.5 * scale * v;
                    out[c * side + r] += 0.5 * scale * v;
                }
            }
        };
        let span = |i: usize| pencil.spans.get(i).cloned().unwrap_or(0..n);
        let mut a0 = vec![0.0; n * n];
        symmetric(&pencil.a0, 0..n, 1.0, &mut a0, n, 0);
        for (i, (l, a)) in base.iter().zip(&pencil.ai).enumerate() {
            if *l != 0.0 {
                symmetric(a, span(i), *l, &mut a0, n, 0);
            }
        }
        let spans: Vec<Range<usize>> = free.iter().map(|&i| span(i)).collect();
        let ai: Vec<Vec<f64>> = free
            .iter()
            .zip(&width)
            .zip(&spans)
            .map(|((&i, w), span)| {
                let side = span.len();
                let mut out = vec![0.0; side * side];
                symmetric(&pencil.ai[i], span.clone(), *w, &mut out, side, span.start);
                out
            })
            .collect();
        let a_scale = (0..n).map(|i| a0[i * n + i].abs()).fold(0.0, f64::max).max(1e-12);
        let mut j_x = vec![0.0; 6 * n];
        for r in 0..6 {
            for c in 0..n {
                j_x[r * n + c] = pencil.j_x[(r, c)];
            }
        }
        let k = free.len();
        let (mut rows, mut rhs) =
            (Vec::with_capacity(linear.rhs.len() * k), Vec::with_capacity(linear.rhs.len()));
        for (row, h) in linear.rows().zip(&linear.rhs) {
            let shift: f64 = row.iter().zip(&base).map(|(a, b)| a * b).sum();
            let start = rows.len();
            rows.extend(free.iter().zip(&width).map(|(&i, w)| row[i] * w));
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
        let column_sums = crate::rows::column_sums(set);
        let total = set.particular().iter().sum::<f64>()
            + column_sums.iter().zip(&base).map(|(a, b)| a * b).sum::<f64>();
        let sums = free.iter().zip(&width).map(|(&i, w)| column_sums[i] * w).collect();
        debug_assert_eq!(rows.len(), rhs.len() * k);
        Frame { n, free, base, width, a0, ai, spans, a_scale, j_x, rows, rhs, total, sums }
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

    /// `x` of `λ` (the held coordinates ignored).
    pub(crate) fn x_of(&self, lambda: &[f64]) -> Vec<f64> {
        self.free.iter().zip(&self.width).map(|(&i, w)| (lambda[i] - self.base[i]) / w).collect()
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

    /// `R`: an orthonormal basis of `null(J_r)` (n × (n − 3), row-major), by Gram–Schmidt
    /// twice on the rotation rows and then the unit vectors; `None` when `J_r` has rank < 3.
    pub(crate) fn rotation_null_basis(&self) -> Option<Vec<f64>> {
        let n = self.n;
        if n < 6 {
            return None;
        }
        let mut basis: Vec<Vec<f64>> = Vec::with_capacity(n);
        let orthogonalise = |v: &mut Vec<f64>, basis: &[Vec<f64>]| {
            for _ in 0..2 {
                for b in basis {
                    let d: f64 = v.iter().zip(b).map(|(a, c)| a * c).sum();
                    for (x, y) in v.iter_mut().zip(b) {
                        *x -= d * y;
                    }
                }
            }
        };
        for r in 3..6 {
            let mut v = self.j_x[r * n..r * n + n].to_vec();
            let scale = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            orthogonalise(&mut v, &basis);
            let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if !(norm > 1e-9 * scale && norm.is_finite()) {
                return None;
            }
            basis.push(v.iter().map(|x| x / norm).collect());
        }
        let mut out = Vec::with_capacity(n * (n - 3));
        let mut columns = 0;
        for e in 0..n {
            if columns == n - 3 {
                break;
            }
            let mut v = vec![0.0; n];
            v[e] = 1.0;
            orthogonalise(&mut v, &basis);
            let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if norm > 0.3 {
                let v: Vec<f64> = v.iter().map(|x| x / norm).collect();
                basis.push(v);
                columns += 1;
            }
        }
        // Row-major n × (n − 3): R[r, c] = basis[3 + c][r].
        for r in 0..n {
            for c in 0..n - 3 {
                out.push(basis[3 + c][r]);
            }
        }
        (columns == n - 3).then_some(out)
    }
}

/// `Rᵀ M R` (M n × n symmetric, R n × p, both row-major) into a new p × p matrix, over the rows
/// of `M` that are not zero only (a decoupled `A_i` has two): `Σ_{i ∈ S} R_iᵀ (M R)_i`.
pub(crate) fn congruence(m: &[f64], r: &[f64], n: usize, p: usize) -> Vec<f64> {
    let rows: Vec<usize> =
        (0..n).filter(|&i| m[i * n..i * n + n].iter().any(|v| *v != 0.0)).collect();
    let mut mr = vec![0.0; n * p];
    for &i in &rows {
        for k in 0..n {
            let v = m[i * n + k];
            if v == 0.0 {
                continue;
            }
            crate::dense::axpy(v, &r[k * p..k * p + p], &mut mr[i * p..i * p + p]);
        }
    }
    let mut out = vec![0.0; p * p];
    for &i in &rows {
        for a in 0..p {
            let ra = r[i * p + a];
            if ra == 0.0 {
                continue;
            }
            crate::dense::axpy(ra, &mr[i * p..i * p + p], &mut out[a * p..a * p + p]);
        }
    }
    crate::dense::symmetrise(&mut out, p);
    out
}
