//! Creep (tangential) forces: Kalker's linear coefficients and saturation laws.
//!
//! Conventions: creepages are the rigid slip of the **wheel relative to the rail**
//! divided by the rolling speed, in the right-handed contact frame `(e1, e2, n)` with
//! `e1` along the direction of travel and `n` the contact normal:
//! `ξ = v·e1/V`, `η = v·e2/V`, `φ = ω·n/V` (1/m). Forces and moment returned act **on
//! the wheel** along `e1`, `e2` and about `n`. The linear (Kalker) law is
//!
//! ```text
//! Fx = −f11 ξ,  Fy = −f22 η − f23 φ,  Mz = f23 η − f33 φ,
//! f11 = G c² C11,  f22 = G c² C22,  f23 = G c³ C23,  f33 = G c⁴ C33,  c = √(ab).
//! ```
//!
//! `C11`, `C22`, `C23` come from Kalker's table (Kalker 1990, *Three-dimensional elastic
//! bodies in rolling contact*, Table E.3), with the values and the interpolation scheme
//! (linear in `g`, quadratic in `1/C` over ν) as used in CONTACT's `linrol` routine
//! (© Vtech CMCC, Apache-2.0), including its asymptotes for `g < 0.1`. `C33` is **not**
//! tabulated here: the spin-moment coefficient uses the simplified-theory relation with
//! Kalker's spin flexibility `L3 = π a √(a/b) / (4 G C23)`, i.e.
//! `f33 = 8 a² b³ / (15 L3)` (TODO: port Kalker's C33 column).
//!
//! Saturation laws: Shen–Hedrick–Elkins (default), Polach, and FASTSIM (Kalker's
//! simplified theory, three flexibilities, Hertzian traction bound).

/// Kalker's linear creep coefficients (dimensionless).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KalkerCoefficients {
    /// Longitudinal `C11`.
    pub c11: f64,
    /// Lateral `C22`.
    pub c22: f64,
    /// Lateral/spin coupling `C23`.
    pub c23: f64,
}

/// Rows g = 0.1 … 1.0; per row C11(ν=0, .25, .5), C22(…), C23(…). Case a ≤ b.
#[allow(clippy::approx_constant)] // tabulated data, 3.14 is not π
const TABLE_A_LE_B: [[f64; 9]; 10] = [
    [2.51, 3.31, 4.85, 2.51, 2.52, 2.53, 0.334, 0.473, 0.731],
    [2.59, 3.37, 4.81, 2.59, 2.63, 2.66, 0.483, 0.603, 0.809],
    [2.68, 3.44, 4.80, 2.68, 2.75, 2.81, 0.607, 0.715, 0.889],
    [2.78, 3.53, 4.82, 2.78, 2.88, 2.98, 0.720, 0.823, 0.977],
    [2.88, 3.62, 4.83, 2.88, 3.01, 3.14, 0.827, 0.929, 1.07],
    [2.98, 3.72, 4.91, 2.98, 3.14, 3.31, 0.930, 1.03, 1.18],
    [3.09, 3.81, 4.97, 3.09, 3.28, 3.48, 1.03, 1.14, 1.29],
    [3.19, 3.91, 5.05, 3.19, 3.41, 3.65, 1.13, 1.25, 1.40],
    [3.29, 4.01, 5.12, 3.29, 3.54, 3.82, 1.23, 1.36, 1.51],
    [3.40, 4.12, 5.20, 3.40, 3.67, 3.98, 1.33, 1.47, 1.63],
];
/// Same, case a > b, rows g = b/a = 0.1 … 1.0.
const TABLE_A_GT_B: [[f64; 9]; 10] = [
    [10.7, 11.7, 12.9, 10.7, 12.8, 16.0, 12.2, 14.6, 18.0],
    [6.96, 7.78, 8.82, 6.96, 8.14, 9.79, 5.72, 6.63, 7.89],
    [5.57, 6.34, 7.34, 5.57, 6.40, 7.51, 3.79, 4.32, 5.01],
    [4.84, 5.57, 6.57, 4.84, 5.48, 6.31, 2.88, 3.24, 3.70],
    [4.37, 5.10, 6.11, 4.37, 4.90, 5.56, 2.35, 2.62, 2.96],
    [4.06, 4.78, 5.80, 4.06, 4.50, 5.04, 2.01, 2.23, 2.50],
    [3.82, 4.54, 5.58, 3.82, 4.21, 4.67, 1.76, 1.95, 2.18],
    [3.65, 4.36, 5.42, 3.65, 3.99, 4.39, 1.58, 1.75, 1.94],
    [3.51, 4.22, 5.30, 3.51, 3.81, 4.16, 1.44, 1.59, 1.77],
    [3.40, 4.12, 5.20, 3.40, 3.67, 3.98, 1.33, 1.47, 1.63],
];

/// Kalker's coefficients for semi-axis ratio `a/b` (`a` along the rolling direction)
/// and Poisson's ratio `nu ∈ [0, 0.5]`.
pub fn kalker_coefficients(a_over_b: f64, nu: f64) -> KalkerCoefficients {
    let pi = std::f64::consts::PI;
    let aob = a_over_b.max(1e-6);
    let (g, table) = if aob <= 1.0 { (aob, &TABLE_A_LE_B) } else { (1.0 / aob, &TABLE_A_GT_B) };
    if g < 0.1 {
        if aob <= 1.0 {
            let c11 = pi * pi / 4.0 / (1.0 - nu);
            let c22 = pi * pi / 4.0;
            let c23 = pi * g.sqrt() / 3.0 / (1.0 - nu) * (1.0 + nu * ((16.0 / g).ln() - 5.0));
            return KalkerCoefficients { c11, c22, c23 };
        }
        let al = (16.0 / (g * g)).ln();
        let l4 = 4.0f64.ln();
        let c11 = 2.0 * pi / (al - 2.0 * nu) / g * (1.0 + (3.0 - l4) / (al - 2.0 * nu));
        let c22 = 2.0 * pi / g * (1.0 + (1.0 - nu) * (3.0 - l4) / ((1.0 - nu) * al + 2.0 * nu))
            / ((1.0 - nu) * al + 2.0 * nu);
        let c23 = 2.0 * pi / 3.0 / g.powf(1.5) / ((1.0 - nu) * al - 2.0 + 4.0 * nu);
        return KalkerCoefficients { c11, c22, c23 };
    }
    // Linear interpolation between table rows in g.
    let x = (10.0 * g - 1.0).clamp(0.0, 9.0);
    let i = (x.floor() as usize).min(8);
    let w = x - i as f64;
    let mut out = [0.0; 3];
    for (c, o) in out.iter_mut().enumerate() {
        let at = |k: usize| (1.0 - w) * table[i][3 * c + k] + w * table[i + 1][3 * c + k];
        // Quadratic Lagrange interpolation of 1/C over nu = 0, 0.25, 0.5.
        let (c0, c1, c2) = (at(0), at(1), at(2));
        let inv = (nu - 0.25) * (nu - 0.5) * 8.0 / c0 - nu * (nu - 0.5) * 16.0 / c1 + nu * (nu - 0.25) * 8.0 / c2;
        *o = 1.0 / inv;
    }
    KalkerCoefficients { c11: out[0], c22: out[1], c23: out[2] }
}

/// Creepages in the contact frame (see module docs).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Creepages {
    /// Longitudinal `ξ` (−).
    pub longitudinal: f64,
    /// Lateral `η` (−).
    pub lateral: f64,
    /// Spin `φ`, 1/m.
    pub spin: f64,
}

/// Creep forces on the wheel in the contact frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CreepForces {
    /// Along `e1`, N.
    pub longitudinal: f64,
    /// Along `e2`, N.
    pub lateral: f64,
    /// Spin moment about `n`, N·m.
    pub spin_moment: f64,
}

/// Creep-force law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CreepModel {
    /// Kalker's linear theory, unsaturated (valid only for small creepage).
    Linear,
    /// Kalker linear forces scaled by the Shen–Hedrick–Elkins (1983) cubic saturation:
    /// with `β = |F_lin|/(μN)`, the resultant is `μN(β − β²/3 + β³/27)` for `β < 3`, and
    /// `μN` beyond. The default.
    ShenHedrickElkins,
    /// Polach (2000/2005) saturation `F = (2μN/π)[k_A ε/(1 + (k_A ε)²) + atan(k_S ε)]`
    /// applied to the resultant, with the gradient `ε = π |F_lin| / (4 μ N)` so that the
    /// initial slope equals Kalker's when `k_A = k_S = 1`. Spin enters through the linear
    /// `f23 φ` term of `F_lin` (Polach's separate spin correction is not included), and
    /// the friction coefficient is constant (TODO: falling friction `μ(w)`).
    Polach {
        /// Reduction factor in the adhesion area (1 = none).
        k_a: f64,
        /// Reduction factor in the slip area (1 = none).
        k_s: f64,
    },
    /// Kalker's simplified theory, FASTSIM (Kalker 1982), with three flexibilities
    /// `L1 = 8a/(3 C11 G)`, `L2 = 8a/(3 C22 G)`, `L3 = π a √(a/b) / (4 C23 G)` and the
    /// Hertzian (semi-ellipsoidal) traction bound `μ p(x, y)`, on `nx × ny` cells
    /// (strips across the rolling direction, marched from the leading edge).
    Fastsim {
        /// Cells per strip along the rolling direction.
        nx: usize,
        /// Number of strips across.
        ny: usize,
    },
}

/// Linear creep coefficients `(f11, f22, f23, f33)` for semi-axes `a` (rolling) and
/// `b`, shear modulus `g` (Pa) and Poisson's ratio `nu`.
pub fn linear_coefficients(a: f64, b: f64, g: f64, nu: f64) -> (f64, f64, f64, f64) {
    if a <= 0.0 || b <= 0.0 {
        return (0.0, 0.0, 0.0, 0.0);
    }
    let k = kalker_coefficients(a / b, nu);
    let c2 = a * b;
    let f11 = g * c2 * k.c11;
    let f22 = g * c2 * k.c22;
    let f23 = g * c2.powf(1.5) * k.c23;
    let l3 = std::f64::consts::PI * a * (a / b).sqrt() / (4.0 * g * k.c23);
    let f33 = 8.0 * a * a * b * b * b / (15.0 * l3);
    (f11, f22, f23, f33)
}

/// Creep forces on the wheel for creepages `c`, ellipse semi-axes `a` (rolling), `b`,
/// normal force `n` (N), friction coefficient `mu`, shear modulus `g` and Poisson's
/// ratio `nu`.
#[allow(clippy::too_many_arguments)]
pub fn creep_forces(model: CreepModel, c: &Creepages, a: f64, b: f64, n: f64, mu: f64, g: f64, nu: f64) -> CreepForces {
    if n <= 0.0 || a <= 0.0 || b <= 0.0 {
        return CreepForces::default();
    }
    if let CreepModel::Fastsim { nx, ny } = model {
        return fastsim(c, a, b, n, mu, g, nu, nx.max(2), ny.max(2));
    }
    let (f11, f22, f23, f33) = linear_coefficients(a, b, g, nu);
    let fx = -f11 * c.longitudinal;
    let fy = -f22 * c.lateral - f23 * c.spin;
    let mz = f23 * c.lateral - f33 * c.spin;
    let lin = (fx * fx + fy * fy).sqrt();
    let limit = mu * n;
    let factor = if lin <= 0.0 || limit <= 0.0 {
        if limit <= 0.0 { 0.0 } else { 1.0 }
    } else {
        match model {
            CreepModel::Linear => 1.0,
            CreepModel::ShenHedrickElkins => {
                let beta = lin / limit;
                let sat = if beta < 3.0 { beta - beta * beta / 3.0 + beta * beta * beta / 27.0 } else { 1.0 };
                sat / beta
            }
            CreepModel::Fastsim { .. } => 1.0, // handled above
            CreepModel::Polach { k_a, k_s } => {
                let eps = std::f64::consts::PI * lin / (4.0 * limit);
                let ka = k_a * eps;
                let f = 2.0 * limit / std::f64::consts::PI * (ka / (1.0 + ka * ka) + (k_s * eps).atan());
                f / lin
            }
        }
    };
    CreepForces { longitudinal: factor * fx, lateral: factor * fy, spin_moment: factor * mz }
}

/// One strip of a contact patch across the rolling direction, for FASTSIM on a
/// non-elliptic patch ([`fastsim_strips`]): the pressure along the strip is
/// semi-elliptic, `p(x) = peak_pressure · √(1 − (x/half_length)²)` on `|x| ≤ half_length`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatchStrip {
    /// Lateral position of the strip's centre line, m, relative to the point where the
    /// creepages are defined (the spin creepage's lever arm).
    pub y: f64,
    /// Width of the strip, m.
    pub width: f64,
    /// Half-length of the strip along the rolling direction, m (the strip spans
    /// `−half_length ≤ x ≤ half_length`).
    pub half_length: f64,
    /// Pressure at `x = 0` of the strip, Pa.
    pub peak_pressure: f64,
}

/// Kalker's three flexibilities of the simplified theory `(L1, L2, L3)` (m/Pa) for an
/// ellipse with semi-axes `a` (rolling), `b`, shear modulus `g` and Poisson's ratio `nu`:
/// `L1 = 8a/(3 C11 G)`, `L2 = 8a/(3 C22 G)`, `L3 = π a √(a/b) / (4 C23 G)`.
pub fn fastsim_flexibilities(a: f64, b: f64, g: f64, nu: f64) -> [f64; 3] {
    let k = kalker_coefficients(a / b, nu);
    let l1 = 8.0 * a / (3.0 * k.c11 * g);
    let l2 = 8.0 * a / (3.0 * k.c22 * g);
    let l3 = std::f64::consts::PI * a * (a / b).sqrt() / (4.0 * k.c23 * g);
    [l1, l2, l3]
}

/// FASTSIM on an elliptical patch (see [`CreepModel::Fastsim`]); forces on the wheel.
/// The ellipse is the strip patch of `ny` strips of width `2b/ny` with half-lengths
/// `a √(1 − (y/b)²)` and the Hertzian traction bound, run by the one FASTSIM
/// ([`fastsim_on_strips`]).
#[allow(clippy::too_many_arguments)]
fn fastsim(c: &Creepages, a: f64, b: f64, n: f64, mu: f64, g: f64, nu: f64, nx: usize, ny: usize) -> CreepForces {
    let flex = fastsim_flexibilities(a, b, g, nu);
    let p0 = 3.0 * n / (2.0 * std::f64::consts::PI * a * b);
    let dy = 2.0 * b / ny as f64;
    let strips = (0..ny).map(|j| {
        let y = -b + (j as f64 + 0.5) * dy;
        (y, dy, a * (1.0 - (y / b).powi(2)).max(0.0).sqrt())
    });
    fastsim_on_strips(c, flex, nx, strips, |x, y, _| {
        mu * p0 * (1.0 - (x / a).powi(2) - (y / b).powi(2)).max(0.0).sqrt()
    })
}

/// FASTSIM (Kalker's simplified theory, three flexibilities `flex = [L1, L2, L3]`) on a
/// patch given as strips across the rolling direction ([`PatchStrip`]), each of `nx`
/// cells marched from its leading edge `x = +half_length`, with the traction bound
/// `μ p(x, y)` of its semi-elliptic pressure. Forces on the wheel; the spin moment is
/// about the point where the creepages are defined (`y = 0`, `x = 0`).
pub fn fastsim_strips(c: &Creepages, strips: &[PatchStrip], flex: [f64; 3], mu: f64, nx: usize) -> CreepForces {
    let nx = nx.max(2);
    fastsim_on_strips(c, flex, nx, strips.iter().map(|s| (s.y, s.width, s.half_length)), |x, _, j| {
        let s = &strips[j];
        mu * s.peak_pressure * (1.0 - (x / s.half_length).powi(2)).max(0.0).sqrt()
    })
}

/// The one FASTSIM: strips `(y, width, half_length)` and the traction bound
/// `bound(x, y, strip index)`.
fn fastsim_on_strips<S, B>(c: &Creepages, flex: [f64; 3], nx: usize, strips: S, bound: B) -> CreepForces
where
    S: Iterator<Item = (f64, f64, f64)>,
    B: Fn(f64, f64, usize) -> f64,
{
    let [l1, l2, l3] = flex;
    let (mut fx, mut fy, mut mz) = (0.0, 0.0, 0.0);
    for (j, (y, dy, ay)) in strips.enumerate() {
        if ay <= 0.0 {
            continue;
        }
        let dx = 2.0 * ay / nx as f64;
        let (mut px, mut py) = (0.0, 0.0);
        for i in 0..nx {
            // Cell centre, marching from the leading edge x = +ay.
            let x = ay - (i as f64 + 0.5) * dx;
            px -= (c.longitudinal / l1 - c.spin * y / l3) * dx;
            py -= (c.lateral / l2 + c.spin * x / l3) * dx;
            let bound = bound(x, y, j);
            let mag = (px * px + py * py).sqrt();
            if mag > bound && mag > 0.0 {
                px *= bound / mag;
                py *= bound / mag;
            }
            let da = dx * dy;
            fx += px * da;
            fy += py * da;
            mz += (x * py - y * px) * da;
        }
    }
    CreepForces { longitudinal: fx, lateral: fy, spin_moment: mz }
}
