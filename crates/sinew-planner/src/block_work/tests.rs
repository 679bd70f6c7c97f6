//! Tests of the per-block kernels of a run.

use super::{BlockWork, step_length};
use crate::program::Block;

/// A step against `I + α (−2 I)`, boundary `α* = ½`: refined, within 6 % below `0.95 α*`;
/// not, the first pass of the 0.8 shortening (`0.8⁴`), which a missing bisection leaves.
#[test]
fn a_refined_step_is_within_six_percent_of_the_boundary() {
    for n in [5, 20] {
        let mut w = BlockWork::default();
        let mut b = Block::default();
        b.recycle(n, 0);
        w.reset(&b);
        for i in 0..n {
            (w.s[i * n + i], w.ds[i * n + i]) = (1.0, -2.0);
        }
        let blocks = std::slice::from_mut(&mut w);
        let refined = step_length(&[], &[], blocks, |w| (&w.s, &w.ds), true);
        let first = step_length(&[], &[], blocks, |w| (&w.s, &w.ds), false);
        assert!((0.95 * 0.5 / 1.06..=0.95 * 0.5).contains(&refined), "n = {n}: {refined}");
        assert!((first - 0.8_f64.powi(4)).abs() < 1e-12, "n = {n}: {first}");
    }
}
