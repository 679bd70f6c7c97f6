//! Stiffness ellipsoid indicators of the end-effector's translational stiffness `K_fd`
//! (eq. 21 ff.).
//!
//! # Math
//! `F_d = K_fd d` (eq. 21). With the eigen-decomposition `K_fd = V Λ Vᵀ` (λ ascending), a unit
//! force along eigenvector `v_k` displaces the end by `1/λ_k` along `v_k`: the deformation
//! ellipsoid `{d = K_fd⁻¹ F : |F| = 1}` has semi-axes `1/λ_k`. `λ_min` gives the largest
//! deformation per unit force (the softest direction); `λ_max/λ_min` is the condition number;
//! the volume is `4π/3 · Π 1/λ_k`; the stiffness along a unit direction `u` is `uᵀ K_fd u`.
//!
//! `K_fd` is symmetric when the load is conservative (gravity, forces fixed in the base frame).
//! Otherwise its symmetric part is used, which gives the same `uᵀ K_fd u` for every `u`.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

use crate::error::StiffnessError;

/// The stiffness ellipsoid of a 3 × 3 translational stiffness.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StiffnessEllipsoid {
    /// Eigenvalues of (the symmetric part of) `K_fd`, ascending, N/m.
    pub eigenvalues: Vector3<f64>,
    /// Unit principal directions, the columns in the order of `eigenvalues` (base frame). Each
    /// is signed so that its largest component is positive (a deterministic choice).
    pub directions: Matrix3<f64>,
    /// The matrix itself (symmetric part), N/m.
    pub k_fd: Matrix3<f64>,
}

impl StiffnessEllipsoid {
    /// The ellipsoid of `k_fd` (N/m).
    ///
    /// # Errors
    /// [`StiffnessError::NonFinite`].
    pub fn new(k_fd: &Matrix3<f64>) -> Result<StiffnessEllipsoid, StiffnessError> {
        if !k_fd.iter().all(|v| v.is_finite()) {
            return Err(StiffnessError::NonFinite { what: "K_fd" });
        }
        let sym = (k_fd + k_fd.transpose()) * 0.5;
        let eigen = SymmetricEigen::new(sym);
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
        let eigenvalues = Vector3::from_fn(|k, _| eigen.eigenvalues[order[k]]);
        let mut directions = Matrix3::zeros();
        for (k, &o) in order.iter().enumerate() {
            let mut v: Vector3<f64> = eigen.eigenvectors.column(o).into_owned();
            let largest =
                v.iter().copied().fold(0.0_f64, |m, x| if x.abs() > m.abs() { x } else { m });
            if largest < 0.0 {
                v = -v;
            }
            directions.set_column(k, &v);
        }
        Ok(StiffnessEllipsoid { eigenvalues, directions, k_fd: sym })
    }

    /// Smallest eigenvalue `λ_min(K_fd)`, N/m: the stiffness of the softest direction.
    pub fn lambda_min(&self) -> f64 {
        self.eigenvalues[0]
    }

    /// Whether `K_fd` is positive definite (every semi-axis finite and positive).
    pub fn is_positive_definite(&self) -> bool {
        self.eigenvalues[0] > 0.0
    }

    /// Semi-axes of the deformation ellipsoid, `1/λ_k` (m/N), in the order of `eigenvalues`
    /// (largest first). `None` unless `K_fd` is positive definite.
    pub fn semi_axes(&self) -> Option<Vector3<f64>> {
        self.is_positive_definite().then(|| self.eigenvalues.map(|l| 1.0 / l))
    }

    /// Condition number `λ_max/λ_min`. `None` unless `K_fd` is positive definite.
    pub fn condition_number(&self) -> Option<f64> {
        self.is_positive_definite().then(|| self.eigenvalues[2] / self.eigenvalues[0])
    }

    /// Volume of the deformation ellipsoid, `4π/3 · Π 1/λ_k` (m³/N³). `None` unless `K_fd` is
    /// positive definite.
    pub fn volume(&self) -> Option<f64> {
        self.semi_axes().map(|a| 4.0 / 3.0 * std::f64::consts::PI * a[0] * a[1] * a[2])
    }

    /// Stiffness along a direction, `uᵀ K_fd u` with `u` normalised (N/m).
    ///
    /// # Errors
    /// [`StiffnessError::InvalidDirection`] for a zero or non-finite `u`.
    pub fn directional_stiffness(&self, u: &Vector3<f64>) -> Result<f64, StiffnessError> {
        let norm = u.norm();
        if !(norm.is_finite() && norm > 0.0) {
            return Err(StiffnessError::InvalidDirection { direction: [u[0], u[1], u[2]] });
        }
        let u = u / norm;
        Ok(u.dot(&(self.k_fd * u)))
    }
}
