//! PyO3 bindings of railslosh, built by maturin as `railslosh._core`.
//!
//! The binding layer is thin: it converts arguments, releases the GIL around every
//! computation (`py.detach`), maps Rust errors to Python exceptions, and catches any
//! Rust panic so that none ever reaches Python as a `PanicException`.
//!
//! Error mapping: invalid parameters and wrong array sizes → `ValueError` naming the
//! field and the allowed range; failures of a computation (inverted element, non-finite
//! values) → `railslosh.RailsloshError`.

use std::panic::{AssertUnwindSafe, catch_unwind};

mod args;
mod bench;
mod cosim;
mod irregularity;
mod maneuvers;
mod rail;
mod vehicle;

use ancf_core::body::FluidBody;
use ancf_core::constitutive::{Fluid, Rheology};
use ancf_core::element::QuadratureOptions;
use ancf_core::error::AncfError;
use ancf_core::mesh::{self, CylinderTankSpec, EllipticCylinderSpec, FluidMesh};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

create_exception!(_core, RailsloshError, PyException, "Base class of railslosh simulation errors.");

fn to_py(e: AncfError) -> PyErr {
    match e {
        AncfError::InvalidParameter { .. } | AncfError::DimensionMismatch { .. } => {
            PyValueError::new_err(e.to_string())
        }
        other => RailsloshError::new_err(other.to_string()),
    }
}

/// Run `f` without the GIL, converting errors and panics.
fn compute<T: Send, F: FnOnce() -> Result<T, AncfError> + Send>(py: Python<'_>, f: F) -> PyResult<T> {
    py.detach(|| catch_unwind(AssertUnwindSafe(f)))
        .map_err(|p| {
            let msg = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            RailsloshError::new_err(format!("internal error (please report): {msg}"))
        })?
        .map_err(to_py)
}

/// Wall-time interval between two calls of a Python progress callback, s.
const PROGRESS_INTERVAL: f64 = 0.5;

/// Calls a Python progress callback `progress(t, t_end, steps, newton_iterations, rejected)`
/// from a run that has released the GIL: after the first step, then at most every
/// [`PROGRESS_INTERVAL`] s of wall time, and at the end (GIL held only for the call). A
/// callback that raises stops the run; its exception is kept and re-raised by [`Self::finish`].
pub(crate) struct PyProgress {
    callback: Option<Py<PyAny>>,
    last: Option<std::time::Instant>,
    error: Option<PyErr>,
}

impl PyProgress {
    pub(crate) fn new(callback: Option<Py<PyAny>>) -> Self {
        Self { callback, last: None, error: None }
    }

    /// The observer of `rail_mbs` runs; `false` stops the run.
    pub(crate) fn observe(&mut self, p: &rail_mbs::vehicle::Progress) -> bool {
        let Some(cb) = &self.callback else { return true };
        let done = p.t >= p.t_end - 1e-12 * (1.0 + p.t_end.abs());
        if !done && self.last.is_some_and(|l| l.elapsed().as_secs_f64() < PROGRESS_INTERVAL) {
            return true;
        }
        self.last = Some(std::time::Instant::now());
        let args = (p.t, p.t_end, p.steps, p.newton_iterations, p.rejected_steps);
        match Python::attach(|py| cb.call1(py, args).map(|_| ())) {
            Ok(()) => true,
            Err(e) => {
                self.error = Some(e);
                false
            }
        }
    }

    /// The callback's exception, if it raised.
    pub(crate) fn finish(self) -> PyResult<()> {
        self.error.map_or(Ok(()), Err)
    }
}

/// (data, indices, indptr, shape) of a CSC matrix.
type CscArrays<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<i64>>, (usize, usize));

fn vec_of(a: &PyReadonlyArray1<'_, f64>, field: &str) -> PyResult<Vec<f64>> {
    Ok(a.as_slice()
        .map_err(|_| PyValueError::new_err(format!("`{field}` must be a contiguous float64 array")))?
        .to_vec())
}

/// A structured ANCF fluid mesh (reference configuration, tank frame).
#[pyclass(name = "FluidMesh", module = "railslosh._core", frozen)]
#[derive(Clone)]
struct PyFluidMesh {
    inner: FluidMesh,
}

#[pymethods]
impl PyFluidMesh {
    /// Node reference coordinates, shape (n_nodes, 12): r, r_x, r_y, r_z.
    #[getter]
    fn nodes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let flat = self.inner.reference_coordinates();
        let n = self.inner.n_nodes();
        Ok(PyArray1::from_vec(py, flat).reshape([n, 12])?.into_any())
    }
    /// Element connectivity, shape (n_elements, 8), node order A..H.
    #[getter]
    fn connectivity<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let flat: Vec<i64> = self.inner.elements.iter().flatten().map(|&x| x as i64).collect();
        Ok(PyArray1::from_vec(py, flat).reshape([self.inner.n_elements(), 8])?.into_any())
    }
    /// Straight-configuration element edge lengths, shape (n_elements, 3).
    #[getter]
    fn element_lengths<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let flat: Vec<f64> = self.inner.lengths.iter().flatten().copied().collect();
        Ok(PyArray1::from_vec(py, flat).reshape([self.inner.n_elements(), 3])?.into_any())
    }
    /// Boundary faces as a list of (element, face, kind) strings.
    #[getter]
    fn boundary(&self) -> Vec<(usize, String, String)> {
        self.inner.boundary.iter().map(|b| (b.element, format!("{:?}", b.face), format!("{:?}", b.kind))).collect()
    }
    #[getter]
    fn n_nodes(&self) -> usize {
        self.inner.n_nodes()
    }
    #[getter]
    fn n_elements(&self) -> usize {
        self.inner.n_elements()
    }
    #[getter]
    fn n_coords(&self) -> usize {
        self.inner.n_coords()
    }
    /// Element counts (length, width, height).
    #[getter]
    fn counts(&self) -> (usize, usize, usize) {
        let c = self.inner.counts;
        (c[0], c[1], c[2])
    }
    /// Exact volume of the region the mesh approximates (m³).
    #[getter]
    fn exact_volume(&self) -> f64 {
        self.inner.exact_volume
    }
    /// Initial free-surface height in the tank frame (m).
    #[getter]
    fn free_surface_z(&self) -> f64 {
        self.inner.free_surface_z
    }
    #[getter]
    fn kind(&self) -> String {
        self.inner.kind.clone()
    }
    fn __repr__(&self) -> String {
        format!(
            "FluidMesh({}, elements={}, nodes={}, coords={})",
            self.inner.kind,
            self.inner.n_elements(),
            self.inner.n_nodes(),
            self.inner.n_coords()
        )
    }
}

/// Box of fluid: origin (m), size (m) and element counts.
/// The liquids of seed 000 Table 2 and water (`rail_mbs::defaults::Oil`): name ->
/// (density kg/m³, dynamic viscosity Pa·s, yield stress Pa).
#[pyfunction]
fn crude_oils() -> Vec<(&'static str, (f64, f64, f64))> {
    use rail_mbs::defaults::Oil;
    [Oil::Light, Oil::Medium, Oil::Heavy, Oil::Water].iter().map(|o| (o.name(), o.properties())).collect()
}

/// Default penalty bulk modulus k_IC = ρ g H / strain, Pa (`rail_mbs::defaults::default_bulk_penalty`).
#[pyfunction]
#[pyo3(signature = (density, depth, strain=rail_mbs::defaults::PENALTY_STRAIN))]
fn default_bulk_penalty(density: f64, depth: f64, strain: f64) -> PyResult<f64> {
    rail_mbs::defaults::default_bulk_penalty(density, depth, strain).map_err(to_py)
}

/// Default penalty bulk viscosity c_TD = 0.2 √(k_IC ρ) h_el, Pa·s
/// (`rail_mbs::defaults::default_bulk_damping`).
#[pyfunction]
fn default_bulk_damping(bulk_penalty: f64, density: f64, element_height: f64) -> PyResult<f64> {
    for (field, value) in [("bulk_penalty", bulk_penalty), ("density", density), ("element_height", element_height)] {
        if !(value.is_finite() && value >= 0.0) {
            return Err(to_py(ancf_core::error::invalid(field, value, "a number >= 0")));
        }
    }
    Ok(rail_mbs::defaults::default_bulk_damping(bulk_penalty, density, element_height))
}

/// Recommended shear stabilization G_s = 0.006 ρ g h_el, Pa, and in a tank with heads
/// (`heads_depth`, the liquid depth H) at least 0.005 ρ g H
/// (`rail_mbs::defaults::default_shear_stabilization`).
#[pyfunction]
#[pyo3(signature = (density, element_height, heads_depth=None))]
fn default_shear_stabilization(density: f64, element_height: f64, heads_depth: Option<f64>) -> PyResult<f64> {
    let depth = heads_depth.unwrap_or(0.0);
    for (field, value) in [("density", density), ("element_height", element_height), ("heads_depth", depth)] {
        if !(value.is_finite() && value >= 0.0) {
            return Err(to_py(ancf_core::error::invalid(field, value, "a number >= 0")));
        }
    }
    Ok(rail_mbs::defaults::default_shear_stabilization(density, element_height, heads_depth))
}

#[pyfunction]
fn box_mesh(py: Python<'_>, origin: [f64; 3], size: [f64; 3], counts: [usize; 3]) -> PyResult<PyFluidMesh> {
    compute(py, || mesh::box_mesh(origin, size, counts)).map(|inner| PyFluidMesh { inner })
}

/// Liquid in a horizontal cylinder with half-ellipsoidal heads.
#[pyfunction]
#[pyo3(signature = (length, radius, head_depth, fill, n_length, n_width, n_height, grading=1.0))]
#[allow(clippy::too_many_arguments)]
fn cylinder_tank(
    py: Python<'_>,
    length: f64,
    radius: f64,
    head_depth: f64,
    fill: f64,
    n_length: usize,
    n_width: usize,
    n_height: usize,
    grading: f64,
) -> PyResult<PyFluidMesh> {
    let spec = CylinderTankSpec { length, radius, head_depth, fill, n_length, n_width, n_height, grading };
    compute(py, || mesh::cylinder_tank(&spec)).map(|inner| PyFluidMesh { inner })
}

/// Liquid in a flat-ended cylinder of elliptical section.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn elliptic_cylinder(
    py: Python<'_>,
    length: f64,
    semi_axis_y: f64,
    semi_axis_z: f64,
    fill: f64,
    n_length: usize,
    n_width: usize,
    n_height: usize,
) -> PyResult<PyFluidMesh> {
    let spec = EllipticCylinderSpec { length, semi_axis_y, semi_axis_z, fill, n_length, n_width, n_height };
    compute(py, || mesh::elliptic_cylinder(&spec)).map(|inner| PyFluidMesh { inner })
}

/// A fluid: density, rheology and penalty parameters (validated on construction).
#[pyclass(name = "Fluid", module = "railslosh._core", frozen)]
#[derive(Clone)]
struct PyFluid {
    inner: Fluid,
}

args::named_readers!(fluid_arg {
    density: f64, viscosity: f64, yield_stress: f64, consistency: Option<f64>, power_index: f64,
    elastic_modulus: Option<f64>, bulk_penalty: f64, bulk_damping: f64, shear_rate_reg: f64,
    shear_stabilization: f64, hourglass_stabilization: f64,
});

#[pymethods]
impl PyFluid {
    #[new]
    #[pyo3(signature = (density, model, *, viscosity=0.0, yield_stress=0.0, consistency=None, power_index=1.0,
                        elastic_modulus=None, bulk_penalty, bulk_damping=0.0, shear_rate_reg=1e-2,
                        shear_stabilization=0.0, hourglass_stabilization=0.0))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        #[pyo3(from_py_with = fluid_arg::density)] density: f64,
        model: &str,
        #[pyo3(from_py_with = fluid_arg::viscosity)] viscosity: f64,
        #[pyo3(from_py_with = fluid_arg::yield_stress)] yield_stress: f64,
        #[pyo3(from_py_with = fluid_arg::consistency)] consistency: Option<f64>,
        #[pyo3(from_py_with = fluid_arg::power_index)] power_index: f64,
        #[pyo3(from_py_with = fluid_arg::elastic_modulus)] elastic_modulus: Option<f64>,
        #[pyo3(from_py_with = fluid_arg::bulk_penalty)] bulk_penalty: f64,
        #[pyo3(from_py_with = fluid_arg::bulk_damping)] bulk_damping: f64,
        #[pyo3(from_py_with = fluid_arg::shear_rate_reg)] shear_rate_reg: f64,
        #[pyo3(from_py_with = fluid_arg::shear_stabilization)] shear_stabilization: f64,
        #[pyo3(from_py_with = fluid_arg::hourglass_stabilization)] hourglass_stabilization: f64,
    ) -> PyResult<Self> {
        let rheology = match model {
            "newtonian" => Rheology::Newtonian { viscosity },
            "bingham" => Rheology::Bingham { viscosity, yield_stress },
            "herschel-bulkley" => {
                Rheology::HerschelBulkley { consistency: consistency.unwrap_or(viscosity), power_index, yield_stress }
            }
            "oldroyd" => Rheology::Oldroyd { viscosity, yield_stress, elastic_modulus },
            "casson" => Rheology::Casson { viscosity, yield_stress },
            other => {
                return Err(PyValueError::new_err(format!(
                    "invalid `model` = {other:?}: expected one of newtonian, bingham, herschel-bulkley, oldroyd, casson"
                )));
            }
        };
        let f = Fluid {
            density,
            rheology,
            bulk_penalty,
            bulk_damping,
            shear_rate_reg,
            oldroyd_switch_width: 0.05,
            shear_stabilization,
            hourglass_stabilization,
        };
        f.validate().map_err(to_py)?;
        Ok(Self { inner: f })
    }
    #[getter]
    fn density(&self) -> f64 {
        self.inner.density
    }
    #[getter]
    fn model(&self) -> &'static str {
        self.inner.rheology.name()
    }
    #[getter]
    fn yield_stress(&self) -> f64 {
        self.inner.rheology.yield_stress()
    }
    #[getter]
    fn bulk_penalty(&self) -> f64 {
        self.inner.bulk_penalty
    }
    #[getter]
    fn bulk_damping(&self) -> f64 {
        self.inner.bulk_damping
    }
    /// Shear stabilization modulus G_s, Pa (0: none).
    #[getter]
    fn shear_stabilization(&self) -> f64 {
        self.inner.shear_stabilization
    }
    /// Non-affine-mode control modulus G_h, Pa (0: none).
    #[getter]
    fn hourglass_stabilization(&self) -> f64 {
        self.inner.hourglass_stabilization
    }
    /// Shear modulus of the Oldroyd elastic branch (0 for other models).
    #[getter]
    fn elastic_modulus(&self) -> f64 {
        self.inner.elastic_modulus()
    }
    fn __repr__(&self) -> String {
        format!("Fluid({:?})", self.inner)
    }
}

/// A meshed fluid body: reference data, constant mass matrix, forces and Jacobians.
#[pyclass(name = "FluidBody", module = "railslosh._core", frozen)]
struct PyFluidBody {
    inner: FluidBody,
}

args::named_readers!(body_arg { viscous_points: usize, penalty_points: usize, mass_points: usize });

#[pymethods]
impl PyFluidBody {
    #[new]
    #[pyo3(signature = (mesh, fluid, viscous_points=3, penalty_points=3, mass_points=4))]
    fn new(
        py: Python<'_>,
        mesh: &PyFluidMesh,
        fluid: &PyFluid,
        #[pyo3(from_py_with = body_arg::viscous_points)] viscous_points: usize,
        #[pyo3(from_py_with = body_arg::penalty_points)] penalty_points: usize,
        #[pyo3(from_py_with = body_arg::mass_points)] mass_points: usize,
    ) -> PyResult<Self> {
        let q = QuadratureOptions { viscous: viscous_points, penalty: penalty_points, mass: mass_points };
        let (m, f) = (mesh.inner.clone(), fluid.inner);
        compute(py, move || FluidBody::new(m, f, q)).map(|inner| Self { inner })
    }
    #[getter]
    fn n_coords(&self) -> usize {
        self.inner.n_coords()
    }
    #[getter]
    fn total_mass(&self) -> f64 {
        self.inner.total_mass()
    }
    #[getter]
    fn reference_volume(&self) -> f64 {
        self.inner.reference_volume()
    }
    #[getter]
    fn mesh(&self) -> PyFluidMesh {
        PyFluidMesh { inner: self.inner.mesh.clone() }
    }
    #[getter]
    fn fluid(&self) -> PyFluid {
        PyFluid { inner: self.inner.fluid }
    }
    /// Reference coordinates (flat, 12 per node).
    fn reference_coordinates<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.reference_coordinates())
    }
    /// Scalar mass matrix M_s (4N×4N) as CSC arrays (data, indices, indptr, shape).
    fn scalar_mass_csc<'py>(&self, py: Python<'py>) -> CscArrays<'py> {
        let m = self.inner.scalar_mass().as_ref();
        let n = m.nrows();
        let mut data = Vec::new();
        let mut idx = Vec::new();
        let mut ptr = vec![0i64];
        for j in 0..m.ncols() {
            for (i, v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
                idx.push(i as i64);
                data.push(*v);
            }
            ptr.push(idx.len() as i64);
        }
        (PyArray1::from_vec(py, data), PyArray1::from_vec(py, idx), PyArray1::from_vec(py, ptr), (n, n))
    }
    /// Generalized gravity force for gravity vector g (m/s²).
    fn gravity_force<'py>(&self, py: Python<'py>, g: [f64; 3]) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.gravity_force(g))
    }
    /// Internal (viscous + penalty) generalized forces f(e, ė).
    fn internal_forces<'py>(
        &self,
        py: Python<'py>,
        e: PyReadonlyArray1<'py, f64>,
        edot: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (e, v) = (vec_of(&e, "e")?, vec_of(&edot, "edot")?);
        let body = &self.inner;
        let out = compute(py, || {
            let mut f = vec![0.0; e.len().max(body.n_coords())];
            body.internal_forces(&e, &v, &mut f).map(|_| f)
        })?;
        Ok(PyArray1::from_vec(py, out))
    }
    /// Internal force and exact Jacobians of element `index`: (f[96], K[96,96], C[96,96]),
    /// compact ordering 3a + i.
    fn element_tangent<'py>(
        &self,
        py: Python<'py>,
        index: usize,
        e: PyReadonlyArray1<'py, f64>,
        edot: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        if index >= self.inner.elements.len() {
            return Err(PyValueError::new_err(format!(
                "invalid `index` = {index}: expected an integer in [0, {})",
                self.inner.elements.len()
            )));
        }
        let (e, v) = (vec_of(&e, "e")?, vec_of(&edot, "edot")?);
        let body = &self.inner;
        let (f, j) = compute(py, || {
            ancf_core::error::check_len("e", e.len(), body.n_coords())?;
            ancf_core::error::check_len("edot", v.len(), body.n_coords())?;
            body.element_tangent(index, &e, &v)
        })?;
        Ok((
            PyArray1::from_vec(py, f.to_vec()).into_any(),
            PyArray1::from_vec(py, j.stiffness).reshape([96, 96])?.into_any(),
            PyArray1::from_vec(py, j.damping).reshape([96, 96])?.into_any(),
        ))
    }
    /// Global indices of the 96 compact coordinates of element `index`.
    fn element_dofs(&self, index: usize) -> PyResult<Vec<usize>> {
        if index >= self.inner.elements.len() {
            return Err(PyValueError::new_err(format!("invalid `index` = {index}")));
        }
        Ok((0..96).map(|c| self.inner.global_index(index, c)).collect())
    }
    /// Current volume ∫ J dV₀.
    fn volume(&self, py: Python<'_>, e: PyReadonlyArray1<'_, f64>) -> PyResult<f64> {
        let e = vec_of(&e, "e")?;
        let body = &self.inner;
        compute(py, || {
            ancf_core::error::check_len("e", e.len(), body.n_coords())?;
            Ok(body.volume(&e))
        })
    }
    /// Centre of mass (m).
    fn center_of_mass(&self, e: PyReadonlyArray1<'_, f64>) -> PyResult<[f64; 3]> {
        let e = vec_of(&e, "e")?;
        ancf_core::error::check_len("e", e.len(), self.inner.n_coords()).map_err(to_py)?;
        Ok(self.inner.center_of_mass(&e))
    }
    /// Kinetic energy ½ ėᵀMė (J).
    fn kinetic_energy(&self, edot: PyReadonlyArray1<'_, f64>) -> PyResult<f64> {
        let v = vec_of(&edot, "edot")?;
        ancf_core::error::check_len("edot", v.len(), self.inner.n_coords()).map_err(to_py)?;
        Ok(self.inner.kinetic_energy(&v))
    }
}

/// Run fluid sloshing in a rigid tank with prescribed motion (see `railslosh.slosh.run`).
///
/// `scenario` is one dict (the stubs' `SloshArgs`): the tank `tank_shape` with its `tank_dims`
/// and `bulkheads`, the motion (`acceleration` per axis x, y, z, `rotation_axis`,
/// `angular_acceleration`), `t_end` and the largest step `step` (every step recorded), and the model settings; keys left
/// out take `rail_mbs::slosh::SloshScenario::new`'s defaults, and an unknown key is an error.
/// Returns a dict of numpy arrays (`t`, `force_tank`, `moment_tank`, `force_global`,
/// `moment_global`, `com_tank`, `volume`, `kinetic_energy`, `potential_energy`,
/// `newton_iterations`, `max_penetration`) plus `error` (None, or the message of the failure
/// that stopped the run; the arrays then hold everything computed before it) and `stats`.
#[pyfunction]
#[pyo3(signature = (mesh, fluid, scenario, *, progress=None, stream=None, checkpoint=None, checkpoint_every=100, resume_from=None))]
#[allow(clippy::too_many_arguments)]
fn run_slosh<'py>(
    py: Python<'py>,
    mesh: &PyFluidMesh,
    fluid: &PyFluid,
    scenario: &Bound<'py, PyDict>,
    progress: Option<Py<PyAny>>,
    stream: Option<std::path::PathBuf>,
    checkpoint: Option<std::path::PathBuf>,
    checkpoint_every: usize,
    resume_from: Option<std::path::PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    use ancf_core::contact::ContactPointRule;
    use ancf_core::tank::{Bulkhead, TankShape};
    use rail_mbs::slosh::{PiecewiseAcceleration, SloshFrame, SloshScenario, StepperChoice};
    let mut a = args::Args::new("scenario", scenario);
    let stepper: Option<String> = a.opt("stepper")?;
    let choice = StepperChoice::parse(stepper.as_deref().unwrap_or("implicit")).map_err(crate::to_py)?;
    let bad = |f: &str, v: String, a: &str| PyValueError::new_err(format!("invalid `{f}` = {v}: expected {a}"));
    let (tank_shape, tank_dims): (String, Vec<f64>) = (a.req("tank_shape")?, a.req("tank_dims")?);
    let shape = match (tank_shape.as_str(), tank_dims.as_slice()) {
        ("cylinder", &[length, radius, head_depth]) => TankShape::Cylinder { length, radius, head_depth },
        ("elliptic", &[length, semi_axis_y, semi_axis_z]) => {
            TankShape::EllipticCylinder { length, semi_axis_y, semi_axis_z }
        }
        ("box", &[x0, y0, z0, x1, y1, z1]) => TankShape::Box { min: [x0, y0, z0], max: [x1, y1, z1] },
        _ => {
            return Err(bad(
                "tank",
                format!("{tank_shape} {tank_dims:?}"),
                "cylinder [length, radius, head_depth], elliptic [length, semi_axis_y, semi_axis_z] or box [min xyz, max xyz]",
            ));
        }
    };
    let (t_end, h): (f64, f64) = (a.req("t_end")?, a.req("step")?);
    if !(t_end.is_finite() && t_end > 0.0) {
        return Err(bad("t_end", t_end.to_string(), "a finite number > 0"));
    }
    if !(h.is_finite() && h > 0.0 && h <= t_end) {
        return Err(bad("step", h.to_string(), "a finite number in (0, t_end]"));
    }
    let snapshot_every: f64 = a.opt("snapshot_every")?.unwrap_or(0.0);
    if !(snapshot_every.is_finite() && snapshot_every >= 0.0) {
        return Err(bad("snapshot_every", snapshot_every.to_string(), "a finite interval >= 0 s (0: no snapshots)"));
    }
    // The model, with the library's defaults for what the dict leaves (rail_mbs::slosh::scenario).
    let mut scenario = SloshScenario::new(mesh.inner.clone(), fluid.inner, shape);
    let bulkheads: Vec<(f64, f64)> = a.opt("bulkheads")?.unwrap_or_default();
    scenario.bulkheads = bulkheads.iter().map(|&(x, thickness)| Bulkhead { x, thickness }).collect();
    scenario.gravity = a.opt("gravity")?.unwrap_or(scenario.gravity);
    if let Some(frame) = a.opt::<String>("frame")? {
        scenario.frame = match frame.as_str() {
            "inertial" => SloshFrame::Inertial,
            "tank" => SloshFrame::Tank,
            other => return Err(bad("frame", format!("{other:?}"), "\"inertial\" or \"tank\"")),
        };
    }
    scenario.quadrature.viscous = a.opt("viscous_points")?.unwrap_or(scenario.quadrature.viscous);
    scenario.quadrature.penalty = a.opt("penalty_points")?.unwrap_or(scenario.quadrature.penalty);
    scenario.contact_points_per_edge = a.opt("contact_points_per_edge")?.unwrap_or(scenario.contact_points_per_edge);
    if let Some(rule) = a.opt::<String>("contact_point_rule")? {
        scenario.contact_point_rule = match rule.as_str() {
            "gauss" => ContactPointRule::Gauss,
            "lobatto" => ContactPointRule::Lobatto,
            other => return Err(bad("contact_point_rule", format!("{other:?}"), "\"gauss\" or \"lobatto\"")),
        };
    }
    scenario.contact_stiffness_factor = a.opt("contact_stiffness_factor")?.unwrap_or(scenario.contact_stiffness_factor);
    scenario.wall_damping_ratio = a.opt("wall_damping_ratio")?.unwrap_or(scenario.wall_damping_ratio);
    scenario.wall_adhesion = a.opt("wall_adhesion")?.unwrap_or(scenario.wall_adhesion);
    // Failure guards (issue 8): relative volume error and wall penetration per smallest element edge.
    scenario.volume_tolerance = a.opt("volume_tolerance")?.unwrap_or(scenario.volume_tolerance);
    scenario.penetration_limit = a.opt("penetration_limit")?.unwrap_or(scenario.penetration_limit);
    let acceleration: [Vec<(f64, f64)>; 3] = a.opt("acceleration")?.unwrap_or_default();
    let rotation_axis: Option<[f64; 3]> = a.opt("rotation_axis")?;
    let angular_acceleration: Vec<(f64, f64)> = a.opt("angular_acceleration")?.unwrap_or_default();
    a.finish()?;
    scenario.validate().map_err(to_py)?;
    let connectivity: Vec<i64> = scenario.mesh.elements.iter().flatten().map(|&n| n as i64).collect();
    let mut observer = PyProgress::new(progress);
    let obs = &mut observer;
    let result = compute(py, move || {
        let names = ["acceleration.x", "acceleration.y", "acceleration.z"];
        for d in 0..3 {
            if !acceleration[d].is_empty() {
                scenario.motion.translation[d] = PiecewiseAcceleration::new(names[d], &acceleration[d])?;
            }
        }
        if let Some(axis) = rotation_axis {
            scenario.motion.rotation =
                Some((axis, PiecewiseAcceleration::new("angular_acceleration", &angular_acceleration)?));
        }
        // Issue 8: `resume_from` continues a run from its last checkpoint, bitwise as if never stopped.
        let (mut run, reason) = scenario.start(choice, h, resume_from.as_deref())?;
        run.set_snapshot_every(snapshot_every).map_err(|e| AncfError::NonFinite { what: e.to_string(), element: 0 })?;
        if let Some(path) = &checkpoint {
            if checkpoint_every == 0 {
                return Err(ancf_core::error::invalid("checkpoint_every", 0, ">= 1 (steps)"));
            }
            run.checkpoints = Some(rail_mbs::integrator::CheckpointFile::new(path, checkpoint_every).map_err(|e| {
                ancf_core::error::invalid("checkpoint", path.display(), &format!("a writable file ({e})"))
            })?);
        }
        let result = match &stream {
            // Every sample appended and flushed as it is computed (issue 8: nothing computed is lost).
            Some(path) => {
                let columns = rail_mbs::slosh::SloshRecord::COLUMNS;
                let mut journal = rail_mbs::integrator::Journal::create(path, &columns, 1).map_err(|e| {
                    ancf_core::error::invalid("stream", path.display(), &format!("a writable file ({e})"))
                })?;
                run.run_to_journaled(t_end, h, &mut |p| obs.observe(p), &mut journal)
            }
            None => run.run_to_observed(t_end, h, &mut |p| obs.observe(p)),
        };
        let err = result.err().map(|e| e.error.to_string());
        let s = *run.stats();
        let margins = run.margins();
        let used = run.stepper.name();
        Ok((run.record, err, s, margins, used, reason, run.snapshots))
    })?;
    observer.finish()?;
    let (rec, err, stats, margins, used, reason, snapshots) = result;
    let d = slosh_record_dict(py, rec)?;
    d.set_item("margins", margins_dict(py, &margins)?)?;
    // the vehicle runs' snapshot layout, with one "car": (t, [nodes × 4 × 3]), tank frame
    let snaps = pyo3::types::PyList::empty(py);
    for (t, e) in snapshots {
        let n = e.len() / 12;
        snaps.append((t, vec![PyArray1::from_vec(py, e).reshape([n, 4, 3])?]))?;
    }
    d.set_item("snapshots", snaps)?;
    let ne = connectivity.len() / 8;
    d.set_item("connectivity", PyArray1::from_vec(py, connectivity).reshape([ne, 8])?)?;
    d.set_item("stepper", used)?;
    d.set_item("stepper_reason", reason)?;
    d.set_item("error", err)?;
    d.set_item("stats", stats_dict(py, &stats)?)?;
    Ok(d)
}

/// The time series of a slosh run's record as numpy arrays (vectors as n × 3).
fn slosh_record_dict<'py>(py: Python<'py>, rec: rail_mbs::slosh::SloshRecord) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let v3 = |x: &Vec<[f64; 3]>| -> PyResult<Bound<'py, PyAny>> {
        let n = x.len();
        Ok(PyArray1::from_vec(py, x.iter().flatten().copied().collect()).reshape([n, 3])?.into_any())
    };
    d.set_item("t", PyArray1::from_vec(py, rec.t))?;
    d.set_item("force_tank", v3(&rec.force_tank)?)?;
    d.set_item("moment_tank", v3(&rec.moment_tank)?)?;
    d.set_item("force_global", v3(&rec.force_global)?)?;
    d.set_item("moment_global", v3(&rec.moment_global)?)?;
    d.set_item("com_tank", v3(&rec.com_tank)?)?;
    d.set_item("volume", PyArray1::from_vec(py, rec.volume))?;
    d.set_item("kinetic_energy", PyArray1::from_vec(py, rec.kinetic_energy))?;
    d.set_item("potential_energy", PyArray1::from_vec(py, rec.potential_energy))?;
    d.set_item("newton_iterations", PyArray1::from_vec(py, rec.newton_iterations.iter().map(|&x| x as i64).collect()))?;
    d.set_item("max_penetration", PyArray1::from_vec(py, rec.max_penetration))?;
    d.set_item("stored_energy", PyArray1::from_vec(py, rec.stored_energy))?;
    d.set_item("input_work", PyArray1::from_vec(py, rec.input_work))?;
    d.set_item("energy_error", PyArray1::from_vec(py, rec.energy_error))?;
    d.set_item("min_volume_ratio", PyArray1::from_vec(py, rec.min_volume_ratio))?;
    d.set_item("containment_gap", PyArray1::from_vec(py, rec.containment_gap))?;
    Ok(d)
}

/// An integrator's statistics (`rail_mbs::integrator::Stats`) as a dict, times in s.
pub(crate) fn stats_dict<'py>(py: Python<'py>, s: &rail_mbs::integrator::Stats) -> PyResult<Bound<'py, PyDict>> {
    let st = PyDict::new(py);
    st.set_item("steps", s.steps)?;
    st.set_item("rejected_steps", s.rejected_steps)?;
    st.set_item("newton_iterations", s.newton_iterations)?;
    st.set_item("factorizations", s.factorizations)?;
    st.set_item("jacobian_evaluations", s.jacobian_evaluations)?;
    st.set_item("time_assembly", s.time_assembly.as_secs_f64())?;
    st.set_item("time_factorization", s.time_factorization.as_secs_f64())?;
    st.set_item("time_solve", s.time_solve.as_secs_f64())?;
    st.set_item("time_total", s.time_total.as_secs_f64())?;
    Ok(st)
}

/// The worst invariant margins of a run (`rail_mbs::invariants::Margins`) as a dict
/// (`worst_energy_error` None where no energy account is kept).
pub(crate) fn margins_dict<'py>(py: Python<'py>, m: &rail_mbs::invariants::Margins) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("worst_gap", m.worst_gap)?;
    d.set_item("worst_gap_time", m.worst_gap_time)?;
    d.set_item("gap_limit", m.gap_limit)?;
    // not measured (vehicle runs keep no energy account): None
    d.set_item("worst_energy_error", m.worst_energy_error.is_finite().then_some(m.worst_energy_error))?;
    d.set_item("worst_energy_time", m.worst_energy_time)?;
    d.set_item("min_volume_ratio", m.min_volume_ratio)?;
    d.set_item("min_volume_ratio_time", m.min_volume_ratio_time)?;
    d.set_item("dissipated", m.dissipated)?;
    Ok(d)
}

/// Names of the validation cases implemented in Rust.
#[pyfunction]
fn validation_cases() -> Vec<&'static str> {
    railslosh_cases::element::CASES
        .iter()
        .chain(railslosh_cases::slosh::CASES.iter())
        .chain(railslosh_cases::contact::CASES.iter())
        .chain(railslosh_cases::vehicle::CASES.iter())
        .chain(railslosh_cases::vehicle::studies::CASES.iter())
        .copied()
        .collect()
}

/// Run one validation case; returns a list of dict records.
#[pyfunction]
#[pyo3(signature = (name, quick=false))]
fn run_validation<'py>(py: Python<'py>, name: String, quick: bool) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let recs = if railslosh_cases::contact::CASES.contains(&name.as_str()) {
        // Missing external data raise `DataNotFoundError` (reported as skipped).
        rail::run_contact_validation(py, name, quick)?
    } else {
        compute(py, move || {
            if railslosh_cases::slosh::CASES.contains(&name.as_str()) {
                railslosh_cases::slosh::run_case(&name, quick)
            } else if railslosh_cases::vehicle::CASES.contains(&name.as_str()) {
                railslosh_cases::vehicle::run_case(&name, quick)
            } else if railslosh_cases::vehicle::studies::CASES.contains(&name.as_str()) {
                railslosh_cases::vehicle::studies::run_case(&name, quick)
            } else {
                railslosh_cases::element::run_case(&name, quick)
            }
        })?
    };
    recs.into_iter()
        .map(|r| {
            let d = PyDict::new(py);
            d.set_item("case", r.case)?;
            d.set_item("quantity", r.quantity)?;
            d.set_item("measured", r.measured)?;
            d.set_item("reference", r.reference)?;
            d.set_item("tolerance", r.tolerance)?;
            d.set_item("passed", r.passed)?;
            Ok(d)
        })
        .collect()
}

/// Test hook: proves that a Rust panic surfaces as `RailsloshError`, never as a panic.
#[pyfunction]
fn _panic_for_test(py: Python<'_>) -> PyResult<()> {
    compute(py, || -> Result<(), AncfError> { panic!("deliberate test panic") })
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("RailsloshError", m.py().get_type::<RailsloshError>())?;
    m.add("WALL_DAMPING_RATIO", ancf_core::contact::WALL_DAMPING_RATIO)?;
    m.add("GRAVITY", ancf_core::constants::GRAVITY)?;
    m.add("TANK_HEAD_DEPTH", rail_mbs::vehicle::TANK_HEAD_DEPTH)?;
    m.add("TANK_CAR_LENGTH", ancf_core::mesh::TANK_CAR_LENGTH)?;
    m.add("TANK_CAR_RADIUS", ancf_core::mesh::TANK_CAR_RADIUS)?;
    m.add("FOOT", ancf_core::constants::FOOT)?;
    m.add("INCH", ancf_core::constants::INCH)?;
    m.add("MPH", ancf_core::constants::MPH)?;
    m.add("ARC_DEGREE_RADIUS_FT", rail_mbs::track::ARC_DEGREE_RADIUS_FT)?;
    m.add_class::<PyFluidMesh>()?;
    m.add_class::<PyFluid>()?;
    m.add_class::<PyFluidBody>()?;
    m.add_function(wrap_pyfunction!(crude_oils, m)?)?;
    m.add_function(wrap_pyfunction!(default_bulk_penalty, m)?)?;
    m.add_function(wrap_pyfunction!(default_bulk_damping, m)?)?;
    m.add_function(wrap_pyfunction!(default_shear_stabilization, m)?)?;
    m.add_function(wrap_pyfunction!(box_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(cylinder_tank, m)?)?;
    m.add_function(wrap_pyfunction!(elliptic_cylinder, m)?)?;
    m.add_function(wrap_pyfunction!(validation_cases, m)?)?;
    m.add_function(wrap_pyfunction!(run_slosh, m)?)?;
    m.add_function(wrap_pyfunction!(run_validation, m)?)?;
    m.add_function(wrap_pyfunction!(bench::work_precision_cases, m)?)?;
    m.add_function(wrap_pyfunction!(bench::run_work_precision, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_for_test, m)?)?;
    rail::register(m)?;
    vehicle::register(m)?;
    irregularity::register(m)?;
    cosim::register(m)?;
    maneuvers::register(m)?;
    Ok(())
}
