//! Track irregularities in the wheel/rail contact geometry (issue 20 §1): a cosine dip of
//! known depth shows up in the contact point's height as a wheel rolls slowly over it
//! (kinematics only, no dynamics), and every channel moves its rail the documented way.

use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};
use rail_mbs::track::{Channel, Defect, Irregularity, Side, Track, TrackPoint};
mod common;
use common::contact::s1002_on_uic60;
use rail_mbs::wheel_rail::{RailPath, WheelPose, WheelRailContact};

fn level_track() -> Track {
    Track::new(vec![
        TrackPoint::new(0.0, 0.0, 0.0, 0.0, 0.025, -0.025),
        TrackPoint::new(100.0, 0.0, 0.0, 0.0, 0.025, -0.025),
    ])
    .unwrap()
}

/// The wheel centre's height at which the wheel just touches the rail (zero penetration),
/// by fixed-point iteration on the penetration, and the contact point there.
fn touching(c: &mut WheelRailContact, x: f64, y: f64) -> (f64, Vector3<f64>) {
    let mut z = 0.45;
    for _ in 0..80 {
        let pose = WheelPose::at_rest(Vector3::new(x, y, z), Matrix3::identity());
        let g = c.find_geometry(&pose).unwrap();
        let Some(deepest) = g.iter().max_by(|a, b| a.penetration.total_cmp(&b.penetration)) else {
            z -= 1e-3; // apart beyond the search's reach: lower the wheel
            continue;
        };
        if deepest.penetration.abs() < 1e-12 {
            return (z, deepest.point_rail);
        }
        // penetration > 0 overlaps: lift the wheel by it (along the contact normal)
        z += deepest.penetration / deepest.normal.z.abs().max(0.5);
    }
    panic!("no touching height at x = {x}");
}

#[test]
fn a_cosine_dip_shows_in_the_contact_point_height_as_the_wheel_rolls_over_it() {
    let (start, length, depth) = (40.0, 3.0, 0.005);
    let mut irr = Irregularity::zero(0.0, 100.0, 0.02).unwrap();
    irr.add_defect(&Defect::CosineDip { start, length, depth }).unwrap();
    let dip = |s: f64| irr.value(Channel::Vertical, s);
    let perfect = Arc::new(level_track());
    let dipped = Arc::new(level_track().with_irregularity(irr.clone()));
    let mut on_perfect = s1002_on_uic60(Side::Left, RailPath::Track(perfect));
    let mut on_dipped = s1002_on_uic60(Side::Left, RailPath::Track(dipped));
    let y = 0.0015; // wheelset 1.5 mm to the left: a tread contact
    let mut deepest = 0.0_f64;
    let mut worst_point = 0.0_f64;
    let mut worst_centre = 0.0_f64;
    for k in 0..=120 {
        let x = 38.5 + 0.05 * k as f64; // the wheel rolls slowly across the dip, 5 cm a step
        let (z0, p0) = touching(&mut on_perfect, x, y);
        let (z1, p1) = touching(&mut on_dipped, x, y);
        // the contact point lies on the dipped rail: its height is the design rail's at the
        // same place plus the dip at the contact point's own distance
        let rail_lift = p1.z - p0.z;
        worst_point = worst_point.max((rail_lift - dip(p1.x)).abs());
        // the wheel centre follows the dip: to within the wheel's radius times the dip's
        // slope squared (r (1 − cos α) ≤ 0.46 × (π d / L)² / 2 = 6.3e-6 m)
        worst_centre = worst_centre.max(((z1 - z0) - dip(x)).abs());
        deepest = deepest.min(z1 - z0);
    }
    println!(
        "dip {depth} m: wheel centre lowest {deepest:.6} m, contact-point height error {worst_point:.2e} m, centre error {worst_centre:.2e} m"
    );
    assert!(worst_point < 1e-6, "contact point height off the dipped rail by {worst_point:e} m");
    assert!((deepest + depth).abs() < 1e-5, "the wheel centre dips {deepest} m, the rail {depth} m");
    assert!(worst_centre < 7e-6, "{worst_centre}");
}

#[test]
fn each_channel_moves_its_rail_as_documented() {
    let n = 101;
    let mut ch = [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
    let values = [0.004, 0.003, 0.002, 0.006]; // vertical, alignment, cross-level, gauge
    for (c, v) in ch.iter_mut().zip(values) {
        c.fill(v);
    }
    let irr = Irregularity::from_samples(0.0, 1.0, ch).unwrap();
    let track = level_track();
    let moved = level_track().with_irregularity(irr);
    let s = 50.0;
    let d = |side| moved.rail_point(s, side) - track.rail_point(s, side);
    let (l, r) = (d(Side::Left), d(Side::Right));
    // left rail: (a + g/2, v − c/2); right rail: (a − g/2, v + c/2), track frame = global here
    assert!((l.y - (0.003 + 0.003)).abs() < 1e-15 && (l.z - (0.004 - 0.001)).abs() < 1e-15, "{l:?}");
    assert!((r.y - (0.003 - 0.003)).abs() < 1e-15 && (r.z - (0.004 + 0.001)).abs() < 1e-15, "{r:?}");
    assert_eq!(l.x, 0.0);
    // the contact sees the same rail: a wheel touching the moved right rail sits higher by
    // v + c/2 (no lateral change for the right rail here)
    let mut c0 = s1002_on_uic60(Side::Right, RailPath::Track(Arc::new(level_track())));
    let mut c1 = s1002_on_uic60(Side::Right, RailPath::Track(Arc::new(moved.clone())));
    let (z0, _) = touching(&mut c0, s, -0.0015);
    let (z1, _) = touching(&mut c1, s, -0.0015);
    assert!(((z1 - z0) - 0.005).abs() < 1e-9, "{}", z1 - z0);
}

#[test]
fn a_wheel_rolling_over_an_irregular_rail_finds_the_same_contact_as_a_fresh_search() {
    // The search warm-starts from the previous solution; over an FRA class 5 vertical profile,
    // rolling and spinning in 1 mm steps for 20 m at a constant small penetration, every
    // contact (points and normal force) equals that of a search from scratch.
    use rail_mbs::track::{IrregularityPsd, TrackSpectrum};
    let mut p = IrregularityPsd::new(TrackSpectrum::Fra { class: 5 }, 1000.0);
    p.start = 58.0;
    p.taper = 5.0;
    p.channels = [true, false, false, false];
    let irr = Irregularity::generate(&p).unwrap();
    let track = Arc::new(level_track().with_irregularity(irr.clone()));
    let mut warm = s1002_on_uic60(Side::Left, RailPath::Track(track.clone()));
    let mut fresh = s1002_on_uic60(Side::Left, RailPath::Track(track));
    let mut misses = 0;
    for k in 0..20_000 {
        let x = 56.0 + 1e-3 * k as f64;
        let z = 0.46 + irr.value(Channel::Vertical, x) - 1.0e-4; // about 1e-4 m penetration
        let pose = WheelPose {
            position: Vector3::new(x, 0.0015, z),
            rotation: nalgebra::Rotation3::from_axis_angle(&Vector3::y_axis(), (x - 56.0) / 0.46).into_inner(),
            velocity: Vector3::new(16.7, 0.0, 0.0),
            angular_velocity: Vector3::new(0.0, 16.7 / 0.46, 0.0),
        };
        let a = warm.evaluate(&pose).unwrap();
        fresh.reset();
        let b = fresh.evaluate(&pose).unwrap();
        let (na, nb): (f64, f64) = (a.iter().map(|p| p.normal_force).sum(), b.iter().map(|p| p.normal_force).sum());
        assert!(nb > 1e3, "in contact at x = {x}");
        if a.len() != b.len() || (na - nb).abs() > 1e-6 * nb {
            misses += 1;
        }
    }
    assert_eq!(misses, 0, "{misses} of 20000 poses differ from a fresh search");
}
