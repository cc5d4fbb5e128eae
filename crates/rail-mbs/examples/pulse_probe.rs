//! Exploratory probe (not a test) of `slosh-load-convergence`'s run: seed 003's rectangular
//! tank under the 0.3 g lateral pulse 0.1–0.6 s, 4³ penalty points, 4×4 contact points.
//! args: NX NY NZ H_MAX K_FACTOR WALL_DAMPING_FACTOR T_END OUT.csv
//! (K_FACTOR scales the bulk penalty k_IC, its damping following the default rule;
//! WALL_DAMPING_FACTOR scales the wall contact damping, 30 in the validation case;
//! environment ADH: the wall adhesion, in units of ρ g H; INC, GROW, EASY, DEC: the adaptive
//! step controller's settings).
//! Writes t, F_y (N), Newton iterations, largest penetration (m) per step.
use std::io::Write;

use ancf_core::FluidBody;
use ancf_core::constants::GRAVITY as G;
use ancf_core::constitutive::Rheology;
use ancf_core::contact::{WallContact, WallContactLaw};
use ancf_core::element::QuadratureOptions;
use ancf_core::mesh::box_mesh;
use ancf_core::tank::{TankGeometry, TankShape};
use rail_mbs::defaults::{default_bulk_damping, liquid, slosh_params};
use rail_mbs::slosh::{PiecewiseAcceleration, PrescribedMotion, SloshFrame, SloshRun, SloshSystem};

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let f = |i: usize, d: f64| a.get(i).map(|s| s.parse().unwrap()).unwrap_or(d);
    let counts = [f(0, 2.0) as usize, f(1, 6.0) as usize, f(2, 3.0) as usize];
    let (h, kfac, dfac, t_end) = (f(3, 0.004), f(4, 1.0), f(5, 30.0), f(6, 4.0));
    let out = a.get(7).cloned().unwrap_or("/tmp/pulse.csv".into());
    let (lx, ly, d) = (0.416, 0.324, 0.132);
    let mesh = box_mesh([-lx / 2.0, -ly / 2.0, 0.0], [lx, ly, d], counts).unwrap();
    let h_el = d / counts[2] as f64;
    let mut fluid = liquid(998.0, Rheology::Newtonian { viscosity: 1e-3 }, d, h_el).unwrap();
    fluid.bulk_penalty *= kfac;
    fluid.bulk_damping = default_bulk_damping(fluid.bulk_penalty, fluid.density, h_el);
    let geo =
        TankGeometry::new(TankShape::Box { min: [-lx / 2.0, -ly / 2.0, 0.0], max: [lx / 2.0, ly / 2.0, 0.3] }, vec![])
            .unwrap();
    let mut law = WallContactLaw::default_for(fluid.density, G, d);
    law.damping *= dfac;
    law.points_per_edge = 4;
    let adh: f64 = std::env::var("ADH").ok().map(|v| v.parse().unwrap()).unwrap_or(0.0);
    let law = law.with_adhesion(adh, fluid.density, G, d).unwrap();
    let quad = QuadratureOptions { penalty: 4, ..QuadratureOptions::default() };
    let body = FluidBody::new(mesh, fluid, quad).unwrap();
    let mut contact = WallContact::new(&body, geo, law).unwrap();
    if std::env::var("NOFS").is_ok() {
        // drop the free-surface points (reference height = the depth)
        let e0 = body.mesh.reference_coordinates();
        contact.points.retain(|pt| {
            let nodes = &body.mesh.elements[pt.element];
            let mut z = 0.0;
            for a in 0..32 {
                z += pt.shape[a] * e0[3 * (4 * nodes[a / 4] + a % 4) + 2];
            }
            z < d - 1e-9
        });
        eprintln!("{} contact points without the free surface", contact.points.len());
    }
    let mut motion = PrescribedMotion::at_rest([0.0; 3]);
    motion.translation[1] = PiecewiseAcceleration::pulse(0.3 * G, 0.1, 0.6, 0.02).unwrap();
    let sys = SloshSystem::new(body, contact, motion, [0.0, 0.0, -G], SloshFrame::Inertial).unwrap();
    // environment INC, GROW, EASY, DEC: the adaptive controller's increase, grow_after,
    // easy_iterations and decrease (default: `slosh_params`)
    let mut params = slosh_params();
    if let rail_mbs::integrator::StepControl::Adaptive(p) = &mut params.step_control {
        let env = |k: &str| std::env::var(k).ok().map(|v| v.parse::<f64>().unwrap());
        p.increase = env("INC").unwrap_or(p.increase);
        p.decrease = env("DEC").unwrap_or(p.decrease);
        p.grow_after = env("GROW").map_or(p.grow_after, |x| x as usize);
        p.easy_iterations = env("EASY").map_or(p.easy_iterations, |x| x as usize);
    }
    let mut run = SloshRun::new(sys, 0.0, params).unwrap();
    let t0 = std::time::Instant::now();
    if let Ok(ev) = std::env::var("EVENT") {
        // per-point F_y around an event: EVENT=ta,tb
        let v: Vec<f64> = ev.split(',').map(|x| x.parse().unwrap()).collect();
        run.run_to(v[0], h).unwrap();
        let sys0 = run.stepper.system();
        let elements = sys0.body.mesh.elements.clone();
        let e0 = sys0.body.mesh.reference_coordinates();
        let np = sys0.contact.points.len();
        let refpos: Vec<[f64; 3]> = sys0
            .contact
            .points
            .iter()
            .map(|pt| {
                let nodes = &elements[pt.element];
                let mut x = [0.0; 3];
                for a in 0..32 {
                    for i in 0..3 {
                        x[i] += pt.shape[a] * e0[3 * (4 * nodes[a / 4] + a % 4) + i];
                    }
                }
                x
            })
            .collect();
        let per_point = |run: &SloshRun| -> Vec<f64> {
            let sys = run.stepper.system();
            let kin = sys.contact_kinematics(run.stepper.t());
            (0..np)
                .map(|k| {
                    let mut c = sys.contact.clone();
                    c.points = vec![sys.contact.points[k].clone()];
                    let mut scratch = vec![0.0; run.stepper.q().len()];
                    c.forces(&sys.body, &kin, run.stepper.q(), run.stepper.v(), &mut scratch, None).force[1]
                })
                .collect()
        };
        let pt_el: Vec<usize> = run.stepper.system().contact.points.iter().map(|p| p.element).collect();
        let mut prev = per_point(&run);
        let mut t = v[0];
        while t < v[1] {
            t += 0.000125;
            run.run_to(t, h).unwrap();
            let cur = per_point(&run);
            let tot: f64 = cur.iter().sum();
            let mut idx: Vec<usize> = (0..np).collect();
            idx.sort_by(|&a, &b| (cur[b] - prev[b]).abs().partial_cmp(&(cur[a] - prev[a]).abs()).unwrap());
            print!("t {t:.6} Fy {tot:8.3}:");
            for &k in idx.iter().take(3) {
                let r = refpos[k];
                print!(
                    "  pt {k} el {} ref ({:.3},{:.3},{:.3}) {:.3}->{:.3}",
                    pt_el[k], r[0], r[1], r[2], prev[k], cur[k]
                );
            }
            println!();
            prev = cur;
        }
        return;
    }
    if let Err(e) = run.run_to(t_end, h) {
        eprintln!("stopped: {e}");
    }
    let r = &run.record;
    let mut w = std::io::BufWriter::new(std::fs::File::create(&out).unwrap());
    writeln!(w, "t,fy,fz,iters,pen").unwrap();
    for i in 0..r.t.len() {
        writeln!(
            w,
            "{},{},{},{},{}",
            r.t[i], r.force_tank[i][1], r.force_tank[i][2], r.newton_iterations[i], r.max_penetration[i]
        )
        .unwrap();
    }
    let st = run.stats();
    eprintln!(
        "{counts:?} h<={h} k x{kfac} wall damping x{dfac}: {} steps, {:.1} s; rejected {}, Newton {}, \
         Jacobians {}, factorizations {}, residuals {}; assembly {:.1} s, factorization {:.1} s, solves {:.1} s",
        r.t.len() - 1,
        t0.elapsed().as_secs_f64(),
        st.rejected_steps,
        st.newton_iterations,
        st.jacobian_evaluations,
        st.factorizations,
        st.residual_evaluations,
        st.time_assembly.as_secs_f64(),
        st.time_factorization.as_secs_f64(),
        st.time_solve.as_secs_f64()
    );
}
