//! `robot.toml` and the explicit `cables.toml` (formats: `sinew_robot::load`,
//! `sinew_routing::spec`). The keys are the formats' fixed bare keys and the layout is the
//! explicit form's (one `[[cable]]` per cable, one inline table per hole); every value, string
//! or number, is written by the `toml` crate (`toml::Value`'s serialisation picks the quoting
//! and escapes whatever a name holds), and every comment is one line ([`comment`]).

use std::fmt::Write as _;

use super::{Tip, comment};
use crate::CASPR_GRAVITY;

/// `robot.toml`'s content: the URDF file, the tip link and where the tip is.
pub(crate) struct RobotToml<'a> {
    /// The CASPR bodies file (in the header comment).
    pub(crate) bodies_file: &'a str,
    /// The URDF's file name, beside `robot.toml`.
    pub(crate) urdf_file: &'a str,
    /// The URDF link of the tip.
    pub(crate) tip_link: &'a str,
    /// The tip, said in a comment.
    pub(crate) tip: &'a Tip,
}

impl RobotToml<'_> {
    /// The file's text. The gravity is CASPR's, `−g` along z of the base frame.
    pub(crate) fn text(&self) -> String {
        let mut r = String::new();
        let _ = writeln!(
            r,
            "# Imported from CASPR by `sinew import caspr` (sinew-import): bodies {}.",
            comment(self.bodies_file)
        );
        let _ = writeln!(r, "urdf = {}", string(self.urdf_file));
        let _ = writeln!(r, "# The tip: {}.", comment(&self.tip.what));
        let _ = writeln!(r, "tip_link = {}", string(self.tip_link));
        let _ = writeln!(
            r,
            "# CASPR's gravity: -m g along z of the base frame, g = {CASPR_GRAVITY} m/s² (SystemModel.GRAVITY_CONSTANT)."
        );
        let _ = writeln!(r, "gravity = {}", floats(&[0.0, 0.0, -CASPR_GRAVITY]));
        r
    }
}

/// `cables.toml`'s content in the explicit form, as the import decided it.
pub(crate) struct CablesToml<'a> {
    /// The CASPR cables file (in the header comment).
    pub(crate) cables_file: &'a str,
    /// The cable set's id (in the header comment).
    pub(crate) cable_set: &'a str,
    /// Whether it is the file's `default_cable_set`.
    pub(crate) default_set: bool,
    /// Young's modulus, Pa.
    pub(crate) youngs_modulus: f64,
    /// Cable diameter, m.
    pub(crate) diameter: f64,
    /// Free length of every cable, m.
    pub(crate) free_length: f64,
    /// The top-level `[f_min, f_max]`, N.
    pub(crate) tension_limits: [f64; 2],
    /// The cables in the file's order.
    pub(crate) cables: Vec<CableToml<'a>>,
}

/// One `[[cable]]`.
pub(crate) struct CableToml<'a> {
    /// Its name, as CASPR gives it.
    pub(crate) name: &'a str,
    /// Its own `[f_min, f_max]`, N, when the cables' limits differ.
    pub(crate) tension_limits: Option<[f64; 2]>,
    /// Its holes in the order written (base first): URDF link name, point in the link frame.
    pub(crate) holes: Vec<(&'a str, [f64; 3])>,
}

impl CablesToml<'_> {
    /// The file's text.
    pub(crate) fn text(&self) -> String {
        let mut c = String::new();
        let _ = writeln!(
            c,
            "# Imported from CASPR by `sinew import caspr` (sinew-import): cables {}, cable set `{}`{}.",
            comment(self.cables_file),
            comment(self.cable_set),
            if self.default_set { " (the file's default_cable_set)" } else { "" }
        );
        let _ = writeln!(
            c,
            "# Each cable's holes are its CASPR attachments in order, as points in the link frame (the joint"
        );
        let _ = writeln!(
            c,
            "# frame; attachment_reference=\"com\" offsets converted by adding the link's <com_location>)."
        );
        let _ = writeln!(
            c,
            "# CASPR's ideal cables have no stiffness: the material and the free length are the import's"
        );
        let _ = writeln!(
            c,
            "# options (defaults: E = 200 GPa steel, d = 1 mm, free length 0.5 m); here E = {} Pa, d = {} m,",
            float(self.youngs_modulus),
            float(self.diameter)
        );
        let _ = writeln!(c, "# free length {} m.", float(self.free_length));
        if self.cables.iter().any(|cable| cable.tension_limits.is_some()) {
            let _ = writeln!(
                c,
                "# The cables' force limits differ: each [[cable]] has its own tension_limits; the top-level value is"
            );
            let _ = writeln!(c, "# the widest [min of force_min, max of force_max], N.");
        } else {
            let _ = writeln!(c, "# tension_limits: force_min (clamped to ≥ 0) and force_max, N.");
        }
        let _ = writeln!(c, "tension_limits = {}", floats(&self.tension_limits));
        let _ = writeln!(c, "free_length = {}", float(self.free_length));
        let _ = writeln!(c);
        let _ = writeln!(c, "[material]");
        let _ = writeln!(c, "youngs_modulus = {}", float(self.youngs_modulus));
        let _ = writeln!(c, "diameter = {}", float(self.diameter));
        for cable in &self.cables {
            let _ = writeln!(c);
            let _ = writeln!(c, "[[cable]]");
            let _ = writeln!(c, "name = {}", string(cable.name));
            if let Some(limits) = &cable.tension_limits {
                let _ = writeln!(c, "tension_limits = {}", floats(limits));
            }
            let _ = writeln!(c, "holes = [");
            for &(link, point) in &cable.holes {
                let mut hole = toml::Table::new();
                hole.insert("link".to_owned(), string(link));
                hole.insert("point".to_owned(), floats(&point));
                let _ = writeln!(c, "  {},", toml::Value::Table(hole));
            }
            let _ = writeln!(c, "]");
        }
        c
    }
}

/// A TOML string, quoted and escaped by the `toml` crate.
fn string(s: &str) -> toml::Value {
    toml::Value::String(s.to_owned())
}

/// A TOML float (always with a `.`, never an exponent); `−0` is written as `0.0`, as before.
fn float(v: f64) -> toml::Value {
    toml::Value::Float(if v == 0.0 { 0.0 } else { v })
}

/// A TOML array of floats.
fn floats(v: &[f64]) -> toml::Value {
    toml::Value::Array(v.iter().map(|&x| float(x)).collect())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::{float, floats, string};

    #[test]
    fn values_read_back_as_written() {
        assert_eq!(float(2.0e11).to_string(), "200000000000.0");
        assert_eq!(float(1.0e-7).to_string(), "0.0000001");
        assert_eq!(float(-0.0).to_string(), "0.0");
        assert_eq!(floats(&[2.0, 450.0]).to_string(), "[2.0, 450.0]");
        for s in ["a1", "a\"b\\c", "a\"b\\c\nd", "it's \"x\"", "''' \"\"\"", "tab\tdel\u{7f}"] {
            let text = format!("name = {}", string(s));
            let table: toml::Table = text.parse().unwrap();
            assert_eq!(table["name"].as_str(), Some(s), "{text}");
        }
        for v in [1.0e-7, 0.019107, -9.81, 2.0e11, 5e-324, f64::MAX] {
            let table: toml::Table = format!("v = {}", float(v)).parse().unwrap();
            assert_eq!(table["v"].as_float().map(f64::to_bits), Some(v.to_bits()));
        }
    }
}
