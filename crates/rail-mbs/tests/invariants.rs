//! Run-time invariants of slosh runs (issue 16): containment, energy balance, element
//! validity. Each failing setup must stop with its typed, located error and keep what
//! it computed; a healthy run must report margins that say so.

use ancf_core::FluidBody;
use ancf_core::constitutive::Rheology;
use ancf_core::contact::{WallContact, WallContactLaw};
use ancf_core::element::QuadratureOptions;
use ancf_core::mesh::box_mesh;
use ancf_core::tank::{TankGeometry, TankShape};
use rail_mbs::cosim::{CosimError, SloshParticipant, SloshParticipantConfig, TankFrameSample, TankMotionInput};
use rail_mbs::defaults::{liquid, slosh_params};
use rail_mbs::integrator::{FailureCause, IntegratorError, SystemError};
use rail_mbs::slosh::{PiecewiseAcceleration, PrescribedMotion, SloshFrame, SloshRun, SloshSystem};

use ancf_core::constants::GRAVITY as G;
const RHO: f64 = 998.0;
// seed 003's rectangular tank: 0.416 × 0.324 m, water 0.132 m deep
const L: [f64; 3] = [0.416, 0.324, 0.132];

/// Water in the seed-003 box tank on a 2×4×2 mesh (4³ force rules, which keep the rest
/// state of this mesh stable), with `law` adjusted by `adjust`, and a lateral pulse of
/// `pulse` m/s² on [0.05, 0.45] s.
fn box_run(frame: SloshFrame, pulse: f64, adjust: impl FnOnce(&mut WallContactLaw)) -> SloshRun {
    let lo = [-0.5 * L[0], -0.5 * L[1], 0.0];
    let mesh = box_mesh(lo, L, [2, 4, 2]).unwrap();
    let fluid = liquid(RHO, Rheology::Newtonian { viscosity: 1e-3 }, L[2], L[2] / 2.0).unwrap();
    let body = FluidBody::new(mesh, fluid, QuadratureOptions { viscous: 4, penalty: 4, mass: 4 }).unwrap();
    let geo = TankGeometry::new(TankShape::Box { min: lo, max: [0.5 * L[0], 0.5 * L[1], 0.3] }, vec![]).unwrap();
    let mut law = WallContactLaw::default_for(RHO, G, L[2]);
    adjust(&mut law);
    let contact = WallContact::new(&body, geo, law).unwrap();
    let mut motion = PrescribedMotion::at_rest([0.0; 3]);
    if pulse != 0.0 {
        motion.translation[1] = PiecewiseAcceleration::pulse(pulse, 0.05, 0.45, 0.02).unwrap();
    }
    let sys = SloshSystem::new(body, contact, motion, [0.0, 0.0, -G], frame).unwrap();
    SloshRun::new(sys, 0.0, slosh_params()).unwrap()
}

#[test]
fn a_dissipative_slosh_run_balances_its_energy_in_both_frames() {
    let mut dissipated = Vec::new();
    for frame in [SloshFrame::Inertial, SloshFrame::Tank] {
        let mut run = box_run(frame, 0.3 * G, |_| {});
        run.run_to(1.0, 0.005).unwrap();
        let m = run.margins();
        let r = &run.record;
        // the pulse put work in, and the liquid moved
        let w = *r.input_work.last().unwrap();
        assert!(r.input_work.iter().any(|x| x.abs() > 0.1), "{frame:?}: no work put in: {w}");
        // E = E0 + W − D with D ≥ 0: the growth ε never exceeds round-off and step error
        assert!(m.worst_energy_error < 1e-3, "{frame:?}: ε = {}", m.worst_energy_error);
        assert!(m.dissipated > 0.0, "{frame:?}: dissipated {}", m.dissipated);
        // nodes are not contact points (Gauss points are): they may sit a few mm in the wall
        assert!(m.worst_gap < 0.25 * run.invariants.limits.containment, "{frame:?}: {m:?}");
        assert!(m.min_volume_ratio > 0.9, "{frame:?}: {m:?}");
        assert_eq!(r.energy_error.len(), r.t.len());
        dissipated.push(m.dissipated);
    }
    // the two formulations account the same physics: the same energy dissipated (the
    // tank-frame one measures it relative to the tank, which moves at constant velocity
    // after the pulse: the kinetic energy of the relative motion is the same)
    let rel = (dissipated[0] - dissipated[1]).abs() / dissipated[0].abs().max(dissipated[1].abs());
    assert!(rel < 0.05, "dissipated energy inertial {} vs tank frame {}", dissipated[0], dissipated[1]);
}

#[test]
fn negative_contact_damping_injects_energy_and_stops_with_the_energy_error() {
    // A Hunt–Crossley wall with c < 0 pushes harder on rebound than on impact: each bounce
    // creates energy. (The law's validation refuses c < 0; this sets it past that, as a
    // defect in a contact model would.)
    let mut run = box_run(SloshFrame::Inertial, 0.3 * G, |_| {});
    run.stepper.system_mut().contact.law.damping *= -20.0;
    let err = run.run_to(2.0, 0.005).expect_err("energy creation must stop the run");
    assert_eq!(err.error.cause(), FailureCause::EnergyGrowth, "{}", err.error);
    let IntegratorError::System { t, source: SystemError::EnergyGrowth { relative, limit, .. } } = err.error.root()
    else {
        panic!("{}", err.error)
    };
    assert!(*relative > *limit && *t > 0.0 && *t < 2.0, "{}", err.error);
    // everything computed is kept, up to and including the violating sample
    assert_eq!(err.record.t.last(), Some(t));
    assert!(err.record.energy_error.iter().rev().skip(1).all(|e| *e <= *limit));
}

/// The co-simulation participant on the `box_run` setup (tank-frame formulation).
fn box_participant() -> SloshParticipant {
    let lo = [-0.5 * L[0], -0.5 * L[1], 0.0];
    let mesh = box_mesh(lo, L, [2, 4, 2]).unwrap();
    let fluid = liquid(RHO, Rheology::Newtonian { viscosity: 1e-3 }, L[2], L[2] / 2.0).unwrap();
    let geo = TankGeometry::new(TankShape::Box { min: lo, max: [0.5 * L[0], 0.5 * L[1], 0.3] }, vec![]).unwrap();
    let mut c = SloshParticipantConfig::new(mesh, fluid, geo);
    c.quadrature = QuadratureOptions { viscous: 4, penalty: 4, mass: 4 };
    c.contact = Some(WallContactLaw::default_for(RHO, G, L[2]));
    c.hht = slosh_params();
    c.h_max = 0.005;
    c.gravity = G;
    SloshParticipant::new(c).unwrap()
}

/// Tank-frame input of `box_run`'s pulse (0.3 g lateral on [0.05, 0.45] s, 0.02 s ramps) at t.
fn pulse_input(t: f64) -> TankMotionInput {
    let (_, _, a) = PiecewiseAcceleration::pulse(0.3 * G, 0.05, 0.45, 0.02).unwrap().eval(t);
    TankMotionInput::TankFrame(TankFrameSample { acceleration: [0.0, a, 0.0], ..TankFrameSample::at_rest(G) })
}

/// Advances `p` in 5 ms windows (the pulse's knots are window ends, so the linear input
/// within each window is exact) to `t_end`.
fn advance_pulse(p: &mut SloshParticipant, t_end: f64) -> Result<(), CosimError> {
    while p.time() < t_end - 1e-9 {
        let (t0, t1) = (p.time(), (p.time() + 0.005).min(t_end));
        p.advance(t1, &pulse_input(t0), &pulse_input(t1))?;
    }
    Ok(())
}

#[test]
fn the_cosimulation_participant_keeps_the_same_energy_account_as_a_tank_frame_run() {
    let mut p = box_participant();
    advance_pulse(&mut p, 1.0).unwrap();
    let m = p.margins();
    assert!(m.worst_energy_error < 1e-3 && m.worst_energy_error.is_finite(), "ε = {}", m.worst_energy_error);
    assert!(m.dissipated > 0.0 && m.worst_gap < 0.25 * m.gap_limit && m.min_volume_ratio > 0.9, "{m:?}");
    // the same physics through SloshRun in the tank frame: the same energy dissipated
    let mut run = box_run(SloshFrame::Tank, 0.3 * G, |_| {});
    run.run_to(1.0, 0.005).unwrap();
    let d = run.margins().dissipated;
    assert!((m.dissipated - d).abs() < 0.05 * d, "participant {} vs run {d}", m.dissipated);
}

#[test]
fn an_energy_creating_participant_stops_with_the_energy_error_and_rolls_back_its_window() {
    let mut p = box_participant();
    p.system_mut().contact.law.damping *= -20.0; // as in the SloshRun test above
    let err = loop {
        let t0 = p.time();
        assert!(t0 < 2.0, "energy creation must stop the participant");
        if let Err(e) = advance_pulse(&mut p, t0 + 0.005) {
            assert_eq!(p.time(), t0, "the failed window is rolled back");
            break e;
        }
    };
    let CosimError::Integrator { source, .. } = &err else { panic!("{err}") };
    assert_eq!(source.cause(), FailureCause::EnergyGrowth, "{err}");
    let IntegratorError::System { source: SystemError::EnergyGrowth { relative, limit, .. }, .. } = source.root()
    else {
        panic!("{err}")
    };
    assert!(relative > limit, "{err}");
}

#[test]
fn leaky_walls_stop_with_the_containment_error_naming_the_site() {
    // walls 1000× too soft: the liquid sinks through the floor
    let mut run = box_run(SloshFrame::Inertial, 0.0, |law| {
        law.stiffness *= 1e-3;
        law.damping *= 1e-3f64.powf(1.5);
    });
    // the per-step penetration guard of the contact points is disabled, so that only the
    // run-time invariant can stop the run
    run.stepper.system_mut().penetration_limit = f64::INFINITY;
    let limit = run.invariants.limits.containment;
    assert!(limit.is_finite() && limit > 0.0);
    let err = run.run_to(2.0, 0.005).expect_err("a liquid falling through its tank must stop the run");
    assert_eq!(err.error.cause(), FailureCause::Containment, "{}", err.error);
    let msg = err.error.to_string();
    assert!(msg.contains("not contained") && msg.contains("beyond the wall"), "{msg}");
    let IntegratorError::System { source: SystemError::Containment { depth, position, .. }, .. } = err.error.root()
    else {
        panic!("{msg}")
    };
    assert!(*depth > limit && position[2] < 0.0, "{msg}");
    assert!(err.record.containment_gap.last().unwrap() > &limit);
}

#[test]
fn a_liquid_at_rest_stays_at_rest_with_flat_energy() {
    let mut run = box_run(SloshFrame::Inertial, 0.0, |_| {});
    run.run_to(2.0, 0.01).unwrap();
    let r = &run.record;
    let half = r.t.iter().position(|t| *t >= 1.0).unwrap();
    let peak = |k: &[f64]| k.iter().fold(0.0f64, |m, x| m.max(*x));
    let (early, late) = (peak(&r.kinetic_energy[..half]), peak(&r.kinetic_energy[half..]));
    let m = run.margins();
    let mgh = run.stepper.system().body.total_mass() * G * L[2];
    // the settling of the penalty pressure is the only motion, and it decays
    assert!(early < 1e-3 * mgh, "kinetic energy while settling {early} J (m g H = {mgh} J)");
    assert!(late < 0.5 * early, "kinetic energy at rest does not decay: {early} J, then {late} J");
    assert!(m.worst_energy_error.abs() < 1e-4, "{m:?}");
    assert!(m.worst_gap < 3e-3 * L[2], "{m:?}");
}

/// A tank at rest for 20 s keeps a flat energy: after the settling of the penalty pressure,
/// the kinetic energy never grows again (SwRI tank, shipped 1×2×2 mesh and quadrature, with
/// the recommended shear stabilization).
#[test]
fn a_tank_at_rest_for_20_s_keeps_a_flat_energy() {
    use ancf_core::mesh::{EllipticCylinderSpec, elliptic_cylinder};
    let spec = EllipticCylinderSpec::swri(1, 2, 2);
    let mesh = elliptic_cylinder(&spec).unwrap();
    let depth = mesh.liquid_depth();
    let mut fluid = liquid(RHO, Rheology::Newtonian { viscosity: 1e-3 }, depth, depth / 2.0).unwrap();
    fluid.shear_stabilization = rail_mbs::defaults::default_shear_stabilization(RHO, depth / 2.0, None);
    let body = FluidBody::new(mesh, fluid, QuadratureOptions { viscous: 4, penalty: 4, mass: 4 }).unwrap();
    let shape = TankShape::EllipticCylinder {
        length: spec.length,
        semi_axis_y: spec.semi_axis_y,
        semi_axis_z: spec.semi_axis_z,
    };
    let law = WallContactLaw { points_per_edge: 5, ..WallContactLaw::default_for(RHO, G, depth) };
    let contact = WallContact::new(&body, TankGeometry::new(shape, vec![]).unwrap(), law).unwrap();
    let sys =
        SloshSystem::new(body, contact, PrescribedMotion::at_rest([0.0; 3]), [0.0, 0.0, -G], SloshFrame::Inertial)
            .unwrap();
    let mgh = sys.body.total_mass() * G * depth;
    let mut run = SloshRun::new(sys, 0.0, slosh_params()).unwrap();
    run.run_to(20.0, 0.02).unwrap();
    let r = &run.record;
    let window = |a: f64, b: f64| {
        r.t.iter().zip(&r.kinetic_energy).filter(|(t, _)| **t >= a && **t < b).fold(0.0f64, |m, (_, k)| m.max(*k))
    };
    let (settling, middle, late) = (window(0.0, 2.0), window(2.0, 10.0), window(10.0, 20.01));
    assert!(settling < 1e-3 * mgh, "settling kinetic energy {settling} J (m g H = {mgh} J)");
    assert!(middle < settling && late <= middle, "kinetic energy grows at rest: {settling}, {middle}, {late} J");
    assert!(late < 1e-6 * mgh, "kinetic energy after 10 s at rest: {late} J (m g H = {mgh} J)");
    let m = run.margins();
    assert!(m.worst_energy_error < 1e-4, "{m:?}");
}
