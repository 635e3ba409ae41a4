//! Static shapes: a solve or an evaluation, its report (the CLI's `dlo shape --json`), the
//! shape sampled along the rod, and its log.

use crate::errors::input_error;
use dlo_planner::statics::report::ShapeReport;
use dlo_planner::statics::{StaticOptions, StaticProblem, evaluate_shape, solve_static};
use pyo3::prelude::*;
use std::path::Path;
use std::time::Instant;

/// One static solve to run.
pub(crate) struct Job {
    pub(crate) name: String,
    pub(crate) problem: StaticProblem,
    pub(crate) initial: Vec<f64>,
    pub(crate) options: StaticOptions,
    pub(crate) report_points: Vec<f64>,
    pub(crate) points: Option<usize>,
}

/// Solves `job` without the GIL, logs it to `log_dir/<name>.mcap` when asked (as `dlo
/// shape` does) and returns a `dlo_planner.results.StaticShape`.
pub(crate) fn solve(py: Python<'_>, mut job: Job, log_dir: Option<&Path>) -> PyResult<Py<PyAny>> {
    check_points(&job.problem, &job.report_points, job.points)?;
    let (sol, secs) = py.detach(|| {
        let t0 = Instant::now();
        let sol = solve_static(&mut job.problem, &job.initial, &job.options);
        (sol, t0.elapsed().as_secs_f64())
    });
    let report = ShapeReport::solved(&job.name, &job.problem, &sol, &job.report_points, secs);
    let text = match log_dir {
        None => serde_json::to_string(&report).expect("report serialises"),
        Some(dir) => {
            let mut value = serde_json::to_value(&report).expect("report serialises");
            let path = crate::logs::log_static(dir, &job.name, &job.problem, &sol.a, &value)?;
            value["mcap"] = path.display().to_string().into();
            value.to_string()
        }
    };
    result(py, "StaticShape", text, job.problem, &sol.a, job.points)
}

/// Evaluates coefficients `a` without optimising (`dlo energy`).
pub(crate) fn evaluate(
    py: Python<'_>,
    name: &str,
    mut problem: StaticProblem,
    a: Vec<f64>,
    report_points: Vec<f64>,
    points: Option<usize>,
) -> PyResult<Py<PyAny>> {
    check_points(&problem, &report_points, points)?;
    let t0 = Instant::now();
    let ev = py.detach(|| evaluate_shape(&mut problem, &a));
    let secs = t0.elapsed().as_secs_f64();
    let report = ShapeReport::evaluated(name, &problem, ev, &a, &report_points, secs);
    let text = serde_json::to_string(&report).expect("report serialises");
    result(py, "StaticShape", text, problem, &a, points)
}

fn check_points(p: &StaticProblem, report_points: &[f64], points: Option<usize>) -> PyResult<()> {
    let l = p.model.rod.length;
    if let Some(i) = report_points.iter().position(|s| !(0.0..=l).contains(s)) {
        return Err(input_error(
            Some(&format!("report_points[{i}]")),
            format!("arc length {} outside [0, {l}]", report_points[i]),
        ));
    }
    if let Some(points) = points
        && !(2..=100_000).contains(&points)
    {
        return Err(input_error(
            Some("points"),
            format!("must be in 2..=100000, got {points}"),
        ));
    }
    Ok(())
}

/// The Python result class `class_name` of `dlo_planner.results`, from a report and the
/// shape `a` of `p`, sampled when first read (see [`Samples`]).
pub(crate) fn result(
    py: Python<'_>,
    class_name: &str,
    report: String,
    p: StaticProblem,
    a: &[f64],
    points: Option<usize>,
) -> PyResult<Py<PyAny>> {
    let samples = Samples {
        problem: p,
        a: a.to_vec(),
        points,
    };
    let class = py.import("dlo_planner.results")?.getattr(class_name)?;
    Ok(class.call1((report, a.to_vec(), samples))?.unbind())
}

/// A solved shape held for sampling along the rod when a result's arrays are first read, so
/// that a call that reads only the report does not pay for them.
#[pyclass(frozen, module = "dlo_planner")]
pub(crate) struct Samples {
    problem: StaticProblem,
    a: Vec<f64>,
    points: Option<usize>,
}

#[pymethods]
impl Samples {
    /// `(s, positions, frames)` as flat lists (the Python class reshapes them).
    fn arrays(&self) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let (s, positions, frames) = sampled(&self.problem, &self.a, self.points);
        let positions = positions.into_iter().flatten().collect();
        let frames = frames.into_iter().flatten().flatten().collect();
        (s, positions, frames)
    }
}

/// Arc lengths, positions and frames (rows; columns ξ, η, ζ) at `n` evenly spaced points,
/// or (`None`) at the quadrature mesh's boundaries, where the solve computed them.
#[allow(clippy::type_complexity)]
pub(crate) fn sampled(
    p: &StaticProblem,
    a: &[f64],
    n: Option<usize>,
) -> (Vec<f64>, Vec<[f64; 3]>, Vec<[[f64; 3]; 3]>) {
    let m = &p.model;
    let l = m.rod.length;
    let shape = m.evaluate(a);
    let (t, positions): (Vec<f64>, Vec<[f64; 3]>) = match n {
        None => (m.mesh.boundaries.clone(), shape.positions.clone()),
        Some(n) => {
            let t: Vec<f64> = (0..n).map(|i| i as f64 / (n - 1) as f64).collect();
            let x = t
                .iter()
                .map(|&ti| m.position_at_in(a, &shape, ti))
                .collect();
            (t, x)
        }
    };
    let frames = t.iter().map(|&ti| m.frame_at(a, ti)).collect();
    let s = t.iter().map(|ti| ti * l).collect();
    let positions = positions.iter().map(|x| x.map(|c| c * l)).collect();
    (s, positions, frames)
}

/// Solves `problem` from its natural start `repeats` times in Rust and returns the seconds
/// each took: the reference against which a solve called from Python is timed
/// (`python/benches/static_call.py`).
#[pyfunction]
#[pyo3(signature = (problem, repeats))]
pub(crate) fn solve_repeatedly(
    py: Python<'_>,
    problem: &crate::model::StaticProblem,
    repeats: usize,
) -> PyResult<Vec<f64>> {
    let built = problem.build()?;
    let settings = dlo_planner::statics::StaticSettings::default();
    let initial = built.natural_start(settings.perturbation);
    let options = settings.options();
    Ok(py.detach(|| {
        (0..repeats)
            .map(|_| {
                let t0 = Instant::now();
                let mut p = built.clone();
                let sol = solve_static(&mut p, &initial, &options);
                let report = ShapeReport::solved("shape", &p, &sol, &[], 0.0);
                std::hint::black_box(serde_json::to_string(&report).expect("report serialises"));
                t0.elapsed().as_secs_f64()
            })
            .collect()
    }))
}
