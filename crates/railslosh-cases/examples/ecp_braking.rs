//! One braking run of the crude-oil studies with its wall time and Newton statistics:
//! `cargo run --release -p railslosh-cases --example ecp_braking -- [light|medium|heavy|water] [nx ny nz] [t_end] [ecp|conventional] [bulkheads|-] [wall_damping_ratio] [condensed|direct] [wall_adhesion] [stab|-]`
use rail_mbs::defaults::{Oil, SETTLE};
use rail_mbs::vehicle::BrakeScope;
use railslosh_cases::vehicle::studies::{BrakingCase, run_braking};

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let oil = Oil::from_name(a.first().map_or("light", |s| s.as_str())).unwrap_or(Oil::Light);
    let n = |i: usize, d: usize| a.get(i).map_or(d, |s| s.parse().unwrap());
    let counts = [n(1, 6), n(2, 4), n(3, 2)];
    let t_end: f64 = a.get(4).map_or(SETTLE + 10.0, |s| s.parse().unwrap());
    let scope =
        if a.get(5).map(|s| s.as_str()) == Some("conventional") { BrakeScope::FrontCar } else { BrakeScope::AllCars };
    let bulkheads = a.get(6).map(|s| s.as_str()) == Some("bulkheads");
    let wall_damping_ratio = a.get(7).map_or(ancf_core::contact::WALL_DAMPING_RATIO, |s| s.parse().unwrap());
    let linear_solver = if a.get(8).map(|s| s.as_str()) == Some("direct") {
        rail_mbs::integrator::LinearSolverKind::Direct
    } else {
        rail_mbs::integrator::LinearSolverKind::Condensed
    };
    let case = BrakingCase {
        oil,
        cars: 2,
        scope,
        bulkheads,
        counts,
        t_end,
        rear_brake_factor: 1.0,
        wall_damping_ratio,
        wall_adhesion: a.get(9).map_or(0.0, |s| s.parse().unwrap()),
        linear_solver,
        shear_stabilization: a.get(10).map(|s| s.as_str()) == Some("stab"),
    };
    let r = run_braking(&case).expect("run");
    let s = &r.train;
    let peak = s.coupler_force.iter().map(|c| c[0].abs()).fold(0.0, f64::max);
    println!(
        "{} crude, {:?}, {} elements/tank, {:.1} s simulated: wall {:.1} s ({:.3} sim s per wall s), steps {} (rejected {}), Newton {} ({:.2}/step), Jacobians {}, time in assembly / factorization / solves {:.1} / {:.1} / {:.1} s, peak |coupler| {:.0} N, final speed {:.2} km/h, max |volume error| {:.2e}",
        oil.name(),
        scope,
        r.elements,
        t_end,
        s.wall_time,
        t_end / s.wall_time,
        s.steps,
        s.rejected_steps,
        s.newton_iterations,
        s.newton_iterations as f64 / s.steps as f64,
        s.jacobian_evaluations,
        s.time_split[0],
        s.time_split[1],
        s.time_split[2],
        peak,
        s.tank_speed.last().map_or(f64::NAN, |v| v[0] * 3.6),
        r.volume_error.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()))
    );
}
