//! Python binding of the maneuver library (`rail_mbs::maneuvers`, the one definition of
//! seed 003's lane changes and bumps): the prescribed motion of a scene's `[maneuver]` and
//! the defaults its keys take.

use ancf_core::error::{AncfError, invalid};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rail_mbs::maneuvers::{BumpProfile, BumpVehicle, LaneChangeCourse, ManeuverSpec};

/// The defaults of the maneuver keys (SI units): `lane_change` {offset, length, hold} (the
/// AVTP double lane change), `bump` {wheelbase, wheel_radius, suspension_frequency,
/// suspension_damping} (the vehicle), `trapezoid` {ramp_up, top, ramp_down} (multiples of
/// the height).
#[pyfunction]
fn maneuver_defaults(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    let lane = PyDict::new(py);
    let c = LaneChangeCourse::AVTP;
    lane.set_item("offset", c.offset)?;
    lane.set_item("length", c.length)?;
    lane.set_item("hold", c.hold.unwrap_or(0.0))?;
    d.set_item("lane_change", lane)?;
    let bump = PyDict::new(py);
    let v = BumpVehicle::default();
    bump.set_item("wheelbase", v.wheelbase)?;
    bump.set_item("wheel_radius", v.wheel_radius)?;
    bump.set_item("suspension_frequency", v.frequency)?;
    bump.set_item("suspension_damping", v.damping_ratio)?;
    d.set_item("bump", bump)?;
    let trap = PyDict::new(py);
    if let BumpProfile::Trapezoid { up_length, top_length, down_length, .. } = BumpProfile::seed003_trapezoid(1.0) {
        trap.set_item("ramp_up", up_length)?;
        trap.set_item("top", top_length)?;
        trap.set_item("ramp_down", down_length)?;
    }
    d.set_item("trapezoid", trap)?;
    Ok(d)
}

fn spec_from_dict(spec: &Bound<'_, PyDict>) -> PyResult<ManeuverSpec> {
    let num = |key: &str| -> PyResult<f64> {
        match spec.get_item(key)? {
            Some(v) => v.extract::<f64>().map_err(|_| crate::to_py(invalid(&format!("maneuver.{key}"), v, "a number"))),
            None => Err(crate::to_py(invalid(&format!("maneuver.{key}"), "missing", "a number"))),
        }
    };
    let kind: String = match spec.get_item("type")? {
        Some(v) => v.extract()?,
        None => String::new(),
    };
    match kind.as_str() {
        "lane_change" => {
            let double = match spec.get_item("double")? {
                Some(v) => v.extract::<bool>()?,
                None => true,
            };
            let course = LaneChangeCourse {
                offset: num("offset")?,
                length: num("length")?,
                hold: double.then(|| num("hold")).transpose()?,
            };
            Ok(ManeuverSpec::LaneChange { speed: num("speed")?, course })
        }
        "bump" => {
            let shape: String = match spec.get_item("shape")? {
                Some(v) => v.extract()?,
                None => "half_round".into(),
            };
            let height = num("height")?;
            let profile = match shape.as_str() {
                "half_round" => BumpProfile::HalfRound { height },
                "trapezoid" => BumpProfile::Trapezoid {
                    height,
                    up_length: num("ramp_up")?,
                    top_length: num("top")?,
                    down_length: num("ramp_down")?,
                },
                other => {
                    return Err(crate::to_py(invalid(
                        "maneuver.shape",
                        format!("{other:?}"),
                        "\"half_round\" or \"trapezoid\"",
                    )));
                }
            };
            let vehicle = BumpVehicle {
                wheelbase: num("wheelbase")?,
                wheel_radius: num("wheel_radius")?,
                frequency: num("suspension_frequency")?,
                damping_ratio: num("suspension_damping")?,
            };
            Ok(ManeuverSpec::Bump { speed: num("speed")?, profile, vehicle })
        }
        other => Err(crate::to_py(invalid("maneuver.type", format!("{other:?}"), "\"lane_change\" or \"bump\""))),
    }
}

/// The prescribed tank motion of one maneuver (`rail_mbs::maneuvers::ManeuverSpec`, built
/// from `spec`: the validated `[maneuver]` table of a slosh scene, SI units, every key
/// given), starting at `t0` (s) and sampled every `dt` (s) to `t_end` (s): a dict with
/// `name`, `acceleration` ({"x", "y", "z"}: lists of (t, a), global m/s²), `rotation_axis`
/// (unit vector or None) and `angular_acceleration` (list of (t, θ̈), rad/s²): the fields of
/// `railslosh.slosh.Motion`.
#[pyfunction]
#[pyo3(signature = (spec, t0, t_end, dt=1e-3))]
fn maneuver_motion<'py>(
    py: Python<'py>,
    spec: &Bound<'py, PyDict>,
    t0: f64,
    t_end: f64,
    dt: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let spec = spec_from_dict(spec)?;
    let (name, motion) = crate::compute(py, move || -> Result<_, AncfError> {
        if !(t_end.is_finite() && t_end > 0.0) {
            return Err(invalid("t_end", t_end, "> 0 (s)"));
        }
        let m = spec.build(t0, t_end, dt)?.until(t_end);
        Ok((m.name.clone(), m.prescribed_motion()?))
    })?;
    let d = PyDict::new(py);
    d.set_item("name", name)?;
    let acc = PyDict::new(py);
    for (axis, sig) in ["x", "y", "z"].iter().zip(&motion.translation) {
        acc.set_item(axis, sig.samples().collect::<Vec<_>>())?;
    }
    d.set_item("acceleration", acc)?;
    match &motion.rotation {
        Some((axis, sig)) => {
            d.set_item("rotation_axis", axis.to_vec())?;
            d.set_item("angular_acceleration", sig.samples().collect::<Vec<_>>())?;
        }
        None => {
            d.set_item("rotation_axis", py.None())?;
            d.set_item("angular_acceleration", Vec::<(f64, f64)>::new())?;
        }
    }
    Ok(d)
}

/// Adds the maneuver functions to the module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(maneuver_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(maneuver_motion, m)?)?;
    Ok(())
}
