//! The line plots: Fig. 4 (E2), E5's trade-off and E6's λ_min against μ, SVG.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use sinew::paper::{E2Point, E5, E6, E6_REGIMES, regime_label};
use sinew::stiffness::FrictionRegime;

use super::axes::Axes;
use super::layout::{Layout, Rect, Target, register_font};
use super::legend::Legend;
use crate::DynResult;

/// One curve of a panel.
#[derive(Debug, Clone)]
struct Series {
    label: String,
    colour: RGBColor,
    points: Vec<(f64, f64)>,
    /// A dot at each point (the planner's budgets), not only the line through them.
    dots: bool,
}

/// Draw `axes` in the panel `area` (pixels of `root`) with `series` and their legend where no
/// curve is.
fn panel<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    area: Rect,
    axes: &Axes<'_>,
    series: &[Series],
    layout: &mut Layout,
) -> DynResult<()>
where
    DB::ErrorType: 'static,
{
    let m = axes.margins(layout.target)?;
    let plot = Rect {
        left: area.left + m.left,
        top: area.top + m.top,
        right: area.right - m.right,
        bottom: area.bottom - m.bottom,
    };
    let mut chart = axes.draw(root, plot, layout)?;
    let mut curves = Vec::new();
    let mut legend = Legend::default();
    for s in series {
        let style = s.colour.stroke_width(2);
        chart.draw_series(LineSeries::new(s.points.iter().copied(), style))?;
        if s.dots {
            chart.draw_series(s.points.iter().map(|&p| Circle::new(p, 3, s.colour.filled())))?;
        }
        curves.push(s.points.iter().map(|p| chart.backend_coord(p)).collect::<Vec<_>>());
        legend.entry(s.label.clone(), s.colour);
    }
    let at = legend.place(plot, &curves, layout.target)?;
    legend.draw(root, at, layout)?;
    layout.curves.extend(curves);
    Ok(())
}

/// The smallest and largest of `values`.
fn span(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)))
}

/// Fig. 4 (E2): the three tensions, and `K_x`, `K_y`, against cable 1's tension. Returns where
/// its parts went, checked ([`Layout::check`]).
pub fn fig4(points: &[E2Point], path: &Path) -> DynResult<Layout> {
    register_font()?;
    let size = (1100, 450);
    let mut layout = Layout::new(Target::Svg, size);
    let root = SVGBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE)?;
    let x = (
        points.first().map_or(0.0, |p| p.tensions[0]),
        points.last().map_or(1.0, |p| p.tensions[0]),
    );
    let f_max = points.iter().flat_map(|p| p.tensions).fold(0.0_f64, f64::max) * 1.05;
    let tensions: Vec<Series> = [RED, BLUE, GREEN]
        .into_iter()
        .enumerate()
        .map(|(k, colour)| Series {
            label: format!("f{}", k + 1),
            colour,
            points: points.iter().map(|p| (p.tensions[0], p.tensions[k])).collect(),
            dots: false,
        })
        .collect();
    let axes = Axes {
        title: Some("(a) cable tensions along the feasible segment"),
        x_desc: "tension of cable 1, f1 (N)",
        y_desc: "tension (N)",
        x,
        y: (0.0, f_max),
        ticks: (6, 7),
        grid: true,
        size: 13.0,
    };
    panel(&root, Rect::sized(0, 0, 550, 450), &axes, &tensions, &mut layout)?;

    let (k_lo, k_hi) = span(points.iter().flat_map(|p| [p.k_x, p.k_y]));
    let pad = 0.05 * (k_hi - k_lo).max(1e-6);
    let stiffness = [("K_x", RED, false), ("K_y", BLUE, true)].map(|(label, colour, y)| Series {
        label: label.to_owned(),
        colour,
        points: points.iter().map(|p| (p.tensions[0], if y { p.k_y } else { p.k_x })).collect(),
        dots: false,
    });
    let axes = Axes {
        title: Some("(b) joint stiffness along the feasible segment"),
        y_desc: "stiffness (N m/rad)",
        y: (k_lo - pad, k_hi + pad),
        ..axes
    };
    panel(&root, Rect::sized(550, 0, 550, 450), &axes, &stiffness, &mut layout)?;
    root.present()?;
    layout.check("Fig. 4")
}

/// E5: the best `λ_min(K_fd)` against the tension budget, one line per model. Returns where
/// its parts went, checked ([`Layout::check`]).
pub fn fig_e5(runs: &[&E5], path: &Path) -> DynResult<Layout> {
    register_font()?;
    let size = (700, 450);
    let mut layout = Layout::new(Target::Svg, size);
    let root = SVGBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE)?;
    let (b0, b1) = span(runs.iter().flat_map(|e| e.tradeoff.iter().map(|t| t.0)));
    let (_, v1) = span(runs.iter().flat_map(|e| e.tradeoff.iter().map(|t| t.1)).chain([0.0]));
    let series: Vec<Series> = runs
        .iter()
        .zip([RED, BLUE])
        .map(|(e, colour)| Series {
            label: e.model.clone(),
            colour,
            points: e.tradeoff.iter().map(|&(b, v, _)| (b, v)).collect(),
            dots: true,
        })
        .collect();
    let axes = Axes {
        title: Some("E5: the stiffest softest direction for a tension budget"),
        x_desc: "tension budget Σf (N)",
        y_desc: "best λ_min(K_fd) (N/m)",
        x: (b0, b1),
        y: (0.0, v1 * 1.1),
        ticks: (10, 8),
        grid: true,
        size: 13.0,
    };
    panel(&root, Rect::sized(0, 0, 700, 450), &axes, &series, &mut layout)?;
    root.present()?;
    layout.check("the E5 trade-off figure")
}

/// E6: `λ_min(K_fd)` against μ, one line per model and regime, the slip regimes (from the
/// frictionless arm at μ = 0) and the stick regimes in two panels (two orders of magnitude
/// apart). Returns where its parts went, checked ([`Layout::check`]).
pub fn fig_e6(e6: &E6, path: &Path) -> DynResult<Layout> {
    register_font()?;
    let size = (1100, 450);
    let mut layout = Layout::new(Target::Svg, size);
    let root = SVGBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE)?;
    let models = ["decoupled", "routed"];
    let colours = [
        [RGBColor(200, 30, 30), RGBColor(240, 130, 40), RGBColor(150, 0, 110)],
        [RGBColor(30, 60, 200), RGBColor(0, 160, 170), RGBColor(20, 130, 40)],
    ];
    let line = |model: &str, regime: FrictionRegime, colour: RGBColor| {
        let mut points: Vec<(f64, f64)> = e6
            .rows
            .iter()
            .filter(|r| r.model == model && r.regime == Some(regime))
            .filter_map(|r| r.lambda_min.map(|k| (r.mu, k)))
            .collect();
        if matches!(regime, FrictionRegime::Slip(_)) {
            let start = e6.rows.iter().find(|r| r.model == model && r.regime.is_none());
            if let Some(k) = start.and_then(|r| r.lambda_min) {
                points.insert(0, (0.0, k));
            }
        }
        Series {
            label: format!("{model}, {}", regime_label(Some(regime))),
            colour,
            points,
            dots: true,
        }
    };
    let (slip, stick): (Vec<FrictionRegime>, Vec<FrictionRegime>) =
        E6_REGIMES.iter().partition(|r| matches!(r, FrictionRegime::Slip(_)));
    let series = |regimes: &[FrictionRegime]| -> Vec<Series> {
        models
            .iter()
            .zip(&colours)
            .flat_map(|(model, colours)| {
                regimes
                    .iter()
                    .zip(colours)
                    .map(move |(&regime, &colour)| line(model, regime, colour))
            })
            .collect()
    };
    let mu_max = e6.rows.iter().map(|r| r.mu).fold(0.0, f64::max);
    let panels = [
        ("(a) slip: every hole sliding one way", series(&slip), Rect::sized(0, 0, 550, 450)),
        ("(b) stick: no hole sliding", series(&stick), Rect::sized(550, 0, 550, 450)),
    ];
    for (title, series, area) in panels {
        let (_, top) = span(series.iter().flat_map(|s| s.points.iter().map(|p| p.1)).chain([0.0]));
        let axes = Axes {
            title: Some(title),
            x_desc: "friction coefficient μ at every hole",
            y_desc: "λ_min(K_fd) (N/m)",
            x: (0.0, mu_max),
            y: (0.0, top * 1.6),
            ticks: (5, 8),
            grid: true,
            size: 13.0,
        };
        panel(&root, area, &axes, &series, &mut layout)?;
    }
    root.present()?;
    layout.check("the E6 figure")
}
