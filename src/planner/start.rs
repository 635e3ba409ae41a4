//! One start's pipeline: the path optimisation from a perturbed straight-line path (the
//! sharpness continuation, then equilibrium tracking, [`super::tracking`]), and the plan's
//! verification and sample refinement: where the verification grid finds tunnelling, or an
//! energy peak the optimiser's samples missed, the grid's worst `k` (and its neighbours) join
//! the samples and the sharpest stage runs again from the current path. Every start refines
//! its own plan, so that the starts compete on verified paths.

use super::observer::Progress;
use super::verify::Verification;
use super::workers::Workers;
use super::{Planner, settings};
use crate::optim::{AlOptions, AlStatus, augmented_lagrangian_warm};
use std::sync::Arc;

/// Optimality tolerance of a 3D rod's sharpness stages before the last (feasibility: a tenth
/// of it); the last stage keeps [`Planner::stage_options`]'. On the generated suite (seeds 1
/// and 2) the 3D plans' median time fell from 1.15 s to 0.91 s and from 1.30 s to 0.97 s, with
/// 29 and 25 of 30 plans executable against 29 and 26. (A planar rod's own attempt has its
/// own, [`OWN_EARLY_STAGE_OPTIMALITY`]; its other attempts carry the curvature from stage to
/// stage and converge every stage.)
const EARLY_STAGE_OPTIMALITY: f64 = 1e-3;

/// Optimality tolerance of the sharpness stages before the last in a planar rod's own attempt
/// (feasibility: a tenth of it), whose stages restart BFGS and the penalty: on the generated
/// suite's planar problems (65 seeds, 2026-12-07) the plans over 0.5 s fell from 239 to 171 of
/// 3,900; on 12 of those seeds from 43 to 32, against 38 with 1e-3, 42 with 1e-4 and 31 with
/// 1e-1 (docs/notes/speed-alternatives.md).
const OWN_EARLY_STAGE_OPTIMALITY: f64 = 1e-2;

/// A quick start's continuation also ends at the first converged stage whose samples peak
/// inside the path more than this fraction above the larger end energy: on the generated suite
/// (seeds 1–6, 256 quick starts) every quick plan that attained the lower bound did so in its
/// first stage, and no sharper stage lowered a quick plan's peak by more than 8 % of it.
const QUICK_PEAK_INSIDE: f64 = 0.25;

/// What the multiplier-method calls of one start have produced so far.
#[derive(Clone)]
pub(super) struct Tally {
    pub(super) lambda: Option<Vec<f64>>,
    pub(super) status: AlStatus,
    pub(super) violation: f64,
    pub(super) evaluations: usize,
}

impl Tally {
    /// Takes in one call's outcome; true when it failed numerically (nothing more to do).
    pub(super) fn absorb(&mut self, out: crate::optim::AlOutcome) -> bool {
        self.evaluations += out.evaluations;
        self.status = out.status;
        self.violation = out.max_violation;
        self.lambda = Some(out.lambda);
        self.status == AlStatus::NumericalFailure
    }
}

/// BFGS's inverse-Hessian approximation and the penalty a sharpness stage ended with (an empty
/// `hinv`: a scaled identity and the first stage's penalty).
#[derive(Clone, Default)]
pub(super) struct Curvature {
    pub(super) hinv: Vec<f64>,
    pub(super) rho: f64,
}

/// Where a start's sharpness stages begin: at stage `stage`, and, where the stages carry the
/// curvature ([`Planner::stages_carry_curvature`]), from `curvature`; or, given `first`, from
/// its path and results (a quick start's first stage, or a lifted plan taken as its stages'
/// result, [`FirstStage::lifted`]). `spent` is the objective evaluations the start has already
/// used (a refinement's rerun): the evaluation budget ([`Planner::over_budget`]) counts them.
#[derive(Clone, Default)]
pub(super) struct Resume {
    pub(super) stage: usize,
    pub(super) curvature: Curvature,
    pub(super) first: Option<Arc<FirstStage>>,
    pub(super) spent: usize,
}

/// A quick start's first sharpness stage, where it ran as a start of the case's own attempt
/// from the same path would: from a scaled identity and the first penalty, and without the
/// quick attempt's penalty hold ever taking effect ([`crate::optim::AlOutcome::penalty_held`]).
/// The case's own start from the same path then begins after it, bit for bit where it would
/// have been, and reports its progress again. A lifted plan is taken as a start's stages'
/// result the same way ([`FirstStage::lifted`]).
pub(super) struct FirstStage {
    /// The path after the stage.
    z: Vec<f64>,
    /// The multiplier method's results after the stage.
    tally: Tally,
    /// The progress the stage reported, with each report's worst shape.
    progress: Vec<(Progress, Vec<f64>)>,
}

impl FirstStage {
    /// A converged plan's path `z`, lifted to more path terms, with its sampled constraints'
    /// `violation` and its rows' multipliers `lambda`, taken as a start's stages' result.
    pub(super) fn lifted(z: Vec<f64>, violation: f64, lambda: Option<Vec<f64>>) -> FirstStage {
        FirstStage {
            z,
            tally: Tally {
                lambda,
                status: AlStatus::Converged,
                violation,
                evaluations: 0,
            },
            progress: Vec::new(),
        }
    }
}

#[derive(Clone)]
pub(super) struct StartRun {
    pub(super) z: Vec<f64>,
    pub(super) status: AlStatus,
    pub(super) violation: f64,
    pub(super) sampled_max: f64,
    pub(super) evaluations: usize,
    pub(super) tracking_rounds: usize,
    pub(super) tracking_rounds_kept: usize,
    /// The samples' largest distance to their equilibria after tracking (units of L): the
    /// replay's deviation estimated on the samples (`None` when not measured).
    pub(super) equilibrium_deviation: Option<f64>,
    /// False for a quick start whose samples peak inside the path after its stages: it cannot
    /// end the search, so it was neither tracked nor is it refined.
    pub(super) settled: bool,
    /// A quick start's BFGS inverse-Hessian approximation and penalty as its last stage ended,
    /// for a refinement's rerun to start from (empty for other starts).
    pub(super) curvature: Curvature,
    /// A quick start's first stage, where the case's own start from the same path may begin
    /// after it ([`FirstStage`]).
    pub(super) first_stage: Option<Arc<FirstStage>>,
    /// The samples of `k` the path was optimised on, and the multipliers of their rows the
    /// last solve ended with (none where nothing was solved).
    pub(super) samples: Arc<(Vec<f64>, Option<Vec<f64>>)>,
}

impl StartRun {
    /// The straight-line path `z = 0` (`n` unknowns) as a run that never optimised: no
    /// evaluations, no violation (its ends are the end shapes and its obstacle clearance is
    /// checked on the verification grid), `sampled_max` the largest energy of its samples; its
    /// `status` is not reported (the plan's `optimiser` is `None`).
    pub(super) fn not_optimised(n: usize, sampled_max: f64) -> StartRun {
        StartRun {
            z: vec![0.0; n],
            status: AlStatus::IterationLimit,
            violation: 0.0,
            sampled_max,
            evaluations: 0,
            tracking_rounds: 0,
            tracking_rounds_kept: 0,
            equilibrium_deviation: None,
            settled: true,
            curvature: Curvature::default(),
            first_stage: None,
            samples: Arc::default(),
        }
    }
}

impl Planner {
    /// The multiplier-method settings of each sharpness stage: the penalty starts at 1e2 (only
    /// the first stage's where stages carry it, [`Planner::stages_carry_curvature`]).
    pub fn stage_options(&self) -> AlOptions {
        AlOptions {
            feasibility_tol: 1e-6,
            optimality_tol: 1e-5,
            rho_initial: 1e2,
            rho_max: 1e8,
            max_outer: 30,
            max_inner: 300,
            active_tol: 1e-7,
            second_order: self.settings.optimiser == settings::Optimiser::Newton,
            max_step: f64::INFINITY,
            newton_multipliers: false,
            hold_penalty_when_feasible: false,
        }
    }

    /// Whether each sharpness stage after the first starts from the BFGS curvature and the
    /// penalty the stage before ended with, and holds the penalty while the path is feasible
    /// ([`AlOptions::hold_penalty_when_feasible`]): on a 3D rod, in a planar rod's quick attempt
    /// and in the attempts after the case's own (fallback path terms, the retry without the
    /// travel term). A refinement's rerun of the sharpest stage starts afresh, its new samples
    /// making it another problem (from the old curvature it left the 3D pillar case without
    /// swept rows tunnelling), except in the quick attempt, whose rerun starts from the
    /// curvature and penalty its stages ended with: on the generated suite (seeds 1–7,
    /// 2026-12-04) the same verdicts and U_max to 1 %, the planar plans' summed time 135 →
    /// 125 s and plans over 0.5 s 63 → 55.
    ///
    /// Restarting both made every stage cost about as much as the first. On the generated
    /// suite (seeds 1–7, 2026-12-04), carrying them took the 3D plans executable from 202 to 204
    /// of 210 and the slowest seed's 95th-percentile plan time from 2.38 to 1.86 s; in the
    /// planar fallbacks, whose evaluation budget cheaper stages stretch further, it took the
    /// planar plans executable from 404 to 408 of 420, every seed at 95 % or more.
    ///
    /// A planar case's own attempt restarts both at every stage: its local minima are a coin
    /// toss that the restarts decide for the low route. Carried there, the paper's case reached
    /// U_max 5.284 instead of 5.238, and equivalent spellings of its poses, equal to the last
    /// bits, reached different minima. The quick attempt carries them, and its plan ends the
    /// search only where no route can be lower: where it attains the lower bound on U_max.
    pub fn stages_carry_curvature(&self) -> bool {
        self.base.model.layout.spatial || self.quick || self.budget.is_some()
    }

    /// Optimises from `z0` on the samples `ks`, from the stage `from` says on, telling `sink`
    /// each outer iteration's progress and worst sampled shape as it happens.
    pub(super) fn optimise_from(
        &self,
        start: usize,
        z0: Vec<f64>,
        ks: &[f64],
        from: Resume,
        workers: &Workers,
        sink: &mut dyn FnMut(Progress, Vec<f64>),
    ) -> StartRun {
        let mut p = self.minimax_problem_at(ks.to_vec());
        p.set_workers(workers.clone());
        let unit = self.base.model.rod.energy_unit();
        let mut c = vec![0.0; crate::optim::Nlp::m(&p)];
        // Energy scale of the sharpness: the straight path's largest sampled energy.
        let zero = vec![0.0; p.path.n_vars()];
        crate::optim::Nlp::values(&mut p, &zero, &mut c);
        let u_ref = p
            .energies()
            .iter()
            .copied()
            .fold(0.0_f64, f64::max)
            .max(1e-3);
        let mut tally = Tally {
            lambda: None,
            status: AlStatus::IterationLimit,
            violation: f64::INFINITY,
            evaluations: from.spent,
        };
        let al = self.stage_options();
        let mut z = z0;
        // A case's own start after the quick start's first stage: its path, multipliers,
        // evaluations and progress are this start's own first stage's.
        if let Some(first) = &from.first {
            z.clone_from(&first.z);
            tally = first.tally.clone();
            for (p, w) in &first.progress {
                sink(Progress { start, ..*p }, w.clone());
            }
        }
        // A quick start records its first stage's progress.
        let mut first_progress = (self.quick && from.stage == 0).then(Vec::new);
        let mut first_stage = None;
        let carry = self.stages_carry_curvature();
        // With loose early stages, the stages before the sharpest stop at this tolerance: they
        // only carry the path to the next one. On a 3D rod, and in a planar rod's own attempt
        // (its stages restarted); the other planar attempts' stages carry the curvature and
        // are cheap.
        let early_tol = match self.settings.early_stages {
            settings::EarlyStages::Exact => None,
            settings::EarlyStages::Loose if self.base.model.layout.spatial => {
                Some(EARLY_STAGE_OPTIMALITY)
            }
            settings::EarlyStages::Loose => (!carry).then_some(OWN_EARLY_STAGE_OPTIMALITY),
        };
        // BFGS's inverse-Hessian approximation (empty: a scaled identity), and the penalty.
        let (mut hinv, mut rho) = if carry && !from.curvature.hinv.is_empty() {
            (from.curvature.hinv, from.curvature.rho)
        } else {
            (Vec::new(), al.rho_initial)
        };
        // No stage to run (a lifted plan, tracked only): the objective of the sharpest stage,
        // which its source ended with.
        if let Some(&b) = self.settings.sharpness.last()
            && from.stage >= self.settings.sharpness.len()
        {
            p.beta = b / u_ref;
        }
        // A quick start's samples peak at an end shape at the current `z`, where measured.
        let mut at_end = None;
        for (stage, &b) in self.settings.sharpness.iter().enumerate().skip(from.stage) {
            // (A start's first stage runs whatever the time.)
            if self.over_budget(tally.evaluations) || (stage > from.stage && self.time_up()) {
                tally.status = AlStatus::IterationLimit;
                break;
            }
            p.beta = b / u_ref;
            let early = early_tol.filter(|_| stage + 1 < self.settings.sharpness.len());
            let al = match early {
                Some(tol) => AlOptions {
                    optimality_tol: tol,
                    feasibility_tol: 0.1 * tol,
                    ..al
                },
                None => al,
            };
            let al = AlOptions {
                rho_initial: rho,
                hold_penalty_when_feasible: carry,
                ..al
            };
            if !carry {
                hinv.clear();
            }
            let out = {
                let sink = &mut *sink;
                let mut record = first_progress.as_mut().filter(|_| stage == 0);
                let mut sink = |p: Progress, w: Vec<f64>| {
                    if let Some(r) = record.as_mut() {
                        r.push((p, w.clone()));
                    }
                    sink(p, w)
                };
                let ks = p.ks.clone();
                let mw = p.mean_weight;
                // `q` is the problem evaluated at the iterate: its sampled energies and shapes
                // are the iterate's.
                augmented_lagrangian_warm(
                    &mut p,
                    &mut z,
                    tally.lambda.as_deref(),
                    al,
                    &mut hinv,
                    &mut |it, q| {
                        let u = q.energies();
                        let (j, &umax) = u
                            .iter()
                            .enumerate()
                            .max_by(|a, b| a.1.total_cmp(b.1))
                            .expect("samples");
                        let mean = u.iter().sum::<f64>() / u.len() as f64;
                        sink(
                            Progress {
                                start,
                                stage,
                                outer: it.outer,
                                smoothed_max: (it.f - mw * mean) * unit,
                                sampled_max: umax * unit,
                                k_worst: ks[j],
                                violation: it.violation,
                                rho: it.rho,
                            },
                            q.sampled()[j].clone(),
                        );
                        !self.stopped()
                    },
                )
            };
            at_end = None;
            if carry {
                rho = out.rho.max(al.rho_initial);
            }
            let held = out.penalty_held;
            if tally.absorb(out) || self.stopped() {
                break;
            }
            if stage == 0
                && !held
                && let Some(progress) = first_progress.take()
            {
                first_stage = Some(Arc::new(FirstStage {
                    z: z.clone(),
                    tally: tally.clone(),
                    progress,
                }));
            }
            // The quick attempt's continuation ends at the first converged stage whose samples
            // peak at an end shape: it has attained the lower bound on the samples, and the
            // sharper stages could only move its interior below that peak.
            if self.quick && tally.status == AlStatus::Converged {
                crate::optim::Nlp::values(&mut p, &z, &mut c);
                at_end = Some(p.peaks_at_an_end());
                if at_end == Some(true) || p.peaks_far_inside(QUICK_PEAK_INSIDE) {
                    break;
                }
            }
        }
        // A quick plan counts only where it attains the lower bound: one whose samples peak
        // inside the path is left as the stages made it (no tracking, no sample refinement).
        let settled = !self.quick
            || at_end.unwrap_or_else(|| {
                crate::optim::Nlp::values(&mut p, &z, &mut c);
                p.peaks_at_an_end()
            });
        // Equilibrium tracking: pull every sampled shape onto the equilibrium its end pose
        // produces (docs/algorithms.md, step 4, says why the paper's objective alone does not).
        let (tracking_rounds, tracking_rounds_kept, equilibrium_deviation) = if settled
            && !matches!(
                tally.status,
                AlStatus::NumericalFailure | AlStatus::Interrupted
            ) {
            self.track(&mut p, &mut z, &mut tally, al)
        } else {
            (0, 0, None)
        };
        crate::optim::Nlp::values(&mut p, &z, &mut c);
        let sampled_max = p
            .energies()
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max)
            * unit;
        StartRun {
            z,
            status: tally.status,
            violation: tally.violation,
            sampled_max,
            evaluations: tally.evaluations,
            tracking_rounds,
            tracking_rounds_kept,
            equilibrium_deviation,
            settled,
            curvature: if self.quick {
                Curvature { hinv, rho }
            } else {
                Curvature::default()
            },
            first_stage,
            samples: Arc::new((ks.to_vec(), tally.lambda)),
        }
    }
}

impl Planner {
    /// Whether a start that has made `evaluations` objective evaluations has used up its
    /// budget (see [`Planner::budget`]).
    pub(super) fn over_budget(&self, evaluations: usize) -> bool {
        self.budget.is_some_and(|b| evaluations >= b)
    }
}

/// One start's plan after its verification and sample refinement.
#[derive(Clone)]
pub(super) struct Verified {
    /// The optimiser's outcome (evaluations include the refinement rounds').
    pub(super) run: StartRun,
    /// The plan on the verification grid.
    pub(super) verification: Verification,
    /// Samples of `k` added by the refinement rounds.
    pub(super) added: Vec<f64>,
}

impl Planner {
    /// Verifies start `start`'s plan `run` (optimised on the samples `uniform`) with `check`
    /// and refines its samples while the grid finds tunnelling or a missed peak, keeping the
    /// best verified path (collision-free first, then the lower true U_max).
    pub(super) fn refine(
        &self,
        start: usize,
        run: StartRun,
        uniform: &[f64],
        check: &(dyn Fn(&[f64]) -> Verification + Sync),
        workers: &Workers,
        sink: &mut dyn FnMut(Progress, Vec<f64>),
    ) -> Verified {
        let tol = self.collision_tolerance();
        let h = 1.0 / (self.settings.verify_k_samples - 1) as f64;
        let gap = self.settings.energy_gap_tolerance;
        let missed_peak = |r: &StartRun, v: &Verification| {
            v.u_max - r.sampled_max > gap * r.sampled_max.abs().max(v.u_max.abs())
        };
        let better = |a: &Verification, b: &Verification| {
            (a.collision_free(tol), -a.u_max) > (b.collision_free(tol), -b.u_max)
        };
        let mut chosen = run;
        let first_stage = chosen.first_stage.take();
        let mut ver = check(&chosen.z);
        let mut ks = uniform.to_vec();
        let mut added = Vec::new();
        let mut kept: Option<(StartRun, Verification)> = None;
        for _ in 0..self.settings.sample_refinements {
            let tunnels = !ver.collision_free(tol);
            let peak = missed_peak(&chosen, &ver);
            if (!tunnels && !peak)
                || !chosen.settled
                || self.stopped()
                || self.over_budget(chosen.evaluations)
                || self.time_up()
            {
                break;
            }
            let worst_k: Vec<f64> = ver
                .obstacles
                .iter()
                .filter(|o| o.clearance < -tol)
                .map(|o| o.k)
                .chain(ver.self_contact.filter(|(g, _)| *g < -tol).map(|(_, k)| k))
                .chain(peak.then_some(ver.k_at_u_max))
                .collect();
            for kw in worst_k {
                // The grid's worst k and its grid neighbours, and the midpoints of the
                // optimiser's interval holding it and of the intervals on either side: the
                // sample spacing halves where the path tunnels or peaks.
                let mut cand = vec![kw - h, kw, kw + h];
                let i = ks
                    .iter()
                    .rposition(|&q| q <= kw)
                    .unwrap_or(0)
                    .min(ks.len() - 2);
                for j in i.saturating_sub(1)..(i + 2).min(ks.len() - 1) {
                    cand.push(0.5 * (ks[j] + ks[j + 1]));
                }
                for k in cand {
                    if k > 0.0 && k < 1.0 && !ks.iter().any(|&q| (q - k).abs() < 0.25 * h) {
                        ks.push(k);
                        added.push(k);
                    }
                }
            }
            ks.sort_by(f64::total_cmp);
            if kept.as_ref().is_none_or(|(_, kv)| better(&ver, kv)) {
                kept = Some((chosen.clone(), ver.clone()));
            }
            // Warm: only the sharpest stage again.
            let last = self.settings.sharpness.len() - 1;
            // A quick start's rerun starts from the curvature and penalty its stages carried.
            // The rerun's evaluations count towards the start's budget: it continues from the
            // evaluations the start has used, and its own include them.
            let from = Resume {
                stage: last,
                curvature: chosen.curvature.clone(),
                first: None,
                spent: chosen.evaluations,
            };
            chosen = self.optimise_from(start, chosen.z.clone(), &ks, from, workers, sink);
            ver = check(&chosen.z);
        }
        if let Some((kr, kv)) = kept
            && better(&kv, &ver)
        {
            chosen = StartRun {
                evaluations: chosen.evaluations,
                ..kr
            };
            ver = kv;
        }
        chosen.first_stage = first_stage;
        Verified {
            run: chosen,
            verification: ver,
            added,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A refinement's rerun counts the evaluations its start used before it: one that starts a
    /// single evaluation short of the budget runs its stage (a stage in progress finishes) and
    /// then no tracking round, where the same rerun with the budget unused tracks.
    #[test]
    fn a_rerun_counts_the_evaluations_its_start_used() {
        let mut p = crate::planner::paper_planner();
        // Tracking runs until the samples lie on their equilibria (the case stops it early).
        p.settings.equilibrium_stop = Some(0.0);
        let budget = 1_000_000;
        p.budget = Some(budget);
        let n = p.path().n_vars();
        let z0: Vec<f64> = (0..n).map(|i| 0.3 * ((i as f64) * 0.7).sin()).collect();
        let ks: Vec<f64> = (0..41).map(|j| f64::from(j) / 40.0).collect();
        let last = p.settings.sharpness.len() - 1;
        let rerun = |spent: usize| {
            let from = Resume {
                stage: last,
                spent,
                ..Resume::default()
            };
            p.optimise_from(0, z0.clone(), &ks, from, &Workers::serial(), &mut |_, _| {})
        };
        let fresh = rerun(0);
        assert!(fresh.tracking_rounds > 0, "the control does not track");
        let late = rerun(budget - 1);
        // The same stage ran (at least one evaluation), and nothing after it.
        let stage = late
            .evaluations
            .checked_sub(budget - 1)
            .expect("the rerun's evaluations include its start's");
        assert!(stage > 0);
        assert!(fresh.evaluations > stage, "{} {stage}", fresh.evaluations);
        assert_eq!(late.tracking_rounds, 0);
    }

    /// A quick start whose first stage converges to samples that peak inside the path more
    /// than a quarter above the larger end energy ends its continuation there: on the paper's
    /// case (whose end shapes' energy is 2.55, and whose first stage leaves the samples peaking
    /// at about twice that) its path is that of a quick start with the first stage alone, bit
    /// for bit, and is neither tracked nor refined.
    #[test]
    fn a_quick_start_peaking_far_inside_ends_after_its_first_stage() {
        let mut quick = crate::planner::paper_planner();
        quick.quick = true;
        quick.budget = Some(quick.settings.fallback_evaluations);
        let mut first_only = quick.clone();
        first_only.settings.sharpness.truncate(1);
        let n = quick.path().n_vars();
        let z0 = vec![1e-2; n];
        let ks: Vec<f64> = (0..41).map(|j| f64::from(j) / 40.0).collect();
        let run = |pl: &Planner| {
            pl.optimise_from(
                0,
                z0.clone(),
                &ks,
                Resume::default(),
                &Workers::serial(),
                &mut |_, _| {},
            )
        };
        let (a, b) = (run(&quick), run(&first_only));
        assert_eq!(a.status, AlStatus::Converged);
        assert!(!a.settled && a.tracking_rounds == 0);
        assert_eq!(a.z, b.z);
        assert_eq!(a.evaluations, b.evaluations);
        let mut p = quick.minimax_problem_at(ks.clone());
        let mut c = vec![0.0; crate::optim::Nlp::m(&p)];
        crate::optim::Nlp::values(&mut p, &a.z, &mut c);
        let u = p.energies();
        let ends = u[0].max(u[u.len() - 1]);
        let top = u.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        assert!(top > (1.0 + QUICK_PEAK_INSIDE) * ends, "{top} vs {ends}");
    }
}
