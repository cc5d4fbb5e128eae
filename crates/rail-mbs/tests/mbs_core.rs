//! Multibody core on the HHT integrator: a torque-free asymmetric body (energy and
//! angular momentum), a physical pendulum on a revolute joint (small-angle period), a
//! body on bushings (static deflection) and a two-body chain with a fixed joint.

use nalgebra::{Matrix3, Vector3};
use rail_mbs::integrator::{Hht, HhtParams, JacobianPolicy};
use rail_mbs::mbs::rotation::axis_angle;
use rail_mbs::mbs::{Bushing, JointKind, Multibody, RigidBody, SpringDamper, SpringLaw};

fn params(alpha: f64) -> HhtParams {
    HhtParams {
        alpha,
        rel_tol: 1e-8,
        abs_tol_acc: 1e-8,
        abs_tol_lambda: 1e-6,
        max_iterations: 20,
        ..Default::default()
    }
}

#[test]
fn torque_free_asymmetric_body_conserves_energy_and_momentum() {
    let mut mb = Multibody::new();
    mb.gravity = Vector3::zeros();
    let mut b = RigidBody::new("top", 2.0, [1.0, 2.0, 3.0], Vector3::zeros());
    b.orientation = axis_angle(&Vector3::new(1.0, 0.5, 0.2), 0.6);
    // Near the intermediate axis plus some spin: a tumbling, non-trivial motion.
    b.angular_velocity = b.orientation * Vector3::new(0.3, 2.0, 0.4);
    let j = b.inertia;
    mb.add_body(b).unwrap();
    let (q0, v0) = mb.initial_coordinates();
    let momentum_energy = |h: &Hht<Multibody>| {
        let s = h.system().state(Some(rail_mbs::mbs::BodyId(0)), h.q(), h.v());
        let wl = s.rotation.transpose() * s.angular_velocity;
        (s.rotation * (j * wl), 0.5 * wl.dot(&(j * wl)))
    };
    let mut hht = Hht::new(mb, 0.0, q0, v0, params(0.0)).unwrap();
    let (l0, e0) = momentum_energy(&hht);
    hht.integrate_to(5.0, 1e-3).unwrap();
    let (l1, e1) = momentum_energy(&hht);
    let p: f64 = hht.q()[3..7].iter().map(|x| x * x).sum();
    println!(
        "energy drift {:.2e}, momentum drift {:.2e}, |p|^2-1 {:.1e}",
        (e1 - e0) / e0,
        (l1 - l0).norm() / l0.norm(),
        p - 1.0
    );
    assert!(((e1 - e0) / e0).abs() < 1e-4, "energy {e0} -> {e1}");
    assert!((l1 - l0).norm() / l0.norm() < 1e-4, "momentum {l0} -> {l1}");
    assert!((p - 1.0).abs() < 1e-10);
}

#[test]
fn physical_pendulum_on_a_revolute_joint_has_the_small_angle_period() {
    // Rod of mass m, length L, pinned at one end about the global Y axis.
    let (m, l) = (3.0, 1.2);
    let ic = m * l * l / 12.0;
    let mut mb = Multibody::new();
    let theta0 = 0.02;
    let mut b = RigidBody::new("rod", m, [ic, ic, 1e-3], Vector3::zeros());
    // Rod axis = body z, hanging down from the pin at the origin, tilted by θ0 about Y.
    b.orientation = axis_angle(&Vector3::y(), theta0);
    b.position = b.orientation * Vector3::new(0.0, 0.0, -0.5 * l);
    let id = mb.add_body(b).unwrap();
    // Pin axis = third column of the joint axes = global Y.
    let axes = Matrix3::from_columns(&[Vector3::z(), Vector3::x(), Vector3::y()]);
    mb.add_joint("pin", JointKind::Revolute, Some(id), None, Vector3::zeros(), axes).unwrap();
    assert_eq!(mb.dof(), 1);
    let (q0, v0) = mb.initial_coordinates();
    let mut hht = Hht::new(mb, 0.0, q0, v0, params(0.0)).unwrap();
    let expected = 2.0 * std::f64::consts::PI * ((ic + m * l * l / 4.0) / (m * 9.80665 * l / 2.0)).sqrt();
    let mut last_x = hht.q()[0];
    let mut crossings = Vec::new();
    let h = 1e-3;
    while hht.t() < 3.0 * expected {
        hht.step(h).unwrap();
        let x = hht.q()[0];
        if last_x > 0.0 && x <= 0.0 {
            crossings.push(hht.t() - h * x / (x - last_x));
        }
        last_x = x;
    }
    let period = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
    println!("period {period:.5} s, expected {expected:.5} s, {} Newton its", hht.stats().newton_iterations);
    assert!((period - expected).abs() / expected < 1e-3);
    // The pin stays closed: the rod end stays at the origin.
    let s = hht.system().state(Some(id), hht.q(), hht.v());
    assert!(s.point(&Vector3::new(0.0, 0.0, 0.5 * l)).norm() < 1e-9);
}

#[test]
fn body_on_bushings_settles_at_the_static_deflection() {
    let mut mb = Multibody::new();
    let m = 1000.0;
    let id = mb.add_body(RigidBody::new("mass", m, [100.0, 100.0, 100.0], Vector3::new(0.0, 0.0, 1.0))).unwrap();
    let k = 1e6;
    for y in [-0.5, 0.5] {
        mb.add_force(Box::new(Bushing {
            name: format!("spring {y}"),
            bodies: [None, Some(id)],
            points: [Vector3::new(0.0, y, 1.0), Vector3::new(0.0, y, 0.0)],
            frame_i: Matrix3::identity(),
            frame_j: Matrix3::identity(),
            offset: Vector3::zeros(),
            stiffness: [k, k, k],
            damping: [2e4, 2e4, 2e4],
            preload: Vector3::zeros(),
            rotational_stiffness: [0.0; 3],
            rotational_damping: [0.0; 3],
            free_axis: None,
            matrix_stiffness: None,
            matrix_damping: None,
        }))
        .unwrap();
    }
    let (q0, v0) = mb.initial_coordinates();
    let mut p = params(-0.3);
    p.jacobian = JacobianPolicy::Automatic;
    let mut hht = Hht::new(mb, 0.0, q0, v0, p).unwrap();
    hht.integrate_to(2.0, 2e-3).unwrap();
    let z = hht.q()[2] - 1.0;
    let expected = -m * 9.80665 / (2.0 * k);
    println!("deflection {z:.6e} vs {expected:.6e}");
    assert!((z - expected).abs() < 1e-4 * expected.abs());
}

#[test]
fn fixed_joint_makes_two_bodies_one_and_a_coupler_spring_transmits_load() {
    // Two bodies welded together hanging on a vertical spring: the spring carries both weights.
    let mut mb = Multibody::new();
    let a = mb.add_body(RigidBody::new("a", 10.0, [1.0, 1.0, 1.0], Vector3::new(0.0, 0.0, 0.0))).unwrap();
    let b = mb.add_body(RigidBody::new("b", 30.0, [2.0, 2.0, 2.0], Vector3::new(0.5, 0.0, 0.0))).unwrap();
    mb.add_joint("weld", JointKind::Fixed, Some(a), Some(b), Vector3::new(0.25, 0.0, 0.0), Matrix3::identity())
        .unwrap();
    // Spring from the ground above the combined centre of mass (x = 0.375).
    mb.add_force(Box::new(SpringDamper {
        name: "hanger".into(),
        bodies: [None, Some(a)],
        points: [Vector3::new(0.375, 0.0, 1.0), Vector3::new(0.375, 0.0, 0.0)],
        free_length: 1.0,
        law: SpringLaw::Linear { stiffness: 1e5, damping: 2e3 },
        actuator: None,
    }))
    .unwrap();
    assert_eq!(mb.dof(), 6);
    let (q0, v0) = mb.initial_coordinates();
    let mut hht = Hht::new(mb, 0.0, q0, v0, params(-0.3)).unwrap();
    hht.integrate_to(3.0, 2e-3).unwrap();
    let t = hht.system().force_outputs(hht.t(), hht.q(), hht.v())[0];
    println!("hanger tension {t:.4} N");
    assert!((t - 40.0 * 9.80665).abs() < 1e-3 * 40.0 * 9.80665);
    // Bodies keep their relative pose.
    let sa = hht.system().state(Some(a), hht.q(), hht.v());
    let sb = hht.system().state(Some(b), hht.q(), hht.v());
    assert!((sb.position - sa.position - sa.rotation * Vector3::new(0.5, 0.0, 0.0)).norm() < 1e-9);
}
