//! Sparse implicit HHT-α integrator for index-3 multibody DAEs.
//!
//! Layering (after Chrono's timestepper / integrable / linear-solver split and
//! diffsol's `set_sparsity → set_linearisation → solve` cycle):
//!
//! * [`MechanicalSystem`] — what a model provides: `M`, `Q`, `∂Q/∂q`, `∂Q/∂v`, `C`,
//!   `C_q`, and a fixed [`SparsityPattern`] declared once;
//! * [`Hht`] — the time stepper: Newmark/HHT formulas, Newton iteration, Jacobian
//!   reuse, step control, [`Stats`];
//! * a private KKT solver: pattern → faer `SymbolicLu` once, `Lu::try_new_with_symbolic`
//!   per refactorization, in-place solves checked for finiteness and residual.
//!
//! # Equations and sign conventions
//!
//! ```text
//! M(q) a = Q(t, q, v) + C_qᵀ λ,     C(q, t) = 0,     v = q̇,  a = v̇
//! ```
//!
//! `Q` is applied minus internal force (a spring contributes `−k x`, so `∂Q/∂q = −k`,
//! a damper `∂Q/∂v = −c`). `C_qᵀ λ` is the constraint force: for a pendulum with
//! `C = x² + y² − L²`, `λ < 0` when the rod is in tension.
//!
//! # HHT-α (as Chrono's `ChTimestepperHHT`)
//!
//! α ∈ [−1/3, 0], γ = (1 − 2α)/2, β = (1 − α)²/4. The unknowns of a step are the new
//! accelerations `a` and multipliers `λ`; positions and velocities follow from
//!
//! ```text
//! q_{n+1} = q_n + h v_n + h² (½ − β) a_n + h² β a
//! v_{n+1} = v_n + h (1 − γ) a_n + h γ a
//! ```
//!
//! and the discrete equations are
//!
//! ```text
//! R(a, λ) = M a/(1+α) − (Q + C_qᵀλ)_{n+1} + α/(1+α) (Q + C_qᵀλ)_n = 0
//! C(q_{n+1}, t_{n+1}) / (β h²)                                        = 0
//! ```
//!
//! i.e. `M a_{n+1} = (1+α) F_{n+1} − α F_n`. Newton solves, per iteration,
//!
//! ```text
//! [ M/(1+α) − hγ ∂Q/∂v − h²β ∂Q/∂q   C_qᵀ ] [ Δa ]   [ −R           ]
//! [ C_q                              0    ] [ −Δλ] = [ −C / (β h²)  ]
//! ```
//!
//! The position-constraint residual is divided by `β h²`, so every block is O(1) as
//! `h → 0` (no ill-conditioning at small steps; accelerations and `λ` are still only
//! resolved to the round-off floor `ε |q| / (β h²)`). `∂(M(q) a)/∂q` is neglected and
//! `∂(C_qᵀλ)/∂q` is included only if the system provides
//! [`MechanicalSystem::constraint_force_jacobian`] (modified Newton otherwise).
//! Constraints may depend on time (`C(q, t)`); only the position level is enforced
//! (index 3), so `C_q v + C_t` drifts at the level of the discretization error.
//!
//! # Newton iteration
//!
//! The predictor is `a = a_n`, `λ = λ_n`. Convergence (Chrono): with weights
//! `w_i = 1/(rel_tol |a_n,i| + abs_tol_acc)` and `1/(rel_tol |λ_n,k| + abs_tol_lambda)`,
//! a step converges when both weighted RMS norms of the correction are < 1, or when
//! the residual 2-norms are below the absolute tolerances, or (our addition) when the
//! second or later correction moves positions only at round-off level,
//! `‖h²βΔa‖∞ ≤ 100 ε ‖q‖∞` (at small `h`, round-off in `C` divided by `βh²` would
//! otherwise defeat a tight `rel_tol`).
//!
//! The estimated convergence rate `ρ = ‖Δ_k‖/‖Δ_{k−1}‖` (WRMS norms) drives the
//! [`JacobianPolicy`]: with [`JacobianPolicy::Automatic`] a matrix from an earlier step
//! is refreshed when `ρ > refresh_rate`. A modified-Newton attempt fails early when
//! `ρ ≥ 1` or when `‖Δ_k‖ ρ^{remaining} > 1` (cannot converge in the remaining
//! iterations); a full-Newton attempt when `ρ > 2`; any attempt after
//! `max_iterations`.
//!
//! # Step control and failures
//!
//! Only Newton non-convergence is recoverable. A failed attempt with a matrix from an
//! earlier step is first retried with a fresh matrix at the same `h`. After that,
//! [`StepControl::Fixed`] returns [`IntegratorError::NewtonDivergence`], and
//! [`StepControl::Adaptive`] multiplies `h` by `decrease` (down to `h_min`, then
//! [`IntegratorError::StepTooSmall`]) and grows it again by `increase` after
//! `grow_after` consecutive easy steps, never beyond the requested step (Chrono's
//! Newton-failure driven controller; there is no local error estimate). Singular KKT
//! matrices (redundant constraints), callback errors and non-finite values at the
//! predictor are reported immediately as [`IntegratorError`]s naming time, step size
//! and the offending entry.
//!
//! The initial acceleration and multipliers are made consistent in [`Hht::new`] (and
//! [`Hht::reinitialize`]).
//!
//! # Example
//!
//! A damped oscillator `m ẍ = −k x − c ẋ` (one coordinate, no constraints):
//!
//! ```
//! use rail_mbs::integrator::{Hht, HhtParams, MechanicalSystem, SparsityPattern, SystemError};
//!
//! struct Oscillator { m: f64, k: f64, c: f64 }
//!
//! impl MechanicalSystem for Oscillator {
//!     fn n_coords(&self) -> usize { 1 }
//!     fn pattern(&self) -> SparsityPattern { SparsityPattern::diagonal(1) }
//!     fn mass_is_constant(&self) -> bool { true }
//!     fn mass(&mut self, _q: &[f64], m: &mut [f64]) -> Result<(), SystemError> {
//!         m[0] = self.m;
//!         Ok(())
//!     }
//!     fn forces(&mut self, _t: f64, q: &[f64], v: &[f64], f: &mut [f64]) -> Result<(), SystemError> {
//!         f[0] = -self.k * q[0] - self.c * v[0];
//!         Ok(())
//!     }
//!     fn force_jacobians(
//!         &mut self, _t: f64, _q: &[f64], _v: &[f64], dq: &mut [f64], dv: &mut [f64],
//!     ) -> Result<(), SystemError> {
//!         dq[0] = -self.k;
//!         dv[0] = -self.c;
//!         Ok(())
//!     }
//! }
//!
//! let sys = Oscillator { m: 1.0, k: 4.0, c: 0.1 };
//! let mut hht = Hht::new(sys, 0.0, vec![0.1], vec![0.0], HhtParams::default())?;
//! hht.integrate_to(1.0, 1e-3)?;
//! assert_eq!(hht.t(), 1.0);
//! assert!(hht.q()[0].abs() < 0.1);
//! println!("{} steps, {} factorizations", hht.stats().steps, hht.stats().factorizations);
//! # Ok::<(), rail_mbs::integrator::IntegratorError>(())
//! ```
//!
//! TODO: local error estimation for accuracy-based step control (Chrono has none
//! either); velocity-level constraint projection; allocation-free refactorization via
//! faer's low-level LU API.

mod condensed;
mod error;
mod explicit;
mod hht;
mod iterative;
mod journal;
mod linear;
mod linear_solver;
mod params;
mod stats;
mod system;

pub use error::{FailureCause, IntegratorError, KktIndex, Quantity, SystemError};
pub use explicit::{BlockMass, Explicit, ExplicitCheckpoint, ExplicitParams, StableStep};
pub(crate) use hht::checkpoint::{Reader as BytesReader, Writer as BytesWriter, bad as bad_checkpoint};
pub use hht::{Checkpoint, Hht, StateRef, StepInfo};
pub use iterative::{IterativeParams, LinearSolverKind};
pub use journal::{CheckpointFile, Journal, read_journal};
pub use params::{AdaptiveParams, HhtParams, JacobianPolicy, Predictor, StepControl};
pub use stats::Stats;
pub use system::{MechanicalSystem, SparsityPattern};
