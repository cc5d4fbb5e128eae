//! Stability of the *sloshing* state (issue 16, docs/validation.md "The SwRI lateral run's growing
//! mode"): runs the SwRI tank of `scripts/swri_lateral_loads.py` (water, `COUNTS` elements, 4³
//! points, 5×5 contact points, ζ_w = 1, adhesion 4, recommended shear stabilization × `STAB`)
//! under the 0.3 g lateral pulse 0–0.5 s to each time T, then linearizes the equations of motion
//! about the state there (central differences of the generalized forces in q and v, frozen in
//! time) and prints:
//! - the lowest eigenvalues ω² of −K_sym against M (negative: a direction of negative
//!   stiffness), for all forces, for the wall contact alone and for the rest;
//! - the largest real part of the first-order system's eigenvalues with the wall terms removed
//!   in turn;
//! - the six eigenvalues μ with the largest real part, each with its mode's parity under the
//!   mirror x → −x (+1 symmetric, −1 antisymmetric) and the nodes that carry it.
//!
//! `cargo run --release -p railslosh-cases --example sloshing_modes -- T...`
//! Environment: `COUNTS` (default `3,6,3`), `STAB` (default 1), `ADH` (default 4), `ZW` (default
//! 1), `DROP=v` (no velocity terms in the linearization).
use ancf_core::constants::GRAVITY as G;
use ancf_core::element::QuadratureOptions;
use faer::Mat;
use faer::linalg::solvers::Solve;
use rail_mbs::integrator::MechanicalSystem;
use rail_mbs::slosh::{PiecewiseAcceleration, SloshScenario, mass_normalized_eigen};
use railslosh_cases::slosh::RestMesh;

fn env(name: &str, default: f64) -> f64 {
    std::env::var(name).ok().map_or(default, |s| s.parse().unwrap())
}

fn main() {
    let times: Vec<f64> = std::env::args().skip(1).map(|s| s.parse().unwrap()).collect();
    let counts: Vec<usize> =
        std::env::var("COUNTS").unwrap_or("3,6,3".into()).split(',').map(|s| s.parse().unwrap()).collect();
    let drop = std::env::var("DROP").unwrap_or_default();
    let tank = RestMesh::Swri([counts[0], counts[1], counts[2]]).tank(None).unwrap();
    let mut fluid = tank.fluid;
    fluid.shear_stabilization = env("STAB", 1.0) * tank.recommended_stabilization();
    let mut sc = SloshScenario::new(tank.mesh, fluid, tank.geometry.shape);
    sc.quadrature = QuadratureOptions { viscous: 4, penalty: 4, ..QuadratureOptions::default() };
    sc.contact_points_per_edge = 5;
    sc.wall_damping_ratio = env("ZW", 1.0);
    sc.wall_adhesion = env("ADH", 4.0);
    sc.motion.translation[1] = PiecewiseAcceleration::pulse(0.3 * G, 0.0, 0.5, 0.01).unwrap();
    let (mut run, _) = sc.start(rail_mbs::slosh::StepperChoice::Implicit, 0.004, None).unwrap();
    for &t in &times {
        run.run_to(t, 0.004).unwrap();
        let (q, v) = (run.stepper.q().to_vec(), run.stepper.v().to_vec());
        let sys = run.stepper.system_mut();
        let n = sys.n_coords();
        let pattern = sys.pattern().dynamics;
        let mut mv = vec![0.0; pattern.len()];
        sys.mass(&q, &mut mv).unwrap();
        let mut m = Mat::<f64>::zeros(n, n);
        for (idx, &(i, j)) in pattern.iter().enumerate() {
            m[(i, j)] += mv[idx];
        }
        // K = ∂Q/∂q, C = ∂Q/∂v by central differences, of every force and of the wall contact's alone
        let kin = sys.contact_kinematics(t);
        let contact = sys.contact.clone();
        let f_all = |sys: &mut rail_mbs::slosh::SloshSystem, q: &[f64], v: &[f64], out: &mut [f64]| {
            sys.forces(t, q, v, out).unwrap()
        };
        let (kq, cv) = linearize(n, &q, &v, !drop.contains('v'), |qq, vv, out| f_all(sys, qq, vv, out));
        let (kc, cc) = linearize(n, &q, &v, !drop.contains('v'), |qq, vv, out| {
            out.iter_mut().for_each(|x| *x = 0.0);
            contact.forces(&sys.body, &kin, qq, vv, out, None);
        });
        // eigenvalues of −K_sym against M
        let lowest = |k: &Mat<f64>| -> Vec<String> {
            let neg = Mat::<f64>::from_fn(n, n, |i, j| -k[(i, j)]);
            let (w, _) = mass_normalized_eigen(&m, &neg).unwrap();
            w[..4].iter().map(|x| format!("{x:.1}")).collect()
        };
        let kf = &kq - &kc;
        println!("  lowest omega^2 of -K_sym/M: contact {:?}, the rest {:?}", lowest(&kc), lowest(&kf));
        let cf = &cv - &cc;
        for (name, k, c) in
            [("fluid only (no wall terms)", &kf, &cf), ("no wall damping", &kq, &cf), ("no wall stiffness", &kf, &cv)]
        {
            let a = first_order(&m, k, c);
            let ev = a.eigenvalues().unwrap();
            let top = ev.iter().map(|z| z.re).fold(f64::NEG_INFINITY, f64::max);
            println!("  {name}: largest Re mu {top:+.3}");
        }
        let a = first_order(&m, &kq, &cv);
        let eig = a.eigen().unwrap();
        let s = eig.S();
        let mut idx: Vec<usize> = (0..2 * n).collect();
        idx.sort_by(|&x, &y| s[y].re.total_cmp(&s[x].re));
        println!(
            "t {t}: stab {} adh {} zw {}: lowest omega^2 of -K_sym/M: {:?}",
            env("STAB", 1.0),
            env("ADH", 4.0),
            env("ZW", 1.0),
            lowest(&kq)
        );
        // the x-mirror image of each node (reference positions) for the modes' parity
        let e0 = sys.body.mesh.reference_coordinates();
        let nodes = n / 12;
        let mirror: Vec<usize> = (0..nodes)
            .map(|p| {
                (0..nodes)
                    .find(|&r| {
                        (e0[12 * r] + e0[12 * p]).abs() < 1e-9
                            && (e0[12 * r + 1] - e0[12 * p + 1]).abs() < 1e-9
                            && (e0[12 * r + 2] - e0[12 * p + 2]).abs() < 1e-9
                    })
                    .unwrap()
            })
            .collect();
        let u = eig.U();
        let mut shown = 0;
        for &k in &idx {
            if shown == 6 {
                break;
            }
            if s[k].im < -1e-9 {
                continue; // one of each complex pair
            }
            shown += 1;
            let mut amp: Vec<(f64, usize)> = (0..nodes)
                .map(|p| ((0..3).map(|i| u[(12 * p + i, k)].norm().powi(2)).sum::<f64>().sqrt(), p))
                .collect();
            amp.sort_by(|x, y| y.0.total_cmp(&x.0));
            let tot: f64 = amp.iter().map(|x| x.0).sum();
            // parity <u, P u>/|u|^2 over the position components: +1 mirror-symmetric, -1 antisymmetric
            let (mut dot, mut nrm) = (0.0, 0.0);
            for p in 0..nodes {
                for i in 0..3 {
                    let sgn = if i == 0 { -1.0 } else { 1.0 };
                    let a = u[(12 * p + i, k)];
                    let b = u[(12 * mirror[p] + i, k)] * sgn;
                    dot += (a.conj() * b).re;
                    nrm += a.norm().powi(2);
                }
            }
            print!("  mu {:+.3} {:+.3}i parity {:+.2}:", s[k].re, s[k].im, dot / nrm);
            for &(w, p) in amp.iter().take(4) {
                print!(" #{p} ({:.3},{:.3},{:.3}) {:.2}", q[12 * p], q[12 * p + 1], q[12 * p + 2], w / tot);
            }
            println!();
        }
    }
}

/// K = ∂f/∂q and C = ∂f/∂v (C = 0 without `velocity`) by central differences.
fn linearize(
    n: usize,
    q: &[f64],
    v: &[f64],
    velocity: bool,
    mut f: impl FnMut(&[f64], &[f64], &mut [f64]),
) -> (Mat<f64>, Mat<f64>) {
    let mut kq = Mat::<f64>::zeros(n, n);
    let mut cv = Mat::<f64>::zeros(n, n);
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    for j in 0..n {
        let dq = 1e-7 * (1.0 + q[j].abs());
        let (mut qp, mut qm) = (q.to_vec(), q.to_vec());
        qp[j] += dq;
        qm[j] -= dq;
        f(&qp, v, &mut fp);
        f(&qm, v, &mut fm);
        for i in 0..n {
            kq[(i, j)] = (fp[i] - fm[i]) / (2.0 * dq);
        }
        if velocity {
            let dv = 1e-6;
            let (mut vp, mut vm) = (v.to_vec(), v.to_vec());
            vp[j] += dv;
            vm[j] -= dv;
            f(q, &vp, &mut fp);
            f(q, &vm, &mut fm);
            for i in 0..n {
                cv[(i, j)] = (fp[i] - fm[i]) / (2.0 * dv);
            }
        }
    }
    (kq, cv)
}

/// The first-order system matrix [[0, I], [M⁻¹K, M⁻¹C]].
fn first_order(m: &Mat<f64>, k: &Mat<f64>, c: &Mat<f64>) -> Mat<f64> {
    let n = m.nrows();
    let llt = m.llt(faer::Side::Lower).unwrap();
    let (mk, mc) = (llt.solve(k), llt.solve(c));
    let mut a = Mat::<f64>::zeros(2 * n, 2 * n);
    for i in 0..n {
        a[(i, n + i)] = 1.0;
        for j in 0..n {
            a[(n + i, j)] = mk[(i, j)];
            a[(n + i, n + j)] = mc[(i, j)];
        }
    }
    a
}
