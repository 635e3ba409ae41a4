//! The planner's MCAP log: a [`PlanObserver`] that writes every shape as it is computed.
//!
//! Topics (all shapes in frame `rod`, see [`super::scene`]):
//!
//! | topic | schema | content |
//! |---|---|---|
//! | `/tf` | `foxglove.FrameTransform` | `world → rod`, gravity down |
//! | `/scene/obstacles` | `foxglove.SceneUpdate` | obstacles as primitives (when there are any) |
//! | `/rod/endpoints`, `/rod/straight`, `/rod/optimal`, `/rod/feasible` | `foxglove.SceneUpdate` | the rod |
//! | `/end_pose/optimal`, `/end_pose/feasible` | `foxglove.PoseInFrame` | controlled end `s = L` |
//! | `/metrics/…` (same four) | JSON | `k`, energy terms, clearance, deviation, stability |
//! | `/reactions/feasible` | JSON | reaction forces of each replayed shape |
//! | `/optimiser/progress` | JSON | per outer iteration: smoothed and sampled max, violation, penalty |
//! | `/optimiser/worst` | `foxglove.SceneUpdate` | the worst sampled shape of each iterate |
//!
//! Log time: path parameter `k` ↦ `10 k` seconds, so the timeline scrubs the deformation, and
//! the optimal and feasible paths sit at the same times. Optimiser iterations are `0.1 s` apart.

use super::scene::{color, end_pose, gravity_transform, obstacles_update, rod_update, time_of_k};
use super::writer::{LogError, McapWriter};
use crate::model::Model;
use crate::obstacle::Obstacle;
use crate::planner::observer::{PathKind, PlanObserver, Progress, ShapeRecord};
use serde_json::json;
use std::fs::File;
use std::io::BufWriter;
use std::sync::{Arc, Mutex};

/// A log file shared with a signal handler (which finishes it on Ctrl-C).
pub type SharedWriter = Arc<Mutex<McapWriter<BufWriter<File>>>>;

/// Locks a shared log; a writer whose holder panicked is still usable (it only appends).
pub fn lock(w: &SharedWriter) -> std::sync::MutexGuard<'_, McapWriter<BufWriter<File>>> {
    match w.lock() {
        Ok(g) => g,
        Err(p) => p.into_inner(),
    }
}

/// The scene every log starts with at time 0: the gravity transform and the obstacles.
fn scene_start(
    w: &mut McapWriter<BufWriter<File>>,
    obstacles: &[Arc<Obstacle>],
    length: f64,
) -> Result<(), LogError> {
    w.proto("/tf", 0, &gravity_transform(0))?;
    if !obstacles.is_empty() {
        w.proto(
            "/scene/obstacles",
            0,
            &obstacles_update(0, obstacles, length),
        )?;
    }
    Ok(())
}

/// Writes the planner's shapes to an MCAP file.
pub struct PlanLog {
    writer: SharedWriter,
    obstacles: Vec<Arc<Obstacle>>,
    error: Option<LogError>,
    iterations: u64,
    shapes: u64,
}

fn metrics_schema() -> serde_json::Value {
    json!({
        "type": "object",
        "properties": {
            "k": {"type": "number"},
            "energy": {"type": "object", "properties": {
                "total": {"type": "number"}, "flexural": {"type": "number"},
                "torsional": {"type": "number"}, "extensional": {"type": "number"},
                "gravitational": {"type": "number"}, "work": {"type": "number"}}},
            "clearance": {"type": ["number", "null"]},
            "deviation": {"type": ["number", "null"]},
            "stable": {"type": ["boolean", "null"]},
            "violation": {"type": ["number", "null"]}
        }
    })
}

impl PlanLog {
    /// A log on `writer` for a problem with `obstacles`.
    pub fn new(writer: SharedWriter, obstacles: Vec<Arc<Obstacle>>) -> Self {
        PlanLog {
            writer,
            obstacles,
            error: None,
            iterations: 0,
            shapes: 0,
        }
    }

    /// The first write error, if any (logging stops at it).
    pub fn error(&self) -> Option<&LogError> {
        self.error.as_ref()
    }

    /// Rod shapes written.
    pub fn shapes(&self) -> u64 {
        self.shapes
    }

    fn with(&mut self, f: impl FnOnce(&mut McapWriter<BufWriter<File>>) -> Result<(), LogError>) {
        if self.error.is_some() {
            return;
        }
        let mut w = lock(&self.writer);
        if w.is_finished() {
            return;
        }
        if let Err(e) = f(&mut w) {
            self.error = Some(e);
        }
    }
}

fn topic(kind: PathKind) -> &'static str {
    match kind {
        PathKind::Endpoint => "endpoints",
        PathKind::Straight => "straight",
        PathKind::Iterate => "iterate",
        PathKind::Optimal => "optimal",
        PathKind::Feasible => "feasible",
    }
}

/// Boundary positions of `a` in case units.
pub fn rod_points(model: &Model, a: &[f64]) -> Vec<[f64; 3]> {
    let l = model.rod.length;
    model
        .evaluate(a)
        .positions
        .iter()
        .map(|p| p.map(|v| v * l))
        .collect()
}

impl PlanObserver for PlanLog {
    fn begin(&mut self, model: &Model) {
        let obstacles = self.obstacles.clone();
        let l = model.rod.length;
        self.with(|w| {
            scene_start(w, &obstacles, l)?;
            w.flush()
        });
    }

    fn phase(&mut self, _name: &str) {
        self.with(|w| w.flush());
    }

    fn shape(&mut self, model: &Model, r: &ShapeRecord) {
        let t = time_of_k(r.k);
        let pts = rod_points(model, r.a);
        let name = topic(r.kind);
        let c = match r.kind {
            PathKind::Endpoint => color(0.3, 0.3, 0.3, 1.0),
            PathKind::Straight => color(0.6, 0.6, 0.6, 0.8),
            PathKind::Iterate => color(0.9, 0.6, 0.1, 1.0),
            PathKind::Optimal => color(0.1, 0.4, 0.9, 1.0),
            PathKind::Feasible => color(0.9, 0.2, 0.2, 1.0),
        };
        let radius = model.rod.radius;
        let angles = model.angles_at(r.a, 1.0);
        let end = *pts.last().expect("at least two boundaries");
        let e = r.energy;
        let metrics = json!({
            "k": r.k,
            "energy": {
                "total": e.potential(), "flexural": e.flexural, "torsional": e.torsional,
                "extensional": e.extensional, "gravitational": e.gravitational, "work": e.work,
            },
            "clearance": r.clearance,
            "deviation": r.deviation,
            "stable": r.stable,
            "violation": r.violation,
        });
        let reactions =
            (!r.reactions.is_empty()).then(|| json!({"k": r.k, "reactions": r.reactions}));
        self.with(|w| {
            w.proto(
                &format!("/rod/{name}"),
                t,
                &rod_update(t, "rod", &pts, radius, c),
            )?;
            if matches!(r.kind, PathKind::Optimal | PathKind::Feasible) {
                w.proto(&format!("/end_pose/{name}"), t, &end_pose(t, end, angles))?;
            }
            w.json(
                &format!("/metrics/{name}"),
                "dlo.ShapeMetrics",
                &metrics_schema(),
                t,
                &metrics,
            )?;
            if let (PathKind::Feasible, Some(rj)) = (r.kind, &reactions) {
                w.json(
                    "/reactions/feasible",
                    "dlo.Reactions",
                    &json!({"type": "object"}),
                    t,
                    rj,
                )?;
            }
            Ok(())
        });
        self.shapes += 1;
    }

    fn progress(&mut self, model: &Model, p: &Progress, worst: &[f64]) {
        self.iterations += 1;
        let t = self.iterations * 100_000_000;
        let pts = rod_points(model, worst);
        let radius = model.rod.radius;
        let msg = json!({
            "start": p.start, "stage": p.stage, "outer": p.outer,
            "smoothed_max": p.smoothed_max, "sampled_max": p.sampled_max,
            "k_worst": p.k_worst, "violation": p.violation, "rho": p.rho,
        });
        self.with(|w| {
            w.json(
                "/optimiser/progress",
                "dlo.OptimiserProgress",
                &json!({"type": "object"}),
                t,
                &msg,
            )?;
            w.proto(
                "/optimiser/worst",
                t,
                &rod_update(t, "worst", &pts, radius, color(0.9, 0.6, 0.1, 1.0)),
            )
        });
    }
}

/// Logs one static solve (`dlo shape`) at time 0: obstacles, transform, rod, metrics.
pub fn log_static(
    writer: &SharedWriter,
    model: &Model,
    obstacles: &[Arc<Obstacle>],
    a: &[f64],
    metrics: &serde_json::Value,
) -> Result<(), LogError> {
    let mut w = lock(writer);
    let pts = rod_points(model, a);
    let end = *pts.last().expect("at least two boundaries");
    scene_start(&mut w, obstacles, model.rod.length)?;
    w.proto(
        "/rod/shape",
        0,
        &rod_update(0, "rod", &pts, model.rod.radius, color(0.1, 0.4, 0.9, 1.0)),
    )?;
    w.proto(
        "/end_pose/shape",
        0,
        &end_pose(0, end, model.angles_at(a, 1.0)),
    )?;
    w.json(
        "/metrics/shape",
        "dlo.ShapeReport",
        &json!({"type": "object"}),
        0,
        metrics,
    )?;
    Ok(())
}

/// Logs a margin computation: the last shape that held for every point and direction on
/// `/grasp/held_shape` (0.1 s apart, in table order) with its limits on `/grasp/limits`.
pub fn log_margin(
    writer: &SharedWriter,
    model: &Model,
    obstacles: &[Arc<Obstacle>],
    margin: &crate::grasp::Margin,
) -> Result<(), LogError> {
    let mut w = lock(writer);
    scene_start(&mut w, obstacles, model.rod.length)?;
    for (i, lim) in margin.table.iter().enumerate() {
        let t = i as u64 * 100_000_000;
        w.proto(
            "/grasp/held_shape",
            t,
            &rod_update(
                t,
                "rod",
                &lim.held_shape,
                model.rod.radius,
                color(0.1, 0.4, 0.9, 1.0),
            ),
        )?;
        w.json(
            "/grasp/limits",
            "dlo.GraspLimit",
            &json!({"type": "object"}),
            t,
            &serde_json::to_value(lim).expect("limit serialises"),
        )?;
    }
    Ok(())
}
