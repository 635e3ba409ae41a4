//! The plan the gripper executes when the optimal path's replay departs from it: the
//! controlled end's trajectory (the optimal path's end poses), with the rod's equilibria along
//! it — the replay's shapes — as the plan's shapes.
//!
//! The optimal path (paper §7) optimises shapes that no end pose need produce; its replay
//! finds the shapes the end poses do produce. Where that replay converges everywhere, stays
//! stable, never snaps through, ends on the goal shape and keeps clear of every obstacle
//! (each replayed shape is a static solve under the obstacles, so it touches them at most),
//! the trajectory executes a plan whose shapes are those equilibria. Their clearance is
//! checked on the verification grid in s: a static solve holds its contacts at its own sample
//! points, and a shape leaning on an obstacle's corner can dip between them. A second replay on
//! twice as many steps confirms that they do not depend on the step: it must reach the same
//! shapes, within the coincidence tolerance, at every `k` both replays share.
//!
//! Where the shapes dip between contact points, the replay is run again with the contacts held
//! on the chords between them (`discretisation.contact: "chords"`, whatever the case says), and
//! its equilibria, checked and confirmed the same way, are the plan if they pass. When no
//! optimised path is executable, the planner checks the straight-line path's end poses the same
//! way (`Planner::run`).

use super::Planner;
use super::observer::PlanObserver;
use super::path::DeformationPath;
use super::pose_line::Detour;
use super::replay::{EarlyStop, Replay, ReplayOptions, max_distance, replay_driven};
use crate::constraints::Constraint;
use crate::rod::model::Model;
use crate::statics::StaticProblem;
use serde::Serialize;

/// The replayed equilibria along the optimal path's trajectory (or, when no optimised path is
/// executable, along the straight-line path's), as a plan.
#[derive(Clone, Debug, Serialize)]
pub struct EquilibriumPlan {
    /// The trajectory executes these shapes: every replay solve converged, every shape is
    /// stable, nothing snaps, the last shape is the goal's, no obstacle is penetrated, and the
    /// confirmation replay agrees.
    pub executable: bool,
    /// Why not, when not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// Which check failed, when not executable: the kind of the failure [`Self::reason`]
    /// starts with (these equilibria's own, not their retries', which
    /// [`Self::retries`] lists).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure: Option<EquilibriaFailure>,
    /// Largest energy of the replayed shapes (case units).
    pub u_max: f64,
    /// `k` where it occurs.
    pub k_at_u_max: f64,
    /// Smallest obstacle clearance of the shapes of both replays on the verification grid in s
    /// (case units; `None` without obstacles); zero where the rod leans on an obstacle.
    pub min_clearance: Option<f64>,
    /// Largest total contact force of the obstacles on a replayed shape (case units; zero when
    /// the rod never touches one), and its `k`.
    pub max_contact_force: f64,
    /// `k` of that force.
    pub k_at_max_contact_force: f64,
    /// Steps of the confirmation replay (`null` when it did not run).
    pub confirmation_steps: Option<usize>,
    /// Largest distance between the two replays' shapes at the `k` they share (fraction of
    /// `L`; `null` when the confirmation did not run).
    pub confirmation_deviation_over_l: Option<f64>,
    /// Where the replay's solves held the obstacle contacts: `"points"` (at the sample points)
    /// or `"chords"` (on the chords between them: as the case says, or the replay run again so
    /// after shapes held at the points dipped between them).
    pub contact: &'static str,
    /// How far (case units) the replay's solves held the rod off the obstacles, on the chords,
    /// where with the contacts on the obstacles themselves the shapes dipped between contact
    /// points (absent: not held off).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_margin: Option<f64>,
    /// The contact samples (intervals between sample points) the replay's solves held the
    /// contacts at, where twice the case's: shapes that still dipped between the chords of
    /// the case's sample points were replayed on the chords of these (absent: the case's).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_samples: Option<usize>,
    /// Whose end poses the gripper follows: `"optimal_path"` (the optimal path's, as the
    /// replay), `"straight_path"` (the straight-line path's, tried when no optimised path is
    /// executable, neither as it stands nor by its equilibria) or `"pose_line"` (a line in the
    /// end's pose space, [`super::pose_line`], tried when neither of those executes); with
    /// [`Self::pose_terms`], those end poses with terms added.
    pub trajectory: &'static str,
    /// Along a pose line: how far it lifts the end mid-way against gravity (units of L).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lift_over_l: Option<f64>,
    /// Along a pose line moved aside: how far it moves the end mid-way across the straight
    /// line, horizontally (units of L; along `up × (goal − start)` where positive,
    /// [`super::pose_line::Detour`]). Absent on lines not moved aside.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub side_over_l: Option<f64>,
    /// Along a course optimised in the end's pose space ([`super::pose_optimisation`]: the
    /// pose line or the path's end poses of [`Self::trajectory`], with terms added): the terms
    /// added to the end's position, the `m`-th times `k^(m+1) (1 − k)` (case units, case
    /// frame). Absent on a course as it was.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pose_terms: Option<Vec<[f64; 3]>>,
    /// Along an optimised course: the largest energy of the equilibria along the course as it
    /// was (case units), against this plan's `u_max`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub course_u_max: Option<f64>,
    /// Along another trajectory than the optimal path's: why the optimal path was not
    /// executable, as it stands or by its equilibria (`None` otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub optimal_path_not_executable: Option<String>,
    /// The retries of these equilibria that were no plan either, in the order they ran: what
    /// each changed (another trajectory, the contacts on chords, held off the obstacles, …)
    /// and why it failed. [`Self::reason`] holds the same, after the first failure, as one
    /// sentence. Absent where nothing was retried.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub retries: Vec<FailedRetry>,
    /// [`Self::reason`] as it was before the first retry failed ([`Self::own_reason`]).
    #[serde(skip)]
    pub(crate) own: Option<String>,
    /// The shapes dip into an obstacle between the solves' contact points.
    #[serde(skip)]
    pub(crate) dips: bool,
    /// Where the replay converges, stays stable and never snaps but ends on another
    /// equilibrium of the goal pose than the goal shape, its shapes clear of the obstacles:
    /// that equilibrium's coefficients (the replay's last shape) and the trajectory that
    /// reached it; then those of the second attempts that failed ([`Self::retry_failed_as`]),
    /// in the order they ran.
    #[serde(skip)]
    pub(crate) reached_goals: Vec<Reached>,
}

/// A retry of replayed equilibria that was no plan either ([`EquilibriumPlan::retries`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FailedRetry {
    /// What the retry changed: `"replayed with contacts on chords"`, `"along the end's pose
    /// line lifted 0.3 L"`, … (a retry of a retry names both, the first one first).
    pub attempt: String,
    /// Which check its equilibria failed.
    pub failure: EquilibriaFailure,
    /// Why its equilibria are no plan.
    pub reason: String,
}

/// Which check keeps replayed equilibria from being a plan ([`EquilibriumPlan::failure`],
/// [`FailedRetry::failure`]); in reports, in snake case (`"snaps_through"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EquilibriaFailure {
    /// The replay did not run.
    NotRun,
    /// A static solve of the replay did not converge.
    NotConverged,
    /// The replayed shape jumps between neighbouring `k` however finely the step is halved.
    SnapsThrough,
    /// A replayed shape is unstable.
    Unstable,
    /// The replay ends on another equilibrium of the goal pose than the goal shape.
    EndsElsewhere,
    /// A replayed shape comes inside an obstacle between the static solve's contact points.
    EntersObstacle,
    /// A replayed shape crosses itself.
    CrossesItself,
    /// The confirmation replay, on twice the steps, fails one of these checks or reaches other
    /// shapes.
    Confirmation,
    /// The start pose's static solve under the retry's contacts did not converge.
    StartNotConverged,
    /// The plan made again to the equilibrium of the goal pose the replay reached is not
    /// executable (the reason is its verdict).
    PlannedAgain,
    /// The run was interrupted.
    Interrupted,
}

/// A failed check: which, and the reason for a reader.
type Failed = (EquilibriaFailure, String);

/// Another equilibrium of the goal pose that replayed equilibria reached
/// ([`EquilibriumPlan::reached_goals`]), and along which trajectory.
#[derive(Clone, Debug)]
pub(crate) struct Reached {
    /// Its Ritz coefficients (the replay's last shape).
    pub(crate) a: Vec<f64>,
    /// [`EquilibriumPlan::trajectory`] of the equilibria that reached it.
    pub(crate) trajectory: &'static str,
    /// Along a pose line, how it leaves the straight line.
    pub(crate) line: Option<Detour>,
}

impl EquilibriumPlan {
    /// Equilibria along the optimal path's trajectory before any check: not executable, no
    /// reason yet, no replayed shape (`u_max` −∞), contacts at the sample points, nothing
    /// retried.
    fn unchecked() -> EquilibriumPlan {
        EquilibriumPlan {
            executable: false,
            reason: None,
            failure: None,
            u_max: f64::NEG_INFINITY,
            k_at_u_max: 0.0,
            min_clearance: None,
            max_contact_force: 0.0,
            k_at_max_contact_force: 0.0,
            confirmation_steps: None,
            confirmation_deviation_over_l: None,
            contact: "points",
            contact_margin: None,
            contact_samples: None,
            trajectory: "optimal_path",
            lift_over_l: None,
            side_over_l: None,
            pose_terms: None,
            course_u_max: None,
            optimal_path_not_executable: None,
            retries: Vec::new(),
            own: None,
            dips: false,
            reached_goals: Vec::new(),
        }
    }

    /// Adds to [`Self::reason`] why a second attempt (`attempt`: what it changed) failed too:
    /// `why`, a failure of the check `failure`.
    pub(super) fn retry_failed(&mut self, attempt: &str, failure: EquilibriaFailure, why: &str) {
        self.add_retry(
            attempt,
            why,
            vec![FailedRetry {
                attempt: attempt.into(),
                failure,
                reason: why.into(),
            }],
        );
    }

    /// Sets [`Self::reason`] and [`Self::failure`] to `failed` (both `None` for `None`).
    fn set_failure(&mut self, failed: Option<Failed>) {
        (self.failure, self.reason) = failed.unzip();
    }

    /// Adds `why` to [`Self::reason`] and `listed` to [`Self::retries`].
    fn add_retry(&mut self, attempt: &str, why: &str, listed: Vec<FailedRetry>) {
        if self.retries.is_empty() {
            self.own.clone_from(&self.reason);
        }
        let first = self.reason.take().unwrap_or_default();
        self.reason = Some(format!("{first}; {attempt}: {why}"));
        self.retries.extend(listed);
    }

    /// Why these equilibria themselves are no plan: [`Self::reason`] without the failures of
    /// their retries ([`Self::retries`]), which follow it there.
    pub fn own_reason(&self) -> Option<&str> {
        if self.retries.is_empty() {
            self.reason.as_deref()
        } else {
            self.own.as_deref()
        }
    }

    /// [`Self::retry_failed`] with the reason of `retry`, the equilibria of a second attempt
    /// (`attempt`: what it changed), which are no plan either; the other equilibria of the
    /// goal pose `retry` reached follow these' ([`Self::reached_goals`]). Its failure is listed
    /// in [`Self::retries`] as its own, then its retries' one by one.
    pub(super) fn retry_failed_as(&mut self, attempt: &str, retry: &EquilibriumPlan) {
        if let Some(why) = &retry.reason {
            let own = FailedRetry {
                attempt: attempt.into(),
                failure: retry.failure.unwrap_or(EquilibriaFailure::Interrupted),
                reason: retry.own_reason().unwrap_or(why).into(),
            };
            let theirs = retry.retries.iter().map(|r| FailedRetry {
                attempt: format!("{attempt}, {}", r.attempt),
                ..r.clone()
            });
            self.add_retry(attempt, why, std::iter::once(own).chain(theirs).collect());
        }
        self.reached_goals
            .extend(retry.reached_goals.iter().cloned());
    }

    /// These equilibria follow `trajectory` (`line` along a pose line), as do those that
    /// reached another equilibrium of the goal pose.
    pub(super) fn set_trajectory(&mut self, trajectory: &'static str, line: Option<Detour>) {
        self.trajectory = trajectory;
        self.lift_over_l = line.map(|d| d.lift);
        self.side_over_l = line.map(|d| d.side).filter(|&s| s != 0.0);
        for r in &mut self.reached_goals {
            r.trajectory = trajectory;
            r.line = line;
        }
    }

    /// Along a pose line, how it leaves the straight line.
    pub fn pose_line(&self) -> Option<Detour> {
        (self.trajectory == "pose_line").then(|| Detour {
            lift: self.lift_over_l.unwrap_or(0.0),
            side: self.side_over_l.unwrap_or(0.0),
        })
    }
}

/// `base` with every obstacle contact held on the chords between sample points, or `None` when
/// it has no obstacle held at its points alone.
pub(super) fn on_chords(base: &StaticProblem) -> Option<StaticProblem> {
    base.constraints
        .iter()
        .any(|c| matches!(c, Constraint::Obstacle(ob) if !ob.chords))
        .then(|| held_off(base, 0.0))
}

/// `base` with every obstacle contact held on the chords between sample points and `margin`
/// (units of L) further off the obstacle than the rod's radius.
pub(super) fn held_off(base: &StaticProblem, margin: f64) -> StaticProblem {
    let mut out = base.clone();
    for con in out.constraints.iter_mut() {
        if let Constraint::Obstacle(ob) = con {
            ob.chords = true;
            ob.clearance += margin;
        }
    }
    out
}

/// An observer that passes on only the question whether to stop: the confirmation replay's
/// shapes are not logged (the log holds the replay they confirm).
struct StopOnly<'a>(&'a mut dyn PlanObserver);

impl PlanObserver for StopOnly<'_> {
    fn stop_requested(&mut self) -> bool {
        self.0.stop_requested()
    }
}

/// The chords the replayed equilibria's contacts were held on, for a reader: `"chords"` (the
/// case's contact samples) or `"the chords of N contact samples"`
/// ([`EquilibriumPlan::contact_samples`]).
pub fn chords_named(samples: Option<usize>) -> String {
    samples.map_or("chords".to_string(), |n| {
        format!("the chords of {n} contact samples")
    })
}

/// Values of `k` for a reader: `[0.015625, 0.01875, 0.025]` (nine decimals, trailing zeros
/// dropped: the replay's steps and bisections are short binary fractions, which `{:?}` can
/// print as `0.018750000000000003`).
pub fn k_list(ks: &[f64]) -> String {
    let each: Vec<String> = ks
        .iter()
        .map(|k| {
            let t = format!("{k:.9}");
            let t = t.trim_end_matches('0');
            t.strip_suffix('.').unwrap_or(t).to_string()
        })
        .collect();
    format!("[{}]", each.join(", "))
}

/// What keeps a replay's shapes from being a plan, if anything: the first failing check of
/// [`EquilibriumPlan::executable`] other than the confirmation. A replay may end on `ends_on`
/// (positions, units of L: another equilibrium of the goal pose) instead of the goal shape.
fn failure(first: &Replay, ends_on: Option<&[[f64; 3]]>) -> Option<Failed> {
    failure_on_the_way(first).or_else(|| ends_elsewhere(first, ends_on))
}

/// The checks of [`failure`] before the goal: every solve converged, nothing snaps, every shape
/// is stable.
fn failure_on_the_way(first: &Replay) -> Option<Failed> {
    use EquilibriaFailure::*;
    let ks = |f: &dyn Fn(&super::replay::ReplayStep) -> bool| -> Vec<f64> {
        first.steps.iter().filter(|s| f(s)).map(|s| s.k).collect()
    };
    if first.steps.is_empty() {
        return Some((NotRun, "the replay did not run".into()));
    }
    if !first.all_converged {
        let at = k_list(&ks(&|s| !s.converged));
        return Some((
            NotConverged,
            format!("replay solves did not converge at k = {at}"),
        ));
    }
    if !first.snaps.is_empty() {
        let at = k_list(&first.snaps);
        return Some((
            SnapsThrough,
            format!("the replay snaps through at k = {at}"),
        ));
    }
    if !first.all_stable {
        let at = k_list(&ks(&|s| s.stable == Some(false)));
        return Some((
            Unstable,
            format!("replayed shapes are unstable at k = {at}"),
        ));
    }
    None
}

/// Where the replay's last shape is not the goal shape (nor within the tolerance of `ends_on`,
/// where given): why (the goal pose holds another equilibrium there).
fn ends_elsewhere(first: &Replay, ends_on: Option<&[[f64; 3]]>) -> Option<Failed> {
    let on_other = |p: &[[f64; 3]]| {
        first
            .steps
            .last()
            .is_some_and(|s| s.k == 1.0 && max_distance(&s.positions, p) <= first.tolerance)
    };
    (first.end_deviation_over_l > first.tolerance && !ends_on.is_some_and(on_other)).then(|| {
        (
            EquilibriaFailure::EndsElsewhere,
            format!(
                "the replay ends {:.3e} L from the goal shape: the goal pose holds another equilibrium there",
                first.end_deviation_over_l
            ),
        )
    })
}

/// Whether the shapes of `replay` keep clear of every obstacle and of themselves on the
/// verification grid in s (the static solves hold their contacts at their own sample points
/// only, and a shape leaning on a corner can dip between them): the first failure, if any,
/// and the smallest obstacle clearance (case units).
fn penetration(
    planner: &Planner,
    fine: &Model,
    replay: &Replay,
) -> (Option<Failed>, Option<f64>, bool) {
    let (worst, self_gap) = super::verify::shapes_clearance(
        fine,
        &planner.obstacles,
        planner.has_self_contact(),
        replay.steps.iter().map(|s| (s.k, s.a.as_slice())),
    );
    let tol = planner.collision_tolerance();
    let deepest = worst
        .iter()
        .min_by(|a, b| a.clearance.total_cmp(&b.clearance));
    let min_clearance = deepest.map(|w| w.clearance);
    if let Some(w) = deepest.filter(|w| w.clearance < -tol) {
        return (
            Some((
                EquilibriaFailure::EntersObstacle,
                format!(
                    "a replayed shape comes {:.3e} inside obstacle '{}' at k = {:.4}, s = {:.4} (between the static solve's contact points)",
                    -w.clearance, w.obstacle, w.k, w.s
                ),
            )),
            min_clearance,
            true,
        );
    }
    if let Some((g, k)) = self_gap.filter(|(g, _)| *g < -tol) {
        return (
            Some((
                EquilibriaFailure::CrossesItself,
                format!("a replayed shape crosses itself (gap {g:.3e}) at k = {k:.4}"),
            )),
            min_clearance,
            false,
        );
    }
    (None, min_clearance, false)
}

impl Planner {
    /// The equilibrium plan of `first`, the replay of `path(z)` under `base` (the planner's
    /// held problem, or its copy [`on_chords`]): checked (clearances on the verification model
    /// `fine`), and confirmed by a replay on twice as many steps (run only when every other
    /// check passes).
    pub(super) fn equilibrium_plan(
        &self,
        base: &StaticProblem,
        path: &DeformationPath,
        z: &[f64],
        first: &Replay,
        fine: &Model,
        observer: &mut dyn PlanObserver,
    ) -> EquilibriumPlan {
        // (Over the equilibria: a solve that did not converge is none.)
        let (iu, u_max) = super::replay::equilibrium_steps(&first.steps)
            .map(|(i, s)| (i, s.u_feasible))
            .fold((0, f64::NEG_INFINITY), |a, b| if b.1 > a.1 { b } else { a });
        // The replay may end on another equilibrium of the goal pose where the planner accepts
        // one ([`Planner::ends_on`]).
        let ends_on = self.ends_on.as_deref().map(Vec::as_slice);
        let on_the_way = failure_on_the_way(first);
        let mut plan = EquilibriumPlan {
            u_max,
            k_at_u_max: first.steps.get(iu).map_or(0.0, |s| s.k),
            min_clearance: first.min_clearance,
            max_contact_force: first.max_contact_force,
            k_at_max_contact_force: first.k_at_max_contact_force,
            contact: if base
                .constraints
                .iter()
                .any(|c| matches!(c, Constraint::Obstacle(ob) if ob.chords))
            {
                "chords"
            } else {
                "points"
            },
            ..EquilibriumPlan::unchecked()
        };
        plan.set_failure(
            on_the_way
                .clone()
                .or_else(|| ends_elsewhere(first, ends_on)),
        );
        if plan.reason.is_none() {
            let (why, clearance, dips) = penetration(self, fine, first);
            plan.set_failure(why);
            plan.min_clearance = clearance;
            plan.dips = dips;
        } else if on_the_way.is_none() {
            // It ends on another equilibrium of the goal pose: where its shapes keep clear, the
            // gripper's motion reaches it (a plan to it is judged on its own,
            // [`super::reached_goal`]); where they dip between the solves' contact points, it
            // may be their artefact, and the shapes are replayed again as any that dip are.
            let (why, clearance, dips) = penetration(self, fine, first);
            if why.is_none() {
                plan.reached_goals
                    .extend(first.steps.last().filter(|s| s.k == 1.0).map(|s| Reached {
                        a: s.a.clone(),
                        trajectory: plan.trajectory,
                        line: None,
                    }));
            } else if dips {
                plan.min_clearance = clearance;
                plan.dips = true;
            }
        }
        if plan.reason.is_some() || self.stopped() {
            if plan.reason.is_none() {
                plan.set_failure(Some((EquilibriaFailure::Interrupted, "interrupted".into())));
            }
            return plan;
        }
        let opts = ReplayOptions {
            steps: 2 * self.settings.replay_steps,
            early_stop: EarlyStop::Failure,
            ..self.settings.replay()
        };
        let second = replay_driven(
            base,
            &self.start,
            path,
            z,
            self.drive.as_deref(),
            opts,
            &self.static_options,
            &mut StopOnly(observer),
            &self.stop,
        );
        if self.stopped() {
            plan.set_failure(Some((EquilibriaFailure::Interrupted, "interrupted".into())));
            return plan;
        }
        // The largest distance between the replays' shapes at the k they share.
        let mut worst: f64 = 0.0;
        let mut j = 0;
        for s in &first.steps {
            while j < second.steps.len() && second.steps[j].k < s.k - 1e-12 {
                j += 1;
            }
            if let Some(t) = second.steps.get(j).filter(|t| (t.k - s.k).abs() <= 1e-12) {
                worst = worst.max(max_distance(&s.positions, &t.positions));
            }
        }
        plan.confirmation_steps = Some(opts.steps);
        plan.confirmation_deviation_over_l = Some(worst);
        let (why, clearance, dips) = penetration(self, fine, &second);
        plan.dips = dips;
        plan.min_clearance = match (plan.min_clearance, clearance) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        let confirmation = failure(&second, ends_on)
            .or(why)
            .map(|(_, r)| format!("the confirmation replay on {} steps: {r}", opts.steps))
            .or_else(|| {
                (worst > first.tolerance).then(|| {
                    format!(
                        "the confirmation replay on {} steps reaches shapes {:.3e} L from the replay's",
                        opts.steps, worst
                    )
                })
            });
        plan.set_failure(confirmation.map(|r| (EquilibriaFailure::Confirmation, r)));
        plan.executable = plan.reason.is_none();
        plan
    }
}

#[cfg(test)]
impl EquilibriumPlan {
    /// Equilibria along the optimal path's trajectory that are no plan: `reason`, a failure
    /// of the check `failure`.
    pub(crate) fn failed(failure: EquilibriaFailure, reason: &str) -> EquilibriumPlan {
        EquilibriumPlan {
            reason: Some(reason.into()),
            failure: Some(failure),
            u_max: 1.0,
            k_at_u_max: 1.0,
            ..EquilibriumPlan::unchecked()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{EquilibriumPlan, FailedRetry};

    /// Each failed retry is listed with what it changed, which check failed and why, a
    /// retry's own retries after it with both names; the reason holds the same as one
    /// sentence, after the plan's own failure, which stays apart with its kind.
    #[test]
    fn failed_retries_are_listed_one_by_one() {
        use super::EquilibriaFailure::*;
        let mut plan = EquilibriumPlan::failed(EndsElsewhere, "the replay ends elsewhere");
        assert_eq!(plan.own_reason(), Some("the replay ends elsewhere"));
        plan.retry_failed(
            "replayed with contacts on chords",
            SnapsThrough,
            "the replay snaps through",
        );
        let mut line = EquilibriumPlan::failed(NotConverged, "solves did not converge");
        line.retry_failed("replayed on chords", EntersObstacle, "a shape dips");
        plan.retry_failed_as("along the end's pose line", &line);
        let listed = |attempt: &str, failure, reason: &str| FailedRetry {
            attempt: attempt.into(),
            failure,
            reason: reason.into(),
        };
        assert_eq!(
            plan.retries,
            [
                listed(
                    "replayed with contacts on chords",
                    SnapsThrough,
                    "the replay snaps through"
                ),
                listed(
                    "along the end's pose line",
                    NotConverged,
                    "solves did not converge"
                ),
                listed(
                    "along the end's pose line, replayed on chords",
                    EntersObstacle,
                    "a shape dips"
                ),
            ]
        );
        assert_eq!(plan.own_reason(), Some("the replay ends elsewhere"));
        assert_eq!(plan.failure, Some(EndsElsewhere));
        assert_eq!(
            plan.reason.as_deref(),
            Some(
                "the replay ends elsewhere; replayed with contacts on chords: the replay snaps through; \
                 along the end's pose line: solves did not converge; replayed on chords: a shape dips"
            )
        );
        // Not serialised where nothing was retried; kinds in snake case.
        let json = serde_json::to_value(EquilibriumPlan::failed(Unstable, "x")).unwrap();
        assert!(json.get("retries").is_none());
        assert_eq!(json["failure"], "unstable");
        let json = serde_json::to_value(&plan).unwrap();
        assert_eq!(json["retries"][2]["reason"], "a shape dips");
        assert_eq!(json["retries"][2]["failure"], "enters_obstacle");
        assert_eq!(json["retries"][0]["failure"], "snaps_through");
        assert_eq!(json["failure"], "ends_elsewhere");
    }

    /// Nine decimals at most, no trailing zeros, and no rounding residue of a sum of steps.
    #[test]
    fn k_lists_read_as_short_decimals() {
        assert_eq!(super::k_list(&[]), "[]");
        assert_eq!(
            super::k_list(&[0.015625, 0.018750000000000003, 0.3109375, 0.0, 1.0]),
            "[0.015625, 0.01875, 0.3109375, 0, 1]"
        );
        assert_eq!(super::k_list(&[0.1 + 0.2]), "[0.3]");
    }
}
