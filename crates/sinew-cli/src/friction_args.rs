//! The friction options (spec §9, clap derive): `--friction`, `--regime`, `--history` of `sinew
//! arm` and `sinew sweep`, with `--direction` for `sinew arm`; and those of `sinew plan` (the
//! same three, stick only: its `--direction` is the objective's).

use clap::{Args, ValueEnum};

/// Friction at the holes (spec §9): `--friction`, `--regime`, `--history`, shared by `sinew
/// arm` and `sinew sweep`. Used when the routing file or `--friction` gives some cable μ > 0;
/// with μ = 0 everywhere the frictionless model, exactly.
#[derive(Debug, Args)]
pub struct RegimeArgs {
    /// The friction coefficient μ ≥ 0 of every cable at every hole (overrides the routing
    /// file's).
    #[arg(long, value_name = "MU", allow_hyphen_values = true)]
    pub friction: Option<f64>,
    /// The regime: every hole sliding toward the actuator (pull) or away from it (release), or
    /// no hole sliding (stick, the default).
    #[arg(long, value_enum)]
    pub regime: Option<Regime>,
    /// How the tensions of a sticking cable were left: by a pull (the default), a release, or
    /// equal along each cable.
    #[arg(long, value_enum)]
    pub history: Option<HistoryArg>,
}

impl RegimeArgs {
    /// μ, the regime and the history asked for.
    pub fn asked(&self) -> (Option<f64>, Option<Regime>, Option<HistoryArg>) {
        (self.friction, self.regime, self.history)
    }
}

/// The friction options of `sinew arm` (spec §9): [`RegimeArgs`] and the direction of the
/// directional response.
#[derive(Debug, Args)]
pub struct FrictionArgs {
    /// `--friction`, `--regime`, `--history`.
    #[command(flatten)]
    pub regime: RegimeArgs,
    /// The force direction of the directional response and of one more stick load limit:
    /// UX,UY,UZ (base frame, any non-zero length). Default: the force part of --wrench.
    #[arg(long, value_name = "UX,UY,UZ", allow_hyphen_values = true)]
    pub direction: Option<String>,
}

impl FrictionArgs {
    /// μ, the regime and the history asked for.
    pub fn asked(&self) -> (Option<f64>, Option<Regime>, Option<HistoryArg>) {
        self.regime.asked()
    }
}

/// Friction at the holes for `sinew plan` (spec §9): a plan in the stick regime after a
/// history. Used when the routing file or `--friction` gives some cable μ > 0.
#[derive(Debug, Args)]
pub struct PlanFrictionArgs {
    /// The friction coefficient μ ≥ 0 of every cable at every hole (overrides the routing
    /// file's).
    #[arg(long, value_name = "MU", allow_hyphen_values = true)]
    pub friction: Option<f64>,
    /// The regime: stick (no hole slides; the default with friction). The slip regimes (pull,
    /// release) are refused: their stiffness is not symmetric and the end stiffness not
    /// concave in the tensions.
    #[arg(long, value_enum)]
    pub regime: Option<Regime>,
    /// How the tensions of a sticking cable were left: by a pull (the default), a release, or
    /// equal along each cable.
    #[arg(long, value_enum)]
    pub history: Option<HistoryArg>,
}

impl PlanFrictionArgs {
    /// μ, the regime and the history asked for.
    pub fn asked(&self) -> (Option<f64>, Option<Regime>, Option<HistoryArg>) {
        (self.friction, self.regime, self.history)
    }
}

/// `--regime`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Regime {
    /// Every hole slides toward the actuator.
    Pull,
    /// Every hole slides away from the actuator.
    Release,
    /// No hole slides.
    Stick,
}

/// `--history`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum HistoryArg {
    /// Last pulled in: every hole on the lower edge of its band.
    Pull,
    /// Last released: every hole on the upper edge.
    Release,
    /// Equal tensions along each cable.
    Equal,
}
