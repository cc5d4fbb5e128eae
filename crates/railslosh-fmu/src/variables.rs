//! The FMU variables (one table, indexed by value reference) and the `modelDescription.xml`
//! generated from it.
//!
//! The checked-in `crates/railslosh-fmu/modelDescription.xml` is compared with
//! [`model_description_xml`] by a unit test; regenerate it with
//! `RAILSLOSH_FMU_BLESS=1 cargo test -p railslosh-fmu model_description`.

/// Model identifier: the name of the shared library inside the FMU.
pub const MODEL_IDENTIFIER: &str = "railslosh_slosh";
/// Instantiation token shared by `modelDescription.xml` and the binary; change it whenever
/// the variables change.
pub const INSTANTIATION_TOKEN: &str = "{5f0c3a52-7d1e-4b8a-9c6f-railslosh-slosh-v1}";
/// Gravitational acceleration used by default and for the equivalent-pendulum frequencies (m/s²).
pub use ancf_core::constants::GRAVITY;

/// Causality of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    /// The independent variable (time).
    Independent,
    /// Set by the importer at communication points.
    Input,
    /// Computed by the FMU.
    Output,
    /// Set before initialization, fixed afterwards.
    Parameter,
    /// Computed from the parameters at initialization.
    CalculatedParameter,
}

impl Causality {
    fn as_str(self) -> &'static str {
        match self {
            Self::Independent => "independent",
            Self::Input => "input",
            Self::Output => "output",
            Self::Parameter => "parameter",
            Self::CalculatedParameter => "calculatedParameter",
        }
    }
}

/// Type of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// fmi3Float64.
    Float64,
    /// fmi3Int32 (stored as an exactly representable f64).
    Int32,
}

/// One FMU variable.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Variable {
    /// Name in `modelDescription.xml`.
    pub name: &'static str,
    /// Type.
    pub kind: Kind,
    /// Causality.
    pub causality: Causality,
    /// Start value (inputs and parameters).
    pub start: Option<f64>,
    /// Smallest allowed value.
    pub min: Option<f64>,
    /// Largest allowed value.
    pub max: Option<f64>,
    /// Unit name (declared in `UnitDefinitions`).
    pub unit: Option<&'static str>,
    /// Description.
    pub description: &'static str,
}

const fn var(
    name: &'static str,
    causality: Causality,
    start: Option<f64>,
    unit: Option<&'static str>,
    description: &'static str,
) -> Variable {
    Variable { name, kind: Kind::Float64, causality, start, min: None, max: None, unit, description }
}

const fn param(
    name: &'static str,
    start: f64,
    min: f64,
    max: f64,
    unit: Option<&'static str>,
    description: &'static str,
) -> Variable {
    Variable {
        name,
        kind: Kind::Float64,
        causality: Causality::Parameter,
        start: Some(start),
        min: Some(min),
        max: Some(max),
        unit,
        description,
    }
}

const fn int_param(name: &'static str, start: f64, min: f64, max: f64, description: &'static str) -> Variable {
    Variable {
        name,
        kind: Kind::Int32,
        causality: Causality::Parameter,
        start: Some(start),
        min: Some(min),
        max: Some(max),
        unit: None,
        description,
    }
}

use Causality::{CalculatedParameter, Independent, Input, Output};

/// Value reference of `time`.
pub const VR_TIME: usize = 0;
/// First of the tank acceleration inputs `a_x, a_y, a_z`.
pub const VR_ACCELERATION: usize = 1;
/// First of the angular velocity inputs `omega_x..z`.
pub const VR_OMEGA: usize = 4;
/// First of the angular acceleration inputs `omega_dot_x..z`.
pub const VR_OMEGA_DOT: usize = 7;
/// First of the gravity inputs `gravity_x..z`.
pub const VR_GRAVITY: usize = 10;
/// First of the force outputs `F_x..z`.
pub const VR_FORCE: usize = 13;
/// First of the moment outputs `M_x..z`.
pub const VR_MOMENT: usize = 16;
/// First of the centre-of-mass outputs `com_x..z`.
pub const VR_COM: usize = 19;
/// `model` (Int32): 0 pendulum, 1 ANCF.
pub const VR_MODEL: usize = 22;
/// `fill`.
pub const VR_FILL: usize = 23;
/// `density`.
pub const VR_DENSITY: usize = 24;
/// `viscosity`.
pub const VR_VISCOSITY: usize = 25;
/// `length`.
pub const VR_LENGTH: usize = 26;
/// `semi_axis_y`.
pub const VR_SEMI_AXIS_Y: usize = 27;
/// `semi_axis_z`.
pub const VR_SEMI_AXIS_Z: usize = 28;
/// First of the reference point `ref_x..z`.
pub const VR_REF: usize = 29;
/// `h_max`.
pub const VR_H_MAX: usize = 32;
/// `damping_ratio`.
pub const VR_DAMPING: usize = 33;
/// First of the Int32 element counts `n_length, n_width, n_height`.
pub const VR_COUNTS: usize = 34;
/// `mass` (calculated parameter).
pub const VR_MASS: usize = 37;
/// `f_longitudinal` (calculated parameter).
pub const VR_F_LONG: usize = 38;
/// `f_lateral` (calculated parameter).
pub const VR_F_LAT: usize = 39;

/// Every variable; the value reference is the index.
pub const VARIABLES: [Variable; 40] = [
    var("time", Independent, None, Some("s"), "Simulation time"),
    var("a_x", Input, Some(0.0), Some("m/s2"), "Tank origin acceleration (inertial, without gravity), tank x"),
    var("a_y", Input, Some(0.0), Some("m/s2"), "Tank origin acceleration (inertial, without gravity), tank y"),
    var("a_z", Input, Some(0.0), Some("m/s2"), "Tank origin acceleration (inertial, without gravity), tank z"),
    var("omega_x", Input, Some(0.0), Some("rad/s"), "Tank angular velocity, tank x"),
    var("omega_y", Input, Some(0.0), Some("rad/s"), "Tank angular velocity, tank y"),
    var("omega_z", Input, Some(0.0), Some("rad/s"), "Tank angular velocity, tank z"),
    var("omega_dot_x", Input, Some(0.0), Some("rad/s2"), "Tank angular acceleration, tank x"),
    var("omega_dot_y", Input, Some(0.0), Some("rad/s2"), "Tank angular acceleration, tank y"),
    var("omega_dot_z", Input, Some(0.0), Some("rad/s2"), "Tank angular acceleration, tank z"),
    var("gravity_x", Input, Some(0.0), Some("m/s2"), "Gravitational acceleration, tank x"),
    var("gravity_y", Input, Some(0.0), Some("m/s2"), "Gravitational acceleration, tank y"),
    var("gravity_z", Input, Some(-GRAVITY), Some("m/s2"), "Gravitational acceleration, tank z"),
    var("F_x", Output, None, Some("N"), "Force of the fluid on the tank, tank x"),
    var("F_y", Output, None, Some("N"), "Force of the fluid on the tank, tank y"),
    var("F_z", Output, None, Some("N"), "Force of the fluid on the tank, tank z"),
    var("M_x", Output, None, Some("N.m"), "Moment of the fluid on the tank about the reference point, tank x"),
    var("M_y", Output, None, Some("N.m"), "Moment of the fluid on the tank about the reference point, tank y"),
    var("M_z", Output, None, Some("N.m"), "Moment of the fluid on the tank about the reference point, tank z"),
    var("com_x", Output, None, Some("m"), "Fluid centre of mass, tank x"),
    var("com_y", Output, None, Some("m"), "Fluid centre of mass, tank y"),
    var("com_z", Output, None, Some("m"), "Fluid centre of mass, tank z"),
    int_param("model", 0.0, 0.0, 1.0, "Slosh model: 0 equivalent pendulum, 1 ANCF brick fluid"),
    param("fill", 0.5, 0.01, 0.97, None, "Liquid volume fraction of the tank"),
    param("density", 1000.0, 1.0, 1e5, Some("kg/m3"), "Liquid density"),
    param("viscosity", 1e-3, 0.0, 1e6, Some("Pa.s"), "Dynamic viscosity, Newtonian (ANCF model)"),
    param("length", 0.324, 1e-3, 100.0, Some("m"), "Tank length (flat ends)"),
    param("semi_axis_y", 0.208585, 1e-3, 10.0, Some("m"), "Lateral semi-axis of the elliptical section"),
    param("semi_axis_z", 0.132131, 1e-3, 10.0, Some("m"), "Vertical semi-axis of the elliptical section"),
    param("ref_x", 0.0, -1e3, 1e3, Some("m"), "Reference point of the moments, tank x"),
    param("ref_y", 0.0, -1e3, 1e3, Some("m"), "Reference point of the moments, tank y"),
    param("ref_z", 0.0, -1e3, 1e3, Some("m"), "Reference point of the moments, tank z"),
    param("h_max", 0.005, 1e-6, 1.0, Some("s"), "Largest internal time step"),
    param("damping_ratio", 0.02, 0.0, 1.0, None, "Damping ratio of the pendulum modes (pendulum model)"),
    int_param("n_length", 2.0, 1.0, 64.0, "ANCF elements along the length"),
    int_param("n_width", 4.0, 1.0, 64.0, "ANCF elements across the width"),
    int_param("n_height", 2.0, 1.0, 64.0, "ANCF elements over the height"),
    var("mass", CalculatedParameter, None, Some("kg"), "Fluid mass"),
    var(
        "f_longitudinal",
        CalculatedParameter,
        None,
        Some("Hz"),
        "First longitudinal slosh frequency, equivalent-pendulum estimate",
    ),
    var(
        "f_lateral",
        CalculatedParameter,
        None,
        Some("Hz"),
        "First lateral slosh frequency, equivalent-pendulum estimate",
    ),
];

/// Units used by the variables: name and SI base-unit exponents (kg, m, s, rad).
const UNITS: [(&str, [i32; 4]); 10] = [
    ("s", [0, 0, 1, 0]),
    ("m", [0, 1, 0, 0]),
    ("kg", [1, 0, 0, 0]),
    ("m/s2", [0, 1, -2, 0]),
    ("rad/s", [0, 0, -1, 1]),
    ("rad/s2", [0, 0, -2, 1]),
    ("N", [1, 1, -2, 0]),
    ("N.m", [1, 2, -2, 0]),
    ("kg/m3", [1, -3, 0, 0]),
    ("Pa.s", [1, -1, -1, 0]),
];

/// Hz as a separate unit (s⁻¹).
const HZ: (&str, [i32; 4]) = ("Hz", [0, 0, -1, 0]);

/// Log categories understood by `fmi3SetDebugLogging`.
pub const LOG_CATEGORIES: [(&str, &str); 3] = [
    ("logStatusError", "Errors: invalid calls, arguments and failed steps"),
    ("logStatusWarning", "Warnings"),
    ("logCalls", "Every fmi3 call"),
];

/// Initial value of every variable: start values; NaN where the FMU computes it.
pub fn start_values() -> Vec<f64> {
    VARIABLES.iter().map(|v| v.start.unwrap_or(f64::NAN)).collect()
}

fn fmt_num(x: f64) -> String {
    // shortest representation that round-trips
    format!("{x:?}")
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// `modelDescription.xml` of the FMU.
pub fn model_description_xml() -> String {
    use std::fmt::Write;
    let mut x = String::new();
    let version = env!("CARGO_PKG_VERSION");
    let _ = writeln!(x, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(x, "<!-- Generated by crates/railslosh-fmu (variables.rs); do not edit by hand. -->");
    let _ = writeln!(
        x,
        r#"<fmiModelDescription fmiVersion="3.0" modelName="{MODEL_IDENTIFIER}" instantiationToken="{INSTANTIATION_TOKEN}"
  description="railslosh: liquid sloshing in a flat-ended tank of elliptical section; loads on the tank from the tank motion (tank frame)"
  generationTool="railslosh-fmu {version}" version="{version}" license="Apache-2.0" variableNamingConvention="flat">"#
    );
    let _ = writeln!(
        x,
        r#"  <CoSimulation modelIdentifier="{MODEL_IDENTIFIER}" canHandleVariableCommunicationStepSize="true" canGetAndSetFMUState="true" canSerializeFMUState="true" canBeInstantiatedOnlyOncePerProcess="false" hasEventMode="true" providesIntermediateUpdate="false" canReturnEarlyAfterIntermediateUpdate="false"/>"#
    );
    x.push_str("  <UnitDefinitions>\n");
    for (name, e) in UNITS.iter().chain(std::iter::once(&HZ)) {
        let mut base = String::new();
        for (k, key) in ["kg", "m", "s", "rad"].iter().enumerate() {
            if e[k] != 0 {
                let _ = write!(base, r#" {key}="{}""#, e[k]);
            }
        }
        let _ = writeln!(x, r#"    <Unit name="{name}"><BaseUnit{base}/></Unit>"#);
    }
    x.push_str("  </UnitDefinitions>\n  <LogCategories>\n");
    for (name, d) in LOG_CATEGORIES {
        let _ = writeln!(x, r#"    <Category name="{name}" description="{}"/>"#, escape(d));
    }
    x.push_str("  </LogCategories>\n");
    x.push_str(r#"  <DefaultExperiment startTime="0.0" stopTime="5.0" stepSize="0.01"/>"#);
    x.push_str("\n  <ModelVariables>\n");
    for (vr, v) in VARIABLES.iter().enumerate() {
        let tag = match v.kind {
            Kind::Float64 => "Float64",
            Kind::Int32 => "Int32",
        };
        let variability = match (v.causality, v.kind) {
            (Causality::Parameter | Causality::CalculatedParameter, _) => "fixed",
            (_, Kind::Int32) => "discrete",
            _ => "continuous",
        };
        let _ = write!(x, r#"    <{tag} name="{}" valueReference="{vr}" causality="{}""#, v.name, v.causality.as_str());
        let _ = write!(x, r#" variability="{variability}""#);
        if let Some(u) = v.unit {
            let _ = write!(x, r#" unit="{u}""#);
        }
        let num = |y: f64| match v.kind {
            Kind::Float64 => fmt_num(y),
            Kind::Int32 => format!("{}", y as i64),
        };
        if let Some(m) = v.min {
            let _ = write!(x, r#" min="{}""#, num(m));
        }
        if let Some(m) = v.max {
            let _ = write!(x, r#" max="{}""#, num(m));
        }
        if let Some(s) = v.start {
            let _ = write!(x, r#" start="{}""#, num(s));
        }
        let _ = writeln!(x, r#" description="{}"/>"#, escape(v.description));
    }
    x.push_str("  </ModelVariables>\n  <ModelStructure>\n");
    for (vr, v) in VARIABLES.iter().enumerate() {
        if v.causality == Causality::Output {
            let _ = writeln!(x, r#"    <Output valueReference="{vr}"/>"#);
        }
    }
    for (vr, v) in VARIABLES.iter().enumerate() {
        if matches!(v.causality, Causality::Output | Causality::CalculatedParameter) {
            let _ = writeln!(x, r#"    <InitialUnknown valueReference="{vr}"/>"#);
        }
    }
    x.push_str("  </ModelStructure>\n</fmiModelDescription>\n");
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_reference_constants_name_the_table() {
        let names = [
            (VR_TIME, "time"),
            (VR_ACCELERATION, "a_x"),
            (VR_OMEGA, "omega_x"),
            (VR_OMEGA_DOT, "omega_dot_x"),
            (VR_GRAVITY, "gravity_x"),
            (VR_FORCE, "F_x"),
            (VR_MOMENT, "M_x"),
            (VR_COM, "com_x"),
            (VR_MODEL, "model"),
            (VR_FILL, "fill"),
            (VR_DENSITY, "density"),
            (VR_VISCOSITY, "viscosity"),
            (VR_LENGTH, "length"),
            (VR_SEMI_AXIS_Y, "semi_axis_y"),
            (VR_SEMI_AXIS_Z, "semi_axis_z"),
            (VR_REF, "ref_x"),
            (VR_H_MAX, "h_max"),
            (VR_DAMPING, "damping_ratio"),
            (VR_COUNTS, "n_length"),
            (VR_MASS, "mass"),
            (VR_F_LONG, "f_longitudinal"),
            (VR_F_LAT, "f_lateral"),
        ];
        for (vr, name) in names {
            assert_eq!(VARIABLES[vr].name, name);
        }
        let mut seen = std::collections::HashSet::new();
        for v in &VARIABLES {
            assert!(seen.insert(v.name), "duplicate {}", v.name);
            if let (Some(s), Some(lo), Some(hi)) = (v.start, v.min, v.max) {
                assert!(lo <= s && s <= hi, "{} start outside [min, max]", v.name);
            }
            if let Some(u) = v.unit {
                assert!(UNITS.iter().chain(std::iter::once(&HZ)).any(|(n, _)| *n == u), "unit {u} undeclared");
            }
        }
    }

    /// The checked-in file is the generated one (regenerate with RAILSLOSH_FMU_BLESS=1).
    #[test]
    fn model_description_is_current() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("modelDescription.xml");
        let xml = model_description_xml();
        if std::env::var_os("RAILSLOSH_FMU_BLESS").is_some() {
            std::fs::write(&path, &xml).unwrap();
        }
        let on_disk = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            on_disk == xml,
            "{} is stale: run `RAILSLOSH_FMU_BLESS=1 cargo test -p railslosh-fmu model_description`",
            path.display()
        );
        assert_eq!(xml.matches("<Output ").count(), 9);
    }
}
