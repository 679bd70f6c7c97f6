//! The fit: which parameters a setup frees and their bounds, the least-squares problem in the
//! unbounded variables, Levenberg–Marquardt from a grid of starts, and how far each fitted
//! parameter can move.

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra_lm::{DMatrix, DVector, Dyn, Owned};

use super::model::{GAP, Geometry, residuals, rms};

/// Hole radius bounds, m: inside the φ60 mm link with 3 mm to the rim.
const RADIUS_BOUNDS: [f64; 2] = [0.005, 0.027];
/// Cable stiffness bounds, N/m.
const STIFFNESS_BOUNDS: [f64; 2] = [200.0, 50_000.0];
/// Joint-centre offsets when the gap is free (a variant), m.
const OFFSET_BOUNDS: [f64; 2] = [0.0, 0.06];

/// Which parameters a fit frees, and how.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Setup {
    pub(super) name: &'static str,
    /// One radius per disc instead of one for both.
    separate_radii: bool,
    /// `Some(gap)`: d2 = gap − d1; `None`: d1 and d2 both free.
    gap: Option<f64>,
    /// Least d2 (m) when the gap is free.
    d2_min: f64,
}

/// The fit written into the robot files.
pub(super) const MAIN: Setup = Setup {
    name: "ρ, θ0, d1 (d2 = 30 mm − d1), k",
    separate_radii: false,
    gap: Some(GAP),
    d2_min: 0.0,
};

/// Refits that show what the data constrain (printed, never written).
pub(super) const VARIANTS: [Setup; 3] = [
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
pub(super) enum Param {
    Radius,
    RadiusP,
    RadiusD,
    Theta0,
    D1,
    D2,
    LogStiffness,
}

impl Setup {
    pub(super) fn params(&self) -> Vec<Param> {
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

    pub(super) fn bounds(&self, p: Param) -> [f64; 2] {
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
pub(super) struct Fit {
    setup: Setup,
    /// Parameter values, [`Setup::params`] order.
    values: Vec<f64>,
    pub(super) geometry: Geometry,
    pub(super) rms: f64,
    pub(super) evaluations: usize,
    /// The start point it came from (index into the starts).
    pub(super) start: usize,
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
pub(super) fn start_points() -> Vec<Geometry> {
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
pub(super) fn fit(setup: Setup, starts: &[Geometry]) -> (Fit, Vec<Fit>) {
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
pub(super) fn tolerances(fit: &Fit) -> Vec<Option<f64>> {
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
