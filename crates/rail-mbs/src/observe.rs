//! What every run kind shares (slosh, vehicle, co-simulation participant): the step loop
//! ([`step_to`] over a [`RunStepper`]), its progress reports, the observer of a run (a progress
//! bar, a stop button), the results stream a run writes its samples to as it goes, and the
//! failure that carries what a stopped run computed.

use crate::integrator::{Hht, IntegratorError, MechanicalSystem, Stats};

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
    /// The progress of `stepper` towards `t_end`.
    pub fn of<R: RunStepper + ?Sized>(stepper: &R, t_end: f64) -> Self {
        let s = stepper.stats();
        Self {
            t: stepper.t(),
            t_end,
            steps: s.steps,
            newton_iterations: s.newton_iterations,
            rejected_steps: s.rejected_steps,
        }
    }
}

/// What [`step_to`] steps: a time integrator, or a run that owns one (a slosh run steps its
/// implicit or explicit stepper and records every step).
pub trait RunStepper {
    /// Time reached, s.
    fn t(&self) -> f64;
    /// Counters of the steps taken so far.
    fn stats(&self) -> &Stats;
    /// One accepted step toward `target` of at most `h` (the stepper's own rule for the last
    /// step; [`Hht::step_toward`] lands on `target` exactly); returns its Newton iterations
    /// (an explicit stepper: its sub-steps).
    fn step_toward(&mut self, target: f64, h: f64) -> Result<usize, IntegratorError>;
}

impl<S: MechanicalSystem> RunStepper for Hht<S> {
    fn t(&self) -> f64 {
        Hht::t(self)
    }
    fn stats(&self) -> &Stats {
        Hht::stats(self)
    }
    fn step_toward(&mut self, target: f64, h: f64) -> Result<usize, IntegratorError> {
        Hht::step_toward(self, target, h).map(|info| info.iterations)
    }
}

/// Whether `t` is short of `target` by more than round-off.
fn short_of(t: f64, target: f64) -> bool {
    target - t > 1e-12 * (1.0 + target.abs())
}

/// The step loop of every run kind (slosh runs, vehicle runs between their recording times,
/// the co-simulation participant over a window, hence the FMU): steps `stepper` toward
/// `target` with steps of at most `h`; after every accepted step calls `after_step` with its
/// Newton iterations (recording, invariant checks, streaming, checkpoints; an error stops the
/// loop), then `observe` with the progress toward `t_end`, and stops with
/// [`stopped_by_observer`] when that returns `false`. Returns at `target` (up to round-off), or
/// the first error, the stepper left at the last accepted step.
pub fn step_to<R: RunStepper + ?Sized>(
    stepper: &mut R,
    target: f64,
    h: f64,
    t_end: f64,
    observe: Observer<'_>,
    mut after_step: impl FnMut(&mut R, usize) -> Result<(), IntegratorError>,
) -> Result<(), IntegratorError> {
    while short_of(stepper.t(), target) {
        let iterations = stepper.step_toward(target, h)?;
        after_step(stepper, iterations)?;
        if !observe(&Progress::of(stepper, t_end)) {
            return Err(stopped_by_observer(stepper.t()));
        }
    }
    Ok(())
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Steps of exactly `min(h, target − t)`, counted.
    #[derive(Default)]
    struct Clock {
        t: f64,
        stats: Stats,
    }

    impl RunStepper for Clock {
        fn t(&self) -> f64 {
            self.t
        }
        fn stats(&self) -> &Stats {
            &self.stats
        }
        fn step_toward(&mut self, target: f64, h: f64) -> Result<usize, IntegratorError> {
            self.t += h.min(target - self.t);
            self.stats.steps += 1;
            self.stats.newton_iterations += 2;
            Ok(2)
        }
    }

    #[test]
    fn the_step_loop_reaches_its_target_calls_back_after_every_step_and_stops_when_told() {
        let mut c = Clock::default();
        let (mut after, mut seen) = (Vec::new(), Vec::new());
        step_to(
            &mut c,
            0.1,
            0.03,
            1.0,
            &mut |p| {
                seen.push((p.t, p.t_end, p.steps, p.newton_iterations));
                true
            },
            |c, iterations| {
                after.push((c.t, iterations));
                Ok(())
            },
        )
        .unwrap();
        // 0.03, 0.06, 0.09, then the remainder 0.01
        assert_eq!(c.stats.steps, 4);
        assert!((c.t - 0.1).abs() < 1e-15);
        assert_eq!(after.len(), 4);
        assert!(after.iter().all(|&(_, i)| i == 2));
        assert_eq!(seen.len(), 4);
        assert_eq!(seen[3].1, 1.0);
        assert_eq!((seen[3].2, seen[3].3), (4, 8));
        // at the target already: no step
        step_to(&mut c, 0.1, 0.03, 1.0, &mut |_| true, |_, _| Ok(())).unwrap();
        assert_eq!(c.stats.steps, 4);
        // the observer stops the loop after the step it was shown
        let mut n = 0;
        let e = step_to(
            &mut c,
            1.0,
            0.1,
            1.0,
            &mut |_| {
                n += 1;
                n < 3
            },
            |_, _| Ok(()),
        )
        .unwrap_err();
        assert_eq!(c.stats.steps, 7);
        assert!(e.to_string().contains("stopped by its progress observer"), "{e}");
        // an error after a step stops the loop there, unobserved
        let e = step_to(&mut c, 1.0, 0.1, 1.0, &mut |_| panic!("not observed"), |c, _| {
            Err(IntegratorError::InvalidSystem { what: format!("check failed at {}", c.t) })
        })
        .unwrap_err();
        assert_eq!(c.stats.steps, 8);
        assert!(e.to_string().contains("check failed"), "{e}");
    }
}
