//! The coupler force and both tanks' liquid loads of one two-car ECP braking run, written every
//! 20 ms to a CSV (docs/validation.md, "coupler-force-convergence"):
//! `cargo run --release -p railslosh-cases --example coupler_history -- OIL NX NY NZ T_END STEP REAR_BRAKE_FACTOR OUT.csv [bulkheads]`,
//! e.g. `-- light 6 4 2 10.5 2e-3 1.0 ecp.csv`. Columns: t (s), coupler (N, tension positive),
//! fx1, fz1, fx2, fz2 (the liquid's load on tank 1 and 2, tank frame, N), cx1, cz1, cx2, cz2
//! (the liquid's centre of mass, tank frame, m), fy1, fy2, cy1, cy2 (the lateral channels, which
//! mirror symmetry keeps at zero in an exact solution). Walls and stabilization as the ECP scenes;
//! `STAB=β` multiplies the recommended shear stabilization by β (0: none) and `HG=η` adds the
//! non-affine-mode control G_h = η ρ g H (docs/validation.md, "The ECP scenes' lateral channels").
use std::io::Write;

use rail_mbs::defaults::Oil;
use rail_mbs::integrator::LinearSolverKind;
use rail_mbs::vehicle::{BrakeScope, TrainScenario};
use railslosh_cases::vehicle::studies::{BrakingCase, run_braking_adjusted};
use railslosh_cases::{SCENE_WALL_ADHESION, SCENE_WALL_DAMPING};

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    if a.len() < 8 {
        eprintln!("usage: coupler_history OIL NX NY NZ T_END STEP REAR_BRAKE_FACTOR OUT.csv [bulkheads]");
        std::process::exit(2);
    }
    let number = |i: usize| a[i].parse::<f64>().unwrap_or_else(|_| panic!("argument {}: a number", i + 1));
    let case = BrakingCase {
        oil: Oil::from_name(&a[0]).expect("OIL: light, medium, heavy or water"),
        cars: 2,
        scope: BrakeScope::AllCars,
        bulkheads: a.get(8).map(String::as_str) == Some("bulkheads"),
        counts: [number(1) as usize, number(2) as usize, number(3) as usize],
        t_end: number(4),
        rear_brake_factor: number(6),
        wall_damping_ratio: SCENE_WALL_DAMPING,
        wall_adhesion: SCENE_WALL_ADHESION,
        linear_solver: LinearSolverKind::Condensed,
        shear_stabilization: true,
    };
    let beta: f64 = std::env::var("STAB").map_or(1.0, |s| s.parse().expect("STAB: a number"));
    let stabilize = |cg: &mut rail_mbs::vehicle::fluid::FluidCargo| {
        // the value build_fluid_train chooses (half full: the depth is the tank radius), times β
        let depth = rail_mbs::vehicle::TankCarParams::standard().expect("standard car").tank_radius;
        let g_s =
            rail_mbs::defaults::default_shear_stabilization(cg.fluid.density, depth / cg.counts[2] as f64, Some(depth));
        cg.fluid.shear_stabilization = beta * g_s;
        cg.shear_stabilization = beta > 0.0; // β = 0: none (not the default)
        let hg: f64 = std::env::var("HG").map_or(0.0, |s| s.parse().expect("HG: a number"));
        cg.fluid.hourglass_stabilization = hg * cg.fluid.density * rail_mbs::track::GRAVITY * depth;
    };
    let r = run_braking_adjusted(&case, number(5), TrainScenario::default_hht().rel_tol, stabilize).expect("run");
    let s = &r.train;
    let mut f = std::fs::File::create(&a[7]).expect("OUT.csv");
    writeln!(f, "t,coupler,fx1,fz1,fx2,fz2,cx1,cz1,cx2,cz2,fy1,fy2,cy1,cy2").unwrap();
    for i in 0..s.t.len() {
        let (l, c) = (&r.fluid_force_tank[i], &r.oil_com_tank[i]);
        writeln!(
            f,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            s.t[i],
            s.coupler_force[i][0],
            l[0][0],
            l[0][2],
            l[1][0],
            l[1][2],
            c[0][0],
            c[0][2],
            c[1][0],
            c[1][2],
            l[0][1],
            l[1][1],
            c[0][1],
            c[1][1]
        )
        .unwrap();
    }
    println!("{} steps, {} Newton iterations, {:.1} s wall", s.steps, s.newton_iterations, s.wall_time);
}
