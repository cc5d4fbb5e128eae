//! Run one wheel/rail contact validation case and print its records:
//! `cargo run --release -p railslosh-cases --example contact_validate -- CASE [quick]`.
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map(String::as_str).unwrap_or("manchester-contact-left");
    let quick = args.iter().any(|a| a == "quick");
    let t = std::time::Instant::now();
    match railslosh_cases::contact::run_case(name, quick) {
        Ok(recs) => {
            for r in recs {
                println!("{r}");
            }
        }
        Err(e) if e.is_data_not_found() => println!("skipped: {e}"),
        Err(e) => println!("error: {e}"),
    }
    println!("wall {:.2} s", t.elapsed().as_secs_f64());
}
