//! `dlo shape` and `dlo energy`: static shapes and their reports.

use super::*;

pub(crate) fn run_shape(path: &std::path::Path, json: bool, log_dir: &Path) -> ExitCode {
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

pub(crate) fn run_energy(path: &std::path::Path, json: bool) -> ExitCode {
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
    let secs = t0.elapsed().as_secs_f64();
    let report = ShapeReport::evaluated(&c.name, &c.problem, ev, &a, &c.report_points, secs);
    print_report(&report, json);
    ExitCode::SUCCESS
}

pub(crate) fn print_report(r: &ShapeReport, json: bool) {
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
    if let Some(b) = &r.balance {
        let _ = writeln!(
            o,
            "  moment balance residual [{:+.3e}, {:+.3e}, {:+.3e}] ({:.1e} of the largest moment)",
            b.moment_residual[0], b.moment_residual[1], b.moment_residual[2], b.relative
        );
    }
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
