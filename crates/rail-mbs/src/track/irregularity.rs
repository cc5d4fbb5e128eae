//! Track irregularities (issue 20 §1): the deviation of the two rails from their design
//! position, as four channels of distance along the track.
//!
//! # Channels and signs (docs/frames.md, "Track irregularities")
//!
//! All in metres, functions of the distance `s` along the centreline, in the track frame
//! (x forward, y left, z up; [`super::Track`]):
//!
//! * **vertical profile** `v`: the mean height of the two rails, positive up;
//! * **alignment** `a`: the mean lateral position of the two rails, positive to the left;
//! * **cross-level** `c`: the height of the right rail minus that of the left rail (the sign
//!   of the design super-elevation: positive raises the right rail);
//! * **gauge** `g`: the widening of the gauge, positive wider.
//!
//! The rails' offsets from their design position ([`Irregularity::rail_offset`]):
//! left rail `(Δy, Δz) = (a + g/2, v − c/2)`, right rail `(a − g/2, v + c/2)`. Each rail is
//! translated, not rotated: the cross-level's roll of the rail profile (c / 1.5 m, a few
//! milliradians) is left out, as in the usual rigid-rail irregularity input.
//!
//! # Sampling and evaluation
//!
//! Channels are sampled on a uniform grid `s₀ + k Δs` and evaluated by cubic Hermite
//! interpolation with centred-difference slopes (C¹, exact for quadratics), so the wheel/rail
//! contact's rail-frame derivatives (central differences over 2 cm) stay smooth. Outside the
//! grid the end values are held.
//!
//! # Sources
//!
//! * **Generated** from a one-sided power spectral density S(Ω) (m² per rad/m, Ω = 2π/λ the
//!   spatial angular frequency) by a sum of cosines with seeded random phases:
//!   x(s) = Σₖ √(2 S(Ωₖ) ΔΩ) cos(Ωₖ (s − s₀) + φₖ), Ωₖ spaced ΔΩ = 2π/L over the requested
//!   wavelength band ([`IrregularityPsd`]), so that the variance within the band is ∫ S dΩ.
//!   The spectra ([`TrackSpectrum`]): the US FRA track classes 1–6 and the ERRI B176 low- and
//!   high-level spectra; their formulas and parameters are in [`TrackSpectrum::psd`].
//! * **Measured** samples ([`Irregularity::from_samples`]).
//! * **Isolated defects** ([`Defect`]) added on top: a cosine dip, a cusp (dipped joint) and a
//!   cross-level twist over a base.

use ancf_core::error::{AncfError, invalid};
use ancf_core::rng::Rng;

use super::Side;

/// The four irregularity channels, in the order of [`Irregularity::channels`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Channel {
    /// Mean height of the two rails, m, positive up.
    Vertical = 0,
    /// Mean lateral position of the two rails, m, positive left.
    Alignment = 1,
    /// Height of the right rail minus the left rail, m.
    CrossLevel = 2,
    /// Gauge widening, m, positive wider.
    Gauge = 3,
}

impl Channel {
    /// The four channels in storage order.
    pub const ALL: [Channel; 4] = [Channel::Vertical, Channel::Alignment, Channel::CrossLevel, Channel::Gauge];

    /// The channel's name (scene keys, file columns, results).
    pub fn name(self) -> &'static str {
        match self {
            Channel::Vertical => "vertical",
            Channel::Alignment => "alignment",
            Channel::CrossLevel => "cross_level",
            Channel::Gauge => "gauge",
        }
    }
}

/// A one-sided track-irregularity spectrum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TrackSpectrum {
    /// The US FRA track classes 1 (worst) to 6 (best).
    Fra {
        /// Track class, 1–6.
        class: u8,
    },
    /// ERRI B176 (UIC) low-level spectrum: good European track.
    ErriLow,
    /// ERRI B176 (UIC) high-level spectrum: poor European track.
    ErriHigh,
}

/// FRA class parameters (A_v, A_a in cm²·rad/m; Ω_s, Ω_c in rad/m), classes 1–6.
/// [textbook: Hamid & Yang (1981) as tabulated by Zhai, *Vehicle–Track Coupled Dynamics*
/// (2020), ch. 3; not checked against the FRA report here.]
const FRA: [(f64, f64, f64, f64); 6] = [
    (1.2107, 3.3634, 0.6046, 0.8245),
    (1.0181, 1.2107, 0.9308, 0.8245),
    (0.6816, 0.4128, 0.8520, 0.8245),
    (0.5376, 0.3027, 1.1312, 0.8245),
    (0.2095, 0.0762, 0.8209, 0.8245),
    (0.0339, 0.0339, 0.4380, 0.8245),
];
/// The FRA spectra's factor k.
const FRA_K: f64 = 0.25;
/// ERRI B176 parameters: Ω_c, Ω_r, Ω_s (rad/m); A_v, A_a (m·rad) low and high level; b half
/// the distance between the rails' contact points (m). [textbook: ERRI B176/DT 290 (1993),
/// as used in the European vehicle-dynamics literature; not checked against the report here.]
const ERRI_OMEGA: (f64, f64, f64) = (0.8246, 0.0206, 0.4380);
const ERRI_A_LOW: (f64, f64) = (4.032e-7, 2.119e-7);
const ERRI_A_HIGH: (f64, f64) = (1.080e-6, 6.125e-7);
const ERRI_B: f64 = 0.75;

impl TrackSpectrum {
    /// Checks the class.
    pub fn validate(&self) -> Result<(), AncfError> {
        match self {
            TrackSpectrum::Fra { class } if !(1..=6).contains(class) => {
                Err(invalid("class", class, "an FRA track class 1–6"))
            }
            _ => Ok(()),
        }
    }

    /// One-sided PSD of `channel` at spatial angular frequency `omega` (rad/m), in m² per
    /// rad/m (cross-level as the height difference of the rails).
    ///
    /// * FRA (k = 0.25; A in cm²·rad/m, converted): S_v = k A_v Ω_c² / (Ω² (Ω² + Ω_c²)),
    ///   S_a = k A_a Ω_c² / (Ω² (Ω² + Ω_c²)), S_c = S_g = 4 k A_v Ω_c² / ((Ω² + Ω_c²)(Ω² + Ω_s²)).
    /// * ERRI B176: S_v = A_v Ω_c² / ((Ω² + Ω_r²)(Ω² + Ω_c²)), S_a the same with A_a, and the
    ///   cross-level angle's S = (A_v / b²) Ω_c² Ω² / ((Ω² + Ω_r²)(Ω² + Ω_c²)(Ω² + Ω_s²)),
    ///   here times (2b)² for the height difference. B176 gives no gauge spectrum: zero.
    pub fn psd(&self, channel: Channel, omega: f64) -> f64 {
        let w2 = omega * omega;
        match *self {
            TrackSpectrum::Fra { class } => {
                let (av, aa, ws, wc) = FRA[(class.clamp(1, 6) - 1) as usize];
                let cm2 = 1e-4; // cm² → m²
                let (av, aa) = (av * cm2, aa * cm2);
                let wc2 = wc * wc;
                match channel {
                    Channel::Vertical => FRA_K * av * wc2 / (w2 * (w2 + wc2)),
                    Channel::Alignment => FRA_K * aa * wc2 / (w2 * (w2 + wc2)),
                    Channel::CrossLevel | Channel::Gauge => 4.0 * FRA_K * av * wc2 / ((w2 + wc2) * (w2 + ws * ws)),
                }
            }
            TrackSpectrum::ErriLow | TrackSpectrum::ErriHigh => {
                let (av, aa) = if *self == TrackSpectrum::ErriLow { ERRI_A_LOW } else { ERRI_A_HIGH };
                let (wc, wr, ws) = ERRI_OMEGA;
                let base = (w2 + wr * wr) * (w2 + wc * wc);
                match channel {
                    Channel::Vertical => av * wc * wc / base,
                    Channel::Alignment => aa * wc * wc / base,
                    Channel::CrossLevel => {
                        // the angle's spectrum (A_v / b²) …, as the height difference over 2b
                        let angle = (av / (ERRI_B * ERRI_B)) * wc * wc * w2 / (base * (w2 + ws * ws));
                        angle * (2.0 * ERRI_B) * (2.0 * ERRI_B)
                    }
                    Channel::Gauge => 0.0,
                }
            }
        }
    }
}

/// What [`Irregularity::generate`] draws.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IrregularityPsd {
    /// The spectrum.
    pub spectrum: TrackSpectrum,
    /// Distance where the irregular track starts, m.
    pub start: f64,
    /// Length of irregular track, m (> 0).
    pub length: f64,
    /// Sample spacing, m (> 0, at most half the shortest wavelength).
    pub step: f64,
    /// Shortest and longest wavelength, m (0 < min < max).
    pub wavelengths: (f64, f64),
    /// Seed of the random phases (the same seed gives the same track).
    pub seed: u64,
    /// Length of the raised-cosine ramp from zero at `start`, m (≥ 0).
    pub taper: f64,
    /// Which channels to draw (the others stay zero), in [`Channel::ALL`] order.
    pub channels: [bool; 4],
}

impl IrregularityPsd {
    /// The defaults for `spectrum` over `length` m: from s = 0, samples every 0.25 m,
    /// wavelengths 1–70 m (the usual range of vehicle-dynamics input), seed 1, a 20 m taper,
    /// all four channels.
    pub fn new(spectrum: TrackSpectrum, length: f64) -> Self {
        Self {
            spectrum,
            start: 0.0,
            length,
            step: 0.25,
            wavelengths: (1.0, 70.0),
            seed: 1,
            taper: 20.0,
            channels: [true; 4],
        }
    }

    /// Checks the ranges.
    pub fn validate(&self) -> Result<(), AncfError> {
        self.spectrum.validate()?;
        let (lo, hi) = self.wavelengths;
        if !self.start.is_finite() {
            return Err(invalid("start", self.start, "a finite distance (m)"));
        }
        if !(self.length.is_finite() && self.length > 0.0) {
            return Err(invalid("length", self.length, "a length > 0 m"));
        }
        if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo) {
            return Err(invalid("wavelengths", format!("[{lo}, {hi}]"), "0 < shortest < longest wavelength (m)"));
        }
        if hi > self.length {
            return Err(invalid(
                "wavelengths",
                format!("[{lo}, {hi}]"),
                &format!("a longest wavelength ≤ the length {} m", self.length),
            ));
        }
        if !(self.step.is_finite() && self.step > 0.0 && self.step <= 0.5 * lo) {
            return Err(invalid(
                "step",
                self.step,
                &format!("0 < step ≤ half the shortest wavelength, {} m", 0.5 * lo),
            ));
        }
        if !(self.taper.is_finite() && self.taper >= 0.0 && self.taper <= self.length) {
            return Err(invalid("taper", self.taper, &format!("0 ≤ taper ≤ the length {} m", self.length)));
        }
        Ok(())
    }
}

/// An isolated defect, added to the channels on top of the rest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Defect {
    /// Vertical cosine dip of both rails: v = −d (1 − cos(2π (s − start)/length))/2 on
    /// [start, start + length].
    CosineDip {
        /// Where it starts, m.
        start: f64,
        /// Its length, m.
        length: f64,
        /// Its depth, m (positive down).
        depth: f64,
    },
    /// Vertical cusp (a dipped joint) of both rails centred at `at`:
    /// v = −d (1 − |s − at|/(length/2))² on |s − at| ≤ length/2 (zero value and slope at its
    /// ends, a kink at the joint).
    Cusp {
        /// The joint, m.
        at: f64,
        /// Its length, m.
        length: f64,
        /// Its depth, m.
        depth: f64,
    },
    /// Cross-level twist: c rises linearly from 0 to `cross_level` over `base` from `start`,
    /// is held for `hold`, and falls back to 0 over the next `base`.
    Twist {
        /// Where it starts, m.
        start: f64,
        /// The twist base, m.
        base: f64,
        /// The cross-level reached, m (right rail minus left).
        cross_level: f64,
        /// Length held at full cross-level, m.
        hold: f64,
    },
}

impl Defect {
    /// The channel it adds to.
    fn channel(&self) -> Channel {
        match self {
            Defect::CosineDip { .. } | Defect::Cusp { .. } => Channel::Vertical,
            Defect::Twist { .. } => Channel::CrossLevel,
        }
    }

    /// The distance range it covers, m.
    pub fn range(&self) -> (f64, f64) {
        match *self {
            Defect::CosineDip { start, length, .. } => (start, start + length),
            Defect::Cusp { at, length, .. } => (at - 0.5 * length, at + 0.5 * length),
            Defect::Twist { start, base, hold, .. } => (start, start + 2.0 * base + hold),
        }
    }

    /// Its shortest feature, m (the grid must resolve it).
    fn feature(&self) -> f64 {
        match *self {
            Defect::CosineDip { length, .. } | Defect::Cusp { length, .. } => length,
            Defect::Twist { base, .. } => base,
        }
    }

    /// The defect's value at `s`, m.
    pub fn value(&self, s: f64) -> f64 {
        let (a, b) = self.range();
        if s <= a || s >= b {
            return 0.0;
        }
        match *self {
            Defect::CosineDip { start, length, depth } => {
                -0.5 * depth * (1.0 - (2.0 * std::f64::consts::PI * (s - start) / length).cos())
            }
            Defect::Cusp { at, length, depth } => {
                let x = 1.0 - (s - at).abs() / (0.5 * length);
                -depth * x * x
            }
            Defect::Twist { start, base, cross_level, hold } => {
                let x = s - start;
                if x < base {
                    cross_level * x / base
                } else if x <= base + hold {
                    cross_level
                } else {
                    cross_level * (2.0 * base + hold - x) / base
                }
            }
        }
    }

    fn validate(&self) -> Result<(), AncfError> {
        let ok = |v: f64| v.is_finite();
        match *self {
            Defect::CosineDip { start, length, depth } | Defect::Cusp { at: start, length, depth } => {
                if !(ok(start) && ok(depth)) {
                    return Err(invalid("defect", format!("{self:?}"), "finite position and depth (m)"));
                }
                if !(ok(length) && length > 0.0) {
                    return Err(invalid("length", length, "a defect length > 0 m"));
                }
            }
            Defect::Twist { start, base, cross_level, hold } => {
                if !(ok(start) && ok(cross_level)) {
                    return Err(invalid("defect", format!("{self:?}"), "finite position and cross-level (m)"));
                }
                if !(ok(base) && base > 0.0) {
                    return Err(invalid("base", base, "a twist base > 0 m"));
                }
                if !(ok(hold) && hold >= 0.0) {
                    return Err(invalid("hold", hold, "a held length ≥ 0 m"));
                }
            }
        }
        Ok(())
    }
}

/// Track irregularity: the four channels on a uniform grid (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Irregularity {
    start: f64,
    step: f64,
    channels: [Vec<f64>; 4],
}

impl Irregularity {
    /// From samples on the uniform grid `start + k step`, one vector per channel in
    /// [`Channel::ALL`] order, all of the same length ≥ 2, finite.
    pub fn from_samples(start: f64, step: f64, channels: [Vec<f64>; 4]) -> Result<Self, AncfError> {
        if !start.is_finite() {
            return Err(invalid("start", start, "a finite distance (m)"));
        }
        if !(step.is_finite() && step > 0.0) {
            return Err(invalid("step", step, "a sample spacing > 0 m"));
        }
        let n = channels[0].len();
        if n < 2 {
            return Err(invalid("samples", n, "at least 2 samples per channel"));
        }
        for (c, x) in Channel::ALL.iter().zip(&channels) {
            if x.len() != n {
                return Err(invalid(
                    c.name(),
                    format!("{} samples", x.len()),
                    &format!("{n} samples, as many as the others"),
                ));
            }
            if let Some(i) = x.iter().position(|v| !v.is_finite()) {
                return Err(invalid(c.name(), format!("{} at sample {i}", x[i]), "finite values (m)"));
            }
        }
        Ok(Self { start, step, channels })
    }

    /// Draws the channels from a spectrum (module docs); the same parameters give the same
    /// track, bit for bit.
    pub fn generate(p: &IrregularityPsd) -> Result<Self, AncfError> {
        p.validate()?;
        let n = (p.length / p.step).round() as usize + 1;
        let d_omega = 2.0 * std::f64::consts::PI / p.length;
        let (lo, hi) = p.wavelengths;
        let k_lo = ((2.0 * std::f64::consts::PI / hi) / d_omega).ceil().max(1.0) as usize;
        let k_hi = ((2.0 * std::f64::consts::PI / lo) / d_omega).floor() as usize;
        let mut rng = Rng::new(p.seed);
        let mut channels: [Vec<f64>; 4] = Default::default();
        for (ci, c) in Channel::ALL.iter().enumerate() {
            // the phases of every channel are drawn, used or not, so that switching a
            // channel off does not change the others
            let phases: Vec<f64> = (k_lo..=k_hi).map(|_| std::f64::consts::PI * rng.uniform()).collect();
            let mut x = vec![0.0; n];
            if p.channels[ci] {
                for (k, phi) in (k_lo..=k_hi).zip(&phases) {
                    let omega = k as f64 * d_omega;
                    let amp = (2.0 * p.spectrum.psd(*c, omega) * d_omega).sqrt();
                    if amp == 0.0 {
                        continue;
                    }
                    for (i, xi) in x.iter_mut().enumerate() {
                        *xi += amp * (omega * i as f64 * p.step + phi).cos();
                    }
                }
                if p.taper > 0.0 {
                    for (i, xi) in x.iter_mut().enumerate() {
                        let u = i as f64 * p.step / p.taper;
                        if u < 1.0 {
                            *xi *= 0.5 * (1.0 - (std::f64::consts::PI * u).cos());
                        }
                    }
                }
            }
            channels[ci] = x;
        }
        Ok(Self { start: p.start, step: p.step, channels })
    }

    /// A perfect track sampled over [start, end] every `step` (for adding defects to).
    pub fn zero(start: f64, end: f64, step: f64) -> Result<Self, AncfError> {
        if !(end.is_finite() && start.is_finite() && end > start) {
            return Err(invalid("end", end, &format!("a distance > the start {start} m")));
        }
        if !(step.is_finite() && step > 0.0) {
            return Err(invalid("step", step, "a sample spacing > 0 m"));
        }
        let n = ((end - start) / step).ceil() as usize + 1;
        Self::from_samples(start, step, [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]])
    }

    /// Adds `defect` to its channel at the grid points (the grid must hold at least 8
    /// samples over its shortest feature, and cover it).
    pub fn add_defect(&mut self, defect: &Defect) -> Result<(), AncfError> {
        defect.validate()?;
        if defect.feature() < 8.0 * self.step {
            return Err(invalid(
                "length",
                defect.feature(),
                &format!("a defect feature ≥ 8 sample spacings, {} m (or a finer `step`)", 8.0 * self.step),
            ));
        }
        let (a, b) = defect.range();
        if a < self.start || b > self.end() {
            return Err(invalid(
                "defect",
                format!("[{a}, {b}] m"),
                &format!("within the irregularity's range [{}, {}] m", self.start, self.end()),
            ));
        }
        let c = defect.channel() as usize;
        let start = self.start;
        let step = self.step;
        for (i, x) in self.channels[c].iter_mut().enumerate() {
            *x += defect.value(start + i as f64 * step);
        }
        Ok(())
    }

    /// First sample's distance, m.
    pub fn start(&self) -> f64 {
        self.start
    }

    /// Sample spacing, m.
    pub fn step(&self) -> f64 {
        self.step
    }

    /// Last sample's distance, m.
    pub fn end(&self) -> f64 {
        self.start + (self.channels[0].len() - 1) as f64 * self.step
    }

    /// The samples, one vector per channel in [`Channel::ALL`] order.
    pub fn channels(&self) -> &[Vec<f64>; 4] {
        &self.channels
    }

    /// `channel` at `s` (cubic Hermite, module docs), m.
    pub fn value(&self, channel: Channel, s: f64) -> f64 {
        let x = &self.channels[channel as usize];
        let n = x.len();
        let u = (s - self.start) / self.step;
        if u <= 0.0 {
            return x[0];
        }
        if u >= (n - 1) as f64 {
            return x[n - 1];
        }
        let i = (u.floor() as usize).min(n - 2);
        let t = u - i as f64;
        let slope = |k: usize| -> f64 {
            if k == 0 {
                x[1] - x[0]
            } else if k == n - 1 {
                x[n - 1] - x[n - 2]
            } else {
                0.5 * (x[k + 1] - x[k - 1])
            }
        };
        let (t2, t3) = (t * t, t * t * t);
        (2.0 * t3 - 3.0 * t2 + 1.0) * x[i]
            + (t3 - 2.0 * t2 + t) * slope(i)
            + (-2.0 * t3 + 3.0 * t2) * x[i + 1]
            + (t3 - t2) * slope(i + 1)
    }

    /// The offset of one rail from its design position at `s`: (lateral Δy, vertical Δz) in
    /// the track frame, m (module docs).
    pub fn rail_offset(&self, s: f64, side: Side) -> (f64, f64) {
        let v = self.value(Channel::Vertical, s);
        let a = self.value(Channel::Alignment, s);
        let c = self.value(Channel::CrossLevel, s);
        let g = self.value(Channel::Gauge, s);
        match side {
            Side::Left => (a + 0.5 * g, v - 0.5 * c),
            Side::Right => (a - 0.5 * g, v + 0.5 * c),
        }
    }

    /// Root-mean-square of each channel's samples, m.
    pub fn rms(&self) -> [f64; 4] {
        let mut out = [0.0; 4];
        for (o, x) in out.iter_mut().zip(&self.channels) {
            *o = (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt();
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hermite_evaluation_is_exact_for_quadratics_and_holds_the_ends() {
        let s: Vec<f64> = (0..21).map(|k| 10.0 + 0.5 * k as f64).collect();
        let q = |x: f64| 0.003 * (x - 12.0) * (x - 12.0) - 0.01 * x + 0.2;
        let ch = [s.iter().map(|&x| q(x)).collect(), vec![0.0; 21], vec![0.0; 21], vec![0.0; 21]];
        let irr = Irregularity::from_samples(10.0, 0.5, ch).unwrap();
        // interior intervals (centred slopes are exact for a quadratic)
        for k in 0..200 {
            let x = 10.5 + 9.0 * k as f64 / 200.0;
            assert!((irr.value(Channel::Vertical, x) - q(x)).abs() < 1e-14, "{x}");
        }
        assert_eq!(irr.value(Channel::Vertical, 0.0), q(10.0));
        assert_eq!(irr.value(Channel::Vertical, 100.0), q(20.0));
    }

    #[test]
    fn rail_offsets_follow_the_sign_conventions() {
        let ch = [vec![0.004; 3], vec![0.002; 3], vec![0.006; 3], vec![0.010; 3]];
        let irr = Irregularity::from_samples(0.0, 1.0, ch).unwrap();
        let (yl, zl) = irr.rail_offset(1.0, Side::Left);
        let (yr, zr) = irr.rail_offset(1.0, Side::Right);
        // mean of the rails = vertical profile and alignment
        assert!((0.5 * (zl + zr) - 0.004).abs() < 1e-15 && (0.5 * (yl + yr) - 0.002).abs() < 1e-15);
        // right minus left height = cross-level; left minus right lateral = gauge widening
        assert!((zr - zl - 0.006).abs() < 1e-15 && (yl - yr - 0.010).abs() < 1e-15);
    }

    #[test]
    fn the_same_seed_gives_the_same_track_and_another_seed_another() {
        let p = IrregularityPsd::new(TrackSpectrum::Fra { class: 4 }, 500.0);
        let a = Irregularity::generate(&p).unwrap();
        let b = Irregularity::generate(&p).unwrap();
        assert_eq!(a, b);
        let c = Irregularity::generate(&IrregularityPsd { seed: 2, ..p }).unwrap();
        assert_ne!(a.channels()[0], c.channels()[0]);
        // the taper: zero at the start, full amplitude after it
        assert_eq!(a.channels()[0][0], 0.0);
        assert!(a.rms()[0] > 1e-4, "{:?}", a.rms());
    }

    #[test]
    fn the_variance_in_the_band_is_the_integral_of_the_spectrum() {
        // without taper the drawn variance is Σ S ΔΩ over the band exactly (the cosines are
        // orthogonal over the periodic grid), which approximates ∫ S dΩ
        for spectrum in [TrackSpectrum::Fra { class: 5 }, TrackSpectrum::ErriHigh] {
            let p = IrregularityPsd { taper: 0.0, ..IrregularityPsd::new(spectrum, 1000.0) };
            let irr = Irregularity::generate(&p).unwrap();
            let (w0, w1) = (2.0 * std::f64::consts::PI / 70.0, 2.0 * std::f64::consts::PI);
            for c in [Channel::Vertical, Channel::Alignment, Channel::CrossLevel] {
                let m = 20_000;
                let dw = (w1 - w0) / m as f64;
                let integral: f64 = (0..m).map(|k| spectrum.psd(c, w0 + (k as f64 + 0.5) * dw) * dw).sum();
                let x = &irr.channels()[c as usize];
                let var = x[..x.len() - 1].iter().map(|v| v * v).sum::<f64>() / (x.len() - 1) as f64;
                assert!((var / integral - 1.0).abs() < 0.03, "{spectrum:?} {c:?}: {var} vs {integral}");
            }
        }
    }

    #[test]
    fn defects_have_their_stated_shape_and_bad_input_is_named() {
        let mut irr = Irregularity::zero(0.0, 100.0, 0.05).unwrap();
        irr.add_defect(&Defect::CosineDip { start: 10.0, length: 2.0, depth: 0.005 }).unwrap();
        irr.add_defect(&Defect::Cusp { at: 40.0, length: 4.0, depth: 0.003 }).unwrap();
        irr.add_defect(&Defect::Twist { start: 60.0, base: 3.0, cross_level: 0.009, hold: 1.0 }).unwrap();
        assert!((irr.value(Channel::Vertical, 11.0) + 0.005).abs() < 1e-12);
        assert_eq!(irr.value(Channel::Vertical, 9.0), 0.0);
        assert!((irr.value(Channel::Vertical, 40.0) + 0.003).abs() < 1e-12);
        assert!((irr.value(Channel::CrossLevel, 63.5) - 0.009).abs() < 1e-12);
        assert!((irr.value(Channel::CrossLevel, 61.5) - 0.0045).abs() < 1e-12);
        let e = irr.add_defect(&Defect::CosineDip { start: 10.0, length: 0.2, depth: 0.005 }).unwrap_err();
        assert!(e.to_string().contains("`length`"), "{e}");
        let e = irr.add_defect(&Defect::CosineDip { start: 99.0, length: 2.0, depth: 0.005 }).unwrap_err();
        assert!(e.to_string().contains("within the irregularity's range"), "{e}");
        let e = Irregularity::generate(&IrregularityPsd::new(TrackSpectrum::Fra { class: 7 }, 100.0)).unwrap_err();
        assert!(e.to_string().contains("`class` = 7"), "{e}");
        let bad = IrregularityPsd { step: 0.6, ..IrregularityPsd::new(TrackSpectrum::ErriLow, 100.0) };
        assert!(Irregularity::generate(&bad).unwrap_err().to_string().contains("`step`"));
    }
}
