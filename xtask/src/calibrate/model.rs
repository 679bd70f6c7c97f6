//! The calibration's model: the single-joint geometry the fit changes, and the 20 residuals it
//! costs against Table II (one universal joint, decoupled cables, computed by the library as the
//! report computes it).

use std::f64::consts::{FRAC_PI_3, PI, TAU};

use sinew::paper::Table2Row;
use sinew::robot::UniformChain;
use sinew::routing::{PatternModel, PerJoint, Routing};
use sinew_testkit::cdhrm5;

use crate::DynResult;

/// The relative error charged to each entry of a configuration that cannot hold the torque.
pub(super) const INFEASIBLE_RESIDUAL: f64 = 10.0;
/// Gap between the two discs of a joint, d1 + d2, m (kept; see the module doc).
pub(super) const GAP: f64 = 0.03;
/// Link length, m (Table I), for the free lengths of the distal joints.
pub(super) const LINK: f64 = 0.22;

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
    pub(super) fn reduced(self) -> Geometry {
        let period = TAU / 3.0;
        let theta0 = (self.theta0 + FRAC_PI_3).rem_euclid(period) - FRAC_PI_3;
        Geometry { theta0, ..self }
    }

    /// Routed length of a joint-1 cable at Q = 0, m: its crossing of the joint.
    fn crossing(&self) -> f64 {
        ((self.rho_d - self.rho_p).powi(2) + (self.d1 + self.d2).powi(2)).sqrt()
    }

    /// The free length that gives joint 1's cables the stiffness `k`: `E·A/k − crossing`, m.
    pub(super) fn free_length(&self, ea: f64) -> f64 {
        ea / self.stiffness - self.crossing()
    }

    /// The values as written into the robot files: lengths to 0.01 mm, θ0 to 1e-5 rad, and the
    /// stiffness that the free length rounded to 0.1 mm gives.
    pub(super) fn rounded(self, ea: f64) -> Geometry {
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
pub(super) fn ea() -> f64 {
    cdhrm5::YOUNGS_MODULUS * PI * 0.25 * cdhrm5::DIAMETER.powi(2)
}

/// A chain of `joints` cdhrm5 joints with the geometry's d1, d2.
pub(super) fn chain(g: &Geometry, joints: usize) -> UniformChain {
    UniformChain { d1: g.d1, d2: g.d2, ..cdhrm5::uniform_chain(joints) }
}

/// Table II (the same computation as the report's, [`sinew::paper::table_2`]) of a one-joint
/// chain with geometry `g`.
pub(super) fn table(g: &Geometry) -> DynResult<Vec<Table2Row>> {
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
pub(super) fn relative_errors(rows: &[Table2Row]) -> Vec<f64> {
    rows.iter().flat_map(Table2Row::relative_errors).collect()
}

pub(super) fn residuals(g: &Geometry) -> Vec<f64> {
    match table(g) {
        Ok(rows) => relative_errors(&rows),
        Err(_) => vec![INFEASIBLE_RESIDUAL; 20],
    }
}

pub(super) fn rms(r: &[f64]) -> f64 {
    (r.iter().map(|x| x * x).sum::<f64>() / r.len().max(1) as f64).sqrt()
}
