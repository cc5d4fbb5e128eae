//! Running trains of tank cars on a track: the scenario, the train's model, the one entry of
//! every vehicle run (`run_vehicle` over the [`Cargo`] trait), its driver and the wheel-off-rail
//! check. The record and its sampling are in `super::record`, re-exported here.

use std::sync::Arc;
use std::time::Instant;

use super::checkpoint::{RunCheckpoints, VehicleCheckpoint};
use super::tank_car::{CarBodies, CarPlacement, TankCarParams, add_coupler, add_tank_car};
use crate::integrator::{
    AdaptiveParams, CheckpointFile, Hht, HhtParams, IntegratorError, MechanicalSystem, Predictor, StepControl,
};
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
    /// How load channels are sampled at the recording times (default: hat-weighted mean
    /// over the steps, an anti-aliasing low-pass; [`LoadFilter`]).
    pub load_filter: LoadFilter,
    /// Interval of fluid mesh snapshots, s (0 = none; fluid runs only).
    pub snapshot_every: f64,
    /// Integrator parameters.
    pub hht: HhtParams,
    /// Whole-run checkpoints written as the run goes ([`super::checkpoint`]; `None`: none).
    pub checkpoints: Option<RunCheckpoints>,
    /// A checkpoint of an earlier run of the same scenario and cargo to continue from
    /// (`None`: start at t = 0). The record then starts at the checkpoint's sample.
    pub resume_from: Option<std::path::PathBuf>,
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

    /// Integrator defaults for a train whose tanks carry ANCF fluid: [`Self::default_hht`]
    /// with the Jacobian refreshed once the Newton contraction rate exceeds 0.5, as slosh runs
    /// ([`crate::defaults::slosh_params`]); the fluid's Jacobian is the costly one to refresh.
    pub fn fluid_hht() -> HhtParams {
        HhtParams { refresh_rate: crate::defaults::slosh_params().refresh_rate, ..Self::default_hht() }
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
            load_filter: LoadFilter::default(),
            snapshot_every: 0.0,
            hht: Self::default_hht(),
            checkpoints: None,
            resume_from: None,
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

/// A rigid-lading run that stopped early: the error and what was recorded up to it.
pub type TrainFailure = RunFailure<TrainRecord>;

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

pub use super::record::{LoadFilter, TrainRecord, hat_mean_resample};
pub(crate) use super::record::{RecordEvent, record_sample, step_and_record};
pub use crate::observe::{Observer, Progress, RunFailure, SampleSink, stopped_by_observer};

/// Longest time a wheel may carry no load before a vehicle run stops with
/// [`SystemError::WheelOffRail`](crate::integrator::SystemError::WheelOffRail), s. Short wheel
/// lifts are part of running on real track (single samples at 0 N over a dip); a wheel without
/// load for 0.1 s has travelled 1–3 m off the rail at the speeds here: the run no longer
/// describes a train on its track, and what it computes after that is not a valid answer.
pub const WHEEL_OFF_RAIL_LIMIT: f64 = 0.1;

/// Watches every wheel's vertical load sample by sample ([`WHEEL_OFF_RAIL_LIMIT`]).
#[derive(Debug, Default)]
struct WheelLiftWatch {
    /// Per wheelset and side: the time of the first sample of the current run without load.
    since: Vec<[Option<f64>; 2]>,
}

impl WheelLiftWatch {
    /// The watch as a flat vector (a run checkpoint): per wheelset and side, 1 and the time,
    /// or 0 and 0.
    fn save(&self) -> Vec<f64> {
        self.since.iter().flatten().flat_map(|s| [s.map_or(0.0, |_| 1.0), s.unwrap_or(0.0)]).collect()
    }

    /// The watch [`Self::save`] wrote; `None` when malformed.
    fn restore(data: &[f64]) -> Option<Self> {
        if !data.len().is_multiple_of(4) {
            return None;
        }
        let side = |c: &[f64]| (c[0] == 1.0).then_some(c[1]);
        Some(Self { since: data.chunks_exact(4).map(|c| [side(&c[..2]), side(&c[2..])]).collect() })
    }

    /// Checks sample `k` of `rec`: a wheel with no load since longer than the limit is an error.
    fn check(&mut self, rec: &TrainRecord, k: usize) -> Result<(), IntegratorError> {
        let (Some(&t), Some(q)) = (rec.t.get(k), rec.wheel_vertical.get(k)) else { return Ok(()) };
        self.since.resize(q.len(), [None, None]);
        for (w, (loads, since)) in q.iter().zip(&mut self.since).enumerate() {
            for side in 0..2 {
                if loads[side] > 0.0 {
                    since[side] = None;
                    continue;
                }
                let t0 = *since[side].get_or_insert(t);
                if t - t0 > WHEEL_OFF_RAIL_LIMIT {
                    let lateral = rec.wheelset_lateral.get(k).and_then(|l| l.get(w)).copied().unwrap_or(f64::NAN);
                    return Err(IntegratorError::System {
                        t,
                        source: crate::integrator::SystemError::WheelOffRail {
                            wheelset: w,
                            side: ["left", "right"][side],
                            since: t0,
                            t,
                            limit: WHEEL_OFF_RAIL_LIMIT,
                            lateral,
                        },
                    });
                }
            }
        }
        Ok(())
    }
}

/// What one kind of train run (rigid lading, equivalent slosh model, ANCF fluid) records: its
/// record and how it samples the vehicle and its cargo. [`drive`] is the one run loop over
/// every kind.
pub(crate) trait TrainRun {
    /// The system the integrator steps.
    type System: crate::integrator::MechanicalSystem;
    /// The run's results (samples plus run data).
    type Record: Default;
    /// The vehicle part of a record.
    fn train(rec: &mut Self::Record) -> &mut TrainRecord;
    /// Records the state of `hht` as a sample of `rec` (`k`: its index); `full` is false for
    /// the load-filter pass, which needs the load channels only.
    fn sample(
        &mut self,
        hht: &mut Hht<Self::System>,
        k: usize,
        rec: &mut Self::Record,
        full: bool,
    ) -> Result<(), IntegratorError>;
    /// Empties the samples of a scratch record.
    fn clear_samples(rec: &mut Self::Record);
    /// The load channels of sample `i`.
    fn loads_into(rec: &Self::Record, i: usize, out: &mut Vec<f64>);
    /// Replaces the load channels of sample `i`.
    fn set_loads(rec: &mut Self::Record, i: usize, loads: &[f64]);
    /// Sample `i` as one results-stream row.
    fn row(rec: &Self::Record, i: usize) -> Vec<f64>;
    /// The recording's own state: the wheel/rail warm starts of the recorded samples (kept
    /// in run checkpoints).
    fn hints(&mut self) -> &mut Vec<f64>;
    /// Run data taken from the integrator at the end (e.g. the fluids' margins).
    fn finish(_hht: &Hht<Self::System>, _rec: &mut Self::Record) {}
}

/// The run loop of every train run: builds the integrator on `sys` from `(q0, v0)`, steps and
/// records through [`step_and_record`], streams each finished sample to `sink`, and returns
/// the record, or the error with everything recorded up to it.
///
/// With `sc.checkpoints` it writes a [`VehicleCheckpoint`] after every `every`-th recorded
/// sample; with `sc.resume_from` it starts from such a checkpoint instead of `(q0, v0)` and
/// records from its sample on (the record's sample 0 is that sample).
pub(crate) fn drive<R: TrainRun>(
    mut run: R,
    sys: R::System,
    (q0, v0): (Vec<f64>, Vec<f64>),
    sc: &TrainScenario,
    observe: Observer<'_>,
    mut sink: Option<SampleSink<'_>>,
    mut rec: R::Record,
) -> Result<R::Record, Box<RunFailure<R::Record>>> {
    let start = Instant::now();
    let setup = (|| {
        let files = sc.checkpoints.as_ref().map(|c| CheckpointFile::new(&c.path, c.every)).transpose()?;
        let (hht, resumed) = match &sc.resume_from {
            None => (Hht::new(sys, 0.0, q0, v0, sc.hht)?, None),
            Some(path) => resume(sys, sc, path).map(|(h, r)| (h, Some(r)))?,
        };
        Ok((hht, resumed, files))
    })();
    let (mut hht, resumed, mut files) = match setup {
        Ok(x) => x,
        Err(error) => {
            R::train(&mut rec).finish(None, start);
            return Err(Box::new(RunFailure { error, record: rec }));
        }
    };
    let mut wheels = WheelLiftWatch::default();
    let resumed = resumed.map(|r| {
        *run.hints() = r.recorder;
        wheels = r.wheel_lift;
        (r.sample, r.filter)
    });
    // the record's sample 0 is the run's sample k0
    let k0 = resumed.as_ref().map_or(0, |r| r.0);
    let every = sc.checkpoints.as_ref().map(|c| c.every);
    // the recorder's state before a sample a checkpoint follows (what a resumed run records it with)
    let mut before: Option<(Vec<f64>, Vec<f64>)> = None;
    let mut scratch = R::Record::default();
    let result = step_and_record(&mut hht, sc, observe, resumed, |hht, event| match event {
        RecordEvent::Sample(k) => {
            if every.is_some_and(|e| (k + 1).is_multiple_of(e)) {
                before = Some((run.hints().clone(), wheels.save()));
            }
            run.sample(hht, k, &mut rec, true)?;
            wheels.check(R::train(&mut rec), k - k0)
        }
        RecordEvent::Loads(out) => {
            R::clear_samples(&mut scratch);
            run.sample(hht, 0, &mut scratch, false)?;
            out.clear();
            R::loads_into(&scratch, 0, out);
            Ok(())
        }
        RecordEvent::Finish(k, loads) => {
            if let Some(l) = loads {
                R::set_loads(&mut rec, k - k0, l);
            }
            match sink.as_mut() {
                Some(sink) => sink(&R::row(&rec, k - k0)),
                None => Ok(()),
            }
        }
        RecordEvent::Recorded(k, hat) => match (files.as_mut(), before.take()) {
            (Some(file), Some((recorder, wheel_lift))) => {
                let mut system = Vec::new();
                hht.system().save_internal_state(&mut system);
                let filter = hat.save();
                let cp =
                    VehicleCheckpoint { sample: k, integrator: hht.checkpoint(), system, recorder, wheel_lift, filter };
                file.write_bytes(&cp.to_bytes())
            }
            _ => Ok(()),
        },
    });
    R::train(&mut rec).finish(Some(hht.stats()), start);
    R::finish(&hht, &mut rec);
    match result {
        Ok(()) => Ok(rec),
        Err(error) => Err(Box::new(RunFailure { error, record: rec })),
    }
}

/// Where a resumed run's recording starts ([`VehicleCheckpoint`]): the sample, the load filter
/// after it, and the recorder's warm starts and wheel-lift watch before it.
struct Resumed {
    sample: usize,
    filter: super::record::HatMean,
    recorder: Vec<f64>,
    wheel_lift: WheelLiftWatch,
}

/// The integrator and the recording state of a run resumed from the checkpoint file at `path`
/// on `sys` (built from the same scenario and cargo as the run that wrote it).
fn resume<S: crate::integrator::MechanicalSystem>(
    sys: S,
    sc: &TrainScenario,
    path: &std::path::Path,
) -> Result<(Hht<S>, Resumed), IntegratorError> {
    let cp = VehicleCheckpoint::from_bytes(&CheckpointFile::read_bytes(path)?)?;
    let mut hht = Hht::restore(sys, &cp.integrator, sc.hht).map_err(|e| {
        crate::integrator::bad_checkpoint(format!(
            "{} does not fit this train (another scenario or cargo?): {e}",
            path.display()
        ))
    })?;
    let mut data = &cp.system[..];
    // the warm starts and accounts do not change the model: the stored Jacobians stay valid
    if hht.system_observed().restore_internal_state(&mut data).is_none() || !data.is_empty() {
        return Err(crate::integrator::bad_checkpoint(format!(
            "the system state of {} does not fit this train (another scenario or cargo?)",
            path.display()
        )));
    }
    let (Some(filter), Some(wheel_lift)) =
        (super::record::HatMean::restore(&cp.filter), WheelLiftWatch::restore(&cp.wheel_lift))
    else {
        return Err(crate::integrator::bad_checkpoint(format!(
            "malformed load-filter or wheel-lift state in {}",
            path.display()
        )));
    };
    Ok((hht, Resumed { sample: cp.sample, filter, recorder: cp.recorder, wheel_lift }))
}

/// The rigid-lading run ([`run_train`]): the vehicle channels only.
struct RigidRun<'a> {
    sc: &'a TrainScenario,
    cars: Vec<CarBodies>,
    couplers: Vec<usize>,
    /// Warm starts of the wheel/rail search at the recorded samples.
    hints: Vec<f64>,
}

impl TrainRun for RigidRun<'_> {
    type System = Multibody;
    type Record = TrainRecord;
    fn train(rec: &mut TrainRecord) -> &mut TrainRecord {
        rec
    }
    fn sample(
        &mut self,
        hht: &mut Hht<Multibody>,
        _k: usize,
        rec: &mut TrainRecord,
        _full: bool,
    ) -> Result<(), IntegratorError> {
        let (t, q, v, a) = (hht.t(), hht.q().to_vec(), hht.v().to_vec(), hht.a().to_vec());
        record_sample(
            hht.system_observed(),
            (t, &q, &v, &a),
            &self.sc.track,
            &self.cars,
            &self.couplers,
            &mut self.hints,
            rec,
        )
    }
    fn clear_samples(rec: &mut TrainRecord) {
        rec.clear_samples();
    }
    fn loads_into(rec: &TrainRecord, i: usize, out: &mut Vec<f64>) {
        rec.loads_into(i, out);
    }
    fn set_loads(rec: &mut TrainRecord, i: usize, loads: &[f64]) {
        rec.set_loads(i, loads);
    }
    fn row(rec: &TrainRecord, i: usize) -> Vec<f64> {
        rec.row(i)
    }
    fn hints(&mut self) -> &mut Vec<f64> {
        &mut self.hints
    }
}

/// What a run returns: the record, or the failure with everything recorded up to it (outer
/// `Err`: the scenario or cargo could not be built).
pub type RunResult<R> = Result<Result<R, Box<RunFailure<R>>>, AncfError>;

/// What the tanks carry, by fluid model: the car's own rigid lading ([`RigidCargo`]), the
/// equivalent slosh model ([`super::EquivalentCargo`]) or the ANCF fluid
/// ([`super::FluidCargo`]). Every vehicle run is [`run_vehicle`] of a [`TrainScenario`] and a
/// cargo: one driver ([`drive`]), one failure type ([`RunFailure`]), one observer and
/// results-stream path, whatever the model.
pub trait Cargo {
    /// The run's record: [`TrainRecord`], extended by the model's own channels.
    type Record;
    /// The columns of the run's results stream, the layout of the rows its [`SampleSink`]
    /// receives.
    fn columns(&self, sc: &TrainScenario) -> Result<Vec<String>, AncfError>;
    /// Builds the train of `sc` with this cargo and runs it ([`run_vehicle`]).
    fn run(&self, sc: &TrainScenario, observe: Observer<'_>, sink: Option<SampleSink<'_>>) -> RunResult<Self::Record>;
}

/// Runs the train of `sc` carrying `cargo`: `observe` is called after every accepted step
/// (returning `false` stops the run), `sink` receives every recorded sample as it is recorded
/// (layout [`Cargo::columns`]). On failure the inner `Err` has the error and what was
/// recorded up to it.
pub fn run_vehicle<C: Cargo>(
    sc: &TrainScenario,
    cargo: &C,
    observe: Observer<'_>,
    sink: Option<SampleSink<'_>>,
) -> RunResult<C::Record> {
    cargo.run(sc, observe, sink)
}

/// The rigid-lading cargo: the tank carries what `TankCarParams::lading` says (a rigid mass at a
/// height, or nothing) and no sloshing liquid.
#[derive(Debug, Clone, Copy, Default)]
pub struct RigidCargo;

impl Cargo for RigidCargo {
    type Record = TrainRecord;
    fn columns(&self, sc: &TrainScenario) -> Result<Vec<String>, AncfError> {
        Ok(TrainRecord::columns(4 * sc.cars, sc.cars.saturating_sub(1), sc.cars))
    }
    fn run(&self, sc: &TrainScenario, observe: Observer<'_>, sink: Option<SampleSink<'_>>) -> RunResult<TrainRecord> {
        let (mb, cars, couplers) = build_train(sc)?;
        let rec = TrainRecord { static_wheel_load: cars[0].static_wheel_load, dof: mb.dof(), ..Default::default() };
        let init = mb.initial_coordinates();
        let hints = cars.iter().flat_map(|c| [c.station; 4]).collect();
        let run = RigidRun { sc, cars, couplers, hints };
        Ok(drive(run, mb, init, sc, observe, sink, rec))
    }
}

/// [`run_vehicle`] of the rigid-lading cargo, without observer or stream.
pub fn run_train(sc: &TrainScenario) -> RunResult<TrainRecord> {
    run_vehicle(sc, &RigidCargo, &mut |_| true, None)
}

#[cfg(test)]
mod wheel_lift_tests {
    use super::*;

    /// A record whose wheelset 1's right wheel carries no load from sample `from` on.
    fn record(n: usize, dt: f64, from: usize) -> TrainRecord {
        let mut r = TrainRecord::default();
        for k in 0..n {
            r.t.push(k as f64 * dt);
            let off = if k >= from { 0.0 } else { 7e4 };
            r.wheel_vertical.push(vec![[7e4, 7e4], [7e4, off]]);
            r.wheelset_lateral.push(vec![0.0, 0.012]);
        }
        r
    }

    #[test]
    fn a_wheel_without_load_for_longer_than_the_limit_stops_the_run_and_a_short_lift_does_not() {
        let dt = 0.02;
        // 5 samples without load span 0.08 s: a lift, not an error
        let short = record(20, dt, 10);
        let mut w = WheelLiftWatch::default();
        for k in 0..15 {
            w.check(&short, k).unwrap();
        }
        // the load comes back: the count restarts
        let mut back = short.clone();
        back.wheel_vertical[15][1][1] = 100.0;
        for k in 15..20 {
            w.check(&back, k).unwrap();
        }
        // without load from 0.2 s: the sample at 0.32 s (> 0.1 s later) is the error, named
        let long = record(20, dt, 10);
        let mut w = WheelLiftWatch::default();
        let mut stopped = None;
        for k in 0..20 {
            if let Err(e) = w.check(&long, k) {
                stopped = Some((k, e));
                break;
            }
        }
        let (k, e) = stopped.expect("the run stops");
        assert_eq!(k, 16);
        assert_eq!(e.cause(), crate::integrator::FailureCause::WheelOffRail);
        let m = e.to_string();
        assert!(
            m.contains("wheel off the rail: wheelset 1") && m.contains("right wheel") && m.contains("0.0120 m"),
            "{m}"
        );
        assert!(m.contains("from t = 0.200 s to 0.320 s"), "{m}");
    }
}
