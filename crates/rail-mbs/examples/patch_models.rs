//! Hertz and Kik–Piotrowski patches on the Manchester left-wheel sweep (issue 21):
//! per case the error of each model against CONTACT (lateral extent of the patch, contact
//! reference point YCP, creep forces FX and FS; FASTSIM 40×40 creep on both) and the cost of
//! one contact evaluation (`WheelRailContact::evaluate` at the solved pose, median over
//! repeats).
//!
//! `cargo run --release -p rail-mbs --example patch_models [-- REPEATS]` (default 51).
//! The data are read from the shared data directory (`RAILSLOSH_SHARED_DATA` or
//! `../shared/data`, see `wheel_rail::manchester`); without them the example says so and
//! stops.

use std::time::Instant;

use rail_mbs::wheel_rail::manchester::{
    DataError, MANCHESTER_DIR, MANCHESTER_FILES, find_dataset, manchester_contact_pair, manchester_patch_case,
    parse_manchester_patches, parse_manchester_reference,
};
use rail_mbs::wheel_rail::{CreepModel, PatchModel};

fn pct(ours: f64, reference: f64) -> f64 {
    100.0 * (ours - reference) / reference.abs()
}

fn main() -> Result<(), DataError> {
    let repeats: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(51).max(1);
    let dir = match find_dataset(MANCHESTER_DIR, &MANCHESTER_FILES) {
        Ok(d) => d,
        Err(e) => {
            println!("skipped: {e}");
            return Ok(());
        }
    };
    let file = dir.join(MANCHESTER_FILES[0]);
    let text = std::fs::read_to_string(&file)
        .map_err(|e| DataError::BadData { file: file.display().to_string(), message: e.to_string() })?;
    let refs = parse_manchester_reference(&text, MANCHESTER_FILES[0])?;
    let maps = parse_manchester_patches(&text, MANCHESTER_FILES[0])?;
    let models = [("Hertz", PatchModel::Hertz), ("KP", PatchModel::kik_piotrowski())];
    println!("Manchester A-2.2 left wheel, 10 kN, FASTSIM 40x40; errors against CONTACT, cost per evaluate call");
    println!(
        "{:>5} {:>5} | {:>6} {:>7} {:>3} | {:>8} | {:>7} {:>7} | {:>8}",
        "y_ws", "model", "w_C(mm)", "dw(%)", "n", "dYCP(mm)", "dFX(%)", "dFS(%)", "eval(us)"
    );
    let mut contacts = Vec::new();
    for (_, pm) in &models {
        let mut c = manchester_contact_pair(&dir, CreepModel::Fastsim { nx: 40, ny: 40 })?;
        c.patch_model = *pm;
        contacts.push(c);
    }
    for (r, m) in refs.iter().zip(&maps) {
        for ((label, _), c) in models.iter().zip(contacts.iter_mut()) {
            let case = manchester_patch_case(c, r)?;
            let mut times = Vec::with_capacity(repeats);
            for _ in 0..repeats {
                let t = Instant::now();
                let pts = c.evaluate(&case.pose)?;
                times.push(t.elapsed().as_secs_f64());
                std::hint::black_box(pts);
            }
            times.sort_by(f64::total_cmp);
            let median = times[times.len() / 2];
            // FX at y = 0 is ~0.3 N in CONTACT: its relative error is meaningless there.
            let dfx = if r.fx.abs() > 10.0 { format!("{:>7.1}", pct(case.fx, r.fx)) } else { format!("{:>7}", "-") };
            println!(
                "{:>5.1} {:>5} | {:>6.2} {:>7.1} {:>3} | {:>8.3} | {dfx} {:>7.1} | {:>8.1}",
                r.y_ws,
                label,
                m.lateral_extent,
                pct(case.lateral_extent, m.lateral_extent),
                case.points,
                case.ycp - r.ycp_tr,
                pct(case.fs, r.fs),
                median * 1e6
            );
        }
    }
    Ok(())
}
