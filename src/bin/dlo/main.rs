//! The `dlo` command-line tool: one run per case file.
//!
//! Exit codes: 0 success; 1 an output could not be written; 2 bad input (case file or usage);
//! 3 the solver did not converge; 4 no collision-free plan; 5 the replay does not coincide with
//! the plan; 6 no static shape reaches the plan's start or goal; 130 interrupted (the log is
//! finished first).
//!
//! `args.rs` holds the command line; one file per command family (`shape.rs`, `plan.rs`,
//! `margin.rs`, `logs.rs`) runs it and renders its report; `log_file.rs` owns the log's
//! lifecycle (and Ctrl-C); `batch.rs` runs several case files at once.

mod args;
mod batch;
mod log_file;
mod logs;
mod margin;
mod output;
mod plan;
mod shape;

use args::*;
use log_file::*;
use logs::*;
use margin::*;
use output::*;
use plan::*;
use shape::*;

use clap::{Parser, Subcommand};
use dlo_planner::case::{self, Case};
use dlo_planner::output::mcap_log::{PlanLog, SharedWriter, log_static};
use dlo_planner::planner::observer::{PlanObserver, Progress, ShapeRecord};
use dlo_planner::planner::{PlanSetupError, PlanVerdict, Planner};
use dlo_planner::statics::report::ShapeReport;
use dlo_planner::statics::{evaluate_shape, solve_static};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::OnceLock;
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
/// Exit code: no static shape reaches a plan's start or goal.
const EXIT_UNREACHABLE: u8 = 6;

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
            threads,
            time_limit,
        } => {
            let speeds = match speed_limits(max_speed, max_angular_speed) {
                Ok(s) => s,
                Err(code) => return code,
            };
            if let Some(Err(e)) = time_limit.map(dlo_planner::planner::settings::check_time_limit) {
                eprintln!("error: --time-limit: {}", e.message);
                return ExitCode::from(EXIT_BAD_INPUT);
            }
            let mut extra = log_args(&log_dir, plot);
            for (flag, v) in [
                ("--max-speed", max_speed),
                ("--max-angular-speed", max_angular_speed),
                ("--time-limit", time_limit),
            ] {
                if let Some(v) = v {
                    extra.extend([flag.to_string(), v.to_string()]);
                }
            }
            let env = match dlo_planner::planner::settings::env_threads() {
                Ok(t) => t.and_then(|t| u16::try_from(t).ok()),
                Err(e) => {
                    eprintln!("error: {e}");
                    return ExitCode::from(EXIT_BAD_INPUT);
                }
            };
            // Cases that run side by side share the cores: one thread each unless told.
            let side_by_side = jobs.unwrap_or_else(cores) > 1;
            if let Some(t) = threads.or(env).or(side_by_side.then_some(1)) {
                extra.extend(["--threads".to_string(), t.to_string()]);
            }
            match single("plan", &cases, Some("plan"), json, jobs, &extra) {
                Ok(case) => run_plan(&case, json, plot, &log_dir, speeds, threads, time_limit),
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
    Err(batch::run(
        command,
        &files,
        extra,
        json,
        jobs.unwrap_or_else(cores),
    ))
}

/// The cores this process may use.
fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
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
