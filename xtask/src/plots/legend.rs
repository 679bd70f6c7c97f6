//! Legends placed where no data is: the first of a few places in the plotting area that keeps a
//! margin from every curve.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::layout::{Anchor, Layout, Rect, Target, extent, text};
use crate::DynResult;

/// Font size of the entries (plotters' size).
const SIZE: f64 = 13.0;
/// Padding inside the box, pixels.
const PAD: i32 = 7;
/// Length of an entry's line sample, and the gap after it, pixels.
const SAMPLE: i32 = 20;
const GAP: i32 = 6;
/// Pixels kept free between the box and any curve or the plotting area's edge.
const CLEARANCE: i32 = 6;

/// A legend: one row per entry, with a line sample in the entry's colour, or none for a note.
#[derive(Debug, Clone, Default)]
pub(super) struct Legend {
    entries: Vec<(String, Option<RGBColor>)>,
}

impl Legend {
    /// An entry with a line sample.
    pub(super) fn entry(&mut self, label: impl Into<String>, colour: RGBColor) {
        self.entries.push((label.into(), Some(colour)));
    }

    /// A row of text without a sample.
    pub(super) fn note(&mut self, text: impl Into<String>) {
        self.entries.push((text.into(), None));
    }

    fn row_height(target: Target) -> DynResult<i32> {
        Ok(extent("(Xy)", SIZE, target)?.height().ceil() as i32 + 4)
    }

    /// The box's width and height, pixels.
    fn size(&self, target: Target) -> DynResult<(i32, i32)> {
        let mut width = 0;
        for (label, colour) in &self.entries {
            let sample = if colour.is_some() { SAMPLE + GAP } else { 0 };
            width = width.max(sample + extent(label, SIZE, target)?.width.ceil() as i32);
        }
        let rows = self.entries.len() as i32;
        Ok((width + 2 * PAD, rows * Self::row_height(target)? + 2 * PAD - 4))
    }

    /// The first place in `plot` whose box keeps [`CLEARANCE`] pixels from every curve and
    /// from the inside of every closed one: the upper left, upper right, lower right and lower
    /// left corners, then the middles of the top, bottom, left and right edges, then any place,
    /// the nearest to a corner first. Where none is free, the one over the fewest pixels of data
    /// (the figure's [`Layout::check`] then reports it).
    pub(super) fn place(
        &self,
        plot: Rect,
        curves: &[Vec<(i32, i32)>],
        target: Target,
    ) -> DynResult<Rect> {
        let (w, h) = self.size(target)?;
        let occupied = Occupied::new(plot, curves);
        let (left, right) = (plot.left + CLEARANCE, plot.right - CLEARANCE - w + 1);
        let (top, bottom) = (plot.top + CLEARANCE, plot.bottom - CLEARANCE - h + 1);
        let (centre, middle) = ((left + right) / 2, (top + bottom) / 2);
        let mut places = vec![
            (left, top),
            (right, top),
            (right, bottom),
            (left, bottom),
            (centre, top),
            (centre, bottom),
            (left, middle),
            (right, middle),
        ];
        let mut rest: Vec<(i32, i32)> = (left..=right.max(left))
            .step_by(2)
            .flat_map(|x| (top..=bottom.max(top)).step_by(2).map(move |y| (x, y)))
            .collect();
        rest.sort_by_key(|&(x, y)| (x - left).min(right - x) + (y - top).min(bottom - y));
        places.extend(rest);
        let cost = |&(x, y): &(i32, i32)| occupied.count(Rect::sized(x, y, w, h).grown(CLEARANCE));
        let best =
            places.iter().find(|p| cost(p) == 0).or_else(|| places.iter().min_by_key(|p| cost(p)));
        let (x, y) = best.copied().unwrap_or((left, top));
        Ok(Rect::sized(x, y, w, h))
    }

    /// Draw the legend in `rect` (from [`Legend::place`]) and record it in `layout`.
    pub(super) fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        rect: Rect,
        layout: &mut Layout,
    ) -> DynResult<()>
    where
        DB::ErrorType: 'static,
    {
        let corners = [(rect.left, rect.top), (rect.right, rect.bottom)];
        root.draw(&Rectangle::new(corners, WHITE.filled()))?;
        root.draw(&Rectangle::new(corners, BLACK.stroke_width(1)))?;
        let row = Self::row_height(layout.target)?;
        for (k, (label, colour)) in self.entries.iter().enumerate() {
            let y = rect.top + PAD + k as i32 * row + (row - 4) / 2;
            let mut x = rect.left + PAD;
            if let Some(colour) = colour {
                root.draw(&PathElement::new(
                    vec![(x, y), (x + SAMPLE, y)],
                    colour.stroke_width(2),
                ))?;
                x += SAMPLE + GAP;
            }
            text(root, layout, label, SIZE, (x, y), Anchor::Left)?;
        }
        layout.legends.push(rect);
        Ok(())
    }
}

/// The pixels of a plotting area that data cover: every curve's pixels, and the inside of every
/// closed curve (an ellipse), counted in a summed-area table so that a box's count is four
/// look-ups.
struct Occupied {
    plot: Rect,
    /// `sums[(y + 1) · (w + 1) + x + 1]`: the covered pixels left of and above `(x, y)`, both
    /// included, relative to the plot's top-left pixel.
    sums: Vec<u32>,
}

impl Occupied {
    fn new(plot: Rect, curves: &[Vec<(i32, i32)>]) -> Occupied {
        let (w, h) = (plot.width().max(0) as usize, plot.height().max(0) as usize);
        let mut covered = vec![false; w * h];
        let mut mark = |x: f64, y: f64| {
            let (col, row) =
                (x.round() as i64 - i64::from(plot.left), y.round() as i64 - i64::from(plot.top));
            if (0..w as i64).contains(&col) && (0..h as i64).contains(&row) {
                covered[row as usize * w + col as usize] = true;
            }
        };
        for curve in curves {
            let points: Vec<(f64, f64)> =
                curve.iter().map(|&(x, y)| (f64::from(x), f64::from(y))).collect();
            for &(x, y) in &points {
                mark(x, y);
            }
            for s in points.windows(2) {
                let ((x0, y0), (x1, y1)) = (s[0], s[1]);
                let steps = (2.0 * (x1 - x0).abs().max((y1 - y0).abs())).ceil().max(1.0);
                for k in 0..=steps as usize {
                    let t = k as f64 / steps;
                    mark(x0 + t * (x1 - x0), y0 + t * (y1 - y0));
                }
            }
            if points.len() > 2 && curve.first() == curve.last() {
                // The inside, row by row: between pairs of the outline's crossings.
                for row in 0..h {
                    let y = f64::from(plot.top) + row as f64 + 0.5;
                    let mut xs: Vec<f64> = points
                        .windows(2)
                        .filter(|s| (s[0].1 <= y) != (s[1].1 <= y))
                        .map(|s| s[0].0 + (y - s[0].1) / (s[1].1 - s[0].1) * (s[1].0 - s[0].0))
                        .collect();
                    xs.sort_by(f64::total_cmp);
                    for pair in xs.chunks_exact(2) {
                        let mut x = pair[0].ceil();
                        while x <= pair[1] {
                            mark(x, y - 0.5);
                            x += 1.0;
                        }
                    }
                }
            }
        }
        let mut sums = vec![0u32; (w + 1) * (h + 1)];
        for row in 0..h {
            for col in 0..w {
                sums[(row + 1) * (w + 1) + col + 1] = u32::from(covered[row * w + col])
                    + sums[row * (w + 1) + col + 1]
                    + sums[(row + 1) * (w + 1) + col]
                    - sums[row * (w + 1) + col];
            }
        }
        Occupied { plot, sums }
    }

    /// How many covered pixels `r` holds (the part of it inside the plot).
    fn count(&self, r: Rect) -> u32 {
        let (w, h) = (self.plot.width().max(0), self.plot.height().max(0));
        let clamp = |v: i32, hi: i32| v.clamp(0, hi) as usize;
        let (x0, x1) = (clamp(r.left - self.plot.left, w), clamp(r.right - self.plot.left + 1, w));
        let (y0, y1) = (clamp(r.top - self.plot.top, h), clamp(r.bottom - self.plot.top + 1, h));
        let at = |x: usize, y: usize| self.sums[y * (w as usize + 1) + x];
        if x1 <= x0 || y1 <= y0 { 0 } else { at(x1, y1) + at(x0, y0) - at(x0, y1) - at(x1, y0) }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn a_legend_goes_to_the_first_corner_that_no_curve_comes_near() {
        let mut legend = Legend::default();
        legend.entry("decoupled", RED);
        legend.entry("routed", BLUE);
        let plot = Rect { left: 0, top: 0, right: 399, bottom: 299 };
        // A curve rising from the lower left to the upper right: the upper left is free.
        let rising = vec![(0, 299), (399, 0)];
        let at = legend.place(plot, std::slice::from_ref(&rising), Target::Svg).unwrap();
        assert_eq!((at.left, at.top), (CLEARANCE, CLEARANCE));
        assert!(!at.grown(CLEARANCE).meets(&rising));
        // A curve along the top edge too: the legend goes to the lower right.
        let top = vec![(0, 20), (399, 20)];
        let at = legend.place(plot, &[rising.clone(), top.clone()], Target::Svg).unwrap();
        assert_eq!((at.right, at.bottom), (399 - CLEARANCE, 299 - CLEARANCE));
        assert!(!at.meets(&rising) && !at.meets(&top));
    }

    #[test]
    fn a_legend_stays_out_of_a_closed_curve_and_off_its_outline() {
        let mut legend = Legend::default();
        legend.entry("(d)", GREEN);
        legend.note("(a)–(c) unstable: no ellipsoid");
        let plot = Rect { left: 0, top: 0, right: 299, bottom: 299 };
        let diamond = vec![(150, 60), (240, 150), (150, 240), (60, 150), (150, 60)];
        let occupied = Occupied::new(plot, std::slice::from_ref(&diamond));
        // Inside it, every pixel counts; a corner of the plot is free.
        assert_eq!(occupied.count(Rect { left: 140, top: 140, right: 160, bottom: 160 }), 441);
        assert_eq!(occupied.count(Rect { left: 0, top: 0, right: 20, bottom: 20 }), 0);
        let at = legend.place(plot, std::slice::from_ref(&diamond), Target::Svg).unwrap();
        assert_eq!((at.left, at.top), (CLEARANCE, CLEARANCE));
        assert!(!at.meets(&diamond) && occupied.count(at.grown(CLEARANCE)) == 0);

        // Two closed bands leave a gap away from the corners and the edges' middles: the
        // legend goes into it, not over a band.
        let bands = [
            vec![(0, 0), (299, 0), (299, 80), (0, 80), (0, 0)],
            vec![(0, 150), (299, 150), (299, 299), (0, 299), (0, 150)],
        ];
        let at = legend.place(plot, &bands, Target::Svg).unwrap();
        assert!(at.top > 80 + CLEARANCE && at.bottom < 150 - CLEARANCE, "{at:?}");
        assert_eq!(Occupied::new(plot, &bands).count(at.grown(CLEARANCE)), 0);
    }
}
