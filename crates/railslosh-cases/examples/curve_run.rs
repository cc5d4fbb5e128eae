//! One run of the crude-oil curve study (seed 000 §8.5: one car driven through the Table 1
//! curve), printing the oil's outward inertia force, the in-plane gravity component and the
//! wall time: `cargo run --release -p railslosh-cases --example curve_run -- [light|medium|heavy|water] [km/h] [nx ny nz] [t_end]`
use rail_mbs::defaults::Oil;
use railslosh_cases::vehicle::studies::curve_run;

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let oil = Oil::from_name(a.first().map_or("light", |s| s.as_str())).unwrap_or(Oil::Light);
    let arg = |i: usize, d: f64| a.get(i).map_or(d, |s| s.parse().expect("a number"));
    let kmh = arg(1, 100.0);
    let counts = [arg(2, 6.0) as usize, arg(3, 4.0) as usize, arg(4, 2.0) as usize];
    let t_end = arg(5, 3.0);
    let t = std::time::Instant::now();
    match curve_run(oil, kmh / 3.6, counts, t_end) {
        Ok((fc, g, _)) => println!(
            "{} crude, {kmh} km/h, {counts:?}: outward inertia {fc:.0} N, gravity component {g:.0} N, ratio {:.3}, wall {:.1} s",
            oil.name(),
            fc / g,
            t.elapsed().as_secs_f64()
        ),
        Err(e) => {
            println!(
                "{} crude, {kmh} km/h, {counts:?}: FAILED after {:.1} s: {e}",
                oil.name(),
                t.elapsed().as_secs_f64()
            );
            std::process::exit(1);
        }
    }
}
