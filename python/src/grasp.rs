//! Grasp margins from Python (paper §6): a grasp built in code or a case file's, computed
//! without the GIL, logged and reported as `dlo margin` does.

use crate::errors::{build_error, settings_error};
use crate::model::{StaticProblem, static_settings};
use dlo_planner::grasp::{Grasp, GraspProblem, GraspSettings, MarginReport};
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

/// The disturbance force margin of the grasp `problem` holds (fingers are position
/// constraints with one bound; see `dlo_planner.grasp_margin`).
#[pyfunction]
#[pyo3(signature = (problem, settings=None, initial=None, solver=None, progress=None, log_dir=None, name="grasp"))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn grasp_margin(
    py: Python<'_>,
    problem: &StaticProblem,
    settings: Option<&Bound<'_, PyAny>>,
    initial: Option<Vec<f64>>,
    solver: Option<&Bound<'_, PyAny>>,
    progress: Option<Py<PyAny>>,
    log_dir: Option<PathBuf>,
    name: &str,
) -> PyResult<Py<PyAny>> {
    let settings: GraspSettings = crate::settings::merged(settings, "grasp")?;
    let static_settings = static_settings(solver)?;
    let built = problem.build()?;
    let initial = problem.initial(&built, initial, static_settings.perturbation)?;
    let grasp_problem = GraspProblem {
        statics: problem.builder.clone(),
        initial,
        static_settings,
    };
    let grasp = py
        .detach(|| Grasp::new(grasp_problem, settings))
        .map_err(settings_error)?;
    margin(py, &grasp, name, progress, log_dir.as_deref())
}

/// Computes the margin of a solved grasp, logs it to `log_dir/<name>.mcap` when asked and
/// returns a `dlo_planner.results.Margin`.
pub(crate) fn margin(
    py: Python<'_>,
    grasp: &Grasp,
    name: &str,
    progress: Option<Py<PyAny>>,
    log_dir: Option<&Path>,
) -> PyResult<Py<PyAny>> {
    let raised: Mutex<Option<PyErr>> = Mutex::new(None);
    let report = |done: usize, total: usize| {
        let Some(cb) = &progress else { return };
        let mut raised = raised.lock().unwrap_or_else(|e| e.into_inner());
        if raised.is_none() {
            let called = Python::attach(|py| {
                let info = pyo3::types::PyDict::new(py);
                info.set_item("done", done)?;
                info.set_item("total", total)?;
                cb.call1(py, ("margin", info)).map(drop)
            });
            *raised = called.err();
        }
    };
    let t0 = Instant::now();
    let margin = py.detach(|| grasp.margin(&report)).map_err(build_error)?;
    let secs = t0.elapsed().as_secs_f64();
    if let Some(e) = raised.into_inner().unwrap_or_else(|e| e.into_inner()) {
        return Err(e);
    }
    let mut report = MarginReport {
        case: name,
        margin: &margin,
        mcap: None,
        timing_s: secs,
    };
    if let Some(dir) = log_dir {
        let (w, path) = crate::logs::open(dir, name)?;
        let p = &grasp.base;
        let logged = dlo_planner::output::mcap_log::log_margin(
            &w,
            &p.model,
            &p.obstacles(),
            &grasp.finger_contacts(),
            &margin,
        );
        let closed = crate::logs::close(&w, &path);
        logged.map_err(|e| crate::errors::output_error(&path, dlo_planner::error::causes(&e)))?;
        closed?;
        report.mcap = Some(path.display().to_string());
    }
    let text = serde_json::to_string(&report).expect("report serialises");
    let class = py.import("dlo_planner.results")?.getattr("Margin")?;
    Ok(class.call1((text,))?.unbind())
}
