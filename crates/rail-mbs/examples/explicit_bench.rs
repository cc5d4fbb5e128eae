//! Explicit against implicit slosh stepping, side by side in one run (issue 17 §4): the
//! seed-003 rectangular tank (0.416 × 0.324 m, water 0.132 m deep) under a 0.3 g lateral
//! pulse for 4 s, each stepper's wall time and its error against an implicit reference with
//! 1 ms steps on the same mesh (centre-of-mass history, RMS lateral load, f₁).
//!
//! `cargo run --release -p rail-mbs --example explicit_bench -- [NX NY NZ] [repeats]`
//! (default 2 6 2, 3 repeats; medians printed as JSON lines).

use std::time::Instant;

use ancf_core::FluidBody;
use ancf_core::constitutive::Rheology;
use ancf_core::contact::{WallContact, WallContactLaw};
use ancf_core::element::QuadratureOptions;
use ancf_core::mesh::box_mesh;
use ancf_core::tank::{TankGeometry, TankShape};
use rail_mbs::integrator::ExplicitParams;
use rail_mbs::slosh::validate::{dominant_frequency, liquid, slosh_params};
use rail_mbs::slosh::{PiecewiseAcceleration, PrescribedMotion, SloshFrame, SloshRecord, SloshRun, SloshSystem};

const G: f64 = 9.81;
const L: [f64; 3] = [0.416, 0.324, 0.132];

fn system(counts: [usize; 3]) -> SloshSystem {
    let lo = [-0.5 * L[0], -0.5 * L[1], 0.0];
    let mesh = box_mesh(lo, L, counts).unwrap();
    let fluid = liquid(998.0, Rheology::Newtonian { viscosity: 1e-3 }, L[2], L[2] / counts[2] as f64).unwrap();
    let body = FluidBody::new(mesh, fluid, QuadratureOptions { viscous: 4, penalty: 4, mass: 4 }).unwrap();
    let geo = TankGeometry::new(TankShape::Box { min: lo, max: [0.5 * L[0], 0.5 * L[1], 0.4] }, vec![]).unwrap();
    let mut law = WallContactLaw::default_for(998.0, G, L[2]);
    law.points_per_edge = 4;
    let contact = WallContact::new(&body, geo, law).unwrap();
    let mut motion = PrescribedMotion::at_rest([0.0; 3]);
    motion.translation[1] = PiecewiseAcceleration::pulse(0.3 * G, 0.05, 0.45, 0.02).unwrap();
    SloshSystem::new(body, contact, motion, [0.0, 0.0, -G], SloshFrame::Inertial).unwrap()
}

fn run(counts: [usize; 3], explicit: bool, h: f64) -> (SloshRecord, f64, usize, usize) {
    let tic = Instant::now();
    let sys = system(counts);
    let mut r = if explicit {
        SloshRun::new_explicit(sys, 0.0, ExplicitParams::default()).unwrap()
    } else {
        SloshRun::new(sys, 0.0, slosh_params()).unwrap()
    };
    if let Err(e) = r.run_to(4.0, h) {
        eprintln!("run stopped: {}", e.error);
    }
    let s = *r.stats();
    (r.record.clone(), tic.elapsed().as_secs_f64(), s.steps, s.residual_evaluations)
}

fn interp(r: &SloshRecord, x: &[f64], t: f64) -> f64 {
    let k = r.t.partition_point(|s| *s < t).clamp(1, r.t.len() - 1);
    let s = ((t - r.t[k - 1]) / (r.t[k] - r.t[k - 1])).clamp(0.0, 1.0);
    x[k - 1] + s * (x[k] - x[k - 1])
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

/// The stable-step estimate at rest, and what sets it (`probe` argument).
fn probe(counts: [usize; 3]) {
    type Adjust = fn(&mut SloshSystem);
    let variants: [(&str, Adjust); 4] = [
        ("as built", |_| {}),
        ("no penalty damping", |s| s.body.fluid.bulk_damping = 0.0),
        ("no contact damping", |s| s.contact.law.damping = 0.0),
        ("contact stiffness x0.1", |s| s.contact.law.stiffness *= 0.1),
    ];
    for (name, adjust) in variants {
        let mut sys = system(counts);
        adjust(&mut sys);
        let (q, v) = sys.initial_state(0.0);
        let m_s = sys.body.scalar_mass().clone();
        let mut e = rail_mbs::integrator::Explicit::new(sys, &m_s, 0.0, q, v, ExplicitParams::default()).unwrap();
        let s = e.estimate_stable_step(200).unwrap();
        println!(
            "{{\"probe\": \"{name}\", \"omega_max\": {:.1}, \"damping_ratio\": {:.3}, \"critical_s\": {:.3e}}}",
            s.omega_max, s.damping_ratio, s.critical
        );
    }
}

/// The stable-step estimates along the explicit run (`trace` argument).
fn trace(counts: [usize; 3]) {
    let sys = system(counts);
    let (q, v) = sys.initial_state(0.0);
    let m_s = sys.body.scalar_mass().clone();
    let mut e = rail_mbs::integrator::Explicit::new(sys, &m_s, 0.0, q, v, ExplicitParams::default()).unwrap();
    for k in 1..=16 {
        let s0 = e.stats().steps;
        e.advance_to(0.25 * k as f64).unwrap();
        let est = e.last_estimate().unwrap();
        let fresh = e.estimate_stable_step(200).unwrap();
        println!(
            "{{\"t\": {:.2}, \"steps\": {}, \"running_critical\": {:.3e}, \"xi\": {:.2}, \"converged_critical\": {:.3e}, \"xi200\": {:.2}}}",
            e.t(),
            e.stats().steps - s0,
            est.critical,
            est.damping_ratio,
            fresh.critical,
            fresh.damping_ratio
        );
    }
}

fn main() {
    if std::env::args().any(|a| a == "probe") {
        return probe([2, 6, 2]);
    }
    if std::env::args().any(|a| a == "trace") {
        return trace([2, 6, 2]);
    }
    let args: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let counts = if args.len() >= 3 { [args[0], args[1], args[2]] } else { [2, 6, 2] };
    let repeats = args.get(3).copied().unwrap_or(3);
    let (reference, ref_wall, _, _) = run(counts, false, 1e-3);
    let com = |r: &SloshRecord| r.com_tank.iter().map(|c| c[1]).collect::<Vec<_>>();
    let fy = |r: &SloshRecord| r.force_tank.iter().map(|c| c[1]).collect::<Vec<_>>();
    let (rc, rf) = (com(&reference), fy(&reference));
    let range = rc.iter().cloned().fold(f64::MIN, f64::max) - rc.iter().cloned().fold(f64::MAX, f64::min);
    let rms = |r: &SloshRecord, f: &[f64]| {
        let v: Vec<f64> = r.t.iter().zip(f).filter(|(t, _)| **t >= 0.5).map(|(_, f)| f * f).collect();
        (v.iter().sum::<f64>() / v.len() as f64).sqrt()
    };
    let f1_ref = dominant_frequency(&reference.t, &rf, 0.6, 0.5, 4.0);
    let rms_ref = rms(&reference, &rf);
    println!(
        "{{\"case\": \"reference\", \"mesh\": {counts:?}, \"stepper\": \"implicit\", \"h\": 0.001, \"wall_s\": {ref_wall:.2}, \"f1_hz\": {f1_ref:.4}, \"rms_fy_n\": {rms_ref:.3}}}"
    );
    for (name, explicit, h) in [("implicit", false, 5e-3), ("explicit", true, 5e-3)] {
        let mut walls = Vec::new();
        let mut last = None;
        for _ in 0..repeats {
            let (rec, wall, steps, forces) = run(counts, explicit, h);
            walls.push(wall);
            last = Some((rec, steps, forces));
        }
        let (rec, steps, forces) = last.unwrap();
        let (c, f) = (com(&rec), fy(&rec));
        let com_err = rec.t.iter().zip(&c).map(|(t, x)| (x - interp(&reference, &rc, *t)).abs()).fold(0.0, f64::max);
        let f1 = dominant_frequency(&rec.t, &f, 0.6, 0.5, 4.0);
        println!(
            "{{\"case\": \"rect_pulse_0.3g_4s\", \"mesh\": {counts:?}, \"stepper\": \"{name}\", \"h_record\": {h}, \
             \"wall_s_median\": {:.3}, \"walls\": {walls:.3?}, \"steps\": {steps}, \"force_evaluations\": {forces}, \
             \"com_error_of_range\": {:.4}, \"rms_fy_error\": {:.4}, \"f1_error\": {:.4}, \"t_reached\": {:.3}}}",
            median(walls.clone()),
            com_err / range,
            rms(&rec, &f) / rms_ref - 1.0,
            f1 / f1_ref - 1.0,
            rec.t.last().unwrap()
        );
    }
}
