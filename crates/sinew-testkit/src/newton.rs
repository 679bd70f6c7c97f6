//! A nonlinear equilibrium solve built from library *values* only, to check the end compliance
//! `C_x` (spec §5): apply a small wrench `δw` at the end-effector, find the new equilibrium `Q`
//! of the elastic cables, gravity and the load by Newton's method, and compare the tip's motion
//! with `C_x δw`. Any cable set, any joints (1 or 2 DOF): only cable lengths, poses, masses and
//! `k_c` are read from the library. `tests/equilibrium.rs` in the facade has the derivation
//! and the measured accuracy on cdhrm5; `tests/general_cables.rs` uses it on other arms.
//!
//! # The model
//! With `f0` the tensions at the reference `Q0`, `L0 = L(Q0)`, `k_c = E A / l_c` and `F0` the
//! wrench the end-effector exerts on its environment (base frame):
//!
//! ```text
//! V(Q) = −Σ_b m_b g · c_b(Q) + Σ_c ( f0_c (L_c − L0_c) + ½ k_c (L_c − L0_c)² ) + (F0 − δw)_f · p(Q)
//! R_i(Q) = −∂V/∂q_i − (F0 − δw)_m · ω_i(Q)
//! ```
//!
//! `R(Q) = 0` at equilibrium; every derivative is an eighth-order central difference of values
//! ([`STENCIL`], [`H_VALUES`]), Newton's matrix a central difference of `R` ([`H_NEWTON`]).
//!
//! Like the fixture loaders, these helpers panic on a library error: the tests call them at
//! configurations the library has already solved.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use faer::Mat;
use faer::linalg::solvers::Solve;
use nalgebra::{IsometryMatrix3, Point3, Rotation3, Vector3, Vector6};
use sinew_robot::{Robot, RobotData};
use sinew_routing::{Order, Routing, RoutingData, compute_cable_geometry};

/// Eighth-order central differences: `f'(x) ≈ Σ_m w_m (f(x + m h) − f(x − m h)) / h`.
pub const STENCIL: [(f64, f64); 4] =
    [(1.0, 4.0 / 5.0), (2.0, -1.0 / 5.0), (3.0, 4.0 / 105.0), (4.0, -1.0 / 280.0)];
/// Step of [`STENCIL`], rad. Against the library's analytic residual (not used here; measured
/// on cdhrm5 by `tests/equilibrium.rs`) the
/// difference is ≤ 1.5e-11 N m at E4 and three random configurations of either routing
/// (2.5e-11 with a sixth-order stencil at 5e-3, 1e-10 with a fourth-order one at 1e-3); the
/// round-off floor of the residual, from the cable lengths' last bits times tensions of hundreds
/// of newtons, is ~1e-11 N m.
pub const H_VALUES: f64 = 1e-2;
/// Step of the central differences of the residual in Newton's matrix, rad.
pub const H_NEWTON: f64 = 1e-5;
/// Newton takes one more step once the residual norm is below this, N m (and then stops at
/// the round-off floor, ~1e-11 N m).
pub const NEWTON_TOLERANCE: f64 = 1e-10;

/// Workspaces for the library's values at one configuration.
#[derive(Debug)]
pub struct Values<'a> {
    robot: &'a Robot,
    routing: &'a Routing,
    kinematics: RobotData,
    cables: RoutingData,
}

impl<'a> Values<'a> {
    /// Workspaces for `robot` and `routing`.
    pub fn new(robot: &'a Robot, routing: &'a Routing) -> Values<'a> {
        Values {
            robot,
            routing,
            kinematics: RobotData::new(robot),
            cables: RoutingData::new(routing),
        }
    }

    /// The cable lengths (m), the tip pose (base frame) and the gravitational potential energy
    /// `−Σ_b m_b g · c_b` (J) at `q`: values, no derivative.
    pub fn at(&mut self, q: &[f64]) -> (&[f64], IsometryMatrix3<f64>, f64) {
        let (robot, routing) = (self.robot, self.routing);
        compute_cable_geometry(
            routing,
            robot,
            &mut self.kinematics,
            &mut self.cables,
            q,
            Order::Lengths,
        )
        .unwrap();
        let g = robot.gravity();
        let gravity_energy = -robot
            .bodies()
            .iter()
            .enumerate()
            .map(|(b, body)| {
                let c = self.kinematics.body_pose(b).unwrap() * Point3::from(body.com);
                body.mass * g.dot(&c.coords)
            })
            .sum::<f64>();
        let tip = robot.tip_pose(&self.kinematics).unwrap();
        (self.cables.lengths().unwrap(), tip, gravity_energy)
    }

    /// End-effector displacement and rotation vector from `q0` to `q`, base frame.
    pub fn motion(&mut self, q0: &[f64], q: &[f64]) -> Vector6<f64> {
        let a = self.at(q0).1;
        let b = self.at(q).1;
        let dp = b.translation.vector - a.translation.vector;
        let dr = (b.rotation * a.rotation.inverse()).scaled_axis();
        Vector6::new(dp[0], dp[1], dp[2], dr[0], dr[1], dr[2])
    }
}

/// The elastic-cable model frozen at a reference equilibrium.
#[derive(Debug)]
pub struct Elastic<'a> {
    values: Values<'a>,
    /// Tensions at the reference, N.
    pub f0: Vec<f64>,
    /// Cable lengths at the reference, m.
    pub l0: Vec<f64>,
    /// Axial stiffness of each cable, N/m.
    pub k: Vec<f64>,
    /// Wrench the end-effector exerts on its environment at the reference, base frame.
    pub load: Vector6<f64>,
}

impl<'a> Elastic<'a> {
    /// The model frozen at the reference `q0`, with the tensions `f0` there and the load `load`.
    pub fn new(
        robot: &'a Robot,
        routing: &'a Routing,
        q0: &[f64],
        f0: Vec<f64>,
        load: Vector6<f64>,
    ) -> Elastic<'a> {
        let mut values = Values::new(robot, routing);
        let l0 = values.at(q0).0.to_vec();
        Elastic { values, f0, l0, k: routing.cable_stiffness().to_vec(), load }
    }

    /// `V(Q)` (with the load `F0 − δw`) and the tip's rotation.
    pub fn energy(&mut self, q: &[f64], dw: &Vector6<f64>) -> (f64, Rotation3<f64>) {
        Potential::energy(self, q, dw)
    }

    /// `R(Q)`: [`Potential::residual`].
    pub fn residual(&mut self, q: &[f64], dw: &Vector6<f64>) -> Vec<f64> {
        Potential::residual(self, q, dw)
    }

    /// Newton's matrix: [`Potential::newton_matrix`].
    pub fn newton_matrix(&mut self, q: &[f64]) -> Mat<f64> {
        Potential::newton_matrix(self, q)
    }

    /// The equilibrium under `δw`: [`Potential::solve`].
    pub fn solve(&mut self, q0: &[f64], jac: &Mat<f64>, dw: &Vector6<f64>) -> Vec<f64> {
        Potential::solve(self, q0, jac, dw)
    }

    /// End-effector displacement and rotation vector from `q0` to `q`, base frame.
    pub fn motion(&mut self, q0: &[f64], q: &[f64]) -> Vector6<f64> {
        self.values.motion(q0, q)
    }
}

impl Potential for Elastic<'_> {
    fn load(&self) -> Vector6<f64> {
        self.load
    }

    fn energy(&mut self, q: &[f64], dw: &Vector6<f64>) -> (f64, Rotation3<f64>) {
        let force = (self.load - dw).fixed_rows::<3>(0).into_owned();
        let (lengths, tip, gravity_energy) = self.values.at(q);
        let cables: f64 = lengths
            .iter()
            .enumerate()
            .map(|(c, l)| {
                let stretch = l - self.l0[c];
                self.f0[c] * stretch + 0.5 * self.k[c] * stretch * stretch
            })
            .sum();
        (gravity_energy + cables + force.dot(&tip.translation.vector), tip.rotation)
    }
}

/// A potential-energy model of the arm under the load `F0 − δw` (gravity, elastic cables, the
/// load's force part), from which the residual, Newton's matrix and the solve follow: the
/// whole-cable springs of [`Elastic`], or a test's own (segment springs in the stick regime).
pub trait Potential {
    /// `F0`, the wrench the end-effector exerts at the reference (base frame).
    fn load(&self) -> Vector6<f64>;

    /// `V(Q)` with the load `F0 − δw`, and the tip's rotation.
    fn energy(&mut self, q: &[f64], dw: &Vector6<f64>) -> (f64, Rotation3<f64>);

    /// `R(Q) = −∂V/∂Q − (F0 − δw)_m · ω(Q)`, zero at equilibrium (N m).
    fn residual(&mut self, q: &[f64], dw: &Vector6<f64>) -> Vec<f64> {
        let moment = (self.load() - dw).fixed_rows::<3>(3).into_owned();
        let h = H_VALUES;
        let mut qs = q.to_vec();
        (0..q.len())
            .map(|i| {
                let mut at = |t: f64| {
                    qs[i] = q[i] + t;
                    let e = self.energy(&qs, dw);
                    qs[i] = q[i];
                    e
                };
                // f(t) = V(q + t) − V(q − t) and log(R(q + t) R(q − t)ᵀ) are odd in t; the
                // weights below cancel their t³ and t⁵ terms: an O(h⁶) derivative.
                let (mut dv, mut omega) = (0.0, Vector3::zeros());
                for (m, w) in STENCIL {
                    let (t, (vp, rp)) = (m * h, at(m * h));
                    let (vm, rm) = at(-t);
                    dv += w * (vp - vm) / h;
                    omega += w * (rp * rm.inverse()).scaled_axis() / h;
                }
                -dv - moment.dot(&omega)
            })
            .collect()
    }

    /// Newton's matrix `∂R/∂Q` at `q`, by central differences of `R`.
    fn newton_matrix(&mut self, q: &[f64]) -> Mat<f64> {
        let n = q.len();
        let mut jac = Mat::<f64>::zeros(n, n);
        let mut qs = q.to_vec();
        for i in 0..n {
            qs[i] = q[i] + H_NEWTON;
            let rp = self.residual(&qs, &Vector6::zeros());
            qs[i] = q[i] - H_NEWTON;
            let rm = self.residual(&qs, &Vector6::zeros());
            qs[i] = q[i];
            for j in 0..n {
                jac[(j, i)] = (rp[j] - rm[j]) / (2.0 * H_NEWTON);
            }
        }
        jac
    }

    /// The equilibrium under `δw` near `q0`: Newton's method with the fixed matrix `jac`.
    fn solve(&mut self, q0: &[f64], jac: &Mat<f64>, dw: &Vector6<f64>) -> Vec<f64> {
        let n = q0.len();
        let lu = jac.partial_piv_lu();
        let norm = |r: &[f64]| r.iter().map(|x| x * x).sum::<f64>().sqrt();
        let mut q = q0.to_vec();
        // Newton stops one step after the residual falls below the tolerance: that step takes
        // the solution to the round-off floor of the residual.
        let mut below = false;
        for _ in 0..50 {
            let r = self.residual(&q, dw);
            if norm(&r) < NEWTON_TOLERANCE {
                if below {
                    return q;
                }
                below = true;
            }
            let step = lu.solve(Mat::from_fn(n, 1, |i, _| -r[i]));
            if below {
                q = (0..n).map(|i| q[i] + step[(i, 0)]).collect();
                continue;
            }
            // Backtracking: halve the step until the residual decreases.
            let mut t = 1.0;
            loop {
                let trial: Vec<f64> = (0..n).map(|i| q[i] + t * step[(i, 0)]).collect();
                if norm(&self.residual(&trial, dw)) < norm(&r) || t < 1e-6 {
                    q = trial;
                    break;
                }
                t *= 0.5;
            }
        }
        let r = self.residual(&q, dw);
        panic!(
            "Newton did not converge: residual {:.3e} at {q:?} (from {q0:?}, δw {dw:?})",
            norm(&r)
        );
    }
}

/// `τ(Q) = −J_c(Q)ᵀ f(Q)` with elastic cables `f = f0 + K_l (L(Q) − L(Q0))` (spec §3), `l0`
/// the lengths at the reference: `K_q` is minus its derivative at the reference.
pub fn elastic_cable_torque(
    robot: &Robot,
    routing: &Routing,
    q: &[f64],
    f0: &[f64],
    l0: &[f64],
) -> Vec<f64> {
    let mut rdata = RobotData::new(robot);
    let mut g = RoutingData::new(routing);
    compute_cable_geometry(routing, robot, &mut rdata, &mut g, q, Order::Jacobian).unwrap();
    let l = g.lengths().unwrap();
    let j = g.jacobian().unwrap();
    let k = routing.cable_stiffness();
    let f: Vec<f64> = (0..f0.len()).map(|c| f0[c] + k[c] * (l[c] - l0[c])).collect();
    (0..robot.dof()).map(|d| -(0..f.len()).map(|c| j[(c, d)] * f[c]).sum::<f64>()).collect()
}
