//! The element validation cases of `railslosh validate` (`railslosh_cases::element`), full
//! forms; moved from ancf-core's element tests with the cases (issue 18).

use railslosh_cases::element::{CASES, run_case};

fn assert_case(name: &str) {
    let recs = run_case(name, false).unwrap();
    assert!(!recs.is_empty());
    for r in &recs {
        assert!(
            r.passed,
            "{}: {} measured {:e} reference {:e} tol {:e}",
            r.case, r.quantity, r.measured, r.reference, r.tolerance
        );
    }
}

#[test]
fn validation_case_element_mass() {
    assert_case("element-mass");
}

#[test]
fn validation_case_element_jacobians() {
    assert_case("element-jacobians");
}

#[test]
fn validation_case_rigid_motion_invariance() {
    assert_case("rigid-motion-invariance");
}

#[test]
fn unknown_case_is_an_error_listing_cases() {
    let err = run_case("nope", true).unwrap_err().to_string();
    for c in CASES {
        assert!(err.contains(c), "{err}");
    }
}
