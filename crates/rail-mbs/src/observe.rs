//! What every run kind shares (slosh, vehicle, co-simulation participant): its progress
//! reports, the observer of a run (a progress bar, a stop button), the results stream a run
//! writes its samples to as it goes, and the failure that carries what a stopped run computed.

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

/// Receives every recorded sample as a flat row (the record's `row` layout, e.g.
/// `TrainRecord::row`, extended by `FluidTrainRecord::row` for fluid runs) as soon as it is
/// recorded: a results stream that an interrupted run cannot lose (e.g. a
/// [`crate::integrator::Journal`]).
pub type SampleSink<'a> = &'a mut dyn FnMut(&[f64]) -> Result<(), IntegratorError>;

/// A run that stopped early: why (time, place, quantity and limit in `error`) and everything
/// recorded up to the last accepted step. The one failure type of every run kind; its record
/// type names the kind (`TrainFailure`, `FluidTrainFailure`, `EquivalentTrainFailure`,
/// `SloshFailure` are this type for the vehicle runs' and the slosh run's records).
#[derive(Debug)]
pub struct RunFailure<R> {
    /// Why it stopped.
    pub error: IntegratorError,
    /// Results up to the failure.
    pub record: R,
}
