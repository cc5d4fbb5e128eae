//! Friction that varies over the rail profile (issue 21): in a two-point contact (tread and
//! flange root) each patch's creep force follows the μ of its own location and saturates there.

use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};
use rail_mbs::profile::uic60_rail;
use rail_mbs::track::Side;
mod common;
use common::contact::{height_for_load, s1002_on_uic60};
use rail_mbs::wheel_rail::{FrictionMap, RailPath, WheelPose, WheelRailContact};

fn right_wheel() -> WheelRailContact {
    s1002_on_uic60(Side::Right, RailPath::Straight { inward_cant: 1.0 / 40.0 })
}

#[test]
fn each_patch_saturates_at_the_friction_of_its_own_location() {
    let mut c = right_wheel();
    // a two-point contact: the wheelset pushed towards the right rail's gauge face
    let mut found = None;
    for i in 0..=70 {
        let y = -0.0048 - 2e-5 * i as f64;
        let pose = WheelPose::at_rest(Vector3::new(0.0, y, 0.46), Matrix3::identity());
        let z = height_for_load(&mut c, &pose, 1e4, 0.01);
        let pose = WheelPose { position: Vector3::new(0.0, y, z), ..pose };
        let pts = c.evaluate(&pose).unwrap();
        if pts.len() == 2 && pts.iter().all(|p| p.normal_force > 500.0) {
            found = Some(pose);
            break;
        }
    }
    let pose = found.expect("a two-point contact between 4.8 and 6.2 mm");
    let pts = c.evaluate(&pose).unwrap();
    let v: Vec<f64> = pts.iter().map(|p| p.geometry.params[1]).collect();
    // the rail coordinate of the flange-root point is the smaller (gauge side): a map with
    // μ = 0.1 there and 0.4 at the tread point, changing midway
    let (v_flange, v_tread) = (v[0].min(v[1]), v[0].max(v[1]));
    let mid = 0.5 * (v_flange + v_tread);
    let map = FrictionMap { profile: vec![(mid - 1e-4, 0.1), (mid + 1e-4, 0.4)], along_track: vec![] };
    map.validate().unwrap();
    c.friction_map = Some(Arc::new(map));
    // rolling at 20 m/s with a large lateral slip (η ≈ 0.05): full sliding in both patches
    let rolling = WheelPose {
        velocity: Vector3::new(20.0, 1.0, 0.0),
        angular_velocity: Vector3::new(0.0, 20.0 / 0.46, 0.0),
        ..pose
    };
    let pts = c.evaluate(&rolling).unwrap();
    assert_eq!(pts.len(), 2);
    for p in &pts {
        let tangential = (p.creep.longitudinal.powi(2) + p.creep.lateral.powi(2)).sqrt();
        let expected = if p.geometry.params[1] < mid { 0.1 } else { 0.4 };
        println!(
            "patch at rail v = {:.2} mm: N = {:.0} N, |F_t|/N = {:.4} (μ = {expected})",
            p.geometry.params[1] * 1e3,
            p.normal_force,
            tangential / p.normal_force
        );
        assert!((tangential / p.normal_force - expected).abs() < 1e-9, "saturates at its own μ");
        assert_eq!(c.friction_at(&p.geometry.params), expected);
    }
    // the uniform map is the scalar friction
    c.friction_map = Some(Arc::new(FrictionMap::uniform(0.3).unwrap()));
    c.reset();
    let a = c.evaluate(&rolling).unwrap();
    c.friction_map = None;
    c.friction = 0.3;
    c.reset();
    let b = c.evaluate(&rolling).unwrap();
    for (p, q) in a.iter().zip(&b) {
        assert_eq!(p.creep, q.creep);
    }
}

#[test]
fn the_lubricated_gauge_face_preset_splits_the_head_at_the_running_band_edge() {
    let rail = uic60_rail(2e-4).unwrap();
    let m = FrictionMap::lubricated_gauge_face(&rail, 0.4, 0.1, 0.003, 0.002).unwrap();
    let (y_top, z_top) = rail.highest_point();
    let v = rail.crossing(y_top, -1.0, z_top - 0.003).unwrap();
    assert!(v < y_top);
    assert_eq!(m.mu(0.0, v - 1e-3), 0.1);
    assert_eq!(m.mu(0.0, y_top), 0.4);
    assert!((m.mu(0.0, v + 1e-3) - 0.25).abs() < 1e-12);
    let e = FrictionMap::lubricated_gauge_face(&rail, 0.4, 0.1, 0.5, 0.002).unwrap_err().to_string();
    assert!(e.contains("`depth` = 0.5"), "{e}");
}
