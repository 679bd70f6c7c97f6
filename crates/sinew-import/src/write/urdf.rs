//! `<name>.urdf`: CASPR's links as URDF text, every name and comment made safe for XML.

use std::fmt::Write as _;

use super::{Tip, comment};
use crate::{BASE_LINK, CasprModel, TIP_LINK};

/// `<name>.urdf`: the base link, per CASPR link its revolute joint(s) (a `U_*` link's first axis
/// into the massless `<link>_cross`, the second with zero translation) and its body, then the
/// fixed joint to the tip. `names[num]` is link `num`'s URDF name (0 the base).
pub(crate) fn write_urdf(model: &CasprModel, name: &str, names: &[String], tip: &Tip) -> String {
    let mut u = String::new();
    let _ = writeln!(u, "<?xml version=\"1.0\"?>");
    let _ = writeln!(
        u,
        "<!-- Imported from CASPR by `sinew import caspr` (sinew-import): bodies {}, cable set `{}`.",
        comment(&model.bodies_file),
        comment(&model.cable_set.id)
    );
    let _ = writeln!(
        u,
        "     Each CASPR link is its joint frame: R_* is one revolute joint at <parent><location>, U_* two"
    );
    let _ = writeln!(
        u,
        "     (the first axis into the massless `<link>_cross`, the second with zero translation). Inertias"
    );
    let _ = writeln!(
        u,
        "     are about the centre of mass (ref=\"joint\" converted by the parallel-axis theorem). Joint limits"
    );
    let _ = writeln!(
        u,
        "     are CASPR's q_min/q_max, or ±π where the file states none. effort and velocity are unused by Sinew. -->"
    );
    let _ = writeln!(u, "<robot name=\"{}\">", attr(name));
    let _ = writeln!(u, "  <link name=\"{BASE_LINK}\"/>");
    for link in &model.links {
        let me = &names[link.num];
        let parent = &names[link.num - 1];
        let _ = writeln!(u);
        let _ = writeln!(
            u,
            "  <!-- CASPR link {} `{}`: {} -->",
            link.num,
            comment(&link.name),
            link.joint.caspr_name()
        );
        if !link.limits_stated {
            let _ = writeln!(u, "  <!-- no q_min/q_max in the CASPR file: limits ±π -->");
        }
        let axes = link.joint.axes();
        for (i, axis) in axes.iter().enumerate() {
            let (from, to, origin) = match (axes.len(), i) {
                (1, _) => (parent.clone(), me.clone(), link.parent_location),
                (_, 0) => (parent.clone(), format!("{me}_cross"), link.parent_location),
                _ => (format!("{me}_cross"), me.clone(), [0.0; 3]),
            };
            let _ =
                writeln!(u, "  <joint name=\"{}_{}\" type=\"revolute\">", attr(me), axis.name());
            let _ = writeln!(
                u,
                "    <parent link=\"{}\"/><child link=\"{}\"/>",
                attr(&from),
                attr(&to)
            );
            let _ = writeln!(
                u,
                "    <origin xyz=\"{}\" rpy=\"0 0 0\"/><axis xyz=\"{}\"/>",
                xyz(origin),
                xyz(axis.unit())
            );
            let _ = writeln!(
                u,
                "    <limit lower=\"{}\" upper=\"{}\" effort=\"0\" velocity=\"0\"/>",
                n(link.q_min[i]),
                n(link.q_max[i])
            );
            let _ = writeln!(u, "  </joint>");
            if axes.len() == 2 && i == 0 {
                let _ = writeln!(u, "  <link name=\"{}_cross\"/>", attr(me));
            }
        }
        if link.mass == 0.0 && link.inertia_com == [[0.0; 3]; 3] {
            let _ = writeln!(u, "  <link name=\"{}\"/>", attr(me));
        } else {
            let i = link.inertia_com;
            let _ = writeln!(u, "  <link name=\"{}\">", attr(me));
            let _ = writeln!(u, "    <inertial>");
            let _ = writeln!(u, "      <origin xyz=\"{}\" rpy=\"0 0 0\"/>", xyz(link.com));
            let _ = writeln!(u, "      <mass value=\"{}\"/>", n(link.mass));
            let _ = writeln!(
                u,
                "      <inertia ixx=\"{}\" ixy=\"{}\" ixz=\"{}\" iyy=\"{}\" iyz=\"{}\" izz=\"{}\"/>",
                n(i[0][0]),
                n(i[0][1]),
                n(i[0][2]),
                n(i[1][1]),
                n(i[1][2]),
                n(i[2][2])
            );
            let _ = writeln!(u, "    </inertial>");
            let _ = writeln!(u, "  </link>");
        }
    }
    let _ = writeln!(u);
    let _ = writeln!(u, "  <!-- The tip: {} -->", comment(&tip.what));
    let _ = writeln!(u, "  <joint name=\"tip_joint\" type=\"fixed\">");
    let _ = writeln!(
        u,
        "    <parent link=\"{}\"/><child link=\"{TIP_LINK}\"/>",
        attr(&names[tip.link])
    );
    let _ = writeln!(u, "    <origin xyz=\"{}\" rpy=\"0 0 0\"/>", xyz(tip.point));
    let _ = writeln!(u, "  </joint>");
    let _ = writeln!(u, "  <link name=\"{TIP_LINK}\"/>");
    let _ = writeln!(u, "</robot>");
    u
}

/// `{}` of an f64: the shortest text that reads back to the same number.
fn n(v: f64) -> String {
    // -0 prints as 0.
    if v == 0.0 { "0".to_owned() } else { format!("{v}") }
}

fn xyz(v: [f64; 3]) -> String {
    format!("{} {} {}", n(v[0]), n(v[1]), n(v[2]))
}

/// Text safe in an XML attribute.
fn attr(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::{attr, n};

    #[test]
    fn numbers_and_attributes() {
        assert_eq!(n(-0.0), "0");
        assert_eq!(n(0.25), "0.25");
        assert_eq!(attr("a<\"&>"), "a&lt;&quot;&amp;&gt;");
    }
}
