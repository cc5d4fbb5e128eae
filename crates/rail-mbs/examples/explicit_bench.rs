//! Explicit against implicit slosh stepping, side by side in one run (issue 17 §4): the
//! seed-003 rectangular tank (0.416 × 0.324 m, water 0.132 m deep) under a 0.3 g lateral
//! pulse for 4 s, each stepper's wall time and its error against an implicit reference with
//! 1 ms steps on the same mesh (centre-of-mass history, RMS lateral load, f₁).
//!
//! `cargo run --release -p rail-mbs --example explicit_bench -- [NX NY NZ] [repeats] [bulk]`
//! (default 2 6 2, 3 repeats; medians printed as JSON lines). `tank`: the ECP study's tank
//! instead (see [`tank_car`]); `probe` and `trace`: the stable-step estimate at rest and along the
//! run. With `bulk`, the penalty bulk
//! modulus is swept over 1, 0.3 and 0.1 × the default 1000 ρ g H (1 repeat unless given), each
//! against the same reference at the default modulus, with the largest volume change.

use std::time::Instant;

use ancf_core::FluidBody;
use ancf_core::constitutive::Rheology;
use ancf_core::contact::{WallContact, WallContactLaw};
use ancf_core::element::QuadratureOptions;
use ancf_core::mesh::{CylinderTankSpec, box_mesh, cylinder_tank};
use ancf_core::tank::{TankGeometry, TankShape};
use rail_mbs::defaults::{Oil, liquid, slosh_params};
use rail_mbs::integrator::ExplicitParams;
use rail_mbs::slosh::analysis::dominant_frequency;
use rail_mbs::slosh::{PiecewiseAcceleration, PrescribedMotion, SloshFrame, SloshRecord, SloshRun, SloshSystem};

use ancf_core::constants::GRAVITY as G;
const L: [f64; 3] = [0.416, 0.324, 0.132];

/// The test tank with the penalty bulk modulus `bulk` × the default k_IC = 1000 ρ g H (the
/// penalty damping follows the default rule c_TD = 0.2 √(k_IC ρ) h_el, so it scales by √bulk).
fn system(counts: [usize; 3], bulk: f64) -> SloshSystem {
    let lo = [-0.5 * L[0], -0.5 * L[1], 0.0];
    let mesh = box_mesh(lo, L, counts).unwrap();
    let mut fluid = liquid(998.0, Rheology::Newtonian { viscosity: 1e-3 }, L[2], L[2] / counts[2] as f64).unwrap();
    fluid.bulk_penalty *= bulk;
    fluid.bulk_damping *= bulk.sqrt();
    let body = FluidBody::new(mesh, fluid, QuadratureOptions { viscous: 4, penalty: 4, mass: 4 }).unwrap();
    let geo = TankGeometry::new(TankShape::Box { min: lo, max: [0.5 * L[0], 0.5 * L[1], 0.4] }, vec![]).unwrap();
    let mut law = WallContactLaw::default_for(998.0, G, L[2]);
    law.points_per_edge = 4;
    let contact = WallContact::new(&body, geo, law).unwrap();
    let mut motion = PrescribedMotion::at_rest([0.0; 3]);
    motion.translation[1] = PiecewiseAcceleration::pulse(0.3 * G, 0.05, 0.45, 0.02).unwrap();
    SloshSystem::new(body, contact, motion, [0.0, 0.0, -G], SloshFrame::Inertial).unwrap()
}

fn run(counts: [usize; 3], bulk: f64, explicit: bool, h: f64) -> (SloshRecord, f64, usize, usize) {
    let tic = Instant::now();
    let sys = system(counts, bulk);
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
        let mut sys = system(counts, 1.0);
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
    let sys = system(counts, 1.0);
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

/// The tank of the ECP study as a slosh run: the tank car's tank (12 m over the heads, R = 1.5 m)
/// half full of the light crude on the paper's 6×4×2 mesh with the vehicle studies'
/// discretization (4³ penalty points, 4×4 contact points), braked at 0.08 g from t = 0.5 s
/// (ramp 0.3 s), wall damping ratio `zeta_w`; `penalty_damping` off sets c_TD = 0.
fn tank_car_tank(zeta_w: f64, penalty_damping: bool) -> SloshSystem {
    let g = rail_mbs::track::GRAVITY;
    let (r, head, fill) = (1.5, 0.5, 0.5);
    let spec = CylinderTankSpec {
        length: 12.0 - 2.0 * head,
        radius: r,
        head_depth: head,
        fill,
        n_length: 6,
        n_width: 4,
        n_height: 2,
        grading: 1.0,
    };
    let mesh = cylinder_tank(&spec).unwrap();
    let depth = 2.0 * r * fill;
    let mut fluid = Oil::Light.fluid(depth, depth / 2.0).unwrap();
    if !penalty_damping {
        fluid.bulk_damping = 0.0;
    }
    let body = FluidBody::new(mesh, fluid, QuadratureOptions { penalty: 4, ..QuadratureOptions::default() }).unwrap();
    let geo =
        TankGeometry::new(TankShape::Cylinder { length: spec.length, radius: r, head_depth: head }, vec![]).unwrap();
    let mut law = WallContactLaw::default_for(fluid.density, g, depth)
        .with_damping_ratio(zeta_w, fluid.density, g, depth)
        .unwrap();
    law.points_per_edge = 4;
    let contact = WallContact::new(&body, geo, law).unwrap();
    let mut motion = PrescribedMotion::at_rest([0.0; 3]);
    motion.translation[0] = PiecewiseAcceleration::pulse(-0.08 * g, 0.5, 10.0, 0.3).unwrap();
    SloshSystem::new(body, contact, motion, [0.0, 0.0, -g], SloshFrame::Inertial).unwrap()
}

/// What sets the explicit step on the tank car's tank, and the cost of 2 s against the implicit
/// stepper (`tank` argument): the stable-step estimate at rest (200 power iterations) and a 2 s run
/// for the shipped ECP configuration (ζ_w = 1) and with the damping terms removed one by one
/// (different models: the centre of mass and load are printed to show how far they move).
fn tank_car(t_end: f64) {
    let variants: [(&str, f64, bool); 4] = [
        ("as shipped (zeta_w 1)", 1.0, true),
        ("no penalty damping", 1.0, false),
        ("no penalty damping, zeta_w 0.1", 0.1, false),
        ("no penalty damping, zeta_w 0", 0.0, false),
    ];
    let implicit = |sys: SloshSystem| {
        let tic = Instant::now();
        let mut r = SloshRun::new(sys, 0.0, slosh_params()).unwrap();
        let ok = r.run_to(t_end, 0.01).is_ok();
        (r.record.clone(), *r.stats(), tic.elapsed().as_secs_f64(), ok)
    };
    let (reference, st, wall, _) = implicit(tank_car_tank(1.0, true));
    let n = reference.t.len() - 1;
    println!(
        "{{\"case\": \"tank_car_tank_2s\", \"stepper\": \"implicit\", \"variant\": \"as shipped (zeta_w 1)\", \"wall_s\": {wall:.2}, \
         \"steps\": {}, \"newton\": {}, \"jacobians\": {}, \"factorizations\": {}, \"time_assembly_s\": {:.2}, \
         \"time_factorization_s\": {:.2}, \"time_solve_s\": {:.2}, \"com_x\": {:.4}, \"force_x\": {:.0}}}",
        st.steps,
        st.newton_iterations,
        st.jacobian_evaluations,
        st.factorizations,
        st.time_assembly.as_secs_f64(),
        st.time_factorization.as_secs_f64(),
        st.time_solve.as_secs_f64(),
        reference.com_tank[n][0],
        reference.force_tank[n][0]
    );
    for (name, zeta_w, pd) in variants {
        let sys = tank_car_tank(zeta_w, pd);
        let (q, v) = sys.initial_state(0.0);
        let m_s = sys.body.scalar_mass().clone();
        let mut e =
            rail_mbs::integrator::Explicit::new(sys.clone(), &m_s, 0.0, q, v, ExplicitParams::default()).unwrap();
        let s = e.estimate_stable_step(200).unwrap();
        let tic = Instant::now();
        let mut r = SloshRun::new_explicit(sys, 0.0, ExplicitParams::default()).unwrap();
        let ok = r.run_to(t_end, 0.01).is_ok();
        let wall = tic.elapsed().as_secs_f64();
        let m = r.record.t.len() - 1;
        println!(
            "{{\"case\": \"tank_car_tank_2s\", \"stepper\": \"explicit\", \"variant\": \"{name}\", \"omega_max\": {:.1}, \
             \"damping_ratio\": {:.3}, \"damping_max\": {:.1}, \"critical_at_rest_s\": {:.3e}, \"wall_s\": {wall:.2}, \
             \"steps\": {}, \"mean_step_s\": {:.3e}, \"ran_to_end\": {ok}, \"com_x\": {:.4}, \"force_x\": {:.0}}}",
            s.omega_max,
            s.damping_ratio,
            s.damping_max,
            s.critical,
            r.stats().steps,
            t_end / r.stats().steps as f64,
            r.record.com_tank[m][0],
            r.record.force_tank[m][0]
        );
    }
}

fn main() {
    if std::env::args().any(|a| a == "tank") {
        return tank_car(2.0);
    }
    if std::env::args().any(|a| a == "probe") {
        return probe([2, 6, 2]);
    }
    if std::env::args().any(|a| a == "trace") {
        return trace([2, 6, 2]);
    }
    let sweep = std::env::args().any(|a| a == "bulk");
    let args: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let counts = if args.len() >= 3 { [args[0], args[1], args[2]] } else { [2, 6, 2] };
    let repeats = args.get(3).copied().unwrap_or(if sweep { 1 } else { 3 });
    // the reference: implicit, 1 ms steps, the default (stiffest) bulk modulus
    let (reference, ref_wall, _, _) = run(counts, 1.0, false, 1e-3);
    let com = |r: &SloshRecord| r.com_tank.iter().map(|c| c[1]).collect::<Vec<_>>();
    let fy = |r: &SloshRecord| r.force_tank.iter().map(|c| c[1]).collect::<Vec<_>>();
    let (rc, rf) = (com(&reference), fy(&reference));
    let range = rc.iter().cloned().fold(f64::MIN, f64::max) - rc.iter().cloned().fold(f64::MAX, f64::min);
    let rms = |r: &SloshRecord, f: &[f64]| {
        let v: Vec<f64> = r.t.iter().zip(f).filter(|(t, _)| **t >= 0.5).map(|(_, f)| f * f).collect();
        (v.iter().sum::<f64>() / v.len() as f64).sqrt()
    };
    // largest relative volume change over the run
    let dv = |r: &SloshRecord| r.volume.iter().map(|v| (v / r.volume[0] - 1.0).abs()).fold(0.0, f64::max);
    let f1_ref = dominant_frequency(&reference.t, &rf, 0.6, 0.5, 4.0);
    let rms_ref = rms(&reference, &rf);
    println!(
        "{{\"case\": \"reference\", \"mesh\": {counts:?}, \"stepper\": \"implicit\", \"h\": 0.001, \"wall_s\": {ref_wall:.2}, \"f1_hz\": {f1_ref:.4}, \"rms_fy_n\": {rms_ref:.3}, \"volume_change\": {:.2e}}}",
        dv(&reference)
    );
    let bulks: &[f64] = if sweep { &[1.0, 0.3, 0.1] } else { &[1.0] };
    for &bulk in bulks {
        for (name, explicit, h) in [("implicit", false, 5e-3), ("explicit", true, 5e-3)] {
            let mut walls = Vec::new();
            let mut last = None;
            for _ in 0..repeats {
                let (rec, wall, steps, forces) = run(counts, bulk, explicit, h);
                walls.push(wall);
                last = Some((rec, steps, forces));
            }
            let (rec, steps, forces) = last.unwrap();
            let (c, f) = (com(&rec), fy(&rec));
            let com_err =
                rec.t.iter().zip(&c).map(|(t, x)| (x - interp(&reference, &rc, *t)).abs()).fold(0.0, f64::max);
            let f1 = dominant_frequency(&rec.t, &f, 0.6, 0.5, 4.0);
            println!(
                "{{\"case\": \"rect_pulse_0.3g_4s\", \"mesh\": {counts:?}, \"bulk_factor\": {bulk}, \"stepper\": \"{name}\", \"h_record\": {h}, \
                 \"wall_s_median\": {:.3}, \"walls\": {walls:.3?}, \"steps\": {steps}, \"force_evaluations\": {forces}, \
                 \"com_error_of_range\": {:.4}, \"rms_fy_error\": {:.4}, \"f1_error\": {:.4}, \"volume_change\": {:.2e}, \"t_reached\": {:.3}}}",
                median(walls.clone()),
                com_err / range,
                rms(&rec, &f) / rms_ref - 1.0,
                f1 / f1_ref - 1.0,
                dv(&rec),
                rec.t.last().unwrap()
            );
        }
    }
}
