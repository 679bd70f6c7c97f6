//! The friction geometry's workspace ([`FrictionData`]) and its accessors.

use std::ops::Range;

use faer::MatRef;

use super::model::{Entry, FrictionModel, Slip, Slot};
use crate::error::{Result, RoutingError};

/// A row over a range of DOFs: `values[j]` is the entry of DOF `dofs.start + j`; every DOF
/// outside `dofs` has an exact zero.
#[derive(Debug, Clone, PartialEq)]
pub struct DofRow<'a> {
    /// The DOFs the row covers.
    pub dofs: Range<usize>,
    /// One value per DOF of `dofs`.
    pub values: &'a [f64],
}

impl DofRow<'_> {
    /// The entry of DOF `d` (0 outside [`DofRow::dofs`]).
    pub fn get(&self, d: usize) -> f64 {
        if self.dofs.contains(&d) { self.values[d - self.dofs.start] } else { 0.0 }
    }
}

/// `∂w_s/∂Q` of one friction segment ([`FrictionData::weight_gradient`]): a row over a range
/// of DOFs, every DOF outside it an exact zero.
#[derive(Debug, Clone, PartialEq)]
pub struct WeightGradient {
    /// The DOFs the row covers.
    pub dofs: Range<usize>,
    /// One value per DOF of `dofs`, 1/rad.
    pub values: Vec<f64>,
}

impl WeightGradient {
    /// The entry of DOF `d` (0 outside [`WeightGradient::dofs`]).
    pub fn get(&self, d: usize) -> f64 {
        if self.dofs.contains(&d) { self.values[d - self.dofs.start] } else { 0.0 }
    }
}

/// One friction segment of a cable at the computed geometry, as
/// [`FrictionData::segments`] yields them: what the stiffness of every regime reads per
/// segment, checked once per cable instead of once per access.
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentRows<'a> {
    /// `ℓ_s`, m (segment 0: the free length).
    pub length: f64,
    /// `w_s` of the last regime's weights (`None` before [`crate::compute_capstan_weights`]).
    pub weight: Option<f64>,
    /// `J_s` over the segment's DOFs ([`FrictionData::segment_jacobian`]).
    pub jacobian: DofRow<'a>,
    /// `∂θ_s/∂Q` of hole `s`, where the segment ends ([`FrictionData::wrap_gradient`]; empty
    /// for the anchor, which has no wrap angle; `None` when the wrap gradients were not
    /// computed, [`crate::compute_friction_angles`] alone).
    pub wrap_gradient: Option<DofRow<'a>>,
    /// The routing segment it is (`None` for segment 0, the free length): its Hessian block is
    /// `H_s` over [`SegmentRows::jacobian`]'s DOFs ([`crate::SegmentHessians::get`]).
    pub routing_segment: Option<usize>,
}

/// One cable's rows at the computed geometry, as [`FrictionData::cable`] gives them: the
/// workspace checked against the model once, then each row read on demand (the slip and stick
/// stiffness loops, which need a few rows of each segment, not all of them).
#[derive(Debug, Clone, Copy)]
pub struct CableRows<'a> {
    /// `ℓ_s`, m, per friction segment (`H` values; `[0]` the free length).
    pub lengths: &'a [f64],
    /// `w_s` of the last regime's weights (`H` values; `None` before
    /// [`crate::compute_capstan_weights`]).
    pub weights: Option<&'a [f64]>,
    /// `θ_k`, rad, per hole (`H` values; the anchor's is 0).
    pub wrap: &'a [f64],
    entries: &'a [Entry],
    jacobians: &'a [f64],
    wrap_gradients: Option<&'a [f64]>,
}

impl<'a> CableRows<'a> {
    /// The number of friction segments (holes), `H`.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether the cable has no holes (never, for a built routing).
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// `J_s` of friction segment `s` ([`FrictionData::segment_jacobian`]; empty for `s ≥ H`).
    #[inline]
    pub fn jacobian(&self, s: usize) -> DofRow<'a> {
        self.entries.get(s).map_or(EMPTY, |e| row(self.jacobians, &e.jacobian))
    }

    /// `∂θ_k/∂Q` of hole `k` ([`FrictionData::wrap_gradient`]; empty for the anchor and for
    /// `k ≥ H`).
    ///
    /// # Errors
    /// [`RoutingError::FrictionNotComputed`] when the wrap gradients were not computed
    /// ([`crate::compute_friction_angles`] alone): [`FrictionData::check_wrap_gradients`]'s.
    #[inline]
    pub fn wrap_gradient(&self, k: usize) -> Result<DofRow<'a>> {
        match self.wrap_gradients {
            Some(store) => Ok(self.entries.get(k).map_or(EMPTY, |e| row(store, &e.wrap))),
            None => Err(GRADIENTS_MISSING),
        }
    }

    /// The routing segment friction segment `s` is (`None` for the free length, `s = 0`, and
    /// for `s ≥ H`): its Hessian block is `H_s` over [`CableRows::jacobian`]'s DOFs.
    pub fn routing_segment(&self, s: usize) -> Option<usize> {
        self.entries.get(s).and_then(|e| e.routing)
    }
}

const EMPTY: DofRow<'static> = DofRow { dofs: 0..0, values: &[] };

/// The reusable workspace of a [`FrictionModel`] (Pinocchio's *data*): the friction geometry
/// at one configuration and one slip regime's weights, sized once so that computing them
/// allocates nothing. Rows are indexed as in the module docs of `crate::friction`: per cable,
/// friction segment `s = 0 … H−1` (0 the free length) and hole `k = 0 … H−2`.
#[derive(Debug, Clone)]
pub struct FrictionData {
    pub(crate) geometry: bool,
    /// Whether `wrap_gradients` hold `∂θ_k/∂Q` at the geometry's configuration.
    pub(crate) gradients: bool,
    pub(crate) slip: Option<Slip>,
    pub(crate) cables: usize,
    pub(crate) dof: usize,
    /// `ℓ_s`, m, per entry.
    pub(crate) lengths: Vec<f64>,
    /// `u_s` (base frame, unit, away from the actuator), per entry.
    pub(crate) directions: Vec<[f64; 3]>,
    /// Hole `s` in the base frame, per entry (computed by the wrap gradients' pass).
    pub(crate) positions: Vec<[f64; 3]>,
    /// Each body's pose `[R (column-major), t]` (base frame) at the geometry's configuration,
    /// one per body: where the wrap gradients' pass places the holes.
    pub(crate) frames: Vec<[f64; 12]>,
    /// `J_s`, per entry's jacobian slot.
    pub(crate) jacobians: Vec<f64>,
    /// `θ_k` per entry (0 at the anchor).
    pub(crate) wrap: Vec<f64>,
    /// Whether `|u_k × u_{k+1}| <` [`super::WRAP_KINK`], per entry.
    pub(crate) kinked: Vec<bool>,
    /// `∂θ_k/∂Q`, per entry's wrap slot.
    pub(crate) wrap_gradients: Vec<f64>,
    /// `w_s`, per entry.
    pub(crate) weights: Vec<f64>,
    /// Scratch, two values per entry: each hole's `|u_k × u_{k+1}|` and `u_k · u_{k+1}` (the
    /// sine and cosine of its wrap angle), then each hole's capstan exponent `σμθ_k` (in `[0]`):
    /// the inputs of `lanes.rs`.
    pub(crate) scratch: [Vec<f64>; 2],
    /// `J̃_c`, m × dof, column-major.
    pub(crate) effective_jacobian: Vec<f64>,
    /// Each joint's axis `a_i` (base frame) at the geometry's configuration, one per DOF.
    pub(crate) axes: Vec<[f64; 3]>,
    /// Each joint's moment `a_i × p_i` (base frame) at the geometry's configuration, one per DOF.
    pub(crate) moments: Vec<[f64; 3]>,
}

impl FrictionData {
    /// A workspace sized for `model`.
    pub fn new(model: &FrictionModel) -> FrictionData {
        let n = model.entries.len();
        let m = model.cables.len();
        FrictionData {
            geometry: false,
            gradients: false,
            slip: None,
            cables: m,
            dof: model.dof,
            lengths: vec![0.0; n],
            directions: vec![[0.0; 3]; n],
            positions: vec![[0.0; 3]; n],
            frames: vec![[0.0; 12]; model.dof + 1],
            jacobians: vec![0.0; model.jacobian_len],
            wrap: vec![0.0; n],
            kinked: vec![false; n],
            wrap_gradients: vec![0.0; model.wrap_len],
            weights: vec![0.0; n],
            scratch: [vec![0.0; n], vec![0.0; n]],
            effective_jacobian: vec![0.0; m * model.dof],
            axes: vec![[0.0; 3]; model.dof],
            moments: vec![[0.0; 3]; model.dof],
        }
    }

    /// The regime of the last [`crate::compute_capstan_weights`] since the geometry was last
    /// computed (`None` before, or after a failed computation).
    pub fn slip(&self) -> Option<Slip> {
        self.slip
    }

    /// Friction segment lengths `ℓ_s` of cable `c`, m (`H` values; `[0]` the free length).
    ///
    /// # Errors
    /// [`RoutingError::NotComputed`] before [`crate::compute_friction_geometry`],
    /// [`RoutingError::NoSuchCable`], [`RoutingError::WorkspaceMismatch`].
    pub fn lengths(&self, model: &FrictionModel, c: usize) -> Result<&[f64]> {
        Ok(&self.lengths[self.geometry_of(model, c)?])
    }

    /// The unit directions `u_s` of cable `c`'s friction segments in the base frame, pointing
    /// away from the actuator (`H` values; `[0]` the entry direction at the pose).
    ///
    /// # Errors
    /// As [`FrictionData::lengths`].
    pub fn directions(&self, model: &FrictionModel, c: usize) -> Result<&[[f64; 3]]> {
        Ok(&self.directions[self.geometry_of(model, c)?])
    }

    /// `J_s = ∂ℓ_s/∂Q` of friction segment `s` of cable `c` (m/rad), over the routing segment's
    /// DOFs (empty for `s = 0` and for a segment within one body).
    ///
    /// # Errors
    /// As [`FrictionData::lengths`]; [`RoutingError::DimensionMismatch`] for `s ≥ H`.
    pub fn segment_jacobian(
        &self,
        model: &FrictionModel,
        c: usize,
        s: usize,
    ) -> Result<DofRow<'_>> {
        self.geometry_of(model, c)?;
        Ok(row(&self.jacobians, &model.entry(c, s)?.jacobian))
    }

    /// The wrap angles `θ_k` of cable `c`, rad, one per hole but the anchor (`H − 1` values;
    /// `[k]` at `cable.holes[k]`).
    ///
    /// # Errors
    /// As [`FrictionData::lengths`].
    pub fn wrap_angles(&self, model: &FrictionModel, c: usize) -> Result<&[f64]> {
        let range = self.geometry_of(model, c)?;
        Ok(&self.wrap[range.start..range.end - 1])
    }

    /// Which holes of cable `c` are at the kink `θ ≈ 0` (or `≈ π`): `|u_k × u_{k+1}| <`
    /// [`super::WRAP_KINK`], where [`FrictionData::wrap_gradient`] is 0 (`H − 1` values).
    ///
    /// # Errors
    /// As [`FrictionData::lengths`].
    pub fn kinked(&self, model: &FrictionModel, c: usize) -> Result<&[bool]> {
        let range = self.geometry_of(model, c)?;
        Ok(&self.kinked[range.start..range.end - 1])
    }

    /// `∂θ_k/∂Q` at hole `k` of cable `c` (rad/rad), over the joints between the lowest and
    /// the highest body of holes `k − 1, k, k + 1`; 0 at a kinked hole.
    ///
    /// # Errors
    /// As [`FrictionData::lengths`]; [`RoutingError::DimensionMismatch`] for `k ≥ H − 1`;
    /// [`RoutingError::FrictionNotComputed`] when the geometry was computed without the wrap
    /// gradients ([`FrictionData::check_wrap_gradients`]).
    pub fn wrap_gradient(&self, model: &FrictionModel, c: usize, k: usize) -> Result<DofRow<'_>> {
        let range = self.geometry_of(model, c)?;
        self.check_wrap_gradients()?;
        if k + 1 >= range.len() {
            let expected = range.len() - 1;
            return Err(RoutingError::DimensionMismatch { what: "hole index", expected, got: k });
        }
        Ok(row(&self.wrap_gradients, &model.entry(c, k)?.wrap))
    }

    /// The capstan weights `w_s` of cable `c` (`H` values, `w_0 = 1`): `T_s = T_0 w_s`.
    ///
    /// # Errors
    /// [`RoutingError::NotComputed`] before [`crate::compute_capstan_weights`], else as
    /// [`FrictionData::lengths`].
    pub fn weights(&self, model: &FrictionModel, c: usize) -> Result<&[f64]> {
        Ok(&self.weights[self.weights_of(model, c)?])
    }

    /// `∂w_s/∂Q` of friction segment `s` of cable `c` (1/rad), over the union of the wrap rows of
    /// holes `0 … s − 1` (empty for `s = 0`): `σ μ w_s Σ_{k<s} ∂θ_k/∂Q`, the sum in hole order.
    ///
    /// Computed on demand from the wrap gradients and allocates its row: the evaluations do
    /// not read these rows (the slip stiffness sums over the holes instead, module docs of
    /// `slip.rs` in `sinew-stiffness`), checks and reports do.
    ///
    /// # Errors
    /// As [`FrictionData::weights`]; [`RoutingError::DimensionMismatch`] for `s ≥ H`;
    /// [`RoutingError::FrictionNotComputed`] without the wrap gradients
    /// ([`FrictionData::check_wrap_gradients`]).
    pub fn weight_gradient(
        &self,
        model: &FrictionModel,
        c: usize,
        s: usize,
    ) -> Result<WeightGradient> {
        let range = self.weights_of(model, c)?;
        self.check_wrap_gradients()?;
        let entry = model.entry(c, s)?;
        let dofs = entry.weight.clone();
        let mut values = vec![0.0; dofs.len()];
        for hole in &model.entries[range.start..range.start + s] {
            let theta = row(&self.wrap_gradients, &hole.wrap);
            for (d, g) in theta.dofs.zip(theta.values) {
                values[d - dofs.start] += g;
            }
        }
        let rate = self.slip.map_or(0.0, Slip::sign) * model.mu[c] * self.weights[range.start + s];
        for v in &mut values {
            *v *= rate;
        }
        Ok(WeightGradient { dofs, values })
    }

    /// Cable `c`'s rows ([`CableRows`]), the workspace checked against `model` once.
    ///
    /// # Errors
    /// As [`FrictionData::lengths`].
    pub fn cable<'a>(&'a self, model: &'a FrictionModel, c: usize) -> Result<CableRows<'a>> {
        let range = self.geometry_of(model, c)?;
        Ok(CableRows {
            lengths: &self.lengths[range.clone()],
            weights: self.slip.map(|_| &self.weights[range.clone()]),
            wrap: &self.wrap[range.clone()],
            entries: &model.entries[range],
            jacobians: &self.jacobians,
            wrap_gradients: self.gradients.then_some(&self.wrap_gradients[..]),
        })
    }

    /// Cable `c`'s friction segments from the actuator to the anchor (`H` of them), the
    /// workspace checked against `model` once: the loops of the regimes' stiffness.
    ///
    /// # Errors
    /// As [`FrictionData::lengths`].
    pub fn segments<'a>(
        &'a self,
        model: &'a FrictionModel,
        c: usize,
    ) -> Result<impl ExactSizeIterator<Item = SegmentRows<'a>> + 'a> {
        let range = self.geometry_of(model, c)?;
        let (weighted, gradients) = (self.slip.is_some(), self.gradients);
        let entries = model.entries.get(range.clone()).unwrap_or(&[]);
        Ok(entries.iter().zip(range).map(move |(entry, e)| SegmentRows {
            length: self.lengths[e],
            weight: weighted.then(|| self.weights[e]),
            jacobian: row(&self.jacobians, &entry.jacobian),
            wrap_gradient: gradients.then(|| row(&self.wrap_gradients, &entry.wrap)),
            routing_segment: entry.routing,
        }))
    }

    /// The effective cable Jacobian `J̃_c = Σ_s w_{c,s} J_{c,s}` of the last regime, m × dof,
    /// m/rad (μ = 0: [`crate::RoutingData::jacobian`] bit for bit).
    ///
    /// # Errors
    /// [`RoutingError::NotComputed`] before [`crate::compute_capstan_weights`].
    pub fn effective_jacobian(&self) -> Result<MatRef<'_, f64>> {
        if self.slip.is_none() {
            return Err(WEIGHTS_MISSING);
        }
        Ok(MatRef::from_column_major_slice(&self.effective_jacobian, self.cables, self.dof))
    }

    /// Whether the wrap gradients `∂θ_k/∂Q` are computed at the geometry's configuration
    /// ([`crate::compute_wrap_gradients`], part of [`crate::compute_friction_geometry`]).
    ///
    /// # Errors
    /// [`RoutingError::FrictionNotComputed`] when they are not (the geometry computed by
    /// [`crate::compute_friction_angles`] alone, or not at all).
    pub fn check_wrap_gradients(&self) -> Result<()> {
        if self.geometry && self.gradients {
            return Ok(());
        }
        Err(GRADIENTS_MISSING)
    }

    /// Cable `c`'s entries, once the geometry is computed.
    fn geometry_of(&self, model: &FrictionModel, c: usize) -> Result<Range<usize>> {
        self.check(model)?;
        if !self.geometry {
            return Err(RoutingError::FrictionNotComputed {
                what: "friction geometry",
                call: "compute_friction_geometry",
            });
        }
        // A match, not `ok_or`: that builds (and drops) the error on every call (session 8's
        // profile: 14 % of the slip stiffness).
        match model.cables.get(c) {
            Some(range) => Ok(range.clone()),
            None => Err(RoutingError::NoSuchCable { cable: c, cables: model.cables.len() }),
        }
    }

    /// Cable `c`'s entries, once the weights are computed.
    fn weights_of(&self, model: &FrictionModel, c: usize) -> Result<Range<usize>> {
        let range = self.geometry_of(model, c)?;
        if self.slip.is_none() {
            return Err(WEIGHTS_MISSING);
        }
        Ok(range)
    }

    /// Check that the workspace was sized for `model`.
    pub(crate) fn check(&self, model: &FrictionModel) -> Result<()> {
        for (what, expected, got) in [
            ("friction workspace (cables)", model.cables.len(), self.cables),
            ("friction workspace (joints)", model.dof, self.dof),
            ("friction workspace (entries)", model.entries.len(), self.lengths.len()),
            ("friction workspace (Jacobian rows)", model.jacobian_len, self.jacobians.len()),
            ("friction workspace (wrap rows)", model.wrap_len, self.wrap_gradients.len()),
        ] {
            if expected != got {
                return Err(RoutingError::WorkspaceMismatch { what, expected, got });
            }
        }
        Ok(())
    }
}

#[inline]
fn row<'a>(store: &'a [f64], slot: &Slot) -> DofRow<'a> {
    DofRow { dofs: slot.dofs.clone(), values: &store[slot.offset..slot.offset + slot.dofs.len()] }
}

/// The one error of every accessor of the wrap gradients before they are computed.
const GRADIENTS_MISSING: RoutingError = RoutingError::FrictionNotComputed {
    what: "wrap gradients",
    call: "compute_wrap_gradients (or compute_friction_geometry)",
};

const WEIGHTS_MISSING: RoutingError =
    RoutingError::FrictionNotComputed { what: "capstan weights", call: "compute_capstan_weights" };
