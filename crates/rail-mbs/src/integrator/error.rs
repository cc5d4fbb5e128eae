//! Typed errors of the integrator and of the systems it advances.

use std::fmt;

/// Location of one unknown of the KKT system `[Δa; −Δλ]`.
///
/// The first `n` unknowns are accelerations of generalized coordinates, the next `m`
/// are Lagrange multipliers of constraints.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KktIndex {
    /// Acceleration of generalized coordinate `i`.
    Coordinate(usize),
    /// Multiplier of constraint `k`.
    Constraint(usize),
}

impl KktIndex {
    /// Maps a raw KKT row/column index to a coordinate or a constraint.
    pub fn from_raw(index: usize, n_coords: usize) -> Self {
        if index < n_coords { Self::Coordinate(index) } else { Self::Constraint(index - n_coords) }
    }
}

impl fmt::Display for KktIndex {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Coordinate(i) => write!(f, "coordinate {i}"),
            Self::Constraint(k) => write!(f, "constraint {k}"),
        }
    }
}

/// Error returned by a [`MechanicalSystem`](super::MechanicalSystem) callback.
///
/// Systems say *which* part of the model failed; the integrator adds *when*
/// (time, step size) by wrapping it in [`IntegratorError::System`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SystemError {
    /// A finite element (e.g. an ANCF fluid element) could not be evaluated.
    #[error("element {index}: {reason}")]
    Element {
        /// Element index in the system's own numbering.
        index: usize,
        /// Human-readable cause (e.g. "inverted element, det J = -0.2").
        reason: String,
    },
    /// A constraint (joint, normalization, contact) could not be evaluated.
    #[error("constraint {index}: {reason}")]
    Constraint {
        /// Constraint index in `0..n_constraints()`.
        index: usize,
        /// Human-readable cause.
        reason: String,
    },
    /// A rigid or flexible body could not be evaluated.
    #[error("body {index}: {reason}")]
    Body {
        /// Body index in the system's own numbering.
        index: usize,
        /// Human-readable cause.
        reason: String,
    },
    /// A finite element inverted (volume ratio `J ≤ 0`) at a quadrature point.
    #[error("element {element} inverted: J = {j:.3e} <= 0 at quadrature point {point}")]
    InvertedElement {
        /// Element index in the system's own numbering.
        element: usize,
        /// Quadrature point index in the element.
        point: usize,
        /// Volume ratio `J = det F` at that point.
        j: f64,
    },
    /// A penalty contact penetrated beyond its admissible limit (checked on every
    /// converged step through [`MechanicalSystem::check_step`](super::MechanicalSystem::check_step)).
    #[error("contact penetration {depth:.3e} m beyond its limit {limit:.3e} m at {contact}")]
    Penetration {
        /// Which contact (e.g. "fluid-wall point 12 (element 3)").
        contact: String,
        /// Penetration depth, m.
        depth: f64,
        /// Admissible penetration, m.
        limit: f64,
    },
    /// A nearly incompressible (penalty) body changed its volume beyond the admissible
    /// relative error (checked on every converged step).
    #[error(
        "{what} volume {volume:.6e} m^3 deviates from its reference {reference:.6e} m^3 by {:.3}% (limit {:.3}%)",
        100.0 * (volume / reference - 1.0), 100.0 * limit
    )]
    VolumeError {
        /// Which body (e.g. "fluid").
        what: String,
        /// Current volume, m³.
        volume: f64,
        /// Reference volume, m³.
        reference: f64,
        /// Admissible relative error.
        limit: f64,
    },
    /// An element's volume ratio J = det F fell below the admissible floor (> 0) at a
    /// quadrature point (run-time invariant, see [`crate::invariants`]).
    #[error("element {element} distorted: J = {j:.3e} at quadrature point {point}, below its limit {limit:.3e}")]
    DistortedElement {
        /// Element index in the system's own numbering.
        element: usize,
        /// Quadrature point (viscous, then penalty, then mass points).
        point: usize,
        /// Volume ratio there.
        j: f64,
        /// Admissible floor.
        limit: f64,
    },
    /// Liquid left its tank: a fluid node, contact point or the centre of mass lies
    /// beyond a wall by more than the admissible gap (run-time invariant, see
    /// [`crate::invariants`]).
    #[error(
        "{what} not contained: {site} at tank-frame ({:.4}, {:.4}, {:.4}) m is {depth:.3e} m beyond the wall (limit {limit:.3e} m)",
        position[0], position[1], position[2]
    )]
    Containment {
        /// Which liquid (e.g. "fluid", "car 0 fluid").
        what: String,
        /// Which node, point or the centre of mass.
        site: String,
        /// Its tank-frame position, m.
        position: [f64; 3],
        /// Gap beyond the wall, m.
        depth: f64,
        /// Admissible gap, m.
        limit: f64,
    },
    /// The liquid's energy grew beyond what the walls put in (run-time invariant, see
    /// [`crate::invariants`]): no physical mechanism creates energy.
    #[error(
        "{what} energy balance broken: E = {energy:.6e} J, E0 = {initial:.6e} J, work put in {input_work:.6e} J: growth {relative:.3e} of the energy scale (limit {limit:.3e})"
    )]
    EnergyGrowth {
        /// Which liquid.
        what: String,
        /// Kinetic + potential + stored energy now, J.
        energy: f64,
        /// Its initial value, J.
        initial: f64,
        /// Work put into the liquid so far (walls, or gravity and pseudo-forces), J.
        input_work: f64,
        /// Growth (E − E0 − W) relative to the energy scale.
        relative: f64,
        /// Admissible growth.
        limit: f64,
    },
    /// A wheel carried no load for longer than the admissible time (run-time invariant of
    /// vehicle runs, [`crate::vehicle::WHEEL_OFF_RAIL_LIMIT`]): the wheel has left the rail
    /// (derailment, or a wheel lift far longer than track tests admit).
    #[error(
        "wheel off the rail: wheelset {wheelset} (front to rear), {side} wheel carried no load from t = {since:.3} s to {t:.3} s, longer than {limit} s (wheelset lateral displacement {lateral:.4} m)"
    )]
    WheelOffRail {
        /// Wheelset index, front to rear over the train.
        wheelset: usize,
        /// "left" or "right".
        side: &'static str,
        /// Time of the first sample without load, s.
        since: f64,
        /// Time of this sample, s.
        t: f64,
        /// Admissible time without load, s.
        limit: f64,
        /// Lateral displacement of the wheelset from the track centreline, m.
        lateral: f64,
    },
    /// Any other model failure.
    #[error("{0}")]
    Other(String),
}

impl From<ancf_core::error::AncfError> for SystemError {
    /// A fluid-body error as the system error that locates it: an inverted element keeps its
    /// element, point and J; a non-finite element value its element; anything else is `Other`.
    fn from(e: ancf_core::error::AncfError) -> Self {
        use ancf_core::error::AncfError;
        match e {
            AncfError::InvertedElement { element, point, j } => SystemError::InvertedElement { element, point, j },
            AncfError::NonFinite { element, what } => SystemError::Element { index: element, reason: what },
            other => SystemError::Other(other.to_string()),
        }
    }
}

/// Which quantity was found non-finite (NaN or ±inf).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// Initial positions `q0`.
    InitialPositions,
    /// Initial velocities `v0`.
    InitialVelocities,
    /// Mass-matrix values.
    Mass,
    /// Generalized forces `Q`.
    Forces,
    /// Force Jacobian `∂Q/∂q`.
    ForceJacobianQ,
    /// Force Jacobian `∂Q/∂v`.
    ForceJacobianV,
    /// Constraint residuals `C`.
    Constraints,
    /// Constraint Jacobian `C_q`.
    ConstraintJacobian,
    /// Constraint acceleration right-hand side (consistent initialization).
    ConstraintAccelerationRhs,
    /// Newton residual (right-hand side of the KKT solve).
    Residual,
    /// Positions of a converged step.
    Positions,
    /// Velocities of a converged step.
    Velocities,
}

impl fmt::Display for Quantity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = match self {
            Self::InitialPositions => "initial positions",
            Self::InitialVelocities => "initial velocities",
            Self::Mass => "mass matrix",
            Self::Forces => "generalized forces Q",
            Self::ForceJacobianQ => "force Jacobian dQ/dq",
            Self::ForceJacobianV => "force Jacobian dQ/dv",
            Self::Constraints => "constraint residual C",
            Self::ConstraintJacobian => "constraint Jacobian C_q",
            Self::ConstraintAccelerationRhs => "constraint acceleration right-hand side",
            Self::Residual => "Newton residual",
            Self::Positions => "positions",
            Self::Velocities => "velocities",
        };
        f.write_str(s)
    }
}

/// Errors of the HHT-α integrator. Each variant says where (time, step size, index)
/// and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IntegratorError {
    /// A parameter is outside its admissible range.
    #[error("invalid `{field}` = {value}: expected {allowed}")]
    InvalidParameter {
        /// Parameter name.
        field: &'static str,
        /// Rejected value.
        value: f64,
        /// Admissible range, in words.
        allowed: &'static str,
    },
    /// The system's dimensions or sparsity pattern are inconsistent.
    #[error("invalid system: {what}")]
    InvalidSystem {
        /// What is inconsistent.
        what: String,
    },
    /// A system callback returned NaN or ±inf.
    #[error("non-finite {what} at t = {t} s (entry {index})")]
    NonFinite {
        /// Time at which the callback was evaluated, s.
        t: f64,
        /// Which quantity.
        what: Quantity,
        /// Index of the first non-finite entry (pattern order for matrices).
        index: usize,
    },
    /// The KKT matrix is singular: a pivot could not be found, or the solution is
    /// non-finite / fails the residual check. Usually redundant or inconsistent
    /// constraints.
    #[error(
        "singular KKT matrix at t = {t} s (h = {h} s): {}{}",
        match pivot_step { Some(p) => format!("no pivot at elimination step {p}"), None => String::from("numerically singular") },
        match unknown { Some(u) => format!(", first bad unknown: {u}"), None => String::new() }
    )]
    SingularMatrix {
        /// Start time of the step (or initial time), s.
        t: f64,
        /// Step size, s (0 for the initial acceleration solve).
        h: f64,
        /// Elimination step at which faer found no pivot (permuted order), if known.
        pivot_step: Option<usize>,
        /// First unknown whose solution was non-finite, if known.
        unknown: Option<KktIndex>,
    },
    /// Newton iterations did not converge (and the step could not be reduced).
    #[error(
        "Newton iteration did not converge at t = {t} s, h = {h} s after {iterations} iterations \
         (last WRMS correction {correction:e}, rate {rate:e}){}",
        largest.as_ref().map_or(String::new(), |w| format!("; largest correction: {w}"))
    )]
    NewtonDivergence {
        /// Start time of the step, s.
        t: f64,
        /// Step size of the last attempt, s.
        h: f64,
        /// Newton iterations of the last attempt.
        iterations: usize,
        /// Weighted RMS norm of the last correction (converged when < 1).
        correction: f64,
        /// Last estimated convergence rate (NaN if fewer than two iterations).
        rate: f64,
        /// The unknown with the largest weighted correction in the last iteration, as the
        /// system describes it ([`super::MechanicalSystem::describe_unknown`]), if any.
        largest: Option<String>,
    },
    /// Adaptive stepping needed a step below `h_min`.
    #[error("step size {h:e} s below h_min = {h_min:e} s at t = {t} s; last failure: {cause}")]
    StepTooSmall {
        /// Time at which the step failed, s.
        t: f64,
        /// Step size that would have been needed, s.
        h: f64,
        /// Configured minimum step size, s.
        h_min: f64,
        /// Why the last attempt failed (e.g. Newton divergence, an inverted element).
        cause: Box<IntegratorError>,
    },
    /// The sparse linear solver failed for a reason other than singularity
    /// (out of memory, index overflow).
    #[error("linear solver failure at t = {t} s: {message}")]
    LinearSolver {
        /// Time, s.
        t: f64,
        /// faer's error, formatted.
        message: String,
    },
    /// A checkpoint could not be decoded or does not fit the system.
    #[error("invalid checkpoint: {what}")]
    Checkpoint {
        /// What is wrong.
        what: String,
    },
    /// A system callback failed.
    #[error("system evaluation failed at t = {t} s: {source}")]
    System {
        /// Time at which the callback was evaluated, s.
        t: f64,
        /// The system's error, naming the element/constraint/body.
        source: SystemError,
    },
}

/// Classification of a failure, for sweeps and for the Python exception
/// (`SimulationError.cause`): every stopped run names one of these.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FailureCause {
    /// Bad parameter or inconsistent system (nothing was integrated).
    InvalidInput,
    /// A finite element inverted (`J ≤ 0`).
    InvertedElement,
    /// Newton iterations diverged or did not converge.
    NewtonDivergence,
    /// A penalty contact penetrated beyond its limit.
    ContactPenetration,
    /// A penalty-incompressible body lost or gained volume beyond its limit.
    VolumeError,
    /// The KKT matrix is singular (redundant/inconsistent constraint set).
    SingularConstraints,
    /// A NaN/Inf appeared in a model quantity.
    NonFinite,
    /// The linear solver failed for another reason (memory, overflow).
    LinearSolver,
    /// Liquid left its tank (run-time invariant).
    Containment,
    /// The liquid's energy grew beyond the work put in (run-time invariant).
    EnergyGrowth,
    /// An element distorted beyond the admissible volume ratio (run-time invariant).
    DistortedElement,
    /// A wheel left the rail (run-time invariant of vehicle runs).
    WheelOffRail,
    /// Another model failure.
    Model,
}

impl FailureCause {
    /// Stable snake-case name (used in Python and in stress tables).
    pub fn name(self) -> &'static str {
        match self {
            Self::InvalidInput => "invalid_input",
            Self::InvertedElement => "inverted_element",
            Self::NewtonDivergence => "newton_divergence",
            Self::ContactPenetration => "contact_penetration",
            Self::VolumeError => "volume_error",
            Self::SingularConstraints => "singular_constraints",
            Self::NonFinite => "non_finite",
            Self::LinearSolver => "linear_solver",
            Self::Containment => "containment",
            Self::EnergyGrowth => "energy_growth",
            Self::DistortedElement => "distorted_element",
            Self::WheelOffRail => "wheel_off_rail",
            Self::Model => "model",
        }
    }
}

impl fmt::Display for FailureCause {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl IntegratorError {
    /// The error that actually stopped the run: for
    /// [`StepTooSmall`](Self::StepTooSmall), the failure of the last attempt.
    pub fn root(&self) -> &IntegratorError {
        match self {
            Self::StepTooSmall { cause, .. } => cause.root(),
            other => other,
        }
    }

    /// Classifies the root cause.
    pub fn cause(&self) -> FailureCause {
        match self.root() {
            Self::InvalidParameter { .. } | Self::InvalidSystem { .. } | Self::Checkpoint { .. } => {
                FailureCause::InvalidInput
            }
            Self::NonFinite { .. } => FailureCause::NonFinite,
            Self::SingularMatrix { .. } => FailureCause::SingularConstraints,
            Self::NewtonDivergence { .. } | Self::StepTooSmall { .. } => FailureCause::NewtonDivergence,
            Self::LinearSolver { .. } => FailureCause::LinearSolver,
            Self::System { source, .. } => match source {
                SystemError::InvertedElement { .. } => FailureCause::InvertedElement,
                SystemError::Penetration { .. } => FailureCause::ContactPenetration,
                SystemError::VolumeError { .. } => FailureCause::VolumeError,
                SystemError::Containment { .. } => FailureCause::Containment,
                SystemError::EnergyGrowth { .. } => FailureCause::EnergyGrowth,
                SystemError::DistortedElement { .. } => FailureCause::DistortedElement,
                SystemError::WheelOffRail { .. } => FailureCause::WheelOffRail,
                _ => FailureCause::Model,
            },
        }
    }

    /// Time at which the failure happened, s (`None` for invalid input).
    pub fn time(&self) -> Option<f64> {
        match self {
            Self::InvalidParameter { .. } | Self::InvalidSystem { .. } | Self::Checkpoint { .. } => None,
            Self::NonFinite { t, .. }
            | Self::SingularMatrix { t, .. }
            | Self::NewtonDivergence { t, .. }
            | Self::StepTooSmall { t, .. }
            | Self::LinearSolver { t, .. }
            | Self::System { t, .. } => Some(*t),
        }
    }
}
