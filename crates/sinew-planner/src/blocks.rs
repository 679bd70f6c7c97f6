//! The matrix inequalities and rows of the interior-point planner's problems, in a frame's
//! coordinates (module docs of `ipm.rs` for the blocks), each divided by a scale of its
//! constant so that its entries are O(1).

use nalgebra::Matrix3;

use crate::frame::{Frame, congruence};
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

/// The base problem: the rows (with `extra` zero columns) and the box, no block.
pub(crate) fn base(f: &Frame, extra: usize) -> Sdp {
    let mut sdp = Sdp::default();
    base_into(f, extra, &mut sdp);
    sdp
}

/// [`base`] into `sdp`'s buffers (its blocks and epigraph removed).
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
    sdp.blocks.clear();
    sdp.lo.clear();
    sdp.lo.extend((0..width).map(|e| if e < k { -1.0 } else { f64::NEG_INFINITY }));
    sdp.hi.clear();
    sdp.hi.extend((0..width).map(|e| if e < k { 1.0 } else { f64::INFINITY }));
    sdp.epigraph = None;
}

/// `(A(x) − shift I)/a_scale`, with `−(t_scale/a_scale) I` for an epigraph variable.
pub(crate) fn margin_block(f: &Frame, shift: f64, extra: usize, epigraph: Option<f64>) -> Block {
    let n = f.n;
    let s = 1.0 / f.a_scale;
    let mut constant: Vec<f64> = f.a0.iter().map(|v| v * s).collect();
    for i in 0..n {
        constant[i * n + i] -= shift * s;
    }
    let mut coefficients: Vec<Option<Vec<f64>>> =
        (0..f.vars()).map(|a| Some(f.ai_dense(a, s))).collect();
    coefficients.extend(std::iter::repeat_n(None, extra));
    if let Some(t_scale) = epigraph {
        let mut d = vec![0.0; n * n];
        for i in 0..n {
            d[i * n + i] = -t_scale * s;
        }
        coefficients[f.vars()] = Some(d);
    }
    Block { n, constant, coefficients, factors: None }
}

/// `Rᵀ(A − τ J_pᵀ K J_p)R / scale`, with `τ` fixed or `τ = t_scale · t`.
pub(crate) fn floor_block(
    f: &Frame,
    rotation_null: Option<&Vec<f64>>,
    floor: Floor,
    tau: Result<f64, f64>,
    extra: usize,
) -> Option<Block> {
    let r = rotation_null?;
    let (n, p) = (f.n, f.n - 3);
    // Q = J_pᵀ K J_p (n × n).
    let mut q = vec![0.0; n * n];
    for a in 0..n {
        for b in 0..n {
            let mut v = 0.0;
            for i in 0..3 {
                for j in 0..3 {
                    v += f.j_x[i * n + a] * floor.k[(i, j)] * f.j_x[j * n + b];
                }
            }
            q[a * n + b] = v;
        }
    }
    let d = congruence(&q, r, n, p);
    let b0 = congruence(&f.a0, r, n, p);
    let scale = (0..p).map(|i| b0[i * p + i].abs()).fold(0.0, f64::max).max(1e-300);
    let s = 1.0 / scale;
    let fixed = tau.unwrap_or(0.0);
    let constant: Vec<f64> = b0.iter().zip(&d).map(|(b, dd)| (b - fixed * dd) * s).collect();
    let mut coefficients: Vec<Option<Vec<f64>>> =
        (0..f.vars()).map(|a| Some(congruence(&f.ai_dense(a, s), r, n, p))).collect();
    coefficients.extend(std::iter::repeat_n(None, extra));
    if let Err(t_scale) = tau {
        coefficients[f.vars()] = Some(d.iter().map(|v| -t_scale * v * s).collect());
    }
    // Where every joint's block spans few DOFs (the decoupled model) and the block is above
    // the fixed-size kernels: factored, `B_a = s A_a` over its span. Below, the fixed-size
    // dense products are faster (cdhrm5: 1.54 M instructions a plan dense, 1.95 M factored);
    // with wide spans among them (routed), the unfactored pairs cost more than before.
    let factored = p > FACTORED_ABOVE && f.spans.iter().all(|s| s.len() <= FACTORED_SPAN);
    let factors = factored.then(|| Factors {
        basis: r.clone(),
        q: n,
        small: (0..coefficients.len())
            .map(|a| {
                f.spans.get(a).map(|span| (span.clone(), f.ai[a].iter().map(|v| v * s).collect()))
            })
            .collect(),
    });
    Some(Block { n: p, constant, coefficients, factors })
}

/// `[[A, J_pᵀu], [uᵀJ_p, s]]` congruence-scaled by `diag(a_scale^{-1/2} I, s_scale^{-1/2})`,
/// `s = s_scale · t`.
pub(crate) fn compliance_block(f: &Frame, u: &nalgebra::Vector3<f64>, s_scale: f64) -> Block {
    let n = f.n;
    let m = n + 1;
    let sa = 1.0 / f.a_scale;
    let cross = 1.0 / (f.a_scale * s_scale).sqrt();
    let mut constant = vec![0.0; m * m];
    for r in 0..n {
        for c in 0..n {
            constant[r * m + c] = f.a0[r * n + c] * sa;
        }
        let b: f64 = (0..3).map(|i| f.j_x[i * n + r] * u[i]).sum();
        constant[r * m + n] = b * cross;
        constant[n * m + r] = b * cross;
    }
    let mut coefficients: Vec<Option<Vec<f64>>> = (0..f.vars())
        .map(|a| {
            let mut e = vec![0.0; m * m];
            f.add_ai(a, sa, &mut e, m);
            Some(e)
        })
        .collect();
    let mut d = vec![0.0; m * m];
    d[n * m + n] = 1.0;
    coefficients.push(Some(d));
    Block { n: m, constant, coefficients, factors: None }
}
