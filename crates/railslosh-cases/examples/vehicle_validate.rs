//! Run one vehicle or crude-oil study validation case and print its records:
//! `cargo run --release -p railslosh-cases --example vehicle_validate -- CASE [quick]`.
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map(String::as_str).unwrap_or("static-wheel-loads");
    let quick = args.iter().any(|a| a == "quick");
    let t = std::time::Instant::now();
    let result = if railslosh_cases::vehicle::studies::CASES.contains(&name) {
        railslosh_cases::vehicle::studies::run_case(name, quick)
    } else {
        railslosh_cases::vehicle::run_case(name, quick)
    };
    match result {
        Ok(recs) => {
            for r in recs {
                println!("{r}");
            }
        }
        Err(e) => println!("error: {e}"),
    }
    println!("wall {:.1} s", t.elapsed().as_secs_f64());
}
