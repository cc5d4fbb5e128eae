//! Helpers shared by integration tests (as in rail-mbs's `tests/common`).

use std::io::Write;

/// External reference data (`../shared/data`) are absent. Under CI (`CI` set), where the
/// data must be present, this fails the test; elsewhere the test is skipped with a line
/// written straight to the process's stderr, which the test harness does not capture, so
/// the skip shows in `cargo test` output instead of reading as a plain "ok".
pub fn data_missing(what: &str) {
    if std::env::var_os("CI").is_some_and(|v| !v.is_empty()) {
        panic!("{what}: reference data missing, but CI is set and the data must be present there");
    }
    let _ = writeln!(std::io::stderr(), "SKIPPED (data not found): {what}");
}
