//! Euler parameters (unit quaternions) `p = [e0, e1, e2, e3]`, the singularity-free
//! rotation parameterisation of the rigid bodies.
//!
//! With `e = [e1, e2, e3]` and `ẽ` its cross-product matrix:
//!
//! ```text
//! A(p) = (2 e0² − 1) I + 2 (e eᵀ + e0 ẽ)          body → global rotation
//! E(p) = [ −e,  ẽ + e0 I ]   (3×4)                ω  = 2 E ṗ  (global angular velocity)
//! G(p) = [ −e, −ẽ + e0 I ]   (3×4)                ω' = 2 G ṗ  (body-frame angular velocity)
//! ```
//!
//! and `A = E Gᵀ`, `E p = G p = 0`. A moment `T` (global) acting on a body does the
//! generalized force `Q_p = 2 Eᵀ T` on its Euler parameters (Nikravesh 1988; Haug 1989).

use nalgebra::{Matrix3, Matrix3x4, Vector3, Vector4};

/// Cross-product matrix `ã` with `ã b = a × b`.
pub fn skew(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// Rotation matrix `A(p)` (body → global).
pub fn rotation(p: &Vector4<f64>) -> Matrix3<f64> {
    let e0 = p[0];
    let e = Vector3::new(p[1], p[2], p[3]);
    Matrix3::identity() * (2.0 * e0 * e0 - 1.0) + (e * e.transpose() + skew(&e) * e0) * 2.0
}

/// `E(p)`: global angular velocity `ω = 2 E(p) ṗ`.
pub fn e_matrix(p: &Vector4<f64>) -> Matrix3x4<f64> {
    let (e0, e1, e2, e3) = (p[0], p[1], p[2], p[3]);
    Matrix3x4::new(-e1, e0, -e3, e2, -e2, e3, e0, -e1, -e3, -e2, e1, e0)
}

/// `G(p)`: body-frame angular velocity `ω' = 2 G(p) ṗ`.
pub fn g_matrix(p: &Vector4<f64>) -> Matrix3x4<f64> {
    let (e0, e1, e2, e3) = (p[0], p[1], p[2], p[3]);
    Matrix3x4::new(-e1, e0, e3, -e2, -e2, -e3, e0, e1, -e3, e2, -e1, e0)
}

/// `∂(A(p) a)/∂p` for a body-fixed vector `a` (3×4), exact for any `p` (also off the
/// unit sphere) for the quadratic form of [`rotation`].
pub fn d_rotate(p: &Vector4<f64>, a: &Vector3<f64>) -> Matrix3x4<f64> {
    let e0 = p[0];
    let e = Vector3::new(p[1], p[2], p[3]);
    let c0 = a * (4.0 * e0) + e.cross(a) * 2.0;
    let ce = (Matrix3::identity() * e.dot(a) + e * a.transpose() - skew(a) * e0) * 2.0;
    let mut m = Matrix3x4::zeros();
    m.set_column(0, &c0);
    m.fixed_view_mut::<3, 3>(0, 1).copy_from(&ce);
    m
}

/// Euler parameters of a rotation matrix (Shepperd's method, `e0 ≥ 0`).
pub fn from_rotation(a: &Matrix3<f64>) -> Vector4<f64> {
    let tr = a.trace();
    let cands = [tr, a[(0, 0)], a[(1, 1)], a[(2, 2)]];
    let k = (0..4).max_by(|&i, &j| cands[i].total_cmp(&cands[j])).unwrap_or(0);
    let mut p = match k {
        0 => {
            let e0 = 0.5 * (1.0 + tr).max(0.0).sqrt();
            let f = 0.25 / e0;
            Vector4::new(e0, (a[(2, 1)] - a[(1, 2)]) * f, (a[(0, 2)] - a[(2, 0)]) * f, (a[(1, 0)] - a[(0, 1)]) * f)
        }
        1 => {
            let e1 = 0.5 * (1.0 + 2.0 * a[(0, 0)] - tr).max(0.0).sqrt();
            let f = 0.25 / e1;
            Vector4::new((a[(2, 1)] - a[(1, 2)]) * f, e1, (a[(1, 0)] + a[(0, 1)]) * f, (a[(0, 2)] + a[(2, 0)]) * f)
        }
        2 => {
            let e2 = 0.5 * (1.0 + 2.0 * a[(1, 1)] - tr).max(0.0).sqrt();
            let f = 0.25 / e2;
            Vector4::new((a[(0, 2)] - a[(2, 0)]) * f, (a[(1, 0)] + a[(0, 1)]) * f, e2, (a[(2, 1)] + a[(1, 2)]) * f)
        }
        _ => {
            let e3 = 0.5 * (1.0 + 2.0 * a[(2, 2)] - tr).max(0.0).sqrt();
            let f = 0.25 / e3;
            Vector4::new((a[(1, 0)] - a[(0, 1)]) * f, (a[(0, 2)] + a[(2, 0)]) * f, (a[(2, 1)] + a[(1, 2)]) * f, e3)
        }
    };
    if p[0] < 0.0 {
        p = -p;
    }
    p / p.norm()
}

/// Euler-parameter rates `ṗ = ½ E(p)ᵀ ω` of a global angular velocity `ω` (unit `p`).
pub fn rates(p: &Vector4<f64>, omega: &Vector3<f64>) -> Vector4<f64> {
    e_matrix(p).transpose() * omega * 0.5
}

/// Rotation about a unit axis by an angle, rad (Rodrigues).
pub fn axis_angle(axis: &Vector3<f64>, angle: f64) -> Matrix3<f64> {
    let k = axis.normalize();
    let (s, c) = angle.sin_cos();
    Matrix3::identity() * c + skew(&k) * s + k * k.transpose() * (1.0 - c)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Vector4<f64> {
        let p = Vector4::new(0.8, -0.3, 0.4, 0.2);
        p / p.norm()
    }

    #[test]
    fn rotation_is_orthonormal_and_equals_e_gt() {
        let p = sample();
        let a = rotation(&p);
        assert!((a.transpose() * a - Matrix3::identity()).norm() < 1e-14);
        assert!((a.determinant() - 1.0).abs() < 1e-14);
        assert!((e_matrix(&p) * g_matrix(&p).transpose() - a).norm() < 1e-14);
        assert!((e_matrix(&p) * p).norm() < 1e-15 && (g_matrix(&p) * p).norm() < 1e-15);
        assert!((from_rotation(&a) - p).norm() < 1e-14);
        // ω' = Aᵀ ω
        let pd = Vector4::new(0.1, 0.7, -0.2, 0.4);
        let w = e_matrix(&p) * pd * 2.0;
        let wl = g_matrix(&p) * pd * 2.0;
        assert!((a.transpose() * w - wl).norm() < 1e-14);
    }

    #[test]
    fn d_rotate_matches_finite_differences() {
        let p = Vector4::new(0.7, -0.3, 0.5, 0.1); // deliberately not unit
        let a = Vector3::new(0.3, -1.2, 0.8);
        let d = d_rotate(&p, &a);
        for k in 0..4 {
            let h = 1e-6;
            let mut pp = p;
            pp[k] += h;
            let mut pm = p;
            pm[k] -= h;
            let fd = (rotation(&pp) * a - rotation(&pm) * a) / (2.0 * h);
            assert!((fd - d.column(k)).norm() < 1e-9, "column {k}");
        }
    }

    #[test]
    fn angular_velocity_matches_rotation_rate() {
        // Ȧ = ω̃ A for p(t) = p + t ṗ (to first order).
        let p = sample();
        let pd = rates(&p, &Vector3::new(0.3, -2.0, 0.5));
        let h = 1e-6;
        let ad = (rotation(&(p + pd * h)) - rotation(&(p - pd * h))) / (2.0 * h);
        let w = e_matrix(&p) * pd * 2.0;
        assert!((ad - skew(&w) * rotation(&p)).norm() < 1e-8);
        assert!((w - Vector3::new(0.3, -2.0, 0.5)).norm() < 1e-14);
        let r = axis_angle(&Vector3::z(), 0.3);
        assert!((from_rotation(&r) - Vector4::new(0.15f64.cos(), 0.0, 0.0, 0.15f64.sin())).norm() < 1e-14);
    }
}
