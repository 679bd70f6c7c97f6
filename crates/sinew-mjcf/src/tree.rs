//! The body tree of the model: which of the robot's bodies become MJCF bodies, with their
//! frames and hinges (a decision made once here; `write.rs` only renders it).

use nalgebra::{IsometryMatrix3, Matrix3, Vector3};
use sinew_robot::Robot;
use sinew_routing::Routing;

/// The mass given to a massless body that must stay a body (it carries holes or the tip), kg:
/// above MuJoCo's `mjMINVAL` (1e-15), which refuses a moving body with less, and small enough
/// that its weight (≈ 1e-11 N) stays far below the statics' 1e-9 relative agreement.
pub const MIN_MASS: f64 = 1e-12;

/// The principal inertia given with [`MIN_MASS`], kg m².
pub const MIN_INERTIA: f64 = 1e-12;

/// A hinge of an MJCF body, in the body's frame.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Hinge {
    /// The robot's revolute joint (index into `Robot::joints`).
    pub joint: usize,
    /// The point on the axis, body frame, m.
    pub pos: Vector3<f64>,
    /// Unit axis, body frame.
    pub axis: Vector3<f64>,
}

/// One MJCF body: robot body `body` (its frame is the MJCF body frame), with the massless
/// bodies before it merged in.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct MjBody {
    /// The robot body (index into `Robot::bodies`, ≥ 1).
    pub body: usize,
    /// The robot bodies merged into it (massless, no hole, no tip), base first.
    pub merged: Vec<usize>,
    /// Its frame in the parent MJCF body's frame (the world for the first) at `Q = 0`.
    pub parent_m_body: IsometryMatrix3<f64>,
    /// Its hinges, in MuJoCo's order of composition (the robot's joint order).
    pub hinges: Vec<Hinge>,
    /// Whether it was massless and got [`MIN_MASS`].
    pub min_mass: bool,
}

/// The bodies of the model, base to tip (each the parent of the next: a serial chain).
pub(crate) fn bodies(robot: &Robot, routing: &Routing) -> Vec<MjBody> {
    let n = robot.bodies().len();
    let mut carries = vec![false; n];
    for cable in routing.cables() {
        for hole in &cable.holes {
            carries[hole.body_point.body] = true;
        }
    }
    carries[robot.tip_point().body] = true;
    let mut out = Vec::new();
    // The origins of the joints not yet given a body: `O_a, …, O_k` of `parent_M_joint`.
    let mut pending: Vec<usize> = Vec::new();
    let mut merged = Vec::new();
    for b in 1..n {
        pending.push(b - 1);
        let massless = robot.bodies()[b].mass <= 0.0;
        // A massless body between two joints, with nothing on it: its joint moves into the
        // next body (MuJoCo refuses a massless moving body; no fake mass needed).
        if massless && !carries[b] && b + 1 < n {
            merged.push(b);
            continue;
        }
        out.push(body(robot, b, &pending, std::mem::take(&mut merged), massless));
        pending.clear();
    }
    out
}

/// The MJCF body of robot body `b` reached through the joints `pending` (consecutive).
///
/// # Math
/// With `G_k = O_a ⋯ O_k` (joint `k`'s frame in the parent body) and `F = G_last` (the body
/// frame), the chain `O_a R_a ⋯ O_last R_last` equals `F · Π_k (F⁻¹G_k) R_k (F⁻¹G_k)⁻¹`: a
/// rotation about the axis `rot(F⁻¹G_k) a_k` through the point `trans(F⁻¹G_k)`, composed in
/// joint order, which is how MuJoCo composes the joints of one body.
fn body(robot: &Robot, b: usize, pending: &[usize], merged: Vec<usize>, massless: bool) -> MjBody {
    let joints = robot.joints();
    let mut g = Vec::with_capacity(pending.len());
    let mut acc = IsometryMatrix3::identity();
    for &k in pending {
        acc *= joints[k].origin;
        g.push(acc);
    }
    let f = acc;
    let f_inv = f.inverse();
    let hinges = pending
        .iter()
        .zip(&g)
        .map(|(&k, g_k)| {
            let local = f_inv * g_k;
            Hinge {
                joint: k,
                pos: local.translation.vector,
                axis: local.rotation * joints[k].axis.into_inner(),
            }
        })
        .collect();
    MjBody { body: b, merged, parent_m_body: f, hinges, min_mass: massless }
}

/// A body's inertia as MuJoCo's `fullinertia` (`Ixx Iyy Izz Ixy Ixz Iyz`).
pub(crate) fn full_inertia(i: &Matrix3<f64>) -> [f64; 6] {
    [i[(0, 0)], i[(1, 1)], i[(2, 2)], i[(0, 1)], i[(0, 2)], i[(1, 2)]]
}
