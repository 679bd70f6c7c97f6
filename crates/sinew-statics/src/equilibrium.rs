//! The equilibrium set of any cable set: every tension vector that balances the load, as
//! `f = f_p + N λ`, and the polytope of `λ` that the tension limits leave (eq. 5, 22–23 for
//! the whole arm, any number of cables, any routing).
//!
//! # Math
//! The cables balance the joints when `−J_cᵀ f = T0` (eq. 5–6), `J_c` the m × dof cable
//! Jacobian. With the singular value decomposition `J_c = U Σ Vᵀ` and `r` its numerical rank
//! ([`crate::SET_RANK_TOLERANCE`]):
//!
//! ```text
//! f_p = −U_r Σ_r⁻¹ V_rᵀ T0        (the minimum-norm balancing tensions, f_p ⊥ N)
//! N   = U[:, r..m]                (an orthonormal basis of null(J_cᵀ), m × (m − r))
//! ```
//!
//! so every balancing tension vector is `f = f_p + N λ`, `λ ∈ R^(m−r)`, and `|f|² = |f_p|² +
//! |λ|²`. The load is balanced at all only when `T0` lies in the span of the cable torques:
//! the residual `T0 + J_cᵀ f_p` is zero (to [`EQUILIBRIUM_TOLERANCE`]); otherwise the motion
//! `δq = V_⊥ V_⊥ᵀ T0` is one the cables cannot resist. The limits `f_min ≤ f ≤ f_max` then
//! make `λ` range over the polytope `{λ : f_min − f_p ≤ N λ ≤ f_max − f_p}`; the load is
//! feasible when it is not empty. With three cables per universal joint and no cable crossing
//! another joint, `N` has one column per joint and the polytope is the box of the per-joint
//! intervals of [`crate::tension_interval`].
//!
//! The set is built block by block: the DOFs linked by the cables that move them (non-zero
//! entries of `J_c`) fall into independent blocks — one per joint in the decoupled model, one
//! for the whole arm when every cable runs from the base — and `N` is block diagonal over them
//! (one column per joint with three cables on each universal joint of a decoupled arm), which
//! keeps the policies' programs sparse. A universal joint driven by three cables has its share
//! in closed form (one normalised cross product, no SVD); any other block by its SVD
//! (module docs of `set_block.rs`).
//!
//! Force closure — some strictly positive `f` in `null(J_cᵀ)`, so that any torque can be held
//! with high enough tensions — is a property of the pose and the routing
//! ([`EquilibriumSet::force_closure`]), not a condition of feasibility.

use std::ops::Range;

use faer::{Mat, MatRef};

use crate::error::{NoEquilibrium, NoEquilibriumCause, StaticsError};
use crate::set_block::{Block, BlockScratch, copy_matrix, zeroed};

/// The relative equilibrium residual `|T0 + J_cᵀ f| / |T0|` accepted as balance.
pub const EQUILIBRIUM_TOLERANCE: f64 = 1e-9;

/// A joint (a cable) is named in a [`NoEquilibrium`] when its largest component of the joint
/// motion (of the certificate's cable weights) is at least this share of the largest overall.
pub(crate) const NAMED_SHARE: f64 = 0.1;

/// The equilibrium set `f = f_p + N λ` of a cable set under a load, and its tension limits.
///
/// Built per configuration by [`EquilibriumSet::new`], or rebuilt into the buffers of the last
/// configuration's by [`EquilibriumSet::rebuild`] (no allocation for an arm whose blocks all
/// have a closed form; an SVD of each block of `J_c` that is not a three-cable joint or a
/// routed chain of them); the tension policies of [`crate::TensionPolicy`] choose a point of
/// it.
#[derive(Debug)]
pub struct EquilibriumSet {
    particular: Vec<f64>,
    null: Mat<f64>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    /// The independent blocks of `J_c` with `J_c⁺` on each.
    blocks: Vec<Block>,
    dof: usize,
    /// Buffers of the rebuild (not part of the set's value).
    scratch: SetScratch,
}

/// The buffers of [`EquilibriumSet::rebuild`].
#[derive(Debug, Default)]
struct SetScratch {
    /// Union–find parents of the DOFs, and the block of each root.
    parent: Vec<usize>,
    slot: Vec<usize>,
    /// Each cable's first DOF it moves.
    first: Vec<Option<usize>>,
    block: BlockScratch,
    residual: Vec<f64>,
}

impl PartialEq for EquilibriumSet {
    fn eq(&self, other: &EquilibriumSet) -> bool {
        self.particular == other.particular
            && self.null == other.null
            && self.lower == other.lower
            && self.upper == other.upper
            && self.blocks == other.blocks
            && self.dof == other.dof
    }
}

/// The independent blocks of `J_c` (m × dof) into `blocks` (their buffers reused): the
/// connected components of the DOFs linked by the cables that move them (a non-zero
/// `J_c[c, d]`), each with its cables (base first), in the order of their first DOF. A cable
/// that moves no DOF is a block of its own with no DOFs, after those; a DOF no cable moves is
/// a block with no cables.
fn independent_blocks(jacobian: MatRef<'_, f64>, blocks: &mut Vec<Block>, s: &mut SetScratch) {
    let (m, dof) = (jacobian.nrows(), jacobian.ncols());
    fn root(parent: &mut [usize], mut d: usize) -> usize {
        while parent[d] != d {
            parent[d] = parent[parent[d]];
            d = parent[d];
        }
        d
    }
    s.parent.clear();
    s.parent.extend(0..dof);
    s.first.clear();
    s.first.extend((0..m).map(|c| (0..dof).find(|&d| jacobian[(c, d)] != 0.0)));
    for (c, first) in s.first.iter().enumerate() {
        let Some(a) = *first else { continue };
        for d in a + 1..dof {
            if jacobian[(c, d)] != 0.0 {
                let (ra, rd) = (root(&mut s.parent, a), root(&mut s.parent, d));
                s.parent[rd] = ra;
            }
        }
    }
    let mut used = 0;
    let mut next = |blocks: &mut Vec<Block>| {
        if used == blocks.len() {
            blocks.push(Block::empty());
        }
        blocks[used].cables.clear();
        blocks[used].dofs.clear();
        used += 1;
        used - 1
    };
    s.slot.clear();
    s.slot.resize(dof, usize::MAX);
    for d in 0..dof {
        let r = root(&mut s.parent, d);
        if s.slot[r] == usize::MAX {
            s.slot[r] = next(blocks);
        }
        blocks[s.slot[r]].dofs.push(d);
    }
    for (c, first) in s.first.iter().enumerate() {
        if let Some(d) = *first {
            let r = root(&mut s.parent, d);
            blocks[s.slot[r]].cables.push(c);
        }
    }
    for (c, first) in s.first.iter().enumerate() {
        if first.is_none() {
            let b = next(blocks);
            blocks[b].cables.push(c);
        }
    }
    blocks.truncate(used);
}

impl Clone for EquilibriumSet {
    fn clone(&self) -> EquilibriumSet {
        EquilibriumSet {
            particular: self.particular.clone(),
            null: self.null.clone(),
            lower: self.lower.clone(),
            upper: self.upper.clone(),
            blocks: self.blocks.clone(),
            dof: self.dof,
            scratch: SetScratch::default(),
        }
    }

    /// Into the buffers already there when the shapes agree: a planner re-planning along a
    /// trajectory copies each step's set into the last one's storage, allocating nothing.
    fn clone_from(&mut self, source: &EquilibriumSet) {
        self.particular.clone_from(&source.particular);
        copy_matrix(&mut self.null, &source.null);
        self.lower.clone_from(&source.lower);
        self.upper.clone_from(&source.upper);
        self.blocks.clone_from(&source.blocks);
        self.dof = source.dof;
    }
}

impl EquilibriumSet {
    /// The equilibrium set of the cable Jacobian `jacobian` (m × dof) under the equilibrium
    /// torques `t0` (dof), with the limits `limits[c] = [f_min, f_max]` of every cable. `groups`
    /// are the arm's joints as DOF ranges (to name them in errors).
    ///
    /// # Errors
    /// [`StaticsError::DimensionMismatch`]; [`StaticsError::NonFiniteInput`] for a NaN in
    /// `J_c` or `T0`; [`StaticsError::NoEquilibrium`] with
    /// [`NoEquilibriumCause::Unreachable`] when `T0` has a component no tensions produce;
    /// [`StaticsError::Numerical`] when the SVD fails.
    pub fn new(
        jacobian: MatRef<'_, f64>,
        t0: &[f64],
        limits: &[[f64; 2]],
        groups: &[Range<usize>],
    ) -> Result<EquilibriumSet, StaticsError> {
        let mut set = EquilibriumSet {
            particular: Vec::new(),
            null: Mat::new(),
            lower: Vec::new(),
            upper: Vec::new(),
            blocks: Vec::new(),
            dof: 0,
            scratch: SetScratch::default(),
        };
        set.rebuild(jacobian, t0, limits, groups)?;
        Ok(set)
    }

    /// [`EquilibriumSet::new`] into this set's buffers: with the arm of the last build (the
    /// same blocks), no allocation where every block has a closed form (module docs of
    /// `set_block.rs`). On an error the set is left partly rebuilt: rebuild it again before use.
    ///
    /// # Errors
    /// As [`EquilibriumSet::new`].
    pub fn rebuild(
        &mut self,
        jacobian: MatRef<'_, f64>,
        t0: &[f64],
        limits: &[[f64; 2]],
        groups: &[Range<usize>],
    ) -> Result<(), StaticsError> {
        let (m, dof) = (jacobian.nrows(), jacobian.ncols());
        for (what, expected, got) in
            [("equilibrium torques T0", dof, t0.len()), ("tension limits", m, limits.len())]
        {
            if expected != got {
                return Err(StaticsError::DimensionMismatch { what, expected, got });
            }
        }
        let finite = t0.iter().all(|v| v.is_finite())
            && (0..dof).all(|j| (0..m).all(|c| jacobian[(c, j)].is_finite()));
        if !finite {
            return Err(StaticsError::NonFiniteInput { what: "cable Jacobian or T0" });
        }
        let s = &mut self.scratch;
        independent_blocks(jacobian, &mut self.blocks, s);
        let mut columns = 0;
        for block in &mut self.blocks {
            block.fill(jacobian, t0, groups, &mut s.block)?;
            columns += block.null.ncols();
        }
        self.particular.clear();
        self.particular.resize(m, 0.0);
        zeroed(&mut self.null, m, columns);
        let mut i = 0;
        for block in &self.blocks {
            for (r, &c) in block.cables.iter().enumerate() {
                self.particular[c] = block.particular[r];
            }
            for k in 0..block.null.ncols() {
                for (r, &c) in block.cables.iter().enumerate() {
                    self.null[(c, i)] = block.null[(r, k)];
                }
                i += 1;
            }
        }
        self.lower.clear();
        self.lower.extend(limits.iter().map(|l| l[0]));
        self.upper.clear();
        self.upper.extend(limits.iter().map(|l| l[1]));
        self.dof = dof;
        // The residual T0 + J_cᵀ f_p: what the cables cannot produce.
        s.residual.clear();
        s.residual.extend(
            (0..dof).map(|d| {
                t0[d] + (0..m).map(|c| jacobian[(c, d)] * self.particular[c]).sum::<f64>()
            }),
        );
        let size = norm(&s.residual);
        if size > EQUILIBRIUM_TOLERANCE * norm(t0) + f64::MIN_POSITIVE {
            let direction: Vec<f64> = s.residual.iter().map(|r| r / size).collect();
            return Err(StaticsError::NoEquilibrium(Box::new(NoEquilibrium {
                joints: joints_along(&direction, groups),
                cause: NoEquilibriumCause::Unreachable { direction, torque: size },
            })));
        }
        Ok(())
    }

    /// The number of cables `m`.
    pub fn cable_count(&self) -> usize {
        self.particular.len()
    }

    /// The dimension of the set, `m − rank(J_c)`: the number of `λ` coordinates.
    pub fn dimension(&self) -> usize {
        self.null.ncols()
    }

    /// `f_p`, the minimum-norm balancing tensions (N; may be outside the limits).
    pub fn particular(&self) -> &[f64] {
        &self.particular
    }

    /// `N` (m × dimension), an orthonormal basis of `null(J_cᵀ)`.
    pub fn null_basis(&self) -> MatRef<'_, f64> {
        self.null.as_ref()
    }

    /// `f_min` of every cable, N.
    pub fn lower(&self) -> &[f64] {
        &self.lower
    }

    /// `f_max` of every cable, N.
    pub fn upper(&self) -> &[f64] {
        &self.upper
    }

    /// The tensions at `λ`: `f = f_p + N λ` (into `out`, m).
    ///
    /// # Errors
    /// [`StaticsError::DimensionMismatch`].
    pub fn tensions(&self, lambda: &[f64], out: &mut [f64]) -> Result<(), StaticsError> {
        let (m, k) = (self.cable_count(), self.dimension());
        if lambda.len() != k {
            return Err(StaticsError::DimensionMismatch {
                what: "λ",
                expected: k,
                got: lambda.len(),
            });
        }
        if out.len() != m {
            return Err(StaticsError::DimensionMismatch {
                what: "tensions",
                expected: m,
                got: out.len(),
            });
        }
        for (c, f) in out.iter_mut().enumerate() {
            *f = self.particular[c] + (0..k).map(|i| self.null[(c, i)] * lambda[i]).sum::<f64>();
        }
        Ok(())
    }

    /// The coordinates `λ = Nᵀ (f − f_p)` of a tension vector (its part in the set).
    pub fn coordinates(&self, tensions: &[f64]) -> Vec<f64> {
        (0..self.dimension())
            .map(|i| {
                (0..self.cable_count().min(tensions.len()))
                    .map(|c| self.null[(c, i)] * (tensions[c] - self.particular[c]))
                    .sum()
            })
            .collect()
    }

    /// `J_c⁺ w`: the joint motion `δq` whose cable length changes `J_c δq` are the part of `w`
    /// (m) in the range of `J_c`.
    pub fn joint_motion(&self, w: &[f64]) -> Vec<f64> {
        let mut motion = vec![0.0; self.dof];
        for b in &self.blocks {
            let on_block: Vec<f64> =
                b.cables.iter().map(|&c| w.get(c).copied().unwrap_or(0.0)).collect();
            for (&d, v) in b.dofs.iter().zip(b.motion(&on_block)) {
                motion[d] = v;
            }
        }
        motion
    }

    /// `J_c δq`: the cable length changes of the joint motion `dq` (dof), through the range
    /// of `J_c` kept in the set (m).
    pub(crate) fn cable_motion(&self, dq: &[f64]) -> Vec<f64> {
        let mut lengths = vec![0.0; self.cable_count()];
        for b in &self.blocks {
            for (r, &c) in b.cables.iter().enumerate() {
                lengths[c] = b
                    .dofs
                    .iter()
                    .enumerate()
                    .map(|(k, &d)| b.range[(r, k)] * dq.get(d).copied().unwrap_or(0.0))
                    .sum();
            }
        }
        lengths
    }

    /// Whether the cables are in force closure at this pose: some strictly positive tension
    /// vector in `null(J_cᵀ)` (every torque can then be held with high enough tensions). One
    /// small LP (solved with clarabel, see [`crate::convex`]); a property, not a condition of
    /// feasibility.
    ///
    /// # Errors
    /// [`StaticsError::Solver`] when the LP solver fails.
    pub fn force_closure(&self) -> Result<bool, StaticsError> {
        crate::convex::force_closure(self.null_basis())
    }
}

/// Euclidean norm.
pub(crate) fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The joints (0-based) whose DOFs carry at least [`NAMED_SHARE`] of the largest component of a
/// joint motion `direction` (dof).
pub(crate) fn joints_along(direction: &[f64], groups: &[Range<usize>]) -> Vec<usize> {
    let largest = direction.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
    groups
        .iter()
        .enumerate()
        .filter(|(_, g)| {
            (g.start..g.end)
                .any(|d| direction.get(d).is_some_and(|v| v.abs() >= NAMED_SHARE * largest))
        })
        .map(|(j, _)| j)
        .collect()
}
