//! `cargo bench -p rail-mbs --bench slosh`: speed of a coupled slosh run.
//!
//! Half-full tank car (12 m shell, R 1.5 m, 0.5 m heads), light crude, braking pulse
//! −0.1 g from t = 0.2 s, inertial formulation, adaptive HHT (h ≤ 0.01 s). Reports simulated
//! seconds per wall second, Newton iterations per step, Jacobian evaluations, and the share
//! of wall time in assembly (forces + Jacobians) vs LU factorization vs solves.
//! Pass `quick` to run only the 48-element mesh.

use std::time::Instant;

use ancf_core::FluidBody;
use ancf_core::constants::GRAVITY as G;
use ancf_core::constitutive::Rheology;
use ancf_core::contact::{WallContact, WallContactLaw};
use ancf_core::element::QuadratureOptions;
use ancf_core::mesh::{CylinderTankSpec, cylinder_tank};
use ancf_core::tank::TankGeometry;
use rail_mbs::defaults::{liquid, slosh_params};
use rail_mbs::slosh::{PiecewiseAcceleration, PrescribedMotion, SloshFrame, SloshRun, SloshSystem};

fn main() {
    let quick = std::env::args().any(|a| a == "quick");
    let threads = std::env::var("RAYON_NUM_THREADS").unwrap_or_else(|_| "default".into());
    println!("slosh run: half-full tank car, light crude, braking -0.1 g, rayon threads: {threads}");
    println!(
        "{:>9} {:>7} {:>9} {:>9} {:>12} {:>10} {:>8} {:>8} {:>10} {:>8}",
        "elements", "coords", "sim s", "wall s", "sim s/wall s", "steps", "it/step", "jac ev", "assembly", "LU"
    );
    let cases: &[([usize; 3], f64)] = if quick { &[([6, 4, 2], 1.0)] } else { &[([6, 4, 2], 2.0), ([25, 5, 4], 0.3)] };
    for &(n, t_end) in cases {
        let spec = CylinderTankSpec::tank_car(n);
        let mesh = cylinder_tank(&spec).unwrap();
        let fluid = liquid(850.0, Rheology::Newtonian { viscosity: 0.005 }, 1.5, 1.5 / n[2] as f64).unwrap();
        let body = FluidBody::new(mesh, fluid, QuadratureOptions::default()).unwrap();
        let geo = TankGeometry::new(spec.shape(), vec![]).unwrap();
        let contact = WallContact::new(&body, geo, WallContactLaw::default_for(850.0, G, 1.5)).unwrap();
        let mut motion = PrescribedMotion::at_rest([0.0; 3]);
        motion.translation[0] = PiecewiseAcceleration::pulse(-0.1 * G, 0.2, 100.0, 0.2).unwrap();
        let (nel, nc) = (body.mesh.n_elements(), body.n_coords());
        let sys = SloshSystem::new(body, contact, motion, [0.0, 0.0, -G], SloshFrame::Inertial).unwrap();
        let t0 = Instant::now();
        let mut run = SloshRun::new(sys, 0.0, slosh_params()).unwrap();
        let res = run.run_to(t_end, 0.01);
        let wall = t0.elapsed().as_secs_f64();
        let s = run.stats();
        let sim = run.stepper.t();
        if let Err(e) = res {
            println!("  ({nel} elements stopped early: {e})");
        }
        println!(
            "{:>9} {:>7} {:>9.2} {:>9.1} {:>12.4} {:>10} {:>8.2} {:>8} {:>9.0}% {:>7.0}%",
            nel,
            nc,
            sim,
            wall,
            sim / wall,
            s.steps,
            s.newton_iterations as f64 / s.steps.max(1) as f64,
            s.jacobian_evaluations,
            100.0 * s.time_assembly.as_secs_f64() / s.time_total.as_secs_f64(),
            100.0 * s.time_factorization.as_secs_f64() / s.time_total.as_secs_f64(),
        );
    }
}
