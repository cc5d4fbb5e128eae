//! Rigid tank geometry seen from the fluid: walls and bulkheads as smooth gap functions.
//!
//! Each wall is described by a function ψ(p) of a point p in the **tank frame** that is
//! the (approximate) signed distance beyond the wall: ψ > 0 means the point has
//! penetrated the wall by ψ. Its gradient ∇ψ points out of the liquid into the wall and
//! has unit length on every wall (exact distances for planes and the cylindrical shell,
//! first-order distances for the quadrics), so the contact stiffness k_p is the same
//! everywhere on the walls. The contact
//! force is potential-like, F = −f_n(ψ, ψ̇) ∇ψ, so exact Jacobians need ∇ψ and ∇²ψ,
//! which every wall provides analytically.
//!
//! | wall | ψ |
//! |---|---|
//! | plane n·p = d | n·p − d (exact) |
//! | cylindrical shell radius R (axis x) | √(y²+z²) − R (exact) |
//! | half-ellipsoidal head, depth d, centre x_c | (g − 1)/\|∇g\|, g = √φ, φ = (x−x_c)²/d² + (y²+z²)/R² |
//! | elliptical shell, semi-axes a (y), b (z) | (g − 1)/\|∇g\|, g = √(y²/a²+z²/b²) |
//! | bulkhead at x_b, thickness t, liquid on side s = ±1 | t/2 − s(x − x_b) |
//!
//! The head ψ equals the shell ψ, with the same gradient, on the tangent plane x = x_c
//! (there g = ρ/R and |∇g| = 1/R, so ψ = ρ − R; ∂ψ/∂x = 0 on both sides), so the tank
//! wall is C¹ across the head/shell junction; on a sphere (d = R) it is exact.

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
    /// two walls may be active at once and both push. Same walls, in the same order, as
    /// [`Self::for_each_hit`].
    pub fn hits(&self, p: [f64; 3], side: &[i8], out: &mut Vec<WallHit>) {
        out.clear();
        self.for_each_hit(p, side, |h| out.push(h));
    }

    /// Calls `sink` with every wall with ψ > 0 at `p` (tank frame), in a fixed order
    /// (shell walls, then the bulkheads in the order of `bulkheads`); no allocation. See
    /// [`Self::hits`].
    ///
    /// At most 3 shell walls are active at once (a box corner; cylinders: shell + one
    /// end), plus one per bulkhead whose liquid side the point has left.
    pub fn for_each_hit(&self, p: [f64; 3], side: &[i8], sink: impl FnMut(WallHit)) {
        self.for_each_hit_with(p, side, true, 0.0, sink);
    }

    /// [`Self::hits`] extended to every wall with ψ > −`reach` (`reach` ≥ 0, m): the walls
    /// within `reach` inside the tank too (wetted points of an adhesive wall,
    /// [`crate::contact::WallContactLaw::tension_capacity`]). `reach` = 0 is [`Self::hits`].
    pub fn hits_within(&self, p: [f64; 3], side: &[i8], reach: f64, out: &mut Vec<WallHit>) {
        out.clear();
        self.for_each_hit_with(p, side, true, reach, |h| out.push(h));
    }

    /// [`Self::for_each_hit`] for the walls with ψ > −`reach`; with `hessian` false, every
    /// `hess` is left zero (the same ψ and ∇ψ, bit for bit; for callers that need no
    /// Jacobian).
    pub(crate) fn for_each_hit_with(
        &self,
        p: [f64; 3],
        side: &[i8],
        hessian: bool,
        reach: f64,
        mut sink: impl FnMut(WallHit),
    ) {
        let [x, y, z] = p;
        match self.shape {
            TankShape::Cylinder { length, radius: r, head_depth: hd } => {
                let xc = 0.5 * length;
                if hd == 0.0 || x.abs() <= xc {
                    let rho = (y * y + z * z).sqrt();
                    if rho - r > -reach {
                        let n = [0.0, y / rho, z / rho];
                        let mut h = M3::zeros();
                        if hessian {
                            for i in 1..3 {
                                for j in 1..3 {
                                    h[(i, j)] = (if i == j { 1.0 } else { 0.0 } - n[i] * n[j]) / rho;
                                }
                            }
                        }
                        sink(WallHit { psi: rho - r, grad: n, hess: h });
                    }
                }
                if hd == 0.0 {
                    plane(p, [1.0, 0.0, 0.0], xc, reach, &mut sink);
                    plane(p, [-1.0, 0.0, 0.0], xc, reach, &mut sink);
                } else if x.abs() > xc {
                    let dx = x - xc * x.signum();
                    let inv = [1.0 / (hd * hd), 1.0 / (r * r), 1.0 / (r * r)];
                    let q = [dx, y, z];
                    if let Some(h) = quadric_hit(&q, &inv, hessian, reach) {
                        sink(h);
                    }
                }
            }
            TankShape::EllipticCylinder { length, semi_axis_y: a, semi_axis_z: b } => {
                let inv = [0.0, 1.0 / (a * a), 1.0 / (b * b)];
                if let Some(h) = quadric_hit(&[0.0, y, z], &inv, hessian, reach) {
                    sink(h);
                }
                plane(p, [1.0, 0.0, 0.0], 0.5 * length, reach, &mut sink);
                plane(p, [-1.0, 0.0, 0.0], 0.5 * length, reach, &mut sink);
            }
            TankShape::Box { min, max } => {
                for d in 0..3 {
                    let mut n = [0.0; 3];
                    n[d] = 1.0;
                    plane(p, n, max[d], reach, &mut sink);
                    n[d] = -1.0;
                    plane(p, n, -min[d], reach, &mut sink);
                }
            }
        }
        for (b, s) in self.bulkheads.iter().zip(side) {
            let s = *s as f64;
            let psi = 0.5 * b.thickness - s * (x - b.x);
            if psi > -reach {
                sink(WallHit { psi, grad: [-s, 0.0, 0.0], hess: M3::zeros() });
            }
        }
    }

    /// Clearance of `p` (tank frame): a lower bound c on the distance from `p` to the set
    /// H of points at which [`Self::hits`] reports a wall (for bulkhead sides `side`). Every
    /// point q with |q − p| ≤ c, c > 0, has no wall hit; c ≤ 0 says nothing.
    /// Equal to [`Self::box_clearance`] of the box [p, p].
    pub fn clearance(&self, p: [f64; 3], side: &[i8]) -> f64 {
        self.box_clearance(p, p, side)
    }

    /// A lower bound c on the distance from every point of the box [`lo`, `hi`] (tank
    /// frame, lo ≤ hi) to the set H of points at which [`Self::hits`] reports a wall (for
    /// bulkhead sides `side`); c > 0: no point within c of the box has a wall hit.
    ///
    /// Derivation, wall by wall: c is the minimum over the walls of a lower bound on the
    /// distance from the box to a set containing that wall's part of H. With
    /// X, Y, Z the largest |x|, |y|, |z| over the box (X about the head centre):
    /// - plane n·q > d (axis normal): d − max over the box of n·q, exact;
    /// - cylindrical shell {ρ > R}: R − √(Y² + Z²) (every box point has ρ ≤ √(Y² + Z²),
    ///   and the distance from ρ to the exterior of the disc is R − ρ);
    /// - elliptic shell {y²/a² + z²/b² > 1}: with the gauge g = √(y²/a² + z²/b²) ≤
    ///   g_max = √(Y²/a² + Z²/b²), m = min(a, b) and E the (convex) ellipse: (y, z) ∈ gE
    ///   and the disc of radius m lies in E, so (y, z) + u ∈ gE + (1 − g)E = E for
    ///   |u| ≤ (1 − g)m: c = (1 − g_max) m;
    /// - head at x_c (depth d, radius R), active for x > x_c only: H ⊂ {x > x_c} ∩
    ///   {φ > 1}, φ = (x − x_c)²/d² + ρ²/R²; the distance is ≥ x_c − max x (half-space)
    ///   and ≥ (1 − √φ_max) min(d, R) (the ellipsoid argument above in 3-D, with
    ///   φ ≤ φ_max = X²/d² + (Y² + Z²)/R²), so ≥ their maximum (mirrored at −x_c);
    /// - bulkhead at x_b, thickness t, liquid side s: H = {s(x − x_b) < t/2}:
    ///   c = min over the box of s(x − x_b) − t/2, exact.
    ///
    /// Computed in floating point: callers that need a strict guarantee must keep a margin
    /// of many ulps of the tank size (see `contact.rs`). Non-finite input gives −∞.
    pub fn box_clearance(&self, lo: [f64; 3], hi: [f64; 3], side: &[i8]) -> f64 {
        // (f64::min ignores NaN: a non-finite box gets no clearance at all)
        if !lo.iter().chain(&hi).all(|v| v.is_finite()) {
            return f64::NEG_INFINITY;
        }
        let amax = |d: usize| lo[d].abs().max(hi[d].abs());
        let (yy, zz) = (amax(1), amax(2));
        let mut c = match self.shape {
            TankShape::Cylinder { length, radius: r, head_depth: hd } => {
                let xc = 0.5 * length;
                let rho = (yy * yy + zz * zz).sqrt();
                let shell = r - rho;
                if hd == 0.0 {
                    shell.min(xc - hi[0]).min(lo[0] + xc)
                } else {
                    let m = hd.min(r);
                    let q = rho * rho / (r * r);
                    let head = |xx: f64| (1.0 - (xx * xx / (hd * hd) + q).sqrt()) * m;
                    let front = (xc - hi[0]).max(head((lo[0] - xc).abs().max((hi[0] - xc).abs())));
                    let rear = (lo[0] + xc).max(head((lo[0] + xc).abs().max((hi[0] + xc).abs())));
                    shell.min(front).min(rear)
                }
            }
            TankShape::EllipticCylinder { length, semi_axis_y: a, semi_axis_z: b } => {
                let g = (yy * yy / (a * a) + zz * zz / (b * b)).sqrt();
                let h = 0.5 * length;
                ((1.0 - g) * a.min(b)).min(h - hi[0]).min(lo[0] + h)
            }
            TankShape::Box { min, max } => {
                let mut c = f64::INFINITY;
                for d in 0..3 {
                    c = c.min(max[d] - hi[d]).min(lo[d] - min[d]);
                }
                c
            }
        };
        for (b, s) in self.bulkheads.iter().zip(side) {
            // min over the box of s(x − x_b)
            let s = *s as f64;
            let gap = if s > 0.0 { s * (lo[0] - b.x) } else { s * (hi[0] - b.x) };
            c = c.min(gap - 0.5 * b.thickness);
        }
        c
    }

    /// A length scale of the tank: the largest absolute coordinate of its interior.
    pub fn size(&self) -> f64 {
        match self.shape {
            TankShape::Cylinder { length, radius, head_depth } => (0.5 * length + head_depth).max(radius),
            TankShape::EllipticCylinder { length, semi_axis_y, semi_axis_z } => {
                (0.5 * length).max(semi_axis_y).max(semi_axis_z)
            }
            TankShape::Box { min, max } => min.iter().chain(&max).fold(0.0f64, |m, v| m.max(v.abs())),
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

/// A plane wall n·p = d: its hit, if ψ = n·p − d > 0.
fn plane(p: [f64; 3], n: [f64; 3], d: f64, reach: f64, sink: &mut impl FnMut(WallHit)) {
    let psi = n[0] * p[0] + n[1] * p[1] + n[2] * p[2] - d;
    if psi > -reach {
        sink(WallHit { psi, grad: n, hess: M3::zeros() });
    }
}

/// ψ = (g − 1)/|∇g| with the gauge g = √φ, φ = Σ inv_i q_i², if positive (∇²ψ only with
/// `hessian`): the first-order distance beyond the quadric g = 1. Since g is homogeneous of
/// degree 1, |∇g| is constant along rays from the centre, ψ grows linearly along them, and
/// |∇ψ| = 1 on the wall, so the wall is equally stiff everywhere (the earlier
/// ψ = s(√φ − 1) had |∇ψ| = s|∇g|: 3× the shell's at the tip of a 0.5 m head on a 1.5 m
/// shell, i.e. 9× its contact stiffness, issue 16).
///
/// With A = D q, B = D² q (D = diag(inv)), w = |A|², r = φ/w, u = 1/|∇g| = √r:
/// ∇g = A/g, ∇²g = D/g − A Aᵀ/g³, ∇r = 2(A − r B)/w, ∇u = (A − r B)/(u w),
/// ∇²u = (A − r B) ∇(1/(u w))ᵀ + (D − r D² − B ∇rᵀ)/(u w) with
/// ∇(1/(u w)) = −∇r/(2 u³ w) − 2 B/(u w²), and
/// ∇ψ = u ∇g + (g − 1) ∇u, ∇²ψ = u ∇²g + ∇g ∇uᵀ + ∇u ∇gᵀ + (g − 1) ∇²u.
fn quadric_hit(q: &[f64; 3], inv: &[f64; 3], hessian: bool, reach: f64) -> Option<WallHit> {
    let a: [f64; 3] = std::array::from_fn(|i| inv[i] * q[i]);
    let b: [f64; 3] = std::array::from_fn(|i| inv[i] * a[i]);
    let phi: f64 = (0..3).map(|i| q[i] * a[i]).sum();
    let g = phi.sqrt();
    // (inside, only points near the wall can be within `reach`: g ≥ 1/2 keeps clear of the
    // centre, where ∇g vanishes)
    if g <= 1.0 && (reach <= 0.0 || g < 0.5) {
        return None;
    }
    let w: f64 = a.iter().map(|x| x * x).sum();
    let r = phi / w;
    let u = r.sqrt();
    let psi = (g - 1.0) * u;
    if psi <= -reach {
        return None;
    }
    let c: [f64; 3] = std::array::from_fn(|i| a[i] - r * b[i]); // A − r B
    let grad_g: [f64; 3] = std::array::from_fn(|i| a[i] / g);
    let grad_u: [f64; 3] = std::array::from_fn(|i| c[i] / (u * w));
    let grad = std::array::from_fn(|i| u * grad_g[i] + (g - 1.0) * grad_u[i]);
    let mut hess = M3::zeros();
    if hessian {
        let grad_r: [f64; 3] = std::array::from_fn(|i| 2.0 * c[i] / w);
        let grad_k: [f64; 3] = std::array::from_fn(|i| -grad_r[i] / (2.0 * u * u * u * w) - 2.0 * b[i] / (u * w * w));
        for i in 0..3 {
            for j in 0..3 {
                let d = if i == j { inv[i] } else { 0.0 };
                let hg = d / g - a[i] * a[j] / (g * g * g);
                let hu = c[i] * grad_k[j] + (d - r * d * inv[i] - b[i] * grad_r[j]) / (u * w);
                hess[(i, j)] = u * hg + grad_g[i] * grad_u[j] + grad_u[i] * grad_g[j] + (g - 1.0) * hu;
            }
        }
        // the formula is symmetric up to round-off; make it exactly so
        hess = 0.5 * (hess + hess.transpose());
    }
    Some(WallHit { psi, grad, hess })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

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
    fn quadric_walls_are_unit_gradient_distances_near_the_wall() {
        // just beyond the wall, at the tip and the rim of a head and around an ellipse:
        // ψ ≈ the distance along the normal, |∇ψ| = 1 (the old ψ = R(√φ − 1) gave 3 at
        // the tip of this head)
        let cyl =
            TankGeometry::new(TankShape::Cylinder { length: 11.0, radius: 1.5, head_depth: 0.5 }, vec![]).unwrap();
        let ell = TankGeometry::new(
            TankShape::EllipticCylinder { length: 0.324, semi_axis_y: 0.2086, semi_axis_z: 0.1321 },
            vec![],
        )
        .unwrap();
        let mut h = Vec::new();
        let eps = 1e-4;
        for k in 0..=8 {
            let t = std::f64::consts::FRAC_PI_2 * k as f64 / 8.0;
            // head surface point at polar angle t from the axis, pushed out along the normal
            let (x, rho) = (5.5 + 0.5 * t.cos(), 1.5 * t.sin());
            let n = Vector3::new(t.cos() / 0.5, 0.0, -t.sin() / 1.5).normalize();
            let p = Vector3::new(x, 0.0, -rho) + eps * n;
            cyl.hits([p[0], p[1], p[2]], &[], &mut h);
            let hit = h.iter().max_by(|a, b| a.psi.total_cmp(&b.psi)).unwrap();
            let gn = Vector3::from(hit.grad).norm();
            assert!((gn - 1.0).abs() < 1e-3, "head, angle {t}: |grad| = {gn}");
            assert!((hit.psi - eps).abs() < 1e-3 * eps + 1e-9, "head, angle {t}: psi = {}", hit.psi);
            // ellipse point at angle t, pushed out along its normal
            let (a, b) = (0.2086, 0.1321);
            let n = Vector3::new(0.0, t.cos() / a, t.sin() / b).normalize();
            let p = Vector3::new(0.0, a * t.cos(), b * t.sin()) + eps * n;
            ell.hits([p[0], p[1], p[2]], &[], &mut h);
            let hit = h[0];
            assert!((Vector3::from(hit.grad).norm() - 1.0).abs() < 1e-3, "ellipse, angle {t}");
            assert!((hit.psi - eps).abs() < 1e-3 * eps + 1e-9, "ellipse, angle {t}: psi = {}", hit.psi);
        }
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
