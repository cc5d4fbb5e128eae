//! Bindings of `rail_mbs::track::irregularity` (issue 20 §1), wrapped for users by
//! `railslosh.irregularity`: generate a track irregularity from a spectrum, add isolated
//! defects, evaluate a spectrum, and hand the samples to the vehicle runs.
//!
//! An irregularity crosses the boundary as a dict of samples on a uniform grid:
//! `{"start": m, "step": m, "vertical": array, "alignment": array, "cross_level": array,
//! "gauge": array}` (metres; signs in `docs/frames.md`).

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rail_mbs::track::{Channel, Defect, Irregularity, IrregularityPsd, TrackSpectrum};

use crate::rail::invalid;
use crate::to_py;

/// The spectrum named `kind` ("fra" with `track_class` 1–6, "erri_low", "erri_high").
fn spectrum(kind: &str, track_class: Option<i64>) -> PyResult<TrackSpectrum> {
    let s = match (kind, track_class) {
        ("fra", Some(c)) if (1..=6).contains(&c) => TrackSpectrum::Fra { class: c as u8 },
        ("fra", Some(c)) => return Err(invalid("class", c, "an FRA track class 1–6")),
        ("fra", None) => return Err(invalid("class", "None", "an FRA track class 1–6 with kind = \"fra\"")),
        ("erri_low", None) => TrackSpectrum::ErriLow,
        ("erri_high", None) => TrackSpectrum::ErriHigh,
        ("erri_low" | "erri_high", Some(c)) => {
            return Err(invalid(
                "class",
                c,
                "no class with the ERRI B176 spectra (kind \"erri_low\" or \"erri_high\")",
            ));
        }
        (other, _) => return Err(invalid("kind", format!("{other:?}"), "\"fra\", \"erri_low\" or \"erri_high\"")),
    };
    Ok(s)
}

fn channel(name: &str) -> PyResult<Channel> {
    Channel::ALL.into_iter().find(|c| c.name() == name).ok_or_else(|| {
        invalid("channel", format!("{name:?}"), "\"vertical\", \"alignment\", \"cross_level\" or \"gauge\"")
    })
}

/// The samples of `irr` as the boundary dict (module docs).
fn to_dict<'py>(py: Python<'py>, irr: &Irregularity) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("start", irr.start())?;
    d.set_item("step", irr.step())?;
    for (c, x) in Channel::ALL.iter().zip(irr.channels()) {
        d.set_item(c.name(), PyArray1::from_slice(py, x))?;
    }
    Ok(d)
}

/// The irregularity of a boundary dict (module docs); errors name the key.
pub(crate) fn from_dict(d: &Bound<'_, PyDict>) -> PyResult<Irregularity> {
    let get = |k: &str| -> PyResult<Bound<'_, PyAny>> {
        d.get_item(k)?.ok_or_else(|| {
            invalid(
                "irregularity",
                format!("a dict without {k:?}"),
                "the keys start, step, vertical, alignment, cross_level, gauge",
            )
        })
    };
    let start: f64 = get("start")?.extract().map_err(|_| invalid("irregularity.start", "?", "a number (m)"))?;
    let step: f64 = get("step")?.extract().map_err(|_| invalid("irregularity.step", "?", "a number (m)"))?;
    let mut ch: [Vec<f64>; 4] = Default::default();
    for (c, x) in Channel::ALL.iter().zip(ch.iter_mut()) {
        *x = get(c.name())?
            .extract::<Vec<f64>>()
            .map_err(|_| invalid(&format!("irregularity.{}", c.name()), "?", "a 1-D array of numbers (m)"))?;
    }
    Irregularity::from_samples(start, step, ch).map_err(to_py)
}

/// Draws a track irregularity from a spectrum (`rail_mbs::track::Irregularity::generate`):
/// `kind` "fra" (with `track_class` 1–6), "erri_low" or "erri_high"; `length` m of track from
/// `start`, samples every `step` m, `wavelengths` (shortest, longest) m, `seed`, a
/// raised-cosine `taper` (m) from zero at the start; `channels` the names to draw (default
/// all four). Returns the samples dict.
#[pyfunction]
#[pyo3(signature = (kind, length, *, track_class=None, start=0.0, step=0.25, wavelengths=(1.0, 70.0), seed=1, taper=20.0, channels=None))]
#[allow(clippy::too_many_arguments)]
pub fn track_irregularity<'py>(
    py: Python<'py>,
    kind: &str,
    length: f64,
    track_class: Option<i64>,
    start: f64,
    step: f64,
    wavelengths: (f64, f64),
    seed: u64,
    taper: f64,
    channels: Option<Vec<String>>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut p = IrregularityPsd::new(spectrum(kind, track_class)?, length);
    p.start = start;
    p.step = step;
    p.wavelengths = wavelengths;
    p.seed = seed;
    p.taper = taper;
    if let Some(names) = channels {
        p.channels = [false; 4];
        for n in &names {
            p.channels[channel(n)? as usize] = true;
        }
    }
    // no GIL while drawing; the kernel's own "invalid `field` = …" errors pass through
    let irr = crate::compute(py, move || Ok(Irregularity::generate(&p)))?.map_err(to_py)?;
    to_dict(py, &irr)
}

/// Adds isolated defects to an irregularity (`samples`, a samples dict) or, without one, to a
/// perfect track sampled over [`start`, `end`] every `step` m. Each defect is a dict with
/// `type` "cosine_dip" (`start`, `length`, `depth`), "cusp" (`at`, `length`, `depth`) or
/// "twist" (`start`, `base`, `cross_level`, `hold` = 0); metres. Returns the samples dict.
#[pyfunction]
#[pyo3(signature = (defects, *, samples=None, start=0.0, end=None, step=0.05))]
pub fn track_irregularity_defects<'py>(
    py: Python<'py>,
    defects: &Bound<'py, PyList>,
    samples: Option<&Bound<'py, PyDict>>,
    start: f64,
    end: Option<f64>,
    step: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let mut irr = match (samples, end) {
        (Some(d), _) => from_dict(d)?,
        (None, Some(end)) => Irregularity::zero(start, end, step).map_err(to_py)?,
        (None, None) => {
            return Err(invalid("end", "None", "the end of the perfect track (m) when no samples are given"));
        }
    };
    for (i, item) in defects.iter().enumerate() {
        let d = item.cast::<PyDict>().map_err(|_| invalid(&format!("defects[{i}]"), "?", "a dict with a `type`"))?;
        let num = |k: &str, default: Option<f64>| -> PyResult<f64> {
            match d.get_item(k)? {
                Some(v) => v.extract::<f64>().map_err(|_| invalid(&format!("defects[{i}].{k}"), v, "a number (m)")),
                None => default.ok_or_else(|| invalid(&format!("defects[{i}].{k}"), "missing", "a number (m)")),
            }
        };
        let kind: String = d
            .get_item("type")?
            .ok_or_else(|| invalid(&format!("defects[{i}].type"), "missing", "\"cosine_dip\", \"cusp\" or \"twist\""))?
            .extract()?;
        let defect = match kind.as_str() {
            "cosine_dip" => Defect::CosineDip {
                start: num("start", None)?,
                length: num("length", None)?,
                depth: num("depth", None)?,
            },
            "cusp" => Defect::Cusp { at: num("at", None)?, length: num("length", None)?, depth: num("depth", None)? },
            "twist" => Defect::Twist {
                start: num("start", None)?,
                base: num("base", None)?,
                cross_level: num("cross_level", None)?,
                hold: num("hold", Some(0.0))?,
            },
            other => {
                return Err(invalid(
                    &format!("defects[{i}].type"),
                    format!("{other:?}"),
                    "\"cosine_dip\", \"cusp\" or \"twist\"",
                ));
            }
        };
        irr.add_defect(&defect).map_err(to_py)?;
    }
    to_dict(py, &irr)
}

/// One-sided PSD (m² per rad/m) of `channel` of the spectrum `kind` (and `track_class`) at
/// the spatial angular frequencies `omega` (rad/m): `TrackSpectrum::psd`.
#[pyfunction]
#[pyo3(signature = (kind, channel_name, omega, *, track_class=None))]
pub fn track_psd<'py>(
    py: Python<'py>,
    kind: &str,
    channel_name: &str,
    omega: PyReadonlyArray1<'py, f64>,
    track_class: Option<i64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let s = spectrum(kind, track_class)?;
    let c = channel(channel_name)?;
    let w = omega.as_slice().map_err(|_| invalid("omega", "?", "a contiguous 1-D float64 array"))?;
    if let Some(x) = w.iter().find(|x| !(x.is_finite() && **x > 0.0)) {
        return Err(invalid("omega", x, "spatial angular frequencies > 0 rad/m"));
    }
    Ok(PyArray1::from_vec(py, w.iter().map(|&x| s.psd(c, x)).collect()))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(track_irregularity, m)?)?;
    m.add_function(wrap_pyfunction!(track_irregularity_defects, m)?)?;
    m.add_function(wrap_pyfunction!(track_psd, m)?)?;
    Ok(())
}
