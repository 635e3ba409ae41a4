//! The planner's observer from Python: the MCAP log (as the CLI writes it), a progress
//! callback, and stopping — when the callback returns `True` or raises, the plan ends as
//! `interrupted` with its log finished (Ctrl-C stops it through the planner's stop handle,
//! see `plan.rs`).

use dlo_planner::output::mcap_log::PlanLog;
use dlo_planner::output::mcap_log::plan_log::rod_points;
use dlo_planner::planner::observer::{PathKind, PlanObserver, Progress, ShapeRecord};
use dlo_planner::rod::model::Model;
use pyo3::prelude::*;
use pyo3::types::PyDict;

pub(crate) struct PyObserver {
    pub(crate) log: Option<PlanLog>,
    pub(crate) callback: Option<Py<PyAny>>,
    /// What the callback raised, or the `KeyboardInterrupt`: raised once the log is finished.
    pub(crate) error: Option<PyErr>,
    /// The callback asked to stop.
    pub(crate) stop: bool,
    /// The planned shape at each replay step: `k` and its positions at the mesh boundaries.
    pub(crate) planned: Vec<(f64, Vec<[f64; 3]>)>,
    /// The replayed shape at each replay step, likewise.
    pub(crate) replayed: Vec<(f64, Vec<[f64; 3]>)>,
}

impl PyObserver {
    pub(crate) fn new(log: Option<PlanLog>, callback: Option<Py<PyAny>>) -> Self {
        PyObserver {
            log,
            callback,
            error: None,
            stop: false,
            planned: Vec::new(),
            replayed: Vec::new(),
        }
    }
}

impl PyObserver {
    /// Calls the callback with `(event, info)`, `info` filled by `fill`.
    fn call(&mut self, event: &str, fill: impl FnOnce(&Bound<'_, PyDict>) -> PyResult<()>) {
        let Some(cb) = &self.callback else { return };
        if self.error.is_some() || self.stop {
            return;
        }
        Python::attach(|py| {
            let info = PyDict::new(py);
            let answer = fill(&info).and_then(|()| cb.call1(py, (event, info)));
            match answer {
                Ok(v) => self.stop = v.bind(py).is_truthy().unwrap_or(false),
                Err(e) => self.error = Some(e),
            }
        });
    }
}

impl PlanObserver for PyObserver {
    fn begin(&mut self, model: &Model) {
        if let Some(l) = &mut self.log {
            l.begin(model);
        }
    }

    fn phase(&mut self, name: &str) {
        if let Some(l) = &mut self.log {
            l.phase(name);
        }
        self.call("phase", |d| d.set_item("name", name));
    }

    fn shape(&mut self, model: &Model, r: &ShapeRecord) {
        if let Some(l) = &mut self.log {
            l.shape(model, r);
        }
        match r.kind {
            PathKind::Optimal => self.planned.push((r.k, rod_points(model, r.a))),
            PathKind::Feasible => self.replayed.push((r.k, rod_points(model, r.a))),
            _ => {}
        }
        if r.kind == PathKind::Feasible {
            self.call("replay", |d| {
                d.set_item("k", r.k)?;
                d.set_item("deviation", r.deviation)?;
                d.set_item("energy", r.energy.potential())
            });
        }
    }

    fn progress(&mut self, model: &Model, p: &Progress, worst: &[f64]) {
        if let Some(l) = &mut self.log {
            l.progress(model, p, worst);
        }
        self.call("iteration", |d| {
            d.set_item("start", p.start)?;
            d.set_item("stage", p.stage)?;
            d.set_item("outer", p.outer)?;
            d.set_item("smoothed_max", p.smoothed_max)?;
            d.set_item("sampled_max", p.sampled_max)?;
            d.set_item("k_worst", p.k_worst)?;
            d.set_item("violation", p.violation)?;
            d.set_item("rho", p.rho)
        });
    }

    fn stop_requested(&mut self) -> bool {
        self.stop || self.error.is_some()
    }
}
