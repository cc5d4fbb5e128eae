//! The one vehicle-run pipeline (issue 18): every fluid model (rigid lading, equivalent slosh
//! model, ANCF fluid) runs through `run_vehicle` over the `Cargo` trait, with the same observer,
//! results stream and failure type.

use std::sync::Arc;

use rail_mbs::defaults::Oil;
use rail_mbs::integrator::IntegratorError;
use rail_mbs::track::Track;
use rail_mbs::vehicle::{
    Cargo, EquivalentCargo, FluidCargo, RigidCargo, RunCheckpoints, RunFailure, SloshAxis, TankCarParams,
    TrainScenario, VehicleCheckpoint, run_vehicle,
};

fn scenario(station: f64) -> TrainScenario {
    let mut p = TankCarParams::standard().expect("car");
    p.lading = Some((30_000.0, -0.3));
    let mut sc = TrainScenario::single(p, Arc::new(Track::straight(3000.0).expect("track")), station, 10.0, 0.06);
    sc.record_every = 0.02;
    sc
}

/// Runs `cargo` twice: to its end with a stream, whose rows must be the record's rows in the
/// cargo's column layout; then stopped by its observer after `stop` steps, which must fail with
/// the observer's error and keep the samples recorded up to then (the first ones of the full run).
fn check_pipeline<C: Cargo>(
    cargo: &C,
    sc: &TrainScenario,
    row: impl Fn(&C::Record, usize) -> Vec<f64>,
    n: impl Fn(&C::Record) -> usize,
) {
    let columns = cargo.columns(sc).expect("columns");
    let mut rows: Vec<Vec<f64>> = Vec::new();
    let mut sink = |r: &[f64]| -> Result<(), IntegratorError> {
        rows.push(r.to_vec());
        Ok(())
    };
    let mut calls = 0;
    let full = run_vehicle(
        sc,
        cargo,
        &mut |_| {
            calls += 1;
            true
        },
        Some(&mut sink),
    )
    .expect("built")
    .unwrap_or_else(|f| panic!("run failed: {}", f.error));
    assert_eq!(n(&full), 4, "0, 0.02, 0.04, 0.06 s");
    assert!(calls >= 60, "the observer is called after every accepted step ({calls})");
    assert_eq!(rows.len(), n(&full), "one stream row per recorded sample");
    for (i, r) in rows.iter().enumerate() {
        assert_eq!(r.len(), columns.len(), "row {i} has the columns' layout");
        assert_eq!(r, &row(&full, i), "stream row {i} is the record's row, bit for bit");
    }

    let mut streamed: Vec<Vec<f64>> = Vec::new();
    let mut sink = |r: &[f64]| -> Result<(), IntegratorError> {
        streamed.push(r.to_vec());
        Ok(())
    };
    let mut steps = 0;
    let stopped = run_vehicle(
        sc,
        cargo,
        &mut |_| {
            steps += 1;
            steps < 50
        },
        Some(&mut sink),
    )
    .expect("built");
    let Err(f) = stopped else { panic!("a run its observer stops must fail") };
    let RunFailure { error, record } = *f;
    assert!(error.to_string().contains("stopped by its progress observer"), "{error}");
    let kept = n(&record);
    assert!((2..n(&full)).contains(&kept), "kept {kept} samples of {}", n(&full));
    // The stream is the record; a sample's load channels are complete (their hat-weighted
    // mean over the interval on each side) one recording interval after it, so every sample
    // but the last equals the full run's.
    assert_eq!(streamed.len(), kept, "every kept sample is in the stream");
    for (i, r) in streamed.iter().enumerate() {
        assert_eq!(&row(&record, i), r, "stream row {i} is the stopped run's record");
        if i + 1 < kept {
            assert_eq!(r, &rows[i], "completed sample {i} of the stopped run equals the full run's");
        }
    }
}

#[test]
fn every_cargo_runs_through_one_pipeline_with_its_stream_observer_and_failure() {
    let sc = scenario(300.0);
    check_pipeline(&RigidCargo, &sc, |r, i| r.row(i), |r| r.t.len());

    let eq = EquivalentCargo::new(870.0, 0.01, 0.5, vec![], SloshAxis::Longitudinal);
    let mut sc_eq = sc.clone();
    sc_eq.car.lading = None;
    check_pipeline(&eq, &sc_eq, |r, i| r.row(i), |r| r.train.t.len());

    let depth = sc_eq.car.tank_radius;
    let fluid = Oil::Light.fluid(depth, depth / 2.0).expect("fluid");
    let ancf = FluidCargo::new(fluid, [2, 2, 2], 0.5, vec![]);
    let mut sc_f = sc_eq.clone();
    sc_f.hht = TrainScenario::fluid_hht();
    check_pipeline(&ancf, &sc_f, |r, i| r.row(i), |r| r.train.t.len());
}

/// Runs `cargo` with checkpoints every 4 samples, stopped by its observer after `stop` steps;
/// then to its end without checkpoints; then resumed from the stopped run's last checkpoint.
/// The resumed run's samples must be the uninterrupted run's from the checkpoint's sample on,
/// bit for bit, and writing checkpoints must not change the run. Returns the checkpoint's sample
/// and the resumed and full records.
fn check_resume<C: Cargo>(
    cargo: &C,
    sc: &TrainScenario,
    stop: usize,
    row: impl Fn(&C::Record, usize) -> Vec<f64>,
    n: impl Fn(&C::Record) -> usize,
) -> (usize, C::Record, C::Record) {
    let dir = std::env::temp_dir().join(format!("railslosh-resume-{}-{stop}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let path = dir.join("run.ckpt");
    let mut sc_ck = sc.clone();
    sc_ck.checkpoints = Some(RunCheckpoints { path: path.clone(), every: 4 });
    let mut steps = 0;
    let stopped = run_vehicle(
        &sc_ck,
        cargo,
        &mut |_| {
            steps += 1;
            steps < stop
        },
        None,
    )
    .expect("built");
    let Err(f) = stopped else { panic!("the observer stops the run") };
    let cp = VehicleCheckpoint::from_bytes(&std::fs::read(&path).expect("a checkpoint was written")).expect("reads");
    assert!((cp.sample + 1).is_multiple_of(4), "taken after every 4th sample ({})", cp.sample);

    let mut rows: Vec<Vec<f64>> = Vec::new();
    let mut sink = |r: &[f64]| -> Result<(), IntegratorError> {
        rows.push(r.to_vec());
        Ok(())
    };
    let full = run_vehicle(sc, cargo, &mut |_| true, Some(&mut sink))
        .expect("built")
        .unwrap_or_else(|f| panic!("full run: {}", f.error));
    for (i, r) in rows.iter().enumerate().take(n(&f.record).saturating_sub(1)) {
        assert_eq!(&row(&f.record, i), r, "checkpoints do not change sample {i}");
    }

    let mut sc_re = sc.clone();
    sc_re.resume_from = Some(path.clone());
    let mut resumed_rows: Vec<Vec<f64>> = Vec::new();
    let mut sink = |r: &[f64]| -> Result<(), IntegratorError> {
        resumed_rows.push(r.to_vec());
        Ok(())
    };
    let resumed = run_vehicle(&sc_re, cargo, &mut |_| true, Some(&mut sink))
        .expect("built")
        .unwrap_or_else(|f| panic!("resumed run: {}", f.error));
    assert_eq!(n(&resumed), n(&full) - cp.sample, "the record starts at the checkpoint's sample");
    for (i, r) in resumed_rows.iter().enumerate() {
        assert_eq!(r, &rows[cp.sample + i], "resumed sample {} equals the full run's, bit for bit", cp.sample + i);
        assert_eq!(r, &row(&resumed, i));
    }
    // a checkpoint of another train is refused, naming the file
    let mut other = sc_re.clone();
    other.cars = sc.cars + 1;
    if let Ok(Err(f)) = run_vehicle(&other, cargo, &mut |_| true, None) {
        assert!(f.error.to_string().contains("checkpoint"), "{}", f.error);
    } else {
        panic!("resuming another train's checkpoint must fail");
    }
    std::fs::remove_dir_all(&dir).ok();
    (cp.sample, resumed, full)
}

#[test]
fn a_resumed_run_continues_bit_for_bit() {
    let mut sc = scenario(300.0);
    sc.t_end = 0.3;
    let (k, _, _) = check_resume(&RigidCargo, &sc, 170, |r, i| r.row(i), |r| r.t.len());
    assert!(k >= 3, "{k}");

    let eq = EquivalentCargo::new(870.0, 0.01, 0.5, vec![], SloshAxis::Longitudinal);
    let mut sc_eq = sc.clone();
    sc_eq.car.lading = None;
    check_resume(&eq, &sc_eq, 170, |r, i| r.row(i), |r| r.train.t.len());

    let depth = sc_eq.car.tank_radius;
    let fluid = Oil::Light.fluid(depth, depth / 2.0).expect("fluid");
    let ancf = FluidCargo::new(fluid, [2, 2, 2], 0.5, vec![]);
    let mut sc_f = sc_eq.clone();
    sc_f.hht = TrainScenario::fluid_hht();
    let (_, resumed, full) = check_resume(&ancf, &sc_f, 170, |r, i| r.row(i), |r| r.train.t.len());
    // the liquids' energy accounts and worst margins carry over
    assert_eq!(resumed.margins, full.margins);
    assert_eq!(resumed.train.steps, full.train.steps);
}
