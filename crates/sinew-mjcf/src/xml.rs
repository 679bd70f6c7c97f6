//! The text of the file: numbers that read back exactly, escaped names and comments.

use nalgebra::{IsometryMatrix3, UnitQuaternion, Vector3};

/// A number as the shortest text that parses back to the same `f64` (`0.1`, `1e-12`, `3.0`).
pub(crate) fn num(x: f64) -> String {
    format!("{x:?}")
}

/// Numbers separated by spaces, as MJCF lists them.
pub(crate) fn nums(xs: &[f64]) -> String {
    xs.iter().map(|&x| num(x)).collect::<Vec<_>>().join(" ")
}

/// A 3-vector as `x y z`.
pub(crate) fn vec3(v: &Vector3<f64>) -> String {
    nums(&[v.x, v.y, v.z])
}

/// ` pos="…" quat="…"` for a frame, each left out when it is the identity's.
pub(crate) fn frame(m: &IsometryMatrix3<f64>) -> String {
    let mut s = String::new();
    let t = m.translation.vector;
    if t != Vector3::zeros() {
        s.push_str(&format!(" pos=\"{}\"", vec3(&t)));
    }
    if m.rotation.matrix() != &nalgebra::Matrix3::identity() {
        let q = UnitQuaternion::from_rotation_matrix(&m.rotation);
        s.push_str(&format!(" quat=\"{}\"", nums(&[q.w, q.i, q.j, q.k])));
    }
    s
}

/// An attribute value: `&`, `<`, `>` and `"` escaped.
pub(crate) fn attr(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// A comment: XML forbids `--` inside one (a trailing `-` is safe: a space follows it).
pub(crate) fn comment(text: &str) -> String {
    let mut s = text.to_owned();
    while s.contains("--") {
        s = s.replace("--", "- -");
    }
    format!("<!-- {s} -->")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_back_exactly() {
        for x in [0.1, -std::f64::consts::FRAC_PI_6, 1e-12, 3.0, 2.0f64.sqrt() * 1e7, -0.0] {
            assert_eq!(num(x).parse::<f64>().ok(), Some(x), "{}", num(x));
        }
        assert_eq!(nums(&[1.0, 0.25]), "1.0 0.25");
    }

    #[test]
    fn names_and_comments_are_escaped() {
        assert_eq!(attr(r#"a<b>&"c""#), "a&lt;b&gt;&amp;&quot;c&quot;");
        assert_eq!(comment("--q a---b -"), "<!-- - -q a- - -b - -->");
        let inner = comment("x---");
        assert!(!inner["<!--".len()..inner.len() - "-->".len()].contains("--"), "{inner}");
    }
}
