//! `cargo bench -p rail-mbs --bench train`: speed of a vehicle run (issue 4 "Speed").
//!
//! Two coupled tank cars (rigid, no fluid; 36 t rigid lading per car 0.5 m below the tank
//! axis), the front car held to 60 km/h by the trajectory constraint, adaptive HHT
//! (α = −0.3, h ≤ 1 ms, recording every 10 ms as `run_train` does), on
//!
//! * the Table 1 track of seed 000 (US units; cant base 1.5 m), front tank centre at
//!   400 ft so that both cars run inside the 3-degree left curve for the whole run, and
//! * tangent track, for comparison.
//!
//! Part 1 reports simulated seconds per wall second, steps, Newton iterations per step,
//! Jacobian evaluations and the share of wall time in assembly (forces, constraints and
//! Jacobians) and in the LU factorization (median of `repeats` runs, by wall time).
//!
//! Part 2 times the wheel/rail contact search of one loaded wheel at a realistic pose
//! (the outer front wheel at the end of a curve run): `WheelRailContact::evaluate`,
//! `find_geometry` and the contact-point `newton` alone, median of many calls, and — for
//! comparison only, the vehicle runs keep the defaults — the warm-start-only search
//! (`always_scan = false`) and a coarser scan. `evaluate` is also timed for every wheel of
//! the train at the end of the curve and of the tangent run. It then counts the contact
//! evaluations of a step: each residual evaluates every wheel once, each Jacobian
//! evaluation once with the full search and 14 times warm-started
//! (`WheelRailContact::evaluate_perturbed`, the forward differences over the 7 coordinates
//! and 7 velocities of the wheelset, see `Multibody::force_jacobians`), and gives the
//! contact cost per wheel per step and its share of the wall time.
//!
//! Arguments: `quick` (0.3 s simulated, 1 repeat), `sim=<s>` (default 1.0),
//! `repeats=<n>` (default 5).

use std::hint::black_box;
use std::sync::Arc;
use std::time::{Duration, Instant};

use rail_mbs::integrator::{Hht, MechanicalSystem, Stats};
use rail_mbs::mbs::{Multibody, SpeedProfile};
use rail_mbs::observe::step_to;
use rail_mbs::track::{FOOT, Track, TrackPoint};
use rail_mbs::vehicle::{TankCarParams, TrainScenario, build_train};
use rail_mbs::wheel_rail::{WheelPose, WheelRailContact};

/// Table 1 of seed 000 (the studies' definition).
fn table1() -> Arc<Track> {
    rail_mbs::track::presets::table1().expect("table 1 track")
}

fn tangent() -> Arc<Track> {
    let pts = vec![TrackPoint::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0), TrackPoint::new(3000.0, 0.0, 0.0, 0.0, 0.0, 0.0)];
    Arc::new(Track::new(pts).expect("tangent track"))
}

fn scenario(track: Arc<Track>, station: f64, t_end: f64) -> TrainScenario {
    let mut car = TankCarParams::standard().expect("standard car");
    car.lading = Some((36_000.0, -0.5));
    let v = 60.0 / 3.6;
    let mut sc = TrainScenario::single(car, track, station, v, t_end);
    sc.cars = 2;
    sc.drive = Some(SpeedProfile::Constant(v));
    sc
}

struct RunResult {
    wall: f64,
    sim: f64,
    stats: Stats,
    hht: Hht<Multibody>,
}

/// The `run_train` loop (its step loop `step_to`: steps of at most `sc.step` landing on every
/// recording time; the contacts evaluated once per sample as the recording does) with the
/// integrator kept.
fn run(sc: &TrainScenario) -> RunResult {
    let (mb, _, _) = build_train(sc).expect("train builds");
    let (q0, v0) = mb.initial_coordinates();
    let start = Instant::now();
    let mut hht = Hht::new(mb, 0.0, q0, v0, sc.hht).expect("integrator starts");
    let n_rec = (sc.t_end / sc.record_every).round() as usize;
    for k in 0..=n_rec {
        let target = (k as f64 * sc.record_every).min(sc.t_end);
        if let Err(e) = step_to(&mut hht, target, sc.step, sc.t_end, &mut |_| true, |_, _| Ok(())) {
            panic!("run failed at t = {}: {e}", hht.t());
        }
        let (q, v) = (hht.q().to_vec(), hht.v().to_vec());
        black_box(hht.system_mut().wheelset_reports(&q, &v).expect("contact report"));
    }
    let wall = start.elapsed().as_secs_f64();
    RunResult { wall, sim: hht.t(), stats: *hht.stats(), hht }
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) }
}

/// Median time (s) of `f` over `n` calls (after 10 warm-up calls).
fn time_calls(n: usize, mut f: impl FnMut()) -> f64 {
    for _ in 0..10 {
        f();
    }
    let mut t: Vec<f64> = (0..n)
        .map(|_| {
            let tic = Instant::now();
            f();
            tic.elapsed().as_secs_f64()
        })
        .collect();
    median(&mut t)
}

fn pct(part: Duration, total: Duration) -> f64 {
    100.0 * part.as_secs_f64() / total.as_secs_f64().max(1e-300)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "quick");
    let arg = |key: &str, default: f64| {
        args.iter().find_map(|a| a.strip_prefix(key).and_then(|v| v.parse::<f64>().ok())).unwrap_or(default)
    };
    let sim = arg("sim=", if quick { 0.3 } else { 1.0 });
    let repeats = arg("repeats=", if quick { 1.0 } else { 5.0 }).max(1.0) as usize;
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!(
        "train run: 2 tank cars, 36 t rigid lading each, front car driven at 60 km/h, {sim} s simulated, \
         median of {repeats} runs ({threads} hardware threads; the vehicle model is single-threaded)"
    );
    println!(
        "{:>16} {:>5} {:>8} {:>8} {:>12} {:>6} {:>5} {:>8} {:>7} {:>9} {:>5} {:>6} {:>10}",
        "track",
        "DOF",
        "sim s",
        "wall s",
        "sim s/wall s",
        "steps",
        "rej",
        "it/step",
        "jac ev",
        "res ev",
        "LU",
        "asm %",
        "LU+solve %"
    );
    let curve_station = 400.0 * FOOT;
    let cases: [(&str, Arc<Track>, f64); 2] =
        [("Table 1, 3° curve", table1(), curve_station), ("tangent", tangent(), curve_station)];
    let mut curve_end: Option<(Hht<Multibody>, Stats, f64)> = None;
    let mut tangent_end: Option<Hht<Multibody>> = None;
    for (name, track, station) in cases {
        let sc = scenario(track, station, sim);
        let mut runs: Vec<RunResult> = (0..repeats).map(|_| run(&sc)).collect();
        runs.sort_by(|a, b| a.wall.total_cmp(&b.wall));
        let walls: Vec<String> = runs.iter().map(|r| format!("{:.2}", r.wall)).collect();
        let r = runs.swap_remove(runs.len() / 2);
        let s = &r.stats;
        println!(
            "{:>16} {:>5} {:>8.2} {:>8.2} {:>12.4} {:>6} {:>5} {:>8.2} {:>7} {:>9} {:>5} {:>5.0}% {:>9.0}%   (walls {})",
            name,
            r.hht.system().dof(),
            r.sim,
            r.wall,
            r.sim / r.wall,
            s.steps,
            s.rejected_steps,
            s.newton_iterations as f64 / s.steps.max(1) as f64,
            s.jacobian_evaluations,
            s.residual_evaluations,
            s.factorizations,
            pct(s.time_assembly, s.time_total),
            pct(s.time_factorization + s.time_solve, s.time_total),
            walls.join(" "),
        );
        if curve_end.is_none() {
            let wall = r.wall;
            curve_end = Some((r.hht, r.stats, wall));
        } else {
            tangent_end = Some(r.hht);
        }
    }

    let calls = if quick { 300 } else { 2000 };
    // Mean over every wheel of the train of the median time of `evaluate`, and the number
    // of wheels with two contact points.
    let all_wheels = |hht: &Hht<Multibody>| {
        let (q, v) = (hht.q(), hht.v());
        let mb = hht.system();
        let mut times = Vec::new();
        let mut two_point = 0;
        for ws in mb.wheelsets() {
            let s = mb.state(Some(ws.body), q, v);
            let pose = WheelPose {
                position: s.position,
                rotation: s.rotation,
                velocity: s.velocity,
                angular_velocity: s.angular_velocity,
            };
            for wheel in &ws.wheels {
                let mut w = wheel.clone();
                two_point += usize::from(w.evaluate(&pose).expect("contact").len() > 1);
                times.push(time_calls(calls / 4, || {
                    black_box(w.evaluate(black_box(&pose)).expect("contact"));
                }));
            }
        }
        let n = times.len() as f64;
        let (lo, hi) = times.iter().fold((f64::INFINITY, 0.0f64), |(a, b), t| (a.min(*t), b.max(*t)));
        (times.iter().sum::<f64>() / n, lo, hi, two_point, times.len())
    };
    let tangent_wheels = all_wheels(&tangent_end.expect("tangent run"));

    // Part 2: contact search cost, at the end state of the median curve run.
    let (mut hht, stats, wall) = curve_end.expect("curve run");
    let (mean_wheel, lo, hi, two_point, wheels) = all_wheels(&hht);
    let (q, v) = (hht.q().to_vec(), hht.v().to_vec());
    let t = hht.t();
    let mb = hht.system_mut();
    let dof = mb.dof();
    let ws0 = mb.wheelsets()[0].clone();
    let pose = {
        let s = mb.state(Some(ws0.body), &q, &v);
        WheelPose {
            position: s.position,
            rotation: s.rotation,
            velocity: s.velocity,
            angular_velocity: s.angular_velocity,
        }
    };
    // Outer (right) wheel of the front wheelset in the left-hand curve: flange closest.
    let wheel: WheelRailContact = ws0.wheels[1].clone();
    let mut w = wheel.clone();
    let pts = w.evaluate(&pose).expect("contact");
    let load: f64 = pts.iter().map(|p| p.normal_force).sum();
    let t_eval = time_calls(calls, || {
        black_box(w.evaluate(black_box(&pose)).expect("contact"));
    });
    let t_geo = time_calls(calls, || {
        black_box(w.find_geometry(black_box(&pose)).expect("contact"));
    });
    let q_prev = w.previous_solutions()[0];
    let t_newton = time_calls(calls, || {
        black_box(w.newton(black_box(&pose), q_prev).expect("newton"));
    });
    let mut warm = wheel.clone();
    warm.settings.always_scan = false;
    warm.evaluate(&pose).expect("contact");
    let t_warm = time_calls(calls, || {
        black_box(warm.evaluate(black_box(&pose)).expect("contact"));
    });
    // a Jacobian column's evaluation at a pose 1e-7 m away (as Multibody::force_jacobians)
    let mut column = wheel.clone();
    column.evaluate(&pose).expect("contact");
    let moved = WheelPose { position: pose.position + nalgebra::Vector3::new(0.0, 1e-7, 0.0), ..pose };
    let t_perturbed = time_calls(calls, || {
        black_box(column.evaluate_perturbed(black_box(&moved)).expect("contact"));
    });
    let mut coarse = wheel.clone();
    coarse.settings.scan_points = 100;
    let n_coarse = coarse.evaluate(&pose).expect("contact").len();
    let t_coarse = time_calls(calls, || {
        black_box(coarse.evaluate(black_box(&pose)).expect("contact"));
    });
    // Whole-system callbacks at the same state (for the contact share of a Jacobian).
    let pat = mb.pattern();
    let (mut dq, mut dv) = (vec![0.0; pat.dynamics.len()], vec![0.0; pat.dynamics.len()]);
    let mut f = vec![0.0; mb.n_coords()];
    let reps = if quick { 5 } else { 21 };
    let t_jac = time_calls(reps, || {
        dq.fill(0.0);
        dv.fill(0.0);
        mb.force_jacobians(t, &q, &v, &mut dq, &mut dv).expect("jacobians");
    });
    let t_forces = time_calls(reps * 10, || {
        mb.forces(t, &q, &v, &mut f).expect("forces");
    });

    // Per wheel and step: one full evaluation per residual, per Jacobian evaluation and per
    // recorded sample, and 14 warm-started ones per Jacobian evaluation.
    let steps = stats.steps.max(1) as f64;
    let samples = (sim / 0.01).round() + 1.0;
    let jacobians = stats.jacobian_evaluations as f64;
    let per_step = (stats.residual_evaluations as f64 + jacobians + samples) / steps;
    let perturbed_per_step = 14.0 * jacobians / steps;
    let wall_per_step = wall / steps;
    let contact_per_wheel_step = per_step * mean_wheel + perturbed_per_step * t_perturbed;
    let jacobian_contact = mean_wheel + 14.0 * t_perturbed;
    println!();
    println!(
        "contact search at the end of the median curve run (t = {t:.2} s), median of {calls} calls \
         ({} per wheel for the all-wheel figures)",
        calls / 4
    );
    println!("{:<64} {:>12}", "quantity", "value");
    let row = |name: &str, value: String| println!("{name:<64} {value:>12}");
    let us = |x: f64| format!("{:.1} µs", 1e6 * x);
    row("outer front wheel: contact points / Q (kN)", format!("{} / {:.1}", pts.len(), load / 1e3));
    row("  WheelRailContact::evaluate (scan every call, default)", us(t_eval));
    row("  WheelRailContact::find_geometry (scan every call)", us(t_geo));
    row("  WheelRailContact::newton from the converged point", us(t_newton));
    row("  evaluate, warm start only (always_scan = false)", us(t_warm));
    row("  evaluate_perturbed (a Jacobian column, 1e-7 m away)", us(t_perturbed));
    row(&format!("  evaluate, scan_points 100 instead of 200 ({n_coarse} points)"), us(t_coarse));
    row(
        &format!("all {wheels} wheels: evaluate mean (min-max); {two_point} with 2 points"),
        format!("{:.1} ({:.0}-{:.0}) µs", 1e6 * mean_wheel, 1e6 * lo, 1e6 * hi),
    );
    row(
        &format!("tangent run end: all {} wheels mean (min-max); {} with 2 points", tangent_wheels.4, tangent_wheels.3),
        format!("{:.1} ({:.0}-{:.0}) µs", 1e6 * tangent_wheels.0, 1e6 * tangent_wheels.1, 1e6 * tangent_wheels.2),
    );
    row(&format!("Multibody::forces ({dof} DOF, {wheels} wheels)"), format!("{:.2} ms", 1e3 * t_forces));
    row("Multibody::force_jacobians", format!("{:.2} ms", 1e3 * t_jac));
    row(
        &format!("  contact share of force_jacobians ({wheels} x (1 full + 14 perturbed))"),
        format!("{:.0} %", 100.0 * wheels as f64 * jacobian_contact / t_jac),
    );
    row("full contact evaluations per wheel per step", format!("{per_step:.2}"));
    row("  of which for Jacobians (1 per Jacobian evaluation)", format!("{:.2}", jacobians / steps));
    row("perturbed evaluations per wheel per step (14 per Jacobian)", format!("{perturbed_per_step:.2}"));
    row("contact cost per wheel per step", us(contact_per_wheel_step));
    row("wall time per step (median curve run)", format!("{:.2} ms", 1e3 * wall_per_step));
    row(
        &format!("contact share of wall time ({wheels} wheels)"),
        format!("{:.0} %", 100.0 * wheels as f64 * contact_per_wheel_step / wall_per_step),
    );
}
