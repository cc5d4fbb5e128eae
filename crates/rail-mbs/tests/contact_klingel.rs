//! Klingel test: a free coned wheelset rolling slowly (kinematic rolling, no slip)
//! oscillates laterally with wavelength `2π √(r0 b / λ)`.
//!
//! The small wheelset model lives in this test: lateral displacement `y` and yaw `ψ`
//! integrated over the distance travelled with RK4,
//! `dy/dx = ψ`, `dψ/dx = −(r_L − r_R) / (2 b r0)`,
//! where the rolling radii `r_L`, `r_R` and the contact half-spacing `b` come from the
//! ECF-A contact search of each wheel (1:20 cone on UIC 60 rails) at every stage.

use nalgebra::{Matrix3, Vector3};
use rail_mbs::profile::{Profile, uic60_rail};
use rail_mbs::track::Side;
use rail_mbs::wheel_rail::{ContactGeometry, RailGeometry, RailPath, WheelGeometry, WheelPose, WheelRailContact};

const R0: f64 = 0.46;
const CONICITY: f64 = 0.05;

fn wheel_rail(side: Side) -> WheelRailContact {
    // Pure cone: radius grows towards the gauge side (negative u): z = λ u.
    let cone: Vec<(f64, f64)> = (0..=100)
        .map(|i| {
            let u = -0.04 + 1e-3 * i as f64;
            (u, CONICITY * u)
        })
        .collect();
    let rail = uic60_rail(2e-4).unwrap();
    let offset = RailGeometry::offset_for_gauge(&rail, 1.435, 0.014).unwrap();
    let mut c = WheelRailContact::new(
        WheelGeometry {
            profile: Profile::from_points("1:20 cone", &cone).unwrap(),
            nominal_radius: R0,
            profile_offset: 0.75,
            side,
        },
        RailGeometry {
            profile: rail,
            side,
            profile_offset: offset,
            vertical_offset: 0.0,
            path: RailPath::Straight { inward_cant: 0.0 },
        },
    );
    c.settings.scan_points = 200;
    c
}

fn rot_z(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// Rolling radius and contact point of one wheel at wheelset state (x, y, ψ).
fn contact(c: &mut WheelRailContact, x: f64, y: f64, psi: f64) -> (f64, ContactGeometry) {
    let pose = WheelPose::at_rest(Vector3::new(x, y, R0 - 1e-4), rot_z(psi));
    let g = c.find_geometry(&pose).expect("contact search");
    let g = *g.iter().max_by(|a, b| a.penetration.total_cmp(&b.penetration)).expect("a contact point");
    let u = g.params[2];
    (R0 - CONICITY * u, g)
}

#[test]
fn klingel_wavelength_of_a_coned_wheelset() {
    let mut left = wheel_rail(Side::Left);
    let mut right = wheel_rail(Side::Right);
    // Centred reference: rolling radius and half-spacing of the contact points.
    let (r_c, gl) = contact(&mut left, 0.0, 0.0, 0.0);
    let (_, gr) = contact(&mut right, 0.0, 0.0, 0.0);
    let b0 = 0.5 * (gl.point_rail.y - gr.point_rail.y);
    let expected = 2.0 * std::f64::consts::PI * (r_c * b0 / CONICITY).sqrt();
    println!("centred: r0 = {r_c:.5} m, b = {b0:.5} m, Klingel wavelength {expected:.3} m");

    let mut rhs = |x: f64, s: [f64; 2]| -> [f64; 2] {
        let (rl, pl) = contact(&mut left, x, s[0], s[1]);
        let (rr, pr) = contact(&mut right, x, s[0], s[1]);
        let b = 0.5 * (pl.point_rail.y - pr.point_rail.y);
        [s[1], -(rl - rr) / (2.0 * b * r_c)]
    };
    let h = 0.2;
    let mut x = 0.0;
    let mut s = [0.002, 0.0];
    let mut crossings = Vec::new();
    let mut amp = 0.0f64;
    while x < 3.2 * expected {
        let k1 = rhs(x, s);
        let k2 = rhs(x + 0.5 * h, [s[0] + 0.5 * h * k1[0], s[1] + 0.5 * h * k1[1]]);
        let k3 = rhs(x + 0.5 * h, [s[0] + 0.5 * h * k2[0], s[1] + 0.5 * h * k2[1]]);
        let k4 = rhs(x + h, [s[0] + h * k3[0], s[1] + h * k3[1]]);
        let next = [
            s[0] + h / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]),
            s[1] + h / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]),
        ];
        if s[0] > 0.0 && next[0] <= 0.0 {
            // Downward zero crossing, linear interpolation.
            crossings.push(x + h * s[0] / (s[0] - next[0]));
        }
        x += h;
        s = next;
        amp = amp.max(s[0].abs());
    }
    assert!(crossings.len() >= 3, "too few oscillations: {crossings:?}");
    let periods: Vec<f64> = crossings.windows(2).map(|w| w[1] - w[0]).collect();
    let measured = periods.iter().sum::<f64>() / periods.len() as f64;
    let err = (measured - expected) / expected;
    println!(
        "measured wavelength {measured:.3} m over {} periods, expected {expected:.3} m ({:+.2} %), max |y| {:.2} mm",
        periods.len(),
        100.0 * err,
        amp * 1e3
    );
    assert!(err.abs() < 0.03, "wavelength error {:.2} %", 100.0 * err);
    // Undamped kinematic motion: amplitude preserved.
    assert!((amp - 0.002).abs() < 1e-4, "amplitude {amp}");
}
