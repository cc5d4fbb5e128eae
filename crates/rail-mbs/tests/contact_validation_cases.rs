//! The wheel/rail validation cases of `railslosh validate` (`rail_mbs::wheel_rail::validate`),
//! quick forms. The Manchester case is skipped with a message when the shared data are absent.

use rail_mbs::wheel_rail::validate::{CASES, ValidationError, run_case};

fn check(name: &str) {
    match run_case(name, true) {
        Ok(records) => {
            assert!(records.len() >= 2, "{name}: too few records");
            for r in &records {
                println!(
                    "{} | {}: {:.6} (ref {:.6}, tol {:.3e})",
                    r.case, r.quantity, r.measured, r.reference, r.tolerance
                );
            }
            let failed: Vec<_> = records.iter().filter(|r| !r.passed).collect();
            assert!(failed.is_empty(), "{name}: failed records {failed:#?}");
        }
        Err(e @ ValidationError::DataNotFound { .. }) => eprintln!("SKIP {name}: {e}"),
        Err(e) => panic!("{name}: {e}"),
    }
}

#[test]
fn manchester_contact_left_quick() {
    check("manchester-contact-left");
}

#[test]
fn klingel_wavelength_quick() {
    check("klingel-wavelength");
}

#[test]
fn every_case_is_dispatched() {
    for name in CASES {
        assert!(!matches!(run_case(name, true), Err(ValidationError::UnknownCase(_))));
    }
}
