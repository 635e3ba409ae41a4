//! A goal given by its pose alone, planned again to the equilibrium of that pose the gripper's
//! motion reaches ([`super::PlanSettings::reached_goal`]).
//!
//! The goal shape of a pose is the equilibrium its static solve finds, a local search from the
//! natural state (or a rod bent towards the pose), and a pose can hold several: a heavy cable
//! sags one way or another, a strip buckles up or down. Where no plan to that shape executes
//! but a replay — the rod's equilibria as the gripper follows the best plan's trajectory, or
//! the straight-line path's or a pose line tried after it — converges, stays stable, never
//! snaps, keeps clear of every obstacle and ends on another equilibrium of the goal pose, the
//! gripper does bring the rod to the goal pose, in that shape. (Where such shapes dip into an obstacle between the solves' contact points,
//! they are first replayed on the chords between them, as any that dip are: the other
//! equilibrium can be the dip's artefact.) The planner then plans again with that shape as the goal (solved at the goal
//! shape's end pose, which the replay held), and reports that plan where it is executable,
//! with both shapes' energies and how far apart they are
//! ([`super::PlanResult::reached_goal`]). The replay of the new plan is its verdict, as for any
//! plan. Where it is not executable, the equilibria along each trajectory that ended on another
//! equilibrium of the goal pose, in the order they were tried, are judged again with the one
//! they reached accepted as their end, every other check as before; the first that passes is
//! the plan (with `replan_failed`), else the first plan is reported, with what the second met.

use super::end_shapes::{on_chords_if_dipping, solve_warm_from};
use super::equilibrium_plan::{EquilibriaFailure, Reached};
use super::judge::Judged;
use super::observer::{PlanObserver, RecordedShapes, Recorder, flush};
use super::path::DeformationPath;
use super::replay::{EarlyStop, max_distance};
use super::result::{PlanResult, PlanStatus, PlanVerdict, ReachedGoal};
use super::trajectory::Trajectory;
use super::verify::fine_model;
use super::{Planner, endpoints::EndPose};
use crate::rod::kinematics::Shape;
use crate::rod::model::Model;
use crate::statics::{SolveStatus, StaticSolution};
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

    /// `result`, or, where it is not executable and the gripper's motion along one of its
    /// search's trajectories reached another equilibrium of a goal given by its pose alone,
    /// the plan to that equilibrium where that one is executable, else `result` with the
    /// equilibria of the first trajectory that passes, judged again with the end it reached
    /// accepted; with the reported plan's replayed shapes (`replayed`, the second search's or
    /// the second judgement's) passed on to `observer`. The second search's other shapes are
    /// not passed on but for the goal shape the plan ends on, at `k = 1` after the first's:
    /// the first search's end shapes and straight path were passed on as they came, and a log
    /// holds one of each along `k` (its optimiser's progress is passed on as it comes).
    pub(super) fn towards_reached_goal(
        &self,
        mut result: PlanResult,
        replayed: RecordedShapes,
        observer: &mut dyn PlanObserver,
    ) -> PlanResult {
        let model = &self.base.model;
        let Some((planner, mut reached, from)) = self.reached_goal_planner(&result) else {
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
        // The equilibria along each trajectory that reached another equilibrium of the goal
        // pose, in the order they were judged, judged again with that end accepted (every
        // other check as before): the first that passes is the plan.
        let tried = result
            .equilibrium_plan
            .as_ref()
            .map(|e| routes(&e.reached_goals))
            .unwrap_or_default();
        let fine = fine_model(model, self.verify_s_intervals(), 4);
        for route in tried {
            if self.stopped() || self.time_up() {
                break;
            }
            // (The equilibrium planned to again is solved already: its planner's goal.)
            let replanned = route.a == from;
            let solved = if replanned {
                Some((reached.clone(), planner.goal.clone()))
            } else {
                self.reached_equilibrium(&route.a, &result)
            };
            let Some((mut this, sol)) = solved else {
                continue;
            };
            let accepting = Planner {
                ends_on: Some(Arc::new(model.evaluate(&this.shape).positions)),
                ..self.clone()
            };
            let Some(j) = accepting.judge_route(&route, &result, &fine, observer) else {
                continue;
            };
            result.timing_s.replay += j.seconds;
            if !j.executable {
                continue;
            }
            // The goal shape the plan ends on: the second search's, or this one.
            if replanned {
                flush(&searched.goal_shape(), model, observer);
            } else {
                self.end_shape(1.0, &sol, observer);
            }
            flush(&j.shapes, model, observer);
            this.first_plan_seconds = reached.first_plan_seconds;
            this.replan_failed = Some(if replanned {
                again.verdict().to_string()
            } else {
                format!(
                    "not planned again to it; the plan made again to the equilibrium {:.3e} L from the goal shape that another trajectory reached: {}",
                    reached.distance_over_l,
                    again.verdict()
                )
            });
            let ks: Vec<f64> = j.replay.steps.iter().map(|s| s.k).collect();
            let optimised = j
                .equilibrium_plan
                .as_ref()
                .is_some_and(|e| e.pose_terms.is_some());
            // Along a pose line or an optimised course, the replayed equilibria's end poses.
            result.trajectory = match route.trajectory {
                t if optimised || t == "pose_line" => {
                    Trajectory::of_replay(model, &self.start.a, &j.replay)
                }
                "straight_path" => {
                    let path = self.path();
                    Trajectory::along(model, &path, &vec![0.0; path.n_vars()], &ks)
                }
                _ => Trajectory::along(model, &self.path_of(&result), &result.z, &ks),
            };
            result.replay = j.replay;
            result.equilibrium_plan = j.equilibrium_plan;
            if let Some(e) = result
                .equilibrium_plan
                .as_mut()
                .filter(|e| e.trajectory != "optimal_path")
            {
                e.optimal_path_not_executable = Some(this.first_plan.clone());
            }
            result.workspace = j.workspace.or(result.workspace);
            result.reached_goal = Some(this);
            return result;
        }
        flush(&replayed, model, observer);
        if let Some(e) = result.equilibrium_plan.as_mut() {
            e.retry_failed(
                &format!(
                    "planned again to the equilibrium of the goal pose the replay ends on ({:.3e} L from the goal shape)",
                    reached.distance_over_l
                ),
                EquilibriaFailure::PlannedAgain,
                &again.verdict().to_string(),
            );
        }
        result
    }

    /// The equilibria along `route`'s trajectory (that of `result`'s optimal path, of the
    /// straight-line path or a pose line), judged again by this planner, with the optimal
    /// path's shapes recorded as those of `result`'s path (`None`: a pose line there is not,
    /// [`Self::pose_line`]).
    fn judge_route(
        &self,
        route: &Reached,
        result: &PlanResult,
        fine: &Model,
        observer: &mut dyn PlanObserver,
    ) -> Option<Judged> {
        let path = self.path_of(result);
        let mut j = match route.trajectory {
            "pose_line" => {
                let line = Arc::new(self.pose_line(route.line?)?);
                self.judge_other_course(Some(&line), fine, observer)
            }
            "straight_path" => self.judge_other_course(None, fine, observer),
            _ => {
                let planned = result.status == PlanStatus::Planned;
                return Some(self.with_finer_if_dipping(|pl| {
                    pl.judge_path(&path, &result.z, planned, EarlyStop::Never, fine, observer)
                }));
            }
        };
        // (A replay of another trajectory records that trajectory's shapes as its optimal ones.)
        let mut a = vec![0.0; path.n()];
        let mut sh = Shape::default();
        j.shapes.set_optimal(|k| {
            let (e, c) = self.path_shape(&path, &result.z, k, &mut a, &mut sh);
            (a.clone(), e, c)
        });
        Some(j)
    }

    /// The planner with the goal shape the gripper's motion reached in `result`'s replay, and
    /// what it reports, where [`super::PlanSettings::reached_goal`] applies: a goal given by
    /// its pose alone, not planned again yet; a plan that is not executable, found before any
    /// stop or time limit, whose replayed equilibria (along the optimal path's trajectory, or
    /// the straight-line path's or a pose line's tried after it) converge, stay stable, never
    /// snap and keep clear of the obstacles but end on another equilibrium of the goal pose:
    /// the first such equilibrium [`Self::reached_equilibrium`] accepts, with the replay's
    /// last shape it was solved from.
    fn reached_goal_planner(
        &self,
        result: &PlanResult,
    ) -> Option<(Planner, ReachedGoal, Vec<f64>)> {
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
        let (reached, goal, from) = ep.reached_goals.iter().find_map(|r| {
            self.reached_equilibrium(&r.a, result)
                .map(|(reached, goal)| (reached, goal, r.a.clone()))
        })?;
        let mut planner = self.clone();
        planner.goal = goal;
        planner.goal_by_pose = false;
        Some((planner, reached, from))
    }

    /// The equilibrium `a`, the last shape of replayed equilibria of `result`, solved again at
    /// the goal shape's end pose under the planner's problem, and what it reports, where that
    /// solve converged, is stable, within the coincidence tolerance of `a` and beyond it from
    /// the goal shape.
    fn reached_equilibrium(
        &self,
        a: &[f64],
        result: &PlanResult,
    ) -> Option<(ReachedGoal, StaticSolution)> {
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
        let reason = result
            .equilibrium_plan
            .as_ref()
            .and_then(|e| e.reason.as_deref());
        let reached = ReachedGoal {
            solved_energy: self.goal.energy.internal(),
            energy: sol.energy.internal(),
            distance_over_l: from_goal,
            first_plan: match reason {
                Some(why) => format!("{}; equilibria: {why}", result.verdict()),
                None => result.verdict().to_string(),
            },
            first_plan_seconds: 0.0,
            shape: sol.a.clone(),
            replan_failed: None,
        };
        Some((reached, sol))
    }
}

/// The trajectories of `reached` (those that reached another equilibrium of the goal pose),
/// each once, with the first equilibrium it reached, in their order.
fn routes(reached: &[Reached]) -> Vec<Reached> {
    let mut out: Vec<Reached> = Vec::new();
    for r in reached {
        if !out
            .iter()
            .any(|o| o.trajectory == r.trajectory && o.line == r.line)
        {
            out.push(r.clone());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::equilibrium_plan::{EquilibriaFailure, EquilibriumPlan, Reached};
    use super::super::pose_line::Detour;

    /// Lifted by `lift`, not moved aside.
    fn lifted(lift: f64) -> Option<Detour> {
        Some(Detour { lift, side: 0.0 })
    }

    /// Equilibria that ended on `a` (one coefficient) along the optimal path's trajectory.
    fn ended_on(a: f64) -> EquilibriumPlan {
        EquilibriumPlan {
            reached_goals: vec![Reached {
                a: vec![a],
                trajectory: "optimal_path",
                line: None,
            }],
            ..EquilibriumPlan::failed(
                EquilibriaFailure::EndsElsewhere,
                "the replay ends elsewhere",
            )
        }
    }

    /// The equilibria reached along the trajectories tried after a plan's own follow its own,
    /// each with the trajectory that reached it; each trajectory is judged again once, with
    /// the first equilibrium it reached.
    #[test]
    fn reached_equilibria_keep_their_order_and_trajectory() {
        let mut plan = ended_on(1.0);
        let on_chords = ended_on(2.0);
        plan.retry_failed_as("replayed with contacts on chords", &on_chords);
        let mut straight = ended_on(3.0);
        straight.set_trajectory("straight_path", None);
        let mut line = ended_on(4.0);
        line.set_trajectory("pose_line", lifted(0.3));
        let mut higher = ended_on(5.0);
        higher.set_trajectory("pose_line", lifted(0.5));
        for (what, retry) in [
            ("straight", &straight),
            ("line", &line),
            ("higher", &higher),
        ] {
            plan.retry_failed_as(what, retry);
        }
        let got: Vec<(f64, &str, Option<Detour>)> = plan
            .reached_goals
            .iter()
            .map(|r| (r.a[0], r.trajectory, r.line))
            .collect();
        assert_eq!(
            got,
            [
                (1.0, "optimal_path", None),
                (2.0, "optimal_path", None),
                (3.0, "straight_path", None),
                (4.0, "pose_line", lifted(0.3)),
                (5.0, "pose_line", lifted(0.5)),
            ]
        );
        let routes: Vec<f64> = super::routes(&plan.reached_goals)
            .iter()
            .map(|r| r.a[0])
            .collect();
        assert_eq!(routes, [1.0, 3.0, 4.0, 5.0]);
        assert_eq!(line.trajectory, "pose_line");
        assert_eq!(line.lift_over_l, Some(0.3));
        assert_eq!(line.side_over_l, None);
        assert_eq!(line.pose_line(), lifted(0.3));
    }
}
