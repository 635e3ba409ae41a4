//! Case files from Python: the same JSON the CLI reads, run as `dlo shape`, `dlo energy`,
//! `dlo plan` and `dlo margin` run it.

use crate::errors::{case_error, input_error};
use pyo3::prelude::*;
use std::path::PathBuf;
use std::time::Instant;

/// A case file, read and validated.
#[pyclass(frozen, module = "dlo_planner")]
pub struct Case {
    inner: dlo_planner::case::Case,
}

#[pymethods]
impl Case {
    /// Reads and validates the case file at `path`.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let inner = py
            .detach(|| dlo_planner::case::load(&path))
            .map_err(case_error)?;
        Ok(Case { inner })
    }

    /// Parses case JSON `text`; `path` names it in errors and anchors relative mesh paths.
    #[staticmethod]
    #[pyo3(signature = (text, path=None))]
    fn parse(text: &str, path: Option<PathBuf>) -> PyResult<Self> {
        let path = path.unwrap_or_else(|| PathBuf::from("<string>"));
        let inner = dlo_planner::case::parse(text, &path).map_err(case_error)?;
        Ok(Case { inner })
    }

    /// The case's name (its logs are `<name>.mcap`).
    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }

    /// Its description.
    #[getter]
    fn description(&self) -> String {
        self.inner.description.clone()
    }

    /// Legal but suspicious values, each with what was assumed (the CLI prints them).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.inner.warnings.clone()
    }

    /// The case's static problem, to change or solve in code.
    #[getter]
    fn problem(&self) -> crate::model::StaticProblem {
        crate::model::StaticProblem {
            builder: self.inner.builder.clone(),
            built: Default::default(),
            spatial: self.inner.problem.model.layout.spatial,
            length: self.inner.problem.model.rod.length,
        }
    }

    /// The static shape, as `dlo shape` computes it (and logs it, to `log_dir/<name>.mcap`).
    #[pyo3(signature = (points=None, log_dir=None))]
    fn solve(
        &self,
        py: Python<'_>,
        points: Option<usize>,
        log_dir: Option<PathBuf>,
    ) -> PyResult<Py<PyAny>> {
        let c = &self.inner;
        let job = crate::shape::Job {
            name: c.name.clone(),
            problem: c.problem.clone(),
            initial: c.initial.clone(),
            options: c.options,
            report_points: c.report_points.clone(),
            points,
        };
        crate::shape::solve(py, job, log_dir.as_deref())
    }

    /// The case's explicit `shape` coefficients evaluated without optimising (`dlo energy`).
    #[pyo3(signature = (points=None))]
    fn evaluate(&self, py: Python<'_>, points: Option<usize>) -> PyResult<Py<PyAny>> {
        let c = &self.inner;
        if !c.explicit_shape {
            return Err(input_error(
                Some("shape"),
                format!(
                    "{}: evaluating needs explicit coefficients",
                    c.path.display()
                ),
            ));
        }
        let (p, a, pts) = (
            c.problem.clone(),
            c.initial.clone(),
            c.report_points.clone(),
        );
        crate::shape::evaluate(py, &c.name, p, a, pts, points)
    }

    /// The case's plan, as `dlo plan` computes it (see `dlo_planner.plan` for the arguments).
    #[pyo3(signature = (progress=None, log_dir=None, max_speed=None, max_angular_speed=None))]
    fn plan(
        &self,
        py: Python<'_>,
        progress: Option<Py<PyAny>>,
        log_dir: Option<PathBuf>,
        max_speed: Option<f64>,
        max_angular_speed: Option<f64>,
    ) -> PyResult<Py<PyAny>> {
        let speeds = crate::plan::speed_limits(max_speed, max_angular_speed)?;
        let t0 = Instant::now();
        use dlo_planner::case::plan::{plan_problem, planner, setup_error};
        use dlo_planner::planner::PlanSetupError;
        let (problem, settings) = plan_problem(&self.inner).map_err(case_error)?;
        let planner = py
            .detach(|| planner(&self.inner, problem, settings))
            .map_err(|e| match e {
                PlanSetupError::Unreachable { end, message } => {
                    let path = self.inner.path.display();
                    crate::errors::unreachable_error(
                        &format!("plan.{end}"),
                        format!("{path}: {message}"),
                    )
                }
                other => case_error(setup_error(&self.inner, other)),
            })?;
        let run = crate::plan::Run {
            name: self.inner.name.clone(),
            obstacles: self.inner.obstacles.clone(),
            endpoints_s: t0.elapsed().as_secs_f64(),
            progress,
            log_dir,
            speeds,
        };
        run.go(py, &planner)
    }

    /// The grasp's disturbance force margin, as `dlo margin` computes it.
    #[pyo3(signature = (progress=None, log_dir=None))]
    fn margin(
        &self,
        py: Python<'_>,
        progress: Option<Py<PyAny>>,
        log_dir: Option<PathBuf>,
    ) -> PyResult<Py<PyAny>> {
        let grasp = py
            .detach(|| dlo_planner::grasp::Grasp::from_case(&self.inner))
            .map_err(case_error)?;
        crate::grasp::margin(py, &grasp, &self.inner.name, progress, log_dir.as_deref())
    }

    fn __repr__(&self) -> String {
        format!(
            "Case({:?} from {})",
            self.inner.name,
            self.inner.path.display()
        )
    }
}
