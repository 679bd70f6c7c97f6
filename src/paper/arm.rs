//! E4 (Fig. 6): the 10-DOF arm in the paper's pose under a 5 N load — equilibrium torques,
//! every joint's tension interval and stiffness range, the four tension cases (a)–(d) of the
//! end stiffness `K_fd` with their ellipsoids and stability margins, and the paper's
//! conclusions (1)–(3) checked against the numbers (spec §6).

use std::fmt::Write as _;

use nalgebra::{Matrix3, Vector3, Vector6};

use crate::indicators::StiffnessEllipsoid;
use crate::robot::Robot;
use crate::routing::Routing;
use crate::statics::TensionChoice;
use crate::stiffness::{ArmStiffness, ArmStiffnessData, EndOutcome, StiffnessError};

use super::claims::Claim;
use super::experiments::{E4_CASES, E4_F0, E4_Q};
use super::fixed;

/// One joint of E4: its tension interval and the range of its stiffness.
#[derive(Debug, Clone, PartialEq)]
pub struct E4Joint {
    /// Tensions at the lowest and the highest level, N.
    pub tensions: [[f64; 3]; 2],
    /// `[K_x at level 0, at level 1]`, N m/rad (the other joints at level 0).
    pub k_x: [f64; 2],
    /// `[K_y at level 0, at level 1]`, N m/rad.
    pub k_y: [f64; 2],
}

/// One of the cases (a)–(d): tension levels and what they give.
#[derive(Debug, Clone, PartialEq)]
pub struct E4Case {
    /// `(a)` … `(d)` and what is raised.
    pub name: &'static str,
    /// Tension level of each joint.
    pub levels: [f64; 5],
    /// Smallest eigenvalue of `K_q + K_W`, N m/rad (negative: unstable). `None` if infeasible.
    pub margin: Option<f64>,
    /// `K_fd` (N/m) and its ellipsoid, when the equilibrium is feasible and stable.
    pub k_fd: Option<(Matrix3<f64>, StiffnessEllipsoid)>,
    /// Why there is no `K_fd`, when there is none.
    pub failure: Option<String>,
}

/// E4 for one routing model.
#[derive(Debug, Clone, PartialEq)]
pub struct E4 {
    /// `decoupled` or `routed`.
    pub model: String,
    /// Tension level of the joints a case does not raise (0 in the paper).
    pub baseline: f64,
    /// `T0 = T_g + J_xᵀ F0`, N m.
    pub t0: Vec<f64>,
    /// Every joint, base first. Empty when the lowest levels are infeasible.
    pub joints: Vec<E4Joint>,
    /// The cases (a)–(d).
    pub cases: Vec<E4Case>,
}

impl E4 {
    /// The run's name in claims and figures: the routing model, and the baseline level when it
    /// is not the paper's 0 (e.g. `decoupled with stable baseline 0.25`).
    pub fn name(&self) -> String {
        if self.baseline == 0.0 {
            self.model.clone()
        } else {
            format!("{} with stable baseline {}", self.model, fixed(self.baseline, 2))
        }
    }
}

/// Run E4 on a five-joint robot with a routing; the joints a case does not raise sit at
/// tension level `baseline` (0 in the paper).
///
/// # Errors
/// Only for a routing the statics cannot handle; infeasible or unstable cases are recorded.
pub fn e4(
    robot: &Robot,
    routing: &Routing,
    model: &str,
    baseline: f64,
) -> Result<E4, crate::Error> {
    let arm = ArmStiffness::new(robot, routing)?;
    let mut data = ArmStiffnessData::new(&arm);
    let f0 = Vector6::from_row_slice(&E4_F0);
    let mut joints = Vec::new();
    // One pose stage for every tension case below.
    arm.set_pose(&mut data, &E4_Q, &f0)?;
    let t0 = data.statics.t0.clone();
    let lowest = arm.set_tensions(&mut data, TensionChoice::Levels(&[0.0; 5]));
    if lowest.is_ok() {
        let base: Vec<[f64; 2]> = (0..5)
            .map(|i| data.joint_stiffness(i).map_or([0.0; 2], |k| [k[(0, 0)], k[(1, 1)]]))
            .collect();
        let intervals = data.intervals().to_vec();
        for i in 0..5 {
            let mut levels = [0.0; 5];
            levels[i] = 1.0;
            let high = match arm.set_tensions(&mut data, TensionChoice::Levels(&levels)) {
                Ok(()) => data.joint_stiffness(i).map_or([f64::NAN; 2], |k| [k[(0, 0)], k[(1, 1)]]),
                Err(_) => [f64::NAN; 2],
            };
            let (lo, hi) = intervals[i].ends();
            joints.push(E4Joint {
                tensions: [[lo[0], lo[1], lo[2]], [hi[0], hi[1], hi[2]]],
                k_x: [base[i][0], high[0]],
                k_y: [base[i][1], high[1]],
            });
        }
    }
    let mut cases = Vec::new();
    for (name, raised) in E4_CASES {
        let levels = raised.map(|r| if r { 1.0 } else { baseline });
        let mut case = E4Case { name, levels, margin: None, k_fd: None, failure: None };
        if let Err(e) = arm.set_tensions(&mut data, TensionChoice::Levels(&levels)) {
            case.failure = Some(format!("infeasible: {e}"));
            cases.push(case);
            continue;
        }
        arm.solve_end(&mut data)?;
        let outcome = data
            .outcome()
            .ok_or(StiffnessError::StageMissing { needs: "solve_end", missing: "end stage" })?;
        case.margin = Some(outcome.margin()?);
        match outcome.end() {
            EndOutcome::Stiff => {
                let k = data.k_fd();
                case.k_fd = Some((k, StiffnessEllipsoid::new(&k)?));
            }
            EndOutcome::Unstable { min_eigenvalue } => {
                case.failure = Some(format!(
                    "unstable equilibrium: K_q + K_W has the eigenvalue {} N m/rad",
                    fixed(min_eigenvalue, 3)
                ));
            }
            end @ EndOutcome::RankDeficient { .. } => {
                case.failure = end.into_result().err().map(|e| e.to_string());
            }
        }
        cases.push(case);
    }
    Ok(E4 { model: model.to_owned(), baseline, t0, joints, cases })
}

fn vector(v: &[f64], decimals: usize) -> String {
    let parts: Vec<String> = v.iter().map(|x| fixed(*x, decimals)).collect();
    format!("[{}]", parts.join(", "))
}

/// E4 as markdown: T0, the joints table, the cases table.
pub fn render_e4(e4: &E4) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Routing model: **{}**; joints not raised at tension level {}.\n",
        e4.model,
        fixed(e4.baseline, 2)
    );
    let _ = writeln!(s, "T0 = {} N m\n", vector(&e4.t0, 3));
    if e4.joints.is_empty() {
        let _ = writeln!(s, "The lowest tension levels are infeasible: no joint table.\n");
    } else {
        let _ = writeln!(
            s,
            "| joint | tensions at lowest level (N) | tensions at highest level (N) | K_x: lowest → highest (N m/rad) | K_y: lowest → highest (N m/rad) | Δk_x | Δk_y |"
        );
        let _ = writeln!(s, "| --- | --- | --- | --- | --- | --- | --- |");
        for (i, j) in e4.joints.iter().enumerate() {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} → {} | {} → {} | {} | {} |",
                i + 1,
                vector(&j.tensions[0], 1),
                vector(&j.tensions[1], 1),
                fixed(j.k_x[0], 3),
                fixed(j.k_x[1], 3),
                fixed(j.k_y[0], 3),
                fixed(j.k_y[1], 3),
                fixed(j.k_x[1] - j.k_x[0], 3),
                fixed(j.k_y[1] - j.k_y[0], 3),
            );
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(
        s,
        "| case | stability margin (N m/rad) | eigenvalues of K_fd (N/m) | semi-axes (m/N) | principal directions (columns) | volume (m³/N³) |"
    );
    let _ = writeln!(s, "| --- | --- | --- | --- | --- | --- |");
    for c in &e4.cases {
        let margin = c.margin.map_or("—".to_owned(), |m| fixed(m, 3));
        match (&c.k_fd, &c.failure) {
            (Some((_, e)), _) => {
                let dirs: Vec<String> = (0..3)
                    .map(|k| {
                        vector(
                            &[e.directions[(0, k)], e.directions[(1, k)], e.directions[(2, k)]],
                            3,
                        )
                    })
                    .collect();
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {} | {} |",
                    c.name,
                    margin,
                    vector(e.eigenvalues.as_slice(), 3),
                    e.semi_axes().map_or("—".to_owned(), |a| vector(a.as_slice(), 4)),
                    dirs.join(" "),
                    e.volume().map_or("—".to_owned(), |v| format!("{v:.4e}")),
                );
            }
            (None, failure) => {
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | | | |",
                    c.name,
                    margin,
                    failure.clone().unwrap_or_default()
                );
            }
        }
    }
    s
}

fn ellipsoid(e4: &E4, k: usize) -> Option<&StiffnessEllipsoid> {
    e4.cases.get(k).and_then(|c| c.k_fd.as_ref()).map(|(_, e)| e)
}

/// Relative change of the directional stiffness along (a)'s principal directions.
fn directional_gain(a: &StiffnessEllipsoid, b: &StiffnessEllipsoid) -> Option<Vector3<f64>> {
    let mut gain = Vector3::zeros();
    for k in 0..3 {
        let u: Vector3<f64> = a.directions.column(k).into_owned();
        let before = a.directional_stiffness(&u).ok()?;
        let after = b.directional_stiffness(&u).ok()?;
        gain[k] = (after - before) / before;
    }
    Some(gain)
}

/// The run's label in evidence: model and baseline level.
fn label(e4: &E4) -> String {
    format!("{}, baseline level {}", e4.model, fixed(e4.baseline, 2))
}

/// The paper's conclusions (1) and (2) on E4's joints, and (3) on its end stiffness.
pub fn claims_e4(e4: &E4) -> Vec<Claim> {
    let mut claims = claims_e4_joints(e4);
    claims.extend(claims_e4_end(e4));
    claims
}

/// Conclusions (1) and (2) on E4's joint table (each joint from its lowest to its highest
/// level, the others at their lowest).
pub fn claims_e4_joints(e4: &E4) -> Vec<Claim> {
    let mut claims = Vec::new();
    let unavailable = |claim: &str, why: &str| Claim::unchecked(claim, why);

    // (1) more tension, more joint stiffness.
    let c1 = format!(
        "Conclusion (1), {}: more cable tension, more joint stiffness (E4, every joint)",
        e4.name()
    );
    if e4.joints.is_empty() {
        claims.push(unavailable(&c1, "the lowest tension levels are infeasible"));
    } else {
        let rises = e4.joints.iter().all(|j| j.k_x[1] > j.k_x[0] && j.k_y[1] > j.k_y[0]);
        let evidence: Vec<String> = e4
            .joints
            .iter()
            .enumerate()
            .map(|(i, j)| {
                format!(
                    "joint {}: Δk_x = {}, Δk_y = {}",
                    i + 1,
                    fixed(j.k_x[1] - j.k_x[0], 3),
                    fixed(j.k_y[1] - j.k_y[0], 3)
                )
            })
            .collect();
        claims.push(Claim::checked(
            c1,
            rises,
            format!("ours ({}): {}", e4.model, evidence.join("; ")),
        ));
    }
    // (2) larger joint angles widen the range: in E4, joint 3 (largest angles) has the widest range.
    let c2 = format!(
        "Conclusion (2), {}: the joint with the largest angles (joint 3) has the widest adjustable range",
        e4.name()
    );
    if e4.joints.is_empty() {
        claims.push(unavailable(&c2, "the lowest tension levels are infeasible"));
    } else {
        let width: Vec<f64> =
            e4.joints.iter().map(|j| (j.k_x[1] - j.k_x[0]) + (j.k_y[1] - j.k_y[0])).collect();
        let widest = width
            .iter()
            .enumerate()
            .fold(0, |best, (i, w)| if *w > width[best] { i } else { best });
        claims.push(Claim::checked(
            c2,
            widest == 2,
            format!(
                "ours ({}): Δk_x + Δk_y by joint = {} N m/rad; widest: joint {}",
                e4.model,
                vector(&width, 3),
                widest + 1
            ),
        ));
    }
    claims
}

/// Conclusion (3) on E4's cases (a)–(d): joint 3 changes the end stiffness most but not in every
/// direction; joint 5 mainly in one direction; 3 and 5 together complement each other.
pub fn claims_e4_end(e4: &E4) -> Vec<Claim> {
    let mut claims = Vec::new();
    let unavailable = |claim: &str, why: &str| Claim::unchecked(claim, why);
    let c3 = format!(
        "Conclusion (3), {}: raising joint 3 changes K_fd most, but not in every direction; joint 5 helps mainly in one direction; joints 3 and 5 together complement each other",
        e4.name()
    );
    let c3 = c3.as_str();
    match (ellipsoid(e4, 0), ellipsoid(e4, 1), ellipsoid(e4, 2), ellipsoid(e4, 3)) {
        (Some(a), Some(b), Some(c), Some(d)) => {
            let change = |x: &StiffnessEllipsoid| (x.k_fd - a.k_fd).norm();
            let (gb, gc) = (directional_gain(a, b), directional_gain(a, c));
            let (Some(gb), Some(gc)) = (gb, gc) else {
                claims.push(unavailable(c3, "a directional stiffness is undefined"));
                return claims;
            };
            let most = change(b) > change(c);
            let uneven_b = gb.max() > 2.0 * gb.min().max(1e-12);
            let mut sorted_c = [gc[0], gc[1], gc[2]];
            sorted_c.sort_by(|x, y| y.total_cmp(x));
            let one_direction_c = sorted_c[0] > 2.0 * sorted_c[1].max(1e-12);
            let complement = d.lambda_min() >= b.lambda_min().max(c.lambda_min());
            claims.push(Claim::checked(
                c3,
                most && uneven_b && one_direction_c && complement,
                format!(
                    "ours ({}): |K_fd(b) − K_fd(a)| = {} vs |K_fd(c) − K_fd(a)| = {} N/m ({}); relative gain along (a)'s principal directions: (b) {} ({}), (c) {} ({}); λ_min: (a) {}, (b) {}, (c) {}, (d) {} N/m ({})",
                    label(e4),
                    fixed(change(b), 3),
                    fixed(change(c), 3),
                    if most { "joint 3 most" } else { "joint 3 not most" },
                    vector(gb.as_slice(), 3),
                    if uneven_b { "uneven" } else { "even" },
                    vector(gc.as_slice(), 3),
                    if one_direction_c { "one direction" } else { "several directions" },
                    fixed(a.lambda_min(), 3),
                    fixed(b.lambda_min(), 3),
                    fixed(c.lambda_min(), 3),
                    fixed(d.lambda_min(), 3),
                    if complement { "(d) stiffest in its softest direction" } else { "(d) not the stiffest" },
                ),
            ));
        }
        _ => {
            let why: Vec<String> = e4
                .cases
                .iter()
                .filter(|c| c.k_fd.is_none())
                .map(|c| format!("{}: {}", c.name, c.failure.clone().unwrap_or_default()))
                .collect();
            claims.push(unavailable(c3, &why.join("; ")));
        }
    }
    claims
}

/// Routed beside decoupled (beyond the paper): how much the distal cables stiffen the proximal
/// joints, and what that does to the end stiffness and the stability margin.
pub fn render_routed_vs_decoupled(decoupled: &E4, routed: &E4) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "In the routed model a cable of joint i also crosses joints 1 … i−1, so its tension and"
    );
    let _ = writeln!(
        s,
        "elasticity load and stiffen them (`K_q` is full). Joint stiffness with every joint at its lowest"
    );
    let _ = writeln!(s, "level (N m/rad):\n");
    let _ = writeln!(s, "| joint | K_x decoupled | K_x routed | K_y decoupled | K_y routed |");
    let _ = writeln!(s, "| --- | --- | --- | --- | --- |");
    for i in 0..5 {
        let cell = |e: &E4, x: bool| {
            e.joints
                .get(i)
                .map_or("—".to_owned(), |j| fixed(if x { j.k_x[0] } else { j.k_y[0] }, 3))
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} |",
            i + 1,
            cell(decoupled, true),
            cell(routed, true),
            cell(decoupled, false),
            cell(routed, false)
        );
    }
    let _ = writeln!(s, "\nEnd stiffness and stability, case by case:\n");
    let _ = writeln!(
        s,
        "| case | margin decoupled | margin routed | λ(K_fd) decoupled (N/m) | λ(K_fd) routed (N/m) |"
    );
    let _ = writeln!(s, "| --- | --- | --- | --- | --- |");
    for (d, r) in decoupled.cases.iter().zip(&routed.cases) {
        let margin = |c: &E4Case| c.margin.map_or("infeasible".to_owned(), |m| fixed(m, 3));
        let eig = |c: &E4Case| {
            c.k_fd.as_ref().map_or_else(
                || {
                    c.failure
                        .clone()
                        .map_or("—".to_owned(), |f| f.split(':').next().unwrap_or("").to_owned())
                },
                |(_, e)| vector(e.eigenvalues.as_slice(), 3),
            )
        };
        let _ =
            writeln!(s, "| {} | {} | {} | {} | {} |", d.name, margin(d), margin(r), eig(d), eig(r));
    }
    s
}
