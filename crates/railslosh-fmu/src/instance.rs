//! One FMU instance: the FMI 3.0 co-simulation state machine, the variable values, the model
//! and the FMU states (snapshots) used for rollback. Safe Rust; [`crate::fmi3`] wraps it in
//! the C API.
//!
//! States (FMI 3.0 §4.2 for co-simulation, without configuration modes):
//! `Instantiated → (EnterInitializationMode) Initialization → (ExitInitializationMode)
//! Step`, or `Event` when the importer asked for event mode (`EnterStepMode` then leads to
//! `Step`); `Terminate` leads to `Terminated`; `Reset` to `Instantiated` from anywhere. A
//! call that fails puts the instance in `Error`, where only getters, `fmi3SetFMUState`,
//! `fmi3Reset` and `fmi3FreeInstance` are allowed.

use std::ffi::{CString, c_char, c_void};

use crate::model::{self, FmuModel, ModelConfig, ModelKind, TankInput};
use crate::variables::*;

/// The instance's mode in the FMI state machine.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// After instantiation or reset: parameters and inputs may be set.
    Instantiated,
    /// Between `fmi3EnterInitializationMode` and `fmi3ExitInitializationMode`.
    Initialization,
    /// Event mode (only when the importer asked for it; there are no events).
    Event,
    /// Step mode: `fmi3DoStep` advances time.
    Step,
    /// After `fmi3Terminate`.
    Terminated,
    /// After a failed call.
    Error,
}

impl Mode {
    fn code(self) -> u8 {
        self as u8
    }

    fn from_code(c: u8) -> Option<Self> {
        [Self::Instantiated, Self::Initialization, Self::Event, Self::Step, Self::Terminated, Self::Error]
            .get(c as usize)
            .copied()
    }
}

/// The importer's log callback (`fmi3LogMessageCallback`).
pub type LogCallback = unsafe extern "C" fn(
    env: *mut c_void,
    status: crate::fmi3::Status,
    category: *const c_char,
    message: *const c_char,
);

/// Logging: the callback and which categories are on.
pub struct Logger {
    pub(crate) callback: Option<LogCallback>,
    pub(crate) env: *mut c_void,
    /// Debug logging on, per category of [`LOG_CATEGORIES`].
    pub(crate) enabled: [bool; 3],
}

impl Logger {
    /// Log `message` under `category`; errors are always passed on, others only when enabled.
    pub fn log(&self, status: crate::fmi3::Status, category: usize, message: &str) {
        let Some(cb) = self.callback else { return };
        if status != crate::fmi3::Status::Error && !self.enabled[category] {
            return;
        }
        let cat = CString::new(LOG_CATEGORIES[category].0).unwrap_or_default();
        let msg = CString::new(message.replace('\0', " ")).unwrap_or_default();
        // SAFETY: the importer supplied the callback and its environment for this instance;
        // both strings live until the call returns.
        unsafe { cb(self.env, status, cat.as_ptr(), msg.as_ptr()) }
    }
}

/// A saved FMU state (`fmi3FMUState`).
#[derive(Debug, Clone, PartialEq)]
pub struct FmuState {
    mode: Mode,
    time: f64,
    values: Vec<f64>,
    model: Option<Vec<u8>>,
}

const MAGIC: &[u8; 8] = b"RLSLOSH1";

impl FmuState {
    /// Serialized form: magic, mode, time, values, model state (little endian).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut b = MAGIC.to_vec();
        b.push(self.mode.code());
        b.extend_from_slice(&self.time.to_le_bytes());
        let push_vec = |b: &mut Vec<u8>, v: &[f64]| {
            b.extend_from_slice(&(v.len() as u64).to_le_bytes());
            for x in v {
                b.extend_from_slice(&x.to_le_bytes());
            }
        };
        push_vec(&mut b, &self.values);
        b.push(self.model.is_some() as u8);
        if let Some(m) = &self.model {
            b.extend_from_slice(&(m.len() as u64).to_le_bytes());
            b.extend_from_slice(m);
        }
        b
    }

    /// Inverse of [`Self::to_bytes`].
    pub fn from_bytes(b: &[u8]) -> Result<Self, String> {
        let mut r = Reader { b, pos: 0 };
        if r.take(8)? != MAGIC {
            return Err(Reader::bad());
        }
        let mode = Mode::from_code(r.take(1)?[0]).ok_or_else(Reader::bad)?;
        let time = r.f64()?;
        let values = r.vec()?;
        if values.len() != VARIABLES.len() {
            return Err(Reader::bad());
        }
        let model = if r.take(1)?[0] != 0 { Some(r.bytes()?.to_vec()) } else { None };
        if r.pos != b.len() {
            return Err(Reader::bad());
        }
        Ok(Self { mode, time, values, model })
    }
}

struct Reader<'a> {
    b: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    fn bad() -> String {
        "serialized FMU state is truncated or not from railslosh_slosh".to_string()
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let s = self.b.get(self.pos..self.pos.saturating_add(n)).ok_or_else(Self::bad)?;
        self.pos += n;
        Ok(s)
    }

    fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_le_bytes(self.take(8)?.try_into().map_err(|_| Self::bad())?))
    }

    fn bytes(&mut self) -> Result<&'a [u8], String> {
        let n = u64::from_le_bytes(self.take(8)?.try_into().map_err(|_| Self::bad())?);
        self.take(usize::try_from(n).map_err(|_| Self::bad())?)
    }

    fn vec(&mut self) -> Result<Vec<f64>, String> {
        let n = u64::from_le_bytes(self.take(8)?.try_into().map_err(|_| Self::bad())?);
        let n = usize::try_from(n).map_err(|_| Self::bad())?;
        if n > self.b.len() / 8 {
            return Err(Self::bad());
        }
        (0..n).map(|_| self.f64()).collect()
    }
}

/// One FMU instance.
pub struct Instance {
    /// Instance name from the importer.
    pub name: String,
    /// Logging.
    pub logger: Logger,
    event_mode_used: bool,
    mode: Mode,
    time: f64,
    stop_time: Option<f64>,
    values: Vec<f64>,
    model: Option<Box<dyn FmuModel>>,
    built_with: Option<ModelConfig>,
}

fn vr_name(vr: usize) -> String {
    VARIABLES.get(vr).map_or_else(|| format!("<unknown vr {vr}>"), |v| format!("`{}` (vr {vr})", v.name))
}

impl Instance {
    /// A new instance in mode `Instantiated` with the start values.
    pub fn new(name: String, logger: Logger, event_mode_used: bool) -> Self {
        Self {
            name,
            logger,
            event_mode_used,
            mode: Mode::Instantiated,
            time: 0.0,
            stop_time: None,
            values: start_values(),
            model: None,
            built_with: None,
        }
    }

    /// Current mode.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Enter the error state (after a failed call).
    pub fn fail(&mut self) {
        self.mode = Mode::Error;
    }

    fn require(&self, call: &str, allowed: &[Mode]) -> Result<(), String> {
        if allowed.contains(&self.mode) {
            Ok(())
        } else {
            Err(format!("{call} is not allowed in mode {:?} (allowed in {allowed:?})", self.mode))
        }
    }

    /// The model configuration from the parameter values.
    pub fn config(&self) -> Result<ModelConfig, String> {
        let v = &self.values;
        let kind = match v[VR_MODEL] as i64 {
            0 => ModelKind::Pendulum,
            1 => ModelKind::Ancf,
            k => return Err(format!("invalid `model` = {k}: expected 0 (pendulum) or 1 (ANCF)")),
        };
        let cfg = ModelConfig {
            kind,
            fill: v[VR_FILL],
            density: v[VR_DENSITY],
            viscosity: v[VR_VISCOSITY],
            length: v[VR_LENGTH],
            semi_axis_y: v[VR_SEMI_AXIS_Y],
            semi_axis_z: v[VR_SEMI_AXIS_Z],
            reference: [v[VR_REF], v[VR_REF + 1], v[VR_REF + 2]],
            h_max: v[VR_H_MAX],
            damping_ratio: v[VR_DAMPING],
            counts: std::array::from_fn(|i| v[VR_COUNTS + i] as usize),
        };
        cfg.validate()?;
        Ok(cfg)
    }

    /// Build the model if there is none or the parameters changed since it was built.
    fn ensure_model(&mut self) -> Result<&mut Box<dyn FmuModel>, String> {
        let cfg = self.config()?;
        if self.model.is_none() || self.built_with != Some(cfg) {
            self.model = None;
            let m = model::build(&cfg, self.time)?;
            self.values[VR_MASS] = m.mass();
            let [fl, fw] = m.slosh_frequencies();
            self.values[VR_F_LONG] = fl;
            self.values[VR_F_LAT] = fw;
            self.model = Some(m);
            self.built_with = Some(cfg);
        }
        Ok(self.model.as_mut().expect("model built above"))
    }

    /// The tank motion inputs.
    pub fn inputs(&self) -> TankInput {
        let g = |k: usize| [self.values[k], self.values[k + 1], self.values[k + 2]];
        TankInput {
            acceleration: g(VR_ACCELERATION),
            angular_velocity: g(VR_OMEGA),
            angular_acceleration: g(VR_OMEGA_DOT),
            gravity: g(VR_GRAVITY),
        }
    }

    fn variable(&self, vr: u32, kind: Kind) -> Result<usize, String> {
        let i = vr as usize;
        let v = VARIABLES.get(i).ok_or_else(|| format!("unknown value reference {vr}"))?;
        if v.kind != kind {
            return Err(format!("variable {} is {:?}, not {kind:?}", vr_name(i), v.kind));
        }
        Ok(i)
    }

    /// Value of a variable of type `kind`.
    pub fn get(&mut self, vr: u32, kind: Kind) -> Result<f64, String> {
        let i = self.variable(vr, kind)?;
        match VARIABLES[i].causality {
            Causality::Independent => Ok(self.time),
            Causality::Output => {
                if self.mode == Mode::Instantiated {
                    return Err(format!("output {} is not available before initialization", vr_name(i)));
                }
                let u = self.inputs();
                let out = self.ensure_model()?.outputs(&u);
                let k = i - VR_FORCE;
                Ok([out.force, out.moment, out.com][k / 3][k % 3])
            }
            Causality::CalculatedParameter => {
                if self.mode == Mode::Instantiated {
                    return Err(format!("{} is not available before initialization", vr_name(i)));
                }
                self.ensure_model()?;
                Ok(self.values[i])
            }
            Causality::Input | Causality::Parameter => Ok(self.values[i]),
        }
    }

    /// Set a variable of type `kind`.
    pub fn set(&mut self, vr: u32, kind: Kind, x: f64) -> Result<(), String> {
        let i = self.variable(vr, kind)?;
        let v = &VARIABLES[i];
        match v.causality {
            Causality::Input => {
                self.require("setting an input", &[Mode::Instantiated, Mode::Initialization, Mode::Event, Mode::Step])?;
                if !x.is_finite() {
                    return Err(format!("invalid input `{}` = {x}: expected a finite number", v.name));
                }
            }
            Causality::Parameter => {
                self.require("setting a parameter", &[Mode::Instantiated, Mode::Initialization])?;
                let (lo, hi) = (v.min.unwrap_or(f64::MIN), v.max.unwrap_or(f64::MAX));
                if !(x.is_finite() && x >= lo && x <= hi) {
                    return Err(format!("invalid `{}` = {x}: expected [{lo}, {hi}]", v.name));
                }
            }
            c => return Err(format!("{} has causality {c:?} and cannot be set", vr_name(i))),
        }
        self.values[i] = x;
        Ok(())
    }

    /// `fmi3EnterInitializationMode`.
    pub fn enter_initialization(&mut self, start: f64, stop: Option<f64>) -> Result<(), String> {
        self.require("fmi3EnterInitializationMode", &[Mode::Instantiated])?;
        if !start.is_finite() || stop.is_some_and(|s| !(s.is_finite() && s >= start)) {
            return Err(format!("invalid start time {start} / stop time {stop:?}"));
        }
        self.time = start;
        self.stop_time = stop;
        self.mode = Mode::Initialization;
        Ok(())
    }

    /// `fmi3ExitInitializationMode`: builds the model.
    pub fn exit_initialization(&mut self) -> Result<(), String> {
        self.require("fmi3ExitInitializationMode", &[Mode::Initialization])?;
        let u = self.inputs();
        crate::model::check_finite(&u)?;
        self.ensure_model()?.start(&u)?;
        self.mode = if self.event_mode_used { Mode::Event } else { Mode::Step };
        Ok(())
    }

    /// `fmi3EnterEventMode`.
    pub fn enter_event_mode(&mut self) -> Result<(), String> {
        if !self.event_mode_used {
            return Err("fmi3EnterEventMode: the instance was created with eventModeUsed = false".into());
        }
        self.require("fmi3EnterEventMode", &[Mode::Step])?;
        self.mode = Mode::Event;
        Ok(())
    }

    /// `fmi3EnterStepMode`.
    pub fn enter_step_mode(&mut self) -> Result<(), String> {
        self.require("fmi3EnterStepMode", &[Mode::Event])?;
        self.mode = Mode::Step;
        Ok(())
    }

    /// `fmi3UpdateDiscreteStates`: there are no discrete states or events.
    pub fn update_discrete_states(&mut self) -> Result<(), String> {
        self.require("fmi3UpdateDiscreteStates", &[Mode::Event])
    }

    /// `fmi3DoStep` from `t` over `h`; returns the time reached.
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<f64, String> {
        self.require("fmi3DoStep", &[Mode::Step])?;
        if !(h.is_finite() && h > 0.0) {
            return Err(format!("invalid communicationStepSize {h}: expected a finite number > 0"));
        }
        let tol = 1e-9 * (1.0 + self.time.abs()).max(h);
        if !t.is_finite() || (t - self.time).abs() > tol {
            return Err(format!("currentCommunicationPoint {t} differs from the FMU time {}", self.time));
        }
        let t_end = t + h;
        if let Some(stop) = self.stop_time
            && t_end > stop + tol
        {
            return Err(format!("step to t = {t_end} passes the stop time {stop}"));
        }
        let u = self.inputs();
        crate::model::check_finite(&u)?;
        let model = self.ensure_model()?;
        let saved = model.save_state();
        if let Err(e) = model.advance(t_end, &u, &u) {
            let restored = model.restore_state(&saved);
            return Err(format!(
                "step from t = {t} to {t_end} failed: {e}{}",
                if restored.is_ok() { " (state restored to the start of the step)" } else { "" }
            ));
        }
        self.time = t_end;
        Ok(t_end)
    }

    /// `fmi3Terminate`.
    pub fn terminate(&mut self) -> Result<(), String> {
        self.require("fmi3Terminate", &[Mode::Step, Mode::Event, Mode::Initialization])?;
        self.mode = Mode::Terminated;
        Ok(())
    }

    /// `fmi3Reset`: start values, no model, mode `Instantiated`.
    pub fn reset(&mut self) {
        self.mode = Mode::Instantiated;
        self.time = 0.0;
        self.stop_time = None;
        self.values = start_values();
        self.model = None;
        self.built_with = None;
    }

    /// `fmi3GetFMUState`.
    pub fn get_state(&self) -> Result<FmuState, String> {
        self.require(
            "fmi3GetFMUState",
            &[Mode::Instantiated, Mode::Initialization, Mode::Event, Mode::Step, Mode::Terminated],
        )?;
        Ok(FmuState {
            mode: self.mode,
            time: self.time,
            values: self.values.clone(),
            model: self.model.as_ref().map(|m| m.save_state()),
        })
    }

    /// `fmi3SetFMUState`: also allowed in `Error`, to roll back after a failed step.
    pub fn set_state(&mut self, s: &FmuState) -> Result<(), String> {
        if s.values.len() != VARIABLES.len() || s.mode == Mode::Error {
            return Err("FMU state is not from this FMU".into());
        }
        self.values.clone_from(&s.values);
        self.time = s.time;
        match &s.model {
            Some(state) => {
                self.ensure_model()?.restore_state(state)?;
            }
            None => {
                self.model = None;
                self.built_with = None;
            }
        }
        self.mode = s.mode;
        Ok(())
    }
}
