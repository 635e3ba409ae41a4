//! Which starts run: groups of `parallel_starts` starts side by side; on a planar rod first the
//! quick attempt ([`Attempt::Quick`]: the first group with the case's path terms, its stages
//! carrying the optimiser's curvature), then with the case's path terms, then with each of
//! `fallback_path_terms`, then (when the objective has a travel term) with the case's path
//! terms and the paper's objective, without the travel term, and last (when tracking follows
//! the slopes of the equilibria) with the paper's objective and tracking's fixed targets
//! ([`Attempt::FixedTargets`]), until a plan replayed after a
//! group (the best not replayed yet) is executable (its replay coincides with it, or its
//! replayed equilibria are a plan; after the quick attempt, only one that attains the lower
//! bound on `U_max` ends the search); and which of the plans is the plan. Where the quick
//! attempt's plan attains that bound, or the case's own plan converged, and it is
//! collision-free but not executable, the same path with the first fallback count's path
//! terms is tracked again before the next attempt ([`Attempt::Lifted`], once per search). Unless the case sets
//! `swept_clearance`, the attempts after one whose plans all tunnel through an obstacle (other
//! than the quick attempt) hold the swept rows.

use super::Planner;
use super::observer::{PlanObserver, Progress};
use super::result::Attempt;
use super::start::{FirstStage, Resume, Verified};
use super::verify::{Verification, verify_grid};
use crate::planner::path::DeformationPath;
use crate::rod::model::Model;
use std::borrow::Cow;
use std::sync::Arc;

/// One start's verified plan and the path-term count it was planned with.
#[derive(Clone)]
pub(super) struct StartPlan {
    /// Index among the starts: `starts` per attempt, in the order the attempts run (on a
    /// planar rod the quick attempt's `0..starts`, of which its first group runs, then the
    /// case's own, then each fallback count's, …).
    pub(super) index: usize,
    /// The attempt it belongs to.
    pub(super) attempt: Attempt,
    /// Path terms of its path.
    pub(super) terms: usize,
    /// Weight of the travel term in its objective.
    pub(super) travel_weight: f64,
    /// Whether its optimiser held the swept-clearance rows.
    pub(super) swept_clearance: bool,
    /// The plan, verified and refined.
    pub(super) plan: Verified,
    /// A lifted plan whose tracking kept no round: the path of the plan it was lifted from,
    /// already judged, so it is not judged again (and that plan ranks before it).
    pub(super) repeat: bool,
}

/// A plan to lift ([`Attempt::Lifted`]): the planner with the first fallback count's path
/// terms (the plan's travel weight and swept rows), the plan's path with the new terms zero,
/// its sampled constraints' violation, and its samples and multipliers
/// ([`super::start::StartRun::samples`]).
struct Lift {
    planner: Planner,
    z: Vec<f64>,
    violation: f64,
    samples: Arc<(Vec<f64>, Option<Vec<f64>>)>,
    /// Objective evaluations it may use, its refinement reruns and their tracking included.
    budget: usize,
}

/// Judges the plans so far (told whether they come from the quick attempt): whether they end
/// the search, and why.
pub(super) type Judge<'a> = dyn FnMut(&[StartPlan], bool, &mut dyn PlanObserver) -> Judgement + 'a;

/// What the judgement of the plans so far says about the search.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Judgement {
    /// No plan is good enough yet: the search goes on.
    GoOn,
    /// A plan is executable (after the quick attempt, only one that attains the lower bound on
    /// `U_max` counts).
    Executable,
    /// The replay left the start shape at k = 0, which no path can change: no plan can be
    /// executable.
    StartLeft,
}

impl Judgement {
    /// Whether the search ends here.
    fn ends(self) -> bool {
        self != Judgement::GoOn
    }
}

/// Deterministic pseudo-random numbers in `[-1, 1]` (xorshift64*).
fn noise(seed: u64, n: usize) -> Vec<f64> {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..n)
        .map(|_| {
            s ^= s >> 12;
            s ^= s << 25;
            s ^= s >> 27;
            let v = s.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
            2.0 * (v as f64 / (1u64 << 53) as f64) - 1.0
        })
        .collect()
}

/// Largest violation of the optimiser's sampled constraints (dimensionless) for which a plan
/// counts as feasible on its samples.
const FEASIBLE_ON_SAMPLES: f64 = 1e-6;

/// The order in which plans are preferred before their `U_max`: collision-free on the
/// verification grid first, then feasible on the optimiser's samples, then estimated to
/// coincide with their replay, then settled (fields compared in that order).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(super) struct PlanClass {
    /// Clear of every obstacle and of itself on the verification grid.
    pub(super) collision_free: bool,
    /// The optimiser's sampled constraints hold.
    pub(super) feasible: bool,
    /// The sampled shapes lie within the coincidence tolerance of their equilibria.
    pub(super) coincides: bool,
    /// Tracked and refined: not a quick plan left as its stages made it, peaking inside the
    /// path ([`super::start::StartRun::settled`]).
    pub(super) settled: bool,
}

impl Planner {
    /// The planner with `terms` path terms and the same settings otherwise: its
    /// [`Planner::path`] is the path of a plan whose `path_terms` is `terms`.
    pub fn with_terms(&self, terms: usize) -> Planner {
        let mut p = self.clone();
        p.settings.path_terms = terms;
        p
    }

    /// The planner with the paper's objective: no travel term, the same settings otherwise.
    fn without_travel(&self) -> Planner {
        let mut p = self.clone();
        p.settings.travel_weight = 0.0;
        p
    }

    /// The planner with the paper's objective and tracking's fixed targets: no travel term, no
    /// slopes, the same settings otherwise.
    fn fixed_targets(&self) -> Planner {
        let mut p = self.without_travel();
        p.settings.equilibrium_slopes = false;
        p
    }

    /// The planner of the quick attempt ([`Attempt::Quick`]), the same settings otherwise.
    fn quick(&self) -> Planner {
        let mut p = self.clone();
        p.quick = true;
        p
    }

    /// `p` with the evaluation budget of the attempts after the case's own
    /// (`fallback_evaluations`).
    fn budgeted(&self, mut p: Planner) -> Planner {
        p.budget = Some(self.settings.fallback_evaluations);
        p
    }

    /// The planner with the swept-clearance rows on, the same settings otherwise.
    fn with_swept_clearance(&self) -> Planner {
        let mut p = self.clone();
        p.settings.swept_clearance = Some(true);
        p
    }

    /// The path `z` of `path` on the verification grid of the quadrature `fine`; with
    /// `skip_inside`, for a report only ([`super::verify::verify_grid`]).
    pub(super) fn verify_on(
        &self,
        fine: &Model,
        path: &DeformationPath,
        z: &[f64],
        skip_inside: bool,
    ) -> Verification {
        verify_grid(
            fine,
            path,
            z,
            self.settings.verify_k_samples,
            &self.obstacles,
            self.base.objective,
            self.has_self_contact(),
            skip_inside,
            &self.workers,
        )
    }

    /// How good plan `r` is before its `U_max` counts ([`PlanClass`]).
    pub(super) fn class(&self, r: &Verified) -> PlanClass {
        PlanClass {
            collision_free: r.verification.collision_free(self.collision_tolerance()),
            feasible: r.run.violation <= FEASIBLE_ON_SAMPLES,
            coincides: r
                .run
                .equilibrium_deviation
                .is_some_and(|d| d <= self.settings.coincide_tolerance),
            settled: r.run.settled,
        }
    }

    /// Runs the starts in groups and the fallback path-term counts (see the module's doc),
    /// verifying each plan on `fine`, until `judge` finds the plans so far good enough (told
    /// whether they come from the quick attempt).
    pub(super) fn run_starts(
        &self,
        fine: &Model,
        observer: &mut dyn PlanObserver,
        judge: &mut Judge<'_>,
    ) -> Vec<StartPlan> {
        let nk = self.settings.k_samples;
        let uniform: Vec<f64> = (0..nk).map(|j| j as f64 / (nk - 1) as f64).collect();
        let starts = self.settings.starts;
        let mut runs: Vec<StartPlan> = Vec::new();
        // On a planar rod the quick attempt, then the case's planner, then one per fallback
        // count, then (with a travel term) the case's without it, then (with the slopes) the
        // case's without it and with fixed tracking targets, each made only when it is
        // reached. A route that must move the end away and back (two shapes at one pose) is
        // one the travel term argues against; one through a fork of the equilibria (a strip
        // that may buckle either way) is one the slopes' targets can lead the wrong way. Each
        // attempt but the case's own has an evaluation budget. (On a 3D rod the case's own
        // stages already carry the curvature.)
        let spatial = self.base.model.layout.spatial;
        let fallbacks = self.settings.fallback_terms(spatial);
        let budget = |p: Planner| Cow::Owned(self.budgeted(p));
        let attempts = (!spatial && self.settings.quick_attempt)
            .then(|| (Attempt::Quick, budget(self.quick())))
            .into_iter()
            .chain(std::iter::once((Attempt::Own, Cow::Borrowed(self))))
            .chain(
                fallbacks
                    .into_iter()
                    .map(|t| (Attempt::Fallback, budget(self.with_terms(t)))),
            )
            .chain(
                (self.settings.travel_weight > 0.0)
                    .then(|| (Attempt::WithoutTravel, budget(self.without_travel()))),
            )
            .chain(
                (self.settings.equilibrium_slopes && self.settings.tracking_weight(spatial) > 0.0)
                    .then(|| (Attempt::FixedTargets, budget(self.fixed_targets()))),
            );
        // Unless the case says otherwise, once an attempt's plans all tunnel through an obstacle
        // between their samples (the verification grid finds them colliding), the attempts
        // after it hold the swept rows that stop a point from crossing a thin obstacle between
        // two samples ([`super::PlanSettings::swept`]).
        let mut tunnelled = false;
        // Each attempt (a lifted one too) has `starts` indices, in the order they run.
        let mut attempt = 0;
        let mut lifted_once = false;
        'attempts: for (kind, pl) in attempts {
            let pl = if tunnelled && self.settings.swept_clearance.is_none() {
                Cow::Owned(pl.with_swept_clearance())
            } else {
                pl
            };
            let path = pl.path();
            let nv = path.n_vars();
            let check = |z: &[f64]| self.verify_on(fine, &path, z, false);
            // Start s: the straight-line path plus a perturbation of seed `seed + s`, 0.01 rad
            // for the first, `start_spread` for the others.
            let zs: Vec<(usize, Vec<f64>, Resume)> = (0..starts)
                .map(|s| {
                    let amp = if s == 0 {
                        1e-2
                    } else {
                        self.settings.start_spread
                    };
                    let z0 = noise(self.settings.seed.wrapping_add(s as u64), nv)
                        .into_iter()
                        .map(|v| amp * v)
                        .collect();
                    // The case's own start begins after the first stage of the quick start
                    // from the same path where that stage ran as its own would have.
                    let first = (kind == Attempt::Own)
                        .then(|| {
                            runs.iter().find(|r| {
                                r.attempt == Attempt::Quick
                                    && r.index == s
                                    && r.terms == pl.settings.path_terms
                                    && r.travel_weight == pl.settings.travel_weight
                                    && r.swept_clearance == pl.settings.swept()
                            })
                        })
                        .flatten()
                        .and_then(|r| r.plan.run.first_stage.clone());
                    let from = Resume {
                        stage: usize::from(first.is_some()),
                        first,
                        ..Resume::default()
                    };
                    (attempt * starts + s, z0, from)
                })
                .collect();
            // The quick attempt runs its first group only.
            let groups = if kind == Attempt::Quick {
                1
            } else {
                usize::MAX
            };
            for group in zs.chunks(self.settings.parallel_starts()).take(groups) {
                // After the first group of the first attempt, nothing new starts once the time
                // limit has passed.
                if !runs.is_empty() && self.time_up() {
                    break 'attempts;
                }
                let done = pl.optimise_starts(group, &uniform, &check, observer);
                // (The quick attempt's plans are not refined when they peak inside the path, so
                // their collisions say nothing about the case's own attempt.)
                tunnelled |=
                    kind != Attempt::Quick && done.iter().all(|v| !self.class(v).collision_free);
                runs.extend(
                    group
                        .iter()
                        .zip(done)
                        .map(|((index, _, _), plan)| StartPlan {
                            index: *index,
                            attempt: kind,
                            terms: pl.settings.path_terms,
                            travel_weight: pl.settings.travel_weight,
                            swept_clearance: pl.settings.swept(),
                            plan,
                            repeat: false,
                        }),
                );
                // Checked before the next group, and before the next fallback planner is made.
                if self.stopped() {
                    break 'attempts;
                }
                let judgement = judge(&runs, kind == Attempt::Quick, observer);
                if judgement.ends() {
                    // Where the case's own attempt has an executable plan and a quick plan
                    // that peaks inside the path (neither tracked nor replayed) is lower, that
                    // plan is lifted and tracked as a plan at the bound is and judged too, and
                    // the better executable plan is the plan.
                    if kind == Attempt::Own
                        && judgement == Judgement::Executable
                        && !self.time_up()
                        && let Some(lift) = self.lower_quick(&runs)
                    {
                        attempt += 1;
                        let run = self.run_lifted(lift, attempt * starts, fine, observer);
                        let repeat = run.repeat;
                        runs.push(run);
                        if !repeat && !self.stopped() {
                            judge(&runs, false, observer);
                        }
                    }
                    break 'attempts;
                }
                // A plan of this group at the lower bound, collision-free but not executable:
                // the same path with more terms, tracked again (once per search).
                let liftable = (!lifted_once)
                    .then(|| self.lift(&runs[runs.len() - group.len()..], kind))
                    .flatten();
                if let Some(lift) = liftable.filter(|_| !self.time_up()) {
                    lifted_once = true;
                    attempt += 1;
                    let run = self.run_lifted(lift, attempt * starts, fine, observer);
                    let repeat = run.repeat;
                    runs.push(run);
                    if self.stopped() || (!repeat && judge(&runs, false, observer).ends()) {
                        break 'attempts;
                    }
                }
            }
            attempt += 1;
        }
        runs
    }

    /// Tracks, verifies and refines `lift`'s path as start `index`, with its planner (on the
    /// evaluation budget), on its source's samples and from its multipliers.
    fn run_lifted(
        &self,
        lift: Lift,
        index: usize,
        fine: &Model,
        observer: &mut dyn PlanObserver,
    ) -> StartPlan {
        let Lift {
            planner,
            z,
            violation,
            samples,
            budget,
        } = lift;
        let lifted = Planner {
            budget: Some(budget),
            ..planner
        };
        // No sharpness stage: the source's converged path is taken as their result, on its
        // samples, with its multipliers.
        let (ks, lambda) = &*samples;
        let from = Resume {
            stage: self.settings.sharpness.len(),
            first: Some(Arc::new(FirstStage::lifted(
                z.clone(),
                violation,
                lambda.clone(),
            ))),
            ..Resume::default()
        };
        let path = lifted.path();
        let check = |z: &[f64]| self.verify_on(fine, &path, z, false);
        let plan = lifted
            .optimise_starts(&[(index, z.clone(), from)], ks, &check, observer)
            .pop()
            .expect("one start");
        StartPlan {
            index,
            attempt: Attempt::Lifted,
            terms: lifted.settings.path_terms,
            travel_weight: lifted.settings.travel_weight,
            swept_clearance: lifted.settings.swept(),
            // Tracking that kept no round leaves the source's path, replayed already.
            repeat: plan.run.z == z,
            plan,
        }
    }

    /// With `lift` on, a quick plan that peaks inside the path, converged and collision-free,
    /// whose `U_max` on the verification grid is lower than every own plan's by more than the
    /// energy gap tolerance (the lowest such): lifted to the first fallback count (none
    /// without one), on a tenth of `fallback_evaluations`.
    fn lower_quick(&self, runs: &[StartPlan]) -> Option<Lift> {
        if !self.settings.lift {
            return None;
        }
        let tol = self.collision_tolerance();
        let own = runs
            .iter()
            .filter(|r| r.attempt == Attempt::Own)
            .map(|r| r.plan.verification.u_max)
            .fold(f64::INFINITY, f64::min);
        let gap = self.settings.energy_gap_tolerance;
        let r = runs
            .iter()
            .filter(|r| {
                let v = &r.plan;
                r.attempt == Attempt::Quick
                    && !v.run.settled
                    && v.run.status == crate::optim::AlStatus::Converged
                    && v.verification.collision_free(tol)
                    && v.verification.u_max < own - gap * own.abs()
            })
            .min_by(|a, b| {
                a.plan
                    .verification
                    .u_max
                    .total_cmp(&b.plan.verification.u_max)
            })?;
        let terms = *self
            .settings
            .fallback_terms(self.base.model.layout.spatial)
            .first()?;
        // An executable plan is in hand: the lift is a refinement of it, on a tenth of a
        // fallback's budget (those that made a lower plan executable on the generated suite
        // took 17-66 evaluations; those that failed, thousands in refinement reruns).
        let budget = self.settings.fallback_evaluations / 10;
        Some(self.lift_of(r, terms.max(r.terms), budget))
    }

    /// `r`'s path lifted to `terms` path terms, with its planner's settings, on `budget`
    /// evaluations.
    fn lift_of(&self, r: &StartPlan, terms: usize, budget: usize) -> Lift {
        let mut pl = self.with_terms(terms);
        pl.settings.travel_weight = r.travel_weight;
        pl.settings.swept_clearance = Some(r.swept_clearance);
        let v = &r.plan;
        Lift {
            z: DeformationPath::lift(&v.run.z, r.terms, terms),
            planner: pl,
            violation: v.run.violation,
            samples: Arc::clone(&v.run.samples),
            budget,
        }
    }

    /// The lift of the best of `group`'s plans (an attempt of kind `kind`) when it is
    /// collision-free, converged and settled, a quick plan peaks at an end shape on the
    /// verification grid, and the first fallback count has more path terms than it.
    fn lift(&self, group: &[StartPlan], kind: Attempt) -> Option<Lift> {
        if !matches!(kind, Attempt::Quick | Attempt::Own) || !self.settings.lift {
            return None;
        }
        let terms = *self
            .settings
            .fallback_terms(self.base.model.layout.spatial)
            .first()?;
        let best = (0..group.len()).max_by(|&i, &j| self.ranked(group, i, j))?;
        let r = &group[best];
        let v = &r.plan;
        let liftable = terms > r.terms
            && v.run.settled
            && v.run.status == crate::optim::AlStatus::Converged
            && v.verification.collision_free(self.collision_tolerance())
            && (kind == Attempt::Own || v.verification.peaks_at_an_end())
            // (Its equilibria on another branch: tracking would not start.)
            && v.run.equilibrium_deviation.is_none_or(|d| d <= super::tracking::TRACK_FAR);
        if !liftable {
            return None;
        }
        Some(self.lift_of(r, terms, self.settings.fallback_evaluations))
    }
}

impl Planner {
    /// Optimises from each of `starts` (start index, perturbation of the straight-line path and
    /// where its stages begin) on the samples `uniform`, then verifies and refines each plan with `check`
    /// ([`Planner::refine`]), on parallel threads when there are several starts, telling
    /// `observer` their progress as it happens.
    pub(super) fn optimise_starts(
        &self,
        starts: &[(usize, Vec<f64>, Resume)],
        uniform: &[f64],
        check: &(dyn Fn(&[f64]) -> Verification + Sync),
        observer: &mut dyn PlanObserver,
    ) -> Vec<Verified> {
        let model = &self.base.model;
        if starts.len() == 1 {
            let mut sink = |p: Progress, w: Vec<f64>| {
                observer.progress(model, &p, &w);
                self.poll(observer);
            };
            let (i, z0, from) = starts[0].clone();
            let run = self.optimise_from(i, z0, uniform, from, &self.workers, &mut sink);
            vec![self.refine(i, run, uniform, check, &self.workers, &mut sink)]
        } else {
            let workers = std::thread::available_parallelism()
                .map_or(1, |n| n.get())
                .min(starts.len());
            let mut results: Vec<Option<Verified>> = (0..starts.len()).map(|_| None).collect();
            // The starts report their progress through a channel, which this thread passes on
            // to the observer while they run.
            let (tx, rx) = std::sync::mpsc::channel::<(Progress, Vec<f64>)>();
            std::thread::scope(|sc| {
                let chunks: Vec<Vec<usize>> = (0..workers)
                    .map(|w| (w..starts.len()).step_by(workers).collect())
                    .collect();
                let handles: Vec<_> = chunks
                    .into_iter()
                    .map(|idx| {
                        let starts = &starts;
                        let uniform = &uniform;
                        let tx = tx.clone();
                        sc.spawn(move || {
                            let mut sink = |p: Progress, w: Vec<f64>| {
                                // The receiver outlives every start.
                                let _ = tx.send((p, w));
                            };
                            idx.into_iter()
                                .map(|j| {
                                    let (i, z0, from) = starts[j].clone();
                                    // The starts already share the cores.
                                    let one = super::workers::Workers::serial();
                                    let run =
                                        self.optimise_from(i, z0, uniform, from, &one, &mut sink);
                                    (j, self.refine(i, run, uniform, check, &one, &mut sink))
                                })
                                .collect::<Vec<_>>()
                        })
                    })
                    .collect();
                drop(tx);
                for (p, w) in rx {
                    observer.progress(model, &p, &w);
                    self.poll(observer);
                }
                for h in handles {
                    for (i, r) in h.join().expect("optimiser thread") {
                        results[i] = Some(r);
                    }
                }
            });
            results
                .into_iter()
                .map(|r| r.expect("every start ran"))
                .collect()
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::planner::path::DeformationPath;

    /// A path lifted to more path terms ([`DeformationPath::lift`], as
    /// [`super::Planner::lift`] makes it) is the same path: its shapes equal the source's at
    /// every `k`, bit for bit.
    #[test]
    fn a_lifted_path_is_the_same_path() {
        let planner = crate::planner::paper_planner();
        let (from, to) = (planner.path(), planner.with_terms(6).path());
        let z: Vec<f64> = super::noise(7, from.n_vars())
            .into_iter()
            .map(|v| 0.3 * v)
            .collect();
        let lifted = DeformationPath::lift(&z, from.terms, to.terms);
        assert_eq!(lifted.len(), to.n_vars());
        let n = from.n();
        let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
        for j in 0..=40 {
            let k = f64::from(j) / 40.0;
            from.shape_at(&z, k, &mut a);
            to.shape_at(&lifted, k, &mut b);
            assert_eq!(a, b, "k = {k}");
        }
    }
}
