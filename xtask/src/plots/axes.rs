//! A chart's frame: the plotting area with its grid, and around it the ticks
//! at round values, their labels with the decimals they need, the axis descriptions and the
//! title, each placed from the font's metrics and recorded in the [`Layout`].

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use sinew::paper::fixed;

use super::layout::{Anchor, Layout, Rect, Target, extent, nice_ticks, text};
use crate::DynResult;

/// A chart whose axes carry the round ticks of [`Axes`].
pub(super) type Chart<DB> = ChartContext<'static, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Length of a tick mark, outside the frame, and the gap from it to its label, pixels.
const TICK: i32 = 5;
const GAP: i32 = 4;
/// Space kept free at the canvas' edge of a panel, pixels.
const PAD: i32 = 8;

/// The axes of one panel.
#[derive(Debug, Clone)]
pub(super) struct Axes<'t> {
    /// Above the plot; `None` for none (a heat map writes its own over the whole canvas).
    pub(super) title: Option<&'t str>,
    pub(super) x_desc: &'t str,
    pub(super) y_desc: &'t str,
    pub(super) x: (f64, f64),
    pub(super) y: (f64, f64),
    /// About how many ticks on each axis.
    pub(super) ticks: (usize, usize),
    /// A grid (bold lines at the ticks, light ones between) in the plotting area.
    pub(super) grid: bool,
    /// Font size of the tick labels; the descriptions get one point more, the title five.
    pub(super) size: f64,
}

/// Pixels around the plotting area that a panel's texts need.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Margins {
    pub(super) left: i32,
    pub(super) right: i32,
    pub(super) top: i32,
    pub(super) bottom: i32,
}

/// Tick values and their labels.
fn labelled(range: (f64, f64), count: usize) -> (Vec<f64>, Vec<String>) {
    let (ticks, decimals) = nice_ticks(range.0, range.1, count);
    let labels = ticks.iter().map(|t| fixed(*t, decimals)).collect();
    (ticks, labels)
}

/// Light grid lines: each tick interval split in five (in two for a step of 2 × 10ⁿ).
fn light_points(ticks: &[f64], range: (f64, f64)) -> Vec<f64> {
    let [a, b, ..] = ticks else { return Vec::new() };
    let step = b - a;
    let mantissa = step / 10f64.powi(step.log10().floor() as i32);
    let parts = if (mantissa - 2.0).abs() < 1e-9 { 4 } else { 5 };
    let fine = step / f64::from(parts);
    let first = (range.0 / fine).ceil() as i64;
    let last = (range.1 / fine).floor() as i64;
    (first..=last).filter(|k| k % i64::from(parts) != 0).map(|k| k as f64 * fine).collect()
}

impl Axes<'_> {
    fn desc_size(&self) -> f64 {
        self.size + 1.0
    }

    fn title_size(&self) -> f64 {
        self.size + 5.0
    }

    /// The pixels each side of the plotting area needs for the texts of these axes.
    pub(super) fn margins(&self, target: Target) -> DynResult<Margins> {
        let (_, x_labels) = labelled(self.x, self.ticks.0);
        let (_, y_labels) = labelled(self.y, self.ticks.1);
        let label_height = extent("0", self.size, target)?.height().ceil() as i32;
        let desc_height = extent(self.x_desc, self.desc_size(), target)?.height().ceil() as i32;
        let mut widest = 0;
        for label in &y_labels {
            widest = widest.max(extent(label, self.size, target)?.width.ceil() as i32);
        }
        let last =
            x_labels.last().map_or(Ok(0.0), |l| extent(l, self.size, target).map(|e| e.width))?;
        let top = match self.title {
            Some(title) => {
                2 * PAD + extent(title, self.title_size(), target)?.height().ceil() as i32
            }
            None => PAD,
        };
        Ok(Margins {
            left: PAD + desc_height + 2 * GAP + widest + GAP + TICK,
            right: PAD.max((last / 2.0).ceil() as i32 + PAD),
            top,
            bottom: TICK + GAP + label_height + 2 * GAP + desc_height + PAD,
        })
    }

    /// Draw the axes around `plot` (pixels of `root`), the grid inside it, and return the chart
    /// that maps data into `plot`.
    pub(super) fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        plot: Rect,
        layout: &mut Layout,
    ) -> DynResult<Chart<DB>>
    where
        DB::ErrorType: 'static,
    {
        let (x_ticks, x_labels) = labelled(self.x, self.ticks.0);
        let (y_ticks, y_labels) = labelled(self.y, self.ticks.1);
        let area =
            root.clone().shrink((plot.left, plot.top), (plot.width() as u32, plot.height() as u32));
        let chart =
            ChartBuilder::on(&area).build_cartesian_2d(self.x.0..self.x.1, self.y.0..self.y.1)?;
        if self.grid {
            // Light lines between the ticks, bold ones at them.
            let (x_fine, y_fine) = (light_points(&x_ticks, self.x), light_points(&y_ticks, self.y));
            for (xs, ys, style) in
                [(&x_fine, &y_fine, BLACK.mix(0.08)), (&x_ticks, &y_ticks, BLACK.mix(0.25))]
            {
                for x in xs {
                    let (px, _) = chart.backend_coord(&(*x, self.y.0));
                    root.draw(&PathElement::new(vec![(px, plot.top), (px, plot.bottom)], style))?;
                }
                for y in ys {
                    let (_, py) = chart.backend_coord(&(self.x.0, *y));
                    root.draw(&PathElement::new(vec![(plot.left, py), (plot.right, py)], style))?;
                }
            }
        }
        // The frame, just outside the plotting area.
        let frame = plot.grown(1);
        root.draw(&Rectangle::new(
            [(frame.left, frame.top), (frame.right, frame.bottom)],
            BLACK.stroke_width(1),
        ))?;

        let below = frame.bottom + TICK + GAP;
        let mut label_bottom = below;
        for (t, label) in x_ticks.iter().zip(&x_labels) {
            let (x, _) = chart.backend_coord(&(*t, self.y.0));
            root.draw(&PathElement::new(vec![(x, frame.bottom), (x, frame.bottom + TICK)], BLACK))?;
            label_bottom = text(root, layout, label, self.size, (x, below), Anchor::Top)?.bottom;
        }
        let mut label_left = frame.left - TICK - GAP;
        for (t, label) in y_ticks.iter().zip(&y_labels) {
            let (_, y) = chart.backend_coord(&(self.x.0, *t));
            root.draw(&PathElement::new(vec![(frame.left - TICK, y), (frame.left, y)], BLACK))?;
            let rect =
                text(root, layout, label, self.size, (frame.left - TICK - GAP, y), Anchor::Right)?;
            label_left = label_left.min(rect.left);
        }
        let centre = ((plot.left + plot.right) / 2, (plot.top + plot.bottom) / 2);
        text(
            root,
            layout,
            self.x_desc,
            self.desc_size(),
            (centre.0, label_bottom + 2 * GAP),
            Anchor::Top,
        )?;
        let desc = extent(self.y_desc, self.desc_size(), layout.target)?.height().ceil() as i32;
        text(
            root,
            layout,
            self.y_desc,
            self.desc_size(),
            (label_left - 2 * GAP - desc, centre.1),
            Anchor::Upwards,
        )?;
        if let Some(title) = self.title {
            let height = extent(title, self.title_size(), layout.target)?.height().ceil() as i32;
            text(
                root,
                layout,
                title,
                self.title_size(),
                (centre.0, frame.top - PAD - height),
                Anchor::Top,
            )?;
        }
        Ok(chart)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn light_lines_split_each_tick_interval() {
        let ticks = [0.0, 1.0, 2.0];
        let fine = light_points(&ticks, (0.0, 2.0));
        assert_eq!(fine.len(), 8);
        assert!(fine.iter().all(|x| ticks.iter().all(|t| (x - t).abs() > 0.1)));
        let (ticks, _) = nice_ticks(0.0, 10.0, 6);
        assert_eq!(light_points(&ticks, (0.0, 10.0)).len(), 15);
    }
}
