//! Parameters of the HHT-α integrator and their validation.

use super::error::IntegratorError;

/// When the Newton matrix (Jacobians + numeric LU) is recomputed.
///
/// Whatever the policy, a change of step size `h` triggers a numeric refactorization
/// (from the stored Jacobian values, without re-evaluating them), since the KKT matrix
/// depends on `h`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum JacobianPolicy {
    /// Full Newton: evaluate Jacobians and refactorize at every iteration.
    EveryIteration,
    /// Modified Newton: evaluate and refactorize at the first iteration of every step
    /// (Chrono's default).
    EveryStep,
    /// Reuse across steps; refresh when the estimated convergence rate exceeds
    /// [`HhtParams::refresh_rate`], or when a step fails with a stale matrix.
    #[default]
    Automatic,
}

/// Initial iterate of Newton's method at each step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Predictor {
    /// `a_{n+1} = a_n`, `λ_{n+1} = λ_n` (Chrono's choice).
    #[default]
    Hold,
    /// Linear extrapolation from the last two accepted steps,
    /// `a_{n+1} = a_n + (h/h_n)(a_n − a_{n−1})` and likewise `λ`: the first correction is
    /// O(h²) instead of O(h) where the motion is smooth. The first step, and the first
    /// after [`Hht::reinitialize`](super::Hht::reinitialize), hold.
    Extrapolate,
}

/// Parameters of adaptive step control (Newton-failure driven, as in Chrono).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptiveParams {
    /// Smallest admissible step, s. Below it, [`IntegratorError::StepTooSmall`].
    pub h_min: f64,
    /// Factor applied to `h` after a failed step, in (0, 1). Default 0.5.
    pub decrease: f64,
    /// Factor applied to `h` after `grow_after` easy steps, ≥ 1. Default 2.
    pub increase: f64,
    /// Number of consecutive easy steps before growing `h`. Default 5.
    pub grow_after: usize,
    /// A step is easy if it converged in fewer than this many iterations. Default 3.
    pub easy_iterations: usize,
}

impl Default for AdaptiveParams {
    fn default() -> Self {
        Self { h_min: 1e-10, decrease: 0.5, increase: 2.0, grow_after: 5, easy_iterations: 3 }
    }
}

/// Step-size control.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum StepControl {
    /// Every step has the requested size; a Newton failure is an error.
    #[default]
    Fixed,
    /// The requested size is a maximum; failed steps are retried with smaller `h`.
    Adaptive(AdaptiveParams),
}

/// Parameters of [`Hht`](super::Hht). Defaults follow Chrono's `ChTimestepperHHT`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HhtParams {
    /// HHT parameter α ∈ [−1/3, 0]. 0 is the trapezoidal rule (no dissipation);
    /// more negative values damp high frequencies more. Default −0.2.
    pub alpha: f64,
    /// Relative tolerance of the Newton correction (WRMS test). Default 1e-4.
    pub rel_tol: f64,
    /// Absolute tolerance on accelerations, m/s² (or rad/s² …). Default 1e-10.
    pub abs_tol_acc: f64,
    /// Absolute tolerance on Lagrange multipliers, N (or N·m …). Default 1e-10.
    pub abs_tol_lambda: f64,
    /// Maximum Newton iterations per step attempt. Default 6.
    pub max_iterations: usize,
    /// Jacobian reuse policy. Default [`JacobianPolicy::Automatic`].
    pub jacobian: JacobianPolicy,
    /// Convergence-rate threshold in (0, 1) above which a stale matrix is refreshed
    /// ([`JacobianPolicy::Automatic`]). Default 0.2.
    pub refresh_rate: f64,
    /// Step control. Default [`StepControl::Fixed`].
    pub step_control: StepControl,
    /// Relative residual tolerance `‖b − A x‖∞ ≤ tol (‖A‖_max ‖x‖∞ + ‖b‖∞)` checked
    /// after each linear solve. Default 1e-9.
    pub linear_residual_tol: f64,
    /// Initial Newton iterate of each step. Default [`Predictor::Hold`].
    pub predictor: Predictor,
}

impl Default for HhtParams {
    fn default() -> Self {
        Self {
            alpha: -0.2,
            rel_tol: 1e-4,
            abs_tol_acc: 1e-10,
            abs_tol_lambda: 1e-10,
            max_iterations: 6,
            jacobian: JacobianPolicy::Automatic,
            refresh_rate: 0.2,
            step_control: StepControl::Fixed,
            linear_residual_tol: 1e-9,
            predictor: Predictor::Hold,
        }
    }
}

fn check(ok: bool, field: &'static str, value: f64, allowed: &'static str) -> Result<(), IntegratorError> {
    if ok { Ok(()) } else { Err(IntegratorError::InvalidParameter { field, value, allowed }) }
}

impl HhtParams {
    /// Newmark γ = (1 − 2α)/2.
    pub fn gamma(&self) -> f64 {
        0.5 - self.alpha
    }

    /// Newmark β = (1 − α)²/4.
    pub fn beta(&self) -> f64 {
        0.25 * (1.0 - self.alpha).powi(2)
    }

    /// Checks every field; returns the first violation.
    pub fn validate(&self) -> Result<(), IntegratorError> {
        let a = self.alpha;
        check((-1.0 / 3.0..=0.0).contains(&a), "alpha", a, "[-1/3, 0]")?;
        check(self.rel_tol.is_finite() && self.rel_tol >= 0.0, "rel_tol", self.rel_tol, "finite, >= 0")?;
        check(self.abs_tol_acc.is_finite() && self.abs_tol_acc > 0.0, "abs_tol_acc", self.abs_tol_acc, "finite, > 0")?;
        check(
            self.abs_tol_lambda.is_finite() && self.abs_tol_lambda > 0.0,
            "abs_tol_lambda",
            self.abs_tol_lambda,
            "finite, > 0",
        )?;
        check(self.max_iterations >= 1, "max_iterations", self.max_iterations as f64, ">= 1")?;
        check(self.refresh_rate > 0.0 && self.refresh_rate < 1.0, "refresh_rate", self.refresh_rate, "(0, 1)")?;
        check(
            self.linear_residual_tol.is_finite() && self.linear_residual_tol > 0.0,
            "linear_residual_tol",
            self.linear_residual_tol,
            "finite, > 0",
        )?;
        if let StepControl::Adaptive(p) = self.step_control {
            check(p.h_min.is_finite() && p.h_min > 0.0, "h_min", p.h_min, "finite, > 0")?;
            check(p.decrease > 0.0 && p.decrease < 1.0, "decrease", p.decrease, "(0, 1)")?;
            check(p.increase.is_finite() && p.increase >= 1.0, "increase", p.increase, "finite, >= 1")?;
            check(p.grow_after >= 1, "grow_after", p.grow_after as f64, ">= 1")?;
        }
        Ok(())
    }
}
