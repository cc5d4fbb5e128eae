//! Profiles: spline interpolation and derivatives, analytic S1002 / UIC60 / AAR-1B
//! sanity, SIMPACK and two-column readers (Manchester data and malformed input).

use std::path::PathBuf;

use rail_mbs::profile::{
    CubicSpline, Profile, ProfileError, ProfileKind, aar1b_wheel_approx, parse_simpack, parse_two_column, read_simpack,
    read_two_column, s1002_wheel, s1002_z, uic60_rail, uic60_z,
};

fn data_dir() -> Option<PathBuf> {
    let p = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/manchester-contact"));
    if p.join("MBench_S1002_v3.prw").is_file() {
        Some(p)
    } else {
        eprintln!("SKIP: Manchester profile data not found at {}", p.display());
        None
    }
}

#[test]
fn spline_interpolates_smooth_function() {
    let n = 61;
    let ys: Vec<f64> = (0..n).map(|i| 3.0 * i as f64 / (n - 1) as f64).collect();
    let zs: Vec<f64> = ys.iter().map(|y| y.sin()).collect();
    let sp = CubicSpline::new(&ys, &zs).unwrap();
    let mut worst = [0.0f64; 3];
    // Interior only: natural end conditions (z'' = 0) are wrong for sin at y = 3.
    for i in 0..1000 {
        let y = 0.3 + 2.4 * i as f64 / 999.0;
        let (z, d, dd) = sp.eval(y);
        worst[0] = worst[0].max((z - y.sin()).abs());
        worst[1] = worst[1].max((d - y.cos()).abs());
        worst[2] = worst[2].max((dd + y.sin()).abs());
    }
    println!("spline errors: value {:.2e}, slope {:.2e}, curvature {:.2e}", worst[0], worst[1], worst[2]);
    assert!(worst[0] < 2e-7, "value error {}", worst[0]);
    assert!(worst[1] < 2e-5, "slope error {}", worst[1]);
    assert!(worst[2] < 5e-3, "second-derivative error {}", worst[2]);
    // Knots are interpolated exactly.
    for (y, z) in ys.iter().zip(&zs) {
        assert!((sp.value(*y) - z).abs() < 1e-14);
    }
}

#[test]
fn spline_derivatives_match_finite_differences_and_are_c2() {
    // Irregular knots, arbitrary data.
    let ys = [0.0, 0.3, 0.35, 1.0, 1.7, 2.0, 2.9, 3.0, 4.4];
    let zs = [0.0, 0.5, 0.4, -0.2, 0.9, 1.1, 0.3, 0.2, 2.0];
    let sp = CubicSpline::new(&ys, &zs).unwrap();
    let h = 1e-6;
    for i in 0..400 {
        let y = 0.01 + 4.38 * i as f64 / 399.0;
        let (_, d, dd) = sp.eval(y);
        let fd1 = (sp.value(y + h) - sp.value(y - h)) / (2.0 * h);
        let fd2 = (sp.derivative(y + h) - sp.derivative(y - h)) / (2.0 * h);
        assert!((d - fd1).abs() < 1e-6 * (1.0 + d.abs()), "y {y}: {d} vs {fd1}");
        assert!((dd - fd2).abs() < 1e-5 * (1.0 + dd.abs()), "y {y}: {dd} vs {fd2}");
    }
    // C2 at interior knots: left and right limits agree.
    for &k in &ys[1..ys.len() - 1] {
        let e = 1e-9;
        let (l, r) = (sp.eval(k - e), sp.eval(k + e));
        assert!((l.0 - r.0).abs() < 1e-8 && (l.1 - r.1).abs() < 1e-6 && (l.2 - r.2).abs() < 1e-5);
    }
    // Natural end conditions.
    assert!(sp.second_derivative(0.0).abs() < 1e-12);
    assert!(sp.second_derivative(4.4).abs() < 1e-12);
    // Invalid input is an error, not a panic.
    assert!(matches!(
        CubicSpline::new(&[0.0, 1.0, 1.0], &[0.0, 1.0, 2.0]),
        Err(ProfileError::NotIncreasing { index: 2, .. })
    ));
    assert!(CubicSpline::new(&[0.0], &[0.0]).is_err());
    assert!(CubicSpline::new(&[0.0, 1.0], &[0.0, f64::NAN]).is_err());
}

#[test]
fn s1002_analytic_sanity() {
    // Nominal point: the tape line (y = 0) is the profile origin.
    assert!(s1002_z(0.0).unwrap().abs() < 1e-12);
    // Flange height 28 mm (tip of the R12 arc at y = -55 mm).
    let mut zmin = f64::INFINITY;
    let mut ymin = 0.0;
    for i in 0..=13_000 {
        let y = -0.070 + 0.130 * i as f64 / 13_000.0;
        let z = s1002_z(y).unwrap();
        if z < zmin {
            zmin = z;
            ymin = y;
        }
    }
    println!("S1002 flange tip: z = {:.4} mm at y = {:.3} mm", zmin * 1e3, ymin * 1e3);
    assert!((zmin + 0.028).abs() < 1e-6);
    assert!((ymin + 0.055).abs() < 2e-5);
    // Section boundaries are continuous to better than 2 micrometres.
    for b in [32.15796, -26.0, -35.0, -38.426669071, -39.764473993, -49.662510381, -62.764705882] {
        let y = b / 1000.0;
        let jump = (s1002_z(y + 1e-9).unwrap() - s1002_z(y - 1e-9).unwrap()).abs();
        assert!(jump < 2e-6, "jump {jump} m at {b} mm");
    }
    // The flange flank (section E) has the 70 deg flange angle: slope 2.7475.
    let p = s1002_wheel(1e-4).unwrap();
    let slope = p.eval(-0.0391).1;
    assert!((slope - 2.747_477).abs() < 0.01, "flank slope {slope}");
    // Field side: the 1:15 cone (slope 0.0667, radius decreasing outwards).
    assert!((p.eval(0.045).1 - 1.0 / 15.0).abs() < 1e-3);
    assert!(s1002_z(0.061).is_none() && s1002_z(-0.0701).is_none());
}

#[test]
fn uic60_and_aar_sanity() {
    let r = uic60_rail(1e-4).unwrap();
    let (yt, zt) = r.highest_point();
    assert!(yt.abs() < 1e-6 && zt.abs() < 1e-12, "crown at ({yt}, {zt})");
    // Crown curvature R300 and the 72 mm head width at 14 mm depth.
    assert!((r.curvature(0.0) + 1.0 / 0.3).abs() < 0.01 / 0.3);
    let yg = r.crossing(0.0, -1.0, -0.014).unwrap();
    assert!((yg + 0.036).abs() < 1e-5, "gauge point {yg}");
    assert!((uic60_z(0.02).unwrap() - uic60_z(-0.02).unwrap()).abs() < 1e-15);
    // R13 corner: the analytic head reaches curvature -1/0.013 between 26 and 36 mm
    // (finite differences of uic60_z, not of the sampled spline).
    let h = 1e-5;
    let kmin = (2600..3550)
        .map(|i| {
            let y = i as f64 * 1e-5;
            let (zm, z0, zp) = (uic60_z(y - h).unwrap(), uic60_z(y).unwrap(), uic60_z(y + h).unwrap());
            let d1 = (zp - zm) / (2.0 * h);
            let d2 = (zp - 2.0 * z0 + zm) / (h * h);
            d2 / (1.0 + d1 * d1).powf(1.5)
        })
        .fold(f64::INFINITY, f64::min);
    println!("UIC60 corner curvature {kmin:.2} 1/m");
    assert!((kmin + 1.0 / 0.013).abs() < 0.02 / 0.013, "corner curvature {kmin}");

    let w = aar1b_wheel_approx().unwrap();
    // 1:20 taper on the tread (z up: radius decreases outwards).
    assert!((w.eval(0.030).1 - 0.05).abs() < 1e-6);
    assert!(w.z(0.0).abs() < 1e-9);
    // 75 degree flange face.
    let max_slope = (0..400).map(|i| w.eval(-0.040 - 1e-5 * (i as f64 * 3.0)).1).fold(0.0f64, f64::max);
    assert!((max_slope - 75f64.to_radians().tan()).abs() < 0.05, "flange slope {max_slope}");
    let (_, ztip) = (0..600)
        .map(|i| {
            let y = -0.070 + 0.03 * i as f64 / 599.0;
            (y, w.z(y))
        })
        .fold((0.0, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
    println!("AAR-1B approx flange height {:.2} mm", -ztip * 1e3);
    assert!((-ztip - 0.0254).abs() < 1.5e-3);
}

#[test]
fn manchester_profiles_read_and_match_analytic() {
    let Some(dir) = data_dir() else {
        return;
    };
    let w = read_simpack(dir.join("MBench_S1002_v3.prw")).unwrap();
    assert_eq!(w.kind, ProfileKind::Wheel);
    assert!(w.mirror_y && !w.mirror_z);
    assert_eq!(w.length_factor, 1000.0);
    assert!(w.comment.contains("S1002"));
    let wp = w.to_profile().unwrap();
    let (lo, hi) = wp.y_range();
    println!("S1002 file: {} points, y in [{:.2}, {:.2}] mm", w.raw_points.len(), lo * 1e3, hi * 1e3);
    assert!(lo < -0.069 && lo > -0.070 && hi > 0.059);
    // Compare with the analytic definition over the running surface.
    let mut worst = 0.0f64;
    for i in 0..=1000 {
        let y = -0.065 + 0.120 * i as f64 / 1000.0;
        worst = worst.max((wp.z(y) - s1002_z(y).unwrap()).abs());
    }
    println!("S1002 file vs analytic: max |dz| = {:.4} mm", worst * 1e3);
    assert!(worst < 0.05e-3, "S1002 file deviates {worst} m from the analytic profile");

    let r = read_simpack(dir.join("MBench_UIC60_v3.prr")).unwrap();
    assert_eq!(r.kind, ProfileKind::Rail);
    assert!(!r.mirror_y);
    let rp = r.to_profile().unwrap();
    // Un-cant the file (1:40) about its crown and compare with the analytic head.
    let ang = (1.0f64 / 40.0).atan();
    let (c, s) = (ang.cos(), ang.sin());
    let pts: Vec<(f64, f64)> = r
        .raw_points
        .iter()
        .filter(|p| p.1 < 12.0) // head top only; the canted side faces are near vertical
        .map(|&(y, z)| {
            let (y, z) = (y / 1000.0, -z / 1000.0);
            // The file's head is tilted towards its gauge side (negative y): rotate it back.
            (c * y + s * z, -s * y + c * z)
        })
        .collect();
    let un = Profile::from_points("uncanted", &pts).unwrap();
    let (yt, zt) = un.highest_point();
    let a = uic60_rail(1e-4).unwrap();
    let mut worst = 0.0f64;
    for i in 0..=400 {
        let y = -0.032 + 0.064 * i as f64 / 400.0;
        worst = worst.max(((un.z(yt + y) - zt) - a.z(y)).abs());
    }
    println!(
        "UIC60 file (uncanted, crown at y = {:.2} mm) vs analytic over |y| < 32 mm: max |dz| = {:.3} mm",
        yt * 1e3,
        worst * 1e3
    );
    assert!(worst < 0.1e-3, "UIC60 analytic head deviates {worst} m from the file");
    let _ = rp;
}

#[test]
fn malformed_files_give_clear_errors() {
    let ok = "! header\n  header.begin\n    type = 0\n  header.end\n  spline.begin\n    units.len.f = 1000\n    point.begin\n 0 0\n 1 0.1\n 2 0.4\n    point.end\n  spline.end\n";
    let p = parse_simpack(ok, "ok.prr").unwrap();
    assert_eq!(p.raw_points.len(), 3);
    assert_eq!(p.to_profile().unwrap().y_range(), (0.0, 0.002));

    let bad_number = ok.replace(" 1 0.1", " 1 abc");
    match parse_simpack(&bad_number, "bad.prr") {
        Err(e @ ProfileError::Parse { line: 9, .. }) => {
            let msg = e.to_string();
            assert!(msg.contains("bad.prr:9") && msg.contains("abc"), "{msg}");
        }
        other => panic!("expected parse error at line 9, got {other:?}"),
    }
    let unclosed = ok.replace("    point.end\n", "");
    assert!(matches!(parse_simpack(&unclosed, "u.prr"), Err(ProfileError::Parse { .. })));
    let no_type = ok.replace("    type = 0\n", "");
    let e = parse_simpack(&no_type, "nt.prr").unwrap_err().to_string();
    assert!(e.contains("nt.prr") && e.contains("type"), "{e}");
    let no_points = "header.begin\n type = 1\nheader.end\n";
    assert!(parse_simpack(no_points, "np.prw").is_err());
    let dup = ok.replace(" 2 0.4", " 1 0.4");
    assert!(parse_simpack(&dup, "dup.prr").unwrap().to_profile().is_err());

    let two = "# y z\n0.0 1.0\n1.0, 2.0\n2.0;3.0;1\n";
    assert_eq!(parse_two_column(two, "t.txt").unwrap().len(), 3);
    let e = parse_two_column("0 1\n1 2 3 4\n", "four.txt").unwrap_err().to_string();
    assert!(e.contains("four.txt:2"), "{e}");
    assert!(parse_two_column("0 1\n1 inf\n", "inf.txt").is_err());
    assert!(parse_two_column("0 1\n", "one.txt").is_err());
    // From disk: a temporary two-column file in mm, converted by the caller.
    let path = std::env::temp_dir().join(format!("railslosh_profile_{}.txt", std::process::id()));
    std::fs::write(&path, "% y z (mm)\n-10 0.5\n0 0\n10 0.5\n").unwrap();
    let pts = read_two_column(&path).unwrap();
    let _ = std::fs::remove_file(&path);
    let mm: Vec<(f64, f64)> = pts.iter().map(|p| (p.0 / 1e3, p.1 / 1e3)).collect();
    let prof = Profile::from_points("disk", &mm).unwrap();
    assert!((prof.z(0.01) - 0.5e-3).abs() < 1e-15 && prof.z(0.0).abs() < 1e-15);
    let e = read_two_column("/nonexistent/profile.txt").unwrap_err().to_string();
    assert!(e.contains("/nonexistent/profile.txt"), "{e}");
    assert!(matches!(read_simpack("/nonexistent/x.prr"), Err(ProfileError::Io { .. })));
}
