//! Fig. 5's heat maps: PNG, drawn by plotters' bitmap backend into a buffer, the text in the
//! embedded DejaVu Sans through `ab_glyph`, encoded by `png`. No system font or library is read,
//! so a file is the same bytes on every machine.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use sinew::indicators::{SweepCell, SweepMaps};
use sinew::paper::fixed;

use super::axes::{Axes, Chart};
use super::layout::{Anchor, Layout, Rect, Target, extent, nice_ticks, register_font, text};
use crate::DynResult;

/// Side of one grid cell, pixels.
pub(super) const CELL: i32 = 4;
/// Width of the colour bar, its distance from the map, and the length of its ticks, pixels.
const BAR_WIDTH: i32 = 24;
const BAR_GAP: i32 = 40;
const TICK: i32 = 5;
/// Font sizes (plotters' size, the font's height in pixels): tick labels, title.
pub(super) const SIZE: f64 = 16.0;
pub(super) const TITLE: f64 = 22.0;
/// Space kept free at the canvas' edges, pixels.
pub(super) const PAD: i32 = 10;
/// Grey of the cells where the torque cannot be held.
pub(super) const INFEASIBLE: RGBColor = RGBColor(200, 200, 200);

/// One heat map of Fig. 5 with its colour bar: `value(cell)` over `q1` (x) and `q2` (y), each
/// grid cell a [`CELL`] × [`CELL`] square, grey where the torque cannot be held. Returns where
/// its parts went, checked ([`Layout::check`]).
pub fn heat_map(
    maps: &SweepMaps,
    title: &str,
    value: impl Fn(&SweepCell) -> f64,
    path: &Path,
) -> DynResult<Layout> {
    register_font()?;
    let n = maps.grid.points;
    let values: Vec<Option<f64>> = maps.cells.iter().map(|c| c.as_ref().map(&value)).collect();
    let lo = values.iter().flatten().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().flatten().copied().fold(f64::NEG_INFINITY, f64::max);
    let (lo, hi) = if lo.is_finite() && hi > lo { (lo, hi) } else { (0.0, 1.0) };
    let colour = |v: f64| ViridisRGB::get_color_normalized(v, lo, hi);

    // The cells are centred on the grid angles, so the map spans half a step more each side.
    let (g0, g1) = (maps.grid.lower, maps.grid.upper);
    let step = (g1 - g0) / (n.max(2) - 1) as f64;
    let q = (g0 - step / 2.0, g1 + step / 2.0);
    let axes = Axes {
        title: None,
        x_desc: "q1 (rad)",
        y_desc: "q2 (rad)",
        x: q,
        y: q,
        ticks: (6, 6),
        grid: false,
        size: SIZE,
    };

    // Layout, pixels: the title, then the bar's unit over the map's top edge.
    let target = Target::Png;
    let m = axes.margins(target)?;
    let side = i32::try_from(n)? * CELL;
    let unit = "N m/rad";
    let title_height = extent(title, TITLE, target)?.height().ceil() as i32;
    let unit_height = extent(unit, SIZE, target)?.height().ceil() as i32;
    // The unit clears a bar label at the bar's top edge (centred on it).
    let unit_gap = (extent("0", SIZE, target)?.height() / 2.0).ceil() as i32 + 6;
    let top = PAD + title_height + PAD + unit_height + unit_gap;
    let plot = Rect::sized(m.left, top, side, side);
    let bar = Rect::sized(plot.right + 1 + BAR_GAP, top, BAR_WIDTH, side);
    let (bar_ticks, decimals) = nice_ticks(lo, hi, 6);
    let bar_labels: Vec<String> = bar_ticks.iter().map(|v| fixed(*v, decimals)).collect();
    let mut widest = extent(unit, SIZE, target)?.width / 2.0 - f64::from(BAR_WIDTH / 2 + TICK + 4);
    for label in &bar_labels {
        widest = widest.max(extent(label, SIZE, target)?.width);
    }
    let title_width = extent(title, TITLE, target)?.width.ceil() as i32;
    let width = (bar.right + TICK + 4 + widest.ceil() as i32 + PAD).max(title_width + 2 * PAD);
    let height = plot.bottom + 1 + m.bottom;
    let size = (u32::try_from(width)?, u32::try_from(height)?);

    let mut layout = Layout::new(target, size);
    let mut rgb = vec![0u8; 3 * size.0 as usize * size.1 as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root, &values, n, plot, colour, &mut layout, &axes)?;
        // The colour bar: one row of pixels per value, top = hi, bottom = lo.
        for y in 0..side {
            let v = lo + (hi - lo) * f64::from(side - 1 - y) / f64::from(side - 1);
            let row = [(bar.left, bar.top + y), (bar.right + 1, bar.top + y + 1)];
            root.draw(&Rectangle::new(row, colour(v).filled()))?;
        }
        let frame = bar.grown(1);
        let corners = [(frame.left, frame.top), (frame.right, frame.bottom)];
        root.draw(&Rectangle::new(corners, BLACK.stroke_width(1)))?;
        for (v, label) in bar_ticks.iter().zip(&bar_labels) {
            let y = bar.bottom - ((v - lo) / (hi - lo) * f64::from(side - 1)).round() as i32;
            let tick = vec![(frame.right, y), (frame.right + TICK, y)];
            root.draw(&PathElement::new(tick, BLACK))?;
            text(&root, &mut layout, label, SIZE, (frame.right + TICK + 4, y), Anchor::Left)?;
        }
        let centre = (bar.left + bar.right) / 2;
        text(
            &root,
            &mut layout,
            unit,
            SIZE,
            (centre, frame.top - unit_gap - unit_height),
            Anchor::Top,
        )?;
        text(&root, &mut layout, title, TITLE, (width / 2, PAD), Anchor::Top)?;
        root.present()?;
    }
    write_png(path, size, &rgb)?;
    layout.check(title)
}

/// The map's cells (`values[a · n + b]`: column `a` from the left, row `b` from the bottom,
/// [`INFEASIBLE`] where `None`) and its axes; returns the chart that maps data into `plot`.
pub(super) fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    values: &[Option<f64>],
    n: usize,
    plot: Rect,
    colour: impl Fn(f64) -> RGBColor,
    layout: &mut Layout,
    axes: &Axes<'_>,
) -> DynResult<Chart<DB>>
where
    DB::ErrorType: 'static,
{
    let n32 = i32::try_from(n)?;
    for a in 0..n32 {
        for b in 0..n32 {
            let fill = values[a as usize * n + b as usize].map_or(INFEASIBLE, &colour);
            // q2 grows upwards: row b counted from the bottom.
            let (x, y) = (plot.left + a * CELL, plot.top + (n32 - 1 - b) * CELL);
            root.draw(&Rectangle::new([(x, y), (x + CELL, y + CELL)], fill.filled()))?;
        }
    }
    axes.draw(root, plot, layout)
}

/// The RGB buffer as an 8-bit RGB PNG.
pub(super) fn write_png(path: &Path, (width, height): (u32, u32), rgb: &[u8]) -> DynResult<()> {
    let file = std::io::BufWriter::new(std::fs::File::create(path)?);
    let mut encoder = png::Encoder::new(file, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::High);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn a_png_heat_map_is_the_same_bytes_twice() {
        let maps = SweepMaps {
            joint: 0,
            torque: [0.0; 2],
            grid: sinew::indicators::AngleGrid { lower: -0.5, upper: 0.5, points: 121 },
            cells: vec![None; 121 * 121],
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
