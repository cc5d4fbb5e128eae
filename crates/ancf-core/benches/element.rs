//! `cargo bench -p ancf-core --bench element`: cost of the ANCF brick force kernels.
//!
//! For each quadrature setting it reports, on ONE thread (a 1-thread rayon pool):
//! - batched internal force (two GEMMs per chunk + point-wise stress): ns/element, GFLOP/s;
//! - the scalar per-element force path, for comparison in the same run;
//! - force + exact Jacobians (K and C, 96×96 each): ns/element, GFLOP/s.
//!
//! Timings are medians of repeated runs. The flop model (per element, NPT = points):
//! GEMMs 2·3NPT·32·6 + 2·32·3NPT·3, plus ≈350 flops per viscous point and ≈250 per
//! penalty point for the stress update; the Jacobian adds ≈127 kflop per point
//! (two 96×96 rank-9 accumulations and 18 directional derivatives).
//! A second table times one element's force + Jacobians through the structured
//! volumetric tangent (`VolumetricJacobian::Structured`, the default from 27 penalty points) and through the generic
//! per-point 9×9 tangent path (`VolumetricJacobian::Generic`), alternated in the same
//! run over the first 64 elements, median of the repetitions.
//! A third table compares the closed-form Newtonian kernel of the deviatoric stress
//! (`DeviatoricPath::Auto`, taken by effectively Newtonian fluids) with the generic kernel
//! (`DeviatoricPath::Generic`, 9 directional derivatives), alternated in the same run, medians:
//! per point (stress alone, and stress + both 9×9 tangents, over 1024 random states) and per
//! element (force + Jacobians, and force alone, over the first 64 elements).
//! A fourth table times the batched body force (1024 elements) and element force + Jacobians
//! (64 elements) with and without clearing the vector registers after faer's GEMMs
//! (`ancf_core::simd`), alternated in the same run.
//! Pass a filter argument (e.g. `cargo bench --bench element -- quick`) for fewer repetitions;
//! `newtonian` runs the third table only, `simd` the fourth only.
//!
//! Caution: on the AVX-512 development machine, scalar (SSE) code that runs after a faer GEMM
//! is 2–4× slower until the upper vector-register state is cleared (faer's kernels leave it
//! dirty). The per-point rows are in the clean state only when the third table runs alone
//! (`-- newtonian`); after the first two tables they include that penalty, and so do, in
//! part, the element rows (the Jacobians call GEMMs), as in the simulator.

use std::hint::black_box;
use std::time::Instant;

use ancf_core::FluidBody;
use ancf_core::constitutive::{DeviatoricPath, Fluid, M3, Rheology, Tangent};
use ancf_core::element::{QuadratureOptions, VolumetricJacobian};
use ancf_core::mesh::box_mesh;
use ancf_core::rng::Rng;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

fn time<F: FnMut()>(reps: usize, mut f: F) -> f64 {
    f(); // warm-up
    median(
        (0..reps)
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed().as_secs_f64()
            })
            .collect(),
    )
}

fn main() {
    let quick = std::env::args().any(|a| a == "quick");
    let reps = if quick { 5 } else { 21 };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let mesh = box_mesh([0.0; 3], [2.0, 1.0, 1.0], [16, 8, 8]).unwrap(); // 1024 elements
    let only = |name: &str| std::env::args().any(|a| a == name);
    if only("simd") {
        pool.install(|| simd_table(&mesh, reps));
        return;
    }
    if !only("newtonian") {
        kernel_tables(&mesh, reps, &pool);
    }
    newtonian_table(&mesh, reps);
    pool.install(|| simd_table(&mesh, reps));
}

/// Batched body force and element force + Jacobians with and without `vzeroupper` after
/// faer's GEMMs ([`ancf_core::simd`]), side by side (ABBA), one thread.
fn simd_table(mesh: &ancf_core::FluidMesh, reps: usize) {
    use ancf_core::simd::set_clear_upper_simd;
    println!();
    println!("vector-register clearing after faer GEMMs, 1 thread, ABBA, median of {} samples", reps * CHUNKS);
    println!(
        "{:<26} {:>6} {:>16} {:>16} {:>8} {:>16} {:>16} {:>8}",
        "fluid", "rule", "force dirty ns", "force clear ns", "speedup", "f+jac dirty us", "f+jac clear us", "speedup"
    );
    let fluids = [
        ("newtonian (light crude)", Fluid::new(850.0, Rheology::Newtonian { viscosity: 0.005 }, 1.25e7).unwrap()),
        (
            "oldroyd (heavy crude)",
            Fluid::new(
                1000.0,
                Rheology::Oldroyd { viscosity: 100.0, yield_stress: 100.0, elastic_modulus: None },
                1.25e7,
            )
            .unwrap(),
        ),
    ];
    for (name, fluid) in fluids {
        for (nv, np) in [(3, 3), (3, 4)] {
            let body =
                FluidBody::new(mesh.clone(), fluid, QuadratureOptions { viscous: nv, penalty: np, mass: 4 }).unwrap();
            let mut rng = Rng::new(2);
            let e: Vec<f64> = body.reference_coordinates().iter().map(|x| x + 0.002 * rng.uniform()).collect();
            let v: Vec<f64> = e.iter().map(|_| 0.1 * rng.uniform()).collect();
            let nel = body.mesh.elements.len();
            let force = |clear: bool| {
                let mut out = vec![0.0; body.n_coords()];
                let (body, e, v) = (&body, &e, &v);
                move |_c: usize| {
                    set_clear_upper_simd(clear);
                    let t = Instant::now();
                    body.internal_forces(e, v, &mut out).unwrap();
                    black_box(&out);
                    t.elapsed().as_secs_f64() / nel as f64
                }
            };
            let (fd, fc) = side_by_side(reps, force(false), force(true));
            let els: Vec<_> =
                (0..64).map(|el| (body.element_coordinates(el, &e), body.element_coordinates(el, &v))).collect();
            let jac = |clear: bool| {
                let mut f = [0.0; ancf_core::shape::N_COORDS];
                let mut k = vec![0.0; ancf_core::shape::N_COORDS * ancf_core::shape::N_COORDS];
                let mut c = k.clone();
                let (body, els) = (&body, &els);
                move |chunk: usize| {
                    set_clear_upper_simd(clear);
                    let t = Instant::now();
                    let m = els.len() / CHUNKS;
                    for (el, (ec, vc)) in els.iter().enumerate().skip(chunk * m).take(m) {
                        let r = &body.elements[el];
                        r.internal_force(el, &body.fluid, &body.tables, ec, vc, &mut f, Some((&mut k, &mut c)))
                            .unwrap();
                        black_box(&f);
                    }
                    t.elapsed().as_secs_f64() / m as f64
                }
            };
            let (jd, jc) = side_by_side(reps, jac(false), jac(true));
            set_clear_upper_simd(true);
            println!(
                "{:<26} {:>6} {:>16.0} {:>16.0} {:>7.2}x {:>16.1} {:>16.1} {:>7.2}x",
                name,
                format!("{nv}^3+{np}^3"),
                1e9 * fd,
                1e9 * fc,
                fd / fc,
                1e6 * jd,
                1e6 * jc,
                jd / jc
            );
        }
    }
}

/// Chunks the work of [`newtonian_table`] is timed in (so that a sample lasts well under a
/// scheduler time slice and an interruption spoils one sample, not a whole side).
const CHUNKS: usize = 8;

/// Times `a(c)` and `b(c)` side by side over `reps` rounds of the chunks c = 0..CHUNKS, in
/// ABBA order (one warm-up round), and returns the medians of the per-chunk times.
fn side_by_side<A: FnMut(usize) -> f64, B: FnMut(usize) -> f64>(reps: usize, mut a: A, mut b: B) -> (f64, f64) {
    (0..CHUNKS).for_each(|c| {
        a(c);
        b(c);
    });
    let (mut ta, mut tb) = (Vec::new(), Vec::new());
    for r in 0..reps * CHUNKS {
        let c = r % CHUNKS;
        if r % 2 == 0 {
            ta.push(a(c));
            tb.push(b(c));
        } else {
            tb.push(b(c));
            ta.push(a(c));
        }
    }
    (median(ta), median(tb))
}

/// Generic vs closed-form Newtonian kernel of the deviatoric stress, per point and per element.
fn newtonian_table(mesh: &ancf_core::FluidMesh, reps: usize) {
    let fluids = [
        ("newtonian (light crude)", Fluid::new(850.0, Rheology::Newtonian { viscosity: 0.005 }, 1.25e7).unwrap()),
        (
            "oldroyd, yield 0",
            Fluid::new(850.0, Rheology::Oldroyd { viscosity: 0.005, yield_stress: 0.0, elastic_modulus: None }, 1.25e7)
                .unwrap(),
        ),
    ];
    println!();
    println!(
        "deviatoric stress kernel, generic vs closed-form Newtonian, 1 thread, ABBA, median of {} samples",
        reps * CHUNKS
    );
    println!("per point (1024 random states, {} per sample):", 1024 / CHUNKS);
    println!(
        "{:<26} {:>14} {:>14} {:>8} {:>16} {:>16} {:>8}",
        "fluid", "P generic ns", "P fast ns", "speedup", "P+T generic ns", "P+T fast ns", "speedup"
    );
    let mut rng = Rng::new(3);
    let states: Vec<(M3, M3)> = (0..1024)
        .map(|_| {
            let f = M3::identity() + M3::from_fn(|_, _| 0.1 * rng.uniform());
            (f, M3::from_fn(|_, _| rng.uniform()))
        })
        .collect();
    let n = states.len() / CHUNKS;
    let states = &states;
    for (name, fluid) in fluids {
        assert!(fluid.is_effectively_newtonian());
        let stress = |path: DeviatoricPath| {
            move |c: usize| {
                let t = Instant::now();
                for (f, fd) in &states[c * n..(c + 1) * n] {
                    black_box(fluid.deviatoric_stress_with(black_box(f), black_box(fd), None, path));
                }
                t.elapsed().as_secs_f64() / n as f64
            }
        };
        let (pg, pf) = side_by_side(reps, stress(DeviatoricPath::Generic), stress(DeviatoricPath::Auto));
        let tangent = |path: DeviatoricPath| {
            let (mut tf, mut tv): (Tangent, Tangent) = ([[0.0; 9]; 9], [[0.0; 9]; 9]);
            move |c: usize| {
                let t = Instant::now();
                for (f, fd) in &states[c * n..(c + 1) * n] {
                    black_box(fluid.deviatoric_stress_with(
                        black_box(f),
                        black_box(fd),
                        Some((&mut tf, &mut tv)),
                        path,
                    ));
                    black_box((&tf, &tv));
                }
                t.elapsed().as_secs_f64() / n as f64
            }
        };
        let (tg, tfast) = side_by_side(reps, tangent(DeviatoricPath::Generic), tangent(DeviatoricPath::Auto));
        println!(
            "{:<26} {:>14.1} {:>14.1} {:>7.2}x {:>16.1} {:>16.1} {:>7.2}x",
            name,
            1e9 * pg,
            1e9 * pf,
            pg / pf,
            1e9 * tg,
            1e9 * tfast,
            tg / tfast
        );
    }
    println!("per element (64 elements, {} per sample, structured volumetric Jacobian):", 64 / CHUNKS);
    println!(
        "{:<26} {:>6} {:>14} {:>14} {:>8} {:>15} {:>15} {:>8}",
        "fluid", "rule", "f+jac gen us", "f+jac fast us", "speedup", "force gen ns", "force fast ns", "speedup"
    );
    for (name, fluid) in fluids {
        for (nv, np) in [(3, 3), (4, 3)] {
            let body =
                FluidBody::new(mesh.clone(), fluid, QuadratureOptions { viscous: nv, penalty: np, mass: 4 }).unwrap();
            let mut rng = Rng::new(2);
            let e: Vec<f64> = body.reference_coordinates().iter().map(|x| x + 0.002 * rng.uniform()).collect();
            let v: Vec<f64> = e.iter().map(|_| 0.1 * rng.uniform()).collect();
            let els: Vec<_> =
                (0..64).map(|el| (body.element_coordinates(el, &e), body.element_coordinates(el, &v))).collect();
            let run = |path: DeviatoricPath, with_jac: bool| {
                let mut f = [0.0; ancf_core::shape::N_COORDS];
                let mut k = vec![0.0; ancf_core::shape::N_COORDS * ancf_core::shape::N_COORDS];
                let mut c = k.clone();
                let (body, els) = (&body, &els);
                move |chunk: usize| {
                    let t = Instant::now();
                    let m = els.len() / CHUNKS;
                    for (el, (ec, vc)) in els.iter().enumerate().skip(chunk * m).take(m) {
                        let r = &body.elements[el];
                        let jac = if with_jac { Some((k.as_mut_slice(), c.as_mut_slice())) } else { None };
                        let vol = VolumetricJacobian::Structured;
                        r.internal_force_paths(el, &body.fluid, &body.tables, (ec, vc), &mut f, jac, vol, path)
                            .unwrap();
                        black_box(&f);
                    }
                    t.elapsed().as_secs_f64() / m as f64
                }
            };
            let (jg, jf) = side_by_side(reps, run(DeviatoricPath::Generic, true), run(DeviatoricPath::Auto, true));
            let (fg, ff) = side_by_side(reps, run(DeviatoricPath::Generic, false), run(DeviatoricPath::Auto, false));
            println!(
                "{:<26} {:>6} {:>14.1} {:>14.1} {:>7.2}x {:>15.0} {:>15.0} {:>7.2}x",
                name,
                format!("{nv}^3+{np}^3"),
                1e6 * jg,
                1e6 * jf,
                jg / jf,
                1e9 * fg,
                1e9 * ff,
                fg / ff
            );
        }
    }
}

/// The first two tables (batched/scalar force and Jacobians; structured vs generic volumetric
/// Jacobian).
fn kernel_tables(mesh: &ancf_core::FluidMesh, reps: usize, pool: &rayon::ThreadPool) {
    let nel = mesh.n_elements() as f64;
    println!("ANCF brick kernels, {} elements, 1 thread, median of {reps} runs", mesh.n_elements());
    println!(
        "{:<30} {:>6} {:>14} {:>9} {:>14} {:>14} {:>13} {:>9}",
        "fluid", "rule", "force ns/el", "GFLOP/s", "scalar ns/el", "batch speedup", "f+jac us/el", "GFLOP/s"
    );
    let fluids = [
        Fluid::new(850.0, Rheology::Newtonian { viscosity: 0.005 }, 1.25e7).unwrap(),
        Fluid::new(1000.0, Rheology::Oldroyd { viscosity: 100.0, yield_stress: 100.0, elastic_modulus: None }, 1.5e7)
            .unwrap(),
    ];
    for fluid in fluids {
        for (nv, np) in [(3, 1), (3, 2), (3, 3), (4, 2), (4, 3)] {
            let body =
                FluidBody::new(mesh.clone(), fluid, QuadratureOptions { viscous: nv, penalty: np, mass: 4 }).unwrap();
            let mut rng = Rng::new(1);
            let e: Vec<f64> = body.reference_coordinates().iter().map(|x| x + 0.002 * rng.uniform()).collect();
            let v: Vec<f64> = e.iter().map(|_| 0.1 * rng.uniform()).collect();
            let mut f = vec![0.0; body.n_coords()];
            let (t_b, t_s, t_j) = pool.install(|| {
                let t_b = time(reps, || body.internal_forces(black_box(&e), black_box(&v), &mut f).unwrap());
                let t_s =
                    time(reps.min(7), || body.internal_forces_scalar(black_box(&e), black_box(&v), &mut f).unwrap());
                let t_j = time(3, || {
                    black_box(body.element_jacobians(black_box(&e), black_box(&v)).unwrap());
                });
                (t_b, t_s, t_j)
            });
            let (pv, pp) = ((nv * nv * nv) as f64, (np * np * np) as f64);
            let npt = pv + pp;
            let flops_f = 2.0 * 3.0 * npt * 32.0 * 6.0 + 2.0 * 32.0 * 3.0 * npt * 3.0 + 350.0 * pv + 250.0 * pp;
            let flops_j = flops_f + 127_000.0 * npt;
            println!(
                "{:<30} {:>6} {:>14.0} {:>9.2} {:>14.0} {:>13.2}x {:>13.1} {:>9.2}",
                format!("{} (rho {})", fluid.rheology.name(), fluid.density),
                format!("{nv}^3+{np}^3"),
                1e9 * t_b / nel,
                flops_f * nel / t_b / 1e9,
                1e9 * t_s / nel,
                t_s / t_b,
                1e6 * t_j / nel,
                flops_j * nel / t_j / 1e9,
            );
        }
    }
    println!();
    println!("force + Jacobians of one element (64 elements per repetition), 1 thread, median of {reps}");
    println!("{:<30} {:>6} {:>16} {:>16} {:>9}", "fluid", "rule", "structured us/el", "generic us/el", "speedup");
    for fluid in fluids {
        for (nv, np) in [(3, 2), (3, 3), (3, 4)] {
            let body =
                FluidBody::new(mesh.clone(), fluid, QuadratureOptions { viscous: nv, penalty: np, mass: 4 }).unwrap();
            let mut rng = Rng::new(2);
            let e: Vec<f64> = body.reference_coordinates().iter().map(|x| x + 0.002 * rng.uniform()).collect();
            let v: Vec<f64> = e.iter().map(|_| 0.1 * rng.uniform()).collect();
            let els: Vec<_> =
                (0..64).map(|el| (body.element_coordinates(el, &e), body.element_coordinates(el, &v))).collect();
            let mut f = [0.0; ancf_core::shape::N_COORDS];
            let mut k = vec![0.0; ancf_core::shape::N_COORDS * ancf_core::shape::N_COORDS];
            let mut c = k.clone();
            let mut run = |generic: bool| {
                let t = Instant::now();
                for (el, (ec, vc)) in els.iter().enumerate() {
                    let r = &body.elements[el];
                    let jac = Some((k.as_mut_slice(), c.as_mut_slice()));
                    let path = if generic { VolumetricJacobian::Generic } else { VolumetricJacobian::Structured };
                    r.internal_force_with(el, &body.fluid, &body.tables, (ec, vc), &mut f, jac, path).unwrap();
                    black_box(&f);
                }
                t.elapsed().as_secs_f64() / els.len() as f64
            };
            run(false);
            run(true);
            let (mut ts, mut tg) = (Vec::new(), Vec::new());
            for _ in 0..reps {
                ts.push(run(false));
                tg.push(run(true));
            }
            let (ts, tg) = (median(ts), median(tg));
            println!(
                "{:<30} {:>6} {:>16.1} {:>16.1} {:>8.2}x",
                format!("{} (rho {})", fluid.rheology.name(), fluid.density),
                format!("{nv}^3+{np}^3"),
                1e6 * ts,
                1e6 * tg,
                tg / ts
            );
        }
    }
}
