//! The slosh co-simulation participant (issue 6): loads, input forms, rollback, added
//! mass and errors. A tiny mesh (a 2×2×2 box of water) keeps the debug-build runtime low
//! (a single element over the depth is not stable at rest beyond about 1.5 s).

use ancf_core::constitutive::{Fluid, Rheology};
use ancf_core::mesh::box_mesh;
use ancf_core::tank::{TankGeometry, TankShape};
use rail_mbs::cosim::maneuvers::{
    BumpVehicle, FOOT, INCH, MPH, Maneuver, half_round_bump, lane_change, trapezoidal_bump,
};
use rail_mbs::cosim::{
    CosimError, Loads, ParticipantState, PoseInput, SloshParticipant, SloshParticipantConfig, TankFrameInput,
    TankFrameSample, TankMotionInput,
};

use ancf_core::constants::GRAVITY as G;
const RHO: f64 = 998.0;
// box of water: 0.4 × 0.3 × 0.1 m in a 0.4 × 0.3 × 0.25 m tank (free surface at z = 0.1)
const L: [f64; 3] = [0.4, 0.3, 0.1];

fn water(depth: f64, h_el: f64) -> Fluid {
    let k = 1000.0 * RHO * G * depth;
    let mut f = Fluid::new(RHO, Rheology::Newtonian { viscosity: 0.05 }, k).unwrap();
    f.bulk_damping = 0.2 * (k * RHO).sqrt() * h_el;
    f
}

fn config(tank_height: f64) -> SloshParticipantConfig {
    let mesh = box_mesh([-L[0] / 2.0, -L[1] / 2.0, 0.0], [L[0], L[1], L[2]], [2, 2, 2]).unwrap();
    let tank = TankGeometry::new(
        TankShape::Box { min: [-L[0] / 2.0, -L[1] / 2.0, 0.0], max: [L[0] / 2.0, L[1] / 2.0, tank_height] },
        vec![],
    )
    .unwrap();
    let mut c = SloshParticipantConfig::new(mesh, water(L[2], L[2] / 2.0), tank);
    c.h_max = 0.005;
    c
}

fn tank_frame(acc: [f64; 3], w: [f64; 3], wd: [f64; 3], g: [f64; 3]) -> TankMotionInput {
    TankMotionInput::TankFrame(TankFrameSample {
        acceleration: acc,
        angular_velocity: w,
        angular_acceleration: wd,
        gravity: g,
    })
}

/// Mean loads over the windows of [t_from, t_to] advanced with a constant input.
fn run_mean(p: &mut SloshParticipant, input: &TankMotionInput, t_to: f64, dt: f64, t_from: f64) -> Loads {
    let mut sum = Loads::default();
    let mut n = 0.0;
    while p.time() < t_to - 1e-12 {
        let l = p.advance(p.time() + dt, input, input).unwrap();
        if p.time() > t_from {
            for i in 0..3 {
                sum.force[i] += l.force[i];
                sum.moment[i] += l.moment[i];
            }
            n += 1.0;
        }
    }
    Loads { force: sum.force.map(|x| x / n), moment: sum.moment.map(|x| x / n) }
}

#[test]
fn hydrostatic_load_is_the_weight_acting_down() {
    let mut c = config(0.25);
    c.reference_point = [0.1, -0.05, 0.0];
    let mut p = SloshParticipant::new(c).unwrap();
    let m = p.fluid_mass();
    assert!((m / (RHO * L[0] * L[1] * L[2]) - 1.0).abs() < 1e-9, "mass {m}");
    let rest = tank_frame([0.0; 3], [0.0; 3], [0.0; 3], [0.0, 0.0, -G]);
    let mean = run_mean(&mut p, &rest, 0.6, 0.02, 0.3);
    let w = m * G;
    assert!((mean.force[2] / -w - 1.0).abs() < 0.01, "Fz {} vs -m g {}", mean.force[2], -w);
    assert!(mean.force[0].abs() < 1e-3 * w && mean.force[1].abs() < 1e-3 * w, "{:?}", mean.force);
    // weight through the centroid (x = y = 0): moment about P = (−P) × F
    let (px, py) = (0.1, -0.05);
    let fz = mean.force[2];
    let expected = [-py * fz, px * fz, 0.0];
    for (i, (m_i, e_i)) in mean.moment.iter().zip(expected).enumerate() {
        assert!((m_i - e_i).abs() < 0.01 * w * 0.1, "M{i} {m_i} vs {e_i}");
    }
    assert!((p.volume() / (L[0] * L[1] * L[2]) - 1.0).abs() < 0.01);
}

#[test]
fn settle_starts_from_equilibrium_at_the_same_time() {
    let rest = tank_frame([0.0; 3], [0.0; 3], [0.0; 3], [0.0, 0.0, -G]);
    // largest |Fz + m g| over the first five 20 ms windows
    let deviation = |p: &mut SloshParticipant, w: f64| -> f64 {
        (1..=5).map(|k| (p.advance(0.02 * k as f64, &rest, &rest).unwrap().force[2] + w).abs()).fold(0.0, f64::max)
    };
    let mut fresh = SloshParticipant::new(config(0.25)).unwrap();
    let w = fresh.fluid_mass() * G;
    // unsettled: the mesh starts unloaded (no wall force at t = 0) and drops into the penalty
    assert!(fresh.loads().force[2].abs() < 1e-9 * w);
    let d_fresh = deviation(&mut fresh, w);
    assert!(d_fresh > 0.05 * w, "unsettled deviation {d_fresh} vs m g {w}");
    let mut p = SloshParticipant::new(config(0.25)).unwrap();
    p.settle(0.6, &rest).unwrap();
    assert_eq!(p.time(), 0.0);
    let d_settled = deviation(&mut p, w);
    assert!(d_settled < 0.02 * w, "settled deviation {d_settled} vs m g {w}");
    assert!(p.settle(-1.0, &rest).unwrap_err().to_string().contains("`duration`"));
}

#[test]
fn constant_tank_acceleration_gives_minus_m_a() {
    let mut p = SloshParticipant::new(config(0.25)).unwrap();
    let m = p.fluid_mass();
    let ax = 0.1 * G;
    // a smooth ramp over 1.5 s (about two sloshing periods of this box: f₁ ≈ 1.13 Hz)
    // leaves little free sloshing; then the acceleration is held
    let t_ramp = 1.5;
    let input = |t: f64| {
        let s = (t / t_ramp).min(1.0);
        let a = ax * s * s * (3.0 - 2.0 * s);
        tank_frame([a, 0.0, 0.0], [0.0; 3], [0.0; 3], [0.0, 0.0, -G])
    };
    let dt = 0.02;
    // momentum balance of the fluid in the tank frame, every window:
    // F_on_tank = −m (a + ẍ_c), ẍ_c by central differences of the centre of mass
    let mut com = vec![p.com_tank()[0]];
    let mut fx = vec![0.0];
    let mut acc = vec![0.0];
    while p.time() < 3.3 - 1e-12 {
        let t0 = p.time();
        let l = p.advance(t0 + dt, &input(t0), &input(t0 + dt)).unwrap();
        com.push(p.com_tank()[0]);
        fx.push(l.force[0]);
        let TankMotionInput::TankFrame(s) = input(t0 + dt) else { unreachable!() };
        acc.push(s.acceleration[0]);
    }
    let mut worst: f64 = 0.0;
    for k in 10..com.len() - 1 {
        let xdd = (com[k + 1] - 2.0 * com[k] + com[k - 1]) / (dt * dt);
        worst = worst.max((fx[k] + m * (acc[k] + xdd)).abs());
    }
    assert!(worst < 0.01 * m * ax, "momentum balance off by {worst} N (m a = {})", m * ax);
    // mean over [1.5, 3.3] s (two sloshing periods) after the ramp
    let k0 = (t_ramp / dt).round() as usize;
    let mean = fx[k0 + 1..].iter().sum::<f64>() / (fx.len() - k0 - 1) as f64;
    assert!((mean / (-m * ax) - 1.0).abs() < 0.015, "mean Fx {mean} vs -m a {}", -m * ax);
    // the liquid piles up at the rear wall (−x): centre of mass moves back
    assert!(p.com_tank()[0] < -1e-3, "com {:?}", p.com_tank());
}

fn rot_x(phi: f64) -> [[f64; 3]; 3] {
    let (s, c) = phi.sin_cos();
    [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
}

fn matmul(a: [[f64; 3]; 3], b: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

#[test]
fn pose_and_tank_frame_inputs_give_the_same_loads() {
    // Tank yawed by 90° (its x axis along global y) and rolled by φ about its own x axis,
    // accelerating along global y and yawing. In tank axes (worked out by hand):
    // R̈ = (a, 0, 0), ω = (0, w sin φ, w cos φ), gravity = (0, −g sin φ, −g cos φ).
    let (phi, a, w, wd) = (0.05_f64, 0.5, 0.2, 0.1);
    let (s, c) = phi.sin_cos();
    let rz = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
    let rot = matmul(rz, rot_x(phi));
    let pose = |k: f64| {
        TankMotionInput::Pose(PoseInput {
            position: [1.0, 2.0, 0.5],
            rotation: rot,
            velocity: [0.0, 3.0, 0.0],
            angular_velocity: [0.0, 0.0, k * w],
            acceleration: [0.0, k * a, 0.0],
            angular_acceleration: [0.0, 0.0, k * wd],
        })
    };
    let tf = |k: f64| {
        tank_frame([k * a, 0.0, 0.0], [0.0, k * w * s, k * w * c], [0.0, k * wd * s, k * wd * c], [0.0, -G * s, -G * c])
    };
    let mut c1 = config(0.25);
    c1.reference_point = [0.0, 0.0, 0.05];
    let mut p1 = SloshParticipant::new(c1.clone()).unwrap();
    let mut p2 = SloshParticipant::new(c1).unwrap();
    // the quaternion of the same rotation gives the same matrix
    let (h, hz) = ((phi / 2.0).cos(), (phi / 2.0).sin());
    let qz = [std::f64::consts::FRAC_1_SQRT_2, 0.0, 0.0, std::f64::consts::FRAC_1_SQRT_2];
    // q = qz ⊗ qx, qx = (h, hz, 0, 0)
    let q = [qz[0] * h, qz[0] * hz, qz[3] * hz, qz[3] * h];
    let rq = PoseInput::rotation_from_quaternion(q).unwrap();
    for i in 0..3 {
        for j in 0..3 {
            assert!((rq[i][j] - rot[i][j]).abs() < 1e-14, "quaternion rotation [{i}][{j}]");
        }
    }
    let dt = 0.02;
    for k in 0..8 {
        let (k0, k1) = (k as f64 / 8.0, (k + 1) as f64 / 8.0);
        let t_end = (k + 1) as f64 * dt;
        let l1 = p1.advance(t_end, &pose(k0), &pose(k1)).unwrap();
        let l2 = p2.advance(t_end, &tf(k0), &tf(k1)).unwrap();
        let scale = l2.force.iter().chain(&l2.moment).fold(0.0_f64, |m, x| m.max(x.abs()));
        for i in 0..3 {
            assert!((l1.force[i] - l2.force[i]).abs() <= 1e-9 * scale, "F{i}: {} vs {}", l1.force[i], l2.force[i]);
            assert!((l1.moment[i] - l2.moment[i]).abs() <= 1e-9 * scale, "M{i}: {} vs {}", l1.moment[i], l2.moment[i]);
        }
    }
}

#[test]
fn rollback_is_bitwise_exact() {
    let mut p = SloshParticipant::new(config(0.25)).unwrap();
    let input =
        |t: f64| tank_frame([2.0 * (5.0 * t).sin(), 1.0, 0.0], [0.1 * t, 0.0, 0.2], [0.1, 0.0, 0.0], [0.0, 0.0, -G]);
    let dt = 0.015;
    for k in 0..4 {
        let (t0, t1) = (k as f64 * dt, (k + 1) as f64 * dt);
        p.advance(t1, &input(t0), &input(t1)).unwrap();
    }
    let saved: ParticipantState = p.save_state();
    let t_saved = p.time();
    let run = |p: &mut SloshParticipant| -> Vec<Loads> {
        (0..3)
            .map(|k| {
                let (t0, t1) = (t_saved + k as f64 * dt, t_saved + (k + 1) as f64 * dt);
                p.advance(t1, &input(t0), &input(t1)).unwrap()
            })
            .collect()
    };
    let first = run(&mut p);
    let com_first = p.com_tank();
    let margins_first = p.margins();
    // a different trial (as an implicit master iterates), then back
    p.restore_state(&saved).unwrap();
    p.advance(t_saved + dt, &input(0.0), &input(1.0)).unwrap();
    p.restore_state(&saved).unwrap();
    assert_eq!(p.time(), t_saved);
    let second = run(&mut p);
    assert_eq!(first, second, "loads after rollback must be bitwise identical");
    assert_eq!(com_first, p.com_tank());
    // the state carries the invariants' account (issue 18): the energy balance and the worst
    // margins go on from the saved state, not from a fresh account
    assert_eq!(p.margins(), margins_first);
    assert!(margins_first.dissipated != 0.0);
    // through the byte form
    let bytes = saved.to_bytes();
    let back = ParticipantState::from_bytes(&bytes).unwrap();
    assert_eq!(back, saved);
    p.restore_state(&back).unwrap();
    assert_eq!(run(&mut p), first);
    assert!(ParticipantState::from_bytes(&bytes[..20]).is_err());
    assert!(ParticipantState::from_bytes(&bytes[..bytes.len() - 1]).is_err());
    let mut longer = bytes.clone();
    longer.push(0);
    assert!(ParticipantState::from_bytes(&longer).is_err());
}

#[test]
fn added_mass_is_the_rigid_body_mass_of_the_fluid() {
    // a full box (tank = fluid region); reference point at a corner of the box
    let mut c = config(L[2]);
    let p_ref = [-L[0] / 2.0, -L[1] / 2.0, 0.0];
    c.reference_point = p_ref;
    let p = SloshParticipant::new(c).unwrap();
    let m = p.fluid_mass();
    let ma = p.added_mass();
    // centre of mass relative to P and inertia about the centroid of a box
    let d = [L[0] / 2.0, L[1] / 2.0, L[2] / 2.0];
    let jc = [
        m * (L[1].powi(2) + L[2].powi(2)) / 12.0,
        m * (L[0].powi(2) + L[2].powi(2)) / 12.0,
        m * (L[0].powi(2) + L[1].powi(2)) / 12.0,
    ];
    let d2: f64 = d.iter().map(|x| x * x).sum();
    let tol = 1e-9 * m;
    for i in 0..3 {
        for j in 0..3 {
            let mi = if i == j { m } else { 0.0 };
            assert!((ma[i][j] - mi).abs() < tol, "translational block [{i}][{j}] = {}", ma[i][j]);
            // parallel-axis theorem: J_P = J_c + m (|d|² I − d dᵀ)
            let jp = if i == j { jc[i] } else { 0.0 } + m * (if i == j { d2 } else { 0.0 } - d[i] * d[j]);
            assert!((ma[3 + i][3 + j] - jp).abs() < 1e-9 * m * d2, "J_P[{i}][{j}] = {} vs {jp}", ma[3 + i][3 + j]);
        }
    }
    // coupling blocks: [m c̃] below, its negative above (c = d)
    let cx = [[0.0, -d[2], d[1]], [d[2], 0.0, -d[0]], [-d[1], d[0], 0.0]];
    for i in 0..3 {
        for j in 0..3 {
            assert!((ma[3 + i][j] - m * cx[i][j]).abs() < tol, "coupling [{i}][{j}]");
            assert!((ma[i][3 + j] + m * cx[i][j]).abs() < tol, "coupling [{i}][{j}] upper");
        }
    }
}

fn err_text(e: CosimError) -> String {
    e.to_string()
}

#[test]
fn invalid_inputs_name_the_field() {
    let bad = |f: &dyn Fn(&mut SloshParticipantConfig), field: &str| {
        let mut c = config(0.25);
        f(&mut c);
        let msg = err_text(SloshParticipant::new(c).err().expect("must fail"));
        assert!(msg.contains(&format!("`{field}`")), "{msg} should name {field}");
    };
    bad(&|c| c.h_max = 0.0, "h_max");
    bad(&|c| c.gravity = -1.0, "gravity");
    bad(&|c| c.reference_point = [0.0, f64::NAN, 0.0], "reference_point");
    bad(&|c| c.t0 = f64::INFINITY, "t0");
    bad(&|c| c.hht.alpha = 0.5, "hht.alpha");
    let mut p = SloshParticipant::new(config(0.25)).unwrap();
    let rest = tank_frame([0.0; 3], [0.0; 3], [0.0; 3], [0.0, 0.0, -G]);
    let msg = err_text(p.advance(-1.0, &rest, &rest).unwrap_err());
    assert!(msg.contains("`t_end`"), "{msg}");
    let nan = tank_frame([f64::NAN, 0.0, 0.0], [0.0; 3], [0.0; 3], [0.0, 0.0, -G]);
    assert!(err_text(p.advance(0.01, &nan, &rest).unwrap_err()).contains("`acceleration`"));
    let skew = TankMotionInput::Pose(PoseInput {
        position: [0.0; 3],
        rotation: [[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        velocity: [0.0; 3],
        angular_velocity: [0.0; 3],
        acceleration: [0.0; 3],
        angular_acceleration: [0.0; 3],
    });
    assert!(err_text(p.advance(0.01, &skew, &rest).unwrap_err()).contains("`rotation`"));
    assert!(err_text(PoseInput::rotation_from_quaternion([1.0, 1.0, 0.0, 0.0]).unwrap_err()).contains("`quaternion`"));
    // nothing advanced after the rejected calls
    assert_eq!(p.time(), 0.0);
}

#[test]
fn tank_frame_input_interpolates_linearly_and_clamps() {
    let a = TankFrameSample::at_rest(9.81);
    let mut b = a;
    b.acceleration = [2.0, -4.0, 6.0];
    b.gravity = [1.0, 0.0, -9.0];
    let inp = TankFrameInput { t0: 1.0, t1: 3.0, start: a, end: b };
    let m = inp.at(1.5);
    assert!((m.acceleration[0] - 0.5).abs() < 1e-15 && (m.acceleration[1] + 1.0).abs() < 1e-15);
    assert!((m.gravity[2] + (9.81 - 0.25 * 0.81)).abs() < 1e-14);
    assert_eq!(inp.at(0.0), a);
    assert_eq!(inp.at(3.0), b);
    assert_eq!(inp.at(7.0), b);
}

// --- seed 003 maneuvers (rail_mbs::cosim::maneuvers) ---

/// Central differences of the sampled positions reproduce the sampled velocities to the
/// Taylor bound h·max|a|/2 (+ `rel` of it for round-off), and those of the velocities
/// reproduce the accelerations to `tol_a` wherever the acceleration has no jump nearby
/// (the bump inputs have velocity kinks, hence acceleration jumps, at the profile corners).
fn check_derivatives(m: &Maneuver, idx: usize, rel: f64, tol_a: f64) {
    let dt = m.times[1] - m.times[0];
    let p = &m.poses;
    let a_max = p.iter().map(|x| x.acceleration[idx].abs()).fold(0.0, f64::max);
    let tol_v = 0.5 * dt * a_max * (1.0 + rel) + 1e-12;
    let mut checked = 0;
    for k in 1..p.len() - 1 {
        let vfd = (p[k + 1].position[idx] - p[k - 1].position[idx]) / (2.0 * dt);
        let afd = (p[k + 1].velocity[idx] - p[k - 1].velocity[idx]) / (2.0 * dt);
        assert!((vfd - p[k].velocity[idx]).abs() < tol_v, "{} v at {k}: {vfd} vs {}", m.name, p[k].velocity[idx]);
        if (p[k + 1].acceleration[idx] - p[k - 1].acceleration[idx]).abs() > 0.05 * a_max {
            continue;
        }
        checked += 1;
        assert!(
            (afd - p[k].acceleration[idx]).abs() < tol_a,
            "{} a at {k}: {afd} vs {}",
            m.name,
            p[k].acceleration[idx]
        );
    }
    assert!(checked > p.len() * 9 / 10, "{}: only {checked} of {} samples smooth", m.name, p.len());
}

#[test]
fn lane_change_kinematics_are_consistent() {
    let m = lane_change(40.0 * MPH, 12.0 * FOOT, 120.0 * FOOT, 0.5, 0.5, 1e-3).unwrap();
    check_derivatives(&m, 1, 0.01, 1e-2);
    let last = m.poses.last().unwrap();
    assert!((last.position[1] - 12.0 * FOOT).abs() < 1e-12 && last.velocity[1] == 0.0);
    // peak lateral acceleration 2πY/T²
    let tl = 120.0 * FOOT / (40.0 * MPH);
    let peak = m.poses.iter().map(|p| p.acceleration[1].abs()).fold(0.0, f64::max);
    assert!((peak / (2.0 * std::f64::consts::PI * 12.0 * FOOT / (tl * tl)) - 1.0).abs() < 1e-3, "{peak}");
    // heading rate: finite difference of the heading angle
    let psi = |p: &PoseInput| p.rotation[1][0].atan2(p.rotation[0][0]);
    for k in (1..m.poses.len() - 1).step_by(50) {
        let fd = (psi(&m.poses[k + 1]) - psi(&m.poses[k - 1])) / 2e-3;
        assert!((fd - m.poses[k].angular_velocity[2]).abs() < 1e-4);
    }
}

#[test]
fn bumps_rise_and_settle() {
    let v = BumpVehicle::default();
    for m in [
        half_round_bump(9.0 * INCH, 10.0 * MPH, &v, 0.2, 3.0, 1e-3).unwrap(),
        trapezoidal_bump(12.0 * INCH, 48.0 * INCH, 0.3, 12.0 * INCH, 10.0 * MPH, &v, 0.2, 3.0, 1e-3).unwrap(),
    ] {
        check_derivatives(&m, 2, 0.01, 0.05);
        let peak = m.poses.iter().map(|p| p.position[2]).fold(0.0, f64::max);
        assert!(peak > 0.02 && peak < 0.5, "{}: peak heave {peak}", m.name);
        let end = m.poses.last().unwrap();
        assert!(end.position[2].abs() < 0.05 * peak, "{}: not settled {}", m.name, end.position[2]);
    }
    assert!(half_round_bump(-1.0, 1.0, &v, 0.0, 0.0, 1e-3).is_err());
}
