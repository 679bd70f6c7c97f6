//! Friction at the holes (spec §9): each cable's segments from the actuator to the anchor,
//! the wrap angle at every hole, and the capstan weights of the two slip regimes, with their
//! derivatives. Geometry only: the statics and stiffness that use it live in the crates above.
//!
//! # Math
//! Cable `c` has holes `0 … H−1` (0-based, [`crate::Cable::holes`]; the last is the anchor) and
//! `H` *friction segments* `s = 0 … H−1`: segment 0 is the free length from the actuator to
//! hole 0 (length `ℓ_0` = [`crate::Cable::free_length`], `J_0 = 0`, `H_0 = 0`), segment `s ≥ 1`
//! joins hole `s−1` to hole `s` (it is [`crate::Routing::segments`]`[cable.segments.start + s − 1]`,
//! whose `index` is `s − 1`). In the spec's 1-based hole numbering, segment `s` joins hole `s` to
//! hole `s+1` and segment 0 ends at hole 1.
//!
//! - `ℓ_s(Q)`, `J_s = ∂ℓ_s/∂Q` (a row over the segment's own DOFs, the same numbers as the
//!   segment's share of `J_c`, so `J_c = Σ_s J_s`), `H_s = ∂²ℓ_s/∂Q²` (the routing's segment
//!   Hessian, [`FrictionModel::segment_hessian`]).
//! - `u_s`: the unit direction of segment `s` in the base frame, pointing away from the
//!   actuator (from hole `s−1` to hole `s`); `u_0` is the *entry direction*
//!   ([`crate::Cable::entry_direction`], given in the first hole's link frame, default `+z`)
//!   turned into the base frame at the pose.
//! - Wrap angle at hole `k = 0 … H−2` (the anchor has none), between the segment arriving
//!   (`k`) and the one leaving (`k + 1`):
//!
//!   ```text
//!   θ_k = atan2(|u_k × u_{k+1}|, u_k · u_{k+1})  ∈ [0, π]
//!   ```
//!
//!   (the spec's `θ_h` at its hole `h = k + 1`). Its gradient, with `n = (u_k × u_{k+1}) / |…|`,
//!   `∂u/∂q_i = (I − u uᵀ) ∂d/∂q_i / ℓ` for a segment vector `d`, `∂u_0/∂q_i = a_i × u_0`:
//!
//!   ```text
//!   ∂θ_k/∂q_i = −(∂u_k/∂q_i) · (n × u_k) + (∂u_{k+1}/∂q_i) · (n × u_{k+1})
//!   ```
//!
//!   A joint that turns both segments rigidly (one before every body of the two) leaves `θ_k`
//!   unchanged, so the gradient is stored over the joints from the lowest to the highest body
//!   of holes `k−1, k, k+1` (holes `0, 1` for `k = 0`), exact zeros elsewhere.
//! - **At θ → 0 (and θ → π)** `θ` is not differentiable: near a straight run it behaves like
//!   the norm of the two vectors' perpendicular difference, a cone. When
//!   `|u_k × u_{k+1}| < `[`WRAP_KINK`] the angle is kept exact (not smoothed: a straight arm has
//!   wrap angles of 0, and the capstan weights stay exact), the hole is flagged
//!   ([`FrictionData::kinked`]) and its gradient is **0**, the least-norm element of the
//!   subdifferential. There the one-sided derivative along `δQ` is `|(I − u uᵀ)(δu_{k+1} − δu_k)| ≥ 0`:
//!   `θ` grows whichever way the joints move, which a first-order model cannot represent with
//!   one gradient.
//! - Capstan weights of the slip regimes ([`Slip`]), going away from the actuator:
//!
//!   ```text
//!   pull:    T_s = T_{s−1} e^{−μ θ_{s−1}}        release:  T_s = T_{s−1} e^{+μ θ_{s−1}}
//!   T_s = T_0 w_s,   w_0 = 1,   w_s = w_{s−1} e^{σ μ θ_{s−1}}   (σ = −1 pull, +1 release)
//!   ∂w_s/∂Q = σ μ w_s Σ_{k < s} ∂θ_k/∂Q
//!   J̃_c = Σ_s w_s J_s                                   (m × dof, like J_c)
//!   ```
//!
//!   `μ` is the cable's ([`crate::Cable::friction_coefficient`]). The joint torque of the
//!   regime is `τ = −Σ_c T_{c,0} J̃_cᵀ`. At μ = 0 every weight is exactly 1 (`e^{−0} = 1`),
//!   every `∂w_s/∂Q` is 0 and `J̃_c` is [`crate::RoutingData::jacobian`] bit for bit: the
//!   segments' rows are computed by the routing's own formula and summed in the same order.
//!
//! Model/data split: [`FrictionModel`] (immutable, built once from a [`crate::Routing`]: the
//! layout of every row and each cable's μ and entry direction) and [`FrictionData`] (the
//! workspace, sized once). [`compute_friction_geometry`] reads the kinematics a
//! [`crate::RoutingData`] holds from its last evaluation; it is [`compute_friction_angles`]
//! (everything but `∂θ_k/∂Q`: what the stick regime reads) then [`compute_wrap_gradients`]
//! (the slip regimes, the directional response and the stick load limit read them), so a stick
//! evaluation skips the gradients. [`compute_capstan_weights`] then gives one regime's weights
//! (`∂w_s/∂Q` is not stored: [`FrictionData::weight_gradient`] computes it on demand). None
//! allocates. Layout: `model.rs`, workspace and its accessors: `data.rs`, the geometry:
//! `geometry.rs`, the weights: `weights.rs`.

mod data;
mod geometry;
mod lanes;
mod model;
mod weights;

pub use data::{CableRows, DofRow, FrictionData, SegmentRows, WeightGradient};
pub use geometry::{
    WRAP_KINK, compute_friction_angles, compute_friction_geometry, compute_wrap_gradients,
};
pub use model::{FrictionModel, Slip};
pub use weights::{capstan_factor, compute_capstan_weights};
