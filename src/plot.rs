//! SVG pictures of a plan, like the paper's Fig. 17–19, drawn from its MCAP log with pure-Rust
//! plotting: snapshots of the optimal and feasible paths, the controlled end's trajectory, and
//! `U(k)` along both paths. Shapes are drawn in the plane of the paper (horizontal `z`,
//! vertical `x`).

use foxglove::Decode;
use foxglove::schemas::SceneUpdate;
use plotters::prelude::*;
use std::collections::BTreeMap;

/// One logged shape.
#[derive(Clone, Debug)]
pub struct Frame {
    /// Path parameter.
    pub k: f64,
    /// Rod points (case units).
    pub points: Vec<[f64; 3]>,
    /// Total energy (case units), from the metrics topic at the same time.
    pub energy: Option<f64>,
}

/// The two paths read back from a log.
#[derive(Clone, Debug, Default)]
pub struct PlanFrames {
    /// `/rod/optimal`.
    pub optimal: Vec<Frame>,
    /// `/rod/feasible`.
    pub feasible: Vec<Frame>,
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
    #[error("the log has no /rod/optimal or /rod/feasible shapes (was it written by `dlo plan`?)")]
    Empty,
    /// Drawing failed.
    #[error("cannot draw: {0}")]
    Draw(String),
}

/// Reads the optimal and feasible paths from the bytes of a plan's MCAP log.
pub fn read_frames(bytes: &[u8]) -> Result<PlanFrames, PlotError> {
    crate::mcap_log::writer::check_magic(bytes)?;
    let stream = mcap::MessageStream::new_with_options(
        bytes,
        enumset::enum_set!(mcap::read::Options::IgnoreEndMagic),
    )?;
    let mut shapes: BTreeMap<(&'static str, u64), Vec<[f64; 3]>> = BTreeMap::new();
    let mut energy: BTreeMap<(&'static str, u64), (f64, f64)> = BTreeMap::new();
    for m in stream {
        let Ok(m) = m else { break };
        let which = match m.channel.topic.as_str() {
            "/rod/optimal" | "/metrics/optimal" => "optimal",
            "/rod/feasible" | "/metrics/feasible" => "feasible",
            _ => continue,
        };
        if m.channel.topic.starts_with("/rod/") {
            let up = SceneUpdate::decode(&m.data[..])
                .map_err(|_| PlotError::Decode(m.channel.topic.clone()))?;
            let pts = up
                .entities
                .first()
                .and_then(|e| e.lines.first())
                .map(|l| l.points.iter().map(|p| [p.x, p.y, p.z]).collect())
                .unwrap_or_default();
            shapes.insert((which, m.log_time), pts);
        } else {
            let v: serde_json::Value = serde_json::from_slice(&m.data)
                .map_err(|_| PlotError::Decode(m.channel.topic.clone()))?;
            if let (Some(k), Some(u)) = (v["k"].as_f64(), v["energy"]["total"].as_f64()) {
                energy.insert((which, m.log_time), (k, u));
            }
        }
    }
    let mut out = PlanFrames::default();
    for ((which, t), points) in shapes {
        let (k, u) = energy
            .get(&(which, t))
            .map_or((t as f64 / 10.0e9, None), |&(k, u)| (k, Some(u)));
        let f = Frame {
            k,
            points,
            energy: u,
        };
        if which == "optimal" {
            out.optimal.push(f);
        } else {
            out.feasible.push(f);
        }
    }
    if out.optimal.is_empty() && out.feasible.is_empty() {
        return Err(PlotError::Empty);
    }
    Ok(out)
}

fn draw_err<E: std::fmt::Debug>(e: E) -> PlotError {
    PlotError::Draw(format!("{e:?}"))
}

/// Writes the SVG picture of `frames` to `path`; `title` heads it.
pub fn plot(frames: &PlanFrames, title: &str, path: &std::path::Path) -> Result<(), PlotError> {
    let root = SVGBackend::new(path, (1200, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(draw_err)?;
    let root = root.titled(title, ("sans-serif", 18)).map_err(draw_err)?;
    let panels = root.split_evenly((1, 3));
    let all: Vec<&[f64; 3]> = frames
        .optimal
        .iter()
        .chain(&frames.feasible)
        .flat_map(|f| f.points.iter())
        .collect();
    let (mut zmin, mut zmax, mut xmin, mut xmax) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in &all {
        zmin = zmin.min(p[2]);
        zmax = zmax.max(p[2]);
        xmin = xmin.min(p[0]);
        xmax = xmax.max(p[0]);
    }
    let pad = 0.05 * ((zmax - zmin).max(xmax - xmin)).max(1e-9);
    let blue = RGBColor(25, 100, 230);
    let red = RGBColor(230, 50, 50);

    // Both shape panels show the paper's plane: horizontal z, vertical x.
    let plane = |area, caption| -> Result<_, PlotError> {
        let mut chart = ChartBuilder::on(area)
            .caption(caption, ("sans-serif", 14))
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(40)
            .build_cartesian_2d((zmin - pad)..(zmax + pad), (xmin - pad)..(xmax + pad))
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .x_desc("z")
            .y_desc("x")
            .draw()
            .map_err(draw_err)?;
        Ok(chart)
    };
    // Snapshots at about seven values of k.
    {
        let mut chart = plane(&panels[0], "shapes (blue optimal, red feasible)")?;
        for (frames, colour) in [(&frames.optimal, blue), (&frames.feasible, red)] {
            for f in snapshots(frames, 7) {
                chart
                    .draw_series(LineSeries::new(
                        f.points.iter().map(|p| (p[2], p[0])),
                        colour.stroke_width(1),
                    ))
                    .map_err(draw_err)?;
            }
        }
    }
    // End-point trajectory.
    {
        let mut chart = plane(&panels[1], "controlled end P(L)")?;
        for (frames, colour) in [(&frames.optimal, blue), (&frames.feasible, red)] {
            chart
                .draw_series(LineSeries::new(
                    frames
                        .iter()
                        .filter_map(|f| f.points.last().map(|p| (p[2], p[0]))),
                    colour.stroke_width(2),
                ))
                .map_err(draw_err)?;
        }
    }
    // U(k).
    {
        let us: Vec<f64> = frames
            .optimal
            .iter()
            .chain(&frames.feasible)
            .filter_map(|f| f.energy)
            .collect();
        let umax = us.iter().copied().fold(0.0_f64, f64::max) * 1.05 + 1e-12;
        let umin = us.iter().copied().fold(0.0_f64, f64::min);
        let mut chart = ChartBuilder::on(&panels[2])
            .caption("potential energy U(k)", ("sans-serif", 14))
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(50)
            .build_cartesian_2d(0.0..1.0, umin..umax)
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .x_desc("k")
            .y_desc("U")
            .draw()
            .map_err(draw_err)?;
        for (frames, colour) in [(&frames.optimal, blue), (&frames.feasible, red)] {
            chart
                .draw_series(LineSeries::new(
                    frames.iter().filter_map(|f| f.energy.map(|u| (f.k, u))),
                    colour.stroke_width(2),
                ))
                .map_err(draw_err)?;
        }
    }
    root.present().map_err(draw_err)?;
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

/// The `F_mub`–`μ` curve (paper Fig. 15) as SVG.
pub fn plot_margin(
    margin: &crate::grasp::Margin,
    title: &str,
    path: &std::path::Path,
) -> Result<(), PlotError> {
    let root = SVGBackend::new(path, (600, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(draw_err)?;
    let mu_max = margin.mu.iter().copied().fold(0.0_f64, f64::max).max(1e-9);
    let f_top = margin
        .f_mub
        .iter()
        .copied()
        .fold(0.0_f64, f64::max)
        .max(1e-12)
        * 1.1;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 16))
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
    let blue = RGBColor(25, 100, 230);
    chart
        .draw_series(LineSeries::new(pts.iter().copied(), blue.stroke_width(2)))
        .map_err(draw_err)?;
    chart
        .draw_series(pts.iter().map(|&p| Circle::new(p, 3, blue.filled())))
        .map_err(draw_err)?;
    root.present().map_err(draw_err)?;
    Ok(())
}
