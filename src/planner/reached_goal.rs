//! A goal given by its pose alone, planned again to the equilibrium of that pose the gripper's
//! motion reaches ([`super::PlanSettings::reached_goal`]).
//!
//! The goal shape of a pose is the equilibrium its static solve finds, a local search from the
//! natural state (or a rod bent towards the pose), and a pose can hold several: a heavy cable
//! sags one way or another, a strip buckles up or down. Where no plan to that shape executes
//! but the replay of the best one — the rod's equilibria as the gripper follows its
//! trajectory — converges, stays stable, never snaps, keeps clear of every obstacle and ends on
//! another equilibrium of the goal pose, the gripper does bring the rod to the goal pose, in
//! that shape. (Where such shapes dip into an obstacle between the solves' contact points,
//! they are first replayed on the chords between them, as any that dip are: the other
//! equilibrium can be the dip's artefact.) The planner then plans again with that shape as the goal (solved at the goal
//! shape's end pose, which the replay held), and reports that plan where it is executable,
//! with both shapes' energies and how far apart they are
//! ([`super::PlanResult::reached_goal`]). The replay of the new plan is its verdict, as for any
//! plan. Where it is not executable, the first plan's replayed equilibria, which end on that
//! equilibrium, are judged again with it accepted as their end, every other check as before;
//! where they pass they are the plan (with `replan_failed`), else the first plan is reported, with
//! what the second met.

use super::end_shapes::{on_chords_if_dipping, solve_warm_from};
use super::observer::{PlanObserver, RecordedShapes, Recorder, flush};
use super::path::DeformationPath;
use super::replay::{EarlyStop, max_distance};
use super::result::{PlanResult, PlanStatus, PlanVerdict, ReachedGoal};
use super::trajectory::Trajectory;
use super::verify::fine_model;
use super::{Planner, endpoints::EndPose};
use crate::statics::SolveStatus;
use std::sync::Arc;

impl Planner {
    /// The path of `result`, a plan of this planner: from the start shape to the goal shape
    /// its optimiser planned to (the goal's solve, or the shape of a [`PlanResult::reached_goal`]
    /// planned again to), with its path terms; its unknowns are `result.z`.
    pub fn path_of(&self, result: &PlanResult) -> DeformationPath {
        let mut p = self.with_terms(result.path_terms);
        if let Some(g) = result.reached_goal.as_ref().filter(|g| g.replanned()) {
            p.goal.a = g.shape.clone();
        }
        p.path()
    }

    /// `result`, or, where it is not executable and the gripper's motion along its trajectory
    /// reached another equilibrium of a goal given by its pose alone, the plan to that
    /// equilibrium where that one is executable, else `result` with its replayed equilibria
    /// judged again with that end accepted, where they pass; with the reported plan's replayed
    /// shapes (`replayed`, the second search's or the second judgement's) passed on to
    /// `observer`. The second search's other
    /// shapes are not passed on but for its goal shape, at `k = 1` after the first's: the
    /// first search's end shapes and straight path were passed on as they came, and a log
    /// holds one of each along `k` (its optimiser's progress is passed on as it comes).
    pub(super) fn towards_reached_goal(
        &self,
        mut result: PlanResult,
        replayed: RecordedShapes,
        observer: &mut dyn PlanObserver,
    ) -> PlanResult {
        let model = &self.base.model;
        let Some((planner, mut reached)) = self.reached_goal_planner(&result) else {
            flush(&replayed, model, observer);
            return result;
        };
        let mut recorder = Recorder::passing(observer);
        recorder.phase("reached goal");
        let (mut again, again_replayed) = planner.search(&mut recorder);
        let searched = recorder.into_shapes();
        reached.first_plan_seconds = result.timing_s.plan + result.timing_s.replay;
        if again.verdict().is_executable() {
            flush(&searched.goal_shape(), model, observer);
            flush(&again_replayed, model, observer);
            again.timing_s.plan += result.timing_s.plan;
            again.timing_s.replay += result.timing_s.replay;
            again.reached_goal = Some(reached);
            return again;
        }
        // A run stopped during the second search is a stopped run.
        if again.status == PlanStatus::Interrupted {
            result.status = PlanStatus::Interrupted;
        }
        result.timing_s.plan += again.timing_s.plan;
        result.timing_s.replay += again.timing_s.replay;
        result.time_limit_reached |= again.time_limit_reached;
        // The first plan's equilibria, which bring the rod to that equilibrium of the goal
        // pose, judged again with that end accepted (every other check as before).
        let along_optimal = result
            .equilibrium_plan
            .as_ref()
            .is_some_and(|e| e.trajectory == "optimal_path");
        if along_optimal && !self.stopped() && !self.time_up() {
            let accepting = Planner {
                ends_on: Some(Arc::new(model.evaluate(&reached.shape).positions)),
                ..self.clone()
            };
            let path = self.path_of(&result);
            let fine = fine_model(model, self.verify_s_intervals(), 4);
            let planned = result.status == PlanStatus::Planned;
            let j =
                accepting.judge_path(&path, &result.z, planned, EarlyStop::Never, &fine, observer);
            result.timing_s.replay += j.seconds;
            if j.executable {
                flush(&searched.goal_shape(), model, observer);
                flush(&j.shapes, model, observer);
                let ks: Vec<f64> = j.replay.steps.iter().map(|s| s.k).collect();
                result.trajectory = Trajectory::along(model, &path, &result.z, &ks);
                result.replay = j.replay;
                result.equilibrium_plan = j.equilibrium_plan;
                result.workspace = j.workspace.or(result.workspace);
                reached.replan_failed = Some(again.verdict().to_string());
                result.reached_goal = Some(reached);
                return result;
            }
        }
        flush(&replayed, model, observer);
        if let Some(e) = result.equilibrium_plan.as_mut() {
            e.retry_failed(
                &format!(
                    "planned again to the equilibrium of the goal pose the replay ends on ({:.3e} L from the goal shape)",
                    reached.distance_over_l
                ),
                &again.verdict().to_string(),
            );
        }
        result
    }

    /// The planner with the goal shape the gripper's motion reached in `result`'s replay, and
    /// what it reports, where [`super::PlanSettings::reached_goal`] applies: a goal given by
    /// its pose alone, not planned again yet; a plan that is not executable, found before any
    /// stop or time limit, whose replayed equilibria converge, stay stable, never snap and keep
    /// clear of the obstacles but end on another equilibrium of the goal pose; that equilibrium, solved again at the goal shape's end
    /// pose under the planner's problem, converged, stable, within the coincidence tolerance of
    /// the replay's last shape and beyond it from the goal shape.
    fn reached_goal_planner(&self, result: &PlanResult) -> Option<(Planner, ReachedGoal)> {
        if !(self.settings.reached_goal && self.goal_by_pose)
            || result.verdict().is_executable()
            || result.verdict() == PlanVerdict::Interrupted
            || result.time_limit_reached
            || result.end_inside_obstacle.is_some()
            || self.stopped()
            || self.time_up()
        {
            return None;
        }
        let ep = result.equilibrium_plan.as_ref()?;
        let a = ep.reached_goal.as_deref()?;
        let model = &self.base.model;
        let goal_positions = model.evaluate(&self.goal.a).positions;
        let pose = EndPose::of(model, &self.goal.a, &goal_positions);
        let sol = solve_warm_from(&mut pose.problem(&self.held), a, &self.static_options);
        let tolerance = self.settings.coincide_tolerance;
        let (sol, _) = on_chords_if_dipping(
            &self.held,
            &self.obstacles,
            &pose,
            sol,
            &self.end_grid.1,
            &self.static_options,
            tolerance,
            true,
        );
        if sol.status != SolveStatus::Converged || sol.stable != Some(true) {
            return None;
        }
        let positions = model.evaluate(&sol.a).positions;
        let from_goal = max_distance(&positions, &goal_positions);
        let from_reached = max_distance(&positions, &model.evaluate(a).positions);
        if from_goal <= tolerance || from_reached > tolerance {
            return None;
        }
        let reached = ReachedGoal {
            solved_energy: self.goal.energy.internal(),
            energy: sol.energy.internal(),
            distance_over_l: from_goal,
            first_plan: match ep.reason.as_deref() {
                Some(why) => format!("{}; equilibria: {why}", result.verdict()),
                None => result.verdict().to_string(),
            },
            first_plan_seconds: 0.0,
            shape: sol.a.clone(),
            replan_failed: None,
        };
        let mut planner = self.clone();
        planner.goal = sol;
        planner.goal_by_pose = false;
        Some((planner, reached))
    }
}
