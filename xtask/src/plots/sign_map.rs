//! E7's map: the sign of the controllable stiffness `A_i` over the hole geometry (`d2` against
//! `d1`), one colour per class, as a PNG like Fig. 5's heat maps (`heat.rs`), with the closed
//! form's boundary at Q0 and the named geometries marked. The legend lists the classes the map
//! holds, with their counts, from the data.

use std::path::Path;

use plotters::prelude::*;
use sinew::paper::{E7, E7_MIN_GAP, TensionEffect, fixed};

use super::axes::Axes;
use super::heat::{CELL, INFEASIBLE, PAD, SIZE, TITLE, draw, write_png};
use super::layout::{Anchor, Layout, Rect, Target, extent, register_font, text};
use crate::DynResult;

/// Side of a legend swatch and the gap after it, pixels.
const SWATCH: i32 = 14;
const GAP: i32 = 8;
/// Distance of the legend from the map, pixels.
const LEGEND_GAP: i32 = 30;
/// Radius of a geometry's marker, pixels.
const MARKER: i32 = 5;

/// A class's colour on the map.
fn colour(class: TensionEffect) -> RGBColor {
    match class {
        TensionEffect::Stiffens => RGBColor(90, 170, 90),
        TensionEffect::Neutral => RGBColor(250, 250, 250),
        TensionEffect::Indefinite => RGBColor(240, 170, 60),
        TensionEffect::Softens => RGBColor(80, 120, 200),
    }
}

/// The words of a class on the map (the font has ≥ and ≤, not the matrix order's ⪰).
fn words(class: TensionEffect) -> &'static str {
    match class {
        TensionEffect::Stiffens => "A ≥ 0 at every pose: tension stiffens",
        TensionEffect::Neutral => "A = 0 at every pose",
        TensionEffect::Indefinite => "A indefinite at some pose",
        TensionEffect::Softens => "A ≤ 0 at every pose: tension softens",
    }
}

const CLASSES: [TensionEffect; 4] = [
    TensionEffect::Stiffens,
    TensionEffect::Neutral,
    TensionEffect::Indefinite,
    TensionEffect::Softens,
];

/// E7's map into `path`; returns where its parts went, checked ([`Layout::check`]). The first two
/// of `e7.cases` (cdhrm5 and the off-centre geometry) are marked.
pub fn fig_e7(e7: &E7, path: &Path) -> DynResult<Layout> {
    register_font()?;
    let map = &e7.map;
    let n = map.axis.len();
    let mm = |x: f64| 1e3 * x;
    let values: Vec<Option<f64>> = map
        .cells
        .iter()
        .map(|c| {
            c.map(|c| CLASSES.iter().position(|k| *k == c.workspace_class).unwrap_or(0) as f64)
        })
        .collect();
    let (lo, hi) = (mm(map.axis[0]), mm(map.axis[n - 1]));
    let half = (hi - lo) / (n.max(2) - 1) as f64 / 2.0;
    let range = (lo - half, hi + half);
    let axes = Axes {
        title: None,
        x_desc: "d1 (mm)",
        y_desc: "d2 (mm)",
        x: range,
        y: range,
        ticks: (5, 5),
        grid: false,
        size: SIZE,
    };
    let title = format!(
        "E7: sign of A = Σ N_c H_c over the workspace, r = {} mm",
        fixed(mm(map.radius), 2)
    );

    // The legend's rows, from the data: the classes present with their counts, then the rest.
    let mut rows: Vec<(String, Row)> = Vec::new();
    for class in CLASSES {
        let count = map.cells.iter().flatten().filter(|c| c.workspace_class == class).count();
        if count > 0 {
            rows.push((format!("{} ({count})", words(class)), Row::Swatch(colour(class))));
        }
    }
    let grey = map.cells.iter().filter(|c| c.is_none()).count();
    if grey > 0 {
        let label = format!("d1 + d2 < {} mm: left out ({grey})", fixed(mm(E7_MIN_GAP), 0));
        rows.push((label, Row::Swatch(INFEASIBLE)));
    }
    rows.push(("closed form at Q0: d1·d2 = 0".to_owned(), Row::Dashed));
    let marks: Vec<(f64, f64, bool)> = e7
        .cases
        .iter()
        .take(2)
        .enumerate()
        .map(|(k, c)| (mm(c.geometry.d1), mm(c.geometry.d2), k == 0))
        .collect();
    for (c, &(d1, d2, round)) in e7.cases.iter().zip(&marks) {
        let name = c.name.split(',').next().unwrap_or(&c.name);
        let name = if round { name.to_owned() } else { "off-centre (CASPR snake's planes)".into() };
        rows.push((format!("{name}: ({}, {}) mm", fixed(d1, 1), fixed(d2, 1)), Row::Marker(round)));
    }

    let target = Target::Png;
    let m = axes.margins(target)?;
    let side = i32::try_from(n)? * CELL;
    let title_height = extent(&title, TITLE, target)?.height().ceil() as i32;
    let top = PAD + title_height + 2 * PAD;
    let plot = Rect::sized(m.left, top, side, side);
    let row_height = extent("(Xy)", SIZE, target)?.height().ceil() as i32 + 6;
    let mut widest = 0;
    for (label, _) in &rows {
        widest = widest.max(extent(label, SIZE, target)?.width.ceil() as i32);
    }
    let legend_left = plot.right + 1 + LEGEND_GAP;
    let title_width = extent(&title, TITLE, target)?.width.ceil() as i32;
    let width = (legend_left + SWATCH + GAP + widest + PAD).max(title_width + 2 * PAD);
    let height = plot.bottom + 1 + m.bottom;
    let size = (u32::try_from(width)?, u32::try_from(height)?);

    let mut layout = Layout::new(target, size);
    let mut rgb = vec![0u8; 3 * size.0 as usize * size.1 as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        root.fill(&WHITE)?;
        let palette = |v: f64| CLASSES.get(v as usize).map_or(INFEASIBLE, |c| colour(*c));
        let chart = draw(&root, &values, n, plot, palette, &mut layout, &axes)?;
        let px = |d1: f64, d2: f64| chart.backend_coord(&(d1, d2));
        // The closed form's boundary at Q0: the axes d1 = 0 and d2 = 0, dashed.
        for (from, to) in [((0.0, range.0), (0.0, range.1)), ((range.0, 0.0), (range.1, 0.0))] {
            let (a, b) = (px(from.0, from.1), px(to.0, to.1));
            let line = dashes(a, b);
            for dash in &line {
                root.draw(&PathElement::new(dash.clone(), BLACK.stroke_width(2)))?;
            }
            layout.curves.push(vec![a, b]);
        }
        for &(d1, d2, round) in &marks {
            marker(&root, px(d1, d2), round)?;
            layout.curves.push(vec![px(d1, d2)]);
        }
        for (k, (label, row)) in rows.iter().enumerate() {
            let y = plot.top + i32::try_from(k)? * row_height + row_height / 2;
            let x = legend_left;
            match row {
                Row::Swatch(c) => {
                    let corners = [(x, y - SWATCH / 2), (x + SWATCH, y + SWATCH / 2)];
                    root.draw(&Rectangle::new(corners, c.filled()))?;
                    root.draw(&Rectangle::new(corners, BLACK.stroke_width(1)))?;
                }
                Row::Dashed => {
                    for dash in dashes((x, y), (x + SWATCH, y)) {
                        root.draw(&PathElement::new(dash, BLACK.stroke_width(2)))?;
                    }
                }
                Row::Marker(round) => marker(&root, (x + SWATCH / 2, y), *round)?,
            }
            text(&root, &mut layout, label, SIZE, (x + SWATCH + GAP, y), Anchor::Left)?;
        }
        text(&root, &mut layout, &title, TITLE, (width / 2, PAD), Anchor::Top)?;
        root.present()?;
    }
    write_png(path, size, &rgb)?;
    layout.check("E7 map")
}

/// What a legend row shows before its text.
enum Row {
    /// A filled square of a class's colour.
    Swatch(RGBColor),
    /// A dashed line: the closed form's boundary.
    Dashed,
    /// A geometry's marker: round (cdhrm5) or square.
    Marker(bool),
}

/// A geometry's marker at `(x, y)`: a white-filled circle or square with a black rim.
fn marker<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    (x, y): (i32, i32),
    round: bool,
) -> DynResult<()>
where
    DB::ErrorType: 'static,
{
    if round {
        root.draw(&Circle::new((x, y), MARKER, WHITE.filled()))?;
        root.draw(&Circle::new((x, y), MARKER, BLACK.stroke_width(2)))?;
    } else {
        let corners = [(x - MARKER, y - MARKER), (x + MARKER, y + MARKER)];
        root.draw(&Rectangle::new(corners, WHITE.filled()))?;
        root.draw(&Rectangle::new(corners, BLACK.stroke_width(2)))?;
    }
    Ok(())
}

/// A straight line from `a` to `b` as dashes of 6 pixels with gaps of 4.
fn dashes(a: (i32, i32), b: (i32, i32)) -> Vec<Vec<(i32, i32)>> {
    let (dx, dy) = (f64::from(b.0 - a.0), f64::from(b.1 - a.1));
    let length = dx.hypot(dy);
    let at = |t: f64| {
        let t = t.min(length) / length.max(1.0);
        (a.0 + (t * dx).round() as i32, a.1 + (t * dy).round() as i32)
    };
    let mut out = Vec::new();
    let mut t = 0.0;
    while t < length {
        out.push(vec![at(t), at(t + 6.0)]);
        t += 10.0;
    }
    out
}
