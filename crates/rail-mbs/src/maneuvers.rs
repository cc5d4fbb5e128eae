//! Seed 003's maneuvers (§3, Phase 1 tests of the small-scale FMTV tank) as prescribed
//! tank motions: pose histories in the global frame, their tank-frame form, and the
//! [`PrescribedMotion`] a slosh run takes. **This module is the one definition of these
//! maneuvers**: the shipped `swri_*` scenes (`[maneuver]` of a slosh scene, through the
//! Python binding) and the co-simulation (`cosim_maneuvers`, `railslosh.cosim`) both build
//! their motion here.
//!
//! Seed 003 names the maneuvers (AVTP lane changes at 20 and 40 mph; 9″ half-round
//! symmetric bump at 10 mph; 12″ half-round at 5 mph; 9″ trapezoidal asymmetric bump at
//! 15 mph; 12″ trapezoidal at 10 mph) but gives no course or profile dimensions, nor the
//! vehicle data. The values chosen here are documented on each item:
//!
//! - **Lane change** ([`LaneChangeCourse`]): the vehicle keeps its forward speed V along
//!   global x and moves laterally by `offset` over a course `length`, duration T = length / V,
//!   on the smooth path y = Y (s − sin 2πs / 2π), s = t/T (lateral acceleration one full sine
//!   period, zero velocity and acceleration at both ends). The AVTP course
//!   ([`LaneChangeCourse::AVTP`]) is a *double* lane change: 3.66 m (12 ft) over 30.5 m
//!   (100 ft), `hold` 15.2 m (50 ft) in the other lane, and the same path back. The tank
//!   heading follows the path tangent, ψ = atan(ẏ / V). Peak lateral acceleration 2πY/T².
//! - **Bumps** ([`BumpProfile`], [`BumpVehicle`]): a two-axle vehicle (wheelbase W) crosses
//!   the bump at constant speed; each axle's wheel-centre rise u(t) passes through a
//!   quarter-car suspension z̈ = ω²(u − z) + 2ζω(u̇ − ż) (natural frequency `frequency`,
//!   damping ratio `damping_ratio`; integrated with RK4 at 0.1 ms). The tank origin sits
//!   midway between the axles: heave (z_f + z_r)/2, pitch θ = (z_r − z_f)/W about +y (nose
//!   up when the front axle rises). Half-round bump of radius H: the wheel (radius r_w)
//!   rolls over it, u = √((H + r_w)² − d²) − r_w (d = horizontal distance to the bump
//!   centre, while positive). Trapezoidal asymmetric bump: ramp up over `up_length`, flat top
//!   `top_length`, ramp down over `down_length` (seed 003's tests: 4 H, 2 H and H,
//!   [`BumpProfile::seed003_trapezoid`]); the wheel centre follows the profile while the
//!   road pushes on it. The wheel is massless and cannot be pulled: where the suspension
//!   would drive the sprung mass down faster than it falls (g + z̈ < 0), the wheel leaves the
//!   road, the sprung mass falls freely and the wheel lands again further on
//!   ([`bump_response`]). Until 2026-11-27 the wheel followed the profile everywhere, and the
//!   tank was pulled down at up to 4.3 g (9″ trapezoid at 15 mph), 3.0 g (9″ half-round at
//!   10 mph) and 2.5 g (12″ trapezoid at 10 mph): a road cannot pull a wheel. Defaults
//!   [`BumpVehicle::default`]: W = 3.9 m, r_w = 0.53 m, 2 Hz, ζ = 0.3 (an FMTV-like
//!   truck; assumed, not from the seed).
//! - The motion of the full-size vehicle is applied to the tank as is (the seed's tank is
//!   the small-scale SwRI elliptical tank, [`ancf_core::mesh::EllipticCylinderSpec::swri`]).
//! - As a [`PrescribedMotion`] ([`Maneuver::prescribed_motion`]) the uniform forward velocity
//!   V and the initial position are dropped (a Galilean change of frame: liquid and tank
//!   start at rest together either way); the global accelerations and the rotation about the
//!   maneuver's fixed axis (z for lane changes, y for bumps) are kept, sampled piecewise
//!   linearly.

use std::f64::consts::PI;

use ancf_core::error::{AncfError, invalid};

use crate::cosim::{CosimError, PoseInput};
use crate::slosh::{PiecewiseAcceleration, PrescribedMotion, TankFrameSample};
pub use crate::track::{FOOT, INCH, MPH};

/// A prescribed tank motion sampled at uniform times.
#[derive(Debug, Clone, PartialEq)]
pub struct Maneuver {
    /// Short name (file-name safe).
    pub name: String,
    /// Sample times (s), uniform, starting at 0.
    pub times: Vec<f64>,
    /// Tank pose, velocity and acceleration at each time (global frame).
    pub poses: Vec<PoseInput>,
    /// The times where the acceleration or angular acceleration jumps (a kink of the road
    /// under a wheel, the start and end of a lane change's jerk), with the one-sided poses;
    /// [`Self::prescribed_motion`] keeps them exactly.
    pub jumps: Vec<Jump>,
}

/// A jump of a maneuver's accelerations at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jump {
    /// Time of the jump (s).
    pub time: f64,
    /// The pose with the accelerations just before it.
    pub before: PoseInput,
    /// The pose with the accelerations just after it.
    pub after: PoseInput,
}

impl Maneuver {
    /// Seed 003's tank-frame form of every sample (gravity −g along global z).
    pub fn tank_frame(&self, gravity: f64) -> Result<Vec<TankFrameSample>, CosimError> {
        self.poses.iter().map(|p| p.to_tank_frame(gravity)).collect()
    }

    /// The maneuver cut after the first sample at or beyond `t_end` (s).
    pub fn until(mut self, t_end: f64) -> Self {
        let n = self.times.partition_point(|&t| t < t_end) + 1;
        self.times.truncate(n);
        self.poses.truncate(n);
        let last = self.times.last().copied().unwrap_or(0.0);
        self.jumps.retain(|j| j.time <= last);
        self
    }

    /// The motion a slosh run prescribes (module docs: forward speed and initial position
    /// dropped): the global accelerations R̈ as piecewise-linear signals through the samples,
    /// and the rotation about its fixed axis with the angular acceleration likewise. A
    /// maneuver whose rotation is not about one fixed axis is refused.
    pub fn prescribed_motion(&self) -> Result<PrescribedMotion, AncfError> {
        // the uniform samples, with each jump as two samples at its time (left and right limits)
        let mut knots: Vec<(f64, &PoseInput)> = Vec::with_capacity(self.times.len() + 2 * self.jumps.len());
        let mut jumps = self.jumps.iter().peekable();
        for (&t, p) in self.times.iter().zip(&self.poses) {
            while let Some(j) = jumps.next_if(|j| j.time <= t) {
                knots.push((j.time, &j.before));
                knots.push((j.time, &j.after));
            }
            if knots.last().is_none_or(|k| k.0 < t) {
                knots.push((t, p));
            }
        }
        let signal = |f: &dyn Fn(&PoseInput) -> f64, field: &str| -> Result<PiecewiseAcceleration, AncfError> {
            if knots.iter().all(|(_, p)| f(p) == 0.0) {
                return Ok(PiecewiseAcceleration::zero());
            }
            let samples: Vec<(f64, f64)> = knots.iter().map(|&(t, p)| (t, f(p))).collect();
            PiecewiseAcceleration::new(field, &samples)
        };
        let translation = [
            signal(&|p| p.acceleration[0], "maneuver.acceleration.x")?,
            signal(&|p| p.acceleration[1], "maneuver.acceleration.y")?,
            signal(&|p| p.acceleration[2], "maneuver.acceleration.z")?,
        ];
        let norm = |v: [f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        // the axis: direction of the largest angular velocity (or acceleration)
        let key = |p: &&PoseInput| norm(p.angular_velocity).max(norm(p.angular_acceleration));
        let rotation = match knots.iter().map(|k| k.1).max_by(|a, b| key(a).total_cmp(&key(b))) {
            Some(p) if key(&p) > 0.0 => {
                let w = if norm(p.angular_velocity) > 0.0 { p.angular_velocity } else { p.angular_acceleration };
                // canonical sign: the largest component positive
                let big = w.iter().copied().fold(0.0_f64, |m, x| if x.abs() > m.abs() { x } else { m });
                let n = norm(w).copysign(big);
                let u = w.map(|x| x / n);
                let off_axis = |v: [f64; 3]| {
                    let c = [v[1] * u[2] - v[2] * u[1], v[2] * u[0] - v[0] * u[2], v[0] * u[1] - v[1] * u[0]];
                    norm(c) > 1e-9 * (1.0 + norm(v))
                };
                if let Some(&(t, _)) =
                    knots.iter().find(|(_, p)| off_axis(p.angular_velocity) || off_axis(p.angular_acceleration))
                {
                    return Err(invalid(
                        &format!("maneuver `{}` rotation", self.name),
                        format!("at t = {t} s"),
                        "a rotation about one fixed axis",
                    ));
                }
                let dot = |v: [f64; 3]| v[0] * u[0] + v[1] * u[1] + v[2] * u[2];
                let angle = signal(&|p| dot(p.angular_acceleration), "maneuver.angular_acceleration")?;
                Some((u, angle))
            }
            _ => None,
        };
        let motion = PrescribedMotion { origin: [0.0; 3], translation, rotation };
        motion.validate()?;
        Ok(motion)
    }
}

fn check(field: &str, v: f64, ok: bool, allowed: &str) -> Result<(), AncfError> {
    if ok && v.is_finite() { Ok(()) } else { Err(invalid(field, v, allowed)) }
}

fn check_timing(t_before: f64, t_after: f64, dt: f64) -> Result<(), AncfError> {
    check("t_before", t_before, t_before >= 0.0, ">= 0 (s)")?;
    check("t_after", t_after, t_after >= 0.0, ">= 0 (s)")?;
    check("dt", dt, dt > 0.0, "> 0 (s)")
}

fn rot_z(psi: f64) -> [[f64; 3]; 3] {
    let (s, c) = psi.sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}

fn rot_y(th: f64) -> [[f64; 3]; 3] {
    let (s, c) = th.sin_cos();
    [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
}

fn sample_times(duration: f64, dt: f64) -> Vec<f64> {
    let n = (duration / dt).ceil() as usize;
    (0..=n).map(|k| k as f64 * dt).collect()
}

/// The course of a lane change (module docs for the path).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LaneChangeCourse {
    /// Lateral offset Y (m), positive to the left (+y).
    pub offset: f64,
    /// Longitudinal length of one lane change (m).
    pub length: f64,
    /// `Some(d)`: a double lane change, back to the first lane after running `d` (m) in the
    /// other; `None`: a single lane change.
    pub hold: Option<f64>,
}

impl LaneChangeCourse {
    /// The AVTP double lane change as the shipped scenes idealize it: 3.66 m (12 ft) over
    /// 30.5 m (100 ft), 15.2 m (50 ft) in the other lane, then back.
    pub const AVTP: Self = Self { offset: 3.66, length: 30.5, hold: Some(15.2) };

    fn validate(&self) -> Result<(), AncfError> {
        check("offset", self.offset, self.offset != 0.0, "non-zero (m)")?;
        check("length", self.length, self.length > 0.0, "> 0 (m)")?;
        if let Some(h) = self.hold {
            check("hold", h, h >= 0.0, ">= 0 (m)")?;
        }
        Ok(())
    }
}

/// Lane change at `speed` (m/s) by `offset` (m) over `length` (m), starting after
/// `t_before` (s) of straight running and sampled every `dt` (s) until `t_after` (s) after
/// its end (module docs for the path). A single lane change; [`lane_change_course`] runs
/// any [`LaneChangeCourse`].
pub fn lane_change(
    speed: f64,
    offset: f64,
    length: f64,
    t_before: f64,
    t_after: f64,
    dt: f64,
) -> Result<Maneuver, AncfError> {
    lane_change_course(speed, &LaneChangeCourse { offset, length, hold: None }, t_before, t_after, dt)
}

/// The lane change (single or double) of `course` at `speed` (m/s), starting after
/// `t_before` (s), sampled every `dt` (s) until `t_after` (s) after its end.
pub fn lane_change_course(
    speed: f64,
    course: &LaneChangeCourse,
    t_before: f64,
    t_after: f64,
    dt: f64,
) -> Result<Maneuver, AncfError> {
    check("speed", speed, speed > 0.0, "> 0 (m/s)")?;
    course.validate()?;
    check_timing(t_before, t_after, dt)?;
    let (offset, tl) = (course.offset, course.length / speed);
    // (start time, sign) of each lane change
    let mut segments = vec![(t_before, 1.0)];
    if let Some(hold) = course.hold {
        segments.push((t_before + tl + hold / speed, -1.0));
    }
    let end = segments.last().map_or(t_before, |s| s.0) + tl;
    let times = sample_times(end + t_after, dt);
    // the pose at t; `side` < 0 / > 0: the limit from the left / right (the jerk, and so the
    // angular acceleration of the heading, jumps where a lane change starts and ends)
    let pose = |t: f64, side: f64| {
        let (mut y, mut yd, mut ydd, mut yddd) = (0.0, 0.0, 0.0, 0.0);
        for &(t0, sign) in &segments {
            let s = ((t - t0) / tl).clamp(0.0, 1.0);
            let w = 2.0 * PI * s;
            y += sign * offset * (s - w.sin() / (2.0 * PI));
            let inside = if side > 0.0 {
                t >= t0 && t < t0 + tl
            } else if side < 0.0 {
                t > t0 && t <= t0 + tl
            } else {
                t > t0 && t < t0 + tl
            };
            if inside {
                yd += sign * offset / tl * (1.0 - w.cos());
                ydd += sign * 2.0 * PI * offset / (tl * tl) * w.sin();
                yddd += sign * 4.0 * PI * PI * offset / (tl * tl * tl) * w.cos();
            }
        }
        let d = speed * speed + yd * yd;
        let psi = yd.atan2(speed);
        let psid = speed * ydd / d;
        let psidd = speed * (yddd * d - 2.0 * yd * ydd * ydd) / (d * d);
        PoseInput {
            position: [speed * t, y, 0.0],
            rotation: rot_z(psi),
            velocity: [speed, yd, 0.0],
            angular_velocity: [0.0, 0.0, psid],
            acceleration: [0.0, ydd, 0.0],
            angular_acceleration: [0.0, 0.0, psidd],
        }
    };
    let poses = times.iter().map(|&t| pose(t, 0.0)).collect();
    // starts and ends of the lane changes, once each (with `hold = 0` the first end is the
    // second start)
    let mut kinks: Vec<f64> = segments.iter().flat_map(|&(t0, _)| [t0, t0 + tl]).filter(|&t| t > 0.0).collect();
    kinks.dedup();
    let jumps = kinks.into_iter().map(|t| Jump { time: t, before: pose(t, -1.0), after: pose(t, 1.0) }).collect();
    Ok(Maneuver { name: format!("lane_change_{:.0}mph", speed / MPH), times, poses, jumps })
}

/// Vehicle data of the bump maneuvers (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BumpVehicle {
    /// Distance between front and rear axle (m).
    pub wheelbase: f64,
    /// Wheel radius (m), for the envelope over half-round bumps.
    pub wheel_radius: f64,
    /// Suspension natural frequency (Hz).
    pub frequency: f64,
    /// Suspension damping ratio.
    pub damping_ratio: f64,
}

impl Default for BumpVehicle {
    fn default() -> Self {
        Self { wheelbase: 3.9, wheel_radius: 0.53, frequency: 2.0, damping_ratio: 0.3 }
    }
}

impl BumpVehicle {
    fn validate(&self) -> Result<(), AncfError> {
        check("wheelbase", self.wheelbase, self.wheelbase > 0.0, "> 0 (m)")?;
        check("wheel_radius", self.wheel_radius, self.wheel_radius > 0.0, "> 0 (m)")?;
        check("frequency", self.frequency, self.frequency > 0.0, "> 0 (Hz)")?;
        check("damping_ratio", self.damping_ratio, self.damping_ratio >= 0.0, ">= 0")
    }
}

/// One axle of [`bump_response`]: the sprung mass's heave z (from its static position), its
/// rate, and, while the wheel is off the road, the wheel centre's height `uw`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Axle {
    z: f64,
    zd: f64,
    uw: f64,
    flying: bool,
}

/// Heave/pitch response of `vehicle` crossing a profile `rise(x, side) -> (u, du/dx)` (x
/// from the front axle's start position; `side` −1 / +1: the limits from the left / right at a
/// kink, 0 elsewhere) with kinks at `kinks` (m), at `speed`; sampled every `dt` for
/// `duration`. The RK4 steps (≤ 0.1 ms) end on every kink under each axle, so the
/// piecewise-smooth response is integrated to fourth order and each kink is a [`Jump`].
///
/// The wheel is massless and the road can only push it: where the suspension would need the
/// road to pull (g + z̈ < 0, the sprung mass driven down faster than it falls), the wheel
/// leaves the road. In flight the suspension carries no force, so the sprung mass falls
/// freely (z̈ = −g) while the spring and damper extend the wheel: 2ζω (u̇_w − ż) = −g − ω² (u_w − z)
/// (with ζ = 0, u_w = z − g/ω²). The wheel lands where u_w comes back down to the profile;
/// the damper then carries the wheel's descent rate relative to the road, a jump of z̈
/// (a [`Jump`] at the RK4 step where it lands). Modes switch at the start of a 0.1 ms step.
fn bump_response(
    name: String,
    rise: &dyn Fn(f64, f64) -> (f64, f64),
    kinks: &[f64],
    speed: f64,
    vehicle: &BumpVehicle,
    duration: f64,
    dt: f64,
) -> Maneuver {
    const SIDE: f64 = 1e-9; // m: a point just beside a kink
    let g = ancf_core::constants::GRAVITY;
    let wn = 2.0 * PI * vehicle.frequency;
    let zeta = vehicle.damping_ratio;
    let wb = vehicle.wheelbase;
    // front offset 0, rear offset W
    let offsets = [0.0, wb];
    // the road under the axle at `offset` at time t (side: as `rise`): height and rate
    let road = |t: f64, offset: f64, side: f64| {
        let (u, du) = rise(speed * t - offset + side * SIDE, side);
        (u, du * speed)
    };
    // z̈ of an axle on the road
    let on_road = |t: f64, z: f64, zd: f64, offset: f64, side: f64| {
        let (u, ud) = road(t, offset, side);
        wn * wn * (u - z) + 2.0 * zeta * wn * (ud - zd)
    };
    // u̇_w of a wheel in flight
    let extension = |z: f64, zd: f64, uw: f64| zd - (g + wn * wn * (uw - z)) / (2.0 * zeta * wn);
    // z̈ of an axle in its mode; a wheel on the road that would need a pull is leaving it
    let accel = |t: f64, a: &Axle, offset: f64, side: f64| {
        if a.flying { -g } else { on_road(t, a.z, a.zd, offset, side).max(-g) }
    };
    // switch modes at time t (side as `rise`); true where a wheel landed
    let switch = |t: f64, st: &mut [Axle; 2], side: f64| {
        let mut landed = false;
        for (a, o) in st.iter_mut().zip(offsets) {
            let (u, _) = road(t, o, side);
            if !a.flying && g + on_road(t, a.z, a.zd, o, side) < 0.0 {
                *a = Axle { uw: u, flying: true, ..*a };
            } else if a.flying && a.uw <= u {
                if g + on_road(t, a.z, a.zd, o, side) >= 0.0 {
                    *a = Axle { uw: u, flying: false, ..*a };
                    landed = true;
                } else {
                    a.uw = u; // grazing: on the road, carrying nothing
                }
            }
        }
        landed
    };
    let pose = |t: f64, st: &[Axle; 2], side: f64| {
        let acc: [f64; 2] = std::array::from_fn(|a| accel(t, &st[a], offsets[a], side));
        let (zf, zr) = (st[0], st[1]);
        let th = (zr.z - zf.z) / wb;
        PoseInput {
            position: [speed * t - 0.5 * wb, 0.0, 0.5 * (zf.z + zr.z)],
            rotation: rot_y(th),
            velocity: [speed, 0.0, 0.5 * (zf.zd + zr.zd)],
            angular_velocity: [0.0, (zr.zd - zf.zd) / wb, 0.0],
            acceleration: [0.0, 0.0, 0.5 * (acc[0] + acc[1])],
            angular_acceleration: [0.0, (acc[1] - acc[0]) / wb, 0.0],
        }
    };
    // RK4 from t0 to t1 (no kink strictly inside), switching modes at each step's start; the
    // landings are appended to `jumps`
    let advance = |st: &mut [Axle; 2], t0: f64, t1: f64, jumps: &mut Vec<Jump>| {
        let n = ((t1 - t0) / 1e-4).ceil().max(1.0) as usize;
        let hs = (t1 - t0) / n as f64;
        for j in 0..n {
            let ts = t0 + j as f64 * hs;
            let (s1, s4) = (if j == 0 { 1.0 } else { 0.0 }, if j + 1 == n { -1.0 } else { 0.0 });
            let before = *st;
            if switch(ts, st, s1) {
                let (b, a) = (pose(ts, &before, s1), pose(ts, st, s1));
                match jumps.last_mut() {
                    Some(last) if last.time == ts => last.after = a,
                    _ => jumps.push(Jump { time: ts, before: b, after: a }),
                }
            }
            for (ax, &o) in st.iter_mut().zip(&offsets) {
                if ax.flying {
                    // z̈ = −g exactly; the wheel's extension by RK4 (algebraic without damping)
                    let (z, zd, uw) = (ax.z, ax.zd, ax.uw);
                    let (z1, zd1) = (z + hs * zd - 0.5 * g * hs * hs, zd - g * hs);
                    let uw1 = if zeta > 0.0 {
                        let (zm, zdm) = (z + 0.5 * hs * zd - 0.125 * g * hs * hs, zd - 0.5 * g * hs);
                        let k1 = extension(z, zd, uw);
                        let k2 = extension(zm, zdm, uw + 0.5 * hs * k1);
                        let k3 = extension(zm, zdm, uw + 0.5 * hs * k2);
                        let k4 = extension(z1, zd1, uw + hs * k3);
                        uw + hs / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
                    } else {
                        z1 - g / (wn * wn)
                    };
                    *ax = Axle { z: z1, zd: zd1, uw: uw1, flying: true };
                } else {
                    let (z, v) = (ax.z, ax.zd);
                    let rhs = |t: f64, z: f64, zd: f64, side: f64| on_road(t, z, zd, o, side);
                    let k1 = (v, rhs(ts, z, v, s1));
                    let k2 = (v + 0.5 * hs * k1.1, rhs(ts + 0.5 * hs, z + 0.5 * hs * k1.0, v + 0.5 * hs * k1.1, 0.0));
                    let k3 = (v + 0.5 * hs * k2.1, rhs(ts + 0.5 * hs, z + 0.5 * hs * k2.0, v + 0.5 * hs * k2.1, 0.0));
                    let k4 = (v + hs * k3.1, rhs(ts + hs, z + hs * k3.0, v + hs * k3.1, s4));
                    ax.z = z + hs / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
                    ax.zd = v + hs / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
                }
            }
        }
    };
    let mut breaks: Vec<f64> =
        kinks.iter().flat_map(|&x| offsets.map(|o| (x + o) / speed)).filter(|&t| t > 0.0 && t < duration).collect();
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    let times = sample_times(duration, dt);
    let mut st = [Axle { z: 0.0, zd: 0.0, uw: 0.0, flying: false }; 2];
    let mut poses = Vec::with_capacity(times.len());
    let mut jumps = Vec::with_capacity(breaks.len());
    let mut next = breaks.iter().copied().peekable();
    let mut now = 0.0;
    for &t in &times {
        while let Some(b) = next.next_if(|&b| b <= t) {
            if b > now {
                advance(&mut st, now, b, &mut jumps);
                now = b;
            }
            jumps.push(Jump { time: b, before: pose(b, &st, -1.0), after: pose(b, &st, 1.0) });
        }
        if t > now {
            advance(&mut st, now, t, &mut jumps);
            now = t;
        }
        poses.push(pose(t, &st, 0.0));
    }
    Maneuver { name, times, poses, jumps }
}

/// The profile of a bump (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BumpProfile {
    /// Half-round symmetric bump of radius = height `height` (m).
    HalfRound {
        /// Height (m).
        height: f64,
    },
    /// Trapezoidal bump: ramp up over `up_length`, flat top `top_length`, ramp down over
    /// `down_length` (m).
    Trapezoid {
        /// Height (m).
        height: f64,
        /// Ramp-up length (m).
        up_length: f64,
        /// Flat-top length (m).
        top_length: f64,
        /// Ramp-down length (m).
        down_length: f64,
    },
}

impl BumpProfile {
    /// Seed 003's asymmetric trapezoid of height `height` as the shipped scenes idealize it
    /// (the seed gives no dimensions): ramp up 4 H, flat top 2 H, steep ramp down H.
    pub fn seed003_trapezoid(height: f64) -> Self {
        Self::Trapezoid { height, up_length: 4.0 * height, top_length: 2.0 * height, down_length: height }
    }
}

/// Half-round symmetric bump of height (= radius) `height` (m) crossed at `speed` (m/s);
/// the front wheel meets the bump after `t_before` (s); sampled every `dt` (s) until
/// `t_after` (s) after the rear wheel has left it.
pub fn half_round_bump(
    height: f64,
    speed: f64,
    vehicle: &BumpVehicle,
    t_before: f64,
    t_after: f64,
    dt: f64,
) -> Result<Maneuver, AncfError> {
    bump(&BumpProfile::HalfRound { height }, speed, vehicle, t_before, t_after, dt)
}

/// Trapezoidal bump of height `height` (m): ramp up over `up_length`, flat top
/// `top_length`, ramp down over `down_length` (m), crossed at `speed` (m/s); timing as
/// [`half_round_bump`].
#[allow(clippy::too_many_arguments)]
pub fn trapezoidal_bump(
    height: f64,
    up_length: f64,
    top_length: f64,
    down_length: f64,
    speed: f64,
    vehicle: &BumpVehicle,
    t_before: f64,
    t_after: f64,
    dt: f64,
) -> Result<Maneuver, AncfError> {
    let profile = BumpProfile::Trapezoid { height, up_length, top_length, down_length };
    bump(&profile, speed, vehicle, t_before, t_after, dt)
}

/// `vehicle` crossing the bump `profile` at `speed` (m/s): the front wheel meets the bump
/// after `t_before` (s); sampled every `dt` (s) until `t_after` (s) after the rear wheel
/// has left it.
pub fn bump(
    profile: &BumpProfile,
    speed: f64,
    vehicle: &BumpVehicle,
    t_before: f64,
    t_after: f64,
    dt: f64,
) -> Result<Maneuver, AncfError> {
    check("speed", speed, speed > 0.0, "> 0 (m/s)")?;
    vehicle.validate()?;
    check_timing(t_before, t_after, dt)?;
    let x0 = speed * t_before;
    type Rise = Box<dyn Fn(f64, f64) -> (f64, f64)>;
    let (rise, kinks, length, name): (Rise, Vec<f64>, f64, String) = match *profile {
        BumpProfile::HalfRound { height } => {
            check("height", height, height > 0.0, "> 0 (m)")?;
            let rw = vehicle.wheel_radius;
            let rr = height + rw;
            let half = (rr * rr - rw * rw).sqrt();
            let xc = x0 + half;
            let rise = move |x: f64, _side: f64| {
                let d = x - xc;
                if d.abs() >= half {
                    (0.0, 0.0)
                } else {
                    let s = (rr * rr - d * d).sqrt();
                    (s - rw, -d / s)
                }
            };
            let name = format!("half_round_{:.0}in_{:.0}mph", height / INCH, speed / MPH);
            (Box::new(rise), vec![xc - half, xc + half], 2.0 * half, name)
        }
        BumpProfile::Trapezoid { height, up_length, top_length, down_length } => {
            check("height", height, height > 0.0, "> 0 (m)")?;
            check("up_length", up_length, up_length > 0.0, "> 0 (m)")?;
            check("top_length", top_length, top_length >= 0.0, ">= 0 (m)")?;
            check("down_length", down_length, down_length > 0.0, "> 0 (m)")?;
            let (x1, x2) = (x0 + up_length, x0 + up_length + top_length);
            let x3 = x2 + down_length;
            let rise = move |x: f64, _side: f64| {
                if x <= x0 || x >= x3 {
                    (0.0, 0.0)
                } else if x < x1 {
                    (height * (x - x0) / up_length, height / up_length)
                } else if x <= x2 {
                    (height, 0.0)
                } else {
                    (height * (x3 - x) / down_length, -height / down_length)
                }
            };
            let name = format!("trapezoid_{:.0}in_{:.0}mph", height / INCH, speed / MPH);
            (Box::new(rise), vec![x0, x1, x2, x3], x3 - x0, name)
        }
    };
    let duration = t_before + (length + vehicle.wheelbase) / speed + t_after;
    Ok(bump_response(name, &*rise, &kinks, speed, vehicle, duration, dt))
}

/// One maneuver, as a scene names it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ManeuverSpec {
    /// A lane change at `speed` (m/s) on `course`.
    LaneChange {
        /// Forward speed (m/s).
        speed: f64,
        /// The course.
        course: LaneChangeCourse,
    },
    /// `vehicle` crossing a bump at `speed` (m/s).
    Bump {
        /// Forward speed (m/s).
        speed: f64,
        /// The bump.
        profile: BumpProfile,
        /// The vehicle.
        vehicle: BumpVehicle,
    },
}

impl ManeuverSpec {
    /// The maneuver starting after `t_before` (s), sampled every `dt` (s) until `t_after` (s)
    /// after its end.
    pub fn build(&self, t_before: f64, t_after: f64, dt: f64) -> Result<Maneuver, AncfError> {
        match self {
            Self::LaneChange { speed, course } => lane_change_course(*speed, course, t_before, t_after, dt),
            Self::Bump { speed, profile, vehicle } => bump(profile, *speed, vehicle, t_before, t_after, dt),
        }
    }

    /// Seed 003's six maneuvers with the dimensions of the module docs (those of the
    /// shipped `swri_*` scenes), in the seed's order.
    pub fn seed003() -> [Self; 6] {
        let vehicle = BumpVehicle::default();
        let lane = |mph: f64| Self::LaneChange { speed: mph * MPH, course: LaneChangeCourse::AVTP };
        let half = |inch: f64, mph: f64| Self::Bump {
            speed: mph * MPH,
            profile: BumpProfile::HalfRound { height: inch * INCH },
            vehicle,
        };
        let trap = |inch: f64, mph: f64| Self::Bump {
            speed: mph * MPH,
            profile: BumpProfile::seed003_trapezoid(inch * INCH),
            vehicle,
        };
        [lane(20.0), lane(40.0), half(9.0, 10.0), half(12.0, 5.0), trap(9.0, 15.0), trap(12.0, 10.0)]
    }
}

/// The six maneuvers of seed 003 §3 ([`ManeuverSpec::seed003`]), each starting after
/// 0.5 s, sampled every `dt` (s), each followed by `t_after` (s) of free sloshing.
pub fn seed003_maneuvers(dt: f64, t_after: f64) -> Result<Vec<Maneuver>, AncfError> {
    ManeuverSpec::seed003().iter().map(|m| m.build(0.5, t_after, dt)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn norm(v: [f64; 3]) -> f64 {
        v.iter().map(|x| x * x).sum::<f64>().sqrt()
    }

    /// The prescribed motion a slosh scene runs reproduces the maneuver's poses: the global
    /// accelerations at every sample, and (integrated) the lateral/vertical position,
    /// velocity, rotation and angular velocity, up to the dropped forward motion.
    #[test]
    fn prescribed_motion_reproduces_every_seed003_maneuver() {
        for m in seed003_maneuvers(1e-3, 1.0).unwrap() {
            let pm = m.prescribed_motion().unwrap();
            let axis = pm.rotation.as_ref().expect("every seed 003 maneuver rotates").0;
            let expected = if m.name.starts_with("lane_change") { [0.0, 0.0, 1.0] } else { [0.0, 1.0, 0.0] };
            assert!(norm(std::array::from_fn(|i| axis[i] - expected[i])) < 1e-12, "{}: axis {axis:?}", m.name);
            let p0 = m.poses[0];
            let scale_r = m.poses.iter().map(|p| p.position[1].abs() + p.position[2].abs()).fold(0.0, f64::max);
            let scale_w = m.poses.iter().map(|p| norm(p.angular_velocity)).fold(0.0, f64::max);
            let (mut err_r, mut err_v, mut err_a, mut err_rot, mut err_w) =
                (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
            for (&t, p) in m.times.iter().zip(&m.poses) {
                if m.jumps.iter().any(|j| j.time == t) {
                    continue; // the sample is one of the two limits there
                }
                let s = pm.state(t);
                let k = &s.kinematics;
                for d in 1..3 {
                    err_r = err_r.max((k.position[d] - (p.position[d] - p0.position[d])).abs());
                    err_v = err_v.max((k.velocity[d] - p.velocity[d]).abs());
                }
                // the forward velocity is dropped, nothing else along x
                assert_eq!(k.velocity[0], 0.0);
                for d in 0..3 {
                    err_a = err_a.max((s.acceleration[d] - p.acceleration[d]).abs());
                    err_w = err_w.max((k.angular_velocity[d] - p.angular_velocity[d]).abs());
                    for e in 0..3 {
                        err_rot = err_rot.max((k.rotation[(d, e)] - p.rotation[d][e]).abs());
                    }
                }
            }
            // point samples across the jumps (before they were kept exactly) gave position
            // errors of up to 15 % of the motion and 1.8e-2 rad of pitch on these maneuvers
            assert!(err_a < 1e-6, "{}: acceleration {err_a}", m.name);
            assert!(err_r < 1e-3 * scale_r, "{}: position {err_r} of {scale_r}", m.name);
            assert!(err_v < 1e-3 * scale_r, "{}: velocity {err_v}", m.name);
            assert!(err_w < 1e-4 * scale_w, "{}: angular velocity {err_w} of {scale_w}", m.name);
            assert!(err_rot < 1e-4, "{}: rotation {err_rot}", m.name);
        }
    }

    /// The road only pushes: neither axle's sprung mass ever accelerates down faster than it
    /// falls, the bumps that drove the old model below −g make a wheel fly, in flight the
    /// sprung mass falls at exactly g, and after the bump the vehicle comes to rest. (Before
    /// the wheel could leave the road the axles reached −4.3 g on the 9″ trapezoid.)
    #[test]
    fn a_wheel_leaves_the_road_rather_than_pull_the_vehicle_down() {
        let g = ancf_core::constants::GRAVITY;
        let wb = BumpVehicle::default().wheelbase;
        let mut flew = 0;
        for m in seed003_maneuvers(1e-3, 2.0).unwrap().into_iter().filter(|m| !m.name.starts_with("lane")) {
            let poses = m.poses.iter().chain(m.jumps.iter().flat_map(|j| [&j.before, &j.after]));
            let mut at_g = 0;
            for p in poses {
                // each axle's heave acceleration from the tank's (midway) heave and pitch
                let (a, th) = (p.acceleration[2], p.angular_acceleration[1]);
                for axle in [a - 0.5 * wb * th, a + 0.5 * wb * th] {
                    assert!(axle >= -g * (1.0 + 1e-12), "{}: an axle at {axle} m/s²", m.name);
                    if (axle + g).abs() < 1e-9 * g {
                        at_g += 1;
                    }
                }
            }
            if at_g > 0 {
                flew += 1;
            }
            let last = m.poses.last().unwrap();
            assert!(last.position[2].abs() < 2e-3 && last.velocity[2].abs() < 2e-2, "{}: {last:?}", m.name);
        }
        // the 9″ half-round at 10 mph and both trapezoids throw a wheel (the 12″ half-round at 5 mph
        // measured −8.4 m/s² on its tank before, each axle alone below −g: it flies too)
        assert_eq!(flew, 4);
    }

    #[test]
    fn the_avtp_course_is_a_double_lane_change_back_to_the_first_lane() {
        let v = 40.0 * MPH;
        let m = lane_change_course(v, &LaneChangeCourse::AVTP, 0.2, 0.5, 1e-3).unwrap();
        let c = LaneChangeCourse::AVTP;
        let peak = m.poses.iter().map(|p| p.position[1]).fold(0.0, f64::max);
        assert!((peak - c.offset).abs() < 1e-9, "{peak}");
        let last = m.poses.last().unwrap();
        assert!(last.position[1].abs() < 1e-9 && last.velocity[1] == 0.0);
        // duration: two lane changes and the hold, then t_after
        let end = 0.2 + (2.0 * c.length + c.hold.unwrap()) / v + 0.5;
        assert!((m.times.last().unwrap() - end).abs() <= 1e-3, "{} vs {end}", m.times.last().unwrap());
        let cut = m.until(1.0);
        assert!(*cut.times.last().unwrap() >= 1.0 && cut.times[cut.times.len() - 2] < 1.0);
        // no hold: straight back (the end of the first lane change is the start of the second)
        let back = LaneChangeCourse { hold: Some(0.0), ..c };
        let m = lane_change_course(v, &back, 0.2, 0.5, 1e-3).unwrap();
        assert_eq!(m.jumps.len(), 3);
        let pm = m.prescribed_motion().unwrap();
        let (y, yd, _) = pm.translation[1].eval(*m.times.last().unwrap());
        assert!(y.abs() < 1e-4 && yd.abs() < 1e-6, "{y} {yd}");
    }

    #[test]
    fn a_rotation_about_a_moving_axis_is_refused() {
        let mut m = half_round_bump(0.2, 3.0, &BumpVehicle::default(), 0.1, 0.2, 1e-3).unwrap();
        let k = m.poses.len() / 2;
        m.poses[k].angular_velocity[0] = 0.1;
        let e = m.prescribed_motion().unwrap_err().to_string();
        assert!(e.contains("rotation about one fixed axis") && e.contains("t = "), "{e}");
    }
}
