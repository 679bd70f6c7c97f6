//! The capstan band of every hole at the pose, after a history (spec §9): what the stick load
//! limit (`stick_limit.rs`) and the directional response (`directional.rs`) both read.
//!
//! Hole `k` of cable `c` (0-based, between friction segments `k` and `k + 1`) holds while
//! `T_k e^{−μθ_k} ≤ T_{k+1} ≤ T_k e^{+μθ_k}`. Each edge's room `g` and its rate `ġ` under an
//! increment (`δT` of the two segments, `δθ_k = ∇θ_k · δQ`):
//!
//! ```text
//! lower:  g⁻ = T_{k+1} − T_k e^{−μθ}      ġ⁻ = δT_{k+1} − e^{−μθ} δT_k + e^{−μθ} μ T_k δθ
//! upper:  g⁺ = T_k e^{+μθ} − T_{k+1}      ġ⁺ = −δT_{k+1} + e^{+μθ} δT_k + e^{+μθ} μ T_k δθ
//! ```
//!
//! written `ġ = a δT_{k+1} + b δT_k + d δθ` ([`Hole::rate_coefficients`]).

use sinew_routing::{DofRow, FrictionData, FrictionModel, Routing};

use crate::error::StiffnessError;
use crate::friction::{History, axial_rigidity};

/// A hole is on an edge of its band when `g ≤ EDGE_TOLERANCE · (T_k + T_{k+1})`: a pull or
/// release distribution puts every hole on an edge up to the rounding of `e^{±μθ}` products
/// (1e-16 relative), and no band a real arm has is this narrow.
pub const EDGE_TOLERANCE: f64 = 1e-12;

/// An edge's rate `ġ` is taken as 0 (the increment neither approaches nor leaves the edge)
/// when `|ġ| ≤ RATE_TOLERANCE ·` the sum of its terms' magnitudes: cancellation, as at a hole
/// inside one body, whose segments keep their lengths and angle.
pub const RATE_TOLERANCE: f64 = 1e-10;

/// Which edge of a hole's capstan band `T_k e^{−μθ} ≤ T_{k+1} ≤ T_k e^{+μθ}`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BandEdge {
    /// `T_{k+1} = T_k e^{−μθ_k}`: the cable slides toward the actuator (as in pull).
    Lower,
    /// `T_{k+1} = T_k e^{+μθ_k}`: the cable slides away from the actuator (as in release).
    Upper,
}

impl BandEdge {
    /// The sign of the material flux through a hole sliding at this edge (distal positive):
    /// −1 at the lower edge (toward the actuator), +1 at the upper one.
    pub fn flux_sign(self) -> f64 {
        match self {
            BandEdge::Lower => -1.0,
            BandEdge::Upper => 1.0,
        }
    }
}

/// A hole and one edge of its band.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct HoleEvent {
    /// The cable (routing order, 0-based).
    pub cable: usize,
    /// The hole, 0-based along the cable from the actuator (between friction segments `hole`
    /// and `hole + 1`; the anchor has none).
    pub hole: usize,
    /// The edge.
    pub edge: BandEdge,
    /// Whether the hole is at the kink `θ ≈ 0` ([`sinew_routing::FrictionData::kinked`]): its
    /// band has no width there, and the one-sided growth of `θ` is not modelled (its gradient
    /// is taken as 0).
    pub kinked: bool,
}

/// Each edge of a hole: `(edge, (a, b, d), g, whether the hole is on it)` ([`Hole::edges`]).
pub(crate) type Edges = [(BandEdge, (f64, f64, f64), f64, bool); 2];

/// One hole's band at the pose.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Hole {
    pub cable: usize,
    pub hole: usize,
    pub kinked: bool,
    /// `T_k`, `T_{k+1}` (N).
    pub tensions: [f64; 2],
    /// `E A/ℓ_k`, `E A/ℓ_{k+1}` (N/m; segment 0 the free length).
    pub springs: [f64; 2],
    /// `e^{−μθ_k}`, `e^{+μθ_k}`.
    pub ratios: [f64; 2],
    pub mu: f64,
}

impl Hole {
    /// The event of this hole at `edge`.
    pub fn event(&self, edge: BandEdge) -> HoleEvent {
        HoleEvent { cable: self.cable, hole: self.hole, edge, kinked: self.kinked }
    }

    /// The room `g` left at `edge` (N).
    pub fn room(&self, edge: BandEdge) -> f64 {
        let [t_k, t_next] = self.tensions;
        match edge {
            BandEdge::Lower => t_next - t_k * self.ratios[0],
            BandEdge::Upper => t_k * self.ratios[1] - t_next,
        }
    }

    /// `(a, b, d)` of `ġ = a δT_{k+1} + b δT_k + d δθ_k` at `edge`.
    pub fn rate_coefficients(&self, edge: BandEdge) -> (f64, f64, f64) {
        let turn = self.mu * self.tensions[0];
        match edge {
            BandEdge::Lower => (1.0, -self.ratios[0], self.ratios[0] * turn),
            BandEdge::Upper => (-1.0, self.ratios[1], self.ratios[1] * turn),
        }
    }

    /// Each edge, lower first: `(edge, (a, b, d), g, whether the hole is on it)`, on it when
    /// `g ≤` [`EDGE_TOLERANCE`] `· (T_k + T_{k+1})`.
    pub fn edges(&self) -> Edges {
        [BandEdge::Lower, BandEdge::Upper].map(|edge| {
            let g = self.room(edge);
            (edge, self.rate_coefficients(edge), g, g <= EDGE_TOLERANCE * self.scale())
        })
    }

    /// `T_k + T_{k+1}`, the scale of `g` and `ġ`'s tolerances.
    pub fn scale(&self) -> f64 {
        self.tensions[0] + self.tensions[1]
    }
}

/// Every hole's band after `history` at the actuator tensions `actuator`, cable by cable, hole
/// by hole. Checks μ > 0 everywhere and, for a pull or release history, its weights.
pub(crate) fn holes(
    model: &FrictionModel,
    routing: &Routing,
    friction: &FrictionData,
    history: History,
    actuator: &[f64],
) -> Result<Vec<Hole>, StiffnessError> {
    if actuator.len() != model.cable_count() {
        let (expected, got) = (model.cable_count(), actuator.len());
        return Err(StiffnessError::DimensionMismatch { what: "actuator tensions", expected, got });
    }
    if let Some(cable) = model.friction_coefficients().iter().position(|&mu| mu <= 0.0) {
        return Err(StiffnessError::StickWithoutFriction { cable });
    }
    if let Some(slip) = history.slip() {
        crate::friction::check_weights(friction, slip)?;
    }
    let ea = axial_rigidity(routing);
    let mut out = Vec::new();
    for (c, (&t_0, &mu)) in actuator.iter().zip(model.friction_coefficients()).enumerate() {
        let lengths = friction.lengths(model, c)?;
        let weights = match history {
            History::Equal => None,
            History::Pull | History::Release => Some(friction.weights(model, c)?),
        };
        let tension = |s: usize| weights.map_or(t_0, |w| t_0 * w[s]);
        let (angles, kinked) = (friction.wrap_angles(model, c)?, friction.kinked(model, c)?);
        // Each segment's spring once (it is after one hole and before the next), and one
        // exponential per hole (`e^{+μθ} = 1/e^{−μθ}`, to a unit of rounding).
        let mut spring = lengths.first().map_or(0.0, |l| ea / l);
        for (k, (&theta, &kinked)) in angles.iter().zip(kinked).enumerate() {
            let next = ea / lengths[k + 1];
            let lower = sinew_routing::capstan_factor(-mu * theta);
            out.push(Hole {
                cable: c,
                hole: k,
                kinked,
                tensions: [tension(k), tension(k + 1)],
                springs: [spring, next],
                ratios: [lower, 1.0 / lower],
                mu,
            });
            spring = next;
        }
    }
    Ok(out)
}

/// `row · x` over the row's DOFs.
pub(crate) fn dot(row: &DofRow<'_>, x: &[f64]) -> f64 {
    row.values.iter().zip(row.dofs.clone()).map(|(v, d)| v * x[d]).sum()
}
