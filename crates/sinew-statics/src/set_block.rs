//! One independent block of `J_c` in the equilibrium set ([`crate::EquilibriumSet`]): its
//! minimum-norm balancing tensions, the columns of `null(J_cᵀ)` it holds, and `J_c⁺` on it.
//!
//! # Math
//! A block is a set of cables and the DOFs they move (cables × DOFs submatrix `J` of `J_c`).
//!
//! - **A universal joint driven by three cables** (every joint of a decoupled arm), `J` 3 × 2
//!   with columns `a`, `b`: in closed form, no SVD. `null(Jᵀ)` is spanned by
//!   `n = a × b / |a × b|`, oriented so that `Σ n > 0` (all positive when the joint is in force
//!   closure). `(Jᵀ)⁺ = (I − n nᵀ) E`, `E` the inverse of the 2 × 2 minor of `Jᵀ` on the two
//!   cables other than the one of `a × b`'s largest component (whose determinant that component
//!   is), placed on their rows; then `f_p = −(Jᵀ)⁺ t` and `J⁺ = ((Jᵀ)⁺)ᵀ`, to rounding times
//!   the block's condition number (not its square, as the normal equations would give). The
//!   product of the singular values is `|a × b|` and the largest is the root of `JᵀJ`'s larger
//!   eigenvalue: the closed form is taken when `σ₂ > 10⁻⁶ σ₁`, the SVD below (where the rank
//!   test of [`SET_RANK_TOLERANCE`] decides).
//! - **Otherwise** the SVD `J = U Σ Vᵀ`, with `r` its numerical rank: `f_p = −U_r Σ_r⁻¹ V_rᵀ t`,
//!   `N = U[:, r..]`, `J⁺ = V_r Σ_r⁻¹ U_rᵀ`, and the range of `J` as `U_r Σ_r V_rᵀ`.

use std::ops::Range;

use faer::{Mat, MatRef};

use crate::error::StaticsError;
use crate::three_cable::{Share, Triangular, three_cable_joint, triangular, triangular_motion};

/// A singular value of `J_c` below this fraction of the largest counts as zero.
pub const SET_RANK_TOLERANCE: f64 = 1e-10;

/// An independent block of `J_c`: cables that move only these DOFs, DOFs that only these
/// cables move, with `J⁺` (DOFs × cables; for the routed closed form, empty and
/// `by_substitution`: see [`Block::motion`]), `J` on its numerical range (cables × DOFs), and the
/// block's share of the set: `f_p` on its cables and its columns of `N` (cables × columns), all
/// in the block's order of cables.
#[derive(Debug, PartialEq)]
pub(crate) struct Block {
    pub(crate) cables: Vec<usize>,
    pub(crate) dofs: Vec<usize>,
    pub(crate) pseudo_inverse: Mat<f64>,
    pub(crate) range: Mat<f64>,
    pub(crate) particular: Vec<f64>,
    pub(crate) null: Mat<f64>,
    /// `J⁺ w` by forward substitution on `range` ([`triangular_motion`]), not `pseudo_inverse`.
    pub(crate) by_substitution: bool,
}

impl Clone for Block {
    fn clone(&self) -> Block {
        Block {
            cables: self.cables.clone(),
            dofs: self.dofs.clone(),
            pseudo_inverse: self.pseudo_inverse.clone(),
            range: self.range.clone(),
            particular: self.particular.clone(),
            null: self.null.clone(),
            by_substitution: self.by_substitution,
        }
    }

    /// Into the buffers already there (a planner keeps one set per step).
    fn clone_from(&mut self, source: &Block) {
        self.cables.clone_from(&source.cables);
        self.dofs.clone_from(&source.dofs);
        copy_matrix(&mut self.pseudo_inverse, &source.pseudo_inverse);
        copy_matrix(&mut self.range, &source.range);
        self.particular.clone_from(&source.particular);
        copy_matrix(&mut self.null, &source.null);
        self.by_substitution = source.by_substitution;
    }
}

/// `target = source`, in `target`'s storage when it has the room.
pub(crate) fn copy_matrix(target: &mut Mat<f64>, source: &Mat<f64>) {
    target.resize_with(source.nrows(), source.ncols(), |_, _| 0.0);
    target.copy_from(source);
}

/// `target` resized to `rows × cols` (in its storage when it has the room) and zeroed.
pub(crate) fn zeroed(target: &mut Mat<f64>, rows: usize, cols: usize) {
    target.resize_with(rows, cols, |_, _| 0.0);
    target.fill(0.0);
}

/// The scratch of [`Block::fill`], kept with the set so that rebuilding it allocates nothing
/// (past the SVD's own, for a block without a closed form).
#[derive(Debug, Default)]
pub(crate) struct BlockScratch {
    /// The torques on the block's DOFs.
    t: Vec<f64>,
    triangular: Triangular,
}

impl Block {
    /// A block with no cables, DOFs or buffers yet.
    pub(crate) fn empty() -> Block {
        Block {
            cables: Vec::new(),
            dofs: Vec::new(),
            pseudo_inverse: Mat::new(),
            range: Mat::new(),
            particular: Vec::new(),
            null: Mat::new(),
            by_substitution: false,
        }
    }

    /// The block's share of the set for its `cables` and `dofs` of `jacobian` (m × dof) under
    /// the torques `t0` (dof), into its buffers; `groups` are the arm's joints as DOF ranges.
    /// In closed form where the block has the shape (module docs), else by the SVD.
    ///
    /// # Errors
    /// [`StaticsError::Numerical`] when the SVD fails.
    pub(crate) fn fill(
        &mut self,
        jacobian: MatRef<'_, f64>,
        t0: &[f64],
        groups: &[Range<usize>],
        scratch: &mut BlockScratch,
    ) -> Result<(), StaticsError> {
        let (m, d) = (self.cables.len(), self.dofs.len());
        self.by_substitution = false;
        if m == 0 {
            // DOFs no cable moves: no share of the set (the set's residual check names them).
            self.particular.clear();
            zeroed(&mut self.null, 0, 0);
            zeroed(&mut self.pseudo_inverse, d, 0);
            zeroed(&mut self.range, 0, d);
            return Ok(());
        }
        self.range.resize_with(m, d, |_, _| 0.0);
        for (c, &dof) in self.dofs.iter().enumerate() {
            for (r, &cable) in self.cables.iter().enumerate() {
                self.range[(r, c)] = jacobian[(cable, dof)];
            }
        }
        scratch.t.clear();
        scratch.t.extend(self.dofs.iter().map(|&d| t0[d]));
        if self.closed_joint(&scratch.t)
            || self.closed_chain(groups, &scratch.t, &mut scratch.triangular)
        {
            return Ok(());
        }
        let t = std::mem::take(&mut scratch.t);
        let svd = self.by_svd(&t);
        scratch.t = t;
        svd
    }

    /// [`three_cable_joint`] on this block's `range` into its share.
    fn closed_joint(&mut self, t: &[f64]) -> bool {
        let (j, _, out) = self.parts();
        three_cable_joint(j, t, out)
    }

    /// [`triangular`] on this block's `range` into its share.
    fn closed_chain(&mut self, groups: &[Range<usize>], t: &[f64], s: &mut Triangular) -> bool {
        let (j, dofs, out) = self.parts();
        let closed = triangular((j, dofs), groups, t, s, out);
        self.by_substitution = closed;
        closed
    }

    /// `J⁺ w` on the block: the joint motion (on its DOFs, in their order) whose cable length
    /// changes are the part of `w` (on its cables, in their order) in the range of `J`. By the
    /// stored `J⁺`, or for the routed closed form by forward substitution on `w − N Nᵀ w`.
    pub(crate) fn motion(&self, w: &[f64]) -> Vec<f64> {
        let (m, d) = (self.cables.len(), self.dofs.len());
        let mut out = vec![0.0; d];
        if self.by_substitution {
            let mut projected = w.to_vec();
            for i in 0..self.null.ncols() {
                let along: f64 = (0..m).map(|c| self.null[(c, i)] * w[c]).sum();
                projected.iter_mut().enumerate().for_each(|(c, x)| *x -= along * self.null[(c, i)]);
            }
            let solved = triangular_motion(self.range.as_ref(), &projected, &mut out);
            // `range` passed the same shape test when the block was filled.
            debug_assert!(solved, "a block of the routed closed form keeps its shape");
            return out;
        }
        for (k, v) in out.iter_mut().enumerate() {
            *v = (0..m.min(self.pseudo_inverse.ncols()))
                .map(|r| self.pseudo_inverse[(k, r)] * w[r])
                .sum();
        }
        out
    }

    /// The block's submatrix of `J_c`, its DOFs, and its share to write.
    fn parts(&mut self) -> (MatRef<'_, f64>, &[usize], Share<'_>) {
        let share = Share {
            particular: &mut self.particular,
            null: &mut self.null,
            pseudo_inverse: &mut self.pseudo_inverse,
        };
        (self.range.as_ref(), &self.dofs, share)
    }

    /// The block by the SVD of its submatrix of `J_c` (in `range` on entry; module docs), `t`
    /// the torques on its DOFs.
    pub(crate) fn by_svd(&mut self, t: &[f64]) -> Result<(), StaticsError> {
        let (m, dofs) = (self.cables.len(), self.dofs.len());
        let svd = self.range.svd().map_err(|_| StaticsError::Numerical { what: "SVD of J_c" })?;
        let s = svd.S().column_vector();
        let largest = if s.nrows() > 0 { s[0] } else { 0.0 };
        let rank = (0..s.nrows()).filter(|&i| s[i] > SET_RANK_TOLERANCE * largest).count();
        let (u, v) = (svd.U(), svd.V());
        // f_p = −U_r Σ_r⁻¹ V_rᵀ t on the block.
        let y: Vec<f64> =
            (0..rank).map(|i| (0..dofs).map(|d| v[(d, i)] * t[d]).sum::<f64>() / s[i]).collect();
        self.particular.clear();
        self.particular.extend((0..m).map(|r| -(0..rank).map(|i| u[(r, i)] * y[i]).sum::<f64>()));
        self.null = Mat::from_fn(m, m - rank, |r, i| u[(r, rank + i)]);
        self.pseudo_inverse =
            Mat::from_fn(dofs, m, |d, r| (0..rank).map(|i| v[(d, i)] * u[(r, i)] / s[i]).sum());
        self.range =
            Mat::from_fn(m, dofs, |r, d| (0..rank).map(|i| u[(r, i)] * s[i] * v[(d, i)]).sum());
        Ok(())
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    /// The block of `j` on cables `0..m` and DOFs `dofs`, its share not yet computed.
    pub(super) fn block_of(j: &Mat<f64>, dofs: Vec<usize>) -> Block {
        Block { cables: (0..j.nrows()).collect(), dofs, range: j.clone(), ..Block::empty() }
    }

    /// A 3 × 2 block `[a b]` with `b = a + δ·e`: `δ` sets its conditioning.
    fn block(a: [f64; 3], e: [f64; 3], delta: f64) -> Mat<f64> {
        Mat::from_fn(3, 2, |r, c| if c == 0 { a[r] } else { a[r] + delta * e[r] })
    }

    #[test]
    fn the_closed_form_of_a_three_cable_joint_is_the_svd_s_answer() {
        let t = [0.7, -1.3];
        let cases = [
            ([0.011, -0.004, -0.007], [0.3, 0.9, -1.2], 1.0),
            ([-0.02, 0.013, 0.006], [1.0, 0.2, 0.4], 0.01),
            ([0.5, 0.1, -0.6], [0.0, 1.0, -1.0], 1e-4),
            ([0.0, 0.0, 0.8], [1.0, -1.0, 0.0], 1e-5),
        ];
        for (a, e, delta) in cases {
            let j = block(a, e, delta);
            let mut closed = block_of(&j, vec![0, 1]);
            assert!(closed.closed_joint(&t), "closed form");
            let (fp, pinv) = (&closed.particular, &closed.pseudo_inverse);
            let n: Vec<f64> = (0..3).map(|c| closed.null[(c, 0)]).collect();
            let mut svd = block_of(&j, vec![0, 1]);
            svd.by_svd(&t).unwrap();
            let s = j.svd().unwrap();
            let s = s.S().column_vector();
            // Both are exact to rounding times the condition number.
            let tolerance = 64.0 * f64::EPSILON * s[0] / s[1];
            let scale = fp.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            for (x, y) in fp.iter().zip(&svd.particular) {
                assert!(
                    (x - y).abs() <= tolerance * scale,
                    "f_p {fp:?} against {:?}",
                    svd.particular
                );
            }
            // Jᵀ f_p = −t.
            for d in 0..2 {
                let v: f64 = (0..3).map(|r| j[(r, d)] * fp[r]).sum();
                assert!((v + t[d]).abs() <= tolerance * scale * s[0], "Jᵀf_p[{d}] = {v}");
            }
            // N up to its sign, which the closed form fixes: Σ n > 0.
            let other: Vec<f64> = (0..3).map(|c| svd.null[(c, 0)]).collect();
            let dot: f64 = n.iter().zip(&other).map(|(x, y)| x * y).sum();
            let sign = if dot < 0.0 { -1.0 } else { 1.0 };
            for (x, y) in n.iter().zip(&other) {
                assert!((x - sign * y).abs() <= tolerance, "n {n:?} against {other:?}");
            }
            assert!(n.iter().sum::<f64>() > 0.0);
            // J⁺ J = I, and against the SVD's.
            let size = pinv.norm_max();
            for d in 0..2 {
                for e in 0..2 {
                    let v: f64 = (0..3).map(|r| pinv[(d, r)] * j[(r, e)]).sum();
                    let expected = if d == e { 1.0 } else { 0.0 };
                    assert!((v - expected).abs() <= tolerance, "J⁺J[{d},{e}] = {v}");
                }
                for r in 0..3 {
                    let (x, y) = (pinv[(d, r)], svd.pseudo_inverse[(d, r)]);
                    assert!((x - y).abs() <= tolerance * size, "J⁺ {x} against {y}");
                }
            }
        }
    }

    #[test]
    fn a_joint_near_rank_one_goes_to_the_svd() {
        // b = a + δ e with e ⊥ a, |a| = |e| = 1: σ₂/σ₁ ≈ δ/2.
        let (a, e) = ([0.0, 0.6, 0.8], [1.0, 0.0, 0.0]);
        let t = [0.0, 0.0];
        let closed = |j: Mat<f64>| block_of(&j, vec![0, 1]).closed_joint(&t);
        assert!(closed(block(a, e, 1e-5)));
        assert!(!closed(block(a, e, 1e-7)));
        assert!(!closed(block(a, e, 0.0)));
        // Another shape is not a three-cable joint.
        assert!(!closed(Mat::<f64>::zeros(4, 2)));
        // A rank-one block: two null columns, by the SVD.
        let j = block(a, e, 0.0);
        let mut set = block_of(&j, vec![0, 1]);
        set.fill(j.as_ref(), &t, &[Range { start: 0, end: 2 }], &mut BlockScratch::default())
            .unwrap();
        assert_eq!(set.null.ncols(), 2);
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod triangular_tests {
    use super::tests::block_of;
    use super::*;
    use crate::three_cable::Triangular;

    /// The columns of a block's `N`, each over its cables.
    fn columns(b: &Block) -> Vec<Vec<f64>> {
        (0..b.null.ncols()).map(|i| (0..b.null.nrows()).map(|c| b.null[(c, i)]).collect()).collect()
    }

    /// A routed block of `joints` joints: three cables end at each joint and cross every joint
    /// before it, with entries from a fixed pseudo-random sequence.
    fn routed(joints: usize, seed: u64) -> Mat<f64> {
        let mut state = seed;
        let mut next = move || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        Mat::from_fn(
            3 * joints,
            2 * joints,
            |c, d| if d / 2 <= c / 3 { 0.02 * next() } else { 0.0 },
        )
    }

    #[test]
    fn the_routed_closed_form_is_the_svd_s_set_with_a_block_triangular_basis() {
        for (joints, seed) in [(1, 3), (2, 5), (5, 7), (8, 11)] {
            let j = routed(joints, seed);
            let (m, dof) = (3 * joints, 2 * joints);
            let dofs: Vec<usize> = (0..dof).collect();
            let groups: Vec<Range<usize>> = (0..joints).map(|l| 2 * l..2 * l + 2).collect();
            let t: Vec<f64> = (0..dof).map(|d| 0.3 * (d as f64 + 1.0).sin()).collect();
            let mut closed = block_of(&j, dofs.clone());
            let mut scratch = Triangular::default();
            assert!(closed.closed_chain(&groups, &t, &mut scratch), "the routed shape");
            let (fp, null, pinv) = (&closed.particular, columns(&closed), &closed.pseudo_inverse);
            let mut svd = block_of(&j, dofs.clone());
            svd.by_svd(&t).unwrap();
            let svd_null = columns(&svd);
            let s = j.svd().unwrap();
            let s = s.S().column_vector();
            let tolerance = 256.0 * f64::EPSILON * s[0] / s[dof - 1];
            let size = |v: &[f64]| v.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
            let scale = size(fp);
            for (x, y) in fp.iter().zip(&svd.particular) {
                assert!((x - y).abs() <= tolerance * scale, "{joints} joints: f_p {x} against {y}");
            }
            // The same subspace: N Nᵀ equal; N orthonormal; column l on joints 0..=l, its own
            // joint's cables summing positive.
            assert_eq!(null.len(), svd_null.len());
            for a in 0..m {
                for b in 0..m {
                    let p: f64 = null.iter().map(|u| u[a] * u[b]).sum();
                    let q: f64 = svd_null.iter().map(|u| u[a] * u[b]).sum();
                    assert!((p - q).abs() <= tolerance, "N Nᵀ[{a},{b}]: {p} against {q}");
                }
            }
            for (l, u) in null.iter().enumerate() {
                for (l2, w) in null.iter().enumerate() {
                    let dot: f64 = u.iter().zip(w).map(|(x, y)| x * y).sum();
                    let expected = if l == l2 { 1.0 } else { 0.0 };
                    assert!((dot - expected).abs() <= 1e-14, "column {l}·{l2} = {dot}");
                }
                assert!(u[3 * (l + 1)..].iter().all(|v| *v == 0.0), "column {l} beyond joint {l}");
                assert!(u[3 * l..3 * l + 3].iter().sum::<f64>() > 0.0);
            }
            // J⁺ on demand, column by column (J⁺ e_c), against the SVD's.
            assert!(closed.by_substitution && pinv.nrows() == 0, "no J⁺ formed");
            let largest = svd.pseudo_inverse.norm_max();
            for c in 0..m {
                let unit: Vec<f64> = (0..m).map(|r| if r == c { 1.0 } else { 0.0 }).collect();
                for (d, x) in closed.motion(&unit).into_iter().enumerate() {
                    let y = svd.pseudo_inverse[(d, c)];
                    assert!((x - y).abs() <= tolerance * largest, "J⁺[{d},{c}] {x} against {y}");
                }
            }
            // Through Block::fill: a closed form is the one taken (one joint's own, for one).
            let mut set = block_of(&j, dofs);
            set.fill(j.as_ref(), &t, &groups, &mut BlockScratch::default()).unwrap();
            if joints > 1 {
                assert_eq!(&set.particular, fp);
            }
            // Refilled with another block's numbers in the same buffers: the fresh answer.
            let other = routed(joints, seed + 100);
            let mut again = block_of(&other, set.dofs.clone());
            again.fill(other.as_ref(), &t, &groups, &mut BlockScratch::default()).unwrap();
            set.fill(other.as_ref(), &t, &groups, &mut BlockScratch::default()).unwrap();
            assert_eq!(set, again);
        }
    }

    #[test]
    fn other_shapes_go_to_the_svd() {
        let j = routed(3, 13);
        let dofs: Vec<usize> = (0..6).collect();
        let t = vec![0.1; 6];
        let joints: Vec<Range<usize>> = (0..3).map(|l| 2 * l..2 * l + 2).collect();
        let tri = |j: MatRef<'_, f64>, groups: &[Range<usize>]| {
            let mut b = block_of(&j.to_owned(), dofs.clone());
            b.closed_chain(groups, &t, &mut Triangular::default())
        };
        assert!(tri(j.as_ref(), &joints));
        // Joints of three DOFs are not universal joints.
        assert!(!tri(j.as_ref(), &[0..3, 3..6]));
        // Four cables at the tip: not three per joint.
        let four = Mat::from_fn(10, 6, |c, d| if c < 9 { j[(c, d)] } else { 0.01 * (d as f64) });
        assert!(!tri(four.as_ref(), &joints));
        // A joint whose own block has rank one.
        let mut flat = j.clone();
        for c in 3..6 {
            flat[(c, 3)] = flat[(c, 2)];
        }
        assert!(!tri(flat.as_ref(), &joints));
    }
}
