//! The HHT-α time stepper (Chrono's `ChTimestepperHHT` formulation).

use std::time::Instant;

use super::error::{IntegratorError, KktIndex, Quantity, SystemError};
use super::linear::{KktSolver, LinearFailure};
use super::params::{HhtParams, JacobianPolicy, Predictor, StepControl};
use super::stats::Stats;
use super::system::{MechanicalSystem, SparsityPattern};

pub(crate) mod checkpoint;
pub use checkpoint::Checkpoint;

/// How the Newton matrix is refreshed during one step attempt.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum RefreshMode {
    EveryIteration,
    AtStart,
    Reuse,
}

/// Result of one step attempt that did not hit a fatal error.
enum Outcome {
    Converged {
        iterations: usize,
    },
    Failed {
        iterations: usize,
        correction: f64,
        rate: f64,
        /// Error to report if the step is given up (e.g. non-finite forces at a
        /// diverged iterate); `None` means plain non-convergence.
        cause: Option<IntegratorError>,
        /// Whether the matrix was (re)evaluated during this attempt.
        refreshed: bool,
    },
}

/// Summary of one accepted step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepInfo {
    /// Size of the accepted step, s.
    pub h: f64,
    /// Newton iterations of the accepted attempt.
    pub iterations: usize,
    /// Attempts needed (1 if the first attempt converged).
    pub attempts: usize,
}

/// Borrowed view of the integrator state.
#[derive(Debug, Clone, Copy)]
pub struct StateRef<'a> {
    /// Time, s.
    pub t: f64,
    /// Generalized positions.
    pub q: &'a [f64],
    /// Generalized velocities.
    pub v: &'a [f64],
    /// Generalized accelerations.
    pub a: &'a [f64],
    /// Lagrange multipliers (constraint force is `C_qᵀ λ`).
    pub lambda: &'a [f64],
}

/// Sparse implicit HHT-α integrator for index-3 DAEs. Owns the system.
///
/// See the [module docs](super) for the formulation and sign conventions.
pub struct Hht<S: MechanicalSystem> {
    system: S,
    params: HhtParams,
    n: usize,
    m: usize,
    pattern: SparsityPattern,
    mass_constant: bool,
    /// `(row, col, value index)` of the pattern entries that can hold mass, sorted by
    /// row: the product `M a` in the residual runs over these only.
    mass_nz: Vec<(u32, u32, u32)>,
    /// The entries of a mass with a constant part that change with `q`
    /// ([`MechanicalSystem::mass_varying_entries`]); `None`: the whole mass changes.
    mass_varying: Option<Vec<usize>>,
    /// Whether `mass_vals` holds a whole evaluation whose constant entries can be kept.
    mass_base_valid: bool,
    // State at t_n.
    t: f64,
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    lambda: Vec<f64>,
    /// Accelerations and multipliers at t_{n−1} and the step h_n = t_n − t_{n−1}
    /// (0: none, the predictor holds), for [`Predictor::Extrapolate`].
    a_prev: Vec<f64>,
    lam_prev: Vec<f64>,
    h_prev: f64,
    /// `Q_n + C_q,nᵀ λ_n`, needed by the α term.
    f_old: Vec<f64>,
    f_old_valid: bool,
    // Newton buffers.
    q_it: Vec<f64>,
    v_it: Vec<f64>,
    a_it: Vec<f64>,
    lam_it: Vec<f64>,
    force: Vec<f64>,
    cval: Vec<f64>,
    mass_vals: Vec<f64>,
    mass_jac: Vec<f64>,
    dq_vals: Vec<f64>,
    dv_vals: Vec<f64>,
    cq_vals: Vec<f64>,
    cq_jac: Vec<f64>,
    rhs: Vec<f64>,
    w_a: Vec<f64>,
    w_l: Vec<f64>,
    kkt: KktSolver,
    /// Whether `mass_jac`, `dq_vals`, `dv_vals`, `cq_jac` hold an evaluation.
    jac_valid: bool,
    /// Step size the current factorization was made for (`None`: not usable).
    factor_h: Option<f64>,
    /// Controller step size (adaptive mode).
    h_current: f64,
    easy_count: usize,
    stats: Stats,
}

/// An adaptive step may be lengthened by this factor to reach the requested step exactly.
const STRETCH: f64 = 1.01;

fn first_non_finite(x: &[f64]) -> Option<usize> {
    x.iter().position(|v| !v.is_finite())
}

fn wrms(x: &[f64], w: &[f64]) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    let s: f64 = x.iter().zip(w).map(|(x, w)| (x * w).powi(2)).sum();
    (s / x.len() as f64).sqrt()
}

fn inf_norm(x: &[f64]) -> f64 {
    x.iter().fold(0.0_f64, |m, v| m.max(v.abs()))
}

fn norm2(x: &[f64]) -> f64 {
    x.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// Wraps a system callback error with the evaluation time.
fn sys_err(t: f64) -> impl Fn(SystemError) -> IntegratorError {
    move |source| IntegratorError::System { t, source }
}

fn check_finite(x: &[f64], t: f64, what: Quantity) -> Result<(), IntegratorError> {
    match first_non_finite(x) {
        Some(index) => Err(IntegratorError::NonFinite { t, what, index }),
        None => Ok(()),
    }
}

fn linear_error(f: LinearFailure, t: f64, h: f64) -> IntegratorError {
    match f {
        LinearFailure::NoPivot(p) => IntegratorError::SingularMatrix { t, h, pivot_step: Some(p), unknown: None },
        LinearFailure::Numeric(u) => IntegratorError::SingularMatrix { t, h, pivot_step: None, unknown: u },
        LinearFailure::Generic(message) => IntegratorError::LinearSolver { t, message },
    }
}

/// `out[j] += Σ_k C_q[k, j] λ[k]` over the constraint pattern.
fn add_cq_t_lambda(pattern: &[(usize, usize)], cq: &[f64], lambda: &[f64], out: &mut [f64]) {
    for (&(k, j), &c) in pattern.iter().zip(cq) {
        out[j] += c * lambda[k];
    }
}

impl<S: MechanicalSystem> Hht<S> {
    /// Validates parameters and the system, builds the KKT pattern and its symbolic LU
    /// (once), and computes consistent initial accelerations and multipliers by
    /// solving
    ///
    /// ```text
    /// [ M    C_qᵀ ] [ a  ]   [ Q ]
    /// [ C_q  0    ] [ −λ ] = [ γ ],   γ = −(C_q v)_q v − 2 C_qt v − C_tt
    /// ```
    ///
    /// at `(t0, q0, v0)`. `γ` comes from
    /// [`MechanicalSystem::constraint_acceleration_rhs`] or, by default, from a
    /// central second difference of `C`. `q0`, `v0` are taken as given (not projected
    /// onto the constraints; the first step enforces `C = 0`).
    pub fn new(system: S, t0: f64, q0: Vec<f64>, v0: Vec<f64>, params: HhtParams) -> Result<Self, IntegratorError> {
        let start = Instant::now();
        let mut hht = Self::build(system, t0, q0, v0, params)?;
        hht.initial_acceleration()?;
        hht.stats.time_total += start.elapsed();
        Ok(hht)
    }

    /// Validation, buffers and symbolic LU, without the initial-acceleration solve.
    fn build(system: S, t0: f64, q0: Vec<f64>, v0: Vec<f64>, params: HhtParams) -> Result<Self, IntegratorError> {
        params.validate()?;
        if !t0.is_finite() {
            return Err(IntegratorError::InvalidParameter { field: "t0", value: t0, allowed: "finite" });
        }
        let n = system.n_coords();
        let m = system.n_constraints();
        if n == 0 {
            return Err(IntegratorError::InvalidSystem { what: "n_coords() is 0".into() });
        }
        if q0.len() != n || v0.len() != n {
            return Err(IntegratorError::InvalidSystem {
                what: format!("q0 has length {}, v0 has length {}, n_coords() is {n}", q0.len(), v0.len()),
            });
        }
        check_finite(&q0, t0, Quantity::InitialPositions)?;
        check_finite(&v0, t0, Quantity::InitialVelocities)?;
        let pattern = system.pattern();
        if let Some((k, &(r, c))) = pattern.dynamics.iter().enumerate().find(|(_, (r, c))| *r >= n || *c >= n) {
            return Err(IntegratorError::InvalidSystem {
                what: format!("dynamics pattern entry {k} = ({r}, {c}) outside {n} x {n}"),
            });
        }
        if let Some((k, &(r, c))) = pattern.constraints.iter().enumerate().find(|(_, (r, c))| *r >= m || *c >= n) {
            return Err(IntegratorError::InvalidSystem {
                what: format!("constraint pattern entry {k} = ({r}, {c}) outside {m} x {n}"),
            });
        }
        let blocks = system.condensed_blocks();
        let kkt = KktSolver::new(n, m, &pattern, params.linear_residual_tol, system.linear_solver(), &blocks)
            .map_err(|e| linear_error(e, t0, 0.0))?;
        let nd = pattern.dynamics.len();
        let nc = pattern.constraints.len();
        let mass_constant = system.mass_is_constant();
        let mass_nz = mass_product_entries(&pattern, system.mass_entries());
        let mass_varying = if mass_constant { None } else { system.mass_varying_entries() };
        if let Some(&k) = mass_varying.as_ref().and_then(|v| v.iter().find(|&&k| k >= nd)) {
            return Err(IntegratorError::InvalidSystem {
                what: format!("varying mass entry {k} outside the {nd} pattern entries"),
            });
        }
        Ok(Self {
            system,
            params,
            n,
            m,
            pattern,
            mass_constant,
            mass_nz,
            mass_varying,
            mass_base_valid: false,
            t: t0,
            q: q0,
            v: v0,
            a: vec![0.0; n],
            lambda: vec![0.0; m],
            a_prev: vec![0.0; n],
            lam_prev: vec![0.0; m],
            h_prev: 0.0,
            f_old: vec![0.0; n],
            f_old_valid: false,
            q_it: vec![0.0; n],
            v_it: vec![0.0; n],
            a_it: vec![0.0; n],
            lam_it: vec![0.0; m],
            force: vec![0.0; n],
            cval: vec![0.0; m],
            mass_vals: vec![0.0; nd],
            mass_jac: vec![0.0; nd],
            dq_vals: vec![0.0; nd],
            dv_vals: vec![0.0; nd],
            cq_vals: vec![0.0; nc],
            cq_jac: vec![0.0; nc],
            rhs: vec![0.0; n + m],
            w_a: vec![0.0; n],
            w_l: vec![0.0; m],
            kkt,
            jac_valid: false,
            factor_h: None,
            h_current: f64::INFINITY,
            easy_count: 0,
            stats: Stats::default(),
        })
    }

    /// KKT coefficients `(1/(1+α), hγ, h²β)` of the Newton matrix for step `h`.
    fn kkt_coeffs(&self, h: f64) -> (f64, f64, f64) {
        let p = &self.params;
        (1.0 / (1.0 + p.alpha), h * p.gamma(), h * h * p.beta())
    }

    fn eval_mass(&mut self, q_is_iterate: bool, t: f64) -> Result<(), IntegratorError> {
        self.mass_base_valid = false;
        self.mass_vals.fill(0.0);
        let q = if q_is_iterate { &self.q_it } else { &self.q };
        self.system.mass(q, &mut self.mass_vals).map_err(sys_err(t))?;
        check_finite(&self.mass_vals, t, Quantity::Mass)?;
        self.mass_base_valid = true;
        Ok(())
    }

    /// The mass at the iterate for a residual: only the varying entries when the system
    /// declares them and a whole evaluation is held, else all of it.
    fn eval_mass_iterate(&mut self, t1: f64) -> Result<(), IntegratorError> {
        let Some(varying) = self.mass_varying.as_ref().filter(|_| self.mass_base_valid) else {
            return self.eval_mass(true, t1);
        };
        for &k in varying {
            self.mass_vals[k] = 0.0;
        }
        if let Err(e) = self.system.mass_varying(&self.q_it, &mut self.mass_vals) {
            self.mass_base_valid = false;
            return Err(sys_err(t1)(e));
        }
        match varying.iter().find(|&&k| !self.mass_vals[k].is_finite()) {
            Some(&index) => {
                self.mass_base_valid = false;
                Err(IntegratorError::NonFinite { t: t1, what: Quantity::Mass, index })
            }
            None => Ok(()),
        }
    }

    fn initial_acceleration(&mut self) -> Result<(), IntegratorError> {
        let (n, m, t) = (self.n, self.m, self.t);
        let tic = Instant::now();
        self.eval_mass(false, t)?;
        self.force.fill(0.0);
        self.system.forces(t, &self.q, &self.v, &mut self.force).map_err(sys_err(t))?;
        check_finite(&self.force, t, Quantity::Forces)?;
        self.stats.residual_evaluations += 1;
        let mut gamma = vec![0.0; m];
        if m > 0 {
            self.cq_vals.fill(0.0);
            self.system.constraint_jacobian(t, &self.q, &mut self.cq_vals).map_err(sys_err(t))?;
            check_finite(&self.cq_vals, t, Quantity::ConstraintJacobian)?;
            let exact = self.system.constraint_acceleration_rhs(t, &self.q, &self.v, &mut gamma).map_err(sys_err(t))?;
            if !exact {
                self.fd_constraint_rhs(&mut gamma)?;
            }
            check_finite(&gamma, t, Quantity::ConstraintAccelerationRhs)?;
        }
        self.kkt.assemble(&self.mass_vals, &self.dq_vals, &self.dv_vals, &self.cq_vals, (1.0, 0.0, 0.0));
        self.stats.time_assembly += tic.elapsed();
        let tic = Instant::now();
        self.kkt.factorize().map_err(|e| linear_error(e, t, 0.0))?;
        self.stats.factorizations += 1;
        self.stats.time_factorization += tic.elapsed();
        let tic = Instant::now();
        self.rhs[..n].copy_from_slice(&self.force);
        self.rhs[n..].copy_from_slice(&gamma);
        self.kkt.solve_in_place(&mut self.rhs).map_err(|e| linear_error(e, t, 0.0))?;
        self.stats.linear_solves += 1;
        self.stats.time_solve += tic.elapsed();
        self.a.copy_from_slice(&self.rhs[..n]);
        for (l, x) in self.lambda.iter_mut().zip(&self.rhs[n..]) {
            *l = -x;
        }
        if self.mass_constant {
            self.mass_jac.copy_from_slice(&self.mass_vals);
        }
        self.factor_h = None;
        Ok(())
    }

    /// `γ ≈ −[C(q+εv, t+ε) − 2C(q, t) + C(q−εv, t−ε)]/ε²`.
    fn fd_constraint_rhs(&mut self, gamma: &mut [f64]) -> Result<(), IntegratorError> {
        let t = self.t;
        let qn = self.q.iter().fold(0.0_f64, |s, x| s.max(x.abs()));
        let vn = self.v.iter().fold(0.0_f64, |s, x| s.max(x.abs()));
        let scale = if vn > 0.0 { (qn / vn).clamp(1e-3, 1.0) } else { 1.0 };
        let eps = 1e-4 * scale;
        let mut c0 = vec![0.0; self.m];
        let mut cp = vec![0.0; self.m];
        let mut cm = vec![0.0; self.m];
        let mut qs = vec![0.0; self.n];
        self.system.constraints(t, &self.q, &mut c0).map_err(sys_err(t))?;
        for (s, out) in [(eps, &mut cp), (-eps, &mut cm)] {
            for ((x, q), v) in qs.iter_mut().zip(&self.q).zip(&self.v) {
                *x = q + s * v;
            }
            self.system.constraints(t + s, &qs, out).map_err(sys_err(t + s))?;
        }
        for k in 0..self.m {
            gamma[k] = -(cp[k] - 2.0 * c0[k] + cm[k]) / (eps * eps);
        }
        Ok(())
    }

    /// Restarts from a new state (e.g. after an impact or a change of the model),
    /// recomputing consistent accelerations and multipliers as in [`Hht::new`].
    /// Statistics keep accumulating; the symbolic factorization is kept.
    pub fn reinitialize(&mut self, t: f64, q: &[f64], v: &[f64]) -> Result<(), IntegratorError> {
        if !t.is_finite() {
            return Err(IntegratorError::InvalidParameter { field: "t", value: t, allowed: "finite" });
        }
        if q.len() != self.n || v.len() != self.n {
            return Err(IntegratorError::InvalidSystem {
                what: format!("q has length {}, v has length {}, n_coords() is {}", q.len(), v.len(), self.n),
            });
        }
        check_finite(q, t, Quantity::InitialPositions)?;
        check_finite(v, t, Quantity::InitialVelocities)?;
        self.t = t;
        self.q.copy_from_slice(q);
        self.v.copy_from_slice(v);
        self.f_old_valid = false;
        self.jac_valid = false;
        self.factor_h = None;
        self.easy_count = 0;
        self.h_prev = 0.0;
        let start = Instant::now();
        let result = self.initial_acceleration();
        self.stats.time_total += start.elapsed();
        result
    }

    /// Time, s.
    pub fn t(&self) -> f64 {
        self.t
    }
    /// Generalized positions at [`t`](Self::t).
    pub fn q(&self) -> &[f64] {
        &self.q
    }
    /// Generalized velocities.
    pub fn v(&self) -> &[f64] {
        &self.v
    }
    /// Generalized accelerations.
    pub fn a(&self) -> &[f64] {
        &self.a
    }
    /// Lagrange multipliers; the constraint force is `C_qᵀ λ`.
    pub fn lambda(&self) -> &[f64] {
        &self.lambda
    }
    /// Borrowed view of the whole state.
    pub fn state(&self) -> StateRef<'_> {
        StateRef { t: self.t, q: &self.q, v: &self.v, a: &self.a, lambda: &self.lambda }
    }
    /// Work counters and timings so far.
    pub fn stats(&self) -> &Stats {
        &self.stats
    }
    /// Parameters in use.
    pub fn params(&self) -> &HhtParams {
        &self.params
    }
    /// Number of structural non-zeros of the KKT matrix.
    pub fn kkt_nnz(&self) -> usize {
        self.kkt.nnz()
    }

    /// Total Krylov (GMRES) iterations so far; 0 with the direct linear solver.
    pub fn linear_iterations(&self) -> usize {
        self.kkt.linear_iterations()
    }
    /// The system.
    pub fn system(&self) -> &S {
        &self.system
    }
    /// The system, mutably (e.g. to change a load). The sparsity pattern, `n`, `m`
    /// and constancy of `M` must not change.
    pub fn system_mut(&mut self) -> &mut S {
        // The model may change: re-evaluate F_n, the Jacobians and the whole mass before reuse.
        self.f_old_valid = false;
        self.jac_valid = false;
        self.mass_base_valid = false;
        &mut self.system
    }
    /// The system, mutably, for an observation that leaves the model unchanged (its
    /// scratch buffers may change, and any warm start it touches must be restored, as
    /// [`crate::mbs::Multibody::wheelset_reports`] does): unlike
    /// [`Hht::system_mut`] the cached forces and Jacobians stay valid, so recording
    /// does not change the solution or its cost.
    pub fn system_observed(&mut self) -> &mut S {
        &mut self.system
    }
    /// Consumes the integrator and returns the system.
    pub fn into_system(self) -> S {
        self.system
    }

    /// Takes one accepted step of size at most `h` (exactly `h` in fixed-step mode).
    ///
    /// In adaptive mode, failed attempts are retried (first with a refreshed matrix if
    /// it was stale, then with `h · decrease`), and the controller's step grows again
    /// after easy steps, never beyond `h`.
    pub fn step(&mut self, h: f64) -> Result<StepInfo, IntegratorError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(IntegratorError::InvalidParameter { field: "h", value: h, allowed: "finite, > 0" });
        }
        let start = Instant::now();
        let result = self.step_inner(h);
        self.stats.time_total += start.elapsed();
        result
    }

    /// Integrates to `t_end` with steps of (at most) `h`; the last step is shortened
    /// to land on `t_end` exactly.
    pub fn integrate_to(&mut self, t_end: f64, h: f64) -> Result<(), IntegratorError> {
        self.integrate_with(t_end, h, |_| {})
    }

    /// Like [`integrate_to`](Self::integrate_to), calling `observer` after every
    /// accepted step.
    pub fn integrate_with(
        &mut self,
        t_end: f64,
        h: f64,
        mut observer: impl FnMut(StateRef<'_>),
    ) -> Result<(), IntegratorError> {
        self.integrate_checked(t_end, h, |_, state| {
            observer(state);
            Ok(())
        })
    }

    /// Like [`integrate_with`](Self::integrate_with), with a `check` of the system and every
    /// accepted state that can stop the integration with an error (e.g. a run-time
    /// invariant); the state is left where the check failed.
    pub fn integrate_checked(
        &mut self,
        t_end: f64,
        h: f64,
        mut check: impl FnMut(&S, StateRef<'_>) -> Result<(), IntegratorError>,
    ) -> Result<(), IntegratorError> {
        if !t_end.is_finite() || t_end < self.t {
            return Err(IntegratorError::InvalidParameter {
                field: "t_end",
                value: t_end,
                allowed: "finite, >= current time",
            });
        }
        // the one step loop of every run kind, without an observer
        crate::observe::step_to(self, t_end, h, t_end, &mut |_| true, |hht, _| check(&hht.system, hht.state()))
    }

    /// One step toward `target` of at most `h`: the step that reaches `target` (up to
    /// round-off) lands on it exactly. A caller stepping from output time to output time
    /// with [`Hht::step`] accumulates round-off in `t` and can be left 1e-12 s short of an
    /// output time; its next request is then a step of 1e-12 s, whose Newton matrix
    /// (scaled by 1/h²) is singular in practice: a 14 s vehicle run on irregular track
    /// stopped at 13.1 s that way, its iterate thrown 1e104 m away. Likewise a remainder
    /// that exceeds `h` by a sliver (an adaptive step of 2.99999979 ms left 2.00000021 ms to
    /// an output time, and a step of 2 ms then left 2.1e-10 s) is taken in one step,
    /// lengthened by up to the 1 % an adaptive step may stretch.
    pub fn step_toward(&mut self, target: f64, h: f64) -> Result<StepInfo, IntegratorError> {
        let remaining = target - self.t;
        let last = remaining <= h * STRETCH;
        // A last step equal to h up to round-off keeps h (no refactorization).
        let h_step = if last && (remaining - h).abs() > 1e-9 * h { remaining } else { h };
        let info = self.step(h_step)?;
        if last && info.h == h_step {
            self.t = target;
        }
        Ok(info)
    }

    /// The unknown with the largest weighted entry of the last Newton correction (still in
    /// `rhs` after a failed attempt), described by the system.
    fn largest_correction(&self) -> Option<String> {
        let n = self.n;
        let weights = self.w_a.iter().chain(&self.w_l);
        let (i, _) = self
            .rhs
            .iter()
            .zip(weights)
            .map(|(x, w)| (x * w).abs())
            .enumerate()
            .filter(|(_, v)| v.is_finite())
            .max_by(|a, b| a.1.total_cmp(&b.1))?;
        Some(self.system.describe_unknown(KktIndex::from_raw(i, n)))
    }

    fn base_mode(&self) -> RefreshMode {
        match self.params.jacobian {
            JacobianPolicy::EveryIteration => RefreshMode::EveryIteration,
            JacobianPolicy::EveryStep => RefreshMode::AtStart,
            JacobianPolicy::Automatic => RefreshMode::Reuse,
        }
    }

    fn step_inner(&mut self, h_req: f64) -> Result<StepInfo, IntegratorError> {
        let adaptive = match self.params.step_control {
            StepControl::Fixed => None,
            StepControl::Adaptive(p) => Some(p),
        };
        let mut h = match adaptive {
            // Stretch the controller's step by up to 1 % (or by less than h_min) rather than
            // leave a sliver of the requested step: a caller landing on an output time would
            // otherwise ask next for a step of, e.g., 1e-11 s, and a single Newton failure on
            // it ends the run, because halving it falls below h_min at once.
            Some(p) if h_req <= STRETCH * self.h_current || h_req - self.h_current < p.h_min => h_req,
            Some(_) => self.h_current,
            None => h_req,
        };
        let mut mode = self.base_mode();
        let mut attempts = 0;
        loop {
            attempts += 1;
            match self.attempt(h, mode)? {
                Outcome::Converged { iterations } => {
                    self.stats.steps += 1;
                    if let Some(p) = adaptive {
                        if iterations < p.easy_iterations {
                            self.easy_count += 1;
                        } else {
                            self.easy_count = 0;
                        }
                        if self.easy_count >= p.grow_after {
                            self.h_current = (self.h_current * p.increase).min(h_req);
                            self.easy_count = 0;
                        }
                    }
                    return Ok(StepInfo { h, iterations, attempts });
                }
                Outcome::Failed { iterations, correction, rate, cause, refreshed } => {
                    self.stats.rejected_steps += 1;
                    if mode == RefreshMode::Reuse && !refreshed {
                        // Stale matrix: refresh it and retry with the same h.
                        mode = RefreshMode::AtStart;
                        continue;
                    }
                    if adaptive.is_none() && mode != RefreshMode::EveryIteration {
                        // Fixed step: a matrix from the start of the step can still be far
                        // from the end-of-step one (e.g. a contact that closes during the
                        // step), and h cannot be reduced: retry with full Newton first.
                        mode = RefreshMode::EveryIteration;
                        continue;
                    }
                    // Only when the run stops: the description scans the correction.
                    let give_up = |h: f64| {
                        cause.clone().unwrap_or_else(|| IntegratorError::NewtonDivergence {
                            t: self.t,
                            h,
                            iterations,
                            correction,
                            rate,
                            largest: if iterations > 0 { self.largest_correction() } else { None },
                        })
                    };
                    let Some(p) = adaptive else {
                        return Err(give_up(h));
                    };
                    let h_new = h * p.decrease;
                    if h_new < p.h_min {
                        return Err(IntegratorError::StepTooSmall {
                            t: self.t,
                            h: h_new,
                            h_min: p.h_min,
                            cause: Box::new(give_up(h)),
                        });
                    }
                    h = h_new;
                    self.h_current = h;
                    self.easy_count = 0;
                    mode = if self.base_mode() == RefreshMode::EveryIteration {
                        RefreshMode::EveryIteration
                    } else {
                        RefreshMode::AtStart
                    };
                }
            }
        }
    }

    /// Evaluates `F_n = Q(t_n, q_n, v_n) + C_q(q_n)ᵀ λ_n` for the α term.
    fn eval_f_old(&mut self) -> Result<(), IntegratorError> {
        let t = self.t;
        self.f_old.fill(0.0);
        self.system.forces(t, &self.q, &self.v, &mut self.f_old).map_err(sys_err(t))?;
        check_finite(&self.f_old, t, Quantity::Forces)?;
        if self.m > 0 {
            self.cq_vals.fill(0.0);
            self.system.constraint_jacobian(t, &self.q, &mut self.cq_vals).map_err(sys_err(t))?;
            check_finite(&self.cq_vals, t, Quantity::ConstraintJacobian)?;
            add_cq_t_lambda(&self.pattern.constraints, &self.cq_vals, &self.lambda, &mut self.f_old);
        }
        self.stats.residual_evaluations += 1;
        self.f_old_valid = true;
        Ok(())
    }

    /// Evaluates forces, constraints (and mass) at the current iterate.
    /// Returns `Err` only for fatal errors; non-finite values are reported through
    /// the returned `Option` so that the caller can treat them as a Newton failure
    /// after the first iteration.
    fn eval_residual_terms(&mut self, t1: f64) -> Result<Option<IntegratorError>, IntegratorError> {
        self.force.fill(0.0);
        // A model error at a trial iterate (e.g. an element inverted by too large a step)
        // is recoverable: the step is retried (smaller, in adaptive mode).
        if let Err(e) = self.system.forces(t1, &self.q_it, &self.v_it, &mut self.force) {
            return Ok(Some(sys_err(t1)(e)));
        }
        if let Err(e) = check_finite(&self.force, t1, Quantity::Forces) {
            return Ok(Some(e));
        }
        if self.m > 0 {
            self.cval.fill(0.0);
            self.system.constraints(t1, &self.q_it, &mut self.cval).map_err(sys_err(t1))?;
            if let Err(e) = check_finite(&self.cval, t1, Quantity::Constraints) {
                return Ok(Some(e));
            }
            self.cq_vals.fill(0.0);
            self.system.constraint_jacobian(t1, &self.q_it, &mut self.cq_vals).map_err(sys_err(t1))?;
            if let Err(e) = check_finite(&self.cq_vals, t1, Quantity::ConstraintJacobian) {
                return Ok(Some(e));
            }
        }
        if !self.mass_constant {
            match self.eval_mass_iterate(t1) {
                Err(e @ IntegratorError::NonFinite { .. }) => return Ok(Some(e)),
                r => r?,
            }
        }
        self.stats.residual_evaluations += 1;
        Ok(None)
    }

    fn eval_jacobians(&mut self, t1: f64) -> Result<Option<IntegratorError>, IntegratorError> {
        // Invalid until the evaluation below succeeds completely.
        self.jac_valid = false;
        self.factor_h = None;
        self.dq_vals.fill(0.0);
        self.dv_vals.fill(0.0);
        if let Err(e) = self.system.force_jacobians(t1, &self.q_it, &self.v_it, &mut self.dq_vals, &mut self.dv_vals) {
            return Ok(Some(sys_err(t1)(e)));
        }
        if let Err(e) = check_finite(&self.dq_vals, t1, Quantity::ForceJacobianQ) {
            return Ok(Some(e));
        }
        if let Err(e) = check_finite(&self.dv_vals, t1, Quantity::ForceJacobianV) {
            return Ok(Some(e));
        }
        if self.m > 0 {
            self.system
                .constraint_force_jacobian(t1, &self.q_it, &self.lam_it, &mut self.dq_vals)
                .map_err(sys_err(t1))?;
            if let Err(e) = check_finite(&self.dq_vals, t1, Quantity::ForceJacobianQ) {
                return Ok(Some(e));
            }
            self.cq_jac.copy_from_slice(&self.cq_vals);
        }
        if !self.mass_constant {
            self.mass_jac.copy_from_slice(&self.mass_vals);
        }
        self.stats.jacobian_evaluations += 1;
        self.jac_valid = true;
        Ok(None)
    }

    /// Positions and velocities of the iterate from the Newmark formulas.
    fn newmark_update(&mut self, h: f64) {
        let (beta, gamma) = (self.params.beta(), self.params.gamma());
        let (cq0, cq1) = (h * h * (0.5 - beta), h * h * beta);
        let (cv0, cv1) = (h * (1.0 - gamma), h * gamma);
        for i in 0..self.n {
            self.q_it[i] = self.q[i] + h * self.v[i] + cq0 * self.a[i] + cq1 * self.a_it[i];
            self.v_it[i] = self.v[i] + cv0 * self.a[i] + cv1 * self.a_it[i];
        }
    }

    fn attempt(&mut self, h: f64, mode: RefreshMode) -> Result<Outcome, IntegratorError> {
        let (n, m) = (self.n, self.m);
        let p = self.params;
        let (alpha, beta) = (p.alpha, p.beta());
        let t1 = self.t + h;
        let coeffs = self.kkt_coeffs(h);
        let c_m = coeffs.0;
        let c_old = alpha / (1.0 + alpha);

        let tic = Instant::now();
        if alpha != 0.0 && !self.f_old_valid {
            self.eval_f_old()?;
        }
        for i in 0..n {
            self.w_a[i] = 1.0 / (p.rel_tol * self.a[i].abs() + p.abs_tol_acc);
        }
        for k in 0..m {
            self.w_l[k] = 1.0 / (p.rel_tol * self.lambda[k].abs() + p.abs_tol_lambda);
        }
        // Predictor: a = a_n, λ = λ_n (Chrono), or extrapolated from t_{n−1}.
        self.a_it.copy_from_slice(&self.a);
        self.lam_it.copy_from_slice(&self.lambda);
        if p.predictor == Predictor::Extrapolate && self.h_prev > 0.0 {
            let r = h / self.h_prev;
            for ((x, a), a0) in self.a_it.iter_mut().zip(&self.a).zip(&self.a_prev) {
                *x += r * (a - a0);
            }
            for ((x, l), l0) in self.lam_it.iter_mut().zip(&self.lambda).zip(&self.lam_prev) {
                *x += r * (l - l0);
            }
        }
        self.stats.time_assembly += tic.elapsed();

        let mut refreshed = false;
        let mut refresh_next = matches!(mode, RefreshMode::AtStart | RefreshMode::EveryIteration);
        let mut prev_e = f64::NAN;
        let mut rate = f64::NAN;
        let mut e = f64::INFINITY;
        let mut iterations = 0;
        let fail = |iterations, correction, rate, cause, refreshed| Outcome::Failed {
            iterations,
            correction,
            rate,
            cause,
            refreshed,
        };

        for k in 0..p.max_iterations {
            let tic = Instant::now();
            self.newmark_update(h);
            if let Some(err) = self.eval_residual_terms(t1)? {
                if k == 0 && !matches!(err, IntegratorError::System { .. }) {
                    return Err(err);
                }
                self.stats.time_assembly += tic.elapsed();
                return Ok(fail(iterations, e, rate, Some(err), refreshed));
            }
            // rhs = [Q + C_qᵀλ − α/(1+α) F_n − M a/(1+α) ;  −C/(βh²)]
            let (r1, r2) = self.rhs.split_at_mut(n);
            r1.copy_from_slice(&self.force);
            add_cq_t_lambda(&self.pattern.constraints, &self.cq_vals, &self.lam_it, r1);
            if alpha != 0.0 {
                for (r, f) in r1.iter_mut().zip(&self.f_old) {
                    *r -= c_old * f;
                }
            }
            let mass = if self.mass_constant { &self.mass_jac } else { &self.mass_vals };
            if !self.system.subtract_mass_product(mass, &self.a_it, c_m, r1) {
                for &(i, j, k) in &self.mass_nz {
                    r1[i as usize] -= c_m * mass[k as usize] * self.a_it[j as usize];
                }
            }
            let scale_c = 1.0 / (beta * h * h);
            for (r, c) in r2.iter_mut().zip(&self.cval) {
                *r = -scale_c * c;
            }
            // Finite inputs can still overflow in the sums above.
            if let Some(index) = first_non_finite(&self.rhs) {
                self.stats.time_assembly += tic.elapsed();
                let err = IntegratorError::NonFinite { t: t1, what: Quantity::Residual, index };
                if k == 0 {
                    return Err(err);
                }
                return Ok(fail(iterations, e, rate, Some(err), refreshed));
            }
            let (r1, r2) = self.rhs.split_at(n);
            if k > 0 && norm2(r1) < p.abs_tol_acc && norm2(r2) < p.abs_tol_lambda {
                // Residual already negligible (Chrono's absolute test).
                self.stats.time_assembly += tic.elapsed();
                return self.commit(h, iterations, (e, rate, refreshed));
            }

            let refresh = refresh_next || mode == RefreshMode::EveryIteration || !self.jac_valid;
            if refresh {
                if let Some(err) = self.eval_jacobians(t1)? {
                    if k == 0 && !matches!(err, IntegratorError::System { .. }) {
                        return Err(err);
                    }
                    self.stats.time_assembly += tic.elapsed();
                    return Ok(fail(iterations, e, rate, Some(err), refreshed));
                }
                refreshed = true;
                refresh_next = false;
            }
            let need_factor = refresh || self.factor_h != Some(h);
            if need_factor {
                self.kkt.assemble(&self.mass_jac, &self.dq_vals, &self.dv_vals, &self.cq_jac, coeffs);
            }
            self.stats.time_assembly += tic.elapsed();
            if need_factor {
                let tic = Instant::now();
                self.factor_h = None;
                self.kkt.factorize().map_err(|f| linear_error(f, self.t, h))?;
                self.factor_h = Some(h);
                self.stats.factorizations += 1;
                self.stats.time_factorization += tic.elapsed();
            }
            let tic = Instant::now();
            self.kkt.solve_in_place(&mut self.rhs).map_err(|f| linear_error(f, self.t, h))?;
            self.stats.linear_solves += 1;
            self.stats.time_solve += tic.elapsed();

            iterations += 1;
            self.stats.newton_iterations += 1;
            for (a, d) in self.a_it.iter_mut().zip(&self.rhs[..n]) {
                *a += d;
            }
            for (l, d) in self.lam_it.iter_mut().zip(&self.rhs[n..]) {
                *l -= d;
            }
            let e_a = wrms(&self.rhs[..n], &self.w_a);
            let e_l = wrms(&self.rhs[n..], &self.w_l);
            e = e_a.max(e_l);
            if !e.is_finite() {
                return Ok(fail(iterations, e, rate, None, refreshed));
            }
            if k > 0 {
                rate = e / prev_e;
            }
            if e_a < 1.0 && e_l < 1.0 || k > 0 && self.roundoff_limited(h) {
                return self.commit(h, iterations, (e, rate, refreshed));
            }
            if k > 0 {
                let stale = mode == RefreshMode::Reuse && !refreshed;
                let remaining = (p.max_iterations - k - 1) as i32;
                if stale && rate > p.refresh_rate {
                    // Modified Newton with a matrix from an earlier step converges too
                    // slowly: refresh it at the next iteration.
                    refresh_next = true;
                } else if mode == RefreshMode::EveryIteration {
                    if rate > 2.0 {
                        return Ok(fail(iterations, e, rate, None, refreshed));
                    }
                } else if rate >= 1.0 || e * rate.powi(remaining) > 1.0 {
                    // Diverging, or cannot reach e < 1 within the remaining iterations.
                    return Ok(fail(iterations, e, rate, None, refreshed));
                }
            }
            prev_e = e;
        }
        Ok(fail(iterations, e, rate, None, refreshed))
    }

    /// Whether the last correction (in `rhs[..n]`) moves positions only at round-off
    /// level, `‖h²β Δa‖∞ ≤ 100 ε ‖q‖∞` (checked from the second iteration on):
    /// further iterations cannot improve the solution. At small `h` the position-constraint residual `C/(βh²)` amplifies
    /// round-off in `C` into `Δa`, which a tight `rel_tol` would never accept.
    fn roundoff_limited(&self, h: f64) -> bool {
        let dq = h * h * self.params.beta() * inf_norm(&self.rhs[..self.n]);
        dq <= 100.0 * f64::EPSILON * inf_norm(&self.q_it)
    }

    /// Accepts the iterate: Newmark update with the converged acceleration, then the
    /// system's acceptance check ([`MechanicalSystem::check_step`], e.g. contact
    /// penetration) and a finiteness check of the new state. A rejected state is a
    /// failed attempt (retried with a smaller step in adaptive mode).
    fn commit(
        &mut self,
        h: f64,
        iterations: usize,
        (e, rate, refreshed): (f64, f64, bool),
    ) -> Result<Outcome, IntegratorError> {
        self.newmark_update(h);
        let t1 = self.t + h;
        let rejected = |cause| Outcome::Failed { iterations, correction: e, rate, cause: Some(cause), refreshed };
        for (x, what) in [(&self.q_it, Quantity::Positions), (&self.v_it, Quantity::Velocities)] {
            if let Some(index) = first_non_finite(x) {
                return Ok(rejected(IntegratorError::NonFinite { t: t1, what, index }));
            }
        }
        if let Err(source) = self.system.check_step(t1, &self.q_it, &self.v_it) {
            return Ok(rejected(IntegratorError::System { t: t1, source }));
        }
        std::mem::swap(&mut self.q, &mut self.q_it);
        std::mem::swap(&mut self.v, &mut self.v_it);
        // a_n, λ_n become the previous values (the iterates are overwritten next step)
        std::mem::swap(&mut self.a_prev, &mut self.a_it);
        std::mem::swap(&mut self.a, &mut self.a_prev);
        std::mem::swap(&mut self.lam_prev, &mut self.lam_it);
        std::mem::swap(&mut self.lambda, &mut self.lam_prev);
        self.h_prev = h;
        self.t += h;
        self.f_old_valid = false;
        Ok(Outcome::Converged { iterations })
    }
}

/// The entries used by the residual's `M a`: those the system declares as mass entries
/// (all pattern entries if it declares none), sorted by row for memory locality.
fn mass_product_entries(pattern: &SparsityPattern, declared: Option<Vec<usize>>) -> Vec<(u32, u32, u32)> {
    let idx: Vec<usize> = match declared {
        Some(v) => v.into_iter().filter(|&k| k < pattern.dynamics.len()).collect(),
        None => (0..pattern.dynamics.len()).collect(),
    };
    let mut nz: Vec<(u32, u32, u32)> = idx
        .into_iter()
        .map(|k| {
            let (i, j) = pattern.dynamics[k];
            (i as u32, j as u32, k as u32)
        })
        .collect();
    nz.sort_unstable();
    nz.dedup();
    nz
}
