//! `cargo bench -p ancf-core --bench contact`: cost of one wall-contact pass
//! ([`WallContact::forces`]) with the conservative culling against the full check of every
//! point (`forces_full`, the previous implementation), side by side in the same run.
//!
//! Fluid: the half-full tank car of the rail-mbs fluid studies (`vehicle::fluid`:
//! cylinder 11 m between the head tangent lines, radius 1.5 m, heads 0.5 m deep, fill 0.5,
//! `cylinder_tank`, 4×4 contact points per face, the default wall law for depth 1.5 m),
//! placed in the global frame on the track (tank origin at x = 150 m, axis 2.35 m above the
//! rail, pitched 0.01 rad), sunk 1.5 mm into the bottom (the rest penetration k_p δ = ρ g H):
//! - "rest": the reference shape;
//! - "tilted": the free surface tilted lengthwise by 0.1 rad (a smooth shear of the
//!   mesh z ↦ z + 0.1 x (z + R)/(z_s + R), gradients mapped by its Jacobian), as in braking.
//!
//! Times: median over repetitions (alternating the passes), residual only (`None`) and
//! with point Jacobians; "no-cull" is the new pass with the cull switched off
//! (`forces_counted(.., Cull::Off)`: every point checked), which separates the gain of the
//! cull from that of the leaner per-point work. `quick` as argument for fewer repetitions.

use std::hint::black_box;
use std::time::Instant;

use ancf_core::FluidBody;
use ancf_core::body::rigid_motion;
use ancf_core::constitutive::{Fluid, M3, Rheology};
use ancf_core::contact::{Cull, TankKinematics, WallContact, WallContactLaw};
use ancf_core::element::QuadratureOptions;
use ancf_core::mesh::{CylinderTankSpec, cylinder_tank};
use ancf_core::tank::{TankGeometry, TankShape};
use nalgebra::{Rotation3, Vector3};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

/// Applies the map `phi` to the tank-frame coordinates: positions x ↦ φ(x), gradients
/// g ↦ ∇φ(x) g (central differences of φ).
fn deform(e: &[f64], phi: impl Fn([f64; 3]) -> [f64; 3]) -> Vec<f64> {
    let mut out = e.to_vec();
    for (node, c) in e.chunks_exact(12).zip(out.chunks_exact_mut(12)) {
        let x = [node[0], node[1], node[2]];
        c[..3].copy_from_slice(&phi(x));
        let h = 1e-6;
        let mut f = M3::zeros();
        for j in 0..3 {
            let (mut xp, mut xm) = (x, x);
            xp[j] += h;
            xm[j] -= h;
            let (a, b) = (phi(xp), phi(xm));
            for i in 0..3 {
                f[(i, j)] = (a[i] - b[i]) / (2.0 * h);
            }
        }
        for s in 1..4 {
            let g = f * Vector3::new(node[3 * s], node[3 * s + 1], node[3 * s + 2]);
            c[3 * s..3 * s + 3].copy_from_slice(g.as_slice());
        }
    }
    out
}

fn main() {
    let quick = std::env::args().any(|a| a == "quick");
    let reps = if quick { 11 } else { 101 };
    let (length, radius, head) = (11.0, 1.5, 0.5);
    let fluid = Fluid::new(850.0, Rheology::Newtonian { viscosity: 0.005 }, 1.25e7).unwrap();
    let geo = TankGeometry::new(TankShape::Cylinder { length, radius, head_depth: head }, vec![]).unwrap();
    let mut law = WallContactLaw::default_for(850.0, 9.81, 1.5);
    law.points_per_edge = 4;
    println!("wall contact pass, half-full tank car (L = 11 m, R = 1.5 m, heads 0.5 m), 4x4 points/face");
    println!("median of {reps} runs each, culled (forces) vs full check (forces_full), same run");
    println!(
        "{:<10} {:<7} {:>7} {:>8} {:>7} {:>12} {:>12} {:>8} {:>12} {:>14} {:>14} {:>8}",
        "mesh",
        "state",
        "points",
        "checked",
        "active",
        "full us",
        "culled us",
        "speedup",
        "no-cull us",
        "full+jac us",
        "culled+jac us",
        "speedup"
    );
    for counts in [[6, 4, 2], [12, 6, 4]] {
        let spec = CylinderTankSpec {
            length,
            radius,
            head_depth: head,
            fill: 0.5,
            n_length: counts[0],
            n_width: counts[1],
            n_height: counts[2],
            grading: 1.0,
        };
        let body = FluidBody::new(cylinder_tank(&spec).unwrap(), fluid, QuadratureOptions::default()).unwrap();
        let contact = WallContact::new(&body, geo.clone(), law).unwrap();
        let e0 = body.reference_coordinates();
        let zs = spec.liquid_depth() - radius;
        let rot = *Rotation3::from_euler_angles(0.0, 0.01, 0.0).matrix();
        let kin = TankKinematics {
            position: [150.0, 0.0, 2.35],
            rotation: rot,
            velocity: [11.0, 0.0, 0.0],
            angular_velocity: [0.0, 0.002, 0.0],
        };
        for (name, tilt) in [("rest", 0.0), ("tilted", 0.1)] {
            let local = deform(&e0, |[x, y, z]| [x, y, z - 0.0015 + tilt * x * (z + radius) / (zs + radius)]);
            let (e, edot) = rigid_motion(&local, &rot, kin.position, kin.angular_velocity, kin.velocity);
            let n = body.n_coords();
            let mut q = vec![0.0; n];
            let mut jac = Vec::new();
            let (load, checked) = contact.forces_counted(&body, &kin, &e, &edot, &mut q, None, Cull::On);
            let mut ts = [vec![], vec![], vec![], vec![], vec![]];
            for _ in 0..reps {
                for (m, t) in ts.iter_mut().enumerate() {
                    q.fill(0.0);
                    let j = if m == 2 || m == 3 { Some(&mut jac) } else { None };
                    let start = Instant::now();
                    let l = match m {
                        0 | 2 => contact.forces_full(&body, &kin, black_box(&e), black_box(&edot), &mut q, j),
                        1 | 3 => contact.forces(&body, &kin, black_box(&e), black_box(&edot), &mut q, j),
                        _ => {
                            contact.forces_counted(&body, &kin, black_box(&e), black_box(&edot), &mut q, j, Cull::Off).0
                        }
                    };
                    t.push(start.elapsed().as_secs_f64() * 1e6);
                    black_box(l);
                }
            }
            let [tf, tc, tfj, tcj, tn] = ts.map(median);
            println!(
                "{:<10} {:<7} {:>7} {:>8} {:>7} {:>12.1} {:>12.1} {:>8.2} {:>12.1} {:>14.1} {:>14.1} {:>8.2}",
                format!("{}x{}x{}", counts[0], counts[1], counts[2]),
                name,
                contact.points.len(),
                checked,
                load.active,
                tf,
                tc,
                tf / tc,
                tn,
                tfj,
                tcj,
                tfj / tcj
            );
        }
    }
}
