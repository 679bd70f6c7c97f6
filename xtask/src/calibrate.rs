//! `cargo xtask calibrate [--check]`: fit the single-joint geometry that the paper does not state
//! to the 20 numbers of its Table II (spec §7), and write it into `robots/cdhrm5`.
//!
//! # The model
//! One universal joint of the platform (eq. 1) with its three cables in the paper's decoupled
//! model, computed by the library as the report computes it ([`sinew::paper::table_2`], through
//! [`sinew::indicators::JointProbe`], the paper's single-joint model): at the five angles of
//! Table II, holding `τ = [0.3, 0.3]` N m with tensions in `[20, 600]` N, the range of `K_x` and
//! of `K_y` over the feasible tensions. The residuals are the 20 relative errors
//! `(ours − paper) / paper`; a parameter set for which a configuration's torque cannot be held
//! (an empty tension interval, lost force closure), or whose geometry the library rejects,
//! costs [`INFEASIBLE_RESIDUAL`] on each of the 20 entries instead: a large residual, no panic.
//!
//! # The parameters
//! | parameter | bounds | why |
//! | --- | --- | --- |
//! | hole radius ρ (one for both discs) | [5, 27] mm | inside the φ60 mm link, ≥ 3 mm from the rim |
//! | θ0, the angle of cable 1 | free, reported modulo 120° | three cables 120° apart |
//! | d1, with d2 = 30 mm − d1 | 0 ≤ d1, d2 | the 30 mm gap between the discs is kept; no disc beyond the joint centre |
//! | k = E·A/l_c of joint 1's cables | [200, 50 000] N/m (fitted in log k) | positive; l_c between 0.2 m and 49 m |
//!
//! Why these and not more: the report prints refits with the gap free, with a radius per disc,
//! and with d2 < 0 allowed. The first two barely move the RMS (the data do not constrain them);
//! the third leaves the physical bounds (see robots/cdhrm5/README.md).
//!
//! # The solver
//! Levenberg–Marquardt (crate `levenberg-marquardt`) on unbounded variables `u`, each bounded
//! parameter mapped as `p = lo + (hi − lo)(1 + sin u)/2` (MINUIT's transform), the Jacobian by
//! central differences in `u`. The problem is not convex: the fit starts from a fixed grid of
//! [`start_points`] and keeps the best. Deterministic; a few seconds in a debug build.

use std::f64::consts::{FRAC_PI_3, PI, TAU};
use std::path::Path;

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra_lm::{DMatrix, DVector, Dyn, Owned};
use sinew::paper::{Table2Row, render_table_2, table_2_patterns};
use sinew::robot::UniformChain;
use sinew::routing::{PatternModel, PerJoint, Routing, RoutingSpec};
use sinew_testkit::cdhrm5;

use crate::DynResult;

/// The relative error charged to each entry of a configuration that cannot hold the torque.
const INFEASIBLE_RESIDUAL: f64 = 10.0;
/// Gap between the two discs of a joint, d1 + d2, m (kept; see the module doc).
const GAP: f64 = 0.03;
/// Link length, m (Table I), for the free lengths of the distal joints.
const LINK: f64 = 0.22;
/// Hole radius bounds, m: inside the φ60 mm link with 3 mm to the rim.
const RADIUS_BOUNDS: [f64; 2] = [0.005, 0.027];
/// Cable stiffness bounds, N/m.
const STIFFNESS_BOUNDS: [f64; 2] = [200.0, 50_000.0];
/// Joint-centre offsets when the gap is free (a variant), m.
const OFFSET_BOUNDS: [f64; 2] = [0.0, 0.06];
/// `cargo xtask calibrate --check` tolerances: lengths (m), θ0 (rad), relative k.
const CHECK_LENGTH: f64 = 5e-5;
const CHECK_ANGLE: f64 = 1e-3;
const CHECK_STIFFNESS: f64 = 1e-3;

/// The single-joint geometry: everything the fit can change.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    /// Hole radius on the proximal disc, m.
    pub rho_p: f64,
    /// Hole radius on the distal disc, m.
    pub rho_d: f64,
    /// Angle of cable 1 of joint 1, rad.
    pub theta0: f64,
    /// Proximal disc to the joint centre, m (eq. 1).
    pub d1: f64,
    /// Joint centre to the distal disc, m (eq. 1).
    pub d2: f64,
    /// `k = E·A/l_c` of joint 1's cables, N/m.
    pub stiffness: f64,
}

impl Geometry {
    /// θ0 reduced to `[−60°, 60°)`: the three cables are 120° apart.
    fn reduced(self) -> Geometry {
        let period = TAU / 3.0;
        let theta0 = (self.theta0 + FRAC_PI_3).rem_euclid(period) - FRAC_PI_3;
        Geometry { theta0, ..self }
    }

    /// Routed length of a joint-1 cable at Q = 0, m: its crossing of the joint.
    fn crossing(&self) -> f64 {
        ((self.rho_d - self.rho_p).powi(2) + (self.d1 + self.d2).powi(2)).sqrt()
    }

    /// The free length that gives joint 1's cables the stiffness `k`: `E·A/k − crossing`, m.
    fn free_length(&self, ea: f64) -> f64 {
        ea / self.stiffness - self.crossing()
    }

    /// The values as written into the robot files: lengths to 0.01 mm, θ0 to 1e-5 rad, and the
    /// stiffness that the free length rounded to 0.1 mm gives.
    fn rounded(self, ea: f64) -> Geometry {
        // Through the decimal text, so that 0.03 stays 0.03 (not 0.030000000000000002).
        let round = |x: f64, decimals: usize| {
            let r = format!("{x:.decimals$}").parse::<f64>().unwrap_or(x);
            if r == 0.0 { 0.0 } else { r }
        };
        let mut g = Geometry {
            rho_p: round(self.rho_p, 5),
            rho_d: round(self.rho_d, 5),
            theta0: round(self.theta0, 5),
            d1: round(self.d1, 5),
            d2: round(self.d2, 5),
            ..self
        };
        let free = round(self.free_length(ea), 4);
        g.stiffness = ea / (free + g.crossing());
        g
    }
}

/// `E·A` of the cdhrm5 cables (Table I's E = 12.5 GPa, a 1 mm cable as the files say), N.
fn ea() -> f64 {
    cdhrm5::YOUNGS_MODULUS * PI * 0.25 * cdhrm5::DIAMETER.powi(2)
}

/// A chain of `joints` cdhrm5 joints with the geometry's d1, d2.
fn chain(g: &Geometry, joints: usize) -> UniformChain {
    UniformChain { d1: g.d1, d2: g.d2, ..cdhrm5::uniform_chain(joints) }
}

/// Table II (the same computation as the report's, [`sinew::paper::table_2`]) of a one-joint
/// chain with geometry `g`.
fn table(g: &Geometry) -> DynResult<Vec<Table2Row>> {
    let chain = chain(g, 1);
    let robot = chain.build()?;
    let mut spec = cdhrm5::chain_routing_spec(&chain, PatternModel::Decoupled);
    spec.free_length = Some(PerJoint::Uniform(g.free_length(ea())));
    if let Some(pattern) = spec.pattern.as_mut() {
        pattern.radius = None;
        pattern.proximal_radius = Some(PerJoint::Uniform(g.rho_p));
        pattern.distal_radius = Some(PerJoint::Uniform(g.rho_d));
        pattern.theta0 = g.theta0;
    }
    let routing = Routing::new(&robot, &spec, "<calibration>")?;
    Ok(sinew::paper::table_2(&robot, &routing)?)
}

/// The 20 relative errors, row by row: K_x min, K_x max, K_y min, K_y max.
fn relative_errors(rows: &[Table2Row]) -> Vec<f64> {
    rows.iter().flat_map(Table2Row::relative_errors).collect()
}

fn residuals(g: &Geometry) -> Vec<f64> {
    match table(g) {
        Ok(rows) => relative_errors(&rows),
        Err(_) => vec![INFEASIBLE_RESIDUAL; 20],
    }
}

fn rms(r: &[f64]) -> f64 {
    (r.iter().map(|x| x * x).sum::<f64>() / r.len().max(1) as f64).sqrt()
}

/// Which parameters a fit frees, and how.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Setup {
    name: &'static str,
    /// One radius per disc instead of one for both.
    separate_radii: bool,
    /// `Some(gap)`: d2 = gap − d1; `None`: d1 and d2 both free.
    gap: Option<f64>,
    /// Least d2 (m) when the gap is free.
    d2_min: f64,
}

/// The fit written into the robot files.
const MAIN: Setup = Setup {
    name: "ρ, θ0, d1 (d2 = 30 mm − d1), k",
    separate_radii: false,
    gap: Some(GAP),
    d2_min: 0.0,
};

/// Refits that show what the data constrain (printed, never written).
const VARIANTS: [Setup; 3] = [
    Setup { name: "gap free: d1, d2 ≥ 0 each", separate_radii: false, gap: None, d2_min: 0.0 },
    Setup { name: "a radius per disc", separate_radii: true, gap: Some(GAP), d2_min: 0.0 },
    Setup {
        name: "radius per disc, gap free, d2 ≥ −10 mm",
        separate_radii: true,
        gap: None,
        d2_min: -0.01,
    },
];

/// A bounded parameter of a setup: `[lo, hi]`, infinite for θ0.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Param {
    Radius,
    RadiusP,
    RadiusD,
    Theta0,
    D1,
    D2,
    LogStiffness,
}

impl Setup {
    fn params(&self) -> Vec<Param> {
        let mut p = if self.separate_radii {
            vec![Param::RadiusP, Param::RadiusD]
        } else {
            vec![Param::Radius]
        };
        p.extend([Param::Theta0, Param::D1]);
        if self.gap.is_none() {
            p.push(Param::D2);
        }
        p.push(Param::LogStiffness);
        p
    }

    fn bounds(&self, p: Param) -> [f64; 2] {
        match p {
            Param::Radius | Param::RadiusP | Param::RadiusD => RADIUS_BOUNDS,
            Param::Theta0 => [f64::NEG_INFINITY, f64::INFINITY],
            Param::D1 => match self.gap {
                Some(gap) => [0.0, gap],
                None => OFFSET_BOUNDS,
            },
            Param::D2 => [self.d2_min, OFFSET_BOUNDS[1]],
            Param::LogStiffness => [STIFFNESS_BOUNDS[0].ln(), STIFFNESS_BOUNDS[1].ln()],
        }
    }

    /// The geometry for parameter values `x` (in [`Setup::params`] order).
    fn geometry(&self, x: &[f64]) -> Geometry {
        let mut g =
            Geometry { rho_p: 0.0, rho_d: 0.0, theta0: 0.0, d1: 0.0, d2: 0.0, stiffness: 0.0 };
        for (p, &v) in self.params().iter().zip(x) {
            match p {
                Param::Radius => (g.rho_p, g.rho_d) = (v, v),
                Param::RadiusP => g.rho_p = v,
                Param::RadiusD => g.rho_d = v,
                Param::Theta0 => g.theta0 = v,
                Param::D1 => g.d1 = v,
                Param::D2 => g.d2 = v,
                Param::LogStiffness => g.stiffness = v.exp(),
            }
        }
        if let Some(gap) = self.gap {
            g.d2 = gap - g.d1;
        }
        g
    }

    /// The parameter values of a geometry, clamped into the bounds.
    fn values(&self, g: &Geometry) -> Vec<f64> {
        self.params()
            .iter()
            .map(|&p| {
                let v = match p {
                    Param::Radius => 0.5 * (g.rho_p + g.rho_d),
                    Param::RadiusP => g.rho_p,
                    Param::RadiusD => g.rho_d,
                    Param::Theta0 => g.theta0,
                    Param::D1 => g.d1,
                    Param::D2 => g.d2,
                    Param::LogStiffness => g.stiffness.ln(),
                };
                let [lo, hi] = self.bounds(p);
                v.clamp(lo, hi)
            })
            .collect()
    }

    /// `u ↦ p`: `lo + (hi − lo)(1 + sin u)/2` for a bounded parameter, `u` itself otherwise.
    fn bounded_values(&self, u: &[f64]) -> Vec<f64> {
        self.params()
            .iter()
            .zip(u)
            .map(|(&p, &u)| match self.bounds(p) {
                [lo, hi] if lo.is_finite() => lo + (hi - lo) * 0.5 * (1.0 + u.sin()),
                _ => u,
            })
            .collect()
    }

    /// The inverse of [`Setup::bounded_values`].
    fn unbounded_values(&self, x: &[f64]) -> Vec<f64> {
        self.params()
            .iter()
            .zip(x)
            .map(|(&p, &x)| match self.bounds(p) {
                [lo, hi] if lo.is_finite() => {
                    (2.0 * (x - lo) / (hi - lo) - 1.0).clamp(-1.0, 1.0).asin()
                }
                _ => x,
            })
            .collect()
    }

    /// Whether parameter `i` of `x` sits on a bound (within 0.1 % of its range).
    fn at_bound(&self, i: usize, x: &[f64]) -> bool {
        let [lo, hi] = self.bounds(self.params()[i]);
        lo.is_finite() && (x[i] - lo).min(hi - x[i]) <= 1e-3 * (hi - lo)
    }
}

/// The least-squares problem in the unbounded variables `u` of a setup's parameters that are
/// not pinned (a pinned parameter keeps its value).
struct Problem {
    setup: Setup,
    /// Per parameter: `Some(u)` pinned at the unbounded value `u`, `None` free.
    pinned: Vec<Option<f64>>,
    /// The free parameters' unbounded values.
    u: DVector<f64>,
}

impl Problem {
    /// Every parameter's unbounded value, the free ones from `u`.
    fn all(&self, u: &[f64]) -> Vec<f64> {
        let mut free = u.iter();
        self.pinned.iter().map(|p| p.or_else(|| free.next().copied()).unwrap_or(0.0)).collect()
    }

    fn residuals_at(&self, u: &[f64]) -> Vec<f64> {
        residuals(&self.setup.geometry(&self.setup.bounded_values(&self.all(u))))
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, u: &DVector<f64>) {
        self.u.copy_from(u);
    }

    fn params(&self) -> DVector<f64> {
        self.u.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        Some(DVector::from_vec(self.residuals_at(self.u.as_slice())))
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        Some(central_differences(self.u.as_slice(), |u| self.residuals_at(u)))
    }
}

/// `∂r/∂x` by central differences, step `1e-6 · max(1, |x|)`.
fn central_differences(x: &[f64], f: impl Fn(&[f64]) -> Vec<f64>) -> DMatrix<f64> {
    let mut columns = Vec::with_capacity(x.len());
    for k in 0..x.len() {
        let h = 1e-6 * x[k].abs().max(1.0);
        let (mut plus, mut minus) = (x.to_vec(), x.to_vec());
        plus[k] += h;
        minus[k] -= h;
        let (rp, rm) = (f(&plus), f(&minus));
        columns.push(DVector::from_iterator(
            rp.len(),
            rp.iter().zip(&rm).map(|(a, b)| (a - b) / (2.0 * h)),
        ));
    }
    DMatrix::from_columns(&columns)
}

/// One fit's outcome.
#[derive(Debug, Clone)]
struct Fit {
    setup: Setup,
    /// Parameter values, [`Setup::params`] order.
    values: Vec<f64>,
    geometry: Geometry,
    rms: f64,
    evaluations: usize,
    /// The start point it came from (index into the starts).
    start: usize,
}

/// Levenberg–Marquardt from `start` (parameter values, clamped into the bounds), the
/// parameters marked in `pin` kept at their start values.
fn fit_from(setup: Setup, start: &[f64], pin: &[bool]) -> Fit {
    let u0 = setup.unbounded_values(start);
    let pinned: Vec<Option<f64>> =
        u0.iter().zip(pin).map(|(&u, &p)| if p { Some(u) } else { None }).collect();
    let free: Vec<f64> = u0.iter().zip(pin).filter(|(_, p)| !**p).map(|(u, _)| *u).collect();
    let problem = Problem { setup, pinned, u: DVector::from_vec(free) };
    let (problem, report) = LevenbergMarquardt::new().with_patience(100).minimize(problem);
    let values = setup.bounded_values(&problem.all(problem.u.as_slice()));
    let geometry = setup.geometry(&values).reduced();
    let rms = rms(&residuals(&geometry));
    Fit { setup, values, geometry, rms, evaluations: report.number_of_evaluations, start: 0 }
}

/// The fixed grid of starting points: θ0 ∈ {−40°, 0°, 40°} (one period), ρ ∈ {12, 22} mm,
/// d1 ∈ {2, 15, 28} mm, and k that gives K = 1.93 N m/rad at q = 0 (`1.5 k ρ²`).
fn start_points() -> Vec<Geometry> {
    let mut v = Vec::new();
    for theta0 in [-40f64, 0.0, 40.0] {
        for rho in [0.012, 0.022] {
            for d1 in [0.002, 0.015, 0.028] {
                v.push(Geometry {
                    rho_p: rho,
                    rho_d: rho,
                    theta0: theta0.to_radians(),
                    d1,
                    d2: GAP - d1,
                    stiffness: 1.93 / (1.5 * rho * rho),
                });
            }
        }
    }
    v
}

/// The best of the fits from every start point. A parameter that ends within 0.1 % of its
/// range from a bound (the sine map approaches a bound only slowly) is then put exactly on it
/// and the others refitted.
fn fit(setup: Setup, starts: &[Geometry]) -> (Fit, Vec<Fit>) {
    let none = vec![false; setup.params().len()];
    let fits: Vec<Fit> = starts.iter().map(|g| fit_from(setup, &setup.values(g), &none)).collect();
    let mut best = fits[0].clone();
    for (i, f) in fits.iter().enumerate() {
        if f.rms < best.rms {
            best = Fit { start: i, ..f.clone() };
        }
    }
    let pin: Vec<bool> = (0..best.values.len()).map(|i| setup.at_bound(i, &best.values)).collect();
    if pin.contains(&true) {
        let params = setup.params();
        let start: Vec<f64> = best
            .values
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                let [lo, hi] = setup.bounds(params[i]);
                match pin[i] {
                    true if v - lo < hi - v => lo,
                    true => hi,
                    false => v,
                }
            })
            .collect();
        let pinned = fit_from(setup, &start, &pin);
        best =
            Fit { evaluations: best.evaluations + pinned.evaluations, start: best.start, ..pinned };
    }
    (best, fits)
}

/// How far each free parameter (not on a bound) can move, the others refitted, before the RMS
/// rises by one percentage point (linearised: `δ_i = √(ΔSSR · [(JᵀJ)⁻¹]_ii)`), in the
/// parameter's own units (k: relative, from log k).
fn tolerances(fit: &Fit) -> Vec<Option<f64>> {
    let setup = fit.setup;
    let free: Vec<usize> =
        (0..fit.values.len()).filter(|&i| !setup.at_bound(i, &fit.values)).collect();
    let j = central_differences(&free.iter().map(|&i| fit.values[i]).collect::<Vec<_>>(), |y| {
        let mut x = fit.values.clone();
        for (k, &i) in free.iter().enumerate() {
            x[i] = y[k];
        }
        residuals(&setup.geometry(&x))
    });
    let n = fit.values.len();
    let m = j.nrows() as f64;
    let d_ssr = m * ((fit.rms + 0.01).powi(2) - fit.rms.powi(2));
    let Some(inverse) = (j.transpose() * &j).try_inverse() else {
        return vec![None; n];
    };
    let mut out = vec![None; n];
    for (k, &i) in free.iter().enumerate() {
        out[i] = Some((d_ssr * inverse[(k, k)]).max(0.0).sqrt());
    }
    out
}

fn describe(g: &Geometry) -> String {
    let radius = if (g.rho_p - g.rho_d).abs() < 1e-9 {
        format!("ρ = {:.2} mm", 1e3 * g.rho_p)
    } else {
        format!("ρ = {:.2} / {:.2} mm (proximal / distal)", 1e3 * g.rho_p, 1e3 * g.rho_d)
    };
    format!(
        "{radius}, θ0 = {:.2}°, d1 = {:.2} mm, d2 = {:.2} mm, k = {:.0} N/m",
        g.theta0.to_degrees(),
        1e3 * g.d1,
        1e3 * g.d2,
        g.stiffness
    )
}

/// `cargo xtask calibrate [--check]`.
pub fn run(args: &[String]) -> DynResult<()> {
    let check = match args {
        [] => false,
        [flag] if flag == "--check" => true,
        _ => return Err("usage: cargo xtask calibrate [--check]".into()),
    };
    let dir = crate::project_root().join("robots/cdhrm5");
    let clock = std::time::Instant::now();
    let starts = start_points();
    let (best, fits) = fit(MAIN, &starts);
    // What the files get: the fit rounded (lengths to 0.01 mm, θ0 to 1e-5 rad).
    let written = best.geometry.rounded(ea());
    let rows = table(&written)?;
    let errors = relative_errors(&rows);

    println!("Calibration of robots/cdhrm5 against Table II (spec §7)\n");
    println!(
        "Model: one universal joint, decoupled cables, τ = [0.3, 0.3] N m, f ∈ [20, 600] N; \
         20 residuals = relative errors of the interval ends."
    );
    println!(
        "Free: {}. Levenberg–Marquardt from {} grid starts; best from start {} ({} evaluations).",
        MAIN.name,
        starts.len(),
        best.start + 1,
        best.evaluations
    );
    let near = fits.iter().filter(|f| f.rms <= best.rms + 1e-4).count();
    println!("{near} of {} starts reach the best RMS (within 0.01 pp).\n", fits.len());

    println!("Fitted parameters:\n");
    println!("| parameter | value | bounds | change costing +1 pp RMS (others refitted) |");
    println!("| --- | --- | --- | --- |");
    let tol = tolerances(&best);
    for (i, p) in MAIN.params().iter().enumerate() {
        let [lo, hi] = MAIN.bounds(*p);
        let g = &best.geometry;
        let (name, value, bounds, unit_tol) = match p {
            Param::Radius => (
                "hole radius ρ (both discs)",
                format!("{:.2} mm", 1e3 * g.rho_p),
                format!("[{:.0}, {:.0}] mm", 1e3 * lo, 1e3 * hi),
                tol[i].map(|t| format!("± {:.2} mm", 1e3 * t)),
            ),
            Param::Theta0 => (
                "θ0 (angle of cable 1)",
                format!("{:.2}° (mod 120°)", g.theta0.to_degrees()),
                "free".to_owned(),
                tol[i].map(|t| format!("± {:.2}°", t.to_degrees())),
            ),
            Param::D1 => (
                "d1 (d2 = 30 mm − d1)",
                format!("{:.2} mm (d2 = {:.2} mm)", 1e3 * g.d1, 1e3 * g.d2),
                format!("[{:.0}, {:.0}] mm", 1e3 * lo, 1e3 * hi),
                tol[i].map(|t| format!("± {:.2} mm", 1e3 * t)),
            ),
            Param::LogStiffness => (
                "k = E·A/l_c (joint 1)",
                format!("{:.0} N/m (l_c = {:.3} m)", g.stiffness, ea() / g.stiffness),
                format!("[{:.0}, {:.0}] N/m", lo.exp(), hi.exp()),
                tol[i].map(|t| format!("± {:.1} %", 100.0 * t)),
            ),
            _ => continue,
        };
        let constrained = unit_tol.unwrap_or_else(|| "on its bound".to_owned());
        println!("| {name} | {value} | {bounds} | {constrained} |");
    }

    println!("\nTable II with the values as written (rounded), ours beside the paper's:\n");
    print!("{}", render_table_2(&rows));
    println!("RMS relative error over the 20 entries, to 0.01 %: {:.2} %", 100.0 * rms(&errors));
    let worst = errors.iter().fold(0.0_f64, |a, e| a.max(e.abs()));
    println!("Largest relative error: {:.1} %\n", 100.0 * worst);
    println!(
        "Qualitative patterns of Table II (the report's check, `sinew::paper::table_2_patterns`):\n"
    );
    print!("{}", sinew::paper::render_claims(&table_2_patterns(&rows)));

    println!(
        "\nWhat the data constrain: refits from the best, each with one restriction lifted:\n"
    );
    println!("| setup | RMS | parameters |");
    println!("| --- | --- | --- |");
    println!(
        "| {} (written) | {:.2} % | {} |",
        MAIN.name,
        100.0 * best.rms,
        describe(&best.geometry)
    );
    for variant in VARIANTS {
        let mut variant_starts = vec![best.geometry];
        variant_starts.extend(starts.iter().step_by(3).copied());
        let (v, _) = fit(variant, &variant_starts);
        println!("| {} | {:.2} % | {} |", variant.name, 100.0 * v.rms, describe(&v.geometry));
    }

    println!("\nValues for the files (rounded): {}", describe(&written));
    println!("Fit took {:.1} s.", clock.elapsed().as_secs_f64());

    if check {
        let differences = compare_with_files(&dir, &written)?;
        if differences.is_empty() {
            println!("\nrobots/cdhrm5 holds the fitted values (within the check tolerances).");
            return Ok(());
        }
        return Err(format!(
            "robots/cdhrm5 differs from the fit:\n{}\nrun `cargo xtask calibrate` to write it",
            differences.join("\n")
        )
        .into());
    }
    write_files(&dir, &written)?;
    println!(
        "\nWrote robots/cdhrm5/cdhrm5.urdf, cables.toml, cables-routed.toml. \
         Update robots/cdhrm5/README.md if the values changed."
    );
    Ok(())
}

/// The five-joint files for geometry `g`: the URDF and the two routing files.
fn file_texts(g: &Geometry) -> DynResult<[(&'static str, String); 3]> {
    let chain = UniformChain { name: "cdhrm5".to_owned(), ..chain(g, 5) };
    chain.build()?;
    let free = g.free_length(ea());
    let pitch = g.d1 + g.d2 + LINK;
    let per_joint: Vec<String> = (0..5).map(|i| fmt_num(free + i as f64 * pitch, 4)).collect();
    let values = Values {
        radius: fmt_num(g.rho_p, 5),
        radius_mm: format!("{:.2}", 1e3 * g.rho_p),
        rim_mm: format!("{:.1}", 30.0 - 1e3 * g.rho_p),
        theta0: fmt_num(g.theta0, 5),
        theta0_deg: format!("{:.2}", g.theta0.to_degrees()),
        free: fmt_num(free, 4),
        per_joint: per_joint.join(", "),
        stiffness: format!("{:.0}", g.stiffness),
        elastic: format!("{:.4}", ea() / g.stiffness),
        gap_mm: format!("{:.0}", 1e3 * (g.d1 + g.d2)),
        pitch: format!("{:.2}", pitch),
    };
    Ok([
        ("cdhrm5.urdf", chain.to_urdf()),
        (sinew::routing::ROUTING_FILE, decoupled_toml(&values)),
        (sinew::routing::ROUTED_ROUTING_FILE, routed_toml(&values)),
    ])
}

fn write_files(dir: &Path, g: &Geometry) -> DynResult<()> {
    for (name, text) in file_texts(g)? {
        std::fs::write(dir.join(name), text)?;
    }
    Ok(())
}

/// The differences between the committed files and geometry `g` beyond the check tolerances.
fn compare_with_files(dir: &Path, g: &Geometry) -> DynResult<Vec<String>> {
    let mut out = Vec::new();
    let robot = sinew::robot::load(dir)?;
    let d1 = robot.joints().first().map_or(f64::NAN, |j| j.origin.translation.z);
    let d2 = robot.link("link1")?.body_m_link.translation.z;
    let mut compare = |what: &str, file: f64, fit: f64, tol: f64, relative: bool| {
        let diff = if relative { (file - fit).abs() / fit.abs() } else { (file - fit).abs() };
        if diff.is_nan() || diff > tol {
            out.push(format!("  {what}: files {file:.6}, fit {fit:.6}"));
        }
    };
    compare("d1 (cdhrm5.urdf)", d1, g.d1, CHECK_LENGTH, false);
    compare("d2 (cdhrm5.urdf)", d2, g.d2, CHECK_LENGTH, false);
    for file in [sinew::routing::ROUTING_FILE, sinew::routing::ROUTED_ROUTING_FILE] {
        let text = std::fs::read_to_string(dir.join(file))?;
        let spec = RoutingSpec::from_toml_str(&text, file)?;
        let pattern = spec.pattern.as_ref().ok_or_else(|| format!("{file}: no [pattern]"))?;
        let radius = |r: &Option<PerJoint>| r.as_ref().and_then(|r| r.get(0));
        let rho_p = radius(&pattern.proximal_radius).or(radius(&pattern.radius));
        let rho_d = radius(&pattern.distal_radius).or(radius(&pattern.radius));
        compare(
            &format!("proximal radius ({file})"),
            rho_p.unwrap_or(f64::NAN),
            g.rho_p,
            CHECK_LENGTH,
            false,
        );
        compare(
            &format!("distal radius ({file})"),
            rho_d.unwrap_or(f64::NAN),
            g.rho_d,
            CHECK_LENGTH,
            false,
        );
        compare(&format!("theta0 ({file})"), pattern.theta0, g.theta0, CHECK_ANGLE, false);
        let routing = Routing::new(&robot, &spec, file)?;
        let k = routing.cable_stiffness().first().copied().unwrap_or(f64::NAN);
        compare(
            &format!("joint-1 cable stiffness ({file})"),
            k,
            g.stiffness,
            CHECK_STIFFNESS,
            true,
        );
    }
    Ok(out)
}

/// `x` rounded to `decimals`, printed without trailing zeros (at least one decimal).
fn fmt_num(x: f64, decimals: usize) -> String {
    let s = format!("{x:.decimals$}");
    let s = s.trim_end_matches('0');
    let s = if s.ends_with('.') { format!("{s}0") } else { s.to_owned() };
    if s == "-0.0" { "0.0".to_owned() } else { s }
}

/// The fitted values as the routing files print them.
struct Values {
    radius: String,
    radius_mm: String,
    rim_mm: String,
    theta0: String,
    theta0_deg: String,
    free: String,
    per_joint: String,
    stiffness: String,
    elastic: String,
    gap_mm: String,
    pitch: String,
}

fn decoupled_toml(v: &Values) -> String {
    format!(
        r#"# Cable routing of cdhrm5, the paper's platform: 15 cables, 3 per universal joint, in the
# paper's DECOUPLED model (spec §2: each cable's length counts only its crossing of the joint
# it drives; proximal crossings run through the central channel). The routed variant is
# cables-routed.toml beside this file. Format: crates/sinew-routing/src/spec.rs. SI units.
#
# Table I states E and the tension limits; everything else is chosen here and explained in
# README.md ("Cable routing"). The hole radius, theta0 and the free length are fitted to Table II
# (spec §7) by `cargo xtask calibrate`, which writes them here; `cargo xtask calibrate --check`
# tells whether this file still holds what the fit gives.

# Section IV of the paper: every cable tension stays in [20, 600] N.
tension_limits = [20.0, 600.0]

# Elastic length l_c = free_length + routed length at Q = 0 (eq. 13: k_c = E·A / l_c).
# Free length from the actuator to the base disc: {free} m, fitted to Table II: joint 1's cables
# have l_c = {elastic} m and k = E·A/l_c = {stiffness} N/m. It lumps the cable run to a remote
# actuation unit and any compliance in series.
# Decoupled: the routed length is only the {gap_mm} mm crossing of the cable's own joint, so the
# free length of joint i (0-based) adds the central channel through the i links before it,
# i · (d1 + d2 + link) = i · {pitch} m. Every cable then has the same elastic length as in the
# routed variant.
free_length = [{per_joint}]

[material]
# Table I: elastic modulus of the cables.
youngs_modulus = 12.5e9
# Not stated: a 1 mm cable (A = 0.785 mm²). At the 600 N limit it carries 764 MPa, within a
# steel wire rope's or braided polymer line's strength; E·A = 9817 N.
diameter = 1.0e-3

[pattern]
model = "decoupled"
# Hole circle radius on every disc: {radius_mm} mm, fitted to Table II; inside the φ60 mm link
# ({rim_mm} mm from the rim, room for the hole, its bushing and a central channel).
radius = {radius}
# Cable k (0, 1, 2) of joint i (0-based) at θ = theta0 + 120°·k + i·joint_offset.
# theta0 = {theta0_deg}°, fitted to Table II (modulo 120°: cable 1 of joint 1 near +x);
# joint_offset = 24° = 360°/15, so the 15 cables use 15 distinct, evenly spaced holes on each disc.
theta0 = {theta0}
joint_offset = 0.41887902047863906
# The disc links of each universal joint, base first: O_i (distal disc of link i-1, the base
# disc for joint 1) and O'_i (proximal disc of link i). Names of the generated URDF.
proximal_discs = ["base_link", "link1_distal", "link2_distal", "link3_distal", "link4_distal"]
distal_discs = ["link1", "link2", "link3", "link4", "link5"]
"#,
        free = v.free,
        elastic = v.elastic,
        stiffness = v.stiffness,
        gap_mm = v.gap_mm,
        pitch = v.pitch,
        per_joint = v.per_joint,
        radius_mm = v.radius_mm,
        rim_mm = v.rim_mm,
        radius = v.radius,
        theta0_deg = v.theta0_deg,
        theta0 = v.theta0,
    )
}

fn routed_toml(v: &Values) -> String {
    format!(
        r#"# Cable routing of cdhrm5 in the ROUTED model (spec §2): the cable of joint i starts at its hole
# on the base disc and passes through its holes (same angle) on the distal and proximal discs
# of every joint before i, ending at its anchor on the distal disc of joint i. Its tension then
# also loads every proximal joint (J_c block lower-triangular). Same cables, holes and material
# as cables.toml (the decoupled default); see README.md ("Cable routing") for the values. The
# hole radius, theta0 and the free length are fitted to Table II by `cargo xtask calibrate`.

tension_limits = [20.0, 600.0]

# Elastic length l_c = free_length + routed length at Q = 0. Here the routed length already
# holds the run along the proximal links ({pitch} m per link), so one free length serves every
# cable: the same {free} m from the actuator to the base disc as cables.toml, and the same
# elastic lengths at Q = 0.
free_length = {free}

[material]
youngs_modulus = 12.5e9
diameter = 1.0e-3

[pattern]
model = "routed"
radius = {radius}
theta0 = {theta0}
joint_offset = 0.41887902047863906
proximal_discs = ["base_link", "link1_distal", "link2_distal", "link3_distal", "link4_distal"]
distal_discs = ["link1", "link2", "link3", "link4", "link5"]
"#,
        pitch = v.pitch,
        free = v.free,
        radius = v.radius,
        theta0 = v.theta0,
    )
}
