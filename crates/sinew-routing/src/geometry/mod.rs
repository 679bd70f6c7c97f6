//! Cable lengths, the cable Jacobian and each cable's Hessian at a configuration.
//!
//! # Math
//! Frames: `o_` is the base frame. Joint `j` has the unit axis `a_j` through the point `p_j`
//! (base frame, from forward kinematics). A segment joins a hole `o_p_A` on body `A` to a hole
//! `o_p_B` on body `B > A`:
//!
//! ```text
//! d = o_p_B − o_p_A,   L = |d|,   u = d / L.
//! ```
//!
//! (Both holes on one body: `L` is constant, and is computed in the body frame.) Joints before
//! `A` move both holes rigidly and joints from `B` on move neither, so `L`
//! depends only on `q_A … q_{B−1}`. For `i, k ∈ [A, B)`, with `v_i = a_i × (o_p_B − p_i)`
//! (`∂d/∂q_i`) and `∂²d/∂q_i∂q_k = a_min × v_max` (kinematics of sinew-robot):
//!
//! ```text
//! ∂L/∂q_i       = u · v_i                                                   (eq. 3)
//! ∂²L/∂q_i∂q_k  = ( v_i · v_k − (u · v_i)(u · v_k) + d · (a_min × v_max) ) / L
//! ```
//!
//! A cable's length `L_c` is the sum of its segments' (eq. 2 for one joint), its row of
//! `J_c = ∂L/∂Q` (m × dof) and its Hessian `H_c = ∂²L_c/∂Q²` (dof × dof) the sums of theirs.
//! Entries outside a segment's joint range are exact zeros, so the decoupled `J_c` is exactly
//! block diagonal and the routed one exactly block lower-triangular.
//!
//! Cost: `O(dof + Σ_s |dofs_s|²)` per configuration, no allocation.

mod batch;
mod compute;
mod segment;

use faer::{MatMut, MatRef};

use crate::error::{Result, RoutingError};
use crate::routing::{Routing, Segment, check_shape, rigid_length};

pub use compute::{compute_cable_geometry, compute_cable_geometry_from_kinematics};
pub(crate) use segment::{Kinematics, length_derivative};

/// What an evaluation computes; each order includes the ones before it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Order {
    /// The cable lengths `L_c(Q)` (and every segment's length).
    Lengths,
    /// Also the cable Jacobian `J_c = ∂L/∂Q`.
    Jacobian,
    /// Also every cable's Hessian `∂²L_c/∂Q²`.
    Hessians,
}

/// The reusable workspace of a [`Routing`] (Pinocchio's *data*): every quantity computed for
/// one configuration, sized once so that evaluating a configuration allocates nothing.
#[derive(Debug, Clone)]
pub struct RoutingData {
    cables: usize,
    dof: usize,
    computed: Option<Order>,
    /// `L_c`, m.
    lengths: Vec<f64>,
    /// Length of every segment, m.
    segment_lengths: Vec<f64>,
    /// Unit direction `u = d / L` of every segment across joints (proximal to distal hole,
    /// base frame), when kept ([`RoutingData::keep_segment_directions`]) at [`Order::Jacobian`]
    /// and above; unwritten for a segment within one body.
    directions: Vec<[f64; 3]>,
    /// Whether evaluations keep `directions`, and whether the last one did.
    keep_directions: bool,
    directions_kept: bool,
    /// `J_c`, m × dof, column-major.
    jacobian: Vec<f64>,
    /// Every segment's Hessian block (`|dofs| × |dofs|`, column-major), one after the other.
    hessians: Vec<f64>,
    /// Body poses in the base frame as `[R (column-major), t]`, copied from the robot workspace.
    frames: Vec<[f64; 12]>,
    /// Joint axes `a_j` in the base frame.
    axes: Vec<[f64; 3]>,
    /// Joint origins `p_j` in the base frame.
    origins: Vec<[f64; 3]>,
    /// Scratch: `v_i = a_i × (o_p_B − p_i)` over one segment's joints.
    v: Vec<[f64; 3]>,
    /// Scratch: `u · v_i`.
    g: Vec<f64>,
    /// Scratch of the batched segment loop: length, `∂L/∂q` (two), Hessian (three), `u` (three)
    /// per entry of the longest batch ([`crate::routing::SegmentPlan`]; empty without a plan).
    batch: [Vec<f64>; 9],
}

impl RoutingData {
    /// A workspace sized for `routing`.
    pub fn new(routing: &Routing) -> RoutingData {
        let m = routing.cable_count();
        RoutingData {
            cables: m,
            dof: routing.dof,
            computed: None,
            lengths: vec![0.0; m],
            // Segments within one body have a constant length: written once, here.
            segment_lengths: routing
                .segments
                .iter()
                .map(|s| rigid_length(s).unwrap_or(0.0))
                .collect(),
            directions: vec![[0.0; 3]; routing.segments.len()],
            keep_directions: false,
            directions_kept: false,
            jacobian: vec![0.0; m * routing.dof],
            hessians: vec![0.0; routing.hessian_len],
            frames: vec![[0.0; 12]; routing.dof + 1],
            axes: vec![[0.0; 3]; routing.dof],
            origins: vec![[0.0; 3]; routing.dof],
            v: vec![[0.0; 3]; routing.max_span],
            g: vec![0.0; routing.max_span],
            batch: std::array::from_fn(|_| {
                vec![0.0; routing.plan.as_ref().map_or(0, |p| p.longest)]
            }),
        }
    }

    /// What the last evaluation computed (`None` before the first, or after a failed one).
    pub fn computed(&self) -> Option<Order> {
        self.computed
    }

    pub(crate) fn need(&self, order: Order, what: &'static str) -> Result<()> {
        match self.computed {
            Some(done) if done >= order => Ok(()),
            _ => Err(RoutingError::NotComputed { what, needed: order }),
        }
    }

    /// The cable lengths `L_c(Q)`, m (length m).
    ///
    /// # Errors
    /// [`RoutingError::NotComputed`] before an evaluation.
    pub fn lengths(&self) -> Result<&[f64]> {
        self.need(Order::Lengths, "cable lengths")?;
        Ok(&self.lengths)
    }

    /// Every segment's length, m, in the order of [`Routing::segments`].
    ///
    /// # Errors
    /// [`RoutingError::NotComputed`] before an evaluation.
    pub fn segment_lengths(&self) -> Result<&[f64]> {
        self.need(Order::Lengths, "segment lengths")?;
        Ok(&self.segment_lengths)
    }

    /// The cable Jacobian `J_c = ∂L/∂Q` (eq. 3), m × dof, m/rad.
    ///
    /// # Errors
    /// [`RoutingError::NotComputed`] unless evaluated with at least [`Order::Jacobian`].
    pub fn jacobian(&self) -> Result<MatRef<'_, f64>> {
        self.need(Order::Jacobian, "cable Jacobian")?;
        Ok(MatRef::from_column_major_slice(&self.jacobian, self.cables, self.dof))
    }

    /// The Hessian block of segment `s` over its joints `segments()[s].dofs` (square, m/rad²).
    ///
    /// # Errors
    /// [`RoutingError::NotComputed`], [`RoutingError::DimensionMismatch`] for `s` out of range.
    pub fn segment_hessian<'a>(&'a self, routing: &Routing, s: usize) -> Result<MatRef<'a, f64>> {
        self.check(routing)?;
        self.need(Order::Hessians, "cable Hessians")?;
        // A match, not `ok_or`: that builds (and drops) the error on every call.
        match hessian_block(routing, &self.hessians, s) {
            Some(block) => Ok(block),
            None => Err(RoutingError::DimensionMismatch {
                what: "segment index",
                expected: routing.segments.len(),
                got: s,
            }),
        }
    }

    /// Every segment's Hessian block, with the workspace checked against `routing` once: for
    /// loops over many segments (the joint stiffness visits each segment once per
    /// configuration), where [`RoutingData::segment_hessian`] would repeat the checks.
    ///
    /// # Errors
    /// [`RoutingError::NotComputed`] unless evaluated with [`Order::Hessians`];
    /// [`RoutingError::WorkspaceMismatch`] for a workspace of another routing.
    pub fn segment_hessians<'a>(&'a self, routing: &'a Routing) -> Result<SegmentHessians<'a>> {
        self.check(routing)?;
        self.need(Order::Hessians, "cable Hessians")?;
        Ok(SegmentHessians { routing, hessians: &self.hessians })
    }

    /// Write cable `c`'s Hessian `H_c = ∂²L_c/∂Q²` (dof × dof, m/rad², symmetric) into `out`.
    ///
    /// # Errors
    /// [`RoutingError::NotComputed`], [`RoutingError::NoSuchCable`],
    /// [`RoutingError::DimensionMismatch`] unless `out` is dof × dof.
    pub fn cable_hessian(
        &self,
        routing: &Routing,
        c: usize,
        mut out: MatMut<'_, f64>,
    ) -> Result<()> {
        self.check(routing)?;
        self.need(Order::Hessians, "cable Hessians")?;
        let Some(cable) = routing.cables.get(c) else {
            return Err(RoutingError::NoSuchCable { cable: c, cables: routing.cables.len() });
        };
        check_shape("cable Hessian", out.nrows(), out.ncols(), self.dof, self.dof)?;
        out.fill(0.0);
        for s in cable.segments.clone() {
            self.add_segment(routing, s, 1.0, out.as_mut());
        }
        Ok(())
    }

    /// `out += Σ_c f_c H_c`: the tension-weighted sum of the cables' Hessians (dof × dof), the
    /// controllable part of the joint stiffness `K = Σ_c f_c H_c + J_cᵀ K_l J_c` (spec §3).
    ///
    /// # Math
    /// `Σ_c f_c ∂²L_c/∂Q²`, accumulated segment block by segment block in
    /// `O(Σ_s |dofs_s|²)`; entries outside every block are left untouched. `f` has length m
    /// (N), `out` is dof × dof.
    ///
    /// # Errors
    /// [`RoutingError::NotComputed`], [`RoutingError::DimensionMismatch`].
    pub fn add_weighted_hessians(
        &self,
        routing: &Routing,
        f: &[f64],
        mut out: MatMut<'_, f64>,
    ) -> Result<()> {
        self.check(routing)?;
        self.need(Order::Hessians, "cable Hessians")?;
        if f.len() != self.cables {
            return Err(RoutingError::DimensionMismatch {
                what: "cable tensions",
                expected: self.cables,
                got: f.len(),
            });
        }
        check_shape("weighted Hessian sum", out.nrows(), out.ncols(), self.dof, self.dof)?;
        for (s, seg) in routing.segments.iter().enumerate() {
            // A cable of zero weight adds nothing (its Hessians are finite): the planner's
            // `A_i` weigh only the cables of one null column.
            if f[seg.cable] != 0.0 {
                self.add_segment(routing, s, f[seg.cable], out.as_mut());
            }
        }
        Ok(())
    }

    /// `out[dofs, dofs] += w · H_s` (sizes checked by the callers).
    fn add_segment(&self, routing: &Routing, s: usize, w: f64, mut out: MatMut<'_, f64>) {
        let seg = &routing.segments[s];
        let (lo, n) = (seg.dofs.start, seg.dofs.len());
        let block = &self.hessians[seg.hessian_offset..seg.hessian_offset + n * n];
        for k in 0..n {
            for i in 0..n {
                out[(lo + i, lo + k)] += w * block[i + k * n];
            }
        }
    }

    /// `J_c` as its column-major entries (`(c, i)` at `c + i m`), as [`RoutingData::jacobian`].
    pub(crate) fn jacobian_entries(&self) -> Result<&[f64]> {
        self.need(Order::Jacobian, "cable Jacobian")?;
        Ok(&self.jacobian)
    }

    /// Whether the evaluations from now on also keep every segment's unit direction (off for a
    /// new workspace). The friction geometry ([`crate::compute_friction_angles`]) reads them
    /// instead of computing them again from the holes, which at 50 DOF is a tenth of a stick
    /// evaluation; the frictionless pipeline needs none, and keeping them costs it about 5 %.
    /// The values are the same bit for bit either way.
    pub fn keep_segment_directions(&mut self, keep: bool) {
        self.keep_directions = keep;
    }

    /// Every segment's unit direction `u = d / L` (proximal to distal hole, base frame; the `u`
    /// of eq. 3), in the order of [`Routing::segments`], for the friction geometry: `Some` when
    /// the last evaluation kept them ([`RoutingData::keep_segment_directions`]) with at least
    /// [`Order::Jacobian`]. Valid for the segments across joints; a segment within one body
    /// has none (its entry is stale).
    pub(crate) fn directions(&self) -> Option<&[[f64; 3]]> {
        self.need(Order::Jacobian, "segment directions").ok()?;
        self.directions_kept.then_some(&self.directions[..])
    }

    /// The kinematics of the last evaluation as plain arrays (body frames, joint axes, joint
    /// origins; base frame), for the friction geometry: valid once [`RoutingData::computed`]
    /// is `Some`.
    pub(crate) fn kinematics(&self) -> Kinematics<'_> {
        (&self.frames, &self.axes, &self.origins)
    }

    /// Check that the workspace was sized for `routing`.
    pub(crate) fn check(&self, routing: &Routing) -> Result<()> {
        for (what, expected, got) in [
            ("routing workspace (cables)", routing.cables.len(), self.cables),
            ("routing workspace (joints)", routing.dof, self.dof),
            ("routing workspace (segments)", routing.segments.len(), self.segment_lengths.len()),
            ("routing workspace (Hessian storage)", routing.hessian_len, self.hessians.len()),
            ("routing workspace (scratch)", routing.max_span, self.v.len()),
            (
                "routing workspace (batch scratch)",
                routing.plan.as_ref().map_or(0, |p| p.longest),
                self.batch[0].len(),
            ),
        ] {
            if expected != got {
                return Err(RoutingError::WorkspaceMismatch { what, expected, got });
            }
        }
        Ok(())
    }
}

/// The Hessian blocks of every segment at the last evaluated configuration, from
/// [`RoutingData::segment_hessians`].
#[derive(Debug, Clone, Copy)]
pub struct SegmentHessians<'a> {
    routing: &'a Routing,
    hessians: &'a [f64],
}

/// One batch of [`SegmentHessians::batches`]: segments that cross the same DOFs.
#[derive(Debug, Clone)]
pub struct HessianBatch<'a> {
    /// The DOFs every segment of the batch crosses.
    pub dofs: std::ops::Range<usize>,
    /// Each segment's cable, in routing order.
    pub cables: &'a [usize],
    /// Each segment's index in [`Routing::segments`], in the same order.
    pub segments: &'a [usize],
    /// The segments' `|dofs| × |dofs|` Hessian blocks (column-major), one after the other.
    pub blocks: &'a [f64],
}

impl<'a> SegmentHessians<'a> {
    /// Segment `s`'s Hessian block `∂²L_s/∂q_i∂q_k` over its joints `segments()[s].dofs`
    /// (square, m/rad², column-major); `None` when `s` is out of range.
    #[inline]
    pub fn get(&self, s: usize) -> Option<MatRef<'a, f64>> {
        hessian_block(self.routing, self.hessians, s)
    }

    /// Segment `s`'s Hessian block as [`SegmentHessians::get`] gives it, as its column-major
    /// entries (`|dofs|²` of them); `None` when `s` is out of range.
    #[inline]
    pub fn entries(&self, s: usize) -> Option<&'a [f64]> {
        let seg = self.routing.segments.get(s)?;
        let n = seg.dofs.len();
        self.hessians.get(seg.hessian_offset..seg.hessian_offset + n * n)
    }

    /// The blocks batch by batch, when the routing is batched ([`Routing::is_batched`]) and no
    /// two batches cross the same DOF; `None` otherwise. A batch's segments cross the same
    /// DOFs and come in routing order, so adding `f_c ·` each block batch by batch sums every
    /// entry of `Σ_c f_c H_c` in the same order as [`SegmentHessians::iter`], reading the
    /// blocks in storage order.
    pub fn batches(&self) -> Option<impl Iterator<Item = HessianBatch<'a>> + 'a> {
        let plan = self.routing.plan.as_ref().filter(|p| p.disjoint)?;
        let hessians = self.hessians;
        Some(plan.batches.iter().filter(|b| b.distal > b.proximal).map(move |b| {
            let n = b.distal - b.proximal;
            let o = plan.hessian.get(b.entries.start).copied().unwrap_or(0);
            HessianBatch {
                dofs: b.proximal..b.distal,
                cables: plan.cable.get(b.entries.clone()).unwrap_or(&[]),
                segments: plan.segment.get(b.entries.clone()).unwrap_or(&[]),
                blocks: hessians.get(o..o + b.entries.len() * n * n).unwrap_or(&[]),
            }
        }))
    }

    /// Every segment with its Hessian block (column-major, `|dofs|²` entries, empty for a
    /// segment whose length depends on no joint), in the order of [`Routing::segments`]: for
    /// loops over all segments, without the per-segment lookups of [`SegmentHessians::get`].
    pub fn iter(&self) -> impl Iterator<Item = (&'a Segment, &'a [f64])> + 'a {
        let hessians = self.hessians;
        self.routing.segments.iter().map(move |seg| {
            let n = seg.dofs.len();
            (seg, hessians.get(seg.hessian_offset..seg.hessian_offset + n * n).unwrap_or(&[]))
        })
    }
}

/// Segment `s`'s block in the Hessian storage of a workspace sized for `routing`.
#[inline]
fn hessian_block<'a>(routing: &Routing, hessians: &'a [f64], s: usize) -> Option<MatRef<'a, f64>> {
    let seg = routing.segments.get(s)?;
    let n = seg.dofs.len();
    let block = hessians.get(seg.hessian_offset..seg.hessian_offset + n * n)?;
    Some(MatRef::from_column_major_slice(block, n, n))
}
