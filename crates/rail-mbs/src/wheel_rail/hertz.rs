//! Hertzian normal contact: contact-ellipse semi-axes, penetration and the stiffness
//! `K_h` of `f_n = K_h δ^{3/2}` from the relative principal curvatures.
//!
//! Exact Hertz theory with complete elliptic integrals `K(e)`, `E(e)` (computed with the
//! arithmetic–geometric mean, accurate to rounding). With the undeformed gap written as
//! `h = A x² + B y²` (`A ≤ B`, so the long semi-axis `a` lies along `x`) and
//! `g = b/a`, `e² = 1 − g²` (Johnson, *Contact Mechanics*, §3.7):
//!
//! * `A / B = (K − E) / (E/g² − K)` fixes `g` (solved by bisection);
//! * `a³ = 3 N (K − E) / (2π E* A e²)`, `b = g a`;
//! * `p0 = 3N / (2π a b)`, `δ = p0 b K / E*`;
//!
//! where `1/E* = (1−ν₁²)/E₁ + (1−ν₂²)/E₂`. Since `a ∝ N^{1/3}` and `δ ∝ N^{2/3}`, the
//! solution is computed once for `N = 1 N` and scaled.

use super::ContactError;

/// Isotropic elastic material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus, Pa.
    pub young: f64,
    /// Poisson's ratio.
    pub poisson: f64,
}

impl Material {
    /// Wheel/rail steel: E = 210 GPa, ν = 0.3.
    pub fn steel() -> Self {
        Self { young: 2.1e11, poisson: 0.3 }
    }
    /// From the shear modulus `g` (Pa) and Poisson's ratio.
    pub fn from_shear(g: f64, poisson: f64) -> Self {
        Self { young: 2.0 * g * (1.0 + poisson), poisson }
    }
    /// Shear modulus `E / (2(1+ν))`, Pa.
    pub fn shear_modulus(&self) -> f64 {
        self.young / (2.0 * (1.0 + self.poisson))
    }
}

/// Combined plane-strain modulus `E*` of two bodies, Pa.
pub fn combined_modulus(m1: &Material, m2: &Material) -> f64 {
    1.0 / ((1.0 - m1.poisson * m1.poisson) / m1.young + (1.0 - m2.poisson * m2.poisson) / m2.young)
}

/// Complete elliptic integrals of the first and second kind, `(K(m), E(m))`, for the
/// parameter `m = k²` in `[0, 1)`, by the arithmetic–geometric mean.
pub fn elliptic_ke(m: f64) -> (f64, f64) {
    let m = m.clamp(0.0, 1.0 - 1e-16);
    let mut a = 1.0f64;
    let mut b = (1.0 - m).sqrt();
    let mut sum = 0.5 * m; // 2^{-1} c0², c0² = m
    let mut pow2 = 0.5;
    for _ in 0..40 {
        let an = 0.5 * (a + b);
        let bn = (a * b).sqrt();
        let cn = 0.5 * (a - b);
        pow2 *= 2.0;
        sum += pow2 * cn * cn;
        a = an;
        b = bn;
        if cn.abs() < 1e-17 {
            break;
        }
    }
    let k = std::f64::consts::PI / (2.0 * a);
    (k, k * (1.0 - sum))
}

/// `(K − E)/m`, accurate also for small `m`.
fn k_minus_e_over_m(m: f64) -> f64 {
    if m < 1e-5 {
        std::f64::consts::FRAC_PI_4 * (1.0 + 0.375 * m)
    } else {
        let (k, e) = elliptic_ke(m);
        (k - e) / m
    }
}

/// Curvature ratio `A/B` produced by the semi-axis ratio `g = b/a ≤ 1`.
fn curvature_ratio(g: f64) -> f64 {
    let m = 1.0 - g * g;
    if m < 1e-9 {
        return 1.0;
    }
    let (k, e) = elliptic_ke(m);
    (k - e) / (e / (g * g) - k)
}

/// Hertz solution for a pair of relative curvatures, scalable in the normal force.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HertzConstants {
    /// Relative curvature `A` along `x` (rolling direction), 1/m (`h = A x² + B y²`).
    pub curvature_x: f64,
    /// Relative curvature `B` along `y` (lateral), 1/m.
    pub curvature_y: f64,
    /// Combined modulus `E*`, Pa.
    pub e_star: f64,
    /// Stiffness `K_h` in `N = K_h δ^{3/2}`, N/m^{3/2}.
    pub stiffness: f64,
    /// Semi-axis along `x` for `N = 1 N`, m.
    a_unit: f64,
    /// Semi-axis along `y` for `N = 1 N`, m.
    b_unit: f64,
    /// Penetration for `N = 1 N`, m.
    delta_unit: f64,
}

impl HertzConstants {
    /// Solves the Hertz problem for relative curvatures `curvature_x` (rolling
    /// direction) and `curvature_y` (lateral), both strictly positive (1/m), and combined
    /// modulus `e_star` (Pa).
    pub fn new(curvature_x: f64, curvature_y: f64, e_star: f64) -> Result<Self, ContactError> {
        if !(curvature_x > 0.0 && curvature_y > 0.0 && curvature_x.is_finite() && curvature_y.is_finite()) {
            return Err(ContactError::NonHertzian { curvature_x, curvature_y });
        }
        if !(e_star > 0.0 && e_star.is_finite()) {
            return Err(ContactError::InvalidInput(format!("E* must be positive, got {e_star}")));
        }
        let (a_c, b_c, swapped) = if curvature_x <= curvature_y {
            (curvature_x, curvature_y, false)
        } else {
            (curvature_y, curvature_x, true)
        };
        let target = a_c / b_c;
        let g = if target > 1.0 - 1e-12 {
            1.0
        } else {
            // curvature_ratio(g) rises monotonically from 0 to 1 on (0, 1]: Illinois
            // (modified regula falsi) on f(g) = ratio(g) − target, bracketed, to 1e-14 in g.
            let f = |g: f64| Ok::<_, std::convert::Infallible>(curvature_ratio(g) - target);
            let (lo, hi) = (1e-9f64, 1.0 - 1e-12);
            let (flo, fhi) = (curvature_ratio(lo) - target, curvature_ratio(hi) - target);
            match ancf_core::roots::illinois(f, (lo, flo), (hi, fhi), |lo, hi| hi - lo < 1e-14, 200) {
                Ok(root) => root.x,
                Err(never) => match never {},
            }
        };
        let m = 1.0 - g * g;
        let n = 1.0;
        let a = (3.0 * n * k_minus_e_over_m(m) / (2.0 * std::f64::consts::PI * e_star * a_c)).cbrt();
        let b = g * a;
        let (k, _) = elliptic_ke(m);
        let p0 = 3.0 * n / (2.0 * std::f64::consts::PI * a * b);
        let delta = p0 * b * k / e_star;
        let (a_unit, b_unit) = if swapped { (b, a) } else { (a, b) };
        Ok(Self { curvature_x, curvature_y, e_star, stiffness: delta.powf(-1.5), a_unit, b_unit, delta_unit: delta })
    }

    /// Normal force for a penetration `delta` (m); zero for `delta ≤ 0`.
    pub fn force(&self, delta: f64) -> f64 {
        if delta <= 0.0 { 0.0 } else { self.stiffness * delta.powf(1.5) }
    }
    /// Penetration for a normal force `n` (N).
    pub fn penetration(&self, n: f64) -> f64 {
        self.delta_unit * n.max(0.0).powf(2.0 / 3.0)
    }
    /// Semi-axes `(a, b)` along `x` (rolling) and `y` (lateral) for a normal force `n`.
    pub fn semi_axes(&self, n: f64) -> (f64, f64) {
        let f = n.max(0.0).cbrt();
        (self.a_unit * f, self.b_unit * f)
    }
    /// Maximum contact pressure `3N/(2π a b)`, Pa.
    pub fn max_pressure(&self, n: f64) -> f64 {
        let (a, b) = self.semi_axes(n);
        if a * b <= 0.0 { 0.0 } else { 3.0 * n / (2.0 * std::f64::consts::PI * a * b) }
    }
}
