//! Work counters and timings.

use std::time::Duration;

/// Counters and wall-clock timings accumulated by [`Hht`](super::Hht).
///
/// `time_assembly` covers system callbacks (forces, Jacobians, mass, constraints) and
/// residual/KKT-value assembly; `time_factorization` the numeric LU;
/// `time_solve` the triangular solves with residual check.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Stats {
    /// Accepted steps.
    pub steps: usize,
    /// Failed step attempts (retried with a fresh matrix or smaller `h`).
    pub rejected_steps: usize,
    /// Newton iterations (linear solves inside steps).
    pub newton_iterations: usize,
    /// Numeric LU factorizations (including the initial-acceleration one).
    pub factorizations: usize,
    /// Evaluations of the force Jacobians.
    pub jacobian_evaluations: usize,
    /// Evaluations of forces/constraints (residuals).
    pub residual_evaluations: usize,
    /// Linear solves (including the initial-acceleration one).
    pub linear_solves: usize,
    /// Time spent in system callbacks and assembly.
    pub time_assembly: Duration,
    /// Time spent in numeric LU factorizations.
    pub time_factorization: Duration,
    /// Time spent in solves.
    pub time_solve: Duration,
    /// Total time inside `step` (and initialization).
    pub time_total: Duration,
}
