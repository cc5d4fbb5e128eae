//! Error type of `ancf-core`. Every failure names where it happened and why.

use thiserror::Error;

/// Errors raised while building or evaluating ANCF fluid models.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum AncfError {
    /// A parameter is outside its allowed range.
    #[error("invalid `{field}` = {value}: expected {allowed}")]
    InvalidParameter {
        /// Name of the offending field, as the user spelled it.
        field: String,
        /// The rejected value, formatted.
        value: String,
        /// The allowed range or set, in words.
        allowed: String,
    },
    /// The reference (initial) geometry of an element is degenerate or inverted.
    #[error(
        "element {element}: reference Jacobian det J0 = {det:.3e} <= 0 at quadrature point {point} (mesh is inverted or degenerate)"
    )]
    DegenerateReference {
        /// Element index.
        element: usize,
        /// Quadrature point index in the element.
        point: usize,
        /// Determinant of the reference Jacobian at that point.
        det: f64,
    },
    /// An element has inverted during the motion (J <= 0).
    #[error("element {element} inverted: J = {j:.3e} <= 0 at quadrature point {point}")]
    InvertedElement {
        /// Element index.
        element: usize,
        /// Quadrature point index in the element.
        point: usize,
        /// Volume ratio at that point.
        j: f64,
    },
    /// A vector or array has the wrong length.
    #[error("`{field}` has length {got}, expected {expected}")]
    DimensionMismatch {
        /// Name of the argument.
        field: String,
        /// Length received.
        got: usize,
        /// Length expected.
        expected: usize,
    },
    /// A computed quantity is NaN or infinite.
    #[error("non-finite value in {what} (element {element})")]
    NonFinite {
        /// What was being computed.
        what: String,
        /// Element index.
        element: usize,
    },
    /// A simulation run by a validation case or driver stopped (the message says where
    /// and why: time, element, contact).
    #[error("simulation failed: {0}")]
    Solver(String),
}

/// Result alias for `ancf-core`.
pub type Result<T> = std::result::Result<T, AncfError>;

/// Build an [`AncfError::InvalidParameter`].
pub fn invalid(field: &str, value: impl std::fmt::Display, allowed: &str) -> AncfError {
    AncfError::InvalidParameter { field: field.to_string(), value: value.to_string(), allowed: allowed.to_string() }
}

/// Check that `value` is finite and strictly positive.
pub fn check_positive(field: &str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 { Ok(()) } else { Err(invalid(field, value, "a finite number > 0")) }
}

/// Check that `value` is finite and non-negative.
pub fn check_non_negative(field: &str, value: f64) -> Result<()> {
    if value.is_finite() && value >= 0.0 { Ok(()) } else { Err(invalid(field, value, "a finite number >= 0")) }
}

/// Check that `value` lies in the closed range `[lo, hi]`.
pub fn check_range(field: &str, value: f64, lo: f64, hi: f64) -> Result<()> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(())
    } else {
        Err(invalid(field, value, &format!("a number in [{lo}, {hi}]")))
    }
}

/// Check a slice length.
pub fn check_len(field: &str, got: usize, expected: usize) -> Result<()> {
    if got == expected { Ok(()) } else { Err(AncfError::DimensionMismatch { field: field.to_string(), got, expected }) }
}
