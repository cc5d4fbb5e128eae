//! Probe: one tank car settling on tangent track (or running at a speed on a curve).
//! `cargo run --release -p rail-mbs --example car_probe -- [speed_kmh] [t_end] [radius]`
use std::sync::Arc;
use std::time::Instant;

use rail_mbs::integrator::{AdaptiveParams, Hht, HhtParams, StepControl};
use rail_mbs::mbs::{Multibody, SpeedProfile};
use rail_mbs::track::{Track, TrackPoint};
use rail_mbs::vehicle::{TankCarParams, add_tank_car, wheel_loads};

fn main() {
    let args: Vec<f64> = std::env::args().skip(1).map(|a| a.parse().unwrap()).collect();
    let v = args.first().copied().unwrap_or(0.0) / 3.6;
    let t_end = args.get(1).copied().unwrap_or(1.0);
    let radius = args.get(2).copied().unwrap_or(0.0);
    let h_super = args.get(3).copied().unwrap_or(0.0);
    let k = if radius > 0.0 { 1.0 / radius } else { 0.0 };
    let track = Arc::new(
        Track::new(vec![
            TrackPoint::new(0.0, k, h_super, 0.0, 0.025, -0.025),
            TrackPoint::new(5000.0, k, h_super, 0.0, 0.025, -0.025),
        ])
        .unwrap(),
    );
    let mut mb = Multibody::new();
    let mut p = TankCarParams::standard().unwrap();
    p.lading = Some((36_000.0, -0.5));
    if std::env::var("NOSCAN").is_ok() {
        p.contact.always_scan = false;
    }
    if std::env::var("WHEEL").as_deref() == Ok("aar") {
        p.contact.wheel_profile = rail_mbs::profile::aar1b_wheel_approx().unwrap();
    }
    let drive = if v > 0.0 { Some(SpeedProfile::Constant(v)) } else { None };
    let placement = rail_mbs::vehicle::CarPlacement { station: 50.0, speed: v, drive, brake: None };
    let car = add_tank_car(&mut mb, "car1", &p, &track, placement).unwrap();
    println!("dof {}, bodies {}, static wheel load {:.1} N", mb.dof(), mb.bodies().len(), car.static_wheel_load);
    let (q0, v0) = mb.initial_coordinates();
    let params = HhtParams {
        alpha: -0.3,
        rel_tol: 1e-4,
        abs_tol_acc: 1e-3,
        abs_tol_lambda: 1e-1,
        max_iterations: 10,
        step_control: StepControl::Adaptive(AdaptiveParams { h_min: 1e-7, easy_iterations: 5, ..Default::default() }),
        ..Default::default()
    };
    let t0 = Instant::now();
    let mut hht = Hht::new(mb, 0.0, q0, v0, params).unwrap();
    let mut next = 0.0;
    while hht.t() < t_end - 1e-12 {
        if let Err(e) = hht.step(1e-3f64.min(t_end - hht.t())) {
            println!("error: {e}");
            break;
        }
        if hht.t() >= next - 1e-9 {
            next += 0.1;
            let (q, vv) = (hht.q().to_vec(), hht.v().to_vec());
            let reps = hht.system_mut().wheelset_reports(&q, &vv).unwrap();
            let mut line = format!("t {:.3}", hht.t());
            for (i, r) in reps.iter().enumerate() {
                let s = hht.system().state(Some(car.wheelsets[i]), &q, &vv);
                let proj = track.project(&s.position, None).unwrap();
                let f = track.frame(proj.s);
                let wl = wheel_loads(r, &f.up(), &f.lateral());
                line += &format!(
                    " | ws{} y {:+.2}mm Q {:.0}/{:.0} Y {:+.0}/{:+.0}",
                    i + 1,
                    proj.lateral * 1e3,
                    wl[0].vertical,
                    wl[1].vertical,
                    wl[0].lateral,
                    wl[1].lateral
                );
            }
            let st = hht.system().state(Some(car.tank), &q, &vv);
            line += &format!(" | tank x {:.4} z {:.4} v {:.3}", st.position.x, st.position.z, st.velocity.norm());
            println!("{line}");
        }
    }
    let s = hht.stats();
    println!(
        "wall {:.2} s, steps {}, newton {}, jac {}, fact {}, failed {}",
        t0.elapsed().as_secs_f64(),
        s.steps,
        s.newton_iterations,
        s.jacobian_evaluations,
        s.factorizations,
        s.rejected_steps
    );
}
