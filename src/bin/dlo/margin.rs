//! `dlo margin`: the disturbance force margin of a grasp.

use super::*;

use dlo_planner::grasp::MarginReport;

pub(crate) fn run_margin(path: &Path, json: bool, plot: bool, log_dir: &Path) -> ExitCode {
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
        mcap: Some(log_path.display().to_string()),
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
