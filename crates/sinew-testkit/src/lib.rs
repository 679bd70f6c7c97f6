//! # sinew-testkit
//!
//! What the workspace's tests, benches and `xtask` share, so that each exists once
//! (`publish = false`; a dev-dependency of the numeric crates, never a normal one):
//!
//! - [`alloc`]: the counting global allocator of the allocation tests (the model/data split's
//!   "evaluating a configuration allocates nothing", docs/ARCHITECTURE.md);
//! - [`cdhrm5`]: the platform's files loaded from the workspace root, the uniform chain with
//!   its link and cable pattern, and the calibrated pattern constants;
//! - [`config`]: seeded random configurations within the joint limits;
//! - [`random_chain`]: seeded random-geometry chains (random rpy, axes, offsets, inertials)
//!   with their link poses computed independently and pattern or explicit routings;
//! - [`numeric`]: the relative-error measures and the central-difference helpers that check
//!   every analytic derivative;
//! - [`one_joint`]: the paper's joint transform (eq. 1) and explicit one-joint routings, the
//!   closed-form fixtures.
//!
//! The E4 pose is not here: its one owner is the experiment layer, `sinew::paper::E4_Q` and
//! `E4_F0` in the facade, which this crate must not depend on (the facade depends on every
//! numeric crate, and they dev-depend on this one). Helpers that need a pose take it as an
//! argument ([`config::near`]); the tests of the paper's experiments live in the facade.
//!
//! Fixture loaders panic with the path and the error: they read the repository's own files,
//! and a test that cannot load them has nothing to check.
#![deny(missing_docs)]

pub mod alloc;
pub mod cdhrm5;
pub mod config;
pub mod newton;
pub mod numeric;
pub mod one_joint;
pub mod random_chain;
