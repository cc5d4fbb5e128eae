//! Explicit central-difference (velocity-Verlet) stepping of a system with a constant mass
//! matrix of the form M = M_s ⊗ I₃ (issue 17): the ANCF fluid's consistent mass, factored
//! once with faer's sparse Cholesky. A step costs one force evaluation and one forward and
//! back solve with three right-hand sides: no Jacobian, no Newton, no refactorization.
//!
//! # Scheme
//! With a_n = M⁻¹ Q(t_n, q_n, v_n):
//!
//! ```text
//! v_{n+½} = v_n + ½h a_n
//! q_{n+1} = q_n + h v_{n+½}
//! a_{n+1} = M⁻¹ Q(t_{n+1}, q_{n+1}, v_{n+½})
//! v_{n+1} = v_{n+½} + ½h a_{n+1}
//! ```
//!
//! Second order and symplectic for forces that depend on q only; velocity-dependent forces
//! (viscous stress, penalty and contact damping) see the half-step velocity, as in the
//! explicit codes (LS-DYNA, Chrono's explicit steppers): first order in those terms only.
//!
//! # Stable step
//! For a linearized undamped system the scheme is stable for h ≤ 2/ω_max, ω²_max the
//! largest eigenvalue of M⁻¹K (K = −∂Q/∂q); with a modal damping ratio ξ at ω_max,
//! h ≤ (2/ω_max)(√(1+ξ²) − ξ). [`Explicit::estimate_stable_step`] finds ω²_max by power
//! iteration on M⁻¹K, with K·x and C·x (C = −∂Q/∂v) by directional differences of Q (so
//! every force, including wall contact, counts), warm-started from the last eigenvector.
//! The most damped mode need not be the stiffest one (a wall-contact point's gradient
//! coordinates under Hunt–Crossley damping c|ψ|ψ̇ are), so a second power iteration finds
//! μ_max, the largest eigenvalue of M⁻¹C, and the estimate is also bounded by
//! 2/(ω_max + μ_max): for a mode with ω ≤ ω_max and 2ξω = μ ≤ μ_max,
//! (2/ω)(√(1+ξ²) − ξ) = 2/(ω(√(1+ξ²) + ξ)) ≥ 2/(ω + μ) ≥ 2/(ω_max + μ_max) (exact for
//! modally damped systems, a heuristic otherwise).
//! The step used is `safety` × the estimate, re-estimated every `estimate_every` steps.

use faer::sparse::SparseColMat;

use super::linear_solver::{LinearFailure, LinearSolver, SparseCholesky};
use super::{IntegratorError, MechanicalSystem, Quantity, Stats};

/// Parameters of the explicit stepper.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExplicitParams {
    /// Fraction of the estimated stable step used (0 < safety ≤ 1). Default 0.8.
    pub safety: f64,
    /// Steps between stable-step estimates. Default 50.
    pub estimate_every: usize,
    /// Power iterations of an estimate (the first one runs 4× as many). Default 12.
    pub power_iterations: usize,
    /// Largest step, s (also when the estimate allows more). Default 0.01.
    pub max_step: f64,
}

impl Default for ExplicitParams {
    fn default() -> Self {
        Self { safety: 0.8, estimate_every: 50, power_iterations: 12, max_step: 0.01 }
    }
}

impl ExplicitParams {
    /// Checks the ranges.
    pub fn validate(&self) -> Result<(), IntegratorError> {
        let bad = |field, value: f64, allowed| Err(IntegratorError::InvalidParameter { field, value, allowed });
        if !(self.safety > 0.0 && self.safety <= 1.0) {
            return bad("safety", self.safety, "(0, 1]");
        }
        if self.estimate_every == 0 {
            return bad("estimate_every", 0.0, ">= 1");
        }
        if self.power_iterations < 2 {
            return bad("power_iterations", self.power_iterations as f64, ">= 2");
        }
        if !(self.max_step > 0.0 && self.max_step.is_finite()) {
            return bad("max_step", self.max_step, "> 0 s");
        }
        Ok(())
    }
}

/// The constant mass M = M_s ⊗ I₃, factored once with the [`SparseCholesky`] linear solver
/// (sequential, so the solve is bitwise the same for any thread count).
pub struct BlockMass {
    chol: SparseCholesky,
    /// The three right-hand sides, column-major (scalar index × component).
    rhs: Vec<f64>,
}

impl std::fmt::Debug for BlockMass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "BlockMass {{ n: {}, nnz(L): {} }}", self.rhs.len() / 3, self.chol.factor_nnz())
    }
}

impl BlockMass {
    /// Factors the scalar block `m_s` (symmetric positive definite, both triangles stored).
    pub fn new(m_s: &SparseColMat<usize, f64>) -> Result<Self, IntegratorError> {
        let fail = |e: LinearFailure| IntegratorError::InvalidSystem {
            what: format!(
                "mass matrix: {}",
                match e {
                    LinearFailure::Generic(m) => m,
                    other => format!("{other:?}"),
                }
            ),
        };
        let mut chol = SparseCholesky::new(m_s.symbolic()).map_err(fail)?;
        chol.factor(m_s.as_ref()).map_err(fail)?;
        let mut rhs = vec![0.0; 3 * m_s.nrows()];
        // Sizes the solve's scratch now, so that a later solve does not allocate.
        chol.solve(&mut rhs, 3).map_err(fail)?;
        Ok(Self { chol, rhs })
    }

    /// a = M⁻¹ f (coordinates 3s + k: scalar index s, component k).
    pub fn solve(&mut self, f: &[f64], a: &mut [f64]) {
        let n = self.rhs.len() / 3;
        for s in 0..n {
            for k in 0..3 {
                self.rhs[s + n * k] = f[3 * s + k];
            }
        }
        // The solve's scratch was sized in `new`, so it cannot fail; if it ever did, the
        // accelerations are NaN, which the stepper's finiteness check reports.
        if self.chol.solve(&mut self.rhs, 3).is_err() {
            self.rhs.fill(f64::NAN);
        }
        for s in 0..n {
            for k in 0..3 {
                a[3 * s + k] = self.rhs[s + n * k];
            }
        }
    }
}

/// Result of a stable-step estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StableStep {
    /// Largest angular frequency ω_max (rad/s).
    pub omega_max: f64,
    /// Modal damping ratio at ω_max.
    pub damping_ratio: f64,
    /// Largest eigenvalue μ_max of M⁻¹C (1/s): twice the damping rate ξω of the most damped
    /// mode.
    pub damping_max: f64,
    /// Critical step: the smaller of (2/ω)(√(1+ξ²) − ξ) and 2/(ω_max + μ_max), s.
    pub critical: f64,
}

/// Everything that determines an explicit run's following steps: the state `(t, q, v, a)`,
/// the stable-step estimator's state (last estimate, steps since it, the power iterations'
/// warm-start vectors) and the statistics. [`Explicit::restore`] continues from it bit for
/// bit. The byte format ([`Self::to_bytes`]) is that of the HHT checkpoint with the magic
/// `RSLEXPCK`: little-endian, `f64` exact, lengths and counters as u64.
#[derive(Debug, Clone, PartialEq)]
pub struct ExplicitCheckpoint {
    /// Time, s.
    pub t: f64,
    /// Positions.
    pub q: Vec<f64>,
    /// Velocities.
    pub v: Vec<f64>,
    /// Accelerations.
    pub a: Vec<f64>,
    /// Warm start of the stiffness power iteration.
    pub eigenvector: Vec<f64>,
    /// Warm start of the damping power iteration.
    pub damped_vector: Vec<f64>,
    /// The last stable-step estimate.
    pub stable: Option<StableStep>,
    /// Steps since that estimate.
    pub since_estimate: usize,
    /// Statistics at the checkpoint.
    pub stats: Stats,
}

const EXPLICIT_MAGIC: &[u8; 8] = b"RSLEXPCK";
const EXPLICIT_VERSION: u32 = 1;

impl ExplicitCheckpoint {
    /// Serializes to bytes (format in the type docs).
    pub fn to_bytes(&self) -> Vec<u8> {
        use super::hht::checkpoint::Writer;
        let mut w = Writer(Vec::with_capacity(128 + 8 * 5 * self.q.len()));
        w.header(EXPLICIT_MAGIC, EXPLICIT_VERSION);
        w.f64(self.t);
        for x in [&self.q, &self.v, &self.a, &self.eigenvector, &self.damped_vector] {
            w.vec(x);
        }
        w.0.push(u8::from(self.stable.is_some()));
        let s =
            self.stable.unwrap_or(StableStep { omega_max: 0.0, damping_ratio: 0.0, damping_max: 0.0, critical: 0.0 });
        for x in [s.omega_max, s.damping_ratio, s.damping_max, s.critical] {
            w.f64(x);
        }
        w.u64(self.since_estimate as u64);
        w.stats(&self.stats);
        w.0
    }

    /// Decodes [`Self::to_bytes`] output; corruption is an [`IntegratorError::Checkpoint`]
    /// naming the field.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, IntegratorError> {
        use super::hht::checkpoint::{Reader, bad};
        let mut r = Reader { bytes, pos: 0 };
        r.versioned(EXPLICIT_MAGIC, "explicit", EXPLICIT_VERSION)?;
        let t = r.f64("t")?;
        let (q, v, a) = (r.vec("q")?, r.vec("v")?, r.vec("a")?);
        let (eigenvector, damped_vector) = (r.vec("eigenvector")?, r.vec("damped_vector")?);
        let has_stable = r.flag("stable")?;
        let s = StableStep {
            omega_max: r.f64("stable.omega_max")?,
            damping_ratio: r.f64("stable.damping_ratio")?,
            damping_max: r.f64("stable.damping_max")?,
            critical: r.f64("stable.critical")?,
        };
        let since_estimate = r.usize("since_estimate")?;
        let stats = r.stats()?;
        r.finish()?;
        let n = q.len();
        if [v.len(), a.len(), eigenvector.len(), damped_vector.len()].iter().any(|&l| l != n) {
            return Err(bad(format!("q, v, a and the warm-start vectors differ in length (q has {n})")));
        }
        Ok(Self { t, q, v, a, eigenvector, damped_vector, stable: has_stable.then_some(s), since_estimate, stats })
    }
}

/// The operator of a power iteration (M⁻¹K or M⁻¹C).
#[derive(Debug, Clone, Copy)]
enum Operator {
    /// K = −∂Q/∂q.
    Stiffness,
    /// C = −∂Q/∂v.
    Damping,
}

fn norm(x: &[f64]) -> f64 {
    x.iter().map(|a| a * a).sum::<f64>().sqrt()
}

/// Explicit central-difference stepper of a constant-mass system (module docs).
pub struct Explicit<S: MechanicalSystem> {
    system: S,
    mass: BlockMass,
    params: ExplicitParams,
    t: f64,
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    force: Vec<f64>,
    eigenvector: Vec<f64>,
    damped_vector: Vec<f64>,
    stable: Option<StableStep>,
    since_estimate: usize,
    stats: Stats,
}

impl<S: MechanicalSystem> std::fmt::Debug for Explicit<S> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Explicit {{ t: {}, n: {}, stable: {:?} }}", self.t, self.q.len(), self.stable)
    }
}

fn non_finite(t: f64, what: Quantity, x: &[f64]) -> Result<(), IntegratorError> {
    match x.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(IntegratorError::NonFinite { t, what, index }),
        None => Ok(()),
    }
}

impl<S: MechanicalSystem> Explicit<S> {
    /// Starts at `(t0, q0, v0)`; `m_s` is the scalar block of the system's mass
    /// (M = M_s ⊗ I₃, `n_coords = 3 × m_s.nrows()`), factored here once.
    pub fn new(
        mut system: S,
        m_s: &SparseColMat<usize, f64>,
        t0: f64,
        q0: Vec<f64>,
        v0: Vec<f64>,
        params: ExplicitParams,
    ) -> Result<Self, IntegratorError> {
        params.validate()?;
        let n = system.n_coords();
        if system.n_constraints() != 0 || 3 * m_s.nrows() != n || q0.len() != n || v0.len() != n {
            return Err(IntegratorError::InvalidSystem {
                what: format!(
                    "explicit stepping needs an unconstrained system with M = M_s ⊗ I3: n = {n}, \
                     3 × dim M_s = {}, constraints {}, |q0| = {}, |v0| = {}",
                    3 * m_s.nrows(),
                    system.n_constraints(),
                    q0.len(),
                    v0.len()
                ),
            });
        }
        let mut mass = BlockMass::new(m_s)?;
        let mut force = vec![0.0; n];
        system.forces(t0, &q0, &v0, &mut force).map_err(|source| IntegratorError::System { t: t0, source })?;
        non_finite(t0, Quantity::Forces, &force)?;
        let mut a = vec![0.0; n];
        mass.solve(&force, &mut a);
        // a smooth, deterministic start vector for the power iteration
        let eigenvector: Vec<f64> = (0..n).map(|i| (i as f64 * 0.618_033_988_75).fract() - 0.5).collect();
        let damped_vector = eigenvector.clone();
        let stats = Stats { residual_evaluations: 1, linear_solves: 1, ..Default::default() };
        Ok(Self {
            system,
            mass,
            params,
            t: t0,
            q: q0,
            v: v0,
            a,
            force,
            eigenvector,
            damped_vector,
            stable: None,
            since_estimate: 0,
            stats,
        })
    }

    /// Snapshot of everything that determines the following steps ([`ExplicitCheckpoint`]).
    /// Taking it does not change the run.
    pub fn checkpoint(&self) -> ExplicitCheckpoint {
        ExplicitCheckpoint {
            t: self.t,
            q: self.q.clone(),
            v: self.v.clone(),
            a: self.a.clone(),
            eigenvector: self.eigenvector.clone(),
            damped_vector: self.damped_vector.clone(),
            stable: self.stable,
            since_estimate: self.since_estimate,
            stats: self.stats,
        }
    }

    /// Continues a run from `checkpoint` with the same `system` (rebuilt by the caller: same
    /// mesh, fluid, tank, motion) and its mass block `m_s`; the steps that follow are bit for
    /// bit those of the uninterrupted run.
    pub fn restore(
        system: S,
        m_s: &SparseColMat<usize, f64>,
        checkpoint: &ExplicitCheckpoint,
        params: ExplicitParams,
    ) -> Result<Self, IntegratorError> {
        params.validate()?;
        let n = system.n_coords();
        if system.n_constraints() != 0 || 3 * m_s.nrows() != n || checkpoint.q.len() != n {
            return Err(IntegratorError::Checkpoint {
                what: format!(
                    "the checkpoint has {} coordinates; the system has {n} (3 × dim M_s = {}, constraints {})",
                    checkpoint.q.len(),
                    3 * m_s.nrows(),
                    system.n_constraints()
                ),
            });
        }
        let c = checkpoint.clone();
        Ok(Self {
            system,
            mass: BlockMass::new(m_s)?,
            params,
            t: c.t,
            q: c.q,
            v: c.v,
            a: c.a,
            force: vec![0.0; n],
            eigenvector: c.eigenvector,
            damped_vector: c.damped_vector,
            stable: c.stable,
            since_estimate: c.since_estimate,
            stats: c.stats,
        })
    }

    /// Current time, s.
    pub fn t(&self) -> f64 {
        self.t
    }
    /// Current coordinates.
    pub fn q(&self) -> &[f64] {
        &self.q
    }
    /// Current velocities.
    pub fn v(&self) -> &[f64] {
        &self.v
    }
    /// Current accelerations.
    pub fn a(&self) -> &[f64] {
        &self.a
    }
    /// The system.
    pub fn system(&self) -> &S {
        &self.system
    }
    /// The system, mutably.
    pub fn system_mut(&mut self) -> &mut S {
        &mut self.system
    }
    /// Consumes the stepper and returns the system.
    pub fn into_system(self) -> S {
        self.system
    }
    /// Counters: steps, force evaluations (`residual_evaluations`), mass solves.
    pub fn stats(&self) -> &Stats {
        &self.stats
    }
    /// The parameters.
    pub fn params(&self) -> &ExplicitParams {
        &self.params
    }
    /// The last stable-step estimate, if any.
    pub fn last_estimate(&self) -> Option<StableStep> {
        self.stable
    }

    fn eval(&mut self, t: f64, q: &[f64], v: &[f64], out: &mut [f64]) -> Result<(), IntegratorError> {
        self.stats.residual_evaluations += 1;
        self.system.forces(t, q, v, out).map_err(|source| IntegratorError::System { t, source })
    }

    /// `y = M⁻¹ A x`, A = K = −∂Q/∂q or C = −∂Q/∂v, by a directional difference at `(t, q, v)`
    /// (`f0 = Q(t, q, v)`; `fp` is scratch).
    #[allow(clippy::too_many_arguments)]
    fn apply(
        &mut self,
        op: Operator,
        t: f64,
        q: &[f64],
        v: &[f64],
        f0: &[f64],
        x: &[f64],
        fp: &mut [f64],
        y: &mut [f64],
    ) -> Result<(), IntegratorError> {
        let size = |z: &[f64]| z.iter().fold(0.0_f64, |m, a| m.max(a.abs())).max(1.0);
        let eps = match op {
            Operator::Stiffness => {
                let eps = 1e-7 * size(q);
                let qp: Vec<f64> = q.iter().zip(x).map(|(a, b)| a + eps * b).collect();
                self.eval(t, &qp, v, fp)?;
                eps
            }
            Operator::Damping => {
                let eps = 1e-7 * size(v);
                let vp: Vec<f64> = v.iter().zip(x).map(|(a, b)| a + eps * b).collect();
                self.eval(t, q, &vp, fp)?;
                eps
            }
        };
        for i in 0..fp.len() {
            fp[i] = -(fp[i] - f0[i]) / eps; // A x
        }
        self.mass.solve(fp, y);
        self.stats.linear_solves += 1;
        Ok(())
    }

    /// `iterations` power iterations on M⁻¹A (A as in [`Self::apply`]) from `x` (left
    /// unnormalized, for the next estimate's warm start); the dominant eigenvalue.
    #[allow(clippy::too_many_arguments)]
    fn dominant(
        &mut self,
        op: Operator,
        x: &mut Vec<f64>,
        iterations: usize,
        t: f64,
        q: &[f64],
        v: &[f64],
        f0: &[f64],
    ) -> Result<f64, IntegratorError> {
        let n = x.len();
        let (mut fp, mut y) = (vec![0.0; n], vec![0.0; n]);
        let mut lambda = 0.0;
        for _ in 0..iterations {
            let nx = norm(x);
            if nx.is_nan() || nx <= 0.0 {
                break;
            }
            x.iter_mut().for_each(|a| *a /= nx);
            self.apply(op, t, q, v, f0, x, &mut fp, &mut y)?;
            lambda = x.iter().zip(&y).map(|(a, b)| a * b).sum::<f64>().abs().max(norm(&y));
            std::mem::swap(x, &mut y);
        }
        Ok(lambda)
    }

    /// Estimates the critical step at the current state (module docs); `iterations` power
    /// iterations from the last eigenvector.
    pub fn estimate_stable_step(&mut self, iterations: usize) -> Result<StableStep, IntegratorError> {
        let n = self.q.len();
        let (t, q, v) = (self.t, self.q.clone(), self.v.clone());
        let mut f0 = vec![0.0; n];
        self.eval(t, &q, &v, &mut f0)?;
        let mut x = std::mem::take(&mut self.eigenvector);
        let lambda = self.dominant(Operator::Stiffness, &mut x, iterations, t, &q, &v, &f0)?;
        let nx = norm(&x);
        if nx > 0.0 {
            x.iter_mut().for_each(|a| *a /= nx);
        }
        // damping ratio at the mode: ξ = (xᵀ C x)/(2 ω xᵀ M x), C x and M x by differences
        let omega = lambda.max(0.0).sqrt();
        let mut xi = 0.0;
        if omega > 0.0 {
            let (mut fp, mut y) = (vec![0.0; n], vec![0.0; n]);
            self.apply(Operator::Damping, t, &q, &v, &f0, &x, &mut fp, &mut y)?;
            // M⁻¹C x ≈ 2 ξ ω x along the mode
            xi = (x.iter().zip(&y).map(|(a, b)| a * b).sum::<f64>() / (2.0 * omega)).max(0.0);
        }
        self.eigenvector = x;
        if !(omega.is_finite() && omega > 0.0) {
            return Err(IntegratorError::InvalidSystem {
                what: format!("stable-step estimate at t = {t} s: no positive stiffness found (ω² = {lambda})"),
            });
        }
        // μ_max: power iteration on M⁻¹C
        let mut x = std::mem::take(&mut self.damped_vector);
        let mu = self.dominant(Operator::Damping, &mut x, iterations, t, &q, &v, &f0)?;
        self.damped_vector = x;
        let mu = if mu.is_finite() { mu } else { 0.0 };
        let critical = (2.0 / omega * ((1.0 + xi * xi).sqrt() - xi)).min(2.0 / (omega + mu));
        let s = StableStep { omega_max: omega, damping_ratio: xi, damping_max: mu, critical };
        self.stable = Some(s);
        self.since_estimate = 0;
        Ok(s)
    }

    /// The step the stepper takes now: `safety` × the critical step (re-estimated when
    /// due), at most `max_step`.
    pub fn stable_step(&mut self) -> Result<f64, IntegratorError> {
        let due = match self.stable {
            None => Some(4 * self.params.power_iterations),
            Some(_) if self.since_estimate >= self.params.estimate_every => Some(self.params.power_iterations),
            Some(_) => None,
        };
        let s = match due {
            Some(it) => self.estimate_stable_step(it)?,
            None => self.stable.expect("estimated above"),
        };
        Ok((self.params.safety * s.critical).min(self.params.max_step))
    }

    /// One velocity-Verlet step of size `h` (module docs), whatever its stability.
    pub fn step(&mut self, h: f64) -> Result<(), IntegratorError> {
        if !(h > 0.0 && h.is_finite()) {
            return Err(IntegratorError::InvalidParameter { field: "h", value: h, allowed: "> 0 s" });
        }
        let n = self.q.len();
        for i in 0..n {
            self.v[i] += 0.5 * h * self.a[i];
            self.q[i] += h * self.v[i];
        }
        let t = self.t + h;
        let mut force = std::mem::take(&mut self.force);
        let (q, v) = (std::mem::take(&mut self.q), std::mem::take(&mut self.v));
        let r = self.eval(t, &q, &v, &mut force);
        (self.q, self.v) = (q, v);
        r?;
        non_finite(t, Quantity::Forces, &force)?;
        self.mass.solve(&force, &mut self.a);
        self.force = force;
        self.stats.linear_solves += 1;
        for i in 0..n {
            self.v[i] += 0.5 * h * self.a[i];
        }
        non_finite(t, Quantity::Velocities, &self.v)?;
        self.t = t;
        self.stats.steps += 1;
        self.since_estimate += 1;
        Ok(())
    }

    /// Steps to `t_end` with stable steps (the last one shortened to land on it); returns
    /// the number of steps.
    pub fn advance_to(&mut self, t_end: f64) -> Result<usize, IntegratorError> {
        let mut steps = 0;
        while t_end - self.t > 1e-12 * (1.0 + t_end.abs()) {
            let h_stable = self.stable_step()?;
            let left = t_end - self.t;
            // spread the interval over equal steps no larger than the stable one
            let k = (left / h_stable).ceil().max(1.0);
            self.step(left / k)?;
            steps += 1;
        }
        self.t = self.t.max(t_end);
        Ok(steps)
    }
}
