//! Physical constants and unit conversions: the one definition of each, used by every crate,
//! the Python package (`railslosh.constants`, from `railslosh._core`) and the FMU.

/// Standard gravity g₀, m/s² (3rd CGPM, 1901; ISO 80000-3). Every run, default and validation
/// case uses it unless the user gives another gravity.
pub const GRAVITY: f64 = 9.80665;
/// One international foot, m.
pub const FOOT: f64 = 0.3048;
/// One inch, m.
pub const INCH: f64 = 0.0254;
/// One mile per hour, m/s.
pub const MPH: f64 = 0.44704;
