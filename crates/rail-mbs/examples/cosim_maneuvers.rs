//! Seed 003's maneuvers (issue 6) on the SwRI elliptical tank, half full of water, run
//! through the co-simulation participant with prescribed tank motion; writes one CSV load
//! history per maneuver to a directory.
//!
//! `cargo run --release -p rail-mbs --example cosim_maneuvers -- [key=value ...]`, keys:
//! `out` (directory, default /tmp/cosim_maneuvers), `dt` (coupling step = sample step, s,
//! default 0.005), `h` (largest integrator step, s, default 0.0025), `after` (free sloshing
//! after each maneuver, s, default 2), `nx ny nz` (mesh, default 2 6 3), `only` (run the
//! maneuvers whose name contains this string).
//!
//! CSV columns: t, the tank-frame input (ax ay az wx wy wz wdx wdy wdz gx gy gz), the
//! loads on the tank about the tank origin (Fx Fy Fz Mx My Mz, tank axes), the fluid
//! centre of mass (cx cy cz, tank frame). Maneuver definitions: `rail_mbs::maneuvers` (the same motions as the shipped `swri_*` scenes).
use std::io::Write;

use ancf_core::constants::GRAVITY as G;
use ancf_core::constitutive::Rheology;
use ancf_core::mesh::{EllipticCylinderSpec, elliptic_cylinder};
use ancf_core::tank::{TankGeometry, TankShape};
use rail_mbs::cosim::maneuvers::seed003_maneuvers;
use rail_mbs::cosim::{SloshParticipant, SloshParticipantConfig, TankMotionInput};
use rail_mbs::defaults::liquid;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<(String, String)> = std::env::args()
        .skip(1)
        .filter_map(|s| s.split_once('=').map(|(k, v)| (k.to_string(), v.to_string())))
        .collect();
    let get = |k: &str| args.iter().find(|(a, _)| a == k).map(|(_, v)| v.clone());
    let num = |k: &str, d: f64| -> Result<f64, String> {
        get(k).map_or(Ok(d), |v| v.parse().map_err(|_| format!("invalid `{k}` = {v}: expected a number")))
    };
    let out = std::path::PathBuf::from(get("out").unwrap_or("/tmp/cosim_maneuvers".into()));
    let (dt, h, after) = (num("dt", 0.005)?, num("h", 0.0025)?, num("after", 2.0)?);
    let counts = [num("nx", 2.0)? as usize, num("ny", 6.0)? as usize, num("nz", 3.0)? as usize];
    let only = get("only").unwrap_or_default();
    std::fs::create_dir_all(&out)?;
    let spec = EllipticCylinderSpec::swri(counts[0], counts[1], counts[2]);
    let depth = spec.semi_axis_z; // half full
    for man in seed003_maneuvers(dt, after)? {
        if !man.name.contains(&only) {
            continue;
        }
        let mesh = elliptic_cylinder(&spec)?;
        let fluid = liquid(998.0, Rheology::Newtonian { viscosity: 1e-3 }, depth, depth / counts[2] as f64)?;
        let tank = TankGeometry::new(
            TankShape::EllipticCylinder {
                length: spec.length,
                semi_axis_y: spec.semi_axis_y,
                semi_axis_z: spec.semi_axis_z,
            },
            vec![],
        )?;
        let mut config = SloshParticipantConfig::new(mesh, fluid, tank);
        config.h_max = h;
        config.gravity = G;
        let mut p = SloshParticipant::new(config)?;
        let inputs = man.tank_frame(G)?;
        let path = out.join(format!("{}.csv", man.name));
        let mut w = std::io::BufWriter::new(std::fs::File::create(&path)?);
        writeln!(w, "t,ax,ay,az,wx,wy,wz,wdx,wdy,wdz,gx,gy,gz,Fx,Fy,Fz,Mx,My,Mz,cx,cy,cz")?;
        let wall = std::time::Instant::now();
        let first = TankMotionInput::TankFrame(inputs[0]);
        let mut loads = p.set_initial_input(&first)?;
        let mut status = "completed".to_string();
        for k in 0..man.times.len() {
            if k > 0 {
                let (a, b) = (TankMotionInput::TankFrame(inputs[k - 1]), TankMotionInput::TankFrame(inputs[k]));
                match p.advance(man.times[k], &a, &b) {
                    Ok(l) => loads = l,
                    Err(e) => {
                        status = format!("stopped: {e}");
                        break;
                    }
                }
            }
            let s = &inputs[k];
            let c = p.com_tank();
            let row: Vec<String> = [man.times[k]]
                .iter()
                .chain(&s.acceleration)
                .chain(&s.angular_velocity)
                .chain(&s.angular_acceleration)
                .chain(&s.gravity)
                .chain(&loads.force)
                .chain(&loads.moment)
                .chain(&c)
                .map(|x| format!("{x:.6e}"))
                .collect();
            writeln!(w, "{}", row.join(","))?;
        }
        w.flush()?;
        let m = p.fluid_mass();
        println!(
            "{}: {} of {:.2} s simulated, {}; m = {m:.2} kg, {} steps, {:.1} s wall -> {}",
            man.name,
            p.time(),
            man.times.last().copied().unwrap_or(0.0),
            status,
            p.stats().steps,
            wall.elapsed().as_secs_f64(),
            path.display()
        );
    }
    Ok(())
}
