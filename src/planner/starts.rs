//! Which starts run: groups of `parallel_starts` starts side by side, first with the case's path
//! terms and then with each of `fallback_path_terms`, until a start's plan is collision-free,
//! feasible on its samples and estimated to coincide with its replay; and which of the plans is
//! the plan.

use super::Planner;
use super::observer::PlanObserver;
use super::optimise::noise;
use super::refine::Verified;
use super::verify::{Verification, verify_with};
use crate::planner::path::DeformationPath;
use crate::rod::model::Model;
use std::borrow::Cow;

/// One start's verified plan and the path-term count it was planned with.
#[derive(Clone)]
pub(super) struct StartPlan {
    /// Index among the starts: the case's own starts first (`0..starts`), then each fallback
    /// count's (`starts..2·starts`, …).
    pub(super) index: usize,
    /// Path terms of its path.
    pub(super) terms: usize,
    /// The plan, verified and refined.
    pub(super) plan: Verified,
}

impl Planner {
    /// The planner with `terms` path terms and the same settings otherwise: its
    /// [`Planner::path`] is the path of a plan whose `path_terms` is `terms`.
    pub fn with_terms(&self, terms: usize) -> Planner {
        let mut p = self.clone();
        p.settings.path_terms = terms;
        p
    }

    /// The path `z` of `path` on the verification grid of the quadrature `fine`.
    pub(super) fn verify_on(
        &self,
        fine: &Model,
        path: &DeformationPath,
        z: &[f64],
    ) -> Verification {
        verify_with(
            fine,
            path,
            z,
            self.settings.verify_k_samples,
            &self.obstacles,
            self.base.objective,
            self.has_self_contact(),
        )
    }

    /// Whether plan `r` is collision-free ([`Planner::collision_tolerance`]), feasible on its
    /// samples, and estimated to coincide with its replay: the order in which plans are
    /// preferred, before `U_max`.
    pub(super) fn class(&self, r: &Verified) -> (bool, bool, bool) {
        (
            r.verification.collision_free(self.collision_tolerance()),
            r.run.violation <= 1e-6,
            r.run
                .equilibrium_deviation
                .is_some_and(|d| d <= self.settings.coincide_tolerance),
        )
    }

    /// Runs the starts in groups and the fallback path-term counts (see the module's doc),
    /// verifying each plan on `fine`.
    pub(super) fn run_starts(
        &self,
        fine: &Model,
        observer: &mut dyn PlanObserver,
    ) -> Vec<StartPlan> {
        let nk = self.settings.k_samples;
        let uniform: Vec<f64> = (0..nk).map(|j| j as f64 / (nk - 1) as f64).collect();
        let starts = self.settings.starts;
        let mut runs: Vec<StartPlan> = Vec::new();
        // The case's planner, then one per fallback count, made only when it is reached.
        let fallbacks = self.settings.fallback_path_terms.iter();
        let attempts = std::iter::once(Cow::Borrowed(self))
            .chain(fallbacks.map(|&t| Cow::Owned(self.with_terms(t))));
        'attempts: for (attempt, pl) in attempts.enumerate() {
            let path = pl.path();
            let nv = path.n_vars();
            let check = |z: &[f64]| self.verify_on(fine, &path, z);
            // Start s: the straight-line path plus a perturbation of seed `seed + s`, 0.01 rad
            // for the first, `start_spread` for the others.
            let zs: Vec<(usize, Vec<f64>)> = (0..starts)
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
                    (attempt * starts + s, z0)
                })
                .collect();
            for group in zs.chunks(self.settings.parallel_starts()) {
                let done = pl.optimise_starts(group, &uniform, &check, observer);
                runs.extend(group.iter().zip(done).map(|((index, _), plan)| StartPlan {
                    index: *index,
                    terms: pl.settings.path_terms,
                    plan,
                }));
                // Checked before the next group, and before the next fallback planner is made.
                if self.stopped() {
                    break 'attempts;
                }
                if runs
                    .iter()
                    .any(|r| self.class(&r.plan) == (true, true, true))
                {
                    break 'attempts;
                }
            }
        }
        runs
    }
}
