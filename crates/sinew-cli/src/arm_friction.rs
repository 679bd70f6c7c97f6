//! `sinew arm` with friction at the holes (spec §9, #27): the regime's tensions along every
//! cable, the dead band, `K_q`, `C_x`, `K_x` and `K_fd` of the regime, and in the stick regime
//! the directional response along ±u and the stick load limits. With μ = 0 everywhere (and no
//! stick asked for) `sinew arm` takes the frictionless path instead, unchanged.

use nalgebra::Vector6;
use serde::Serialize;
use sinew::routing::{FrictionModel, Routing, Slip, compute_wrap_gradients};
use sinew::stiffness::{
    ArmStiffness, ArmStiffnessData, BandEdge, DirectionalResponse, EndOutcome, FrictionArmData,
    FrictionRegime, History, HoleEvent, StickLoadLimit, base_directions, directional_response,
    stick_load_limits,
};

use crate::cli::ArmArgs;
use crate::error::{CliError, library_error};
use crate::friction_args::{FrictionArgs, HistoryArg, Regime};
use crate::input::{Loaded, levels, numbers_n, pose, tension_choice, wrench};
use crate::output::{
    Fmt, Rows, Table, cartesian_labels, emit, faer_rows, matrix, na_rows, print_json, q_labels,
};

/// The friction model and regime the options and the routing file ask for; `None` for the
/// frictionless path (every μ = 0 and neither `--regime stick` nor `--history` given).
///
/// # Errors
/// A negative or non-finite `--friction`; `--history` with a slip regime; the stick regime
/// asked for at μ = 0.
pub fn requested(
    (friction, regime, history): (Option<f64>, Option<Regime>, Option<HistoryArg>),
    routing: &Routing,
) -> Result<Option<(FrictionModel, FrictionRegime)>, CliError> {
    let mut model = FrictionModel::new(routing);
    if let Some(mu) = friction {
        model = model
            .with_friction_coefficient(mu)
            .map_err(|e| CliError::input(format!("--friction: {e}")))?;
    }
    let history_asked = history.is_some();
    let history = match history {
        None | Some(HistoryArg::Pull) => History::Pull,
        Some(HistoryArg::Release) => History::Release,
        Some(HistoryArg::Equal) => History::Equal,
    };
    let stick_asked = regime == Some(Regime::Stick) || history_asked;
    let regime = match regime {
        Some(Regime::Pull) | Some(Regime::Release) if history_asked => {
            return Err(CliError::input("--history: applies to --regime stick only"));
        }
        Some(Regime::Pull) => FrictionRegime::Slip(Slip::Pull),
        Some(Regime::Release) => FrictionRegime::Slip(Slip::Release),
        Some(Regime::Stick) | None => FrictionRegime::Stick(history),
    };
    let frictionless = model.friction_coefficients().iter().all(|&mu| mu == 0.0);
    match (frictionless, stick_asked) {
        (true, false) => Ok(None),
        (true, true) => Err(CliError::input(
            "--regime stick: every cable has μ = 0 (no band to stick in); give --friction MU > 0",
        )),
        (false, _) => Ok(Some((model, regime))),
    }
}

/// The JSON document of `sinew arm` with friction.
#[derive(Debug, Serialize)]
struct ArmFrictionOut {
    command: &'static str,
    robot: String,
    routing_file: String,
    model: &'static str,
    gravity: [f64; 3],
    q: Vec<f64>,
    wrench: Vec<f64>,
    friction: FrictionOut,
    cables: Vec<String>,
    t0: Vec<f64>,
    /// The actuator tensions, N.
    tensions: Vec<f64>,
    segments: Vec<SegmentsOut>,
    /// Per cable, `[T₀^release, T₀^pull]`, N.
    dead_band: Vec<[f64; 2]>,
    k_q: Rows,
    /// Frobenius norm of `K_q`'s skew part (0 in the stick regime).
    k_q_skew_norm: f64,
    k_w: Rows,
    j_x: Rows,
    stable: bool,
    min_eigenvalue: f64,
    c_x: Option<Rows>,
    k_x: Option<Rows>,
    k_fd: Option<Rows>,
    directional: Option<DirectionalOut>,
    stick_load_limit: Option<Vec<LimitOut>>,
    notes: Vec<String>,
}

/// `friction` of `sinew arm` and `sinew sweep`: μ per cable, the regime and its history.
#[derive(Debug, Serialize)]
pub struct FrictionOut {
    /// Per cable.
    pub mu: Vec<f64>,
    /// `pull`, `release` or `stick`.
    pub regime: &'static str,
    /// The stick regime's history (null in a slip regime).
    pub history: Option<&'static str>,
}

impl FrictionOut {
    /// The document's `friction` for `model` in `regime`.
    pub fn new(model: &FrictionModel, regime: FrictionRegime) -> FrictionOut {
        let (regime, history) = match regime {
            FrictionRegime::Slip(Slip::Pull) => ("pull", None),
            FrictionRegime::Slip(Slip::Release) => ("release", None),
            FrictionRegime::Stick(history) => ("stick", Some(history_name(history))),
        };
        FrictionOut { mu: model.friction_coefficients().to_vec(), regime, history }
    }

    /// One line of text: `regime stick (history: pull), μ = …`.
    pub fn describe(&self) -> String {
        format!(
            "regime {}{}, μ = {}",
            self.regime,
            self.history.map(|h| format!(" (history: {h})")).unwrap_or_default(),
            Fmt::Fixed(3).list(&self.mu)
        )
    }
}

#[derive(Debug, Serialize)]
struct SegmentsOut {
    cable: String,
    /// From the actuator (the free length) to the anchor, N.
    tensions: Vec<f64>,
    /// At every hole but the anchor, rad.
    wrap_angles: Vec<f64>,
    /// The free length, then every segment, m.
    lengths: Vec<f64>,
}

#[derive(Debug, Serialize)]
struct HoleOut {
    cable: String,
    /// 0-based from the actuator.
    hole: usize,
    edge: &'static str,
    kinked: bool,
}

#[derive(Debug, Serialize)]
struct ResponseOut {
    /// `uᵀ δx` per newton along u, m/N.
    compliance: f64,
    /// N/m.
    stiffness: f64,
    sliding: Vec<HoleOut>,
}

#[derive(Debug, Serialize)]
struct DirectionalOut {
    /// The unit force direction u (base frame).
    direction: [f64; 3],
    plus: ResponseOut,
    minus: ResponseOut,
}

#[derive(Debug, Serialize)]
struct LimitOut {
    /// The wrench direction (force, moment).
    direction: [f64; 6],
    /// N (N m for a moment); null when no hole ever reaches an edge.
    magnitude: Option<f64>,
    /// The hole that reaches an edge first.
    first: Option<HoleOut>,
    /// Holes pushed over their edge at once (magnitude 0).
    at_once: Vec<HoleOut>,
}

fn hole_out(e: &HoleEvent, routing: &Routing) -> HoleOut {
    HoleOut {
        cable: routing.cables()[e.cable].name.clone(),
        hole: e.hole,
        edge: match e.edge {
            BandEdge::Lower => "lower",
            BandEdge::Upper => "upper",
        },
        kinked: e.kinked,
    }
}

fn response_out(r: &DirectionalResponse, routing: &Routing) -> ResponseOut {
    ResponseOut {
        compliance: r.compliance,
        stiffness: r.stiffness,
        sliding: r.sliding.iter().map(|e| hole_out(e, routing)).collect(),
    }
}

fn limit_out(l: &StickLoadLimit, routing: &Routing) -> LimitOut {
    LimitOut {
        direction: l.direction.into(),
        magnitude: l.magnitude.is_finite().then_some(l.magnitude),
        first: l.first.as_ref().map(|e| hole_out(e, routing)),
        at_once: l.at_once.iter().map(|e| hole_out(e, routing)).collect(),
    }
}

/// The unit force direction of the directional response: `--direction`, else the force of
/// the load; `None` when neither gives one.
fn direction(args: &FrictionArgs, wrench: &[f64]) -> Result<Option<Vector6<f64>>, CliError> {
    let u = match &args.direction {
        Some(text) => {
            let u = numbers_n("--direction", text, 3, "a force direction UX,UY,UZ")?;
            let norm = u.iter().map(|x| x * x).sum::<f64>().sqrt();
            if !(norm > 0.0 && norm.is_finite()) {
                return Err(CliError::input("--direction: a zero or non-finite direction"));
            }
            [u[0] / norm, u[1] / norm, u[2] / norm]
        }
        None => {
            let norm = wrench[..3].iter().map(|x| x * x).sum::<f64>().sqrt();
            if norm == 0.0 {
                return Ok(None);
            }
            [wrench[0] / norm, wrench[1] / norm, wrench[2] / norm]
        }
    };
    Ok(Some(Vector6::new(u[0], u[1], u[2], 0.0, 0.0, 0.0)))
}

/// Run `sinew arm` with friction.
pub fn run(
    args: &ArmArgs,
    loaded: &Loaded,
    (model, regime): (FrictionModel, FrictionRegime),
) -> Result<(), CliError> {
    let (robot, routing) = (&loaded.robot, &loaded.routing);
    let q = pose(&args.q, args.deg, robot)?;
    let wrench = wrench(args.wrench.as_deref())?;
    let u = direction(&args.friction, &wrench)?;
    let history = match regime {
        FrictionRegime::Stick(history) => Some(history),
        FrictionRegime::Slip(_) => None,
    };
    if history.is_some() && u.is_none() {
        return Err(CliError::input(
            "--direction: required in the stick regime when --wrench has no force (the directional response's direction)",
        ));
    }
    let arm = ArmStiffness::new(robot, routing).map_err(library_error)?.checking_limits();
    let mut data = ArmStiffnessData::new(&arm);
    let mut out = FrictionArmData::new(&arm, &model);
    let f0 = Vector6::from_column_slice(&wrench);
    let levels = levels(&args.tensions, robot.joint_count())?;
    let choice = tension_choice(levels.as_deref(), &args.tensions);
    let outcome = arm
        .evaluate_with_friction(&mut data, &mut out, (&model, regime), &q, &f0, choice)
        .map_err(library_error)?;
    let mut notes = Vec::new();
    let k_q = out.stiffness.stiffness().map_err(library_error)?.to_owned();
    let k_w = data.k_w().to_owned();
    let j_x = data.j_x().to_owned();
    let stable = !matches!(outcome, EndOutcome::Unstable { .. });
    let (mut directional, mut limits) = (None, None);
    match (history, u) {
        (Some(history), Some(u)) if stable => {
            let increment = (k_q.as_ref(), k_w.as_ref(), j_x.as_ref());
            compute_wrap_gradients(&model, &mut out.friction).map_err(library_error)?;
            let (f, t) = (&out.friction, &out.actuator);
            let [plus, minus] = directional_response(&model, routing, f, history, t, increment, &u)
                .map_err(library_error)?;
            directional = Some(DirectionalOut {
                direction: [u[0], u[1], u[2]],
                plus: response_out(&plus, routing),
                minus: response_out(&minus, routing),
            });
            let mut directions = base_directions().to_vec();
            directions.extend([u, -u]);
            let found = stick_load_limits(&model, routing, f, history, t, increment, &directions)
                .map_err(library_error)?;
            limits = Some(found.iter().map(|l| limit_out(l, routing)).collect());
        }
        (Some(_), _) => notes.push("unstable: no directional response or stick load limit".to_owned()),
        (None, _) => notes.push(
            "slip regime: K_q is the stiffness for motions that keep every hole sliding the same way (not symmetric: see k_q_skew_norm)".to_owned(),
        ),
    }
    let segments = (0..routing.cable_count())
        .map(|c| -> Result<SegmentsOut, CliError> {
            Ok(SegmentsOut {
                cable: routing.cables()[c].name.clone(),
                tensions: out.segments[c].clone(),
                wrap_angles: out.friction.wrap_angles(&model, c).map_err(library_error)?.to_vec(),
                lengths: out.friction.lengths(&model, c).map_err(library_error)?.to_vec(),
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let full_rank = matches!(outcome, EndOutcome::Stiff);
    let g = robot.gravity();
    let doc = ArmFrictionOut {
        command: "arm",
        robot: robot.name().to_owned(),
        routing_file: loaded.routing_file.display().to_string(),
        model: args.common.model.name(),
        gravity: [g.x, g.y, g.z],
        q,
        wrench,
        friction: FrictionOut::new(&model, regime),
        cables: routing.cables().iter().map(|c| c.name.clone()).collect(),
        t0: data.statics.t0.clone(),
        tensions: out.actuator.clone(),
        segments,
        dead_band: out.dead_band.clone(),
        k_q: faer_rows(k_q.as_ref()),
        k_q_skew_norm: out.stiffness.skew_norm().map_err(library_error)?,
        k_w: faer_rows(k_w.as_ref()),
        j_x: faer_rows(j_x.as_ref()),
        stable,
        min_eigenvalue: out.stability_margin(&mut data).map_err(library_error)?,
        c_x: stable.then(|| faer_rows(out.end.compliance())),
        k_x: full_rank.then(|| faer_rows(out.end.stiffness())),
        k_fd: full_rank.then(|| na_rows(&out.end.k_fd())),
        directional,
        stick_load_limit: limits,
        notes,
    };
    if args.common.json { print_json(&doc) } else { emit(&render(&doc, routing)) }
}

fn render(out: &ArmFrictionOut, routing: &Routing) -> String {
    let mut s = format!(
        "arm `{}` ({}: {}) with friction: {}\n",
        out.robot,
        out.model,
        out.routing_file,
        out.friction.describe(),
    );
    s.push_str(&format!("  Q  = {} rad\n", Fmt::Fixed(5).list(&out.q)));
    s.push_str(&format!("  F0 = {} (N, N m)\n\n", Fmt::Fixed(4).list(&out.wrench)));
    s.push_str("Cables: actuator tension, at the anchor, dead band of the anchor tension (N):\n");
    let mut t = Table::new(&["cable", "actuator", "anchor", "band low", "band high"]).left(&[0]);
    for (c, seg) in out.segments.iter().enumerate() {
        t.row(vec![
            seg.cable.clone(),
            Fmt::Fixed(3).num(out.tensions[c]),
            Fmt::Fixed(3).num(seg.tensions.last().copied().unwrap_or(f64::NAN)),
            Fmt::Fixed(3).num(out.dead_band[c][0]),
            Fmt::Fixed(3).num(out.dead_band[c][1]),
        ]);
    }
    s.push_str(&t.render(2));
    let (ql, cl) = (q_labels(routing.joint_groups()), cartesian_labels());
    s.push('\n');
    s.push_str(&matrix("K_q of the regime (N m/rad):", &out.k_q, Fmt::Fixed(4), &ql, &ql));
    s.push_str(&format!(
        "\nStability: {}, smallest eigenvalue of the symmetric part of K_q + K_W = {} N m/rad\n\n",
        if out.stable { "STABLE" } else { "UNSTABLE" },
        Fmt::Fixed(6).num(out.min_eigenvalue)
    ));
    if let Some(c_x) = &out.c_x {
        s.push_str(&matrix("C_x (m/N, rad/(N m)):", c_x, Fmt::Sci(4), &cl, &cl));
        s.push('\n');
    }
    if let Some(k_fd) = &out.k_fd {
        let xyz = &cl[..3];
        s.push_str(&matrix("K_fd = K_x[0:3, 0:3] (N/m):", k_fd, Fmt::Fixed(3), xyz, xyz));
        s.push('\n');
    }
    if let Some(d) = &out.directional {
        s.push_str(&format!(
            "Directional response along u = {}:\n",
            Fmt::Fixed(4).list(&d.direction)
        ));
        for (sign, r) in [("+u", &d.plus), ("−u", &d.minus)] {
            s.push_str(&format!(
                "  {sign}: {} N/m ({} m/N), {} holes slide\n",
                Fmt::Fixed(3).num(r.stiffness),
                Fmt::Sci(4).num(r.compliance),
                r.sliding.len()
            ));
        }
        s.push('\n');
    }
    if let Some(limits) = &out.stick_load_limit {
        s.push_str("Stick load limits (the wrench increment before a hole slides):\n");
        let mut t = Table::new(&["direction", "limit", "first hole"]).left(&[0, 2]);
        for l in limits {
            let first =
                l.first.as_ref().map(|h| format!("{} hole {} ({})", h.cable, h.hole, h.edge));
            let magnitude = l.magnitude.map_or_else(|| "none".to_owned(), |m| Fmt::Sci(3).num(m));
            let note = if l.at_once.is_empty() {
                String::new()
            } else {
                format!(", {} at once", l.at_once.len())
            };
            t.row(vec![
                Fmt::Fixed(2).list(&l.direction),
                magnitude,
                first.unwrap_or_default() + &note,
            ]);
        }
        s.push_str(&t.render(2));
    }
    for note in &out.notes {
        s.push_str(&format!("note: {note}\n"));
    }
    s
}

/// `--history`'s word for a history.
pub fn history_name(history: History) -> &'static str {
    match history {
        History::Pull => "pull",
        History::Release => "release",
        History::Equal => "equal",
    }
}
