//! The report's figures, drawn with plotters as SVG.

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

/// One heat map of Fig. 5 with its colour bar: `value(cell)` over `q1` (x) and `q2` (y).
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
    let colour = |v: f64| ViridisRGB::get_color_normalized(v, lo, hi);

    let root = SVGBackend::new(path, (680, 540)).into_drawing_area();
    root.fill(&WHITE)?;
    let (main, bar) = root.split_horizontally(540);
    let (g0, g1) = (maps.grid.lower, maps.grid.upper);
    let step = (g1 - g0) / (n - 1) as f64;
    let mut chart = ChartBuilder::on(&main)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(55)
        .build_cartesian_2d(
            (g0 - step / 2.0)..(g1 + step / 2.0),
            (g0 - step / 2.0)..(g1 + step / 2.0),
        )?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("q1 (rad)")
        .y_desc("q2 (rad)")
        .x_label_formatter(&|v| fixed(*v, 2))
        .y_label_formatter(&|v| fixed(*v, 2))
        .label_style(("sans-serif", 14))
        .draw()?;
    chart.draw_series((0..n).flat_map(|a| (0..n).map(move |b| (a, b))).map(|(a, b)| {
        let (x, y) = (maps.grid.angle(a), maps.grid.angle(b));
        let fill = match values[a * n + b] {
            Some(v) => colour(v).filled(),
            None => RGBColor(200, 200, 200).filled(),
        };
        Rectangle::new([(x - step / 2.0, y - step / 2.0), (x + step / 2.0, y + step / 2.0)], fill)
    }))?;

    let mut bar_chart = ChartBuilder::on(&bar)
        .margin_top(20)
        .margin_bottom(57)
        .margin_right(10)
        .y_label_area_size(60)
        .caption("N m/rad", ("sans-serif", 15))
        .build_cartesian_2d(0.0..1.0, lo..hi)?;
    bar_chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_label_formatter(&|v| fixed(*v, 1))
        .label_style(("sans-serif", 14))
        .draw()?;
    let levels = 100;
    bar_chart.draw_series((0..levels).map(|k| {
        let v0 = lo + (hi - lo) * k as f64 / levels as f64;
        let v1 = lo + (hi - lo) * (k + 1) as f64 / levels as f64;
        Rectangle::new([(0.0, v0), (1.0, v1)], colour(0.5 * (v0 + v1)).filled())
    }))?;
    root.present()?;
    Ok(())
}

/// Fig. 6 (E4): the deformation ellipsoids `{K_fd⁻¹ F : |F| = 1 N}` of the cases (a)–(d),
/// projected on the base frame's xy, xz and yz planes; one row per routing model.
pub fn fig6(models: &[&sinew::paper::E4], path: &Path) -> DynResult<()> {
    use nalgebra::{Matrix2, Matrix3};
    let rows = models.len().max(1);
    let root = SVGBackend::new(path, (1200, 400 * rows as u32)).into_drawing_area();
    root.fill(&WHITE)?;
    let areas = root.split_evenly((rows, 3));
    let planes = [("x", "y", 0usize, 1usize), ("x", "z", 0, 2), ("y", "z", 1, 2)];
    let colours = [BLACK, RED, BLUE, GREEN];
    for (r, e4) in models.iter().enumerate() {
        // Each case's projected outline on each plane.
        let mut outlines: Vec<Vec<Vec<(f64, f64)>>> = vec![Vec::new(); 3];
        let mut extent: f64 = 1e-9;
        for case in &e4.cases {
            let Some((k_fd, _)) = &case.k_fd else {
                for o in outlines.iter_mut() {
                    o.push(Vec::new());
                }
                continue;
            };
            let a: Matrix3<f64> = k_fd.try_inverse().unwrap_or_else(Matrix3::zeros);
            let a2 = a * a.transpose();
            for (p, &(_, _, i, j)) in planes.iter().enumerate() {
                let m = Matrix2::new(a2[(i, i)], a2[(i, j)], a2[(j, i)], a2[(j, j)]);
                let l = m.cholesky().map(|c| c.l()).unwrap_or_else(Matrix2::zeros);
                let pts: Vec<(f64, f64)> = (0..=120)
                    .map(|k| {
                        let t = std::f64::consts::TAU * k as f64 / 120.0;
                        let v = l * nalgebra::Vector2::new(t.cos(), t.sin());
                        extent = extent.max(v[0].abs()).max(v[1].abs());
                        (v[0], v[1])
                    })
                    .collect();
                outlines[p].push(pts);
            }
        }
        let extent = extent * 1.1;
        for (p, &(h, v, _, _)) in planes.iter().enumerate() {
            let area = &areas[r * 3 + p];
            let mut chart = ChartBuilder::on(area)
                .caption(
                    format!("{}, baseline {}: {h}{v} projection", e4.model, fixed(e4.baseline, 2)),
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
            for (c, pts) in outlines[p].iter().enumerate() {
                if pts.is_empty() {
                    continue;
                }
                let colour = colours[c % colours.len()];
                let label = e4.cases[c].name.split(' ').next().unwrap_or("").to_owned();
                chart
                    .draw_series(LineSeries::new(pts.iter().copied(), colour.stroke_width(2)))?
                    .label(label)
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                    });
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperLeft)
                .border_style(BLACK)
                .background_style(WHITE)
                .draw()?;
        }
    }
    root.present()?;
    Ok(())
}
