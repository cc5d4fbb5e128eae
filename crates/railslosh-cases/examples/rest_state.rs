//! Rest-state stability probe (issue 16 §6, docs/validation.md "A stable rest state"): settles a
//! liquid at rest (viscosity 10⁴ Pa·s, `TS` s, default 3), then prints the smallest eigenvalues
//! λ = ω² H/g of the linearization about that state and the frequencies of the modes with the
//! largest longitudinal and lateral effective mass, for each shear stabilization given as a
//! multiple β of ρ g H (−1: the recommended `default_shear_stabilization`).
//!
//! `cargo run --release -p railslosh-cases --example rest_state -- KIND NV NP PPE NX NY NZ BETA...`
//! with KIND `box` (seed 003 rectangular tank), `swri` (SwRI elliptic tank) or `car` (the tank
//! car half full of light crude; `HEAD=0` for flat ends), NV/NP the viscous/penalty points per
//! direction, PPE the contact points per face edge and NX NY NZ the element counts.
//! `SHAPE=1` also prints the nodes that carry the three lowest modes; `ADH=a` gives the walls an
//! adhesion of a ρ g H (`WallContactLaw::with_adhesion`). The models are those of the `rest-state`
//! case (`railslosh_cases::slosh::RestMesh::tank`, settled by `railslosh_cases::slosh::settled`).
use ancf_core::constants::GRAVITY as G;
use ancf_core::element::QuadratureOptions;
use rail_mbs::slosh::linear_modes;
use railslosh_cases::slosh::{RestMesh, settled};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let kind = args[0].clone();
    let a: Vec<f64> = args[1..].iter().map(|s| s.parse().unwrap()).collect();
    let (nv, np, ppe) = (a[0] as usize, a[1] as usize, a[2] as usize);
    let c = [a[3] as usize, a[4] as usize, a[5] as usize];
    let gs = &a[6..];
    let mesh = match kind.as_str() {
        "swri" => RestMesh::Swri(c),
        "box" => RestMesh::Box(c),
        _ => RestMesh::Car(c),
    };
    let head: Option<f64> = std::env::var("HEAD").ok().map(|s| s.parse().unwrap());
    let tank = mesh.tank(head).unwrap();
    let (rho, depth) = (tank.fluid.density, tank.depth);
    let working = tank.fluid.rheology;
    let g_default = tank.recommended_stabilization();
    let adhesion: f64 = std::env::var("ADH").ok().map_or(0.0, |v| v.parse().unwrap());
    let law = tank.wall_law(ppe).with_adhesion(adhesion, rho, G, depth).unwrap();
    let ts: f64 = std::env::var("TS").map(|s| s.parse().unwrap()).unwrap_or(3.0);
    let quadrature = QuadratureOptions { viscous: nv, penalty: np, mass: 4 };
    let (mut sys, q, run_v) = settled(tank.mesh, tank.fluid, tank.geometry, law, quadrature, ts).unwrap();
    let rgh = rho * G * depth;
    {
        use rail_mbs::integrator::MechanicalSystem;
        let n = sys.n_coords();
        let mut res = vec![0.0; n];
        sys.forces(ts, &q, &vec![0.0; n], &mut res).unwrap();
        let gn: f64 = sys.body.gravity_force([0.0, 0.0, -G]).iter().map(|x| x * x).sum::<f64>().sqrt();
        let rn: f64 = res.iter().map(|x| x * x).sum::<f64>().sqrt();
        let vmax = run_v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        println!("settled: |Q|/|Q_g| = {:.2e}, max |v| = {vmax:.2e}", rn / gn);
    }
    for &g in gs {
        sys.body.fluid.rheology = working;
        // g < 0: the library default; else the multiple g of rho g H
        sys.body.fluid.shear_stabilization = if g >= 0.0 { g * rgh } else { g_default };
        if let Ok(h) = std::env::var("HG") {
            // the non-affine-mode control G_h = HG rho g H (read when the body is built)
            let mut fluid = sys.body.fluid;
            fluid.hourglass_stabilization = h.parse::<f64>().unwrap() * rgh;
            sys.body = ancf_core::FluidBody::new(sys.body.mesh.clone(), fluid, quadrature).unwrap();
        }
        let g = sys.body.fluid.shear_stabilization / rgh;
        let modes = linear_modes(&mut sys, ts, &q).unwrap();
        let lam: Vec<String> = modes.omega_sq.iter().take(4).map(|w| format!("{:.4}", w * depth / G)).collect();
        let mut fl = [0.0; 2];
        for (k, axis) in [0usize, 1].into_iter().enumerate() {
            let d = modes.dominant(axis);
            fl[k] = modes.omega_sq[d].max(0.0).sqrt() / (2.0 * std::f64::consts::PI);
        }
        if std::env::var("SHAPE").is_ok() {
            for mode in 0..3 {
                let col = modes.shapes.col(mode);
                let n = col.nrows() / 12;
                let mut amp: Vec<(f64, usize)> =
                    (0..n).map(|k| ((0..3).map(|i| col[12 * k + i].powi(2)).sum::<f64>().sqrt(), k)).collect();
                let tot_pos: f64 = amp.iter().map(|a| a.0 * a.0).sum();
                let tot: f64 = (0..col.nrows()).map(|i| col[i] * col[i]).sum();
                amp.sort_by(|a, b| b.0.total_cmp(&a.0));
                print!("  mode {mode}: pos share {:.2}; top nodes", tot_pos / tot);
                for &(v, k) in amp.iter().take(4) {
                    print!(
                        " #{k} ({:.2},{:.2},{:.2}) d=[{:.2},{:.2},{:.2}]/{v:.2}",
                        q[12 * k],
                        q[12 * k + 1],
                        q[12 * k + 2],
                        col[12 * k],
                        col[12 * k + 1],
                        col[12 * k + 2]
                    );
                }
                println!();
            }
        }
        println!(
            "{kind} {nv}/{np}/{ppe} {c:?} beta {g} (G {:.2} Pa): lambda {} | f_x {:.4} Hz f_y {:.4} Hz",
            g * rgh,
            lam.join(" "),
            fl[0],
            fl[1]
        );
    }
}
