//! What the figures share: the embedded font, texts measured and drawn with it, round tick
//! values, boxes in pixels, and a figure's [`Layout`] (where its texts, legends and curves went),
//! which [`Layout::check`] holds to: every text inside the canvas and clear of the others, no
//! legend over a curve.

use std::sync::OnceLock;

use ab_glyph::{Font, FontRef, PxScale, ScaleFont};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{FontStyle, FontTransform};

use crate::DynResult;

/// DejaVu Sans, from Debian's `fonts-dejavu-core` 2.37 (licence: `xtask/assets/DejaVuSans-LICENSE`).
const FONT_DATA: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// The font family of every text. An SVG names DejaVu Sans first, so that a viewer that has it
/// draws the metrics the layout was computed with (its own sans-serif otherwise); in a PNG the
/// embedded font draws every glyph.
pub(super) const FAMILY: &str = "DejaVu Sans, sans-serif";

/// The embedded font, parsed once.
fn font() -> DynResult<&'static FontRef<'static>> {
    static FONT: OnceLock<Option<FontRef<'static>>> = OnceLock::new();
    FONT.get_or_init(|| FontRef::try_from_slice(FONT_DATA).ok())
        .as_ref()
        .ok_or_else(|| "the embedded DejaVu Sans does not parse".into())
}

/// Give plotters the embedded font, under [`FAMILY`] and as its default `sans-serif` (once).
/// Plotters' `ab_glyph` feature reads no system font: a text in a family not registered is an
/// error, never a fallback that differs between machines.
pub(super) fn register_font() -> DynResult<()> {
    static DONE: OnceLock<bool> = OnceLock::new();
    let ok = *DONE.get_or_init(|| {
        [FAMILY, "sans-serif"].into_iter().all(|family| {
            plotters::style::register_font(family, FontStyle::Normal, FONT_DATA).is_ok()
        })
    });
    if ok { Ok(()) } else { Err("plotters does not take the embedded DejaVu Sans".into()) }
}

/// What a figure is drawn into: the text metrics differ.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(super) enum Target {
    /// Plotters' SVG backend: `font-size` is plotters' size / 1.24, the text's em; the viewer
    /// draws the glyphs.
    #[default]
    Svg,
    /// Plotters' bitmap backend: `ab_glyph` draws the glyphs at plotters' size as the font's
    /// height (ascent − descent).
    Png,
}

/// A box in pixels of the canvas, edges included.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Rect {
    pub(super) left: i32,
    pub(super) top: i32,
    pub(super) right: i32,
    pub(super) bottom: i32,
}

impl Rect {
    /// The box `width` × `height` whose top-left pixel is `(left, top)`.
    pub(super) fn sized(left: i32, top: i32, width: i32, height: i32) -> Rect {
        Rect { left, top, right: left + width - 1, bottom: top + height - 1 }
    }

    pub(super) fn width(&self) -> i32 {
        self.right - self.left + 1
    }

    pub(super) fn height(&self) -> i32 {
        self.bottom - self.top + 1
    }

    /// The box grown by `by` pixels on every side.
    pub(super) fn grown(&self, by: i32) -> Rect {
        Rect {
            left: self.left - by,
            top: self.top - by,
            right: self.right + by,
            bottom: self.bottom + by,
        }
    }

    fn contains(&self, (x, y): (i32, i32)) -> bool {
        (self.left..=self.right).contains(&x) && (self.top..=self.bottom).contains(&y)
    }

    fn overlaps(&self, other: &Rect) -> bool {
        self.left <= other.right
            && other.left <= self.right
            && self.top <= other.bottom
            && other.top <= self.bottom
    }

    fn inside(&self, other: &Rect) -> bool {
        other.left <= self.left
            && self.right <= other.right
            && other.top <= self.top
            && self.bottom <= other.bottom
    }

    /// Whether a curve through `points` (straight segments between them) touches the box.
    pub(super) fn meets(&self, points: &[(i32, i32)]) -> bool {
        let hit = |(x, y): (f64, f64)| self.contains((x.round() as i32, y.round() as i32));
        points.iter().any(|&(x, y)| hit((f64::from(x), f64::from(y))))
            || points.windows(2).any(|w| {
                let (a, b) = (
                    (f64::from(w[0].0), f64::from(w[0].1)),
                    (f64::from(w[1].0), f64::from(w[1].1)),
                );
                // Every half pixel along the segment.
                let steps = (2.0 * (b.0 - a.0).abs().max((b.1 - a.1).abs())).ceil().max(1.0);
                (0..=steps as usize).any(|k| {
                    let t = k as f64 / steps;
                    hit((a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1)))
                })
            })
    }
}

/// Where each part of a figure went, pixels: what [`Layout::check`] checks and the tests assert.
#[derive(Debug, Clone, Default)]
pub struct Layout {
    pub(super) target: Target,
    /// The canvas, `(width, height)`.
    pub(super) size: (u32, u32),
    /// Every text with its box (ink extent, from the font's ascent and descent).
    pub(super) texts: Vec<(String, Rect)>,
    /// The legend boxes.
    pub(super) legends: Vec<Rect>,
    /// The plotted data: each curve's points, joined by straight segments (an ellipse: points
    /// on its outline, closed).
    pub(super) curves: Vec<Vec<(i32, i32)>>,
}

impl Layout {
    pub(super) fn new(target: Target, size: (u32, u32)) -> Layout {
        Layout { target, size, ..Layout::default() }
    }

    /// What is wrong with the figure: a text not wholly inside the canvas, two texts over each
    /// other, a legend box that a curve crosses or that leaves the canvas.
    pub(super) fn problems(&self) -> Vec<String> {
        let canvas = Rect::sized(0, 0, self.size.0 as i32, self.size.1 as i32);
        let mut out = Vec::new();
        for (k, (text, rect)) in self.texts.iter().enumerate() {
            if !rect.inside(&canvas) {
                out.push(format!("text `{text}` at {rect:?} leaves the canvas {:?}", self.size));
            }
            for (other, r) in &self.texts[k + 1..] {
                if rect.overlaps(r) {
                    out.push(format!("texts `{text}` and `{other}` overlap"));
                }
            }
        }
        for legend in &self.legends {
            if !legend.inside(&canvas) {
                out.push(format!("legend {legend:?} leaves the canvas"));
            }
            if self.curves.iter().any(|c| legend.meets(c)) {
                out.push(format!("legend {legend:?} covers plotted data"));
            }
        }
        out
    }

    /// The figure as drawn, or an error listing its [`Layout::problems`].
    pub(super) fn check(self, what: &str) -> DynResult<Layout> {
        let problems = self.problems();
        if problems.is_empty() {
            Ok(self)
        } else {
            Err(format!("{what}: {}", problems.join("; ")).into())
        }
    }
}

/// A text's extent at plotters' font size `size` on `target`: its advance width and its ascent
/// and descent from the baseline, pixels.
#[derive(Debug, Clone, Copy)]
pub(super) struct Extent {
    pub(super) width: f64,
    pub(super) ascent: f64,
    pub(super) descent: f64,
}

impl Extent {
    pub(super) fn height(&self) -> f64 {
        self.ascent + self.descent
    }
}

/// [`Extent`] of `text`: advances and kerning as plotters' `ab_glyph` layout sums them.
pub(super) fn extent(text: &str, size: f64, target: Target) -> DynResult<Extent> {
    let font = font()?;
    let scale = match target {
        Target::Png => size,
        Target::Svg => {
            let em = font.units_per_em().ok_or("the embedded font has no em size")?;
            size / 1.24 * f64::from(font.height_unscaled() / em)
        }
    };
    let scaled = font.as_scaled(PxScale::from(scale as f32));
    let (mut width, mut previous) = (0.0_f32, None);
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(p) = previous {
            width += scaled.kern(p, id);
        }
        width += scaled.h_advance(id);
        previous = Some(id);
    }
    Ok(Extent {
        width: f64::from(width),
        ascent: f64::from(scaled.ascent()),
        descent: f64::from(-scaled.descent()),
    })
}

/// How a text hangs from the point it is drawn at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Anchor {
    /// Horizontal, the point at the top centre of its box.
    Top,
    /// Horizontal, the point at the middle of its right edge.
    Right,
    /// Horizontal, the point at the middle of its left edge.
    Left,
    /// Reading upwards (a y axis' description), the point at the middle of its left edge.
    Upwards,
}

/// Draw `text` in black at plotters' font size `size`, its box hung from `at` by `anchor`, and
/// record it in `layout`; returns its box.
pub(super) fn text<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    layout: &mut Layout,
    text: &str,
    size: f64,
    at: (i32, i32),
    anchor: Anchor,
) -> DynResult<Rect>
where
    DB::ErrorType: 'static,
{
    let e = extent(text, size, layout.target)?;
    // The baseline's distance below the point plotters is given for a top-anchored text.
    let drop = match layout.target {
        Target::Svg => 0.76 * size / 1.24,
        Target::Png => size / 2.0,
    };
    let (w, half) = (e.width.ceil() as i32, (e.width / 2.0).ceil() as i32);
    let (ascent, descent) = (e.ascent.ceil() as i32, e.descent.ceil() as i32);
    let style = TextStyle::from((FAMILY, size).into_font()).color(&BLACK);
    let (x, y) = at;
    let (rect, h_pos, point) = match anchor {
        Anchor::Top | Anchor::Left | Anchor::Right => {
            let baseline = match anchor {
                Anchor::Top => y + ascent,
                _ => y + (ascent - descent) / 2,
            };
            let (left, h_pos) = match anchor {
                Anchor::Top => (x - half, HPos::Center),
                Anchor::Right => (x - w, HPos::Right),
                _ => (x, HPos::Left),
            };
            let rect =
                Rect { left, top: baseline - ascent, right: left + w, bottom: baseline + descent };
            (rect, h_pos, (x, baseline - drop.round() as i32))
        }
        Anchor::Upwards => {
            // Turned a quarter left: the baseline is a vertical line, the ascent to its left.
            let baseline = x + ascent;
            let rect = Rect { left: x, top: y - half, right: baseline + descent, bottom: y + half };
            (rect, HPos::Center, (baseline - drop.round() as i32, y))
        }
    };
    let style = style.pos(Pos::new(h_pos, VPos::Top));
    let style =
        if anchor == Anchor::Upwards { style.transform(FontTransform::Rotate270) } else { style };
    root.draw_text(text, &style, point)?;
    layout.texts.push((text.to_owned(), rect));
    Ok(rect)
}

/// About `count` round tick values (1, 2 or 5 times a power of ten apart) in `[lo, hi]`, and
/// the decimals their labels need. The power of ten is an integer exponent, so that the
/// decimals do not hang on the last bit of a logarithm.
pub(super) fn nice_ticks(lo: f64, hi: f64, count: usize) -> (Vec<f64>, usize) {
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

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use sinew::paper::fixed;

    #[test]
    fn ticks_are_round_and_inside_the_range() {
        let (ticks, decimals) = nice_ticks(-0.5454, 0.5454, 6);
        let labels: Vec<String> = ticks.iter().map(|t| fixed(*t, decimals)).collect();
        assert_eq!(labels, ["-0.4", "-0.2", "0.0", "0.2", "0.4"]);
        let (ticks, decimals) = nice_ticks(1.93, 16.3, 6);
        assert_eq!((ticks, decimals), (vec![5.0, 10.0, 15.0], 0));
        // Whole numbers get no decimals (E5's budgets: 1000, not 1000.0).
        let (ticks, decimals) = nice_ticks(600.0, 9000.0, 10);
        assert_eq!(ticks.first().map(|t| fixed(*t, decimals)).as_deref(), Some("1000"));
    }

    #[test]
    fn a_curve_meets_a_box_it_crosses_between_its_points() {
        let r = Rect { left: 10, top: 10, right: 20, bottom: 20 };
        assert!(r.meets(&[(15, 15)]));
        // Both ends outside, the segment through the box.
        assert!(r.meets(&[(0, 15), (30, 15)]));
        assert!(r.meets(&[(0, 0), (30, 30)]));
        assert!(!r.meets(&[(0, 0), (30, 0), (30, 30)]));
        assert!(!r.meets(&[(21, 0), (21, 30)]));
    }

    #[test]
    fn the_checks_find_a_text_off_the_canvas_and_a_legend_on_the_data() {
        let mut layout = Layout::new(Target::Svg, (100, 50));
        layout.texts.push(("inside".into(), Rect { left: 0, top: 0, right: 40, bottom: 10 }));
        layout.curves.push(vec![(5, 45), (95, 45)]);
        layout.legends.push(Rect { left: 60, top: 5, right: 95, bottom: 30 });
        assert!(layout.problems().is_empty(), "{:?}", layout.problems());
        layout.texts.push(("clipped".into(), Rect { left: 80, top: 0, right: 100, bottom: 10 }));
        layout.texts.push(("over".into(), Rect { left: 30, top: 5, right: 50, bottom: 15 }));
        layout.legends.push(Rect { left: 10, top: 30, right: 30, bottom: 48 });
        let problems = layout.problems();
        assert_eq!(problems.len(), 3, "{problems:?}");
        let found = |what: &str| problems.iter().any(|p| p.contains(what));
        assert!(found("text `clipped` at"), "{problems:?}");
        assert!(found("texts `inside` and `over` overlap"), "{problems:?}");
        assert!(found("covers plotted data"), "{problems:?}");
    }

    #[test]
    fn text_extents_follow_the_font() {
        let one = extent("0", 13.0, Target::Png).unwrap();
        let four = extent("0000", 13.0, Target::Png).unwrap();
        assert!((four.width - 4.0 * one.width).abs() < 1e-6);
        // The PNG's size is the font's height; the SVG's, an em 1.24 times smaller.
        assert!((one.height() - 13.0).abs() < 0.01, "{one:?}");
        let svg = extent("0", 13.0, Target::Svg).unwrap();
        assert!(svg.width < one.width && svg.height() < one.height());
    }
}
