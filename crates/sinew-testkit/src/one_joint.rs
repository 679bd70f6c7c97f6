//! One universal joint of the paper (eq. 1) and explicit routings on it: the closed-form
//! fixtures of the geometry and friction tests (a cable through one hole, whose wrap angle and
//! capstan ratio follow from eq. 1 alone).

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

/// The start of an explicit routing file: cdhrm5's tension limits and material, a free length
/// of 1 m; `[[cable]]` tables follow.
pub const HEADER: &str = r#"
tension_limits = [20.0, 600.0]
free_length = 1.0
[material]
youngs_modulus = 12.5e9
diameter = 1.0e-3
"#;

/// eq. (1): `T = Trans(0,0,d1) · Rot(x, q1) · Rot(y, q2) · Trans(0,0,d2)`, the distal disc's
/// frame in the proximal one's.
pub fn eq1(d1: f64, d2: f64, q: [f64; 2]) -> Isometry3<f64> {
    let rot = |axis, angle| {
        Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_axis_angle(axis, angle),
        )
    };
    Isometry3::translation(0.0, 0.0, d1)
        * rot(&Vector3::x_axis(), q[0])
        * rot(&Vector3::y_axis(), q[1])
        * Isometry3::translation(0.0, 0.0, d2)
}

/// A routing of one cable `one` on a one-joint chain (`base_link`, `link1`): from a hole at
/// `(rho, 0, 0)` on the base disc to its anchor at the same point of the distal disc, with
/// friction coefficient `mu` and the entry direction `entry` (its x and z; y is 0).
pub fn one_hole_routing(rho: f64, mu: f64, entry: &Vector3<f64>) -> String {
    format!(
        "{HEADER}[[cable]]\nname = \"one\"\nfriction_coefficient = {mu}\nentry_direction = [{}, 0.0, {}]\nholes = [{{ link = \"base_link\", point = [{rho}, 0.0, 0.0] }}, {{ link = \"link1\", point = [{rho}, 0.0, 0.0] }}]\n",
        entry.x, entry.z
    )
}
