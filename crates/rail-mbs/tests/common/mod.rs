//! Helpers shared by integration tests.

use std::io::Write;

/// External reference data (`../shared/data`) are absent. Under CI (`CI` set), where the
/// data must be present, this fails the test; elsewhere the test is skipped with a line
/// written straight to the process's stderr, which the test harness does not capture, so
/// the skip shows in `cargo test` output instead of reading as a plain "ok".
#[allow(dead_code)] // the contact-helper test binaries do not read external data
pub fn data_missing(what: &str) {
    if std::env::var_os("CI").is_some_and(|v| !v.is_empty()) {
        panic!("{what}: reference data missing, but CI is set and the data must be present there");
    }
    let _ = writeln!(std::io::stderr(), "SKIPPED (data not found): {what}");
}

/// Wheel/rail contact helpers shared by the contact tests.
#[allow(dead_code)] // each test binary uses some of them
pub mod contact {
    use rail_mbs::profile::{s1002_wheel, uic60_rail};
    use rail_mbs::track::Side;
    use rail_mbs::wheel_rail::{RailGeometry, RailPath, WheelGeometry, WheelPose, WheelRailContact};

    /// An S1002 wheel (r0 = 0.46 m, profile 0.75 m from the wheelset centre) on a UIC 60 rail
    /// on `path`, the gauge point 14 mm below the crown at 1435/2 mm from the centreline.
    pub fn s1002_on_uic60(side: Side, path: RailPath) -> WheelRailContact {
        let rail = uic60_rail(2e-4).unwrap();
        let offset = RailGeometry::offset_for_gauge(&rail, 1.435, 0.014).unwrap();
        WheelRailContact::new(
            WheelGeometry { profile: s1002_wheel(2e-4).unwrap(), nominal_radius: 0.46, profile_offset: 0.75, side },
            RailGeometry { profile: rail, side, profile_offset: offset, vertical_offset: 0.0, path },
        )
    }

    /// The wheel-centre height at which the contact's total vertical force on the wheel is
    /// `fz` (N), by bisection within ± `bracket` m of the pose's height.
    pub fn height_for_load(c: &mut WheelRailContact, pose: &WheelPose, fz: f64, bracket: f64) -> f64 {
        let mut p = *pose;
        let mut f = |z: f64| {
            p.position.z = z;
            c.evaluate(&p).unwrap().iter().map(|q| q.force_on_wheel().z).sum::<f64>()
        };
        let (mut lo, mut hi) = (pose.position.z - bracket, pose.position.z + bracket);
        assert!(f(lo) > fz && f(hi) < fz, "bracket");
        for _ in 0..60 {
            let m = 0.5 * (lo + hi);
            if f(m) > fz { lo = m } else { hi = m }
        }
        0.5 * (lo + hi)
    }
}
