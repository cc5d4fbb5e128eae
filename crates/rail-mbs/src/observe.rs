//! Progress reports and the observer of a run (a progress bar, a stop button): one type for
//! every run kind (slosh, vehicle, co-simulation participant).

use crate::integrator::{Hht, IntegratorError};

/// Progress of a run, passed to an [`Observer`] after every accepted step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Simulated time reached, s.
    pub t: f64,
    /// End time of the run, s.
    pub t_end: f64,
    /// Accepted steps so far.
    pub steps: usize,
    /// Newton iterations so far.
    pub newton_iterations: usize,
    /// Rejected step attempts so far.
    pub rejected_steps: usize,
}

impl Progress {
    /// The progress of `hht` towards `t_end`.
    pub fn of<S: crate::integrator::MechanicalSystem>(hht: &Hht<S>, t_end: f64) -> Self {
        let s = hht.stats();
        Self {
            t: hht.t(),
            t_end,
            steps: s.steps,
            newton_iterations: s.newton_iterations,
            rejected_steps: s.rejected_steps,
        }
    }
}

/// Observer of a run (e.g. a progress bar): called after every accepted step; returning
/// `false` stops the run, which then fails with [`stopped_by_observer`] at that time.
pub type Observer<'a> = &'a mut dyn FnMut(&Progress) -> bool;

/// The error of a run stopped by its [`Observer`].
pub fn stopped_by_observer(t: f64) -> IntegratorError {
    IntegratorError::InvalidSystem { what: format!("run stopped by its progress observer at t = {t} s") }
}
