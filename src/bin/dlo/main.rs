//! The `dlo` command-line tool: one run per case file.
//!
//! Exit codes: 0 success; 1 an output could not be written; 2 bad input (case file or usage);
//! 3 the solver did not converge; 4 no collision-free plan; 5 the replay does not coincide with
//! the plan; 130 interrupted (the log is finished first).

mod batch;

use clap::{Parser, Subcommand};
use dlo_planner::case::{self, Case};
use dlo_planner::output::mcap_log::{McapWriter, PlanLog, SharedWriter, log_static};
use dlo_planner::planner::observer::{PlanObserver, Progress, ShapeRecord};
use dlo_planner::planner::{PlanVerdict, Planner};
use dlo_planner::statics::report::{ShapeReport, coefficients_json, pose};
use dlo_planner::statics::{evaluate_shape, solve_static};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Instant;

/// Exit code: an output could not be written.
const EXIT_OUTPUT: u8 = 1;
/// Exit code: no collision-free plan.
const EXIT_COLLISION: u8 = 4;
/// Exit code: the replay does not coincide with the plan.
const EXIT_NOT_COINCIDENT: u8 = 5;
/// Exit code: interrupted.
const EXIT_INTERRUPTED: i32 = 130;

/// Exit code: bad input.
const EXIT_BAD_INPUT: u8 = 2;
/// Exit code: the solver did not converge.
const EXIT_NOT_CONVERGED: u8 = 3;

#[derive(Parser)]
#[command(
    name = "dlo",
    version,
    about = "Static shapes and deformation paths of deformable linear objects (Wakamatsu & Hirai 2004)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Solve the static shape of a case (minimum internal energy under its constraints).
    Shape {
        /// Case files (JSON) or folders of them; several run in parallel, with a summary.
        #[arg(required = true, value_name = "CASE")]
        cases: Vec<PathBuf>,
        /// With several cases: how many run at a time (default: the machine's cores).
        #[arg(long)]
        jobs: Option<usize>,
        /// Print a JSON object on stdout instead of the readable summary.
        #[arg(long)]
        json: bool,
        /// Directory of the MCAP log (`<case name>.mcap`).
        #[arg(long, default_value = "logs")]
        log_dir: PathBuf,
    },
    /// Evaluate the shape given by the case's explicit coefficients, without optimising.
    Energy {
        /// Case file (JSON) with a `shape` section.
        case: PathBuf,
        /// Print a JSON object on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Plan a deformation path (the case's `plan` section), verify it and replay it by the
    /// controlled end; log every shape to `<log-dir>/<case name>.mcap`.
    Plan {
        /// Case files (JSON) with a `plan` section, or folders of case files (those with a
        /// `plan` section run); several run in parallel, with a summary.
        #[arg(required = true, value_name = "CASE")]
        cases: Vec<PathBuf>,
        /// With several cases: how many run at a time (default: the machine's cores).
        #[arg(long)]
        jobs: Option<usize>,
        /// Print a JSON object on stdout.
        #[arg(long)]
        json: bool,
        /// Also write an SVG picture of the plan next to the log.
        #[arg(long)]
        plot: bool,
        /// Directory of the MCAP log and the gripper trajectory (`<case name>.trajectory.csv`).
        #[arg(long, default_value = "logs")]
        log_dir: PathBuf,
        /// Time the gripper trajectory for an end that moves at most this fast (case length
        /// units per second).
        #[arg(long, value_name = "SPEED")]
        max_speed: Option<f64>,
        /// With `--max-speed`: the end also turns at most this fast (rad/s; default unlimited).
        #[arg(long, value_name = "RAD_PER_S", requires = "max_speed")]
        max_angular_speed: Option<f64>,
    },
    /// Disturbance force margin of a grasp (the case's `grasp` section, paper §6): `F_mub` for
    /// each friction coefficient, where and in which direction it is attained.
    Margin {
        /// Case files (JSON) with fingers among their constraints and a `grasp` section, or
        /// folders of case files (those with a `grasp` section run).
        #[arg(required = true, value_name = "CASE")]
        cases: Vec<PathBuf>,
        /// With several cases: how many run at a time (default: the machine's cores).
        #[arg(long)]
        jobs: Option<usize>,
        /// Print a JSON object on stdout.
        #[arg(long)]
        json: bool,
        /// Also write the F_mub–μ curve as SVG next to the log.
        #[arg(long)]
        plot: bool,
        /// Directory of the MCAP log.
        #[arg(long, default_value = "logs")]
        log_dir: PathBuf,
    },
    /// Rewrite an MCAP file whose writer was killed into a fully indexed one.
    Recover {
        /// The broken file.
        broken: PathBuf,
        /// Where to write the recovered file.
        fixed: PathBuf,
    },
    /// Print an MCAP file's topics, schemas, message counts and time range.
    Inspect {
        /// The file.
        file: PathBuf,
        /// Print a JSON object on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Draw the optimal and feasible paths of a plan's MCAP log as SVG.
    Plot {
        /// The log written by `dlo plan`.
        file: PathBuf,
        /// The SVG to write (default: the log's name with `.svg`).
        output: Option<PathBuf>,
    },
}

fn main() -> ExitCode {
    let code = run();
    if STDOUT_FAILED.load(std::sync::atomic::Ordering::SeqCst) {
        // The output is lost: that is worse than any verdict but an interruption.
        return ExitCode::from(EXIT_OUTPUT);
    }
    code
}

fn run() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() { EXIT_BAD_INPUT } else { 0 });
        }
    };
    match cli.command {
        Command::Shape {
            cases,
            jobs,
            json,
            log_dir,
        } => match single(
            "shape",
            &cases,
            None,
            json,
            jobs,
            &log_args(&log_dir, false),
        ) {
            Ok(case) => run_shape(&case, json, &log_dir),
            Err(code) => code,
        },
        Command::Energy { case, json } => run_energy(&case, json),
        Command::Plan {
            cases,
            jobs,
            json,
            plot,
            log_dir,
            max_speed,
            max_angular_speed,
        } => {
            let speeds = match speed_limits(max_speed, max_angular_speed) {
                Ok(s) => s,
                Err(code) => return code,
            };
            let mut extra = log_args(&log_dir, plot);
            for (flag, v) in [
                ("--max-speed", max_speed),
                ("--max-angular-speed", max_angular_speed),
            ] {
                if let Some(v) = v {
                    extra.extend([flag.to_string(), v.to_string()]);
                }
            }
            match single("plan", &cases, Some("plan"), json, jobs, &extra) {
                Ok(case) => run_plan(&case, json, plot, &log_dir, speeds),
                Err(code) => code,
            }
        }
        Command::Margin {
            cases,
            jobs,
            json,
            plot,
            log_dir,
        } => match single(
            "margin",
            &cases,
            Some("grasp"),
            json,
            jobs,
            &log_args(&log_dir, plot),
        ) {
            Ok(case) => run_margin(&case, json, plot, &log_dir),
            Err(code) => code,
        },
        Command::Recover { broken, fixed } => run_recover(&broken, &fixed),
        Command::Inspect { file, json } => run_inspect(&file, json),
        Command::Plot { file, output } => {
            let out = output.unwrap_or_else(|| file.with_extension("svg"));
            if same_file(&file, &out) {
                eprintln!(
                    "error: {}: the picture would overwrite its own log: give another OUT.svg",
                    out.display()
                );
                return ExitCode::from(EXIT_BAD_INPUT);
            }
            run_plot(&file, &out)
        }
    }
}

/// The arguments every case of a batch gets: its log folder, and `--plot`.
fn log_args(log_dir: &Path, plot: bool) -> Vec<String> {
    let mut a = vec!["--log-dir".to_string(), log_dir.display().to_string()];
    if plot {
        a.push("--plot".into());
    }
    a
}

/// The one case file of a single run; several (or a folder) run as a batch instead, whose exit
/// code comes back as the error.
fn single(
    command: &str,
    cases: &[PathBuf],
    section: Option<&str>,
    json: bool,
    jobs: Option<usize>,
    extra: &[String],
) -> Result<PathBuf, ExitCode> {
    if let [case] = cases
        && !case.is_dir()
    {
        return Ok(case.clone());
    }
    let files = batch::expand(cases, section).map_err(|e| {
        eprintln!("error: {e}");
        ExitCode::from(EXIT_BAD_INPUT)
    })?;
    let jobs = jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    Err(batch::run(command, &files, extra, json, jobs))
}

/// The log being written and its final path, finished and moved into place by the Ctrl-C
/// (and SIGTERM) handler.
static ACTIVE_LOG: OnceLock<(SharedWriter, PathBuf)> = OnceLock::new();

/// Where the log bound for `path` is written until it is finished: a name of this process's own
/// beside it, so that a run killed hard leaves the previous run's finished log whole (and its
/// own finished chunks, for `dlo recover`), and two runs at once never write one file.
fn partial_path(path: &Path) -> PathBuf {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(format!(".{}.partial", std::process::id()));
    path.with_file_name(name)
}

/// Opens the log bound for `dir/<name>.mcap` (under [`partial_path`], its header on disk at
/// once) and arms the Ctrl-C and SIGTERM handler to finish it.
fn open_log(dir: &Path, name: &str) -> Result<(SharedWriter, PathBuf), ExitCode> {
    let path = dir.join(format!("{name}.mcap"));
    let tmp = partial_path(&path);
    let created = McapWriter::create(&tmp).and_then(|mut w| w.flush().map(|()| w));
    let w = created.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        eprintln!(
            "error: {}: cannot create the log: {}",
            path.display(),
            causes(&e)
        );
        ExitCode::from(EXIT_OUTPUT)
    })?;
    let shared: SharedWriter = Arc::new(Mutex::new(w));
    if ACTIVE_LOG.set((shared.clone(), path.clone())).is_ok() {
        let _ = ctrlc::set_handler(|| {
            if let Some((w, path)) = ACTIVE_LOG.get() {
                let mut w = dlo_planner::output::mcap_log::lock(w);
                if w.finish().is_ok() {
                    let _ = std::fs::rename(partial_path(path), path);
                }
            }
            eprintln!("interrupted: the log was finished and is readable");
            std::process::exit(EXIT_INTERRUPTED);
        });
    }
    Ok((shared, path))
}

/// Finishes a log and moves it into place; reports failure as exit code 1 and then leaves no
/// half-written file.
fn close_log(w: &SharedWriter, path: &Path) -> Result<(), ExitCode> {
    let tmp = partial_path(path);
    let mut guard = dlo_planner::output::mcap_log::lock(w);
    let was_open = !guard.is_finished();
    let finished = guard.finish().map_err(|e| causes(&e));
    drop(guard);
    let moved = match finished {
        Ok(()) if was_open => std::fs::rename(&tmp, path).map_err(|e| e.to_string()),
        other => other,
    };
    moved.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        eprintln!("error: {}: cannot finish the log: {e}", path.display());
        ExitCode::from(EXIT_OUTPUT)
    })
}

fn load(path: &std::path::Path) -> Result<Case, ExitCode> {
    let case = case::load(path).map_err(|e| {
        eprintln!("error: {e}");
        ExitCode::from(EXIT_BAD_INPUT)
    })?;
    for w in &case.warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
    Ok(case)
}

fn run_shape(path: &std::path::Path, json: bool, log_dir: &Path) -> ExitCode {
    let mut c = match load(path) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let (log, log_path) = match open_log(log_dir, &c.name) {
        Ok(l) => l,
        Err(code) => return code,
    };
    let t0 = Instant::now();
    let sol = solve_static(&mut c.problem, &c.initial, &c.options);
    let secs = t0.elapsed().as_secs_f64();
    let report = ShapeReport::solved(&c.name, &c.problem, &sol, &c.report_points, secs);
    let metrics = serde_json::to_value(&report).expect("report serialises");
    let logged = log_static(&log, &c.problem.model, &c.obstacles, &sol.a, &metrics)
        .map_err(|e| causes(&e))
        .and_then(|()| close_log(&log, &log_path).map_err(|_| "cannot finish".to_string()));
    if let Err(e) = logged {
        eprintln!("error: {}: cannot write the log: {e}", log_path.display());
        return ExitCode::from(EXIT_OUTPUT);
    }
    print_report(&report, json);
    if sol.status == dlo_planner::statics::SolveStatus::Converged {
        ExitCode::SUCCESS
    } else {
        eprintln!(
            "error: {}: the solve did not converge ({}): violation {:.2e}, KKT residual {:.2e}",
            path.display(),
            report.status,
            sol.max_violation,
            sol.kkt_residual
        );
        ExitCode::from(EXIT_NOT_CONVERGED)
    }
}

fn run_energy(path: &std::path::Path, json: bool) -> ExitCode {
    let mut c = match load(path) {
        Ok(c) => c,
        Err(code) => return code,
    };
    if !c.explicit_shape {
        eprintln!(
            "error: {}: field `shape`: `dlo energy` needs explicit coefficients",
            path.display()
        );
        return ExitCode::from(EXIT_BAD_INPUT);
    }
    let t0 = Instant::now();
    let a = c.initial.clone();
    let ev = evaluate_shape(&mut c.problem, &a);
    let p = &c.problem;
    let report = ShapeReport {
        case: c.name.clone(),
        status: "evaluated".into(),
        energy: ev.energy.into(),
        reactions: ev.reactions,
        balance: ev.balance,
        self_contacts: ev.self_contacts,
        max_violation: ev.max_violation,
        kkt_residual: Some(ev.kkt_residual),
        stable: None,
        stability: None,
        min_reduced_eigenvalue: None,
        neutral_modes: None,
        gauge_modes: None,
        end_pose: pose(p, &a, p.model.rod.length),
        points: c.report_points.iter().map(|&s| pose(p, &a, s)).collect(),
        coefficients: coefficients_json(p, &a),
        angle_frame: p.model.angle_frame(),
        outer_iterations: None,
        timing_s: t0.elapsed().as_secs_f64(),
    };
    print_report(&report, json);
    ExitCode::SUCCESS
}

/// Writes to stdout, ignoring a closed pipe (e.g. `dlo shape … | head`).
/// Set when stdout could not be written (other than a closed pipe): the run then exits with 1.
static STDOUT_FAILED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Writes to stdout. A closed pipe (e.g. `dlo shape … | head`) ends the output quietly; any
/// other failure (a full device) is reported and makes the exit code 1.
fn emit(text: &str) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    let written = out.write_all(text.as_bytes()).and_then(|()| out.flush());
    if let Err(e) = written
        && e.kind() != std::io::ErrorKind::BrokenPipe
        && !STDOUT_FAILED.swap(true, std::sync::atomic::Ordering::SeqCst)
    {
        eprintln!("error: stdout: cannot write: {e}");
    }
}

fn print_report(r: &ShapeReport, json: bool) {
    use std::fmt::Write;
    if json {
        emit(&format!(
            "{}\n",
            serde_json::to_string_pretty(r).expect("report serialises")
        ));
        return;
    }
    let mut o = String::new();
    let _ = writeln!(o, "case {}: {}", r.case, r.status);
    let e = &r.energy;
    let _ = writeln!(
        o,
        "  energy U = {:.6e}  (flexural {:.6e}, torsional {:.6e}, extensional {:.6e}, gravitational {:.6e}; work {:.6e})",
        e.total, e.flexural, e.torsional, e.extensional, e.gravitational, e.work
    );
    let _ = write!(o, "  max violation {:.2e}", r.max_violation);
    if let Some(k) = r.kkt_residual {
        let _ = write!(o, ", KKT residual {k:.2e}");
    }
    o.push_str(match r.stability {
        Some(dlo_planner::statics::stability::Verdict::Stable) => ", stable",
        Some(dlo_planner::statics::stability::Verdict::Unstable) => ", UNSTABLE",
        Some(dlo_planner::statics::stability::Verdict::Marginal) => ", stability marginal",
        None => "",
    });
    if let Some(n @ 1..) = r.neutral_modes {
        let _ = write!(
            o,
            " ({n} neutral mode{}: the second-order check cannot decide along {})",
            if n == 1 { "" } else { "s" },
            if n == 1 { "it" } else { "them" }
        );
    }
    let _ = writeln!(o);
    for re in &r.reactions {
        let _ = writeln!(
            o,
            "  reaction {:24} force [{:+.6e}, {:+.6e}, {:+.6e}]  moment [{:+.6e}, {:+.6e}, {:+.6e}]",
            re.constraint,
            re.force[0],
            re.force[1],
            re.force[2],
            re.moment[0],
            re.moment[1],
            re.moment[2]
        );
    }
    let b = &r.balance;
    let _ = writeln!(
        o,
        "  moment balance residual [{:+.3e}, {:+.3e}, {:+.3e}] ({:.1e} of the largest moment)",
        b.moment_residual[0], b.moment_residual[1], b.moment_residual[2], b.relative
    );
    if let Some(c) = r.self_contacts.first() {
        let f = (c.force[0].powi(2) + c.force[1].powi(2) + c.force[2].powi(2)).sqrt();
        let _ = writeln!(
            o,
            "  self-contact at {} pair(s) of points; largest force {f:.6e} between s = {:.4} and s = {:.4}",
            r.self_contacts.len(),
            c.s[0],
            c.s[1]
        );
    }
    if let Some(f) = r.angle_frame {
        let _ = writeln!(
            o,
            "  angles measured from a frame whose pole points along [{:+.4}, {:+.4}, {:+.4}] (angle_frame; coefficients are in it)",
            f[0][2], f[1][2], f[2][2]
        );
    }
    for p in &r.points {
        let _ = writeln!(
            o,
            "  s = {:10.4}: x = [{:+.6}, {:+.6}, {:+.6}]",
            p.s, p.position[0], p.position[1], p.position[2]
        );
    }
    let _ = writeln!(o, "  time {:.3} ms", r.timing_s * 1e3);
    emit(&o);
}

/// Progress on stderr (only when it is a terminal) plus the MCAP log.
struct CliObserver {
    log: PlanLog,
    tty: bool,
    started: Instant,
}

impl PlanObserver for CliObserver {
    fn begin(&mut self, model: &dlo_planner::rod::model::Model) {
        self.log.begin(model);
    }
    fn phase(&mut self, name: &str) {
        self.log.phase(name);
        if self.tty {
            eprint!(
                "\r\x1b[2K[{:7.2} s] {name}",
                self.started.elapsed().as_secs_f64()
            );
        }
    }
    fn shape(&mut self, model: &dlo_planner::rod::model::Model, r: &ShapeRecord) {
        self.log.shape(model, r);
        if self.tty && r.kind == dlo_planner::planner::observer::PathKind::Feasible {
            eprint!(
                "\r\x1b[2K[{:7.2} s] replay k = {:.3}  d = {:.2e}",
                self.started.elapsed().as_secs_f64(),
                r.k,
                r.deviation.unwrap_or(0.0)
            );
        }
    }
    fn progress(&mut self, model: &dlo_planner::rod::model::Model, p: &Progress, worst: &[f64]) {
        self.log.progress(model, p, worst);
        if self.tty {
            eprint!(
                "\r\x1b[2K[{:7.2} s] optimise start {} stage {} iteration {}: max U {:.4e} at k = {:.3}, violation {:.1e}",
                self.started.elapsed().as_secs_f64(),
                p.start,
                p.stage,
                p.outer,
                p.sampled_max,
                p.k_worst,
                p.violation
            );
        }
    }
}

#[derive(serde::Serialize)]
struct PlanReport<'a> {
    case: &'a str,
    verdict: dlo_planner::planner::PlanVerdict,
    #[serde(flatten)]
    result: &'a dlo_planner::planner::PlanResult,
    start_energy: f64,
    goal_energy: f64,
    mcap: String,
    log_shapes: u64,
    trajectory_csv: String,
}

/// The validated `--max-speed` and `--max-angular-speed` (the latter infinite when absent).
fn speed_limits(v: Option<f64>, w: Option<f64>) -> Result<Option<[f64; 2]>, ExitCode> {
    let Some(v) = v else { return Ok(None) };
    let w = w.unwrap_or(f64::INFINITY);
    for (name, x, inf_ok) in [("--max-speed", v, false), ("--max-angular-speed", w, true)] {
        if !(x > 0.0 && (inf_ok || x.is_finite())) {
            eprintln!("error: {name}: must be a positive finite number, got {x}");
            return Err(ExitCode::from(EXIT_BAD_INPUT));
        }
    }
    Ok(Some([v, w]))
}

/// Writes `text` to `path` through a temporary file ([`partial_path`], as the log) moved into
/// place, so that a failed write leaves no half-written file (and an earlier run's file stays
/// whole until the new one is).
fn write_atomically(path: &Path, text: &str) -> Result<(), ExitCode> {
    let tmp = partial_path(path);
    let written = std::fs::write(&tmp, text).and_then(|()| std::fs::rename(&tmp, path));
    written.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        eprintln!("error: {}: cannot write: {e}", path.display());
        ExitCode::from(EXIT_OUTPUT)
    })
}

fn run_plan(
    path: &Path,
    json: bool,
    plot: bool,
    log_dir: &Path,
    speeds: Option<[f64; 2]>,
) -> ExitCode {
    let c = match load(path) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let t0 = Instant::now();
    let planner = match Planner::from_case(&c) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(EXIT_BAD_INPUT);
        }
    };
    let t_end = t0.elapsed().as_secs_f64();
    let (log, log_path) = match open_log(log_dir, &c.name) {
        Ok(l) => l,
        Err(code) => return code,
    };
    let mut obs = CliObserver {
        log: PlanLog::new(log.clone(), c.obstacles.clone()),
        tty: std::io::stderr().is_terminal(),
        started: Instant::now(),
    };
    let mut result = planner.run(&mut obs);
    result.timing_s.endpoints = t_end;
    if let Some([v, w]) = speeds {
        result.trajectory.time_parameterise(v, w);
    }
    if obs.tty {
        eprintln!();
    }
    if let Some(e) = obs.log.error() {
        eprintln!(
            "error: {}: cannot write the log: {}",
            log_path.display(),
            causes(e)
        );
        let _ = close_log(&log, &log_path);
        return ExitCode::from(EXIT_OUTPUT);
    }
    if let Err(code) = close_log(&log, &log_path) {
        return code;
    }
    let csv_path = log_dir.join(format!("{}.trajectory.csv", c.name));
    if let Err(code) = write_atomically(&csv_path, &result.trajectory.to_csv()) {
        return code;
    }
    let report = PlanReport {
        case: &c.name,
        verdict: result.verdict(),
        result: &result,
        start_energy: planner.start.energy.internal(),
        goal_energy: planner.goal.energy.internal(),
        mcap: log_path.display().to_string(),
        log_shapes: obs.log.shapes(),
        trajectory_csv: csv_path.display().to_string(),
    };
    if json {
        emit(&format!(
            "{}\n",
            serde_json::to_string_pretty(&report).expect("report serialises")
        ));
    } else {
        emit(&plan_summary(&report));
    }
    if plot {
        let svg = log_path.with_extension("svg");
        if run_plot(&log_path, &svg) != ExitCode::SUCCESS {
            return ExitCode::from(EXIT_OUTPUT);
        }
    }
    match result.verdict() {
        PlanVerdict::SelfCollision => {
            let (gap, k) = result.verification.self_contact.unwrap_or((0.0, 0.0));
            eprintln!(
                "error: {}: no collision-free plan: the verification grid finds the rod crossing itself (gap {gap:.3e} at k = {k:.3}); {}",
                path.display(),
                TRY_COLLISION
            );
            ExitCode::from(EXIT_COLLISION)
        }
        PlanVerdict::ObstacleCollision => {
            eprintln!(
                "error: {}: no collision-free plan: the verification grid finds clearance {:.3e} (obstacle {} at k = {:.3}, s = {:.4}); {}",
                path.display(),
                result.min_clearance.unwrap_or(0.0),
                result
                    .verification
                    .obstacles
                    .iter()
                    .min_by(|a, b| a.clearance.total_cmp(&b.clearance))
                    .map_or("?", |o| o.obstacle.as_str()),
                result
                    .verification
                    .obstacles
                    .iter()
                    .min_by(|a, b| a.clearance.total_cmp(&b.clearance))
                    .map_or(0.0, |o| o.k),
                result
                    .verification
                    .obstacles
                    .iter()
                    .min_by(|a, b| a.clearance.total_cmp(&b.clearance))
                    .map_or(0.0, |o| o.s),
                TRY_COLLISION
            );
            ExitCode::from(EXIT_COLLISION)
        }
        PlanVerdict::NotConverged => {
            eprintln!(
                "error: {}: the path optimiser did not converge ({:?}, violation {:.2e})",
                path.display(),
                result.optimiser,
                result.violation
            );
            ExitCode::from(EXIT_NOT_CONVERGED)
        }
        PlanVerdict::Departs | PlanVerdict::SnapsThrough => {
            eprintln!(
                "error: {}: the replay by the controlled end does not coincide with the plan: max deviation {:.3} L at k = {:.3} (tolerance {} L){}; {}",
                path.display(),
                result.replay.max_deviation_over_l,
                result.replay.k_at_max_deviation,
                result.replay.tolerance,
                if result.replay.snaps.is_empty() {
                    String::new()
                } else {
                    format!(", snap-through at k = {}", snap_list(&result.replay.snaps))
                },
                TRY_DEPARTURE
            );
            ExitCode::from(EXIT_NOT_COINCIDENT)
        }
        PlanVerdict::Executable => ExitCode::SUCCESS,
    }
}

/// What to try when no plan is collision-free (the case file's `plan` fields).
const TRY_COLLISION: &str = "try plan.swept_clearance: true, more plan.k_samples, more path terms (plan.fallback_path_terms, e.g. [6, 8]) or more plan.starts";

/// What to try when the replay departs from the plan.
const TRY_DEPARTURE: &str = "try more path terms (plan.fallback_path_terms, e.g. [6, 8]), more plan.starts, or a stronger plan.equilibrium_weight; the replayed path in the log is what the controlled end does";

fn plan_summary(r: &PlanReport) -> String {
    use std::fmt::Write;
    let p = r.result;
    let mut o = String::new();
    let _ = writeln!(
        o,
        "case {}: {} ({}; optimiser {})",
        r.case, r.verdict, p.status, p.optimiser
    );
    let _ = writeln!(
        o,
        "  U_max {:.6e} at k = {:.3} (optimiser's samples {:.6e})   straight path U_max {:.6e}   start {:.6e}  goal {:.6e}",
        p.u_max, p.k_at_u_max, p.sampled_u_max, p.u_max_straight, r.start_energy, r.goal_energy
    );
    let _ = writeln!(
        o,
        "  clearance {}   straight path clearance {}   optimiser violation {:.2e}",
        p.min_clearance.map_or("n/a".into(), |c| format!("{c:.4e}")),
        p.min_clearance_straight
            .map_or("n/a".into(), |c| format!("{c:.4e}")),
        p.violation
    );
    if p.starts.len() + p.starts_not_run > 1 {
        // Starts with fallback path terms ran: say which count each start used.
        let fallback = p
            .starts
            .iter()
            .any(|s| s.path_terms != p.starts[0].path_terms);
        let not_run = if p.starts_not_run > 0 {
            format!(
                " ({} more not run: a plan is estimated to coincide)",
                p.starts_not_run
            )
        } else {
            String::new()
        };
        let _ = writeln!(
            o,
            "  starts: {}{not_run}, chosen {} (path terms {}); verified U_max (sampled; samples' distance to their equilibria) {}",
            p.starts.len(),
            p.chosen_start,
            p.path_terms,
            p.starts
                .iter()
                .map(|s| {
                    let clear = if s.collision_free { "" } else { ", collides" };
                    let (u, us, st) = (s.u_max, s.sampled_u_max, s.status);
                    let d = s
                        .equilibrium_deviation
                        .map_or("n/a".into(), |d| format!("{d:.4} L"));
                    let m = if fallback {
                        format!("m = {}: ", s.path_terms)
                    } else {
                        String::new()
                    };
                    format!("{m}{u:.4} ({us:.4}; {d}; {st:?}{clear})")
                })
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let rp = &p.replay;
    let _ = writeln!(
        o,
        "  replay: max deviation {:.4} L at k = {:.3} (tolerance {} L) -> {}; U_max {:.6e}; all stable {}; all converged {}; snap-through at k = [{}]",
        rp.max_deviation_over_l,
        rp.k_at_max_deviation,
        rp.tolerance,
        if rp.coincide {
            "coincide"
        } else {
            "DO NOT COINCIDE"
        },
        rp.u_max,
        rp.all_stable,
        rp.all_converged,
        snap_list(&rp.snaps)
    );
    if let Some(c) = rp.min_clearance {
        let contact = if rp.max_contact_force > 0.0 {
            format!(
                "leans on obstacles: largest contact force {:.4e} at k = {:.3}",
                rp.max_contact_force, rp.k_at_max_contact_force
            )
        } else {
            "touches no obstacle".to_string()
        };
        let _ = writeln!(o, "  replayed path: clearance {c:.4e}; {contact}");
    }
    let t = &p.trajectory;
    let _ = writeln!(
        o,
        "  gripper: path length {:.4e} (straight line {:.4e}), largest step {:.4e}; turns {:.4} rad (largest step {:.4} rad){}; poses {}",
        t.path_length,
        t.straight_distance,
        t.largest_step,
        t.rotation_angle,
        t.largest_rotation_step,
        t.duration_s
            .map_or(String::new(), |d| format!("; duration {d:.3} s")),
        r.trajectory_csv
    );
    let _ = writeln!(
        o,
        "  log {} ({} shapes)   time: endpoints {:.3} s, plan {:.3} s, replay {:.3} s",
        r.mcap, r.log_shapes, p.timing_s.endpoints, p.timing_s.plan, p.timing_s.replay
    );
    o
}

/// An error and its chain of causes, `outer: inner: …` (the MCAP crate wraps I/O errors in a
/// generic message whose cause says what went wrong).
fn causes(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        text.push_str(&format!(": {s}"));
        source = s.source();
    }
    text
}

/// The `k` of snap-throughs, four decimals each.
fn snap_list(snaps: &[f64]) -> String {
    snaps
        .iter()
        .map(|k| format!("{k:.4}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The largest log read by `inspect`, `recover` and `plot` (bytes).
const MAX_LOG_BYTES: u64 = 4 << 30;

fn read_file(path: &Path) -> Result<Vec<u8>, ExitCode> {
    case::read_capped(path, MAX_LOG_BYTES).map_err(|e| {
        eprintln!("error: {}: cannot read: {e}", path.display());
        ExitCode::from(EXIT_BAD_INPUT)
    })
}

/// Whether two paths name the same file (an existing one, or the same path as written).
fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
}

fn run_recover(broken: &Path, fixed: &Path) -> ExitCode {
    let bytes = match read_file(broken) {
        Ok(b) => b,
        Err(c) => return c,
    };
    if same_file(broken, fixed) {
        eprintln!(
            "error: {}: the recovered log would overwrite its input: give another FIXED.mcap",
            fixed.display()
        );
        return ExitCode::from(EXIT_BAD_INPUT);
    }
    // Written beside the output under a name of this process's own, never the input's.
    let tmp = partial_path(fixed);
    let out = match std::fs::File::create(&tmp) {
        Ok(f) => std::io::BufWriter::new(f),
        Err(e) => {
            eprintln!("error: {}: cannot create: {e}", tmp.display());
            return ExitCode::from(EXIT_OUTPUT);
        }
    };
    match dlo_planner::output::mcap_log::recover::recover(&bytes, out) {
        Ok(r) => {
            if let Err(e) = std::fs::rename(&tmp, fixed) {
                let _ = std::fs::remove_file(&tmp);
                eprintln!("error: {}: cannot write: {e}", fixed.display());
                return ExitCode::from(EXIT_OUTPUT);
            }
            emit(&format!(
                "recovered {} messages from {} into {}{}\n",
                r.messages,
                broken.display(),
                fixed.display(),
                match (&r.stopped_at, &r.damage) {
                    (Some(s), _) => format!(" (the input was cut short: {s})"),
                    (None, Some(d)) =>
                        format!(" (every message was read; the input is damaged: {d})"),
                    (None, None) => " (the input was complete)".into(),
                }
            ));
            ExitCode::SUCCESS
        }
        // Reading is from memory: an I/O error is the output's.
        Err(mcap::McapError::Io(e)) => {
            let _ = std::fs::remove_file(&tmp);
            eprintln!("error: {}: cannot write: {e}", fixed.display());
            ExitCode::from(EXIT_OUTPUT)
        }
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            eprintln!("error: {}: not an MCAP file: {e}", broken.display());
            ExitCode::from(EXIT_BAD_INPUT)
        }
    }
}

fn run_inspect(file: &Path, json: bool) -> ExitCode {
    use std::fmt::Write;
    let bytes = match read_file(file) {
        Ok(b) => b,
        Err(c) => return c,
    };
    let ins = match dlo_planner::output::mcap_log::inspect::inspect(&bytes) {
        Ok(i) => i,
        Err(e) => {
            eprintln!("error: {}: not an MCAP file: {e}", file.display());
            return ExitCode::from(EXIT_BAD_INPUT);
        }
    };
    if json {
        emit(&format!(
            "{}\n",
            serde_json::to_string_pretty(&ins).expect("inspection serialises")
        ));
        return ExitCode::SUCCESS;
    }
    let mut o = String::new();
    let _ = writeln!(
        o,
        "{}: {} messages, {} s to {} s, {}",
        file.display(),
        ins.messages,
        ins.start_time.map_or(0.0, |t| t as f64 * 1e-9),
        ins.end_time.map_or(0.0, |t| t as f64 * 1e-9),
        if ins.indexed {
            "indexed"
        } else {
            "NOT indexed (run `dlo recover`)"
        }
    );
    for (name, t) in &ins.topics {
        let _ = writeln!(
            o,
            "  {name:28} {:26} {:9} {:7} messages  {:8.3} s .. {:8.3} s",
            t.schema,
            t.encoding,
            t.messages,
            t.first_log_time as f64 * 1e-9,
            t.last_log_time as f64 * 1e-9
        );
    }
    if let Some(s) = &ins.stopped_at {
        let _ = writeln!(o, "  the file ends early: {s}");
    } else if let Some(d) = &ins.damage {
        let _ = writeln!(o, "  every message was read, but the file is damaged: {d}");
    }
    emit(&o);
    ExitCode::SUCCESS
}

fn run_plot(file: &Path, out: &Path) -> ExitCode {
    let bytes = match read_file(file) {
        Ok(b) => b,
        Err(c) => return c,
    };
    let frames = match dlo_planner::output::plot::read_frames(&bytes) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("error: {}: {e}", file.display());
            return ExitCode::from(EXIT_BAD_INPUT);
        }
    };
    let title = file
        .file_stem()
        .map_or("plan".into(), |s| s.to_string_lossy().into_owned());
    match dlo_planner::output::plot::plot(&frames, &title, out) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}: {e}", out.display());
            ExitCode::from(EXIT_OUTPUT)
        }
    }
}

#[derive(serde::Serialize)]
struct MarginReport<'a> {
    case: &'a str,
    #[serde(flatten)]
    margin: &'a dlo_planner::grasp::Margin,
    mcap: String,
    timing_s: f64,
}

fn run_margin(path: &Path, json: bool, plot: bool, log_dir: &Path) -> ExitCode {
    use std::fmt::Write;
    let c = match load(path) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let grasp = match dlo_planner::grasp::Grasp::from_case(&c) {
        Ok(g) => g,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(EXIT_BAD_INPUT);
        }
    };
    let (log, log_path) = match open_log(log_dir, &c.name) {
        Ok(l) => l,
        Err(code) => return code,
    };
    let tty = std::io::stderr().is_terminal();
    let t0 = Instant::now();
    let progress = |done: usize, total: usize| {
        if tty {
            eprint!(
                "\r\x1b[2K[{:6.2} s] margin {done}/{total}",
                t0.elapsed().as_secs_f64()
            );
        }
    };
    let margin = match grasp.margin(&progress) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("error: {e}");
            let _ = close_log(&log, &log_path);
            return ExitCode::from(EXIT_BAD_INPUT);
        }
    };
    let secs = t0.elapsed().as_secs_f64();
    if tty {
        eprintln!();
    }
    let fingers = grasp.finger_contacts();
    let logged = dlo_planner::output::mcap_log::log_margin(
        &log,
        &c.problem.model,
        &c.obstacles,
        &fingers,
        &margin,
    )
    .map_err(|e| causes(&e))
    .and_then(|()| close_log(&log, &log_path).map_err(|_| "cannot finish".to_string()));
    if let Err(e) = logged {
        eprintln!("error: {}: cannot write the log: {e}", log_path.display());
        return ExitCode::from(EXIT_OUTPUT);
    }
    let report = MarginReport {
        case: &c.name,
        margin: &margin,
        mcap: log_path.display().to_string(),
        timing_s: secs,
    };
    if json {
        emit(&format!(
            "{}\n",
            serde_json::to_string_pretty(&report).expect("report serialises")
        ));
    } else {
        let mut o = String::new();
        let _ = writeln!(
            o,
            "case {}: disturbance force margin over {} points × {} directions",
            c.name,
            grasp.points.len(),
            grasp.directions.len()
        );
        for (name, f) in &margin.initial_forces {
            let _ = writeln!(
                o,
                "  initial contact {name:16} normal {:.6e}  tangential {:.3e}",
                f.normal, f.tangential
            );
        }
        for k in 0..margin.mu.len() {
            let d = margin.direction[k];
            let _ = writeln!(
                o,
                "  mu = {:5.2}: F_mub = {:.6e}{} at s_a = {:.4}, n = [{:+.3}, {:+.3}, {:+.3}]",
                margin.mu[k],
                margin.f_mub[k],
                if margin.capped[k] {
                    " (search cap: nothing failed)"
                } else {
                    ""
                },
                margin.s_a[k],
                d[0],
                d[1],
                d[2]
            );
        }
        let unconverged: usize = margin.table.iter().map(|l| l.unconverged).sum();
        let _ = writeln!(
            o,
            "  unconverged solves: {unconverged}   log {}   time {:.3} s",
            log_path.display(),
            secs
        );
        emit(&o);
    }
    if plot {
        let svg = log_path.with_extension("svg");
        if let Err(e) = dlo_planner::output::plot::plot_margin(
            &margin,
            &grasp.initial_points(),
            &fingers,
            &format!("{}: disturbance force margin", c.name),
            &svg,
        ) {
            eprintln!("error: {}: {e}", svg.display());
            return ExitCode::from(EXIT_OUTPUT);
        }
    }
    ExitCode::SUCCESS
}
