//! One work–precision sweep, printed point by point as it runs (the full sweeps take an
//! hour or more; `railslosh bench` runs the same sweeps and writes CSV/JSON and a plot):
//! `cargo run --release -p railslosh-cases --example work_precision -- [slosh-tank|ecp-braking|ecp-braking-spread] [quick]`
use railslosh_cases::work_precision::{WorkPoint, run_case_with};

fn fields(v: &[(String, f64)]) -> String {
    v.iter().map(|(k, x)| format!("{k}={x:.6e}")).collect::<Vec<_>>().join(" ")
}

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let case = a.first().map_or("ecp-braking-spread", |s| s.as_str());
    let quick = a.get(1).map(|s| s.as_str()) == Some("quick");
    let mut print = |p: &WorkPoint| {
        println!(
            "{}{} | {} | wall {:.1} s, steps {}, Newton {}, Jacobians {} | {}{}",
            p.case,
            if p.reference { " (reference)" } else { "" },
            fields(&p.settings),
            p.wall_s,
            p.steps,
            p.newton_iterations,
            p.jacobians,
            fields(&p.errors),
            p.failure.as_ref().map_or(String::new(), |f| format!(" | FAILED: {f}")),
        )
    };
    if let Err(e) = run_case_with(case, quick, &mut print) {
        eprintln!("{e}");
        std::process::exit(1);
    }
}
