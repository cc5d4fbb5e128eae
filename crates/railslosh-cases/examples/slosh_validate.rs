//! Run one slosh validation case and print its records:
//! `cargo run --release -p railslosh-cases --example slosh_validate -- CASE [quick]`.
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map(String::as_str).unwrap_or("hydrostatic-cylinder");
    let quick = args.iter().any(|a| a == "quick");
    let t = std::time::Instant::now();
    match railslosh_cases::slosh::run_case(name, quick) {
        Ok(recs) => {
            for r in recs {
                println!("{r}");
            }
        }
        Err(e) => println!("error: {e}"),
    }
    println!("wall {:.1} s", t.elapsed().as_secs_f64());
}
