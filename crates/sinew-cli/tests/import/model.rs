//! The synthetic CASPR model of crates/sinew-import/tests/data/universal_*.xml (cable set
//! `basic`), rebuilt here from the XML's numbers alone: its kinematics, each cable's length and
//! its first and second derivatives (product rule on the rotations, no finite differences), and
//! the paper's statics on it. Nothing here calls Sinew: the import test compares the `sinew`
//! commands' JSON with these numbers.

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

pub type V3 = Vector3<f64>;

/// CASPR's defaults in `sinew import caspr`: E = 200 GPa, d = 1 mm, free length 0.5 m.
pub const YOUNGS_MODULUS: f64 = 200e9;
pub const DIAMETER: f64 = 1e-3;
pub const FREE_LENGTH: f64 = 0.5;
/// force_min, force_max of every cable of `basic`.
pub const LIMITS: [f64; 2] = [5.0, 300.0];
pub const GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

/// The revolute joints, base first: (origin in the parent frame, unit axis). Link 1
/// (`base_side`, U_XY) sits at `<location>0 0 0.03` of the base, link 2 (`tip_side`, U_XZ) at
/// `0 0 0.13` of link 1; a universal joint's second axis has no translation.
const JOINTS: [([f64; 3], [f64; 3]); 4] = [
    ([0.0, 0.0, 0.03], [1.0, 0.0, 0.0]),
    ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
    ([0.0, 0.0, 0.13], [1.0, 0.0, 0.0]),
    ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
];

/// Link l's frame follows joints 0..LAST[l].
const LAST: [usize; 3] = [0, 2, 4];

/// (mass, centre of mass in the link frame) of links 1 and 2 (`<com_location>`).
pub const MASSES: [(usize, f64, [f64; 3]); 2] =
    [(1, 0.3, [0.0, 0.0, 0.05]), (2, 0.2, [0.0, 0.0, 0.04])];

/// The tip: `<end_location>` of link 2.
pub const TIP: (usize, [f64; 3]) = (2, [0.0, 0.0, 0.09]);

/// One hole: (link, point in the link's joint frame).
pub type Hole = (usize, [f64; 3]);

/// The six cables of `basic`: a1..a3 (attachment_reference="joint") from the base to link 1;
/// b1..b3 ("com": CASPR's z 0.01 and 0.05 on link 1 are 0.06 and 0.1 in its joint frame, its com
/// being at 0.05; 0.03 on link 2 is 0.07, its com at 0.04) from the base through link 1 to link 2.
pub fn cables() -> Vec<(&'static str, Vec<Hole>)> {
    let a = |x: f64, y: f64| vec![(0, [x, y, 0.0]), (1, [x, y, 0.1])];
    let b = |x: f64, y: f64| {
        vec![(0, [x, y, 0.0]), (1, [x, y, 0.06]), (1, [x, y, 0.1]), (2, [x, y, 0.07])]
    };
    vec![
        ("a1", a(0.019107, 0.00591)),
        ("a2", a(-0.014672, 0.013592)),
        ("a3", a(-0.004435, -0.019502)),
        ("b1", b(0.005544, 0.024378)),
        ("b2", b(-0.023883, -0.007388)),
        ("b3", b(0.01834, -0.01699)),
    ]
}

fn skew(a: &V3) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// The `order`-th derivative of the rotation by `q` about the unit `axis`: R(q) Sⁿ, S = [a]×.
fn rotation(axis: &V3, q: f64, order: usize) -> Matrix3<f64> {
    let s = skew(axis);
    let r = Matrix3::identity() + s * q.sin() + s * s * (1.0 - q.cos());
    (0..order).fold(r, |m, _| m * s)
}

/// The derivative of a point fixed in `link`, in the base frame, taken `orders[j]` times
/// with respect to q_j (the base point itself when every order is 0).
pub fn point(link: usize, p: [f64; 3], q: &[f64; 4], orders: [usize; 4]) -> V3 {
    if (LAST[link]..4).any(|j| orders[j] > 0) {
        return V3::zeros();
    }
    let mut v = V3::from(p);
    let mut constant = true;
    for j in (0..LAST[link]).rev() {
        let (origin, axis) = JOINTS[j];
        v = rotation(&V3::from(axis), q[j], orders[j]) * v;
        if orders[j] == 0 && constant {
            v += V3::from(origin);
        }
        constant &= orders[j] == 0;
    }
    v
}

fn unit(i: usize) -> [usize; 4] {
    let mut o = [0; 4];
    o[i] += 1;
    o
}

fn pair(i: usize, j: usize) -> [usize; 4] {
    let mut o = unit(i);
    o[j] += 1;
    o
}

/// A polyline's length L(Q), ∂L/∂Q and ∂²L/∂Q².
pub fn length(holes: &[Hole], q: &[f64; 4]) -> (f64, DVector<f64>, DMatrix<f64>) {
    let (mut l, mut jac, mut hess) = (0.0, DVector::zeros(4), DMatrix::zeros(4, 4));
    for w in holes.windows(2) {
        let d = |o: [usize; 4]| point(w[1].0, w[1].1, q, o) - point(w[0].0, w[0].1, q, o);
        let s = d([0; 4]);
        let (n, u) = (s.norm(), s.normalize());
        l += n;
        let di: Vec<V3> = (0..4).map(|i| d(unit(i))).collect();
        for i in 0..4 {
            jac[i] += u.dot(&di[i]);
            for j in 0..4 {
                hess[(i, j)] +=
                    (di[i].dot(&di[j]) - u.dot(&di[i]) * u.dot(&di[j])) / n + u.dot(&d(pair(i, j)));
            }
        }
    }
    (l, jac, hess)
}

/// k = E A / (free length + routed length at Q = 0).
pub fn stiffness(holes: &[Hole]) -> f64 {
    let area = std::f64::consts::PI * DIAMETER * DIAMETER / 4.0;
    YOUNGS_MODULUS * area / (FREE_LENGTH + length(holes, &[0.0; 4]).0)
}

/// The geometric Jacobian of the tip (6 × 4, linear rows first, base frame).
pub fn tip_jacobian(q: &[f64; 4]) -> DMatrix<f64> {
    let mut jx = DMatrix::zeros(6, 4);
    let mut frame = Matrix3::identity();
    for j in 0..4 {
        let (_, axis) = JOINTS[j];
        let omega = frame * V3::from(axis);
        let v = point(TIP.0, TIP.1, q, unit(j));
        for r in 0..3 {
            jx[(r, j)] = v[r];
            jx[(r + 3, j)] = omega[r];
        }
        frame *= rotation(&V3::from(axis), q[j], 0);
    }
    jx
}

/// T0 = T_g + J_xᵀ F (a force F at the tip, no moment) and K_W = ∂T0/∂Q: the torques that
/// hold each weight m g and the tip's reaction −F.
pub fn load(q: &[f64; 4], force: [f64; 3], gravity: bool) -> (DVector<f64>, DMatrix<f64>) {
    let g = if gravity { V3::from(GRAVITY) } else { V3::zeros() };
    let mut pulls: Vec<(usize, [f64; 3], V3)> =
        MASSES.iter().map(|&(link, m, com)| (link, com, -m * g)).collect();
    pulls.push((TIP.0, TIP.1, V3::from(force)));
    let (mut t0, mut kw) = (DVector::zeros(4), DMatrix::zeros(4, 4));
    for (link, p, f) in pulls {
        for i in 0..4 {
            t0[i] += f.dot(&point(link, p, q, unit(i)));
            for j in 0..4 {
                kw[(i, j)] += f.dot(&point(link, p, q, pair(i, j)));
            }
        }
    }
    (t0, kw)
}

/// One joint's three cables holding `torque`: a (2 × 3) f = −torque, f = f_p + λ n (f_p the
/// minimum-norm solution, n the unit null vector with Σ n ≥ 0), λ within the limits.
pub struct Interval {
    pub particular: DVector<f64>,
    pub null: DVector<f64>,
    /// `[λ_min, λ_max]`; λ_min > λ_max when no tensions within the limits hold the torque.
    pub lambda: [f64; 2],
}

impl Interval {
    pub fn new(a: &DMatrix<f64>, torque: &DVector<f64>) -> Interval {
        let (r0, r1) = (a.row(0).transpose(), a.row(1).transpose());
        let r0 = V3::new(r0[0], r0[1], r0[2]);
        let r1 = V3::new(r1[0], r1[1], r1[2]);
        let mut n = r0.cross(&r1).normalize();
        if n.sum() < 0.0 {
            n = -n;
        }
        let aat = a * a.transpose();
        let particular = a.transpose() * aat.try_inverse().unwrap() * (-torque);
        let mut lambda = [f64::NEG_INFINITY, f64::INFINITY];
        for c in 0..3 {
            let ends = LIMITS.map(|b| (b - particular[c]) / n[c]);
            let (lo, hi) = if n[c] > 0.0 { (ends[0], ends[1]) } else { (ends[1], ends[0]) };
            lambda = [lambda[0].max(lo), lambda[1].min(hi)];
        }
        Interval { particular, null: DVector::from_column_slice(n.as_slice()), lambda }
    }

    pub fn tensions(&self, lambda: f64) -> DVector<f64> {
        &self.particular + &self.null * lambda
    }
}

/// Every cable's (L, J, H) at Q and its stiffness k.
pub fn all(q: &[f64; 4]) -> Vec<(f64, DVector<f64>, DMatrix<f64>, f64)> {
    cables()
        .iter()
        .map(|(_, holes)| {
            let (l, j, h) = length(holes, q);
            (l, j, h, stiffness(holes))
        })
        .collect()
}

/// The rows of cables `cables` and the columns `dofs` of J_cᵀ.
pub fn block(
    q: &[f64; 4],
    cables: std::ops::Range<usize>,
    dofs: std::ops::Range<usize>,
) -> DMatrix<f64> {
    let every = all(q);
    DMatrix::from_fn(dofs.len(), cables.len(), |r, c| every[cables.start + c].1[dofs.start + r])
}

/// K_q = Σ f_c H_c (controllable) and Σ k_c J_c J_cᵀ (inherent), 4 × 4.
pub fn joint_stiffness(q: &[f64; 4], f: &[f64]) -> (DMatrix<f64>, DMatrix<f64>) {
    let (mut kc, mut ki) = (DMatrix::zeros(4, 4), DMatrix::zeros(4, 4));
    for ((_, j, h, k), &f) in all(q).iter().zip(f) {
        kc += h * f;
        ki += j * j.transpose() * *k;
    }
    (kc, ki)
}

/// The least 2-norm tensions within the limits that balance T0 (J_cᵀ f = −T0), by
/// enumerating the active sets of at most two bounds (the set has dimension 2).
pub fn least_norm(q: &[f64; 4], t0: &DVector<f64>) -> DVector<f64> {
    let a = block(q, 0..6, 0..4);
    let bounds: Vec<(usize, f64)> = (0..6).flat_map(|c| LIMITS.map(|b| (c, b))).collect();
    let mut sets: Vec<Vec<(usize, f64)>> = vec![vec![]];
    for (i, &x) in bounds.iter().enumerate() {
        sets.push(vec![x]);
        sets.extend(bounds[i + 1..].iter().filter(|y| y.0 != x.0).map(|&y| vec![x, y]));
    }
    let mut best: Option<DVector<f64>> = None;
    for set in sets {
        let free: Vec<usize> = (0..6).filter(|c| set.iter().all(|s| s.0 != *c)).collect();
        let mut rhs = -t0;
        for &(c, b) in &set {
            rhs -= a.column(c) * b;
        }
        let af = DMatrix::from_fn(4, free.len(), |r, k| a[(r, free[k])]);
        let Some(inv) = (&af * af.transpose()).try_inverse() else { continue };
        let ff = af.transpose() * inv * rhs;
        let mut f = DVector::zeros(6);
        for &(c, b) in &set {
            f[c] = b;
        }
        for (k, &c) in free.iter().enumerate() {
            f[c] = ff[k];
        }
        let feasible = f.iter().all(|x| (LIMITS[0] - 1e-9..=LIMITS[1] + 1e-9).contains(x))
            && (&a * &f + t0).norm() < 1e-9;
        if feasible && best.as_ref().is_none_or(|b| f.norm() < b.norm()) {
            best = Some(f);
        }
    }
    best.unwrap()
}
