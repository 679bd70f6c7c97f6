//! The command line: subcommands and options (clap derive).

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

use crate::friction_args::{FrictionArgs, PlanFrictionArgs, RegimeArgs};

/// Stiffness of cable-driven hyper-redundant manipulators, from a robot folder.
///
/// SI units throughout (m, rad, N, N m, N/m, N m/rad). Universal joints are numbered from 1
/// on the command line (`--joint 1` is the joint at the base, as in the paper); the JSON
/// output counts them from 0 (its `joint` fields). Exit codes: 0 success (an unstable
/// equilibrium is a result), 1 the model has no answer (e.g. an infeasible load), 2 bad
/// input (options, counts, limits, robot files). See docs/cli.md.
#[derive(Debug, Parser)]
#[command(name = "sinew", version, propagate_version = true)]
pub struct Cli {
    /// What to compute.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// The expanded cable routing (every cable's holes, material, limits) and the joints.
    Routing(RoutingArgs),
    /// One universal joint alone: its feasible tension interval and stiffness range (eq. 20).
    ///
    /// The paper's single-joint model: the joint's own three cables hold the torque (the only
    /// cables with tension), the other joints stay at 0; the inherent stiffness counts every
    /// cable crossing the joint (routed: the distal joints' cables too). Prints λ_min and λ_max (eq. 22–23), the
    /// tensions at both ends, the controllable, inherent and total 2 × 2 stiffness at both
    /// ends, and σ_x, σ_y = [[K_min, K_max], Δk].
    Joint(JointArgs),
    /// The whole arm in a pose under a load: T0, tensions, K_q, K_W, C_x, K_x, K_fd, stability.
    ///
    /// T0 = T_g + J_xᵀ F0 (eq. 6), every joint's feasible tension interval and the tensions at
    /// the chosen levels, K_q, K_W = ∂T0/∂Q, J_x, then C_x = J_x (K_q + K_W)⁻¹ J_xᵀ and
    /// K_x = C_x⁻¹ (eq. 19), K_fd = K_x[0:3, 0:3] (rotations held) and K_t = (C_x[0:3, 0:3])⁻¹
    /// (rotations free), and the stiffness ellipsoid of K_fd. An unstable equilibrium
    /// (K_q + K_W not positive definite) is a result, exit 0: C_x, K_x and K_fd are then
    /// absent (null in JSON). An infeasible load is an error, exit 1.
    Arm(ArmArgs),
    /// A joint's stiffness range over a grid of its two angles (Fig. 5 maps).
    ///
    /// N × N points over the joint's angle limits (both axes), the other joints at 0: the
    /// minimum and maximum of K_x and of K_y (about the first and the second axis) over the
    /// feasible tensions at each point, empty
    /// (null in JSON) where the torque cannot be held.
    Sweep(SweepArgs),
    /// The tensions that optimise the end stiffness in a pose under a load, certified.
    ///
    /// Keeps static equilibrium exactly, every tension within its limits and the arm stable
    /// (smallest eigenvalue of K_q + K_W ≥ --margin), within an optional --budget on the total
    /// tension. The end stiffness is concave in the tensions (under gravity and a force, no
    /// moment), so the optimum is global; the answer carries a gap: the true optimum is at most
    /// `gap` better. Any cable set, both models.
    Plan(PlanArgs),
    /// Write a Sinew robot folder from another tool's model files.
    #[command(subcommand)]
    Import(ImportSource),
    /// Write the robot, its cables and chosen tensions in another tool's format.
    #[command(subcommand)]
    Export(ExportTarget),
}

/// The formats `sinew export` writes.
#[derive(Debug, Subcommand)]
pub enum ExportTarget {
    /// A MuJoCo model (MJCF) of the robot at the pose, its cables holding it with the tensions
    /// that `sinew arm` (--levels, --policy) or `sinew plan` (--plan OBJECTIVE) chooses.
    ///
    /// Springs (K_l and a spring length giving each tension at the pose) or motors (the
    /// tensions as ctrl, gear -1), optionally one spring per segment (--split segments). The
    /// load is not in the model: apply −F0 at site `tip`. Nothing is written on any error.
    Mjcf(MjcfArgs),
}

/// How the cables enter the MJCF model (`--cables`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CablesAs {
    /// Elastic tendons: the whole joint stiffness (controllable + inherent).
    Springs,
    /// Inextensible tendons pulled by motors: the controllable part alone.
    Motors,
}

/// `--split`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SplitAs {
    /// One spring tendon per segment between holes (the stick model; springs only).
    Segments,
}

/// `sinew export mjcf`.
#[derive(Debug, Args)]
pub struct MjcfArgs {
    #[command(flatten)]
    pub common: Common,
    /// The pose: one angle per revolute joint, base first (rad; degrees with --deg).
    #[arg(long, value_name = "Q1,...,Qd", allow_hyphen_values = true)]
    pub q: String,
    /// F0, the wrench the end-effector exerts, base frame: FX,FY,FZ,MX,MY,MZ (N, N m).
    /// Default zero.
    #[arg(long, value_name = "FX,FY,FZ,MX,MY,MZ", allow_hyphen_values = true)]
    pub wrench: Option<String>,
    #[command(flatten)]
    pub tensions: TensionArgs,
    /// Plan the tensions instead, as `sinew plan --objective OBJECTIVE` with the plan options.
    #[arg(long, value_enum, value_name = "OBJECTIVE", conflicts_with_all = ["levels", "policy"])]
    pub plan: Option<PlanObjective>,
    #[command(flatten)]
    pub options: PlanOptions,
    /// Cables as springs (default) or as motors.
    #[arg(long, value_enum, default_value_t = CablesAs::Springs)]
    pub cables: CablesAs,
    /// One spring tendon per segment between holes instead of one per cable.
    #[arg(long, value_enum)]
    pub split: Option<SplitAs>,
    /// Damping of every hinge, N m s/rad (default 1, near critical for cdhrm5).
    #[arg(long, value_name = "N·m·s/rad", allow_hyphen_values = true)]
    pub damping: Option<String>,
    /// Ignore gravity (zero gravity vector instead of robot.toml's, in the model too).
    #[arg(long)]
    pub no_gravity: bool,
    /// Read --q in degrees (the file is in radians).
    #[arg(long)]
    pub deg: bool,
    /// The MJCF file to write.
    #[arg(long, value_name = "FILE.xml")]
    pub out: PathBuf,
}

/// The tools `sinew import` reads.
#[derive(Debug, Subcommand)]
pub enum ImportSource {
    /// A CASPR model (bodies and cables XML, optionally operational spaces) as a robot folder:
    /// `<name>.urdf`, robot.toml, cables.toml (explicit holes).
    ///
    /// R_X/R_Y/R_Z links become one revolute joint, U_XY/U_XZ/U_YZ two (the second with zero
    /// translation, a massless cross link between). The folder is written beside --out and
    /// renamed into place, so nothing is written on failure; an existing non-empty --out is
    /// refused. Warnings go to standard error.
    Caspr(CasprArgs),
}

/// `sinew import caspr`.
#[derive(Debug, Args)]
pub struct CasprArgs {
    /// CASPR bodies file (`<bodies_system>`).
    #[arg(long, value_name = "FILE")]
    pub bodies: PathBuf,
    /// CASPR cables file (`<cables>`).
    #[arg(long, value_name = "FILE")]
    pub cables: PathBuf,
    /// CASPR operational spaces file: its default set's point is the tip (else the last
    /// link's end location).
    #[arg(long, value_name = "FILE")]
    pub operational_spaces: Option<PathBuf>,
    /// The cable set's id (default: the file's default_cable_set).
    #[arg(long, value_name = "ID")]
    pub cable_set: Option<String>,
    /// Young's modulus of the cables, Pa (default 200e9, steel).
    #[arg(long, value_name = "PA", allow_hyphen_values = true)]
    pub youngs_modulus: Option<String>,
    /// Cable diameter, m (default 1e-3).
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    pub diameter: Option<String>,
    /// Free length from the actuator to the first hole, m (default 0.5).
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    pub free_length: Option<String>,
    /// Tension limits of every cable, N, instead of the file's force_min/force_max.
    #[arg(long, value_name = "MIN,MAX", allow_hyphen_values = true)]
    pub tension_limits: Option<String>,
    /// The robot's name (URDF name and file name; default: the bodies file's name without
    /// `_bodies.xml`).
    #[arg(long, value_name = "NAME")]
    pub name: Option<String>,
    /// The robot folder to create (must not exist, or be empty).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// A tension policy (`--policy`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Policy {
    /// Least total tension Σ f (LP).
    LeastTotal,
    /// Least 2-norm |f| (QP).
    LeastNorm,
    /// Farthest from the limits: the greatest least distance of a tension to f_min or f_max.
    Safest,
}

impl Policy {
    /// The library's policy.
    pub fn tension_policy(self) -> sinew::statics::TensionPolicy {
        match self {
            Policy::LeastTotal => sinew::statics::TensionPolicy::LeastTotal,
            Policy::LeastNorm => sinew::statics::TensionPolicy::LeastNorm,
            Policy::Safest => sinew::statics::TensionPolicy::Safest,
        }
    }
}

/// Which routing file of the robot folder to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Model {
    /// `DIR/cables.toml`: each cable crosses only the joint it drives (the paper's model).
    Decoupled,
    /// `DIR/cables-routed.toml`: each cable also passes through every proximal disc.
    Routed,
}

impl Model {
    /// The routing file's name in a robot folder.
    pub fn file_name(self) -> &'static str {
        match self {
            Model::Decoupled => sinew::routing::ROUTING_FILE,
            Model::Routed => sinew::routing::ROUTED_ROUTING_FILE,
        }
    }

    /// The option value.
    pub fn name(self) -> &'static str {
        match self {
            Model::Decoupled => "decoupled",
            Model::Routed => "routed",
        }
    }
}

/// Options shared by every subcommand.
#[derive(Debug, Args)]
pub struct Common {
    /// Robot folder: robot.toml (URDF path, tip link, gravity), the URDF, cables.toml
    /// (decoupled routing) and cables-routed.toml (routed routing).
    #[arg(long, value_name = "DIR")]
    pub robot: PathBuf,
    /// Routing model: `decoupled` reads DIR/cables.toml, `routed` reads DIR/cables-routed.toml.
    #[arg(long, value_enum, default_value_t = Model::Decoupled)]
    pub model: Model,
    /// Print one JSON document (schema in docs/cli.md) instead of tables.
    #[arg(long)]
    pub json: bool,
}

/// `sinew routing`.
#[derive(Debug, Args)]
pub struct RoutingArgs {
    #[command(flatten)]
    pub common: Common,
}

/// `sinew joint`.
#[derive(Debug, Args)]
pub struct JointArgs {
    #[command(flatten)]
    pub common: Common,
    /// Universal joint, numbered from 1 at the base (the paper's numbering; JSON `joint` is
    /// 0-based). The other joints stay at 0 and their cables at zero tension.
    #[arg(long, value_name = "I", allow_hyphen_values = true)]
    pub joint: String,
    /// The joint's two angles, about its first then its second revolute joint (the URDF's
    /// order, any axes): Q1,Q2 (rad; degrees with --deg).
    #[arg(long, value_name = "Q1,Q2", allow_hyphen_values = true)]
    pub q: String,
    /// The torque the joint's three cables hold: T1,T2 (N m).
    #[arg(long, value_name = "T1,T2", allow_hyphen_values = true)]
    pub torque: String,
    /// Read --q in degrees (the output stays in radians).
    #[arg(long)]
    pub deg: bool,
}

/// `sinew arm`.
#[derive(Debug, Args)]
pub struct ArmArgs {
    #[command(flatten)]
    pub common: Common,
    /// The pose: one angle per revolute joint, base first, the first then the second axis of
    /// each universal joint (rad; degrees with --deg).
    #[arg(long, value_name = "Q1,...,Q2n", allow_hyphen_values = true)]
    pub q: String,
    /// F0, the wrench the end-effector exerts on its environment, base frame:
    /// FX,FY,FZ,MX,MY,MZ (N, N m). Default zero.
    #[arg(long, value_name = "FX,FY,FZ,MX,MY,MZ", allow_hyphen_values = true)]
    pub wrench: Option<String>,
    #[command(flatten)]
    pub tensions: TensionArgs,
    /// Ignore gravity (zero gravity vector instead of robot.toml's).
    #[arg(long)]
    pub no_gravity: bool,
    /// Read --q in degrees (the output stays in radians).
    #[arg(long)]
    pub deg: bool,
    #[command(flatten)]
    pub friction: FrictionArgs,
}

/// How `sinew arm` and `sinew export mjcf` choose the tensions: levels or a policy.
#[derive(Debug, Args)]
pub struct TensionArgs {
    /// Tension level of each joint in [0, 1] along its feasible interval (0: least total
    /// tension, 1: most), S1,...,Sn base first: the paper's closed form, for three cables per
    /// universal joint. Default all 0 where it applies, else `--policy least-total`.
    #[arg(long, value_name = "S1,...,Sn", allow_hyphen_values = true, conflicts_with = "policy")]
    pub levels: Option<String>,
    /// Choose the tensions by a policy over every tension vector that balances the load (any
    /// cable set): least total tension, least 2-norm, or farthest from the limits.
    #[arg(long, value_enum)]
    pub policy: Option<Policy>,
}

/// What a plan requires beyond its objective (`sinew plan`, `sinew export mjcf --plan`).
#[derive(Debug, Args)]
pub struct PlanOptions {
    /// The direction of stiffness-along and compliance-along: UX,UY,UZ (base frame, any
    /// non-zero length: it is normalised).
    #[arg(long, value_name = "UX,UY,UZ", allow_hyphen_values = true)]
    pub direction: Option<String>,
    /// Require the smallest eigenvalue of K_fd to be at least this (N/m).
    #[arg(long, value_name = "N/m", allow_hyphen_values = true)]
    pub k_min: Option<String>,
    /// Require K_fd ⪰ K_des: nine numbers, row by row, symmetric positive definite (N/m).
    #[arg(long, value_name = "K11,...,K33", allow_hyphen_values = true)]
    pub k_des: Option<String>,
    /// Stability margin: smallest eigenvalue of K_q + K_W at least this (N m/rad, > 0).
    #[arg(long, value_name = "N·m/rad", allow_hyphen_values = true)]
    pub margin: Option<String>,
    /// Total tension at most this (N).
    #[arg(long, value_name = "N", allow_hyphen_values = true)]
    pub budget: Option<String>,
    /// The tensions of joint J's own cables sum to at most N (joints numbered from 1);
    /// repeat for several joints.
    #[arg(long, value_name = "J:N", allow_hyphen_values = true)]
    pub joint_budget: Vec<String>,
    /// Hold joint J at tension level S in [0, 1] (joints numbered from 1; the paper's levels,
    /// decoupled model); repeatable.
    #[arg(long, value_name = "J:S", allow_hyphen_values = true)]
    pub fixed_level: Vec<String>,
    /// Stop when the certified gap is at most this fraction of the value (default 1e-6).
    #[arg(long, value_name = "REL", allow_hyphen_values = true)]
    pub gap: Option<String>,
}

/// What `sinew plan` optimises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum PlanObjective {
    /// Maximise u·K_fd·u, the stiffness along --direction with the end's rotation held (N/m).
    StiffnessAlong,
    /// Minimise u·C_x·u, the compliance along --direction with rotations free (m/N).
    ComplianceAlong,
    /// Maximise the smallest eigenvalue of K_fd: the softest direction (N/m).
    MinStiffness,
    /// Maximise log det K_fd: the smallest deformation ellipsoid.
    Volume,
    /// Minimise the total tension (N) subject to --k-min, --k-des and --margin.
    LeastTension,
}

/// `sinew plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    #[command(flatten)]
    pub common: Common,
    /// The pose: one angle per revolute joint, base first (rad; degrees with --deg).
    #[arg(
        long,
        value_name = "Q1,...,Qd",
        allow_hyphen_values = true,
        required_unless_present = "trajectory"
    )]
    pub q: Option<String>,
    /// F0, the wrench the end-effector exerts, base frame: FX,FY,FZ,MX,MY,MZ (N, N m). The
    /// moment must be zero. Default zero.
    #[arg(long, value_name = "FX,FY,FZ,MX,MY,MZ", allow_hyphen_values = true)]
    pub wrench: Option<String>,
    /// Plan along a trajectory instead of at --q: a CSV file, one row per step, the angles
    /// then optionally the six F0 components (else --wrench for every step); `#` comments and
    /// a header line allowed. Each step is warm-started from the one before; the rows come out
    /// as CSV (or JSON with --json).
    #[arg(long, value_name = "FILE.csv", conflicts_with = "q")]
    pub trajectory: Option<PathBuf>,
    /// Along a trajectory: the largest rate of change of any cable's tension (N/s), with --dt.
    #[arg(long, value_name = "N/s", allow_hyphen_values = true, requires_all = ["trajectory", "dt"])]
    pub rate: Option<String>,
    /// Along a trajectory: the time between two steps (s), with --rate.
    #[arg(long, value_name = "s", allow_hyphen_values = true, requires_all = ["trajectory", "rate"])]
    pub dt: Option<String>,
    /// What to optimise.
    #[arg(long, value_enum)]
    pub objective: PlanObjective,
    #[command(flatten)]
    pub options: PlanOptions,
    #[command(flatten)]
    pub friction: PlanFrictionArgs,
    /// Ignore gravity (zero gravity vector instead of robot.toml's).
    #[arg(long)]
    pub no_gravity: bool,
    /// Read --q in degrees (the output stays in radians).
    #[arg(long)]
    pub deg: bool,
}

/// `sinew sweep`.
#[derive(Debug, Args)]
pub struct SweepArgs {
    #[command(flatten)]
    pub common: Common,
    /// Universal joint, numbered from 1 at the base (JSON `joint` is 0-based). The other
    /// joints stay at 0.
    #[arg(long, value_name = "I", allow_hyphen_values = true)]
    pub joint: String,
    /// The torque the joint's three cables hold: T1,T2 (N m).
    #[arg(long, value_name = "T1,T2", allow_hyphen_values = true)]
    pub torque: String,
    /// Grid points per axis (2 to 1001: time and output grow as N²) over the joint's angle
    /// limits.
    #[arg(long, value_name = "N", allow_hyphen_values = true)]
    pub grid: String,
    /// Write the maps as CSV (q1_rad,q2_rad,k_x_min,k_x_max,k_y_min,k_y_max; empty fields
    /// where infeasible) to FILE; the tables are then replaced by a summary.
    #[arg(long, value_name = "FILE.csv")]
    pub out: Option<PathBuf>,
    /// Friction at the holes (spec §9): the regime's statics (actuator tensions) and joint
    /// stiffness.
    #[command(flatten)]
    pub friction: RegimeArgs,
}
