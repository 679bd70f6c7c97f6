//! The report's figures: the line plots (Fig. 4, Fig. 6) drawn with plotters as SVG, the heat
//! maps of Fig. 5 as PNG.

use std::path::Path;

use plotters::prelude::*;
use sinew::indicators::SweepMaps;
use sinew::paper::{E2Point, fixed};

use crate::DynResult;

/// Fig. 4 (E2): the three tensions, and `K_x`, `K_y`, against cable 1's tension.
pub fn fig4(points: &[E2Point], path: &Path) -> DynResult<()> {
    let root = SVGBackend::new(path, (1100, 450)).into_drawing_area();
    root.fill(&WHITE)?;
    let (left, right) = root.split_horizontally(550);
    let x0 = points.first().map_or(0.0, |p| p.tensions[0]);
    let x1 = points.last().map_or(1.0, |p| p.tensions[0]);
    let f_max = points.iter().flat_map(|p| p.tensions).fold(0.0_f64, f64::max) * 1.05;
    let mut chart = ChartBuilder::on(&left)
        .caption("(a) cable tensions along the feasible segment", ("sans-serif", 18))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, 0.0..f_max)?;
    chart.configure_mesh().x_desc("tension of cable 1, f1 (N)").y_desc("tension (N)").draw()?;
    let colours = [RED, BLUE, GREEN];
    for k in 0..3 {
        let colour = colours[k];
        chart
            .draw_series(LineSeries::new(
                points.iter().map(|p| (p.tensions[0], p.tensions[k])),
                colour.stroke_width(2),
            ))?
            .label(format!("f{}", k + 1))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
    }
    chart.configure_series_labels().border_style(BLACK).background_style(WHITE).draw()?;

    let k_lo = points.iter().flat_map(|p| [p.k_x, p.k_y]).fold(f64::INFINITY, f64::min);
    let k_hi = points.iter().flat_map(|p| [p.k_x, p.k_y]).fold(f64::NEG_INFINITY, f64::max);
    let pad = 0.05 * (k_hi - k_lo).max(1e-6);
    let mut chart = ChartBuilder::on(&right)
        .caption("(b) joint stiffness along the feasible segment", ("sans-serif", 18))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, (k_lo - pad)..(k_hi + pad))?;
    chart
        .configure_mesh()
        .x_desc("tension of cable 1, f1 (N)")
        .y_desc("stiffness (N m/rad)")
        .draw()?;
    for (label, colour, pick) in [("K_x", RED, 0usize), ("K_y", BLUE, 1usize)] {
        chart
            .draw_series(LineSeries::new(
                points.iter().map(move |p| (p.tensions[0], if pick == 0 { p.k_x } else { p.k_y })),
                colour.stroke_width(2),
            ))?
            .label(label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
    }
    chart.configure_series_labels().border_style(BLACK).background_style(WHITE).draw()?;
    root.present()?;
    Ok(())
}

/// E5: the best `λ_min(K_fd)` against the tension budget, one line per model.
pub fn fig_e5(runs: &[&sinew::paper::E5], path: &Path) -> DynResult<()> {
    let root = SVGBackend::new(path, (700, 450)).into_drawing_area();
    root.fill(&WHITE)?;
    let points = runs.iter().flat_map(|e| e.tradeoff.iter());
    let (mut b0, mut b1, mut v1) = (f64::INFINITY, f64::NEG_INFINITY, 0.0_f64);
    for &(b, v, _) in points {
        (b0, b1, v1) = (b0.min(b), b1.max(b), v1.max(v));
    }
    let mut chart = ChartBuilder::on(&root)
        .caption("E5: the stiffest softest direction for a tension budget", ("sans-serif", 18))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(b0..b1, 0.0..v1 * 1.1)?;
    chart
        .configure_mesh()
        .x_desc("tension budget Σf (N)")
        .y_desc("best λ_min(K_fd) (N/m)")
        .draw()?;
    for (e, colour) in runs.iter().zip([RED, BLUE]) {
        chart
            .draw_series(LineSeries::new(
                e.tradeoff.iter().map(|&(b, v, _)| (b, v)),
                colour.stroke_width(2),
            ))?
            .label(e.model.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        chart.draw_series(
            e.tradeoff.iter().map(|&(b, v, _)| Circle::new((b, v), 3, colour.filled())),
        )?;
    }
    chart.configure_series_labels().border_style(BLACK).background_style(WHITE).draw()?;
    root.present()?;
    Ok(())
}

/// One heat map of Fig. 5 with its colour bar, `value(cell)` over `q1` (x) and `q2` (y), as a
/// PNG drawn pixel by pixel: each grid cell a [`CELL`] × [`CELL`] square (grey where the
/// torque cannot be held), the axes with ticks, and the text in an 8 × 8 bitmap font (the
/// `font8x8` crate's data) at twice its size. No system font is read, so the file is the same
/// bytes on every machine.
pub fn heat_map(
    maps: &SweepMaps,
    title: &str,
    value: impl Fn(&sinew::indicators::SweepCell) -> f64,
    path: &Path,
) -> DynResult<()> {
    let n = maps.grid.points;
    let values: Vec<Option<f64>> = maps.cells.iter().map(|c| c.as_ref().map(&value)).collect();
    let lo = values.iter().flatten().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().flatten().copied().fold(f64::NEG_INFINITY, f64::max);
    let (lo, hi) = if lo.is_finite() && hi > lo { (lo, hi) } else { (0.0, 1.0) };
    let colour = |v: f64| {
        let c = ViridisRGB::get_color_normalized(v, lo, hi);
        [c.0, c.1, c.2]
    };

    // Layout, pixels: the map's left and top edges, its side, the colour bar's left edge.
    let side = n * CELL;
    let (left, top) = (136, 64);
    let bar = left + side + 40;
    let width = (bar + BAR_WIDTH + 110).max(title.chars().count() * GLYPH + 16);
    let mut img = Canvas::new(width, top + side + 76);

    for a in 0..n {
        for b in 0..n {
            let rgb = values[a * n + b].map_or(INFEASIBLE, colour);
            // q2 grows upwards: row b counted from the bottom.
            img.fill(left + a * CELL, top + (n - 1 - b) * CELL, CELL, CELL, rgb);
        }
    }
    for y in 0..side {
        let v = lo + (hi - lo) * (side - 1 - y) as f64 / (side - 1) as f64;
        img.fill(bar, top + y, BAR_WIDTH, 1, colour(v));
    }
    img.frame(left, top, side, side);
    img.frame(bar, top, BAR_WIDTH, side);

    // Axes: the cells are centred on the grid angles, so the map spans half a step more.
    let (g0, g1) = (maps.grid.lower, maps.grid.upper);
    let step = (g1 - g0) / (n - 1) as f64;
    let (q0, q1) = (g0 - step / 2.0, g1 + step / 2.0);
    let to_pixel = |q: f64| ((q - q0) / (q1 - q0) * side as f64).round() as usize;
    let (ticks, decimals) = nice_ticks(q0, q1, 6);
    for q in ticks {
        let label = fixed(q, decimals);
        let x = left + to_pixel(q).min(side - 1);
        img.fill(x, top + side, 1, TICK, BLACK_RGB);
        img.text(x.saturating_sub(img.width_of(&label) / 2), top + side + TICK + 4, &label);
        let y = top + side - to_pixel(q).max(1);
        img.fill(left - TICK, y, TICK, 1, BLACK_RGB);
        let x = (left - TICK - 4).saturating_sub(img.width_of(&label));
        img.text(x, y.saturating_sub(GLYPH / 2), &label);
    }
    let x_title = "q1 (rad)";
    let x = (left + side / 2).saturating_sub(img.width_of(x_title) / 2);
    img.text(x, top + side + TICK + GLYPH + 14, x_title);
    let y_title = "q2 (rad)";
    img.text_upwards(left - 116, top + (side + img.width_of(y_title)) / 2, y_title);
    let (ticks, decimals) = nice_ticks(lo, hi, 6);
    for v in ticks {
        let y = top + side - 1 - ((v - lo) / (hi - lo) * (side - 1) as f64).round() as usize;
        img.fill(bar + BAR_WIDTH, y, TICK, 1, BLACK_RGB);
        img.text(bar + BAR_WIDTH + TICK + 4, y.saturating_sub(GLYPH / 2), &fixed(v, decimals));
    }
    let unit = "N m/rad";
    img.text((bar + BAR_WIDTH / 2).saturating_sub(img.width_of(unit) / 2), top - GLYPH - 8, unit);
    img.text(img.width.saturating_sub(img.width_of(title)) / 2, 12, title);
    img.write_png(path)
}

/// Side of one grid cell of a heat map, pixels.
const CELL: usize = 4;
/// Width of the colour bar, pixels.
const BAR_WIDTH: usize = 24;
/// Length of a tick mark, pixels.
const TICK: usize = 6;
/// The font's scale: each of its 8 × 8 dots is a `SCALE` × `SCALE` square.
const SCALE: usize = 2;
/// Height (and advance) of one character, pixels.
const GLYPH: usize = 8 * SCALE;
/// Grey of the cells where the torque cannot be held.
const INFEASIBLE: [u8; 3] = [200, 200, 200];
const BLACK_RGB: [u8; 3] = [0, 0, 0];

/// About `count` round tick values (1, 2 or 5 times a power of ten apart) in `[lo, hi]`, and
/// the decimals their labels need. The power of ten is an integer exponent, so that the
/// decimals do not hang on the last bit of a logarithm.
fn nice_ticks(lo: f64, hi: f64, count: usize) -> (Vec<f64>, usize) {
    let raw = (hi - lo) / count as f64;
    let mut exponent = raw.log10().floor() as i32;
    let mut mantissa =
        [1.0, 2.0, 5.0, 10.0].into_iter().find(|m| m * 10f64.powi(exponent) >= raw).unwrap_or(10.0);
    if mantissa == 10.0 {
        (mantissa, exponent) = (1.0, exponent + 1);
    }
    let step = mantissa * 10f64.powi(exponent);
    let decimals = usize::try_from(-exponent).unwrap_or(0);
    let (first, last) = ((lo / step).ceil() as i64, (hi / step).floor() as i64);
    ((first..=last).map(|k| k as f64 * step).collect(), decimals)
}

/// An RGB image on a white background, drawn pixel by pixel.
struct Canvas {
    width: usize,
    height: usize,
    rgb: Vec<u8>,
}

impl Canvas {
    fn new(width: usize, height: usize) -> Canvas {
        Canvas { width, height, rgb: vec![255; 3 * width * height] }
    }

    /// Fill the `w` × `h` rectangle whose top-left pixel is `(x, y)`; clipped to the image.
    fn fill(&mut self, x: usize, y: usize, w: usize, h: usize, rgb: [u8; 3]) {
        for row in y..(y + h).min(self.height) {
            for col in x..(x + w).min(self.width) {
                let k = 3 * (row * self.width + col);
                self.rgb[k..k + 3].copy_from_slice(&rgb);
            }
        }
    }

    /// A one-pixel black frame just outside the `w` × `h` rectangle at `(x, y)`.
    fn frame(&mut self, x: usize, y: usize, w: usize, h: usize) {
        self.fill(x - 1, y - 1, w + 2, 1, BLACK_RGB);
        self.fill(x - 1, y + h, w + 2, 1, BLACK_RGB);
        self.fill(x - 1, y - 1, 1, h + 2, BLACK_RGB);
        self.fill(x + w, y - 1, 1, h + 2, BLACK_RGB);
    }

    fn width_of(&self, text: &str) -> usize {
        text.chars().count() * GLYPH
    }

    /// The dots of `ch` (ASCII; anything else as `?`): `(column, row)` from the top left.
    fn dots(ch: char) -> impl Iterator<Item = (usize, usize)> {
        let glyph =
            font8x8::legacy::BASIC_LEGACY[if ch.is_ascii() { ch as usize } else { b'?' as usize }];
        (0..8).flat_map(move |row| {
            (0..8).filter(move |col| glyph[row] & (1 << col) != 0).map(move |col| (col, row))
        })
    }

    /// `text` in black, left to right, its top-left corner at `(x, y)`.
    fn text(&mut self, x: usize, y: usize, text: &str) {
        for (k, ch) in text.chars().enumerate() {
            for (col, row) in Self::dots(ch) {
                self.fill(x + k * GLYPH + col * SCALE, y + row * SCALE, SCALE, SCALE, BLACK_RGB);
            }
        }
    }

    /// `text` in black, bottom to top (turned a quarter left), starting at `(x, bottom)`.
    fn text_upwards(&mut self, x: usize, bottom: usize, text: &str) {
        for (k, ch) in text.chars().enumerate() {
            for (col, row) in Self::dots(ch) {
                if let Some(y) = bottom.checked_sub(k * GLYPH + (col + 1) * SCALE) {
                    self.fill(x + row * SCALE, y, SCALE, SCALE, BLACK_RGB);
                }
            }
        }
    }

    /// Write the image as an 8-bit RGB PNG.
    fn write_png(&self, path: &Path) -> DynResult<()> {
        let file = std::io::BufWriter::new(std::fs::File::create(path)?);
        let mut encoder =
            png::Encoder::new(file, u32::try_from(self.width)?, u32::try_from(self.height)?);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::High);
        let mut writer = encoder.write_header()?;
        writer.write_image_data(&self.rgb)?;
        writer.finish()?;
        Ok(())
    }
}

/// Fig. 6 (E4): the deformation ellipsoids `{K_fd⁻¹ F : |F| = 1 N}` of the cases (a)–(d),
/// projected on the base frame's xy, xz and yz planes; one row per routing model.
///
/// Plotters draws the axes and legends; it places points on whole pixels, so a curve made of
/// its line segments shows steps and corners. The ellipses are therefore SVG `<ellipse>`
/// elements, exact at any zoom, written where a marker stands in plotters' output (above the
/// grid, below the legend).
pub fn fig6(models: &[&sinew::paper::E4], path: &Path) -> DynResult<()> {
    use nalgebra::{Matrix2, Matrix3};
    let rows = models.len().max(1);
    let planes = [("x", "y", 0usize, 1usize), ("x", "z", 0, 2), ("y", "z", 1, 2)];
    let colours = [BLACK, RED, BLUE, GREEN];
    let mut svg = String::new();
    // Per panel, in drawing order: its ellipses as SVG elements.
    let mut panels: Vec<String> = Vec::new();
    {
        let root = SVGBackend::with_string(&mut svg, (1200, 400 * rows as u32)).into_drawing_area();
        root.fill(&WHITE)?;
        let areas = root.split_evenly((rows, 3));
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
            for (p, &(h, v, _, _)) in planes.iter().enumerate() {
                let area = &areas[r * 3 + p];
                let mut chart = ChartBuilder::on(area)
                    .caption(
                        format!(
                            "{}, baseline {}: {h}{v} projection",
                            e4.model,
                            fixed(e4.baseline, 2)
                        ),
                        ("sans-serif", 16),
                    )
                    .margin(10)
                    .x_label_area_size(40)
                    .y_label_area_size(55)
                    .build_cartesian_2d(-extent..extent, -extent..extent)?;
                chart
                    .configure_mesh()
                    .x_desc(format!("d{h} per unit force (m/N)"))
                    .y_desc(format!("d{v} (m/N)"))
                    .x_labels(6)
                    .y_labels(6)
                    .x_label_formatter(&|x| fixed(*x, 3))
                    .y_label_formatter(&|y| fixed(*y, 3))
                    .draw()?;
                root.draw(&Rectangle::new([(0, 0), (1, 1)], MARKER.filled()))?;
                // Pixels per unit on each axis; the pixel y axis points down.
                let (xs, ys) = chart.plotting_area().get_pixel_range();
                let (sx, sy) = (
                    f64::from(xs.end - xs.start) / (2.0 * extent),
                    f64::from(ys.end - ys.start) / (2.0 * extent),
                );
                let (cx, cy) = chart.backend_coord(&(0.0, 0.0));
                let mut elements = String::new();
                for (c, m) in blocks[p].iter().enumerate() {
                    let Some(m) = m else { continue };
                    let colour = colours[c % colours.len()];
                    let d = Matrix2::new(sx, 0.0, 0.0, -sy);
                    elements.push_str(&svg_ellipse(&(d * m * d), (cx, cy), colour));
                    let label = e4.cases[c].name.split(' ').next().unwrap_or("").to_owned();
                    chart
                        .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())?
                        .label(label)
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                        });
                }
                panels.push(elements);
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperLeft)
                    .border_style(BLACK)
                    .background_style(WHITE)
                    .draw()?;
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
    Ok(())
}

/// The colour of the marker rectangle that stands for a panel's ellipses in plotters' SVG.
const MARKER: RGBColor = RGBColor(1, 2, 3);

fn hex(c: RGBColor) -> String {
    format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
}

/// The ellipse `{x : xᵀ M⁻¹ x = 1}` around `centre`, `M` in pixels² (y down), as an SVG
/// element: its semi-axes are the square roots of `M`'s eigenvalues, rotated by the angle of
/// the larger one's eigenvector.
fn svg_ellipse(m: &nalgebra::Matrix2<f64>, centre: (i32, i32), colour: RGBColor) -> String {
    let (a, b, d) = (m[(0, 0)], 0.5 * (m[(0, 1)] + m[(1, 0)]), m[(1, 1)]);
    let mean = 0.5 * (a + d);
    let radius = (0.25 * (a - d).powi(2) + b * b).sqrt();
    let (rx, ry) = ((mean + radius).max(0.0).sqrt(), (mean - radius).max(0.0).sqrt());
    let angle = 0.5 * (2.0 * b).atan2(a - d);
    let (cx, cy) = centre;
    format!(
        "<ellipse cx=\"{cx}\" cy=\"{cy}\" rx=\"{rx:.3}\" ry=\"{ry:.3}\" transform=\"rotate({}, {cx}, {cy})\" fill=\"none\" stroke=\"{}\" stroke-width=\"2\"/>\n",
        fixed(angle.to_degrees(), 4),
        hex(colour)
    )
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn ticks_are_round_and_inside_the_range() {
        let (ticks, decimals) = nice_ticks(-0.5454, 0.5454, 6);
        let labels: Vec<String> = ticks.iter().map(|t| fixed(*t, decimals)).collect();
        assert_eq!(labels, ["-0.4", "-0.2", "0.0", "0.2", "0.4"]);
        let (ticks, decimals) = nice_ticks(1.93, 16.3, 6);
        assert_eq!((ticks, decimals), (vec![5.0, 10.0, 15.0], 0));
    }

    #[test]
    fn an_svg_ellipse_has_the_eigen_axes_of_its_matrix() {
        let axis_aligned = svg_ellipse(&nalgebra::Matrix2::new(9.0, 0.0, 0.0, 4.0), (10, 20), RED);
        assert_eq!(
            axis_aligned,
            "<ellipse cx=\"10\" cy=\"20\" rx=\"3.000\" ry=\"2.000\" transform=\"rotate(0.0000, 10, 20)\" fill=\"none\" stroke=\"#FF0000\" stroke-width=\"2\"/>\n"
        );
        // R diag(9, 4) Rᵀ with R a rotation by 30°.
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let r = nalgebra::Matrix2::new(c, -s, s, c);
        let m = r * nalgebra::Matrix2::new(9.0, 0.0, 0.0, 4.0) * r.transpose();
        let rotated = svg_ellipse(&m, (0, 0), BLUE);
        assert!(rotated.contains("rx=\"3.000\" ry=\"2.000\" transform=\"rotate(30.0000, 0, 0)\""));
    }

    #[test]
    fn a_png_heat_map_is_the_same_bytes_twice() {
        let maps = SweepMaps {
            joint: 0,
            torque: [0.0; 2],
            grid: sinew::indicators::AngleGrid { lower: -0.5, upper: 0.5, points: 3 },
            cells: vec![None; 9],
        };
        let dir = std::env::temp_dir().join(format!("sinew-heat-map-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (a, b) = (dir.join("a.png"), dir.join("b.png"));
        heat_map(&maps, "t", |c| c.k_x.range[0], &a).unwrap();
        heat_map(&maps, "t", |c| c.k_x.range[0], &b).unwrap();
        let bytes = std::fs::read(&a).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        assert_eq!(bytes, std::fs::read(&b).unwrap());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
