//! The culled wall-contact pass (`WallContact::forces`) against the full check of every
//! point (`forces_full`): bit-identical outputs on many states, the cull really skips
//! points, the tank clearance is a true lower bound of the distance to the walls, and the
//! pass allocates nothing (a counting global allocator counts the current thread's
//! allocations).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use ancf_core::FluidBody;
use ancf_core::body::rigid_motion;
use ancf_core::constitutive::{Fluid, M3, Rheology};
use ancf_core::contact::{Cull, PointJacobian, TankKinematics, WallContact, WallContactLaw, WallFriction};
use ancf_core::element::QuadratureOptions;
use ancf_core::mesh::{
    CylinderTankSpec, EllipticCylinderSpec, FluidMesh, box_mesh, cylinder_tank, cylinder_tank_compartments,
    elliptic_cylinder,
};
use ancf_core::rng::Rng;
use ancf_core::tank::{Bulkhead, TankGeometry, TankShape};
use nalgebra::{Rotation3, Vector3};

struct CountingAllocator;

thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

fn bump() {
    // `try_with`: the allocator can be called while the thread-local is being destroyed.
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

// SAFETY: every call is forwarded unchanged to the system allocator.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        bump();
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        bump();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        bump();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

/// Allocations of the current thread so far.
fn allocations() -> u64 {
    ALLOCATIONS.with(Cell::get)
}

fn body(mesh: FluidMesh) -> FluidBody {
    let fluid = Fluid::new(850.0, Rheology::Newtonian { viscosity: 0.01 }, 1e6).unwrap();
    FluidBody::new(mesh, fluid, QuadratureOptions::default()).unwrap()
}

/// Tank-frame coordinates: the reference ones mapped by x ↦ x + δ(x) with a smooth random
/// δ of amplitude `amp` (gradients mapped by I + ∇δ), plus a rigid shift; then placed in
/// the global frame by `kin` (velocities: the rigid motion plus a random field).
fn state(b: &FluidBody, kin: &TankKinematics, amp: f64, shift: [f64; 3], seed: u64) -> (Vec<f64>, Vec<f64>) {
    lifted(b, kin, amp, shift, 0.0, 0.0, seed)
}

/// [`state`] with the free surface of the half-full tank-car cylinder lifted by `lift`,
/// and independent uniform noise of amplitude `gradient_noise` on every gradient.
fn lifted(
    b: &FluidBody,
    kin: &TankKinematics,
    amp: f64,
    shift: [f64; 3],
    lift: f64,
    gradient_noise: f64,
    seed: u64,
) -> (Vec<f64>, Vec<f64>) {
    let mut rng = Rng::new(seed);
    let k: Vec<[f64; 3]> = (0..3).map(|_| rng.vec3(2.0)).collect();
    let ph: Vec<f64> = (0..3).map(|_| 3.0 * rng.uniform()).collect();
    let c: Vec<[f64; 3]> = (0..3).map(|_| rng.vec3(amp)).collect();
    // δ(x) = Σ_m c_m sin(k_m·x + φ_m), ∇δ = Σ_m c_m cos(·) k_mᵀ
    let delta = |x: [f64; 3]| {
        let mut d = [0.0; 3];
        let mut g = M3::zeros();
        for m in 0..3 {
            let arg = k[m][0] * x[0] + k[m][1] * x[1] + k[m][2] * x[2] + ph[m];
            for i in 0..3 {
                d[i] += c[m][i] * arg.sin();
                for j in 0..3 {
                    g[(i, j)] += c[m][i] * arg.cos() * k[m][j];
                }
            }
        }
        (d, g)
    };
    let mut local = b.reference_coordinates();
    for node in local.chunks_exact_mut(12) {
        let x = [node[0], node[1], node[2]];
        let (mut d, mut g) = delta(x);
        // lift the free surface (z = 0 of a half-full cylinder of radius 1.5) by `lift`,
        // keeping the bottom (z = −1.5)
        d[2] += lift * (x[2] + 1.5) / 1.5;
        g[(2, 2)] += lift / 1.5;
        for i in 0..3 {
            node[i] += d[i] + shift[i];
        }
        for s in 1..4 {
            let v = g * Vector3::new(node[3 * s], node[3 * s + 1], node[3 * s + 2]);
            for i in 0..3 {
                node[3 * s + i] += v[i] + gradient_noise * rng.uniform();
            }
        }
    }
    let (e, mut ed) = rigid_motion(&local, &kin.rotation, kin.position, kin.angular_velocity, kin.velocity);
    for v in ed.iter_mut() {
        *v += 0.2 * rng.uniform();
    }
    (e, ed)
}

fn moving(seed: u64) -> TankKinematics {
    let mut rng = Rng::new(seed + 100);
    let r = rng.vec3(0.4);
    TankKinematics {
        position: [150.0 + 50.0 * rng.uniform(), rng.uniform(), 2.35],
        rotation: *Rotation3::from_euler_angles(r[0], r[1], r[2]).matrix(),
        velocity: rng.vec3(10.0),
        angular_velocity: rng.vec3(0.5),
    }
}

fn bits(x: &[f64]) -> Vec<u64> {
    x.iter().map(|v| v.to_bits()).collect()
}

fn jac_bits(j: &[PointJacobian]) -> Vec<(usize, Vec<u64>)> {
    j.iter()
        .map(|p| {
            let mut v = bits(p.d_position.as_slice());
            v.extend(bits(p.d_velocity.as_slice()));
            v.extend(bits(p.force.as_slice()));
            v.extend(bits(p.arm.as_slice()));
            (p.point, v)
        })
        .collect()
}

/// Points checked by the production cull ([`Cull::On`]) and by the bound tried on every
/// face ([`Cull::Always`]), of `total`; `active` in contact.
struct Counts {
    checked: usize,
    checked_always: usize,
    total: usize,
    active: usize,
}

/// Culled (both modes) and full passes agree bit for bit (generalized forces added onto
/// the same random `out`, load, active count, Jacobian list).
fn assert_identical(c: &WallContact, b: &FluidBody, kin: &TankKinematics, e: &[f64], ed: &[f64]) -> Counts {
    let mut rng = Rng::new(7);
    let init: Vec<f64> = (0..b.n_coords()).map(|_| rng.uniform()).collect();
    let (mut q1, mut q2) = (init.clone(), init.clone());
    let (mut j1, mut j2) = (vec![], vec![]);
    let full = c.forces_full(b, kin, e, ed, &mut q1, Some(&mut j1));
    let (culled, checked) = c.forces_counted(b, kin, e, ed, &mut q2, Some(&mut j2), Cull::On);
    assert_eq!(bits(&q1), bits(&q2), "generalized forces differ");
    assert_eq!(full.active, culled.active);
    assert_eq!(bits(&full.force), bits(&culled.force));
    assert_eq!(bits(&full.moment), bits(&culled.moment));
    assert_eq!(full.max_penetration.to_bits(), culled.max_penetration.to_bits());
    assert_eq!(jac_bits(&j1), jac_bits(&j2), "point Jacobians differ");
    // residual-only path (no Jacobians computed) and the public entry point
    let mut q3 = init.clone();
    let l3 = c.forces(b, kin, e, ed, &mut q3, None);
    assert_eq!(bits(&q1), bits(&q3));
    assert_eq!((l3.active, bits(&l3.force), bits(&l3.moment)), (full.active, bits(&full.force), bits(&full.moment)));
    // the unculled counted path checks every point
    let mut q4 = init.clone();
    let (_, all) = c.forces_counted(b, kin, e, ed, &mut q4, None, Cull::Off);
    assert_eq!(all, c.points.len());
    assert_eq!(bits(&q1), bits(&q4));
    // the bound tried on every face (no heuristics): the bound alone must be conservative
    let (mut q5, mut j5) = (init, vec![]);
    let (l5, checked_always) = c.forces_counted(b, kin, e, ed, &mut q5, Some(&mut j5), Cull::Always);
    assert_eq!(bits(&q1), bits(&q5), "generalized forces differ (bound on every face)");
    assert_eq!((l5.active, bits(&l5.force), bits(&l5.moment)), (full.active, bits(&full.force), bits(&full.moment)));
    assert_eq!(l5.max_penetration.to_bits(), full.max_penetration.to_bits());
    assert_eq!(jac_bits(&j1), jac_bits(&j5));
    assert!(checked_always <= checked);
    Counts { checked, checked_always, total: c.points.len(), active: full.active }
}

fn laws(depth: f64) -> Vec<WallContactLaw> {
    let base = WallContactLaw::default_for(850.0, 9.81, depth);
    [
        WallFriction::Frictionless,
        WallFriction::Coulomb { coefficient: 0.4, slip_velocity: 0.05 },
        WallFriction::NoSlip { drag: 2e3, activation_depth: 0.003 },
    ]
    .into_iter()
    .enumerate()
    .map(|(i, friction)| WallContactLaw { friction, points_per_edge: 2 + i, ..base })
    .collect()
}

fn tank_car(counts: [usize; 3]) -> CylinderTankSpec {
    CylinderTankSpec { length: 11.0, radius: 1.5, head_depth: 0.5, ..CylinderTankSpec::tank_car(counts) }
}

#[test]
fn culled_pass_is_bit_identical_in_a_cylinder_tank_with_heads() {
    let spec = tank_car([6, 4, 2]);
    let b = body(cylinder_tank(&spec).unwrap());
    let geo = TankGeometry::new(TankShape::Cylinder { length: 11.0, radius: 1.5, head_depth: 0.5 }, vec![]).unwrap();
    let mut culled_somewhere = false;
    let mut distorted_skipped = 0;
    for law in laws(1.5) {
        let c = WallContact::new(&b, geo.clone(), law).unwrap();
        // rest (sunk into the bottom), tank at the origin and moving
        for (seed, kin) in [(1, TankKinematics::identity()), (2, moving(2))] {
            let (e, ed) = state(&b, &kin, 0.0, [0.0, 0.0, -0.0015], seed);
            let n = assert_identical(&c, &b, &kin, &e, &ed);
            // the production cull skips points at rest
            let (checked, total, active) = (n.checked, n.total, n.active);
            assert!(active > 0 && checked < total, "rest: {checked}/{total}, {active} active");
            culled_somewhere = true;
        }
        // sloshing-like distortions of growing amplitude: shell and heads penetrated
        for seed in 3..9 {
            let kin = moving(seed);
            let amp = 0.02 * (seed - 2) as f64;
            let shift = [0.3 * (seed as f64 - 5.5), 0.05, -0.01];
            let (e, ed) = state(&b, &kin, amp, shift, seed);
            let n = assert_identical(&c, &b, &kin, &e, &ed);
            let checked = n.checked_always;
            let total = n.total;
            let active = n.active;
            assert!(active > 0);
            distorted_skipped += total - checked;
        }
    }
    assert!(culled_somewhere);
    assert!(distorted_skipped > 0, "no distorted state culled anything");
}

#[test]
fn culled_pass_is_bit_identical_when_the_free_surface_nears_the_roof() {
    // Sweeping the free surface up to the roof in 1 cm steps makes the cull decisions of
    // the surface faces marginal: a bound that misses any term (e.g. the gradient
    // functions' share) skips a penetrating point somewhere in the sweep.
    let b = body(cylinder_tank(&tank_car([6, 4, 2])).unwrap());
    let geo = TankGeometry::new(TankShape::Cylinder { length: 11.0, radius: 1.5, head_depth: 0.5 }, vec![]).unwrap();
    let mut law = WallContactLaw::default_for(850.0, 9.81, 1.5);
    law.points_per_edge = 4;
    let c = WallContact::new(&b, geo, law).unwrap();
    let (mut skipped, mut roof_hits) = (0, 0);
    for step in 0..60 {
        let lift = 0.9 + 0.01 * step as f64;
        let kin = moving(step);
        let (e, ed) = lifted(&b, &kin, 0.01, [0.0, 0.0, -0.0015], lift, 0.3, step);
        let n = assert_identical(&c, &b, &kin, &e, &ed);
        let checked = n.checked_always;
        let total = n.total;
        let active = n.active;
        skipped += total - checked;
        roof_hits += active;
    }
    assert!(skipped > 0 && roof_hits > 0);
}

#[test]
fn culled_pass_is_bit_identical_with_bulkheads_flat_ends_box_and_elliptic_tanks() {
    // compartments: shifting the liquid axially pushes one side into each bulkhead
    let spec = tank_car([6, 3, 2]);
    let bh = [(-1.8, 0.02), (1.8, 0.02)];
    let b = body(cylinder_tank_compartments(&spec, &bh).unwrap());
    let geo = TankGeometry::new(
        TankShape::Cylinder { length: 11.0, radius: 1.5, head_depth: 0.5 },
        bh.iter().map(|&(x, thickness)| Bulkhead { x, thickness }).collect(),
    )
    .unwrap();
    let mut bulkhead_hit = false;
    // points skipped by the cull, per tank: the comparisons must cover culled states
    let mut skipped = 0;
    for law in laws(1.5) {
        let c = WallContact::new(&b, geo.clone(), law).unwrap();
        for seed in 0..6 {
            let kin = moving(seed);
            let shift = [0.02 * (seed as f64 - 2.5), 0.0, -0.002];
            let (e, ed) = state(&b, &kin, 0.01 * seed as f64, shift, seed);
            let n = assert_identical(&c, &b, &kin, &e, &ed);
            let checked = n.checked_always;
            let total = n.total;
            skipped += total - checked;
            // a bulkhead hit: some point is pushed along ∓x (the shell pushes radially)
            let mut j = vec![];
            c.forces(&b, &kin, &e, &ed, &mut vec![0.0; b.n_coords()], Some(&mut j));
            bulkhead_hit |= j.iter().any(|p| {
                let f = kin.rotation.transpose() * p.force;
                f[0].abs() > 0.9 * f.norm() && f.norm() > 0.0
            });
        }
    }
    assert!(bulkhead_hit, "no state pushed liquid into a bulkhead");
    assert!(skipped > 0, "compartments: nothing culled");

    // flat-ended cylinder (end planes)
    let flat = CylinderTankSpec { head_depth: 0.0, ..tank_car([4, 3, 2]) };
    let b = body(cylinder_tank(&flat).unwrap());
    let geo = TankGeometry::new(TankShape::Cylinder { length: 11.0, radius: 1.5, head_depth: 0.0 }, vec![]).unwrap();
    let mut skipped = 0;
    for law in laws(1.5) {
        let c = WallContact::new(&b, geo.clone(), law).unwrap();
        for seed in 0..4 {
            let kin = moving(seed);
            let (e, ed) = state(&b, &kin, 0.03 * seed as f64, [0.05 * seed as f64, 0.0, -0.002], seed);
            let n = assert_identical(&c, &b, &kin, &e, &ed);
            let checked = n.checked_always;
            let total = n.total;
            skipped += total - checked;
        }
    }
    assert!(skipped > 0, "flat ends: nothing culled");

    // box tank, 10 % smaller than the liquid block at a corner and with a bulkhead
    let b = body(box_mesh([-0.6, -0.3, 0.0], [1.2, 0.6, 0.4], [4, 2, 2]).unwrap());
    let geo = TankGeometry::new(
        TankShape::Box { min: [-0.59, -0.29, 0.002], max: [0.58, 0.3, 0.6] },
        vec![Bulkhead { x: 0.01, thickness: 0.01 }],
    )
    .unwrap();
    let mut skipped = 0;
    for law in laws(0.4) {
        let c = WallContact::new(&b, geo.clone(), law).unwrap();
        for seed in 0..4 {
            let kin = moving(seed);
            let (e, ed) = state(&b, &kin, 0.01 * seed as f64, [0.0; 3], seed);
            let n = assert_identical(&c, &b, &kin, &e, &ed);
            let checked = n.checked_always;
            let total = n.total;
            let active = n.active;
            assert!(active > 0);
            skipped += total - checked;
        }
    }
    assert!(skipped > 0, "box: nothing culled");

    // elliptic cylinder (quadric shell and end planes)
    let es = EllipticCylinderSpec::swri(3, 4, 2);
    let b = body(elliptic_cylinder(&es).unwrap());
    let geo = TankGeometry::new(
        TankShape::EllipticCylinder { length: es.length, semi_axis_y: es.semi_axis_y, semi_axis_z: es.semi_axis_z },
        vec![],
    )
    .unwrap();
    let mut skipped = 0;
    for law in laws(0.1) {
        let c = WallContact::new(&b, geo.clone(), law).unwrap();
        for seed in 0..4 {
            let kin = moving(seed);
            let (e, ed) = state(&b, &kin, 0.004 * seed as f64, [0.003 * seed as f64, 0.0, -0.0005], seed);
            let n = assert_identical(&c, &b, &kin, &e, &ed);
            let checked = n.checked_always;
            let total = n.total;
            let active = n.active;
            assert!(active > 0);
            skipped += total - checked;
        }
    }
    assert!(skipped > 0, "elliptic: nothing culled");
}

#[test]
fn non_finite_states_are_never_culled_into_a_different_result() {
    let b = body(cylinder_tank(&tank_car([4, 2, 2])).unwrap());
    let geo = TankGeometry::new(TankShape::Cylinder { length: 11.0, radius: 1.5, head_depth: 0.5 }, vec![]).unwrap();
    let c = WallContact::new(&b, geo, WallContactLaw::default_for(850.0, 9.81, 1.5)).unwrap();
    let kin = moving(1);
    let (mut e, ed) = state(&b, &kin, 0.02, [0.0, 0.0, -0.002], 1);
    e[12 * 7 + 4] = f64::NAN; // a gradient
    e[12 * 30 + 2] = f64::INFINITY; // a position
    let mut rng = Rng::new(2);
    let init: Vec<f64> = (0..b.n_coords()).map(|_| rng.uniform()).collect();
    let (mut q1, mut q2) = (init.clone(), init);
    let l1 = c.forces_full(&b, &kin, &e, &ed, &mut q1, None);
    let l2 = c.forces(&b, &kin, &e, &ed, &mut q2, None);
    assert_eq!(bits(&q1), bits(&q2));
    assert_eq!((l1.active, bits(&l1.force)), (l2.active, bits(&l2.force)));
}

#[test]
fn cull_skips_free_surface_points_of_a_half_full_tank_at_rest() {
    for counts in [[6, 4, 2], [12, 6, 4]] {
        let b = body(cylinder_tank(&tank_car(counts)).unwrap());
        let geo =
            TankGeometry::new(TankShape::Cylinder { length: 11.0, radius: 1.5, head_depth: 0.5 }, vec![]).unwrap();
        let mut law = WallContactLaw::default_for(850.0, 9.81, 1.5);
        law.points_per_edge = 4;
        let c = WallContact::new(&b, geo, law).unwrap();
        let kin = moving(4);
        let (e, ed) = state(&b, &kin, 0.0, [0.0, 0.0, -0.0015], 4);
        let n = assert_identical(&c, &b, &kin, &e, &ed);
        let checked = n.checked;
        let total = n.total;
        let active = n.active;
        // the free surface has counts[0]·counts[1] faces of 16 points, most of them far
        // from the shell: at least a third of them must be skipped
        let surface = 16 * counts[0] * counts[1];
        assert!(total - checked >= surface / 3, "{counts:?}: skipped {} of {surface}", total - checked);
        assert!(checked >= active);
    }
}

/// ψ of every wall of `g` at `p` (tank frame), whether active there or not, for the
/// walls with closed forms: planes and the circular shell (exact distances).
fn exact_walls(g: &TankGeometry, p: [f64; 3]) -> Vec<f64> {
    let [x, y, z] = p;
    match g.shape {
        TankShape::Cylinder { length, radius, head_depth } => {
            let mut v = vec![];
            if head_depth == 0.0 || x.abs() <= 0.5 * length {
                v.push((y * y + z * z).sqrt() - radius);
            }
            if head_depth == 0.0 {
                v.extend([x - 0.5 * length, -x - 0.5 * length]);
            }
            v
        }
        TankShape::EllipticCylinder { length, .. } => vec![x - 0.5 * length, -x - 0.5 * length],
        TankShape::Box { min, max } => (0..3).flat_map(|d| [p[d] - max[d], min[d] - p[d]]).collect(),
    }
}

#[test]
fn clearance_is_a_lower_bound_of_the_distance_to_every_wall() {
    let geos = [
        TankGeometry::new(
            TankShape::Cylinder { length: 11.0, radius: 1.5, head_depth: 0.5 },
            vec![Bulkhead { x: -1.8, thickness: 0.02 }, Bulkhead { x: 1.8, thickness: 0.02 }],
        )
        .unwrap(),
        TankGeometry::new(TankShape::Cylinder { length: 2.0, radius: 0.5, head_depth: 0.9 }, vec![]).unwrap(),
        TankGeometry::new(TankShape::Cylinder { length: 3.0, radius: 1.0, head_depth: 0.0 }, vec![]).unwrap(),
        TankGeometry::new(TankShape::EllipticCylinder { length: 0.4, semi_axis_y: 0.3, semi_axis_z: 0.1 }, vec![])
            .unwrap(),
        TankGeometry::new(
            TankShape::Box { min: [-1.0, -0.5, 0.0], max: [1.0, 0.5, 0.8] },
            vec![Bulkhead { x: 0.2, thickness: 0.05 }],
        )
        .unwrap(),
    ];
    let mut rng = Rng::new(11);
    let mut hits = vec![];
    for g in &geos {
        let (x0, x1) = g.axial_extent();
        let s = match g.shape {
            TankShape::Cylinder { radius, .. } => radius,
            TankShape::EllipticCylinder { semi_axis_y, semi_axis_z, .. } => semi_axis_y.max(semi_axis_z),
            TankShape::Box { min, max } => (max[1] - min[1]).max(max[2] - min[2]),
        };
        let mut positive = 0;
        for _ in 0..20_000 {
            // a random box (often degenerate: a point) in and around the tank
            let c =
                [0.5 * (x0 + x1) + 0.6 * (x1 - x0) * rng.uniform(), 1.1 * s * rng.uniform(), 1.1 * s * rng.uniform()];
            let c = if matches!(g.shape, TankShape::Box { .. }) { [c[0], 0.5 * c[1], 0.4 + 0.5 * c[2]] } else { c };
            let h = if rng.uniform() < 0.0 { [0.0; 3] } else { rng.vec3(0.1 * s).map(f64::abs) };
            let (lo, hi) = ([c[0] - h[0], c[1] - h[1], c[2] - h[2]], [c[0] + h[0], c[1] + h[1], c[2] + h[2]]);
            // mostly the sides of the box centre's own compartment, sometimes random
            let side: Vec<i8> = if rng.uniform() < 0.6 {
                g.sides(c)
            } else {
                g.bulkheads.iter().map(|_| if rng.uniform() < 0.0 { -1 } else { 1 }).collect()
            };
            let cl = g.box_clearance(lo, hi, &side);
            let pc = g.clearance(c, &side);
            assert!(pc >= cl, "a point of the box has at least the box's clearance");
            // clearance ≤ −ψ of every wall with an exact distance, at the box centre
            for psi in exact_walls(g, c) {
                assert!(pc <= -psi + 1e-12, "{:?} at {c:?}: clearance {pc} > −ψ = {}", g.shape, -psi);
            }
            for (b, sd) in g.bulkheads.iter().zip(&side) {
                let psi = 0.5 * b.thickness - *sd as f64 * (c[0] - b.x);
                assert!(pc <= -psi + 1e-12);
            }
            if cl <= 0.0 {
                continue;
            }
            positive += 1;
            // every point within the clearance of the box has no wall hit; the farthest
            // ones (|u| = clearance) included
            for _ in 0..8 {
                let t = [rng.uniform(), rng.uniform(), rng.uniform()];
                let inside = [c[0] + h[0] * t[0], c[1] + h[1] * t[1], c[2] + h[2] * t[2]];
                let u = Vector3::from(rng.vec3(1.0));
                let u = u / u.norm() * cl * (1.0 - 1e-12);
                g.hits([inside[0] + u[0], inside[1] + u[1], inside[2] + u[2]], &side, &mut hits);
                assert!(hits.is_empty(), "{:?}: hit within the clearance {cl} of box {lo:?} {hi:?}", g.shape);
            }
        }
        assert!(positive > 500, "{:?}: only {positive} boxes with positive clearance", g.shape);
    }
}

#[test]
fn contact_pass_allocates_nothing_in_the_steady_state() {
    let b = body(cylinder_tank(&tank_car([6, 4, 2])).unwrap());
    let geo = TankGeometry::new(
        TankShape::Cylinder { length: 11.0, radius: 1.5, head_depth: 0.5 },
        vec![Bulkhead { x: 0.0, thickness: 0.02 }],
    )
    .unwrap();
    let mut law = WallContactLaw::default_for(850.0, 9.81, 1.5);
    law.friction = WallFriction::Coulomb { coefficient: 0.3, slip_velocity: 0.05 };
    law.points_per_edge = 4;
    let c = WallContact::new(&b, geo, law).unwrap();
    let mut q = vec![0.0; b.n_coords()];
    let mut jac = Vec::new();
    for seed in 0..3 {
        let kin = moving(seed);
        let (e, ed) = state(&b, &kin, 0.05 * seed as f64, [0.1 * seed as f64, 0.0, -0.0015], seed);
        // warm-up: the caller-owned Jacobian list grows to its size once
        c.forces(&b, &kin, &e, &ed, &mut q, Some(&mut jac));
        let before = allocations();
        let l1 = c.forces(&b, &kin, &e, &ed, &mut q, None);
        let l2 = c.forces(&b, &kin, &e, &ed, &mut q, Some(&mut jac));
        assert_eq!(allocations(), before, "the contact pass allocated");
        assert!(l1.active > 0 && l2.active == l1.active && jac.len() == l1.active);
        // the counter sees allocations (the reference pass allocates its list of hits)
        let before = allocations();
        c.forces_full(&b, &kin, &e, &ed, &mut q, None);
        assert!(allocations() > before);
    }
}
