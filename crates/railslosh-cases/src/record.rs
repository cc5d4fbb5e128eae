//! The record of one validation check, the common output of every case of this crate.

/// One validation check.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    /// Case name (e.g. `element-mass`).
    pub case: String,
    /// What was measured.
    pub quantity: String,
    /// Measured value.
    pub measured: f64,
    /// Reference value.
    pub reference: f64,
    /// Allowed |measured − reference| (absolute unless the quantity says "relative").
    pub tolerance: f64,
    /// Whether the check passed.
    pub passed: bool,
}

/// One line: case, quantity, measured, reference, tolerance and verdict.
impl std::fmt::Display for Record {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} {}: measured {:.6} reference {:.6} tol {:.3e} -> {}",
            self.case,
            self.quantity,
            self.measured,
            self.reference,
            self.tolerance,
            if self.passed { "ok" } else { "FAIL" }
        )
    }
}

impl Record {
    /// Check |measured − reference| ≤ tolerance.
    pub fn abs(case: &str, quantity: impl Into<String>, measured: f64, reference: f64, tolerance: f64) -> Self {
        let passed = (measured - reference).abs() <= tolerance && measured.is_finite();
        Self { case: case.into(), quantity: quantity.into(), measured, reference, tolerance, passed }
    }
    /// Check |measured| ≤ limit.
    pub fn at_most(case: &str, quantity: impl Into<String>, measured: f64, limit: f64) -> Self {
        Self {
            case: case.into(),
            quantity: quantity.into(),
            measured,
            reference: 0.0,
            tolerance: limit,
            passed: measured.is_finite() && measured.abs() <= limit,
        }
    }
    /// Check measured ≥ limit (signed; the limit is reported as the reference, with a zero
    /// tolerance).
    pub fn at_least(case: &str, quantity: impl Into<String>, measured: f64, limit: f64) -> Self {
        Self {
            case: case.into(),
            quantity: quantity.into(),
            measured,
            reference: limit,
            tolerance: 0.0,
            passed: measured.is_finite() && measured >= limit,
        }
    }
    /// Check measured < limit (signed; the limit is reported as the reference, with a zero
    /// tolerance).
    pub fn less_than(case: &str, quantity: impl Into<String>, measured: f64, limit: f64) -> Self {
        Self {
            case: case.into(),
            quantity: quantity.into(),
            measured,
            reference: limit,
            tolerance: 0.0,
            passed: measured.is_finite() && measured < limit,
        }
    }
}
