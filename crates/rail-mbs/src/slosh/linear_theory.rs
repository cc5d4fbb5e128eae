//! Linear potential-flow (modal) solution of sloshing in a rectangular tank under a
//! horizontal acceleration history: the analytic reference of the validation case
//! `slosh-linear-potential-flow`.
//!
//! # Model and derivation
//!
//! Two-dimensional rectangular tank of length `L` along the excitation, liquid depth `h`,
//! incompressible inviscid liquid in irrotational motion, small amplitudes (linearized free
//! surface); the tank translates with a prescribed horizontal acceleration `a(t)`. This is
//! the textbook problem of Abramson (ed.), *The Dynamic Behavior of Liquids in Moving
//! Containers*, NASA SP-106 (1966), ch. 2 (natural frequencies of rectangular tanks) and
//! ch. 6 (equivalent mechanical models, after Graham & Rodriguez 1952), and of Ibrahim,
//! *Liquid Sloshing Dynamics: Theory and Applications*, Cambridge University Press (2005),
//! ch. 1–2 (linear sloshing, rectangular containers) and ch. 7 (equivalent mechanical
//! models). The derivation is repeated here so that each factor can be checked.
//!
//! Coordinates in the tank: `s ∈ [0, L]` along the motion, `z ∈ [−h, 0]` (free surface at
//! rest at z = 0); `x = s − L/2` is measured from the centre. With `U(t)` the tank velocity
//! (U̇ = a), the inertial velocity potential satisfying Laplace's equation, the wall
//! conditions ∂Φ/∂s = U at s = 0, L and ∂Φ/∂z = 0 on the bottom is
//!
//! ```text
//! Φ = U x + Σ_j A_j(t) cos(k_j s) cosh(k_j (z + h)) / cosh(k_j h),   k_j = j π / L.
//! ```
//!
//! With the surface elevation η = Σ_j η_j(t) cos(k_j s), the linear kinematic condition
//! η_t = Φ_z gives η̇_j = k_j tanh(k_j h) A_j, and the linear dynamic condition
//! Φ_t + g η = 0 (z = 0), with `x = Σ_{j odd} c_j cos(k_j s)`, c_j = −4L/(j²π²) (the cosine
//! series of s − L/2 on [0, L]; even terms vanish), gives Ȧ_j + g η_j + c_j a = 0. Hence
//!
//! ```text
//! η̈_j + ω_j² η_j = −(ω_j²/g) c_j a,   ω_j² = g k_j tanh(k_j h),
//! ```
//!
//! and only the modes antisymmetric about the centre (j = 2n − 1) are excited:
//! **k_n = (2n − 1) π / L, ω_n² = g k_n tanh(k_n h)**.
//!
//! The liquid's horizontal momentum (per unit width, ρ the density, m = ρ L h) is
//! P = ρ ∫∫ Φ_x = ρ ∫ [Φ(L) − Φ(0)] dz = m U − 2 ρ Σ_{j odd} A_j tanh(k_j h)/k_j
//! = m U − 2 ρ Σ η̇_j / k_j². The force of the walls on the liquid is Ṗ (gravity is
//! vertical), so the force of the liquid **on the tank** is
//!
//! ```text
//! F = −Ṗ = −m a + 2 ρ Σ_n η̈_n / k_n².
//! ```
//!
//! Writing η_n = −β_n x_n with β_n = (ω_n²/g)·4L/((2n−1)²π²) turns each surface mode into a
//! mass–spring oscillator attached to the tank, x_n its displacement relative to the tank:
//!
//! ```text
//! ẍ_n + ω_n² x_n = −a(t),
//! F = −m a − Σ_n m_n ẍ_n = −(m − Σ_n m_n) a + Σ_n m_n ω_n² x_n,
//! m_n / m = 2 ρ β_n / (k_n² m) = 8 tanh(k_n h) / ((2n − 1)³ π³ h / L).
//! ```
//!
//! This is Graham & Rodriguez's equivalent mechanical model as given by Abramson (1966,
//! ch. 6) and Ibrahim (2005, ch. 7): a fixed mass m₀ = m − Σ m_n moving with the tank and
//! sloshing masses m_n on springs k_n = m_n ω_n². Limits (checked in the tests): for a
//! shallow tank (k_n h → 0) m_n/m → 8/((2n−1)²π²) and Σ m_n → m (Σ 1/(2n−1)² = π²/8); for a
//! deep one (tanh → 1) Σ m_n/m → 7 ζ(3) L / (π³ h) ≈ 0.2714 L/h → 0 (Σ 1/(2n−1)³ = 7ζ(3)/8).
//! Seed 003's tank (L = 0.324 m, h = 0.132 m) has f₁ = 1.436 Hz, m₁/m = 0.542 and
//! Σ m_n/m = 0.575.
//!
//! Optionally each oscillator is damped, ẍ_n + 2ζω_n ẋ_n + ω_n² x_n = −a, with the dashpot
//! acting between the mass and the tank, so that F = −(m − Σ m_n) a + Σ m_n (ω_n² x_n +
//! 2ζω_n ẋ_n). The textbook (potential-flow) reference is undamped, ζ = 0.
//!
//! # Viscous dissipation (the reference of the viscous law in a sloshing flow)
//!
//! The relative potential of mode n, A_n cos(k_n s) cosh(k_n(z + h))/cosh(k_n h), carries
//! the kinetic energy ½ρ∫|∇Φ_n|² = ½ m_n ẋ_n² (per the substitutions above: with
//! A_n = η̇_n/(k_n tanh k_n h) and η_n = −β_n x_n the ratio of the two is L²k_n²/((2n−1)²π²) = 1),
//! so the oscillators' energies are the liquid's. A Newtonian liquid of kinematic viscosity ν
//! in this potential flow dissipates 2μ∫Σ_ij (∂²Φ/∂x_i∂x_j)² dV (Lamb, *Hydrodynamics*, §348;
//! with free-slip walls there is no boundary layer). Averaged over s, Σ_ij Φ_ij² of mode n is
//! k_n⁴ A_n² cosh(2k_n(z+h))/cosh²(k_n h) and |∇Φ_n|² is half of k_n² A_n² cosh(2k_n(z+h))/
//! cosh²(k_n h), so the mode dissipates **8νk_n² times its kinetic energy at every instant**,
//! whatever the depth (the modes are orthogonal, so the sum is the sum over modes); the energy
//! of a free standing wave decays at 4νk_n², its amplitude at 2νk_n².
//! [`RectangularTankModes::viscous_dissipation_rate`] gives the kinetic-energy-weighted mean of
//! 8νk_n² over a response: the ratio of viscous power to relative kinetic energy a resolved
//! viscous law must reproduce.
//!
//! # Integration
//!
//! The acceleration is piecewise linear in time (samples (t_i, a_i) with the convention of
//! [`super::PiecewiseAcceleration::new`]: zero up to the first sample, linear between
//! samples, constant after the last). On each interval where a is linear the mode equations
//! are integrated **exactly**: the particular solution of ẍ + 2ζωẋ + ω²x = −(a₀ + s τ) is
//! x_p = −(a₀ + s τ)/ω² + 2ζ s/ω³, and the homogeneous remainder is propagated by the
//! closed-form damped free oscillation. The only error is round-off.

use ancf_core::constants::GRAVITY as G;
use ancf_core::error::{Result, invalid};

/// Analytic first sloshing frequency of a rectangular tank of length `l` along the motion,
/// depth `h`: f = √(g k tanh(k h)) / 2π, k = π / l (seed 003 appendix C §4.1).
pub fn rect_tank_frequency(l: f64, h: f64) -> f64 {
    let k = std::f64::consts::PI / l;
    (G * k * (k * h).tanh()).sqrt() / (2.0 * std::f64::consts::PI)
}

/// Modal mass ratio m_n/m of antisymmetric mode `n` (1-based) of a rectangular tank of
/// length `length` along the motion and liquid depth `depth`:
/// 8 tanh(k_n h)/((2n − 1)³ π³ h/L), k_n = (2n − 1)π/L (see the module docs).
pub fn modal_mass_ratio(n: usize, length: f64, depth: f64) -> f64 {
    let j = (2 * n - 1) as f64;
    let k = j * std::f64::consts::PI / length;
    8.0 * (k * depth).tanh() / (j.powi(3) * std::f64::consts::PI.powi(3) * depth / length)
}

/// The first `n_modes` antisymmetric sloshing modes of a 2-D rectangular tank as an
/// equivalent mechanical model (module docs), and their response to a horizontal
/// acceleration history.
#[derive(Debug, Clone, PartialEq)]
pub struct RectangularTankModes {
    /// Tank length along the excitation L (m).
    pub length: f64,
    /// Liquid depth h (m).
    pub depth: f64,
    /// Liquid mass m (kg).
    pub mass: f64,
    /// Gravity g (m/s²).
    pub g: f64,
    /// Damping ratio ζ of every mode (0: the potential-flow solution).
    pub damping_ratio: f64,
    omega: Vec<f64>,
    modal_mass: Vec<f64>,
}

impl RectangularTankModes {
    /// Modes n = 1..=`n_modes` of a tank of length `length` (along the excitation), liquid
    /// depth `depth`, liquid mass `mass`, gravity `g`; undamped.
    pub fn new(length: f64, depth: f64, mass: f64, g: f64, n_modes: usize) -> Result<Self> {
        for (name, v) in [("length", length), ("depth", depth), ("mass", mass), ("g", g)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(name, v, "a finite positive number"));
            }
        }
        if n_modes == 0 {
            return Err(invalid("n_modes", 0, "at least 1"));
        }
        let omega = (1..=n_modes)
            .map(|n| {
                let k = (2 * n - 1) as f64 * std::f64::consts::PI / length;
                (g * k * (k * depth).tanh()).sqrt()
            })
            .collect();
        let modal_mass = (1..=n_modes).map(|n| mass * modal_mass_ratio(n, length, depth)).collect();
        Ok(Self { length, depth, mass, g, damping_ratio: 0.0, omega, modal_mass })
    }

    /// The same modes with damping ratio `zeta` (0 ≤ ζ < 1) on every mode.
    pub fn with_damping(mut self, zeta: f64) -> Result<Self> {
        if !(zeta.is_finite() && (0.0..1.0).contains(&zeta)) {
            return Err(invalid("damping_ratio", zeta, "0 <= zeta < 1"));
        }
        self.damping_ratio = zeta;
        Ok(self)
    }

    /// Circular frequencies ω_n (rad/s).
    pub fn omegas(&self) -> &[f64] {
        &self.omega
    }

    /// Natural frequencies f_n = ω_n/2π (Hz).
    pub fn frequencies(&self) -> Vec<f64> {
        self.omega.iter().map(|w| w / (2.0 * std::f64::consts::PI)).collect()
    }

    /// Sloshing (modal) masses m_n (kg).
    pub fn modal_masses(&self) -> &[f64] {
        &self.modal_mass
    }

    /// Fixed mass m₀ = m − Σ m_n that moves with the tank (kg).
    pub fn fixed_mass(&self) -> f64 {
        self.mass - self.modal_mass.iter().sum::<f64>()
    }

    /// Viscous dissipation of the potential flow relative to its kinetic energy (1/s), over the
    /// response to `accel` sampled at `times` (as [`Self::force_history`]): ∫Σ_n 8νk_n² T_n dt /
    /// ∫Σ_n T_n dt with T_n = ½ m_n ẋ_n² the kinetic energy of mode n relative to the tank and
    /// ν = `kinematic_viscosity` (module docs, "Viscous dissipation"); trapezoidal in time.
    pub fn viscous_dissipation_rate(
        &self,
        accel: &[(f64, f64)],
        times: &[f64],
        kinematic_viscosity: f64,
    ) -> Result<f64> {
        if !(kinematic_viscosity.is_finite() && kinematic_viscosity >= 0.0) {
            return Err(invalid("kinematic_viscosity", kinematic_viscosity, "a number >= 0"));
        }
        let states = self.response(accel, times)?;
        let (mut dissipation, mut kinetic) = (Vec::with_capacity(times.len()), Vec::with_capacity(times.len()));
        for st in &states {
            let (mut d, mut t) = (0.0, 0.0);
            for (n, ([_, v], &mn)) in st.iter().zip(&self.modal_mass).enumerate() {
                let k = (2 * n + 1) as f64 * std::f64::consts::PI / self.length;
                let energy = 0.5 * mn * v * v;
                d += 8.0 * kinematic_viscosity * k * k * energy;
                t += energy;
            }
            dissipation.push(d);
            kinetic.push(t);
        }
        let trapezoid = |y: &[f64]| {
            y.windows(2).zip(times.windows(2)).map(|(w, t)| 0.5 * (w[0] + w[1]) * (t[1] - t[0])).sum::<f64>()
        };
        let kinetic = trapezoid(&kinetic);
        if kinetic <= 0.0 {
            return Err(invalid("accel", "no sloshing over times", "an excitation that moves the liquid"));
        }
        Ok(trapezoid(&dissipation) / kinetic)
    }

    /// Horizontal force of the liquid on the tank (N, along the excitation; the sign
    /// convention of [`super::SloshRecord::force_tank`]: a tank accelerating in +y feels
    /// −m a quasi-statically) at each of `times` (non-decreasing), for the tank acceleration
    /// given by the samples `accel` = [(t_i, a_i)] (strictly increasing times; zero before
    /// the first sample, linear between samples, constant after the last), starting at rest.
    pub fn force_history(&self, accel: &[(f64, f64)], times: &[f64]) -> Result<Vec<f64>> {
        let states = self.response(accel, times)?;
        let m0 = self.fixed_mass();
        Ok(times
            .iter()
            .zip(&states)
            .map(|(&t, st)| {
                let a = acceleration_at(accel, t);
                let modal: f64 = st
                    .iter()
                    .zip(self.omega.iter().zip(&self.modal_mass))
                    .map(|([x, v], (&w, &mn))| mn * (w * w * x + 2.0 * self.damping_ratio * w * v))
                    .sum();
                -m0 * a + modal
            })
            .collect())
    }

    /// Modal displacements and velocities [x_n, ẋ_n] (relative to the tank) at each of
    /// `times`, integrated exactly for the piecewise-linear acceleration `accel`.
    pub fn response(&self, accel: &[(f64, f64)], times: &[f64]) -> Result<Vec<Vec<[f64; 2]>>> {
        check_samples(accel)?;
        if times.iter().any(|t| !t.is_finite()) {
            return Err(invalid("times", "non-finite", "finite times"));
        }
        for (i, w) in times.windows(2).enumerate() {
            if w[1] < w[0] {
                return Err(invalid(&format!("times[{}]", i + 1), w[1], "non-decreasing times"));
            }
        }
        let n = self.omega.len();
        let mut state = vec![[0.0; 2]; n];
        let mut t_cur = accel[0].0;
        let mut out = Vec::with_capacity(times.len());
        for &t in times {
            while t > t_cur {
                // next break point: the next knot after t_cur, or t
                let knot = accel.iter().map(|s| s.0).find(|&tk| tk > t_cur);
                let t_next = knot.map_or(t, |tk| tk.min(t));
                let (a0, slope) = segment(accel, t_cur);
                let h = t_next - t_cur;
                for (st, &w) in state.iter_mut().zip(&self.omega) {
                    *st = propagate(*st, w, self.damping_ratio, a0, slope, h);
                }
                t_cur = t_next;
            }
            out.push(state.clone());
        }
        Ok(out)
    }
}

fn check_samples(accel: &[(f64, f64)]) -> Result<()> {
    if accel.is_empty() {
        return Err(invalid("accel", "[]", "at least one (time, acceleration) sample"));
    }
    for (i, w) in accel.windows(2).enumerate() {
        if w[1].0.partial_cmp(&w[0].0) != Some(std::cmp::Ordering::Greater) {
            return Err(invalid(&format!("accel[{}].time", i + 1), w[1].0, "strictly increasing times"));
        }
    }
    if accel.iter().any(|(t, a)| !t.is_finite() || !a.is_finite()) {
        return Err(invalid("accel", "non-finite sample", "finite numbers"));
    }
    Ok(())
}

/// a(t) with the convention of [`super::PiecewiseAcceleration::eval`] (0 for t ≤ t₀).
fn acceleration_at(accel: &[(f64, f64)], t: f64) -> f64 {
    if t <= accel[0].0 {
        return 0.0;
    }
    let (a0, _) = segment(accel, t);
    a0
}

/// (a(t), da/dt) on the segment that starts at or before `t` (t ≥ first sample), valid
/// up to the next knot.
fn segment(accel: &[(f64, f64)], t: f64) -> (f64, f64) {
    match accel.iter().position(|s| s.0 > t) {
        None => (accel[accel.len() - 1].1, 0.0),
        Some(0) => (0.0, 0.0),
        Some(i) => {
            let ((ta, aa), (tb, ab)) = (accel[i - 1], accel[i]);
            let slope = (ab - aa) / (tb - ta);
            (aa + slope * (t - ta), slope)
        }
    }
}

/// Exact solution after time `h` of ẍ + 2ζωẋ + ω²x = −(a0 + slope τ) from [x, ẋ].
fn propagate([x0, v0]: [f64; 2], w: f64, zeta: f64, a0: f64, slope: f64, h: f64) -> [f64; 2] {
    // particular solution x_p(τ) = −(a0 + slope τ)/ω² + 2ζ slope/ω³, ẋ_p = −slope/ω²
    let xp = |tau: f64| -(a0 + slope * tau) / (w * w) + 2.0 * zeta * slope / (w * w * w);
    let vp = -slope / (w * w);
    let (y0, yd0) = (x0 - xp(0.0), v0 - vp);
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let e = (-zeta * w * h).exp();
    let (s, c) = (wd * h).sin_cos();
    let y = e * (y0 * (c + zeta * w / wd * s) + yd0 * s / wd);
    let yd = e * (yd0 * (c - zeta * w / wd * s) - y0 * w * w / wd * s);
    [y + xp(h), yd + vp]
}

#[cfg(test)]
mod tests {
    use super::*;

    use ancf_core::constants::GRAVITY as G;
    // seed 003's tank: 0.324 m along the excitation, 0.132 m water, 0.416 m long
    const L: f64 = 0.324;
    const H: f64 = 0.132;
    const M: f64 = 998.0 * 0.416 * 0.324 * 0.132;

    fn seed_tank() -> RectangularTankModes {
        RectangularTankModes::new(L, H, M, G, 50).unwrap()
    }

    fn peak(x: &[f64]) -> f64 {
        x.iter().fold(0.0, |m, v| m.max(v.abs()))
    }

    #[test]
    fn viscous_dissipation_of_a_standing_wave_is_8_nu_k_squared_times_its_kinetic_energy() {
        let nu = 1e-6;
        let k1 = std::f64::consts::PI / L;
        let pulse = [(0.1, 0.0), (0.12, 0.3), (0.48, 0.3), (0.5, 0.0)];
        let times: Vec<f64> = (0..=3500).map(|i| 0.5 + 1e-3 * i as f64).collect();
        // one mode: exactly 8 ν k₁²
        let one = RectangularTankModes::new(L, H, M, G, 1).unwrap();
        let r1 = one.viscous_dissipation_rate(&pulse, &times, nu).unwrap();
        assert!((r1 / (8.0 * nu * k1 * k1) - 1.0).abs() < 1e-12, "{r1}");
        // fifty: the higher modes (k_n = (2n−1) k₁) add a little
        let r = seed_tank().viscous_dissipation_rate(&pulse, &times, nu).unwrap();
        let excess = r / (8.0 * nu * k1 * k1) - 1.0;
        assert!(excess > 0.0 && excess < 0.2, "{excess}");
        // the time samples' spacing does not matter (a grid 20 times as dense over 0.5–0.6 s)
        let mut uneven: Vec<f64> = (0..2000).map(|i| 0.5 + 5e-5 * i as f64).collect();
        uneven.extend((0..=3400).map(|i| 0.6 + 1e-3 * i as f64));
        let ru = seed_tank().viscous_dissipation_rate(&pulse, &uneven, nu).unwrap();
        assert!((ru / r - 1.0).abs() < 1e-3, "{ru} vs {r}");
        // linear in ν; no motion, no ratio
        let r2 = seed_tank().viscous_dissipation_rate(&pulse, &times, 2.0 * nu).unwrap();
        assert!((r2 / r - 2.0).abs() < 1e-12);
        assert!(seed_tank().viscous_dissipation_rate(&[(0.0, 0.0), (1.0, 0.0)], &times, nu).is_err());
        assert!(seed_tank().viscous_dissipation_rate(&pulse, &times, -1.0).is_err());
    }

    #[test]
    fn first_mode_is_seed_003_frequency() {
        let f1 = seed_tank().frequencies()[0];
        assert!((f1 / 1.436 - 1.0).abs() < 1e-3, "f1 = {f1}");
        // and agrees with the closed form of the first mode
        let fr = super::rect_tank_frequency(L, H);
        assert!((f1 - fr).abs() < 1e-12);
        // higher modes: odd wavenumbers only, increasing
        let f = seed_tank().frequencies();
        let k2 = 3.0 * std::f64::consts::PI / L;
        assert!((f[1] - (G * k2 * (k2 * H).tanh()).sqrt() / (2.0 * std::f64::consts::PI)).abs() < 1e-12);
        assert!(f.windows(2).all(|w| w[1] > w[0]));
    }

    #[test]
    fn modal_masses_have_the_shallow_and_deep_limits() {
        let sum = |l: f64, h: f64| {
            let m = RectangularTankModes::new(l, h, 1.0, G, 50).unwrap();
            m.modal_masses().iter().sum::<f64>()
        };
        // shallow: m_n/m → 8/((2n−1)²π²), Σ → 1; the 50-mode truncation leaves
        // Σ_{n>50} 8/((2n−1)²π²) ≈ 8/(π² · 2 · 99) = 0.0041
        let tail: f64 =
            (51..200_000).map(|n| 8.0 / (((2 * n - 1) as f64).powi(2) * std::f64::consts::PI.powi(2))).sum();
        let s = sum(1.0, 1e-5);
        assert!((s + tail - 1.0).abs() < 1e-4, "shallow sum {s}, tail {tail}");
        assert!(s < 1.0);
        // deep: Σ m_n/m → 7 ζ(3) L/(π³ h)
        let zeta3 = 1.202_056_903_159_594;
        let (l, h) = (1.0, 20.0);
        let s = sum(l, h);
        let deep = 7.0 * zeta3 * l / (std::f64::consts::PI.powi(3) * h);
        assert!((s / deep - 1.0).abs() < 1e-3, "deep sum {s} vs {deep}");
        // seed 003's tank
        let m = seed_tank();
        let r1 = m.modal_masses()[0] / M;
        let rs = m.modal_masses().iter().sum::<f64>() / M;
        assert!((r1 - 0.5424).abs() < 1e-3, "m1/m = {r1}");
        assert!((rs - 0.5752).abs() < 1e-3, "sum m_n/m = {rs}");
        assert!((m.fixed_mass() / M - (1.0 - rs)).abs() < 1e-12);
    }

    #[test]
    fn slow_ramp_is_quasi_static() {
        // a ramps from 0 to a_max over 100 s: each mode lags by x_n = −a/ω² + s/ω³ sin(ω t)
        // (s the ramp rate), so |F + m a| ≤ Σ m_n ω_n² s/ω_n³ = Σ m_n s/ω_n.
        let m = seed_tank();
        let a_max = 0.3 * G;
        let t_ramp = 100.0;
        let accel = [(0.0, 0.0), (t_ramp, a_max)];
        let times: Vec<f64> = (0..=2000).map(|i| i as f64 * 0.05).collect();
        let f = m.force_history(&accel, &times).unwrap();
        let s = a_max / t_ramp;
        let bound: f64 = m.modal_masses().iter().zip(m.omegas()).map(|(mn, w)| mn * s / w).sum();
        for (&t, &fi) in times.iter().zip(&f) {
            let a = a_max * t / t_ramp;
            assert!((fi + M * a).abs() <= bound * (1.0 + 1e-9) + 1e-12, "t = {t}: F = {fi}, -m a = {}", -M * a);
        }
        assert!(bound < 1e-3 * M * a_max);
        // after the ramp, constant a: the load oscillates about −m a with the lag amplitude
        let f_end = m.force_history(&accel, &[t_ramp + 3.0]).unwrap()[0];
        assert!((f_end + M * a_max).abs() <= 2.0 * bound);
    }

    #[test]
    fn step_response_within_the_two_mass_bound() {
        // (nearly) a step: ramp over 1 ms, then constant. Undamped, each mode's spring force
        // m_n ω_n² x_n = −m_n a (1 − cos ω_n t) for a true step, so |F| ≤ (m + Σ m_n) a, and
        // just after the step only the fixed mass has been accelerated: F(0+) = −m₀ a.
        let m = seed_tank();
        let a = 0.03 * G;
        let accel = [(0.0, 0.0), (1e-3, a)];
        let times: Vec<f64> = (0..=40_000).map(|i| i as f64 * 1e-4).collect();
        let f = m.force_history(&accel, &times).unwrap();
        let sum_mn: f64 = m.modal_masses().iter().sum();
        let bound = (M + sum_mn) * a;
        let pk = peak(&f);
        assert!(pk <= bound * (1.0 + 1e-3), "peak {pk} vs bound {bound}");
        // the first mode's overshoot: at t = π/ω₁ the load reaches nearly (m + m₁) a
        let t_half = std::f64::consts::PI / m.omegas()[0];
        let f_half = m.force_history(&accel, &[t_half + 5e-4]).unwrap()[0];
        assert!(-f_half > (M + 0.9 * m.modal_masses()[0]) * a, "F(T/2) = {f_half}");
        // just after the ramp
        let f0 = m.force_history(&accel, &[1e-3]).unwrap()[0];
        assert!((f0 + m.fixed_mass() * a).abs() < 0.1 * sum_mn * a, "F(0+) = {f0}, -m0 a = {}", -m.fixed_mass() * a);
    }

    /// Fine fixed-step RK4 of the mode equations, for comparison with the exact propagation.
    fn rk4_force(m: &RectangularTankModes, accel: &[(f64, f64)], t_end: f64, dt: f64) -> Vec<(f64, f64)> {
        let z = m.damping_ratio;
        let n = m.omegas().len();
        let mut x = vec![[0.0; 2]; n];
        let mut t = accel[0].0;
        let mut out = Vec::new();
        let rhs = |t: f64, s: [f64; 2], w: f64| [s[1], -acceleration_at(accel, t) - 2.0 * z * w * s[1] - w * w * s[0]];
        while t < t_end - 1e-12 {
            for (s, &w) in x.iter_mut().zip(m.omegas()) {
                let k1 = rhs(t, *s, w);
                let k2 = rhs(t + dt / 2.0, [s[0] + dt / 2.0 * k1[0], s[1] + dt / 2.0 * k1[1]], w);
                let k3 = rhs(t + dt / 2.0, [s[0] + dt / 2.0 * k2[0], s[1] + dt / 2.0 * k2[1]], w);
                let k4 = rhs(t + dt, [s[0] + dt * k3[0], s[1] + dt * k3[1]], w);
                for d in 0..2 {
                    s[d] += dt / 6.0 * (k1[d] + 2.0 * k2[d] + 2.0 * k3[d] + k4[d]);
                }
            }
            t += dt;
            let a = acceleration_at(accel, t);
            let f: f64 = x
                .iter()
                .zip(m.omegas().iter().zip(m.modal_masses()))
                .map(|(s, (&w, &mn))| mn * (w * w * s[0] + 2.0 * z * w * s[1]))
                .sum();
            out.push((t, -m.fixed_mass() * a + f));
        }
        out
    }

    #[test]
    fn exact_integration_matches_rk4_and_finite_differences() {
        // 5 modes (highest f ≈ 5 Hz) so that a 0.1 ms RK4 step is converged; knots on the
        // RK4 grid (RK4 samples a(t) only at t, t + dt/2, t + dt)
        let accel = [(0.1, 0.0), (0.12, 0.3), (0.3, 0.3), (0.32, -0.2), (0.6, 0.1), (0.7, 0.0)];
        for zeta in [0.0, 0.05] {
            let m = RectangularTankModes::new(L, H, M, G, 5).unwrap().with_damping(zeta).unwrap();
            let rk = rk4_force(&m, &accel, 2.0, 1e-4);
            let times: Vec<f64> = rk.iter().map(|p| p.0).collect();
            let f = m.force_history(&accel, &times).unwrap();
            let scale = peak(&f);
            let err = rk.iter().zip(&f).map(|(p, fe)| (p.1 - fe).abs()).fold(0.0, f64::max);
            assert!(err < 1e-6 * scale, "zeta {zeta}: max |F_exact - F_rk4| = {err}, peak {scale}");
            // displacement and velocity consistent: central difference of x vs ẋ, and the
            // mode equation with a central second difference
            let dt = 1e-5;
            for &t in &[0.05, 0.11, 0.25, 0.5, 1.3] {
                let st = m.response(&accel, &[t - dt, t, t + dt]).unwrap();
                let a = acceleration_at(&accel, t);
                for (n, &w) in m.omegas().iter().enumerate() {
                    let (xm, x0, xp) = (st[0][n][0], st[1][n][0], st[2][n][0]);
                    let v = st[1][n][1];
                    let vs = 1e-3 + v.abs();
                    assert!(((xp - xm) / (2.0 * dt) - v).abs() < 1e-5 * vs, "t {t} mode {n}: dx/dt vs v");
                    let acc = (xp - 2.0 * x0 + xm) / (dt * dt);
                    let res = acc + 2.0 * zeta * w * v + w * w * x0 + a;
                    assert!(res.abs() < 1e-3 * (1e-3 + a.abs() + w * w * x0.abs()), "t {t} mode {n}: residual {res}");
                }
            }
        }
    }

    #[test]
    fn undamped_modal_energy_is_constant_after_the_pulse() {
        // after the pulse (a = 0) each undamped mode keeps ½(ẋ² + ω² x²); the load then
        // oscillates about zero with the residual amplitude 2 a |sin(ω T_p/2)|/ω² per mode
        // (rectangular pulse of length T_p, ramps negligible)
        let m = seed_tank();
        let a = 0.03 * G;
        let (t0, t1) = (0.1, 0.5);
        let accel = [(t0, 0.0), (t0 + 1e-6, a), (t1 - 1e-6, a), (t1, 0.0)];
        let times: Vec<f64> = (0..200).map(|i| t1 + 0.0173 * i as f64).collect();
        let st = m.response(&accel, &times).unwrap();
        for (n, &w) in m.omegas().iter().enumerate().take(5) {
            let e: Vec<f64> = st.iter().map(|s| 0.5 * (s[n][1].powi(2) + w * w * s[n][0].powi(2))).collect();
            let e0 = e[0];
            assert!(e.iter().all(|&ei| (ei / e0 - 1.0).abs() < 1e-9), "mode {n}");
            let amp = (2.0 * e0).sqrt() / w;
            let amp_ref = 2.0 * a * (w * (t1 - t0) / 2.0).sin().abs() / (w * w);
            assert!((amp / amp_ref - 1.0).abs() < 1e-4, "mode {n}: amplitude {amp} vs {amp_ref}");
        }
    }

    #[test]
    fn invalid_input_is_rejected() {
        assert!(RectangularTankModes::new(0.0, H, M, G, 5).is_err());
        assert!(RectangularTankModes::new(L, H, M, G, 0).is_err());
        assert!(seed_tank().with_damping(1.0).is_err());
        let m = seed_tank();
        assert!(m.force_history(&[], &[0.0]).is_err());
        assert!(m.force_history(&[(0.0, 1.0), (0.0, 2.0)], &[0.0]).is_err());
        assert!(m.force_history(&[(0.0, 1.0)], &[1.0, 0.5]).is_err());
    }
}
