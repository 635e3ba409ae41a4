//! The `dlo` command-line tool: one run per case file.
//!
//! Exit codes: 0 success; 1 an output could not be written; 2 bad input (case file or usage);
//! 3 the solver did not converge; 130 interrupted.

use clap::{Parser, Subcommand};
use dlo_planner::case::{self, Case};
use dlo_planner::report::{ShapeReport, coefficients_json, pose};
use dlo_planner::statics::{evaluate_shape, solve_static};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

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
        /// Case file (JSON).
        case: PathBuf,
        /// Print a JSON object on stdout instead of the readable summary.
        #[arg(long)]
        json: bool,
    },
    /// Evaluate the shape given by the case's explicit coefficients, without optimising.
    Energy {
        /// Case file (JSON) with a `shape` section.
        case: PathBuf,
        /// Print a JSON object on stdout.
        #[arg(long)]
        json: bool,
    },
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() { EXIT_BAD_INPUT } else { 0 });
        }
    };
    match cli.command {
        Command::Shape { case, json } => run_shape(&case, json),
        Command::Energy { case, json } => run_energy(&case, json),
    }
}

fn load(path: &std::path::Path) -> Result<Case, ExitCode> {
    case::load(path).map_err(|e| {
        eprintln!("error: {e}");
        ExitCode::from(EXIT_BAD_INPUT)
    })
}

fn run_shape(path: &std::path::Path, json: bool) -> ExitCode {
    let mut c = match load(path) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let t0 = Instant::now();
    let sol = solve_static(&mut c.problem, &c.initial, &c.options);
    let secs = t0.elapsed().as_secs_f64();
    let report = ShapeReport::solved(&c.name, &c.problem, &sol, &c.report_points, secs);
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
    let (energy, viol, reactions, kkt) = evaluate_shape(&mut c.problem, &a);
    let p = &c.problem;
    let report = ShapeReport {
        case: c.name.clone(),
        status: "evaluated".into(),
        energy: energy.into(),
        reactions,
        max_violation: viol,
        kkt_residual: Some(kkt),
        stable: None,
        min_reduced_eigenvalue: None,
        end_pose: pose(p, &a, p.model.rod.length),
        points: c.report_points.iter().map(|&s| pose(p, &a, s)).collect(),
        coefficients: coefficients_json(p, &a),
        outer_iterations: None,
        timing_s: t0.elapsed().as_secs_f64(),
    };
    print_report(&report, json);
    ExitCode::SUCCESS
}

/// Writes to stdout, ignoring a closed pipe (e.g. `dlo shape … | head`).
fn emit(text: &str) {
    use std::io::Write;
    let _ = std::io::stdout().lock().write_all(text.as_bytes());
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
    o.push_str(match r.stable {
        Some(true) => ", stable",
        Some(false) => ", UNSTABLE",
        None => "",
    });
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
