//! Equilibrium tracking: after the sharpness stages, the planner replays its own samples (the
//! equilibria their end poses produce) and pulls each sampled shape onto that equilibrium by a
//! term in the objective, re-optimising, round after round while it helps (docs/algorithms.md,
//! step 4). Each target follows its sample's end pose through the equilibrium's slopes
//! (`equilibrium_slopes.rs`), unless `equilibrium_slopes` is off.

use super::endpoints::EndPose;
use super::equilibrium_slopes::Slope;
use super::minimax::MinimaxProblem;
use super::start::Tally;
use super::{Planner, replay};
use crate::constraints::Constraint;
use crate::optim::{AlOptions, augmented_lagrangian_observed};

/// Equilibrium tracking ends after a round that brings the sampled shapes less than this
/// fraction closer to their equilibria.
const TRACK_PROGRESS: f64 = 0.1;

/// Equilibrium tracking does not start when the sampled shapes lie farther than this (units of
/// L) from their equilibria: those equilibria are on another branch than the path's shapes (the
/// march along the samples has snapped through, or the route passes where no equilibrium
/// holds), and pulling the path towards them crawls (the pull fights the obstacle rows at
/// penalties up to the cap) and seldom brings the shapes near (docs/notes/speed-alternatives.md).
pub(super) const TRACK_FAR: f64 = 0.25;

impl Planner {
    /// Runs the equilibrium-tracking rounds on `p` from the path `z` (the sharpness stages'
    /// result), with the stages' multiplier-method settings `al`; returns how many rounds ran,
    /// how many of them the path keeps, and the kept path's samples' largest distance to their
    /// equilibria (units of L; `None` when it was not measured: no tracking, or a numerical
    /// failure).
    pub(super) fn track(
        &self,
        p: &mut MinimaxProblem,
        z: &mut [f64],
        tally: &mut Tally,
        al: AlOptions,
    ) -> (usize, usize, Option<f64>) {
        if self
            .settings
            .tracking_weight(self.base.model.layout.spatial)
            <= 0.0
        {
            return (0, 0, None);
        }
        let mut estimate = None;
        let mut failed = false;
        let mut tracking_rounds = 0;
        let mut kept = 0;
        p.track_weight = self
            .settings
            .tracking_weight(self.base.model.layout.spatial);
        // Targets keep the optimiser's safety margin from obstacles.
        let mut inflated = self.base.clone();
        for con in inflated.constraints.iter_mut() {
            if let Constraint::Obstacle(ob) = con {
                *ob = super::optimiser_obstacle(ob, self.safety());
            }
        }
        // Rounds stop early when the sampled shapes already lie within `equilibrium_stop` of
        // the coincidence tolerance from their equilibria, or when a round brought them less
        // than `TRACK_PROGRESS` closer (the route is then as executable as tracking makes it);
        // none run when the shapes start farther than `TRACK_FAR` from them.
        let spatial = self.base.model.layout.spatial;
        let done = self.settings.tracking_stop(spatial) * self.settings.coincide_tolerance;
        let mut dev_prev = f64::INFINITY;
        // The path before the last round, with its tally: a round that leaves the samples
        // farther from their equilibria is undone.
        let mut before: Option<(Vec<f64>, Tally)> = None;
        // The equilibria the samples' end poses produce: the first round's replayed along the
        // samples, each later round's along stretches of them side by side, each stretch
        // started from the round before's equilibrium at its first `k` (the path has moved a
        // little), shared out over the optimiser's threads.
        let mut solved: Option<Vec<crate::statics::StaticSolution>> = None;
        let equilibria = |p: &MinimaxProblem, z: &[f64], solved: &mut Option<Vec<_>>| {
            let found = match solved {
                None => replay::equilibria(
                    &inflated,
                    &self.start,
                    &p.path,
                    z,
                    &p.ks,
                    &self.static_options,
                ),
                Some(from) => replay::equilibria_from(
                    &inflated,
                    &self.start,
                    from,
                    &p.path,
                    z,
                    &p.ks,
                    &self.static_options,
                    p.workers(),
                ),
            };
            let (positions, sols): (Vec<_>, Vec<_>) = found.into_iter().unzip();
            *solved = Some(sols);
            positions
        };
        for _ in 0..self.settings.equilibrium_rounds {
            if self.stopped() || self.over_budget(tally.evaluations) || self.time_up() {
                break;
            }
            let targets = equilibria(p, z, &mut solved);
            let moved = p.targets.as_ref().map_or(f64::INFINITY, |old| {
                old.iter()
                    .zip(&targets)
                    .flat_map(|(a, b)| a.iter().zip(b))
                    .map(|(u, v)| (0..3).map(|i| (u[i] - v[i]).abs()).fold(0.0, f64::max))
                    .fold(0.0, f64::max)
            });
            // The replay's deviation, estimated on the samples.
            let dev = p.distance_to(z, &targets);
            if dev > dev_prev
                && let Some((z_prev, tally_prev)) = before.take()
            {
                z.copy_from_slice(&z_prev);
                let evaluations = tally.evaluations;
                *tally = Tally {
                    evaluations,
                    ..tally_prev
                };
                kept = tracking_rounds - 1;
                estimate = Some(dev_prev);
                break;
            }
            // Equilibria on another branch: not tracked.
            if tracking_rounds == 0 && dev > TRACK_FAR {
                estimate = Some(dev);
                break;
            }
            p.targets = Some(targets);
            p.slopes = solved
                .as_deref()
                .filter(|_| self.settings.equilibrium_slopes)
                .map(|sols| slopes_of(&inflated, p, z, sols));
            // Targets that no longer move: the path already sits on its equilibria.
            if moved < 1e-4 || dev <= done || dev > (1.0 - TRACK_PROGRESS) * dev_prev {
                estimate = Some(dev);
                break;
            }
            dev_prev = dev;
            tracking_rounds += 1;
            kept = tracking_rounds;
            before = Some((z.to_vec(), tally.clone()));
            // Newton steps here in either mode: the sharpness stages have chosen the route,
            // and tracking only pulls its shapes onto their equilibria.
            let al_t = AlOptions {
                second_order: true,
                ..al
            };
            let out =
                augmented_lagrangian_observed(p, z, tally.lambda.as_deref(), al_t, &mut |_, _| {
                    !self.stopped()
                });
            if tally.absorb(out) {
                failed = true;
                break;
            }
        }
        // The rounds' budget spent (or none allowed): measure the kept path's samples once
        // more, so that the estimate is there for choosing among starts.
        if estimate.is_none() && !failed {
            let targets = equilibria(p, z, &mut solved);
            estimate = Some(p.distance_to(z, &targets));
        }
        (tracking_rounds, kept, estimate)
    }
}

/// The slopes of the equilibria `sols` of the samples of `p`'s path `z` (solved under `base`)
/// with respect to their end poses; `None` for an equilibrium that did not converge.
fn slopes_of(
    base: &crate::statics::problem::StaticProblem,
    p: &MinimaxProblem,
    z: &[f64],
    sols: &[crate::statics::StaticSolution],
) -> Vec<Option<Slope>> {
    let model = &base.model;
    let mut a = vec![0.0; p.path.n()];
    p.ks.iter()
        .zip(sols)
        .map(|(&k, sol)| {
            if sol.status != crate::statics::SolveStatus::Converged {
                return None;
            }
            p.path.shape_at(z, k, &mut a);
            let shape = model.evaluate(&a);
            let pose = EndPose::of(model, &a, &shape.positions);
            Slope::of(base, &pose, sol)
        })
        .collect()
}
