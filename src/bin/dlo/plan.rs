//! `dlo plan`: the plan's progress, report, summary and exit code.

use super::*;

/// Progress on stderr (only when it is a terminal) plus the MCAP log.
pub(crate) struct CliObserver {
    log: PlanLog,
    tty: bool,
    started: Instant,
}

impl PlanObserver for CliObserver {
    fn stop_requested(&mut self) -> bool {
        STOP.load(std::sync::atomic::Ordering::SeqCst)
    }
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

use dlo_planner::planner::PlanReport;

/// The validated `--max-speed` and `--max-angular-speed` (the latter infinite when absent).
pub(crate) fn speed_limits(v: Option<f64>, w: Option<f64>) -> Result<Option<[f64; 2]>, ExitCode> {
    dlo_planner::planner::trajectory::speed_limits(v, w).map_err(|e| {
        eprintln!("error: --{}: {}", e.field.replace('_', "-"), e.message);
        ExitCode::from(EXIT_BAD_INPUT)
    })
}

pub(crate) fn run_plan(
    path: &Path,
    json: bool,
    plot: bool,
    log_dir: &Path,
    speeds: Option<[f64; 2]>,
    threads: Option<u16>,
    time_limit: Option<f64>,
) -> ExitCode {
    let c = match load(path) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let t0 = Instant::now();
    // Whether the start was given a shape (else solved for its pose alone).
    let mut start_written = false;
    let built = case::plan::plan_problem(&c).map(|(problem, mut settings)| {
        start_written = problem.start.shape.is_some();
        if let Some(t) = threads {
            settings.threads = Some(usize::from(t));
        }
        if time_limit.is_some() {
            settings.time_limit = time_limit;
        }
        case::plan::planner(&c, problem, settings)
    });
    let planner = match built {
        Ok(Ok(p)) => p,
        Ok(Err(PlanSetupError::Unreachable { end, message })) => {
            return unreachable_end(&c, json, end, &message);
        }
        Ok(Err(e)) => {
            eprintln!("error: {}", case::plan::setup_error(&c, e));
            return ExitCode::from(EXIT_BAD_INPUT);
        }
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
    COOPERATIVE.store(true, std::sync::atomic::Ordering::SeqCst);
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
    if result.verdict() == PlanVerdict::Interrupted {
        eprintln!("interrupted: the log was finished and is readable");
        return ExitCode::from(EXIT_INTERRUPTED as u8);
    }
    let csv_path = log_dir.join(format!("{}.trajectory.csv", c.name));
    if let Err(code) = write_atomically(&csv_path, &result.trajectory.to_csv()) {
        return code;
    }
    let report = PlanReport {
        mcap: Some(log_path.display().to_string()),
        log_shapes: Some(obs.log.shapes()),
        trajectory_csv: Some(csv_path.display().to_string()),
        ..PlanReport::new(&c.name, &planner, &result)
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
                "error: {}: no collision-free plan: the verification grid finds the rod crossing itself (gap {gap:.3e} at k = {k:.3}){}; {}",
                path.display(),
                time_limit_note(&result),
                what_to_try(&planner, Failure::Collision)
            );
            ExitCode::from(EXIT_COLLISION)
        }
        PlanVerdict::ObstacleCollision if result.end_inside_obstacle.is_some() => {
            let e = result.end_inside_obstacle.as_ref().expect("matched");
            let tries = &result.contact_samples_tried;
            let tried = if tries.is_empty() {
                String::new()
            } else {
                format!(
                    "; made again with more contact points: {}",
                    contact_tries_text(tries, e)
                )
            };
            // More contact points than any tried, unless the last try's end did not solve.
            let more = match tries.last() {
                None => Some("more contact points".to_string()),
                Some(last) if last.dipped.is_some() => {
                    Some(format!("more than {} contact points", last.samples))
                }
                Some(_) => None,
            };
            let advice = match more {
                Some(more) => format!(
                    "try an end pose farther from the obstacle, or {more} (discretisation.samples)"
                ),
                None => "try an end pose farther from the obstacle".to_string(),
            };
            eprintln!(
                "error: {}: no collision-free plan: the {} shape itself comes {:.3e} inside obstacle {} at s = {:.4} (between the contact points its static solve holds clear{tried}), so no path from it is collision-free; {advice}",
                path.display(),
                e.end,
                -e.clearance,
                e.obstacle,
                e.s,
            );
            ExitCode::from(EXIT_COLLISION)
        }
        PlanVerdict::ObstacleCollision => {
            let worst = result
                .verification
                .obstacles
                .iter()
                .min_by(|a, b| a.clearance.total_cmp(&b.clearance));
            eprintln!(
                "error: {}: no collision-free plan: the verification grid finds clearance {:.3e} (obstacle {} at k = {:.3}, s = {:.4}){}; {}",
                path.display(),
                result.min_clearance.unwrap_or(0.0),
                worst.map_or("?", |o| o.obstacle.as_str()),
                worst.map_or(0.0, |o| o.k),
                worst.map_or(0.0, |o| o.s),
                equilibria_not_a_plan(&result),
                what_to_try(&planner, Failure::Collision)
            );
            ExitCode::from(EXIT_COLLISION)
        }
        PlanVerdict::OutsideWorkspace => {
            let w = result.workspace.expect("checked when outside");
            eprintln!(
                "error: {}: the controlled end leaves plan.workspace by {:.3e} at k = {:.3}; try wider bounds or other start and goal poses",
                path.display(),
                w.largest_excess,
                w.k
            );
            ExitCode::from(EXIT_COLLISION)
        }
        PlanVerdict::NotConverged => {
            eprintln!(
                "error: {}: the path optimiser did not converge ({}, violation {:.2e}){}; {}",
                path.display(),
                result.optimiser.map_or("not run".into(), |o| o.to_string()),
                result.violation,
                equilibria_not_a_plan(&result),
                what_to_try(&planner, Failure::NotConverged)
            );
            ExitCode::from(EXIT_NOT_CONVERGED)
        }
        PlanVerdict::Departs | PlanVerdict::SnapsThrough => {
            eprintln!(
                "error: {}: the replay by the controlled end does not coincide with the plan: max deviation {:.3} L at k = {:.3} (tolerance {} L){}{}; {}",
                path.display(),
                result.replay.max_deviation_over_l,
                result.replay.k_at_max_deviation,
                result.replay.tolerance,
                if result.replay.snaps.is_empty() {
                    String::new()
                } else {
                    format!(", snap-through at k = {}", snap_list(&result.replay.snaps))
                },
                equilibria_not_a_plan(&result),
                if result.replay.start_held() {
                    what_to_try(&planner, Failure::Departure)
                } else if start_written {
                    format!(
                        "the start shape is not held by its end pose (not a stable equilibrium there): the replay leaves it by {:.3} L at k = 0, so no path from it can be executed by the controlled end; start from the pose alone (plan.start without `shape`) or from a shape the pose holds",
                        result.replay.start_deviation_over_l
                    )
                } else {
                    format!(
                        "the replay leaves the start shape solved for the start pose by {:.3} L at k = 0 (the solve's equilibrium is not one the replay's first solve stays on), so no path from it can be executed by the controlled end; give plan.start a starting `shape` near the equilibrium wanted, or move the start pose a little",
                        result.replay.start_deviation_over_l
                    )
                }
            );
            ExitCode::from(EXIT_NOT_COINCIDENT)
        }
        PlanVerdict::Executable => ExitCode::SUCCESS,
        PlanVerdict::Interrupted => ExitCode::from(EXIT_INTERRUPTED as u8),
        PlanVerdict::Unreachable => ExitCode::from(EXIT_UNREACHABLE),
    }
}

/// The verdict of a plan whose start or goal no static shape reaches: a report (no plan, no
/// log) and exit code 6.
fn unreachable_end(c: &Case, json: bool, end: &str, message: &str) -> ExitCode {
    let verdict = PlanVerdict::Unreachable;
    if json {
        let report = serde_json::json!({
            "case": c.name, "verdict": verdict, "end": end, "message": message,
        });
        emit(&format!(
            "{}\n",
            serde_json::to_string_pretty(&report).expect("report serialises")
        ));
    } else {
        emit(&format!("case {}: {verdict}: the {end}\n", c.name));
    }
    eprintln!(
        "error: {}: field `plan.{end}`: {message}; nothing was planned",
        c.path.display()
    );
    ExitCode::from(EXIT_UNREACHABLE)
}

/// Which kind of failure [`what_to_try`] advises on.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Failure {
    /// No plan is collision-free on the verification grid.
    Collision,
    /// The replay by the controlled end departs from the plan, or snaps through.
    Departure,
    /// The path optimiser did not converge.
    NotConverged,
}

/// What to try after `failure`, in the case file's `plan` fields, with values beyond what
/// `planner` already ran (its settings as the case and the defaults made them).
pub(crate) fn what_to_try(planner: &Planner, failure: Failure) -> String {
    let s = &planner.settings;
    let spatial = planner.base.model.layout.spatial;
    // The counts the run tried and one more; none tried: two, from six terms on.
    let mut terms = s.fallback_terms(spatial);
    match terms.iter().max() {
        Some(&largest) => terms.push(largest + 4),
        None => {
            let first = s.path_terms.max(4) + 2;
            terms.extend([first, first + 2]);
        }
    }
    let terms = format!(
        "more path terms (plan.fallback_path_terms: [{}])",
        terms
            .iter()
            .map(usize::to_string)
            .collect::<Vec<_>>()
            .join(", ")
    );
    let starts = format!(
        "more starts (plan.starts: {}, now {})",
        (2 * s.starts).max(4),
        s.starts
    );
    let mut tries = Vec::new();
    match failure {
        Failure::Collision => {
            if !s.swept() {
                tries.push("plan.swept_clearance: true".to_string());
            }
            tries.push(format!(
                "more samples of k (plan.k_samples: {}, now {})",
                2 * s.k_samples - 1,
                s.k_samples
            ));
            tries.push(terms);
            tries.push(starts);
        }
        Failure::Departure => {
            tries.push(terms);
            tries.push(starts);
            let w = s.tracking_weight(spatial);
            tries.push(if w > 0.0 {
                format!(
                    "stronger equilibrium tracking (plan.equilibrium_weight: {:e}, now {w:e})",
                    10.0 * w
                )
            } else {
                "equilibrium tracking (plan.equilibrium_weight: 1e4, now off)".to_string()
            });
        }
        Failure::NotConverged => {
            tries.push(starts);
            tries.push(terms);
            tries.push(format!(
                "a larger budget for the attempts after the case's own (plan.fallback_evaluations: {}, now {})",
                2 * s.fallback_evaluations,
                s.fallback_evaluations
            ));
        }
    }
    let last = tries.pop().expect("at least one");
    let tried = if tries.is_empty() {
        last
    } else {
        format!("{} or {last}", tries.join(", "))
    };
    match failure {
        Failure::Departure => {
            format!("try {tried}; the replayed path in the log is what the controlled end does")
        }
        _ => format!(
            "try {tried}; or plan in two legs through a pose between the start and the goal"
        ),
    }
}

/// What the plans made again with more contact samples found, each with its samples: the
/// depth its end shape still dipped, with its end and obstacle where they are not those of
/// `reference`, or that its end shapes did not solve: `dips 4.657e-5 with 64, no static end
/// shape with 128`.
fn contact_tries_text(
    tries: &[dlo_planner::planner::ContactTry],
    reference: &dlo_planner::planner::EndInside,
) -> String {
    tries
        .iter()
        .map(|t| {
            let Some(d) = &t.dipped else {
                return format!("no static end shape with {}", t.samples);
            };
            let other =
                if (d.end, d.obstacle.as_str()) == (reference.end, reference.obstacle.as_str()) {
                    String::new()
                } else {
                    format!(" (the {} shape, obstacle {})", d.end, d.obstacle)
                };
            format!("dips {:.3e} with {}{other}", -d.clearance, t.samples)
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Why the replayed equilibria are not a plan either, when they were checked (their own
/// failure, then how many retries failed too and how; the summary and the report list each
/// retry), and that the time limit ended the search, when it did.
fn equilibria_not_a_plan(result: &dlo_planner::planner::PlanResult) -> String {
    let why = result
        .equilibrium_plan
        .as_ref()
        .and_then(|e| Some((e.own_reason()?, &e.retries)))
        .map_or(String::new(), |(own, retries)| {
            let also = if retries.is_empty() {
                String::new()
            } else {
                format!(
                    "; {} retr{} failed too ({}; each in the summary and in the report's equilibrium_plan.retries)",
                    retries.len(),
                    if retries.len() == 1 { "y" } else { "ies" },
                    retry_outcomes(retries)
                )
            };
            format!("; the replayed equilibria are not a plan either: {own}{also}")
        });
    format!("{why}{}", time_limit_note(result))
}

/// How the retries `retries` failed, counted by kind: `5 snap through, 2 stop converging`.
fn retry_outcomes(retries: &[dlo_planner::planner::equilibrium_plan::FailedRetry]) -> String {
    use dlo_planner::planner::equilibrium_plan::EquilibriaFailure::*;
    let kinds = [
        (Confirmation, "fail their confirmation replay"),
        (SnapsThrough, "snap through"),
        (NotConverged, "stop converging"),
        (EndsElsewhere, "end on another equilibrium of the goal pose"),
        (EntersObstacle, "dip into an obstacle"),
        (CrossesItself, "cross themselves"),
    ];
    let mut counts = vec![0usize; kinds.len() + 1];
    for r in retries {
        let i = kinds
            .iter()
            .position(|(f, _)| *f == r.failure)
            .unwrap_or(kinds.len());
        counts[i] += 1;
    }
    kinds
        .iter()
        .map(|(_, name)| *name)
        .chain(std::iter::once("fail otherwise"))
        .zip(counts)
        .filter(|(_, n)| *n > 0)
        .map(|(name, n)| format!("{n} {name}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// That the time limit ended the search, when it did (appended to a failure's message).
fn time_limit_note(result: &dlo_planner::planner::PlanResult) -> &'static str {
    if result.time_limit_reached {
        "; the search ended at its time limit (plan.time_limit, --time-limit) before it had tried everything: a longer limit may find a plan"
    } else {
        ""
    }
}

pub(crate) fn plan_summary(r: &PlanReport) -> String {
    use std::fmt::Write;
    let p = r.result;
    let mut o = String::new();
    let _ = writeln!(
        o,
        "case {}: {}{} ({}; {})",
        r.case,
        r.verdict,
        match (r.executed_path, p.along_pose_line()) {
            (Some("equilibria"), _) if p.along_straight_trajectory() =>
                " by the replayed equilibria along the straight-line path's trajectory".into(),
            (Some("equilibria"), Some(d)) => format!(
                " by the replayed equilibria along a line in the end's pose space{}",
                match d.describe() {
                    d if d.is_empty() => d,
                    d => format!(" {d} mid-way"),
                }
            ),
            (Some("equilibria"), None) =>
                " by the replayed equilibria along the optimal path's trajectory".into(),
            (Some(_), _) if p.straight_path_plan => " along the straight-line path".into(),
            (Some(_), _) => " as optimised".into(),
            (None, _) => String::new(),
        },
        p.status,
        match (p.optimiser, &p.end_inside_obstacle) {
            (Some(o), _) => format!("optimiser {o}"),
            (None, Some(e)) => format!(
                "optimiser not run: the {} shape lies inside obstacle {}, so no path is collision-free",
                e.end, e.obstacle
            ),
            (None, None) if p.along_straight_trajectory() => {
                "optimiser not run: the equilibria along the straight-line path's trajectory peak within the energy-gap tolerance of the lower bound on U_max".into()
            }
            (None, None) => "optimiser not run: the straight-line path attains the lower bound on U_max, the larger end energy".into(),
        }
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
    if let Some(g) = &p.reached_goal {
        let _ = writeln!(
            o,
            "  goal shape: the equilibrium of the goal pose the gripper's motion reached (energy {:.6e}), {:.3e} L from the one its static solve found (energy {:.6e}); the plan to that one: {}",
            g.energy, g.distance_over_l, g.solved_energy, g.first_plan
        );
        if let Some(why) = &g.replan_failed {
            let along = match (p.along_pose_line(), p.along_straight_trajectory()) {
                (Some(d), _) => format!("along {}", d.line_name()),
                (None, true) => "along the straight path's trajectory".into(),
                (None, false) => "along the first plan's trajectory".into(),
            };
            let _ = writeln!(
                o,
                "  the plan is the first search's replayed equilibria {along}, which end on it (planned again: {why})"
            );
        }
    }
    if let Some(c) = &p.contact_samples {
        let _ = writeln!(
            o,
            "  contact samples: {} (the case's {} let the {} shape dip {:.3e} into obstacle {} at s = {:.4} between them)",
            c.samples,
            c.case_samples,
            c.dipped.end,
            -c.dipped.clearance,
            c.dipped.obstacle,
            c.dipped.s
        );
    }
    // Named after the end the case's own samples let dip.
    let dipped = p.contact_samples.as_ref().map(|c| &c.dipped);
    if !p.contact_samples_tried.is_empty()
        && let Some(e) = dipped.or(p.end_inside_obstacle.as_ref())
    {
        let _ = writeln!(
            o,
            "  more contact samples tried: the {} shape {}",
            e.end,
            contact_tries_text(&p.contact_samples_tried, e)
        );
    }
    if p.starts.len() + p.starts_not_run > 1 {
        // Starts with fallback path terms ran: say which count each start used.
        let fallback = p
            .starts
            .iter()
            .any(|s| s.path_terms != p.starts[0].path_terms);
        // Starts of several attempts ran: say which each start belongs to.
        let attempts = p.starts.iter().any(|s| s.attempt != p.starts[0].attempt);
        let not_run = if p.starts_not_run > 0 {
            format!(
                " ({} more not run: {})",
                p.starts_not_run,
                if p.time_limit_reached {
                    "an earlier plan is executable, or the time limit ended the search"
                } else {
                    "an earlier plan is executable"
                }
            )
        } else {
            String::new()
        };
        let _ = writeln!(
            o,
            "  starts: {}{not_run}, chosen {} (path terms {}); verified U_max (sampled; samples' distance to their equilibria) {}",
            p.starts.len(),
            p.chosen_start.map_or("none".into(), |c| c.to_string()),
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
                    let a = if attempts {
                        format!("{}: ", s.attempt.name())
                    } else {
                        String::new()
                    };
                    format!("{a}{m}{u:.4} ({us:.4}; {d}; {st:?}{clear})")
                })
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    if p.time_limit_reached {
        let _ = writeln!(
            o,
            "  time limit: the search ended at it; nothing new started after it, and the plan is the best found by then"
        );
    }
    let rp = &p.replay;
    // A solve that did not converge is no equilibrium: its energy, clearance and contact
    // force are left out.
    let unconverged = rp.steps.iter().filter(|s| !s.converged).count();
    let of_equilibria = if unconverged > 0 && unconverged < rp.steps.len() {
        format!(" (of the converged solves; {unconverged} did not converge)")
    } else {
        String::new()
    };
    if rp.steps.is_empty() {
        let _ = writeln!(o, "  replay: not run");
    } else {
        let _ = writeln!(
            o,
            "  replay: max deviation {:.4} L at k = {:.3} (tolerance {} L) -> {}; U_max {:.6e}{of_equilibria}; all stable {}; all converged {}; snap-through at k = {}",
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
    }
    if let Some(c) = rp.min_clearance {
        let contact = if rp.max_contact_force > 0.0 {
            format!(
                "leans on obstacles: largest contact force {:.4e} at k = {:.3}",
                rp.max_contact_force, rp.k_at_max_contact_force
            )
        } else {
            "touches no obstacle".to_string()
        };
        let _ = writeln!(
            o,
            "  replayed path: clearance {c:.4e}; {contact}{of_equilibria}"
        );
    }
    if let Some(w) = &p.workspace {
        let _ = writeln!(
            o,
            "  workspace: {} (largest excess {:.3e} at k = {:.3})",
            if w.within {
                "the end stays inside"
            } else {
                "the end LEAVES it"
            },
            w.largest_excess,
            w.k
        );
    }
    if let Some(e) = &p.equilibrium_plan {
        if let Some(why) = &e.optimal_path_not_executable {
            let follows = match e.pose_line() {
                Some(d) if d.side != 0.0 => format!(
                    "a line in its pose space, {} mid-way, horizontally across the straight line; the replay is that line's",
                    d.describe()
                ),
                Some(d) if d.lift != 0.0 => format!(
                    "a line in its pose space, {} mid-way against gravity; the replay is that line's",
                    d.describe()
                ),
                Some(_) => "a line in its pose space; the replay is that line's".into(),
                None => "the straight-line path's end poses".into(),
            };
            let _ = writeln!(
                o,
                "  the optimal path is not executable ({why}); the gripper follows {follows}"
            );
        }
        // A course optimised in the end's pose space
        // ([`dlo_planner::planner::pose_optimisation`]).
        if let (Some(u), Some(t)) = (e.course_u_max, &e.pose_terms) {
            let _ = writeln!(
                o,
                "  the end's positions along it optimised (terms {}): its equilibria peak at U_max {:.6e} instead of {u:.6e}",
                t.iter()
                    .map(|c| format!("[{:.4}, {:.4}, {:.4}]", c[0], c[1], c[2]))
                    .collect::<Vec<_>>()
                    .join(", "),
                e.u_max
            );
        }
        let _ = writeln!(
            o,
            "  replayed equilibria as the plan: {}; U_max {:.6e} at k = {:.3}{}{}",
            match e.own_reason() {
                None => "executable".to_string(),
                Some(why) => format!("not executable ({why})"),
            },
            e.u_max,
            e.k_at_u_max,
            {
                let chords =
                    dlo_planner::planner::equilibrium_plan::chords_named(e.contact_samples);
                match (e.contact_margin, e.contact) {
                    (Some(m), _) => {
                        format!("; contacts on {chords}, held {m:.2e} off the obstacles")
                    }
                    (None, "chords") => format!("; contacts on {chords}"),
                    _ => String::new(),
                }
            },
            match (e.confirmation_steps, e.confirmation_deviation_over_l) {
                (Some(n), Some(d)) =>
                    format!("; a replay on {n} steps reaches them within {d:.2e} L"),
                _ => String::new(),
            }
        );
        // Retries that were no plan either, one a line.
        if !e.retries.is_empty() {
            let _ = writeln!(o, "  retried, no plan either:");
        }
        for r in &e.retries {
            let _ = writeln!(o, "    {}: {}", r.attempt, r.reason);
        }
    }
    let t = &p.trajectory;
    if t.poses.is_empty() {
        let _ = writeln!(o, "  gripper: no trajectory (the replay did not run)");
    } else {
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
            r.trajectory_csv.as_deref().unwrap_or("not written")
        );
    }
    let _ = writeln!(
        o,
        "  log {} ({} shapes)   time: endpoints {:.3} s, plan {:.3} s, replay {:.3} s",
        r.mcap.as_deref().unwrap_or("not written"),
        r.log_shapes.unwrap_or(0),
        p.timing_s.endpoints,
        p.timing_s.plan,
        p.timing_s.replay
    );
    o
}

/// The `k` of snap-throughs, in brackets (as the library's reasons list them).
pub(crate) fn snap_list(snaps: &[f64]) -> String {
    dlo_planner::planner::equilibrium_plan::k_list(snaps)
}
