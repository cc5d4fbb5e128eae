//! The wheel/rail validation cases of `railslosh validate` (`railslosh_cases::contact`),
//! quick forms. Without the shared data the Manchester case fails under CI and is skipped
//! visibly elsewhere (`common::data_missing`).

use railslosh_cases::contact::{CASES, ValidationError, run_case};

mod common;

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
        Err(e) if e.is_data_not_found() => common::data_missing(&format!("{name}: {e}")),
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
fn contact_mirror_symmetry_quick() {
    check("contact-mirror-symmetry");
}

#[test]
fn contact_sweep_refinement_quick() {
    check("contact-sweep-refinement");
}

#[test]
fn contact_variable_friction_quick() {
    check("contact-variable-friction");
}

#[test]
fn contact_nadal_climb_quick() {
    check("contact-nadal-climb");
}

#[test]
fn every_case_is_dispatched() {
    for name in CASES {
        assert!(!matches!(run_case(name, true), Err(ValidationError::UnknownCase(_))));
    }
}
