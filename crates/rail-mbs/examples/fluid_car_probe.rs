//! Probe: cars with ANCF fluid braking on tangent track.
//! `cargo run --release -p rail-mbs --example fluid_car_probe -- [cars] [t_end] [nx ny nz] [oil] [scope]`
use std::sync::Arc;

use ancf_core::constitutive::{Fluid, Rheology};
use ancf_core::element::QuadratureOptions;
use rail_mbs::mbs::Table;
use rail_mbs::track::{Track, TrackPoint};
use rail_mbs::vehicle::{BrakeScope, FluidCargo, TankCarParams, TrainScenario, run_fluid_train};

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let cars: usize = a.first().map_or(1, |s| s.parse().unwrap());
    let t_end: f64 = a.get(1).map_or(2.0, |s| s.parse().unwrap());
    let n: [usize; 3] = [
        a.get(2).map_or(4, |s| s.parse().unwrap()),
        a.get(3).map_or(4, |s| s.parse().unwrap()),
        a.get(4).map_or(2, |s| s.parse().unwrap()),
    ];
    let oil = a.get(5).map_or("light", |s| s.as_str());
    let scope = if a.get(6).map(|s| s.as_str()) == Some("front") { BrakeScope::FrontCar } else { BrakeScope::AllCars };
    let (rho, mu, tau) = match oil {
        "light" => (850.0, 0.005, 0.0),
        "medium" => (900.0, 10.0, 30.0),
        "heavy" => (1000.0, 100.0, 100.0),
        _ => (998.0, 1e-3, 0.0),
    };
    let rheology = if tau > 0.0 {
        Rheology::Oldroyd { viscosity: mu, yield_stress: tau, elastic_modulus: None }
    } else {
        Rheology::Newtonian { viscosity: mu }
    };
    let g = 9.80665;
    let depth = 1.5;
    let k = 1000.0 * rho * g * depth;
    let mut fluid = Fluid::new(rho, rheology, k).unwrap();
    fluid.bulk_damping = 0.2 * (k * rho).sqrt() * (1.5 / n[2] as f64);
    let mut cargo = FluidCargo::new(fluid, n, 0.5, vec![]);
    if std::env::var("DEFAULT_DISC").is_ok() {
        cargo.quadrature = QuadratureOptions::default();
        cargo.wall_stiffness_factor = 1.0;
        cargo.contact_points_per_edge = 3;
    }
    let track = Arc::new(
        Track::new(vec![
            TrackPoint::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
            TrackPoint::new(3000.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        ])
        .unwrap(),
    );
    let v0 = 40.0 / 3.6;
    let mut sc = TrainScenario::single(TankCarParams::standard().unwrap(), track, 200.0, v0, t_end);
    sc.cars = cars;
    sc.record_every = 0.1;
    sc.step = 2e-3;
    let tq = 7000.0;
    let brake = Table::new("brake", vec![0.0, 0.5, 1.0], vec![0.0, 0.0, tq]).unwrap();
    sc.brake = Some((brake, scope));
    if let Ok(r) = std::env::var("REFRESH") {
        sc.hht.refresh_rate = r.parse().unwrap();
    }
    if let Ok(r) = std::env::var("STEP") {
        sc.step = r.parse().unwrap();
    }
    if let Ok(r) = std::env::var("RELTOL") {
        sc.hht.rel_tol = r.parse().unwrap();
    }
    let out = run_fluid_train(&sc, &cargo).unwrap();
    let rec = match out {
        Ok(r) => r,
        Err(f) => {
            println!("FAILED: {}", f.error);
            f.record
        }
    };
    println!("fluid mass {:.0} kg, {} elements, dof {}", rec.fluid_mass, rec.elements, rec.train.dof);
    for (i, t) in rec.train.t.iter().enumerate() {
        let c = &rec.oil_com_tank[i];
        let q = &rec.train.wheel_vertical[i];
        println!(
            "t {t:.2} v {:.3} com_x {:+.4} com_z {:+.4} Ffx {:+.0} Q1 {:.0}/{:.0} Q4 {:.0}/{:.0} cpl {:?} dV {:+.2e}",
            rec.train.tank_speed[i][0],
            c[0][0],
            c[0][2],
            rec.fluid_force_tank[i][0][0],
            q[0][0],
            q[0][1],
            q[3][0],
            q[3][1],
            rec.train.coupler_force[i].iter().map(|x| (x / 1e3).round()).collect::<Vec<_>>(),
            rec.volume_error[i][0]
        );
    }
    let s = &rec.train;
    println!(
        "wall {:.1} s, steps {}, rejected {}, newton {}, jac {}",
        s.wall_time, s.steps, s.rejected_steps, s.newton_iterations, s.jacobian_evaluations
    );
}
