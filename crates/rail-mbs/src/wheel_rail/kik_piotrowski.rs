//! Semi-Hertzian (non-elliptic) contact patch: the Kik–Piotrowski method (Kik & Piotrowski
//! 1996; Piotrowski & Kik 2008, *Vehicle System Dynamics* 46, 27–48), for the gauge corner
//! and flange where the lateral curvature changes across the patch and Hertz's ellipse
//! (constant curvatures) does not hold.
//!
//! # Method
//!
//! Input: the undeformed **separation** `h(y)` of the wheel and rail surfaces along the
//! contact normal as a function of the lateral coordinate `y` in the contact plane
//! (`y = 0` at the contact point, where `h` is smallest), the relative longitudinal
//! curvature `A(y)` (`h(x, y) = h(y) + A(y) x²`, `A = cos γ / (2 R_wheel)` for a straight
//! rail) and the rigid penetration `δ` of the contact point.
//!
//! * **Patch.** The bodies are brought together by the *virtual* penetration `ε δ` (`ε ≈
//!   0.55`, [`DEFAULT_EPSILON`]): the patch is the interpenetration region
//!   `g(x, y) = ε δ − h(y) − A(y) x² > 0` connected to the contact point, i.e. the
//!   interval `y_lo < y < y_hi` where `g(y) = ε δ − h(y) > 0`, each strip `y` of half-length
//!   `x_l(y) = √(g(y)/A(y))`. (`ε = 1/2` reproduces Hertz's circle for equal curvatures;
//!   0.55 is the authors' compromise for elongated patches.)
//! * **Pressure.** Semi-elliptic along the rolling direction and proportional to `x_l` across:
//!   `p(x, y) = p0 √(x_l(y)² − x²) / x_l(0)`, the Hertz form when the patch is an ellipse.
//! * **Normal force.** `p0` follows from requiring the elastic approach at the contact point
//!   (half-space, Boussinesq) to equal the full rigid penetration `δ`:
//!   `δ = 1/(π E*) ∬ p(x, y) / √(x² + y²) dx dy`, so that
//!
//!   ```text
//!   N = π E* δ · ∬ √(x_l² − x²) dx dy / ∬ √(x_l² − x²)/√(x² + y²) dx dy
//!   ```
//!
//!   (`E*` the combined modulus of [`super::hertz::combined_modulus`]; `E/(2(1 − ν²))` for
//!   equal materials, the form of the 2008 paper). `N(δ)` rises monotonically; the
//!   penetration for a given force is found by a bracketed 1-D solve
//!   ([`KpPatch::at_force`]).
//!
//! # Discretization
//!
//! `strips` equal strips over `[y_lo, y_hi]` (edges found by bisection of `g(y) = 0`
//! outward from the contact point), `x_l` taken at each strip's centre. The numerator is
//! `Σ (π/2) x_l² Δy`. In the denominator the `1/r` kernel is integrated over each strip's
//! width exactly (`asinh`), so the singular strip through the contact point needs no
//! special care, and along `x` by Gauss–Legendre (`x = x_l sin θ`, `θ = π s²/2`, which
//! smooths both the square-root edge and the logarithmic singularity at `x = 0`).
//! Strip peak pressures are `p_j = N x_l,j / Σ (π/2) x_l² Δy`.
//!
//! # Tangential forces
//!
//! FASTSIM on the strips ([`super::creep::fastsim_strips`], the crate's one FASTSIM),
//! with the traction bound `μ p(x, y)` of the KP pressure and Kalker's flexibilities of
//! the **equivalent ellipse**: the ellipse with the patch's area and the ratio
//! `a/b = x_l,max / ((y_hi − y_lo)/2)` of its longest strip to its half-width (Piotrowski &
//! Kik 2008, §5). The saturation laws (Shen–Hedrick–Elkins, Polach, linear) use the
//! equivalent ellipse's semi-axes.
//!
//! # Limits
//!
//! * The separation is taken in one cross-section through the contact point (the rail's,
//!   at the contact point's station), as in the published method: yaw enters only through
//!   the contact point's position.
//! * Only the interpenetration interval connected to the contact point forms its patch, and
//!   it ends at a saddle of `h` (a local maximum beyond which the separation falls again by
//!   more than 1 % of `εδ`): the far side belongs to the next contact point's own patch.
//!   Where two contact points' regions meet (CONTACT's one wide patch at the conformal
//!   S1002/UIC 60 tread) they are two adjacent patches, each with its own `p0`, so the force
//!   changes continuously with the penetration (a merged patch would jump).
//! * Elliptic limit: for a quadratic separation `h = B y²` the patch is the ellipse with
//!   semi-axes `√(εδ/A)`, `√(εδ/B)`, and the force is
//!   `N = (2π/3) E* δ a' b' / (min(a', b') K(e'))` ([`elliptic_limit_force`]) — a few
//!   per cent from Hertz (for `A = B` exactly `√(2ε) = 1.049` times Hertz's force).

use super::ContactError;
use super::creep::{
    CreepForces, CreepModel, Creepages, PatchStrip, creep_forces, fastsim_flexibilities, fastsim_strips,
};
use super::hertz::elliptic_ke;

/// Virtual-penetration factor of Piotrowski & Kik (2008).
pub const DEFAULT_EPSILON: f64 = 0.55;
/// Default number of strips across a Kik–Piotrowski patch.
pub const DEFAULT_STRIPS: usize = 60;
/// Allowed range of the virtual-penetration factor `ε`.
pub const EPSILON_RANGE: (f64, f64) = (0.05, 1.0);
/// Allowed range of the number of strips.
pub const STRIPS_RANGE: (usize, usize) = (4, 5000);

/// The project's one "invalid `field` = value: expected …" message, as a contact error.
fn invalid(field: &str, value: impl std::fmt::Display, allowed: &str) -> ContactError {
    ContactError::InvalidInput(ancf_core::error::invalid(field, value, allowed).to_string())
}

/// Normal-contact (patch) model of a wheel/rail contact point.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum PatchModel {
    /// Hertz's ellipse from the relative curvatures at the contact point (the default).
    #[default]
    Hertz,
    /// The Kik–Piotrowski non-elliptic patch (module docs).
    KikPiotrowski {
        /// Virtual-penetration factor `ε` (0.55 in the 2008 paper), in [`EPSILON_RANGE`].
        epsilon: f64,
        /// Number of strips across the patch, in [`STRIPS_RANGE`].
        strips: usize,
    },
}

impl PatchModel {
    /// Kik–Piotrowski with the published `ε = 0.55` and [`DEFAULT_STRIPS`] strips.
    pub fn kik_piotrowski() -> Self {
        Self::KikPiotrowski { epsilon: DEFAULT_EPSILON, strips: DEFAULT_STRIPS }
    }

    /// Checks the parameters (typed error naming the field and its allowed range).
    pub fn validate(&self) -> Result<(), ContactError> {
        if let Self::KikPiotrowski { epsilon, strips } = *self {
            let (lo, hi) = EPSILON_RANGE;
            if !(epsilon.is_finite() && (lo..=hi).contains(&epsilon)) {
                return Err(invalid("patch_model.epsilon", epsilon, &format!("a number in [{lo}, {hi}]")));
            }
            let (lo, hi) = STRIPS_RANGE;
            if !(lo..=hi).contains(&strips) {
                return Err(invalid("patch_model.strips", strips, &format!("an integer in [{lo}, {hi}]")));
            }
        }
        Ok(())
    }
}

/// Undeformed separation across a contact (module docs): `h(y)` (m) and the relative
/// longitudinal curvature `A(y)` (1/m) for `y` in `range()`.
pub trait SeparationFn {
    /// `(h(y), A(y))`.
    fn at(&self, y: f64) -> (f64, f64);
    /// The interval of `y` where the separation is known, m (contains 0).
    fn range(&self) -> (f64, f64);
}

/// A separation sampled at increasing `y`, linearly interpolated.
#[derive(Debug, Clone, PartialEq)]
pub struct SampledSeparation {
    /// Lateral coordinates, m (strictly increasing, spanning 0).
    pub y: Vec<f64>,
    /// Separation `h(y)`, m.
    pub h: Vec<f64>,
    /// Relative longitudinal curvature `A(y)`, 1/m (> 0).
    pub curvature_x: Vec<f64>,
}

impl SampledSeparation {
    /// Checks and wraps samples.
    pub fn new(y: Vec<f64>, h: Vec<f64>, curvature_x: Vec<f64>) -> Result<Self, ContactError> {
        if y.len() < 3 || h.len() != y.len() || curvature_x.len() != y.len() {
            return Err(invalid(
                "separation.y",
                format!("{} samples ({} h, {} A)", y.len(), h.len(), curvature_x.len()),
                "at least 3 samples of y, h and A of equal length",
            ));
        }
        for i in 0..y.len() {
            if !y[i].is_finite() || (i > 0 && y[i] <= y[i - 1]) {
                return Err(invalid(&format!("separation.y[{i}]"), y[i], "finite, strictly increasing (m)"));
            }
            if !h[i].is_finite() {
                return Err(invalid(&format!("separation.h[{i}]"), h[i], "a finite separation (m)"));
            }
            if !(curvature_x[i].is_finite() && curvature_x[i] > 0.0) {
                return Err(invalid(
                    &format!("separation.curvature_x[{i}]"),
                    curvature_x[i],
                    "a finite number > 0 (1/m)",
                ));
            }
        }
        if !(y[0] <= 0.0 && y[y.len() - 1] >= 0.0) {
            return Err(invalid("separation.y", format!("[{}, {}]", y[0], y[y.len() - 1]), "an interval containing 0"));
        }
        Ok(Self { y, h, curvature_x })
    }
}

impl SeparationFn for SampledSeparation {
    fn at(&self, y: f64) -> (f64, f64) {
        let n = self.y.len();
        let k = self.y.partition_point(|&v| v < y).clamp(1, n - 1);
        let t = (y - self.y[k - 1]) / (self.y[k] - self.y[k - 1]);
        (
            self.h[k - 1] + t * (self.h[k] - self.h[k - 1]),
            self.curvature_x[k - 1] + t * (self.curvature_x[k] - self.curvature_x[k - 1]),
        )
    }
    fn range(&self) -> (f64, f64) {
        (self.y[0], self.y[self.y.len() - 1])
    }
}

/// The separation of Hertz's geometry, `h = B y²` with constant `A` (the elliptic limit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadraticSeparation {
    /// Relative longitudinal curvature `A`, 1/m.
    pub curvature_x: f64,
    /// Relative lateral curvature `B`, 1/m.
    pub curvature_y: f64,
    /// Half-width of the known interval, m.
    pub half_width: f64,
}

impl SeparationFn for QuadraticSeparation {
    fn at(&self, y: f64) -> (f64, f64) {
        (self.curvature_y * y * y, self.curvature_x)
    }
    fn range(&self) -> (f64, f64) {
        (-self.half_width, self.half_width)
    }
}

/// A Kik–Piotrowski patch at one penetration (module docs). Lengths in m, forces in N,
/// pressures in Pa; `y` along the contact's lateral axis, 0 at the contact point.
#[derive(Debug, Clone, PartialEq)]
pub struct KpPatch {
    /// Rigid penetration `δ` of the contact point, m.
    pub penetration: f64,
    /// Virtual-penetration factor `ε`.
    pub epsilon: f64,
    /// Normal force, N.
    pub normal_force: f64,
    /// Strips with their half-lengths and peak pressures.
    pub strips: Vec<PatchStrip>,
    /// Lateral edges of the patch `(y_lo, y_hi)`, m.
    pub lateral_extent: (f64, f64),
    /// Whether an edge is the end of the known separation (the patch may be wider).
    pub truncated: bool,
    /// Longest strip half-length, m.
    pub max_half_length: f64,
    /// Patch area, m².
    pub area: f64,
    /// Lateral position of the pressure centroid (the contact reference point), m.
    pub centroid: f64,
    /// Pressure at the contact point `p0 = p(0, 0)`, Pa.
    pub max_pressure: f64,
}

/// Copyable summary of a [`KpPatch`] (what a [`super::ContactPoint`] carries).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatchSummary {
    /// Lateral edges `(y_lo, y_hi)` relative to the contact point along `e2`, m.
    pub lateral_extent: (f64, f64),
    /// Longest strip half-length, m.
    pub max_half_length: f64,
    /// Area, m².
    pub area: f64,
    /// Pressure centroid along `e2` relative to the contact point, m.
    pub centroid: f64,
    /// Pressure at the contact point, Pa.
    pub max_pressure: f64,
    /// Whether the patch reaches the end of the sampled separation.
    pub truncated: bool,
}

/// Gauss–Legendre nodes and weights on `[0, 1]`.
fn gauss_legendre_01(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        // Newton on P_n from the Chebyshev-like first guess.
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        out.push((0.5 * (1.0 + x), 0.5 * w));
    }
    out
}

/// Nodes of the kernel integral along a strip.
const KERNEL_NODES: usize = 48;

fn kernel_nodes() -> &'static [(f64, f64)] {
    static NODES: std::sync::OnceLock<Vec<(f64, f64)>> = std::sync::OnceLock::new();
    NODES.get_or_init(|| gauss_legendre_01(KERNEL_NODES))
}

/// The edge of a patch between `inside` (`g > 0`) and `outside` (`g ≤ 0`): 60 bisections of the
/// virtual interpenetration `g`.
fn edge_between(g: &impl Fn(f64) -> f64, mut inside: f64, mut outside: f64) -> f64 {
    for _ in 0..60 {
        let mid = 0.5 * (inside + outside);
        if g(mid) > 0.0 {
            inside = mid;
        } else {
            outside = mid;
        }
    }
    0.5 * (inside + outside)
}

/// The strips of a Kik–Piotrowski patch over its lobes and their sums
/// ([`KpPatch::at_penetration`]: one lobe; [`KpPatch::combined`]: several).
struct StripSums {
    strips: Vec<PatchStrip>,
    /// `Σ (π/2) x_l² Δy`.
    num: f64,
    /// For each centre `y_k`, `Σ` of the strips' half-space kernels about `y_k`.
    den: Vec<f64>,
    area: f64,
    /// `Σ (π/2) x_l² Δy y`.
    moment: f64,
    x_max: f64,
}

impl StripSums {
    /// `strips` strips shared among the `lobes` (intervals of `y`) in proportion to their widths
    /// (at least one each), each with half-length `x_l = √((g_v − h(y))₊ / A(y))` at its centre,
    /// and the kernels about each of `centres`.
    fn over(sep: &impl SeparationFn, gv: f64, lobes: &[(f64, f64)], strips: usize, centres: &[f64]) -> Self {
        let total: f64 = lobes.iter().map(|l| l.1 - l.0).sum();
        let mut out = Vec::with_capacity(strips + lobes.len());
        let (mut num, mut area, mut moment, mut x_max) = (0.0, 0.0, 0.0, 0.0f64);
        let mut den = vec![0.0; centres.len()];
        for &(a, b) in lobes {
            let k = ((strips as f64 * (b - a) / total).round() as usize).max(1);
            let width = (b - a) / k as f64;
            for j in 0..k {
                let y = a + (j as f64 + 0.5) * width;
                let (h, ax) = sep.at(y);
                let xl = ((gv - h).max(0.0) / ax).sqrt();
                let q = std::f64::consts::FRAC_PI_2 * xl * xl * width;
                num += q;
                moment += q * y;
                area += 2.0 * xl * width;
                x_max = x_max.max(xl);
                if xl > 0.0 {
                    for (d, &yk) in den.iter_mut().zip(centres) {
                        *d += strip_kernel(xl, y - 0.5 * width - yk, y + 0.5 * width - yk);
                    }
                }
                out.push(PatchStrip { y, width, half_length: xl, peak_pressure: 0.0 });
            }
        }
        Self { strips: out, num, den, area, moment, x_max }
    }
}

/// `∫_{−c}^{c} √(c² − x²) ∫_{d1}^{d2} 1/√(x² + y²) dy dx` (the strip `d1 < y < d2` of
/// constant half-length `c`).
fn strip_kernel(c: f64, d1: f64, d2: f64) -> f64 {
    let half_pi = std::f64::consts::FRAC_PI_2;
    let mut sum = 0.0;
    for &(s, w) in kernel_nodes() {
        let th = half_pi * s * s;
        let (sn, cs) = th.sin_cos();
        let x = c * sn;
        // ∫ dy/√(x²+y²) = asinh(y/x); at x → 0 the s² map makes the log term vanish.
        let inner = if x > 0.0 { (d2 / x).asinh() - (d1 / x).asinh() } else { 0.0 };
        sum += w * cs * cs * inner * std::f64::consts::PI * s;
    }
    2.0 * c * c * sum
}

/// Elliptic limit of the method (module docs): the KP normal force at penetration `delta`
/// for `h = A x² + B y²` (`curvature_x = A`, `curvature_y = B`), computed in closed form.
pub fn elliptic_limit_force(curvature_x: f64, curvature_y: f64, e_star: f64, delta: f64, epsilon: f64) -> f64 {
    if delta <= 0.0 {
        return 0.0;
    }
    let a = (epsilon * delta / curvature_x).sqrt();
    let b = (epsilon * delta / curvature_y).sqrt();
    let (short, long) = if a <= b { (a, b) } else { (b, a) };
    let (k, _) = elliptic_ke(1.0 - (short / long).powi(2));
    2.0 * std::f64::consts::PI / 3.0 * e_star * delta * a * b / (short * k)
}

impl KpPatch {
    /// The patch at penetration `delta` (m, > 0) for the separation `sep`, factor `epsilon`,
    /// `strips` strips and combined modulus `e_star` (Pa).
    pub fn at_penetration(
        sep: &impl SeparationFn,
        delta: f64,
        epsilon: f64,
        strips: usize,
        e_star: f64,
    ) -> Result<Self, ContactError> {
        PatchModel::KikPiotrowski { epsilon, strips }.validate()?;
        if !(delta.is_finite() && delta > 0.0) {
            return Err(invalid("penetration", delta, "a finite penetration > 0 m"));
        }
        if !(e_star.is_finite() && e_star > 0.0) {
            return Err(invalid("e_star", e_star, "a finite modulus > 0 Pa"));
        }
        let gv = epsilon * delta;
        let g = |y: f64| gv - sep.at(y).0;
        if g(0.0) <= 0.0 {
            return Err(ContactError::InvalidInput(format!(
                "Kik-Piotrowski: no interpenetration at the contact point (h(0) = {:e} m >= eps*delta = {gv:e} m)",
                sep.at(0.0).0
            )));
        }
        let (lo_end, hi_end) = sep.range();
        let mut truncated = false;
        // Tolerance of the saddle test: a drop of h below its running maximum by more than
        // this ends the patch at the maximum (the next contact's side of the saddle).
        let tol = (0.01 * gv).max(1e-9);
        let mut edge = |end: f64| -> f64 {
            // March from 0 to `end` in 400 steps: the edge is the first zero of g (refined by
            // bisection) or the saddle, whichever comes first.
            let n = 400;
            let (mut prev, mut h_max, mut y_max) = (0.0, sep.at(0.0).0, 0.0);
            for i in 1..=n {
                let y = end * i as f64 / n as f64;
                let h = sep.at(y).0;
                if gv - h <= 0.0 {
                    return edge_between(&g, prev, y);
                }
                if h > h_max {
                    (h_max, y_max) = (h, y);
                } else if h < h_max - tol {
                    return y_max;
                }
                prev = y;
            }
            truncated = true;
            end
        };
        let (y_lo, y_hi) = (edge(lo_end), edge(hi_end));
        let StripSums { strips: mut out, num, den, area, moment, x_max } =
            StripSums::over(sep, gv, &[(y_lo, y_hi)], strips, &[0.0]);
        let den = den[0];
        let n = std::f64::consts::PI * e_star * delta * num / den;
        for s in &mut out {
            s.peak_pressure = n * s.half_length / num;
        }
        let (_, a0) = sep.at(0.0);
        let xl0 = (g(0.0) / a0).sqrt();
        Ok(Self {
            penetration: delta,
            epsilon,
            normal_force: n,
            strips: out,
            lateral_extent: (y_lo, y_hi),
            truncated,
            max_half_length: x_max,
            area,
            centroid: moment / num,
            max_pressure: n * xl0 / num,
        })
    }

    /// One patch over the union of several interpenetration regions (CONTACT's combined patch,
    /// [`super::contact::PatchCombination`]): the virtual interpenetration `g(y) = ε δ − h(y)`
    /// of the separation `sep` (`y = 0` at the deepest point, `h(0) = 0`, penetration `delta`)
    /// over `span` (the union of the rigid regions, m), without the single patch's stop at a
    /// saddle of `h`: every interval of `span` where `g > 0` is a lobe, and the `strips` strips
    /// are shared among the lobes in proportion to their widths (at least one each). One
    /// pressure law over all lobes, `p = (N/Σ(π/2) x_l² Δy) √(x_l² − x²)`, and `N` from the
    /// elastic approach held in the mean over the regions: for `approach = [(y_k, δ_k, W_k)]`
    /// (each region's point, its rigid penetration in this frame, its weight)
    /// `Σ W_k (u(y_k) − δ_k) = 0`, `u(y_k)` the half-space displacement at `y_k`. With one
    /// region (or the other weights zero) this is the single patch's condition at `y = 0`, and
    /// where no saddle limits the single patch (the other lobes empty) the patch is
    /// [`Self::at_penetration`]'s.
    pub fn combined(
        sep: &impl SeparationFn,
        delta: f64,
        epsilon: f64,
        strips: usize,
        e_star: f64,
        span: (f64, f64),
        approach: &[(f64, f64, f64)],
    ) -> Result<Self, ContactError> {
        PatchModel::KikPiotrowski { epsilon, strips }.validate()?;
        if !(delta.is_finite() && delta > 0.0) {
            return Err(invalid("penetration", delta, "a finite penetration > 0 m"));
        }
        let gv = epsilon * delta;
        let g = |y: f64| gv - sep.at(y).0;
        let (lo_end, hi_end) = sep.range();
        let (lo, hi) = (span.0.max(lo_end), span.1.min(hi_end));
        if !(lo <= 0.0 && hi >= 0.0 && g(0.0) > 0.0) {
            return Err(ContactError::InvalidInput(format!(
                "Kik-Piotrowski combined patch: span [{lo:e}, {hi:e}] m must hold the deepest point y = 0 with g > 0"
            )));
        }
        let truncated = lo > span.0 || hi < span.1;
        // the lobes: intervals where g > 0, found on a grid of 400 steps per side of 0 (the
        // single patch's march) and refined by bisection
        let crossing = |inside: f64, outside: f64| edge_between(&g, inside, outside);
        let n = 400;
        let mut grid: Vec<f64> = (0..=n).rev().map(|i| lo * i as f64 / n as f64).collect();
        grid.extend((1..=n).map(|i| hi * i as f64 / n as f64));
        let mut lobes: Vec<(f64, f64)> = Vec::new();
        let mut start: Option<f64> = (g(grid[0]) > 0.0).then_some(grid[0]);
        for w in grid.windows(2) {
            let (a, b) = (w[0], w[1]);
            match (start, g(b) > 0.0) {
                (None, true) => start = Some(if g(a) > 0.0 { a } else { crossing(b, a) }),
                (Some(s), false) => {
                    lobes.push((s, crossing(a, b)));
                    start = None;
                }
                _ => {}
            }
        }
        if let Some(s) = start {
            lobes.push((s, hi));
        }
        lobes.retain(|l| l.1 > l.0);
        let centres: Vec<f64> = approach.iter().map(|a| a.0).collect();
        let StripSums { strips: mut out, num, den, area, moment, x_max } =
            StripSums::over(sep, gv, &lobes, strips, &centres);
        let (mut rigid, mut elastic) = (0.0, 0.0);
        for (&(_, dk, wk), d) in approach.iter().zip(&den) {
            rigid += wk * dk;
            elastic += wk * d;
        }
        if !(elastic > 0.0 && rigid > 0.0) {
            return Err(ContactError::InvalidInput(
                "Kik-Piotrowski combined patch: the approach weights must be positive".into(),
            ));
        }
        let force = std::f64::consts::PI * e_star * num * rigid / elastic;
        for s in &mut out {
            s.peak_pressure = force * s.half_length / num;
        }
        let (_, a0) = sep.at(0.0);
        let xl0 = (g(0.0) / a0).sqrt();
        Ok(Self {
            penetration: delta,
            epsilon,
            normal_force: force,
            strips: out,
            lateral_extent: (lobes[0].0, lobes[lobes.len() - 1].1),
            truncated,
            max_half_length: x_max,
            area,
            centroid: moment / num,
            max_pressure: force * xl0 / num,
        })
    }

    /// The patch carrying the normal force `force` (N, > 0): the penetration by a bracketed
    /// solve of `N(δ) = force` (doubling from 1 µm, then Illinois regula falsi to 1e-12
    /// relative in `δ`).
    pub fn at_force(
        sep: &impl SeparationFn,
        force: f64,
        epsilon: f64,
        strips: usize,
        e_star: f64,
    ) -> Result<Self, ContactError> {
        if !(force.is_finite() && force > 0.0) {
            return Err(invalid("normal_force", force, "a finite force > 0 N"));
        }
        let f = |d: f64| Self::at_penetration(sep, d, epsilon, strips, e_star).map(|p| p.normal_force - force);
        let (mut lo, mut hi) = (0.0, 1e-6);
        let (mut flo, mut fhi) = (-force, f(hi)?);
        let mut k = 0;
        while fhi < 0.0 {
            lo = hi;
            flo = fhi;
            hi *= 2.0;
            fhi = f(hi)?;
            k += 1;
            if k > 40 {
                return Err(ContactError::InvalidInput(format!(
                    "Kik-Piotrowski: no penetration up to {hi} m carries {force} N"
                )));
            }
        }
        let root = ancf_core::roots::illinois(f, (lo, flo), (hi, fhi), |lo, hi| hi - lo <= 1e-12 * hi, 200)?;
        let d = if root.exact { root.x } else { 0.5 * (root.lo + root.hi) };
        Self::at_penetration(sep, d, epsilon, strips, e_star)
    }

    /// Pressure at `(x, y)`, Pa (zero outside the patch; `y` resolved to its strip).
    pub fn pressure(&self, x: f64, y: f64) -> f64 {
        let (lo, hi) = self.lateral_extent;
        if !(y >= lo && y <= hi) || self.strips.is_empty() {
            return 0.0;
        }
        let w = (hi - lo) / self.strips.len() as f64;
        let j = (((y - lo) / w) as usize).min(self.strips.len() - 1);
        let mut s = &self.strips[j];
        if (y - s.y).abs() > 0.5 * s.width {
            // a combined patch's strips differ in width between its lobes (Self::combined)
            match self.strips.iter().find(|s| (y - s.y).abs() <= 0.5 * s.width) {
                Some(found) => s = found,
                None => return 0.0,
            }
        }
        if s.half_length <= 0.0 || x.abs() >= s.half_length {
            return 0.0;
        }
        s.peak_pressure * (1.0 - (x / s.half_length).powi(2)).sqrt()
    }

    /// Semi-axes `(a, b)` of the equivalent ellipse (module docs): area and length-to-width
    /// ratio of the patch.
    pub fn equivalent_ellipse(&self) -> (f64, f64) {
        let half_width = 0.5 * (self.lateral_extent.1 - self.lateral_extent.0);
        if self.area <= 0.0 || half_width <= 0.0 || self.max_half_length <= 0.0 {
            return (0.0, 0.0);
        }
        let ratio = self.max_half_length / half_width;
        let a = (self.area / std::f64::consts::PI * ratio).sqrt();
        (a, a / ratio)
    }

    /// The same patch carrying `force` instead of its own normal force (pressures scaled;
    /// e.g. with contact damping).
    pub fn scaled_to(&self, force: f64) -> Self {
        let mut out = self.clone();
        let k = if self.normal_force > 0.0 { force / self.normal_force } else { 0.0 };
        for s in &mut out.strips {
            s.peak_pressure *= k;
        }
        out.normal_force = force;
        out.max_pressure *= k;
        out
    }

    /// Creep forces on the wheel for `creepages` (module docs: FASTSIM on the strips with
    /// `nx` cells per strip for [`CreepModel::Fastsim`], the other laws on the equivalent
    /// ellipse); friction `mu`, shear modulus `g` (Pa), Poisson's ratio `nu`. The spin
    /// moment is about the contact point (`y = 0`).
    pub fn creep(&self, model: CreepModel, creepages: &Creepages, mu: f64, g: f64, nu: f64) -> CreepForces {
        let (a, b) = self.equivalent_ellipse();
        if self.normal_force <= 0.0 || a <= 0.0 {
            return CreepForces::default();
        }
        match model {
            CreepModel::Fastsim { nx, .. } => {
                fastsim_strips(creepages, &self.strips, fastsim_flexibilities(a, b, g, nu), mu, nx)
            }
            other => creep_forces(other, creepages, a, b, self.normal_force, mu, g, nu),
        }
    }

    /// The copyable summary.
    pub fn summary(&self) -> PatchSummary {
        PatchSummary {
            lateral_extent: self.lateral_extent,
            max_half_length: self.max_half_length,
            area: self.area,
            centroid: self.centroid,
            max_pressure: self.max_pressure,
            truncated: self.truncated,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials() {
        let q = gauss_legendre_01(12);
        let s: f64 = q.iter().map(|(x, w)| w * x.powi(7)).sum();
        assert!((s - 0.125).abs() < 1e-14, "{s}");
    }

    #[test]
    fn bad_parameters_name_the_field() {
        let e = PatchModel::KikPiotrowski { epsilon: 1.5, strips: 40 }.validate().unwrap_err().to_string();
        assert!(e.contains("`patch_model.epsilon`") && e.contains("[0.05, 1]"), "{e}");
        let e = PatchModel::KikPiotrowski { epsilon: 0.55, strips: 1 }.validate().unwrap_err().to_string();
        assert!(e.contains("`patch_model.strips`") && e.contains("[4, 5000]"), "{e}");
    }
}
