//! The generated planning suite: problems in the style a cable-routing user writes, with every
//! planner setting at its default, planned, verified and replayed, and the outcome counted.
//!
//!     cargo run --release --example plan_suite -- --seed 1
//!     cargo run --release --example plan_suite -- --seed 1 --planar 60 --spatial 30 --verbose
//!     cargo run --release --example plan_suite -- --seed 1 --write target/suite   # the case files
//!     cargo run --release --example plan_suite -- --seed 1 --only 3d   # plan the 3D problems only
//!     cargo run --release --example plan_suite -- --seed 1 --only none --write target/suite
//!     cargo run --release --example plan_suite -- --seed 1 --plan '{"path_terms": 4}'
//!     cargo run --release --example plan_suite -- --seed 1 --case '{"angle_frame": "case"}'
//!     cargo run --release --example plan_suite -- --seed 1 --case '{"rod": {"radius": 0.03}}'
//!     cargo run --release --example plan_suite -- --seed 1 --family hanging   # another family
//!     cargo run --release --example plan_suite -- --seed 1 --family table     # and a 3D one
//!     cargo run --release --example plan_suite -- --seed 1 --units 0.6,0.02   # L = 0.6, Rf = 0.02
//!     cargo run --release --example plan_suite -- --seeds 1-16,21-26   # pooled over seeds too
//!
//! Planar: a strip (L = 1, Rf = 1, r = 0.005) clamped at the origin along +z (θ(0) = 0), one to
//! three obstacles (boxes, balls, capsules along y) beyond its swing, start and goal end poses
//! on either side of the z axis, with and without a prescribed end angle, some with weight.
//! 3D: a cable with torsion (L = 1, Rf = 1, Rt = 0.77, r = 0.01) clamped by its frame at the
//! origin (θ(0) = 0, φ(0) + ψ(0) = 0), one or two obstacles among capsule bars, cylinders,
//! balls, boxes and the triangle-mesh cube of `planning_cases/meshes`, start and goal
//! positions on opposite sides with tangents and twists. Problems whose start or goal has no
//! static shape (or lies inside an obstacle) are generated again and not counted.
//! The hanging family (`--family hanging`, [`hanging_problem`]), planar problems of another
//! style that no default was chosen on: a heavy strip clamped along +x, hanging among
//! obstacles below and beside its clamp. The table family (`--family table`,
//! [`table_problem`]), 3D problems of a third: a heavy cable dragged across a table, past a
//! cup standing on it.
//!
//! For each problem: whether the plan is collision-free (`planned`) and coincides with its
//! replay, whether the replay snaps, the plan time (end solves, plan, verification and
//! replay), the gripper's path length over the straight-line distance between its ends, and an
//! independent clearance check of every plan called collision-free on a grid twice as fine in
//! k as the verification's and four times as fine in s, and of every plan executable
//! by its replayed equilibria at each replayed shape on a grid four times finer in s (the
//! worst of these is the "worst false collision-free" of the table: it must be ≥ −1e-6 L, and
//! the runner exits with 1 after the table, naming the plans, where one is not).

use dlo_planner::case;
use dlo_planner::planner::observer::Silent;
use dlo_planner::planner::verify::fine_model;
use dlo_planner::planner::{PlanResult, PlanStatus, Planner};
use dlo_planner::rod::kinematics::Shape;
use std::path::Path;
use std::time::Instant;

/// Upper bound of a capsule bar's rotation (rad): a range bound, not π, kept so that each seed
/// gives the problems the docs quote.
#[allow(clippy::approx_constant)]
const ROTATION_RANGE: f64 = 3.14;

/// splitmix64: a small, fixed pseudo-random sequence (the suite must not depend on a crate's
/// generator changing).
pub struct Rng(pub u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [a, b).
    fn uniform(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// Ranges of a generated planar obstacle: its centre's x and z, a box's half-extents in x and
/// z, a ball's radius and a bar's (a capsule along y).
struct ObstacleRanges {
    x: (f64, f64),
    z: (f64, f64),
    box_x: (f64, f64),
    box_z: (f64, f64),
    ball: (f64, f64),
    bar: (f64, f64),
}

/// Obstacle `j` of a planar problem, drawn from `r`: a box, a ball or a bar, one in three each.
fn planar_obstacle(rng: &mut Rng, j: usize, r: &ObstacleRanges) -> String {
    let x = rng.uniform(r.x.0, r.x.1);
    let z = rng.uniform(r.z.0, r.z.1);
    let shape = match rng.below(3) {
        0 => format!(
            r#"{{"type": "cuboid", "half_extents": [{}, 0.5, {}]}}"#,
            rng.uniform(r.box_x.0, r.box_x.1),
            rng.uniform(r.box_z.0, r.box_z.1)
        ),
        1 => format!(
            r#"{{"type": "ball", "radius": {}}}"#,
            rng.uniform(r.ball.0, r.ball.1)
        ),
        _ => format!(
            r#"{{"type": "capsule", "a": [0, -0.5, 0], "b": [0, 0.5, 0], "radius": {}}}"#,
            rng.uniform(r.bar.0, r.bar.1)
        ),
    };
    format!(r#"{{"name": "o{j}", "shape": {shape}, "position": [{x}, 0, {z}]}}"#)
}

pub fn planar_problem(rng: &mut Rng, i: usize) -> String {
    let n_obs = 1 + rng.below(3);
    let ranges = ObstacleRanges {
        x: (-0.25, 0.25),
        z: (0.75, 1.15),
        box_x: (0.04, 0.2),
        box_z: (0.04, 0.3),
        ball: (0.04, 0.15),
        bar: (0.03, 0.1),
    };
    let obstacles: Vec<String> = (0..n_obs)
        .map(|j| planar_obstacle(rng, j, &ranges))
        .collect();
    let end = |rng: &mut Rng, side: f64| {
        let r = rng.uniform(0.55, 0.9);
        let a = side * rng.uniform(0.25, 0.7);
        let (x, z) = (r * a.sin(), r * a.cos());
        if rng.below(3) == 0 {
            format!(r#"{{"x": {x}, "z": {z}}}"#)
        } else {
            format!(
                r#"{{"x": {x}, "z": {z}, "theta": {}}}"#,
                side * rng.uniform(0.2, 1.2)
            )
        }
    };
    let (start, goal) = (end(rng, 1.0), end(rng, -1.0));
    let weight = if rng.below(4) == 0 {
        format!(r#", "weight_per_length": {}"#, rng.uniform(0.5, 3.0))
    } else {
        String::new()
    };
    format!(
        r#"{{"name": "planar_{i}", "planar": true,
  "rod": {{"length": 1.0, "flexural_rigidity": 1.0, "radius": 0.005{weight}}},
  "constraints": [{{"type": "orientation", "s": 0.0, "theta": 0.0}}],
  "obstacles": [{}],
  "plan": {{"start": {start}, "goal": {goal}}}}}"#,
        obstacles.join(", ")
    )
}

/// A problem of the hanging family (`--family hanging`), unlike those the defaults were chosen
/// on: the strip clamped at the origin along +x (θ(0) = π/2), most of it heavy (weight 1–10
/// per length, four problems in five), so that it hangs; one or two obstacles below and beside
/// the clamp, among which it hangs; start and goal end poses anywhere to the right of the
/// clamp, from 0.55 L to 0.9 L away, two in three with an end angle within 0.6 rad of pointing
/// away from the clamp.
pub fn hanging_problem(rng: &mut Rng, i: usize) -> String {
    let n_obs = 1 + rng.below(2);
    let ranges = ObstacleRanges {
        x: (0.25, 0.75),
        z: (-0.5, 0.25),
        box_x: (0.03, 0.12),
        box_z: (0.03, 0.12),
        ball: (0.04, 0.12),
        bar: (0.03, 0.08),
    };
    let obstacles: Vec<String> = (0..n_obs)
        .map(|j| planar_obstacle(rng, j, &ranges))
        .collect();
    let end = |rng: &mut Rng| {
        let r = rng.uniform(0.55, 0.9);
        let a = rng.uniform(-1.2, 1.0);
        let (x, z) = (r * a.cos(), r * a.sin());
        if rng.below(3) == 0 {
            format!(r#"{{"x": {x}, "z": {z}}}"#)
        } else {
            let theta = std::f64::consts::FRAC_PI_2 - a + rng.uniform(-0.6, 0.6);
            format!(r#"{{"x": {x}, "z": {z}, "theta": {theta}}}"#)
        }
    };
    let (start, goal) = (end(rng), end(rng));
    let weight = if rng.below(5) == 0 {
        0.0
    } else {
        rng.uniform(1.0, 10.0)
    };
    format!(
        r#"{{"name": "hanging_{i}", "planar": true,
  "rod": {{"length": 1.0, "flexural_rigidity": 1.0, "radius": 0.005, "weight_per_length": {weight}}},
  "constraints": [{{"type": "orientation", "s": 0.0, "theta": {}}}],
  "obstacles": [{}],
  "plan": {{"start": {start}, "goal": {goal}}}}}"#,
        std::f64::consts::FRAC_PI_2,
        obstacles.join(", ")
    )
}

/// A problem of the table family (`--family table`), unlike those the defaults were chosen on:
/// a heavy cable (weight 2–25 per length, flexural rigidity 1, torsional 0.77, radius 0.01)
/// clamped by its frame at the origin along +z, lying on a table (a half-space 0.1–0.3 L below
/// the clamp; x is up) with, in three problems of five, a cup standing on it (a vertical
/// cylinder of radius 0.03–0.06 and height 0.08–0.15 between the ends' sides); its end moved
/// from one side of the z axis to the other, 0.01–0.1 L above the table, 0.5–0.85 L out along
/// z and 0.15–0.4 L to the side, its tangent along the table within 0.5 rad of +z, with a twist.
pub fn table_problem(rng: &mut Rng, i: usize) -> String {
    let weight = rng.uniform(2.0, 25.0);
    let below = rng.uniform(0.1, 0.3);
    let mut obstacles = vec![format!(
        r#"{{"name": "table", "shape": {{"type": "half_space", "normal": [1, 0, 0]}}, "position": [{}, 0, 0]}}"#,
        -below
    )];
    if rng.below(5) < 3 {
        let half = rng.uniform(0.04, 0.075);
        obstacles.push(format!(
            r#"{{"name": "cup", "shape": {{"type": "cylinder", "half_height": {half}, "radius": {}}}, "position": [{}, {}, {}], "rotation": [0, 0, 1.5707963267948966]}}"#,
            rng.uniform(0.03, 0.06),
            -below + half,
            rng.uniform(-0.1, 0.1),
            rng.uniform(0.4, 0.7)
        ));
    }
    let end = |rng: &mut Rng, side: f64| {
        let yaw = rng.uniform(-0.5, 0.5);
        format!(
            r#"{{"position": [{}, {}, {}], "tangent": [0, {}, {}], "twist": {}}}"#,
            -below + rng.uniform(0.01, 0.1),
            side * rng.uniform(0.15, 0.4),
            rng.uniform(0.5, 0.85),
            yaw.sin(),
            yaw.cos(),
            rng.uniform(-0.5, 0.5)
        )
    };
    let (start, goal) = (end(rng, 1.0), end(rng, -1.0));
    format!(
        r#"{{"name": "table_{i}", "planar": false,
  "rod": {{"length": 1.0, "flexural_rigidity": 1.0, "torsional_rigidity": 0.77, "radius": 0.01, "weight_per_length": {weight}}},
  "constraints": [{{"type": "orientation", "s": 0.0, "theta": 0.0, "phi_plus_psi": 0.0}}],
  "obstacles": [{}],
  "plan": {{"start": {start}, "goal": {goal}}}}}"#,
        obstacles.join(", ")
    )
}

pub fn spatial_problem(rng: &mut Rng, i: usize) -> String {
    let n_obs = 1 + rng.below(2);
    let mut obstacles = Vec::new();
    // The ends' azimuths: the goal on the other side of the z axis.
    let az0 = rng.uniform(0.0, std::f64::consts::TAU);
    let az1 = az0 + std::f64::consts::PI + rng.uniform(-0.8, 0.8);
    for j in 0..n_obs {
        // Near the cable's natural axis, beyond the clamp, where the straight-line path sweeps.
        let p = [
            rng.uniform(-0.2, 0.2),
            rng.uniform(-0.2, 0.2),
            rng.uniform(0.75, 1.1),
        ];
        let shape = match rng.below(5) {
            0 => format!(
                r#"{{"type": "capsule", "a": [0, -1, 0], "b": [0, 1, 0], "radius": {}}}, "rotation": [0, 0, {}]"#,
                rng.uniform(0.04, 0.1),
                rng.uniform(0.0, ROTATION_RANGE)
            ),
            1 => format!(
                r#"{{"type": "cylinder", "half_height": 1.0, "radius": {}}}, "rotation": [0, 0, -1.5707963267948966]"#,
                rng.uniform(0.04, 0.1)
            ),
            2 => format!(
                r#"{{"type": "ball", "radius": {}}}"#,
                rng.uniform(0.05, 0.15)
            ),
            3 => format!(
                r#"{{"type": "cuboid", "half_extents": [{}, {}, {}]}}"#,
                rng.uniform(0.04, 0.15),
                rng.uniform(0.04, 0.15),
                rng.uniform(0.04, 0.15)
            ),
            _ => format!(
                r#"{{"type": "triangle_mesh", "obj": "meshes/cube.obj", "scale": {}}}"#,
                rng.uniform(0.1, 0.3)
            ),
        };
        obstacles.push(format!(
            r#"{{"name": "o{j}", "shape": {shape}, "position": [{}, {}, {}]}}"#,
            p[0], p[1], p[2]
        ));
    }
    let end = |rng: &mut Rng, az: f64| {
        let r = rng.uniform(0.6, 0.9);
        let polar = rng.uniform(0.2, 0.6);
        let pos = [
            r * polar.sin() * az.cos(),
            r * polar.sin() * az.sin(),
            r * polar.cos(),
        ];
        let tilt = polar + rng.uniform(0.2, 0.6);
        let t = [tilt.sin() * az.cos(), tilt.sin() * az.sin(), tilt.cos()];
        format!(
            r#"{{"position": [{}, {}, {}], "tangent": [{}, {}, {}], "twist": {}}}"#,
            pos[0],
            pos[1],
            pos[2],
            t[0],
            t[1],
            t[2],
            rng.uniform(-0.5, 0.5)
        )
    };
    let (start, goal) = (end(rng, az0), end(rng, az1));
    format!(
        r#"{{"name": "spatial_{i}", "planar": false,
  "rod": {{"length": 1.0, "flexural_rigidity": 1.0, "torsional_rigidity": 0.77, "radius": 0.01}},
  "constraints": [{{"type": "orientation", "s": 0.0, "theta": 0.0, "phi_plus_psi": 0.0}}],
  "obstacles": [{}],
  "plan": {{"start": {start}, "goal": {goal}}}}}"#,
        obstacles.join(", ")
    )
}

/// One problem's outcome.
pub struct Outcome {
    pub name: String,
    pub planned: bool,
    pub coincide: bool,
    /// The verdict is executable: the optimal path coincides with its replay, or the
    /// replayed equilibria along its trajectory are a confirmed plan.
    pub executable: bool,
    /// Executable by the replayed equilibria (not the optimal path itself).
    pub by_equilibria: bool,
    /// Of those, along the straight-line path's trajectory (no optimised path executable).
    pub by_straight: bool,
    /// Of those, along a line in the end's pose space (neither an optimised path nor the
    /// straight-line path's trajectory executable): how it leaves the straight line.
    pub by_pose_line: Option<dlo_planner::planner::pose_line::Detour>,
    /// Along a course optimised in the end's pose space: the largest energy of the equilibria
    /// along the course as it was, and along the optimised one.
    pub pose_optimised: Option<[f64; 2]>,
    /// The plan ends on another equilibrium of the goal pose than its static solve's, which
    /// the gripper's motion reached (`PlanResult::reached_goal`).
    pub reached_goal: bool,
    /// Of those, the first plan's replayed equilibria, which end on it (the plan made again to
    /// it was not executable: `ReachedGoal::replan_failed`).
    pub reached_not_replanned: bool,
    /// Why not executable: the verdict, and why the replayed equilibria are not a plan.
    pub why_not: Option<String>,
    pub snaps: bool,
    pub seconds: f64,
    pub travel: f64,
    /// The independent check's smallest clearance (units of L) and its k, for plans called
    /// collision-free.
    pub checked_clearance: Option<(f64, f64)>,
    pub u_max: f64,
    pub deviation: f64,
    /// The replay's smallest clearance (units of L; infinite without obstacles), whether every
    /// replay solve converged and every replayed shape is stable.
    pub replay: (f64, bool, bool),
    /// The attempt of every start that ran, in order, the chosen one marked `*` (`straight`:
    /// the straight-line path, no start ran).
    pub attempts: String,
}

/// The plan's smallest clearance to any obstacle on `2 (verify_k − 1) + 1` values of k, each
/// shape at `4 verify_s + 1` points in s (both grids twice or four times the verification
/// grid's; units of L), and where in k.
fn independent_clearance(p: &Planner, r: &PlanResult) -> (f64, f64) {
    let model = fine_model(&p.base.model, 4 * p.verify_s_intervals(), 2);
    let path = p.path_of(r);
    let n = 2 * (p.settings.verify_k_samples - 1);
    let mut a = vec![0.0; path.n()];
    let mut shape = Shape::default();
    let mut worst = (f64::INFINITY, 0.0);
    for i in 0..=n {
        let k = i as f64 / n as f64;
        path.shape_at(&r.z, k, &mut a);
        model.evaluate_into(&a, &mut shape);
        let g = gap(p, &shape.positions);
        if g < worst.0 {
            worst = (g, k);
        }
    }
    worst
}

/// The smallest surface gap `d − r` (units of L) of the dimensionless `positions` to any
/// obstacle.
fn gap(p: &Planner, positions: &[[f64; 3]]) -> f64 {
    let model = &p.base.model;
    let l = model.rod.length;
    let mut worst = f64::INFINITY;
    for x in positions {
        for o in &p.obstacles {
            worst = worst.min((o.signed_distance_value(x.map(|v| v * l)) - model.rod.radius) / l);
        }
    }
    worst
}

/// The smallest clearance to any obstacle (units of L) of the replayed shapes on a grid four
/// times finer in s than the model's boundary points, and where in k.
fn replay_clearance(p: &Planner, r: &PlanResult) -> (f64, f64) {
    let model = &p.base.model;
    let mut worst = (f64::INFINITY, 0.0);
    let Some(first) = r.replay.steps.first() else {
        return worst;
    };
    let fine = fine_model(model, 4 * (first.positions.len() - 1), 2);
    for step in &r.replay.steps {
        let g = gap(p, &fine.evaluate(&step.a).positions);
        if g < worst.0 {
            worst = (g, step.k);
        }
    }
    worst
}

/// A generated problem (written with `L = 1` and `Rf = 1`) in units where the rod is `length`
/// long and its flexural rigidity is `rigidity`: every length times `length` (the rod's length
/// and radius, the held end's conditions, the obstacles' places and sizes, the end positions),
/// the rigidities times `rigidity`, the weight per length times `rigidity / length³`. Angles and
/// directions are kept, so the problem is the same one: its energies scale by `rigidity /
/// length` and its lengths by `length`.
pub fn in_units(text: &str, length: f64, rigidity: f64) -> String {
    use serde_json::Value;
    let mut v: Value = serde_json::from_str(text).expect("generated JSON");
    let times = |x: &mut Value, f: f64| match x {
        Value::Number(n) => *x = (n.as_f64().expect("a number") * f).into(),
        Value::Array(a) => a
            .iter_mut()
            .for_each(|y| *y = (y.as_f64().expect("a number") * f).into()),
        _ => panic!("a number or an array of numbers: {x}"),
    };
    let scale = |o: &mut Value, keys: &[&str], f: f64| {
        for key in keys {
            if let Some(x) = o.get_mut(*key) {
                times(x, f);
            }
        }
    };
    let rod = &mut v["rod"];
    scale(rod, &["length", "radius"], length);
    scale(rod, &["flexural_rigidity", "torsional_rigidity"], rigidity);
    scale(rod, &["weight_per_length"], rigidity / length.powi(3));
    let lengths = ["s", "x", "y", "z", "position"];
    for c in v["constraints"].as_array_mut().into_iter().flatten() {
        scale(c, &lengths, length);
    }
    for o in v["obstacles"].as_array_mut().into_iter().flatten() {
        scale(o, &["position"], length);
        let shape = o["shape"].as_object_mut().expect("a shape");
        for (key, value) in shape.iter_mut() {
            if !matches!(key.as_str(), "type" | "obj") {
                times(value, length);
            }
        }
    }
    for end in ["start", "goal"] {
        scale(&mut v["plan"][end], &lengths, length);
    }
    scale(&mut v["plan"], &["safety_margin"], length);
    serde_json::to_string_pretty(&v).expect("JSON")
}

/// `fields` written over `v`: an object's fields one by one, so that `{"rod": {"radius": 0.03}}`
/// changes the rod's radius and keeps its other fields; anything else replaced.
pub fn merge(v: &mut serde_json::Value, fields: &serde_json::Value) {
    match (v.as_object_mut(), fields.as_object()) {
        (Some(o), Some(f)) => {
            for (key, value) in f {
                merge(
                    o.entry(key.clone()).or_insert(serde_json::Value::Null),
                    value,
                );
            }
        }
        _ => *v = fields.clone(),
    }
}

/// The case of a generated problem, with `plan` settings and `top` case fields given.
fn problem_case(
    text: &str,
    name: &str,
    plan: &serde_json::Value,
    top: &serde_json::Value,
) -> Option<case::Case> {
    case_of(text, name, plan, top).ok()
}

/// A generated problem's case file with `plan` settings and `top` case fields given.
fn with_fields(text: &str, plan: &serde_json::Value, top: &serde_json::Value) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_str(text).expect("generated JSON");
    for (key, value) in plan.as_object().into_iter().flatten() {
        v["plan"][key] = value.clone();
    }
    merge(&mut v, top);
    v
}

/// [`problem_case`], or why the case file it makes is not a case.
fn case_of(
    text: &str,
    name: &str,
    plan: &serde_json::Value,
    top: &serde_json::Value,
) -> Result<case::Case, String> {
    let v = with_fields(text, plan, top);
    // The case's folder in this crate, wherever the runner is started from: the 3D problems'
    // mesh (`meshes/cube.obj`) is read relative to it.
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("planning_cases")
        .join(format!("{name}.json"));
    case::parse(&v.to_string(), &path).map_err(|e| e.to_string())
}

/// Whether a generated problem counts (its start and goal have static shapes), without
/// planning it.
fn counts(text: &str, name: &str, plan: &serde_json::Value, top: &serde_json::Value) -> bool {
    problem_case(text, name, plan, top).is_some_and(|c| Planner::from_case(&c).is_ok())
}

pub fn run(
    text: &str,
    name: &str,
    plan: &serde_json::Value,
    top: &serde_json::Value,
) -> Option<Outcome> {
    let c = problem_case(text, name, plan, top)?;
    let t0 = Instant::now();
    let p = Planner::from_case(&c).ok()?;
    let r = p.run(&mut Silent);
    let seconds = t0.elapsed().as_secs_f64();
    let planned = r.status == PlanStatus::Planned;
    let executed = r.executed_path();
    // The report's replay is the straight-line path's where the plan follows its trajectory,
    // the pose line's along one.
    let along_straight = r.along_straight_trajectory();
    let t = &r.trajectory;
    Some(Outcome {
        name: name.to_string(),
        planned,
        coincide: planned && r.replay.coincide && !r.along_other_trajectory(),
        executable: executed.is_some(),
        by_equilibria: executed == Some("equilibria"),
        by_straight: executed.is_some() && along_straight,
        by_pose_line: r.along_pose_line().filter(|_| executed.is_some()),
        pose_optimised: r
            .equilibrium_plan
            .as_ref()
            .filter(|_| executed.is_some())
            .and_then(|e| e.course_u_max.map(|before| [before, e.u_max])),
        reached_goal: r.reached_goal.is_some(),
        reached_not_replanned: r.reached_goal.as_ref().is_some_and(|g| !g.replanned()),
        why_not: executed.is_none().then(|| {
            format!(
                "{}{}",
                r.verdict(),
                r.equilibrium_plan
                    .as_ref()
                    .and_then(|e| e.reason.as_ref())
                    .map_or(String::new(), |w| format!("; equilibria: {w}"))
            )
        }),
        snaps: !r.replay.snaps.is_empty(),
        seconds,
        travel: t.path_length / t.straight_distance.max(1e-12),
        checked_clearance: match executed {
            Some("equilibria") => Some(replay_clearance(&p, &r)),
            _ => planned.then(|| independent_clearance(&p, &r)),
        },
        u_max: r.u_max,
        deviation: r.replay.max_deviation_over_l,
        replay: (
            r.replay
                .min_clearance
                .map_or(f64::INFINITY, |c| c / p.base.model.rod.length),
            r.replay.all_converged,
            r.replay.all_stable,
        ),
        attempts: if r.starts.is_empty() {
            "straight".into()
        } else {
            r.starts
                .iter()
                .map(|s| {
                    let mark = if Some(s.start) == r.chosen_start {
                        "*"
                    } else {
                        ""
                    };
                    format!("{}{mark}", s.attempt.name())
                })
                .collect::<Vec<_>>()
                .join(",")
        },
    })
}

/// Where the `q` quantile of `n` sorted values lies: index `round((n − 1) q)`.
fn percentile_index(n: usize, q: f64) -> usize {
    ((n - 1) as f64 * q).round() as usize
}

fn percentile(v: &mut [f64], q: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[percentile_index(v.len(), q)]
}

fn table(kind: &str, out: &[Outcome]) -> String {
    let n = out.len();
    let planned = out.iter().filter(|o| o.planned).count();
    let coincide = out.iter().filter(|o| o.coincide).count();
    let executable = out.iter().filter(|o| o.executable).count();
    let by_equilibria = out.iter().filter(|o| o.by_equilibria).count();
    let by_straight = out.iter().filter(|o| o.by_straight).count();
    let by_line = out.iter().filter(|o| o.by_pose_line.is_some()).count();
    let reached = out.iter().filter(|o| o.reached_goal).count();
    let optimised = out.iter().filter(|o| o.pose_optimised.is_some()).count();
    let snaps = out.iter().filter(|o| o.snaps).count();
    let mut times: Vec<f64> = out.iter().map(|o| o.seconds).collect();
    let mut travel: Vec<f64> = out.iter().map(|o| o.travel).collect();
    let worst = out
        .iter()
        .filter_map(|o| o.checked_clearance.map(|c| c.0))
        .fold(f64::INFINITY, f64::min);
    let pct = |k: usize| 100.0 * k as f64 / n.max(1) as f64;
    format!(
        "| {kind} | {n} | {planned} ({:.0} %) | {coincide} ({:.0} %) | {executable} ({:.0} %; {by_equilibria} by the equilibria, {by_straight} of them along the straight path, {by_line} along a pose line; {reached} to a reached goal; {optimised} optimised in the end's pose space) | {snaps} | {:.3} s | {:.3} s | {:+.2e} L | {:.2} / {:.2} |\n",
        pct(planned),
        pct(coincide),
        pct(executable),
        percentile(&mut times.clone(), 0.5),
        percentile(&mut times, 0.95),
        worst,
        percentile(&mut travel.clone(), 0.5),
        percentile(&mut travel, 0.95),
    )
}

/// The lines `--verbose` writes for outcome `o` (standard error).
fn report(o: &Outcome) {
    eprintln!(
        "{:16} planned {:5} coincide {:5} executable {:5} snaps {:5} U_max {:.4} d/L {:.4} travel {:.2} time {:.3} s clearance {} replay clearance {:+.2e} converged {} stable {} attempts {}",
        o.name,
        o.planned,
        o.coincide,
        o.executable,
        o.snaps,
        o.u_max,
        o.deviation,
        o.travel,
        o.seconds,
        // Only plans called collision-free (or executable by their
        // replayed equilibria) are checked.
        o.checked_clearance
            .map_or("unchecked".to_string(), |(d, k)| {
                format!("{d:+.2e} at k = {k:.4}")
            }),
        o.replay.0,
        o.replay.1,
        o.replay.2,
        o.attempts
    );
    if let Some(d) = o.by_pose_line {
        eprintln!(
            "{:16} executable along a line in the end's pose space {}{}",
            o.name,
            match d.describe() {
                d if d.is_empty() => "lifted 0 L".to_string(),
                d => d,
            },
            o.pose_optimised.map_or(String::new(), |[a, b]| format!(
                ", optimised: U_max {a:.4} -> {b:.4}"
            ))
        );
    }
    if let (None, Some([a, b])) = (o.by_pose_line, o.pose_optimised) {
        eprintln!(
            "{:16} executable along the {} end poses optimised in the end's pose space: U_max {a:.4} -> {b:.4}",
            o.name,
            if o.by_straight {
                "straight path's"
            } else {
                "optimal path's"
            }
        );
    }
    if o.reached_not_replanned {
        eprintln!(
            "{:16} executable by its first search's equilibria, which end on another equilibrium of the goal pose",
            o.name
        );
    } else if o.reached_goal {
        eprintln!(
            "{:16} planned to the equilibrium of the goal pose its first plan's motion reached",
            o.name
        );
    }
    if let Some(why) = &o.why_not {
        // A departure's or a snap's verdict already says it.
        let lead = if why.starts_with("not executable") {
            ""
        } else {
            "not executable: "
        };
        eprintln!("{:16} {lead}{why}", o.name);
    }
}

/// Seeds from `1-16,21,500-523` (ranges inclusive); exits with a message on anything else.
pub fn parse_seeds(list: &str) -> Vec<u64> {
    let bad = || -> ! {
        eprintln!("plan_suite: --seeds takes a list such as 1-16,21,500-523, not {list:?}");
        std::process::exit(2);
    };
    let mut seeds = Vec::new();
    for part in list.split(',') {
        let num = |t: &str| t.trim().parse::<u64>().unwrap_or_else(|_| bad());
        match part.split_once('-') {
            Some((a, b)) if num(a) <= num(b) => seeds.extend(num(a)..=num(b)),
            Some(_) => bad(),
            None => seeds.push(num(part)),
        }
    }
    seeds
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |flag: &str, default: u64| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .map_or(default, |v| v.parse().expect("a number"))
    };
    // `--seeds 1-16,21,500-523`: several seeds one after another, each with its own table,
    // then the pooled table; `--seed N` (1 by default) for one.
    let seeds: Vec<u64> = match args.iter().position(|a| a == "--seeds") {
        Some(i) => parse_seeds(args.get(i + 1).map_or("", |s| s.as_str())),
        None => vec![arg("--seed", 1)],
    };
    // `--family hanging`: the planar problems of [`hanging_problem`] instead of the suite's,
    // and no 3D problems unless `--spatial` asks for them; `--family table`: the 3D problems
    // of [`table_problem`], and no planar ones unless `--planar` asks for them.
    let family = args
        .iter()
        .position(|a| a == "--family")
        .and_then(|i| args.get(i + 1))
        .map(|f| {
            assert!(
                f == "hanging" || f == "table",
                "--family: `hanging` or `table`"
            );
            f.clone()
        });
    let hanging = family.as_deref() == Some("hanging");
    let on_table = family.as_deref() == Some("table");
    let n_planar = arg("--planar", if on_table { 0 } else { 60 }) as usize;
    let n_spatial = arg("--spatial", if hanging { 0 } else { 30 }) as usize;
    let planar_kind = if hanging { "hanging" } else { "planar" };
    let spatial_kind = if on_table { "table" } else { "spatial" };
    let spatial_label = if on_table { "table" } else { "3D" };
    let verbose = args.iter().any(|a| a == "--verbose");
    // `--write DIR`: every generated case file is written there, for `dlo plan DIR/NAME.json`
    // (with the `--units`, `--plan` and `--case` it is planned with).
    let write_dir = args
        .iter()
        .position(|a| a == "--write")
        .and_then(|i| args.get(i + 1))
        .map(std::path::PathBuf::from);
    // `--plan '{"path_terms": 4}'`: planner settings given to every problem (to measure other
    // settings on the same problems); `--case '{"angle_frame": "case"}'`: case fields given to
    // every problem, objects field by field (`--case '{"rod": {"radius": 0.03}}'`); none by
    // default.
    let json_arg = |flag: &str| -> serde_json::Value {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .map_or(serde_json::json!({}), |t| {
                serde_json::from_str(t).expect("a JSON object")
            })
    };
    let (plan, top) = (json_arg("--plan"), json_arg("--case"));
    let given = |f: &serde_json::Value| f.as_object().is_some_and(|o| !o.is_empty());
    let (plan_given, top_given) = (given(&plan), given(&top));
    // `--units 0.6,0.02`: every problem with the rod's length and flexural rigidity in other
    // units ([`in_units`]); `1,1` by default, the problems as generated.
    let units = args
        .iter()
        .position(|a| a == "--units")
        .and_then(|i| args.get(i + 1))
        .map(|u| {
            let v: Vec<f64> = u
                .split(',')
                .map(|x| x.parse().expect("--units LENGTH,RIGIDITY: numbers"))
                .collect();
            assert!(
                v.len() == 2 && v.iter().all(|x| x.is_finite() && *x > 0.0),
                "--units LENGTH,RIGIDITY: two positive numbers"
            );
            (v[0], v[1])
        });
    // `--only planar` or `--only 3d`: the other kind's problems are generated (the stream of
    // problems stays the same) but not planned; `--only none` plans none (with `--write`, the
    // case files alone).
    let only = args
        .iter()
        .position(|a| a == "--only")
        .and_then(|i| args.get(i + 1))
        .map(|k| match k.as_str() {
            "planar" => 0,
            "none" => 2,
            _ => 1,
        });
    let generate = |kind: usize, rng: &mut Rng, i: usize| {
        let text = if kind == 0 && hanging {
            hanging_problem(rng, i)
        } else if kind == 0 {
            planar_problem(rng, i)
        } else if on_table {
            table_problem(rng, i)
        } else {
            spatial_problem(rng, i)
        };
        match units {
            Some((l, r)) => in_units(&text, l, r),
            None => text,
        }
    };
    // The table of both kinds' outcomes (a kind not planned, `--only`, has no row).
    let print_table = |out: &[Vec<Outcome>; 2]| {
        println!(
            "| problems | n | collision-free | coincide with replay | executable | replay snaps | median time | 95th pct time | worst false collision-free | gripper travel / straight (median / 95th) |"
        );
        println!("|---|---|---|---|---|---|---|---|---|---|");
        if n_planar > 0 && only.is_none_or(|o| o == 0) {
            print!("{}", table(planar_kind, &out[0]));
        }
        if n_spatial > 0 && only.is_none_or(|o| o == 1) {
            print!("{}", table(spatial_label, &out[1]));
        }
    };
    let mut all: [Vec<Outcome>; 2] = [Vec::new(), Vec::new()];
    let mut per_seed_p95: [Vec<f64>; 2] = [Vec::new(), Vec::new()];
    for (nth, &seed) in seeds.iter().enumerate() {
        // Settings or case fields that no generated problem takes would have every problem
        // generated again, for ever: the first of each kind must be a case.
        for (kind, count) in [(0, n_planar), (1, n_spatial)] {
            let text = generate(kind, &mut Rng(seed), 0);
            if let (true, Err(e)) = (count > 0, case_of(&text, "first", &plan, &top)) {
                eprintln!(
                    "plan_suite: --plan and --case make no case of the generated problems: {e}"
                );
                std::process::exit(2);
            }
        }
        let mut rng = Rng(seed);
        let mut skipped = [0usize; 2];
        let mut results: [Vec<Outcome>; 2] = [Vec::new(), Vec::new()];
        let mut regenerated = [0usize; 2];
        for (kind, count) in [(0, n_planar), (1, n_spatial)] {
            let mut i = 0;
            while results[kind].len() < count {
                let name = format!("{}_{seed}_{i}", [planar_kind, spatial_kind][kind]);
                let text = generate(kind, &mut rng, i);
                i += 1;
                if let Some(dir) = &write_dir {
                    std::fs::create_dir_all(dir).expect("--write: a directory");
                    // The mesh by its path in this crate, so that `dlo plan` finds it from there:
                    // `"meshes/` becomes the folder's path as a JSON string, without its closing
                    // quote (the file name and the quote follow).
                    let meshes =
                        Path::new(env!("CARGO_MANIFEST_DIR")).join("planning_cases/meshes/");
                    let quoted = format!("{:?}", meshes.display().to_string());
                    let open = &quoted[..quoted.len() - 1];
                    // With `--plan` or `--case`, the case file as planned.
                    let written = if plan_given || top_given {
                        serde_json::to_string_pretty(&with_fields(&text, &plan, &top))
                            .expect("JSON")
                    } else {
                        text.clone()
                    };
                    let written =
                        written.replace(r#""obj": "meshes/"#, &format!(r#""obj": {open}"#));
                    std::fs::write(dir.join(format!("{name}.json")), &written)
                        .expect("--write: writable");
                }
                if only.is_some_and(|o| o != kind) {
                    if counts(&text, &name, &plan, &top) {
                        skipped[kind] += 1;
                        if skipped[kind] == count {
                            break;
                        }
                    } else {
                        regenerated[kind] += 1;
                    }
                    continue;
                }
                match run(&text, &name, &plan, &top) {
                    Some(o) => {
                        if verbose {
                            report(&o);
                        }
                        results[kind].push(o);
                    }
                    None => regenerated[kind] += 1,
                }
            }
        }
        if nth > 0 {
            println!();
        }
        println!(
            "Suite seed {seed}: {} {planar_kind} and {} {spatial_label} problems (generated again where start or goal has no static shape: {} {planar_kind}, {} {spatial_label}){}, planner settings {}{}.\n",
            n_planar,
            n_spatial,
            regenerated[0],
            regenerated[1],
            units.map_or(String::new(), |(l, r)| format!(
                " in units where L = {l} and Rf = {r}"
            )),
            if plan_given {
                plan.to_string()
            } else {
                "all at their defaults".to_string()
            },
            if top_given {
                format!(", case fields {top}")
            } else {
                String::new()
            }
        );
        print_table(&results);
        for (kind, out) in results.into_iter().enumerate() {
            let mut times: Vec<f64> = out.iter().map(|o| o.seconds).collect();
            per_seed_p95[kind].push(percentile(&mut times, 0.95));
            all[kind].extend(out);
        }
    }
    if seeds.len() > 1 {
        println!(
            "\nPooled over the {} seeds {}: {} {planar_kind} and {} {spatial_label} problems planned.\n",
            seeds.len(),
            seeds
                .iter()
                .map(u64::to_string)
                .collect::<Vec<_>>()
                .join(", "),
            all[0].len(),
            all[1].len(),
        );
        print_table(&all);
        // Against the 95th-percentile targets of the suite (docs/results.md): per seed, and
        // pooled as the count of plans over the limit against the 5 % it allows.
        println!();
        for (kind, label, limit) in [(0, planar_kind, 0.5), (1, spatial_label, 2.0)] {
            let p95 = &per_seed_p95[kind];
            if all[kind].is_empty() {
                continue;
            }
            let within = p95.iter().filter(|&&t| t <= limit).count();
            // The pooled percentile is within the limit while the plans above its place are.
            let n = all[kind].len();
            let allowed = n - 1 - percentile_index(n, 0.95);
            let over = all[kind].iter().filter(|o| o.seconds > limit).count();
            let (lo, hi) = p95
                .iter()
                .fold((f64::INFINITY, 0.0_f64), |(a, b), &t| (a.min(t), b.max(t)));
            println!(
                "{label}: 95th percentile within {limit} s on {within} of {} seeds ({lo:.2}–{hi:.2} s); {over} plans over {limit} s (the pooled 95th percentile is within it while at most {allowed} are).",
                p95.len(),
            );
        }
    }
    // A plan called collision-free (or executable by its replayed equilibria) that the finer
    // check finds inside an obstacle fails the run.
    let false_clear: Vec<String> = all
        .iter()
        .flatten()
        .filter_map(|o| {
            o.checked_clearance
                .filter(|(d, _)| *d < -1e-6)
                .map(|(d, k)| format!("{} ({d:+.2e} L at k = {k:.4})", o.name))
        })
        .collect();
    if !false_clear.is_empty() {
        eprintln!(
            "plan_suite: plans called collision-free lie inside an obstacle on the finer check: {}",
            false_clear.join(", ")
        );
        std::process::exit(1);
    }
}
