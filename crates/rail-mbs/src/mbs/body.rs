//! Rigid bodies: inertia, initial state, and the kinematic state read from `q`, `v`.
//!
//! Every rigid body owns seven coordinates `[x, y, z, e0, e1, e2, e3]` (origin at the
//! centre of mass, global frame; Euler parameters of body → global) and seven
//! velocities (their time derivatives), plus the normalization constraint `pᵀp = 1`.
//!
//! Equations of motion (Nikravesh 1988, Haug 1989) with `J` the body-frame inertia
//! tensor about the centre of mass:
//!
//! ```text
//! m r̈ = F,      4 Gᵀ J G p̈ = 2 Eᵀ T + 8 Ġᵀ J Ġ p + 2 p λ_norm
//! ```
//!
//! `4 Gᵀ J G` is singular along `p`; the normalization constraint removes that
//! direction in the KKT system of the integrator.

use nalgebra::{Matrix3, Matrix4, Vector3, Vector4};

use super::rotation::{e_matrix, from_rotation, g_matrix, rates, rotation};
use ancf_core::error::AncfError;

/// Index of a rigid body in a [`Multibody`](super::Multibody).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BodyId(pub usize);

/// Something forces and joints attach to: the ground (fixed global frame) or a body.
pub type Attachment = Option<BodyId>;

/// A rigid body.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidBody {
    /// Name used in error messages and results.
    pub name: String,
    /// Mass, kg.
    pub mass: f64,
    /// Inertia tensor about the centre of mass in the body frame, kg·m².
    pub inertia: Matrix3<f64>,
    /// Initial position of the centre of mass, m (global).
    pub position: Vector3<f64>,
    /// Initial orientation, body → global.
    pub orientation: Matrix3<f64>,
    /// Initial velocity of the centre of mass, m/s (global).
    pub velocity: Vector3<f64>,
    /// Initial angular velocity, rad/s (global).
    pub angular_velocity: Vector3<f64>,
}

impl RigidBody {
    /// A body at rest at `position` with identity orientation and diagonal inertia
    /// `[Ixx, Iyy, Izz]`.
    pub fn new(name: &str, mass: f64, inertia: [f64; 3], position: Vector3<f64>) -> Self {
        Self {
            name: name.to_string(),
            mass,
            inertia: Matrix3::from_diagonal(&Vector3::from(inertia)),
            position,
            orientation: Matrix3::identity(),
            velocity: Vector3::zeros(),
            angular_velocity: Vector3::zeros(),
        }
    }

    /// Checks mass, inertia (symmetric positive definite) and finiteness.
    pub fn validate(&self) -> Result<(), AncfError> {
        let field = |f: &str| format!("body '{}' {f}", self.name);
        if !(self.mass.is_finite() && self.mass > 0.0) {
            return Err(AncfError::InvalidParameter {
                field: field("mass"),
                value: self.mass.to_string(),
                allowed: "finite, > 0 kg".into(),
            });
        }
        let sym = (self.inertia - self.inertia.transpose()).norm() <= 1e-12 * self.inertia.norm();
        let pd = self.inertia.symmetric_eigenvalues().iter().all(|&l| l > 0.0 && l.is_finite());
        if !(sym && pd) {
            return Err(AncfError::InvalidParameter {
                field: field("inertia"),
                value: format!("{:?}", self.inertia.as_slice()),
                allowed: "symmetric positive definite, kg m^2".into(),
            });
        }
        let ortho = (self.orientation.transpose() * self.orientation - Matrix3::identity()).norm() < 1e-9
            && self.orientation.determinant() > 0.0;
        if !ortho {
            return Err(AncfError::InvalidParameter {
                field: field("orientation"),
                value: format!("{:?}", self.orientation.as_slice()),
                allowed: "a proper rotation matrix".into(),
            });
        }
        let finite = self.position.iter().chain(self.velocity.iter()).chain(self.angular_velocity.iter());
        if let Some(v) = finite.copied().find(|v| !v.is_finite()) {
            return Err(AncfError::InvalidParameter {
                field: field("initial state"),
                value: v.to_string(),
                allowed: "finite".into(),
            });
        }
        Ok(())
    }

    /// Initial coordinates `[r, p]` and velocities `[ṙ, ṗ]`.
    pub fn initial_coordinates(&self) -> ([f64; 7], [f64; 7]) {
        let p = from_rotation(&self.orientation);
        let pd = rates(&p, &self.angular_velocity);
        let r = &self.position;
        let v = &self.velocity;
        ([r.x, r.y, r.z, p[0], p[1], p[2], p[3]], [v.x, v.y, v.z, pd[0], pd[1], pd[2], pd[3]])
    }

    /// Mass matrix block (7×7, row-major): `diag(m I, 4 Gᵀ J G)`.
    pub fn mass_block(&self, q: &[f64]) -> [[f64; 7]; 7] {
        let p = Vector4::new(q[3], q[4], q[5], q[6]);
        let g = g_matrix(&p);
        let mpp: Matrix4<f64> = g.transpose() * self.inertia * g * 4.0;
        let mut m = [[0.0; 7]; 7];
        for (i, row) in m.iter_mut().enumerate().take(3) {
            row[i] = self.mass;
        }
        for i in 0..4 {
            for j in 0..4 {
                m[3 + i][3 + j] = mpp[(i, j)];
            }
        }
        m
    }

    /// Gravity and quadratic-velocity (gyroscopic) forces on the body's seven coordinates.
    pub fn inertial_forces(&self, q: &[f64], v: &[f64], gravity: &Vector3<f64>) -> [f64; 7] {
        let pd = Vector4::new(v[3], v[4], v[5], v[6]);
        let p = Vector4::new(q[3], q[4], q[5], q[6]);
        let gd = g_matrix(&pd);
        let qv = gd.transpose() * (self.inertia * (gd * p)) * 8.0;
        let f = gravity * self.mass;
        [f.x, f.y, f.z, qv[0], qv[1], qv[2], qv[3]]
    }
}

/// Kinematic state of a body (or of the ground) at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyState {
    /// Position of the origin (centre of mass), m.
    pub position: Vector3<f64>,
    /// Euler parameters.
    pub params: Vector4<f64>,
    /// Rotation body → global.
    pub rotation: Matrix3<f64>,
    /// Velocity of the origin, m/s.
    pub velocity: Vector3<f64>,
    /// Angular velocity, rad/s (global).
    pub angular_velocity: Vector3<f64>,
}

impl BodyState {
    /// The ground: at the origin, not rotated, at rest.
    pub fn ground() -> Self {
        Self {
            position: Vector3::zeros(),
            params: Vector4::new(1.0, 0.0, 0.0, 0.0),
            rotation: Matrix3::identity(),
            velocity: Vector3::zeros(),
            angular_velocity: Vector3::zeros(),
        }
    }

    /// State from a body's 7 coordinates and 7 velocities.
    pub fn from_coordinates(q: &[f64], v: &[f64]) -> Self {
        let p = Vector4::new(q[3], q[4], q[5], q[6]);
        let pd = Vector4::new(v[3], v[4], v[5], v[6]);
        Self {
            position: Vector3::new(q[0], q[1], q[2]),
            params: p,
            rotation: rotation(&p),
            velocity: Vector3::new(v[0], v[1], v[2]),
            angular_velocity: e_matrix(&p) * pd * 2.0,
        }
    }

    /// Global position of a body-fixed point `s` (body frame, from the origin).
    pub fn point(&self, s: &Vector3<f64>) -> Vector3<f64> {
        self.position + self.rotation * s
    }

    /// Global velocity of a body-fixed point `s`.
    pub fn point_velocity(&self, s: &Vector3<f64>) -> Vector3<f64> {
        self.velocity + self.angular_velocity.cross(&(self.rotation * s))
    }

    /// Generalized forces on `[r, p]` of a force `f` (global) at the origin and a
    /// moment `t` (global): `[f, 2 Eᵀ t]`.
    pub fn generalized(&self, f: &Vector3<f64>, t: &Vector3<f64>) -> [f64; 7] {
        let qp = e_matrix(&self.params).transpose() * t * 2.0;
        [f.x, f.y, f.z, qp[0], qp[1], qp[2], qp[3]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mbs::rotation::axis_angle;

    #[test]
    fn kinetic_energy_from_mass_block_matches_rigid_body_formula() {
        let mut b = RigidBody::new("b", 3.0, [2.0, 5.0, 7.0], Vector3::new(1.0, 2.0, 3.0));
        b.orientation = axis_angle(&Vector3::new(1.0, 2.0, -0.5), 0.7);
        b.velocity = Vector3::new(0.3, -0.1, 0.2);
        b.angular_velocity = Vector3::new(1.5, -0.4, 2.0);
        let (q, v) = b.initial_coordinates();
        let m = b.mass_block(&q);
        let mut t = 0.0;
        for i in 0..7 {
            for j in 0..7 {
                t += 0.5 * v[i] * m[i][j] * v[j];
            }
        }
        let wl = b.orientation.transpose() * b.angular_velocity;
        let expected = 0.5 * b.mass * b.velocity.norm_squared() + 0.5 * wl.dot(&(b.inertia * wl));
        assert!((t - expected).abs() < 1e-12 * expected, "{t} vs {expected}");
        let s = BodyState::from_coordinates(&q, &v);
        assert!((s.angular_velocity - b.angular_velocity).norm() < 1e-13);
        assert!((s.rotation - b.orientation).norm() < 1e-13);
    }

    #[test]
    fn invalid_inertia_names_the_field() {
        let b = RigidBody::new("tank", 1.0, [1.0, -1.0, 1.0], Vector3::zeros());
        let e = b.validate().unwrap_err().to_string();
        assert!(e.contains("tank") && e.contains("inertia"), "{e}");
    }
}
