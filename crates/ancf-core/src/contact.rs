//! Fluid–wall and fluid–bulkhead penalty contact (seed 000 §5).
//!
//! Contact is checked at Gauss points of every boundary face of the fluid mesh (walls and
//! free surface alike, so a splashing free surface meets the tank roof). At a point with
//! tank-frame position p and velocity relative to the wall v, every wall with penetration
//! ψ > 0 (see [`crate::tank`]) pushes back with the traction
//!
//! f_n = k_p ψ + c_p |ψ| ψ̇ (≥ 0), ψ̇ = ∇ψ·v, **F_n = −w f_n ∇ψ**,
//!
//! plus a tangential traction from [`WallFriction`]: none, regularized Coulomb
//! F_t = −w μ f_n v_t/√(|v_t|² + v_ε²) (the seed's f_t = μ f_n), or no-slip as a tangential
//! viscous penalty F_t = −w c_t χ(ψ) v_t. Here w is the reference area the point represents,
//! so k_p is a stiffness per unit area (Pa/m) and the model does not depend on how many
//! points are used. The equal and opposite force acts on the tank at the same point
//! (seed: Q_CB^t); [`WallContact::forces`] returns its resultant and moment.
//!
//! Positions and velocities are mapped into the tank frame with the tank kinematics
//! (R, A, Ṙ, ω): p = Aᵀ(r − R), v = Aᵀ(ṙ − Ṙ − ω × (r − R)). In a tank-frame formulation
//! pass [`TankKinematics::identity`].

use nalgebra::Vector3;

use crate::body::{FluidBody, gather_compact};
use crate::constitutive::{M3, smoothstep};
use crate::element::scaled;
use crate::error::{Result, check_non_negative, check_positive, invalid};
use crate::mesh::Face;
use crate::quadrature::gauss_legendre;
use crate::shape::{N_SHAPE, normalized_shape};
use crate::tank::{TankGeometry, WallHit};

/// Tangential behaviour at the walls.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WallFriction {
    /// No tangential force (free slip).
    Frictionless,
    /// Regularized Coulomb friction f_t = μ f_n (seed 000 §5.2).
    Coulomb {
        /// Friction coefficient μ.
        coefficient: f64,
        /// Regularization slip velocity v_ε (m/s).
        slip_velocity: f64,
    },
    /// No-slip as a tangential viscous penalty F_t = −c_t χ(ψ) v_t per unit area.
    NoSlip {
        /// Drag coefficient c_t (Pa·s/m).
        drag: f64,
        /// Penetration over which the drag switches on smoothly (m).
        activation_depth: f64,
    },
}

/// Penalty contact law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallContactLaw {
    /// k_p, normal stiffness per unit area (Pa/m).
    pub stiffness: f64,
    /// c_p of f_n = k_p ψ + c_p |ψ| ψ̇ (Pa·s/m²).
    pub damping: f64,
    /// Tangential law.
    pub friction: WallFriction,
    /// Gauss points per face edge (points per face = this squared).
    pub points_per_edge: usize,
}

impl WallContactLaw {
    /// Defaults derived from the fluid and the liquid depth H (see `docs/architecture.md`):
    /// - k_p = 1000 ρ g: the hydrostatic pressure at the bottom, ρ g H, is carried with a
    ///   penetration δ_e = 10⁻³ H;
    /// - c_p such that the liquid column bouncing on the wall (mass ρH per unit area on the
    ///   spring k_p) is damped (ζ = 0.1) at the equilibrium penetration:
    ///   c_p δ_e = 2 ζ √(k_p ρ H), ζ = 0.1;
    /// - frictionless walls; 3×3 points per face.
    pub fn default_for(density: f64, gravity: f64, depth: f64) -> Self {
        let k = 1000.0 * density * gravity;
        let delta_e = density * gravity * depth / k;
        let c = 2.0 * 0.1 * (k * density * depth).sqrt() / delta_e;
        Self { stiffness: k, damping: c, friction: WallFriction::Frictionless, points_per_edge: 3 }
    }

    /// Validate; errors name the field.
    pub fn validate(&self) -> Result<()> {
        check_positive("contact.stiffness", self.stiffness)?;
        check_non_negative("contact.damping", self.damping)?;
        if !(1..=6).contains(&self.points_per_edge) {
            return Err(invalid("contact.points_per_edge", self.points_per_edge, "an integer in [1, 6]"));
        }
        match self.friction {
            WallFriction::Frictionless => Ok(()),
            WallFriction::Coulomb { coefficient, slip_velocity } => {
                check_non_negative("contact.friction.coefficient", coefficient)?;
                check_positive("contact.friction.slip_velocity", slip_velocity)
            }
            WallFriction::NoSlip { drag, activation_depth } => {
                check_non_negative("contact.friction.drag", drag)?;
                check_positive("contact.friction.activation_depth", activation_depth)
            }
        }
    }
}

/// Rigid motion of the tank: position R of its origin, rotation A (tank → global),
/// velocity Ṙ and angular velocity ω (global components).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TankKinematics {
    /// R (m).
    pub position: [f64; 3],
    /// A, columns are the tank axes in global components.
    pub rotation: M3,
    /// Ṙ (m/s).
    pub velocity: [f64; 3],
    /// ω (rad/s), global components.
    pub angular_velocity: [f64; 3],
}

impl TankKinematics {
    /// The tank at rest at the global origin (tank frame = global frame).
    pub fn identity() -> Self {
        Self { position: [0.0; 3], rotation: M3::identity(), velocity: [0.0; 3], angular_velocity: [0.0; 3] }
    }
}

/// A contact point on the fluid boundary.
#[derive(Debug, Clone)]
pub struct ContactPoint {
    /// Element index.
    pub element: usize,
    /// Physical shape-function values N_a at the point (32).
    pub shape: [f64; N_SHAPE],
    /// Reference area represented by the point (m²).
    pub weight: f64,
    /// Side of each bulkhead on which the point's liquid lies.
    pub sides: Vec<i8>,
}

/// Resultant contact load on the tank and diagnostics.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactLoad {
    /// Force of the fluid on the tank through contact (N, global).
    pub force: [f64; 3],
    /// Its moment about the tank origin R (N·m, global).
    pub moment: [f64; 3],
    /// Number of points in contact.
    pub active: usize,
    /// Largest penetration (m).
    pub max_penetration: f64,
}

/// Jacobian of the contact force at one active point (global frame).
#[derive(Debug, Clone, Copy)]
pub struct PointJacobian {
    /// Index into [`WallContact::points`].
    pub point: usize,
    /// ∂F/∂r.
    pub d_position: M3,
    /// ∂F/∂ṙ.
    pub d_velocity: M3,
    /// The contact force F on the fluid at this point (N, global).
    pub force: Vector3<f64>,
    /// The point's position relative to the tank origin, r − R (m, global).
    pub arm: Vector3<f64>,
}

/// Contact between one fluid body and one tank.
#[derive(Debug, Clone)]
pub struct WallContact {
    /// Tank walls and bulkheads.
    pub geometry: TankGeometry,
    /// Contact law.
    pub law: WallContactLaw,
    /// Contact points.
    pub points: Vec<ContactPoint>,
}

impl WallContact {
    /// Sample contact points on every boundary face of `body`'s mesh. The bulkhead side of
    /// each point is taken from its reference position (the tank frame at t = 0).
    pub fn new(body: &FluidBody, geometry: TankGeometry, law: WallContactLaw) -> Result<Self> {
        law.validate()?;
        let (gx, gw) = gauss_legendre(law.points_per_edge)?;
        let mut points = Vec::new();
        for bf in &body.mesh.boundary {
            let el = bf.element;
            let r = &body.elements[el];
            let ehat = scaled(&gather_compact(&body.mesh.nodes, &body.mesh.elements[el]), &r.scale);
            let (fixed, val, (d1, d2)) = match bf.face {
                Face::XMin => (0, -1.0, (1, 2)),
                Face::XMax => (0, 1.0, (1, 2)),
                Face::YMin => (1, -1.0, (0, 2)),
                Face::YMax => (1, 1.0, (0, 2)),
                Face::ZMin => (2, -1.0, (0, 1)),
                Face::ZMax => (2, 1.0, (0, 1)),
            };
            for (s, ws) in gx.iter().zip(&gw) {
                for (t, wt) in gx.iter().zip(&gw) {
                    let mut xi = [0.0; 3];
                    xi[fixed] = val;
                    xi[d1] = *s;
                    xi[d2] = *t;
                    let (n, dn) = normalized_shape(xi);
                    let mut x = Vector3::zeros();
                    let mut t1 = Vector3::zeros();
                    let mut t2 = Vector3::zeros();
                    let mut shape = [0.0; N_SHAPE];
                    for a in 0..N_SHAPE {
                        let ea = Vector3::from(ehat[a]);
                        x += ea * n[a];
                        t1 += ea * dn[a][d1];
                        t2 += ea * dn[a][d2];
                        shape[a] = n[a] * r.scale[a];
                    }
                    let weight = ws * wt * t1.cross(&t2).norm();
                    let sides = geometry.sides([x[0], x[1], x[2]]);
                    points.push(ContactPoint { element: el, shape, weight, sides });
                }
            }
        }
        Ok(Self { geometry, law, points })
    }

    /// Position and velocity of a contact point (global).
    fn point_state(&self, body: &FluidBody, k: usize, e: &[f64], edot: &[f64]) -> (Vector3<f64>, Vector3<f64>) {
        let pt = &self.points[k];
        let nodes = &body.mesh.elements[pt.element];
        let mut r = Vector3::zeros();
        let mut v = Vector3::zeros();
        for a in 0..N_SHAPE {
            let g = 3 * (4 * nodes[a / 4] + a % 4);
            let na = pt.shape[a];
            r += na * Vector3::new(e[g], e[g + 1], e[g + 2]);
            v += na * Vector3::new(edot[g], edot[g + 1], edot[g + 2]);
        }
        (r, v)
    }

    /// Add the contact generalized forces on the fluid to `out` and return the load on the
    /// tank. With `jacobians`, also collect the point Jacobians of every active point.
    pub fn forces(
        &self,
        body: &FluidBody,
        kin: &TankKinematics,
        e: &[f64],
        edot: &[f64],
        out: &mut [f64],
        mut jacobians: Option<&mut Vec<PointJacobian>>,
    ) -> ContactLoad {
        let mut load = ContactLoad::default();
        let a_mat = kin.rotation;
        let at = a_mat.transpose();
        let rt = Vector3::from(kin.position);
        let w = Vector3::from(kin.angular_velocity);
        let wt = w.cross_matrix();
        let mut hits = Vec::new();
        if let Some(j) = jacobians.as_mut() {
            j.clear();
        }
        for (k, pt) in self.points.iter().enumerate() {
            let (r, rd) = self.point_state(body, k, e, edot);
            let d = r - rt;
            let p = at * d;
            self.geometry.hits([p[0], p[1], p[2]], &pt.sides, &mut hits);
            if hits.is_empty() {
                continue;
            }
            let v = at * (rd - Vector3::from(kin.velocity) - w.cross(&d));
            let (fk, jp, jv) = self.point_force(&hits, &v, pt.weight);
            let f = a_mat * fk;
            load.active += 1;
            load.max_penetration = hits.iter().fold(load.max_penetration, |m, h| m.max(h.psi));
            let nodes = &body.mesh.elements[pt.element];
            for a in 0..N_SHAPE {
                let g = 3 * (4 * nodes[a / 4] + a % 4);
                for i in 0..3 {
                    out[g + i] += pt.shape[a] * f[i];
                }
            }
            let m = d.cross(&(-f));
            for i in 0..3 {
                load.force[i] -= f[i];
                load.moment[i] += m[i];
            }
            if let Some(j) = jacobians.as_mut() {
                let dv = a_mat * jv * at;
                let dp = a_mat * jp * at - dv * wt;
                j.push(PointJacobian { point: k, d_position: dp, d_velocity: dv, force: f, arm: d });
            }
        }
        load
    }

    /// Tank-frame contact force at one point and its Jacobians ∂F/∂p, ∂F/∂v.
    fn point_force(&self, hits: &[WallHit], v: &Vector3<f64>, w: f64) -> (Vector3<f64>, M3, M3) {
        let (k, c) = (self.law.stiffness, self.law.damping);
        let mut f = Vector3::zeros();
        let mut jp = M3::zeros();
        let mut jv = M3::zeros();
        for h in hits {
            let g = Vector3::from(h.grad);
            let hm = h.hess;
            let psi = h.psi;
            let psid = g.dot(v);
            let fnorm = psi * (k + c * psid);
            let hv = hm * v;
            let (fnorm, dfn_dp, dfn_dv) = if fnorm > 0.0 {
                (fnorm, (k + c * psid) * g + (c * psi) * hv, (c * psi) * g)
            } else {
                (0.0, Vector3::zeros(), Vector3::zeros())
            };
            f -= w * fnorm * g;
            jp -= w * (g * dfn_dp.transpose() + fnorm * hm);
            jv -= w * g * dfn_dv.transpose();
            if matches!(self.law.friction, WallFriction::Frictionless) {
                continue;
            }
            // tangential relative velocity and its derivatives
            let q = g.dot(&g);
            let s = psid;
            let vt = v - (s / q) * g;
            let dvt_dv = M3::identity() - g * g.transpose() / q;
            let hg = hm * g;
            let dvt_dp = -(g * hv.transpose() / q + (s / q) * hm - (2.0 * s / (q * q)) * g * hg.transpose());
            match self.law.friction {
                WallFriction::Frictionless => {}
                WallFriction::Coulomb { coefficient: mu, slip_velocity: eps } => {
                    let m = (vt.dot(&vt) + eps * eps).sqrt();
                    let dir = M3::identity() / m - vt * vt.transpose() / (m * m * m);
                    f -= w * mu * fnorm * vt / m;
                    jp -= w * mu * (vt / m * dfn_dp.transpose() + fnorm * dir * dvt_dp);
                    jv -= w * mu * (vt / m * dfn_dv.transpose() + fnorm * dir * dvt_dv);
                }
                WallFriction::NoSlip { drag, activation_depth } => {
                    let (chi, dchi) = smoothstep(psi / activation_depth);
                    f -= w * drag * chi * vt;
                    jp -= w * drag * (vt * (dchi / activation_depth) * g.transpose() + chi * dvt_dp);
                    jv -= w * drag * chi * dvt_dv;
                }
            }
        }
        (f, jp, jv)
    }
}

/// Scatter point Jacobians into a dense global matrix (tests and small problems):
/// `kr[i*n + j] += ∂Q_i/∂e_j`, `kv` likewise for ė.
pub fn dense_jacobians(contact: &WallContact, body: &FluidBody, jac: &[PointJacobian], kr: &mut [f64], kv: &mut [f64]) {
    let n = body.n_coords();
    for pj in jac {
        let pt = &contact.points[pj.point];
        let nodes = &body.mesh.elements[pt.element];
        for a in 0..N_SHAPE {
            let ga = 3 * (4 * nodes[a / 4] + a % 4);
            for b in 0..N_SHAPE {
                let gb = 3 * (4 * nodes[b / 4] + b % 4);
                let nn = pt.shape[a] * pt.shape[b];
                for i in 0..3 {
                    for j in 0..3 {
                        kr[(ga + i) * n + gb + j] += nn * pj.d_position[(i, j)];
                        kv[(ga + i) * n + gb + j] += nn * pj.d_velocity[(i, j)];
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constitutive::{Fluid, Rheology};
    use crate::element::QuadratureOptions;
    use crate::mesh::box_mesh;
    use crate::tank::{Bulkhead, TankShape};
    use crate::validate::Rng;
    use nalgebra::Rotation3;

    fn setup(friction: WallFriction) -> (FluidBody, WallContact, TankKinematics, Vec<f64>, Vec<f64>) {
        let mesh = box_mesh([-0.3, -0.2, 0.0], [0.6, 0.4, 0.3], [2, 2, 1]).unwrap();
        let fluid = Fluid::new(1000.0, Rheology::Newtonian { viscosity: 1.0 }, 1e5).unwrap();
        let body = FluidBody::new(mesh, fluid, QuadratureOptions::default()).unwrap();
        // a slightly smaller tank and a bulkhead: many points penetrate
        let geo = TankGeometry::new(
            TankShape::Box { min: [-0.29, -0.195, 0.004], max: [0.29, 0.195, 0.29] },
            vec![Bulkhead { x: 0.01, thickness: 0.01 }],
        )
        .unwrap();
        let law = WallContactLaw { stiffness: 1e6, damping: 2e5, friction, points_per_edge: 2 };
        let contact = WallContact::new(&body, geo, law).unwrap();
        let rot = *Rotation3::from_euler_angles(0.1, -0.2, 0.3).matrix();
        let kin = TankKinematics {
            position: [1.0, -0.5, 0.2],
            rotation: rot,
            velocity: [3.0, 0.2, -0.1],
            angular_velocity: [0.3, -0.2, 0.5],
        };
        let mut rng = Rng::new(3);
        // fluid coordinates: reference placed into the tank frame, plus noise
        let e0 = body.reference_coordinates();
        let mut e = vec![0.0; e0.len()];
        for (s, (x, y)) in e0.chunks_exact(3).zip(e.chunks_exact_mut(3)).enumerate() {
            let v = rot * Vector3::new(x[0], x[1], x[2]);
            let v = if s % 4 == 0 { v + Vector3::from(kin.position) } else { v };
            for i in 0..3 {
                y[i] = v[i] + 0.002 * rng.uniform();
            }
        }
        let edot: Vec<f64> = e.iter().map(|_| 0.3 * rng.uniform()).collect();
        (body, contact, kin, e, edot)
    }

    #[test]
    fn contact_jacobians_match_finite_differences() {
        for friction in [
            WallFriction::Frictionless,
            WallFriction::Coulomb { coefficient: 0.4, slip_velocity: 0.05 },
            WallFriction::NoSlip { drag: 2e3, activation_depth: 0.003 },
        ] {
            let (body, contact, kin, e, edot) = setup(friction);
            let n = body.n_coords();
            let mut q = vec![0.0; n];
            let mut jac = Vec::new();
            let load = contact.forces(&body, &kin, &e, &edot, &mut q, Some(&mut jac));
            assert!(load.active > 10, "active {}", load.active);
            let mut kr = vec![0.0; n * n];
            let mut kv = vec![0.0; n * n];
            dense_jacobians(&contact, &body, &jac, &mut kr, &mut kv);
            for (which, k) in [(0, &kr), (1, &kv)] {
                let scale = k.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                let mut worst = 0.0f64;
                for d in 0..n {
                    let h = 1e-7;
                    let (mut xp, mut xm) =
                        if which == 0 { (e.clone(), e.clone()) } else { (edot.clone(), edot.clone()) };
                    xp[d] += h;
                    xm[d] -= h;
                    let (mut qp, mut qm) = (vec![0.0; n], vec![0.0; n]);
                    if which == 0 {
                        contact.forces(&body, &kin, &xp, &edot, &mut qp, None);
                        contact.forces(&body, &kin, &xm, &edot, &mut qm, None);
                    } else {
                        contact.forces(&body, &kin, &e, &xp, &mut qp, None);
                        contact.forces(&body, &kin, &e, &xm, &mut qm, None);
                    }
                    for r in 0..n {
                        let fd = (qp[r] - qm[r]) / (2.0 * h);
                        worst = worst.max((fd - k[r * n + d]).abs());
                    }
                }
                assert!(worst / scale < 1e-6, "{friction:?} {which}: {:.2e}", worst / scale);
            }
        }
    }

    #[test]
    fn tank_load_is_equal_and_opposite_to_the_fluid_load() {
        let (body, contact, kin, e, edot) = setup(WallFriction::Coulomb { coefficient: 0.3, slip_velocity: 0.05 });
        let mut q = vec![0.0; body.n_coords()];
        let load = contact.forces(&body, &kin, &e, &edot, &mut q, None);
        // the resultant of the generalized forces on position coordinates (sum of N_a over
        // position functions is 1) equals minus the tank force
        let mut f = [0.0; 3];
        for (s, x) in q.chunks_exact(3).enumerate() {
            if s % 4 == 0 {
                for i in 0..3 {
                    f[i] += x[i];
                }
            }
        }
        for i in 0..3 {
            assert!((f[i] + load.force[i]).abs() < 1e-9 * load.force.iter().fold(1.0f64, |m, x| m.max(x.abs())));
        }
        assert!(load.max_penetration > 0.003);
    }

    #[test]
    fn points_cover_the_boundary_area() {
        let mesh = box_mesh([0.0; 3], [0.6, 0.4, 0.3], [3, 2, 2]).unwrap();
        let body = FluidBody::new(
            mesh,
            Fluid::new(1000.0, Rheology::Newtonian { viscosity: 1.0 }, 1e5).unwrap(),
            QuadratureOptions::default(),
        )
        .unwrap();
        let geo = TankGeometry::new(TankShape::Box { min: [0.0; 3], max: [0.6, 0.4, 0.5] }, vec![]).unwrap();
        let c = WallContact::new(&body, geo, WallContactLaw::default_for(1000.0, 9.81, 0.3)).unwrap();
        let area: f64 = c.points.iter().map(|p| p.weight).sum();
        assert!((area - 2.0 * (0.6 * 0.4 + 0.6 * 0.3 + 0.4 * 0.3)).abs() < 1e-12);
    }
}
