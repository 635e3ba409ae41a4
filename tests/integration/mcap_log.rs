//! The MCAP logs read back with the `mcap` crate: every message decodes as its schema, the rod
//! shapes logged equal the shapes computed, log times never go backwards on a topic; a killed
//! writer's finished chunks are recovered. Logs are left in `target/test-logs/` for the
//! reference Python reader (`.ci/run`).

use dlo_planner::case;
use dlo_planner::output::foxglove::{FrameTransform, Message, PoseInFrame, SceneUpdate};
use dlo_planner::output::mcap_log::recover::recover;
use dlo_planner::output::mcap_log::{McapWriter, PlanLog, SharedWriter};
use dlo_planner::planner::Planner;
use dlo_planner::planner::observer::{PlanObserver, Progress, ShapeRecord};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Arc, Mutex};

fn log_dir() -> PathBuf {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-logs");
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Counts shapes and forwards to the log.
struct Counting {
    log: PlanLog,
    shapes: u64,
}

impl PlanObserver for Counting {
    fn begin(&mut self, m: &dlo_planner::rod::model::Model) {
        self.log.begin(m);
    }
    fn phase(&mut self, n: &str) {
        self.log.phase(n);
    }
    fn shape(&mut self, m: &dlo_planner::rod::model::Model, r: &ShapeRecord) {
        self.shapes += 1;
        self.log.shape(m, r);
    }
    fn progress(&mut self, m: &dlo_planner::rod::model::Model, p: &Progress, w: &[f64]) {
        self.log.progress(m, p, w);
    }
}

/// Decodes every message; returns messages per topic. Panics on a bad message or time order.
fn check_log(bytes: &[u8]) -> HashMap<String, usize> {
    let summary = mcap::Summary::read(bytes).unwrap();
    assert!(summary.is_some(), "the log has a summary (it was finished)");
    let mut last: HashMap<String, u64> = HashMap::new();
    let mut counts: HashMap<String, usize> = HashMap::new();
    for m in mcap::MessageStream::new(bytes).unwrap() {
        let m = m.unwrap();
        let topic = m.channel.topic.clone();
        let schema = m.channel.schema.as_ref().unwrap().name.clone();
        match schema.as_str() {
            "foxglove.SceneUpdate" => {
                let u = SceneUpdate::decode(&m.data[..]).unwrap();
                assert!(!u.entities.is_empty(), "{topic}");
                if topic.starts_with("/rod/") {
                    let line = &u.entities[0].lines[0];
                    assert!(line.points.len() >= 2);
                    assert!(line.thickness > 0.0);
                }
            }
            "foxglove.FrameTransform" => {
                let t = FrameTransform::decode(&m.data[..]).unwrap();
                assert_eq!(t.child_frame_id, "rod");
            }
            "foxglove.PoseInFrame" => {
                PoseInFrame::decode(&m.data[..]).unwrap();
            }
            _ => {
                assert_eq!(m.channel.message_encoding, "json", "{topic} {schema}");
                let _: serde_json::Value = serde_json::from_slice(&m.data).unwrap();
            }
        }
        if let Some(&t) = last.get(&topic) {
            assert!(m.log_time >= t, "{topic}: time goes backwards");
        }
        last.insert(topic.clone(), m.log_time);
        *counts.entry(topic).or_default() += 1;
    }
    counts
}

#[test]
fn plan_log_decodes_and_counts_every_shape() {
    let c = case::load(Path::new("planning_cases/plan_paper_planar.json")).unwrap();
    let p = Planner::from_case(&c).unwrap();
    let path = log_dir().join("plan_paper_planar.mcap");
    let w: SharedWriter = Arc::new(Mutex::new(McapWriter::create(&path).unwrap()));
    let mut obs = Counting {
        log: PlanLog::new(w.clone(), c.obstacles.clone()),
        shapes: 0,
    };
    let r = p.run(&mut obs);
    assert!(obs.log.error().is_none());
    w.lock().unwrap().finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let counts = check_log(&bytes);
    let rods: usize = counts
        .iter()
        .filter(|(t, _)| t.starts_with("/rod/"))
        .map(|(_, n)| n)
        .sum();
    assert_eq!(rods as u64, obs.shapes);
    assert_eq!(counts["/rod/feasible"], r.replay.steps.len());
    assert_eq!(counts["/rod/optimal"], r.replay.steps.len());
    assert_eq!(counts["/metrics/feasible"], r.replay.steps.len());
    assert_eq!(counts["/scene/obstacles"], 1);
    assert!(counts["/optimiser/progress"] > 0);
}

#[test]
fn shape_command_logs_its_solve() {
    let dir = log_dir();
    let out = Command::new(env!("CARGO_BIN_EXE_dlo"))
        .args(["shape", "planning_cases/grasp_a_080.json", "--log-dir"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(dir.join("grasp_a_080.mcap")).unwrap();
    let counts = check_log(&bytes);
    assert_eq!(counts["/rod/shape"], 1);
}

/// A writer stopped without finishing (as if killed): the chunks it closed are recovered.
#[test]
fn unfinished_log_is_recovered() {
    let path = log_dir().join("unfinished_unit.mcap");
    let mut w = McapWriter::create(&path).unwrap();
    let up = dlo_planner::output::mcap_log::scene::rod_update(
        0,
        "rod",
        &[[0.0; 3], [0.0, 0.0, 1.0]],
        0.01,
        dlo_planner::output::mcap_log::scene::color(1.0, 0.0, 0.0, 1.0),
    );
    // A scene a viewer can show: the frame transform first, as every log has it.
    w.proto(
        "/tf",
        0,
        &dlo_planner::output::mcap_log::scene::gravity_transform(0),
    )
    .unwrap();
    for i in 0..500u64 {
        w.proto("/rod/optimal", i * 1000, &up).unwrap();
    }
    w.flush().unwrap();
    for i in 500..510u64 {
        w.proto("/rod/optimal", i * 1000, &up).unwrap();
    }
    // The bytes on disk now are what a killed process leaves; the writer never finishes.
    let bytes = std::fs::read(&path).unwrap();
    std::mem::forget(w);
    std::fs::remove_file(&path).unwrap();
    assert!(
        mcap::Summary::read(&bytes)
            .map(|s| s.is_none())
            .unwrap_or(true)
    );
    let mut fixed = std::io::Cursor::new(Vec::new());
    let r = recover(&bytes, &mut fixed).unwrap();
    assert!(r.truncated);
    assert!(r.messages >= 500, "{}", r.messages);
    let fixed = fixed.into_inner();
    let counts = check_log(&fixed);
    assert_eq!(counts.values().sum::<usize>() as u64, r.messages);
    assert_eq!(counts["/tf"], 1);
    std::fs::write(log_dir().join("recovered_unit.mcap"), &fixed).unwrap();
}

/// Starts `dlo plan` on the paper case with its log in `target/test-logs/<sub>/` and returns
/// once the chunk with the straight-line path is on disk (closed when optimisation starts,
/// about 4 KiB in): the run is then mid-way.
#[cfg(unix)]
fn plan_until_first_chunks(sub: &str) -> (std::process::Child, PathBuf) {
    let dir = log_dir().join(sub);
    let _ = std::fs::remove_dir_all(&dir);
    plan_into_until_first_chunks(&dir)
}

/// Starts `dlo plan` on the paper's case with its log in `dir`, and returns once the log it is
/// writing (under its temporary name, `<name>.mcap.<pid>.partial`) holds the straight path's 41
/// shapes in finished chunks (read as `dlo inspect` reads an unfinished log), however busy the
/// machine. The case verifies on a grid 50 times finer than its own, so that the run is still
/// going (for seconds) when the caller signals or kills it, however fast the machine.
fn plan_into_until_first_chunks(dir: &Path) -> (std::process::Child, PathBuf) {
    std::fs::create_dir_all(dir).unwrap();
    let mut case: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string("planning_cases/plan_paper_planar.json").unwrap(),
    )
    .unwrap();
    case["plan"]["verify_k_samples"] = 20001.into();
    let path = dir.join("slow_plan_paper_planar.json");
    std::fs::write(&path, case.to_string()).unwrap();
    let child = Command::new(env!("CARGO_BIN_EXE_dlo"))
        .arg("plan")
        .arg(&path)
        .arg("--log-dir")
        .arg(dir)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let log = dir.join(format!("plan_paper_planar.mcap.{}.partial", child.id()));
    let t0 = std::time::Instant::now();
    let straight_on_disk = || {
        let bytes = std::fs::read(&log).unwrap_or_default();
        dlo_planner::output::mcap_log::inspect::inspect(&bytes)
            .ok()
            .and_then(|i| i.topics.get("/rod/straight").map(|t| t.messages))
            == Some(41)
    };
    while !straight_on_disk() && t0.elapsed().as_secs() < 60 {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    (child, log)
}

/// A real run killed with SIGKILL mid-way leaves a file whose finished chunks `dlo recover`
/// turns into an indexed log.
#[test]
#[cfg(unix)]
fn killed_plan_is_recovered_by_the_cli() {
    let (mut child, broken) = plan_until_first_chunks("killed");
    child.kill().unwrap();
    let status = child.wait().unwrap();
    assert!(!status.success(), "the run was killed before it finished");
    let fixed = log_dir().join("killed_recovered.mcap");
    let out = Command::new(env!("CARGO_BIN_EXE_dlo"))
        .arg("recover")
        .arg(&broken)
        .arg(&fixed)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(&fixed).unwrap();
    let counts = check_log(&bytes);
    assert!(
        counts.get("/scene/obstacles").copied().unwrap_or(0) == 1,
        "{counts:?}"
    );
    let inspect = Command::new(env!("CARGO_BIN_EXE_dlo"))
        .arg("inspect")
        .arg(&fixed)
        .arg("--json")
        .output()
        .unwrap();
    assert!(inspect.status.success());
    let v: serde_json::Value = serde_json::from_slice(&inspect.stdout).unwrap();
    assert_eq!(v["indexed"], true);
    assert_eq!(
        v["messages"].as_u64().unwrap() as usize,
        counts.values().sum::<usize>()
    );
}

#[test]
fn plot_writes_an_svg_from_a_log() {
    let dir = log_dir().join("plot");
    let out = Command::new(env!("CARGO_BIN_EXE_dlo"))
        .args([
            "plan",
            "planning_cases/plan_paper_planar.json",
            "--plot",
            "--log-dir",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    // Exit 0 or 5 (replay verdict); the picture is written either way.
    assert!(
        matches!(out.status.code(), Some(0) | Some(5)),
        "{:?}",
        out.status
    );
    let svg = std::fs::read_to_string(dir.join("plan_paper_planar.svg")).unwrap();
    assert!(
        svg.starts_with("<svg") && svg.contains("polyline"),
        "{}",
        &svg[..200.min(svg.len())]
    );
    // The scene: the block (filled triangles of its silhouette), the legend's entries, and the
    // colour bar along k (50 filled rectangles in the ramp's colours, from its first stop).
    assert!(svg.contains("<polygon"), "no obstacle drawn");
    for label in [
        "obstacle",
        "plan at k",
        "replay by the end pose",
        "start",
        "goal",
    ] {
        assert!(svg.contains(label), "legend lacks {label}");
    }
    let c = dlo_planner::output::plot::ramp(0.01);
    let fill = format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2);
    assert!(svg.contains(&fill), "no colour bar ({fill})");
    // A planar case has one view; the paper's case has no y extent.
    assert!(!svg.contains("top view"));
}

/// `dlo plot` also draws a static shape's log and a grasp log (its held shapes and fingers),
/// and says what it needs of any other log.
#[test]
fn plot_draws_shape_and_grasp_logs() {
    let dir = log_dir().join("plot-others");
    let dlo = env!("CARGO_BIN_EXE_dlo");
    for (cmd, case) in [
        ("shape", "planning_cases/pinned_buckling_080.json"),
        ("margin", "planning_cases/grasp_b_pinch.json"),
    ] {
        let out = Command::new(dlo)
            .args([cmd, case, "--log-dir"])
            .arg(&dir)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let name = Path::new(case).file_stem().unwrap().to_str().unwrap();
        let log = dir.join(format!("{name}.mcap"));
        let svg = dir.join(format!("{name}.log.svg"));
        let out = Command::new(dlo)
            .arg("plot")
            .arg(&log)
            .arg(&svg)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.contains("polyline"));
        if cmd == "margin" {
            assert!(text.contains("finger"), "fingers missing");
            assert!(text.contains("held shapes"));
        } else {
            assert!(text.contains("static shape"));
        }
    }
}

/// Ctrl-C (SIGINT) and SIGTERM finish the log before exiting with code 130: the file is
/// indexed and in place.
#[test]
#[cfg(unix)]
fn interrupted_plan_leaves_a_finished_log() {
    // Ctrl-C (SIGINT) and SIGTERM alike.
    for signal in ["INT", "TERM"] {
        let (child, partial) = plan_until_first_chunks(&format!("interrupted-{signal}"));
        let status = Command::new("kill")
            .args([format!("-{signal}"), child.id().to_string()])
            .status()
            .unwrap();
        assert!(status.success());
        let out = child.wait_with_output().unwrap();
        assert_eq!(
            out.status.code(),
            Some(130),
            "{signal}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        // Finished and moved into place.
        assert!(!partial.exists(), "{signal}: the temporary log is left");
        let bytes = std::fs::read(partial.with_file_name("plan_paper_planar.mcap")).unwrap();
        let counts = check_log(&bytes);
        assert!(counts["/rod/straight"] == 41, "{signal}: {counts:?}");
    }
}

/// `dlo margin --json --plot` prints the documented keys, draws the curve and logs every held
/// shape.
#[test]
fn margin_command_reports_plots_and_logs() {
    let dir = log_dir().join("margin");
    let out = Command::new(env!("CARGO_BIN_EXE_dlo"))
        .args([
            "margin",
            "planning_cases/grasp_b_pinch.json",
            "--json",
            "--plot",
            "--log-dir",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in [
        "f_mub",
        "s_a",
        "direction",
        "timing_s",
        "table",
        "mu",
        "capped",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    let table = v["table"].as_array().unwrap();
    assert_eq!(table.len(), 81);
    let svg = std::fs::read_to_string(dir.join("grasp_b_pinch.svg")).unwrap();
    assert!(svg.starts_with("<svg"));
    let counts = check_log(&std::fs::read(dir.join("grasp_b_pinch.mcap")).unwrap());
    assert_eq!(counts["/grasp/held_shape"], 81);
    assert_eq!(counts["/grasp/limits"], 81);
}

/// A rerun killed hard leaves the previous run's finished log as it was (the new log is written
/// under a temporary name and moved into place only when finished), and its own finished chunks
/// in that temporary file.
#[test]
#[cfg(unix)]
fn killed_rerun_keeps_the_finished_log() {
    let dir = log_dir().join("rerun");
    let _ = std::fs::remove_dir_all(&dir);
    let out = Command::new(env!("CARGO_BIN_EXE_dlo"))
        .args(["plan", "planning_cases/plan_paper_planar.json", "--log-dir"])
        .arg(&dir)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    let log = dir.join("plan_paper_planar.mcap");
    let before = std::fs::read(&log).unwrap();
    check_log(&before);
    let (mut child, partial) = plan_into_until_first_chunks(&dir);
    child.kill().unwrap();
    child.wait().unwrap();
    assert_eq!(
        std::fs::read(&log).unwrap(),
        before,
        "the finished log changed"
    );
    assert!(std::fs::metadata(&partial).unwrap().len() > 0);
    let _ = std::fs::remove_file(&partial);
}
