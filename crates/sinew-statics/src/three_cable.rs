//! The equilibrium set's closed forms for universal joints driven by three cables each (module
//! docs of `set_block.rs` for the single joint): no SVD where the routing has this shape.
//!
//! # Math
//! **One joint**, `J` 3 × 2 with columns `a`, `b`: `null(Jᵀ)` is spanned by
//! `n = a × b / |a × b|` (oriented so that `Σ n > 0`), and `(Jᵀ)⁺ = (I − n nᵀ) E`, `E` the
//! inverse of the 2 × 2 minor of `Jᵀ` on the two cables other than the one of `a × b`'s
//! largest component, placed on their rows.
//!
//! **A routed arm**: every cable ends at one joint and crosses only joints before it, so with
//! the cables grouped by the joint they end at, `J_cᵀ` is block upper triangular with the
//! joints' own 3 × 2 blocks `B_l` on its diagonal. `J_cᵀ f = r` is solved from the tip:
//! `f_l = (B_lᵀ)⁺ (r_l − Σ_{l' > l} B_{l'l}ᵀ f_{l'})`. The vector `v_j` with `n_j` on joint
//! `j`'s cables, zero beyond, and the back-substitution of `r = 0` before, lies in
//! `null(J_cᵀ)`; the `v_j` are independent (triangular) and there are `m − dof` of them, so
//! Gram–Schmidt (twice) in the order `j = 0, 1, …` gives an orthonormal `N` whose column `j`
//! lives on the cables of joints `0..=j`: the block-triangular basis built from the tip. Then
//! `f_p = f* − N Nᵀ f*` for the back-substituted `f*` of `r = −t`. `J_c⁺` is not formed: `J_c`
//! is block lower triangular with the blocks `B_l` on its diagonal, so `J_c⁺ w` comes on demand
//! by forward substitution from the base on `w − N Nᵀ w` ([`triangular_motion`]). Taken when
//! every joint's own block passes the single joint's conditioning test; anything else goes to
//! the SVD.

use std::ops::Range;

use faer::{Mat, MatRef};

/// The closed form of a three-cable joint is taken when its smallest singular value is at least
/// this fraction of its largest.
const CLOSED_FORM_CONDITION: f64 = 1e-6;

/// `n` and `(Jᵀ)⁺` (3 × 2, rows by cable) of a 3 × 2 block of columns `a`, `b`, or `None` for a
/// block too close to rank 1 (module docs).
fn joint_pieces(a: [f64; 3], b: [f64; 3]) -> Option<([f64; 3], [[f64; 2]; 3])> {
    let dot = |u: &[f64; 3], w: &[f64; 3]| u[0] * w[0] + u[1] * w[1] + u[2] * w[2];
    let cross = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let (aa, ab, bb) = (dot(&a, &a), dot(&a, &b), dot(&b, &b));
    let area = dot(&cross, &cross).sqrt();
    // σ₁² is the larger eigenvalue of JᵀJ; σ₁ σ₂ = |a × b|.
    let largest = (0.5 * (aa + bb + ((aa - bb).powi(2) + 4.0 * ab * ab).sqrt())).sqrt();
    if !(area.is_finite() && largest > 0.0 && area / largest > CLOSED_FORM_CONDITION * largest) {
        return None;
    }
    let sign = if cross.iter().sum::<f64>() < 0.0 { -1.0 } else { 1.0 };
    let n: [f64; 3] = std::array::from_fn(|r| sign * cross[r] / area);
    let r = (0..3).fold(0, |best, i| if cross[i].abs() > cross[best].abs() { i } else { best });
    let (p, q) = ((r + 1) % 3, (r + 2) % 3);
    // Jᵀ on cables (p, q): [[a_p, a_q], [b_p, b_q]], determinant (a × b)_r.
    let det = cross[r];
    let mut e = [[0.0; 2]; 3];
    e[p] = [b[q] / det, -a[q] / det];
    e[q] = [-b[p] / det, a[p] / det];
    let mut inverse = [[0.0; 2]; 3];
    for col in 0..2 {
        let along: f64 = (0..3).map(|c| n[c] * e[c][col]).sum();
        for c in 0..3 {
            inverse[c][col] = e[c][col] - n[c] * along;
        }
    }
    Some((n, inverse))
}

/// A block's share of the equilibrium set, written by the closed forms: `f_p` on its cables,
/// its columns of `N` (cables × columns) and `J⁺` (DOFs × cables; empty where it comes on
/// demand), in the block's order.
pub(crate) struct Share<'a> {
    pub(crate) particular: &'a mut Vec<f64>,
    pub(crate) null: &'a mut Mat<f64>,
    pub(crate) pseudo_inverse: &'a mut Mat<f64>,
}

/// The closed form of a 3 × 2 block `j` under the torques `t`: `f_p`, `n` and `J⁺` into
/// `out`; `false` (`out` untouched) for another shape or a block too close to rank 1.
pub(crate) fn three_cable_joint(j: MatRef<'_, f64>, t: &[f64], out: Share<'_>) -> bool {
    if j.nrows() != 3 || j.ncols() != 2 {
        return false;
    }
    let column = |d: usize| [j[(0, d)], j[(1, d)], j[(2, d)]];
    let Some((n, inverse)) = joint_pieces(column(0), column(1)) else { return false };
    out.particular.clear();
    out.particular.extend((0..3).map(|c| -(inverse[c][0] * t[0] + inverse[c][1] * t[1])));
    out.null.resize_with(3, 1, |_, _| 0.0);
    out.pseudo_inverse.resize_with(2, 3, |_, _| 0.0);
    for c in 0..3 {
        out.null[(c, 0)] = n[c];
        for d in 0..2 {
            out.pseudo_inverse[(d, c)] = inverse[c][d];
        }
    }
    true
}

/// The scratch of [`triangular`], kept with the set.
#[derive(Debug, Default)]
pub(crate) struct Triangular {
    /// The cables that end at each joint.
    ends: Vec<[usize; 3]>,
    /// How many cables end at each joint.
    counts: Vec<usize>,
    /// Each joint's own `n` and `(B_lᵀ)⁺`.
    pieces: Vec<([f64; 3], [[f64; 2]; 3])>,
    /// `N`'s columns, m each, one after the other.
    null: Vec<f64>,
    /// Right-hand sides (dof) and a back-substituted vector (m).
    rhs: Vec<f64>,
    column: Vec<f64>,
}

impl Triangular {
    /// Each cable's joint (that of its last non-zero DOF of `j`, cables × DOFs with two DOFs
    /// per joint) and each joint's own `n` and `(B_lᵀ)⁺`; `false` unless three cables end at
    /// every joint and each joint's own block has the closed form.
    fn chain_pieces(&mut self, j: MatRef<'_, f64>) -> bool {
        let (m, dof) = (j.nrows(), j.ncols());
        let joints = dof / 2;
        // Each cable's joint: that of its last non-zero DOF; three per joint.
        self.ends.clear();
        self.ends.resize(joints, [0; 3]);
        self.counts.clear();
        self.counts.resize(joints, 0);
        for c in 0..m {
            let Some(last) = (0..dof).rev().find(|&d| j[(c, d)] != 0.0) else { return false };
            let l = last / 2;
            if self.counts[l] == 3 {
                return false;
            }
            self.ends[l][self.counts[l]] = c;
            self.counts[l] += 1;
        }
        if self.counts.iter().any(|&n| n != 3) {
            return false;
        }
        self.pieces.clear();
        for (l, cables) in self.ends.iter().enumerate() {
            let column = |d: usize| cables.map(|c| j[(c, 2 * l + d)]);
            let Some(pieces) = joint_pieces(column(0), column(1)) else { return false };
            self.pieces.push(pieces);
        }
        true
    }
}

/// The routed arm's block-triangular closed form (module docs) of the block `j` (cables ×
/// DOFs, its `dofs` global) under the torques `t` (on the block's DOFs), with the arm's joints
/// `groups`: `f_p` and `N`'s columns into `out`, its `J⁺` left empty (on demand by
/// [`triangular_motion`]); `false` (`out` untouched) when the block
/// does not have the shape (two DOFs per joint, three cables ending at each) or a joint's own
/// block is too close to rank 1.
pub(crate) fn triangular(
    (j, dofs): (MatRef<'_, f64>, &[usize]),
    groups: &[Range<usize>],
    t: &[f64],
    s: &mut Triangular,
    out: Share<'_>,
) -> bool {
    let (m, dof) = (j.nrows(), j.ncols());
    // The block's joints: consecutive pairs of its DOFs, each a whole joint of the arm.
    if dof % 2 != 0 || m != 3 * dof / 2 {
        return false;
    }
    let joints = dof / 2;
    for l in 0..joints {
        let Some(g) = groups.iter().find(|g| g.start == dofs[2 * l]) else { return false };
        if g.len() != 2 || dofs[2 * l + 1] != g.start + 1 {
            return false;
        }
    }
    if !s.chain_pieces(j) {
        return false;
    }
    let (ends, pieces) = (&s.ends, &s.pieces);
    // J_cᵀ f = r on the joints before `from`, from the tip down, with f already set on the
    // cables of joints `from..=upto` (and zero beyond).
    let solve = |r: &[f64], from: usize, upto: usize, f: &mut [f64]| {
        for l in (0..from).rev() {
            let mut rest = [r[2 * l], r[2 * l + 1]];
            for cables in &ends[l + 1..=upto] {
                for &c in cables {
                    rest[0] -= j[(c, 2 * l)] * f[c];
                    rest[1] -= j[(c, 2 * l + 1)] * f[c];
                }
            }
            let inverse = &pieces[l].1;
            for (row, &c) in ends[l].iter().enumerate() {
                f[c] = inverse[row][0] * rest[0] + inverse[row][1] * rest[1];
            }
        }
    };
    s.rhs.clear();
    s.rhs.resize(dof, 0.0);
    s.null.clear();
    s.null.resize(m * joints, 0.0);
    for top in 0..joints {
        let (done, rest) = s.null.split_at_mut(top * m);
        let v = &mut rest[..m];
        // n_top on joint top's cables; the joints before balance its torques on them.
        for (row, &c) in ends[top].iter().enumerate() {
            v[c] = pieces[top].0[row];
        }
        solve(&s.rhs, top, top, v);
        // Gram–Schmidt twice against the columns before.
        for _ in 0..2 {
            for u in done.chunks_exact(m) {
                let along: f64 = u.iter().zip(v.iter()).map(|(a, b)| a * b).sum();
                v.iter_mut().zip(u).for_each(|(x, y)| *x -= along * y);
            }
        }
        let size = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !(size > 0.0 && size.is_finite()) {
            return false;
        }
        v.iter_mut().for_each(|x| *x /= size);
    }
    let null = &s.null;
    let project = |f: &mut [f64]| {
        for u in null.chunks_exact(m) {
            let along: f64 = u.iter().zip(f.iter()).map(|(a, b)| a * b).sum();
            f.iter_mut().zip(u).for_each(|(x, y)| *x -= along * y);
        }
    };
    s.column.clear();
    s.column.resize(m, 0.0);
    s.rhs.iter_mut().zip(t).for_each(|(r, t)| *r = -t);
    solve(&s.rhs, joints, joints - 1, &mut s.column);
    project(&mut s.column);
    out.particular.clone_from(&s.column);
    // `J⁺` on demand ([`triangular_motion`]): no matrix here.
    out.pseudo_inverse.resize_with(0, 0, |_, _| 0.0);
    out.null.resize_with(m, joints, |_, _| 0.0);
    for (i, u) in null.chunks_exact(m).enumerate() {
        for (c, v) in u.iter().enumerate() {
            out.null[(c, i)] = *v;
        }
    }
    true
}

/// `J⁺ w` of a block that [`triangular`] took, `j` its submatrix of `J_c` (cables × DOFs) and
/// `w` (on its cables) already projected onto the range of `j` (`w − N Nᵀ w`): the joint
/// motion `δq` (into `out`, dof) with `j δq = w`, by forward substitution from the base. The
/// cables of joint `l` move only the joints up to `l`, so `δq_l = B_l⁺ (w_l − Σ_{l' < l}
/// J_{l l'} δq_{l'})` with `B_l⁺ = ((B_lᵀ)⁺)ᵀ`, a left inverse of the joint's own block; the
/// system is consistent and `j` has full column rank, so this is the least-squares solution
/// `J⁺ w`. `false` (`out` untouched) when `j` does not have the shape.
pub(crate) fn triangular_motion(j: MatRef<'_, f64>, w: &[f64], out: &mut [f64]) -> bool {
    let mut s = Triangular::default();
    if j.ncols() % 2 != 0 || j.nrows() != 3 * j.ncols() / 2 || !s.chain_pieces(j) {
        return false;
    }
    for (l, (cables, (_, inverse))) in s.ends.iter().zip(&s.pieces).enumerate() {
        let rest = cables.map(|c| w[c] - (0..2 * l).map(|d| j[(c, d)] * out[d]).sum::<f64>());
        for d in 0..2 {
            out[2 * l + d] = (0..3).map(|row| inverse[row][d] * rest[row]).sum();
        }
    }
    true
}
