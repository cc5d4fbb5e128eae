//! Hertz normal contact (closed forms, elliptic integrals) and creep laws.

use rail_mbs::wheel_rail::{
    CreepModel, Creepages, HertzConstants, Material, combined_modulus, creep_forces, elliptic_ke, kalker_coefficients,
    linear_coefficients,
};

#[test]
fn elliptic_integrals_reference_values() {
    // K(m), E(m) for m = 0, 0.5, 0.9 (Abramowitz & Stegun, table 17.1).
    let cases = [
        (0.0, std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2),
        (0.5, 1.854_074_677_301_372, 1.350_643_881_047_675),
        (0.9, 2.578_092_113_348_173, 1.104_774_732_704_073),
    ];
    for (m, k, e) in cases {
        let (kk, ee) = elliptic_ke(m);
        assert!((kk - k).abs() < 1e-13 && (ee - e).abs() < 1e-13, "m = {m}: {kk} {ee}");
    }
    // Independent check by Simpson quadrature of the defining integrals.
    let m = 0.77;
    let n = 2000;
    let (mut k, mut e) = (0.0, 0.0);
    for i in 0..=n {
        let t = std::f64::consts::FRAC_PI_2 * i as f64 / n as f64;
        let w = if i == 0 || i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let s = (1.0 - m * t.sin().powi(2)).sqrt();
        k += w / s;
        e += w * s;
    }
    let h = std::f64::consts::FRAC_PI_2 / n as f64 / 3.0;
    let (kk, ee) = elliptic_ke(m);
    assert!((kk - k * h).abs() < 1e-10 && (ee - e * h).abs() < 1e-10);
}

#[test]
fn sphere_on_plane_and_crossed_cylinders() {
    let steel = Material::steel();
    let es = combined_modulus(&steel, &steel);
    assert!((es - steel.young / (2.0 * (1.0 - 0.09))).abs() < 1e-3);
    // Sphere of radius R on a plane == two crossed cylinders of radius R.
    let r = 0.46;
    let h = HertzConstants::new(0.5 / r, 0.5 / r, es).unwrap();
    for n in [1e3, 1e4, 1e5] {
        let a_exact = (3.0 * n * r / (4.0 * es)).cbrt();
        let (a, b) = h.semi_axes(n);
        assert!((a - a_exact).abs() < 1e-12 * a_exact.max(1.0) + 1e-15 && (b - a).abs() < 1e-15);
        let d_exact = a_exact * a_exact / r;
        assert!((h.penetration(n) - d_exact).abs() < 1e-9 * d_exact);
        assert!((h.force(d_exact) - n).abs() < 1e-8 * n);
    }
    let k_exact = 4.0 / 3.0 * es * r.sqrt();
    assert!((h.stiffness - k_exact).abs() < 1e-9 * k_exact);
}

#[test]
fn elliptical_contact_satisfies_hertz_relations() {
    // Wheel (R 0.46 m) crossed with a rail crown (R 0.3 m): A = 1/(2·0.46), B = 1/(2·0.3).
    let es = combined_modulus(&Material::steel(), &Material::steel());
    let (ca, cb) = (0.5 / 0.46, 0.5 / 0.30);
    let h = HertzConstants::new(ca, cb, es).unwrap();
    let n = 1e5;
    let (a, b) = h.semi_axes(n);
    assert!(a > b, "long axis along the smaller curvature");
    // Re-derive the curvatures from the semi-axes with Johnson's eq. (3.69) using
    // independently integrated elliptic integrals.
    let e2 = 1.0 - (b / a).powi(2);
    let m = 4000;
    let (mut kk, mut ee) = (0.0, 0.0);
    for i in 0..=m {
        let t = std::f64::consts::FRAC_PI_2 * i as f64 / m as f64;
        let w = if i == 0 || i == m {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let s = (1.0 - e2 * t.sin().powi(2)).sqrt();
        kk += w / s;
        ee += w * s;
    }
    let hq = std::f64::consts::FRAC_PI_2 / m as f64 / 3.0;
    let (kk, ee) = (kk * hq, ee * hq);
    let p0 = 3.0 * n / (2.0 * std::f64::consts::PI * a * b);
    let big_a = p0 * b / (es * a * a * e2) * (kk - ee);
    let big_b = p0 * b / (es * a * a * e2) * ((a / b).powi(2) * ee - kk);
    let delta = p0 * b * kk / es;
    assert!((big_a - ca).abs() < 1e-8 * ca, "A {big_a} vs {ca}");
    assert!((big_b - cb).abs() < 1e-8 * cb, "B {big_b} vs {cb}");
    assert!((h.penetration(n) - delta).abs() < 1e-8 * delta);
    // Swapping the curvatures swaps the axes.
    let hs = HertzConstants::new(cb, ca, es).unwrap();
    let (a2, b2) = hs.semi_axes(n);
    assert!((a2 - b).abs() < 1e-14 && (b2 - a).abs() < 1e-14);
    // Non-Hertzian input is an error, not a panic.
    assert!(HertzConstants::new(-1.0, 2.0, es).is_err());
    assert!(HertzConstants::new(1.0, f64::NAN, es).is_err());
}

#[test]
fn kalker_table_values_and_interpolation() {
    // Table nodes at nu = 0.25.
    let k = kalker_coefficients(1.0, 0.25);
    assert!((k.c11 - 4.12).abs() < 1e-12 && (k.c22 - 3.67).abs() < 1e-12 && (k.c23 - 1.47).abs() < 1e-12);
    let k = kalker_coefficients(0.5, 0.0);
    assert!((k.c11 - 2.88).abs() < 1e-12 && (k.c23 - 0.827).abs() < 1e-12);
    let k = kalker_coefficients(1.0 / 0.3, 0.5);
    assert!((k.c11 - 7.34).abs() < 1e-12 && (k.c22 - 7.51).abs() < 1e-12);
    // Between nodes: monotone in a/b and in nu.
    let k1 = kalker_coefficients(1.0 / 0.45, 0.28);
    let (lo, hi) = (kalker_coefficients(1.0 / 0.4, 0.28), kalker_coefficients(1.0 / 0.5, 0.28));
    assert!(k1.c11 < lo.c11 && k1.c11 > hi.c11);
    assert!(kalker_coefficients(1.0, 0.28).c11 > kalker_coefficients(1.0, 0.25).c11);
    // Asymptotes join the table reasonably at g = 0.1.
    let (t, a) = (kalker_coefficients(0.1, 0.25), kalker_coefficients(0.0999, 0.25));
    assert!((t.c11 - a.c11).abs() / t.c11 < 0.05, "{} {}", t.c11, a.c11);
}

#[test]
fn creep_laws_are_linear_at_small_creep_and_saturate() {
    let (a, b, n, mu) = (6e-3, 4e-3, 5e4, 0.3);
    let (g, nu) = (8.0e10, 0.28);
    let (f11, f22, f23, _f33) = linear_coefficients(a, b, g, nu);
    let small = Creepages { longitudinal: 1e-6, lateral: -2e-6, spin: 1e-5 };
    for model in [CreepModel::Linear, CreepModel::ShenHedrickElkins, CreepModel::Polach { k_a: 1.0, k_s: 1.0 }] {
        let f = creep_forces(model, &small, a, b, n, mu, g, nu);
        let fx = -f11 * small.longitudinal;
        let fy = -f22 * small.lateral - f23 * small.spin;
        assert!((f.longitudinal - fx).abs() < 1e-3 * fx.abs(), "{model:?}");
        assert!((f.lateral - fy).abs() < 1e-3 * fy.abs(), "{model:?}");
        // Large creepage: the resultant approaches mu N (and never exceeds it).
        let big = Creepages { longitudinal: 0.05, lateral: 0.02, spin: 0.0 };
        let f = creep_forces(model, &big, a, b, n, mu, g, nu);
        let res = f.longitudinal.hypot(f.lateral);
        if model != CreepModel::Linear {
            assert!(res <= mu * n * (1.0 + 1e-9) && res > 0.95 * mu * n, "{model:?}: {res}");
            // Direction follows the linear force (FASTSIM: the slip direction).
            let ratio = f.lateral / f.longitudinal;
            let lin =
                if matches!(model, CreepModel::Fastsim { .. }) { 0.02 / 0.05 } else { (f22 * 0.02) / (f11 * 0.05) };
            assert!((ratio - lin).abs() < 2e-2 * lin, "{model:?}: {ratio} vs {lin}");
        }
    }
    // Forces oppose the slip.
    let f = creep_forces(
        CreepModel::ShenHedrickElkins,
        &Creepages { longitudinal: 1e-3, lateral: 0.0, spin: 0.0 },
        a,
        b,
        n,
        mu,
        g,
        nu,
    );
    assert!(f.longitudinal < 0.0);
    // No load, no force.
    let z = creep_forces(CreepModel::ShenHedrickElkins, &small, a, b, 0.0, mu, g, nu);
    assert_eq!(z.longitudinal, 0.0);
    // Shen-Hedrick-Elkins at beta = 1: 1 - 1/3 + 1/27 of the linear force.
    let beta_one = Creepages { longitudinal: -mu * n / f11, lateral: 0.0, spin: 0.0 };
    let f = creep_forces(CreepModel::ShenHedrickElkins, &beta_one, a, b, n, mu, g, nu);
    assert!((f.longitudinal - mu * n * (1.0 - 1.0 / 3.0 + 1.0 / 27.0)).abs() < 1e-6 * mu * n);
}
