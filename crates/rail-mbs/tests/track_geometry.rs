//! Track geometry: closed-form straight and circular track, spiral heading, Table 1 of
//! seed 000 in US units, balance speed, frames, rails and projection.

use nalgebra::Vector3;
use rail_mbs::track::{FOOT, GRAVITY, INCH, Side, Track, TrackError, TrackPoint, curvature_from_degree};

fn table1(cant_base: f64) -> Track {
    // Seed 000, Table 1 (rail_mbs::track::presets): distance (ft), curvature (deg),
    // super-elevation (in); grade 0, right/left rail cant 0.025/-0.025 rad.
    let rows = rail_mbs::track::presets::TABLE1_ROWS;
    let pts = rows.iter().map(|&(d, c, e)| TrackPoint::from_us(d, c, e, 0.0, 0.025, -0.025)).collect();
    Track::with_options(pts, Track::STANDARD_GAUGE, cant_base, Vector3::zeros(), 0.0).expect("table 1 track")
}

#[test]
fn straight_track_is_exact() {
    let pts = vec![TrackPoint::new(0.0, 0.0, 0.0, 0.02, 0.0, 0.0), TrackPoint::new(1000.0, 0.0, 0.0, 0.02, 0.0, 0.0)];
    let t = Track::new(pts).unwrap();
    let theta = 0.02f64.atan();
    for s in [0.0, 1.0, 123.456, 777.0, 1000.0, 1100.0, -50.0] {
        let r = t.position(s);
        let exact = Vector3::new(s * theta.cos(), 0.0, s * theta.sin());
        assert!((r - exact).norm() < 1e-10, "s = {s}: {r:?} vs {exact:?}");
        let f = t.frame(s);
        let rot = f.rotation;
        assert!((rot.transpose() * rot - nalgebra::Matrix3::identity()).norm() < 1e-12);
        assert!((rot.determinant() - 1.0).abs() < 1e-12);
        assert!((f.tangent() - Vector3::new(theta.cos(), 0.0, theta.sin())).norm() < 1e-12);
    }
}

#[test]
fn circular_track_matches_closed_form() {
    for &radius in &[500.0, -300.0] {
        let k = 1.0 / radius;
        let pts = vec![TrackPoint::new(0.0, k, 0.0, 0.0, 0.0, 0.0), TrackPoint::new(2000.0, k, 0.0, 0.0, 0.0, 0.0)];
        let t = Track::new(pts).unwrap();
        let mut worst = 0.0f64;
        for i in 0..=200 {
            let s = 10.0 * i as f64;
            let exact = Vector3::new(radius * (s * k).sin(), radius * (1.0 - (s * k).cos()), 0.0);
            worst = worst.max((t.position(s) - exact).norm());
            assert!((t.heading(s) - s * k).abs() < 1e-12);
        }
        println!("circle R = {radius} m: max position error {worst:.3e} m over 2 km");
        assert!(worst < 1e-9, "circle position error {worst}");
        // Positive curvature turns left: the lateral axis points to the centre.
        let f = t.frame(100.0);
        let centre = Vector3::new(0.0, radius, 0.0);
        let to_centre = (centre - f.origin).normalize() * radius.signum();
        assert!((to_centre - f.lateral()).norm() < 1e-9);
    }
}

#[test]
fn spiral_heading_is_integral_of_curvature() {
    // Straight 50 m, clothoid 0 -> 1/400 over 150 m, circle 100 m.
    let k1 = 1.0 / 400.0;
    let pts = vec![
        TrackPoint::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        TrackPoint::new(50.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        TrackPoint::new(200.0, k1, 0.1, 0.0, 0.0, 0.0),
        TrackPoint::new(300.0, k1, 0.1, 0.0, 0.0, 0.0),
    ];
    let t = Track::new(pts).unwrap();
    // Heading of the computed centreline (finite differences of the position) against
    // an independent trapezoidal integral of the interpolated curvature.
    let n = 30_000;
    let h = 300.0 / n as f64;
    let mut integral = 0.0;
    let mut x = Vector3::zeros();
    let mut worst_heading = 0.0f64;
    let mut worst_pos = 0.0f64;
    for i in 0..n {
        let (sa, sb) = (i as f64 * h, (i + 1) as f64 * h);
        integral += 0.5 * h * (t.curvature(sa) + t.curvature(sb));
        // Independent position: Simpson on the heading integral.
        let ang = |s: f64| {
            if s <= 50.0 {
                0.0
            } else if s <= 200.0 {
                0.5 * k1 / 150.0 * (s - 50.0).powi(2)
            } else {
                0.5 * k1 * 150.0 + k1 * (s - 200.0)
            }
        };
        let dir = |s: f64| Vector3::new(ang(s).cos(), ang(s).sin(), 0.0);
        x += (dir(sa) + dir(0.5 * (sa + sb)) * 4.0 + dir(sb)) * (h / 6.0);
        if (i + 1) % 1000 == 0 {
            let dp = (t.position(sb + 1e-4) - t.position(sb - 1e-4)) / 2e-4;
            let psi = dp.y.atan2(dp.x);
            worst_heading = worst_heading.max((psi - integral).abs());
            worst_pos = worst_pos.max((t.position(sb) - x).norm());
        }
    }
    println!("spiral: max heading error {worst_heading:.2e} rad, position error {worst_pos:.2e} m");
    assert!(worst_heading < 1e-7, "heading error {worst_heading}");
    assert!(worst_pos < 1e-8, "position error {worst_pos}");
    // End heading = 0.5 k1 150 + k1 100.
    assert!((t.heading(300.0) - (0.5 * k1 * 150.0 + k1 * 100.0)).abs() < 1e-12);
    // Super-elevation ramps linearly along the spiral.
    assert!((t.superelevation(125.0) - 0.05).abs() < 1e-12);
}

#[test]
fn table1_units_and_balance_speed() {
    let t = table1(1.44);
    // 3 degrees, arc definition: R = 5729.58/3 ft = 582.1 m.
    let r = 1.0 / t.curvature(400.0 * FOOT);
    println!("Table 1 curve radius {r:.2} m");
    assert!((r - 5729.578 / 3.0 * FOOT).abs() < 0.01);
    assert!((r - 582.0).abs() < 0.5);
    assert!((curvature_from_degree(-3.0) + 1.0 / r).abs() < 1e-15);
    assert!((t.superelevation(400.0 * FOOT) - 3.0 * INCH).abs() < 1e-15);
    let v = t.balance_speed(400.0 * FOOT).expect("curve has a balance speed");
    let v_kmh = v * 3.6;
    let v_check = (GRAVITY * r * 3.0 * INCH / 1.44).sqrt();
    println!("Table 1 balance speed with G = 1.44 m, h = 3 in: {v:.3} m/s = {v_kmh:.2} km/h");
    assert!((v - v_check).abs() < 1e-12);
    assert!((v_kmh - 60.0).abs() < 4.0, "seed 000 quotes roughly 60 km/h, got {v_kmh}");
    // The second (right-hand) curve has the same balance speed; tangent track has none.
    let v2 = t.balance_speed(1300.0 * FOOT).unwrap();
    assert!((v2 - v).abs() < 1e-12);
    assert!(t.balance_speed(50.0 * FOOT).is_none());
    // Spiral B-C: curvature halfway is 1.5 degrees.
    assert!((t.curvature(200.0 * FOOT) - curvature_from_degree(1.5)).abs() < 1e-15);
    // First curve turns left, second right.
    assert!(t.heading(700.0 * FOOT) > 0.1);
    let total = t.heading(2800.0 * FOOT);
    assert!(total.abs() < 1e-12, "equal and opposite curves: net heading {total}");
}

#[test]
fn superelevation_raises_the_outer_rail() {
    let t = table1(1.5);
    let s = 450.0 * FOOT; // left curve, right rail raised by 3 in over the cant base
    let rr = t.rail_point(s, Side::Right);
    let rl = t.rail_point(s, Side::Left);
    let dz = rr.z - rl.z;
    let expect = 3.0 * INCH * t.gauge() / 1.5;
    assert!((dz - expect).abs() < 1e-12, "rail height difference {dz} vs {expect}");
    assert!(((rr - rl).norm() - t.gauge()).abs() < 1e-12);
    // Second curve (right-hand): left rail raised.
    let s2 = 1350.0 * FOOT;
    assert!(t.rail_point(s2, Side::Left).z > t.rail_point(s2, Side::Right).z);
    // Inward cant: both rail up-axes tilt towards the track centre.
    for side in [Side::Left, Side::Right] {
        let fr = t.rail_frame(20.0, side, Vector3::zeros());
        let local_up = t.frame(20.0).rotation.transpose() * fr.up();
        assert!((t.rail_inward_cant(20.0, side) - 0.025).abs() < 1e-15);
        assert!((local_up.y + side.sign() * 0.025f64.sin()).abs() < 1e-12, "{side:?} rail up axis {local_up:?}");
    }
}

#[test]
fn projection_recovers_trajectory_coordinates() {
    let t = table1(1.5);
    for &(s, lat, vert) in &[(123.4, 0.3, 0.1), (180.0, -0.7, 0.9), (500.0, 1.0, -0.2)] {
        let f = t.frame(s);
        let p = f.origin + f.lateral() * lat + f.up() * vert;
        let pr = t.project(&p, None).unwrap();
        assert!((pr.s - s).abs() < 1e-8, "s {} vs {s}", pr.s);
        assert!((pr.lateral - lat).abs() < 1e-8);
        assert!((pr.vertical - vert).abs() < 1e-8);
        let pr2 = t.project(&p, Some(s + 3.0)).unwrap();
        assert!((pr2.s - s).abs() < 1e-8);
    }
}

#[test]
fn invalid_tables_are_rejected() {
    let p = |s: f64| TrackPoint::new(s, 0.0, 0.0, 0.0, 0.0, 0.0);
    assert_eq!(Track::new(vec![p(0.0)]).unwrap_err(), TrackError::TooFewPoints(1));
    assert!(matches!(Track::new(vec![p(0.0), p(10.0), p(10.0)]), Err(TrackError::NotIncreasing { index: 2, .. })));
    assert!(matches!(
        Track::new(vec![p(0.0), TrackPoint::new(5.0, f64::NAN, 0.0, 0.0, 0.0, 0.0)]),
        Err(TrackError::NonFinite { index: 1, field: "curvature" })
    ));
    assert!(matches!(
        Track::new(vec![p(0.0), TrackPoint::new(5.0, 0.0, 2.0, 0.0, 0.0, 0.0)]),
        Err(TrackError::SuperElevationTooLarge { .. })
    ));
}
