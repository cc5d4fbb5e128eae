//! [`SloshParticipant`]: the tank-frame slosh model behind a co-simulation interface
//! (conventions in the [module docs](super)).

use ancf_core::FluidBody;
use ancf_core::constitutive::{Fluid, M3};
use ancf_core::contact::{WallContact, WallContactLaw};
use ancf_core::element::QuadratureOptions;
use ancf_core::error::AncfError;
use ancf_core::mesh::FluidMesh;
use ancf_core::tank::TankGeometry;
use nalgebra::{Matrix3, Vector3};

use crate::defaults::slosh_params;
use crate::integrator::{BytesReader, BytesWriter, Checkpoint, Hht, HhtParams, IntegratorError, Stats};
use crate::invariants::{InvariantMonitor, Margins};
use crate::slosh::{PrescribedMotion, SloshFrame, SloshSystem, TankFrameInput, TankFrameSample};

/// Errors of the co-simulation participant.
#[derive(Debug, thiserror::Error)]
pub enum CosimError {
    /// A parameter or input is outside its allowed range.
    #[error("invalid `{field}` = {value}: expected {allowed}")]
    InvalidParameter {
        /// Name of the offending field (config field or input key).
        field: String,
        /// The rejected value, formatted.
        value: String,
        /// The allowed range, in words.
        allowed: String,
    },
    /// The fluid model could not be built.
    #[error("slosh model: {0}")]
    Model(AncfError),
    /// The integrator failed (at construction, or in the window [t0, t1]; after a failed
    /// window the participant is back at t0).
    #[error("slosh integration failed in window [{t0}, {t1}] s (state restored to t = {t0} s): {source}")]
    Integrator {
        /// Window start (s).
        t0: f64,
        /// Window end (s).
        t1: f64,
        /// The integrator error.
        source: IntegratorError,
    },
    /// A saved state does not fit this participant.
    #[error("invalid participant state: {0}")]
    State(String),
}

fn invalid(field: &str, value: impl std::fmt::Display, allowed: &str) -> CosimError {
    CosimError::InvalidParameter { field: field.into(), value: value.to_string(), allowed: allowed.into() }
}

impl From<AncfError> for CosimError {
    fn from(e: AncfError) -> Self {
        match e {
            AncfError::InvalidParameter { field, value, allowed } => Self::InvalidParameter { field, value, allowed },
            other => Self::Model(other),
        }
    }
}

fn integrator_error(t0: f64, t1: f64, e: IntegratorError) -> CosimError {
    match e {
        IntegratorError::InvalidParameter { field, value, allowed } => invalid(&format!("hht.{field}"), value, allowed),
        source => CosimError::Integrator { t0, t1, source },
    }
}

fn check_vec(field: &str, v: &[f64; 3]) -> Result<(), CosimError> {
    if v.iter().all(|x| x.is_finite()) { Ok(()) } else { Err(invalid(field, format!("{v:?}"), "finite numbers")) }
}

/// Configuration of a [`SloshParticipant`]. [`SloshParticipantConfig::new`] fills the
/// defaults; every public field may be changed before [`SloshParticipant::new`].
#[derive(Debug, Clone)]
pub struct SloshParticipantConfig {
    /// Fluid mesh in the tank frame (its reference configuration is the initial state).
    pub mesh: FluidMesh,
    /// Fluid properties.
    pub fluid: Fluid,
    /// Tank shell and bulkheads, tank frame.
    pub tank: TankGeometry,
    /// Wall contact law; `None` (default): [`WallContactLaw::default_for`] the fluid
    /// density, `gravity` and the liquid depth of the mesh (free surface − lowest node).
    pub contact: Option<WallContactLaw>,
    /// Quadrature of the fluid elements (default [`QuadratureOptions::default`]).
    pub quadrature: QuadratureOptions,
    /// HHT parameters (default [`slosh_params`]: α = −0.3, adaptive steps).
    pub hht: HhtParams,
    /// Largest integrator step (s), > 0. Default 0.005 s.
    pub h_max: f64,
    /// Point (tank frame, m) about which moments are reported and the added mass is
    /// given. Default the tank origin.
    pub reference_point: [f64; 3],
    /// Magnitude of gravity g (m/s², ≥ 0), used for pose inputs (gravity −g along global
    /// z), the initial rest state and the default contact law. Default [`ancf_core::constants::GRAVITY`].
    pub gravity: f64,
    /// Start time (s). Default 0.
    pub t0: f64,
}

impl SloshParticipantConfig {
    /// A configuration with the defaults listed on the fields.
    pub fn new(mesh: FluidMesh, fluid: Fluid, tank: TankGeometry) -> Self {
        Self {
            mesh,
            fluid,
            tank,
            contact: None,
            quadrature: QuadratureOptions::default(),
            hht: slosh_params(),
            h_max: 0.005,
            reference_point: [0.0; 3],
            gravity: ancf_core::constants::GRAVITY,
            t0: 0.0,
        }
    }

    /// Checks the participant's own fields (the mesh, fluid, tank and contact law are
    /// checked when the model is built).
    pub fn validate(&self) -> Result<(), CosimError> {
        if !(self.h_max.is_finite() && self.h_max > 0.0) {
            return Err(invalid("h_max", self.h_max, "a finite step > 0 (s)"));
        }
        if !(self.gravity.is_finite() && self.gravity >= 0.0) {
            return Err(invalid("gravity", self.gravity, "a finite magnitude >= 0 (m/s^2)"));
        }
        check_vec("reference_point", &self.reference_point)?;
        if !self.t0.is_finite() {
            return Err(invalid("t0", self.t0, "a finite time (s)"));
        }
        self.hht.validate().map_err(|e| integrator_error(self.t0, self.t0, e))
    }
}

/// Tank motion in the global frame (form 2 of the interface).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseInput {
    /// Position R of the tank origin (m, global). Not used by the tank-frame model.
    pub position: [f64; 3],
    /// Rotation A, tank → global (`x_global = R + A x_tank`), row-major, orthonormal with
    /// determinant +1 (to 1e-6).
    pub rotation: [[f64; 3]; 3],
    /// Velocity Ṙ (m/s, global). Not used by the tank-frame model.
    pub velocity: [f64; 3],
    /// Angular velocity ω (rad/s, global components).
    pub angular_velocity: [f64; 3],
    /// Acceleration R̈ of the tank origin (m/s², global).
    pub acceleration: [f64; 3],
    /// Angular acceleration ω̇ (rad/s², global components).
    pub angular_acceleration: [f64; 3],
}

impl PoseInput {
    /// Rotation matrix of a unit quaternion `[w, x, y, z]` (norm 1 to 1e-6).
    pub fn rotation_from_quaternion(q: [f64; 4]) -> Result<[[f64; 3]; 3], CosimError> {
        let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !(n.is_finite() && (n - 1.0).abs() <= 1e-6) {
            return Err(invalid("quaternion", format!("{q:?}"), "a unit quaternion [w, x, y, z] (norm 1 to 1e-6)"));
        }
        let [w, x, y, z] = q.map(|c| c / n);
        Ok([
            [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)],
            [2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)],
            [2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)],
        ])
    }

    /// Seed 003's tank-frame form: A^T R̈, A^T ω, A^T ω̇ and A^T (0, 0, −g).
    pub fn to_tank_frame(&self, gravity: f64) -> Result<TankFrameSample, CosimError> {
        check_vec("position", &self.position)?;
        check_vec("velocity", &self.velocity)?;
        check_vec("angular_velocity", &self.angular_velocity)?;
        check_vec("acceleration", &self.acceleration)?;
        check_vec("angular_acceleration", &self.angular_acceleration)?;
        let r = &self.rotation;
        let a = M3::new(r[0][0], r[0][1], r[0][2], r[1][0], r[1][1], r[1][2], r[2][0], r[2][1], r[2][2]);
        let dev = (a.transpose() * a - M3::identity()).abs().max();
        if !(dev <= 1e-6 && a.determinant() > 0.0) {
            return Err(invalid("rotation", format!("{r:?}"), "an orthonormal matrix with determinant +1 (to 1e-6)"));
        }
        let at = a.transpose();
        let tr = |v: [f64; 3]| -> [f64; 3] { (at * Vector3::from(v)).into() };
        Ok(TankFrameSample {
            acceleration: tr(self.acceleration),
            angular_velocity: tr(self.angular_velocity),
            angular_acceleration: tr(self.angular_acceleration),
            gravity: tr([0.0, 0.0, -gravity]),
        })
    }
}

/// Tank motion at one coupling time, in either form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TankMotionInput {
    /// Seed 003's interface: everything in tank axes.
    TankFrame(TankFrameSample),
    /// Pose, velocity and acceleration in global axes.
    Pose(PoseInput),
}

impl From<TankFrameSample> for TankMotionInput {
    fn from(s: TankFrameSample) -> Self {
        Self::TankFrame(s)
    }
}

impl From<PoseInput> for TankMotionInput {
    fn from(p: PoseInput) -> Self {
        Self::Pose(p)
    }
}

/// Force and moment the fluid exerts on the tank: tank axes, moment about the
/// participant's reference point.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Loads {
    /// Force (N).
    pub force: [f64; 3],
    /// Moment (N·m).
    pub moment: [f64; 3],
}

/// Saved state of a [`SloshParticipant`] (opaque; [`ParticipantState::to_bytes`] for
/// storage): the integrator's checkpoint, the loads and the invariants' account, so that a
/// restored participant goes on with the energy balance and margins it had (issue 18).
#[derive(Debug, Clone, PartialEq)]
pub struct ParticipantState {
    checkpoint: Checkpoint,
    loads: Loads,
    /// [`InvariantMonitor::save_account`].
    account: Vec<f64>,
}

const STATE_MAGIC: &[u8; 8] = b"RSLCOSM2";
const STATE_VERSION: u32 = 1;

impl ParticipantState {
    /// Time of the saved state (s).
    pub fn time(&self) -> f64 {
        self.checkpoint.t
    }

    /// Serialized form: magic `RSLCOSM2`, a version (u32 LE), the 6 load components (f64 LE),
    /// the invariants' account (u64 length, f64 LE values), then the integrator checkpoint's
    /// own byte format (u64 length, bytes). Exact. (The `RSLCOSIM` form before 2026-11-28,
    /// without the account, is not read.)
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut w = BytesWriter(Vec::new());
        w.header(STATE_MAGIC, STATE_VERSION);
        for &x in self.loads.force.iter().chain(&self.loads.moment) {
            w.f64(x);
        }
        w.vec(&self.account);
        w.bytes(&self.checkpoint.to_bytes());
        w.0
    }

    /// Inverse of [`to_bytes`](Self::to_bytes).
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, CosimError> {
        let err = |e: IntegratorError| CosimError::State(e.to_string());
        let mut r = BytesReader { bytes, pos: 0 };
        r.versioned(STATE_MAGIC, "slosh participant", STATE_VERSION).map_err(err)?;
        let mut l = [0.0; 6];
        for (k, x) in l.iter_mut().enumerate() {
            *x = r.f64(["force.x", "force.y", "force.z", "moment.x", "moment.y", "moment.z"][k]).map_err(err)?;
        }
        let account = r.vec("account").map_err(err)?;
        let checkpoint = Checkpoint::from_bytes(r.bytes("checkpoint").map_err(err)?).map_err(err)?;
        r.finish().map_err(err)?;
        let loads = Loads { force: [l[0], l[1], l[2]], moment: [l[3], l[4], l[5]] };
        Ok(Self { checkpoint, loads, account })
    }
}

/// The slosh model as a co-simulation participant (see the [module docs](super)).
pub struct SloshParticipant {
    hht: Hht<SloshSystem>,
    params: HhtParams,
    reference_point: Vector3<f64>,
    gravity: f64,
    h_max: f64,
    loads: Loads,
    /// Run-time invariants: containment and element validity (also checked inside every
    /// step by `SloshSystem::check_step`) and the tank-frame energy balance.
    invariants: InvariantMonitor,
}

impl SloshParticipant {
    /// Builds the model; the fluid starts at rest in the tank in its mesh configuration,
    /// the tank at rest with gravity −g along tank z.
    pub fn new(config: SloshParticipantConfig) -> Result<Self, CosimError> {
        config.validate()?;
        let depth = config.mesh.liquid_depth();
        let law = match config.contact {
            Some(law) => law,
            None => {
                if !(depth.is_finite() && depth > 0.0) {
                    return Err(invalid("mesh.free_surface_z", config.mesh.free_surface_z, "above the lowest node"));
                }
                WallContactLaw::default_for(config.fluid.density, config.gravity.max(1e-3), depth)
            }
        };
        let body = FluidBody::new(config.mesh, config.fluid, config.quadrature)?;
        let contact = WallContact::new(&body, config.tank, law)?;
        let mut sys = SloshSystem::new(
            body,
            contact,
            PrescribedMotion::at_rest([0.0; 3]),
            [0.0, 0.0, -config.gravity],
            SloshFrame::Tank,
        )?;
        sys.tank_input = Some(TankFrameInput::constant(TankFrameSample::at_rest(config.gravity)));
        let (q, v) = sys.initial_state(config.t0);
        let invariants = sys.invariant_monitor();
        let hht = Hht::new(sys, config.t0, q, v, config.hht).map_err(|e| integrator_error(config.t0, config.t0, e))?;
        let mut p = Self {
            hht,
            params: config.hht,
            reference_point: Vector3::from(config.reference_point),
            gravity: config.gravity,
            h_max: config.h_max,
            loads: Loads::default(),
            invariants,
        };
        p.restart_energy().map_err(|e| integrator_error(config.t0, config.t0, e))?;
        p.loads = p.current_loads();
        Ok(p)
    }

    /// Checks the invariants of an accepted state with `monitor` (energy: tank frame, the
    /// work of gravity and the pseudo-forces).
    fn check_state(
        monitor: &mut InvariantMonitor,
        sys: &SloshSystem,
        t: f64,
        q: &[f64],
        v: &[f64],
    ) -> Result<(), IntegratorError> {
        let kin = sys.contact_kinematics(t);
        let stored = crate::invariants::stored_energy(&sys.body, &sys.contact, &kin, q);
        let energy = sys.tank_frame_energy(t, q, v, stored);
        sys.account_state(monitor, t, q, energy).map(|_| ()).map_err(|source| IntegratorError::System { t, source })
    }

    /// A new energy account from the current state (margins kept).
    fn restart_energy(&mut self) -> Result<(), IntegratorError> {
        self.invariants.restart_energy();
        let (t, sys) = (self.hht.t(), self.hht.system());
        Self::check_state(&mut self.invariants, sys, t, self.hht.q(), self.hht.v())
    }

    /// The slosh system, for tools and tests that change the model in place (the caller
    /// answers for keeping it consistent; cached forces and Jacobians are invalidated).
    pub fn system_mut(&mut self) -> &mut SloshSystem {
        self.hht.system_mut()
    }

    /// The worst invariant margins so far (gap, volume ratio, energy error, dissipated
    /// energy of the current energy account).
    pub fn margins(&self) -> Margins {
        self.invariants.margins()
    }

    /// The tank-frame form of an input (pose inputs are converted with this participant's
    /// gravity); validates it.
    pub fn tank_frame_sample(&self, input: &TankMotionInput) -> Result<TankFrameSample, CosimError> {
        match input {
            TankMotionInput::TankFrame(s) => {
                check_vec("acceleration", &s.acceleration)?;
                check_vec("angular_velocity", &s.angular_velocity)?;
                check_vec("angular_acceleration", &s.angular_acceleration)?;
                check_vec("gravity", &s.gravity)?;
                Ok(*s)
            }
            TankMotionInput::Pose(p) => p.to_tank_frame(self.gravity),
        }
    }

    /// Makes the current state's accelerations consistent with a (constant) input at the
    /// current time, e.g. the initial tank motion before the first window (the HHT
    /// accelerations are recomputed; positions and velocities are kept). Returns the loads.
    pub fn set_initial_input(&mut self, input: &TankMotionInput) -> Result<Loads, CosimError> {
        let s = self.tank_frame_sample(input)?;
        let t = self.hht.t();
        let (q, v) = (self.hht.q().to_vec(), self.hht.v().to_vec());
        self.hht.system_mut().tank_input = Some(TankFrameInput::constant(s));
        self.hht.reinitialize(t, &q, &v).map_err(|e| integrator_error(t, t, e))?;
        self.restart_energy().map_err(|e| integrator_error(t, t, e))?;
        self.loads = self.current_loads();
        Ok(self.loads)
    }

    /// Advances from the current time t to `t_end` (> t) with the input interpolated
    /// linearly from `input_start` (at t) to `input_end` (at t_end), in equal steps
    /// ≤ `h_max`; returns the loads at `t_end`. On failure the state is restored to t.
    pub fn advance(
        &mut self,
        t_end: f64,
        input_start: &TankMotionInput,
        input_end: &TankMotionInput,
    ) -> Result<Loads, CosimError> {
        let t0 = self.hht.t();
        if !(t_end.is_finite() && t_end > t0) {
            return Err(invalid("t_end", t_end, &format!("a finite time > the current time {t0} s")));
        }
        let start = self.tank_frame_sample(input_start)?;
        let end = self.tank_frame_sample(input_end)?;
        let saved = self.hht.checkpoint();
        self.hht.system_mut().tank_input = Some(TankFrameInput { t0, t1: t_end, start, end });
        let n = ((t_end - t0) / self.h_max).ceil().max(1.0);
        let h = (t_end - t0) / n;
        let mut monitor = self.invariants.clone();
        let checked =
            self.hht.integrate_checked(t_end, h, |sys, s| Self::check_state(&mut monitor, sys, s.t, s.q, s.v));
        if let Err(e) = checked {
            let sys = self.hht.system().clone();
            self.hht = Hht::restore(sys, &saved, self.params).map_err(|e| integrator_error(t0, t0, e))?;
            return Err(integrator_error(t0, t_end, e));
        }
        self.invariants = monitor;
        self.loads = self.current_loads();
        Ok(self.loads)
    }

    /// Lets the fluid settle for `duration` (s) under a constant input (e.g. the tank at
    /// rest) and then sets the clock back to the current time, keeping the settled state.
    /// Starts a co-simulation from (near) hydrostatic equilibrium instead of the unloaded
    /// mesh configuration, whose wall contact carries no load at first. Returns the loads.
    pub fn settle(&mut self, duration: f64, input: &TankMotionInput) -> Result<Loads, CosimError> {
        if !(duration.is_finite() && duration > 0.0) {
            return Err(invalid("duration", duration, "a finite time > 0 (s)"));
        }
        let t0 = self.hht.t();
        self.advance(t0 + duration, input, input)?;
        let mut cp = self.hht.checkpoint();
        cp.t = t0;
        let sys = self.hht.system().clone();
        self.hht = Hht::restore(sys, &cp, self.params).map_err(|e| integrator_error(t0, t0, e))?;
        self.restart_energy().map_err(|e| integrator_error(t0, t0, e))?;
        self.loads = self.current_loads();
        Ok(self.loads)
    }

    /// Saves the complete state for [`restore_state`](Self::restore_state).
    pub fn save_state(&self) -> ParticipantState {
        let mut account = Vec::new();
        self.invariants.save_account(&mut account);
        ParticipantState { checkpoint: self.hht.checkpoint(), loads: self.loads, account }
    }

    /// Returns exactly to a saved state of this participant (or of one built from the
    /// same configuration), its energy account and worst margins included: an implicit
    /// coupling that iterates a window by restoring goes on with one energy balance over the
    /// whole run.
    pub fn restore_state(&mut self, state: &ParticipantState) -> Result<(), CosimError> {
        let sys = self.hht.system().clone();
        let hht = Hht::restore(sys, &state.checkpoint, self.params).map_err(|e| CosimError::State(e.to_string()))?;
        let mut invariants = hht.system().invariant_monitor();
        if invariants.restore_whole_account(&state.account).is_none() {
            return Err(CosimError::State("the invariants' account does not fit this participant".into()));
        }
        self.hht = hht;
        self.loads = state.loads;
        self.invariants = invariants;
        Ok(())
    }

    fn current_loads(&self) -> Loads {
        let sys = self.hht.system();
        let load = sys.contact_load(self.hht.t(), self.hht.q(), self.hht.v());
        let f = Vector3::from(load.force);
        let m = Vector3::from(load.moment) - self.reference_point.cross(&f);
        Loads { force: load.force, moment: m.into() }
    }

    /// Loads at the current time (as last returned).
    pub fn loads(&self) -> Loads {
        self.loads
    }

    /// Rigid-body mass matrix (6×6) of the fluid in its current configuration about the
    /// reference point P, tank axes, for velocities (v_P, ω):
    /// `[[m I, −m c̃], [m c̃, J_P]]`, c = centre of mass − P,
    /// J_P = ∫ρ (|r|² I − r rᵀ) dV, r = x − P. Exact for the ANCF field: the second
    /// moment ∫ρ x xᵀ is Σ_ab M_s,ab e_a e_bᵀ with the scalar mass matrix M_s.
    pub fn added_mass(&self) -> [[f64; 6]; 6] {
        let body = &self.hht.system().body;
        let e = self.hht.q();
        let m = body.total_mass();
        let ms = body.scalar_mass().as_ref();
        let mut s2 = Matrix3::<f64>::zeros();
        for j in 0..ms.ncols() {
            let ej = Vector3::new(e[3 * j], e[3 * j + 1], e[3 * j + 2]);
            for (i, val) in ms.row_idx_of_col(j).zip(ms.val_of_col(j)) {
                let ei = Vector3::new(e[3 * i], e[3 * i + 1], e[3 * i + 2]);
                s2 += *val * ei * ej.transpose();
            }
        }
        let m1 = Vector3::from(body.mass_moment(e));
        let p = self.reference_point;
        let s2p = s2 - p * m1.transpose() - m1 * p.transpose() + m * p * p.transpose();
        let jp = Matrix3::identity() * s2p.trace() - s2p;
        let mc = (m1 - m * p).cross_matrix();
        let mut out = [[0.0; 6]; 6];
        for r in 0..3 {
            out[r][r] = m;
            for c in 0..3 {
                out[r][3 + c] = -mc[(r, c)];
                out[3 + r][c] = mc[(r, c)];
                out[3 + r][3 + c] = jp[(r, c)];
            }
        }
        out
    }

    /// Current time (s).
    pub fn time(&self) -> f64 {
        self.hht.t()
    }

    /// Fluid mass (kg).
    pub fn fluid_mass(&self) -> f64 {
        self.hht.system().body.total_mass()
    }

    /// Fluid centre of mass, tank frame (m).
    pub fn com_tank(&self) -> [f64; 3] {
        self.hht.system().body.center_of_mass(self.hht.q())
    }

    /// Fluid volume ∫J dV₀ (m³).
    pub fn volume(&self) -> f64 {
        self.hht.system().body.volume(self.hht.q())
    }

    /// Integrator statistics (accumulated; restored with the state).
    pub fn stats(&self) -> &Stats {
        self.hht.stats()
    }

    /// Reference point of the moments (tank frame, m).
    pub fn reference_point(&self) -> [f64; 3] {
        self.reference_point.into()
    }

    /// Largest integrator step (s).
    pub fn h_max(&self) -> f64 {
        self.h_max
    }

    /// Gravity magnitude (m/s²).
    pub fn gravity(&self) -> f64 {
        self.gravity
    }
}
