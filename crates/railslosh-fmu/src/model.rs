//! The model behind the FMU: the [`FmuModel`] trait, its inputs and outputs, and the
//! configuration read from the FMU parameters.
//!
//! Frames and signs follow `docs/frames.md`: every vector is in the **tank frame** K (x along
//! the tank axis, y left, z up, origin at the tank centre); loads are those the fluid exerts
//! **on the tank**, moments about the reference point `ref_x, ref_y, ref_z`.

/// Tank motion at one instant, tank frame (seed 003's co-simulation interface): the type the
/// slosh participant takes (`at_rest(g)`, `lerp`).
pub use rail_mbs::slosh::TankFrameSample as TankInput;

/// The first non-finite component of an input, named as the FMU input variable.
pub fn check_finite(u: &TankInput) -> Result<(), String> {
    let groups = [
        ("a", u.acceleration),
        ("omega", u.angular_velocity),
        ("omega_dot", u.angular_acceleration),
        ("gravity", u.gravity),
    ];
    for (name, v) in groups {
        for (c, x) in ["x", "y", "z"].iter().zip(v) {
            if !x.is_finite() {
                return Err(format!("invalid input `{name}_{c}` = {x}: expected a finite number"));
            }
        }
    }
    Ok(())
}

/// Fluid loads on the tank and the fluid centre of mass, tank frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Outputs {
    /// Force of the fluid on the tank (N).
    pub force: [f64; 3],
    /// Moment of the fluid on the tank about the reference point (N·m).
    pub moment: [f64; 3],
    /// Fluid centre of mass (m).
    pub com: [f64; 3],
}

/// Which slosh model the FMU runs (the `model` parameter).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelKind {
    /// Equivalent pendulum model ([`crate::pendulum`]), fast.
    Pendulum = 0,
    /// ANCF brick fluid of railslosh ([`crate::ancf`]).
    Ancf = 1,
}

/// Parameters of the slosh model, from the FMU parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelConfig {
    /// Which model.
    pub kind: ModelKind,
    /// Liquid volume fraction of the tank, in (0, 0.97].
    pub fill: f64,
    /// Liquid density (kg/m³).
    pub density: f64,
    /// Dynamic viscosity, Newtonian (Pa·s).
    pub viscosity: f64,
    /// Tank length, flat ends (m).
    pub length: f64,
    /// Lateral (y) semi-axis of the elliptical cross-section (m).
    pub semi_axis_y: f64,
    /// Vertical (z) semi-axis of the elliptical cross-section (m).
    pub semi_axis_z: f64,
    /// Reference point of the moments, tank frame (m).
    pub reference: [f64; 3],
    /// Largest internal time step (s).
    pub h_max: f64,
    /// Damping ratio of the pendulum modes (pendulum model only).
    pub damping_ratio: f64,
    /// ANCF elements along the length, across the width, over the height.
    pub counts: [usize; 3],
}

fn invalid(name: &str, value: impl std::fmt::Display, allowed: &str) -> String {
    format!("invalid `{name}` = {value}: expected {allowed}")
}

fn check_range(name: &str, x: f64, lo: f64, hi: f64) -> Result<(), String> {
    if x.is_finite() && x >= lo && x <= hi { Ok(()) } else { Err(invalid(name, x, &format!("[{lo}, {hi}]"))) }
}

impl ModelConfig {
    /// Validate every field; errors name the FMU parameter and the allowed range.
    pub fn validate(&self) -> Result<(), String> {
        if !(self.fill.is_finite() && self.fill > 0.0 && self.fill <= 0.97) {
            return Err(invalid("fill", self.fill, "a volume fraction in (0, 0.97]"));
        }
        check_range("density", self.density, 1.0, 1e5)?;
        check_range("viscosity", self.viscosity, 0.0, 1e6)?;
        check_range("length", self.length, 1e-3, 100.0)?;
        check_range("semi_axis_y", self.semi_axis_y, 1e-3, 10.0)?;
        check_range("semi_axis_z", self.semi_axis_z, 1e-3, 10.0)?;
        for (c, x) in ["x", "y", "z"].iter().zip(self.reference) {
            check_range(&format!("ref_{c}"), x, -1e3, 1e3)?;
        }
        check_range("h_max", self.h_max, 1e-6, 1.0)?;
        check_range("damping_ratio", self.damping_ratio, 0.0, 1.0)?;
        for (name, n) in ["n_length", "n_width", "n_height"].iter().zip(self.counts) {
            if !(1..=64).contains(&n) {
                return Err(invalid(name, n, "an integer in [1, 64]"));
            }
        }
        Ok(())
    }
}

/// A slosh model driven by the FMU.
///
/// The FMU holds the tank motion constant over a communication step (zero-order hold) and
/// passes the same input as `u0` and `u1`; models interpolate linearly between them.
pub trait FmuModel: Send {
    /// Current model time (s).
    fn time(&self) -> f64;
    /// Advance from [`Self::time`] to `t_end`, the tank motion interpolated linearly from `u0`
    /// (at the current time) to `u1` (at `t_end`). On error the state is unspecified; the
    /// caller restores a saved state.
    fn advance(&mut self, t_end: f64, u0: &TankInput, u1: &TankInput) -> Result<(), String>;
    /// Loads and centre of mass at the current state, with the tank motion `u` now.
    fn outputs(&self, u: &TankInput) -> Outputs;
    /// Fluid mass (kg).
    fn mass(&self) -> f64;
    /// Equivalent-pendulum estimate of the first slosh frequencies (Hz), [longitudinal, lateral].
    fn slosh_frequencies(&self) -> [f64; 2];
    /// Called once when initialization ends, with the inputs at the start time (default: nothing).
    fn start(&mut self, _u: &TankInput) -> Result<(), String> {
        Ok(())
    }
    /// The complete dynamic state (time included), serialized.
    fn save_state(&self) -> Vec<u8>;
    /// Restore a state from [`Self::save_state`] of a model built with the same configuration.
    fn restore_state(&mut self, state: &[u8]) -> Result<(), String>;
}

/// Build the model selected by `config.kind`, starting at `t0` from rest relative to the tank.
pub fn build(config: &ModelConfig, t0: f64) -> Result<Box<dyn FmuModel>, String> {
    config.validate()?;
    match config.kind {
        ModelKind::Pendulum => Ok(Box::new(crate::pendulum::Pendulum::new(config, t0)?)),
        ModelKind::Ancf => crate::ancf::build(config, t0),
    }
}
