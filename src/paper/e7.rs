//! E7 (beyond the paper, spec §10): when tension stiffens. The closed form of `tension.rs`
//! beside the numbers, for a set of hole geometries and over a map of `d1` against `d2` at
//! cdhrm5's hole radius, and conclusion (1) checked with its condition attached.

use std::fmt::Write as _;

use crate::indicators::JointProbe;
use crate::robot::Robot;
use crate::routing::{Routing, RoutingSpec};

use super::claim::Claim;
use super::experiments::{
    E3_RANGE, E7_MIN_GAP, E7_OFF_CENTRE, E7_POINTS, E7_POSES, E7_RANGE_MM, TABLE_2_TORQUE,
};
use super::fixed;
use super::tension::{
    HoleGeometry, TensionEffect, classify_q0, criterion_q0, eigenvalues, joint_geometry,
    single_joint, tension_stiffness, zero_tolerance,
};

/// `A_i` of one geometry: at Q0 and over the workspace.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct E7Cell {
    /// Eigenvalues of `A_i(Q0)`, computed (routing's `H_c`, statics' `N`), m.
    pub q0: [f64; 2],
    /// Their class.
    pub q0_class: TensionEffect,
    /// The smallest and the largest eigenvalue of `A_i` over the [`E7_POSES`]² poses, m.
    pub workspace: [f64; 2],
    /// The class over the workspace: stiffens (or softens) when `A_i ⪰ 0` (`⪯ 0`) at every
    /// pose, indefinite when it is indefinite at one or changes sign between poses.
    pub workspace_class: TensionEffect,
}

/// One row of E7's table: a named geometry, the closed form and the numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct E7Case {
    /// What the geometry is.
    pub name: String,
    /// Its holes.
    pub geometry: HoleGeometry,
    /// The closed form's `c = −d1 d2/(d1 + d2)`, m (E7.5).
    pub criterion: f64,
    /// The closed form's class at Q0.
    pub closed_form: Option<TensionEffect>,
    /// The numbers.
    pub cell: E7Cell,
    /// `K_x` at Q0 holding Table II's torque, at the lowest and the highest tension, N m/rad.
    pub k_x: [f64; 2],
    /// `K_y`, the same.
    pub k_y: [f64; 2],
}

/// E7's map: [`E7Cell`]s over `d1` (first index) and `d2` (second) at one hole radius.
#[derive(Debug, Clone, PartialEq)]
pub struct E7Map {
    /// The values of `d1` and of `d2` on the grid, m (both axes alike).
    pub axis: Vec<f64>,
    /// The hole radius, m.
    pub radius: f64,
    /// `cells[a · n + b]` at `d1 = axis[a]`, `d2 = axis[b]`; `None` where the gap
    /// `d1 + d2 < `[`E7_MIN_GAP`] or the joint has no null direction.
    pub cells: Vec<Option<E7Cell>>,
}

impl E7Map {
    /// The cell at `d1 = axis[a]`, `d2 = axis[b]`.
    pub fn cell(&self, a: usize, b: usize) -> Option<&E7Cell> {
        self.cells.get(a * self.axis.len() + b).and_then(Option::as_ref)
    }

    /// How many cells the closed form classifies as the numbers do at Q0, and how many cells
    /// there are.
    pub fn closed_form_agreement(&self) -> (usize, usize) {
        let n = self.axis.len();
        let (mut agree, mut total) = (0, 0);
        for a in 0..n {
            for b in 0..n {
                if let Some(c) = self.cell(a, b) {
                    let g =
                        HoleGeometry { d1: self.axis[a], d2: self.axis[b], radius: self.radius };
                    total += 1;
                    agree += usize::from(
                        classify_q0(g.d1, g.d2, zero_tolerance(&g)) == Some(c.q0_class),
                    );
                }
            }
        }
        (agree, total)
    }

    /// The number of cells of each workspace class, in [`TensionEffect`]'s order.
    pub fn workspace_counts(&self) -> Vec<(TensionEffect, usize)> {
        let mut counts = std::collections::BTreeMap::new();
        for c in self.cells.iter().flatten() {
            *counts.entry(c.workspace_class).or_insert(0) += 1;
        }
        counts.into_iter().collect()
    }
}

/// E7: the cases, the map and the claim.
#[derive(Debug, Clone, PartialEq)]
pub struct E7 {
    /// The table's geometries, cdhrm5's first and the off-centre one second.
    pub cases: Vec<E7Case>,
    /// The map at cdhrm5's hole radius.
    pub map: E7Map,
    /// Conclusion (1) with its condition.
    pub claim: Claim,
}

/// The poses where the workspace class is decided: [`E7_POSES`]² over the joint limits.
fn poses() -> Vec<[f64; 2]> {
    let step =
        |k: usize| E3_RANGE[0] + (E3_RANGE[1] - E3_RANGE[0]) * k as f64 / (E7_POSES - 1) as f64;
    (0..E7_POSES).flat_map(|a| (0..E7_POSES).map(move |b| [step(a), step(b)])).collect()
}

/// The numbers of one geometry.
fn cell(template: &RoutingSpec, g: HoleGeometry) -> Result<E7Cell, crate::Error> {
    let (robot, routing) = single_joint(template, g)?;
    let tol = zero_tolerance(&g);
    let q0 = eigenvalues(&tension_stiffness(&robot, &routing, [0.0, 0.0])?);
    let mut workspace = [f64::INFINITY, f64::NEG_INFINITY];
    let (mut weak_up, mut weak_down, mut indefinite) = (true, true, false);
    for q in poses() {
        let e = eigenvalues(&tension_stiffness(&robot, &routing, q)?);
        workspace = [workspace[0].min(e[0]), workspace[1].max(e[1])];
        let class = TensionEffect::of_eigenvalues(e, tol);
        weak_up &= class.tension_never_softens();
        weak_down &= class.tension_never_stiffens();
        indefinite |= class == TensionEffect::Indefinite;
    }
    let workspace_class = match (indefinite, weak_up, weak_down) {
        (false, true, true) => TensionEffect::Neutral,
        (false, true, false) => TensionEffect::Stiffens,
        (false, false, true) => TensionEffect::Softens,
        _ => TensionEffect::Indefinite,
    };
    Ok(E7Cell { q0, q0_class: TensionEffect::of_eigenvalues(q0, tol), workspace, workspace_class })
}

fn case(template: &RoutingSpec, name: &str, g: HoleGeometry) -> Result<E7Case, crate::Error> {
    let (robot, routing) = single_joint(template, g)?;
    let range = JointProbe::new(&robot, &routing, 0)?.evaluate(
        &robot,
        &routing,
        [0.0, 0.0],
        TABLE_2_TORQUE,
    )?;
    Ok(E7Case {
        name: name.to_owned(),
        geometry: g,
        criterion: criterion_q0(g.d1, g.d2),
        closed_form: classify_q0(g.d1, g.d2, zero_tolerance(&g)),
        cell: cell(template, g)?,
        k_x: [range.k_at_min[(0, 0)], range.k_at_max[(0, 0)]],
        k_y: [range.k_at_min[(1, 1)], range.k_at_max[(1, 1)]],
    })
}

/// E7 on joint 1 of `robot` with its (pattern) `routing`, read from `template`, the text of
/// its routing file: the table's geometries and the map at its hole radius.
///
/// # Errors
/// A routing not of the pattern form; geometry errors of the table's cases.
pub fn e7(robot: &Robot, routing: &Routing, template: &RoutingSpec) -> Result<E7, crate::Error> {
    let radius = template
        .pattern
        .as_ref()
        .and_then(|p| p.radius.as_ref())
        .and_then(|r| r.get(0))
        .unwrap_or(f64::NAN);
    let paper = joint_geometry(robot, routing, 0, radius)?;
    let mm = 1e-3;
    let [d1, d2] = E7_OFF_CENTRE;
    let named = [
        ("cdhrm5, the paper's platform (fitted)", paper),
        ("off-centre: CASPR snake's hole planes", HoleGeometry { d1, d2, radius }),
        ("the same, r = 10 mm", HoleGeometry { d1, d2, radius: 10.0 * mm }),
        ("centre mid-gap", HoleGeometry { d1: 15.0 * mm, d2: 15.0 * mm, radius }),
        ("centre on the proximal disc", HoleGeometry { d1: 0.0, d2: 30.0 * mm, radius }),
        ("centre outside the gap", HoleGeometry { d1: 35.0 * mm, d2: -5.0 * mm, radius }),
        ("centre outside, narrow gap", HoleGeometry { d1: -5.0 * mm, d2: 10.0 * mm, radius }),
    ];
    let cases =
        named.iter().map(|(name, g)| case(template, name, *g)).collect::<Result<Vec<_>, _>>()?;
    let n = E7_POINTS;
    let axis: Vec<f64> = (0..n)
        .map(|k| {
            let lo = E7_RANGE_MM[0];
            (lo + (E7_RANGE_MM[1] - lo) * k as f64 / (n - 1) as f64) * mm
        })
        .collect();
    let mut cells = Vec::with_capacity(n * n);
    for &d1 in &axis {
        for &d2 in &axis {
            let g = HoleGeometry { d1, d2, radius };
            cells.push((d1 + d2 >= E7_MIN_GAP).then(|| cell(template, g).ok()).flatten());
        }
    }
    let map = E7Map { axis, radius, cells };
    let claim = claim_e7(&cases, &map);
    Ok(E7 { cases, map, claim })
}

fn claim_e7(cases: &[E7Case], map: &E7Map) -> Claim {
    let text = "Conclusion (1) with its condition (E7): more tension, more stiffness holds where A_i = Σ N_c H_c ⪰ 0. At Q0 A_i = −d1·d2/(d1 + d2)·ΣN·I, so it needs d1·d2 ≤ 0 (the holes not on both sides of the joint centre); away from Q0 that is not enough (a gap narrow against the hole radius makes A_i indefinite at bent poses, see the map). cdhrm5 (d2 = 0) meets it at every pose of the grid over its workspace, the off-centre geometry does not";
    let (Some(paper), Some(off)) = (cases.first(), cases.get(1)) else {
        return Claim::unchecked(text, "no geometries");
    };
    let (agree, total) = map.closed_form_agreement();
    // Necessity over the map: wherever d1·d2 > 0, tension softens some pose.
    let n = map.axis.len();
    let necessary = (0..n * n).all(|k| {
        let (d1, d2) = (map.axis[k / n], map.axis[k % n]);
        map.cell(k / n, k % n)
            .is_none_or(|c| d1 * d2 <= 0.0 || c.workspace_class != TensionEffect::Stiffens)
    });
    let holds = necessary
        && paper.cell.workspace_class.tension_never_softens()
        && off.closed_form == Some(TensionEffect::Softens)
        && off.cell.q0_class == TensionEffect::Softens
        && off.k_x[1] < off.k_x[0]
        && agree == total
        && total > 0;
    let mm = |x: f64| fixed(1e3 * x, 3);
    let evidence = format!(
        "ours: cdhrm5 (d1 = {} mm, d2 = {} mm): A_i(Q0) eigenvalues [{}, {}] mm, over the workspace [{}, {}] mm ({}); off-centre (d1 = {} mm, d2 = {} mm): closed form c = {} mm, A_i(Q0) eigenvalues [{}, {}] mm, K_x at Q0 from {} to {} N m/rad as tension rises, over the workspace [{}, {}] mm ({}); the closed form classifies {agree} of {total} map points as the numbers do; no map point with d1·d2 > 0 has A_i ⪰ 0 over the workspace: {necessary}",
        mm(paper.geometry.d1),
        mm(paper.geometry.d2),
        mm(paper.cell.q0[0]),
        mm(paper.cell.q0[1]),
        mm(paper.cell.workspace[0]),
        mm(paper.cell.workspace[1]),
        paper.cell.workspace_class.label(),
        mm(off.geometry.d1),
        mm(off.geometry.d2),
        mm(off.criterion),
        mm(off.cell.q0[0]),
        mm(off.cell.q0[1]),
        fixed(off.k_x[0], 3),
        fixed(off.k_x[1], 3),
        mm(off.cell.workspace[0]),
        mm(off.cell.workspace[1]),
        off.cell.workspace_class.label(),
    );
    Claim::checked(text, holds, evidence)
}

/// E7's table and map summary as markdown.
pub fn render_e7(e7: &E7) -> String {
    let mut s = String::new();
    let mm = |x: f64| fixed(1e3 * x, 3);
    let class = |c: Option<TensionEffect>| c.map_or("—", TensionEffect::label);
    let _ = writeln!(
        s,
        "| geometry | d1 (mm) | d2 (mm) | r (mm) | c = −d1·d2/(d1 + d2) (mm) | closed form at Q0 | λ(A_i(Q0)) (mm) | numbers at Q0 | λ(A_i) over the workspace (mm) | over the workspace | K_x at Q0: lowest → highest tension (N m/rad) | K_y (N m/rad) |"
    );
    let _ =
        writeln!(s, "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    for c in &e7.cases {
        let g = c.geometry;
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | [{}, {}] | {} | [{}, {}] | {} | {} → {} | {} → {} |",
            c.name,
            mm(g.d1),
            mm(g.d2),
            mm(g.radius),
            mm(c.criterion),
            class(c.closed_form),
            mm(c.cell.q0[0]),
            mm(c.cell.q0[1]),
            c.cell.q0_class.label(),
            mm(c.cell.workspace[0]),
            mm(c.cell.workspace[1]),
            c.cell.workspace_class.label(),
            fixed(c.k_x[0], 3),
            fixed(c.k_x[1], 3),
            fixed(c.k_y[0], 3),
            fixed(c.k_y[1], 3),
        );
    }
    let (agree, total) = e7.map.closed_form_agreement();
    let n = e7.map.axis.len();
    let _ = writeln!(
        s,
        "\nMap: d1, d2 ∈ [{}, {}] mm on a {n} × {n} grid at r = {} mm, points with d1 + d2 ≥ {} mm: {total}. At Q0 the closed form classifies {agree} of them as the numbers do. Over the workspace ({E7_POSES} × {E7_POSES} poses in [−π/6, π/6]²):",
        fixed(E7_RANGE_MM[0], 1),
        fixed(E7_RANGE_MM[1], 1),
        mm(e7.map.radius),
        mm(E7_MIN_GAP),
    );
    for (class, count) in e7.map.workspace_counts() {
        let _ = writeln!(s, "- {}: {count} points", class.label());
    }
    let _ = writeln!(s, "\n{}", super::claims::render_claims(std::slice::from_ref(&e7.claim)));
    s
}
