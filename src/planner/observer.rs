//! What the planner tells the outside world while it works: every shape it computes and the
//! optimiser's progress. The library prints nothing; the CLI's progress line and the MCAP log
//! are observers.

use crate::rod::energy::EnergyTerms;
use crate::rod::model::Model;
use crate::statics::Reaction;
use std::sync::atomic::{AtomicBool, Ordering};

/// Which computation a shape belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PathKind {
    /// The start and goal static solves.
    Endpoint,
    /// The straight-line path `c = 0`.
    Straight,
    /// The worst shape of an optimiser iterate.
    Iterate,
    /// The optimal path on the verification grid.
    Optimal,
    /// The feasibility replay.
    Feasible,
}

/// One computed shape.
#[derive(Clone, Copy, Debug)]
pub struct ShapeRecord<'a> {
    /// Which computation produced it.
    pub kind: PathKind,
    /// Path parameter `k ∈ [0, 1]`.
    pub k: f64,
    /// Ritz coefficients.
    pub a: &'a [f64],
    /// Energy terms in the case's units.
    pub energy: EnergyTerms,
    /// Smallest clearance to any obstacle (case units; `None` without obstacles).
    pub clearance: Option<f64>,
    /// Distance to the optimal path's shape at the same `k` (replay only, case units).
    pub deviation: Option<f64>,
    /// Stability verdict (replay only).
    pub stable: Option<bool>,
    /// Reactions (replay only).
    pub reactions: &'a [Reaction],
    /// Constraint violation of the static solve (endpoints and replay; units of L).
    pub violation: Option<f64>,
}

/// Progress of the minimax optimiser after one outer iteration.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// Index of the start (multi-start).
    pub start: usize,
    /// Continuation stage (sharpness index).
    pub stage: usize,
    /// Outer iteration within the stage.
    pub outer: usize,
    /// Smoothed maximum (case units).
    pub smoothed_max: f64,
    /// True maximum over the sampled `k` (case units).
    pub sampled_max: f64,
    /// `k` of the sampled maximum.
    pub k_worst: f64,
    /// Constraint violation (dimensionless).
    pub violation: f64,
    /// Penalty parameter.
    pub rho: f64,
}

/// Receives what the planner computes. All methods default to doing nothing.
pub trait PlanObserver {
    /// Called once before anything else with the model every shape refers to.
    fn begin(&mut self, _model: &Model) {}
    /// A phase starts: `"endpoints"`, `"optimise"` (every start optimises, verifies and refines
    /// its plan), `"select"` (the start with the best verified plan is chosen), `"replay"`;
    /// then, where a goal given by its pose alone is planned again to the equilibrium the
    /// gripper's motion reached ([`super::PlanSettings::reached_goal`]), `"reached goal"` and
    /// the same phases again.
    fn phase(&mut self, _name: &str) {}
    /// A shape was computed.
    fn shape(&mut self, _model: &Model, _record: &ShapeRecord) {}
    /// The optimiser finished an outer iteration; `worst` is the shape at `k_worst`.
    fn progress(&mut self, _model: &Model, _p: &Progress, _worst: &[f64]) {}
    /// Asked after every progress report, at every phase and at every replay step: `true`
    /// stops the run (see [`super::Planner::stop_handle`]).
    fn stop_requested(&mut self) -> bool {
        false
    }
}

/// An observer that ignores everything.
#[derive(Clone, Copy, Debug, Default)]
pub struct Silent;

impl PlanObserver for Silent {}

/// Asks `observer` whether to stop and sets `stop` if so; whether the run is to stop.
pub(crate) fn poll(observer: &mut dyn PlanObserver, stop: &AtomicBool) -> bool {
    if observer.stop_requested() {
        stop.store(true, Ordering::Relaxed);
    }
    stop.load(Ordering::Relaxed)
}

/// A shape kept by a [`Recorder`].
#[derive(Clone, Debug)]
struct Recorded {
    kind: PathKind,
    k: f64,
    a: Vec<f64>,
    energy: EnergyTerms,
    clearance: Option<f64>,
    deviation: Option<f64>,
    stable: Option<bool>,
    reactions: Vec<Reaction>,
    violation: Option<f64>,
}

/// Keeps the shapes it is told of, to pass them on later ([`flush`]) or never, and
/// asks `inner` whether to stop: a plan judged before it is chosen logs its replay only if it
/// is chosen.
pub(crate) struct Recorder<'a> {
    inner: &'a mut dyn PlanObserver,
    shapes: Vec<Recorded>,
    /// Phases and the optimiser's progress are passed on to `inner` as they come.
    passing: bool,
}

impl<'a> Recorder<'a> {
    /// A recorder that asks `inner` whether to stop.
    pub(crate) fn new(inner: &'a mut dyn PlanObserver) -> Self {
        Recorder {
            inner,
            shapes: Vec::new(),
            passing: false,
        }
    }

    /// A recorder that also passes on phases and the optimiser's progress to `inner` (a
    /// second search, whose shapes are passed on only where its plan is reported).
    pub(crate) fn passing(inner: &'a mut dyn PlanObserver) -> Self {
        Recorder {
            passing: true,
            ..Recorder::new(inner)
        }
    }

    /// The shapes kept, to pass on with [`flush`].
    pub(crate) fn into_shapes(self) -> RecordedShapes {
        RecordedShapes(self.shapes)
    }
}

/// Shapes a [`Recorder`] kept.
#[derive(Clone, Debug, Default)]
pub(crate) struct RecordedShapes(Vec<Recorded>);

impl RecordedShapes {
    /// The goal shape among them (the end shape at `k = 1`), if any.
    pub(crate) fn goal_shape(&self) -> RecordedShapes {
        RecordedShapes(
            self.0
                .iter()
                .filter(|r| r.kind == PathKind::Endpoint && r.k == 1.0)
                .cloned()
                .collect(),
        )
    }

    /// Gives every optimal-path shape the coefficients, energy and clearance `f(k)` returns
    /// (a replay of another path records that path's shapes as its optimal ones).
    pub(crate) fn set_optimal(
        &mut self,
        mut f: impl FnMut(f64) -> (Vec<f64>, EnergyTerms, Option<f64>),
    ) {
        for r in self.0.iter_mut().filter(|r| r.kind == PathKind::Optimal) {
            (r.a, r.energy, r.clearance) = f(r.k);
        }
    }
}

/// Tells `observer` of every shape in `shapes`, in the order they were computed.
pub(crate) fn flush(shapes: &RecordedShapes, model: &Model, observer: &mut dyn PlanObserver) {
    for r in &shapes.0 {
        observer.shape(
            model,
            &ShapeRecord {
                kind: r.kind,
                k: r.k,
                a: &r.a,
                energy: r.energy,
                clearance: r.clearance,
                deviation: r.deviation,
                stable: r.stable,
                reactions: &r.reactions,
                violation: r.violation,
            },
        );
    }
}

impl PlanObserver for Recorder<'_> {
    fn shape(&mut self, _model: &Model, r: &ShapeRecord) {
        self.shapes.push(Recorded {
            kind: r.kind,
            k: r.k,
            a: r.a.to_vec(),
            energy: r.energy,
            clearance: r.clearance,
            deviation: r.deviation,
            stable: r.stable,
            reactions: r.reactions.to_vec(),
            violation: r.violation,
        });
    }

    fn phase(&mut self, name: &str) {
        if self.passing {
            self.inner.phase(name);
        }
    }

    fn progress(&mut self, model: &Model, p: &Progress, worst: &[f64]) {
        if self.passing {
            self.inner.progress(model, p, worst);
        }
    }

    fn stop_requested(&mut self) -> bool {
        self.inner.stop_requested()
    }
}
