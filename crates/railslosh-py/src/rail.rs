//! Bindings of the track, profile and wheel/rail contact code of `rail-mbs`, wrapped for
//! users by `railslosh.rail`.
//!
//! As in `lib.rs`: every computation runs without the GIL and inside `catch_unwind`
//! (through [`crate::compute`]), invalid input raises `ValueError` naming the field and the
//! allowed range, and failed computations raise `railslosh.RailsloshError`. Vector
//! arguments are contiguous 1-D float64 arrays (the Python wrappers convert).

use std::sync::Arc;

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::create_exception;
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rail_mbs::profile::{self, Profile, ProfileError, ProfileKind};
use rail_mbs::track::{INCH, Side, Track, TrackError, TrackPoint};
use rail_mbs::wheel_rail::{
    ContactError, CreepModel, Creepages, FrictionMap, GaugeFaceLubrication, Material, PatchCombination, PatchModel,
    RailGeometry, RailPath, VerticalTarget, WheelGeometry, WheelRailContact, WheelState, kik_piotrowski,
    solve_vertical,
};
use railslosh_cases::contact::ValidationError;

use crate::RailsloshError;

create_exception!(
    _core,
    DataNotFoundError,
    RailsloshError,
    "External reference data (e.g. the Manchester contact benchmark) were not found; the case is skipped."
);

/// Runs `f` through [`crate::compute`] (no GIL, panics caught) and hands back its own result.
fn guarded<T: Send, E: Send, F: FnOnce() -> Result<T, E> + Send>(py: Python<'_>, f: F) -> PyResult<Result<T, E>> {
    crate::compute(py, move || Ok(f()))
}

/// Runs an infallible `f` through [`crate::compute`].
fn detached<T: Send, F: FnOnce() -> T + Send>(py: Python<'_>, f: F) -> PyResult<T> {
    crate::compute(py, move || Ok(f()))
}

pub(crate) fn invalid(field: &str, value: impl std::fmt::Display, allowed: &str) -> PyErr {
    PyValueError::new_err(format!("invalid `{field}` = {value}: expected {allowed}"))
}

fn finite(field: &str, v: f64) -> PyResult<f64> {
    if v.is_finite() { Ok(v) } else { Err(invalid(field, v, "a finite number")) }
}

fn positive(field: &str, v: f64, unit: &str) -> PyResult<f64> {
    if v > 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(invalid(field, v, format!("a finite number > 0 {unit}").trim_end()))
    }
}

fn in_range(field: &str, v: f64, lo: f64, hi: f64, unit: &str) -> PyResult<f64> {
    if v >= lo && v <= hi { Ok(v) } else { Err(invalid(field, v, format!("[{lo}, {hi}] {unit}").trim_end())) }
}

fn count_in(field: &str, v: i64, lo: i64, hi: i64) -> PyResult<usize> {
    if (lo..=hi).contains(&v) { Ok(v as usize) } else { Err(invalid(field, v, &format!("an integer in [{lo}, {hi}]"))) }
}

fn slice<'a>(a: &'a PyReadonlyArray1<'_, f64>, field: &str) -> PyResult<&'a [f64]> {
    a.as_slice().map_err(|_| PyValueError::new_err(format!("`{field}` must be a contiguous 1-D float64 array")))
}

fn side_of(side: &str) -> PyResult<Side> {
    match side {
        "left" => Ok(Side::Left),
        "right" => Ok(Side::Right),
        other => Err(invalid("side", format!("{other:?}"), "one of \"left\", \"right\"")),
    }
}

fn arr<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyAny> {
    PyArray1::from_vec(py, v).into_any()
}

fn arr3<'py>(py: Python<'py>, v: Vec<[f64; 3]>) -> PyResult<Bound<'py, PyAny>> {
    let n = v.len();
    Ok(PyArray1::from_vec(py, v.into_iter().flatten().collect()).reshape([n, 3])?.into_any())
}

fn profile_err(e: ProfileError) -> PyErr {
    match e {
        ProfileError::Io { ref source, .. } if source.kind() == std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(e.to_string())
        }
        ProfileError::Io { .. } => PyOSError::new_err(e.to_string()),
        other => PyValueError::new_err(other.to_string()),
    }
}

fn contact_err(e: ContactError) -> PyErr {
    match e {
        ContactError::InvalidInput(m) => PyValueError::new_err(format!("invalid contact input: {m}")),
        other => RailsloshError::new_err(other.to_string()),
    }
}

/// Maps the errors of the contact validation cases: missing data → `DataNotFoundError`,
/// unknown case → `ValueError`, anything else → `RailsloshError`.
fn validation_err(e: ValidationError) -> PyErr {
    match e {
        e if e.is_data_not_found() => DataNotFoundError::new_err(e.to_string()),
        ValidationError::UnknownCase(_) => PyValueError::new_err(e.to_string()),
        other => RailsloshError::new_err(other.to_string()),
    }
}

/// Runs a contact validation case (`railslosh_cases::contact`) for `run_validation`.
pub(crate) fn run_contact_validation(
    py: Python<'_>,
    name: String,
    quick: bool,
) -> PyResult<Vec<railslosh_cases::Record>> {
    guarded(py, move || railslosh_cases::contact::run_case(&name, quick))?.map_err(validation_err)
}

// ---------------------------------------------------------------------------------------
// Track
// ---------------------------------------------------------------------------------------

/// Longest distance table accepted, m (the centreline is tabulated every ≤ 5 m).
const MAX_TABLE_SPAN: f64 = 1.0e6;
/// Queries may extend this far beyond the ends of the table, m.
const MAX_EXTRAPOLATION: f64 = 1.0e4;

/// Field names of the table columns in SI and US units.
const SI_FIELDS: [&str; 6] = ["s", "curvature", "superelevation", "grade", "cant_right", "cant_left"];
const US_FIELDS: [&str; 6] =
    ["distance_ft", "degree_of_curvature", "superelevation_in", "grade_percent", "cant_right", "cant_left"];

/// Track geometry from a segment table (see `rail_mbs::track`).
#[pyclass(name = "Track", module = "railslosh._core", frozen)]
pub struct PyTrack {
    inner: Arc<Track>,
    us: bool,
}

impl PyTrack {
    fn queries(&self, s: &PyReadonlyArray1<'_, f64>) -> PyResult<Vec<f64>> {
        let (a, b) = self.inner.range();
        let (lo, hi) = (a - MAX_EXTRAPOLATION, b + MAX_EXTRAPOLATION);
        let v = slice(s, "s")?.to_vec();
        for &x in &v {
            if !(x >= lo && x <= hi) {
                return Err(invalid("s", x, &format!("finite distances in [{lo}, {hi}] m (table range ± 10 km)")));
            }
        }
        Ok(v)
    }

    fn map<'py>(
        &self,
        py: Python<'py>,
        s: PyReadonlyArray1<'py, f64>,
        f: fn(&Track, f64) -> f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let s = self.queries(&s)?;
        let t = &*self.inner;
        let out = detached(py, || s.iter().map(|&x| f(t, x)).collect::<Vec<f64>>())?;
        Ok(arr(py, out))
    }

    fn map3<'py>(
        &self,
        py: Python<'py>,
        s: PyReadonlyArray1<'py, f64>,
        f: impl Fn(&Track, f64) -> [f64; 3] + Send + Sync,
    ) -> PyResult<Bound<'py, PyAny>> {
        let s = self.queries(&s)?;
        let t = &*self.inner;
        let out = detached(py, || s.iter().map(|&x| f(t, x)).collect::<Vec<[f64; 3]>>())?;
        arr3(py, out)
    }
}

crate::args::named_readers!(track_arg { gauge: f64, cant_base: f64, origin: [f64; 3], heading: f64 });

#[pymethods]
impl PyTrack {
    /// Table columns (equal lengths) in SI units (`units="si"`: m, 1/m, m, fraction, rad,
    /// rad) or US units (`units="us"`: ft, degrees of curvature (arc definition), in,
    /// percent, rad, rad); gauge and cant base in m; start point (m) and heading (rad).
    #[new]
    #[pyo3(signature = (s, curvature, superelevation, grade, cant_right, cant_left, *, units="si",
                        gauge=Track::STANDARD_GAUGE, cant_base=Track::DEFAULT_CANT_BASE, origin=[0.0, 0.0, 0.0], heading=0.0))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        s: PyReadonlyArray1<'_, f64>,
        curvature: PyReadonlyArray1<'_, f64>,
        superelevation: PyReadonlyArray1<'_, f64>,
        grade: PyReadonlyArray1<'_, f64>,
        cant_right: PyReadonlyArray1<'_, f64>,
        cant_left: PyReadonlyArray1<'_, f64>,
        units: &str,
        #[pyo3(from_py_with = track_arg::gauge)] gauge: f64,
        #[pyo3(from_py_with = track_arg::cant_base)] cant_base: f64,
        #[pyo3(from_py_with = track_arg::origin)] origin: [f64; 3],
        #[pyo3(from_py_with = track_arg::heading)] heading: f64,
    ) -> PyResult<Self> {
        let us = match units {
            "si" => false,
            "us" => true,
            other => return Err(invalid("units", format!("{other:?}"), "one of \"si\", \"us\"")),
        };
        let names = if us { US_FIELDS } else { SI_FIELDS };
        let cols = [&s, &curvature, &superelevation, &grade, &cant_right, &cant_left];
        let cols: Vec<&[f64]> = cols.iter().zip(names).map(|(c, n)| slice(c, n)).collect::<PyResult<_>>()?;
        let n = cols[0].len();
        if n < 2 {
            return Err(invalid(names[0], format!("{n} points"), "a table of at least 2 points"));
        }
        for (c, name) in cols.iter().zip(names).skip(1) {
            if c.len() != n {
                return Err(PyValueError::new_err(format!("`{name}` has length {}, expected {n}", c.len())));
            }
        }
        positive("gauge", gauge, "m")?;
        positive("cant_base", cant_base, "m")?;
        for (k, v) in origin.iter().enumerate() {
            finite(&format!("origin[{k}]"), *v)?;
        }
        finite("heading", heading)?;
        let points: Vec<TrackPoint> = (0..n)
            .map(|i| {
                let r = [cols[0][i], cols[1][i], cols[2][i], cols[3][i], cols[4][i], cols[5][i]];
                if us {
                    TrackPoint::from_us(r[0], r[1], r[2], r[3], r[4], r[5])
                } else {
                    TrackPoint::new(r[0], r[1], r[2], r[3], r[4], r[5])
                }
            })
            .collect();
        let (s0, s1) = (points[0].s, points[n - 1].s);
        if (s1 - s0).abs() > MAX_TABLE_SPAN {
            return Err(invalid(
                names[0],
                format!("[{}, {}]", cols[0][0], cols[0][n - 1]),
                "a table at most 1000 km long",
            ));
        }
        let to_user = |k: usize, si: f64| -> f64 {
            match (us, k) {
                (true, 0) => si / rail_mbs::track::FOOT,
                (true, 2) => si / INCH,
                _ => si,
            }
        };
        let field = |k: usize| names[k];
        let built = guarded(py, move || Track::with_options(points, gauge, cant_base, origin.into(), heading))?;
        let inner = built.map_err(|e| match e {
            TrackError::TooFewPoints(n) => invalid(field(0), format!("{n} points"), "a table of at least 2 points"),
            TrackError::NotIncreasing { index, s } => {
                invalid(&format!("{}[{index}]", field(0)), to_user(0, s), "strictly increasing distances")
            }
            TrackError::NonFinite { index, field: f } => {
                let k = SI_FIELDS.iter().position(|x| *x == f).unwrap_or(0);
                invalid(&format!("{}[{index}]", field(k)), "non-finite", "a finite number")
            }
            TrackError::SuperElevationTooLarge { index, e, base } => invalid(
                &format!("{}[{index}]", field(2)),
                to_user(2, e),
                &format!(
                    "|superelevation| < cant_base = {base} m{}",
                    if us { format!(" = {:.3} in", base / INCH) } else { String::new() }
                ),
            ),
            TrackError::BadGauge { gauge, .. } => invalid("gauge", gauge, "a finite number > 0 m"),
            other => RailsloshError::new_err(other.to_string()),
        })?;
        Ok(Self { inner: Arc::new(inner), us })
    }

    /// Track gauge, m.
    #[getter]
    fn gauge(&self) -> f64 {
        self.inner.gauge()
    }
    /// Base over which super-elevation is measured, m.
    #[getter]
    fn cant_base(&self) -> f64 {
        self.inner.cant_base()
    }
    /// First and last distance of the table, m.
    #[getter]
    fn range(&self) -> (f64, f64) {
        self.inner.range()
    }
    /// The table in SI units, shape (n, 6): s, curvature, superelevation, grade,
    /// cant_right, cant_left.
    #[getter]
    fn table<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let pts = self.inner.points();
        let flat: Vec<f64> =
            pts.iter().flat_map(|p| [p.s, p.curvature, p.superelevation, p.grade, p.cant_right, p.cant_left]).collect();
        Ok(PyArray1::from_vec(py, flat).reshape([pts.len(), 6])?.into_any())
    }
    /// Units the table was given in ("si" or "us").
    #[getter]
    fn units(&self) -> &'static str {
        if self.us { "us" } else { "si" }
    }

    /// Centreline positions at `s`, shape (n, 3), m.
    fn position<'py>(&self, py: Python<'py>, s: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyAny>> {
        self.map3(py, s, |t, x| t.position(x).into())
    }
    /// Unit tangents at `s`, shape (n, 3).
    fn tangent<'py>(&self, py: Python<'py>, s: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyAny>> {
        self.map3(py, s, |t, x| t.tangent(x).into())
    }
    /// Track frames at `s`: origins (n, 3) and rotations (n, 3, 3) whose columns are the
    /// axes x (tangent), y (left), z (up) in global coordinates.
    fn frame<'py>(
        &self,
        py: Python<'py>,
        s: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let s = self.queries(&s)?;
        let t = &*self.inner;
        let frames =
            detached(py, || s.iter().map(|&x| t.frame(x)).map(|f| (f.origin, f.rotation)).collect::<Vec<_>>())?;
        let n = frames.len();
        let origins: Vec<[f64; 3]> = frames.iter().map(|f| f.0.into()).collect();
        // Row-major (n, 3, 3): entry [k, i, j] = R_ij.
        let rot: Vec<f64> =
            frames.iter().flat_map(|f| (0..3).flat_map(move |i| (0..3).map(move |j| f.1[(i, j)]))).collect();
        Ok((arr3(py, origins)?, PyArray1::from_vec(py, rot).reshape([n, 3, 3])?.into_any()))
    }
    /// Signed curvature at `s`, 1/m (positive = curve to the left).
    fn curvature<'py>(&self, py: Python<'py>, s: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyAny>> {
        self.map(py, s, Track::curvature)
    }
    /// Signed super-elevation at `s`, m (positive = right rail raised).
    fn superelevation<'py>(&self, py: Python<'py>, s: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyAny>> {
        self.map(py, s, Track::superelevation)
    }
    /// Grade at `s` (fraction, positive climbing).
    fn grade<'py>(&self, py: Python<'py>, s: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyAny>> {
        self.map(py, s, Track::grade)
    }
    /// Heading at `s`, rad (from +X towards +Y).
    fn heading<'py>(&self, py: Python<'py>, s: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyAny>> {
        self.map(py, s, Track::heading)
    }
    /// Bank (roll) angle of the track frame at `s`, rad (negative when the right rail is raised).
    fn bank_angle<'py>(&self, py: Python<'py>, s: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyAny>> {
        self.map(py, s, Track::bank_angle)
    }
    /// Balance speed `sqrt(g R h / B)` at `s`, m/s; NaN on tangent track or adverse
    /// super-elevation, 0 on a curve without super-elevation.
    fn balance_speed<'py>(&self, py: Python<'py>, s: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyAny>> {
        self.map(py, s, |t, x| t.balance_speed(x).unwrap_or(f64::NAN))
    }
    /// Points of the gauge line of one rail ("left" or "right") at `s`, shape (n, 3), m.
    fn rail_point<'py>(
        &self,
        py: Python<'py>,
        s: PyReadonlyArray1<'py, f64>,
        side: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let side = side_of(side)?;
        self.map3(py, s, move |t, x| t.rail_point(x, side).into())
    }
    /// Inward cant of one rail at `s`, rad (positive = head tilted towards the track centre).
    fn rail_inward_cant<'py>(
        &self,
        py: Python<'py>,
        s: PyReadonlyArray1<'py, f64>,
        side: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let side = side_of(side)?;
        let s = self.queries(&s)?;
        let t = &*self.inner;
        let out = detached(py, || s.iter().map(|&x| t.rail_inward_cant(x, side)).collect::<Vec<_>>())?;
        Ok(arr(py, out))
    }
    /// Projects global points (flat, 3 per point) onto the centreline: (s, lateral, vertical).
    fn project<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let p = slice(&points, "points")?.to_vec();
        if p.len() % 3 != 0 {
            return Err(PyValueError::new_err(format!("`points` has {} values, expected a multiple of 3", p.len())));
        }
        if let Some(bad) = p.iter().find(|v| !v.is_finite()) {
            return Err(invalid("points", bad, "finite coordinates (m)"));
        }
        let t = &*self.inner;
        let res = guarded(py, || {
            let mut hint = None;
            let mut out = Vec::with_capacity(p.len() / 3);
            for c in p.chunks(3) {
                let pr = t.project(&[c[0], c[1], c[2]].into(), hint)?;
                hint = Some(pr.s);
                out.push(pr);
            }
            Ok::<_, TrackError>(out)
        })?
        .map_err(|e| RailsloshError::new_err(e.to_string()))?;
        Ok((
            arr(py, res.iter().map(|r| r.s).collect()),
            arr(py, res.iter().map(|r| r.lateral).collect()),
            arr(py, res.iter().map(|r| r.vertical).collect()),
        ))
    }
    fn __repr__(&self) -> String {
        let (a, b) = self.inner.range();
        format!(
            "Track(points={}, s=[{a}, {b}] m, gauge={} m, cant_base={} m, units={})",
            self.inner.points().len(),
            self.inner.gauge(),
            self.inner.cant_base(),
            self.units()
        )
    }
}

// ---------------------------------------------------------------------------------------
// Profiles
// ---------------------------------------------------------------------------------------

/// A wheel or rail profile z(y) (m; y towards the field side, z up; see `rail_mbs::profile`).
#[pyclass(name = "Profile", module = "railslosh._core", frozen)]
#[derive(Clone)]
pub struct PyProfile {
    inner: Profile,
    kind: Option<&'static str>,
}

fn spacing_ok(spacing: f64) -> PyResult<f64> {
    in_range("spacing", spacing, 1e-5, 5e-3, "m")
}

#[pymethods]
impl PyProfile {
    /// S1002 wheel profile sampled every `spacing` m.
    #[staticmethod]
    #[pyo3(signature = (spacing=2e-4))]
    fn s1002(py: Python<'_>, spacing: f64) -> PyResult<Self> {
        let spacing = spacing_ok(spacing)?;
        let p = guarded(py, move || profile::s1002_wheel(spacing))?.map_err(profile_err)?;
        Ok(Self { inner: p, kind: Some("wheel") })
    }
    /// UIC 60 rail head (uncanted) sampled every `spacing` m.
    #[staticmethod]
    #[pyo3(signature = (spacing=2e-4))]
    fn uic60(py: Python<'_>, spacing: f64) -> PyResult<Self> {
        let spacing = spacing_ok(spacing)?;
        let p = guarded(py, move || profile::uic60_rail(spacing))?.map_err(profile_err)?;
        Ok(Self { inner: p, kind: Some("rail") })
    }
    /// Approximate AAR-1B wheel profile (not the licensed contour).
    #[staticmethod]
    fn aar1b_approx(py: Python<'_>) -> PyResult<Self> {
        let p = guarded(py, profile::aar1b_wheel_approx)?.map_err(profile_err)?;
        Ok(Self { inner: p, kind: Some("wheel") })
    }
    /// SIMPACK `.prr`/`.prw` file (converted to m, z up; shift and mirror flags applied).
    #[staticmethod]
    fn from_simpack(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Self> {
        let (p, kind) = guarded(py, move || {
            let f = profile::read_simpack(&path)?;
            Ok::<_, ProfileError>((f.to_profile()?, f.kind))
        })?
        .map_err(profile_err)?;
        Ok(Self { inner: p, kind: Some(if kind == ProfileKind::Rail { "rail" } else { "wheel" }) })
    }
    /// Profile through points (y, z) in m, crate convention; sorted by y, duplicates rejected.
    #[staticmethod]
    #[pyo3(signature = (y, z, name="points", kind=None))]
    fn from_points(
        py: Python<'_>,
        y: PyReadonlyArray1<'_, f64>,
        z: PyReadonlyArray1<'_, f64>,
        name: &str,
        kind: Option<&str>,
    ) -> PyResult<Self> {
        let (y, z) = (slice(&y, "y")?, slice(&z, "z")?);
        if y.len() != z.len() {
            return Err(PyValueError::new_err(format!("`z` has length {}, expected {}", z.len(), y.len())));
        }
        if y.len() < 2 {
            return Err(invalid("y", format!("{} points", y.len()), "at least 2 points"));
        }
        for (field, v) in [("y", y), ("z", z)] {
            if let Some(bad) = v.iter().find(|x| !x.is_finite() || x.abs() > 1.0) {
                return Err(invalid(field, bad, "finite coordinates with |value| <= 1 m"));
            }
        }
        let kind = match kind {
            None => None,
            Some("rail") => Some("rail"),
            Some("wheel") => Some("wheel"),
            Some(other) => return Err(invalid("kind", format!("{other:?}"), "None, \"rail\" or \"wheel\"")),
        };
        let pts: Vec<(f64, f64)> = y.iter().copied().zip(z.iter().copied()).collect();
        let name = name.to_string();
        let p = guarded(py, move || Profile::from_points(&name, &pts))?.map_err(profile_err)?;
        Ok(Self { inner: p, kind })
    }
    /// Two-column text file of (y, z) pairs; `scale` converts the file unit to m (1e-3 for
    /// mm), `z_down` flips z (files with z downwards), `mirror_y` flips y.
    #[staticmethod]
    #[pyo3(signature = (path, *, scale=1.0, z_down=false, mirror_y=false, kind=None))]
    fn from_two_column(
        py: Python<'_>,
        path: std::path::PathBuf,
        scale: f64,
        z_down: bool,
        mirror_y: bool,
        kind: Option<&str>,
    ) -> PyResult<Self> {
        positive("scale", scale, "(file unit in m)")?;
        let kind = match kind {
            None => None,
            Some("rail") => Some("rail"),
            Some("wheel") => Some("wheel"),
            Some(other) => return Err(invalid("kind", format!("{other:?}"), "None, \"rail\" or \"wheel\"")),
        };
        let p = guarded(py, move || {
            let raw = profile::read_two_column(&path)?;
            let pts: Vec<(f64, f64)> = raw
                .iter()
                .map(|&(y, z)| (if mirror_y { -y } else { y } * scale, if z_down { -z } else { z } * scale))
                .collect();
            let name = path.file_name().map(|n| n.to_string_lossy().to_string()).unwrap_or_default();
            Profile::from_points(&name, &pts)
        })?
        .map_err(profile_err)?;
        Ok(Self { inner: p, kind })
    }

    /// Profile name.
    #[getter]
    fn name(&self) -> String {
        self.inner.name().to_string()
    }
    /// "rail", "wheel" or None (unknown).
    #[getter]
    fn kind(&self) -> Option<&'static str> {
        self.kind
    }
    /// Lateral range of the data, m.
    #[getter]
    fn y_range(&self) -> (f64, f64) {
        self.inner.y_range()
    }
    /// Spline knots, shape (k, 2): y, z (m).
    #[getter]
    fn knots<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let sp = self.inner.spline();
        let flat: Vec<f64> = sp.knots().iter().zip(sp.values()).flat_map(|(y, z)| [*y, *z]).collect();
        Ok(PyArray1::from_vec(py, flat).reshape([sp.knots().len(), 2])?.into_any())
    }
    /// Highest point (y, z), m.
    fn highest_point(&self, py: Python<'_>) -> PyResult<(f64, f64)> {
        detached(py, || self.inner.highest_point())
    }
    /// `n` evenly spaced samples over the range, shape (n, 2): y, z (m).
    fn sample<'py>(&self, py: Python<'py>, n: i64) -> PyResult<Bound<'py, PyAny>> {
        let n = count_in("n", n, 2, 1_000_000)?;
        let flat: Vec<f64> = detached(py, || self.inner.sample(n).into_iter().flat_map(|(y, z)| [y, z]).collect())?;
        Ok(PyArray1::from_vec(py, flat).reshape([n, 2])?.into_any())
    }
    /// z, dz/dy and d²z/dy² at `y` (the spline continues linearly outside the data).
    fn eval<'py>(
        &self,
        py: Python<'py>,
        y: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let y = slice(&y, "y")?;
        if let Some(bad) = y.iter().find(|v| !v.is_finite()) {
            return Err(invalid("y", bad, "finite lateral coordinates (m)"));
        }
        let p = &self.inner;
        let (z, d, dd) = detached(py, || {
            let (mut z, mut d, mut dd) = (Vec::new(), Vec::new(), Vec::new());
            for &v in y {
                let e = p.eval(v);
                z.push(e.0);
                d.push(e.1);
                dd.push(e.2);
            }
            (z, d, dd)
        })?;
        Ok((arr(py, z), arr(py, d), arr(py, dd)))
    }
    /// Copy restricted to the longest run where the chord slope stays below `max_slope`.
    fn trim_steep_ends(&self, py: Python<'_>, max_slope: f64) -> PyResult<Self> {
        positive("max_slope", max_slope, "")?;
        let inner = guarded(py, || self.inner.trim_steep_ends(max_slope))?.map_err(profile_err)?;
        Ok(Self { inner, kind: self.kind })
    }
    fn __repr__(&self) -> String {
        let (a, b) = self.inner.y_range();
        format!(
            "Profile({:?}, kind={}, y=[{a:.4}, {b:.4}] m, knots={})",
            self.inner.name(),
            self.kind.unwrap_or("None"),
            self.inner.spline().knots().len()
        )
    }
}

// ---------------------------------------------------------------------------------------
// Contact
// ---------------------------------------------------------------------------------------

/// The creep law `name` with its parameters: Polach's reduction factors `k_a`, `k_s` (default
/// 1, 1; each in (0, 1]) and FASTSIM's grid `nx`, `ny` (default 40 × 40; each 2 to 400).
fn creep_model_of(name: &str, params: Option<&Bound<'_, PyDict>>) -> PyResult<CreepModel> {
    let get = |key: &str, default: f64| -> PyResult<f64> {
        match params.map(|d| d.get_item(key)).transpose()?.flatten() {
            Some(v) => v.extract::<f64>().map_err(|_| invalid(&format!("creep_parameters.{key}"), v, "a number")),
            None => Ok(default),
        }
    };
    let allowed: &[&str] = match name {
        "polach" => &["k_a", "k_s"],
        "fastsim" => &["nx", "ny"],
        _ => &[],
    };
    if let Some(d) = params {
        for k in d.keys() {
            let k: String = k.extract()?;
            if !allowed.contains(&k.as_str()) {
                return Err(invalid(
                    "creep_parameters",
                    format!("{k:?}"),
                    &format!("one of {allowed:?} with creep_model {name:?}"),
                ));
            }
        }
    }
    match name {
        "shen-hedrick-elkins" => Ok(CreepModel::ShenHedrickElkins),
        "polach" => {
            let k_a = get("k_a", 1.0)?;
            let k_s = get("k_s", 1.0)?;
            for (k, v) in [("creep_parameters.k_a", k_a), ("creep_parameters.k_s", k_s)] {
                if !(v > 0.0 && v <= 1.0) {
                    return Err(invalid(k, v, "a reduction factor in (0, 1]"));
                }
            }
            Ok(CreepModel::Polach { k_a, k_s })
        }
        "linear" => Ok(CreepModel::Linear),
        "fastsim" => {
            let nx = get("nx", 40.0)?;
            let ny = get("ny", 40.0)?;
            for (k, v) in [("creep_parameters.nx", nx), ("creep_parameters.ny", ny)] {
                if !(v.fract() == 0.0 && (2.0..=400.0).contains(&v)) {
                    return Err(invalid(k, v, "a whole number of cells from 2 to 400"));
                }
            }
            Ok(CreepModel::Fastsim { nx: nx as usize, ny: ny as usize })
        }
        other => Err(invalid(
            "creep_model",
            format!("{other:?}"),
            "one of \"shen-hedrick-elkins\", \"polach\", \"linear\", \"fastsim\"",
        )),
    }
}

/// The patch model `name` ("hertz" or "kik_piotrowski") with the Kik–Piotrowski options
/// `kp_epsilon` (virtual-penetration factor, default 0.55) and `kp_strips` (default 60), which
/// only "kik_piotrowski" takes.
fn patch_model_of(name: &str, epsilon: Option<f64>, strips: Option<i64>) -> PyResult<PatchModel> {
    match name {
        "hertz" => {
            if let Some(e) = epsilon {
                return Err(invalid("kp_epsilon", e, "None with patch_model \"hertz\""));
            }
            if let Some(n) = strips {
                return Err(invalid("kp_strips", n, "None with patch_model \"hertz\""));
            }
            Ok(PatchModel::Hertz)
        }
        "kik_piotrowski" => {
            let (lo, hi) = kik_piotrowski::EPSILON_RANGE;
            let epsilon = in_range("kp_epsilon", epsilon.unwrap_or(kik_piotrowski::DEFAULT_EPSILON), lo, hi, "")?;
            let (slo, shi) = kik_piotrowski::STRIPS_RANGE;
            let strips =
                count_in("kp_strips", strips.unwrap_or(kik_piotrowski::DEFAULT_STRIPS as i64), slo as i64, shi as i64)?;
            Ok(PatchModel::KikPiotrowski { epsilon, strips })
        }
        other => Err(invalid("patch_model", format!("{other:?}"), "one of \"hertz\", \"kik_piotrowski\"")),
    }
}

/// The patch rule `name` ("separate", or "contact": CONTACT's D_SEP/D_COMB rule with `a_sep`,
/// `d_sep`, `d_comb`, default its program defaults π, 8 mm, 4 mm), which only "contact" takes.
fn patch_combination_of(
    name: &str,
    a_sep: Option<f64>,
    d_sep: Option<f64>,
    d_comb: Option<f64>,
) -> PyResult<PatchCombination> {
    match name {
        "separate" => {
            for (field, value) in [("a_sep", a_sep), ("d_sep", d_sep), ("d_comb", d_comb)] {
                if let Some(v) = value {
                    return Err(invalid(field, v, "None with patch_combination \"separate\""));
                }
            }
            Ok(PatchCombination::Separate)
        }
        "contact" => {
            let mut rule = PatchCombination::contact();
            if let PatchCombination::Contact { a_sep: a, d_sep: s, d_comb: c } = &mut rule {
                *a = a_sep.unwrap_or(*a);
                *s = d_sep.unwrap_or(*s);
                *c = d_comb.unwrap_or(*c);
            }
            rule.validate().map_err(|e| PyValueError::new_err(e.to_string()))?;
            Ok(rule)
        }
        other => Err(invalid("patch_combination", format!("{other:?}"), "one of \"separate\", \"contact\"")),
    }
}

/// One wheel on its straight rail at the height carrying `load` (N, total vertical force
/// on the wheel) or reaching `penetration` (m); see `railslosh.rail.contact`.
#[pyfunction]
#[pyo3(signature = (wheel, rail, *, side="left", nominal_radius=0.46, wheel_offset=0.75, rail_offset=None,
                    gauge=1.435, gauge_depth=0.014, rail_cant=0.0, trim_slope=None, lateral_shift=0.0, yaw=0.0,
                    roll=0.0, load=None, penetration=None, speed=0.0, lateral_velocity=0.0, yaw_rate=0.0,
                    axle_rate=None, creepages=None, creep_model="shen-hedrick-elkins", creep_parameters=None,
                    friction=0.3, friction_profile=None, young=2.1e11, poisson=0.3, scan_points=400,
                    patch_model="hertz", kp_epsilon=None, kp_strips=None, patch_combination="separate",
                    a_sep=None, d_sep=None, d_comb=None))]
#[allow(clippy::too_many_arguments)]
pub fn wheel_rail_contact<'py>(
    py: Python<'py>,
    wheel: &PyProfile,
    rail: &PyProfile,
    side: &str,
    nominal_radius: f64,
    wheel_offset: f64,
    rail_offset: Option<f64>,
    gauge: f64,
    gauge_depth: f64,
    rail_cant: f64,
    trim_slope: Option<f64>,
    lateral_shift: f64,
    yaw: f64,
    roll: f64,
    load: Option<f64>,
    penetration: Option<f64>,
    speed: f64,
    lateral_velocity: f64,
    yaw_rate: f64,
    axle_rate: Option<f64>,
    creepages: Option<[f64; 3]>,
    creep_model: &str,
    creep_parameters: Option<&Bound<'py, PyDict>>,
    friction: f64,
    friction_profile: Option<Vec<(f64, f64)>>,
    young: f64,
    poisson: f64,
    scan_points: i64,
    patch_model: &str,
    kp_epsilon: Option<f64>,
    kp_strips: Option<i64>,
    patch_combination: &str,
    a_sep: Option<f64>,
    d_sep: Option<f64>,
    d_comb: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let side = side_of(side)?;
    let friction_map = match friction_profile {
        Some(profile) => {
            let m = FrictionMap { profile, along_track: Vec::new() };
            m.validate().map_err(contact_err)?;
            Some(Arc::new(m))
        }
        None => None,
    };
    in_range("nominal_radius", nominal_radius, 0.1, 1.5, "m")?;
    in_range("wheel_offset", wheel_offset, 0.3, 1.2, "m")?;
    in_range("gauge", gauge, 0.6, 2.0, "m")?;
    in_range("gauge_depth", gauge_depth, 0.0, 0.05, "m")?;
    in_range("rail_cant", rail_cant, -0.2, 0.2, "rad")?;
    in_range("lateral_shift", lateral_shift, -0.05, 0.05, "m")?;
    in_range("yaw", yaw, -0.1, 0.1, "rad")?;
    in_range("roll", roll, -0.1, 0.1, "rad")?;
    in_range("speed", speed, 0.0, 200.0, "m/s")?;
    in_range("lateral_velocity", lateral_velocity, -10.0, 10.0, "m/s")?;
    in_range("yaw_rate", yaw_rate, -10.0, 10.0, "rad/s")?;
    if let Some(w) = axle_rate {
        in_range("axle_rate", w, -1000.0, 1000.0, "rad/s")?;
    }
    in_range("friction", friction, 0.0, 2.0, "")?;
    positive("young", young, "Pa")?;
    in_range("poisson", poisson, 0.0, 0.49, "")?;
    let scan_points = count_in("scan_points", scan_points, 20, 20_000)?;
    if let Some(t) = trim_slope {
        positive("trim_slope", t, "")?;
    }
    let target = match (load, penetration) {
        (Some(l), None) => VerticalTarget::Load(in_range("load", l, 1.0, 1e7, "N")?),
        (None, Some(p)) => VerticalTarget::Penetration(in_range("penetration", p, 1e-9, 2e-3, "m")?),
        _ => {
            return Err(PyValueError::new_err(
                "invalid `load`/`penetration`: expected exactly one of them (load in N or penetration in m)",
            ));
        }
    };
    let creepages = match creepages {
        None => None,
        Some(c) => {
            in_range("creepages[0]", c[0], -1.0, 1.0, "(longitudinal)")?;
            in_range("creepages[1]", c[1], -1.0, 1.0, "(lateral)")?;
            in_range("creepages[2]", c[2], -100.0, 100.0, "1/m (spin)")?;
            Some(Creepages { longitudinal: c[0], lateral: c[1], spin: c[2] })
        }
    };
    let model = creep_model_of(creep_model, creep_parameters)?;
    let patch = patch_model_of(patch_model, kp_epsilon, kp_strips)?;
    let combination = patch_combination_of(patch_combination, a_sep, d_sep, d_comb)?;
    if let Some(o) = rail_offset {
        in_range("rail_offset", o, 0.3, 1.2, "m")?;
    }
    let rail_full = &rail.inner;
    // Gauge point on the full profile, then the optional trim (both without the GIL).
    let (offset, rail_profile) = detached(py, || {
        let offset = rail_offset.or_else(|| RailGeometry::offset_for_gauge(rail_full, gauge, gauge_depth));
        let trimmed = match trim_slope {
            Some(t) => rail_full.trim_steep_ends(t),
            None => Ok(rail_full.clone()),
        };
        (offset, trimmed)
    })?;
    let offset = offset.ok_or_else(|| {
        invalid(
            "gauge_depth",
            gauge_depth,
            "a depth the rail profile reaches on its gauge side (or give `rail_offset`)",
        )
    })?;
    let rail_profile = rail_profile.map_err(profile_err)?;
    let mut contact = WheelRailContact::new(
        WheelGeometry { profile: wheel.inner.clone(), nominal_radius, profile_offset: wheel_offset, side },
        RailGeometry {
            profile: rail_profile,
            side,
            profile_offset: offset,
            vertical_offset: 0.0,
            path: RailPath::Straight { inward_cant: rail_cant },
        },
    );
    let mat = Material { young, poisson };
    contact.wheel_material = mat;
    contact.rail_material = mat;
    contact.friction = friction;
    contact.friction_map = friction_map;
    contact.creep_model = model;
    contact.patch_model = patch;
    contact.settings.patch_combination = combination;
    contact.settings.scan_points = scan_points;
    let state = WheelState { lateral_shift, yaw, roll, speed, lateral_velocity, yaw_rate, axle_rate, creepages };
    let res = guarded(py, move || {
        let r = solve_vertical(&mut contact, &state, target)?;
        Ok::<_, ContactError>((r, contact))
    })?;
    let (res, contact) = res.map_err(contact_err)?;
    let pts = &res.points;
    let d = PyDict::new(py);
    d.set_item("height", res.height)?;
    d.set_item("vertical_force", res.vertical_force)?;
    d.set_item("lateral_force", pts.iter().map(|p| p.force_on_wheel().y).sum::<f64>())?;
    d.set_item("rail_offset", offset)?;
    let col = |f: &dyn Fn(&rail_mbs::wheel_rail::ContactPoint) -> f64| pts.iter().map(f).collect::<Vec<f64>>();
    let vec3 = |f: &dyn Fn(&rail_mbs::wheel_rail::ContactPoint) -> [f64; 3]| pts.iter().map(f).collect::<Vec<_>>();
    d.set_item("y_track", arr(py, col(&|p| p.point().y)))?;
    d.set_item("friction", arr(py, col(&|p| contact.friction_at(&p.geometry.params))))?;
    d.set_item("rail_v", arr(py, col(&|p| p.geometry.params[1])))?;
    d.set_item("y_rail", arr(py, col(&|p| p.geometry.params[1])))?;
    d.set_item("y_wheel", arr(py, col(&|p| p.geometry.params[2])))?;
    d.set_item("rolling_radius", arr(py, col(&|p| nominal_radius - contact.wheel.profile.z(p.geometry.params[2]))))?;
    d.set_item("contact_angle", arr(py, col(&|p| p.geometry.normal.z.clamp(-1.0, 1.0).acos())))?;
    d.set_item("penetration", arr(py, col(&|p| p.geometry.penetration)))?;
    d.set_item("normal_force", arr(py, col(&|p| p.normal_force)))?;
    d.set_item("creep_longitudinal", arr(py, col(&|p| p.creep.longitudinal)))?;
    d.set_item("creep_lateral", arr(py, col(&|p| p.creep.lateral)))?;
    d.set_item("spin_moment", arr(py, col(&|p| p.creep.spin_moment)))?;
    d.set_item("semi_axis_a", arr(py, col(&|p| p.semi_axes.0)))?;
    d.set_item("semi_axis_b", arr(py, col(&|p| p.semi_axes.1)))?;
    d.set_item(
        "max_pressure",
        arr(py, col(&|p| p.patch.map_or_else(|| p.hertz.max_pressure(p.normal_force), |s| s.max_pressure))),
    )?;
    d.set_item(
        "patch_area",
        arr(py, col(&|p| p.patch.map_or(std::f64::consts::PI * p.semi_axes.0 * p.semi_axes.1, |s| s.area))),
    )?;
    d.set_item(
        "patch_width",
        arr(py, col(&|p| p.patch.map_or(2.0 * p.semi_axes.1, |s| s.lateral_extent.1 - s.lateral_extent.0))),
    )?;
    d.set_item("reference_point", arr3(py, vec3(&|p| p.reference_point().into()))?)?;
    d.set_item(
        "creepages",
        arr3(py, pts.iter().map(|p| [p.creepages.longitudinal, p.creepages.lateral, p.creepages.spin]).collect())?,
    )?;
    d.set_item("point", arr3(py, vec3(&|p| p.point().into()))?)?;
    d.set_item("normal", arr3(py, vec3(&|p| p.geometry.normal.into()))?)?;
    d.set_item("e1", arr3(py, vec3(&|p| p.geometry.e1.into()))?)?;
    d.set_item("e2", arr3(py, vec3(&|p| p.geometry.e2.into()))?)?;
    d.set_item("force_on_wheel", arr3(py, vec3(&|p| p.force_on_wheel().into()))?)?;
    d.set_item("method", pts.iter().map(|p| format!("{:?}", p.geometry.method).to_lowercase()).collect::<Vec<_>>())?;
    Ok(d)
}

/// Registers the classes and functions of this file in `railslosh._core`.
/// The `(v, μ)` table of a lubricated gauge face on `rail` (`rail_mbs::wheel_rail::FrictionMap::
/// lubricated_gauge_face`): `mu_gauge` on the gauge side up to the point `depth` (m) below the
/// rail top, `mu_top` on the rest of the head, linear over `width` (m).
#[pyfunction]
#[pyo3(signature = (rail, *, mu_top=GaugeFaceLubrication::DEFAULT.mu_top, mu_gauge=GaugeFaceLubrication::DEFAULT.mu_gauge,
                    depth=GaugeFaceLubrication::DEFAULT.depth, width=GaugeFaceLubrication::DEFAULT.width))]
pub fn lubricated_gauge_face(
    rail: &PyProfile,
    mu_top: f64,
    mu_gauge: f64,
    depth: f64,
    width: f64,
) -> PyResult<Vec<(f64, f64)>> {
    FrictionMap::lubricated_gauge_face(&rail.inner, mu_top, mu_gauge, depth, width)
        .map(|m| m.profile)
        .map_err(contact_err)
}

/// Nadal's flange-climb limit (tan δ − μ)/(1 + μ tan δ) for contact angle δ (rad) and friction μ
/// (`rail_mbs::wheel_rail::nadal_limit`).
#[pyfunction]
fn nadal_limit(contact_angle: f64, friction: f64) -> f64 {
    rail_mbs::wheel_rail::nadal_limit(contact_angle, friction)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("DataNotFoundError", m.py().get_type::<DataNotFoundError>())?;
    let g = GaugeFaceLubrication::DEFAULT;
    let d = PyDict::new(m.py());
    for (k, v) in [("mu_top", g.mu_top), ("mu_gauge", g.mu_gauge), ("depth", g.depth), ("width", g.width)] {
        d.set_item(k, v)?;
    }
    m.add("LUBRICATED_GAUGE_FACE", d)?;
    m.add_class::<PyTrack>()?;
    m.add_class::<PyProfile>()?;
    m.add_function(wrap_pyfunction!(wheel_rail_contact, m)?)?;
    m.add_function(wrap_pyfunction!(lubricated_gauge_face, m)?)?;
    m.add_function(wrap_pyfunction!(nadal_limit, m)?)?;
    Ok(())
}
