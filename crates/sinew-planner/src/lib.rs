//! # sinew-planner
//!
//! The tensions that make the arm stiffest where it matters, with static equilibrium exact,
//! every tension within its limits and the arm stable — each answer certified by a gap.
//!
//! # Math
//! Every balancing tension vector is `f = f_p + N λ` (the equilibrium set of
//! [`sinew_statics::EquilibriumSet`], any cable set); the limits make `λ` range over a polytope.
//! `K_q` is affine in `λ` (the controllable part `Σ f_c H_c` is linear in `f`, the inherent part
//! does not depend on it), so `A(λ) = K_q + K_W = A_0 + Σ λ_i A_i`, symmetric under a
//! conservative load (gravity and a force, no moment). On `{A ≻ 0}` the end stiffness
//! `K_x = (J_x A⁻¹ J_xᵀ)⁻¹` is matrix-concave in `λ`: `wᵀ K_x w = min { δqᵀ A δq : J_x δq = w }`
//! is a minimum of functions affine in `λ`. Hence `uᵀ K_fd u`, `λ_min(K_fd)`, `log det K_fd`
//! and the stability margin `λ_min(A)` are concave and `uᵀ C_x u` convex: each objective
//! ([`Objective`]) is a convex problem, whose local optimum is the global one.
//!
//! # Methods
//! The default ([`Method::InteriorPoint`]) writes the non-smooth objectives and every
//! requirement as small linear matrix inequalities (`ipm.rs`, `blocks.rs`), keeps `uᵀK_fd u` and
//! `log det K_fd` smooth with analytic Hessians (`smooth.rs`), and runs a primal–dual
//! interior-point method (`sdp.rs`: Mehrotra predictor–corrector, HKM direction). Every answer
//! carries a certificate that does not depend on the method: for a feasible `λ̄` and any
//! multipliers `y ≥ 0`, `Z ⪰ 0`, the Lagrangian is concave and bounds `φ` on the feasible set,
//! so its linearisation at `λ̄` maximised over the closed-form box of `λ` bounds the optimum
//! ([`Plan::gap`]). The bundle method ([`Method::Bundle`], `bundle.rs`: a level bundle method on
//! clarabel LPs and QPs, whose LP bound certifies its answers) is kept as a second, independent
//! method. With a moment in the load `K_W` is not symmetric and the argument fails:
//! [`PlanError::NonConservativeLoad`].
//!
//! [`Planner::plan_along`] re-plans along a trajectory, warm-started ([`Step`], [`RateLimit`],
//! [`AlongStep`]); [`Planner::replan`] makes one such step at a time, for a control loop. [`Planner::plan_in_stick`] plans with friction at the holes, in the stick
//! regime after a history (spec §9: `K_stick` is affine in the actuator tensions and
//! symmetric, so the same problem and certificate apply; [`StickPlanData`]).
//!
//! Model and workspace as elsewhere: [`Planner`] (the arm), [`PlannerData`] (reusable). The
//! interior-point method sizes its buffers once per run and allocates nothing per iteration
//! (`tests/allocations.rs`); a plan's set-up still allocates (the equilibrium set, the pencil,
//! the blocks of each phase), and the bundle method's clarabel allocates each subproblem.
#![deny(missing_docs)]

mod active;
mod along;
mod answer;
mod block_work;
mod blocks;
mod bundle;
#[cfg(test)]
mod checks;
mod data;
mod dense;
mod error;
mod frame;
mod interior;
mod ipm;
mod ipm_work;
mod kkt;
mod least;
mod margin_row;
mod pencil;
mod phases;
mod plan;
mod problem;
mod program;
mod restore;
mod rows;
mod sdp;
mod smooth;
mod stick_plan;

pub use along::{AlongStep, RateLimit, Step};
pub use error::{InputProblem, PlanError};
pub use plan::{Planner, PlannerData};
pub use problem::{
    DEFAULT_GAP, DEFAULT_MARGIN, Method, Objective, Plan, PlanSettings, Requirements,
};
pub use stick_plan::StickPlanData;
