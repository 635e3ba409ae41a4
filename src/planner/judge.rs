//! How a plan is judged: its replay by the controlled end, and where the plan is not
//! executable as it stands, its replayed equilibria as a plan, with their retries on the chords
//! between contact points and held off the obstacles.

use super::equilibrium_plan;
use super::observer::{PlanObserver, RecordedShapes, Recorder};
use super::path::DeformationPath;
use super::replay::{self, EarlyStop, Replay, ReplayOptions, replay_driven};
use super::result;
use super::starts::StartPlan;
use super::{HOLD_OFF_ROUNDS, Planner, hold_off_margin};
use crate::optim::AlStatus;
use crate::statics::problem::StaticProblem;

/// A plan replayed: its replay, its replayed equilibria as a plan where it is not executable
/// as it stands, the shapes both computed (logged if it is chosen) and the seconds they took.
pub(super) struct Judged {
    pub(super) replay: Replay,
    pub(super) equilibrium_plan: Option<equilibrium_plan::EquilibriumPlan>,
    /// The controlled end against the workspace (`None` without one).
    pub(super) workspace: Option<result::WorkspaceCheck>,
    pub(super) shapes: RecordedShapes,
    pub(super) seconds: f64,
    /// The optimal path coincides with its replay (collision-free and converged), or the
    /// replayed equilibria are a plan.
    pub(super) executable: bool,
    /// The replayed equilibria still dipped between contact points when the retries on the
    /// case's contact samples (chords, held off) had failed: those on twice the samples
    /// ([`Planner::finer_contacts`]) may pass.
    pub(super) dips_on_case_samples: bool,
}

impl Judged {
    /// Nothing replayed (the run was stopped first).
    pub(super) fn not_run(tolerance: f64) -> Judged {
        Judged {
            replay: Replay::not_run(tolerance),
            equilibrium_plan: None,
            workspace: None,
            shapes: RecordedShapes::default(),
            seconds: 0.0,
            executable: false,
            dips_on_case_samples: false,
        }
    }
}

impl Planner {
    /// The best of `runs`: collision-free first, then feasible on the samples, then estimated
    /// to coincide with its replay, then the lower verified `U_max`, the lower sampled maximum,
    /// the lower index.
    pub(super) fn best_of(&self, runs: &[StartPlan]) -> usize {
        (0..runs.len())
            .max_by(|&i, &j| self.ranked(runs, i, j))
            .expect("at least one start")
    }

    /// How `runs[i]` compares with `runs[j]` in [`Self::best_of`]'s order (greater: better).
    pub(super) fn ranked(&self, runs: &[StartPlan], i: usize, j: usize) -> std::cmp::Ordering {
        let (a, b) = (&runs[i].plan, &runs[j].plan);
        self.class(a)
            .cmp(&self.class(b))
            .then(b.verification.u_max.total_cmp(&a.verification.u_max))
            .then(b.run.sampled_max.total_cmp(&a.run.sampled_max))
            .then(j.cmp(&i))
    }

    /// Replays `run`'s plan and, where the plan is not executable as it stands, checks its
    /// replayed equilibria as a plan on the verification model `fine`; the shapes are kept,
    /// not logged.
    pub(super) fn judge(
        &self,
        run: &StartPlan,
        fine: &crate::rod::model::Model,
        observer: &mut dyn PlanObserver,
    ) -> Judged {
        let path = self.with_terms(run.terms).path();
        let planned = run
            .plan
            .verification
            .collision_free(self.collision_tolerance())
            && run.plan.run.status == AlStatus::Converged;
        self.judge_path(
            &path,
            &run.plan.run.z,
            planned,
            EarlyStop::Never,
            fine,
            observer,
        )
    }

    /// `judge(self)`, or, where its equilibria still dip into an obstacle between the chords
    /// of the case's contact samples, `judge` of the copy that judges them again on twice as
    /// many ([`Planner::finer_contacts`]), as the optimised plans' are when nothing executes.
    pub(super) fn with_finer_if_dipping(
        &self,
        mut judge: impl FnMut(&Planner) -> Judged,
    ) -> Judged {
        let j = judge(self);
        if j.executable
            || !j.dips_on_case_samples
            || self.finer_retry
            || self.finer_contacts.is_none()
            || self.stopped()
            || self.time_up()
        {
            return j;
        }
        judge(&Planner {
            finer_retry: true,
            ..self.clone()
        })
    }

    /// The replay of `path(z)` from the start shape under `base` (the held problem, or a copy
    /// with other contacts), with the plan's replay settings, ended early by `early_stop`.
    pub(super) fn replay_under(
        &self,
        base: &StaticProblem,
        path: &DeformationPath,
        z: &[f64],
        early_stop: EarlyStop,
        observer: &mut dyn PlanObserver,
    ) -> Replay {
        replay_driven(
            base,
            &self.start,
            path,
            z,
            self.drive.as_deref(),
            ReplayOptions {
                early_stop,
                ..self.settings.replay()
            },
            &self.static_options,
            observer,
            &self.stop,
        )
    }

    /// [`Self::judge`] of `path(z)`, executable as it stands when it coincides with its replay
    /// and `planned` (collision-free and converged); its replay ends early by `early_stop`
    /// (the replays of the equilibria's retries end at a solve that does not converge or a
    /// snap-through).
    pub(super) fn judge_path(
        &self,
        path: &DeformationPath,
        z: &[f64],
        planned: bool,
        early_stop: EarlyStop,
        fine: &crate::rod::model::Model,
        observer: &mut dyn PlanObserver,
    ) -> Judged {
        let t = std::time::Instant::now();
        let mut rec = Recorder::new(observer);
        let mut rep = self.replay_under(&self.held, path, z, early_stop, &mut rec);
        let workspace = self.workspace_check(path, z);
        let within = workspace.is_none_or(|w| w.within);
        let as_planned = planned && rep.coincide;
        let mut equilibrium_plan =
            (!as_planned && self.settings.equilibrium_plans && !self.stopped())
                .then(|| self.equilibrium_plan(&self.held, path, z, &rep, fine, &mut rec));
        if let Some(ep) = equilibrium_plan.as_mut() {
            let l = self.base.model.rod.length;
            ep.contact_margin = self.start_contacts.filter(|&m| m > 0.0).map(|m| m * l);
        }
        let mut shapes = rec.into_shapes();
        let mut dips_on_case_samples = false;
        // Equilibria that dip between the solves' contact points: replayed again with the
        // contacts on the chords between them, and where they still dip, held off the obstacles
        // by twice the depth (at most a twentieth of the coincidence tolerance, so that the
        // shapes stay well within it of the equilibria on the obstacles themselves). Where they
        // still dip after that, on the copy that judges plans again when nothing was executable
        // (`finer_retry`, which goes straight there: the case's retries ran and failed as they
        // did the first time), the same on twice the contact samples, whose chords dip about a
        // quarter as deep, from the start pose solved there.
        if let Some(ep) = equilibrium_plan
            .as_mut()
            .filter(|e| e.dips && !self.stopped())
        {
            let l = self.base.model.rod.length;
            let coincide = self.settings.coincide_tolerance;
            let start_margin = self.start_contacts.unwrap_or(0.0);
            // Replays the shapes under `held` (off the obstacles by `margin`, units of L, on
            // `samples` contact samples where not the case's); where they are a plan, it is
            // this one. Returns how deep they dip between contact points (0 where they do not).
            let mut run = |pl: &Planner,
                           held: &StaticProblem,
                           what: &str,
                           margin: f64,
                           samples: Option<usize>,
                           ep: &mut equilibrium_plan::EquilibriumPlan,
                           rep: &mut Replay,
                           shapes: &mut RecordedShapes| {
                let mut rec = Recorder::new(observer);
                let again = pl.replay_under(held, path, z, EarlyStop::Failure, &mut rec);
                let plan = pl.equilibrium_plan(held, path, z, &again, fine, &mut rec);
                if plan.executable {
                    *ep = equilibrium_plan::EquilibriumPlan {
                        contact_margin: (margin > 0.0).then_some(margin * l),
                        contact_samples: samples,
                        ..plan
                    };
                    *rep = again;
                    *shapes = rec.into_shapes();
                    return 0.0;
                }
                ep.retry_failed_as(what, &plan);
                match plan.min_clearance {
                    Some(c) if plan.dips => -c,
                    _ => 0.0,
                }
            };
            let mut depth = ep.min_clearance.map_or(0.0, |c| -c);
            for level in usize::from(self.finer_retry)..2 {
                if ep.executable || depth <= 0.0 || self.stopped() {
                    break;
                }
                if level == 1 {
                    dips_on_case_samples = true;
                }
                // The planner (its start shape solved there), the problem without the end, its
                // chords (`None`: the replay above held them already), and its contact samples
                // where not the case's.
                let (pl, base, chords, samples) = if level == 0 {
                    let chords = equilibrium_plan::on_chords(&self.held);
                    (std::borrow::Cow::Borrowed(self), &self.base, chords, None)
                } else {
                    let Some((n, finer)) =
                        self.finer_contacts.as_deref().filter(|_| self.finer_retry)
                    else {
                        break;
                    };
                    let held = equilibrium_plan::held_off(finer, start_margin);
                    let what = format!(
                        "replayed with contacts on {}",
                        equilibrium_plan::chords_named(Some(*n))
                    );
                    let Some(start) = replay::start_under(&held, &self.start, &self.static_options)
                    else {
                        ep.retry_failed(
                            &what,
                            equilibrium_plan::EquilibriaFailure::StartNotConverged,
                            "the start pose's solve did not converge",
                        );
                        break;
                    };
                    let mut pl = self.clone();
                    pl.start = start;
                    (std::borrow::Cow::Owned(pl), finer, Some(held), Some(*n))
                };
                let on = equilibrium_plan::chords_named(samples);
                if let Some(chords) = chords {
                    let what = format!("replayed with contacts on {on}");
                    let (m, s) = (start_margin, samples);
                    depth = run(&pl, &chords, &what, m, s, ep, &mut rep, &mut shapes);
                }
                // Held off by twice the depth; where the shapes still dip, by twice their new
                // depth more ([`HOLD_OFF_ROUNDS`] times at most, within the same cap in all).
                let mut margin = hold_off_margin(depth, l, coincide);
                for _ in 0..HOLD_OFF_ROUNDS {
                    let Some(m) = margin.filter(|_| !ep.executable && !self.stopped()) else {
                        break;
                    };
                    // On top of the margin the start shape already needed.
                    let held_by = m + start_margin;
                    let held = equilibrium_plan::held_off(base, held_by);
                    let what = format!(
                        "replayed on {on} held {:.1e} off the obstacles",
                        held_by * l
                    );
                    depth = run(
                        &pl,
                        &held,
                        &what,
                        held_by,
                        samples,
                        ep,
                        &mut rep,
                        &mut shapes,
                    );
                    margin = (depth > 0.0)
                        .then(|| hold_off_margin(m * l / 2.0 + depth, l, coincide))
                        .flatten();
                }
            }
        }
        let executable = !self.stopped()
            && within
            && (as_planned || equilibrium_plan.as_ref().is_some_and(|e| e.executable));
        Judged {
            replay: rep,
            equilibrium_plan,
            workspace,
            shapes,
            seconds: t.elapsed().as_secs_f64(),
            executable,
            dips_on_case_samples,
        }
    }
}
