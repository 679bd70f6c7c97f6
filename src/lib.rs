//! # Sinew
//!
//! Joint-to-end stiffness of cable-driven hyper-redundant manipulators: how stiff each joint is
//! for given cable tensions and angles, how stiff the end-effector is in a pose under a load,
//! and how to distribute the tensions to make it stiffer without breaking static balance.
//!
//! This facade re-exports the workspace crates, each under a short name:
//!
//! - [`robot`]: URDF → immutable chain model, kinematics, Jacobians and their derivatives,
//!   gravity torques (`sinew-robot`).
//! - [`routing`]: cables as polylines through disc holes — lengths, cable Jacobian `J_c`, each
//!   cable's Hessian and the cable stiffness `K_l`, decoupled and routed (`sinew-routing`).
//! - [`statics`]: cable-joint statics, tension intervals and distribution, `T0` and `∂T0/∂Q`
//!   (`sinew-statics`).
//! - [`stiffness`]: joint stiffness, `K_q`, end compliance and stiffness (`sinew-stiffness`).
//! - [`indicators`]: the paper's joint indicators, sweeps and stiffness ellipsoids
//!   (`sinew-indicators`).
//! - [`planner`]: the tensions that optimise the end stiffness, certified by a gap
//!   (`sinew-planner`).
//!
//! [`paper`] holds the paper's experiments (spec §6) as data, checks and fixed-precision
//! tables, for `cargo xtask reproduce` and the snapshot tests; [`Error`] gathers every crate's
//! error, each by one path, [`Error::kind`] says what kind of failure it is ([`ErrorKind`]:
//! input, infeasible, unstable, rank-deficient, numerical) and [`Error::input_at_fault`] which
//! input to change ([`InputAtFault`]).
//!
//! Depend on a single crate (e.g. `sinew-robot`) when that is all you need.
#![deny(missing_docs)]

mod error;
pub mod paper;

pub use error::{Error, ErrorKind, InputAtFault};
pub use sinew_indicators as indicators;
pub use sinew_planner as planner;
pub use sinew_robot as robot;
pub use sinew_routing as routing;
pub use sinew_statics as statics;
pub use sinew_stiffness as stiffness;
