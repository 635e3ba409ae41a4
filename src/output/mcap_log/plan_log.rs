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
//! Log time: the run's wall-clock start `t0` (so the viewer's timeline says when it ran) plus
//! `10 k` seconds for path parameter `k`, so the timeline scrubs the deformation, and the
//! optimal and feasible paths sit at the same times. Optimiser iterations are `0.1 s` apart
//! from `t0`.
//!
//! The plan is drawn translucent and the replay thinner and opaque inside it, so the replay
//! stays visible where the two coincide. Every JSON schema uses single types only (what
//! Foxglove's reader accepts): a value that does not exist is left out of the message.

use super::json_schemas;
use super::scene::{
    color, end_pose, gravity_transform, obstacles_update, rod_thickness, rod_update, time_of_k,
    wall_clock_ns,
};
use super::writer::{LogError, McapWriter};
use crate::output::topics;
use crate::planner::observer::{PathKind, PlanObserver, Progress, ShapeRecord};
use crate::rod::model::Model;
use crate::scene::obstacle::Obstacle;
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

/// The scene every log starts with at its start time `t0`: the gravity transform and the
/// obstacles.
fn scene_start(
    w: &mut McapWriter<BufWriter<File>>,
    t0: u64,
    obstacles: &[Arc<Obstacle>],
    length: f64,
) -> Result<(), LogError> {
    w.proto(topics::TRANSFORMS, t0, &gravity_transform(t0))?;
    if !obstacles.is_empty() {
        w.proto(
            topics::OBSTACLES,
            t0,
            &obstacles_update(t0, obstacles, length),
        )?;
    }
    Ok(())
}

/// Writes the planner's shapes to an MCAP file.
pub struct PlanLog {
    writer: SharedWriter,
    obstacles: Vec<Arc<Obstacle>>,
    t0: u64,
    error: Option<LogError>,
    iterations: u64,
    shapes: u64,
}

/// The `/metrics/*` message of one shape (see [`json_schemas::METRICS`]).
fn metrics(r: &ShapeRecord) -> serde_json::Value {
    let e = r.energy;
    let mut m = serde_json::Map::new();
    m.insert("k".into(), json!(r.k));
    m.insert(
        "energy".into(),
        json!({
            "total": e.potential(), "flexural": e.flexural, "torsional": e.torsional,
            "extensional": e.extensional, "gravitational": e.gravitational, "work": e.work,
        }),
    );
    let optional = [
        ("clearance", r.clearance.map(|v| json!(v))),
        ("deviation", r.deviation.map(|v| json!(v))),
        ("stable", r.stable.map(|v| json!(v))),
        ("violation", r.violation.map(|v| json!(v))),
    ];
    for (key, value) in optional {
        if let Some(v) = value {
            m.insert(key.into(), v);
        }
    }
    serde_json::Value::Object(m)
}

impl PlanLog {
    /// A log on `writer` for a problem with `obstacles`, starting at the wall clock's now.
    pub fn new(writer: SharedWriter, obstacles: Vec<Arc<Obstacle>>) -> Self {
        Self::starting_at(writer, obstacles, wall_clock_ns())
    }

    /// A log whose time starts at `t0` (ns since the Unix epoch).
    pub fn starting_at(writer: SharedWriter, obstacles: Vec<Arc<Obstacle>>, t0: u64) -> Self {
        PlanLog {
            writer,
            obstacles,
            t0,
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

/// The rod, end-pose and metrics topics of a kind of path.
fn topics(kind: PathKind) -> (&'static str, &'static str, &'static str) {
    use crate::output::topics::*;
    match kind {
        PathKind::Endpoint => (ROD_ENDPOINTS, "", METRICS_ENDPOINTS),
        PathKind::Straight => (ROD_STRAIGHT, "", METRICS_STRAIGHT),
        PathKind::Iterate => (ROD_ITERATE, "", METRICS_ITERATE),
        PathKind::Optimal => (ROD_OPTIMAL, END_POSE_OPTIMAL, METRICS_OPTIMAL),
        PathKind::Feasible => (ROD_FEASIBLE, END_POSE_FEASIBLE, METRICS_FEASIBLE),
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
        let t0 = self.t0;
        self.with(|w| {
            scene_start(w, t0, &obstacles, l)?;
            w.flush()
        });
    }

    fn phase(&mut self, _name: &str) {
        self.with(|w| w.flush());
    }

    fn shape(&mut self, model: &Model, r: &ShapeRecord) {
        let t = self.t0 + time_of_k(r.k);
        let pts = rod_points(model, r.a);
        let (rod_topic, pose_topic, metrics_topic) = topics(r.kind);
        let thick = rod_thickness(model.rod.radius, model.rod.length);
        // Entity id, colour and thickness: the two end shapes are separate entities (both stay
        // on screen); the plan is a translucent tube with the replay thinner and opaque inside.
        let (id, c, thickness) = match r.kind {
            PathKind::Endpoint if r.k < 0.5 => ("start", color(0.15, 0.65, 0.25, 1.0), thick),
            PathKind::Endpoint => ("goal", color(0.55, 0.2, 0.7, 1.0), thick),
            PathKind::Straight => ("straight", color(0.6, 0.6, 0.6, 0.6), thick),
            PathKind::Iterate => ("iterate", color(0.9, 0.6, 0.1, 1.0), thick),
            PathKind::Optimal => ("optimal", color(0.1, 0.4, 0.9, 0.45), 1.6 * thick),
            PathKind::Feasible => ("feasible", color(0.9, 0.2, 0.2, 1.0), 0.6 * thick),
        };
        let frame = model.frame_at(r.a, 1.0);
        let end = *pts.last().expect("at least two boundaries");
        let metrics = metrics(r);
        let reactions =
            (!r.reactions.is_empty()).then(|| json!({"k": r.k, "reactions": r.reactions}));
        self.with(|w| {
            w.proto(rod_topic, t, &rod_update(t, id, &pts, thickness, c))?;
            if matches!(r.kind, PathKind::Optimal | PathKind::Feasible) {
                w.proto(pose_topic, t, &end_pose(t, end, frame))?;
            }
            w.json(
                metrics_topic,
                "dlo.ShapeMetrics",
                &json_schemas::METRICS,
                t,
                &metrics,
            )?;
            if let (PathKind::Feasible, Some(rj)) = (r.kind, &reactions) {
                w.json(
                    topics::REACTIONS_FEASIBLE,
                    "dlo.Reactions",
                    &json_schemas::REACTIONS,
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
        let t = self.t0 + self.iterations * 100_000_000;
        let pts = rod_points(model, worst);
        let thickness = rod_thickness(model.rod.radius, model.rod.length);
        let msg = json!({
            "start": p.start, "stage": p.stage, "outer": p.outer,
            "smoothed_max": p.smoothed_max, "sampled_max": p.sampled_max,
            "k_worst": p.k_worst, "violation": p.violation, "rho": p.rho,
        });
        self.with(|w| {
            w.json(
                topics::OPTIMISER_PROGRESS,
                "dlo.OptimiserProgress",
                &json_schemas::PROGRESS,
                t,
                &msg,
            )?;
            w.proto(
                topics::OPTIMISER_WORST,
                t,
                &rod_update(t, "worst", &pts, thickness, color(0.9, 0.6, 0.1, 1.0)),
            )
        });
    }
}

/// Logs one static solve (`dlo shape`) at the wall clock's now: obstacles, transform, rod,
/// metrics.
pub fn log_static(
    writer: &SharedWriter,
    model: &Model,
    obstacles: &[Arc<Obstacle>],
    a: &[f64],
    metrics: &serde_json::Value,
) -> Result<(), LogError> {
    let mut w = lock(writer);
    let t0 = wall_clock_ns();
    let pts = rod_points(model, a);
    let end = *pts.last().expect("at least two boundaries");
    let thickness = rod_thickness(model.rod.radius, model.rod.length);
    scene_start(&mut w, t0, obstacles, model.rod.length)?;
    w.proto(
        topics::SHAPE,
        t0,
        &rod_update(t0, "shape", &pts, thickness, color(0.1, 0.4, 0.9, 1.0)),
    )?;
    w.proto(
        topics::END_POSE_SHAPE,
        t0,
        &end_pose(t0, end, model.frame_at(a, 1.0)),
    )?;
    w.json(
        topics::METRICS_SHAPE,
        "dlo.ShapeReport",
        &json_schemas::SHAPE_REPORT,
        t0,
        metrics,
    )?;
    Ok(())
}

/// Logs a margin computation: the fingers on `/grasp/fingers` (an arrow per finger, ending at
/// its contact point on the undisturbed grasp and pointing the way it pushes), the last shape
/// that held for every point and direction on `/grasp/held_shape` (0.1 s apart, in table
/// order) with its limits on `/grasp/limits`.
pub fn log_margin(
    writer: &SharedWriter,
    model: &Model,
    obstacles: &[Arc<Obstacle>],
    fingers: &[([f64; 3], [f64; 3])],
    margin: &crate::grasp::Margin,
) -> Result<(), LogError> {
    let mut w = lock(writer);
    let t0 = wall_clock_ns();
    let thickness = rod_thickness(model.rod.radius, model.rod.length);
    scene_start(&mut w, t0, obstacles, model.rod.length)?;
    if !fingers.is_empty() {
        w.proto(
            topics::GRASP_FINGERS,
            t0,
            &super::scene::fingers_update(t0, fingers, model.rod.length),
        )?;
    }
    for (i, lim) in margin.table.iter().enumerate() {
        let t = t0 + i as u64 * 100_000_000;
        w.proto(
            topics::GRASP_HELD_SHAPE,
            t,
            &rod_update(
                t,
                "held_shape",
                &lim.held_shape,
                thickness,
                color(0.1, 0.4, 0.9, 1.0),
            ),
        )?;
        w.json(
            topics::GRASP_LIMITS,
            "dlo.GraspLimit",
            &json_schemas::GRASP_LIMIT,
            t,
            &serde_json::to_value(lim).expect("limit serialises"),
        )?;
    }
    Ok(())
}
