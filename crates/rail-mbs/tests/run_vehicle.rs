//! The one vehicle-run pipeline (issue 18): every fluid model (rigid lading, equivalent slosh
//! model, ANCF fluid) runs through `run_vehicle` over the `Cargo` trait, with the same observer,
//! results stream and failure type.

use std::sync::Arc;

use rail_mbs::defaults::Oil;
use rail_mbs::integrator::IntegratorError;
use rail_mbs::track::Track;
use rail_mbs::vehicle::{
    Cargo, EquivalentCargo, FluidCargo, RigidCargo, RunFailure, SloshAxis, TankCarParams, TrainScenario, run_vehicle,
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
