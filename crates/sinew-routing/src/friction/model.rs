//! The immutable description of the friction geometry ([`FrictionModel`]): where every
//! segment's, hole's and weight's row lives, and each cable's μ and entry direction.

use std::ops::Range;

use faer::MatRef;

use crate::error::{Result, RoutingError};
use crate::geometry::RoutingData;
use crate::routing::{MIN_SEGMENT_LENGTH, Routing};
use crate::vec3::{dot, scale};

/// The slip regime: which way every hole of a cable slides (spec §9). It sets the sign `σ` of
/// the capstan exponent, `T_s = T_{s−1} e^{σ μ θ}`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Slip {
    /// The cable slides toward the actuator at every hole: tension falls going distally,
    /// `T_s = T_{s−1} e^{−μθ}` (`σ = −1`).
    Pull,
    /// The cable slides away from the actuator: tension rises going distally,
    /// `T_s = T_{s−1} e^{+μθ}` (`σ = +1`).
    Release,
}

impl Slip {
    /// `σ`: −1 for [`Slip::Pull`], +1 for [`Slip::Release`].
    pub fn sign(self) -> f64 {
        match self {
            Slip::Pull => -1.0,
            Slip::Release => 1.0,
        }
    }
}

/// A row over a range of DOFs in a flat store: `values` at `offset`, one per DOF of `dofs`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Slot {
    pub(crate) dofs: Range<usize>,
    pub(crate) offset: usize,
}

impl Slot {
    /// A slot of `dofs` at the end of a store of `len` entries (grown by it).
    fn push(dofs: Range<usize>, len: &mut usize) -> Slot {
        let slot = Slot { offset: *len, dofs };
        *len += slot.dofs.len();
        slot
    }
}

/// Friction segment `s` of a cable (from hole `s − 1`, or from the actuator for `s = 0`, to
/// hole `s`) and hole `s`, where it ends and segment `s + 1` begins (module docs of
/// `crate::friction`).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Entry {
    /// Its segment in [`Routing::segments`] (`None`: segment 0, the free length).
    pub(crate) routing: Option<usize>,
    /// Whether that routing segment's `proximal` end is the hole further from the actuator.
    pub(crate) reversed: bool,
    /// `J_s` over the segment's DOFs.
    pub(crate) jacobian: Slot,
    /// Hole `s`'s body.
    pub(crate) hole_body: usize,
    /// Hole `s` in its body frame, m.
    pub(crate) hole_point: [f64; 3],
    /// `∂θ_s/∂Q` at hole `s` (empty for the anchor).
    pub(crate) wrap: Slot,
    /// The DOFs of `∂w_s/∂Q`: the union of the wrap rows of holes `0 … s−1`.
    pub(crate) weight: Range<usize>,
    /// For a segment within one body (constant length, `s ≥ 1`): its unit direction away from
    /// the actuator in that body's frame, so that its direction at a pose is one rotation.
    pub(crate) rigid_direction: Option<[f64; 3]>,
}

/// A friction segment the friction angles can copy whole from the routing's evaluation: one
/// across joints, run proximal to distal, of a cable whose segments cross distinct DOFs, so
/// that its `J_s` is `J_c` over its DOFs and its direction the routing's (`crate::friction`'s
/// geometry, when the routing kept both). Packed, so that the pass over every such segment
/// reads a few contiguous bytes per segment instead of its [`Entry`].
///
/// Such a cable never runs back: its holes lie on the bodies up to its anchor's, so a segment
/// run distal to proximal across a joint is followed by one across the same joint again.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Copied {
    /// Its index in [`FrictionModel::entries`].
    pub(crate) entry: usize,
    /// Its cable.
    pub(crate) cable: usize,
    /// Its segment in [`Routing::segments`].
    pub(crate) routing: usize,
    /// Its first DOF.
    pub(crate) dofs_start: usize,
    /// Where its `J_s` starts in the store of rows ([`Entry::jacobian`]'s offset).
    pub(crate) offset: usize,
    /// How many DOFs it crosses (at least one).
    pub(crate) dofs: usize,
}

/// A friction segment within one body (`s ≥ 1`): a constant length, no `J_s`, and a direction
/// that turns with its body (the friction angles' geometry). Packed, as [`Copied`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Turned {
    /// Its index in [`FrictionModel::entries`].
    pub(crate) entry: usize,
    /// Its segment in [`Routing::segments`].
    pub(crate) routing: usize,
    /// The body it lies in.
    pub(crate) body: usize,
    /// [`Entry::rigid_direction`].
    pub(crate) direction: [f64; 3],
}

/// The immutable description of a routing's friction geometry (Pinocchio's *model*): built once
/// by [`FrictionModel::new`] from a [`Routing`], read by [`crate::compute_friction_geometry`]
/// and [`crate::compute_capstan_weights`], which write a [`crate::FrictionData`].
///
/// Rows are indexed per cable by friction segment `s = 0 … H−1` (0 the free length) and by
/// hole `k = 0 … H−2` (the anchor, hole `H − 1`, has no wrap angle).
#[derive(Debug, Clone, PartialEq)]
pub struct FrictionModel {
    pub(crate) source: String,
    pub(crate) dof: usize,
    pub(crate) routing_segments: usize,
    /// Each cable's entries (`H` of them) in [`FrictionModel::entries`].
    pub(crate) cables: Vec<Range<usize>>,
    pub(crate) entries: Vec<Entry>,
    /// Each cable's μ.
    pub(crate) mu: Vec<f64>,
    /// Each cable's entry direction in its first hole's body frame (unit).
    pub(crate) entry_direction: Vec<[f64; 3]>,
    /// Each cable's free length, m.
    pub(crate) free_length: Vec<f64>,
    /// The segments after the free lengths, as the friction angles visit them: those they copy
    /// from the routing when it kept its Jacobian and directions, those within one body, and
    /// the others (their entries), each in entry order.
    pub(crate) copied: Vec<Copied>,
    pub(crate) turned: Vec<Turned>,
    pub(crate) placed: Vec<usize>,
    pub(crate) jacobian_len: usize,
    pub(crate) wrap_len: usize,
}

impl FrictionModel {
    /// The friction geometry of `routing`, each cable with its own μ and entry direction
    /// ([`crate::Cable::friction_coefficient`], [`crate::Cable::entry_direction`]).
    pub fn new(routing: &Routing) -> FrictionModel {
        let mut entries = Vec::with_capacity(routing.segments.len() + routing.cables.len());
        let mut cables = Vec::with_capacity(routing.cables.len());
        let (mut jacobian_len, mut wrap_len) = (0, 0);
        for cable in &routing.cables {
            let first = entries.len();
            let holes = &cable.holes;
            let body = |k: usize| holes[k].body_point.body;
            let mut union: Option<Range<usize>> = None;
            for k in 0..holes.len() {
                let (routing_segment, reversed, dofs) = match k {
                    0 => (None, false, 0..0),
                    _ => {
                        let r = cable.segments.start + k - 1;
                        (Some(r), body(k - 1) > body(k), routing.segments[r].dofs.clone())
                    }
                };
                let weight = union.clone().unwrap_or(0..0);
                // The bodies whose joints can change θ_k: those of holes k − 1 (none before the
                // first: the entry direction turns with hole 0's body), k and k + 1.
                let wrap_dofs = if k + 1 < holes.len() {
                    let near = [k.saturating_sub(1), k, k + 1].map(body);
                    let lo = near.iter().copied().min().unwrap_or(0);
                    lo..near.iter().copied().max().unwrap_or(0)
                } else {
                    0..0
                };
                if !wrap_dofs.is_empty() {
                    union = Some(match union {
                        Some(u) => u.start.min(wrap_dofs.start)..u.end.max(wrap_dofs.end),
                        None => wrap_dofs.clone(),
                    });
                }
                let p = holes[k].body_point.point;
                let rigid_direction = match k {
                    0 => None,
                    _ if body(k - 1) != body(k) => None,
                    _ => {
                        let before = holes[k - 1].body_point.point;
                        let d = [p.x - before.x, p.y - before.y, p.z - before.z];
                        let length = dot(&d, &d).sqrt();
                        // A degenerate one is left to the evaluation, which names it.
                        (length >= MIN_SEGMENT_LENGTH).then(|| scale(&d, 1.0 / length))
                    }
                };
                entries.push(Entry {
                    routing: routing_segment,
                    reversed,
                    jacobian: Slot::push(dofs, &mut jacobian_len),
                    hole_body: body(k),
                    hole_point: [p.x, p.y, p.z],
                    wrap: Slot::push(wrap_dofs, &mut wrap_len),
                    weight,
                    rigid_direction,
                });
            }
            cables.push(first..entries.len());
        }
        // Per cable: whether no two of its segments cross the same DOF, so that each `J_s` is
        // `J_c` over the segment's DOFs (the routing's own values, bit for bit).
        let disjoint: Vec<bool> = routing
            .cables
            .iter()
            .map(|c| disjoint(&routing.segments[c.segments.clone()]))
            .collect();
        let (mut copied, mut turned, mut placed) = (Vec::new(), Vec::new(), Vec::new());
        for (c, range) in cables.iter().enumerate() {
            for (e, entry) in entries.iter().enumerate().take(range.end).skip(range.start + 1) {
                match entry.routing {
                    Some(routing)
                        if disjoint[c]
                            && !entry.reversed
                            && entry.rigid_direction.is_none()
                            && !entry.jacobian.dofs.is_empty() =>
                    {
                        copied.push(Copied {
                            entry: e,
                            cable: c,
                            routing,
                            dofs_start: entry.jacobian.dofs.start,
                            offset: entry.jacobian.offset,
                            dofs: entry.jacobian.dofs.len(),
                        });
                    }
                    Some(routing) if entry.jacobian.dofs.is_empty() => {
                        if let Some(direction) = entry.rigid_direction {
                            turned.push(Turned {
                                entry: e,
                                routing,
                                body: entry.hole_body,
                                direction,
                            });
                        } else {
                            placed.push(e);
                        }
                    }
                    _ => placed.push(e),
                }
            }
        }
        FrictionModel {
            source: routing.source.clone(),
            dof: routing.dof,
            routing_segments: routing.segments.len(),
            cables,
            entries,
            mu: routing.cables.iter().map(|c| c.friction_coefficient).collect(),
            entry_direction: routing
                .cables
                .iter()
                .map(|c| [c.entry_in_body.x, c.entry_in_body.y, c.entry_in_body.z])
                .collect(),
            free_length: routing.cables.iter().map(|c| c.free_length).collect(),
            copied,
            turned,
            placed,
            jacobian_len,
            wrap_len,
        }
    }

    /// This model with every cable's μ set to `mu` (a front end's `--friction`), entry
    /// directions unchanged.
    ///
    /// # Errors
    /// [`RoutingError::InvalidFrictionCoefficient`] for a negative or non-finite `mu`.
    pub fn with_friction_coefficient(mut self, mu: f64) -> Result<FrictionModel> {
        if !(mu.is_finite() && mu >= 0.0) {
            return Err(RoutingError::InvalidFrictionCoefficient {
                file: self.source,
                cable: String::new(),
                field: "friction coefficient (override)".to_owned(),
                value: mu,
            });
        }
        self.mu.fill(mu);
        Ok(self)
    }

    /// Number of revolute joints (the columns of `J_s`, `J̃`).
    pub fn dof(&self) -> usize {
        self.dof
    }

    /// Number of segments of the routing it was built for ([`Routing::segments`]).
    pub fn routing_segment_count(&self) -> usize {
        self.routing_segments
    }

    /// Number of cables.
    pub fn cable_count(&self) -> usize {
        self.cables.len()
    }

    /// Number of friction segments of cable `c` (its holes, `H`: the free length and one per
    /// routing segment); `None` for no such cable.
    pub fn segment_count(&self, c: usize) -> Option<usize> {
        self.cables.get(c).map(|r| r.len())
    }

    /// Each cable's friction coefficient μ (routing order).
    pub fn friction_coefficients(&self) -> &[f64] {
        &self.mu
    }

    /// The segment of [`Routing::segments`] that is friction segment `s` of cable `c` (`None`
    /// for `s = 0`, the free length, and for no such segment).
    pub fn routing_segment(&self, c: usize, s: usize) -> Option<usize> {
        self.entry(c, s).ok().and_then(|e| e.routing)
    }

    /// `H_s = ∂²ℓ_s/∂Q²` of friction segment `s` of cable `c` over its DOFs (square, m/rad²): the
    /// routing's segment Hessian ([`RoutingData::segment_hessian`]), with those DOFs (the same
    /// as [`crate::FrictionData::segment_jacobian`]'s). `None` for `s = 0` (`H_0 = 0`).
    ///
    /// # Errors
    /// [`RoutingError::NoSuchCable`], [`RoutingError::DimensionMismatch`] for `s` out of range,
    /// then those of [`RoutingData::segment_hessian`].
    pub fn segment_hessian<'a>(
        &self,
        routing: &Routing,
        routing_data: &'a RoutingData,
        c: usize,
        s: usize,
    ) -> Result<Option<(Range<usize>, MatRef<'a, f64>)>> {
        self.check(routing)?;
        let entry = self.entry(c, s)?;
        match entry.routing {
            None => Ok(None),
            Some(r) => {
                Ok(Some((entry.jacobian.dofs.clone(), routing_data.segment_hessian(routing, r)?)))
            }
        }
    }

    /// Entry `s` of cable `c`.
    pub(crate) fn entry(&self, c: usize, s: usize) -> Result<&Entry> {
        // Matches, not `ok_or`: that builds (and drops) the error on every call.
        let Some(range) = self.cables.get(c) else {
            return Err(RoutingError::NoSuchCable { cable: c, cables: self.cables.len() });
        };
        match self.entries.get(range.start + s).filter(|_| s < range.len()) {
            Some(entry) => Ok(entry),
            None => Err(RoutingError::DimensionMismatch {
                what: "friction segment or hole index",
                expected: range.len(),
                got: s,
            }),
        }
    }

    /// Check that the model was built for `routing` (its DOFs, cables and segments).
    pub(crate) fn check(&self, routing: &Routing) -> Result<()> {
        for (what, expected, got) in [
            ("friction model (joints)", routing.dof, self.dof),
            ("friction model (cables)", routing.cables.len(), self.cables.len()),
            ("friction model (segments)", routing.segments.len(), self.routing_segments),
        ] {
            if expected != got {
                return Err(RoutingError::WorkspaceMismatch { what, expected, got });
            }
        }
        Ok(())
    }
}

/// Whether no two of `segments` (one cable's) cross the same DOF.
fn disjoint(segments: &[crate::routing::Segment]) -> bool {
    let crossing = |s: &&crate::routing::Segment| !s.dofs.is_empty();
    segments.iter().filter(crossing).enumerate().all(|(i, a)| {
        let later = segments.iter().filter(crossing).skip(i + 1);
        later.into_iter().all(|b| a.dofs.end <= b.dofs.start || b.dofs.end <= a.dofs.start)
    })
}
