//! Exploratory probe (not a test): time response of a half-full cylinder slice (R = 1.5 m, water)
//! to a lateral pulse; writes t, com_y, com_z, F_y, KE, max penetration to a CSV file.
//! `cargo run --release -p rail-mbs --example slosh_transverse -- [key=value ...]`, keys: nx ny nz
//! L amp (g) dur (s) t (end) h out (csv) mu np (penalty rule) ppe (contact points per edge)
//! kc (contact stiffness factor; the damping scales as kc^cexp, default 1.5) easy maxit.
//! Defaults are the default discretization on 1x8x4; `amp=0` leaves the tank at rest.
use ancf_core::FluidBody;
use ancf_core::constants::GRAVITY as G;
use ancf_core::constitutive::Rheology;
use ancf_core::contact::{WallContact, WallContactLaw};
use ancf_core::element::QuadratureOptions;
use ancf_core::mesh::{CylinderTankSpec, cylinder_tank};
use ancf_core::tank::{TankGeometry, TankShape};
use rail_mbs::defaults::{liquid, slosh_params};
use rail_mbs::slosh::{PiecewiseAcceleration, PrescribedMotion, SloshFrame, SloshRun, SloshSystem};
use std::io::Write;

fn main() {
    // key=value arguments
    let args: Vec<(String, String)> = std::env::args()
        .skip(1)
        .filter_map(|s| s.split_once('=').map(|(k, v)| (k.to_string(), v.to_string())))
        .collect();
    let f = |k: &str, d: f64| args.iter().find(|(a, _)| a == k).map(|(_, v)| v.parse().unwrap()).unwrap_or(d);
    let (nx, ny, nz) = (f("nx", 1.0) as usize, f("ny", 8.0) as usize, f("nz", 4.0) as usize);
    let amp = f("amp", 0.05);
    let dur = f("dur", 0.4);
    let t_end = f("t", 14.0);
    let h = f("h", 0.02);
    let out =
        args.iter().find(|(a, _)| a == "out").map(|(_, v)| v.clone()).unwrap_or("/tmp/slosh_transverse.csv".into());
    let mu = f("mu", 1e-3);
    let np = f("np", 3.0) as usize;
    let ppe = f("ppe", 3.0) as usize;
    let kc = f("kc", 1.0);
    let r = 1.5;
    let l = f("L", 1.0);
    let spec = CylinderTankSpec {
        length: l,
        radius: r,
        head_depth: 0.0,
        fill: 0.5,
        n_length: nx,
        n_width: ny,
        n_height: nz,
        grading: 1.0,
    };
    let mesh = cylinder_tank(&spec).unwrap();
    let fluid = liquid(998.0, Rheology::Newtonian { viscosity: mu }, r, r / nz as f64).unwrap();
    let geo = TankGeometry::new(TankShape::Cylinder { length: l, radius: r, head_depth: 0.0 }, vec![]).unwrap();
    let body = FluidBody::new(mesh, fluid, QuadratureOptions { viscous: 3, penalty: np, mass: 4 }).unwrap();
    // stiffer walls keep the damping ratio of the default law: c ~ k^1.5
    let mut law = WallContactLaw { points_per_edge: ppe, ..WallContactLaw::default_for(998.0, G, r) };
    law.stiffness *= kc;
    law.damping *= kc.powf(f("cexp", 1.5));
    let contact = WallContact::new(&body, geo, law).unwrap();
    let mut motion = PrescribedMotion::at_rest([0.0; 3]);
    if amp != 0.0 {
        motion.translation[1] = PiecewiseAcceleration::pulse(amp * G, 0.0, dur, 0.05).unwrap();
    }
    let sys = SloshSystem::new(body, contact, motion, [0.0, 0.0, -G], SloshFrame::Inertial).unwrap();
    let t0 = std::time::Instant::now();
    let mut params = slosh_params();
    if let rail_mbs::integrator::StepControl::Adaptive(p) = &mut params.step_control {
        p.easy_iterations = f("easy", p.easy_iterations as f64) as usize;
    }
    params.max_iterations = f("maxit", params.max_iterations as f64) as usize;
    let mut run = SloshRun::new(sys, 0.0, params).unwrap();
    if let Err(e) = run.run_to(t_end, h) {
        println!("FAILED: {e}");
        run.record = e.record;
    }
    let rec = &run.record;
    let mut w = std::io::BufWriter::new(std::fs::File::create(&out).unwrap());
    writeln!(w, "t,com_y,com_z,fy,ke,pen").unwrap();
    for i in 0..rec.t.len() {
        writeln!(
            w,
            "{},{},{},{},{},{}",
            rec.t[i],
            rec.com_tank[i][1],
            rec.com_tank[i][2],
            rec.force_tank[i][1],
            rec.kinetic_energy[i],
            rec.max_penetration[i]
        )
        .unwrap();
    }
    let s = run.stats();
    println!("wall {:.1}s steps {} newton {}", t0.elapsed().as_secs_f64(), s.steps, s.newton_iterations);
}
