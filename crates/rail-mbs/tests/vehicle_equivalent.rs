//! The equivalent (spring–mass / pendulum) slosh model of a tank car's liquid
//! (`rail_mbs::vehicle::equivalent`): its mass and static centroid equal the ANCF liquid's,
//! its modal formulas reproduce hand values and the static-tilt identity, a slosh body rings
//! at its frequency and decays at its damping ratio, and a constant acceleration displaces
//! it by `a/ω²` and loads the tank with `M a`.

use std::f64::consts::PI;
use std::sync::Arc;

use ancf_core::element::QuadratureOptions;
use ancf_core::error::AncfError;
use ancf_core::mesh::{cylinder_tank, cylinder_tank_compartments};
use ancf_core::{Fluid, FluidBody, Rheology};
use nalgebra::{Matrix3, Vector3};
use rail_mbs::integrator::{Hht, HhtParams};
use rail_mbs::mbs::{JointKind, Multibody, RigidBody};
use rail_mbs::track::{GRAVITY, Track, TrackPoint};
use rail_mbs::vehicle::equivalent::{
    EquivalentModel, SloshMode, add_slosh_body, cylinder_lambda, rectangular_mode, rectangular_modes, segment,
};
use rail_mbs::vehicle::{EquivalentCargo, SloshAxis, TankCarParams, TrainScenario, run_equivalent_train};

const LIGHT: (f64, f64) = (850.0, 0.005);

fn model(fill: f64, bulkheads: Vec<(f64, f64)>, axis: SloshAxis) -> EquivalentModel {
    let car = TankCarParams::standard().unwrap();
    EquivalentCargo::new(LIGHT.0, LIGHT.1, fill, bulkheads, axis).model(&car, GRAVITY).unwrap()
}

/// The ANCF liquid of the same tank, fill and bulkheads (as `build_fluid_train`).
fn ancf_liquid(fill: f64, bulkheads: &[(f64, f64)]) -> (FluidBody, f64) {
    let spec = TankCarParams::standard().unwrap().tank_spec(fill, [9, 4, 3]);
    let mesh = if bulkheads.is_empty() { cylinder_tank(&spec) } else { cylinder_tank_compartments(&spec, bulkheads) };
    let mesh = mesh.unwrap();
    let exact = mesh.exact_volume;
    let fluid = Fluid::new(LIGHT.0, Rheology::Newtonian { viscosity: LIGHT.1 }, 1e7).unwrap();
    (FluidBody::new(mesh, fluid, QuadratureOptions::default()).unwrap(), exact)
}

#[test]
fn mass_and_static_centroid_equal_the_ancf_liquid() {
    for (fill, bulkheads) in [(0.5, vec![]), (0.3, vec![]), (0.8, vec![(-1.8, 0.02), (1.8, 0.02)])] {
        let (body, exact_volume) = ancf_liquid(fill, &bulkheads);
        let com = body.center_of_mass(&body.reference_coordinates());
        for axis in [SloshAxis::Longitudinal, SloshAxis::Lateral] {
            let m = model(fill, bulkheads.clone(), axis);
            println!(
                "fill {fill} {axis:?}: M = {:.2} kg (mesh exact {:.2}, quadrature {:.2}), centroid {:?} vs {:?}",
                m.mass,
                LIGHT.0 * exact_volume,
                body.total_mass(),
                m.centroid,
                com
            );
            assert!((m.mass / (LIGHT.0 * exact_volume) - 1.0).abs() < 1e-9);
            // The quadrature mass of the curved mesh converges to the exact volume (0.5 % off at 9×4×3).
            assert!((m.mass / body.total_mass() - 1.0).abs() < 1e-2);
            for (k, (a, b)) in m.centroid.iter().zip(&com).enumerate() {
                assert!((a - b).abs() < 5e-3, "centroid[{k}] {a} vs {b}");
            }
            // The equivalent system: m0 + Σ m1 = M, and its first moments are the liquid's.
            assert_eq!(m.modes.len(), bulkheads.len() + 1);
            let total: f64 = m.modes.iter().map(|s| s.mass + s.fixed_mass).sum();
            assert!((total / m.mass - 1.0).abs() < 1e-12);
            let rest: Vec<[f64; 3]> = m.modes.iter().map(|s| s.position).collect();
            let c = m.center_of_mass(&rest);
            for (k, (a, b)) in c.iter().zip(&m.centroid).enumerate() {
                assert!((a - b).abs() < 1e-9, "{axis:?} first moment {k}: {a} vs {b}");
            }
            for s in &m.modes {
                assert!(s.mass > 0.0 && s.fixed_mass > 0.0 && s.damping_ratio > 0.0 && s.damping_ratio <= 1.0);
            }
        }
    }
}

#[test]
fn rectangular_first_mode_matches_hand_values_and_the_static_tilt_identity() {
    // L = 2 m, h = 0.5 m: πh/L = π/4, tanh = 0.6557942; ω² = 10.105469 s⁻², m1/M = 0.6768118.
    let (omega, m1) = rectangular_mode(2.0, 0.5, 1.0, 9.81).unwrap();
    assert!((omega * omega - 10.105469).abs() < 1e-5, "ω² = {}", omega * omega);
    assert!((m1 - 0.6768118).abs() < 1e-6, "m1 = {m1}");
    // Σ m_n l_n = M L²/(12 h) = M BM (notes §3), l_n = g/ω_n².
    for (l, h) in [(2.0, 0.5), (12.0, 1.5), (1.0, 2.0)] {
        let modes = rectangular_modes(l, h, 1.0, 9.81, 400).unwrap();
        let sum: f64 = modes.iter().map(|(w, m)| m * 9.81 / (w * w)).sum();
        let bm = l * l / (12.0 * h);
        assert!((sum / bm - 1.0).abs() < 1e-6, "L {l} h {h}: Σ m l = {sum} vs BM {bm}");
        // The sloshing masses never exceed the liquid (Σ m_n → M).
        assert!(modes.iter().map(|(_, m)| m).sum::<f64>() < 1.0);
    }
}

#[test]
fn longitudinal_model_uses_the_rectangular_formulas_of_each_compartment() {
    let m = model(0.5, vec![(-1.8, 0.02), (1.8, 0.02)], SloshAxis::Longitudinal);
    let seg = segment(1.5, m.depth).unwrap();
    assert!((m.depth - 1.5).abs() < 1e-9, "half fill is half depth");
    let h_eq = seg.area / (2.0 * seg.half_width);
    for (s, c) in m.modes.iter().zip(&m.compartments) {
        let r = PI * h_eq / c.length;
        let w2 = PI * GRAVITY / c.length * r.tanh();
        assert!((s.omega * s.omega / w2 - 1.0).abs() < 1e-12);
        assert!((s.mass / (c.mass * 8.0 * r.tanh() / (PI.powi(3) * h_eq / c.length)) - 1.0).abs() < 1e-12);
        // m1 and m0 sit at the compartment's liquid centroid.
        assert_eq!(s.position, c.centroid);
        assert_eq!(s.fixed_position, c.centroid);
    }
    // The middle compartment (no heads) is 3.58 m of shell: L_c is exactly its length.
    assert!((m.compartments[1].length - 3.58).abs() < 1e-9);
}

#[test]
fn lateral_pendulum_matches_the_static_tilt_identity() {
    // Flat ends: the liquid is a prism of the segment, Σ m1 l1 = M BM with BM = (2w)³/(12A).
    let car = TankCarParams::standard().unwrap();
    for fill in [0.1, 0.3, 0.5, 0.7, 0.9] {
        let mut cargo = EquivalentCargo::new(LIGHT.0, LIGHT.1, fill, vec![(0.5, 0.02)], SloshAxis::Lateral);
        cargo.head_depth = 0.0;
        let m = cargo.model(&car, GRAVITY).unwrap();
        let (r, h) = (1.5, m.depth);
        let alpha = ((r - h) / r).acos();
        let area = 0.5 * r * r * (2.0 * alpha - (2.0 * alpha).sin());
        let bm = (2.0 * r * alpha.sin()).powi(3) / (12.0 * area);
        let sum: f64 = m.modes.iter().map(|s| s.mass * s.pendulum_length).sum();
        println!("fill {fill}: λ = {:.4}, Σ m1 l1 = {sum:.1}, M BM = {:.1}", m.lambda, m.mass * bm);
        assert!((sum / (m.mass * bm) - 1.0).abs() < 1e-9);
        // Flat ends: the volume fraction is the area fraction.
        assert!((area / (PI * r * r) - fill).abs() < 1e-6);
        for s in &m.modes {
            assert!((s.omega * s.omega - m.lambda * GRAVITY / r).abs() < 1e-12);
            assert!((s.pendulum_length - r / m.lambda).abs() < 1e-12);
            assert_eq!(s.fixed_position[2], 0.0, "m0 on the axis");
        }
    }
    // Half full: m1 = 0.575 M, l1 = 0.738 R (notes §3).
    let m = model(0.5, vec![], SloshAxis::Lateral);
    assert!((m.sloshing_mass() / m.mass - 0.575).abs() < 0.01, "{}", m.sloshing_mass() / m.mass);
    assert!((m.modes[0].pendulum_length / 1.5 - 0.738).abs() < 0.002);
}

#[test]
fn lambda_table_matches_the_half_full_value_and_the_low_fill_limit() {
    let half = cylinder_lambda(0.5).unwrap();
    assert!((half - 1.3557).abs() < 0.002, "λ(0.5) = {half}");
    let low = cylinder_lambda(0.01).unwrap();
    assert!((low - 1.0).abs() < 0.01, "λ(0.01) = {low}");
    // Increasing with the fill, off the grid too.
    let mut last = 0.0;
    for i in 0..=94 {
        let l = cylinder_lambda(0.01 + 0.00999 * i as f64).unwrap();
        assert!(l > last);
        last = l;
    }
    for bad in [0.0, 0.005, 0.96, 1.0, f64::NAN] {
        assert!(matches!(cylinder_lambda(bad), Err(AncfError::InvalidParameter { .. })), "{bad}");
    }
}

#[test]
fn bad_parameters_are_typed_errors_naming_the_field() {
    let car = TankCarParams::standard().unwrap();
    let field_of = |cargo: EquivalentCargo| match cargo.model(&car, GRAVITY) {
        Err(AncfError::InvalidParameter { field, allowed, .. }) => {
            assert!(!allowed.is_empty());
            field
        }
        other => panic!("expected an invalid parameter, got {other:?}"),
    };
    let ok = EquivalentCargo::new(850.0, 0.005, 0.5, vec![], SloshAxis::Longitudinal);
    assert_eq!(field_of(EquivalentCargo { fill: 1.2, ..ok.clone() }), "fill");
    assert_eq!(field_of(EquivalentCargo { fill: 1e-3, ..ok.clone() }), "fill"); // depth below 1 % of the diameter
    assert_eq!(field_of(EquivalentCargo { density: -1.0, ..ok.clone() }), "density");
    assert_eq!(field_of(EquivalentCargo { viscosity: f64::NAN, ..ok.clone() }), "viscosity");
    assert_eq!(field_of(EquivalentCargo { head_depth: 2.0, ..ok.clone() }), "head_depth");
    assert_eq!(field_of(EquivalentCargo { bulkheads: vec![(6.0, 0.02)], ..ok.clone() }), "bulkheads[0].x");
    assert_eq!(field_of(EquivalentCargo { bulkheads: vec![(1.0, 0.02), (0.5, 0.02)], ..ok.clone() }), "bulkheads[1].x");
    assert_eq!(field_of(EquivalentCargo { bulkheads: vec![(1.0, 0.0)], ..ok }), "bulkheads[0].thickness");
}

/// A tank welded to the ground with one slosh body; returns the system, the slosh body and
/// the index of its spring.
fn grounded_tank(mode: &SloshMode, axis: SloshAxis, gravity: Vector3<f64>) -> (Multibody, usize) {
    let mut mb = Multibody::new();
    mb.gravity = gravity;
    let tank = mb.add_body(RigidBody::new("tank", 15_000.0, [1e4, 2e5, 2e5], Vector3::new(0.0, 0.0, 2.35))).unwrap();
    mb.add_joint("weld", JointKind::Fixed, Some(tank), None, Vector3::new(0.0, 0.0, 2.35), Matrix3::identity())
        .unwrap();
    add_slosh_body(&mut mb, "slosh", tank, Vector3::from(mode.position), mode, axis).unwrap();
    let spring = mb.forces().len() - 1;
    (mb, spring)
}

fn hht_params() -> HhtParams {
    HhtParams { alpha: -0.05, rel_tol: 1e-8, abs_tol_acc: 1e-8, ..TrainScenario::default_hht() }
}

#[test]
fn slosh_body_rings_at_its_frequency_and_decays_at_its_damping_ratio() {
    let car = TankCarParams::standard().unwrap();
    for (axis, mu) in [(SloshAxis::Longitudinal, 100.0), (SloshAxis::Lateral, 100.0)] {
        // Heavy-crude viscosity: ζ of a few per cent, well above the integrator's own damping.
        let m = EquivalentCargo::new(1000.0, mu, 0.5, vec![], axis).model(&car, GRAVITY).unwrap();
        let mode = m.modes[0];
        assert!(mode.damping_ratio > 0.01 && mode.damping_ratio < 0.3, "ζ = {}", mode.damping_ratio);
        let (mut mb, _) = grounded_tank(&mode, axis, Vector3::new(0.0, 0.0, -GRAVITY));
        let k = axis.index();
        let mut delta = Vector3::zeros();
        delta[k] = 0.05;
        let body = rail_mbs::mbs::BodyId(1);
        mb.displace_body(body, delta).unwrap();
        let x0 = mode.position[k];
        let (q0, v0) = mb.initial_coordinates();
        let mut hht = Hht::new(mb, 0.0, q0, v0, hht_params()).unwrap();
        let h = 1e-3;
        let (mut t, mut x) = (vec![0.0], vec![0.05]);
        let period = 2.0 * PI / mode.omega;
        while hht.t() < 6.0 * period {
            hht.step(h).unwrap();
            t.push(hht.t());
            x.push(hht.q()[7 + k] - x0);
        }
        // Damped period from the upward zero crossings, damping from successive maxima.
        let mut ups = Vec::new();
        let mut peaks = Vec::new();
        for i in 1..x.len() - 1 {
            if x[i - 1] < 0.0 && x[i] >= 0.0 {
                ups.push(t[i - 1] + (t[i] - t[i - 1]) * (-x[i - 1]) / (x[i] - x[i - 1]));
            }
            if x[i] > x[i - 1] && x[i] >= x[i + 1] && x[i] > 0.0 {
                peaks.push(x[i]);
            }
        }
        let td = (ups[ups.len() - 1] - ups[0]) / (ups.len() - 1) as f64;
        let wd = 2.0 * PI / td;
        let z = mode.damping_ratio;
        let wd_expected = mode.omega * (1.0 - z * z).sqrt();
        let dec = (peaks[0] / peaks[peaks.len() - 1]).ln() / (peaks.len() - 1) as f64;
        let z_measured = dec / (4.0 * PI * PI + dec * dec).sqrt();
        println!(
            "{axis:?}: ω_d {wd:.5} vs {wd_expected:.5} rad/s, ζ {z_measured:.5} vs {z:.5} ({} peaks)",
            peaks.len()
        );
        assert!((wd / wd_expected - 1.0).abs() < 0.01);
        assert!((z_measured / z - 1.0).abs() < 0.1);
    }
}

#[test]
fn constant_acceleration_displaces_by_a_over_omega_squared_and_loads_the_tank_with_m_a() {
    // In the frame of a tank accelerating at a, the liquid feels gravity plus −a: a welded tank
    // under the gravity (−a, 0, −g) is the tank braking (or curving) at a constant rate.
    let car = TankCarParams::standard().unwrap();
    let a = 1.5;
    for axis in [SloshAxis::Longitudinal, SloshAxis::Lateral] {
        let m = EquivalentCargo::new(850.0, 0.005, 0.5, vec![], axis).model(&car, GRAVITY).unwrap();
        let mut mode = m.modes[0];
        mode.damping_ratio = 0.5; // settle within the run
        let k = axis.index();
        let mut gravity = Vector3::new(0.0, 0.0, -GRAVITY);
        gravity[k] = -a;
        let (mb, spring) = grounded_tank(&mode, axis, gravity);
        let (q0, v0) = mb.initial_coordinates();
        let mut hht = Hht::new(mb, 0.0, q0, v0, hht_params()).unwrap();
        hht.integrate_to(25.0 / mode.omega, 2e-3).unwrap();
        let sys = hht.system();
        let (q, v) = (hht.q(), hht.v());
        let d = q[7 + k] - mode.position[k];
        let expected = -a / (mode.omega * mode.omega);
        let wrench = sys.forces()[spring].wrenches(hht.t(), &sys.state(Some(rail_mbs::mbs::BodyId(0)), q, v), &{
            sys.state(Some(rail_mbs::mbs::BodyId(1)), q, v)
        });
        // Liquid load on the tank along the axis: the spring's pull plus the weight of m0.
        let load = wrench[0].force[k] + mode.fixed_mass * gravity[k];
        println!("{axis:?}: displacement {d:.6} vs {expected:.6} m, load {load:.1} vs {:.1} N", -m.mass * a);
        assert!((d / expected - 1.0).abs() < 0.01);
        assert!((load / (-m.mass * a) - 1.0).abs() < 0.01);
    }
}

#[test]
fn car_at_rest_carries_its_liquid_and_records_the_liquid_centroid() {
    let car = TankCarParams::standard().unwrap();
    let track = Arc::new(
        Track::new(vec![
            TrackPoint::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
            TrackPoint::new(200.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        ])
        .unwrap(),
    );
    let sc = TrainScenario::single(car.clone(), track, 50.0, 0.0, 0.3);
    let cargo = EquivalentCargo::new(850.0, 0.005, 0.5, vec![(-1.8, 0.02), (1.8, 0.02)], SloshAxis::Longitudinal);
    let rec = run_equivalent_train(&sc, &cargo).unwrap().unwrap();
    let model = rec.model.as_ref().unwrap();
    let weight = (car.total_mass() + model.mass) * GRAVITY;
    let last = rec.train.t.len() - 1;
    let q: f64 = rec.train.wheel_vertical[last].iter().flatten().sum();
    println!("wheel loads {q:.0} N vs weight {weight:.0} N; dof {}", rec.train.dof);
    assert!((q / weight - 1.0).abs() < 0.01);
    assert_eq!(rec.train.dof, 68 + 6 * 3);
    for k in 0..3 {
        assert!((rec.oil_com_tank[0][0][k] - model.centroid[k]).abs() < 1e-6, "t = 0 centroid {k}");
        assert!((rec.oil_com_tank[last][0][k] - model.centroid[k]).abs() < 5e-3, "settled centroid {k}");
    }
    assert_eq!(rec.slosh_displacement[last][0].len(), 3);
    assert_eq!(rec.row(last).len(), rail_mbs::vehicle::EquivalentTrainRecord::columns(4, 0, 1, 3).len());
}

#[test]
fn damping_is_the_stokes_layer_formula_capped_at_critical() {
    use rail_mbs::vehicle::equivalent::stokes_damping_ratio;
    // ν = 1e-6 m²/s, ω = 1 rad/s, h = 1 m, b = 2 m: ζ = (1/2) √(5e-7) (1 + 1) = 7.0711e-4.
    assert!((stokes_damping_ratio(1e-6, 1.0, 1.0, 2.0) - 7.0710678e-4).abs() < 1e-10);
    assert_eq!(stokes_damping_ratio(1e4, 1.0, 1.0, 2.0), 1.0);
    // An Oldroyd liquid damps with its plastic viscosity; its yield stress is ignored.
    let oldroyd = Rheology::Oldroyd { viscosity: 100.0, yield_stress: 100.0, elastic_modulus: None };
    let fluid = Fluid::new(1000.0, oldroyd, 1e7).unwrap();
    let cargo = EquivalentCargo::from_fluid(&fluid, 0.5, vec![], SloshAxis::Lateral);
    assert_eq!((cargo.density, cargo.viscosity), (1000.0, 100.0));
    let m = cargo.model(&TankCarParams::standard().unwrap(), GRAVITY).unwrap();
    let s = m.modes[0];
    let expected = stokes_damping_ratio(0.1, s.omega, m.equivalent_depth, m.compartments[0].length);
    assert_eq!(s.damping_ratio, expected);
}

#[test]
fn a_free_tank_pushed_by_a_constant_force_carries_its_liquid_at_m_a() {
    // No gravity; a constant force F accelerates the tank (m_t + m0) and its slosh mass m1 at
    // a = F/(m_t + M). Once the mode has settled, the slosh mass lags by a/ω² and the liquid's
    // load on the tank (spring pull plus the inertia of m0) is −M a.
    use rail_mbs::mbs::{SpringDamper, SpringLaw, Table};
    let car = TankCarParams::standard().unwrap();
    for axis in [SloshAxis::Longitudinal, SloshAxis::Lateral] {
        let m = EquivalentCargo::new(850.0, 0.005, 0.5, vec![], axis).model(&car, GRAVITY).unwrap();
        let mut mode = m.modes[0];
        mode.damping_ratio = 0.5;
        let k = axis.index();
        let mut mb = Multibody::new();
        mb.gravity = Vector3::zeros();
        let m_tank = 15_000.0 + mode.fixed_mass;
        // A huge rotational inertia keeps the tank from pitching (rolling) under the spring's
        // moment: it translates only, as if guided.
        let tank = mb.add_body(RigidBody::new("tank", m_tank, [1e12; 3], Vector3::zeros())).unwrap();
        add_slosh_body(&mut mb, "slosh", tank, Vector3::from(mode.position), &mode, axis).unwrap();
        let spring = mb.forces().len() - 1;
        let force = 30_000.0;
        let mut far = Vector3::zeros();
        far[k] = 1e6;
        mb.add_force(Box::new(SpringDamper {
            name: "push".into(),
            bodies: [None, Some(tank)],
            points: [far, Vector3::zeros()],
            free_length: 1e6,
            law: SpringLaw::Linear { stiffness: 0.0, damping: 0.0 },
            actuator: Some(Table::new("push", vec![0.0, 1e4], vec![force, force]).unwrap()),
        }))
        .unwrap();
        let (q0, v0) = mb.initial_coordinates();
        let mut hht = Hht::new(mb, 0.0, q0, v0, hht_params()).unwrap();
        let t_end = 25.0 / mode.omega;
        hht.integrate_to(t_end - 1.0, 2e-3).unwrap();
        let v1 = hht.v()[k];
        hht.integrate_to(t_end, 2e-3).unwrap();
        let a = force / (m_tank + mode.mass);
        let a_measured = hht.v()[k] - v1;
        let (q, v) = (hht.q(), hht.v());
        let sys = hht.system();
        let (st, ss) = (sys.state(Some(tank), q, v), sys.state(Some(rail_mbs::mbs::BodyId(1)), q, v));
        let d = (st.rotation.transpose() * (ss.position - st.position))[k] - mode.position[k];
        let wrench = sys.forces()[spring].wrenches(hht.t(), &st, &ss);
        let load = wrench[0].force[k] - mode.fixed_mass * a;
        println!(
            "{axis:?}: a {a_measured:.6} vs {a:.6} m/s², lag {d:.6} vs {:.6} m, load {load:.1} vs {:.1} N",
            -a / mode.omega.powi(2),
            -m.mass * a
        );
        assert!((a_measured / a - 1.0).abs() < 1e-3);
        assert!((d / (-a / mode.omega.powi(2)) - 1.0).abs() < 0.01);
        assert!((load / (-m.mass * a) - 1.0).abs() < 0.01);
    }
}
