//! The search of [`Planner::run`]: the straight path first, then the starts, each group's best
//! plan judged, the chosen plan's report, and the plan again towards a goal pose's equilibrium
//! the gripper's motion reaches.

use super::end_course::EndCourse;
use super::equilibrium_plan::EquilibriumPlan;
use super::judge::Judged;
use super::observer::{PathKind, PlanObserver, RecordedShapes, ShapeRecord};
use super::result::{Attempt, PlanResult, PlanStatus, StartSummary, Timing};
use super::start::{self, Verified};
use super::starts::{Judgement, StartPlan};
use super::verify::fine_model;
use super::{Planner, clearance, pose_line, trajectory};
use crate::optim::AlStatus;
use crate::rod::kinematics::Shape;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

impl Planner {
    /// Runs the starts, replaying the best plan not yet replayed after each group (its shapes
    /// kept, to be logged if it is chosen); returns every start's plan, the chosen one (the best
    /// executable one if any, else the best by class and `U_max`) and its judgement.
    fn optimise_and_judge(
        &self,
        fine: &crate::rod::model::Model,
        observer: &mut dyn PlanObserver,
    ) -> (Vec<StartPlan>, usize, Judged) {
        // The starts stop once a replayed plan is executable (after the quick attempt, only
        // one that attains the lower bound on U_max), or as soon as a replay leaves the start
        // shape at k = 0, which no path can change.
        let mut judged: Vec<(usize, Judged)> = Vec::new();
        let mut judge = |runs: &[StartPlan], quick: bool, observer: &mut dyn PlanObserver| {
            // The best plan not replayed yet (a plan replayed and found not executable does
            // not stand in the way of the next attempt's).
            let Some(best) = (0..runs.len())
                .filter(|&i| !runs[i].repeat && !judged.iter().any(|(j, _)| *j == i))
                .max_by(|&i, &j| self.ranked(runs, i, j))
            else {
                return Judgement::GoOn;
            };
            // A quick plan that peaks inside the path cannot end the search: not replayed yet.
            if quick && !runs[best].plan.verification.peaks_at_an_end() {
                return Judgement::GoOn;
            }
            let j = self.judge(&runs[best], fine, observer);
            let (held, executable) = (j.replay.start_held(), j.executable);
            judged.push((best, j));
            if !held {
                return Judgement::StartLeft;
            }
            // (A quick plan got here only if it attains the lower bound.)
            let found = if quick {
                executable
            } else {
                judged.iter().any(|(_, j)| j.executable)
            };
            if found {
                Judgement::Executable
            } else {
                Judgement::GoOn
            }
        };
        let runs = self.run_starts(fine, observer, &mut judge);
        // Nothing executable: the plans judged whose replayed equilibria still dipped between
        // contact points after the retries on the case's, best first, judged again with twice
        // the contact samples, until one is executable. (Last, so that no plan the search found
        // is traded for one of these.)
        if self.finer_contacts.is_some() && !judged.iter().any(|(_, j)| j.executable) {
            let mut order: Vec<usize> = (0..judged.len())
                .filter(|&n| judged[n].1.dips_on_case_samples)
                .collect();
            order.sort_by(|&a, &b| self.ranked(&runs, judged[b].0, judged[a].0));
            let finer = Planner {
                finer_retry: true,
                ..self.clone()
            };
            for n in order {
                // (Past a time limit nothing new starts.)
                if self.stopped() || self.time_up() {
                    break;
                }
                let again = finer.judge(&runs[judged[n].0], fine, observer);
                if again.executable {
                    judged[n].1 = again;
                    break;
                }
            }
        }
        // The best executable plan judged, else the best plan.
        let best = judged
            .iter()
            .filter(|(_, j)| j.executable)
            .map(|(i, _)| *i)
            .max_by(|&i, &j| self.ranked(&runs, i, j))
            .unwrap_or_else(|| self.best_of(&runs));
        let judged = match judged.into_iter().find(|(i, _)| *i == best) {
            Some((_, j)) => j,
            None if self.stopped() => Judged::not_run(self.settings.coincide_tolerance),
            None => self.judge(&runs[best], fine, observer),
        };
        (runs, best, judged)
    }

    /// Optimises, verifies and replays the plan: the straight-line path when it already
    /// attains the lower bound on `U_max` and executes as it stands
    /// ([`PlanSettings::straight_path_first`](super::PlanSettings::straight_path_first)), else the best of the starts. With
    /// [`PlanSettings::time_limit`](super::PlanSettings::time_limit), the search starts nothing new once the limit has passed
    /// (counted from this call) and judges the best plan found by then.
    pub fn run(&self, observer: &mut dyn PlanObserver) -> PlanResult {
        match self.settings.time_limit {
            // A copy with this run's own deadline and flag: runs of one planner do not share
            // them. (A limit set after validation: none where the deadline cannot be
            // represented; the search's first stage only at or below zero.)
            Some(limit) => Planner {
                deadline: std::time::Duration::try_from_secs_f64(limit.max(0.0))
                    .ok()
                    .and_then(|d| std::time::Instant::now().checked_add(d)),
                timed_out: Arc::new(AtomicBool::new(false)),
                ..self.clone()
            }
            .run_searched(observer),
            None => self.run_searched(observer),
        }
    }

    /// [`Planner::run`] on this planner's deadline.
    fn run_searched(&self, observer: &mut dyn PlanObserver) -> PlanResult {
        observer.begin(&self.base.model);
        let (result, replayed) = self.search(observer);
        self.towards_reached_goal(result, replayed, observer)
    }

    /// Tells `observer` of the end shape `sol` at `k` (0: the start, 1: the goal).
    pub(super) fn end_shape(
        &self,
        k: f64,
        sol: &crate::statics::StaticSolution,
        observer: &mut dyn PlanObserver,
    ) {
        let model = &self.base.model;
        let sh = model.evaluate(&sol.a);
        observer.shape(
            model,
            &ShapeRecord {
                kind: PathKind::Endpoint,
                k,
                a: &sol.a,
                energy: sol.energy,
                clearance: clearance(&self.base, &sh.positions),
                deviation: None,
                stable: sol.stable,
                reactions: &sol.reactions,
                violation: Some(sol.max_violation),
            },
        );
    }

    /// The search of [`Planner::run`]: the plan, and its replay's shapes, not yet logged.
    pub(super) fn search(&self, observer: &mut dyn PlanObserver) -> (PlanResult, RecordedShapes) {
        let model = &self.base.model;
        observer.phase("endpoints");
        for (k, sol) in [(0.0, &self.start), (1.0, &self.goal)] {
            self.end_shape(k, sol, observer);
        }
        let t0 = std::time::Instant::now();
        let path = self.path();
        let nv = path.n_vars();
        let fine = fine_model(model, self.verify_s_intervals(), 4);
        // Reported only: where its shapes lie inside an obstacle, at grid values.
        let straight = self.verify_on(&fine, &path, &vec![0.0; nv], true);
        {
            let mut a = vec![0.0; path.n()];
            let mut sh = Shape::default();
            let steps = self.settings.replay_steps;
            for i in 0..=steps {
                let k = i as f64 / steps as f64;
                let (e, c) = self.path_shape(&path, &vec![0.0; nv], k, &mut a, &mut sh);
                observer.shape(
                    model,
                    &ShapeRecord {
                        kind: PathKind::Straight,
                        k,
                        a: &a,
                        energy: e,
                        clearance: c,
                        deviation: None,
                        stable: None,
                        reactions: &[],
                        violation: None,
                    },
                );
            }
        }

        observer.phase("optimise");
        self.poll(observer);
        let tol = self.collision_tolerance();
        // An end inside an obstacle: no path is collision-free, nothing to optimise. Else the
        // straight path when it already attains the lower bound and executes as it stands;
        // else the starts.
        let ends = self.end_clearances();
        let end_inside = self.end_inside_obstacle(&ends);
        // The plan is the equilibria along the straight path's trajectory or a pose line.
        let mut along_other = false;
        let (runs, best, mut judged) = if end_inside.is_some() {
            (
                Vec::new(),
                None,
                Judged::not_run(self.settings.coincide_tolerance),
            )
        } else {
            match self.straight_path_plan(&straight, observer) {
                Some(j) => (Vec::new(), None, j),
                None => match self.straight_trajectory_plan(&straight, &ends, &fine, observer) {
                    Some(j) => {
                        along_other = true;
                        (Vec::new(), None, j)
                    }
                    None => {
                        let (runs, best, judged) = self.optimise_and_judge(&fine, observer);
                        // Executable by the equilibria along the optimal path's end poses: that
                        // course optimised in the end's pose space, where that lowers the peak.
                        let by_equilibria = judged
                            .equilibrium_plan
                            .as_ref()
                            .is_some_and(|e| e.executable && e.trajectory == "optimal_path");
                        let judged = if judged.executable && by_equilibria {
                            let path = self.with_terms(runs[best].terms).path();
                            let z = &runs[best].plan.run.z;
                            let course = EndCourse::path(path.clone(), z.clone());
                            self.optimised_plan(course, (&path, z), judged, &fine, observer)
                        } else {
                            judged
                        };
                        (runs, Some(best), judged)
                    }
                },
            }
        };
        observer.phase("select");
        let path_terms = best.map_or(self.settings.path_terms, |b| runs[b].terms);
        let path = self.with_terms(path_terms).path();
        // The chosen start's plan, or the straight path's (no optimiser run, no samples added).
        let Verified {
            run: chosen,
            verification: ver,
            added,
        } = match best {
            Some(b) => runs[b].plan.clone(),
            None => Verified {
                run: start::StartRun::not_optimised(path.n_vars(), straight.u_max),
                verification: straight.clone(),
                added: Vec::new(),
            },
        };
        let optimiser = best.map(|_| chosen.status);
        let chosen = &chosen;
        // Nothing executable: the trajectory of the straight-line path's end, with the
        // equilibria the end poses produce (touching obstacles where the straight shapes cross
        // them), as the plan if they pass.
        if !judged.executable
            && end_inside.is_none()
            && judged.replay.start_held()
            && self.settings.equilibrium_plans
            && !self.stopped()
        {
            let why = judged
                .equilibrium_plan
                .as_ref()
                .and_then(|e| e.reason.clone())
                .unwrap_or_else(|| {
                    if judged.workspace.as_ref().is_some_and(|w| !w.within) {
                        "its end leaves the workspace".into()
                    } else {
                        "not executable".into()
                    }
                });
            // The straight-line path's trajectory, then the pose lines in their order
            // ([`pose_line::DETOURS`]); the first whose equilibria pass is the plan.
            // Of those that fail, only why is kept (not their replayed shapes).
            let mut found = None;
            let mut failed: Vec<(String, Option<EquilibriumPlan>)> = Vec::new();
            // (No line moved aside on a planar rod.)
            let lines = pose_line::DETOURS
                .iter()
                .filter_map(|&d| self.pose_line(d))
                .map(|l| Some(Arc::new(l)));
            for line in std::iter::once(None).chain(lines) {
                if line.is_some() && (!self.settings.pose_lines || self.stopped() || self.time_up())
                {
                    break;
                }
                // (Its course optimised in the end's pose space where it is a plan.)
                let s = self.judge_other_course(line.as_ref(), &fine, observer);
                if s.executable {
                    found = Some(s);
                    break;
                }
                let what = match &line {
                    None => "along the straight path's trajectory".into(),
                    Some(l) => format!("along {}", l.detour.line_name()),
                };
                failed.push((what, s.equilibrium_plan));
            }
            if let Some(mut s) = found {
                if let Some(e) = s.equilibrium_plan.as_mut() {
                    e.optimal_path_not_executable = Some(why);
                }
                judged = s;
                along_other = true;
            } else if let Some(e) = judged.equilibrium_plan.as_mut() {
                for (what, f) in &failed {
                    if let Some(f) = f {
                        e.retry_failed_as(what, f);
                    }
                }
            }
        }
        let t_plan = t0.elapsed().as_secs_f64() - judged.seconds;

        observer.phase("replay");
        // Along the straight path or a pose line, the replay recorded the straight path's shapes
        // as its optimal ones (logged as the straight path's already): the log's optimal path is
        // the optimiser's.
        if along_other {
            let mut a = vec![0.0; path.n()];
            let mut sh = Shape::default();
            judged.shapes.set_optimal(|k| {
                let (e, c) = self.path_shape(&path, &chosen.z, k, &mut a, &mut sh);
                (a.clone(), e, c)
            });
        }
        let interrupted = self.poll(observer) || self.stopped();
        let t_replay = judged.seconds;
        let (rep, equilibrium_plan, judged_workspace) =
            (judged.replay, judged.equilibrium_plan, judged.workspace);
        let ks: Vec<f64> = rep.steps.iter().map(|s| s.k).collect();
        let straight_path = self.path();
        let straight_z = vec![0.0; straight_path.n_vars()];
        let (traj_path, traj_z) = if along_other {
            (&straight_path, &straight_z)
        } else {
            (&path, &chosen.z)
        };
        // Along a pose line or an optimised course, the end poses of the replayed equilibria,
        // which hold them.
        let along_line = equilibrium_plan
            .as_ref()
            .is_some_and(|e| e.trajectory == "pose_line" || e.pose_terms.is_some());
        let trajectory = if along_line {
            trajectory::Trajectory::of_replay(model, &self.start.a, &rep)
        } else {
            trajectory::Trajectory::along(model, traj_path, traj_z, &ks)
        };
        // Judged with the replay; a run stopped before it is checked here.
        let workspace = judged_workspace.or_else(|| self.workspace_check(traj_path, traj_z));
        let status = if interrupted {
            PlanStatus::Interrupted
        } else if end_inside.is_some() || !ver.collision_free(tol) {
            PlanStatus::Collision
        } else if workspace.as_ref().is_some_and(|w| !w.within) {
            PlanStatus::OutsideWorkspace
        } else if optimiser.is_some_and(|o| o != AlStatus::Converged) {
            PlanStatus::NotConverged
        } else {
            PlanStatus::Planned
        };
        let result = PlanResult {
            status,
            optimiser,
            straight_path_plan: best.is_none() && end_inside.is_none(),
            end_inside_obstacle: end_inside,
            contact_samples: self.contact_refinement.clone(),
            contact_samples_tried: self.contact_tries.clone(),
            u_max: ver.u_max,
            k_at_u_max: ver.k_at_u_max,
            sampled_u_max: chosen.sampled_max,
            u_max_straight: straight.u_max,
            min_clearance: ver.min_clearance,
            min_clearance_straight: straight.min_clearance,
            violation: chosen.violation,
            starts: runs
                .iter()
                .map(|r| {
                    let v = &r.plan;
                    StartSummary {
                        start: r.index,
                        attempt: r.attempt,
                        path_terms: r.terms,
                        travel_weight: r.travel_weight,
                        swept_clearance: r.swept_clearance,
                        status: v.run.status,
                        sampled_u_max: v.run.sampled_max,
                        u_max: v.verification.u_max,
                        collision_free: v.verification.collision_free(tol),
                        violation: v.run.violation,
                        evaluations: v.run.evaluations,
                        tracking_rounds: v.run.tracking_rounds,
                        tracking_rounds_kept: v.run.tracking_rounds_kept,
                        equilibrium_deviation: v.run.equilibrium_deviation,
                    }
                })
                .collect(),
            time_limit_reached: self.timed_out.load(Ordering::Relaxed),
            starts_not_run: self.settings.starts
                - runs.iter().filter(|r| r.attempt == Attempt::Own).count(),
            path_terms,
            chosen_start: best.map(|b| runs[b].index),
            path: path.c_vectors(&chosen.z),
            added_samples: added,
            z: chosen.z.clone(),
            verification: ver,
            replay: rep,
            equilibrium_plan,
            workspace,
            trajectory,
            timing_s: Timing {
                endpoints: 0.0,
                plan: t_plan,
                replay: t_replay,
            },
            reached_goal: None,
        };
        (result, judged.shapes)
    }
}
