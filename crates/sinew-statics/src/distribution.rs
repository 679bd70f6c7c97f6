//! Tension distribution over a whole arm: every joint's feasible interval and the tensions at
//! chosen tension levels (eq. 22–23, spec §4), for the decoupled and the routed models.
//!
//! # Math
//! Joint `i`'s DOF are balanced when `−Σ_c J_c[c, 2i..2i+2] f_c = T0[2i..2i+2]`. Its own three
//! cables see the torque `τ_i = T0_i + Σ_{c distal} J_c[c, 2i..2i+2] f_c`, where the sum runs
//! over the cables of joints beyond `i` that cross it (none in the decoupled model). So the
//! joints are solved from the tip to the base: the tensions chosen at distal joints are known
//! torques at proximal ones. With no crossing cable the joints are independent and are solved
//! from the base, so that an infeasible load names the joint nearest the base.
//!
//! Supported routings: three cables per universal joint, cables ordered by joint, no cable
//! changing length with the DOF of a joint beyond its own. Others are
//! [`StaticsError::UnsupportedRouting`].

use faer::MatRef;
use nalgebra::Vector2;
use sinew_routing::Routing;

use crate::error::{StaticsError, UnsupportedRouting};
use crate::interval::{TensionInterval, TensionLimits, joint_block, tension_interval};

/// How the cables of a routing map onto the joints: three per universal joint.
#[derive(Debug, Clone, PartialEq)]
pub struct CableLayout {
    joints: usize,
    crossing: bool,
}

impl CableLayout {
    /// Check that a routing fits the closed-form solver: 2n DOF, three cables per universal
    /// joint in joint order ([`Routing::cables_of_joint`]), none whose length depends on a
    /// joint beyond its own ([`Routing::cable_joint_span`]). Records whether some cable also
    /// crosses proximal joints (the routed model: not [`Routing::is_decoupled`]).
    ///
    /// # Errors
    /// [`UnsupportedRouting`] saying what does not fit.
    pub fn new(routing: &Routing) -> Result<CableLayout, UnsupportedRouting> {
        let unsupported = Err;
        let dof = routing.dof();
        if !dof.is_multiple_of(2) {
            return unsupported(UnsupportedRouting::OddDof { dof });
        }
        if let Some((joint, g)) =
            routing.joint_groups().iter().enumerate().find(|(_, g)| g.len() != 2)
        {
            return unsupported(UnsupportedRouting::NotUniversal { joint, dofs: g.len() });
        }
        if !routing.has_uniform_limits() {
            let limits = routing.tension_limits();
            let c = routing.cable_limits().iter().position(|l| *l != limits).unwrap_or(0);
            let cable = routing.cables().get(c).map(|c| c.name.clone()).unwrap_or_default();
            return unsupported(UnsupportedRouting::CableLimits { cable });
        }
        let joints = dof / 2;
        let cables = routing.cables();
        if cables.len() != 3 * joints {
            return unsupported(UnsupportedRouting::CableCount { cables: cables.len(), joints });
        }
        for joint in 0..joints {
            if routing.cables_of_joint(joint) != (3 * joint..3 * joint + 3) {
                // Three per joint in all, so some cable is out of joint order.
                let c = (0..cables.len()).find(|&c| cables[c].joint != c / 3).unwrap_or(0);
                let cable = cables[c].name.clone();
                return unsupported(UnsupportedRouting::CableOrder {
                    cable,
                    joint: cables[c].joint,
                });
            }
        }
        for (c, cable) in cables.iter().enumerate() {
            let beyond = routing.cable_joint_span(c).is_some_and(|span| span.end > cable.joint + 1);
            if beyond {
                let name = cable.name.clone();
                return unsupported(UnsupportedRouting::BeyondOwnJoint {
                    cable: name,
                    joint: cable.joint,
                });
            }
        }
        Ok(CableLayout { joints, crossing: !routing.is_decoupled() })
    }

    /// Number of universal joints.
    pub fn joints(&self) -> usize {
        self.joints
    }

    /// Whether some cable also crosses (and loads) proximal joints: the routed model.
    pub fn crossing(&self) -> bool {
        self.crossing
    }
}

/// Every joint's feasible interval and the tensions at the given tension levels.
///
/// `t0` (2n) are the torques the cables must supply (e.g. from
/// [`crate::equilibrium_torques`]); `levels[i] ∈ [0, 1]` places joint `i` on its interval.
/// Writes `intervals` (n) and `tensions` (3n, N). No allocation.
///
/// # Errors
/// [`StaticsError::Infeasible`] naming the first joint that fails (solving order above),
/// [`StaticsError::InvalidLevel`], [`StaticsError::DimensionMismatch`].
pub fn distribute_tensions(
    layout: &CableLayout,
    jacobian: MatRef<'_, f64>,
    limits: TensionLimits,
    t0: &[f64],
    levels: &[f64],
    intervals: &mut [TensionInterval],
    tensions: &mut [f64],
) -> Result<(), StaticsError> {
    let n = layout.joints;
    let sizes = [
        ("cable Jacobian rows", 3 * n, jacobian.nrows()),
        ("cable Jacobian columns", 2 * n, jacobian.ncols()),
        ("equilibrium torques T0", 2 * n, t0.len()),
        ("tension levels", n, levels.len()),
        ("tension intervals", n, intervals.len()),
        ("tensions", 3 * n, tensions.len()),
    ];
    for (what, expected, got) in sizes {
        if expected != got {
            return Err(StaticsError::DimensionMismatch { what, expected, got });
        }
    }
    for (joint, &level) in levels.iter().enumerate() {
        if !(0.0..=1.0).contains(&level) {
            return Err(StaticsError::InvalidLevel { joint, level });
        }
    }
    let mut solve = |i: usize, tensions: &mut [f64]| -> Result<(), StaticsError> {
        let mut tau = Vector2::new(t0[2 * i], t0[2 * i + 1]);
        if layout.crossing {
            // The distal cables' torques, each component summed over the cables in order; the
            // two components side by side (two independent chains of additions, which the
            // processor overlaps; the same sums in the same order).
            let distal = 3 * (i + 1)..3 * n;
            let columns = (jacobian.col(2 * i), jacobian.col(2 * i + 1));
            match (columns.0.try_as_col_major(), columns.1.try_as_col_major()) {
                (Some(c0), Some(c1)) => {
                    let (c0, c1) = (&c0.as_slice()[distal.clone()], &c1.as_slice()[distal.clone()]);
                    let (mut t0, mut t1) = (tau[0], tau[1]);
                    for ((j0, j1), f) in c0.iter().zip(c1).zip(&tensions[distal.clone()]) {
                        t0 += j0 * f;
                        t1 += j1 * f;
                    }
                    tau = Vector2::new(t0, t1);
                }
                _ => {
                    for (k, t) in tau.iter_mut().enumerate() {
                        let column = jacobian.col(2 * i + k);
                        for c in distal.clone() {
                            *t += column[c] * tensions[c];
                        }
                    }
                }
            }
        }
        let interval = tension_interval(i, &joint_block(jacobian, i), &tau, limits)?;
        let f = interval.tensions_at_level(levels[i]);
        tensions[3 * i..3 * i + 3].copy_from_slice(f.as_slice());
        intervals[i] = interval;
        Ok(())
    };
    if layout.crossing {
        for i in (0..n).rev() {
            solve(i, tensions)?;
        }
    } else {
        for i in 0..n {
            solve(i, tensions)?;
        }
    }
    Ok(())
}
