//! Python binding of the slosh co-simulation participant (`rail_mbs::cosim`, issue 6):
//! `railslosh._core.SloshParticipant` and its opaque `SloshParticipantState`.
//!
//! Inputs are dicts. Tank-frame form (seed 003's interface, tank axes):
//! `{"acceleration", "angular_velocity", "angular_acceleration", "gravity"}`; missing keys
//! are zero, except `gravity` = (0, 0, −g). Pose form (global axes), recognised by a
//! `"rotation"` (3×3, tank → global) or `"quaternion"` ([w, x, y, z]) key:
//! `{"position", "rotation" | "quaternion", "velocity", "angular_velocity", "acceleration",
//! "angular_acceleration"}`, missing vectors zero. Unknown keys raise `ValueError`.
//! Every computation runs without the GIL with panics caught; invalid input raises
//! `ValueError` naming the field, integration failures `RailsloshError`.

use std::panic::{AssertUnwindSafe, catch_unwind};

use ancf_core::element::QuadratureOptions;
use ancf_core::tank::{Bulkhead, TankGeometry, TankShape};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use rail_mbs::cosim::{
    CosimError, Loads, ParticipantState, PoseInput, SloshParticipant, SloshParticipantConfig, TankFrameSample,
    TankMotionInput,
};

fn cosim_err(e: CosimError) -> PyErr {
    match e {
        CosimError::InvalidParameter { .. } | CosimError::State(_) => PyValueError::new_err(e.to_string()),
        other => crate::RailsloshError::new_err(other.to_string()),
    }
}

/// Runs `f` without the GIL; panics become `RailsloshError`, errors are mapped.
fn run<T: Send>(py: Python<'_>, f: impl FnOnce() -> Result<T, CosimError> + Send) -> PyResult<T> {
    py.detach(|| catch_unwind(AssertUnwindSafe(f)))
        .map_err(|p| {
            let msg = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            crate::RailsloshError::new_err(format!("internal error (please report): {msg}"))
        })?
        .map_err(cosim_err)
}

fn bad(field: &str, value: impl std::fmt::Display, allowed: &str) -> PyErr {
    PyValueError::new_err(format!("invalid `{field}` = {value}: expected {allowed}"))
}

fn vec3(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<[f64; 3]> {
    let v: Vec<f64> = match obj.extract::<PyReadonlyArray1<'_, f64>>() {
        Ok(a) => a.as_array().to_vec(),
        Err(_) => obj
            .extract::<Vec<f64>>()
            .map_err(|_| bad(field, obj.repr().map_or("?".into(), |r| r.to_string()), "a sequence of 3 floats"))?,
    };
    v.try_into().map_err(|v: Vec<f64>| bad(field, format!("{v:?}"), "a sequence of 3 floats"))
}

fn mat3(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<[[f64; 3]; 3]> {
    let rows: Vec<Vec<f64>> = match obj.extract::<PyReadonlyArray2<'_, f64>>() {
        Ok(a) => a.as_array().rows().into_iter().map(|r| r.to_vec()).collect(),
        Err(_) => obj
            .extract::<Vec<Vec<f64>>>()
            .map_err(|_| bad(field, obj.repr().map_or("?".into(), |r| r.to_string()), "a 3x3 matrix"))?,
    };
    if rows.len() != 3 || rows.iter().any(|r| r.len() != 3) {
        return Err(bad(field, format!("{rows:?}"), "a 3x3 matrix"));
    }
    Ok(std::array::from_fn(|i| std::array::from_fn(|j| rows[i][j])))
}

const TANK_KEYS: [&str; 4] = ["acceleration", "angular_velocity", "angular_acceleration", "gravity"];
const POSE_KEYS: [&str; 7] =
    ["position", "rotation", "quaternion", "velocity", "angular_velocity", "acceleration", "angular_acceleration"];

fn parse_input(d: &Bound<'_, PyDict>, field: &str, g: f64) -> PyResult<TankMotionInput> {
    let is_pose = d.contains("rotation")? || d.contains("quaternion")?;
    let allowed: &[&str] = if is_pose { &POSE_KEYS } else { &TANK_KEYS };
    for k in d.keys() {
        let key: String = k.extract().map_err(|_| bad(field, k.to_string(), "string keys"))?;
        if !allowed.contains(&key.as_str()) {
            let form = if is_pose { "pose" } else { "tank-frame" };
            return Err(bad(&format!("{field}.{key}"), "given", &format!("a {form} input key, one of {allowed:?}")));
        }
    }
    let get = |key: &str, default: [f64; 3]| -> PyResult<[f64; 3]> {
        match d.get_item(key)? {
            Some(v) => vec3(&v, &format!("{field}.{key}")),
            None => Ok(default),
        }
    };
    if is_pose {
        if d.contains("rotation")? && d.contains("quaternion")? {
            return Err(bad(field, "rotation and quaternion", "only one of `rotation`, `quaternion`"));
        }
        let rotation = match d.get_item("rotation")? {
            Some(r) => mat3(&r, &format!("{field}.rotation"))?,
            None => {
                let q = d.get_item("quaternion")?.expect("checked above");
                let q: Vec<f64> = match q.extract::<PyReadonlyArray1<'_, f64>>() {
                    Ok(a) => a.as_array().to_vec(),
                    Err(_) => {
                        q.extract().map_err(|_| bad(&format!("{field}.quaternion"), "?", "4 floats [w, x, y, z]"))?
                    }
                };
                let q: [f64; 4] = q.try_into().map_err(|v: Vec<f64>| {
                    bad(&format!("{field}.quaternion"), format!("{v:?}"), "4 floats [w, x, y, z]")
                })?;
                PoseInput::rotation_from_quaternion(q).map_err(cosim_err)?
            }
        };
        Ok(TankMotionInput::Pose(PoseInput {
            position: get("position", [0.0; 3])?,
            rotation,
            velocity: get("velocity", [0.0; 3])?,
            angular_velocity: get("angular_velocity", [0.0; 3])?,
            acceleration: get("acceleration", [0.0; 3])?,
            angular_acceleration: get("angular_acceleration", [0.0; 3])?,
        }))
    } else {
        Ok(TankMotionInput::TankFrame(TankFrameSample {
            acceleration: get("acceleration", [0.0; 3])?,
            angular_velocity: get("angular_velocity", [0.0; 3])?,
            angular_acceleration: get("angular_acceleration", [0.0; 3])?,
            gravity: get("gravity", [0.0, 0.0, -g])?,
        }))
    }
}

fn tank_geometry(shape: &str, dims: &[f64], bulkheads: &[(f64, f64)]) -> PyResult<TankGeometry> {
    let shape = match (shape, dims) {
        ("cylinder", &[length, radius, head_depth]) => TankShape::Cylinder { length, radius, head_depth },
        ("elliptic", &[length, semi_axis_y, semi_axis_z]) => {
            TankShape::EllipticCylinder { length, semi_axis_y, semi_axis_z }
        }
        ("box", &[x0, y0, z0, x1, y1, z1]) => TankShape::Box { min: [x0, y0, z0], max: [x1, y1, z1] },
        _ => {
            return Err(bad(
                "tank",
                format!("{shape} {dims:?}"),
                "cylinder [length, radius, head_depth], elliptic [length, semi_axis_y, semi_axis_z] or box [min xyz, max xyz]",
            ));
        }
    };
    let bh = bulkheads.iter().map(|&(x, thickness)| Bulkhead { x, thickness }).collect();
    TankGeometry::new(shape, bh).map_err(|e| cosim_err(e.into()))
}

type Pair<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

fn loads_py<'py>(py: Python<'py>, l: Loads) -> Pair<'py> {
    (PyArray1::from_vec(py, l.force.to_vec()), PyArray1::from_vec(py, l.moment.to_vec()))
}

/// Saved state of a `SloshParticipant` (opaque; `to_bytes` / `from_bytes` for storage).
#[pyclass(name = "SloshParticipantState", module = "railslosh._core", frozen)]
struct PyParticipantState {
    inner: ParticipantState,
}

#[pymethods]
impl PyParticipantState {
    /// Time of the saved state (s).
    #[getter]
    fn time(&self) -> f64 {
        self.inner.time()
    }
    /// Exact serialized form.
    fn to_bytes<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &self.inner.to_bytes())
    }
    /// Inverse of `to_bytes`.
    #[staticmethod]
    fn from_bytes(data: &[u8]) -> PyResult<Self> {
        Ok(Self { inner: ParticipantState::from_bytes(data).map_err(cosim_err)? })
    }
}

/// The slosh model as a co-simulation participant (see `rail_mbs::cosim`).
#[pyclass(name = "SloshParticipant", module = "railslosh._core")]
struct PySloshParticipant {
    inner: SloshParticipant,
}

crate::args::named_readers!(participant_arg {
    tank_shape: String, tank_dims: Vec<f64>, bulkheads: Vec<(f64, f64)>, h_max: f64,
    reference_point: [f64; 3], gravity: f64, t0: f64, viscous_points: usize, penalty_points: usize,
});

#[pymethods]
impl PySloshParticipant {
    #[new]
    #[pyo3(signature = (mesh, fluid, tank_shape, tank_dims, bulkheads=Vec::new(), h_max=0.005,
                        reference_point=[0.0, 0.0, 0.0], gravity=ancf_core::constants::GRAVITY, t0=0.0, viscous_points=3, penalty_points=3))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        mesh: &crate::PyFluidMesh,
        fluid: &crate::PyFluid,
        #[pyo3(from_py_with = participant_arg::tank_shape)] tank_shape: String,
        #[pyo3(from_py_with = participant_arg::tank_dims)] tank_dims: Vec<f64>,
        #[pyo3(from_py_with = participant_arg::bulkheads)] bulkheads: Vec<(f64, f64)>,
        #[pyo3(from_py_with = participant_arg::h_max)] h_max: f64,
        #[pyo3(from_py_with = participant_arg::reference_point)] reference_point: [f64; 3],
        #[pyo3(from_py_with = participant_arg::gravity)] gravity: f64,
        #[pyo3(from_py_with = participant_arg::t0)] t0: f64,
        #[pyo3(from_py_with = participant_arg::viscous_points)] viscous_points: usize,
        #[pyo3(from_py_with = participant_arg::penalty_points)] penalty_points: usize,
    ) -> PyResult<Self> {
        let tank = tank_geometry(&tank_shape, &tank_dims, &bulkheads)?;
        let mut c = SloshParticipantConfig::new(mesh.inner.clone(), fluid.inner, tank);
        c.h_max = h_max;
        c.reference_point = reference_point;
        c.gravity = gravity;
        c.t0 = t0;
        c.quadrature = QuadratureOptions { viscous: viscous_points, penalty: penalty_points, ..c.quadrature };
        let inner = run(py, move || SloshParticipant::new(c))?;
        Ok(Self { inner })
    }

    /// Advance to `t_end` with the input interpolated linearly from `input_start` (now) to
    /// `input_end` (at `t_end`); returns (force, moment) of the fluid on the tank, tank
    /// axes, moment about the reference point.
    fn advance<'py>(
        &mut self,
        py: Python<'py>,
        t_end: f64,
        input_start: &Bound<'py, PyDict>,
        input_end: &Bound<'py, PyDict>,
    ) -> PyResult<Pair<'py>> {
        let g = self.inner.gravity();
        let (a, b) = (parse_input(input_start, "input_start", g)?, parse_input(input_end, "input_end", g)?);
        let p = &mut self.inner;
        let l = run(py, move || p.advance(t_end, &a, &b))?;
        Ok(loads_py(py, l))
    }

    /// Make the accelerations consistent with a constant input at the current time (e.g.
    /// the initial tank motion); returns (force, moment).
    fn set_initial_input<'py>(&mut self, py: Python<'py>, input: &Bound<'py, PyDict>) -> PyResult<Pair<'py>> {
        let a = parse_input(input, "input", self.inner.gravity())?;
        let p = &mut self.inner;
        let l = run(py, move || p.set_initial_input(&a))?;
        Ok(loads_py(py, l))
    }

    /// Let the fluid settle for `duration` s under a constant input, then set the clock
    /// back (the settled state is kept); returns (force, moment).
    fn settle<'py>(&mut self, py: Python<'py>, duration: f64, input: &Bound<'py, PyDict>) -> PyResult<Pair<'py>> {
        let a = parse_input(input, "input", self.inner.gravity())?;
        let p = &mut self.inner;
        let l = run(py, move || p.settle(duration, &a))?;
        Ok(loads_py(py, l))
    }

    /// Saved state for `restore_state` (exact rollback).
    fn save_state(&self, py: Python<'_>) -> PyResult<PyParticipantState> {
        let p = &self.inner;
        let inner = run(py, move || Ok(p.save_state()))?;
        Ok(PyParticipantState { inner })
    }

    /// Return exactly to a saved state.
    fn restore_state(&mut self, py: Python<'_>, state: &PyParticipantState) -> PyResult<()> {
        let (p, s) = (&mut self.inner, &state.inner);
        run(py, move || p.restore_state(s))
    }

    /// 6×6 rigid-body mass matrix of the fluid about the reference point, tank axes,
    /// for velocities (v_P, ω).
    fn added_mass<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let p = &self.inner;
        let m = run(py, move || Ok(p.added_mass()))?;
        Ok(PyArray1::from_vec(py, m.iter().flatten().copied().collect()).reshape([6, 6])?.into_any())
    }

    /// Loads at the current time: (force, moment).
    fn loads<'py>(&self, py: Python<'py>) -> Pair<'py> {
        loads_py(py, self.inner.loads())
    }

    /// Magnitude of gravity of the default input and the rest state, m/s².
    #[getter]
    fn gravity(&self) -> f64 {
        self.inner.gravity()
    }

    /// Current time (s).
    #[getter]
    fn time(&self) -> f64 {
        self.inner.time()
    }
    /// Fluid mass (kg).
    #[getter]
    fn fluid_mass(&self) -> f64 {
        self.inner.fluid_mass()
    }
    /// Fluid centre of mass, tank frame (m).
    #[getter]
    fn com_tank<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.com_tank().to_vec())
    }
    /// Fluid volume (m³).
    #[getter]
    fn volume(&self) -> f64 {
        self.inner.volume()
    }
    /// Reference point of the moments (tank frame, m).
    #[getter]
    fn reference_point<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.reference_point().to_vec())
    }
    /// Worst run-time invariant margins so far (dict as a slosh run's `margins`: worst gap and
    /// its limit, smallest volume ratio, worst energy error of the tank-frame energy account,
    /// energy dissipated); a window that breaks an invariant raises and is rolled back.
    #[getter]
    fn margins<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        crate::margins_dict(py, &self.inner.margins())
    }
    /// Largest integrator step (s).
    #[getter]
    fn h_max(&self) -> f64 {
        self.inner.h_max()
    }
    /// Integrator statistics.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        crate::stats_dict(py, self.inner.stats())
    }
}

/// Seed 003's six maneuvers as prescribed tank motions (`rail_mbs::maneuvers`, dimensions
/// documented there; the same motions as the shipped `swri_*` scenes), each starting after
/// `t_before` s, sampled every `dt` s with `t_after` s of free sloshing:
/// a list of dicts with `name` and arrays `t` (n), tank-frame `acceleration`,
/// `angular_velocity`, `angular_acceleration`, `gravity` (n×3), and the global pose
/// `position`, `velocity`, `pose_acceleration`, `pose_angular_velocity`,
/// `pose_angular_acceleration` (n×3), `rotation` (n×3×3).
#[pyfunction]
#[pyo3(signature = (dt=0.005, t_after=2.0, gravity=ancf_core::constants::GRAVITY, t_before=0.5))]
fn seed003_maneuvers<'py>(
    py: Python<'py>,
    dt: f64,
    t_after: f64,
    gravity: f64,
    t_before: f64,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    use rail_mbs::maneuvers::ManeuverSpec;
    let mans = run(py, move || {
        let mans =
            ManeuverSpec::seed003().iter().map(|m| m.build(t_before, t_after, dt)).collect::<Result<Vec<_>, _>>()?;
        mans.into_iter()
            .map(|m| {
                let tf = m.tank_frame(gravity)?;
                Ok((m, tf))
            })
            .collect::<Result<Vec<_>, CosimError>>()
    })?;
    let mut out = Vec::with_capacity(mans.len());
    for (m, tf) in mans {
        let n = m.times.len();
        let d = PyDict::new(py);
        let arr = |v: Vec<[f64; 3]>| -> PyResult<Bound<'py, PyAny>> {
            Ok(PyArray1::from_vec(py, v.into_iter().flatten().collect()).reshape([n, 3])?.into_any())
        };
        d.set_item("name", &m.name)?;
        d.set_item("t", PyArray1::from_vec(py, m.times.clone()))?;
        d.set_item("acceleration", arr(tf.iter().map(|s| s.acceleration).collect())?)?;
        d.set_item("angular_velocity", arr(tf.iter().map(|s| s.angular_velocity).collect())?)?;
        d.set_item("angular_acceleration", arr(tf.iter().map(|s| s.angular_acceleration).collect())?)?;
        d.set_item("gravity", arr(tf.iter().map(|s| s.gravity).collect())?)?;
        d.set_item("position", arr(m.poses.iter().map(|p| p.position).collect())?)?;
        d.set_item("velocity", arr(m.poses.iter().map(|p| p.velocity).collect())?)?;
        d.set_item("pose_acceleration", arr(m.poses.iter().map(|p| p.acceleration).collect())?)?;
        d.set_item("pose_angular_velocity", arr(m.poses.iter().map(|p| p.angular_velocity).collect())?)?;
        d.set_item("pose_angular_acceleration", arr(m.poses.iter().map(|p| p.angular_acceleration).collect())?)?;
        let rot: Vec<f64> = m.poses.iter().flat_map(|p| p.rotation.into_iter().flatten()).collect();
        d.set_item("rotation", PyArray1::from_vec(py, rot).reshape([n, 3, 3])?)?;
        out.push(d);
    }
    Ok(out)
}

/// Adds the co-simulation classes and functions to the module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PySloshParticipant>()?;
    m.add_class::<PyParticipantState>()?;
    m.add_function(wrap_pyfunction!(seed003_maneuvers, m)?)?;
    Ok(())
}
