//! The slosh runs' step controller (issue 17): growing the step after
//! [`SLOSH_GROW_AFTER`] easy steps instead of the integrator's default 5, because a step grown
//! after 5 mostly fails again and every failure costs refactorizations (docs/benchmarks.md,
//! "Growing the step less often"), and the run that shows every step to an inspector.

use ancf_core::FluidBody;
use ancf_core::constants::GRAVITY as G;
use ancf_core::constitutive::Rheology;
use ancf_core::contact::{WallContact, WallContactLaw};
use ancf_core::element::QuadratureOptions;
use ancf_core::mesh::box_mesh;
use ancf_core::tank::{TankGeometry, TankShape};
use rail_mbs::defaults::{SLOSH_GROW_AFTER, liquid, slosh_params};
use rail_mbs::integrator::{AdaptiveParams, HhtParams, StepControl};
use rail_mbs::slosh::{PiecewiseAcceleration, PrescribedMotion, SloshFrame, SloshRun, SloshSystem};

/// Seed 003's rectangular tank of water (2×4×2) under the 0.3 g lateral pulse 0.1–0.6 s of
/// `slosh-load-convergence`.
fn pulse_system() -> SloshSystem {
    let (lx, ly, d) = (0.416, 0.324, 0.132);
    let mesh = box_mesh([-lx / 2.0, -ly / 2.0, 0.0], [lx, ly, d], [2, 4, 2]).unwrap();
    let fluid = liquid(998.0, Rheology::Newtonian { viscosity: 1e-3 }, d, d / 2.0).unwrap();
    let geo =
        TankGeometry::new(TankShape::Box { min: [-lx / 2.0, -ly / 2.0, 0.0], max: [lx / 2.0, ly / 2.0, 0.3] }, vec![])
            .unwrap();
    let mut law =
        WallContactLaw::default_for(fluid.density, G, d).with_damping_ratio(1.0, fluid.density, G, d).unwrap();
    law.points_per_edge = 4;
    let body = FluidBody::new(mesh, fluid, QuadratureOptions { penalty: 4, ..QuadratureOptions::default() }).unwrap();
    let contact = WallContact::new(&body, geo, law).unwrap();
    let mut motion = PrescribedMotion::at_rest([0.0; 3]);
    motion.translation[1] = PiecewiseAcceleration::pulse(0.3 * G, 0.1, 0.6, 0.02).unwrap();
    SloshSystem::new(body, contact, motion, [0.0, 0.0, -G], SloshFrame::Inertial).unwrap()
}

/// [`pulse_system`] run to 0.9 s with steps ≤ 5 ms: (rejected attempts, factorizations, final
/// lateral load).
fn pulse(params: HhtParams) -> (usize, usize, f64) {
    let mut run = SloshRun::new(pulse_system(), 0.0, params).unwrap();
    run.run_to(0.9, 0.005).unwrap();
    let s = run.stats();
    (s.rejected_steps, s.factorizations, run.record.force_tank.last().unwrap()[1])
}

#[test]
fn the_slosh_controller_grows_its_step_less_often_and_fails_fewer_steps_for_the_same_answer() {
    let shipped = slosh_params();
    let StepControl::Adaptive(adaptive) = shipped.step_control else { panic!("slosh runs step adaptively") };
    assert_eq!(adaptive.grow_after, SLOSH_GROW_AFTER);
    let eager =
        HhtParams { step_control: StepControl::Adaptive(AdaptiveParams { grow_after: 5, ..adaptive }), ..shipped };
    let (rejected, factorizations, fy) = pulse(shipped);
    let (rejected_eager, factorizations_eager, fy_eager) = pulse(eager);
    eprintln!(
        "rejected {rejected} vs {rejected_eager}, factorizations {factorizations} vs {factorizations_eager}, F_y {fy} vs {fy_eager} N"
    );
    // fewer failed attempts and fewer factorizations than growing after 5 easy steps
    assert!(rejected * 4 < rejected_eager * 3, "rejected {rejected} vs {rejected_eager} growing after 5");
    assert!(factorizations * 4 < factorizations_eager * 3, "{factorizations} vs {factorizations_eager}");
    // the same lateral load at the end, within 2 % of the pulse load m 0.3 g (m = 17.8 kg)
    let pulse_load = 998.0 * 0.416 * 0.324 * 0.132 * 0.3 * G;
    assert!((fy - fy_eager).abs() < 0.02 * pulse_load, "F_y {fy} vs {fy_eager} N");
}

#[test]
fn an_inspected_run_takes_the_same_steps_and_shows_every_one() {
    let mut plain = SloshRun::new(pulse_system(), 0.0, slosh_params()).unwrap();
    plain.run_to(0.3, 0.005).unwrap();
    let mut inspected = SloshRun::new(pulse_system(), 0.0, slosh_params()).unwrap();
    let mut seen = Vec::new();
    inspected
        .run_to_inspected(0.3, 0.005, &mut |run: &SloshRun| {
            seen.push((run.stepper.t(), run.stepper.v().iter().map(|v| v * v).sum::<f64>()));
            Ok(())
        })
        .unwrap();
    assert_eq!(plain.record.t, inspected.record.t);
    assert_eq!(plain.record.force_tank, inspected.record.force_tank);
    assert_eq!(plain.stepper.q(), inspected.stepper.q());
    // every accepted step, after it is recorded: the record's times (the first is t = 0)
    assert_eq!(seen.iter().map(|s| s.0).collect::<Vec<_>>(), plain.record.t[1..]);
    // an error from the inspector stops the run there
    let mut stopped = SloshRun::new(pulse_system(), 0.0, slosh_params()).unwrap();
    let err = stopped
        .run_to_inspected(0.3, 0.005, &mut |run: &SloshRun| {
            if run.stepper.t() > 0.1 {
                Err(rail_mbs::integrator::IntegratorError::InvalidSystem { what: "enough".into() })
            } else {
                Ok(())
            }
        })
        .unwrap_err();
    assert!(err.to_string().contains("enough"), "{err}");
    assert!(stopped.stepper.t() > 0.1 && stopped.stepper.t() < 0.12);
}
