//! The search's time limit (`plan.time_limit`, `--time-limit`): a limit the search never
//! reaches leaves the plan the same bit for bit; one already passed when the first stage
//! ends starts nothing after it, and the plan found by then is judged and reported as such.

use crate::common::shipped_variant;
use dlo_planner::planner::observer::Silent;
use dlo_planner::planner::{Attempt, PlanResult, PlanSettings, PlanStatus, Planner};
use std::process::Command;

/// The shipped case `name` planned with `plan.time_limit` set to `limit` (none: left out).
fn planned(name: &str, limit: Option<f64>) -> PlanResult {
    let c = shipped_variant(name, |v| {
        if let Some(t) = limit {
            v["plan"]["time_limit"] = serde_json::json!(t);
        }
    });
    Planner::from_case(&c).unwrap().run(&mut Silent)
}

/// A million seconds: the paper's plan is the one without a limit, bit for bit.
#[test]
fn a_limit_not_reached_changes_nothing() {
    let free = planned("plan_paper_planar.json", None);
    let limited = planned("plan_paper_planar.json", Some(1e6));
    assert!(!free.time_limit_reached && !limited.time_limit_reached);
    assert_eq!(limited.z, free.z);
    assert_eq!(limited.u_max.to_bits(), free.u_max.to_bits());
    assert_eq!(limited.starts.len(), free.starts.len());
    assert_eq!(limited.chosen_start, free.chosen_start);
    assert_eq!(
        limited.replay.max_deviation_over_l.to_bits(),
        free.replay.max_deviation_over_l.to_bits()
    );
}

/// A nanosecond on the paper's case: its quick start's first stage runs (a start's first stage
/// always does) and ends the quick continuation there (its samples peak inside the path, at
/// twice the end energies); the case's own attempt, which would run next, does not start. The
/// quick plan is judged as the best found: replayed, with the lower bound on U_max (every
/// path passes through both end shapes) as an independent check.
#[test]
fn a_limit_passed_starts_nothing_new_and_judges_the_plan_so_far() {
    let r = planned("plan_paper_planar.json", Some(1e-9));
    assert!(r.time_limit_reached);
    assert_eq!(r.starts.len(), 1, "only the quick start ran");
    assert_eq!(r.starts[0].attempt, Attempt::Quick);
    let own_starts = 2; // the case's `plan.starts`
    assert_eq!(r.starts_not_run, own_starts);
    assert_eq!(r.chosen_start, Some(0));
    // Judged as any plan: verified on the grid, replayed step by step.
    assert_eq!(r.u_max.to_bits(), r.starts[0].u_max.to_bits());
    assert!(!r.replay.steps.is_empty(), "the replay ran");
    let ends = (r.replay.steps.first(), r.replay.steps.last());
    let bound = ends.0.unwrap().u_optimal.max(ends.1.unwrap().u_optimal);
    assert!(
        r.u_max >= bound * (1.0 - 1e-9),
        "{} below the bound {bound}",
        r.u_max
    );
    // The quick plan peaks inside the path, more than twice the end energies (the docs:
    // 5.273 against 2.547), and the replayed equilibria along its trajectory are executable.
    assert!(r.u_max > 2.0 * bound, "{} vs {bound}", r.u_max);
    assert_eq!(r.executed_path(), Some("equilibria"));
    // The full search finds the lower route (5.238 against the quick plan's 5.27).
    let free = planned("plan_paper_planar.json", None);
    assert!(free.u_max < r.u_max, "{} vs {}", free.u_max, r.u_max);
}

/// A 3D case cut after its own start's first sharpness stage: that start says
/// `iteration_limit`, so the plan is reported as not converged, whatever its replay shows.
#[test]
fn a_start_cut_short_is_not_called_converged() {
    let r = planned("plan_cable_under_bar.json", Some(1e-9));
    assert!(!r.straight_path_plan, "the case optimises");
    assert!(r.time_limit_reached);
    assert_eq!(r.starts.len(), 1);
    assert_eq!(r.starts[0].attempt, Attempt::Own);
    assert_eq!(
        r.starts[0].status,
        dlo_planner::optim::AlStatus::IterationLimit
    );
    assert_eq!(r.status, PlanStatus::NotConverged);
}

/// Limits that pass while the paper's case is in its stages, tracking rounds or reruns (where
/// each falls depends on the machine's speed): a stage or round cut there ends as unfinished
/// (`iteration_limit`), never as a stopped run, and the plan found by then is still verified
/// and replayed.
#[test]
fn a_limit_passed_mid_search_ends_it_as_unfinished_not_stopped() {
    for limit in [0.002, 0.005, 0.01, 0.02, 0.05] {
        let r = planned("plan_paper_planar.json", Some(limit));
        assert_ne!(r.status, PlanStatus::Interrupted, "{limit}");
        for s in &r.starts {
            assert_ne!(
                s.status,
                dlo_planner::optim::AlStatus::Interrupted,
                "{limit}"
            );
        }
        assert!(!r.replay.steps.is_empty(), "{limit}: the replay ran");
        assert!(r.u_max.is_finite() && r.chosen_start.is_some(), "{limit}");
    }
}

#[test]
fn bad_limits_are_refused_naming_the_field() {
    for (t, needle) in [
        (0.0, "must be positive"),
        (-1.0, "must be positive"),
        (f64::NAN, "finite"),
        (2e6, "at most"),
    ] {
        let s = PlanSettings {
            time_limit: Some(t),
            ..PlanSettings::default()
        };
        let e = s.validate(1.0).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("time_limit") && msg.contains(needle),
            "{t}: {msg}"
        );
    }
    let out = Command::new(env!("CARGO_BIN_EXE_dlo"))
        .args([
            "plan",
            "planning_cases/plan_paper_planar.json",
            "--time-limit",
            "0",
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--time-limit") && !err.contains("panicked"),
        "{err}"
    );
    assert!(out.stdout.is_empty());
}
