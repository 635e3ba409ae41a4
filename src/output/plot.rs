//! SVG pictures drawn from MCAP logs with pure-Rust plotting, like the paper's Fig. 17–19:
//! a plan's snapshots coloured along `k` (with a colour bar), its replay, the start and goal
//! shapes, the controlled end's path and `U(k)`; a static shape; a grasp's held shapes and
//! fingers. Obstacles are drawn as their silhouettes in each view (for a planar case the x–z
//! view; a 3D case adds a top view, z–y). Shapes are in the paper's axes: horizontal `z`,
//! vertical `x` (up).

use crate::output::foxglove::{Message, Pose, SceneUpdate};
use crate::output::topics;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::collections::BTreeMap;

/// One logged shape.
#[derive(Clone, Debug)]
pub struct Frame {
    /// Path parameter (a plan), or the index over the count (a grasp's held shapes).
    pub k: f64,
    /// Rod points (case units).
    pub points: Vec<[f64; 3]>,
    /// Total energy (case units), from the metrics topic at the same time.
    pub energy: Option<f64>,
}

/// What a log holds that can be drawn.
#[derive(Clone, Debug, Default)]
pub struct PlanFrames {
    /// `/rod/optimal`.
    pub optimal: Vec<Frame>,
    /// `/rod/feasible`.
    pub feasible: Vec<Frame>,
    /// `U(k)` of the straight-line path (`/metrics/straight`).
    pub straight_energy: Vec<(f64, f64)>,
    /// The start and goal shapes (`/rod/endpoints`).
    pub start: Option<Vec<[f64; 3]>>,
    /// See `start`.
    pub goal: Option<Vec<[f64; 3]>>,
    /// A static solve's shape (`/rod/shape`).
    pub shape: Option<Vec<[f64; 3]>>,
    /// A grasp's held shapes (`/grasp/held_shape`), in table order.
    pub held: Vec<Frame>,
    /// Finger contacts (`/grasp/fingers`): position and the unit direction it pushes in.
    pub fingers: Vec<([f64; 3], [f64; 3])>,
    /// Obstacles (`/scene/obstacles`) as triangles in the rod frame.
    pub obstacles: Vec<[[f64; 3]; 3]>,
}

/// Errors of [`read_frames`] and [`plot`].
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The log could not be read.
    #[error("cannot read the log: {0}")]
    Log(#[from] mcap::McapError),
    /// A message did not decode.
    #[error("message on {0} does not decode")]
    Decode(String),
    /// Nothing to draw.
    #[error(
        "the log has no rod shapes to draw (/rod/optimal, /rod/feasible, /rod/shape or /grasp/held_shape: was it written by `dlo plan`, `shape` or `margin`?)"
    )]
    Empty,
    /// Drawing failed.
    #[error("cannot draw: {0}")]
    Draw(String),
}

fn line_points(up: &SceneUpdate) -> Vec<[f64; 3]> {
    up.entities
        .first()
        .and_then(|e| e.lines.first())
        .map(|l| l.points.iter().map(|p| [p.x, p.y, p.z]).collect())
        .unwrap_or_default()
}

/// Position and rotation matrix (rows) of a pose.
fn pose_parts(p: &Option<Pose>) -> ([f64; 3], [[f64; 3]; 3]) {
    let Some(p) = p else {
        return (
            [0.0; 3],
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        );
    };
    let t = p.position.as_ref().map_or([0.0; 3], |v| [v.x, v.y, v.z]);
    let q = p
        .orientation
        .as_ref()
        .map_or([1.0, 0.0, 0.0, 0.0], |q| [q.w, q.x, q.y, q.z]);
    (t, crate::planner::trajectory::rotation_of_quaternion(q))
}

fn place(t: [f64; 3], m: [[f64; 3]; 3], p: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| t[i] + m[i][0] * p[0] + m[i][1] * p[1] + m[i][2] * p[2])
}

/// Triangles of a unit shape `f(u, v)` on a `nu × nv` grid of `[0, 1]²`.
fn grid_triangles(nu: usize, nv: usize, f: impl Fn(f64, f64) -> [f64; 3]) -> Vec<[[f64; 3]; 3]> {
    let mut out = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            let (u0, u1) = (i as f64 / nu as f64, (i + 1) as f64 / nu as f64);
            let (v0, v1) = (j as f64 / nv as f64, (j + 1) as f64 / nv as f64);
            let (a, b, c, d) = (f(u0, v0), f(u1, v0), f(u1, v1), f(u0, v1));
            out.push([a, b, c]);
            out.push([a, c, d]);
        }
    }
    out
}

/// Every primitive of an obstacle update as triangles in the rod frame.
fn obstacle_triangles(up: &SceneUpdate) -> Vec<[[f64; 3]; 3]> {
    use std::f64::consts::{PI, TAU};
    let mut out = Vec::new();
    let mut add = |pose: &Option<Pose>, tris: Vec<[[f64; 3]; 3]>| {
        let (t, m) = pose_parts(pose);
        out.extend(tris.into_iter().map(|tri| tri.map(|p| place(t, m, p))));
    };
    for e in &up.entities {
        for c in &e.cubes {
            let s = c.size.as_ref().map_or([0.0; 3], |v| [v.x, v.y, v.z]);
            let mut tris = Vec::new();
            // Six faces, each a unit grid mapped onto the face.
            for axis in 0..3 {
                for sign in [-0.5, 0.5] {
                    let (a1, a2) = ((axis + 1) % 3, (axis + 2) % 3);
                    tris.extend(grid_triangles(1, 1, |u, v| {
                        let mut p = [0.0; 3];
                        p[axis] = sign * s[axis];
                        p[a1] = (u - 0.5) * s[a1];
                        p[a2] = (v - 0.5) * s[a2];
                        p
                    }));
                }
            }
            add(&c.pose, tris);
        }
        for sp in &e.spheres {
            let s = sp.size.as_ref().map_or([0.0; 3], |v| [v.x, v.y, v.z]);
            add(
                &sp.pose,
                grid_triangles(24, 12, |u, v| {
                    let (a, b) = (TAU * u, PI * v);
                    [
                        0.5 * s[0] * b.sin() * a.cos(),
                        0.5 * s[1] * b.sin() * a.sin(),
                        0.5 * s[2] * b.cos(),
                    ]
                }),
            );
        }
        for cy in &e.cylinders {
            let s = cy.size.as_ref().map_or([0.0; 3], |v| [v.x, v.y, v.z]);
            let mut tris = grid_triangles(24, 1, |u, v| {
                let a = TAU * u;
                [0.5 * s[0] * a.cos(), 0.5 * s[1] * a.sin(), (v - 0.5) * s[2]]
            });
            for z in [-0.5, 0.5] {
                tris.extend(grid_triangles(24, 1, |u, v| {
                    let a = TAU * u;
                    [0.5 * v * s[0] * a.cos(), 0.5 * v * s[1] * a.sin(), z * s[2]]
                }));
            }
            add(&cy.pose, tris);
        }
        for tl in &e.triangles {
            let pts: Vec<[f64; 3]> = tl.points.iter().map(|p| [p.x, p.y, p.z]).collect();
            add(
                &tl.pose,
                pts.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
            );
        }
    }
    out
}

/// Reads what can be drawn from the bytes of a `dlo plan`, `shape` or `margin` log.
pub fn read_frames(bytes: &[u8]) -> Result<PlanFrames, PlotError> {
    let mut shapes: BTreeMap<(&'static str, u64), Vec<[f64; 3]>> = BTreeMap::new();
    let mut energy: BTreeMap<(&'static str, u64), (f64, f64)> = BTreeMap::new();
    let mut out = PlanFrames::default();
    let decode = |m: &mcap::Message| {
        SceneUpdate::decode(&m.data[..]).map_err(|_| PlotError::Decode(m.channel.topic.clone()))
    };
    // A broken file is drawn as far as it can be read.
    crate::output::mcap_log::reader::for_each_readable(bytes, |m| -> Result<(), PlotError> {
        let topic = m.channel.topic.as_str();
        match topic {
            topics::ROD_OPTIMAL | topics::ROD_FEASIBLE | topics::GRASP_HELD_SHAPE => {
                let which = match topic {
                    topics::ROD_OPTIMAL => "optimal",
                    topics::ROD_FEASIBLE => "feasible",
                    _ => "held",
                };
                shapes.insert((which, m.log_time), line_points(&decode(m)?));
            }
            topics::METRICS_OPTIMAL | topics::METRICS_FEASIBLE | topics::METRICS_STRAIGHT => {
                let v: serde_json::Value = serde_json::from_slice(&m.data)
                    .map_err(|_| PlotError::Decode(m.channel.topic.clone()))?;
                if let (Some(k), Some(u)) = (v["k"].as_f64(), v["energy"]["total"].as_f64()) {
                    match topic {
                        topics::METRICS_OPTIMAL => energy.insert(("optimal", m.log_time), (k, u)),
                        topics::METRICS_FEASIBLE => energy.insert(("feasible", m.log_time), (k, u)),
                        _ => {
                            out.straight_energy.push((k, u));
                            None
                        }
                    };
                }
            }
            topics::ROD_ENDPOINTS => {
                let up = decode(m)?;
                let pts = line_points(&up);
                match up.entities.first().map(|e| e.id.as_str()) {
                    Some("goal") => out.goal = Some(pts),
                    _ if out.start.is_none() => out.start = Some(pts),
                    _ => out.goal = Some(pts),
                }
            }
            topics::SHAPE => out.shape = Some(line_points(&decode(m)?)),
            topics::OBSTACLES => out.obstacles = obstacle_triangles(&decode(m)?),
            topics::GRASP_FINGERS => {
                for e in decode(m)?.entities {
                    for a in &e.arrows {
                        // The arrow ends at the contact, pointing the way the finger pushes.
                        let (t, r) = pose_parts(&a.pose);
                        let n = [r[0][0], r[1][0], r[2][0]];
                        let len = a.shaft_length + a.head_length;
                        out.fingers.push(([0, 1, 2].map(|i| t[i] + len * n[i]), n));
                    }
                }
            }
            _ => {}
        }
        Ok(())
    })?;
    let held_count = shapes.keys().filter(|(w, _)| *w == "held").count();
    for ((which, t), points) in shapes {
        let (k, u) = energy
            .get(&(which, t))
            .map_or((0.0, None), |&(k, u)| (k, Some(u)));
        let f = Frame {
            k,
            points,
            energy: u,
        };
        match which {
            "optimal" => out.optimal.push(f),
            "feasible" => out.feasible.push(f),
            _ => {
                let i = out.held.len();
                out.held.push(Frame {
                    k: i as f64 / (held_count.max(2) - 1) as f64,
                    ..f
                });
            }
        }
    }
    if out.optimal.is_empty()
        && out.feasible.is_empty()
        && out.shape.is_none()
        && out.held.is_empty()
    {
        return Err(PlotError::Empty);
    }
    Ok(out)
}

fn draw_err<E: std::fmt::Debug>(e: E) -> PlotError {
    PlotError::Draw(format!("{e:?}"))
}

/// The colour ramp along `k ∈ [0, 1]` (perceptually ordered, blue → teal → green → yellow,
/// after the upper three quarters of viridis).
pub fn ramp(k: f64) -> RGBColor {
    const STOPS: [(f64, [f64; 3]); 5] = [
        (0.0, [59.0, 82.0, 139.0]),
        (0.33, [33.0, 145.0, 140.0]),
        (0.66, [94.0, 201.0, 98.0]),
        (0.85, [190.0, 220.0, 50.0]),
        (1.0, [253.0, 200.0, 37.0]),
    ];
    let k = k.clamp(0.0, 1.0);
    let i = STOPS
        .iter()
        .rposition(|s| s.0 <= k)
        .unwrap_or(0)
        .min(STOPS.len() - 2);
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let t = (k - a.0) / (b.0 - a.0);
    let c = [0, 1, 2].map(|j| (a.1[j] + t * (b.1[j] - a.1[j])).round() as u8);
    RGBColor(c[0], c[1], c[2])
}

const START: RGBColor = RGBColor(38, 166, 64);
const GOAL: RGBColor = RGBColor(140, 51, 179);
const REPLAY: RGBColor = RGBColor(230, 50, 50);
const END_PATH: RGBColor = RGBColor(20, 20, 20);
const OBSTACLE: RGBColor = RGBColor(196, 202, 212);
const PLAN: RGBColor = RGBColor(25, 100, 230);
const FEASIBLE: RGBColor = RGBColor(230, 50, 50);

/// A view of the scene: the two rod-frame axes it shows (horizontal, vertical) and their names.
#[derive(Clone, Copy)]
struct View {
    h: usize,
    v: usize,
    caption: &'static str,
}

const SIDE: View = View {
    h: 2,
    v: 0,
    caption: "side view (z right, x up)",
};
const TOP: View = View {
    h: 2,
    v: 1,
    caption: "top view (z right, y up)",
};

fn axis_name(i: usize) -> &'static str {
    ["x", "y", "z"][i]
}

/// Draws one view: obstacles, the `k`-coloured snapshots, the replay, start and goal, the
/// controlled end's path and the fingers, with a legend.
fn draw_view(
    area: &DrawingArea<SVGBackend, Shift>,
    f: &PlanFrames,
    view: View,
    bounds: ([f64; 3], [f64; 3]),
) -> Result<(), PlotError> {
    let (lo, hi) = bounds;
    let (h, v) = (view.h, view.v);
    let span = (hi[h] - lo[h]).max(hi[v] - lo[v]).max(1e-9);
    let pad = 0.06 * span;
    // Equal scales: centre the shorter axis' range.
    let (ch, cv) = (0.5 * (lo[h] + hi[h]), 0.5 * (lo[v] + hi[v]));
    let half = 0.5 * span + pad;
    let mut chart = ChartBuilder::on(area)
        .caption(view.caption, ("sans-serif", 14))
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(45)
        .build_cartesian_2d((ch - half)..(ch + half), (cv - half)..(cv + half))
        .map_err(draw_err)?;
    chart
        .configure_mesh()
        .x_desc(axis_name(h))
        .y_desc(axis_name(v))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(draw_err)?;
    let pr = |p: &[f64; 3]| (p[h], p[v]);
    if !f.obstacles.is_empty() {
        chart
            .draw_series(
                f.obstacles
                    .iter()
                    .map(|t| Polygon::new(t.iter().map(pr).collect::<Vec<_>>(), OBSTACLE.filled())),
            )
            .map_err(draw_err)?
            .label("obstacle")
            .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], OBSTACLE.filled()));
    }
    let line = |pts: &[[f64; 3]]| pts.iter().map(pr).collect::<Vec<_>>();
    let mut legend_k = false;
    let shaped = if f.optimal.is_empty() {
        &f.held
    } else {
        &f.optimal
    };
    for fr in snapshots(shaped, 11) {
        let s = chart
            .draw_series(LineSeries::new(
                line(&fr.points),
                ramp(fr.k).stroke_width(4),
            ))
            .map_err(draw_err)?;
        if !legend_k {
            legend_k = true;
            s.label(if f.optimal.is_empty() {
                "held shapes (colour: order in the table)"
            } else {
                "plan at k (colour bar)"
            })
            .legend(|(x, y)| PathElement::new([(x, y), (x + 14, y)], ramp(0.5).stroke_width(4)));
        }
    }
    let mut legend_r = false;
    for fr in snapshots(&f.feasible, 11) {
        let s = chart
            .draw_series(LineSeries::new(line(&fr.points), REPLAY.stroke_width(1)))
            .map_err(draw_err)?;
        if !legend_r {
            legend_r = true;
            s.label("replay by the end pose")
                .legend(|(x, y)| PathElement::new([(x, y), (x + 14, y)], REPLAY.stroke_width(1)));
        }
    }
    if !f.optimal.is_empty() {
        chart
            .draw_series(DashedLineSeries::new(
                f.optimal.iter().filter_map(|fr| fr.points.last().map(pr)),
                4,
                3,
                END_PATH.stroke_width(1),
            ))
            .map_err(draw_err)?
            .label("controlled end's path")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 14, y)], END_PATH.stroke_width(1)));
    }
    for (pts, colour, name) in [
        (&f.start, START, "start"),
        (&f.goal, GOAL, "goal"),
        (&f.shape, PLAN, "static shape"),
    ] {
        if let Some(pts) = pts {
            chart
                .draw_series(LineSeries::new(line(pts), colour.stroke_width(4)))
                .map_err(draw_err)?
                .label(name)
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 14, y)], colour.stroke_width(4))
                });
        }
    }
    if !f.fingers.is_empty() {
        let len = 0.08 * span;
        for (i, (p, n)) in f.fingers.iter().enumerate() {
            // The finger sits on the side it pushes from: a line ending at the contact.
            let tail = [0, 1, 2].map(|c| p[c] - len * n[c]);
            chart
                .draw_series([TriangleMarker::new(pr(p), 5, FEASIBLE.filled())])
                .map_err(draw_err)?;
            let s = chart
                .draw_series(LineSeries::new(
                    [pr(&tail), pr(p)],
                    FEASIBLE.stroke_width(3),
                ))
                .map_err(draw_err)?;
            if i == 0 {
                s.label("finger (pushes towards the rod)").legend(|(x, y)| {
                    PathElement::new([(x, y), (x + 14, y)], FEASIBLE.stroke_width(3))
                });
            }
        }
    }
    draw_legend(&mut chart)
}

/// The legend of a chart's labelled series, in its upper right corner.
fn draw_legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<
        'a,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
) -> Result<(), PlotError> {
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK.mix(0.3))
        .label_font(("sans-serif", 11))
        .draw()
        .map_err(draw_err)
}

/// A vertical colour bar of [`ramp`] from `k = 0` (bottom) to 1 (top).
fn draw_colour_bar(area: &DrawingArea<SVGBackend, Shift>, label: &str) -> Result<(), PlotError> {
    let mut chart = ChartBuilder::on(area)
        .margin_top(40)
        .margin_bottom(40)
        .margin_left(5)
        .margin_right(5)
        .y_label_area_size(45)
        .build_cartesian_2d(0.0..1.0, 0.0..1.0)
        .map_err(draw_err)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .disable_y_mesh()
        .disable_x_axis()
        .y_labels(6)
        .y_label_style(("sans-serif", 12))
        .y_desc(label)
        .axis_desc_style(("sans-serif", 13))
        .draw()
        .map_err(draw_err)?;
    let n = 50;
    chart
        .draw_series((0..n).map(|i| {
            let (a, b) = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
            Rectangle::new([(0.0, a), (1.0, b)], ramp(0.5 * (a + b)).filled())
        }))
        .map_err(draw_err)?;
    Ok(())
}

/// Draws `U(k)` along the plan, its replay and the straight-line path.
fn draw_energy(area: &DrawingArea<SVGBackend, Shift>, f: &PlanFrames) -> Result<(), PlotError> {
    let us: Vec<f64> = f
        .optimal
        .iter()
        .chain(&f.feasible)
        .filter_map(|fr| fr.energy)
        .chain(f.straight_energy.iter().map(|e| e.1))
        .collect();
    let umax = us.iter().copied().fold(0.0_f64, f64::max) * 1.05 + 1e-12;
    let umin = us.iter().copied().fold(0.0_f64, f64::min);
    let mut chart = ChartBuilder::on(area)
        .caption("potential energy U(k)", ("sans-serif", 14))
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(50)
        .build_cartesian_2d(0.0..1.0, umin..umax)
        .map_err(draw_err)?;
    chart
        .configure_mesh()
        .light_line_style(WHITE.mix(0.0))
        .x_desc("k")
        .y_desc("U")
        .draw()
        .map_err(draw_err)?;
    let mut straight = f.straight_energy.clone();
    straight.sort_by(|a, b| a.0.total_cmp(&b.0));
    chart
        .draw_series(DashedLineSeries::new(
            straight,
            5,
            4,
            RGBColor(150, 150, 150).stroke_width(2),
        ))
        .map_err(draw_err)?
        .label("straight-line path")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 14, y)], RGBColor(150, 150, 150)));
    // The plan wide, the replay narrow on top of it: both stay visible where they coincide.
    for (frames, colour, width, name) in [
        (&f.optimal, PLAN, 5, "plan"),
        (&f.feasible, FEASIBLE, 2, "replay"),
    ] {
        chart
            .draw_series(LineSeries::new(
                frames.iter().filter_map(|fr| fr.energy.map(|u| (fr.k, u))),
                colour.stroke_width(width),
            ))
            .map_err(draw_err)?
            .label(name)
            .legend(move |(x, y)| {
                PathElement::new([(x, y), (x + 14, y)], colour.stroke_width(width))
            });
    }
    draw_legend(&mut chart)
}

/// Writes the SVG picture of `frames` to `path`; `title` heads it. A plan gets its views, a
/// colour bar along `k` and `U(k)`; a static shape or a grasp its views (a grasp's colour bar
/// orders its held shapes).
pub fn plot(frames: &PlanFrames, title: &str, path: &std::path::Path) -> Result<(), PlotError> {
    let pts: Vec<&[f64; 3]> = frames
        .optimal
        .iter()
        .chain(&frames.feasible)
        .chain(&frames.held)
        .flat_map(|f| f.points.iter())
        .chain(frames.start.iter().flatten())
        .chain(frames.goal.iter().flatten())
        .chain(frames.shape.iter().flatten())
        .chain(frames.fingers.iter().map(|f| &f.0))
        .collect();
    let mut lo = [f64::MAX; 3];
    let mut hi = [f64::MIN; 3];
    for p in &pts {
        for c in 0..3 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    // Obstacles widen the view by at most the rod's own extent on each side.
    let extent = (0..3).map(|c| hi[c] - lo[c]).fold(0.0, f64::max).max(1e-9);
    let spatial = hi[1] - lo[1] > 1e-9 * extent;
    for t in &frames.obstacles {
        for p in t {
            for c in 0..3 {
                lo[c] = lo[c].min(p[c].max(lo[c] - 0.5 * extent));
                hi[c] = hi[c].max(p[c].min(hi[c] + 0.5 * extent));
            }
        }
    }
    let plan = !frames.optimal.is_empty();
    let ramped = plan || !frames.held.is_empty();
    let views: Vec<View> = if spatial { vec![SIDE, TOP] } else { vec![SIDE] };
    let view_w = 480u32;
    let width =
        view_w * views.len() as u32 + if ramped { 100 } else { 0 } + if plan { 440 } else { 0 };
    let root = SVGBackend::new(path, (width, 460)).into_drawing_area();
    root.fill(&WHITE).map_err(draw_err)?;
    let root = root.titled(title, ("sans-serif", 18)).map_err(draw_err)?;
    let mut rest = root;
    for view in views {
        let (a, b) = rest.split_horizontally(view_w);
        draw_view(&a, frames, view, (lo, hi))?;
        rest = b;
    }
    if ramped {
        let (a, b) = rest.split_horizontally(100);
        draw_colour_bar(&a, if plan { "k" } else { "table order" })?;
        rest = b;
    }
    if plan {
        draw_energy(&rest, frames)?;
    }
    rest.present().map_err(draw_err)?;
    Ok(())
}

/// About `n` frames spread evenly in `k`.
fn snapshots(frames: &[Frame], n: usize) -> Vec<&Frame> {
    let mut out: Vec<&Frame> = Vec::new();
    for i in 0..n {
        let target = i as f64 / (n - 1) as f64;
        if let Some(f) = frames
            .iter()
            .min_by(|a, b| (a.k - target).abs().total_cmp(&(b.k - target).abs()))
            && !out.iter().any(|g| std::ptr::eq(*g, f))
        {
            out.push(f);
        }
    }
    out
}

/// The `F_mub`–`μ` curve (paper Fig. 15) beside the grasped rod and its fingers, as SVG.
/// `shape` is the initial grasped shape and `fingers` each finger's contact point and the unit
/// direction it pushes in (case units).
pub fn plot_margin(
    margin: &crate::grasp::Margin,
    shape: &[[f64; 3]],
    fingers: &[([f64; 3], [f64; 3])],
    title: &str,
    path: &std::path::Path,
) -> Result<(), PlotError> {
    let root = SVGBackend::new(path, (1080, 440)).into_drawing_area();
    root.fill(&WHITE).map_err(draw_err)?;
    let root = root.titled(title, ("sans-serif", 16)).map_err(draw_err)?;
    let (left, right) = root.split_horizontally(480);
    let scene = PlanFrames {
        shape: Some(shape.to_vec()),
        fingers: fingers.to_vec(),
        ..PlanFrames::default()
    };
    let mut lo = [f64::MAX; 3];
    let mut hi = [f64::MIN; 3];
    for p in shape.iter().chain(fingers.iter().map(|f| &f.0)) {
        for c in 0..3 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    let mut view = SIDE;
    view.caption = "the grasp (z right, x up)";
    draw_view(&left, &scene, view, (lo, hi))?;
    let mu_max = margin.mu.iter().copied().fold(0.0_f64, f64::max).max(1e-9);
    let f_top = margin
        .f_mub
        .iter()
        .copied()
        .fold(0.0_f64, f64::max)
        .max(1e-12)
        * 1.1;
    let mut chart = ChartBuilder::on(&right)
        .caption("disturbance force margin", ("sans-serif", 14))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..mu_max * 1.05, 0.0..f_top)
        .map_err(draw_err)?;
    chart
        .configure_mesh()
        .x_desc("friction coefficient μ")
        .y_desc("disturbance force margin F_mub")
        .draw()
        .map_err(draw_err)?;
    let pts: Vec<(f64, f64)> = margin
        .mu
        .iter()
        .copied()
        .zip(margin.f_mub.iter().copied())
        .collect();
    chart
        .draw_series(LineSeries::new(pts.iter().copied(), PLAN.stroke_width(2)))
        .map_err(draw_err)?;
    chart
        .draw_series(pts.iter().map(|&p| Circle::new(p, 3, PLAN.filled())))
        .map_err(draw_err)?;
    root.present().map_err(draw_err)?;
    Ok(())
}
