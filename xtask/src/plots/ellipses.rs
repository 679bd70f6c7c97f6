//! Fig. 6 (E4): the deformation ellipsoids of the cases (a)–(d), SVG.

use std::path::Path;

use nalgebra::{Matrix2, Matrix3};
use plotters::prelude::*;
use sinew::paper::{E4, E4Case, fixed};

use super::axes::Axes;
use super::layout::{Layout, Rect, Target, register_font};
use super::legend::Legend;
use crate::DynResult;

/// Side of one panel, pixels.
const PANEL: i32 = 400;
/// The colour of the marker rectangle that stands for a panel's ellipses in plotters' SVG.
const MARKER: RGBColor = RGBColor(1, 2, 3);
/// The cases' colours, (a)–(d).
const COLOURS: [RGBColor; 4] = [BLACK, RED, BLUE, GREEN];

/// Fig. 6 (E4): the deformation ellipsoids `{K_fd⁻¹ F : |F| = 1 N}` of the cases (a)–(d),
/// projected on the base frame's xy, xz and yz planes; one row per routing model. A case
/// without an ellipsoid (unstable, infeasible) is named in the panel's legend with the reason.
/// Returns where its parts went, checked ([`Layout::check`]).
///
/// Plotters draws the axes' grid; it places points on whole pixels, so a curve made of its line
/// segments shows steps and corners. The ellipses are therefore SVG `<ellipse>` elements, exact
/// at any zoom, written where a marker stands in plotters' output (above the grid, below the
/// legend).
pub fn fig6(models: &[&E4], path: &Path) -> DynResult<Layout> {
    register_font()?;
    let planes = [("x", "y", 0usize, 1usize), ("x", "z", 0, 2), ("y", "z", 1, 2)];
    let rows = models.len().max(1) as i32;
    let size = (3 * PANEL as u32, (rows * PANEL) as u32);
    let mut layout = Layout::new(Target::Svg, size);
    let mut svg = String::new();
    // Per panel, in drawing order: its ellipses as SVG elements.
    let mut panels: Vec<String> = Vec::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE)?;
        for (r, e4) in models.iter().enumerate() {
            // Each case's projected ellipse on each plane: the 2 × 2 block `M` of `A Aᵀ`
            // (`A = K_fd⁻¹`), the outline `{x : xᵀ M⁻¹ x = 1}`, whose extent along each axis
            // is the square root of that diagonal entry of `M`.
            let mut blocks: Vec<Vec<Option<Matrix2<f64>>>> = vec![Vec::new(); 3];
            let mut extent: f64 = 1e-9;
            for case in &e4.cases {
                let Some((k_fd, _)) = &case.k_fd else {
                    for b in blocks.iter_mut() {
                        b.push(None);
                    }
                    continue;
                };
                let a: Matrix3<f64> = k_fd.try_inverse().unwrap_or_else(Matrix3::zeros);
                let a2 = a * a.transpose();
                for (p, &(_, _, i, j)) in planes.iter().enumerate() {
                    let m = Matrix2::new(a2[(i, i)], a2[(i, j)], a2[(j, i)], a2[(j, j)]);
                    extent = extent.max(m[(0, 0)].max(0.0).sqrt()).max(m[(1, 1)].max(0.0).sqrt());
                    blocks[p].push(Some(m));
                }
            }
            let extent = extent * 1.1;
            let title_of = |h: &str, v: &str| {
                format!("{}, baseline {}: {h}{v} projection", e4.model, fixed(e4.baseline, 2))
            };
            for (p, &(h, v, _, _)) in planes.iter().enumerate() {
                let (title, x_desc, y_desc) =
                    (title_of(h, v), format!("d{h} per unit force (m/N)"), format!("d{v} (m/N)"));
                let axes = Axes {
                    title: Some(&title),
                    x_desc: &x_desc,
                    y_desc: &y_desc,
                    x: (-extent, extent),
                    y: (-extent, extent),
                    ticks: (6, 6),
                    grid: true,
                    size: 12.0,
                };
                // A square plotting area, so that an ellipse keeps its shape.
                let m = axes.margins(layout.target)?;
                let (left, top) = (p as i32 * PANEL, r as i32 * PANEL);
                let side = (PANEL - m.left - m.right).min(PANEL - m.top - m.bottom);
                let plot = Rect::sized(left + m.left, top + m.top, side, side);
                let chart = axes.draw(&root, plot, &mut layout)?;
                root.draw(&Rectangle::new([(0, 0), (1, 1)], MARKER.filled()))?;
                // Pixels per unit on each axis; the pixel y axis points down.
                let (xs, ys) = chart.plotting_area().get_pixel_range();
                let (sx, sy) = (
                    f64::from(xs.end - xs.start) / (2.0 * extent),
                    f64::from(ys.end - ys.start) / (2.0 * extent),
                );
                let centre = chart.backend_coord(&(0.0, 0.0));
                let d = Matrix2::new(sx, 0.0, 0.0, -sy);
                let mut elements = String::new();
                let mut curves = Vec::new();
                let mut legend = Legend::default();
                for (c, m) in blocks[p].iter().enumerate() {
                    let Some(m) = m else { continue };
                    let colour = COLOURS[c % COLOURS.len()];
                    let m = d * m * d;
                    elements.push_str(&svg_ellipse(&m, centre, colour));
                    curves.push(ellipse_outline(&m, centre));
                    legend.entry(case_label(&e4.cases[c]), colour);
                }
                // On two rows (`(a)–(c) unstable:`, `no ellipsoid`): a narrower box fits
                // beside the ellipses.
                for note in missing(&e4.cases) {
                    note.split_inclusive(": ").for_each(|row| legend.note(row.trim_end()));
                }
                panels.push(elements);
                let at = legend.place(plot, &curves, layout.target)?;
                legend.draw(&root, at, &mut layout)?;
                layout.curves.extend(curves);
            }
        }
        root.present()?;
    }
    let mut panels = panels.into_iter();
    let marker = format!("fill=\"{}\"", hex(MARKER));
    let mut out = String::with_capacity(svg.len());
    for line in svg.lines() {
        if line.contains(&marker) {
            out.push_str(&panels.next().unwrap_or_default());
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    std::fs::write(path, out)?;
    layout.check("Fig. 6")
}

/// A case's short name, `(a)`.
fn case_label(case: &E4Case) -> String {
    case.name.split(' ').next().unwrap_or("").to_owned()
}

/// The legend's notes for the cases without an ellipsoid, one per reason (the first word of
/// the case's failure: `unstable`, `infeasible`), e.g. `(a)–(c) unstable: no ellipsoid`.
fn missing(cases: &[E4Case]) -> Vec<String> {
    let mut reasons: Vec<(String, Vec<usize>)> = Vec::new();
    for (k, case) in cases.iter().enumerate().filter(|(_, c)| c.k_fd.is_none()) {
        let failure = case.failure.as_deref().unwrap_or("no result");
        let reason = failure.split([' ', ':']).next().unwrap_or(failure).to_owned();
        match reasons.iter_mut().find(|(r, _)| *r == reason) {
            Some((_, ks)) => ks.push(k),
            None => reasons.push((reason, vec![k])),
        }
    }
    reasons
        .into_iter()
        .map(|(reason, ks)| {
            let consecutive = ks.windows(2).all(|w| w[1] == w[0] + 1);
            let names = match (ks.first(), ks.last()) {
                (Some(&a), Some(&b)) if consecutive && ks.len() >= 3 => {
                    format!("{}–{}", case_label(&cases[a]), case_label(&cases[b]))
                }
                _ => ks.iter().map(|&k| case_label(&cases[k])).collect::<Vec<_>>().join(", "),
            };
            format!("{names} {reason}: no ellipsoid")
        })
        .collect()
}

fn hex(c: RGBColor) -> String {
    format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
}

/// The semi-axes and the angle (rad, of the first semi-axis from the pixel x axis) of the
/// ellipse `{x : xᵀ M⁻¹ x = 1}`: the square roots of `M`'s eigenvalues, the angle of the larger
/// one's eigenvector.
fn semi_axes(m: &Matrix2<f64>) -> (f64, f64, f64) {
    let (a, b, d) = (m[(0, 0)], 0.5 * (m[(0, 1)] + m[(1, 0)]), m[(1, 1)]);
    let mean = 0.5 * (a + d);
    let radius = (0.25 * (a - d).powi(2) + b * b).sqrt();
    let (rx, ry) = ((mean + radius).max(0.0).sqrt(), (mean - radius).max(0.0).sqrt());
    (rx, ry, 0.5 * (2.0 * b).atan2(a - d))
}

/// The ellipse `{x : xᵀ M⁻¹ x = 1}` around `centre`, `M` in pixels² (y down), as an SVG
/// element, rotated by the angle of [`semi_axes`].
fn svg_ellipse(m: &Matrix2<f64>, centre: (i32, i32), colour: RGBColor) -> String {
    let (rx, ry, angle) = semi_axes(m);
    let (cx, cy) = centre;
    format!(
        "<ellipse cx=\"{cx}\" cy=\"{cy}\" rx=\"{rx:.3}\" ry=\"{ry:.3}\" transform=\"rotate({}, {cx}, {cy})\" fill=\"none\" stroke=\"{}\" stroke-width=\"2\"/>\n",
        fixed(angle.to_degrees(), 4),
        hex(colour)
    )
}

/// Points on the outline of [`svg_ellipse`]'s ellipse, one per degree, closed (for the legend's
/// placement and the layout's check).
fn ellipse_outline(m: &Matrix2<f64>, (cx, cy): (i32, i32)) -> Vec<(i32, i32)> {
    let (rx, ry, angle) = semi_axes(m);
    let (c, s) = (angle.cos(), angle.sin());
    (0..=360)
        .map(|k| {
            let t = f64::from(k).to_radians();
            let (u, v) = (rx * t.cos(), ry * t.sin());
            let x = f64::from(cx) + c * u - s * v;
            let y = f64::from(cy) + s * u + c * v;
            (x.round() as i32, y.round() as i32)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_svg_ellipse_has_the_eigen_axes_of_its_matrix() {
        let axis_aligned = svg_ellipse(&Matrix2::new(9.0, 0.0, 0.0, 4.0), (10, 20), RED);
        assert_eq!(
            axis_aligned,
            "<ellipse cx=\"10\" cy=\"20\" rx=\"3.000\" ry=\"2.000\" transform=\"rotate(0.0000, 10, 20)\" fill=\"none\" stroke=\"#FF0000\" stroke-width=\"2\"/>\n"
        );
        // R diag(9, 4) Rᵀ with R a rotation by 30°.
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let r = Matrix2::new(c, -s, s, c);
        let m = r * Matrix2::new(9.0, 0.0, 0.0, 4.0) * r.transpose();
        let rotated = svg_ellipse(&m, (0, 0), BLUE);
        assert!(rotated.contains("rx=\"3.000\" ry=\"2.000\" transform=\"rotate(30.0000, 0, 0)\""));
    }

    #[test]
    fn the_outline_lies_on_the_ellipse_the_svg_draws() {
        // A 100 × 40 pixel ellipse turned by 30°: its points satisfy xᵀ M⁻¹ x = 1 to a pixel.
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let r = Matrix2::new(c, -s, s, c);
        let m = r * Matrix2::new(100.0 * 100.0, 0.0, 0.0, 40.0 * 40.0) * r.transpose();
        let inverse = m.try_inverse().unwrap_or_else(Matrix2::zeros);
        let outline = ellipse_outline(&m, (200, 100));
        assert_eq!(outline.first(), outline.last());
        for (x, y) in outline {
            let p = nalgebra::Vector2::new(f64::from(x - 200), f64::from(y - 100));
            let q = (p.transpose() * inverse * p)[(0, 0)].sqrt();
            assert!((q - 1.0).abs() < 0.03, "({x}, {y}): {q}");
        }
    }

    #[test]
    fn cases_without_an_ellipsoid_are_named_with_their_reason() {
        let case = |name: &'static str, failure: Option<&str>| E4Case {
            name,
            levels: [0.0; 5],
            margin: None,
            k_fd: None,
            failure: failure.map(str::to_owned),
        };
        let unstable = Some("unstable equilibrium: K_q + K_W has the eigenvalue -0.1 N m/rad");
        let mut cases = vec![
            case("(a) every joint at the baseline level", unstable),
            case("(b) joint 3 at its highest level", unstable),
            case("(c) joint 5 at its highest level", unstable),
            case("(d) joints 3 and 5 at their highest levels", Some("infeasible: no tensions")),
        ];
        assert_eq!(
            missing(&cases),
            ["(a)–(c) unstable: no ellipsoid", "(d) infeasible: no ellipsoid"]
        );
        cases.remove(1);
        assert_eq!(missing(&cases)[0], "(a), (c) unstable: no ellipsoid");
    }
}
