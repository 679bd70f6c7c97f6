//! The matrix inequalities and rows of the interior-point planner's problems, in a frame's
//! coordinates (module docs of `ipm.rs` for the blocks), each divided by a scale of its
//! constant so that its entries are O(1).

use nalgebra::Matrix3;

use crate::frame::{Frame, congruence, span_congruence};
use crate::program::Factors;
use crate::sdp::{Block, Sdp};

/// The widest span (DOFs) of a coefficient kept factored in a floor block: a universal joint's
/// two; a routed cable's span from the base is not worth it.
const FACTORED_SPAN: usize = 4;

/// The least block size whose floor is factored: the fixed-size kernels' largest.
const FACTORED_ABOVE: usize = 17;

/// The floor a phase or a requirement puts on `K_fd`: `K_fd ⪰ τ K`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Floor {
    /// `K` (N/m-less: `K_fd ⪰ τ K`).
    pub(crate) k: Matrix3<f64>,
}

/// The scratch of [`floor_block`], kept between blocks.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    /// `P = J_p R` (3 × p).
    jp: Vec<f64>,
    d: Vec<f64>,
    b0: Vec<f64>,
    t: Vec<f64>,
}

/// The base problem: the rows (with `extra` zero columns) and the box, no block.
#[cfg(test)]
pub(crate) fn base(f: &Frame, extra: usize) -> Sdp {
    let mut sdp = Sdp::default();
    base_into(f, extra, &mut sdp);
    sdp
}

/// [`base`]'s problem into `sdp`'s
/// buffers (its blocks kept as spares for [`push_block`]).
pub(crate) fn base_into(f: &Frame, extra: usize, sdp: &mut Sdp) {
    let k = f.vars();
    let width = k + extra;
    sdp.c0 = 0.0;
    sdp.c.clear();
    sdp.c.resize(width, 0.0);
    sdp.rows.clear();
    for r in 0..f.rhs.len() {
        sdp.rows.extend_from_slice(&f.rows[r * k..r * k + k]);
        sdp.rows.extend(std::iter::repeat_n(0.0, extra));
    }
    sdp.rhs.clone_from(&f.rhs);
    sdp.clear_blocks();
    sdp.lo.clear();
    sdp.lo.extend((0..width).map(|e| if e < k { -1.0 } else { f64::NEG_INFINITY }));
    sdp.hi.clear();
    sdp.hi.extend((0..width).map(|e| if e < k { 1.0 } else { f64::INFINITY }));
}

/// A block filled by `fill` (in an earlier block's buffers) pushed onto `sdp`; its index.
pub(crate) fn push_block(sdp: &mut Sdp, fill: impl FnOnce(&mut Block)) -> usize {
    let mut b = sdp.next_block();
    fill(&mut b);
    sdp.blocks.push(b);
    sdp.blocks.len() - 1
}

/// `(A(x) − shift I)/a_scale`, with `−(t_scale/a_scale) I` for an epigraph variable.
pub(crate) fn margin_block(
    f: &Frame,
    shift: f64,
    extra: usize,
    epigraph: Option<f64>,
    b: &mut Block,
) {
    let n = f.n;
    let s = 1.0 / f.a_scale;
    b.recycle(n, f.vars() + extra);
    for (c, v) in b.constant.iter_mut().zip(&f.a0) {
        *c = v * s;
    }
    for i in 0..n {
        b.constant[i * n + i] -= shift * s;
    }
    for a in 0..f.vars() {
        let mut e = b.fresh(n * n);
        f.add_ai(a, s, &mut e, n);
        b.coefficients[a] = Some(e);
    }
    if let Some(t_scale) = epigraph {
        let mut d = b.fresh(n * n);
        for i in 0..n {
            d[i * n + i] = -t_scale * s;
        }
        b.coefficients[f.vars()] = Some(d);
    }
}

/// `Rᵀ(A − τ J_pᵀ K J_p)R / scale`, with `τ` fixed or `τ = t_scale · t`; `r` the basis `R`
/// of `null(J_r)` (n × (n − 3)).
pub(crate) fn floor_block(
    f: &Frame,
    r: &[f64],
    floor: Floor,
    tau: Result<f64, f64>,
    extra: usize,
    (b, scratch): (&mut Block, &mut Scratch),
) {
    let (n, p) = (f.n, f.n - 3);
    let Scratch { jp, d, b0, t } = scratch;
    // P = J_p R (3 × p), then D = Rᵀ J_pᵀ K J_p R = Pᵀ K P (its lower triangle, mirrored).
    jp.clear();
    for i in 0..3 {
        for c in 0..p {
            jp.push((0..n).map(|a| f.j_x[i * n + a] * r[a * p + c]).sum());
        }
    }
    for m in [&mut *d, &mut *b0] {
        m.clear();
        m.resize(p * p, 0.0);
    }
    for a in 0..p {
        let kp: [f64; 3] =
            std::array::from_fn(|j| (0..3).map(|i| jp[i * p + a] * floor.k[(i, j)]).sum());
        for c in 0..=a {
            let v = (0..3).map(|j| kp[j] * jp[j * p + c]).sum();
            d[a * p + c] = v;
            d[c * p + a] = v;
        }
    }
    congruence(&f.a0, r, (n, p), t, b0);
    let scale = (0..p).map(|i| b0[i * p + i].abs()).fold(0.0, f64::max).max(1e-300);
    let s = 1.0 / scale;
    let fixed = tau.unwrap_or(0.0);
    b.recycle(p, f.vars() + extra);
    for ((c, v), dd) in b.constant.iter_mut().zip(b0.iter()).zip(d.iter()) {
        *c = (v - fixed * dd) * s;
    }
    for a in 0..f.vars() {
        let mut e = b.fresh(p * p);
        span_congruence((&f.ai[a], f.spans[a].clone(), s), r, p, t, &mut e);
        b.coefficients[a] = Some(e);
    }
    if let Err(t_scale) = tau {
        let mut e = b.fresh(p * p);
        for (o, v) in e.iter_mut().zip(d.iter()) {
            *o = -t_scale * v * s;
        }
        b.coefficients[f.vars()] = Some(e);
    }
    // Where every joint's block spans few DOFs (the decoupled model) and the block is above
    // the fixed-size kernels: factored, `B_a = s A_a` over its span. Below, the fixed-size
    // dense products are faster (cdhrm5: 1.54 M instructions a plan dense, 1.95 M factored);
    // with wide spans among them (routed), the unfactored pairs cost more than before. (The
    // factors are allocated per block: only above the fixed-size kernels.)
    let factored = p > FACTORED_ABOVE && f.spans.iter().all(|s| s.len() <= FACTORED_SPAN);
    b.factors = factored.then(|| {
        // The basis `R` (n × p) and below it `P = J_p R` (3 × p): the epigraph's coefficient
        // `−t s Rᵀ J_pᵀ K J_p R = Pᵀ (−t s K) P` is then factored too, on the rows n..n+3 (its
        // Schur terms 3 × 3 forms instead of five p × p products an iteration).
        let mut basis = Vec::with_capacity((n + 3) * p);
        basis.extend_from_slice(&r[..n * p]);
        basis.extend_from_slice(jp);
        let mut small: Vec<_> = (0..b.coefficients.len())
            .map(|a| {
                f.spans.get(a).map(|span| (span.clone(), f.ai[a].iter().map(|v| v * s).collect()))
            })
            .collect();
        if let (Err(t_scale), Some(slot)) = (tau, small.get_mut(f.vars())) {
            let k = (0..9).map(|e| -t_scale * s * floor.k[(e / 3, e % 3)]).collect();
            *slot = Some((n..n + 3, k));
        }
        Factors { basis, q: n + 3, small }
    });
}

/// `[[A, J_pᵀu], [uᵀJ_p, s]]` congruence-scaled by `diag(a_scale^{-1/2} I, s_scale^{-1/2})`,
/// `s = s_scale · t`.
pub(crate) fn compliance_block(f: &Frame, u: &nalgebra::Vector3<f64>, s_scale: f64, b: &mut Block) {
    let n = f.n;
    let m = n + 1;
    let sa = 1.0 / f.a_scale;
    let cross = 1.0 / (f.a_scale * s_scale).sqrt();
    b.recycle(m, f.vars() + 1);
    for r in 0..n {
        for c in 0..n {
            b.constant[r * m + c] = f.a0[r * n + c] * sa;
        }
        let v: f64 = (0..3).map(|i| f.j_x[i * n + r] * u[i]).sum();
        b.constant[r * m + n] = v * cross;
        b.constant[n * m + r] = v * cross;
    }
    for a in 0..f.vars() {
        let mut e = b.fresh(m * m);
        f.add_ai(a, sa, &mut e, m);
        b.coefficients[a] = Some(e);
    }
    let mut d = b.fresh(m * m);
    d[n * m + n] = 1.0;
    b.coefficients[f.vars()] = Some(d);
}
