//! Plans from Python: a problem built in code or a case file's, run without the GIL, logged
//! and reported as `dlo plan` does.

use crate::errors::setup_error;
use crate::model::{End, StaticProblem, static_settings};
use crate::observer::PyObserver;
use dlo_planner::output::mcap_log::PlanLog;
use dlo_planner::planner::{PlanProblem, PlanReport, PlanSettings, Planner};
use dlo_planner::scene::Obstacle;
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

/// Plans how the controlled end (`s = L`) takes the rod held as `problem` says from `start` to
/// `goal` (see `dlo_planner.plan`).
#[pyfunction]
#[pyo3(signature = (problem, start, goal, settings=None, solver=None, progress=None, log_dir=None, name="plan", max_speed=None, max_angular_speed=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn plan(
    py: Python<'_>,
    problem: &StaticProblem,
    start: &End,
    goal: &End,
    settings: Option<&Bound<'_, PyAny>>,
    solver: Option<&Bound<'_, PyAny>>,
    progress: Option<Py<PyAny>>,
    log_dir: Option<PathBuf>,
    name: &str,
    max_speed: Option<f64>,
    max_angular_speed: Option<f64>,
) -> PyResult<Py<PyAny>> {
    let settings: PlanSettings = crate::settings::merged(settings, "plan")?;
    let static_settings = static_settings(solver)?;
    let held = problem.build()?;
    let (start, goal) = (start.resolve(&held)?, goal.resolve(&held)?);
    let mut plan_problem = PlanProblem::new(held, start, goal);
    plan_problem.static_settings = static_settings;
    let speeds = speed_limits(max_speed, max_angular_speed)?;
    let t0 = Instant::now();
    let planner = py
        .detach(|| Planner::with_contact_samples(&problem.builder, plan_problem, settings))
        .map_err(setup_error)?;
    let obstacles = planner.obstacles.clone();
    let run = Run {
        name: name.to_string(),
        obstacles,
        endpoints_s: t0.elapsed().as_secs_f64(),
        progress,
        log_dir,
        speeds,
    };
    run.go(py, &planner)
}

/// The validated speed limits of a time parameterisation (`None` without one).
pub(crate) fn speed_limits(v: Option<f64>, w: Option<f64>) -> PyResult<Option<[f64; 2]>> {
    dlo_planner::planner::trajectory::speed_limits(v, w).map_err(crate::errors::settings_error)
}

/// One run of a ready planner and what to do with it.
pub(crate) struct Run {
    pub(crate) name: String,
    pub(crate) obstacles: Vec<Arc<Obstacle>>,
    /// Seconds the start and goal solves took.
    pub(crate) endpoints_s: f64,
    pub(crate) progress: Option<Py<PyAny>>,
    pub(crate) log_dir: Option<PathBuf>,
    pub(crate) speeds: Option<[f64; 2]>,
}

impl Run {
    /// Runs the plan without the GIL; writes the log and the trajectory CSV (when `log_dir` is
    /// set, as `dlo plan` writes them); returns a `dlo_planner.results.Plan`, or raises what
    /// the progress callback raised (a `KeyboardInterrupt` on Ctrl-C) once the log is
    /// finished.
    pub(crate) fn go(self, py: Python<'_>, planner: &Planner) -> PyResult<Py<PyAny>> {
        let log = match &self.log_dir {
            Some(dir) => Some(crate::logs::open(dir, &self.name)?),
            None => None,
        };
        let plan_log = log
            .as_ref()
            .map(|(w, _)| PlanLog::new(w.clone(), self.obstacles.clone()));
        let mut obs = PyObserver::new(plan_log, self.progress);
        let (mut result, interrupt) = run_interruptibly(py, planner, &mut obs);
        if obs.error.is_none() {
            obs.error = interrupt;
        }
        result.timing_s.endpoints = self.endpoints_s;
        if let Some([v, w]) = self.speeds {
            result.trajectory.time_parameterise(v, w);
        }
        let mut report = PlanReport::new(&self.name, planner, &result);
        if let (Some((w, path)), Some(dir)) = (&log, &self.log_dir) {
            let log_error = obs
                .log
                .as_ref()
                .and_then(|l| l.error())
                .map(|e| dlo_planner::error::causes(e));
            crate::logs::close(w, path)?;
            if let Some(e) = log_error {
                return Err(crate::errors::output_error(path, e));
            }
            report.mcap = Some(path.display().to_string());
            report.log_shapes = obs.log.as_ref().map(|l| l.shapes());
            if result.verdict() != dlo_planner::planner::PlanVerdict::Interrupted {
                let csv = dir.join(format!("{}.trajectory.csv", self.name));
                crate::logs::write(&csv, &result.trajectory.to_csv())?;
                report.trajectory_csv = Some(csv.display().to_string());
            }
        }
        if let Some(e) = obs.error {
            return Err(e);
        }
        let text = serde_json::to_string(&report).expect("report serialises");
        let class = py.import("dlo_planner.results")?.getattr("Plan")?;
        let (planned, replayed) = (shapes(obs.planned), shapes(obs.replayed));
        Ok(class.call1((text, planned, replayed))?.unbind())
    }
}

/// Shapes in increasing `k` as `(k, flat positions)` for the Python `Shapes` class.
fn shapes(mut rows: Vec<(f64, Vec<[f64; 3]>)>) -> (Vec<f64>, Vec<f64>) {
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    let k = rows.iter().map(|r| r.0).collect();
    let x = rows.into_iter().flat_map(|r| r.1).flatten().collect();
    (k, x)
}

/// Runs `planner` on a thread of its own while this one, without the GIL, waits for it and
/// lets Python handle signals every 20 ms: Ctrl-C (`KeyboardInterrupt`, returned) asks the
/// planner to stop, so that the run ends as `interrupted` and its log is finished.
fn run_interruptibly(
    py: Python<'_>,
    planner: &Planner,
    obs: &mut PyObserver,
) -> (dlo_planner::planner::PlanResult, Option<PyErr>) {
    use std::sync::atomic::Ordering;
    use std::sync::mpsc::{RecvTimeoutError, channel};
    let stop = planner.stop_handle();
    py.detach(|| {
        std::thread::scope(|scope| {
            let (done, finished) = channel();
            let worker = scope.spawn(move || {
                let result = planner.run(obs);
                let _ = done.send(());
                result
            });
            let mut interrupt = None;
            loop {
                match finished.recv_timeout(std::time::Duration::from_millis(20)) {
                    Ok(()) | Err(RecvTimeoutError::Disconnected) => break,
                    Err(RecvTimeoutError::Timeout) => {
                        if interrupt.is_none()
                            && let Err(e) = Python::attach(|py| py.check_signals())
                        {
                            stop.store(true, Ordering::Relaxed);
                            interrupt = Some(e);
                        }
                    }
                }
            }
            let result = worker
                .join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
            (result, interrupt)
        })
    })
}
