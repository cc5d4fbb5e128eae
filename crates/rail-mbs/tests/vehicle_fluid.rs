//! The monolithic fluid–vehicle system: its assembled Jacobians (including the
//! fluid↔tank coupling blocks) match finite differences of its forces, and a fluid at
//! rest in a free tank body hanging on springs puts its whole weight on the tank.

use ancf_core::FluidBody;
use ancf_core::constitutive::{Fluid, Rheology};
use ancf_core::contact::{WallContact, WallContactLaw};
use ancf_core::element::QuadratureOptions;
use ancf_core::mesh::{CylinderTankSpec, cylinder_tank};
use ancf_core::tank::{TankGeometry, TankShape};
use nalgebra::{Matrix3, Vector3};
use rail_mbs::integrator::{Hht, MechanicalSystem};
use rail_mbs::mbs::rotation::axis_angle;
use rail_mbs::mbs::{BodyId, Bushing, Multibody, RigidBody};
use rail_mbs::vehicle::{FluidVehicle, TankFluid};

fn system(with_springs: bool) -> FluidVehicle {
    let spec = CylinderTankSpec {
        length: 3.0,
        radius: 1.0,
        head_depth: 0.3,
        fill: 0.5,
        n_length: 2,
        n_width: 2,
        n_height: 2,
        grading: 1.0,
    };
    let mesh = cylinder_tank(&spec).unwrap();
    let k = 1000.0 * 850.0 * 9.81 * 1.0;
    let mut fluid = Fluid::new(850.0, Rheology::Newtonian { viscosity: 0.05 }, k).unwrap();
    fluid.bulk_damping = 0.2 * (k * 850.0f64).sqrt() * 0.5;
    let body = FluidBody::new(mesh, fluid, QuadratureOptions::default()).unwrap();
    let geo = TankGeometry::new(TankShape::Cylinder { length: 3.0, radius: 1.0, head_depth: 0.3 }, vec![]).unwrap();
    let contact = WallContact::new(&body, geo, WallContactLaw::default_for(850.0, 9.81, 1.0)).unwrap();
    let mut mb = Multibody::new();
    let mut tank = RigidBody::new("tank", 2000.0, [800.0, 2000.0, 2000.0], Vector3::new(1.0, 0.5, 2.0));
    if !with_springs {
        tank.orientation = axis_angle(&Vector3::new(0.2, 1.0, 0.4), 0.05);
        tank.velocity = Vector3::new(0.3, -0.1, 0.05);
        tank.angular_velocity = Vector3::new(0.05, 0.1, -0.08);
    }
    let id = mb.add_body(tank).unwrap();
    if with_springs {
        for x in [-1.0, 1.0] {
            for y in [-0.5, 0.5] {
                mb.add_force(Box::new(Bushing {
                    name: format!("spring {x} {y}"),
                    bodies: [None, Some(id)],
                    points: [Vector3::new(1.0 + x, 0.5 + y, 0.0), Vector3::new(x, y, -2.0)],
                    frame_i: Matrix3::identity(),
                    frame_j: Matrix3::identity(),
                    offset: Vector3::zeros(),
                    stiffness: [1e7; 3],
                    damping: [1e5; 3],
                    preload: Vector3::zeros(),
                    rotational_stiffness: [0.0; 3],
                    rotational_damping: [0.0; 3],
                    free_axis: None,
                    matrix_stiffness: None,
                    matrix_damping: None,
                }))
                .unwrap();
            }
        }
    }
    FluidVehicle::new(mb, vec![TankFluid { tank: BodyId(0), body, contact }]).unwrap()
}

fn dense(pattern: &[(usize, usize)], values: &[f64], n: usize) -> Vec<f64> {
    let mut m = vec![0.0; n * n];
    for (&(r, c), v) in pattern.iter().zip(values) {
        m[r * n + c] += v;
    }
    m
}

#[test]
fn coupled_jacobians_match_finite_differences() {
    let mut sys = system(false);
    let n = sys.n_coords();
    let (mut q, mut v) = sys.initial_coordinates();
    // Push the liquid 3 mm down and 2 mm sideways into the shell, with a deforming velocity.
    for (i, x) in q[7..].iter_mut().enumerate() {
        if i % 12 == 2 {
            *x -= 3e-3;
        }
        if i % 12 == 1 {
            *x += 2e-3;
        }
    }
    for (i, x) in v[7..].iter_mut().enumerate() {
        *x += 0.01 * ((i as f64) * 0.7).sin();
    }
    let pat = sys.pattern().dynamics;
    let (mut dq, mut dv) = (vec![0.0; pat.len()], vec![0.0; pat.len()]);
    sys.force_jacobians(0.0, &q, &v, &mut dq, &mut dv).unwrap();
    let (kq, kv) = (dense(&pat, &dq, n), dense(&pat, &dv, n));
    let mut f0 = vec![0.0; n];
    sys.forces(0.0, &q, &v, &mut f0).unwrap();
    let scale = f0.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    // Tank columns (0..7) and a spread of fluid columns.
    let cols: Vec<usize> = (0..7).chain((7..n).step_by(13)).collect();
    let mut worst: f64 = 0.0;
    for &c in &cols {
        for velocity in [false, true] {
            let h = if velocity { 1e-6 } else { 1e-7 };
            let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
            let (mut xp, mut xm) = if velocity { (v.clone(), v.clone()) } else { (q.clone(), q.clone()) };
            xp[c] += h;
            xm[c] -= h;
            if velocity {
                sys.forces(0.0, &q, &xp, &mut fp).unwrap();
                sys.forces(0.0, &q, &xm, &mut fm).unwrap();
            } else {
                sys.forces(0.0, &xp, &v, &mut fp).unwrap();
                sys.forces(0.0, &xm, &v, &mut fm).unwrap();
            }
            let k = if velocity { &kv } else { &kq };
            let col_scale = (0..n).map(|r| ((fp[r] - fm[r]) / (2.0 * h)).abs()).fold(0.0f64, f64::max).max(1.0);
            for r in 0..n {
                let fd = (fp[r] - fm[r]) / (2.0 * h);
                let err = (fd - k[r * n + c]).abs() / col_scale;
                if err > worst {
                    worst = err;
                }
                assert!(err < 2e-4, "column {c} (velocity {velocity}) row {r}: fd {fd:.6e} vs {:.6e}", k[r * n + c]);
            }
        }
    }
    println!("worst relative Jacobian error {worst:.2e} (force scale {scale:.3e})");
}

#[test]
fn fluid_weight_is_carried_by_the_tank_springs() {
    let sys = system(true);
    let (q0, v0) = sys.initial_coordinates();
    let fluid_mass = sys.fluids[0].body.total_mass();
    let params = rail_mbs::vehicle::TrainScenario::default_hht();
    let mut hht = Hht::new(sys, 0.0, q0, v0, params).unwrap();
    hht.integrate_to(1.0, 2e-3).unwrap();
    let (q, v) = (hht.q().to_vec(), hht.v().to_vec());
    let sys = hht.system();
    let load = sys.fluid_load(0, &q, &v);
    let w = fluid_mass * 9.80665;
    println!("fluid load on tank {:?} N, fluid weight {w:.1} N", load.force);
    assert!((-load.force[2] - w).abs() < 0.01 * w, "vertical load {} vs {w}", -load.force[2]);
    assert!(load.force[0].abs() < 0.01 * w && load.force[1].abs() < 0.01 * w);
    // The springs carry tank + fluid: the tank sank by (m_t + m_f) g / (4 k).
    let sag = 2.0 - q[2];
    let expected = (2000.0 + fluid_mass) * 9.80665 / 4e7;
    println!("tank sag {sag:.4e} m vs {expected:.4e} m");
    assert!((sag - expected).abs() < 0.02 * expected);
}

/// `mass_entries` (used by the integrator to form `M a` over mass entries only) covers
/// every entry `mass` writes, at a rotated tank state, for the monolithic system and for a
/// fluid in a prescribed-motion tank; and the integrator gives the same first step with and
/// without the declaration.
/// A fluid vehicle with its mass shortcuts hidden (`mass_varying_entries`, `subtract_mass_product`)
/// and, without `mass_entries`, its declaration of the mass entries: every other method forwarded.
struct Plain {
    sys: FluidVehicle,
    mass_entries: bool,
}
impl MechanicalSystem for Plain {
    fn n_coords(&self) -> usize {
        self.sys.n_coords()
    }
    fn n_constraints(&self) -> usize {
        self.sys.n_constraints()
    }
    fn pattern(&self) -> rail_mbs::integrator::SparsityPattern {
        self.sys.pattern()
    }
    fn mass_is_constant(&self) -> bool {
        self.sys.mass_is_constant()
    }
    fn linear_solver(&self) -> rail_mbs::integrator::LinearSolverKind {
        self.sys.linear_solver()
    }
    fn condensed_blocks(&self) -> Vec<std::ops::Range<usize>> {
        self.sys.condensed_blocks()
    }
    fn mass_entries(&self) -> Option<Vec<usize>> {
        if self.mass_entries { self.sys.mass_entries() } else { None }
    }
    fn mass(&mut self, q: &[f64], v: &mut [f64]) -> Result<(), rail_mbs::integrator::SystemError> {
        self.sys.mass(q, v)
    }
    fn forces(&mut self, t: f64, q: &[f64], v: &[f64], o: &mut [f64]) -> Result<(), rail_mbs::integrator::SystemError> {
        self.sys.forces(t, q, v, o)
    }
    fn force_jacobians(
        &mut self,
        t: f64,
        q: &[f64],
        v: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
    ) -> Result<(), rail_mbs::integrator::SystemError> {
        self.sys.force_jacobians(t, q, v, dq, dv)
    }
    fn constraints(&mut self, t: f64, q: &[f64], o: &mut [f64]) -> Result<(), rail_mbs::integrator::SystemError> {
        self.sys.constraints(t, q, o)
    }
    fn constraint_jacobian(
        &mut self,
        t: f64,
        q: &[f64],
        o: &mut [f64],
    ) -> Result<(), rail_mbs::integrator::SystemError> {
        self.sys.constraint_jacobian(t, q, o)
    }
    fn constraint_force_jacobian(
        &mut self,
        t: f64,
        q: &[f64],
        lambda: &[f64],
        dq: &mut [f64],
    ) -> Result<bool, rail_mbs::integrator::SystemError> {
        self.sys.constraint_force_jacobian(t, q, lambda, dq)
    }
    fn check_step(&mut self, t: f64, q: &[f64], v: &[f64]) -> Result<(), rail_mbs::integrator::SystemError> {
        self.sys.check_step(t, q, v)
    }
}

#[test]
fn declared_mass_entries_cover_the_mass_matrix() {
    let mut sys = system(false);
    let (q, _) = sys.initial_coordinates();
    let nd = sys.pattern().dynamics.len();
    let mut m = vec![0.0; nd];
    sys.mass(&q, &mut m).unwrap();
    let declared: std::collections::HashSet<usize> = sys.mass_entries().unwrap().into_iter().collect();
    let missing: Vec<usize> = (0..nd).filter(|k| m[*k] != 0.0 && !declared.contains(k)).collect();
    assert!(
        missing.is_empty(),
        "{} mass entries not declared, e.g. {:?}",
        missing.len(),
        &missing[..missing.len().min(5)]
    );
    assert!(declared.len() < nd / 2, "declared {} of {nd} entries", declared.len());

    let (q0, v0) = sys.initial_coordinates();
    let params = rail_mbs::integrator::HhtParams { abs_tol_acc: 1e-6, max_iterations: 20, ..Default::default() };
    let mut a = Hht::new(system(false), 0.0, q0.clone(), v0.clone(), params).unwrap();
    let mut b = Hht::new(Plain { sys: system(false), mass_entries: false }, 0.0, q0, v0, params).unwrap();
    a.step(1e-3).unwrap();
    b.step(1e-3).unwrap();
    let dev = a.q().iter().zip(b.q()).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(dev < 1e-12, "declared vs undeclared mass entries: max |dq| = {dev:e}");
}

#[test]
fn unknowns_are_described_by_body_and_fluid_node() {
    // Newton-divergence messages name the unknown with the largest correction through
    // `describe_unknown`: rigid coordinates by body, fluid coordinates by node and slot.
    use rail_mbs::integrator::KktIndex;
    let sys = system(true);
    assert_eq!(sys.describe_unknown(KktIndex::Coordinate(1)), "coordinate 1 = y of body 'tank'");
    assert_eq!(sys.describe_unknown(KktIndex::Coordinate(5)), "coordinate 5 = e2 of body 'tank'");
    // node 2, slot 1 (∂r/∂X), z: 7 rigid + 12·2 + 3 + 2
    assert_eq!(
        sys.describe_unknown(KktIndex::Coordinate(36)),
        "coordinate 36 = gradient d/dX z of node 2 of fluid 0 (tank 'tank')"
    );
    assert_eq!(
        sys.describe_unknown(KktIndex::Constraint(0)),
        "constraint 0 = Euler-parameter normalization of body 'tank'"
    );
    let n = sys.n_coords();
    assert_eq!(sys.describe_unknown(KktIndex::Coordinate(n)), format!("coordinate {n}"));
}

/// Final state bits of a few steps of the studies' tank car (light crude, 6×4×2 mesh)
/// inside a rayon pool of `threads` workers.
fn fluid_car_in_pool(threads: usize) -> Vec<u64> {
    use rail_mbs::defaults::Oil;
    use rail_mbs::track::Track;
    use rail_mbs::vehicle::{FluidCargo, TankCarParams, TrainScenario, build_fluid_train};
    use std::sync::Arc;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| {
        let p = TankCarParams::standard().unwrap();
        let depth = p.tank_radius;
        let fluid = Oil::Light.fluid(depth, depth / 2.0).unwrap();
        let cargo = FluidCargo::new(fluid, [6, 4, 2], 0.5, vec![]);
        let track = Arc::new(Track::straight(3000.0).unwrap());
        let sc = TrainScenario::single(p, track, 300.0, 10.0, 1.0);
        let (sys, _, _) = build_fluid_train(&sc, &cargo).unwrap();
        let (q0, v0) = sys.initial_coordinates();
        let mut hht = Hht::new(sys, 0.0, q0, v0, sc.hht).unwrap();
        hht.integrate_to(0.016, 4e-3).unwrap();
        [hht.q(), hht.v(), hht.a()].iter().flat_map(|x| x.iter().map(|v| v.to_bits())).collect()
    })
}

/// The parallel element assembly is deterministic and the sparse LU runs sequentially, so
/// the tank car's trajectory does not depend on the number of threads (with faer's
/// thread-count-dependent supernodal LU the last bits of this case differed).
#[test]
fn fluid_car_results_do_not_depend_on_the_thread_count() {
    let one = fluid_car_in_pool(1);
    assert!(fluid_car_in_pool(2) == one, "2 threads differ from 1 thread");
}

/// Two cars (two fluids, each coupled only to its tank body): a few steps solved by static
/// condensation (the default) and by one LU of the whole matrix take the same Newton
/// iterations to the same state, and the condensed solve does not depend on the thread count.
#[test]
fn condensed_and_direct_solves_give_the_same_train_run() {
    use rail_mbs::defaults::Oil;
    use rail_mbs::integrator::LinearSolverKind;
    use rail_mbs::track::Track;
    use rail_mbs::vehicle::{FluidCargo, TankCarParams, TrainScenario, build_fluid_train};
    use std::sync::Arc;
    let run = |kind: LinearSolverKind, threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let p = TankCarParams::standard().unwrap();
            let fluid = Oil::Light.fluid(p.tank_radius, p.tank_radius / 2.0).unwrap();
            let mut cargo = FluidCargo::new(fluid, [2, 2, 2], 0.5, vec![]);
            cargo.linear_solver = kind;
            let track = Arc::new(Track::straight(3000.0).unwrap());
            let mut sc = TrainScenario::single(p, track, 300.0, 10.0, 1.0);
            sc.cars = 2;
            let (sys, _, _) = build_fluid_train(&sc, &cargo).unwrap();
            assert_eq!(sys.condensed_blocks().len(), 2);
            let (q0, v0) = sys.initial_coordinates();
            let mut hht = Hht::new(sys, 0.0, q0, v0, sc.hht).unwrap();
            hht.integrate_to(0.04, 4e-3).unwrap();
            (hht.q().to_vec(), hht.stats().newton_iterations)
        })
    };
    let (qd, nd) = run(LinearSolverKind::Direct, 1);
    let (qc, nc) = run(LinearSolverKind::Condensed, 1);
    assert_eq!(nd, nc, "Newton iterations");
    let scale = qd.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let diff = qd.iter().zip(&qc).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(diff < 1e-10 * scale, "condensed differs from direct by {diff:.3e} (scale {scale:.3e})");
    let (q2, _) = run(LinearSolverKind::Condensed, 2);
    assert!(q2.iter().zip(&qc).all(|(a, b)| a.to_bits() == b.to_bits()), "2 threads differ from 1 thread");
}

/// The fluid vehicle's mass shortcuts: only the rigid bodies' mass entries change with q (the
/// fluids' consistent mass is constant), and its own `M a` (the fluids' M_s ⊗ I₃ from the scalar
/// mass) is bit for bit the integrator's product over the pattern entries; the tank car run with
/// them equals, bit for bit, the run with both hidden.
#[test]
fn the_mass_shortcuts_give_the_same_run_bit_for_bit() {
    use rail_mbs::defaults::Oil;
    use rail_mbs::track::Track;
    use rail_mbs::vehicle::{FluidCargo, TankCarParams, TrainScenario, build_fluid_train};
    use std::sync::Arc;

    // unit checks on the free tank of `system(false)`, which rotates
    let mut sys = system(false);
    let (q0, v0) = sys.initial_coordinates();
    let nd = sys.pattern().dynamics.len();
    let (mut m0, mut m1) = (vec![0.0; nd], vec![0.0; nd]);
    sys.mass(&q0, &mut m0).unwrap();
    let mut q1 = q0.clone();
    for (k, x) in q1.iter_mut().enumerate().take(7) {
        *x += 0.1 * (k as f64 + 1.0).sin(); // moves and turns the tank body (unnormalized parameters are fine here)
    }
    sys.mass(&q1, &mut m1).unwrap();
    let varying: std::collections::HashSet<usize> = sys.mass_varying_entries().unwrap().into_iter().collect();
    assert!(varying.len() < nd / 10, "{} of {nd} entries declared varying", varying.len());
    let changed: Vec<usize> = (0..nd).filter(|k| m0[*k] != m1[*k]).collect();
    assert!(!changed.is_empty(), "the rigid mass must change with the Euler parameters");
    assert!(changed.iter().all(|k| varying.contains(k)), "an entry outside the declared ones changed");
    let mut part = m0.clone();
    for &k in &varying {
        part[k] = 0.0;
    }
    sys.mass_varying(&q1, &mut part).unwrap();
    assert!(part.iter().zip(&m1).all(|(a, b)| a.to_bits() == b.to_bits()), "mass_varying on m(q0) != m(q1)");
    let n = sys.n_coords();
    let a: Vec<f64> = (0..n).map(|i| (0.37 * i as f64).sin() * 3.0 + v0[i]).collect();
    let pattern = sys.pattern().dynamics;
    let mut entries: Vec<(usize, usize, usize)> =
        sys.mass_entries().unwrap().into_iter().map(|k| (pattern[k].0, pattern[k].1, k)).collect();
    entries.sort_unstable();
    entries.dedup();
    let (scale, start) = (0.731, (0..n).map(|i| i as f64 * 0.01).collect::<Vec<_>>());
    let mut by_pattern = start.clone();
    for &(i, j, k) in &entries {
        by_pattern[i] -= scale * m1[k] * a[j];
    }
    let mut own = start;
    assert!(sys.subtract_mass_product(&m1, &a, scale, &mut own));
    assert!(by_pattern.iter().zip(&own).all(|(x, y)| x.to_bits() == y.to_bits()), "M a differs");

    let car = || {
        let p = TankCarParams::standard().unwrap();
        let fluid = Oil::Light.fluid(p.tank_radius, p.tank_radius / 2.0).unwrap();
        let cargo = FluidCargo::new(fluid, [2, 2, 2], 0.5, vec![]);
        let track = Arc::new(Track::straight(3000.0).unwrap());
        let sc = TrainScenario::single(p, track, 300.0, 10.0, 1.0);
        let (sys, _, _) = build_fluid_train(&sc, &cargo).unwrap();
        (sys, sc.hht)
    };
    let (fast, params) = car();
    let (q0, v0) = fast.initial_coordinates();
    let mut a = Hht::new(fast, 0.0, q0.clone(), v0.clone(), params).unwrap();
    let mut b = Hht::new(Plain { sys: car().0, mass_entries: true }, 0.0, q0, v0, params).unwrap();
    a.integrate_to(0.02, 4e-3).unwrap();
    b.integrate_to(0.02, 4e-3).unwrap();
    assert_eq!(a.stats().newton_iterations, b.stats().newton_iterations);
    for (x, y) in [(a.q(), b.q()), (a.v(), b.v()), (a.a(), b.a())] {
        assert!(x.iter().zip(y).all(|(x, y)| x.to_bits() == y.to_bits()), "the runs differ");
    }
}
