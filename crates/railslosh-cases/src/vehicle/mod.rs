//! Validation cases of the vehicle model (JSON records like the element and slosh
//! cases):
//!
//! | case | what |
//! |---|---|
//! | `static-wheel-loads` | the tank car settles on tangent track with every wheel load equal to its static share within 1 %, without drifting |
//! | `balance-speed-curving` | on a 1000 m curve with 42.5 mm super-elevation (balance speed 60 km/h): left and right wheel loads equal within 5 % at the balance speed; the outer wheels carry more above it, the inner wheels below it |
//! | `lateral-stability` | at 60 km/h on tangent track a 2 mm lateral displacement of every wheelset decays |

use std::sync::Arc;

use ancf_core::error::{AncfError, Result, invalid};
use rail_mbs::mbs::SpeedProfile;
use rail_mbs::track::{Track, TrackPoint};
use rail_mbs::vehicle::{TankCarParams, TrainRecord, TrainScenario, run_train};

use crate::Record;

pub mod studies;

/// Names of the vehicle validation cases.
pub const CASES: [&str; 3] = ["static-wheel-loads", "balance-speed-curving", "lateral-stability"];

/// Runs one case; `quick` selects the short CI form.
pub fn run_case(name: &str, quick: bool) -> Result<Vec<Record>> {
    match name {
        "static-wheel-loads" => static_wheel_loads(quick),
        "balance-speed-curving" => balance_speed_curving(quick),
        "lateral-stability" => lateral_stability(quick),
        other => Err(invalid("case", other, &format!("one of {CASES:?}"))),
    }
}

/// Loaded car: the tank with 36 t of rigid lading 0.5 m below the tank axis (about a
/// half-full tank of crude oil).
fn loaded_car() -> Result<TankCarParams> {
    let mut p = TankCarParams::standard()?;
    p.lading = Some((36_000.0, -0.5));
    Ok(p)
}

fn run(sc: &TrainScenario) -> Result<TrainRecord> {
    match run_train(sc)? {
        Ok(r) => Ok(r),
        Err(f) => {
            Err(AncfError::Solver(format!("vehicle run failed: {} (after {} samples)", f.error, f.record.t.len())))
        }
    }
}

fn tangent_track() -> Result<Arc<Track>> {
    let t = Track::straight(5000.0).map_err(|e| invalid("track", e, "a valid track"))?;
    Ok(Arc::new(t))
}

fn static_wheel_loads(quick: bool) -> Result<Vec<Record>> {
    let c = "static-wheel-loads";
    let sc = TrainScenario::single(loaded_car()?, tangent_track()?, 50.0, 0.0, if quick { 0.5 } else { 2.0 });
    let rec = run(&sc)?;
    let q0 = rec.static_wheel_load;
    let last = rec.wheel_vertical.last().ok_or_else(|| AncfError::Solver("no samples".into()))?;
    let worst = last.iter().flat_map(|w| w.iter()).map(|q| (q - q0).abs() / q0).fold(0.0, f64::max);
    let drift = rec.tank_station.last().map_or(f64::NAN, |s| (s[0] - 50.0).abs());
    Ok(vec![
        Record::at_most(
            c,
            format!("max |Q - Q_static| / Q_static over the 8 wheels (Q_static = {q0:.0} N, {} DOF)", rec.dof),
            worst,
            0.01,
        ),
        Record::at_most(c, "longitudinal drift of the tank centre (m)".to_string(), drift, 1e-3),
    ])
}

/// Curve of radius 1000 m, super-elevation for a 60 km/h balance speed over the 1.5 m
/// cant base, rail cant 1:40, the car already on the curve.
fn curve() -> Result<(Arc<Track>, f64)> {
    let r = 1000.0;
    let v_bal: f64 = 60.0 / 3.6;
    let e = v_bal * v_bal * Track::DEFAULT_CANT_BASE / (rail_mbs::track::GRAVITY * r);
    let pts = vec![
        TrackPoint::new(0.0, 1.0 / r, e, 0.0, 0.025, -0.025),
        TrackPoint::new(5000.0, 1.0 / r, e, 0.0, 0.025, -0.025),
    ];
    let t = Track::new(pts).map_err(|e| invalid("track", e, "a valid track"))?;
    let vb = t.balance_speed(10.0).unwrap_or(f64::NAN);
    Ok((Arc::new(t), vb))
}

fn balance_speed_curving(quick: bool) -> Result<Vec<Record>> {
    let c = "balance-speed-curving";
    let (track, vb) = curve()?;
    let (t_end, t_avg) = if quick { (2.5, 1.3) } else { (6.0, 2.4) };
    let mut car = loaded_car()?;
    // A US freight car runs on AAR-1B (1:20 tread) wheels; see docs/validation.md for S1002.
    car.contact.wheel_profile = rail_mbs::profile::aar1b_wheel_approx().map_err(|e| invalid("profile", e, "valid"))?;
    let speeds = [0.6 * vb, vb, 1.4 * vb];
    let results: Vec<Result<TrainRecord>> = std::thread::scope(|s| {
        let handles: Vec<_> = speeds
            .iter()
            .map(|&v| {
                let mut sc = TrainScenario::single(car.clone(), track.clone(), 50.0, v, t_end);
                sc.drive = Some(SpeedProfile::Constant(v));
                sc.record_every = 0.02;
                s.spawn(move || run(&sc))
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap_or_else(|_| Err(AncfError::Solver("panic".into())))).collect()
    });
    // Outer rail of this left curve = right wheels (side 1).
    let mut ratio = [0.0; 3];
    for (k, r) in results.into_iter().enumerate() {
        let rec = r?;
        let (mut inner, mut outer) = (0.0, 0.0);
        for w in 0..4 {
            inner += rec.mean_vertical(t_avg, w, 0);
            outer += rec.mean_vertical(t_avg, w, 1);
        }
        ratio[k] = outer / inner;
    }
    Ok(vec![
        Record::abs(
            c,
            format!(
                "outer/inner wheel load at the balance speed {:.1} km/h (R 1000 m, AAR-1B approx. wheels)",
                vb * 3.6
            ),
            ratio[1],
            1.0,
            0.05,
        ),
        Record::less_than(
            c,
            format!("inner/outer wheel load - 1 at 1.4 x balance speed ({:.1} km/h), must be < 0", 1.4 * vb * 3.6),
            1.0 / ratio[2] - 1.0,
            0.0,
        ),
        Record::less_than(
            c,
            format!("outer/inner wheel load - 1 at 0.6 x balance speed ({:.1} km/h), must be < 0", 0.6 * vb * 3.6),
            ratio[0] - 1.0,
            0.0,
        ),
    ])
}

fn lateral_stability(quick: bool) -> Result<Vec<Record>> {
    let c = "lateral-stability";
    let v = 60.0 / 3.6;
    let mut sc = TrainScenario::single(loaded_car()?, tangent_track()?, 50.0, v, if quick { 2.0 } else { 5.0 });
    sc.drive = Some(SpeedProfile::Constant(v));
    sc.wheelset_lateral_offset = 2e-3;
    sc.record_every = 0.01;
    let rec = run(&sc)?;
    let amp = |t0: f64, t1: f64| {
        rec.t
            .iter()
            .zip(&rec.wheelset_lateral)
            .filter(|(t, _)| **t >= t0 && **t < t1)
            .flat_map(|(_, y)| y.iter().map(|v| v.abs()))
            .fold(0.0, f64::max)
    };
    let t_end = sc.t_end;
    let (a0, a1) = (amp(0.0, 0.5), amp(t_end - 0.5, t_end + 1.0));
    Ok(vec![Record::at_most(
        c,
        format!("wheelset lateral amplitude, last 0.5 s / first 0.5 s (2 mm initial offset, {:.0} km/h)", v * 3.6),
        a1 / a0,
        0.5,
    )])
}
