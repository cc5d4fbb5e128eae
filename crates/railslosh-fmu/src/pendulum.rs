//! Equivalent pendulum model of the liquid in a flat-ended tank of elliptical section: a
//! rigid mass and two planar pendulums (first longitudinal and first lateral slosh mode),
//! moving in the tank frame under the tank's linear and angular motion.
//!
//! ## Parameters from the geometry
//! The liquid section below the free surface z_s (from the fill) has area A, free-surface
//! width W and mean depth d = A/W; its centre of mass is at height
//! z̄ = −(a/b)(2/3)(b² − z_s²)^{3/2} / A. The modes come from the vehicle's equivalent model
//! (`rail_mbs::vehicle::equivalent`), the one implementation of these rules:
//!
//! - longitudinal: the first mode of the rectangular tank of length L and depth d
//!   (`rectangular_mode`): ω² = (π g / L) tanh(π d / L), m_L = m · 8 L tanh(π d / L) / (π³ d);
//! - lateral, circular section (a = b = R, liquid depth 1–95 % of the diameter): the
//!   transverse eigenvalue λ(h/2R) of the horizontal cylinder (`cylinder_lambda`, the Steklov
//!   table) and `cylinder_lateral_mode`: ω² = λ g / R, m_W = m d̄ λ / R (d̄ = −z̄);
//! - lateral, elliptical section (a ≠ b), or a circle outside that depth range: the
//!   "equivalent rectangular tank" of width W and depth d, the rule above with L → W (no
//!   eigenvalue table exists for the ellipse; for the half-full circle this rule gives
//!   λ = 1.325 against the exact 1.3557, 2.3 % low);
//! - g = [`GRAVITY`]; pendulum length l = g / ω², hinged at l above z̄ so that each bob hangs
//!   at the liquid's centre of mass (the static moment is exact; the dynamic moment arm is
//!   approximate; for the circle l = R/λ as in the vehicle model);
//! - the rigid mass m₀ = m − m_L − m_W sits at the centre of mass. Where m_L + m_W would
//!   exceed 0.9 m (shallow fills) both are scaled down to 0.9 m.
//!
//! ## Dynamics
//! A bob of mass m at r(θ) = P + l u(θ), u = sin θ ê − cos θ ẑ (ê = x̂ or ŷ), tangent
//! t = cos θ ê + sin θ ẑ, in a tank with origin acceleration a₀, angular velocity ω and
//! angular acceleration α (tank frame) has the inertial acceleration
//! a_p = a₀ + α×r + ω×(ω×r) + 2ω×ṙ + r̈ with ṙ = lθ̇ t, r̈ = lθ̈ t − lθ̇² u. Its
//! equation of motion along t, with modal damping ζ, is
//! l θ̈ = (g − a₀ − α×r − ω×(ω×r) − 2ω×ṙ)·t − 2ζω_n l θ̇.
//! Every mass i loads the tank with F_i = m_i (g − a_i) (the pendulum constraint and the
//! damper act between bob and tank), and M = Σ (r_i − r_ref) × F_i. In a steady tank motion
//! the bobs come to rest relative to the tank and F = m (g − a₀ − α×r̄ − ω×(ω×r̄)).
//!
//! Time integration: classical Runge–Kutta 4 with steps ≤ `h_max`.

use ancf_core::mesh::circle_segment_area;
use nalgebra::Vector3;
use rail_mbs::vehicle::equivalent::{DEPTH_FRACTION_RANGE, cylinder_lambda, cylinder_lateral_mode, rectangular_mode};

use crate::model::{FmuModel, ModelConfig, Outputs, TankInput};
use crate::variables::GRAVITY;

type V3 = Vector3<f64>;

/// Geometry and modal data of the liquid, derived from the configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LiquidSection {
    /// Liquid section area (m²).
    pub area: f64,
    /// Free-surface height in the tank frame (m).
    pub z_surface: f64,
    /// Free-surface width (m).
    pub width: f64,
    /// Mean depth A / W (m).
    pub mean_depth: f64,
    /// Height of the centre of mass in the tank frame (m).
    pub z_com: f64,
    /// Liquid mass (kg).
    pub mass: f64,
}

impl LiquidSection {
    /// The liquid of `config` (fill fraction of the elliptical section).
    pub fn new(config: &ModelConfig) -> Self {
        let (a, b) = (config.semi_axis_y, config.semi_axis_z);
        let target = config.fill * std::f64::consts::PI * a * b;
        let seg = |h: f64| (a / b) * circle_segment_area(b, h);
        let h = ancf_core::roots::bisect(0.0, 2.0 * b, 100, |h| seg(h) < target);
        let zs = h - b;
        let area = seg(h);
        let width = 2.0 * a * (1.0 - (zs / b).powi(2)).max(0.0).sqrt();
        let z_com = -(a / b) * (2.0 / 3.0) * (b * b - zs * zs).max(0.0).powf(1.5) / area;
        Self {
            area,
            z_surface: zs,
            width,
            mean_depth: area / width,
            z_com,
            mass: config.density * area * config.length,
        }
    }

    /// First slosh mode of the equivalent rectangular tank of extent `span` along the
    /// sloshing direction (`rail_mbs::vehicle::equivalent::rectangular_mode`): (ω² at
    /// g = [`GRAVITY`], sloshing mass).
    pub fn mode(&self, span: f64) -> Result<(f64, f64), String> {
        let (omega, m) = rectangular_mode(span, self.mean_depth, self.mass, GRAVITY).map_err(|e| e.to_string())?;
        Ok((omega * omega, m))
    }

    /// First lateral mode (module docs): the horizontal cylinder's eigenvalue for a circular
    /// section of radius `a` = `b` within the table's depth range, else the equivalent
    /// rectangular tank of width W. (ω², sloshing mass).
    pub fn lateral_mode(&self, a: f64, b: f64) -> Result<(f64, f64), String> {
        let fraction = (self.z_surface + b) / (2.0 * b);
        let (lo, hi) = DEPTH_FRACTION_RANGE;
        if (a - b).abs() <= 1e-12 * b && (lo..=hi).contains(&fraction) {
            let lam = cylinder_lambda(fraction).map_err(|e| e.to_string())?;
            let (omega, m) = cylinder_lateral_mode(b, lam, self.mass, -self.z_com, GRAVITY);
            return Ok((omega * omega, m));
        }
        self.mode(self.width)
    }
}

/// One planar pendulum.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Bob {
    /// Swing direction ê (unit, x̂ or ŷ).
    dir: V3,
    /// Pivot (m).
    pivot: V3,
    /// Length (m).
    length: f64,
    /// Mass (kg).
    mass: f64,
    /// Nominal natural frequency (rad/s) for the damping term.
    omega_n: f64,
}

impl Bob {
    fn unit(&self, th: f64) -> (V3, V3) {
        let z = V3::z();
        (th.sin() * self.dir - th.cos() * z, th.cos() * self.dir + th.sin() * z)
    }

    /// Position, relative velocity and the non-relative part of the inertial acceleration.
    fn kinematics(&self, th: f64, thd: f64, inp: &TankInput) -> (V3, V3, V3, V3, V3) {
        let (u, t) = self.unit(th);
        let r = self.pivot + self.length * u;
        let rd = (self.length * thd) * t;
        let (w, alpha) = (V3::from(inp.angular_velocity), V3::from(inp.angular_acceleration));
        let a_frame = V3::from(inp.acceleration) + alpha.cross(&r) + w.cross(&w.cross(&r)) + 2.0 * w.cross(&rd);
        (r, rd, a_frame, u, t)
    }

    /// Angular acceleration θ̈.
    fn accel(&self, th: f64, thd: f64, inp: &TankInput, zeta: f64) -> f64 {
        let (_, _, a_frame, _, t) = self.kinematics(th, thd, inp);
        (V3::from(inp.gravity) - a_frame).dot(&t) / self.length - 2.0 * zeta * self.omega_n * thd
    }

    /// Position and force on the tank.
    fn load(&self, th: f64, thd: f64, inp: &TankInput, zeta: f64) -> (V3, V3) {
        let (r, _, a_frame, u, t) = self.kinematics(th, thd, inp);
        let thdd = self.accel(th, thd, inp, zeta);
        let rdd = (self.length * thdd) * t - (self.length * thd * thd) * u;
        (r, self.mass * (V3::from(inp.gravity) - (a_frame + rdd)))
    }
}

/// The equivalent pendulum model.
#[derive(Debug, Clone, PartialEq)]
pub struct Pendulum {
    section: LiquidSection,
    rigid_mass: f64,
    com0: V3,
    bobs: [Bob; 2],
    zeta: f64,
    reference: V3,
    h_max: f64,
    /// Time and [θ_x, θ̇_x, θ_y, θ̇_y] (longitudinal, lateral).
    t: f64,
    y: [f64; 4],
}

impl Pendulum {
    /// Model of `config` at rest relative to the tank at time `t0`.
    pub fn new(config: &ModelConfig, t0: f64) -> Result<Self, String> {
        config.validate()?;
        let s = LiquidSection::new(config);
        let (w2_long, mut m_long) = s.mode(config.length)?;
        let (w2_lat, mut m_lat) = s.lateral_mode(config.semi_axis_y, config.semi_axis_z)?;
        let cap = 0.9 * s.mass;
        if m_long + m_lat > cap {
            let f = cap / (m_long + m_lat);
            m_long *= f;
            m_lat *= f;
        }
        let com0 = V3::new(0.0, 0.0, s.z_com);
        let bob = |dir: V3, w2: f64, m: f64| {
            let l = GRAVITY / w2;
            Bob { dir, pivot: V3::new(0.0, 0.0, s.z_com + l), length: l, mass: m, omega_n: w2.sqrt() }
        };
        Ok(Self {
            section: s,
            rigid_mass: s.mass - m_long - m_lat,
            com0,
            bobs: [bob(V3::x(), w2_long, m_long), bob(V3::y(), w2_lat, m_lat)],
            zeta: config.damping_ratio,
            reference: V3::from(config.reference),
            h_max: config.h_max,
            t: t0,
            y: [0.0; 4],
        })
    }

    /// The liquid section data.
    pub fn section(&self) -> &LiquidSection {
        &self.section
    }

    /// Sloshing masses (kg), [longitudinal, lateral].
    pub fn sloshing_masses(&self) -> [f64; 2] {
        [self.bobs[0].mass, self.bobs[1].mass]
    }

    /// Pendulum angles (rad), [longitudinal, lateral].
    pub fn angles(&self) -> [f64; 2] {
        [self.y[0], self.y[2]]
    }

    fn rhs(&self, y: &[f64; 4], inp: &TankInput) -> [f64; 4] {
        [y[1], self.bobs[0].accel(y[0], y[1], inp, self.zeta), y[3], self.bobs[1].accel(y[2], y[3], inp, self.zeta)]
    }
}

impl FmuModel for Pendulum {
    fn time(&self) -> f64 {
        self.t
    }

    fn advance(&mut self, t_end: f64, u0: &TankInput, u1: &TankInput) -> Result<(), String> {
        let t0 = self.t;
        let span = t_end - t0;
        if !(span.is_finite() && span >= 0.0) {
            return Err(format!("cannot advance from t = {t0} to t = {t_end}"));
        }
        let n = (span / self.h_max).ceil().max(1.0) as usize;
        let h = span / n as f64;
        let at = |t: f64| if span > 0.0 { u0.lerp(u1, (t - t0) / span) } else { *u1 };
        let mut y = self.y;
        for k in 0..n {
            let t = t0 + k as f64 * h;
            let (ua, um, ub) = (at(t), at(t + 0.5 * h), at(t + h));
            let step = |y: &[f64; 4], d: &[f64; 4], c: f64| -> [f64; 4] { std::array::from_fn(|i| y[i] + c * d[i]) };
            let k1 = self.rhs(&y, &ua);
            let k2 = self.rhs(&step(&y, &k1, 0.5 * h), &um);
            let k3 = self.rhs(&step(&y, &k2, 0.5 * h), &um);
            let k4 = self.rhs(&step(&y, &k3, h), &ub);
            y = std::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
        }
        if let Some(i) = y.iter().position(|x| !x.is_finite()) {
            return Err(format!("pendulum state component {i} became non-finite before t = {t_end}"));
        }
        self.y = y;
        self.t = t_end;
        Ok(())
    }

    fn outputs(&self, u: &TankInput) -> Outputs {
        let (mut force, mut moment, mut com) = (V3::zeros(), V3::zeros(), V3::zeros());
        let mut add_mass = |r: V3, f: V3, m: f64| {
            force += f;
            moment += (r - self.reference).cross(&f);
            com += m * r;
        };
        let (w, alpha) = (V3::from(u.angular_velocity), V3::from(u.angular_acceleration));
        let r0 = self.com0;
        let a0 = V3::from(u.acceleration) + alpha.cross(&r0) + w.cross(&w.cross(&r0));
        add_mass(r0, self.rigid_mass * (V3::from(u.gravity) - a0), self.rigid_mass);
        for (k, bob) in self.bobs.iter().enumerate() {
            let (r, f) = bob.load(self.y[2 * k], self.y[2 * k + 1], u, self.zeta);
            add_mass(r, f, bob.mass);
        }
        Outputs { force: force.into(), moment: moment.into(), com: (com / self.section.mass).into() }
    }

    fn mass(&self) -> f64 {
        self.section.mass
    }

    fn slosh_frequencies(&self) -> [f64; 2] {
        let f = |b: &Bob| b.omega_n / (2.0 * std::f64::consts::PI);
        [f(&self.bobs[0]), f(&self.bobs[1])]
    }

    fn save_state(&self) -> Vec<u8> {
        std::iter::once(self.t).chain(self.y).flat_map(f64::to_le_bytes).collect()
    }

    fn restore_state(&mut self, state: &[u8]) -> Result<(), String> {
        if state.len() != 40 {
            return Err(format!("a pendulum state has 40 bytes, got {}", state.len()));
        }
        let x: Vec<f64> = state.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes"))).collect();
        self.t = x[0];
        self.y.copy_from_slice(&x[1..]);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::ModelKind;

    fn config(a: f64, b: f64, fill: f64) -> ModelConfig {
        ModelConfig {
            kind: ModelKind::Pendulum,
            fill,
            density: 1000.0,
            viscosity: 1e-3,
            length: 2.0,
            semi_axis_y: a,
            semi_axis_z: b,
            reference: [0.0; 3],
            h_max: 1e-3,
            damping_ratio: 0.0,
            counts: [2, 4, 2],
        }
    }

    #[test]
    fn half_full_circle_section() {
        let r = 0.5;
        let s = LiquidSection::new(&config(r, r, 0.5));
        assert!(s.z_surface.abs() < 1e-12);
        assert!((s.width - 2.0 * r).abs() < 1e-12);
        // centroid of a half disc: 4R/(3π) below the diameter
        assert!((s.z_com + 4.0 * r / (3.0 * std::f64::consts::PI)).abs() < 1e-12);
        assert!((s.mass - 1000.0 * 0.5 * std::f64::consts::PI * r * r * 2.0).abs() < 1e-9);
        // the equivalent rectangular tank gives ω²R/g = (π/2) tanh(π²/8) = 1.325 ...
        let (w2, m1) = s.mode(s.width).unwrap();
        let lam = w2 * r / GRAVITY;
        assert!((lam - 0.5 * std::f64::consts::PI * (std::f64::consts::PI.powi(2) / 8.0).tanh()).abs() < 1e-12);
        assert!(m1 > 0.0 && m1 < s.mass);
        // ... but the circle's lateral mode is the cylinder's, shared with the vehicle model:
        // λ = 1.3557 (Budiansky; McIver 1989), m_W = m d̄ λ / R, pendulum length R/λ
        let (w2, m1) = s.lateral_mode(r, r).unwrap();
        let lam = w2 * r / GRAVITY;
        assert!((lam - 1.3557).abs() < 3e-4, "lambda {lam}");
        assert!((m1 - s.mass * (-s.z_com) * lam / r).abs() < 1e-9 * s.mass);
        let p = Pendulum::new(&config(r, r, 0.5), 0.0).unwrap();
        assert!((p.bobs[1].length - r / lam).abs() < 1e-12);
        // an ellipse keeps the equivalent rectangular tank
        let e = LiquidSection::new(&config(0.6, 0.4, 0.5));
        assert_eq!(e.lateral_mode(0.6, 0.4).unwrap(), e.mode(e.width).unwrap());
    }

    /// The longitudinal mode is the vehicle model's rectangular-tank mode.
    #[test]
    fn longitudinal_mode_is_the_vehicle_models() {
        let c = config(0.4, 0.3, 0.7);
        let s = LiquidSection::new(&c);
        let (omega, m) = rectangular_mode(c.length, s.mean_depth, s.mass, GRAVITY).unwrap();
        let (w2, m1) = s.mode(c.length).unwrap();
        assert_eq!((w2, m1), (omega * omega, m));
    }

    #[test]
    fn static_loads_are_weight_at_the_centre_of_mass() {
        let c = config(0.4, 0.3, 0.7);
        let p = Pendulum::new(&c, 0.0).unwrap();
        let out = p.outputs(&TankInput::at_rest(crate::variables::GRAVITY));
        let m = p.mass();
        assert!((out.force[2] + m * GRAVITY).abs() < 1e-9 * m);
        assert!(out.force[0].abs() < 1e-9 && out.force[1].abs() < 1e-9);
        assert!((out.com[2] - p.section().z_com).abs() < 1e-12);
        let masses = p.sloshing_masses();
        assert!(p.rigid_mass > 0.0 && (p.rigid_mass + masses[0] + masses[1] - m).abs() < 1e-9 * m);
    }

    /// Constant lateral acceleration, damped: the pendulum settles at tan θ = a/g and the
    /// force is m(g − a); the moment is that of the total force at the displaced centre of mass.
    #[test]
    fn steady_acceleration_settles_to_rigid_body_load() {
        let mut c = config(0.4, 0.4, 0.5);
        c.damping_ratio = 0.3;
        c.reference = [0.1, -0.2, 0.3];
        let mut p = Pendulum::new(&c, 0.0).unwrap();
        let mut u = TankInput::at_rest(crate::variables::GRAVITY);
        u.acceleration = [0.5, 2.0, 0.0];
        p.advance(40.0, &u, &u).unwrap();
        let out = p.outputs(&u);
        let m = p.mass();
        let expect = m * (V3::from(u.gravity) - V3::from(u.acceleration));
        for i in 0..3 {
            assert!((out.force[i] - expect[i]).abs() < 1e-6 * m, "force {i}: {:?} vs {expect:?}", out.force);
        }
        let th = p.angles();
        assert!((th[1] - (-(2.0f64 / GRAVITY).atan())).abs() < 1e-8, "lateral angle {}", th[1]);
        assert!((th[0] - (-(0.5f64 / GRAVITY).atan())).abs() < 1e-8);
        let mom = (V3::from(out.com) - V3::from(c.reference)).cross(&expect);
        for (got, want) in out.moment.iter().zip(mom.iter()) {
            assert!((got - want).abs() < 1e-6 * m);
        }
    }

    /// Undamped small oscillation: the lateral force oscillates at ω = √(g/l) with g the
    /// magnitude of the gravity input (here a lower gravity, so the test sees g enter).
    #[test]
    fn free_lateral_oscillation_frequency() {
        let c = config(0.6, 0.4, 0.5);
        let mut p = Pendulum::new(&c, 0.0).unwrap();
        let mut u = TankInput::at_rest(crate::variables::GRAVITY);
        u.gravity = [0.0, 0.0, -6.0];
        u.acceleration = [0.0, 0.3, 0.0];
        p.advance(0.05, &u, &u).unwrap();
        u.acceleration = [0.0; 3];
        let omega = (6.0 / p.bobs[1].length).sqrt();
        let (mut crossings, mut last) = (Vec::new(), p.outputs(&u).force[1]);
        let dt = 1e-3;
        for _ in 0..16000 {
            let t = p.time() + dt;
            p.advance(t, &u, &u).unwrap();
            let f = p.outputs(&u).force[1];
            if last <= 0.0 && f > 0.0 {
                crossings.push(t - dt * f / (f - last));
            }
            last = f;
        }
        let n = crossings.len();
        assert!(n >= 5);
        let period = (crossings[n - 1] - crossings[0]) / (n - 1) as f64;
        let omega_m = 2.0 * std::f64::consts::PI / period;
        assert!((omega_m / omega - 1.0).abs() < 1e-3, "measured {omega_m}, expected {omega}");
    }

    /// Tank rotating, bobs hanging at the centre of mass with θ̇ = 0: an undamped bob's
    /// tangential load vanishes (l θ̈ = (g − a)·t), so F_x = (m₀ + m_W)(g − a)_x,
    /// F_y = (m₀ + m_L)(g − a)_y and F_z = m (g − a)_z, a = α×r̄ + ω×(ω×r̄).
    #[test]
    fn rotation_terms_and_free_bob_tangential_load() {
        let c = config(0.4, 0.4, 0.5);
        let p = Pendulum::new(&c, 0.0).unwrap();
        let mut u = TankInput::at_rest(crate::variables::GRAVITY);
        u.angular_velocity = [0.3, -0.4, 0.2];
        u.angular_acceleration = [0.5, 0.2, 0.7];
        let out = p.outputs(&u);
        let r = p.com0;
        let w = V3::from(u.angular_velocity);
        let a = V3::from(u.angular_acceleration).cross(&r) + w.cross(&w.cross(&r));
        let g_a = V3::from(u.gravity) - a;
        let m = p.mass();
        let [m_long, m_lat] = p.sloshing_masses();
        assert!((out.force[0] - (m - m_long) * g_a[0]).abs() < 1e-9 * m);
        assert!((out.force[1] - (m - m_lat) * g_a[1]).abs() < 1e-9 * m);
        assert!((out.force[2] - m * g_a[2]).abs() < 1e-9 * m);
        // moment about the origin: all masses at r̄
        let mom = r.cross(&V3::from(out.force));
        for (got, want) in out.moment.iter().zip(mom.iter()) {
            assert!((got - want).abs() < 1e-9 * m);
        }
    }

    #[test]
    fn save_restore_round_trip() {
        let c = config(0.4, 0.3, 0.6);
        let mut p = Pendulum::new(&c, 0.0).unwrap();
        let mut u = TankInput::at_rest(crate::variables::GRAVITY);
        u.acceleration = [0.2, 1.0, 0.0];
        p.advance(0.3, &u, &u).unwrap();
        let s = p.save_state();
        p.advance(0.6, &u, &u).unwrap();
        let after = p.outputs(&u);
        p.restore_state(&s).unwrap();
        assert_eq!(p.time(), 0.3);
        p.advance(0.6, &u, &u).unwrap();
        assert_eq!(p.outputs(&u), after);
        assert!(p.restore_state(&[1, 2, 3]).is_err());
    }
}
