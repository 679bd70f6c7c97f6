//! # sinew-robot
//!
//! URDF → an immutable serial-chain model ([`Robot`]) and a reusable workspace ([`RobotData`]).
//! For a configuration `Q` it gives every body pose, the 6 × dof geometric Jacobian of any
//! point fixed on any link (linear rows first, base frame), that Jacobian's derivative with
//! respect to `Q`, the gravity torques `T_g(Q)` and `∂T_g/∂Q` — all analytic, all without
//! allocation once the workspace exists (Pinocchio's model/data split).
//!
//! ```no_run
//! # fn main() -> Result<(), sinew_robot::RobotError> {
//! let robot = sinew_robot::load("robots/cdhrm5")?;
//! let mut data = sinew_robot::RobotData::new(&robot);
//! let q = vec![0.1; robot.dof()];
//! robot.forward_kinematics(&mut data, &q)?;
//! let mut jacobian = faer::Mat::<f64>::zeros(6, robot.dof());
//! robot.point_jacobian(&data, &robot.tip_point(), jacobian.as_mut())?;
//! # Ok(()) }
//! ```
//!
//! **Invariant:** nothing in this crate mutates a [`Robot`] after it is built; every
//! per-configuration function writes only into a [`RobotData`] or a caller's buffer.
#![deny(missing_docs)]

mod description;
mod display;
mod error;
mod error_kind;
mod generate;
mod gravity;
mod kinematics;
mod model;
mod urdf;

pub use description::{DESCRIPTION_FILE, RobotDescription, load, load_urdf};
pub use display::Compact;
pub use error::{Result, RobotError};
pub use error_kind::ErrorKind;
pub use generate::UniformChain;
pub use kinematics::RobotData;
pub use model::{Body, BodyPoint, ChainSettings, Joint, LinkPlacement, Robot};
