//! Seed 003's maneuvers (§3, Phase 1 tests of the small-scale FMTV tank) as prescribed
//! tank motions: pose histories in the global frame, and their tank-frame form.
//!
//! Seed 003 names the maneuvers (AVTP lane changes at 20 and 40 mph; 9″ half-round
//! symmetric bump at 10 mph; 12″ half-round at 5 mph; 9″ trapezoidal asymmetric bump at
//! 15 mph; 12″ trapezoidal at 10 mph) but gives no course or profile dimensions, nor the
//! vehicle data. The values chosen here are documented on each function:
//!
//! - **Lane change**: the vehicle keeps its forward speed V along global x and moves
//!   laterally by `offset` (default 12 ft = 3.658 m, one lane) over a course `length`
//!   (default 120 ft = 36.58 m), duration T = length / V, on the smooth path
//!   y = Y (s − sin 2πs / 2π), s = t/T (lateral acceleration one full sine period, zero
//!   velocity and acceleration at both ends). The tank heading follows the path tangent,
//!   ψ = atan(ẏ / V). Peak lateral acceleration 2πY/T²: 0.14 g at 20 mph, 0.56 g at 40 mph.
//! - **Bumps**: a two-axle vehicle (wheelbase W) crosses the bump at constant speed; each
//!   axle's wheel-centre rise u(t) passes through a quarter-car suspension
//!   z̈ = ω²(u − z) + 2ζω(u̇ − ż) (natural frequency `frequency`, damping ratio
//!   `damping_ratio`; integrated with RK4 at 0.1 ms). The tank origin sits midway between
//!   the axles: heave (z_f + z_r)/2, pitch θ = (z_r − z_f)/W about +y (nose up when the
//!   front axle rises). Half-round bump of radius H: the wheel (radius r_w) rolls over it,
//!   u = √((H + r_w)² − d²) − r_w (d = horizontal distance to the bump centre, while
//!   positive). Trapezoidal asymmetric bump: ramp up over `up_length` (default 4 H), flat
//!   top `top_length` (default 0.3 m), ramp down over `down_length` (default H); the wheel
//!   centre follows the profile. Defaults [`BumpVehicle::default`]: W = 3.9 m,
//!   r_w = 0.53 m, 1.5 Hz, ζ = 0.3 (an FMTV-like truck; assumed, not from the seed).
//! - The motion of the full-size vehicle is applied to the tank as is (the seed's tank is
//!   the small-scale SwRI elliptical tank, [`ancf_core::mesh::EllipticCylinderSpec::swri`]).

use std::f64::consts::PI;

use super::participant::{CosimError, PoseInput};
use crate::slosh::TankFrameSample;

/// One mile per hour in m/s.
pub const MPH: f64 = 0.44704;
/// One inch in m.
pub const INCH: f64 = 0.0254;
/// One foot in m.
pub const FOOT: f64 = 0.3048;

/// A prescribed tank motion sampled at uniform times.
#[derive(Debug, Clone, PartialEq)]
pub struct Maneuver {
    /// Short name (file-name safe).
    pub name: String,
    /// Sample times (s), uniform, starting at 0.
    pub times: Vec<f64>,
    /// Tank pose, velocity and acceleration at each time (global frame).
    pub poses: Vec<PoseInput>,
}

impl Maneuver {
    /// Seed 003's tank-frame form of every sample (gravity −g along global z).
    pub fn tank_frame(&self, gravity: f64) -> Result<Vec<TankFrameSample>, CosimError> {
        self.poses.iter().map(|p| p.to_tank_frame(gravity)).collect()
    }
}

fn check(field: &str, v: f64, ok: bool, allowed: &str) -> Result<(), CosimError> {
    if ok && v.is_finite() {
        Ok(())
    } else {
        Err(CosimError::InvalidParameter { field: field.into(), value: v.to_string(), allowed: allowed.into() })
    }
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

/// Lane change at `speed` (m/s) by `offset` (m) over `length` (m), starting after
/// `t_before` (s) of straight running and sampled every `dt` (s) until `t_after` (s) after
/// its end (module docs for the path).
pub fn lane_change(
    speed: f64,
    offset: f64,
    length: f64,
    t_before: f64,
    t_after: f64,
    dt: f64,
) -> Result<Maneuver, CosimError> {
    check("speed", speed, speed > 0.0, "> 0 (m/s)")?;
    check("offset", offset, true, "finite (m)")?;
    check("length", length, length > 0.0, "> 0 (m)")?;
    check("t_before", t_before, t_before >= 0.0, ">= 0 (s)")?;
    check("t_after", t_after, t_after >= 0.0, ">= 0 (s)")?;
    check("dt", dt, dt > 0.0, "> 0 (s)")?;
    let tl = length / speed;
    let times = sample_times(t_before + tl + t_after, dt);
    let poses = times
        .iter()
        .map(|&t| {
            let s = ((t - t_before) / tl).clamp(0.0, 1.0);
            let inside = t > t_before && t < t_before + tl;
            let w = 2.0 * PI * s;
            let y = offset * (s - w.sin() / (2.0 * PI));
            let (yd, ydd, yddd) = if inside {
                (
                    offset / tl * (1.0 - w.cos()),
                    2.0 * PI * offset / (tl * tl) * w.sin(),
                    4.0 * PI * PI * offset / (tl * tl * tl) * w.cos(),
                )
            } else {
                (0.0, 0.0, 0.0)
            };
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
        })
        .collect();
    Ok(Maneuver { name: format!("lane_change_{:.0}mph", speed / MPH), times, poses })
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
        Self { wheelbase: 3.9, wheel_radius: 0.53, frequency: 1.5, damping_ratio: 0.3 }
    }
}

impl BumpVehicle {
    fn validate(&self) -> Result<(), CosimError> {
        check("wheelbase", self.wheelbase, self.wheelbase > 0.0, "> 0 (m)")?;
        check("wheel_radius", self.wheel_radius, self.wheel_radius > 0.0, "> 0 (m)")?;
        check("frequency", self.frequency, self.frequency > 0.0, "> 0 (Hz)")?;
        check("damping_ratio", self.damping_ratio, self.damping_ratio >= 0.0, ">= 0")
    }
}

/// Heave/pitch response of `vehicle` crossing a profile `rise(x) -> (u, du/dx)` (x from
/// the front axle's start position) at `speed`; lead-in distance `lead` (m), sampled
/// every `dt` for `duration`.
fn bump_response(
    name: String,
    rise: &dyn Fn(f64) -> (f64, f64),
    speed: f64,
    vehicle: &BumpVehicle,
    duration: f64,
    dt: f64,
) -> Maneuver {
    let wn = 2.0 * PI * vehicle.frequency;
    let zeta = vehicle.damping_ratio;
    let wb = vehicle.wheelbase;
    // wheel input of an axle at time t: (u, u̇)
    let input = |t: f64, offset: f64| {
        let (u, du) = rise(speed * t - offset);
        (u, du * speed)
    };
    let rhs = |t: f64, z: f64, zd: f64, offset: f64| {
        let (u, ud) = input(t, offset);
        wn * wn * (u - z) + 2.0 * zeta * wn * (ud - zd)
    };
    let times = sample_times(duration, dt);
    let sub = ((dt / 1e-4).ceil() as usize).max(1);
    let hs = dt / sub as f64;
    // state per axle: (z, ż); front offset 0, rear offset W
    let mut st = [(0.0_f64, 0.0_f64); 2];
    let offsets = [0.0, wb];
    let mut poses = Vec::with_capacity(times.len());
    for (k, &t) in times.iter().enumerate() {
        if k > 0 {
            for j in 0..sub {
                let ts = times[k - 1] + j as f64 * hs;
                for (a, s) in st.iter_mut().enumerate() {
                    let o = offsets[a];
                    let (z, v) = *s;
                    let k1 = (v, rhs(ts, z, v, o));
                    let k2 = (v + 0.5 * hs * k1.1, rhs(ts + 0.5 * hs, z + 0.5 * hs * k1.0, v + 0.5 * hs * k1.1, o));
                    let k3 = (v + 0.5 * hs * k2.1, rhs(ts + 0.5 * hs, z + 0.5 * hs * k2.0, v + 0.5 * hs * k2.1, o));
                    let k4 = (v + hs * k3.1, rhs(ts + hs, z + hs * k3.0, v + hs * k3.1, o));
                    *s = (
                        z + hs / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0),
                        v + hs / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1),
                    );
                }
            }
        }
        let acc: Vec<f64> = (0..2).map(|a| rhs(t, st[a].0, st[a].1, offsets[a])).collect();
        let (zf, zr) = (st[0], st[1]);
        let heave = 0.5 * (zf.0 + zr.0);
        let heave_d = 0.5 * (zf.1 + zr.1);
        let heave_dd = 0.5 * (acc[0] + acc[1]);
        let th = (zr.0 - zf.0) / wb;
        let thd = (zr.1 - zf.1) / wb;
        let thdd = (acc[1] - acc[0]) / wb;
        poses.push(PoseInput {
            position: [speed * t - 0.5 * wb, 0.0, heave],
            rotation: rot_y(th),
            velocity: [speed, 0.0, heave_d],
            angular_velocity: [0.0, thd, 0.0],
            acceleration: [0.0, 0.0, heave_dd],
            angular_acceleration: [0.0, thdd, 0.0],
        });
    }
    Maneuver { name, times, poses }
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
) -> Result<Maneuver, CosimError> {
    check("height", height, height > 0.0, "> 0 (m)")?;
    check("speed", speed, speed > 0.0, "> 0 (m/s)")?;
    vehicle.validate()?;
    check("t_before", t_before, t_before >= 0.0, ">= 0 (s)")?;
    check("t_after", t_after, t_after >= 0.0, ">= 0 (s)")?;
    check("dt", dt, dt > 0.0, "> 0 (s)")?;
    let rr = height + vehicle.wheel_radius;
    let rw = vehicle.wheel_radius;
    let half = (rr * rr - rw * rw).sqrt();
    let xc = speed * t_before + half;
    let rise = move |x: f64| {
        let d = x - xc;
        if d.abs() >= half {
            (0.0, 0.0)
        } else {
            let s = (rr * rr - d * d).sqrt();
            (s - rw, -d / s)
        }
    };
    let duration = t_before + (2.0 * half + vehicle.wheelbase) / speed + t_after;
    let name = format!("half_round_{:.0}in_{:.0}mph", height / INCH, speed / MPH);
    Ok(bump_response(name, &rise, speed, vehicle, duration, dt))
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
) -> Result<Maneuver, CosimError> {
    check("height", height, height > 0.0, "> 0 (m)")?;
    check("up_length", up_length, up_length > 0.0, "> 0 (m)")?;
    check("top_length", top_length, top_length >= 0.0, ">= 0 (m)")?;
    check("down_length", down_length, down_length > 0.0, "> 0 (m)")?;
    check("speed", speed, speed > 0.0, "> 0 (m/s)")?;
    vehicle.validate()?;
    check("t_before", t_before, t_before >= 0.0, ">= 0 (s)")?;
    check("t_after", t_after, t_after >= 0.0, ">= 0 (s)")?;
    check("dt", dt, dt > 0.0, "> 0 (s)")?;
    let x0 = speed * t_before;
    let (x1, x2, x3) = (x0 + up_length, x0 + up_length + top_length, x0 + up_length + top_length + down_length);
    let rise = move |x: f64| {
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
    let duration = t_before + (x3 - x0 + vehicle.wheelbase) / speed + t_after;
    let name = format!("trapezoid_{:.0}in_{:.0}mph", height / INCH, speed / MPH);
    Ok(bump_response(name, &rise, speed, vehicle, duration, dt))
}

/// The six maneuvers of seed 003 §3 with the default dimensions of the module docs,
/// sampled every `dt` (s), each followed by `t_after` (s) of free sloshing.
pub fn seed003_maneuvers(dt: f64, t_after: f64) -> Result<Vec<Maneuver>, CosimError> {
    let v = BumpVehicle::default();
    let (offset, length) = (12.0 * FOOT, 120.0 * FOOT);
    let trap = |h: f64, mph: f64| trapezoidal_bump(h, 4.0 * h, 0.3, h, mph * MPH, &v, 0.5, t_after, dt);
    Ok(vec![
        lane_change(20.0 * MPH, offset, length, 0.5, t_after, dt)?,
        lane_change(40.0 * MPH, offset, length, 0.5, t_after, dt)?,
        half_round_bump(9.0 * INCH, 10.0 * MPH, &v, 0.5, t_after, dt)?,
        half_round_bump(12.0 * INCH, 5.0 * MPH, &v, 0.5, t_after, dt)?,
        trap(9.0 * INCH, 15.0)?,
        trap(12.0 * INCH, 10.0)?,
    ])
}
