//! # sinew-indicators
//!
//! The paper's stiffness indicators (section III.C):
//!
//! - the joint stiffness indicator `σ_{i,x} = [K_{i,x}, Δk_{i,x}]ᵀ`, `σ_{i,y}` (eq. 20) of a
//!   joint over its feasible tension interval ([`JointProbe`], [`JointStiffnessRange`]);
//! - sweeps of those over a grid of the joint's angles, in parallel ([`sweep_joint`], the
//!   paper's Fig. 5; [`sweep_probe`] for a probe's own configuration);
//! - both with friction at the holes (spec §9, [`JointProbe::with_friction`]): the regime's
//!   statics, with the actuator tensions as unknowns, and its joint stiffness;
//! - the end stiffness ellipsoid of `K_fd` (eq. 21): semi-axes, principal directions, `λ_min`,
//!   condition number, volume, directional stiffness ([`StiffnessEllipsoid`], defined in
//!   sinew-stiffness with the evaluation outcome that gives it, re-exported here).
#![deny(missing_docs)]

mod error;
mod joint;
mod probe_friction;
mod range;
mod sweep;

pub use error::IndicatorError;
pub use joint::JointProbe;
pub use range::{Indicator, JointStiffnessRange};
pub use sinew_stiffness::StiffnessEllipsoid;
pub use sweep::{AngleGrid, SweepCell, SweepMaps, sweep_joint, sweep_probe};
