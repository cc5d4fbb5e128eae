//! The contact of the S1002 wheel on UIC 60 (1:40) across the flange root: the left wheel
//! swept toward the flange, each contact point printed with its lateral place on the wheel
//! (from the wheelset centre), penetration, relative curvatures (the local `B` at the point,
//! and `B_region = δ/w²` of the rigid interpenetration region `h(y) < δ` of half-width `w`,
//! `WheelRailContact::region_curvature`, with that `w`), normal force and how it was found
//! (docs/validation.md, "The scan's gap at the flange root" and "The conformal stretch of the
//! flange root").
//!
//! `cargo run --release -p railslosh-cases --example flange_root_sweep -- MODE LOAD Y0 SPAN N [Y_REF]`
//! - `MODE` `load`: at each shift the wheel height that carries `LOAD` (N); `fixed`: the height
//!   that carries `LOAD` at shift `Y_REF` (m), kept;
//! - the shifts `Y0 + SPAN k/N` (m), k = 0..N; the wheel rolls at 8.33 m/s, no yaw.
use rail_mbs::track::Side;
use rail_mbs::wheel_rail::{VerticalTarget, WheelState, solve_vertical};
use railslosh_cases::contact::s1002_on_uic60;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let num = |i: usize, d: f64| -> Result<f64, std::num::ParseFloatError> { a.get(i).map_or(Ok(d), |s| s.parse()) };
    let fixed = a.first().is_some_and(|m| m == "fixed");
    let (load, y0, span, n, y_ref) =
        (num(1, 95e3)?, num(2, 0.004)?, num(3, 0.004)?, num(4, 80.0)? as usize, num(5, 0.007)?);
    let mut c = s1002_on_uic60(Side::Left)?;
    let state = |y: f64| WheelState { lateral_shift: y, speed: 8.33, ..WheelState::default() };
    let z_fixed = solve_vertical(&mut c, &state(y_ref), VerticalTarget::Load(load))?.pose.position.z;
    if fixed {
        println!("wheel height {z_fixed:.6} m (carries {load} N at {:.3} mm)", y_ref * 1e3);
    }
    for k in 0..=n.max(1) {
        let y = y0 + span * k as f64 / n.max(1) as f64;
        c.reset();
        let pose = if fixed {
            state(y).pose(c.wheel.nominal_radius, z_fixed)
        } else {
            match solve_vertical(&mut c, &state(y), VerticalTarget::Load(load)) {
                Ok(l) => l.pose,
                Err(e) => {
                    println!("y {:7.3} mm: {e}", y * 1e3);
                    continue;
                }
            }
        };
        c.reset();
        let pts = c.evaluate(&pose)?;
        let f: nalgebra::Vector3<f64> = pts.iter().map(|p| p.force_on_wheel()).sum();
        let mut line = format!("y {:7.3} mm  Fy {:9.0} N  Fz {:9.0} N |", y * 1e3, f.y, f.z);
        for p in &pts {
            let b_region = c.region_curvature(&pose, &p.geometry).unwrap_or(f64::NAN);
            line += &format!(
                " [at {:7.2} mm  δ {:6.1} µm  B {:6.2}  B_region {:6.2} (region ±{:5.2} mm)  A {:5.2}  N {:7.0}  {:?}]",
                (p.point().y - y) * 1e3,
                p.geometry.penetration * 1e6,
                p.geometry.curvature_y,
                b_region,
                (p.geometry.penetration / b_region).sqrt() * 1e3,
                p.geometry.curvature_x,
                p.normal_force,
                p.geometry.method
            );
        }
        println!("{line}");
    }
    Ok(())
}
