//! The explicit, factor-once fluid stepper (issue 17): the mass solve, energy conservation,
//! the stable-step estimate against the measured limit, agreement with the implicit stepper,
//! bitwise results for any thread count, and bitwise checkpoint/restart.

use ancf_core::FluidBody;
use ancf_core::constitutive::Rheology;
use ancf_core::contact::{WallContact, WallContactLaw};
use ancf_core::element::QuadratureOptions;
use ancf_core::mesh::box_mesh;
use ancf_core::tank::{TankGeometry, TankShape};
use rail_mbs::defaults::liquid;
use rail_mbs::integrator::{BlockMass, Explicit, ExplicitCheckpoint, ExplicitParams};
use rail_mbs::slosh::analysis::dominant_frequency;
use rail_mbs::slosh::{PiecewiseAcceleration, PrescribedMotion, SloshFrame, SloshRun, SloshSystem};

use ancf_core::constants::GRAVITY as G;
const RHO: f64 = 998.0;
// seed 003's rectangular tank: 0.416 × 0.324 m, water 0.132 m deep
const L: [f64; 3] = [0.416, 0.324, 0.132];

/// Water in the seed-003 box tank (2×4×2, 4³ force points), lid at `lid` m, viscosity
/// `mu`, wall law adjusted by `adjust`, lateral pulse `pulse` m/s² on [0.05, 0.45] s.
fn box_system(lid: f64, mu: f64, pulse: f64, adjust: impl FnOnce(&mut WallContactLaw)) -> SloshSystem {
    let lo = [-0.5 * L[0], -0.5 * L[1], 0.0];
    let mesh = box_mesh(lo, L, [2, 4, 2]).unwrap();
    let mut fluid = liquid(RHO, Rheology::Newtonian { viscosity: mu }, L[2], L[2] / 2.0).unwrap();
    if mu == 0.0 {
        fluid.bulk_damping = 0.0; // undamped: no viscous stress, no penalty damping
    }
    let body = FluidBody::new(mesh, fluid, QuadratureOptions { viscous: 4, penalty: 4, mass: 4 }).unwrap();
    let geo = TankGeometry::new(TankShape::Box { min: lo, max: [0.5 * L[0], 0.5 * L[1], lid] }, vec![]).unwrap();
    let mut law = WallContactLaw::default_for(RHO, G, L[2]);
    adjust(&mut law);
    let contact = WallContact::new(&body, geo, law).unwrap();
    let mut motion = PrescribedMotion::at_rest([0.0; 3]);
    if pulse != 0.0 {
        motion.translation[1] = PiecewiseAcceleration::pulse(pulse, 0.05, 0.45, 0.02).unwrap();
    }
    SloshSystem::new(body, contact, motion, [0.0, 0.0, -G], SloshFrame::Inertial).unwrap()
}

/// Kinetic + gravitational + stored (penalty, contact) energy of the explicit state.
fn energy(e: &Explicit<SloshSystem>) -> f64 {
    let s = e.system();
    let kin = s.contact_kinematics(e.t());
    s.body.kinetic_energy(e.v())
        + s.body.potential_energy(e.q(), s.gravity)
        + rail_mbs::invariants::stored_energy(&s.body, &s.contact, &kin, e.q())
}

/// An undamped sloshing start: the reference mesh with a lateral velocity field
/// v_y = 0.1 z/H (m/s), which excites the sloshing and the compressive modes.
fn undamped_start(sys: &SloshSystem) -> (Vec<f64>, Vec<f64>) {
    let (q, mut v) = sys.initial_state(0.0);
    for (s, vs) in v.chunks_exact_mut(3).enumerate() {
        let node = s / 4;
        match s % 4 {
            0 => vs[1] = 0.1 * q[12 * node + 2] / L[2],
            3 => vs[1] = 0.1 / L[2], // ∂v/∂z
            _ => {}
        }
    }
    (q, v)
}

fn undamped_box() -> SloshSystem {
    box_system(0.3, 0.0, 0.0, |law| law.damping = 0.0)
}

#[test]
fn the_factored_mass_solves_m_a_equals_f() {
    let sys = undamped_box();
    let m = sys.body.scalar_mass();
    let mut mass = BlockMass::new(m).unwrap();
    let n = 3 * m.nrows();
    let f: Vec<f64> = (0..n).map(|i| ((i * 7919) % 101) as f64 - 50.0).collect();
    let mut a = vec![0.0; n];
    mass.solve(&f, &mut a);
    // M a with M = M_s ⊗ I3
    let mut ma = vec![0.0; n];
    let m = m.as_ref();
    for j in 0..m.ncols() {
        for (i, val) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
            for k in 0..3 {
                ma[3 * i + k] += val * a[3 * j + k];
            }
        }
    }
    let worst = ma.iter().zip(&f).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    assert!(worst < 1e-9 * 50.0, "|M a − f| = {worst}");
}

#[test]
fn an_undamped_fluid_in_a_closed_box_conserves_energy() {
    let sys = undamped_box();
    let (q, v) = undamped_start(&sys);
    let m_s = sys.body.scalar_mass().clone();
    let mut e = Explicit::new(sys, &m_s, 0.0, q, v, ExplicitParams::default()).unwrap();
    let e0 = energy(&e);
    let ke0 = e.system().body.kinetic_energy(e.v());
    let mut worst = [0.0_f64; 2];
    for k in 1..=100 {
        e.advance_to(0.02 * k as f64).unwrap();
        worst[(k - 1) / 50] = worst[(k - 1) / 50].max((energy(&e) - e0).abs());
    }
    // symplectic: the energy error is a bounded fraction of the kinetic energy put in
    // (0.2 % at 0.8 of the critical step), and does not grow from the first second to the second
    assert!(worst[1] < 5e-3 * ke0, "energy error {worst:?} J of {ke0} J kinetic ({} steps)", e.stats().steps);
    assert!(worst[1] < 1.5 * worst[0], "energy error grows: {worst:?} J");
    assert!(e.stats().steps > 100, "steps {}", e.stats().steps);
}

/// Runs `steps` fixed steps of `h`; whether the energy stayed bounded.
fn stays_bounded(h: f64, steps: usize) -> bool {
    let sys = undamped_box();
    let (q, v) = undamped_start(&sys);
    let m_s = sys.body.scalar_mass().clone();
    let mut e = Explicit::new(sys, &m_s, 0.0, q, v, ExplicitParams::default()).unwrap();
    let e0 = energy(&e);
    for _ in 0..steps {
        if e.step(h).is_err() {
            return false;
        }
    }
    let e1 = energy(&e);
    e1.is_finite() && (e1 - e0).abs() < 0.5 * e0.abs().max(1.0)
}

#[test]
fn the_measured_stable_step_matches_the_estimate_within_20_percent() {
    let sys = undamped_box();
    let (q, v) = undamped_start(&sys);
    let m_s = sys.body.scalar_mass().clone();
    let mut e = Explicit::new(sys, &m_s, 0.0, q, v, ExplicitParams::default()).unwrap();
    let est = e.estimate_stable_step(200).unwrap();
    assert!(est.damping_ratio < 1e-3, "undamped: ξ = {}", est.damping_ratio);
    // bisection on the fixed step between a stable and an unstable one
    let (mut lo, mut hi) = (0.5 * est.critical, 2.0 * est.critical);
    assert!(stays_bounded(lo, 400), "unstable at half the estimate {}", est.critical);
    assert!(!stays_bounded(hi, 400), "stable at twice the estimate {}", est.critical);
    for _ in 0..8 {
        let mid = 0.5 * (lo + hi);
        if stays_bounded(mid, 400) { lo = mid } else { hi = mid }
    }
    let measured = 0.5 * (lo + hi);
    let ratio = measured / est.critical;
    assert!((ratio - 1.0).abs() <= 0.2, "measured {measured:e} s against the estimate {:e} s", est.critical);
}

fn pulse_run(explicit: bool, t_end: f64) -> SloshRun {
    let sys = box_system(0.3, 1e-3, 0.03 * G, |_| {});
    let mut run = if explicit {
        SloshRun::new_explicit(sys, 0.0, ExplicitParams::default()).unwrap()
    } else {
        SloshRun::new(sys, 0.0, rail_mbs::defaults::slosh_params()).unwrap()
    };
    run.run_to(t_end, 0.005).unwrap();
    run
}

#[test]
fn explicit_and_implicit_agree_on_hydrostatics_and_the_sloshing_frequency() {
    let (ex, im) = (pulse_run(true, 3.0), pulse_run(false, 3.0));
    let (re, ri) = (&ex.record, &im.record);
    // the implicit stepper may shorten steps: compare on the explicit record's times
    let at = |r: &rail_mbs::slosh::SloshRecord, x: &dyn Fn(usize) -> f64, t: f64| {
        let k = r.t.partition_point(|s| *s < t).clamp(1, r.t.len() - 1);
        let s = ((t - r.t[k - 1]) / (r.t[k] - r.t[k - 1])).clamp(0.0, 1.0);
        x(k - 1) + s * (x(k) - x(k - 1))
    };
    // hydrostatics: at rest before the pulse the walls carry the weight
    let w = ex.stepper.system().body.total_mass() * G;
    // hydrostatics: on average the walls carry the weight (the liquid starts from the
    // unloaded mesh and settles, then sloshes laterally)
    let fz = |r: &rail_mbs::slosh::SloshRecord| {
        let v: Vec<f64> = r.t.iter().zip(&r.force_tank).filter(|(t, _)| **t >= 1.0).map(|(_, f)| f[2]).collect();
        -v.iter().sum::<f64>() / v.len() as f64
    };
    assert!((fz(re) / w - 1.0).abs() < 0.01 && (fz(ri) / w - 1.0).abs() < 0.01, "{} {} {w}", fz(re), fz(ri));
    // f1 from the lateral load after the pulse
    let fy = |r: &rail_mbs::slosh::SloshRecord| r.force_tank.iter().map(|f| f[1]).collect::<Vec<_>>();
    let fe = dominant_frequency(&re.t, &fy(re), 0.6, 0.5, 4.0);
    let fi = dominant_frequency(&ri.t, &fy(ri), 0.6, 0.5, 4.0);
    assert!((fe / fi - 1.0).abs() < 0.01, "f1 explicit {fe} Hz, implicit {fi} Hz");
    // the centre of mass histories agree within 2 % of their range
    let y = |r: &rail_mbs::slosh::SloshRecord| r.com_tank.iter().map(|c| c[1]).collect::<Vec<_>>();
    let (ye, yi_raw) = (y(re), y(ri));
    let yi: Vec<f64> = re.t.iter().map(|&t| at(ri, &|k| yi_raw[k], t)).collect();
    let range = yi.iter().cloned().fold(f64::NEG_INFINITY, f64::max) - yi.iter().cloned().fold(f64::INFINITY, f64::min);
    let worst = ye.iter().zip(&yi).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(worst < 0.02 * range, "COM difference {worst} m of range {range} m");
    // and the explicit run checked the invariants on every recorded step
    assert!(ex.margins().worst_energy_error < 1e-3, "{:?}", ex.margins());
}

#[test]
fn explicit_results_are_bitwise_the_same_for_one_and_two_threads() {
    let run_with = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| pulse_run(true, 0.3).stepper.q().to_vec())
    };
    let (a, b) = (run_with(1), run_with(2));
    assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()), "results differ between 1 and 2 threads");
}

/// A run stopped at a checkpoint and restored (through the byte format, into a freshly built
/// system) continues bit for bit as the uninterrupted run, stable-step estimates included;
/// a corrupted checkpoint is refused naming what is wrong.
#[test]
fn explicit_checkpoint_restart_is_bitwise() {
    let start = |sys: SloshSystem| {
        let (q, v) = sys.initial_state(0.0);
        let m_s = sys.body.scalar_mass().clone();
        Explicit::new(sys, &m_s, 0.0, q, v, ExplicitParams::default()).unwrap()
    };
    let system = || box_system(0.3, 1e-3, 0.3 * G, |_| {});
    let mut e = start(system());
    e.advance_to(0.06).unwrap();
    let bytes = e.checkpoint().to_bytes();
    e.advance_to(0.12).unwrap();
    let cp = ExplicitCheckpoint::from_bytes(&bytes).unwrap();
    assert_eq!(cp.to_bytes(), bytes);
    let sys = system();
    let m_s = sys.body.scalar_mass().clone();
    let mut r = Explicit::restore(sys, &m_s, &cp, ExplicitParams::default()).unwrap();
    r.advance_to(0.12).unwrap();
    assert_eq!(r.stats().steps, e.stats().steps);
    for (x, y) in [(e.q(), r.q()), (e.v(), r.v()), (e.a(), r.a())] {
        assert!(x.iter().zip(y).all(|(a, b)| a.to_bits() == b.to_bits()), "restored run differs");
    }
    let mut bad = bytes.clone();
    bad.truncate(bytes.len() - 3);
    assert!(ExplicitCheckpoint::from_bytes(&bad).unwrap_err().to_string().contains("truncated"));
    bad = bytes.clone();
    bad[0] = b'X';
    assert!(ExplicitCheckpoint::from_bytes(&bad).unwrap_err().to_string().contains("magic"));
}
