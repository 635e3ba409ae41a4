//! The path optimisation of one start (the sharpness continuation, then equilibrium tracking),
//! and several starts on parallel threads.

use super::observer::{PlanObserver, Progress};
use super::refine::Verified;
use super::verify::Verification;
use super::{Planner, settings};
use crate::optim::{AlOptions, AlStatus, augmented_lagrangian_observed};

/// Deterministic pseudo-random numbers in `[-1, 1]` (xorshift64*).
pub(super) fn noise(seed: u64, n: usize) -> Vec<f64> {
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
}

impl Planner {
    /// The multiplier-method settings of each sharpness stage (the penalty restarts at 1e2).
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
        }
    }

    /// Optimises from `z0` on the samples `ks`, from sharpness stage `first_stage` on, telling
    /// `sink` each outer iteration's progress and worst sampled shape as it happens.
    pub(super) fn optimise_from(
        &self,
        start: usize,
        z0: Vec<f64>,
        ks: &[f64],
        first_stage: usize,
        sink: &mut dyn FnMut(Progress, Vec<f64>),
    ) -> StartRun {
        let mut p = self.minimax_problem_at(ks.to_vec());
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
            evaluations: 0,
        };
        let al = self.stage_options();
        let mut z = z0;
        for (stage, &b) in self.settings.sharpness.iter().enumerate().skip(first_stage) {
            p.beta = b / u_ref;
            let out = {
                let sink = &mut *sink;
                let ks = p.ks.clone();
                let mw = p.mean_weight;
                // `q` is the problem evaluated at the iterate: its sampled energies and shapes
                // are the iterate's.
                augmented_lagrangian_observed(
                    &mut p,
                    &mut z,
                    tally.lambda.as_deref(),
                    al,
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
            if tally.absorb(out) || self.stopped() {
                break;
            }
        }
        // Equilibrium tracking: pull every sampled shape onto the equilibrium its end pose
        // produces (see the README for why the paper's objective alone does not).
        let (tracking_rounds, tracking_rounds_kept, equilibrium_deviation) = if !matches!(
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
        }
    }

    /// Optimises from each of `starts` (start index and perturbation of the straight-line path)
    /// on the samples `uniform`, then verifies and refines each plan with `check`
    /// ([`Planner::refine`]), on parallel threads when there are several starts, telling
    /// `observer` their progress as it happens.
    pub(super) fn optimise_starts(
        &self,
        starts: &[(usize, Vec<f64>)],
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
            let (i, z0) = starts[0].clone();
            let run = self.optimise_from(i, z0, uniform, 0, &mut sink);
            vec![self.refine(i, run, uniform, check, &mut sink)]
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
                                    let (i, z0) = starts[j].clone();
                                    let run = self.optimise_from(i, z0, uniform, 0, &mut sink);
                                    (j, self.refine(i, run, uniform, check, &mut sink))
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
