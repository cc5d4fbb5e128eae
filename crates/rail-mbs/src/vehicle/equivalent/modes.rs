//! The sloshing modes of the equivalent model's tanks: the horizontal cylinder's λ table (first
//! transverse mode) and its lateral mode, the circular segment, the rectangular tank's modes
//! and the Stokes-layer damping ratio (formulas in the parent module's docs and
//! `../shared/notes`). The vehicle model that uses them is the parent module.

use ancf_core::error::{AncfError, check_positive, invalid};

/// `λ = ω₁²R/g` of the first antisymmetric transverse sloshing mode of a horizontal circular
/// cylinder at liquid depth fractions `h/2R = i/100`, `i = 0..=99`.
///
/// Generated with the Python Steklov finite-element solve
/// `railslosh.cosim.emulators.cylinder_lambda(i/100, resolution=48)` (P1 elements, Richardson
/// extrapolation over 48 and 96 elements across the diameter), printed to 6 decimals; entry 0
/// is the exact low-fill limit λ → 1 (notes §1b). Half fill: 1.355725 (Budiansky 1960:
/// 1.3557). A Python test compares [`cylinder_lambda`] at off-grid fills with the Python solve.
pub const LAMBDA_TABLE: [f64; 100] = [
    1.0, 1.004093, 1.008125, 1.012224, 1.016520, 1.020926, 1.025360, 1.029826, 1.034421, 1.039068, //
    1.043848, 1.048694, 1.053635, 1.058687, 1.063843, 1.069086, 1.074435, 1.079901, 1.085463, 1.091167, //
    1.096987, 1.102907, 1.108978, 1.115176, 1.121515, 1.127986, 1.134613, 1.141383, 1.148315, 1.155410, //
    1.162669, 1.170105, 1.177719, 1.185527, 1.193517, 1.201733, 1.210134, 1.218756, 1.227627, 1.236711, //
    1.246051, 1.255643, 1.265522, 1.275671, 1.286106, 1.296853, 1.307920, 1.319326, 1.331080, 1.343208, //
    1.355725, 1.368650, 1.382005, 1.395813, 1.410097, 1.424887, 1.440211, 1.456098, 1.472592, 1.489703, //
    1.507502, 1.526012, 1.545284, 1.565413, 1.586378, 1.608283, 1.631198, 1.655214, 1.680380, 1.706812, //
    1.734617, 1.763912, 1.794812, 1.827500, 1.862106, 1.898861, 1.937972, 1.979670, 2.024315, 2.072166, //
    2.123674, 2.179392, 2.239736, 2.305458, 2.377405, 2.456711, 2.544495, 2.642397, 2.752580, 2.877758, //
    3.021478, 3.188956, 3.387804, 3.627271, 3.926028, 4.311120, 4.834699, 5.604224, 6.895258, 9.823418, //
];

/// Smallest and largest liquid depth fraction `h/2R` the equivalent model accepts: the cubic
/// interpolation of [`LAMBDA_TABLE`] stays within 0.1 % of the Steklov solve up to 0.95 and
/// λ grows without bound towards a full tank.
pub const DEPTH_FRACTION_RANGE: (f64, f64) = (0.01, 0.95);

/// Frequency of the stiff (non-sloshing) directions of a slosh body, Hz.
pub const STIFF_FREQUENCY: f64 = 20.0;
/// Damping ratio of the stiff directions.
pub const STIFF_DAMPING_RATIO: f64 = 0.1;
/// Radius of gyration of a slosh body about each of its axes, m.
pub const SLOSH_BODY_GYRATION: f64 = 0.2;

/// `λ(h/2R)` of a horizontal circular cylinder, by 4-point Lagrange (cubic) interpolation of
/// [`LAMBDA_TABLE`]; `depth_fraction` in [`DEPTH_FRACTION_RANGE`].
pub fn cylinder_lambda(depth_fraction: f64) -> Result<f64, AncfError> {
    let (lo, hi) = DEPTH_FRACTION_RANGE;
    if !(depth_fraction.is_finite() && (lo..=hi).contains(&depth_fraction)) {
        return Err(invalid("depth fraction h/(2R)", depth_fraction, &format!("{lo} to {hi}")));
    }
    let x = depth_fraction * 100.0;
    let i0 = ((x.floor() as usize).saturating_sub(1)).min(LAMBDA_TABLE.len() - 4);
    let mut s = 0.0;
    for j in 0..4 {
        let xj = (i0 + j) as f64;
        let mut l = 1.0;
        for k in (0..4).filter(|&k| k != j) {
            let xk = (i0 + k) as f64;
            l *= (x - xk) / (xj - xk);
        }
        s += LAMBDA_TABLE[i0 + j] * l;
    }
    Ok(s)
}

/// First transverse sloshing mode of liquid of mass `mass` in a horizontal circular cylinder of
/// radius `radius` with eigenvalue `lambda` ([`cylinder_lambda`]) and centroid `centroid_depth`
/// below the axis: `(ω, m₁)` with `ω² = λ g/R` (pendulum length `l₁ = g/ω² = R/λ`) and, from
/// static-tilt matching (`m₁ l₁ = M BM`, `BM = d` for a circle: the metacentre is on the axis),
/// `m₁ = min(M d λ/R, M)`. Used by the vehicle's equivalent model and the FMU's pendulum.
pub fn cylinder_lateral_mode(radius: f64, lambda: f64, mass: f64, centroid_depth: f64, g: f64) -> (f64, f64) {
    ((lambda * g / radius).sqrt(), (mass * centroid_depth * lambda / radius).min(mass))
}

/// A circular segment: the liquid cross-section of a horizontal cylinder.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Half-angle α of the wetted arc, rad (`cos α = (R − h)/R`).
    pub alpha: f64,
    /// Area `A`, m².
    pub area: f64,
    /// Free-surface half-width `w`, m.
    pub half_width: f64,
    /// Centroid depth below the axis `d`, m.
    pub centroid_depth: f64,
    /// Metacentric radius `BM = (2w)³/(12A)`, m (equals `d` for a circle).
    pub metacentric_radius: f64,
}

/// The segment of liquid depth `depth` in a cylinder of radius `radius` (notes §1b).
pub fn segment(radius: f64, depth: f64) -> Result<Segment, AncfError> {
    check_positive("radius", radius)?;
    if !(depth > 0.0 && depth < 2.0 * radius) {
        return Err(invalid("depth", depth, &format!("0 < depth < 2R = {}", 2.0 * radius)));
    }
    let alpha = ((radius - depth) / radius).acos();
    let s2 = 2.0 * alpha - (2.0 * alpha).sin();
    let area = 0.5 * radius * radius * s2;
    let w = radius * alpha.sin();
    Ok(Segment {
        alpha,
        area,
        half_width: w,
        centroid_depth: 4.0 * radius * alpha.sin().powi(3) / (3.0 * s2),
        metacentric_radius: (2.0 * w).powi(3) / (12.0 * area),
    })
}

/// First sloshing mode of a rectangular tank of length `length` (along the motion) and
/// liquid depth `depth` holding `mass` (notes §3, Abramson SP-106 / Dodge 2000 ch. 3):
/// `(ω, m₁)` with `ω² = (πg/L) tanh(πh/L)`, `m₁ = M · 8 tanh(πh/L)/(π³ h/L)`.
pub fn rectangular_mode(length: f64, depth: f64, mass: f64, g: f64) -> Result<(f64, f64), AncfError> {
    rectangular_modes(length, depth, mass, g, 1).map(|m| m[0])
}

/// The first `n` antisymmetric modes `(ω_n, m_n)` of a rectangular tank (`n′ = 2n − 1`):
/// `ω_n² = (n′πg/L) tanh(n′πh/L)`, `m_n = M · 8 tanh(n′πh/L)/(n′³π³ h/L)`.
pub fn rectangular_modes(length: f64, depth: f64, mass: f64, g: f64, n: usize) -> Result<Vec<(f64, f64)>, AncfError> {
    check_positive("length", length)?;
    check_positive("depth", depth)?;
    check_positive("mass", mass)?;
    check_positive("gravity", g)?;
    use std::f64::consts::PI;
    Ok((1..=n)
        .map(|k| {
            let np = (2 * k - 1) as f64;
            let r = np * PI * depth / length;
            let omega = (np * PI * g / length * r.tanh()).sqrt();
            let m = mass * 8.0 * r.tanh() / (np.powi(3) * PI.powi(3) * depth / length);
            (omega, m)
        })
        .collect())
}

/// Viscous damping ratio of a slosh mode (module docs): Stokes-layer formula, capped at 1.
pub fn stokes_damping_ratio(nu: f64, omega: f64, depth: f64, breadth: f64) -> f64 {
    let z = (0.5 / depth) * (nu / (2.0 * omega)).sqrt() * (1.0 + 2.0 * depth / breadth);
    z.min(1.0)
}
