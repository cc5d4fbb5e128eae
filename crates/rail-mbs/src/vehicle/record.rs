//! A train run's record and how it is taken: [`TrainRecord`] (wheel loads, derailment
//! indicators, couplers, tanks), its samples of the vehicle state (`record_sample`), the load
//! filter ([`LoadFilter`], the hat-weighted mean and [`hat_mean_resample`]), and the loop that
//! steps the integrator and records at the recording times (`step_and_record`), which every
//! vehicle run's driver (`super::run::drive`) uses. Split from `run.rs` (issue 18: files over
//! ~600 lines).

use nalgebra::Vector3;

use super::run::{Observer, TrainScenario};
use super::tank_car::{CarBodies, wheel_loads};
use crate::integrator::{Hht, IntegratorError};
use crate::mbs::Multibody;
use crate::observe::step_to;
use crate::track::Track;

pub(crate) use super::load_filter::HatMean;
pub use super::load_filter::{LoadFilter, hat_mean_resample};

/// Recorded results of a train run. Arrays are indexed `[sample][...]`.
#[derive(Debug, Clone, Default)]
pub struct TrainRecord {
    /// Times, s.
    pub t: Vec<f64>,
    /// Vertical wheel load `Q`, N: `[sample][wheelset][left, right]`, wheelsets front to
    /// rear over all cars.
    pub wheel_vertical: Vec<Vec<[f64; 2]>>,
    /// Lateral wheel force `Y` (track-left positive), N, same layout.
    pub wheel_lateral: Vec<Vec<[f64; 2]>>,
    /// Lateral displacement of each wheelset from the centreline, m: `[sample][wheelset]`.
    pub wheelset_lateral: Vec<Vec<f64>>,
    /// Coupler forces (tension positive), N: `[sample][coupler]`.
    pub coupler_force: Vec<Vec<f64>>,
    /// Tank-centre arc length along the track, m: `[sample][car]`.
    pub tank_station: Vec<Vec<f64>>,
    /// Tank speed, m/s: `[sample][car]`.
    pub tank_speed: Vec<Vec<f64>>,
    /// Acceleration of each car body's reference point (the tank centre), in the car body's
    /// axes (x forward, y left, z up; gravity not included), m/s²: `[sample][car][x, y, z]`.
    /// A load channel: recorded through the [`LoadFilter`] like the wheel loads, so that the
    /// ride indices see no aliasing.
    pub car_acceleration: Vec<Vec<[f64; 3]>>,
    /// Static wheel load on level track, N.
    pub static_wheel_load: f64,
    /// Newton iterations, steps, rejected steps, Jacobian evaluations.
    pub newton_iterations: usize,
    /// Accepted steps.
    pub steps: usize,
    /// Rejected steps.
    pub rejected_steps: usize,
    /// Jacobian evaluations.
    pub jacobian_evaluations: usize,
    /// Wall time, s.
    pub wall_time: f64,
    /// Where the integrator's time went, s: system callbacks and assembly (forces,
    /// Jacobians), numeric factorizations, linear solves ([`crate::integrator::Stats`]).
    pub time_split: [f64; 3],
    /// Degrees of freedom of the model.
    pub dof: isize,
}

impl TrainRecord {
    /// Copies the integrator's counters (when it was built) and the wall time since `start`.
    pub(crate) fn finish(&mut self, stats: Option<&crate::integrator::Stats>, start: std::time::Instant) {
        if let Some(s) = stats {
            self.newton_iterations = s.newton_iterations;
            self.steps = s.steps;
            self.rejected_steps = s.rejected_steps;
            self.jacobian_evaluations = s.jacobian_evaluations;
            self.time_split =
                [s.time_assembly.as_secs_f64(), s.time_factorization.as_secs_f64(), s.time_solve.as_secs_f64()];
        }
        self.wall_time = start.elapsed().as_secs_f64();
    }

    /// Column names of [`Self::row`] for a train with `wheelsets` wheelsets, `couplers`
    /// couplers and `cars` cars (the layout of the rows a [`super::run_vehicle`] sink receives).
    pub fn columns(wheelsets: usize, couplers: usize, cars: usize) -> Vec<String> {
        let mut c = vec!["t".to_string()];
        for w in 0..wheelsets {
            for side in ["left", "right"] {
                c.push(format!("wheel_vertical[{w}].{side}"));
            }
        }
        for w in 0..wheelsets {
            for side in ["left", "right"] {
                c.push(format!("wheel_lateral[{w}].{side}"));
            }
        }
        c.extend((0..wheelsets).map(|w| format!("wheelset_lateral[{w}]")));
        c.extend((0..couplers).map(|k| format!("coupler_force[{k}]")));
        c.extend((0..cars).map(|k| format!("tank_station[{k}]")));
        c.extend((0..cars).map(|k| format!("tank_speed[{k}]")));
        for k in 0..cars {
            for axis in ["x", "y", "z"] {
                c.push(format!("car_acceleration[{k}].{axis}"));
            }
        }
        c
    }

    /// Sample `i` as one flat row in the order of [`Self::columns`].
    pub fn row(&self, i: usize) -> Vec<f64> {
        let mut r = vec![self.t[i]];
        r.extend(self.wheel_vertical[i].iter().flatten());
        r.extend(self.wheel_lateral[i].iter().flatten());
        r.extend(&self.wheelset_lateral[i]);
        r.extend(&self.coupler_force[i]);
        r.extend(&self.tank_station[i]);
        r.extend(&self.tank_speed[i]);
        r.extend(self.car_acceleration[i].iter().flatten());
        r
    }

    /// The load channels of sample `i` (filtered by [`LoadFilter`]): wheel `Q` and `Y` per
    /// wheelset and side, the coupler forces, then the car-body accelerations, appended to
    /// `out`.
    pub fn loads_into(&self, i: usize, out: &mut Vec<f64>) {
        out.extend(self.wheel_vertical[i].iter().flatten());
        out.extend(self.wheel_lateral[i].iter().flatten());
        out.extend(&self.coupler_force[i]);
        out.extend(self.car_acceleration[i].iter().flatten());
    }

    /// Replaces the load channels of sample `i` by `loads` (layout of
    /// [`TrainRecord::loads_into`]); returns how many values it used.
    pub fn set_loads(&mut self, i: usize, loads: &[f64]) -> usize {
        let mut it = loads.iter().copied();
        let mut n = 0;
        for w in self.wheel_vertical[i].iter_mut().chain(self.wheel_lateral[i].iter_mut()) {
            for x in w.iter_mut() {
                *x = it.next().unwrap_or(*x);
                n += 1;
            }
        }
        for x in self.coupler_force[i].iter_mut().chain(self.car_acceleration[i].iter_mut().flatten()) {
            *x = it.next().unwrap_or(*x);
            n += 1;
        }
        n
    }

    /// Removes every sample (keeps the run's metadata).
    pub(crate) fn clear_samples(&mut self) {
        self.t.clear();
        self.wheel_vertical.clear();
        self.wheel_lateral.clear();
        self.wheelset_lateral.clear();
        self.coupler_force.clear();
        self.tank_station.clear();
        self.tank_speed.clear();
        self.car_acceleration.clear();
    }

    /// Mean over samples with `t ≥ t0` of the vertical load of `(wheelset, side)`.
    pub fn mean_vertical(&self, t0: f64, wheelset: usize, side: usize) -> f64 {
        let v: Vec<f64> = self
            .t
            .iter()
            .zip(&self.wheel_vertical)
            .filter(|(t, _)| **t >= t0)
            .map(|(_, q)| q[wheelset][side])
            .collect();
        v.iter().sum::<f64>() / v.len().max(1) as f64
    }

    /// `L/V = |Y|/Q` per wheel: `[sample][wheelset][side]` (0 where unloaded).
    pub fn l_over_v(&self) -> Vec<Vec<[f64; 2]>> {
        self.wheel_vertical
            .iter()
            .zip(&self.wheel_lateral)
            .map(|(q, y)| {
                q.iter().zip(y).map(|(q, y)| [0, 1].map(|s| if q[s] > 0.0 { y[s].abs() / q[s] } else { 0.0 })).collect()
            })
            .collect()
    }

    /// Wheel unloading ratio `ΔQ/Q₀ = (Q₀ − Q)/Q₀`: `[sample][wheelset][side]`.
    pub fn unloading(&self) -> Vec<Vec<[f64; 2]>> {
        let q0 = self.static_wheel_load;
        self.wheel_vertical.iter().map(|q| q.iter().map(|q| [0, 1].map(|s| (q0 - q[s]) / q0)).collect()).collect()
    }
}

/// Records one sample of the rigid vehicle state (wheel loads, couplers, tanks) of a
/// multibody system at `(t, q, v, a)` (rigid coordinates only; `a` the integrator's
/// accelerations).
pub(crate) fn record_sample(
    mb: &mut Multibody,
    (t, q, v, a): (f64, &[f64], &[f64], &[f64]),
    track: &Track,
    cars: &[CarBodies],
    couplers: &[usize],
    hints: &mut [f64],
    rec: &mut TrainRecord,
) -> Result<(), IntegratorError> {
    let reps = mb.wheelset_reports(q, v).map_err(|e| IntegratorError::System { t, source: e })?;
    let mb = &*mb;
    let mut qv = Vec::new();
    let mut yv = Vec::new();
    let mut lat = Vec::new();
    for car in cars {
        for (w, ws) in car.wheelsets.iter().enumerate() {
            let s = mb.state(Some(*ws), q, v);
            let k = car.contacts[w];
            let proj = track.project(&s.position, Some(hints[k])).ok();
            let (up, left, y) = match proj {
                Some(p) => {
                    hints[k] = p.s;
                    let f = track.frame(p.s);
                    (f.up(), f.lateral(), p.lateral)
                }
                None => (Vector3::z(), Vector3::y(), f64::NAN),
            };
            let wl = wheel_loads(&reps[k], &up, &left);
            qv.push([wl[0].vertical, wl[1].vertical]);
            yv.push([wl[0].lateral, wl[1].lateral]);
            lat.push(y);
        }
    }
    let forces = mb.force_outputs(t, q, v);
    rec.t.push(t);
    rec.wheel_vertical.push(qv);
    rec.wheel_lateral.push(yv);
    rec.wheelset_lateral.push(lat);
    rec.coupler_force.push(couplers.iter().map(|&c| forces[c]).collect());
    let mut st = Vec::new();
    let mut sp = Vec::new();
    let mut acc = Vec::new();
    for car in cars {
        let s = mb.state(Some(car.tank), q, v);
        st.push(track.project(&s.position, Some(car.station)).map_or(f64::NAN, |p| p.s));
        sp.push(s.velocity.norm());
        // the body state with the accelerations in place of the velocities: its "velocity"
        // is the origin's acceleration r̈ (the translational coordinates are the origin's)
        let r_dd = mb.state(Some(car.tank), q, a).velocity;
        acc.push((s.rotation.transpose() * r_dd).into());
    }
    rec.tank_station.push(st);
    rec.tank_speed.push(sp);
    rec.car_acceleration.push(acc);
    Ok(())
}

/// What [`step_and_record`] asks of a run's recorder.
pub(crate) enum RecordEvent<'a> {
    /// Record point sample `k` at the integrator's state (all channels).
    Sample(usize),
    /// Sample `k` is recorded and the load filter has moved past it: a run checkpoint may be
    /// taken here (the filter's state is what a resumed run starts from).
    Recorded(usize, &'a HatMean),
    /// Write the load channels at the integrator's state into the vector (cleared first).
    Loads(&'a mut Vec<f64>),
    /// Sample `k` is final: replace its load channels by these (when filtered), then emit it
    /// to the results stream.
    Finish(usize, Option<&'a [f64]>),
}

/// Steps `hht` to every recording time of `sc` (0, `record_every`, … `t_end`), asking
/// `record` for point sample `k` there, and for the load channels after every accepted step
/// when `sc.load_filter` is [`LoadFilter::HatMean`]; a sample is finished (its loads
/// replaced by their hat-weighted mean and emitted) once the next recording time is reached,
/// or when the run stops, with the part of its window integrated so far. Calls `observe`
/// after every step; stops at the first error or when `observe` returns `false`.
///
/// `resume`: the sample a run checkpoint was taken after and the load filter then: the run
/// records that sample again at the integrator's (restored) state and goes on from there.
pub(crate) fn step_and_record<S: crate::integrator::MechanicalSystem>(
    hht: &mut Hht<S>,
    sc: &TrainScenario,
    observe: Observer<'_>,
    resume: Option<(usize, HatMean)>,
    mut record: impl FnMut(&mut Hht<S>, RecordEvent<'_>) -> Result<(), IntegratorError>,
) -> Result<(), IntegratorError> {
    let n_rec = (sc.t_end / sc.record_every).round() as usize;
    let filtered = sc.load_filter == LoadFilter::HatMean;
    let (k0, mut restored) = match resume {
        Some((k, hat)) => (k, Some(hat)),
        None => (0, None),
    };
    let mut hat = HatMean::default();
    let mut buf = Vec::new();
    // the last sample recorded and not yet finished
    let mut pending: Option<usize> = None;
    let mut result = Ok(());
    'samples: for k in k0..=n_rec {
        let t_prev = if k == 0 { 0.0 } else { ((k - 1) as f64 * sc.record_every).min(sc.t_end) };
        let target = (k as f64 * sc.record_every).min(sc.t_end);
        // the filtered load channels take every step
        let stepped = step_to(hht, target, sc.step, sc.t_end, &mut *observe, |hht, _| {
            if filtered {
                record(hht, RecordEvent::Loads(&mut buf))?;
                hat.step(t_prev, target, hht.t(), buf.clone());
            }
            Ok(())
        });
        if let Err(e) = stepped {
            result = Err(e);
            break 'samples;
        }
        if let Err(e) = record(hht, RecordEvent::Sample(k)) {
            result = Err(e);
            break;
        }
        // sample k − 1's window [t_{k−2}, t_k] is complete
        if let Some(j) = pending.take() {
            record(hht, RecordEvent::Finish(j, hat.mean(0).as_deref()))?;
        }
        if let Some(h) = restored.take() {
            // resumed: the filter as it was after this sample
            hat = h;
        } else if filtered {
            if k == 0 {
                if let Err(e) = record(hht, RecordEvent::Loads(&mut buf)) {
                    result = Err(e);
                    break;
                }
                hat.start(hht.t(), buf.clone());
            } else {
                hat.shift();
            }
        }
        pending = Some(k);
        if let Err(e) = record(hht, RecordEvent::Recorded(k, &hat)) {
            result = Err(e);
            break;
        }
    }
    // the last sample: its window ends at t_end, or where the run stopped (then with the
    // part integrated so far)
    if let Some(j) = pending {
        record(hht, RecordEvent::Finish(j, hat.mean(0).as_deref()))?;
    }
    result
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::integrator::{HhtParams, MechanicalSystem, SparsityPattern, SystemError};
    use crate::vehicle::TankCarParams;

    /// x'' = −ω² x (undamped).
    struct Oscillator {
        k: f64,
    }

    impl MechanicalSystem for Oscillator {
        fn n_coords(&self) -> usize {
            1
        }
        fn pattern(&self) -> SparsityPattern {
            SparsityPattern::diagonal(1)
        }
        fn mass_is_constant(&self) -> bool {
            true
        }
        fn mass(&mut self, _q: &[f64], m: &mut [f64]) -> Result<(), SystemError> {
            m[0] = 1.0;
            Ok(())
        }
        fn forces(&mut self, _t: f64, q: &[f64], _v: &[f64], f: &mut [f64]) -> Result<(), SystemError> {
            f[0] = -self.k * q[0];
            Ok(())
        }
        fn force_jacobians(
            &mut self,
            _t: f64,
            _q: &[f64],
            _v: &[f64],
            dq: &mut [f64],
            _dv: &mut [f64],
        ) -> Result<(), SystemError> {
            dq[0] = -self.k;
            Ok(())
        }
    }

    /// Records the oscillator's x (the "load") at the recording times with `filter`.
    fn recorded(freq: f64, filter: LoadFilter, t_end: f64) -> (Vec<f64>, Vec<f64>) {
        let track = Arc::new(Track::straight(100.0).unwrap());
        let mut sc = TrainScenario::single(TankCarParams::standard().unwrap(), track, 50.0, 0.0, t_end);
        sc.step = 2.5e-4;
        sc.record_every = 0.02;
        sc.load_filter = filter;
        sc.hht = HhtParams { alpha: 0.0, ..HhtParams::default() };
        let w = 2.0 * std::f64::consts::PI * freq;
        let mut hht = Hht::new(Oscillator { k: w * w }, 0.0, vec![1.0], vec![0.0], sc.hht).unwrap();
        let (mut t, mut x, mut finished) = (Vec::new(), Vec::new(), Vec::new());
        step_and_record(&mut hht, &sc, &mut |_| true, None, |hht, event| {
            match event {
                RecordEvent::Sample(k) => {
                    assert_eq!(k, t.len());
                    t.push(hht.t());
                    x.push(hht.q()[0]);
                }
                RecordEvent::Loads(out) => {
                    out.clear();
                    out.push(hht.q()[0]);
                }
                RecordEvent::Finish(k, loads) => {
                    assert_eq!(k, finished.len(), "samples finish in order, once");
                    if let Some(l) = loads {
                        x[k] = l[0];
                    }
                    finished.push(k);
                }
                RecordEvent::Recorded(k, _) => assert_eq!(k + 1, t.len(), "after the sample"),
            }
            Ok(())
        })
        .unwrap();
        assert_eq!(finished.len(), t.len(), "every sample is finished");
        (t, x)
    }

    #[test]
    fn hat_mean_resampling_is_the_hat_weighted_mean() {
        // a 30 Hz load at irregular steps resampled to 0.02 s: each value equals the hat-weighted
        // mean of the piecewise-linear series, integrated independently on a 1 µs grid
        let t: Vec<f64> = (0..=300)
            .map(|i| i as f64 * 1e-3 + 3e-4 * ((i * 7 % 5) as f64 - 2.0).max(0.0) * (i > 0) as u8 as f64)
            .collect();
        let f: Vec<Vec<f64>> =
            t.iter().map(|&x| vec![(2.0 * std::f64::consts::PI * 30.0 * x).sin(), 1.0 + x]).collect();
        let dt = 0.02;
        let out = super::hat_mean_resample(&t, &f, dt).unwrap();
        assert_eq!(out.len(), (t[t.len() - 1] / dt + 1e-9).floor() as usize + 1);
        let lin = |x: f64, c: usize| {
            let i = t.partition_point(|&s| s <= x).clamp(1, t.len() - 1) - 1;
            f[i][c] + (x - t[i]) / (t[i + 1] - t[i]) * (f[i + 1][c] - f[i][c])
        };
        for (k, v) in out.iter().enumerate() {
            let tk = k as f64 * dt;
            let (lo, hi) = ((tk - dt).max(0.0), (tk + dt).min(t[t.len() - 1]));
            let n = ((hi - lo) / 1e-6).round() as usize;
            let (mut num, mut den) = ([0.0; 2], 0.0);
            for j in 0..=n {
                let x = lo + (hi - lo) * j as f64 / n as f64;
                let w = (1.0 - (x - tk).abs() / dt) * if j == 0 || j == n { 0.5 } else { 1.0 };
                den += w;
                for (c, n) in num.iter_mut().enumerate() {
                    *n += w * lin(x, c);
                }
            }
            for c in 0..2 {
                assert!((v[c] - num[c] / den).abs() < 1e-6, "sample {k}, channel {c}: {} vs {}", v[c], num[c] / den);
            }
        }
        // a linear load keeps its value at every interior grid time (the hats are symmetric)
        assert!((out[5][1] - (1.0 + 5.0 * dt)).abs() < 1e-9);
        assert!(super::hat_mean_resample(&[0.0, 0.0], &[vec![1.0], vec![1.0]], dt).is_err());
    }

    #[test]
    fn hat_mean_removes_what_point_samples_alias() {
        // 50 Hz at a 0.02 s record: point samples alias it to a constant (x ≈ 1 at every
        // sample, a false static load); its hat mean is sinc²(1) = 0
        let (_, sampled) = recorded(50.0, LoadFilter::Sample, 0.4);
        let (_, mean) = recorded(50.0, LoadFilter::HatMean, 0.4);
        let interior = 1..sampled.len() - 1;
        let alias = sampled[interior.clone()].iter().sum::<f64>() / interior.len() as f64;
        assert!(alias > 0.9, "point samples alias 50 Hz to {alias}");
        let worst = mean[interior].iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        assert!(worst < 0.01, "hat mean leaves {worst} of a 50 Hz signal");
    }

    #[test]
    fn hat_mean_keeps_a_slow_load_and_its_phase() {
        // 1 Hz: the hat mean is the point value times sinc²(0.02) = 0.99868, no delay
        let (t, sampled) = recorded(1.0, LoadFilter::Sample, 1.0);
        let (_, mean) = recorded(1.0, LoadFilter::HatMean, 1.0);
        let s = (std::f64::consts::PI * 0.02).sin() / (std::f64::consts::PI * 0.02);
        for k in 1..t.len() - 1 {
            let want = s * s * sampled[k];
            assert!((mean[k] - want).abs() < 2e-4, "t = {}: mean {} against {want}", t[k], mean[k]);
        }
    }
}
