//! Exploratory probe (not a test): hydrostatic settling.
//! args: shape(box|cyl) penalty_points ctd_factor mu h alpha policy(0 every-iter,1 auto)
use ancf_core::FluidBody;
use ancf_core::constitutive::{Fluid, Rheology};
use ancf_core::contact::{WallContact, WallContactLaw};
use ancf_core::element::QuadratureOptions;
use ancf_core::mesh::{CylinderTankSpec, box_mesh, cylinder_tank};
use ancf_core::tank::{TankGeometry, TankShape};
use rail_mbs::integrator::{HhtParams, JacobianPolicy};
use rail_mbs::slosh::{PrescribedMotion, SloshFrame, SloshRun, SloshSystem};

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let f = |i: usize, d: f64| a.get(i).map(|s| s.parse().unwrap()).unwrap_or(d);
    let shape = a.first().cloned().unwrap_or("box".into());
    let np = f(1, 2.0) as usize;
    let ctd_factor = f(2, 0.2);
    let mu = f(3, 0.005);
    let h = f(4, 0.01);
    let alpha = f(5, -0.3);
    let policy = if f(6, 0.0) == 0.0 { JacobianPolicy::EveryIteration } else { JacobianPolicy::Automatic };
    let rho = 850.0;
    let (mesh, geo, depth, hel) = if shape == "box" {
        (
            box_mesh([-0.208, -0.162, 0.0], [0.416, 0.324, 0.132], [4, 4, 2]).unwrap(),
            TankGeometry::new(TankShape::Box { min: [-0.208, -0.162, 0.0], max: [0.208, 0.162, 0.3] }, vec![]).unwrap(),
            0.132,
            0.066,
        )
    } else {
        let spec = CylinderTankSpec::tank_car([6, 4, 2]);
        (cylinder_tank(&spec).unwrap(), TankGeometry::new(spec.shape(), vec![]).unwrap(), 1.5, 0.75)
    };
    let k = 1000.0 * rho * 9.81 * depth;
    let mut fluid = Fluid::new(rho, Rheology::Newtonian { viscosity: mu }, k).unwrap();
    fluid.bulk_damping = ctd_factor * (k * rho).sqrt() * hel;
    let body = FluidBody::new(mesh, fluid, QuadratureOptions { viscous: 3, penalty: np, mass: 4 }).unwrap();
    let contact = WallContact::new(&body, geo, WallContactLaw::default_for(rho, 9.81, depth)).unwrap();
    let m = body.total_mass();
    let v0 = body.reference_volume();
    let sys =
        SloshSystem::new(body, contact, PrescribedMotion::at_rest([0.0; 3]), [0.0, 0.0, -9.81], SloshFrame::Inertial)
            .unwrap();
    let mut run = SloshRun::new(
        sys,
        0.0,
        HhtParams { alpha, abs_tol_acc: 1e-3, max_iterations: 10, jacobian: policy, ..Default::default() },
    )
    .unwrap();
    let t0 = std::time::Instant::now();
    for tend in [0.1, 0.3, 0.6, 1.0, 2.0] {
        if let Err(e) = run.run_to(tend, h) {
            println!("FAILED: {e}");
            break;
        }
        let r = &run.record;
        let i = r.t.len() - 1;
        println!(
            "t={:.2} Fz/mg={:.5} Fx={:.2e} Fy={:.2e} vol_err={:.2e} com_z={:.4} pen={:.2e} it={} KE={:.2e}",
            r.t[i],
            -r.force_global[i][2] / (m * 9.81),
            r.force_global[i][0],
            r.force_global[i][1],
            r.volume[i] / v0 - 1.0,
            r.com_tank[i][2],
            r.max_penetration[i],
            r.newton_iterations[i],
            r.kinetic_energy[i]
        );
    }
    let s = run.stats();
    println!(
        "wall {:.2}s steps {} newton {} fact {} jac {} | asm {:.2}s fact {:.2}s",
        t0.elapsed().as_secs_f64(),
        s.steps,
        s.newton_iterations,
        s.factorizations,
        s.jacobian_evaluations,
        s.time_assembly.as_secs_f64(),
        s.time_factorization.as_secs_f64()
    );
}
