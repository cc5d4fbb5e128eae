//! Bindings of the vehicle model: tank-car parameters (defaults with sources) and
//! train runs with wheel loads, derailment indicators and coupler forces as arrays.

use std::sync::Arc;

use ancf_core::error::{AncfError, invalid};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rail_mbs::defaults::{Oil, brake_torque};
use rail_mbs::mbs::{SpeedProfile, Table};
use rail_mbs::profile::aar1b_wheel_approx;
use rail_mbs::track::{Track, TrackPoint};
use rail_mbs::vehicle::{
    BrakeScope, Cargo, EquivalentCargo, EquivalentModel, EquivalentTrainRecord, FluidCargo, FluidTrainRecord,
    LoadFilter, RigidCargo, SampleSink, SloshAxis, TankCarParams, TrainRecord, TrainScenario, TruckModel, run_vehicle,
};

use crate::args::Args;
use crate::{PyProgress, compute};

/// Scalar fields of [`TankCarParams`] a user can override, with getters and setters.
type Field = (&'static str, fn(&TankCarParams) -> f64, fn(&mut TankCarParams, f64));

const FIELDS: &[Field] = &[
    ("tank_length", |p| p.tank_length, |p, v| p.tank_length = v),
    ("tank_radius", |p| p.tank_radius, |p, v| p.tank_radius = v),
    ("tank_axis_height", |p| p.tank_axis_height, |p, v| p.tank_axis_height = v),
    ("tank_mass", |p| p.tank.mass, |p, v| p.tank.mass = v),
    ("lading_length", |p| p.lading_length, |p, v| p.lading_length = v),
    ("stub_sill_mass", |p| p.stub_sill.mass, |p, v| p.stub_sill.mass = v),
    ("truck_centers", |p| p.truck_centers, |p, v| p.truck_centers = v),
    ("wheelbase", |p| p.wheelbase, |p, v| p.wheelbase = v),
    ("wheel_radius", |p| p.wheel_radius, |p, v| p.wheel_radius = v),
    ("wheelset_mass", |p| p.wheelset.mass, |p, v| p.wheelset.mass = v),
    ("bolster_mass", |p| p.bolster.mass, |p, v| p.bolster.mass = v),
    ("frame_mass", |p| p.frame.mass, |p, v| p.frame.mass = v),
    ("equalizer_mass", |p| p.equalizer.mass, |p, v| p.equalizer.mass = v),
    ("journal_half_span", |p| p.journal_half_span, |p, v| p.journal_half_span = v),
    ("secondary_half_span", |p| p.secondary_half_span, |p, v| p.secondary_half_span = v),
    ("primary_kx", |p| p.primary.stiffness[0], |p, v| p.primary.stiffness[0] = v),
    ("primary_ky", |p| p.primary.stiffness[1], |p, v| p.primary.stiffness[1] = v),
    ("primary_kz", |p| p.primary.stiffness[2], |p, v| p.primary.stiffness[2] = v),
    ("primary_cx", |p| p.primary.damping[0], |p, v| p.primary.damping[0] = v),
    ("primary_cy", |p| p.primary.damping[1], |p, v| p.primary.damping[1] = v),
    ("primary_cz", |p| p.primary.damping[2], |p, v| p.primary.damping[2] = v),
    ("secondary_kx", |p| p.secondary.stiffness[0], |p, v| p.secondary.stiffness[0] = v),
    ("secondary_ky", |p| p.secondary.stiffness[1], |p, v| p.secondary.stiffness[1] = v),
    ("secondary_kz", |p| p.secondary.stiffness[2], |p, v| p.secondary.stiffness[2] = v),
    ("secondary_cx", |p| p.secondary.damping[0], |p, v| p.secondary.damping[0] = v),
    ("secondary_cy", |p| p.secondary.damping[1], |p, v| p.secondary.damping[1] = v),
    ("secondary_cz", |p| p.secondary.damping[2], |p, v| p.secondary.damping[2] = v),
    ("journal_k", |p| p.journal.stiffness[0], |p, v| p.journal.stiffness = [v; 3]),
    ("journal_c", |p| p.journal.damping[0], |p, v| p.journal.damping = [v; 3]),
    ("journal_tilt_stiffness", |p| p.journal_tilt_stiffness, |p, v| p.journal_tilt_stiffness = v),
    ("coupler_height", |p| p.coupler_height, |p, v| p.coupler_height = v),
    ("coupler_reach", |p| p.coupler_reach, |p, v| p.coupler_reach = v),
    ("friction", |p| p.contact.friction, |p, v| p.contact.friction = v),
    ("contact_damping", |p| p.contact.damping, |p, v| p.contact.damping = v),
];

fn car_params(overrides: Option<&Bound<'_, PyDict>>, wheel_profile: &str) -> PyResult<TankCarParams> {
    let mut p = TankCarParams::standard().map_err(crate::to_py)?;
    match wheel_profile {
        "s1002" => {}
        "aar1b" => {
            p.contact.wheel_profile =
                aar1b_wheel_approx().map_err(|e| crate::to_py(invalid("wheel_profile", e, "a valid profile")))?
        }
        other => return Err(crate::to_py(invalid("wheel_profile", other, "'s1002' or 'aar1b'"))),
    }
    if let Some(d) = overrides {
        for (k, v) in d.iter() {
            let key: String = k.extract()?;
            if key == "truck" {
                let bad = || crate::to_py(invalid("car.truck", &v, "'rigid_frame' or 'three_piece'"));
                let name: String = v.extract().map_err(|_| bad())?;
                p.truck = TruckModel::from_name(&name).map_err(|_| bad())?;
                continue;
            }
            let Some(f) = FIELDS.iter().find(|f| f.0 == key) else {
                let names: Vec<&str> = FIELDS.iter().map(|f| f.0).chain(["truck"]).collect();
                return Err(crate::to_py(invalid("car", &key, &format!("one of {names:?}"))));
            };
            let x: f64 = v.extract().map_err(|_| crate::to_py(invalid(&format!("car.{key}"), v, "a number")))?;
            (f.2)(&mut p, x);
        }
    }
    p.validate().map_err(crate::to_py)?;
    Ok(p)
}

/// The wheel/rail friction map of a run (`friction_map=` of the run functions) on the car's
/// rail profile: `None`, or a dict with either `profile` = `[(v, mu), ...]` (μ over the rail
/// profile's lateral coordinate, m) or `preset = "lubricated_gauge_face"` with `mu_top`,
/// `mu_gauge`, `depth` (m below the rail top), `width` (m) (`FrictionMap::lubricated_gauge_face`),
/// and optionally `along_track` = `[(s, factor), ...]` (a factor on μ over the distance s, m).
fn friction_map_of(
    spec: Option<&Bound<'_, PyDict>>,
    rail: &rail_mbs::profile::Profile,
) -> PyResult<Option<Arc<rail_mbs::wheel_rail::FrictionMap>>> {
    use rail_mbs::wheel_rail::FrictionMap;
    let Some(d) = spec else { return Ok(None) };
    let err = |e: rail_mbs::wheel_rail::ContactError| crate::to_py(invalid("friction_map", e, "a valid friction map"));
    const KEYS: [&str; 7] = ["preset", "profile", "mu_top", "mu_gauge", "depth", "width", "along_track"];
    for k in d.keys() {
        let k: String = k.extract()?;
        if !KEYS.contains(&k.as_str()) {
            return Err(crate::to_py(invalid("friction_map", &k, &format!("keys among {KEYS:?}"))));
        }
    }
    let num = |k: &str, default: f64| -> PyResult<f64> {
        match d.get_item(k)? {
            None => Ok(default),
            Some(v) => v.extract().map_err(|_| crate::to_py(invalid(&format!("friction_map.{k}"), v, "a number"))),
        }
    };
    let table = |k: &str| -> PyResult<Option<Vec<(f64, f64)>>> {
        match d.get_item(k)? {
            None => Ok(None),
            Some(v) => v.extract().map(Some).map_err(|_| {
                crate::to_py(invalid(&format!("friction_map.{k}"), v, "a list of (position, value) pairs"))
            }),
        }
    };
    let preset: Option<String> = d.get_item("preset")?.map(|v| v.extract()).transpose()?;
    let mut map = match (preset.as_deref(), table("profile")?) {
        (Some("lubricated_gauge_face"), None) => {
            let g = rail_mbs::wheel_rail::GaugeFaceLubrication::DEFAULT;
            FrictionMap::lubricated_gauge_face(
                rail,
                num("mu_top", g.mu_top)?,
                num("mu_gauge", g.mu_gauge)?,
                num("depth", g.depth)?,
                num("width", g.width)?,
            )
            .map_err(err)?
        }
        (None, Some(profile)) => FrictionMap { profile, along_track: Vec::new() },
        (Some(p), None) => return Err(crate::to_py(invalid("friction_map.preset", p, "'lubricated_gauge_face'"))),
        _ => {
            return Err(crate::to_py(invalid(
                "friction_map",
                "{...}",
                "either preset = 'lubricated_gauge_face' or a profile table, one of them",
            )));
        }
    };
    if let Some(t) = table("along_track")? {
        map.along_track = t;
    }
    map.validate().map_err(err)?;
    Ok(Some(Arc::new(map)))
}

/// Arc length (m) of every wheelset at t = 0, front to rear over `cars` cars whose front tank
/// centre is at `station`: read off the train `rail_mbs::vehicle::build_train` builds (on a
/// straight track from the origin, where s is the global x), so it is that builder's placement.
#[pyfunction]
#[pyo3(signature = (cars=1, station=50.0, car=None))]
pub fn wheelset_stations(
    py: Python<'_>,
    cars: usize,
    station: f64,
    car: Option<&Bound<'_, PyDict>>,
) -> PyResult<Vec<f64>> {
    let params = car_params(car, "s1002")?;
    let length = station.abs() + 100.0 * cars as f64 + 100.0;
    let track =
        Arc::new(Track::straight(length).map_err(|e| crate::to_py(invalid("station", station, &e.to_string())))?);
    let mut sc = TrainScenario::single(params, track, station, 0.0, 1.0);
    sc.cars = cars;
    compute(py, move || {
        let (mb, bodies, _) = rail_mbs::vehicle::build_train(&sc)?;
        Ok(bodies.iter().flat_map(|c| c.wheelsets.iter().map(|w| mb.bodies()[w.0].position.x)).collect())
    })
}

/// Default tank-car parameters (the overridable scalar fields), the DOF count and the
/// total mass; `car` overrides fields as in `run_train`.
#[pyfunction]
#[pyo3(signature = (car=None, wheel_profile="s1002"))]
pub fn tank_car_parameters<'py>(
    py: Python<'py>,
    car: Option<&Bound<'py, PyDict>>,
    wheel_profile: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let p = car_params(car, wheel_profile)?;
    let d = PyDict::new(py);
    for f in FIELDS {
        d.set_item(f.0, (f.1)(&p))?;
    }
    d.set_item("total_mass", p.total_mass())?;
    let track = Arc::new(
        Track::new(vec![
            TrackPoint::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
            TrackPoint::new(100.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        ])
        .map_err(|e| crate::to_py(invalid("track", e, "valid")))?,
    );
    let sc = TrainScenario::single(p, track, 50.0, 0.0, 1.0);
    let dof = compute(py, move || rail_mbs::vehicle::build_train(&sc).map(|(mb, _, _)| mb.dof()))?;
    d.set_item("dof", dof)?;
    Ok(d)
}

/// The track of a segment table, with the rails displaced by `irregularity` (a samples dict
/// of `railslosh._core.track_irregularity`) when given.
fn track_of(rows: Vec<Vec<f64>>, irregularity: Option<&Bound<'_, PyDict>>) -> PyResult<Arc<Track>> {
    let track = track_from_table(rows).map_err(crate::to_py)?;
    Ok(Arc::new(match irregularity {
        Some(d) => track.with_irregularity(crate::irregularity::from_dict(d)?),
        None => track,
    }))
}

fn track_from_table(rows: Vec<Vec<f64>>) -> Result<Track, AncfError> {
    let mut pts = Vec::with_capacity(rows.len());
    for (i, r) in rows.iter().enumerate() {
        if r.len() != 6 {
            return Err(invalid(
                &format!("track row {i}"),
                format!("{r:?}"),
                "6 numbers: s, curvature, superelevation, grade, cant_right, cant_left",
            ));
        }
        pts.push(TrackPoint::new(r[0], r[1], r[2], r[3], r[4], r[5]));
    }
    Track::new(pts).map_err(|e| invalid("track", e, "a valid segment table"))
}

fn arr<'py>(py: Python<'py>, v: Vec<f64>, shape: &[usize]) -> PyResult<Bound<'py, PyAny>> {
    Ok(PyArray1::from_vec(py, v).reshape(shape.to_vec())?.into_any())
}

fn record_dict<'py>(py: Python<'py>, r: &TrainRecord) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let nt = r.t.len();
    let nw = r.wheel_vertical.first().map_or(0, |x| x.len());
    let flat3 = |a: &Vec<Vec<[f64; 2]>>| a.iter().flat_map(|s| s.iter().flat_map(|w| w.iter().copied())).collect();
    let flat2 = |a: &Vec<Vec<f64>>| a.iter().flat_map(|s| s.iter().copied()).collect::<Vec<f64>>();
    d.set_item("t", PyArray1::from_vec(py, r.t.clone()))?;
    d.set_item("wheel_vertical", arr(py, flat3(&r.wheel_vertical), &[nt, nw, 2])?)?;
    d.set_item("wheel_lateral", arr(py, flat3(&r.wheel_lateral), &[nt, nw, 2])?)?;
    d.set_item("l_over_v", arr(py, flat3(&r.l_over_v()), &[nt, nw, 2])?)?;
    d.set_item("unloading", arr(py, flat3(&r.unloading()), &[nt, nw, 2])?)?;
    d.set_item("wheelset_lateral", arr(py, flat2(&r.wheelset_lateral), &[nt, nw])?)?;
    let nc = r.coupler_force.first().map_or(0, |x| x.len());
    d.set_item("coupler_force", arr(py, flat2(&r.coupler_force), &[nt, nc])?)?;
    let ncar = r.tank_station.first().map_or(0, |x| x.len());
    d.set_item("tank_station", arr(py, flat2(&r.tank_station), &[nt, ncar])?)?;
    d.set_item("tank_speed", arr(py, flat2(&r.tank_speed), &[nt, ncar])?)?;
    let acc: Vec<f64> = r.car_acceleration.iter().flat_map(|s| s.iter().flat_map(|c| c.iter().copied())).collect();
    d.set_item("car_acceleration", arr(py, acc, &[nt, ncar, 3])?)?;
    d.set_item("static_wheel_load", r.static_wheel_load)?;
    d.set_item("dof", r.dof)?;
    let s = PyDict::new(py);
    s.set_item("steps", r.steps)?;
    s.set_item("rejected_steps", r.rejected_steps)?;
    s.set_item("newton_iterations", r.newton_iterations)?;
    s.set_item("jacobian_evaluations", r.jacobian_evaluations)?;
    s.set_item("wall_time", r.wall_time)?;
    d.set_item("stats", s)?;
    Ok(d)
}

/// Brake table and scope from the Python arguments.
fn brake_scope_of(scope: &str) -> PyResult<BrakeScope> {
    match scope {
        "all" => Ok(BrakeScope::AllCars),
        "front" => Ok(BrakeScope::FrontCar),
        other => Err(crate::to_py(invalid("brake_scope", other, "'all' or 'front'"))),
    }
}

fn brake_of(times: Option<Vec<f64>>, torques: Option<Vec<f64>>, scope: &str) -> PyResult<Option<(Table, BrakeScope)>> {
    let scope = brake_scope_of(scope)?;
    match (times, torques) {
        (Some(t), Some(m)) => Ok(Some((Table::new("brake_times/brake_torques", t, m).map_err(crate::to_py)?, scope))),
        (None, None) => Ok(None),
        _ => Err(crate::to_py(invalid("brake_times/brake_torques", "one missing", "both or neither"))),
    }
}

/// The scenario of a vehicle run from its `train` dict, the one form the three run functions
/// take (the stubs' `railslosh._core.TrainArgs`, built by `railslosh.vehicle`'s one
/// `_train_args`): the car with its overrides, wheel profile, friction map and rigid lading,
/// the track (rows `(s, curvature, superelevation, grade, cant_right, cant_left)`, SI) with its
/// irregularity, and the run settings. Keys left out take [`TrainScenario::single`]'s defaults.
fn train_scenario(d: &Bound<'_, PyDict>) -> PyResult<TrainScenario> {
    let mut a = Args::new("train", d);
    let car: Option<Bound<'_, PyDict>> = a.opt("car")?;
    let wheel_profile: Option<String> = a.opt("wheel_profile")?;
    let mut params = car_params(car.as_ref(), wheel_profile.as_deref().unwrap_or("s1002"))?;
    let friction_map: Option<Bound<'_, PyDict>> = a.opt("friction_map")?;
    params.contact.friction_map = friction_map_of(friction_map.as_ref(), &params.contact.rail_profile)?;
    let lading_mass = a.opt("lading_mass")?.unwrap_or(0.0);
    let lading_height = a.opt("lading_height")?.unwrap_or(0.0);
    if lading_mass != 0.0 {
        params.lading = Some((lading_mass, lading_height));
    }
    let scope: Option<String> = a.opt("brake_scope")?;
    let brake = brake_of(a.opt("brake_times")?, a.opt("brake_torques")?, scope.as_deref().unwrap_or("all"))?;
    let irregularity: Option<Bound<'_, PyDict>> = a.opt("irregularity")?;
    let track = track_of(a.req("track")?, irregularity.as_ref())?;
    let mut sc = TrainScenario::single(params, track, a.req("station")?, a.req("speed")?, a.req("t_end")?);
    sc.cars = a.opt("cars")?.unwrap_or(sc.cars);
    sc.step = a.opt("step")?.unwrap_or(sc.step);
    sc.record_every = a.opt("record_every")?.unwrap_or(sc.record_every);
    if let Some(f) = a.opt::<String>("load_filter")? {
        sc.load_filter = LoadFilter::parse(&f).map_err(crate::to_py)?;
    }
    sc.snapshot_every = a.opt("snapshot_every")?.unwrap_or(sc.snapshot_every);
    sc.drive = a.opt("drive_speed")?.map(SpeedProfile::Constant);
    sc.brake = brake;
    sc.brake_factors = a.opt("brake_factors")?.unwrap_or_default();
    sc.wheelset_lateral_offset = a.opt("wheelset_lateral_offset")?.unwrap_or(sc.wheelset_lateral_offset);
    sc.coupler = (a.opt("coupler_stiffness")?, a.opt("coupler_damping")?);
    let every: Option<usize> = a.opt("checkpoint_every")?;
    if let Some(path) = a.opt::<std::path::PathBuf>("checkpoint")? {
        let every = every.unwrap_or(50);
        if every == 0 {
            return Err(crate::to_py(invalid("checkpoint_every", every, "an integer >= 1 (recorded samples)")));
        }
        sc.checkpoints = Some(rail_mbs::vehicle::RunCheckpoints { path, every });
    }
    sc.resume_from = a.opt("resume_from")?;
    a.finish()?;
    Ok(sc)
}

/// Runs `sc` carrying `cargo` with the GIL released ([`rail_mbs::vehicle::run_vehicle`]):
/// `progress` called as it goes and, when `stream` names a file, every recorded sample appended
/// to it (layout [`Cargo::columns`]). Returns the record as a dict (`to_dict`), with an `error`
/// entry when the run stopped early.
fn run_cargo<'py, C: Cargo + Send + Sync>(
    py: Python<'py>,
    sc: TrainScenario,
    cargo: C,
    (progress, stream): (Option<Py<PyAny>>, Option<std::path::PathBuf>),
    to_dict: impl Fn(Python<'py>, &C::Record) -> PyResult<Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>>
where
    C::Record: Send,
{
    let mut observer = PyProgress::new(progress);
    let obs = &mut observer;
    let (record, error) = compute(py, move || {
        let mut journal = match stream.as_deref() {
            Some(path) => Some(open_stream(path, &cargo.columns(&sc)?)?),
            None => None,
        };
        let mut append = |row: &[f64]| journal.as_mut().map_or(Ok(()), |j| j.append(row));
        let sink: Option<SampleSink<'_>> = if stream.is_some() { Some(&mut append) } else { None };
        Ok(match run_vehicle(&sc, &cargo, &mut |p| obs.observe(p), sink)? {
            Ok(r) => (r, None),
            Err(f) => (f.record, Some(f.error.to_string())),
        })
    })?;
    observer.finish()?;
    let d = to_dict(py, &record)?;
    if let Some(e) = error {
        d.set_item("error", e)?;
    }
    Ok(d)
}

/// Runs a train of rigid-lading tank cars (`train`: a `TrainArgs` dict; `lading_mass`,
/// `lading_height` in it give the rigid lading). Returns a dict of arrays; on a failed run the
/// dict has an `error` entry and the results so far.
#[pyfunction]
#[pyo3(signature = (train, *, progress=None, stream=None))]
pub fn run_train<'py>(
    py: Python<'py>,
    train: &Bound<'py, PyDict>,
    progress: Option<Py<PyAny>>,
    stream: Option<std::path::PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let sc = train_scenario(train)?;
    run_cargo(py, sc, RigidCargo, (progress, stream), |py, r| record_dict(py, r))
}

/// The results stream of a run (`stream=` path): every recorded sample is appended and
/// flushed as it is computed, so an interrupted run keeps it (issue 8).
fn open_stream(
    path: &std::path::Path,
    columns: &[String],
) -> Result<rail_mbs::integrator::Journal, ancf_core::error::AncfError> {
    let names: Vec<&str> = columns.iter().map(String::as_str).collect();
    rail_mbs::integrator::Journal::create(path, &names, 1)
        .map_err(|e| invalid("stream", path.display(), &format!("a writable file ({e})")))
}

fn oil_of(name: &str) -> PyResult<Oil> {
    Oil::from_name(name).map_err(crate::to_py)
}

/// The largest time step of an ANCF braking run with brake scope `brake_scope` (`"all"`: ECP,
/// `"front"`: conventional) and liquid `oil`, s (`rail_mbs::defaults::braking_step`: 2 ms for ECP
/// with light crude or water, 1 ms with medium or heavy crude, 4 ms for conventional braking;
/// the step at which each run's coupler force is converged, docs/validation.md).
#[pyfunction]
pub fn braking_step(brake_scope: &str, oil: &str) -> PyResult<f64> {
    Ok(rail_mbs::defaults::braking_step(brake_scope_of(brake_scope)?, oil_of(oil)?))
}

fn fluid_record_dict<'py>(py: Python<'py>, r: &FluidTrainRecord) -> PyResult<Bound<'py, PyDict>> {
    let d = record_dict(py, &r.train)?;
    let nt = r.oil_com_tank.len();
    let nc = r.oil_com_tank.first().map_or(0, |x| x.len());
    let flat = |a: &Vec<Vec<[f64; 3]>>| a.iter().flat_map(|s| s.iter().flat_map(|c| c.iter().copied())).collect();
    d.set_item("oil_com_tank", arr(py, flat(&r.oil_com_tank), &[nt, nc, 3])?)?;
    d.set_item("oil_com_global", arr(py, flat(&r.oil_com_global), &[nt, nc, 3])?)?;
    d.set_item("fluid_force_tank", arr(py, flat(&r.fluid_force_tank), &[nt, nc, 3])?)?;
    let per_car = |a: &Vec<Vec<f64>>| -> Vec<f64> { a.iter().flat_map(|s| s.iter().copied()).collect() };
    d.set_item("volume_error", arr(py, per_car(&r.volume_error), &[nt, nc])?)?;
    d.set_item("containment_gap", arr(py, per_car(&r.containment_gap), &[nt, nc])?)?;
    d.set_item("min_volume_ratio", arr(py, per_car(&r.min_volume_ratio), &[nt, nc])?)?;
    d.set_item("energy_error", arr(py, per_car(&r.energy_error), &[nt, nc])?)?;
    let snaps = pyo3::types::PyList::empty(py);
    for (t, cars) in &r.snapshots {
        let arrays: Vec<Bound<'py, PyAny>> =
            cars.iter().map(|e| arr(py, e.clone(), &[e.len() / 12, 4, 3])).collect::<PyResult<_>>()?;
        snaps.append((*t, arrays))?;
    }
    d.set_item("snapshots", snaps)?;
    d.set_item("fluid_mass", r.fluid_mass)?;
    d.set_item("margins", crate::margins_dict(py, &r.margins)?)?;
    d.set_item("elements", r.elements)?;
    let conn: Vec<i64> = r.connectivity.iter().flatten().map(|&n| n as i64).collect();
    let ne = r.connectivity.len();
    d.set_item("connectivity", PyArray1::from_vec(py, conn).reshape([ne, 8])?)?;
    Ok(d)
}

/// Brake torque table `(times, torques)` per wheelset that slows a car of total mass
/// `mass` (kg) from `v0` to `v1` (m/s) in `duration` s (seed 000 §8.2 design, see
/// `rail_mbs::defaults::brake_torque`).
#[pyfunction]
#[pyo3(signature = (mass, v0=40.0 / 3.6, v1=5.0 / 3.6, duration=10.0))]
pub fn design_brake_torque(mass: f64, v0: f64, v1: f64, duration: f64) -> PyResult<(Vec<f64>, Vec<f64>)> {
    let p = TankCarParams::standard().map_err(crate::to_py)?;
    ancf_core::error::check_positive("mass", mass).map_err(crate::to_py)?;
    ancf_core::error::check_positive("duration", duration).map_err(crate::to_py)?;
    let t = brake_torque(&p, mass, v0, v1, duration).map_err(crate::to_py)?;
    Ok((t.x, t.y))
}

/// The ANCF cargo of a fluid run from its `cargo` dict (the stubs'
/// `railslosh._core.FluidCargoArgs`) on the car `car`: `oil` names a liquid of seed 000 Table 2
/// (or water) unless `fluid` (a `railslosh.Fluid`) is given; `counts` elements along the length,
/// width and height; `fill` the volume fraction (required); `bulkheads` `[(x, thickness)]`;
/// `wall_damping_ratio` the damping ratio of the liquid column on the penalty wall
/// (`WallContactLaw::with_damping_ratio`); `wall_adhesion` the suction an adhesive wall holds, in
/// units of ρ g H (`WallContactLaw::with_adhesion`); `shear_stabilization` gives a fluid without
/// its own the recommended one (`FluidCargo::shear_stabilization`). Keys left out take
/// `FluidCargo::new`'s defaults (light crude, 6 × 4 × 2 elements).
fn fluid_cargo(d: &Bound<'_, PyDict>, car: &TankCarParams) -> PyResult<FluidCargo> {
    let mut a = Args::new("cargo", d);
    let counts: (usize, usize, usize) = a.opt("counts")?.unwrap_or((6, 4, 2));
    let fill: f64 = a.req("fill")?;
    ancf_core::mesh::check_fill(fill).map_err(crate::to_py)?;
    let depth = 2.0 * car.tank_radius * fill;
    let oil: Option<String> = a.opt("oil")?;
    let fluid = match a.opt::<Bound<'_, crate::PyFluid>>("fluid")? {
        Some(f) => f.get().inner,
        None => oil_of(oil.as_deref().unwrap_or("light"))?
            .fluid(depth, depth / counts.2.max(1) as f64)
            .map_err(crate::to_py)?,
    };
    let bulkheads = a.opt("bulkheads")?.unwrap_or_default();
    let mut cargo = FluidCargo::new(fluid, [counts.0, counts.1, counts.2], fill, bulkheads);
    cargo.wall_damping_ratio = a.opt("wall_damping_ratio")?.unwrap_or(cargo.wall_damping_ratio);
    cargo.wall_adhesion = a.opt("wall_adhesion")?.unwrap_or(cargo.wall_adhesion);
    cargo.shear_stabilization = a.opt("shear_stabilization")?.unwrap_or(cargo.shear_stabilization);
    a.finish()?;
    Ok(cargo)
}

/// Runs a train whose tanks carry an ANCF fluid, monolithic with the cars (`train`: a
/// `TrainArgs` dict, `cargo`: a `FluidCargoArgs` dict), on the integrator settings of fluid
/// trains (`TrainScenario::fluid_hht`). Returns the `run_train` arrays plus the oil centre of
/// mass (tank and global frames), the fluid load on each tank, volume errors, the run-time
/// invariants and mesh snapshots.
#[pyfunction]
#[pyo3(signature = (train, cargo, *, progress=None, stream=None))]
pub fn run_fluid_train<'py>(
    py: Python<'py>,
    train: &Bound<'py, PyDict>,
    cargo: &Bound<'py, PyDict>,
    progress: Option<Py<PyAny>>,
    stream: Option<std::path::PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut sc = train_scenario(train)?;
    sc.hht = TrainScenario::fluid_hht();
    let cargo = fluid_cargo(cargo, &sc.car)?;
    run_cargo(py, sc, cargo, (progress, stream), |py, r| fluid_record_dict(py, r))
}

fn slosh_axis_of(name: &str) -> PyResult<SloshAxis> {
    match name {
        "longitudinal" => Ok(SloshAxis::Longitudinal),
        "lateral" => Ok(SloshAxis::Lateral),
        other => Err(crate::to_py(invalid("slosh_axis", other, "'longitudinal' or 'lateral'"))),
    }
}

/// The equivalent cargo of a named oil (or a `railslosh.Fluid`).
fn equivalent_cargo(
    oil: &str,
    fluid: Option<Bound<'_, crate::PyFluid>>,
    fill: f64,
    bulkheads: Option<Vec<(f64, f64)>>,
    slosh_axis: &str,
) -> PyResult<EquivalentCargo> {
    let axis = slosh_axis_of(slosh_axis)?;
    let bulkheads = bulkheads.unwrap_or_default();
    Ok(match fluid {
        Some(f) => EquivalentCargo::from_fluid(&f.get().inner, fill, bulkheads, axis),
        None => {
            let (rho, mu, _) = oil_of(oil)?.properties();
            EquivalentCargo::new(rho, mu, fill, bulkheads, axis)
        }
    })
}

fn model_dict<'py>(py: Python<'py>, m: &EquivalentModel) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item(
        "slosh_axis",
        match m.axis {
            SloshAxis::Longitudinal => "longitudinal",
            SloshAxis::Lateral => "lateral",
        },
    )?;
    d.set_item("mass", m.mass)?;
    d.set_item("depth", m.depth)?;
    d.set_item("depth_fraction", m.depth_fraction)?;
    d.set_item("lambda", m.lambda)?;
    d.set_item("equivalent_depth", m.equivalent_depth)?;
    d.set_item("centroid", m.centroid.to_vec())?;
    let modes = pyo3::types::PyList::empty(py);
    for (s, c) in m.modes.iter().zip(&m.compartments) {
        let e = PyDict::new(py);
        e.set_item("mass", s.mass)?;
        e.set_item("fixed_mass", s.fixed_mass)?;
        e.set_item("omega", s.omega)?;
        e.set_item("frequency", s.omega / (2.0 * std::f64::consts::PI))?;
        e.set_item("damping_ratio", s.damping_ratio)?;
        e.set_item("position", s.position.to_vec())?;
        e.set_item("fixed_position", s.fixed_position.to_vec())?;
        e.set_item("pendulum_length", s.pendulum_length)?;
        e.set_item("compartment_mass", c.mass)?;
        e.set_item("compartment_length", c.length)?;
        modes.append(e)?;
    }
    d.set_item("modes", modes)?;
    Ok(d)
}

/// The hat-weighted means (`rail_mbs::vehicle::hat_mean_resample`, the load filter of vehicle
/// runs) of a series `values` (samples × channels) at increasing times `t`, on the grid
/// t₀, t₀ + `dt`, … up to the last time: returns (grid samples × channels).
#[pyfunction]
pub fn hat_mean_resample<'py>(
    py: Python<'py>,
    t: Vec<f64>,
    values: Vec<Vec<f64>>,
    dt: f64,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    let out = compute(py, move || rail_mbs::vehicle::hat_mean_resample(&t, &values, dt))?;
    let m = out.first().map_or(0, Vec::len);
    if out.iter().any(|r| r.len() != m) {
        return Err(pyo3::exceptions::PyValueError::new_err(
            "invalid `values`: expected rows of equal length (one per sample)",
        ));
    }
    let n = out.len();
    PyArray1::from_vec(py, out.into_iter().flatten().collect()).reshape([n, m])
}

/// `λ = ω₁²R/g` of a horizontal circular cylinder at liquid depth fraction `h/2R` (the Rust
/// table of `rail_mbs::vehicle::equivalent`, interpolated).
#[pyfunction]
pub fn equivalent_lambda(py: Python<'_>, depth_fraction: f64) -> PyResult<f64> {
    compute(py, move || rail_mbs::vehicle::equivalent::cylinder_lambda(depth_fraction))
}

/// The equivalent slosh model (masses, frequencies, damping ratios, positions) of the liquid
/// of one car: `fill` is the volume fraction, as in `run_fluid_train`.
#[pyfunction]
#[pyo3(signature = (fill=0.5, *, oil="light", fluid=None, bulkheads=None, slosh_axis="longitudinal", car=None))]
pub fn equivalent_model<'py>(
    py: Python<'py>,
    fill: f64,
    oil: &str,
    fluid: Option<Bound<'py, crate::PyFluid>>,
    bulkheads: Option<Vec<(f64, f64)>>,
    slosh_axis: &str,
    car: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let params = car_params(car, "s1002")?;
    let cargo = equivalent_cargo(oil, fluid, fill, bulkheads, slosh_axis)?;
    let m = compute(py, move || cargo.model(&params, rail_mbs::track::GRAVITY))?;
    model_dict(py, &m)
}

fn equivalent_record_dict<'py>(py: Python<'py>, r: &EquivalentTrainRecord) -> PyResult<Bound<'py, PyDict>> {
    let d = record_dict(py, &r.train)?;
    let nt = r.oil_com_tank.len();
    let nc = r.oil_com_tank.first().map_or(0, |x| x.len());
    let com: Vec<f64> = r.oil_com_tank.iter().flat_map(|s| s.iter().flat_map(|c| c.iter().copied())).collect();
    d.set_item("oil_com_tank", arr(py, com, &[nt, nc, 3])?)?;
    let nm = r.model.as_ref().map_or(0, |m| m.modes.len());
    let disp: Vec<f64> = r.slosh_displacement.iter().flat_map(|s| s.iter().flatten().copied()).collect();
    d.set_item("slosh_displacement", arr(py, disp, &[nt, nc, nm])?)?;
    if let Some(m) = &r.model {
        d.set_item("fluid_mass", m.mass)?;
        d.set_item("equivalent_model", model_dict(py, m)?)?;
    }
    Ok(d)
}

/// Runs a train whose tanks carry the equivalent spring–mass / pendulum model of their
/// liquid (`rail_mbs::vehicle::equivalent`; `train`: a `TrainArgs` dict, `cargo`: an
/// `EquivalentCargoArgs` dict): one slosh mass per compartment along the slosh axis. Returns
/// the `run_train` arrays plus the liquid centre of mass in the tank frame, the slosh
/// displacements and the model.
#[pyfunction]
#[pyo3(signature = (train, cargo, *, progress=None, stream=None))]
pub fn run_equivalent_train<'py>(
    py: Python<'py>,
    train: &Bound<'py, PyDict>,
    cargo: &Bound<'py, PyDict>,
    progress: Option<Py<PyAny>>,
    stream: Option<std::path::PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let sc = train_scenario(train)?;
    // The stubs' `railslosh._core.EquivalentCargoArgs`: as `equivalent_model` takes them.
    let mut a = Args::new("cargo", cargo);
    let (oil, slosh_axis): (Option<String>, Option<String>) = (a.opt("oil")?, a.opt("slosh_axis")?);
    let cargo = equivalent_cargo(
        oil.as_deref().unwrap_or("light"),
        a.opt("fluid")?,
        a.req("fill")?,
        a.opt("bulkheads")?,
        slosh_axis.as_deref().unwrap_or("longitudinal"),
    )?;
    a.finish()?;
    run_cargo(py, sc, cargo, (progress, stream), |py, r| equivalent_record_dict(py, r))
}

/// Registers the vehicle functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(tank_car_parameters, m)?)?;
    m.add_function(wrap_pyfunction!(wheelset_stations, m)?)?;
    m.add_function(wrap_pyfunction!(run_train, m)?)?;
    m.add_function(wrap_pyfunction!(run_fluid_train, m)?)?;
    m.add_function(wrap_pyfunction!(design_brake_torque, m)?)?;
    m.add_function(wrap_pyfunction!(run_equivalent_train, m)?)?;
    m.add_function(wrap_pyfunction!(equivalent_model, m)?)?;
    m.add_function(wrap_pyfunction!(equivalent_lambda, m)?)?;
    m.add_function(wrap_pyfunction!(hat_mean_resample, m)?)?;
    m.add_function(wrap_pyfunction!(braking_step, m)?)?;
    Ok(())
}
