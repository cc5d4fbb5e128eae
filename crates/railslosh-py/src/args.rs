//! A run's settings passed as one dict instead of long keyword lists (issue 18): the vehicle
//! runs' `train` and `cargo`, the slosh run's `scenario`. The stubs type each dict
//! (`railslosh._core.TrainArgs`, ...); here they are read key by key into the Rust scenario.

use ancf_core::error::invalid;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The keyword arguments of a run held in one dict (`train`, `cargo`), read key by key: a value
/// of the wrong type is a `TypeError` naming its key and value, a missing required key or an
/// unknown one a `ValueError` naming it, and `None` or a left-out key means the default.
pub(crate) struct Args<'a, 'py> {
    d: &'a Bound<'py, PyDict>,
    what: &'static str,
    read: Vec<&'static str>,
}

impl<'a, 'py> Args<'a, 'py> {
    pub(crate) fn new(what: &'static str, d: &'a Bound<'py, PyDict>) -> Self {
        Self { d, what, read: Vec::new() }
    }

    /// The value of `key`, `None` when it is left out or `None`.
    pub(crate) fn opt<T: for<'b> FromPyObject<'b, 'py>>(&mut self, key: &'static str) -> PyResult<Option<T>>
    where
        for<'b> <T as FromPyObject<'b, 'py>>::Error: Into<PyErr>,
    {
        self.read.push(key);
        let Some(v) = self.d.get_item(key)? else { return Ok(None) };
        if v.is_none() {
            return Ok(None);
        }
        v.extract::<T>().map(Some).map_err(|e| named_type_error(key, &v, e.into()))
    }

    /// The value of `key`, which must be given.
    pub(crate) fn req<T: for<'b> FromPyObject<'b, 'py>>(&mut self, key: &'static str) -> PyResult<T>
    where
        for<'b> <T as FromPyObject<'b, 'py>>::Error: Into<PyErr>,
    {
        let what = self.what;
        self.opt(key)?.ok_or_else(|| crate::to_py(invalid(&format!("{what}.{key}"), "missing", "a value")))
    }

    /// Checks that every key of the dict was read: a misspelt one is an error, not a setting
    /// silently left at its default.
    pub(crate) fn finish(self) -> PyResult<()> {
        for k in self.d.keys() {
            let k: String = k.extract()?;
            if !self.read.contains(&k.as_str()) {
                return Err(crate::to_py(invalid(self.what, &k, &format!("keys among {:?}", self.read))));
            }
        }
        Ok(())
    }
}

/// An argument `name` of a class constructor, read with an error that names it: a wrong type
/// is a `TypeError` ([`named_type_error`]); a value the type cannot hold (a negative count, a
/// point of two coordinates) a `ValueError` in the same form. Functions get the name from
/// `railslosh.limits.name_native_arguments`; classes cannot be wrapped that way, so their
/// constructors read each argument through a reader of [`named_readers!`].
pub(crate) fn named<'py, T>(name: &str, obj: &Bound<'py, PyAny>) -> PyResult<T>
where
    T: for<'b> FromPyObject<'b, 'py>,
    for<'b> <T as FromPyObject<'b, 'py>>::Error: Into<PyErr>,
{
    obj.extract::<T>().map_err(|e| {
        let e: PyErr = e.into();
        let py = obj.py();
        if e.is_instance_of::<pyo3::exceptions::PyTypeError>(py) {
            named_type_error(name, obj, e)
        } else {
            let shown = obj.repr().map_or_else(|_| "?".to_string(), |r| r.to_string());
            let why = if e.is_instance_of::<pyo3::exceptions::PyOverflowError>(py) {
                format!("expected a non-negative integer in range ({})", e.value(py))
            } else {
                e.value(py).to_string()
            };
            pyo3::exceptions::PyValueError::new_err(format!("invalid `{name}` = {shown}: {why}"))
        }
    })
}

/// `from_py_with` readers, one per argument name, that name their argument in errors
/// ([`named`]): `named_readers!(fluid_arg { density: f64, consistency: Option<f64> })` makes
/// `fluid_arg::density` and `fluid_arg::consistency` (`None` reads as not given).
macro_rules! named_readers {
    ($module:ident { $($name:ident : $ty:ty),* $(,)? }) => {
        mod $module {
            use pyo3::prelude::*;
            $(pub(super) fn $name(obj: &Bound<'_, PyAny>) -> PyResult<$ty> {
                $crate::args::named(stringify!($name), obj)
            })*
        }
    };
}
pub(crate) use named_readers;

/// The `TypeError` of an argument `name` whose value `obj` has the wrong type (`error`, PyO3's),
/// in the one form of input errors: ``invalid `t_end` = 'x': must be real number, not str``.
/// PyO3 itself names the argument only in an exception note, which `str(error)` leaves out.
pub(crate) fn named_type_error(name: &str, obj: &Bound<'_, PyAny>, error: PyErr) -> PyErr {
    let shown = obj.repr().map_or_else(|_| "?".to_string(), |r| r.to_string());
    pyo3::exceptions::PyTypeError::new_err(format!("invalid `{name}` = {shown}: {}", error.value(obj.py())))
}
