//! Running trains of tank cars (rigid lading) on a track and recording wheel loads,
//! derailment indicators and coupler forces.

use std::sync::Arc;
use std::time::Instant;

use nalgebra::Vector3;

use super::tank_car::{CarBodies, CarPlacement, TankCarParams, add_coupler, add_tank_car, wheel_loads};
use crate::integrator::{AdaptiveParams, Hht, HhtParams, IntegratorError, Predictor, StepControl};
use crate::mbs::{Multibody, SpeedProfile, Table};
use crate::track::Track;
use ancf_core::error::{AncfError, check_positive, invalid};

/// Which cars brake.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BrakeScope {
    /// Every wheelset of every car at once (ECP braking).
    AllCars,
    /// Only the front car (conventional braking as modelled in seed 000 §8.2).
    FrontCar,
}

/// A train scenario: `n` identical tank cars coupled front to rear on a track.
#[derive(Debug, Clone)]
pub struct TrainScenario {
    /// Number of cars (≥ 1).
    pub cars: usize,
    /// Car parameters.
    pub car: TankCarParams,
    /// Track.
    pub track: Arc<Track>,
    /// Arc length of the front car's tank centre at `t = 0`, m.
    pub station: f64,
    /// Initial speed, m/s.
    pub speed: f64,
    /// Speed profile the front car is held to by a trajectory joint, if any.
    pub drive: Option<SpeedProfile>,
    /// Brake torque per wheelset (N·m against s) and which cars brake.
    pub brake: Option<(Table, BrakeScope)>,
    /// Per-car factor on the brake torque (missing entries = 1), e.g. to model the spread
    /// of brake forces between cars.
    pub brake_factors: Vec<f64>,
    /// Coupler stiffness and damping (defaults of seed 000 §8.2 when `None`).
    pub coupler: (Option<f64>, Option<f64>),
    /// Initial lateral displacement of every wheelset (a disturbance), m.
    pub wheelset_lateral_offset: f64,
    /// End time, s.
    pub t_end: f64,
    /// (Maximum) step, s.
    pub step: f64,
    /// Recording interval, s.
    pub record_every: f64,
    /// Interval of fluid mesh snapshots, s (0 = none; fluid runs only).
    pub snapshot_every: f64,
    /// Integrator parameters.
    pub hht: HhtParams,
}

impl TrainScenario {
    /// Integrator defaults for vehicles: α = −0.3, adaptive steps, extrapolating predictor
    /// (10–15 % fewer Newton iterations on the ECP braking study, `docs/benchmarks.md`).
    pub fn default_hht() -> HhtParams {
        HhtParams {
            predictor: Predictor::Extrapolate,
            alpha: -0.3,
            rel_tol: 1e-4,
            abs_tol_acc: 1e-3,
            abs_tol_lambda: 1e-1,
            max_iterations: 10,
            step_control: StepControl::Adaptive(AdaptiveParams {
                h_min: 1e-7,
                easy_iterations: 5,
                ..Default::default()
            }),
            ..Default::default()
        }
    }

    /// One car on `track` at `station`, moving at `speed`.
    pub fn single(car: TankCarParams, track: Arc<Track>, station: f64, speed: f64, t_end: f64) -> Self {
        Self {
            cars: 1,
            car,
            track,
            station,
            speed,
            drive: None,
            brake: None,
            coupler: (None, None),
            brake_factors: Vec::new(),
            wheelset_lateral_offset: 0.0,
            t_end,
            step: 1e-3,
            record_every: 0.01,
            snapshot_every: 0.0,
            hht: Self::default_hht(),
        }
    }

    /// Checks the scenario fields.
    pub fn validate(&self) -> Result<(), AncfError> {
        if self.cars == 0 || self.cars > 50 {
            return Err(invalid("cars", self.cars, "1 to 50"));
        }
        check_positive("t_end", self.t_end)?;
        check_positive("step", self.step)?;
        check_positive("record_every", self.record_every)?;
        if !(self.speed.is_finite() && self.speed.abs() < 100.0) {
            return Err(invalid("speed", self.speed, "|speed| < 100 m/s"));
        }
        if let Some(f) = self.brake_factors.iter().find(|f| !(f.is_finite() && **f >= 0.0 && **f <= 10.0)) {
            return Err(invalid("brake_factors", f, "[0, 10]"));
        }
        if !(self.wheelset_lateral_offset.is_finite() && self.wheelset_lateral_offset.abs() < 0.01) {
            return Err(invalid("wheelset_lateral_offset", self.wheelset_lateral_offset, "|offset| < 0.01 m"));
        }
        self.hht.validate().map_err(|e| invalid("hht", e, "valid integrator parameters"))?;
        Ok(())
    }
}

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
        }
        self.wall_time = start.elapsed().as_secs_f64();
    }

    /// Column names of [`Self::row`] for a train with `wheelsets` wheelsets, `couplers`
    /// couplers and `cars` cars (the layout of a results stream, `run_train_streamed`).
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
        r
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

/// A run that stopped early: the error and what was recorded up to it.
#[derive(Debug)]
pub struct TrainFailure {
    /// Why it stopped.
    pub error: IntegratorError,
    /// Results up to the failure.
    pub record: TrainRecord,
}

/// Builds the multibody model of a scenario; returns it with the cars and couplers.
pub fn build_train(sc: &TrainScenario) -> Result<(Multibody, Vec<CarBodies>, Vec<usize>), AncfError> {
    sc.validate()?;
    let mut mb = Multibody::new();
    let mut cars = Vec::with_capacity(sc.cars);
    let pitch = 2.0 * sc.car.coupler_reach + 1.0;
    for k in 0..sc.cars {
        let factor = sc.brake_factors.get(k).copied().unwrap_or(1.0);
        let scaled = |t: &Table| Table { x: t.x.clone(), y: t.y.iter().map(|y| y * factor).collect() };
        let brake = match &sc.brake {
            Some((t, BrakeScope::AllCars)) => Some(scaled(t)),
            Some((t, BrakeScope::FrontCar)) if k == 0 => Some(scaled(t)),
            _ => None,
        };
        let drive = if k == 0 { sc.drive.clone() } else { None };
        let station = sc.station - pitch * k as f64;
        let placement = CarPlacement { station, speed: sc.speed, drive, brake };
        cars.push(add_tank_car(&mut mb, &format!("car{}", k + 1), &sc.car, &sc.track, placement)?);
    }
    if sc.wheelset_lateral_offset != 0.0 {
        // Displace every wheelset laterally (along the local track-left axis).
        for car in &cars {
            for ws in car.wheelsets {
                mb.displace_body(ws, sc.track.frame(car.station).lateral() * sc.wheelset_lateral_offset)?;
            }
        }
    }
    let mut couplers = Vec::new();
    for k in 1..sc.cars {
        let (c1, c2) = (&cars[k - 1], &cars[k]);
        couplers.push(add_coupler(&mut mb, &format!("coupler{k}"), &sc.car, c1, c2, sc.coupler.0, sc.coupler.1)?);
    }
    Ok((mb, cars, couplers))
}

/// Records one sample of the rigid vehicle state (wheel loads, couplers, tanks) of a
/// multibody system at `(t, q, v)` (rigid coordinates only).
pub(crate) fn record_sample(
    mb: &mut Multibody,
    (t, q, v): (f64, &[f64], &[f64]),
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
    for car in cars {
        let s = mb.state(Some(car.tank), q, v);
        st.push(track.project(&s.position, Some(car.station)).map_or(f64::NAN, |p| p.s));
        sp.push(s.velocity.norm());
    }
    rec.tank_station.push(st);
    rec.tank_speed.push(sp);
    Ok(())
}

/// Progress of a run, passed to an [`Observer`] after every accepted step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Simulated time reached, s.
    pub t: f64,
    /// End time of the run, s.
    pub t_end: f64,
    /// Accepted steps so far.
    pub steps: usize,
    /// Newton iterations so far.
    pub newton_iterations: usize,
    /// Rejected step attempts so far.
    pub rejected_steps: usize,
}

impl Progress {
    /// The progress of `hht` towards `t_end`.
    pub fn of<S: crate::integrator::MechanicalSystem>(hht: &Hht<S>, t_end: f64) -> Self {
        let s = hht.stats();
        Self {
            t: hht.t(),
            t_end,
            steps: s.steps,
            newton_iterations: s.newton_iterations,
            rejected_steps: s.rejected_steps,
        }
    }
}

/// Observer of a run (e.g. a progress bar): called after every accepted step; returning
/// `false` stops the run, which then fails with [`stopped_by_observer`] at that time.
pub type Observer<'a> = &'a mut dyn FnMut(&Progress) -> bool;

/// The error of a run stopped by its [`Observer`].
pub fn stopped_by_observer(t: f64) -> IntegratorError {
    IntegratorError::InvalidSystem { what: format!("run stopped by its progress observer at t = {t} s") }
}

/// Steps `hht` to every recording time of `sc` (0, `record_every`, … `t_end`), calling
/// `record(hht, k)` at sample `k` and `observe` after every step; stops at the first
/// error or when `observe` returns `false`.
pub(crate) fn step_and_record<S: crate::integrator::MechanicalSystem>(
    hht: &mut Hht<S>,
    sc: &TrainScenario,
    observe: Observer<'_>,
    mut record: impl FnMut(&mut Hht<S>, usize) -> Result<(), IntegratorError>,
) -> Result<(), IntegratorError> {
    let n_rec = (sc.t_end / sc.record_every).round() as usize;
    for k in 0..=n_rec {
        let target = (k as f64 * sc.record_every).min(sc.t_end);
        while hht.t() < target - 1e-12 {
            hht.step(sc.step.min(target - hht.t()))?;
            if !observe(&Progress::of(hht, sc.t_end)) {
                return Err(stopped_by_observer(hht.t()));
            }
        }
        record(hht, k)?;
    }
    Ok(())
}

/// Runs a scenario; on failure returns what was recorded so far with the error.
pub fn run_train(sc: &TrainScenario) -> Result<Result<TrainRecord, Box<TrainFailure>>, AncfError> {
    run_train_observed(sc, &mut |_| true)
}

/// Receives every recorded sample as a flat row (`TrainRecord::row` layout, extended by
/// `FluidTrainRecord::row` for fluid runs) as soon as it is recorded: a results stream that
/// an interrupted run cannot lose (e.g. a [`crate::integrator::Journal`]).
pub type SampleSink<'a> = &'a mut dyn FnMut(&[f64]) -> Result<(), IntegratorError>;

/// [`run_train`] with an [`Observer`] of its progress.
pub fn run_train_observed(
    sc: &TrainScenario,
    observe: Observer<'_>,
) -> Result<Result<TrainRecord, Box<TrainFailure>>, AncfError> {
    run_train_streamed(sc, observe, None)
}

/// [`run_train_observed`] that also passes every recorded sample to `sink`.
pub fn run_train_streamed(
    sc: &TrainScenario,
    observe: Observer<'_>,
    mut sink: Option<SampleSink<'_>>,
) -> Result<Result<TrainRecord, Box<TrainFailure>>, AncfError> {
    let (mb, cars, couplers) = build_train(sc)?;
    let mut rec = TrainRecord { static_wheel_load: cars[0].static_wheel_load, dof: mb.dof(), ..Default::default() };
    let (q0, v0) = mb.initial_coordinates();
    let start = Instant::now();
    let finish = |hht: Option<&Hht<Multibody>>, mut rec: TrainRecord| {
        rec.finish(hht.map(|h| h.stats()), start);
        rec
    };
    let mut hht = match Hht::new(mb, 0.0, q0, v0, sc.hht) {
        Ok(h) => h,
        Err(error) => return Ok(Err(Box::new(TrainFailure { error, record: finish(None, rec) }))),
    };
    let mut hints: Vec<f64> = cars.iter().flat_map(|c| [c.station; 4]).collect();
    let result = step_and_record(&mut hht, sc, observe, |hht, _| {
        let (t, q, v) = (hht.t(), hht.q().to_vec(), hht.v().to_vec());
        record_sample(hht.system_mut(), (t, &q, &v), &sc.track, &cars, &couplers, &mut hints, &mut rec)?;
        match sink.as_mut() {
            Some(sink) => sink(&rec.row(rec.t.len() - 1)),
            None => Ok(()),
        }
    });
    if let Err(error) = result {
        return Ok(Err(Box::new(TrainFailure { error, record: finish(Some(&hht), rec) })));
    }
    Ok(Ok(finish(Some(&hht), rec)))
}
