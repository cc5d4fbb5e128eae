//! Prescribed rigid motion of a tank.
//!
//! Translation: the acceleration R̈(t) of the tank origin is piecewise linear in time
//! (a table of samples, constant after the last one), integrated exactly to Ṙ and R.
//! Rotation: about a fixed global axis u by an angle θ(t) whose angular acceleration is
//! piecewise linear likewise; A = Rot(u, θ), ω = θ̇ u, ω̇ = θ̈ u.

use ancf_core::constitutive::M3;
use ancf_core::contact::TankKinematics;
use ancf_core::error::{AncfError, Result, invalid};
use nalgebra::{Rotation3, Unit, Vector3};

/// A scalar signal with piecewise-linear second derivative, integrated exactly.
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseAcceleration {
    times: Vec<f64>,
    acc: Vec<f64>,
    // value and rate at each knot
    pos: Vec<f64>,
    vel: Vec<f64>,
}

impl PiecewiseAcceleration {
    /// From samples (t_i, a_i) with increasing times, starting at rest at value 0 at the first
    /// time. Before the first sample the signal is 0. A time given twice in a row is a jump of
    /// the acceleration there (the first value is the limit from the left, the second from the
    /// right; the integrals stay continuous), so piecewise-smooth signals are represented
    /// without the O(Δa·Δt) error of sampling across the jump.
    pub fn new(field: &str, samples: &[(f64, f64)]) -> Result<Self> {
        if samples.is_empty() {
            return Err(invalid(field, "[]", "at least one (time, acceleration) sample"));
        }
        for (i, w) in samples.windows(2).enumerate() {
            let repeated = w[1].0 == w[0].0 && (i == 0 || samples[i - 1].0 < w[0].0);
            if !(w[1].0 > w[0].0 || repeated) {
                return Err(invalid(
                    &format!("{field}[{}].time", i + 1),
                    w[1].0,
                    "increasing times (a time at most twice in a row: a jump)",
                ));
            }
        }
        if samples.iter().any(|(t, a)| !t.is_finite() || !a.is_finite()) {
            return Err(invalid(field, "non-finite sample", "finite numbers"));
        }
        let times: Vec<f64> = samples.iter().map(|s| s.0).collect();
        let acc: Vec<f64> = samples.iter().map(|s| s.1).collect();
        let mut pos = vec![0.0];
        let mut vel = vec![0.0];
        for i in 1..times.len() {
            let h = times[i] - times[i - 1];
            let (a0, a1) = (acc[i - 1], acc[i]);
            let v0 = vel[i - 1];
            vel.push(v0 + h * (a0 + a1) / 2.0);
            pos.push(pos[i - 1] + v0 * h + h * h * (2.0 * a0 + a1) / 6.0);
        }
        Ok(Self { times, acc, pos, vel })
    }

    /// A constant acceleration `a` on [t0, t1), zero elsewhere (a rectangular pulse; the
    /// edges are ramps of width `ramp`).
    pub fn pulse(a: f64, t0: f64, t1: f64, ramp: f64) -> Result<Self> {
        if !(t1 > t0 + 2.0 * ramp && ramp > 0.0) {
            return Err(invalid("pulse", format!("[{t0}, {t1}] ramp {ramp}"), "t1 > t0 + 2 ramp, ramp > 0"));
        }
        Self::new("pulse", &[(t0, 0.0), (t0 + ramp, a), (t1 - ramp, a), (t1, 0.0)])
    }

    /// The samples (t_i, a_i) it was built from.
    pub fn samples(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.times.iter().copied().zip(self.acc.iter().copied())
    }

    /// The signal that is zero for all time.
    pub fn zero() -> Self {
        Self::new("zero", &[(0.0, 0.0)]).expect("valid")
    }

    /// (value, rate, acceleration) at time t.
    pub fn eval(&self, t: f64) -> (f64, f64, f64) {
        let n = self.times.len();
        if t <= self.times[0] {
            return (0.0, 0.0, 0.0);
        }
        // first knot after t (binary search: maneuvers carry thousands of samples)
        let i = match self.times.partition_point(|&x| x <= t) {
            k if k < n => k - 1,
            _ => {
                let (a, v, p) = (self.acc[n - 1], self.vel[n - 1], self.pos[n - 1]);
                let s = t - self.times[n - 1];
                return (p + v * s + 0.5 * a * s * s, v + a * s, a);
            }
        };
        let h = self.times[i + 1] - self.times[i];
        let s = t - self.times[i];
        let (a0, a1) = (self.acc[i], self.acc[i + 1]);
        let slope = (a1 - a0) / h;
        let a = a0 + slope * s;
        let v = self.vel[i] + a0 * s + 0.5 * slope * s * s;
        let p = self.pos[i] + self.vel[i] * s + 0.5 * a0 * s * s + slope * s * s * s / 6.0;
        (p, v, a)
    }
}

/// Full kinematics of the tank at one time, including accelerations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TankState {
    /// Position, rotation, velocity and angular velocity.
    pub kinematics: TankKinematics,
    /// R̈ (m/s², global).
    pub acceleration: [f64; 3],
    /// ω̇ (rad/s², global).
    pub angular_acceleration: [f64; 3],
}

/// Prescribed tank motion: translation plus rotation about a fixed axis.
#[derive(Debug, Clone, PartialEq)]
pub struct PrescribedMotion {
    /// Initial position of the tank origin (m).
    pub origin: [f64; 3],
    /// Translational acceleration per global axis.
    pub translation: [PiecewiseAcceleration; 3],
    /// Rotation axis (global, unit) and angle signal.
    pub rotation: Option<([f64; 3], PiecewiseAcceleration)>,
}

impl PrescribedMotion {
    /// A tank at rest at `origin`.
    pub fn at_rest(origin: [f64; 3]) -> Self {
        let z = PiecewiseAcceleration::zero();
        Self { origin, translation: [z.clone(), z.clone(), z], rotation: None }
    }

    /// The state at time t.
    pub fn state(&self, t: f64) -> TankState {
        let mut r = self.origin;
        let mut v = [0.0; 3];
        let mut a = [0.0; 3];
        for d in 0..3 {
            let (p, vd, ad) = self.translation[d].eval(t);
            r[d] += p;
            v[d] = vd;
            a[d] = ad;
        }
        let (rot, w, wd) = match &self.rotation {
            None => (M3::identity(), [0.0; 3], [0.0; 3]),
            Some((axis, sig)) => {
                let u = Vector3::from(*axis).normalize();
                let (th, thd, thdd) = sig.eval(t);
                let m = *Rotation3::from_axis_angle(&Unit::new_unchecked(u), th).matrix();
                ((m), (u * thd).into(), (u * thdd).into())
            }
        };
        TankState {
            kinematics: TankKinematics { position: r, rotation: rot, velocity: v, angular_velocity: w },
            acceleration: a,
            angular_acceleration: wd,
        }
    }

    /// Validate the rotation axis.
    pub fn validate(&self) -> Result<()> {
        if let Some((axis, _)) = &self.rotation {
            let n = Vector3::from(*axis).norm();
            if !(n > 0.0 && n.is_finite()) {
                return Err(AncfError::InvalidParameter {
                    field: "motion.rotation.axis".into(),
                    value: format!("{axis:?}"),
                    allowed: "a non-zero finite vector".into(),
                });
            }
        }
        Ok(())
    }
}

/// Tank motion as seen in the tank frame at one instant (seed 003's co-simulation
/// interface, appendix C eq. 7.40): all vectors in tank axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TankFrameSample {
    /// Acceleration of the tank origin R̈, tank components (m/s²).
    pub acceleration: [f64; 3],
    /// Angular velocity ω of the tank, tank components (rad/s).
    pub angular_velocity: [f64; 3],
    /// Angular acceleration ω̇ of the tank, tank components (rad/s²).
    pub angular_acceleration: [f64; 3],
    /// Gravity vector (direction × g), tank components (m/s²).
    pub gravity: [f64; 3],
}

impl TankFrameSample {
    /// A tank at rest, gravity `g` along −z of the tank.
    pub fn at_rest(g: f64) -> Self {
        Self {
            acceleration: [0.0; 3],
            angular_velocity: [0.0; 3],
            angular_acceleration: [0.0; 3],
            gravity: [0.0, 0.0, -g],
        }
    }

    /// `(1 − s) self + s other`, component-wise.
    pub fn lerp(&self, other: &Self, s: f64) -> Self {
        let l = |a: [f64; 3], b: [f64; 3]| std::array::from_fn(|i| a[i] + s * (b[i] - a[i]));
        Self {
            acceleration: l(self.acceleration, other.acceleration),
            angular_velocity: l(self.angular_velocity, other.angular_velocity),
            angular_acceleration: l(self.angular_acceleration, other.angular_acceleration),
            gravity: l(self.gravity, other.gravity),
        }
    }

    /// Whether every component is finite.
    pub fn is_finite(&self) -> bool {
        [self.acceleration, self.angular_velocity, self.angular_acceleration, self.gravity]
            .iter()
            .all(|v| v.iter().all(|x| x.is_finite()))
    }
}

/// Tank-frame motion over a time window [t0, t1], linearly interpolated between the samples
/// at its ends (constant outside). Used by [`SloshSystem`](super::SloshSystem) in the
/// tank-frame formulation instead of its [`PrescribedMotion`] when set (co-simulation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TankFrameInput {
    /// Window start (s).
    pub t0: f64,
    /// Window end (s), ≥ t0.
    pub t1: f64,
    /// Sample at t0.
    pub start: TankFrameSample,
    /// Sample at t1.
    pub end: TankFrameSample,
}

impl TankFrameInput {
    /// A constant input for all time.
    pub fn constant(sample: TankFrameSample) -> Self {
        Self { t0: 0.0, t1: 0.0, start: sample, end: sample }
    }

    /// The interpolated sample at t.
    pub fn at(&self, t: f64) -> TankFrameSample {
        if self.t1 <= self.t0 {
            return if t < self.t0 { self.start } else { self.end };
        }
        let s = ((t - self.t0) / (self.t1 - self.t0)).clamp(0.0, 1.0);
        if s == 1.0 { self.end } else { self.start.lerp(&self.end, s) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn piecewise_acceleration_integrates_exactly() {
        let s = PiecewiseAcceleration::new("a", &[(0.0, 0.0), (1.0, 2.0), (3.0, 2.0), (4.0, -1.0)]).unwrap();
        // numerically integrate a(t) with a fine trapezoid and compare v and x
        let (mut v, mut x) = (0.0, 0.0);
        let n = 500_000;
        let h = 5.0 / n as f64;
        for k in 0..n {
            let t = k as f64 * h;
            let (_, _, a0) = s.eval(t);
            let (_, _, a1) = s.eval(t + h);
            x += v * h + h * h * (2.0 * a0 + a1) / 6.0;
            v += 0.5 * h * (a0 + a1);
        }
        let (p, vv, a) = s.eval(5.0);
        assert!((vv - v).abs() < 1e-8 && (p - x).abs() < 1e-7 && (a + 1.0).abs() < 1e-15, "{p} {x} {vv} {v}");
        assert!(PiecewiseAcceleration::new("a", &[(1.0, 0.0), (0.5, 1.0)]).is_err());
    }

    #[test]
    fn a_repeated_time_is_an_exact_jump() {
        // a = 0 until 1, then 2: v = 2 (t - 1), x = (t - 1)² after the jump
        let s = PiecewiseAcceleration::new("a", &[(0.0, 0.0), (1.0, 0.0), (1.0, 2.0), (3.0, 2.0)]).unwrap();
        assert_eq!(s.eval(0.5), (0.0, 0.0, 0.0));
        assert_eq!(s.eval(1.0).2, 2.0);
        let (x, v, a) = s.eval(2.5);
        assert!((x - 2.25).abs() < 1e-14 && (v - 3.0).abs() < 1e-14 && a == 2.0, "{x} {v} {a}");
        // a time three times in a row is refused
        let e = PiecewiseAcceleration::new("a", &[(0.0, 0.0), (1.0, 0.0), (1.0, 2.0), (1.0, 3.0)]).unwrap_err();
        assert!(e.to_string().contains("a[3].time"), "{e}");
    }
}
