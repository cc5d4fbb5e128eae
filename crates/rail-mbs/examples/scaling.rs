//! Cost per step against fluid mesh size (issue 7: "no faster than about n^1.2").
//!
//! `cargo run --release -p rail-mbs --example scaling -- [direct|iterative|explicit] [steps] [n1,n2,...]`
//!
//! Water in a 4 m × 2 m × 1.5 m box tank, 1 m deep, under a 0.3 g lateral pulse, meshed
//! with about n ANCF bricks (4:2:1 cells). After two warm-up steps, `steps` HHT steps of
//! 2 ms are timed one by one; one JSON line per mesh gives the median wall time per
//! step and its split (forces + Jacobians, factorization / preconditioner, solves),
//! Newton and Krylov iterations. Thread count: RAYON_NUM_THREADS.
//!
//! `explicit`: the explicit stepper (velocity Verlet, the mass factored once) instead, at a
//! fixed step of 0.8 × its estimated stable step; the JSON line gives the median wall time per
//! step and the stable step (issue 17: per-step cost against n, and thread scaling).
use std::time::Instant;

use ancf_core::FluidBody;
use ancf_core::constitutive::{Fluid, Rheology};
use ancf_core::contact::{WallContact, WallContactLaw};
use ancf_core::element::QuadratureOptions;
use ancf_core::mesh::box_mesh;
use ancf_core::tank::{TankGeometry, TankShape};
use rail_mbs::integrator::{BlockMass, Explicit, ExplicitParams, Hht, HhtParams, IterativeParams, LinearSolverKind};
use rail_mbs::slosh::{PiecewiseAcceleration, PrescribedMotion, SloshFrame, SloshSystem};

/// Box counts with about `n` elements and 2:1 length:width, 2:1 width:height cells.
fn counts_for(n: usize) -> [usize; 3] {
    match n {
        0..=150 => [6, 4, 4],
        151..=500 => [12, 6, 4],
        501..=1500 => [20, 10, 5],
        1501..=4500 => [30, 20, 5],
        _ => [40, 25, 10],
    }
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Wall time of each of `steps` calls of `step`, timed one by one after two untimed warm-up
/// calls, and the error that stopped them, if any.
fn time_steps(steps: usize, mut step: impl FnMut() -> Result<(), String>) -> (Vec<f64>, Option<String>) {
    let mut per_step = Vec::with_capacity(steps);
    for k in 0..steps + 2 {
        if k == 2 {
            per_step.clear();
        }
        let tic = Instant::now();
        if let Err(e) = step() {
            return (per_step, Some(e));
        }
        per_step.push(tic.elapsed().as_secs_f64());
    }
    (per_step, None)
}

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let iterative = a.first().map(|s| s.as_str()) == Some("iterative");
    let explicit = a.first().map(|s| s.as_str()) == Some("explicit");
    let steps: usize = a.get(1).map_or(10, |s| s.parse().expect("steps"));
    let sizes: Vec<usize> = a
        .get(2)
        .map_or("100,300,1000,3000,10000", |s| s.as_str())
        .split(',')
        .map(|s| s.parse().expect("element count"))
        .collect();
    let threads = rayon::current_num_threads();
    let (rho, depth) = (1000.0, 1.0);
    for &target in &sizes {
        let counts = counts_for(target);
        let t_build = Instant::now();
        let mesh = box_mesh([-2.0, -1.0, 0.0], [4.0, 2.0, depth], counts).expect("mesh");
        let fluid =
            Fluid::new(rho, Rheology::Newtonian { viscosity: 1e-3 }, 1000.0 * rho * 9.81 * depth).expect("fluid");
        let body = FluidBody::new(mesh, fluid, QuadratureOptions::default()).expect("body");
        let geo =
            TankGeometry::new(TankShape::Box { min: [-2.0, -1.0, 0.0], max: [2.0, 1.0, 1.5] }, vec![]).expect("tank");
        let contact = WallContact::new(&body, geo, WallContactLaw::default_for(rho, 9.81, depth)).expect("contact");
        let (n_el, n_coords) = (body.elements.len(), body.n_coords());
        let mut motion = PrescribedMotion::at_rest([0.0; 3]);
        motion.translation[1] = PiecewiseAcceleration::pulse(0.3 * 9.81, 0.0, 0.5, 0.01).expect("pulse");
        let mut sys = SloshSystem::new(body, contact, motion, [0.0, 0.0, -9.81], SloshFrame::Inertial).expect("system");
        if explicit {
            explicit_steps(sys, steps, t_build, threads);
            continue;
        }
        if iterative {
            let env = |k: &str, d: usize| std::env::var(k).ok().and_then(|v| v.parse().ok()).unwrap_or(d);
            let d = IterativeParams::default();
            sys.linear_solver = LinearSolverKind::Iterative(IterativeParams {
                block: env("SCALING_BLOCK", d.block),
                restart: env("SCALING_RESTART", d.restart),
                ..d
            });
        }
        let params = HhtParams { alpha: -0.3, abs_tol_acc: 1e-3, max_iterations: 10, ..Default::default() };
        let (q0, v0) = sys.initial_state(0.0);
        let mut hht = Hht::new(sys, 0.0, q0, v0, params).expect("integrator");
        let build = t_build.elapsed().as_secs_f64();
        let h = 2e-3;
        let s0 = *hht.stats();
        let it0 = hht.linear_iterations();
        let (mut per_step, failed) = time_steps(steps, || hht.step(h).map(|_| ()).map_err(|e| e.to_string()));
        let s = hht.stats();
        let total_steps = (s.steps - s0.steps).max(1) as f64;
        let linear = hht.linear_iterations() - it0;
        let solves = (s.newton_iterations - s0.newton_iterations).max(1);
        println!(
            "{{\"solver\": \"{}\", \"threads\": {threads}, \"elements\": {n_el}, \"coords\": {n_coords}, \"kkt_nnz\": {}, \
             \"build_s\": {build:.3}, \"median_step_s\": {:.5}, \"steps\": {}, \"newton_per_step\": {:.2}, \
             \"jacobians\": {}, \"assembly_s_per_step\": {:.5}, \"factor_s_per_step\": {:.5}, \"solve_s_per_step\": {:.5}, \
             \"krylov_per_solve\": {:.1}, \"failed\": {}}}",
            if iterative { "iterative" } else { "direct" },
            hht.kkt_nnz(),
            if per_step.is_empty() { f64::NAN } else { median(&mut per_step) },
            s.steps - s0.steps,
            (s.newton_iterations - s0.newton_iterations) as f64 / total_steps,
            s.jacobian_evaluations - s0.jacobian_evaluations,
            (s.time_assembly - s0.time_assembly).as_secs_f64() / total_steps,
            (s.time_factorization - s0.time_factorization).as_secs_f64() / total_steps,
            (s.time_solve - s0.time_solve).as_secs_f64() / total_steps,
            linear as f64 / solves as f64,
            failed.map_or("null".to_string(), |e| format!("{e:?}")),
        );
    }
}

/// The explicit stepper's cost per step on `sys` (module docs, `explicit`).
fn explicit_steps(sys: SloshSystem, steps: usize, t_build: Instant, threads: usize) {
    let (n_el, n_coords) = (sys.body.elements.len(), sys.body.n_coords());
    let (q0, v0) = sys.initial_state(0.0);
    let m_s = sys.body.scalar_mass().clone();
    // the stepper's set-up: the mass factorization and the initial force evaluation
    let t_setup = Instant::now();
    let mut e = Explicit::new(sys, &m_s, 0.0, q0, v0, ExplicitParams::default()).expect("explicit stepper");
    let setup = t_setup.elapsed().as_secs_f64();
    let h = e.stable_step().expect("stable step");
    let build = t_build.elapsed().as_secs_f64();
    // the mass solve alone (two triangular solves for the three directions), on a copy
    let mut mass = BlockMass::new(&m_s).expect("mass");
    let f: Vec<f64> = (0..n_coords).map(|i| (i as f64 * 0.618_033_988_75).fract() - 0.5).collect();
    let mut a = vec![0.0; n_coords];
    let mut per_solve: Vec<f64> = (0..steps.max(3))
        .map(|_| {
            let tic = Instant::now();
            mass.solve(&f, &mut a);
            tic.elapsed().as_secs_f64()
        })
        .collect();
    let (mut per_step, failed) = time_steps(steps, || e.step(h).map_err(|err| err.to_string()));
    println!(
        "{{\"solver\": \"explicit\", \"threads\": {threads}, \"elements\": {n_el}, \"coords\": {n_coords}, \
         \"build_s\": {build:.3}, \"setup_s\": {setup:.4}, \"step_h_s\": {h:.3e}, \"median_step_s\": {:.6}, \
         \"median_mass_solve_s\": {:.6}, \"steps\": {}, \"failed\": {}}}",
        if per_step.is_empty() { f64::NAN } else { median(&mut per_step) },
        median(&mut per_solve),
        per_step.len(),
        failed.map_or("null".to_string(), |e| format!("{e:?}")),
    );
}
