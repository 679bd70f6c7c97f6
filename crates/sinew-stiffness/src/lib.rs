//! # sinew-stiffness
//!
//! Joint stiffness and end stiffness of a cable-driven hyper-redundant manipulator (paper
//! section III; spec §3, §5).
#![deny(missing_docs)]

mod end;
mod error;

pub use end::{EndStiffnessData, RANK_TOLERANCE, end_compliance, end_stiffness, stability_margin};
pub use error::StiffnessError;
