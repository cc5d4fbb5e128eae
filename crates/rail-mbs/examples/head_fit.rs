//! How the tank car's fluid mesh fits its ellipsoidal heads, and how its liquid settles
//! (issue 16 §6, docs/validation.md "A stable rest state"): prints the mesh's volume error, the
//! contact points of the reference mesh that overlap the walls and the largest gaps between the
//! front end face and the head, then runs the liquid at rest for `T` s (10⁴ Pa·s settling
//! viscosity, or the light crude itself with `WORK=1`) and prints, each second, the largest kinetic
//! energy of that second and the fastest node.
//!
//! `cargo run --release -p rail-mbs --example head_fit -- NX NY NZ HEAD T [stab]` with the element
//! counts, the head depth (m; the tank keeps `TankCarParams::standard`'s overall length) and
//! `stab` for the recommended shear stabilization.
use ancf_core::FluidBody;
use ancf_core::constants::GRAVITY as G;
use ancf_core::constitutive::Rheology;
use ancf_core::contact::{WallContact, WallContactLaw};
use ancf_core::element::QuadratureOptions;
use ancf_core::mesh::{CylinderTankSpec, cylinder_tank};
use ancf_core::shape::N_SHAPE;
use ancf_core::tank::TankGeometry;
use rail_mbs::defaults::{Oil, default_shear_stabilization, slosh_params};
use rail_mbs::slosh::{PrescribedMotion, SloshFrame, SloshRun, SloshSystem};
use rail_mbs::vehicle::TankCarParams;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let a: Vec<f64> = args[..5].iter().map(|s| s.parse().expect("a number")).collect();
    let c = [a[0] as usize, a[1] as usize, a[2] as usize];
    let (head, t_end) = (a[3], a[4]);
    let stabilized = args.get(5).map(String::as_str) == Some("stab");
    let p = TankCarParams::standard().unwrap();
    let spec = CylinderTankSpec { length: p.tank_length - 2.0 * head, head_depth: head, ..p.tank_spec(0.5, c) };
    let geo = TankGeometry::new(spec.shape(), vec![]).unwrap();
    let depth = spec.radius;
    let mut fluid = Oil::Light.fluid(depth, depth / c[2] as f64).unwrap();
    if std::env::var("WORK").is_err() {
        fluid.rheology = Rheology::Newtonian { viscosity: 1e4 };
    }
    if stabilized {
        fluid.shear_stabilization =
            default_shear_stabilization(fluid.density, depth / c[2] as f64, (head > 0.0).then_some(depth));
    }
    let rho = fluid.density;
    let body =
        FluidBody::new(cylinder_tank(&spec).unwrap(), fluid, QuadratureOptions { viscous: 3, penalty: 4, mass: 4 })
            .unwrap();
    println!(
        "mesh volume {:.4} m3, exact {:.4} m3, error {:.3e}",
        body.reference_volume(),
        body.mesh.exact_volume,
        body.reference_volume() / body.mesh.exact_volume - 1.0
    );
    let law = WallContactLaw { points_per_edge: 4, ..WallContactLaw::default_for(rho, G, depth) };
    let contact = WallContact::new(&body, geo, law).unwrap();
    // the reference mesh against the walls: overlaps anywhere, gaps of the front end face
    let e0 = body.reference_coordinates();
    let (mut hits, mut overlaps, mut gaps) = (Vec::new(), Vec::new(), Vec::new());
    let mut gap_volume = 0.0;
    for pt in &contact.points {
        let nodes = &body.mesh.elements[pt.element];
        let mut r = [0.0; 3];
        for (a, n) in pt.shape.iter().enumerate().take(N_SHAPE) {
            for (i, ri) in r.iter_mut().enumerate() {
                *ri += n * e0[3 * (4 * nodes[a / 4] + a % 4) + i];
            }
        }
        hits.clear();
        contact.geometry.hits_within(r, &pt.sides, 0.5, &mut hits);
        let psi = hits.iter().map(|h| h.psi).fold(f64::NEG_INFINITY, f64::max);
        if psi > 0.0 {
            overlaps.push((psi, pt.element, r));
        }
        if pt.wetted && r[0] > 0.5 * spec.length + 1e-6 {
            gaps.push((psi, pt.element, r));
            gap_volume += -psi.min(0.0) * pt.weight;
        }
    }
    overlaps.sort_by(|a, b| b.0.total_cmp(&a.0));
    gaps.sort_by(|a, b| a.0.total_cmp(&b.0));
    println!("{} of {} contact points overlap a wall; the deepest:", overlaps.len(), contact.points.len());
    for (psi, el, r) in overlaps.iter().take(4) {
        println!("  {:.2} mm, element {el}, at ({:.3}, {:.3}, {:.3})", 1e3 * psi, r[0], r[1], r[2]);
    }
    println!("front end face: {} contact points, gap volume {gap_volume:.4} m3; the widest gaps:", gaps.len());
    for (psi, el, r) in gaps.iter().take(4) {
        println!("  {:.1} mm, element {el}, at ({:.3}, {:.3}, {:.3})", -1e3 * psi, r[0], r[1], r[2]);
    }
    let sys =
        SloshSystem::new(body, contact, PrescribedMotion::at_rest([0.0; 3]), [0.0, 0.0, -G], SloshFrame::Inertial)
            .unwrap();
    let mut run = SloshRun::new(sys, 0.0, slosh_params()).unwrap();
    let mut t = 0.0;
    while t < t_end - 1e-9 {
        t += 1.0;
        run.run_to(t, 0.02).unwrap();
        let (q, v) = (run.stepper.q(), run.stepper.v());
        let speed = |k: usize| (0..3).map(|i| v[12 * k + i].powi(2)).sum::<f64>().sqrt();
        let k = (0..v.len() / 12).max_by(|&a, &b| speed(a).total_cmp(&speed(b))).unwrap();
        let r = &run.record;
        let ke = r.t.iter().zip(&r.kinetic_energy).filter(|(s, _)| **s > t - 1.0).fold(0.0f64, |m, (_, e)| m.max(*e));
        println!(
            "t = {t:.0} s: largest kinetic energy of the last second {ke:.3e} J; fastest node #{k} at ({:.3}, {:.3}, {:.3}), {:.2e} m/s",
            q[12 * k],
            q[12 * k + 1],
            q[12 * k + 2],
            speed(k)
        );
    }
}
