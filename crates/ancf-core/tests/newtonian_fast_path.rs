//! The closed-form Newtonian kernel of the deviatoric stress (`newtonian_stress`, taken by
//! `Fluid::deviatoric_stress` for effectively Newtonian fluids) against the generic kernel,
//! finite differences, rigid motion and the element Jacobians; and the detection of
//! effectively Newtonian laws against `Rheology::two_eta` itself.

use ancf_core::constitutive::{DeviatoricPath, Fluid, M3, Rheology, Tangent, newtonian_stress};
use ancf_core::element::VolumetricJacobian::{Generic, Structured};
use ancf_core::element::{ElementRef, QuadratureOptions, ShapeTables, box_element, to_compact};
use ancf_core::rng::Rng;
use ancf_core::shape::N_COORDS;

fn fluid(rheology: Rheology) -> Fluid {
    Fluid::new(850.0, rheology, 1.0e6).unwrap()
}

/// Laws whose 2η(s) is constant: every one must be detected and take the fast kernel.
fn newtonian_laws() -> Vec<Rheology> {
    vec![
        Rheology::Newtonian { viscosity: 0.8 },
        Rheology::Oldroyd { viscosity: 0.005, yield_stress: 0.0, elastic_modulus: None },
        Rheology::Oldroyd { viscosity: 3.0, yield_stress: 0.0, elastic_modulus: Some(500.0) },
        Rheology::Bingham { viscosity: 0.5, yield_stress: 0.0 },
        Rheology::Casson { viscosity: 0.4, yield_stress: 0.0 },
        Rheology::HerschelBulkley { consistency: 0.7, power_index: 1.0, yield_stress: 0.0 },
        Rheology::HerschelBulkley { consistency: 0.0, power_index: 0.6, yield_stress: 0.0 },
    ]
}

/// Laws whose 2η(s) depends on s (or that have an elastic branch).
fn non_newtonian_laws() -> Vec<Rheology> {
    vec![
        Rheology::Bingham { viscosity: 0.5, yield_stress: 3.0 },
        Rheology::Bingham { viscosity: 0.0, yield_stress: 3.0 },
        Rheology::Oldroyd { viscosity: 0.5, yield_stress: 40.0, elastic_modulus: Some(800.0) },
        Rheology::Oldroyd { viscosity: 0.5, yield_stress: 1e-3, elastic_modulus: None },
        Rheology::Casson { viscosity: 0.4, yield_stress: 2.5 },
        Rheology::Casson { viscosity: 0.0, yield_stress: 2.5 },
        Rheology::HerschelBulkley { consistency: 0.7, power_index: 0.6, yield_stress: 0.0 },
        Rheology::HerschelBulkley { consistency: 0.7, power_index: 1.4, yield_stress: 0.0 },
        Rheology::HerschelBulkley { consistency: 0.7, power_index: 1.0, yield_stress: 2.0 },
        Rheology::HerschelBulkley { consistency: 0.0, power_index: 1.0, yield_stress: 2.0 },
    ]
}

fn random_m3(rng: &mut Rng, s: f64) -> M3 {
    M3::from_fn(|_, _| s * rng.uniform())
}

/// A random deformation gradient with det F > 0, well away from singular.
fn random_f(rng: &mut Rng) -> M3 {
    loop {
        let f = M3::identity() * (0.5 + rng.uniform().abs()) + random_m3(rng, 0.4);
        if f.determinant() > 0.2 {
            return f;
        }
    }
}

fn max_abs(t: &Tangent) -> f64 {
    t.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()))
}

fn max_diff(a: &Tangent, b: &Tangent) -> f64 {
    a.iter().flatten().zip(b.iter().flatten()).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

/// Stress and both tangents through the given kernel.
fn eval(fl: &Fluid, f: &M3, fd: &M3, path: DeviatoricPath) -> (M3, Tangent, Tangent) {
    let (mut tf, mut tv) = ([[0.0; 9]; 9], [[0.0; 9]; 9]);
    let p = fl.deviatoric_stress_with(f, fd, Some((&mut tf, &mut tv)), path).unwrap();
    (p, tf, tv)
}

#[test]
fn detection_agrees_with_two_eta_for_every_law() {
    // constant_two_eta must be Some(c) exactly when two_eta(s) = (c, 0) for all s > 0.
    let ss = [1e-4, 1e-2, 0.3, 1.0, 7.0, 1e3];
    for r in newtonian_laws() {
        let c = r.constant_two_eta().unwrap_or_else(|| panic!("{r:?} not detected as Newtonian"));
        assert!(r.is_effectively_newtonian());
        for s in ss {
            let (a, da) = r.two_eta(s);
            assert_eq!(a, c, "{r:?} at s = {s}");
            assert_eq!(da, 0.0, "{r:?} at s = {s}");
        }
    }
    for r in non_newtonian_laws() {
        assert_eq!(r.constant_two_eta(), None, "{r:?} detected as Newtonian");
        assert!(!r.is_effectively_newtonian());
        let fl = fluid(r);
        assert!(!fl.is_effectively_newtonian(), "{r:?}");
        // either 2η varies with s, or the fluid has the elastic branch
        let varies = ss.iter().any(|&s| r.two_eta(s).1 != 0.0 || r.two_eta(s).0 != r.two_eta(1.0).0);
        assert!(varies || fl.has_elastic_branch(), "{r:?}: constant 2η but rejected");
    }
    for r in newtonian_laws() {
        let fl = fluid(r);
        assert!(!fl.has_elastic_branch());
        assert_eq!(fl.newtonian_two_eta(), r.constant_two_eta());
    }
}

#[test]
fn fast_kernel_equals_generic_kernel_on_random_states() {
    let mut rng = Rng::new(7);
    for r in newtonian_laws() {
        let fl = fluid(r);
        for _ in 0..50 {
            let f = random_f(&mut rng);
            let fd = random_m3(&mut rng, 2.0);
            let (p0, tf0, tv0) = eval(&fl, &f, &fd, DeviatoricPath::Auto);
            let (p1, tf1, tv1) = eval(&fl, &f, &fd, DeviatoricPath::Generic);
            // the same stress operations: bit-identical
            assert_eq!(p0, p1, "{r:?}");
            let (sf, sv) = (max_abs(&tf1), max_abs(&tv1));
            if fl.newtonian_two_eta() == Some(0.0) {
                assert!(p0.norm() == 0.0 && max_abs(&tf0) == 0.0 && max_abs(&tv0) == 0.0 && sf == 0.0 && sv == 0.0);
                continue;
            }
            assert!(sf > 0.0 && sv > 0.0);
            let (ef, ev) = (max_diff(&tf0, &tf1) / sf, max_diff(&tv0, &tv1) / sv);
            assert!(ef < 1e-12 && ev < 1e-12, "{r:?}: dF {ef:e}, dFdot {ev:e}");
        }
    }
}

#[test]
fn fast_kernel_tangents_match_central_differences() {
    let mut rng = Rng::new(11);
    let two_eta = 1.6;
    for _ in 0..20 {
        let f = random_f(&mut rng);
        let fd = random_m3(&mut rng, 1.5);
        let (mut tf, mut tv) = ([[0.0; 9]; 9], [[0.0; 9]; 9]);
        newtonian_stress(two_eta, &f, &fd, Some((&mut tf, &mut tv))).unwrap();
        let h = 1e-6;
        let (mut ef, mut ev) = (0.0f64, 0.0f64);
        for kl in 0..9 {
            let mut dx = M3::zeros();
            dx[(kl / 3, kl % 3)] = h;
            let dpf = (newtonian_stress(two_eta, &(f + dx), &fd, None).unwrap()
                - newtonian_stress(two_eta, &(f - dx), &fd, None).unwrap())
                / (2.0 * h);
            let dpv = (newtonian_stress(two_eta, &f, &(fd + dx), None).unwrap()
                - newtonian_stress(two_eta, &f, &(fd - dx), None).unwrap())
                / (2.0 * h);
            for ij in 0..9 {
                ef = ef.max((tf[ij][kl] - dpf[(ij / 3, ij % 3)]).abs());
                ev = ev.max((tv[ij][kl] - dpv[(ij / 3, ij % 3)]).abs());
            }
        }
        let (ef, ev) = (ef / max_abs(&tf), ev / max_abs(&tv));
        assert!(ef < 1e-7 && ev < 1e-7, "FD error dF {ef:e}, dFdot {ev:e}");
    }
}

#[test]
fn rigid_motion_gives_zero_newtonian_stress() {
    // Ḟ = W F with W skew: L = W, D = 0, so P = 0 for every F; a stretching rate of the
    // same size gives a stress of order 2η|W||F⁻¹|.
    let mut rng = Rng::new(5);
    let fl = fluid(Rheology::Newtonian { viscosity: 2.0 });
    for _ in 0..20 {
        let f = random_f(&mut rng);
        let [a, b, c] = rng.vec3(3.0);
        let w = M3::new(0.0, -c, b, c, 0.0, -a, -b, a, 0.0);
        let rigid = fl.deviatoric_stress(&f, &(w * f), None).unwrap();
        let stretch = fl.deviatoric_stress(&f, &(w.abs() * f), None).unwrap();
        assert!(stretch.norm() > 0.1, "reference stress {}", stretch.norm());
        assert!(rigid.norm() <= 1e-13 * stretch.norm(), "rigid-motion stress {:e}", rigid.norm());
    }
}

#[test]
fn non_newtonian_fluids_do_not_take_the_fast_kernel() {
    // Auto must equal the generic kernel bit for bit, and differ from the Newtonian kernel
    // with the law's high-rate viscosity.
    let mut rng = Rng::new(3);
    for r in non_newtonian_laws() {
        let fl = fluid(r);
        for _ in 0..5 {
            let f = random_f(&mut rng);
            let fd = random_m3(&mut rng, 0.5);
            let (p0, tf0, tv0) = eval(&fl, &f, &fd, DeviatoricPath::Auto);
            let (p1, tf1, tv1) = eval(&fl, &f, &fd, DeviatoricPath::Generic);
            assert_eq!((p0, tf0, tv0), (p1, tf1, tv1), "{r:?}");
            let two_eta = r.two_eta(1e9).0;
            let pn = newtonian_stress(two_eta, &f, &fd, None).unwrap();
            assert!((p0 - pn).norm() > 1e-6 * p0.norm(), "{r:?}: Newtonian stress returned");
        }
    }
}

#[test]
fn element_force_and_jacobians_equal_between_kernels() {
    // A distorted curved element with velocities, both volumetric paths, 3³ and 4³ viscous rules.
    let mut rng = Rng::new(17);
    for viscous in [3, 4] {
        let tables = ShapeTables::new(QuadratureOptions { viscous, penalty: 3, mass: 4 }).unwrap();
        let l = [0.5, 0.3, 0.25];
        let e0 = box_element([0.1, -0.2, 0.3], l);
        let el = ElementRef::new(0, &e0, l, &tables).unwrap();
        let e: Vec<f64> = e0.iter().flatten().map(|x| x + 0.04 * rng.uniform()).collect();
        let v: Vec<f64> = e.iter().map(|_| 0.5 * rng.uniform()).collect();
        let (ec, vc) = (to_compact(&e), to_compact(&v));
        for r in newtonian_laws().into_iter().filter(|r| r.constant_two_eta() != Some(0.0)) {
            let mut fl = fluid(r);
            fl.bulk_damping = 300.0;
            for vol in [Structured, Generic] {
                let mut f = [[0.0; N_COORDS]; 2];
                let mut kk = [vec![0.0; N_COORDS * N_COORDS], vec![0.0; N_COORDS * N_COORDS]];
                let mut cc = kk.clone();
                let [f0, f1] = &mut f;
                let [k0, k1] = &mut kk;
                let [c0, c1] = &mut cc;
                el.internal_force_paths(0, &fl, &tables, (&ec, &vc), f0, Some((k0, c0)), vol, DeviatoricPath::Auto)
                    .unwrap();
                el.internal_force_paths(0, &fl, &tables, (&ec, &vc), f1, Some((k1, c1)), vol, DeviatoricPath::Generic)
                    .unwrap();
                assert_eq!(f[0], f[1], "{r:?}: forces differ");
                let rel = |a: &[f64], b: &[f64]| {
                    let s = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                    assert!(s > 0.0);
                    a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / s
                };
                let (dk, dc) = (rel(&kk[0], &kk[1]), rel(&cc[0], &cc[1]));
                assert!(dk < 1e-12 && dc < 1e-12, "{r:?}, {vol:?}, rule {viscous}: dK {dk:e}, dC {dc:e}");
                // and the default entry point takes the fast kernel
                let mut f2 = [0.0; N_COORDS];
                el.internal_force(0, &fl, &tables, &ec, &vc, &mut f2, None).unwrap();
                assert_eq!(f2, f[0]);
            }
        }
    }
}
