//! A warm start's way back into the interior: whether a point mapped from the previous pose
//! is strictly inside the rows, the margin and the floors, and else one least-norm step onto
//! the linearised violated constraints (issue #24's restoration step).

use nalgebra::DMatrix;

use crate::ipm::Interior;
use crate::ipm_work::{IpmWork, floor_value, margin_exceeds};

impl Interior<'_> {
    /// Whether `x` is strictly inside the rows, the margin and the floors (checked in `w`'s
    /// buffers).
    pub(crate) fn strictly_inside(&self, x: &[f64], w: &mut IpmWork) -> bool {
        let f = self.frame;
        let k = f.vars();
        let rows = (0..f.rhs.len()).all(|r| {
            f.rows[r * k..r * k + k].iter().zip(x).map(|(a, b)| a * b).sum::<f64>() < f.rhs[r]
        });
        rows && margin_exceeds(f, x, self.requirements.margin, &mut w.a)
            && self.floors().into_iter().flatten().all(|(floor, tau, _)| {
                floor_value(f, x, &floor, &mut w.end).is_some_and(|v| v > tau)
            })
    }

    /// `x` when strictly inside; else one least-norm step onto the linearised violated rows
    /// and margin (each moved a little inside), kept when it lands strictly inside: into
    /// `w.x`, and whether there is one.
    pub(crate) fn restored(&self, x: &[f64], w: &mut IpmWork) -> bool {
        if self.strictly_inside(x, w) {
            w.x.clear();
            w.x.extend_from_slice(x);
            return true;
        }
        let f = self.frame;
        let (k, n) = (f.vars(), f.n);
        // Active constraints as J d = b.
        let (mut jac, mut b): (Vec<Vec<f64>>, Vec<f64>) = (Vec::new(), Vec::new());
        const INSIDE: f64 = 1e-4;
        for r in 0..f.rhs.len() {
            let g = &f.rows[r * k..r * k + k];
            let slack = f.rhs[r] - g.iter().zip(x).map(|(a, c)| a * c).sum::<f64>();
            if slack < INSIDE {
                jac.push(g.to_vec());
                b.push(slack - INSIDE);
            }
        }
        let m = self.requirements.margin;
        let mut a = vec![0.0; n * n];
        f.a_at(x, &mut a);
        let eigen = DMatrix::from_row_slice(n, n, &a).symmetric_eigen();
        let i = eigen.eigenvalues.imin();
        let needed = m + INSIDE * f.a_scale.max(m);
        if eigen.eigenvalues[i] < needed {
            let v = eigen.eigenvectors.column(i);
            let v: Vec<f64> = v.iter().copied().collect();
            let h: Vec<f64> = (0..k).map(|a| f.ai_form(a, &v)).collect();
            jac.push(h.iter().map(|v| -v).collect());
            b.push(eigen.eigenvalues[i] - needed);
        }
        let p = jac.len();
        let gram =
            DMatrix::from_fn(p, p, |r, c| jac[r].iter().zip(&jac[c]).map(|(u, w)| u * w).sum());
        let Some(factor) = gram.cholesky() else { return false };
        let steps = factor.solve(&nalgebra::DVector::from_vec(b));
        let mut restored = x.to_vec();
        for (row, wr) in jac.iter().zip(steps.iter()) {
            for (xa, g) in restored.iter_mut().zip(row) {
                *xa += wr * g;
            }
        }
        let inside = self.strictly_inside(&restored, w);
        if inside {
            w.x.clone_from(&restored);
        }
        inside
    }
}
