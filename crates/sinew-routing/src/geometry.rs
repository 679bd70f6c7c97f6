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
//! Joints before `A` move both holes rigidly and joints from `B` on move neither, so `L`
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

use faer::{MatMut, MatRef};
use sinew_robot::{Robot, RobotData};

use crate::error::{Result, RoutingError};
use crate::routing::{MIN_SEGMENT_LENGTH, Routing, check_shape};

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
            segment_lengths: vec![0.0; routing.segments.len()],
            jacobian: vec![0.0; m * routing.dof],
            hessians: vec![0.0; routing.hessian_len],
            frames: vec![[0.0; 12]; routing.dof + 1],
            axes: vec![[0.0; 3]; routing.dof],
            origins: vec![[0.0; 3]; routing.dof],
            v: vec![[0.0; 3]; routing.max_span],
            g: vec![0.0; routing.max_span],
        }
    }

    /// What the last evaluation computed (`None` before the first, or after a failed one).
    pub fn computed(&self) -> Option<Order> {
        self.computed
    }

    fn need(&self, order: Order, what: &'static str) -> Result<()> {
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
        hessian_block(routing, &self.hessians, s).ok_or(RoutingError::DimensionMismatch {
            what: "segment index",
            expected: routing.segments.len(),
            got: s,
        })
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
        let cable = routing
            .cables
            .get(c)
            .ok_or(RoutingError::NoSuchCable { cable: c, cables: routing.cables.len() })?;
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
            self.add_segment(routing, s, f[seg.cable], out.as_mut());
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

    fn check(&self, routing: &Routing) -> Result<()> {
        for (what, expected, got) in [
            ("routing workspace (cables)", routing.cables.len(), self.cables),
            ("routing workspace (joints)", routing.dof, self.dof),
            ("routing workspace (segments)", routing.segments.len(), self.segment_lengths.len()),
            ("routing workspace (Hessian storage)", routing.hessian_len, self.hessians.len()),
            ("routing workspace (scratch)", routing.max_span, self.v.len()),
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

impl<'a> SegmentHessians<'a> {
    /// Segment `s`'s Hessian block `∂²L_s/∂q_i∂q_k` over its joints `segments()[s].dofs`
    /// (square, m/rad², column-major); `None` when `s` is out of range.
    #[inline]
    pub fn get(&self, s: usize) -> Option<MatRef<'a, f64>> {
        hessian_block(self.routing, self.hessians, s)
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

/// Forward kinematics at `q`, then [`compute_cable_geometry_from_kinematics`]: the cable
/// lengths, and up to `order` the cable Jacobian and the cables' Hessians, into `data`.
///
/// # Math
/// See [`compute_cable_geometry_from_kinematics`]: eq. 2–3; shapes `L` m, `J_c` m × dof,
/// `H_c` dof × dof.
///
/// # Errors
/// [`RoutingError::RobotMismatch`], [`RoutingError::WorkspaceMismatch`],
/// [`RoutingError::Robot`] for a wrong or non-finite `q`, [`RoutingError::DegenerateSegment`].
pub fn compute_cable_geometry(
    routing: &Routing,
    robot: &Robot,
    robot_data: &mut RobotData,
    data: &mut RoutingData,
    q: &[f64],
    order: Order,
) -> Result<()> {
    routing.check_robot(robot)?;
    data.computed = None;
    robot.forward_kinematics(robot_data, q)?;
    compute_cable_geometry_from_kinematics(routing, robot, robot_data, data, order)
}

/// The cable lengths, and up to `order` the cable Jacobian and the cables' Hessians, from
/// forward kinematics already computed in `robot_data` (by `robot.forward_kinematics`; this
/// function cannot tell which `Q` that was).
///
/// Allocates nothing. On error `data` holds nothing valid ([`RoutingData::computed`] is `None`).
///
/// # Math
/// Frames: `o_` is the base frame. Joint `j` has the unit axis `a_j` through the point `p_j`.
/// A segment joins a hole `o_p_A` on body `A` to a hole `o_p_B` on body `B > A`:
/// `d = o_p_B − o_p_A`, `L = |d|`, `u = d / L`. Joints before `A` move both holes rigidly and
/// joints from `B` on move neither, so `L` depends only on `q_A … q_{B−1}`. For `i, k` in that
/// range, with `v_i = a_i × (o_p_B − p_i) = ∂d/∂q_i` and `∂²d/∂q_i∂q_k = a_min × v_max`:
///
/// ```text
/// ∂L/∂q_i       = u · v_i                                                   (eq. 3)
/// ∂²L/∂q_i∂q_k  = ( v_i · v_k − (u · v_i)(u · v_k) + d · (a_min × v_max) ) / L
/// ```
///
/// A cable's length is the sum of its segments' (eq. 2 for one joint); its row of `J_c`
/// (m × dof) and its Hessian (dof × dof) are the sums of theirs, with exact zeros outside each
/// segment's joints. Cost `O(dof + Σ_s |dofs_s|²)`.
///
/// # Errors
/// [`RoutingError::RobotMismatch`], [`RoutingError::WorkspaceMismatch`],
/// [`RoutingError::DegenerateSegment`] when a segment is shorter than
/// [`MIN_SEGMENT_LENGTH`] (never a NaN).
pub fn compute_cable_geometry_from_kinematics(
    routing: &Routing,
    robot: &Robot,
    robot_data: &RobotData,
    data: &mut RoutingData,
    order: Order,
) -> Result<()> {
    routing.check_robot(robot)?;
    data.check(routing)?;
    data.computed = None;
    let dof = routing.dof;
    if robot_data.joint_axis(dof.saturating_sub(1)).is_none()
        || robot_data.joint_axis(dof).is_some()
        || robot_data.body_pose(dof).is_none()
    {
        let got = (0..).take_while(|&j| robot_data.joint_axis(j).is_some()).count();
        return Err(RoutingError::WorkspaceMismatch {
            what: "robot workspace (joints)",
            expected: dof,
            got,
        });
    }
    // The kinematics as plain arrays (base frame), once per evaluation.
    for b in 0..=dof {
        let (Some(pose), Some(frame)) = (robot_data.body_pose(b), data.frames.get_mut(b)) else {
            return Err(mismatch(dof));
        };
        // Column-major rotation, then the translation.
        frame[..9].copy_from_slice(pose.rotation.matrix().as_slice());
        frame[9..].copy_from_slice(pose.translation.vector.as_slice());
    }
    for j in 0..dof {
        let (Some(a), Some(p)) = (robot_data.joint_axis(j), robot_data.joint_origin(j)) else {
            return Err(mismatch(dof));
        };
        data.axes[j] = [a[0], a[1], a[2]];
        data.origins[j] = [p[0], p[1], p[2]];
    }

    data.lengths.fill(0.0);
    if order >= Order::Jacobian {
        data.jacobian.fill(0.0);
    }
    let m = data.cables;
    let RoutingData {
        frames,
        axes,
        origins,
        lengths,
        segment_lengths,
        jacobian,
        hessians,
        v,
        g,
        ..
    } = data;
    for (s, seg) in routing.segments.iter().enumerate() {
        let o_p_a = transform(&frames[seg.proximal.body], &seg.proximal_point);
        let o_p_b = transform(&frames[seg.distal.body], &seg.distal_point);
        let d = sub(&o_p_b, &o_p_a);
        let length = dot(&d, &d).sqrt();
        if length.is_nan() || length < MIN_SEGMENT_LENGTH {
            let cable = routing.cables.get(seg.cable).map(|c| c.name.clone()).unwrap_or_default();
            return Err(RoutingError::DegenerateSegment {
                cable,
                segment: seg.index,
                length,
                min: MIN_SEGMENT_LENGTH,
            });
        }
        segment_lengths[s] = length;
        lengths[seg.cable] += length;
        if order == Order::Lengths || seg.dofs.is_empty() {
            continue;
        }
        let inv_length = 1.0 / length;
        let u = scale(&d, inv_length);
        let (lo, n) = (seg.dofs.start, seg.dofs.len());
        for k in 0..n {
            // v_k = a_k × (o_p_B − p_k) = ∂d/∂q_k,  g_k = u · v_k = ∂L/∂q_k.
            let v_k = cross(&axes[lo + k], &sub(&o_p_b, &origins[lo + k]));
            let g_k = dot(&u, &v_k);
            v[k] = v_k;
            g[k] = g_k;
            jacobian[seg.cable + (lo + k) * m] += g_k;
        }
        if order < Order::Hessians {
            continue;
        }
        let block = &mut hessians[seg.hessian_offset..seg.hessian_offset + n * n];
        for k in 0..n {
            // d · (a_i × v_k) = a_i · (v_k × d) for i ≤ k.
            let t = cross(&v[k], &d);
            let (v_k, g_k) = (v[k], g[k]);
            for i in 0..=k {
                let h = (dot(&v[i], &v_k) - g[i] * g_k + dot(&axes[lo + i], &t)) * inv_length;
                block[i + k * n] = h;
                block[k + i * n] = h;
            }
        }
    }
    data.computed = Some(order);
    Ok(())
}

fn mismatch(dof: usize) -> RoutingError {
    RoutingError::WorkspaceMismatch { what: "robot workspace (joints)", expected: dof, got: 0 }
}

// Plain 3-vector arithmetic: the inner loops stay fast without relying on inlining of generic
// code (the test profile is opt-level 1).

#[inline(always)]
fn transform(frame: &[f64; 12], p: &[f64; 3]) -> [f64; 3] {
    [
        frame[0] * p[0] + frame[3] * p[1] + frame[6] * p[2] + frame[9],
        frame[1] * p[0] + frame[4] * p[1] + frame[7] * p[2] + frame[10],
        frame[2] * p[0] + frame[5] * p[1] + frame[8] * p[2] + frame[11],
    ]
}

#[inline(always)]
fn sub(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
fn scale(a: &[f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline(always)]
fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
