//! Work–precision sweeps (`railslosh bench`): run time against error.

use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::compute;

/// Names of the work–precision sweeps.
#[pyfunction]
pub(crate) fn work_precision_cases() -> Vec<&'static str> {
    railslosh_cases::work_precision::CASES.to_vec()
}

/// Run one work–precision sweep; returns one dict per point: `case`, `reference`,
/// `settings` (dict), `wall_s`, `steps`, `newton_iterations`, `jacobians`, `errors` (dict),
/// `failure` (str or None).
#[pyfunction]
#[pyo3(signature = (case, quick=false))]
pub(crate) fn run_work_precision<'py>(py: Python<'py>, case: String, quick: bool) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let points = compute(py, move || railslosh_cases::work_precision::run_case(&case, quick))?;
    points
        .into_iter()
        .map(|p| {
            let d = PyDict::new(py);
            d.set_item("case", p.case)?;
            d.set_item("reference", p.reference)?;
            let s = PyDict::new(py);
            for (k, v) in p.settings {
                s.set_item(k, v)?;
            }
            d.set_item("settings", s)?;
            d.set_item("wall_s", p.wall_s)?;
            d.set_item("steps", p.steps)?;
            d.set_item("newton_iterations", p.newton_iterations)?;
            d.set_item("jacobians", p.jacobians)?;
            let e = PyDict::new(py);
            for (k, v) in p.errors {
                e.set_item(k, v)?;
            }
            d.set_item("errors", e)?;
            d.set_item("failure", p.failure)?;
            d.set_item("history_t", p.history.0)?;
            d.set_item("history", p.history.1)?;
            Ok(d)
        })
        .collect()
}
