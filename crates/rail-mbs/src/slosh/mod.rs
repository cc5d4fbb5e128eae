//! Fluid sloshing in a rigid tank with prescribed motion: the system, the run driver and
//! the recorded outputs.
//!
//! Data flow: [`SloshSystem`] (fluid body + wall contact + motion) → [`SloshRun`] (HHT
//! integrator loop) → [`SloshRecord`] (time series, recorded every step); [`modes`] gives the
//! small-amplitude modes of a [`SloshSystem`] about a state at rest.

pub mod analysis;
pub mod checkpoint;
pub mod linear_theory;
pub mod modes;
pub mod motion;
pub mod scenario;
pub mod system;

pub use checkpoint::SloshCheckpoint;
pub use modes::{LinearModes, linear_modes, mass_normalized_eigen};
pub use motion::{PiecewiseAcceleration, PrescribedMotion, TankFrameInput, TankFrameSample, TankState};
pub use scenario::SloshScenario;
pub use system::{SloshFrame, SloshSystem};

use nalgebra::Vector3;

use crate::integrator::{
    Checkpoint, CheckpointFile, Explicit, ExplicitParams, Hht, HhtParams, IntegratorError, Journal, Stats,
};
use crate::invariants::{EnergySample, InvariantMonitor, Margins};
use crate::observe::{Observer, RunFailure, RunStepper, step_to};

/// Time series recorded by a slosh run. Loads are the force and moment the fluid exerts on
/// the tank (through wall and bulkhead contact), moments about the tank origin.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SloshRecord {
    /// Time (s).
    pub t: Vec<f64>,
    /// Fluid force on the tank, tank frame (N).
    pub force_tank: Vec<[f64; 3]>,
    /// Fluid moment on the tank about its origin, tank frame (N·m).
    pub moment_tank: Vec<[f64; 3]>,
    /// Fluid force on the tank, global frame (N).
    pub force_global: Vec<[f64; 3]>,
    /// Fluid moment on the tank about its origin, global frame (N·m).
    pub moment_global: Vec<[f64; 3]>,
    /// Fluid centre of mass in the tank frame (m).
    pub com_tank: Vec<[f64; 3]>,
    /// Fluid volume ∫J dV₀ (m³).
    pub volume: Vec<f64>,
    /// Kinetic energy (J), inertial velocities.
    pub kinetic_energy: Vec<f64>,
    /// Gravitational potential energy (J).
    pub potential_energy: Vec<f64>,
    /// Newton iterations of the step (implicit), or explicit sub-steps since the last
    /// sample.
    pub newton_iterations: Vec<usize>,
    /// Largest wall penetration (m).
    pub max_penetration: Vec<f64>,
    /// Stored elastic energy: volumetric penalty + contact springs (J).
    pub stored_energy: Vec<f64>,
    /// Work put into the liquid since the start (J): by the walls (inertial frame), or by
    /// gravity and the pseudo-forces (tank frame); see [`crate::invariants`].
    pub input_work: Vec<f64>,
    /// Energy growth ε = (E − E₀ − W_in)/E_ref (≤ 0 for a physical run; [`crate::invariants`]).
    pub energy_error: Vec<f64>,
    /// Smallest volume ratio J = det F at any quadrature point.
    pub min_volume_ratio: Vec<f64>,
    /// Largest wall gap of any fluid node, contact point or the centre of mass (m).
    pub containment_gap: Vec<f64>,
}

impl SloshRecord {
    /// Column names of [`SloshRecord::row`] (vectors as `_x`, `_y`, `_z`).
    pub const COLUMNS: [&'static str; 26] = [
        "t",
        "force_tank_x",
        "force_tank_y",
        "force_tank_z",
        "moment_tank_x",
        "moment_tank_y",
        "moment_tank_z",
        "force_global_x",
        "force_global_y",
        "force_global_z",
        "moment_global_x",
        "moment_global_y",
        "moment_global_z",
        "com_tank_x",
        "com_tank_y",
        "com_tank_z",
        "volume",
        "kinetic_energy",
        "potential_energy",
        "newton_iterations",
        "max_penetration",
        "stored_energy",
        "input_work",
        "energy_error",
        "min_volume_ratio",
        "containment_gap",
    ];

    /// Sample `i` as one row of [`SloshRecord::COLUMNS`].
    pub fn row(&self, i: usize) -> Vec<f64> {
        let mut r = vec![self.t[i]];
        for v in [&self.force_tank, &self.moment_tank, &self.force_global, &self.moment_global, &self.com_tank] {
            r.extend_from_slice(&v[i]);
        }
        r.extend([
            self.volume[i],
            self.kinetic_energy[i],
            self.potential_energy[i],
            self.newton_iterations[i] as f64,
            self.max_penetration[i],
            self.stored_energy[i],
            self.input_work[i],
            self.energy_error[i],
            self.min_volume_ratio[i],
            self.containment_gap[i],
        ]);
        r
    }
}

/// The time stepper of a slosh run (issue 17): implicit HHT-α (Newton on the sparse
/// system), or explicit central differences with the constant mass factored once
/// ([`crate::integrator::Explicit`]), sub-stepping within each recorded step at the stable
/// step.
#[allow(clippy::large_enum_variant)] // one per run, never moved in a loop
pub enum SloshStepper {
    /// Implicit HHT-α.
    Implicit(Hht<SloshSystem>),
    /// Explicit central differences.
    Explicit(Box<Explicit<SloshSystem>>),
}

impl std::fmt::Debug for SloshStepper {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "SloshStepper::{}(t = {})", self.name(), self.t())
    }
}

impl SloshStepper {
    /// Current time, s.
    pub fn t(&self) -> f64 {
        match self {
            Self::Implicit(h) => h.t(),
            Self::Explicit(e) => e.t(),
        }
    }
    /// Current coordinates.
    pub fn q(&self) -> &[f64] {
        match self {
            Self::Implicit(h) => h.q(),
            Self::Explicit(e) => e.q(),
        }
    }
    /// Current velocities.
    pub fn v(&self) -> &[f64] {
        match self {
            Self::Implicit(h) => h.v(),
            Self::Explicit(e) => e.v(),
        }
    }
    /// The system.
    pub fn system(&self) -> &SloshSystem {
        match self {
            Self::Implicit(h) => h.system(),
            Self::Explicit(e) => e.system(),
        }
    }
    /// The system, mutably (the implicit stepper then re-evaluates its cached forces).
    pub fn system_mut(&mut self) -> &mut SloshSystem {
        match self {
            Self::Implicit(h) => h.system_mut(),
            Self::Explicit(e) => e.system_mut(),
        }
    }
    /// Counters (for the explicit stepper: steps, force evaluations, mass solves).
    pub fn stats(&self) -> &Stats {
        match self {
            Self::Implicit(h) => h.stats(),
            Self::Explicit(e) => e.stats(),
        }
    }
    /// The implicit integrator, if this is one.
    pub fn hht(&self) -> Option<&Hht<SloshSystem>> {
        match self {
            Self::Implicit(h) => Some(h),
            Self::Explicit(_) => None,
        }
    }
    /// Name: `"implicit"` or `"explicit"`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Implicit(_) => "implicit",
            Self::Explicit(_) => "explicit",
        }
    }
    /// Consumes the stepper and returns the system.
    pub fn into_system(self) -> SloshSystem {
        match self {
            Self::Implicit(h) => h.into_system(),
            Self::Explicit(e) => e.into_system(),
        }
    }
    /// Advances by one recorded step to `t + h`: one HHT step (it may take a shorter
    /// one), or explicit sub-steps landing on `t + h`. Returns the Newton iterations
    /// (implicit) or the sub-steps (explicit).
    fn advance(&mut self, h: f64) -> Result<usize, IntegratorError> {
        match self {
            Self::Implicit(hht) => hht.step(h).map(|i| i.iterations),
            Self::Explicit(e) => {
                let t = e.t() + h;
                e.advance_to(t)
            }
        }
    }
}

/// A slosh run steps its stepper and records every step: a step toward `target` is one
/// `SloshStepper::advance` of `min(h, target − t)`.
impl RunStepper for SloshRun {
    fn t(&self) -> f64 {
        self.stepper.t()
    }
    fn stats(&self) -> &Stats {
        self.stepper.stats()
    }
    fn step_toward(&mut self, target: f64, h: f64) -> Result<usize, IntegratorError> {
        let t = self.stepper.t();
        self.stepper.advance(h.min(target - t))
    }
}

/// Which stepper a slosh run uses (scene `[solver] stepper`, Python `stepper=`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StepperChoice {
    /// Implicit HHT-α (default).
    #[default]
    Implicit,
    /// Explicit central differences, constant mass factored once.
    Explicit,
    /// The cheaper of the two, from the stable step at the start (see
    /// [`IMPLICIT_STEP_COST`]).
    Auto,
}

impl StepperChoice {
    /// Parses `"implicit"`, `"explicit"` or `"auto"`.
    pub fn parse(name: &str) -> Result<Self, ancf_core::error::AncfError> {
        match name {
            "implicit" => Ok(Self::Implicit),
            "explicit" => Ok(Self::Explicit),
            "auto" => Ok(Self::Auto),
            other => Err(ancf_core::error::invalid("stepper", other, "\"implicit\", \"explicit\" or \"auto\"")),
        }
    }
}

/// Cost of one implicit slosh step in force evaluations (what one explicit step costs),
/// measured with `cargo run --release -p rail-mbs --example explicit_bench` (docs/benchmarks.md,
/// "Explicit against implicit"): Newton iterations × (force + Jacobian share + sparse solve).
pub const IMPLICIT_STEP_COST: f64 = 25.0;

/// Called with the run after every accepted, recorded step ([`SloshRun::run_to_inspected`]);
/// an error stops the run.
pub type Inspector<'a> = &'a mut dyn FnMut(&SloshRun) -> Result<(), IntegratorError>;

/// A slosh run: the stepper, its system and the record.
pub struct SloshRun {
    /// The time stepper (owns the system).
    pub stepper: SloshStepper,
    /// Outputs so far.
    pub record: SloshRecord,
    /// Periodic checkpoints (`None`: none written): after every accepted step the file
    /// is rewritten once `every` steps have passed since the last one (issue 8), as a
    /// [`SloshCheckpoint`] (the stepper's checkpoint and the invariants' account).
    pub checkpoints: Option<CheckpointFile>,
    /// The run-time invariants, checked on every accepted step (issue 16). A run resumed
    /// from a [`SloshCheckpoint`] goes on with the account it saved.
    pub invariants: InvariantMonitor,
    /// Fluid snapshots (issue 19): time and the nodal coordinates in the **tank frame** (12
    /// per node: position and the three position gradients), taken every
    /// [`SloshRun::set_snapshot_every`] seconds at the first recorded step on or after each
    /// multiple; a violating state is recorded before the run stops, so it is in here too.
    pub snapshots: Vec<(f64, Vec<f64>)>,
    snapshot_every: f64,
    next_snapshot: f64,
}

/// A failed run: the error and everything recorded up to the last accepted step.
pub type SloshFailure = RunFailure<SloshRecord>;

impl std::fmt::Display for RunFailure<SloshRecord> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "slosh run failed after {} recorded steps: {}", self.record.t.len(), self.error)
    }
}

impl SloshRun {
    /// Start at t0 from the system's initial state (fluid moving rigidly with the tank).
    pub fn new(system: SloshSystem, t0: f64, params: HhtParams) -> Result<Self, IntegratorError> {
        let (q, v) = system.initial_state(t0);
        let hht = Hht::new(system, t0, q, v, params)?;
        Self::with_stepper(SloshStepper::Implicit(hht))
    }

    /// [`SloshRun::new`] with the explicit stepper (issue 17): the fluid's constant mass
    /// is factored once and each recorded step is sub-stepped at the stable step.
    pub fn new_explicit(system: SloshSystem, t0: f64, params: ExplicitParams) -> Result<Self, IntegratorError> {
        let (q, v) = system.initial_state(t0);
        let m_s = system.body.scalar_mass().clone();
        let e = Explicit::new(system, &m_s, t0, q, v, params)?;
        Self::with_stepper(SloshStepper::Explicit(Box::new(e)))
    }

    /// A run with the stepper `choice` for recorded steps of `h`; returns it with the
    /// reason of the choice (for `auto`: the estimated cost of both per recorded step).
    pub fn with_choice(
        system: SloshSystem,
        t0: f64,
        choice: StepperChoice,
        h: f64,
        implicit: HhtParams,
        explicit: ExplicitParams,
    ) -> Result<(Self, String), IntegratorError> {
        match choice {
            StepperChoice::Implicit => Ok((Self::new(system, t0, implicit)?, "requested: implicit".into())),
            StepperChoice::Explicit => Ok((Self::new_explicit(system, t0, explicit)?, "requested: explicit".into())),
            StepperChoice::Auto => {
                let (q, v) = system.initial_state(t0);
                let m_s = system.body.scalar_mass().clone();
                let mut e = Explicit::new(system, &m_s, t0, q, v, explicit)?;
                let h_e = e.stable_step()?;
                let explicit_cost = (h / h_e).ceil();
                let reason = format!(
                    "auto: stable explicit step {h_e:.3e} s, {explicit_cost:.0} force evaluations per {h} s step \
                     against about {IMPLICIT_STEP_COST:.0} for an implicit step"
                );
                if explicit_cost <= IMPLICIT_STEP_COST {
                    Ok((Self::with_stepper(SloshStepper::Explicit(Box::new(e)))?, format!("{reason}: explicit")))
                } else {
                    Ok((Self::new(e.into_system(), t0, implicit)?, format!("{reason}: implicit")))
                }
            }
        }
    }

    fn with_stepper(stepper: SloshStepper) -> Result<Self, IntegratorError> {
        Self::with_account(stepper, None)
    }

    /// A run of `stepper` whose invariants go on from `account` (saved by
    /// [`InvariantMonitor::save_account`]; `None`: a fresh account), with its first sample
    /// recorded.
    fn with_account(stepper: SloshStepper, account: Option<&[f64]>) -> Result<Self, IntegratorError> {
        let mut invariants = stepper.system().invariant_monitor();
        if let Some(data) = account
            && invariants.restore_whole_account(data).is_none()
        {
            return Err(crate::integrator::bad_checkpoint(
                "the invariants' account does not fit this run (a checkpoint of another slosh run?)",
            ));
        }
        let mut run = Self {
            stepper,
            record: SloshRecord::default(),
            checkpoints: None,
            invariants,
            snapshots: Vec::new(),
            snapshot_every: 0.0,
            next_snapshot: f64::INFINITY,
        };
        run.record_state(0)?;
        Ok(run)
    }

    /// Takes a fluid snapshot now and then every `every` s of simulated time (0: none, the
    /// default); earlier snapshots are dropped.
    pub fn set_snapshot_every(&mut self, every: f64) -> Result<(), IntegratorError> {
        if !(every.is_finite() && every >= 0.0) {
            return Err(IntegratorError::InvalidParameter {
                field: "snapshot_every",
                value: every,
                allowed: "a finite interval >= 0 s",
            });
        }
        self.snapshots.clear();
        self.snapshot_every = every;
        self.next_snapshot = if every > 0.0 { self.stepper.t() } else { f64::INFINITY };
        self.take_snapshot();
        Ok(())
    }

    /// The current state's nodal coordinates in the tank frame, if a snapshot is due.
    fn take_snapshot(&mut self) {
        let t = self.stepper.t();
        if self.snapshot_every <= 0.0 || t < self.next_snapshot - 1e-9 * self.snapshot_every {
            return;
        }
        while self.next_snapshot <= t + 1e-9 * self.snapshot_every {
            self.next_snapshot += self.snapshot_every;
        }
        let sys = self.stepper.system();
        let q = self.stepper.q();
        let e = match sys.frame {
            SloshFrame::Tank => q.to_vec(),
            SloshFrame::Inertial => {
                let k = sys.motion.state(t).kinematics;
                let (at, r) = (k.rotation.transpose(), Vector3::from(k.position));
                let mut e = vec![0.0; q.len()];
                for (s, (out, x)) in e.chunks_exact_mut(3).zip(q.chunks_exact(3)).enumerate() {
                    let x = Vector3::new(x[0], x[1], x[2]);
                    let y = if s % 4 == 0 { at * (x - r) } else { at * x };
                    out.copy_from_slice(y.as_slice());
                }
                e
            }
        };
        self.snapshots.push((t, e));
    }

    /// Resume from a checkpoint of an earlier run of the same system (same mesh, fluid,
    /// tank, motion and parameters): the record starts with the checkpoint's state, and
    /// the continuation is bitwise identical to the uninterrupted run's (its first
    /// sample reports 0 Newton iterations). Implicit runs; [`Self::resume_from_bytes`] takes
    /// either kind.
    pub fn resume(system: SloshSystem, checkpoint: &Checkpoint, params: HhtParams) -> Result<Self, IntegratorError> {
        let hht = Hht::restore(system, checkpoint, params)?;
        Self::with_stepper(SloshStepper::Implicit(hht))
    }

    /// Resume from the bytes of a checkpoint file, continuing bit for bit; `implicit`/`explicit`
    /// are the stepper parameters of the original run. A [`SloshCheckpoint`] (what
    /// [`SloshRun::checkpoints`] writes) also restores the invariants' account, so energy error,
    /// input work and worst margins go on as in the uninterrupted run. A bare stepper
    /// checkpoint of either kind (told apart by their magics; what runs wrote before
    /// 2026-11-28) is taken too, with a fresh account starting at the checkpoint.
    pub fn resume_from_bytes(
        system: SloshSystem,
        bytes: &[u8],
        implicit: HhtParams,
        explicit: ExplicitParams,
    ) -> Result<Self, IntegratorError> {
        let whole;
        let (stepper_bytes, account) = if SloshCheckpoint::is_one(bytes) {
            whole = SloshCheckpoint::from_bytes(bytes)?;
            (&whole.stepper[..], Some(&whole.account[..]))
        } else {
            (bytes, None)
        };
        let stepper = if stepper_bytes.starts_with(b"RSLEXPCK") {
            let cp = crate::integrator::ExplicitCheckpoint::from_bytes(stepper_bytes)?;
            let m_s = system.body.scalar_mass().clone();
            SloshStepper::Explicit(Box::new(Explicit::restore(system, &m_s, &cp, explicit)?))
        } else {
            SloshStepper::Implicit(Hht::restore(system, &Checkpoint::from_bytes(stepper_bytes)?, implicit)?)
        };
        Self::with_account(stepper, account)
    }

    /// This run's checkpoint now (what [`SloshRun::checkpoints`] writes).
    pub fn checkpoint(&self) -> SloshCheckpoint {
        let stepper = match &self.stepper {
            SloshStepper::Implicit(hht) => hht.checkpoint().to_bytes(),
            SloshStepper::Explicit(e) => e.checkpoint().to_bytes(),
        };
        let mut account = Vec::new();
        self.invariants.save_account(&mut account);
        SloshCheckpoint { stepper, account }
    }

    /// Write a checkpoint if one is due.
    fn checkpoint_if_due(&mut self) -> Result<(), IntegratorError> {
        let steps = self.stepper.stats().steps;
        let Some(mut file) = self.checkpoints.take() else {
            return Ok(());
        };
        let written = file.maybe_write_bytes(steps, || self.checkpoint().to_bytes());
        self.checkpoints = Some(file);
        written.map(|_| ())
    }

    /// Integrate to `t_end` with steps of (at most) `h`, recording every step.
    pub fn run_to(&mut self, t_end: f64, h: f64) -> Result<(), Box<SloshFailure>> {
        self.run_to_observed(t_end, h, &mut |_| true)
    }

    /// [`SloshRun::run_to`] calling `observe` after every accepted step; the run stops
    /// (with [`crate::vehicle::stopped_by_observer`]) when it returns `false`.
    pub fn run_to_observed(&mut self, t_end: f64, h: f64, observe: Observer<'_>) -> Result<(), Box<SloshFailure>> {
        self.step_loop(t_end, h, observe, None, None)
    }

    /// [`SloshRun::run_to`] handing the run to `inspect` after every accepted step, once the
    /// step is recorded (e.g. to evaluate a quantity of the state that the record does not
    /// carry); an error from `inspect` stops the run. The steps are those of `run_to`.
    pub fn run_to_inspected(&mut self, t_end: f64, h: f64, inspect: Inspector<'_>) -> Result<(), Box<SloshFailure>> {
        self.step_loop(t_end, h, &mut |_| true, None, Some(inspect))
    }

    /// The step loop of every run method ([`step_to`], the loop of every run kind): step,
    /// record, append the sample to `journal` (if any), write a due checkpoint, hand the run
    /// to `inspect` (if any), and ask `observe` whether to go on.
    fn step_loop(
        &mut self,
        t_end: f64,
        h: f64,
        observe: Observer<'_>,
        mut journal: Option<&mut Journal>,
        mut inspect: Option<Inspector<'_>>,
    ) -> Result<(), Box<SloshFailure>> {
        step_to(self, t_end, h, t_end, observe, |run, iterations| {
            run.record_state(iterations)?;
            if let Some(j) = journal.as_deref_mut() {
                j.append(&run.record.row(run.record.t.len() - 1))?;
            }
            run.checkpoint_if_due()?;
            match inspect.as_deref_mut() {
                Some(f) => f(run),
                None => Ok(()),
            }
        })
        .map_err(|error| Box::new(SloshFailure { error, record: self.record.clone() }))
    }

    /// [`SloshRun::run_to_observed`] that also appends every recorded sample (and any
    /// not yet written) to `journal` (columns [`SloshRecord::COLUMNS`], created by the
    /// caller), flushed as the journal says: an interrupted run keeps every sample already
    /// written (read back with [`crate::integrator::read_journal`]). Results are the same
    /// as without the journal.
    pub fn run_to_journaled(
        &mut self,
        t_end: f64,
        h: f64,
        observe: Observer<'_>,
        journal: &mut Journal,
    ) -> Result<(), Box<SloshFailure>> {
        let fail = |run: &Self, error| Box::new(SloshFailure { error, record: run.record.clone() });
        while journal.rows() < self.record.t.len() {
            journal.append(&self.record.row(journal.rows())).map_err(|e| fail(self, e))?;
        }
        self.step_loop(t_end, h, observe, Some(&mut *journal), None)?;
        journal.flush().map_err(|e| fail(self, e))
    }

    /// Integrator statistics.
    pub fn stats(&self) -> &Stats {
        self.stepper.stats()
    }

    /// Worst invariant margins so far (containment gap, energy growth, volume ratio).
    pub fn margins(&self) -> Margins {
        self.invariants.margins()
    }

    /// Records the current (accepted) state, then checks the run-time invariants on it
    /// ([`crate::invariants`]): a violation is returned as a located error at this time,
    /// with the violating sample recorded.
    fn record_state(&mut self, iterations: usize) -> Result<(), IntegratorError> {
        let sys = self.stepper.system();
        let (t, q, v) = (self.stepper.t(), self.stepper.q(), self.stepper.v());
        let load = sys.contact_load(t, q, v);
        let state = sys.motion.state(t);
        let a = state.kinematics.rotation;
        let (f, m) = (Vector3::from(load.force), Vector3::from(load.moment));
        let (fk, mk, fg, mg) = match sys.frame {
            SloshFrame::Inertial => (a.transpose() * f, a.transpose() * m, f, m),
            SloshFrame::Tank => (f, m, a * f, a * m),
        };
        let body = &sys.body;
        let com = Vector3::from(body.center_of_mass(q));
        let com_tank = match sys.frame {
            SloshFrame::Inertial => a.transpose() * (com - Vector3::from(state.kinematics.position)),
            SloshFrame::Tank => com,
        };
        // inertial velocity and position for the energies
        let kin = sys.contact_kinematics(t);
        let stored = crate::invariants::stored_energy(body, &sys.contact, &kin, q);
        let (ke, pe) = match sys.frame {
            SloshFrame::Inertial => (body.kinetic_energy(v), body.potential_energy(q, sys.gravity)),
            SloshFrame::Tank => {
                let (w, rt, vt) = (
                    Vector3::from(state.kinematics.angular_velocity),
                    Vector3::from(state.kinematics.position),
                    Vector3::from(state.kinematics.velocity),
                );
                let mut qi = vec![0.0; q.len()];
                let mut vi = vec![0.0; q.len()];
                for s in 0..q.len() / 3 {
                    let x = a * Vector3::new(q[3 * s], q[3 * s + 1], q[3 * s + 2]);
                    let xd = a * Vector3::new(v[3 * s], v[3 * s + 1], v[3 * s + 2]) + w.cross(&x);
                    let (p, pd) = if s % 4 == 0 { (x + rt, xd + vt) } else { (x, xd) };
                    qi[3 * s..3 * s + 3].copy_from_slice(p.as_slice());
                    vi[3 * s..3 * s + 3].copy_from_slice(pd.as_slice());
                }
                (body.kinetic_energy(&vi), body.potential_energy(&qi, sys.gravity))
            }
        };
        let r = &mut self.record;
        r.t.push(t);
        r.force_tank.push(fk.into());
        r.moment_tank.push(mk.into());
        r.force_global.push(fg.into());
        r.moment_global.push(mg.into());
        r.com_tank.push(com_tank.into());
        r.volume.push(body.volume(q));
        r.kinetic_energy.push(ke);
        r.potential_energy.push(pe);
        r.newton_iterations.push(iterations);
        r.max_penetration.push(load.max_penetration);
        r.stored_energy.push(stored);
        let energy = match sys.frame {
            SloshFrame::Inertial => EnergySample {
                kinetic: ke,
                potential: pe,
                stored,
                input_power: crate::invariants::wall_power(fg.into(), mg.into(), &state.kinematics),
            },
            SloshFrame::Tank => sys.tank_frame_energy(t, q, v, stored),
        };
        let checked = sys.account_state(&mut self.invariants, t, q, energy);
        let m = checked.as_ref().ok();
        let w = self.invariants.input_work();
        r.input_work.push(m.map_or(w, |m| m.input_work));
        r.energy_error.push(m.map_or(f64::NAN, |m| m.energy_error));
        let margins = self.invariants.margins();
        r.min_volume_ratio.push(m.map_or(margins.min_volume_ratio, |m| m.min_volume_ratio));
        r.containment_gap.push(m.map_or(margins.worst_gap, |m| m.gap));
        let checked = checked.map(|_| ());
        self.take_snapshot();
        checked.map_err(|source| IntegratorError::System { t, source })
    }
}
