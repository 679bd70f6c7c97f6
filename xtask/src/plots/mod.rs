//! The report's figures, all drawn with plotters and the embedded DejaVu Sans
//! (`xtask/assets/`, through plotters' `ab_glyph` feature: no system font): the line plots
//! (Fig. 4, E5, E6) and the ellipses (Fig. 6) as SVG, the heat maps of Fig. 5 and E7's map as PNG.
//!
//! Every text is placed from the font's metrics and every legend where no curve is; each figure
//! returns its [`layout::Layout`] and fails rather than be written with a text outside its canvas or
//! over another, or a legend over its data.
//!
//! - [`layout`]: the font, text extents, round ticks, the layout and its check;
//! - [`axes`]: a panel's frame, grid, ticks, labels and title;
//! - [`legend`]: legends and where they go;
//! - [`lines`], [`heat`], [`ellipses`], [`sign_map`]: the figures.

mod axes;
mod ellipses;
mod heat;
mod layout;
mod legend;
mod lines;
mod sign_map;

pub use ellipses::fig6;
pub use heat::heat_map;
pub use lines::{fig_e5, fig_e6, fig4};
pub use sign_map::fig_e7;

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use std::path::PathBuf;

    use sinew::paper::{self, Report};

    use super::layout::Layout;
    use super::*;

    /// Every figure of the report, from the report's own numbers, into a temporary directory:
    /// each text inside its canvas and clear of the others, each legend clear of the data
    /// (the figure functions fail otherwise), and the same bytes when drawn twice.
    #[test]
    fn every_figure_keeps_its_texts_inside_and_its_legends_off_the_data() {
        let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
        let report = Report::compute(&root.join(paper::ROBOT_DIR)).unwrap();
        let dir = std::env::temp_dir().join(format!("sinew-figures-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let e4 = [&report.e4_decoupled, &report.e4_stable, &report.e4_routed];
        let e5 = [&report.e5_decoupled, &report.e5_routed];
        let draw = |tag: &str| -> Vec<(String, Layout)> {
            let path = |name: &str| dir.join(format!("{tag}-{name}"));
            let mut out = vec![
                (paper::FIG4_FILE.to_owned(), fig4(&report.e2, &path(paper::FIG4_FILE)).unwrap()),
                (paper::FIG6_FILE.to_owned(), fig6(&e4, &path(paper::FIG6_FILE)).unwrap()),
                (paper::FIG_E5_FILE.to_owned(), fig_e5(&e5, &path(paper::FIG_E5_FILE)).unwrap()),
            ];
            let e7 = fig_e7(&report.e7, &path(paper::FIG_E7_FILE)).unwrap();
            out.push((paper::FIG_E7_FILE.to_owned(), e7));
            let e6 = fig_e6(&report.e6, &path(paper::FIG_E6_FILE)).unwrap();
            out.push((paper::FIG_E6_FILE.to_owned(), e6));
            for map in paper::FIG5_MAPS {
                let layout = heat_map(&report.e3, map.title, map.value, &path(map.file)).unwrap();
                out.push((map.file.to_owned(), layout));
            }
            out
        };
        let figures = draw("a");
        for (name, layout) in &figures {
            assert!(layout.problems().is_empty(), "{name}: {:?}", layout.problems());
            assert!(
                !layout.texts.is_empty() && !layout.curves.is_empty() || name.ends_with(".png")
            );
        }
        // Fig. 4: two legends; Fig. 6: one per panel; E5: one.
        let legends: Vec<usize> = figures.iter().map(|(_, l)| l.legends.len()).collect();
        assert_eq!(&legends[..3], [2, 9, 1]);
        // The decoupled baseline-0 row says why it shows (d) alone.
        let fig6 = &figures[1].1;
        let texts: Vec<&str> = fig6.texts.iter().map(|(t, _)| t.as_str()).collect();
        assert!(texts.windows(2).any(|w| w == ["(a)–(c) unstable:", "no ellipsoid"]));
        // E5's ticks carry no needless decimals, and its last x label is inside the canvas.
        let e5 = &figures[2].1;
        assert!(e5.texts.iter().any(|(t, _)| t == "8000"));
        assert!(!e5.texts.iter().any(|(t, _)| t.ends_with(".0")));
        draw("b");
        for (name, _) in &figures {
            let read = |tag: &str| std::fs::read(dir.join(format!("{tag}-{name}"))).unwrap();
            assert!(read("a") == read("b"), "{name} differs between two drawings");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
