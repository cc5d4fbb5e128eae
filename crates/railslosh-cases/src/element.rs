//! Validation cases of the element, run by `railslosh validate` and by the test suite.
//!
//! Each case returns [`Record`]s: one measured quantity against its reference with a
//! tolerance. The cases are written once here and reused by the Rust tests, the Python
//! tests and the CLI, so that what CI checks is exactly what users can run.

// Index loops mirror the tensor index notation of the formulas (as in ancf-core).
#![allow(clippy::needless_range_loop)]

use nalgebra::{Rotation3, Vector3};

use ancf_core::FluidBody;
use ancf_core::body::rigid_motion;
use ancf_core::constitutive::{Fluid, M3, Rheology};
use ancf_core::element::{ElementRef, QuadratureOptions, ShapeTables, box_element};
use ancf_core::error::Result;
use ancf_core::mesh::{CylinderTankSpec, EllipticCylinderSpec, box_mesh, cylinder_tank, elliptic_cylinder};
use ancf_core::rng::Rng;
use ancf_core::shape::{N_COORDS, N_SHAPE};
use ancf_core::testing::{jacobian_fd_error, sample_fluids, sample_label};

use crate::Record;

/// Names of the cases this module provides.
pub const CASES: [&str; 3] = ["element-mass", "element-jacobians", "rigid-motion-invariance"];

/// Run a case by name. `quick` uses fewer random samples.
pub fn run_case(name: &str, quick: bool) -> Result<Vec<Record>> {
    match name {
        "element-mass" => element_mass(),
        "element-jacobians" => element_jacobians(if quick { 2 } else { 6 }),
        "rigid-motion-invariance" => rigid_motion_invariance(if quick { 3 } else { 10 }),
        other => Err(ancf_core::error::invalid("case", other, &format!("one of {CASES:?}"))),
    }
}

fn element_mass() -> Result<Vec<Record>> {
    let c = "element-mass";
    let mut out = Vec::new();
    let tables = ShapeTables::new(QuadratureOptions::default())?;
    let rho = 7850.0;
    let el = ElementRef::new(0, &box_element([0.0; 3], [1.0; 3]), [1.0; 3], &tables)?;
    let m = el.mass_compact(rho, &tables);
    out.push(Record::abs(
        c,
        "M_compact(0,0), 1 m cube, rho=7850 (Chrono 3843 test value)",
        m[0],
        394.784391534388,
        1e-9,
    ));
    let pos_sum: f64 = (0..8).flat_map(|k| (0..8).map(move |l| (4 * k, 4 * l))).map(|(a, b)| m[a * N_SHAPE + b]).sum();
    out.push(Record::abs(c, "sum of position-position block = rho V (kg), 1 m cube", pos_sum, rho, 1e-9));
    let asym =
        (0..N_SHAPE * N_SHAPE).map(|k| (m[k] - m[(k % N_SHAPE) * N_SHAPE + k / N_SHAPE]).abs()).fold(0.0, f64::max);
    out.push(Record::at_most(c, "max |M - M^T| of the compact mass", asym, 1e-12));
    let mmat = faer::Mat::from_fn(N_SHAPE, N_SHAPE, |i, j| m[i * N_SHAPE + j]);
    let eig = mmat
        .self_adjoint_eigenvalues(faer::Side::Lower)
        .map_err(|_| ancf_core::error::AncfError::NonFinite { what: "mass eigenvalues".into(), element: 0 })?;
    let lmin = eig.iter().copied().fold(f64::INFINITY, f64::min);
    out.push(Record {
        case: c.into(),
        quantity: "smallest eigenvalue of compact mass (must be > 0: SPD)".into(),
        measured: lmin,
        reference: 0.0,
        tolerance: 0.0,
        passed: lmin > 0.0,
    });
    let g = ancf_core::constants::GRAVITY;
    let gs = el.gravity_scale(rho, &tables);
    out.push(Record::abs(c, "gravity force, position entry (N): -rho V g / 8", -gs[0] * g, -rho * g / 8.0, 1e-8));
    out.push(Record::abs(
        c,
        "gravity force, z-slope entry at node A (N): -rho V g L / 48",
        -gs[3] * g,
        -rho * g / 48.0,
        1e-8,
    ));

    // Meshes: total mass = rho V.
    let fluid = Fluid::new(850.0, Rheology::Newtonian { viscosity: 0.005 }, 1e6)?;
    let bx =
        FluidBody::new(box_mesh([0.0; 3], [0.416, 0.324, 0.132], [3, 2, 2])?, fluid, QuadratureOptions::default())?;
    out.push(Record::abs(
        c,
        "box 0.416x0.324x0.132 m, 3x2x2: relative error of total mass vs rho V",
        bx.total_mass() / (850.0 * bx.mesh.exact_volume) - 1.0,
        0.0,
        1e-12,
    ));
    for (n, tol) in [([8, 4, 2], 6e-3), ([16, 8, 4], 2.5e-3)] {
        let spec = CylinderTankSpec::tank_car(n);
        let body = FluidBody::new(cylinder_tank(&spec)?, fluid, QuadratureOptions::default())?;
        out.push(Record::abs(
            c,
            format!(
                "half-full tank car (12 m with its heads, R 1.5 m), {}x{}x{}: relative error of total mass vs rho V_exact",
                n[0], n[1], n[2]
            ),
            body.total_mass() / (850.0 * body.mesh.exact_volume) - 1.0,
            0.0,
            tol,
        ));
        // the 4^3 mass rule integrates the curved geometry: compare with a 7^3 rule
        let hi = FluidBody::new(body.mesh.clone(), fluid, QuadratureOptions { mass: 7, ..Default::default() })?;
        out.push(Record::abs(
            c,
            format!("tank {}x{}x{}: relative difference of total mass, 4^3 vs 7^3 mass rule", n[0], n[1], n[2]),
            body.total_mass() / hi.total_mass() - 1.0,
            0.0,
            1e-6,
        ));
    }
    let sw =
        FluidBody::new(elliptic_cylinder(&EllipticCylinderSpec::swri(4, 6, 3))?, fluid, QuadratureOptions::default())?;
    out.push(Record::abs(
        c,
        "SwRI elliptical tank half full, 4x6x3: relative error of total mass vs rho V_exact",
        sw.total_mass() / (850.0 * sw.mesh.exact_volume) - 1.0,
        0.0,
        5e-3,
    ));
    Ok(out)
}

/// A randomly deformed state of a unit element: e = e0 + perturbation, ė random.
fn random_state(rng: &mut Rng, e0: &[[f64; 3]; N_SHAPE], amp: f64, vamp: f64) -> (Vec<f64>, Vec<f64>) {
    let mut e = vec![0.0; N_COORDS];
    let mut v = vec![0.0; N_COORDS];
    for a in 0..N_SHAPE {
        for i in 0..3 {
            e[3 * a + i] = e0[a][i] + amp * rng.uniform();
            v[3 * a + i] = vamp * rng.uniform();
        }
    }
    (e, v)
}

fn element_jacobians(samples: usize) -> Result<Vec<Record>> {
    let c = "element-jacobians";
    let mut out = Vec::new();
    let tables = ShapeTables::new(QuadratureOptions { viscous: 3, penalty: 2, mass: 4 })?;
    let l = [0.5, 0.3, 0.2];
    let e0 = box_element([0.1, -0.2, 0.05], l);
    let el = ElementRef::new(0, &e0, l, &tables)?;
    let mut rng = Rng::new(2024);
    for fluid in sample_fluids() {
        let (mut ek, mut ec) = (0.0f64, 0.0f64);
        for _ in 0..samples {
            let (e, v) = random_state(&mut rng, &e0, 0.03, 0.5);
            let mut fl = fluid;
            if let Rheology::Oldroyd { viscosity, elastic_modulus, .. } = fluid.rheology {
                // put the first viscous point inside the elastic/viscous blend band
                let ehat = ancf_core::element::scaled(&ancf_core::element::to_compact(&e), &el.scale);
                let mut fhat = M3::zeros();
                for a in 0..N_SHAPE {
                    for i in 0..3 {
                        for j in 0..3 {
                            fhat[(i, j)] += ehat[a][i] * tables.viscous.dn[0][a][j];
                        }
                    }
                }
                let f = fhat * el.viscous[0].jinv;
                let g = elastic_modulus.unwrap_or(0.0);
                let se = 2.0 * g * ancf_core::constitutive::dev(&(0.5 * (f.transpose() * f - M3::identity())));
                let ne = (0.5 * se.component_mul(&se).sum()).sqrt();
                fl.rheology = Rheology::Oldroyd { viscosity, yield_stress: ne * 1.01, elastic_modulus };
            }
            let (a, b) = jacobian_fd_error(&fl, &el, &tables, &e, &v)?;
            ek = ek.max(a);
            ec = ec.max(b);
        }
        let name = sample_label(&fluid);
        out.push(Record::at_most(
            c,
            format!("{name}: max relative FD error of K = df/de ({samples} random states)"),
            ek,
            1e-6,
        ));
        out.push(Record::at_most(
            c,
            format!("{name}: max relative FD error of C = df/dedot ({samples} random states)"),
            ec,
            1e-6,
        ));
    }
    Ok(out)
}

fn rigid_motion_invariance(samples: usize) -> Result<Vec<Record>> {
    let c = "rigid-motion-invariance";
    let mut out = Vec::new();
    let mesh = box_mesh([0.0; 3], [0.6, 0.4, 0.3], [2, 2, 1])?;
    let e0 = mesh.reference_coordinates();
    let mut rng = Rng::new(99);
    for fluid in sample_fluids() {
        let body = FluidBody::new(mesh.clone(), fluid, QuadratureOptions::default())?;
        let n = body.n_coords();
        let mut f = vec![0.0; n];
        let (mut rigid, mut objectivity) = (0.0f64, 0.0f64);
        for _ in 0..samples {
            let axis = Vector3::from(rng.vec3(1.0)).normalize();
            let rot: M3 =
                *Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), 2.0 * rng.uniform()).matrix();
            let (e, v) = rigid_motion(&e0, &rot, rng.vec3(5.0), rng.vec3(2.0), rng.vec3(3.0));
            // force scale: same speed, deforming velocity field
            let vdef: Vec<f64> = v.iter().map(|x| x + 0.5 * rng.uniform()).collect();
            let mut fref = vec![0.0; n];
            body.internal_forces(&e, &vdef, &mut fref)?;
            let scale = fref.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            body.internal_forces(&e, &v, &mut f)?;
            rigid = rigid.max(f.iter().fold(0.0f64, |m, x| m.max(x.abs())) / scale);
            // objectivity: rotate a deformed state; forces rotate with it
            let ed: Vec<f64> = e0.iter().map(|x| x + 0.01 * rng.uniform()).collect();
            let vd: Vec<f64> = e0.iter().map(|_| 0.3 * rng.uniform()).collect();
            let (er, _) = rigid_motion(&ed, &rot, [0.0; 3], [0.0; 3], [0.0; 3]);
            let (vr, _) = rigid_motion(&vd, &rot, [0.0; 3], [0.0; 3], [0.0; 3]);
            let mut f1 = vec![0.0; n];
            let mut f2 = vec![0.0; n];
            body.internal_forces(&ed, &vd, &mut f1)?;
            body.internal_forces(&er, &vr, &mut f2)?;
            let (f1r, _) = rigid_motion(&f1, &rot, [0.0; 3], [0.0; 3], [0.0; 3]);
            let s = f1.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            objectivity = objectivity.max(f1r.iter().zip(&f2).fold(0.0f64, |m, (a, b)| m.max((a - b).abs())) / s);
        }
        let name = sample_label(&fluid);
        out.push(Record::at_most(
            c,
            format!("{name}: max |f| under rigid motion, relative to a deforming state"),
            rigid,
            1e-10,
        ));
        out.push(Record::at_most(
            c,
            format!("{name}: objectivity, max |f(Qe,Qv) - Q f(e,v)| relative"),
            objectivity,
            1e-10,
        ));
    }
    Ok(out)
}
