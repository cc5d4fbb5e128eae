//! The vehicle validation cases of `railslosh validate` (`railslosh_cases::vehicle`), quick
//! forms; moved from rail-mbs's vehicle tests with the cases (issue 18).

use railslosh_cases::vehicle as validate;

#[test]
fn static_wheel_loads_case_passes_quick() {
    let recs = validate::run_case("static-wheel-loads", true).unwrap();
    for r in &recs {
        println!("{}: {} (limit {})", r.quantity, r.measured, r.tolerance);
        assert!(r.passed, "{r:?}");
    }
}
