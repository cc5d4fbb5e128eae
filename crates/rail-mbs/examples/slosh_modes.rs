//! Exploratory probe (not a test): linear modes of a half-full cylinder slice (or a box section)
//! about its settled hydrostatic state: smallest eigenvalues, the modes with lateral effective
//! mass, and the energy split of the lowest modes.
//! `cargo run --release -p rail-mbs --example slosh_modes -- [key=value ...]`, keys: ny nz nx L
//! np (penalty rule) mu (settling viscosity) kf (penalty factor) ts (settling time) tol (Newton
//! tolerance) ppe (contact points per edge) nm (mass rule) kc (contact stiffness factor)
//! box (1: box section) bw bd (box width, depth) R (radius, the length scale of lambda)
//! newton shift (static Newton refinement steps and their mass shift) list (1: list all modes
//! with lambda < 3).
use ancf_core::FluidBody;
use ancf_core::constants::GRAVITY as G;
use ancf_core::constitutive::Rheology;
use ancf_core::contact::{WallContact, WallContactLaw};
use ancf_core::element::QuadratureOptions;
use ancf_core::mesh::{CylinderTankSpec, box_mesh, cylinder_tank};
use ancf_core::tank::{TankGeometry, TankShape};
use faer::linalg::solvers::Solve;
use faer::{Mat, Par, Side};
use rail_mbs::defaults::{liquid, slosh_params};
use rail_mbs::integrator::{HhtParams, MechanicalSystem};
use rail_mbs::slosh::{PrescribedMotion, SloshFrame, SloshRun, SloshSystem};

fn main() {
    // key=value arguments
    let args: Vec<(String, String)> = std::env::args()
        .skip(1)
        .filter_map(|s| s.split_once('=').map(|(k, v)| (k.to_string(), v.to_string())))
        .collect();
    let f = |k: &str, d: f64| args.iter().find(|(a, _)| a == k).map(|(_, v)| v.parse().unwrap()).unwrap_or(d);
    let (ny, nz) = (f("ny", 8.0) as usize, f("nz", 4.0) as usize);
    let np = f("np", 3.0) as usize;
    let mu_settle = f("mu", 1e4);
    let kf = f("kf", 1.0);
    let l = f("L", 1.0);
    let nx = f("nx", 1.0) as usize;
    let t_settle = f("ts", 4.0);
    let ppe = f("ppe", 3.0) as usize;
    let nmass = f("nm", 4.0) as usize;
    let kcf = f("kc", 1.0);
    let is_box = f("box", 0.0) != 0.0;
    let list = f("list", 0.0) != 0.0;
    let r = f("R", 1.5);
    let (mesh, geo, depth) = if is_box {
        // a box, by default of the same depth and width as the half cylinder
        let (w, d) = (f("bw", 2.0 * r), f("bd", r));
        (
            box_mesh([-l / 2.0, -w / 2.0, -d], [l, w, d], [nx, ny, nz]).unwrap(),
            TankGeometry::new(TankShape::Box { min: [-l / 2.0, -w / 2.0, -d], max: [l / 2.0, w / 2.0, d] }, vec![])
                .unwrap(),
            d,
        )
    } else {
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
        (
            cylinder_tank(&spec).unwrap(),
            TankGeometry::new(TankShape::Cylinder { length: l, radius: r, head_depth: 0.0 }, vec![]).unwrap(),
            r,
        )
    };
    let mut fluid = liquid(998.0, Rheology::Newtonian { viscosity: mu_settle }, depth, depth / nz as f64).unwrap();
    fluid.bulk_penalty *= kf;
    fluid.bulk_damping *= kf.sqrt();
    let body = FluidBody::new(mesh, fluid, QuadratureOptions { viscous: 3, penalty: np, mass: nmass }).unwrap();
    let mut law = WallContactLaw { points_per_edge: ppe, ..WallContactLaw::default_for(998.0, G, depth) };
    law.stiffness *= kcf;
    law.damping *= kcf;
    let contact = WallContact::new(&body, geo, law).unwrap();
    let mass = body.total_mass();
    let sys =
        SloshSystem::new(body, contact, PrescribedMotion::at_rest([0.0; 3]), [0.0, 0.0, -G], SloshFrame::Inertial)
            .unwrap();
    let t0 = std::time::Instant::now();
    let tol = f("tol", 1e-3);
    let mut run =
        SloshRun::new(sys, 0.0, HhtParams { abs_tol_acc: tol, rel_tol: 1e-4f64.min(tol), ..slosh_params() }).unwrap();
    run.run_to(t_settle, 0.02).unwrap();
    let q = run.stepper.q().to_vec();
    {
        let rec = &run.record;
        let nrec = rec.t.len();
        for i in [nrec / 4, nrec / 2, 3 * nrec / 4, nrec - 1] {
            println!("t {:.2} KE {:.3e} com {:?}", rec.t[i], rec.kinetic_energy[i], rec.com_tank[i]);
        }
        let vv = run.stepper.v();
        let vmax = vv.iter().enumerate().filter(|(i, _)| i % 12 < 3).map(|(_, x)| x.abs()).fold(0.0, f64::max);
        println!("max nodal speed {vmax:.3e}");
    }
    let mut sys = run.stepper.into_system();
    let n = sys.n_coords();
    let v0 = vec![0.0; n];
    let mut res = vec![0.0; n];
    sys.forces(t_settle, &q, &v0, &mut res).unwrap();
    let gnorm: f64 = sys.body.gravity_force([0.0, 0.0, -G]).iter().map(|x| x * x).sum::<f64>().sqrt();
    let rnorm: f64 = res.iter().map(|x| x * x).sum::<f64>().sqrt();
    let rpos: f64 = res.iter().enumerate().filter(|(i, _)| i % 12 < 3).map(|(_, x)| x * x).sum::<f64>().sqrt();
    println!("position-coordinate residual / |Q_g| = {:.2e}", rpos / gnorm);
    println!("settled in {:.1}s: |Q|/|Q_g| = {:.2e}, n = {n}", t0.elapsed().as_secs_f64(), rnorm / gnorm);
    let pat = sys.pattern().dynamics;
    let mut mv = vec![0.0; pat.len()];
    sys.mass(&q, &mut mv).unwrap();
    let mut q = q;
    let shift = f("shift", 1.0);
    for it in 0..(f("newton", 0.0) as usize) {
        let mut dq = vec![0.0; pat.len()];
        let mut dv = vec![0.0; pat.len()];
        sys.force_jacobians(t_settle, &q, &v0, &mut dq, &mut dv).unwrap();
        let mut a = Mat::<f64>::zeros(n, n);
        for (idx, &(i, j)) in pat.iter().enumerate() {
            a[(i, j)] += shift * mv[idx] - dq[idx];
        }
        let mut res = vec![0.0; n];
        sys.forces(t_settle, &q, &v0, &mut res).unwrap();
        let rhs = Mat::<f64>::from_fn(n, 1, |i, _| res[i]);
        let dx = a.partial_piv_lu().solve(&rhs);
        for i in 0..n {
            q[i] += dx[(i, 0)];
        }
        let mut res = vec![0.0; n];
        sys.forces(t_settle, &q, &v0, &mut res).unwrap();
        let rn: f64 = res.iter().map(|x| x * x).sum::<f64>().sqrt();
        println!("newton {it}: |Q|/|Q_g| = {:.2e}", rn / gnorm);
    }
    let mut dq = vec![0.0; pat.len()];
    let mut dv = vec![0.0; pat.len()];
    sys.force_jacobians(t_settle, &q, &v0, &mut dq, &mut dv).unwrap();
    let mut m = Mat::<f64>::zeros(n, n);
    let mut k = Mat::<f64>::zeros(n, n);
    for (idx, &(i, j)) in pat.iter().enumerate() {
        m[(i, j)] += mv[idx];
        k[(i, j)] -= dq[idx];
    }
    let mut asym: f64 = 0.0;
    let mut kmax: f64 = 0.0;
    for i in 0..n {
        for j in 0..n {
            asym = asym.max((k[(i, j)] - k[(j, i)]).abs());
            kmax = kmax.max(k[(i, j)].abs());
        }
    }
    println!("K asymmetry {:.2e} of max {:.2e}", asym, kmax);
    let ks = Mat::<f64>::from_fn(n, n, |i, j| 0.5 * (k[(i, j)] + k[(j, i)]));
    let llt = m.llt(Side::Lower).unwrap();
    let lm = llt.L().to_owned();
    // A = L^-1 K L^-T
    let mut b = ks.clone();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(lm.as_ref(), b.as_mut(), Par::Seq);
    let mut bt = b.transpose().to_owned();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(lm.as_ref(), bt.as_mut(), Par::Seq);
    let am = Mat::<f64>::from_fn(n, n, |i, j| 0.5 * (bt[(i, j)] + bt[(j, i)]));
    let eig = am.self_adjoint_eigen(Side::Lower).unwrap();
    let (s, u) = (eig.S(), eig.U());
    // phi = L^-T y
    let mut phi = u.to_owned();
    faer::linalg::triangular_solve::solve_upper_triangular_in_place(lm.transpose(), phi.as_mut(), Par::Seq);
    // rigid lateral translation: position y components (coordinate 12 n + 1)
    let ry: Vec<f64> = (0..n).map(|i| if i % 12 == 1 { 1.0 } else { 0.0 }).collect();
    let rz: Vec<f64> = (0..n).map(|i| if i % 12 == 2 { 1.0 } else { 0.0 }).collect();
    let mr = |r: &[f64]| -> Vec<f64> { (0..n).map(|i| (0..n).map(|j| m[(i, j)] * r[j]).sum()).collect() };
    let (mry, mrz) = (mr(&ry), mr(&rz));
    println!("total mass {mass:.1}, r^T M r = {:.1}", (0..n).map(|i| ry[i] * mry[i]).sum::<f64>());
    let mut shown = 0;
    for c in 0..n {
        let w2 = s[c];
        let lam = w2 * r / G;
        let col = phi.col(c);
        let py: f64 = (0..n).map(|i| col[i] * mry[i]).sum();
        let pz: f64 = (0..n).map(|i| col[i] * mrz[i]).sum();
        // phi^T M phi = 1 (mass-normalized)
        let (fy, fz) = (py * py / mass, pz * pz / mass);
        if lam > -1.0
            && (lam < 0.05 && c % 20 == 0
                || (0.05..20.0).contains(&lam) && (fy > 1e-3 || fz > 1e-3 || (lam < 3.0 && list)))
        {
            println!("mode {c:4}: lambda = {lam:10.4}  m_eff,y/m = {fy:.4}  m_eff,z/m = {fz:.4}");
            shown += 1;
        }
        if shown > 60 {
            break;
        }
    }
    // internal-force (penalty) part of K alone
    let mut kint = Mat::<f64>::zeros(n, n);
    let jacs = sys.body.element_jacobians(&q, &v0).unwrap();
    for (el, jac) in jacs.iter().enumerate() {
        let nodes = sys.body.mesh.elements[el];
        let g = |a: usize, i: usize| 12 * nodes[a / 4] + 3 * (a % 4) + i;
        for a in 0..32 {
            for i in 0..3 {
                for b in 0..32 {
                    for kk in 0..3 {
                        kint[(g(a, i), g(b, kk))] += jac.stiffness[96 * (3 * a + i) + 3 * b + kk];
                    }
                }
            }
        }
    }
    let quad = |kk: &Mat<f64>, v: faer::ColRef<'_, f64>| -> f64 {
        let mut s = 0.0;
        for i in 0..n {
            for j in 0..n {
                s += v[i] * kk[(i, j)] * v[j];
            }
        }
        s
    };
    for c in 0..4 {
        let col = phi.col(c);
        let (et, ei) = (quad(&ks, col), quad(&kint, col));
        let mut best = (0, 0.0f64);
        for i in 0..n {
            if col[i].abs() > best.1 {
                best = (i, col[i].abs());
            }
        }
        println!(
            "mode {c}: phi K phi = {et:.3e}: internal {ei:.3e}, contact {:.3e}; largest coordinate node {} vector {} comp {}",
            et - ei,
            best.0 / 12,
            (best.0 % 12) / 3,
            best.0 % 3
        );
    }
    // shape of the lowest modes: largest nodal amplitude and where
    for c in 0..6 {
        let col = phi.col(c);
        let mut best = (0, 0.0f64);
        let mut pos2 = 0.0;
        let mut tot2 = 0.0;
        for i in 0..n {
            tot2 += col[i] * col[i];
            if i % 12 < 3 {
                pos2 += col[i] * col[i];
            }
            if i % 12 < 3 && col[i].abs() > best.1 {
                best = (i, col[i].abs());
            }
        }
        let node = best.0 / 12;
        println!(
            "mode {c}: lambda {:.3}, pos fraction {:.3}, max at node {node} comp {} X = {:?}",
            s[c] * r / G,
            pos2 / tot2,
            best.0 % 12,
            &q[12 * node..12 * node + 3]
        );
    }
    let nz0 = (0..n).filter(|&c| s[c] * r / G < 0.05).count();
    let nneg = (0..n).filter(|&c| s[c] * r / G < -0.01).count();
    println!(
        "min lambda {:.4}, {nneg} below -0.01; lambdas 0..8: {:?}",
        s[0] * r / G,
        (0..8).map(|c| (s[c] * r / G * 1e4).round() / 1e4).collect::<Vec<_>>()
    );
    println!("{nz0} modes with lambda < 0.05; wall {:.1}s", t0.elapsed().as_secs_f64());
}
