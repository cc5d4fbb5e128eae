//! Rigid tank geometry seen from the fluid: walls and bulkheads as smooth gap functions.
//!
//! Each wall is described by a function ψ(p) of a point p in the **tank frame** that is
//! the (approximate) signed distance beyond the wall: ψ > 0 means the point has
//! penetrated the wall by ψ. Its gradient ∇ψ points out of the liquid into the wall and
//! has unit length on exact-distance walls (planes, the cylindrical shell). The contact
//! force is potential-like, F = −f_n(ψ, ψ̇) ∇ψ, so exact Jacobians need ∇ψ and ∇²ψ,
//! which every wall provides analytically.
//!
//! | wall | ψ |
//! |---|---|
//! | plane n·p = d | n·p − d (exact) |
//! | cylindrical shell radius R (axis x) | √(y²+z²) − R (exact) |
//! | half-ellipsoidal head, depth d, centre x_c | R(√φ − 1), φ = (x−x_c)²/d² + (y²+z²)/R² |
//! | elliptical shell, semi-axes a (y), b (z) | √(ab)(√(y²/a²+z²/b²) − 1) |
//! | bulkhead at x_b, thickness t, liquid on side s = ±1 | t/2 − s(x − x_b) |
//!
//! The head ψ equals the shell ψ, with the same gradient, on the tangent plane x = x_c,
//! so the tank wall is C¹ across the head/shell junction; on a sphere (d = R) it is exact.

use crate::constitutive::M3;
use crate::error::{Result, check_positive, invalid};

/// Shape of the tank shell, in the tank frame (x along the axis).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TankShape {
    /// Horizontal cylinder (axis x, centred at the origin) with half-ellipsoidal heads.
    Cylinder {
        /// Shell length between head tangent lines (m).
        length: f64,
        /// Radius (m).
        radius: f64,
        /// Head depth (m); 0 gives flat ends.
        head_depth: f64,
    },
    /// Flat-ended cylinder of elliptical section, centred at the origin.
    EllipticCylinder {
        /// Length (m).
        length: f64,
        /// Lateral semi-axis (m).
        semi_axis_y: f64,
        /// Vertical semi-axis (m).
        semi_axis_z: f64,
    },
    /// Closed rectangular box between two corners.
    Box {
        /// Minimum corner (m).
        min: [f64; 3],
        /// Maximum corner (m).
        max: [f64; 3],
    },
}

/// A bulkhead: a plane across the tank at `x`, of thickness `thickness`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bulkhead {
    /// Axial position of the mid-plane in the tank frame (m).
    pub x: f64,
    /// Thickness (m).
    pub thickness: f64,
}

/// Tank shell plus bulkheads.
#[derive(Debug, Clone, PartialEq)]
pub struct TankGeometry {
    /// Shell.
    pub shape: TankShape,
    /// Bulkheads, sorted by x.
    pub bulkheads: Vec<Bulkhead>,
}

/// One active wall at a point: penetration, gradient and Hessian of ψ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallHit {
    /// ψ > 0: penetration depth (m).
    pub psi: f64,
    /// ∇ψ (points into the wall).
    pub grad: [f64; 3],
    /// ∇²ψ.
    pub hess: M3,
}

impl TankGeometry {
    /// Validate and build.
    pub fn new(shape: TankShape, mut bulkheads: Vec<Bulkhead>) -> Result<Self> {
        match shape {
            TankShape::Cylinder { length, radius, head_depth } => {
                check_positive("tank.length", length)?;
                check_positive("tank.radius", radius)?;
                if !(head_depth.is_finite() && head_depth >= 0.0) {
                    return Err(invalid("tank.head_depth", head_depth, "a finite number >= 0"));
                }
            }
            TankShape::EllipticCylinder { length, semi_axis_y, semi_axis_z } => {
                check_positive("tank.length", length)?;
                check_positive("tank.semi_axis_y", semi_axis_y)?;
                check_positive("tank.semi_axis_z", semi_axis_z)?;
            }
            TankShape::Box { min, max } => {
                for d in 0..3 {
                    if !(max[d] > min[d]) {
                        return Err(invalid(&format!("tank.max[{d}]"), max[d], "greater than tank.min"));
                    }
                }
            }
        }
        let (lo, hi) = self_axial_extent(&shape);
        bulkheads.sort_by(|a, b| a.x.total_cmp(&b.x));
        for (i, b) in bulkheads.iter().enumerate() {
            check_positive(&format!("bulkheads[{i}].thickness"), b.thickness)?;
            if !(b.x - 0.5 * b.thickness > lo && b.x + 0.5 * b.thickness < hi) {
                return Err(invalid(&format!("bulkheads[{i}].x"), b.x, &format!("inside the shell, in ({lo}, {hi})")));
            }
            if i > 0 && b.x - 0.5 * b.thickness <= bulkheads[i - 1].x + 0.5 * bulkheads[i - 1].thickness {
                return Err(invalid(&format!("bulkheads[{i}].x"), b.x, "bulkheads must not overlap"));
            }
        }
        Ok(Self { shape, bulkheads })
    }

    /// Axial extent (x_min, x_max) of the tank interior.
    pub fn axial_extent(&self) -> (f64, f64) {
        self_axial_extent(&self.shape)
    }

    /// Every wall with ψ > 0 at `p` (tank frame). `side` gives, for each bulkhead, the
    /// side of its liquid (−1: x < x_b, +1: x > x_b). Walls are independent: at a corner
    /// two walls may be active at once and both push.
    pub fn hits(&self, p: [f64; 3], side: &[i8], out: &mut Vec<WallHit>) {
        out.clear();
        let [x, y, z] = p;
        let plane = |n: [f64; 3], d: f64, out: &mut Vec<WallHit>| {
            let psi = n[0] * x + n[1] * y + n[2] * z - d;
            if psi > 0.0 {
                out.push(WallHit { psi, grad: n, hess: M3::zeros() });
            }
        };
        match self.shape {
            TankShape::Cylinder { length, radius: r, head_depth: hd } => {
                let xc = 0.5 * length;
                if hd == 0.0 || x.abs() <= xc {
                    let rho = (y * y + z * z).sqrt();
                    if rho - r > 0.0 {
                        let n = [0.0, y / rho, z / rho];
                        let mut h = M3::zeros();
                        for i in 1..3 {
                            for j in 1..3 {
                                h[(i, j)] = (if i == j { 1.0 } else { 0.0 } - n[i] * n[j]) / rho;
                            }
                        }
                        out.push(WallHit { psi: rho - r, grad: n, hess: h });
                    }
                }
                if hd == 0.0 {
                    plane([1.0, 0.0, 0.0], xc, out);
                    plane([-1.0, 0.0, 0.0], xc, out);
                } else if x.abs() > xc {
                    let dx = x - xc * x.signum();
                    let inv = [1.0 / (hd * hd), 1.0 / (r * r), 1.0 / (r * r)];
                    let q = [dx, y, z];
                    if let Some(h) = quadric_hit(&q, &inv, r) {
                        out.push(h);
                    }
                }
            }
            TankShape::EllipticCylinder { length, semi_axis_y: a, semi_axis_z: b } => {
                let inv = [0.0, 1.0 / (a * a), 1.0 / (b * b)];
                if let Some(h) = quadric_hit(&[0.0, y, z], &inv, (a * b).sqrt()) {
                    out.push(h);
                }
                plane([1.0, 0.0, 0.0], 0.5 * length, out);
                plane([-1.0, 0.0, 0.0], 0.5 * length, out);
            }
            TankShape::Box { min, max } => {
                for d in 0..3 {
                    let mut n = [0.0; 3];
                    n[d] = 1.0;
                    plane(n, max[d], out);
                    n[d] = -1.0;
                    plane(n, -min[d], out);
                }
            }
        }
        for (b, s) in self.bulkheads.iter().zip(side) {
            let s = *s as f64;
            let psi = 0.5 * b.thickness - s * (x - b.x);
            if psi > 0.0 {
                out.push(WallHit { psi, grad: [-s, 0.0, 0.0], hess: M3::zeros() });
            }
        }
    }

    /// Side (−1 or +1) of each bulkhead on which the point `p` lies.
    pub fn sides(&self, p: [f64; 3]) -> Vec<i8> {
        self.bulkheads.iter().map(|b| if p[0] < b.x { -1 } else { 1 }).collect()
    }
}

fn self_axial_extent(shape: &TankShape) -> (f64, f64) {
    match *shape {
        TankShape::Cylinder { length, head_depth, .. } => (-0.5 * length - head_depth, 0.5 * length + head_depth),
        TankShape::EllipticCylinder { length, .. } => (-0.5 * length, 0.5 * length),
        TankShape::Box { min, max } => (min[0], max[0]),
    }
}

/// ψ = s(√φ − 1) with φ = Σ q_i² inv_i, if positive.
fn quadric_hit(q: &[f64; 3], inv: &[f64; 3], s: f64) -> Option<WallHit> {
    let phi: f64 = (0..3).map(|i| q[i] * q[i] * inv[i]).sum();
    let sq = phi.sqrt();
    let psi = s * (sq - 1.0);
    if psi <= 0.0 {
        return None;
    }
    // ∇φ = 2 inv q; ∇ψ = s ∇φ / (2√φ); ∇²ψ = s [∇²φ/(2√φ) − ∇φ∇φᵀ/(4 φ^{3/2})]
    let gphi = [2.0 * inv[0] * q[0], 2.0 * inv[1] * q[1], 2.0 * inv[2] * q[2]];
    let grad = [s * gphi[0] / (2.0 * sq), s * gphi[1] / (2.0 * sq), s * gphi[2] / (2.0 * sq)];
    let mut hess = M3::zeros();
    for i in 0..3 {
        for j in 0..3 {
            let d = if i == j { 2.0 * inv[i] / (2.0 * sq) } else { 0.0 };
            hess[(i, j)] = s * (d - gphi[i] * gphi[j] / (4.0 * phi * sq));
        }
    }
    Some(WallHit { psi, grad, hess })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fd_check(g: &TankGeometry, p: [f64; 3]) {
        let mut hits = Vec::new();
        g.hits(p, &[], &mut hits);
        assert!(!hits.is_empty(), "{p:?}");
        let h = 1e-6;
        for (k, hit) in hits.iter().enumerate() {
            for d in 0..3 {
                let (mut pp, mut pm) = (p, p);
                pp[d] += h;
                pm[d] -= h;
                let (mut a, mut b) = (Vec::new(), Vec::new());
                g.hits(pp, &[], &mut a);
                g.hits(pm, &[], &mut b);
                let fd = (a[k].psi - b[k].psi) / (2.0 * h);
                assert!((fd - hit.grad[d]).abs() < 1e-7, "grad {d}: {fd} vs {}", hit.grad[d]);
                for i in 0..3 {
                    let fd = (a[k].grad[i] - b[k].grad[i]) / (2.0 * h);
                    assert!((fd - hit.hess[(i, d)]).abs() < 1e-5, "hess {i}{d}");
                }
            }
        }
    }

    #[test]
    fn wall_gradients_and_hessians_match_finite_differences() {
        let cyl =
            TankGeometry::new(TankShape::Cylinder { length: 10.0, radius: 1.5, head_depth: 0.5 }, vec![]).unwrap();
        fd_check(&cyl, [1.0, 0.9, -1.3]); // shell
        fd_check(&cyl, [5.3, 0.4, -1.2]); // head
        let ell = TankGeometry::new(
            TankShape::EllipticCylinder { length: 0.324, semi_axis_y: 0.2086, semi_axis_z: 0.1321 },
            vec![],
        )
        .unwrap();
        fd_check(&ell, [0.0, 0.15, -0.11]);
    }

    #[test]
    fn shell_and_head_agree_at_the_tangent_plane_and_distances_are_exact() {
        let g = TankGeometry::new(TankShape::Cylinder { length: 10.0, radius: 1.5, head_depth: 0.7 }, vec![]).unwrap();
        let mut a = Vec::new();
        let mut b = Vec::new();
        g.hits([5.0 - 1e-12, 0.3, -1.52], &[], &mut a);
        g.hits([5.0 + 1e-12, 0.3, -1.52], &[], &mut b);
        assert!((a[0].psi - b[0].psi).abs() < 1e-10);
        for i in 0..3 {
            assert!((a[0].grad[i] - b[0].grad[i]).abs() < 1e-9);
        }
        // exact radial distance on the shell
        g.hits([0.0, 0.0, -1.6], &[], &mut a);
        assert!((a[0].psi - 0.1).abs() < 1e-14);
        // nothing inside
        g.hits([0.0, 0.0, 0.0], &[], &mut a);
        assert!(a.is_empty());
    }

    #[test]
    fn bulkheads_push_liquid_back_to_its_own_side() {
        let g = TankGeometry::new(
            TankShape::Box { min: [-1.0, -0.5, 0.0], max: [1.0, 0.5, 1.0] },
            vec![Bulkhead { x: 0.0, thickness: 0.02 }],
        )
        .unwrap();
        let mut h = Vec::new();
        g.hits([-0.005, 0.0, 0.5], &[-1], &mut h);
        assert_eq!(h.len(), 1);
        assert!((h[0].psi - 0.005).abs() < 1e-15 && h[0].grad[0] == 1.0);
        g.hits([-0.005, 0.0, 0.5], &[1], &mut h); // liquid of the other compartment: deep inside
        assert_eq!(h.len(), 1);
        assert!((h[0].psi - 0.015).abs() < 1e-15 && h[0].grad[0] == -1.0);
        assert!(TankGeometry::new(g.shape, vec![Bulkhead { x: 1.5, thickness: 0.01 }]).is_err());
    }
}
