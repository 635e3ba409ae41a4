//! The end's course optimised in its own pose space: where the plan is the equilibria along
//! a course of the controlled end — the optimal path's end poses (seeded by the
//! coefficient-space plan, paper §7), the straight-line path's, or a pose line — its positions
//! are moved by polynomial terms that lower the peak energy of the equilibria the gripper
//! passes through.
//!
//! The course's position gets `Σ_m c_m k^(m+1) (1 − k)` (`m = 0, 1`, each `c_m` a vector in
//! the layout's position components; units of L): zero at both ends, as the paper's path
//! terms are (§7.1); its frame stays the course's. Every shape along it is the equilibrium its
//! end pose produces, marched from the start along `k` as the replay does, so the plan
//! coincides with its replay by construction. The objective is a smoothed maximum
//! (log-sum-exp) of those equilibria's energies `U_j`, plus a small tie-breaking term on how
//! far the end's velocity leaves the course's, `w ∫ |Σ c_m b_m'(k)|² dk` (`w` a hundredth of
//! the course's own peak energy per L²), which keeps the gripper on the shorter of routes of
//! nearly equal peak.
//!
//! Its gradient needs no sensitivity of the shapes: by the envelope theorem the derivative of
//! an equilibrium's energy with respect to the prescribed end position is minus the multipliers
//! of the position rows (`ℒ = U + Σ λ c`, `c = x(L) − p`): the force the gripper exerts on the
//! rod. Obstacle contacts stay in every solve; where they are active their multipliers take
//! part in the equilibrium, and the envelope theorem holds as long as the contact set does not
//! change. A step whose solve does not converge, or whose shape jumps (as a snap-through in
//! the replay: farther than three times the reference path's shapes move, and 0.02 L), is
//! bisected as the replay's are; where that does not mend it the objective is infinite, and
//! the line search backs off.
//!
//! BFGS minimises it in two stages (the maximum's sharpness 30, then 300, over the course's
//! own peak), over at most 40 marches; a course that already peaks at an end shape (the lower
//! bound on every path's peak) is left as it is, and so is one whose peak the optimisation
//! lowers by less than 1 %. The optimised course — or, where its equilibria are no
//! plan, the course half-way to it — is then judged as the course itself was (the replay with
//! its bisections, the confirmation on twice the steps, stability, clearance on the
//! verification grid), and it replaces the course only where it passes and peaks lower.

use super::Planner;
use super::end_course::EndCourse;
use super::judge::Judged;
use super::observer::PlanObserver;
use super::path::DeformationPath;
use super::replay::{EarlyStop, max_distance, solve_held};
use super::settings::PoseOptimisation;
use crate::optim::bfgs::{BfgsOptions, bfgs};
use crate::rod::kinematics::Shape;
use crate::statics::problem::StaticProblem;
use crate::statics::{SolveStatus, StaticOptions, StaticSolution};
use std::sync::Arc;

/// Position terms optimised (`k (1 − k)` and `k² (1 − k)`).
pub const TERMS: usize = 2;

/// Sharpness of the smoothed maximum in its two stages, over the peak energy of the course as
/// it is: the log-sum-exp over `n` samples exceeds the maximum by at most `ln n / β`.
const SHARPNESS: [f64; 2] = [30.0, 300.0];

/// The tie-breaking weight on the end's velocity off the course, times the peak energy of the
/// course as it is (per L²).
const TRAVEL_WEIGHT: f64 = 0.01;

/// BFGS iterations per stage.
const ITERATIONS: usize = 8;

/// Marches at most, over both stages.
const MARCHES: usize = 40;

/// The least fraction of the course's own peak the optimised course must lower it by to be
/// judged: a route changed for less is not worth its judgement.
const LEAST_GAIN: f64 = 0.01;

/// The equilibria along a course and the derivatives of their energies.
#[derive(Clone, Debug)]
pub struct March {
    /// Path parameters, from 0 to 1.
    pub ks: Vec<f64>,
    /// Energy of each equilibrium (dimensionless, `Rf/L`; the case's objective).
    pub energies: Vec<f64>,
    /// Derivative of each energy with respect to the end's position (dimensionless, per L):
    /// minus the multipliers of the end's position rows; zero in components not prescribed.
    pub gradients: Vec<[f64; 3]>,
}

/// The equilibria of `base` with the end at `course`'s poses from `k = 0` to 1 in `steps`
/// uniform steps, each solved from the one before (the first from `start`), with the
/// derivatives of their energies ([`March`]). A step whose solve does not converge or whose
/// shape jumps farther than three times the reference shapes `reference(z)` move between the
/// same `k` (and 0.02 L) is bisected, up to `refinements` times, as the replay's are; `None`
/// where that does not mend it.
pub fn march(
    base: &StaticProblem,
    start: &StaticSolution,
    course: &EndCourse,
    reference: (&DeformationPath, &[f64]),
    (steps, refinements): (usize, usize),
    opts: &StaticOptions,
) -> Option<March> {
    let model = &base.model;
    let (path, z) = reference;
    let mut a = vec![0.0; path.n()];
    let mut shape = Shape::default();
    let mut reference_at = |k: f64| {
        path.shape_at(z, k, &mut a);
        model.evaluate_into(&a, &mut shape);
        shape.positions.clone()
    };
    let row = base.constraints.len();
    let solve = |k: f64, from: &StaticSolution| {
        let pose = course.end_pose(model, k);
        let (p, sol) = solve_held(base, from, &pose, opts, true);
        let mut g = [0.0; 3];
        for (r, &(c, _)) in p.rows_of(row).zip(&pose.position) {
            g[c] = -sol.lambda[r];
        }
        let positions = model.evaluate(&sol.a).positions;
        (sol, positions, g)
    };
    let mut out = March {
        ks: Vec::new(),
        energies: Vec::new(),
        gradients: Vec::new(),
    };
    let mut record = |k: f64, sol: &StaticSolution, g: [f64; 3]| {
        out.ks.push(k);
        out.energies.push(sol.energy_scaled.value(base.objective));
        out.gradients.push(g);
    };
    let (mut sol, mut positions, g) = solve(0.0, start);
    if sol.status != SolveStatus::Converged {
        return None;
    }
    record(0.0, &sol, g);
    let mut k_now = 0.0;
    for i in 1..=steps {
        let mut pending = vec![(i as f64 / steps as f64, 0usize)];
        while let Some((k, depth)) = pending.pop() {
            let (next, next_positions, g) = solve(k, &sol);
            let moved = max_distance(&reference_at(k), &reference_at(k_now));
            let jumped = max_distance(&next_positions, &positions) > (3.0 * moved).max(0.02);
            if jumped || next.status != SolveStatus::Converged {
                if depth < refinements {
                    pending.push((k, depth + 1));
                    pending.push((0.5 * (k_now + k), depth + 1));
                    continue;
                }
                return None;
            }
            record(k, &next, g);
            (sol, positions, k_now) = (next, next_positions, k);
        }
    }
    Some(out)
}

/// `∫₀¹ b_m'(k) b_n'(k) dk` for `b_m = k^(m+1) (1 − k)`.
fn gram(m: usize, n: usize) -> f64 {
    let (p, q) = ((m + 1) as f64, (n + 1) as f64);
    let s = p + q;
    p * q / (s - 1.0) - (p * (q + 1.0) + (p + 1.0) * q) / s + (p + 1.0) * (q + 1.0) / (s + 1.0)
}

/// The smoothed maximum `max + ln Σ exp(β (U_j − max)) / β` of `u`, and its weights
/// `∂/∂U_j` (summing to 1).
fn smooth_max(u: &[f64], beta: f64) -> (f64, Vec<f64>) {
    let top = u.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let e: Vec<f64> = u.iter().map(|&v| (beta * (v - top)).exp()).collect();
    let sum: f64 = e.iter().sum();
    (
        top + sum.ln() / beta,
        e.into_iter().map(|v| v / sum).collect(),
    )
}

/// The objective of the optimisation (see the module documentation) and its gradient with
/// respect to the terms, flattened as `x[m · comps.len() + i]` for component `comps[i]`.
pub struct Objective<'a> {
    /// The course without terms.
    pub course: &'a EndCourse,
    /// The position components optimised.
    pub comps: Vec<usize>,
    /// Sharpness of the smoothed maximum (per unit of dimensionless energy).
    pub beta: f64,
    /// Weight of the travel term (dimensionless energy per L²).
    pub weight: f64,
}

impl Objective<'_> {
    /// The course with terms `x`.
    pub fn course_at(&self, x: &[f64]) -> EndCourse {
        let n = self.comps.len();
        let terms = (0..TERMS)
            .map(|m| {
                let mut t = [0.0; 3];
                for (i, &c) in self.comps.iter().enumerate() {
                    t[c] = x[m * n + i];
                }
                t
            })
            .collect();
        self.course.with_terms(terms)
    }

    /// The objective at `x` given the march along [`Self::course_at`]`(x)`, with its gradient
    /// in `g`.
    pub fn value(&self, x: &[f64], march: &March, g: &mut [f64]) -> f64 {
        let n = self.comps.len();
        let (f, w) = smooth_max(&march.energies, self.beta);
        g.iter_mut().for_each(|v| *v = 0.0);
        for ((&k, gj), wj) in march.ks.iter().zip(&march.gradients).zip(&w) {
            let mut b = 1.0 - k;
            for m in 0..TERMS {
                b *= k;
                for (i, &c) in self.comps.iter().enumerate() {
                    g[m * n + i] += wj * gj[c] * b;
                }
            }
        }
        let mut travel = 0.0;
        for m in 0..TERMS {
            for q in 0..TERMS {
                let gmq = gram(m, q);
                for i in 0..n {
                    travel += gmq * x[m * n + i] * x[q * n + i];
                    g[m * n + i] += 2.0 * self.weight * gmq * x[q * n + i];
                }
            }
        }
        f + self.weight * travel
    }
}

impl Planner {
    /// The terms on `course` (without terms of its own) that lower the peak energy of the
    /// equilibria along it (see the module documentation), the replay's jumps measured against
    /// the shapes of `reference`; `None` where the march along the course itself fails, the
    /// run is stopped, or nothing lowers the peak by [`LEAST_GAIN`] of it.
    pub(super) fn optimise_course(
        &self,
        course: &EndCourse,
        reference: (&DeformationPath, &[f64]),
    ) -> Option<EndCourse> {
        let model = &self.base.model;
        let steps = (self.settings.replay_steps, self.settings.replay_refinements);
        let opts = StaticOptions {
            stability: false,
            balance: false,
            ..self.static_options
        };
        let run = |c: &EndCourse| march(&self.held, &self.start, c, reference, steps, &opts);
        let first = run(course)?;
        let peak = |m: &March| m.energies.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        // Every course passes through both end shapes: the larger end energy bounds the peak.
        let bound = first.energies[0].max(*first.energies.last()?);
        let at_bound = |u: f64| u <= bound + 1e-9 * bound.abs().max(1e-9);
        if at_bound(peak(&first)) {
            return None;
        }
        let scale = peak(&first).abs().max(1e-9);
        let comps = model.layout.components().to_vec();
        let mut x = vec![0.0; TERMS * comps.len()];
        let mut marches = 1;
        let mut best: (f64, Vec<f64>) = (peak(&first), x.clone());
        let mut objective = Objective {
            course,
            comps,
            beta: 1.0,
            weight: TRAVEL_WEIGHT * scale,
        };
        for rel in SHARPNESS {
            if at_bound(best.0) {
                break;
            }
            objective.beta = rel / scale;
            let mut h = Vec::new();
            bfgs(
                |x, g| {
                    // At the bound nothing is lower: the line search backs off to it.
                    if at_bound(best.0) || marches >= MARCHES || self.stopped() || self.time_up() {
                        return f64::INFINITY;
                    }
                    marches += 1;
                    match run(&objective.course_at(x)) {
                        Some(m) => {
                            if peak(&m) < best.0 {
                                best = (peak(&m), x.to_vec());
                            }
                            objective.value(x, &m, g)
                        }
                        None => f64::INFINITY,
                    }
                },
                &mut x,
                &mut h,
                BfgsOptions {
                    grad_tol: 1e-6,
                    max_iter: ITERATIONS,
                    f_rel_tol: 1e-4,
                },
            );
        }
        (best.0 < peak(&first) - LEAST_GAIN * scale).then(|| objective.course_at(&best.1))
    }

    /// The equilibria along `course` judged as a plan on the verification model `fine` (as
    /// [`Self::judge_path`] judges a path's, compared with the shapes of `reference`), their
    /// replays ending at the first failure.
    pub(super) fn judge_driven(
        &self,
        course: &Arc<EndCourse>,
        reference: (&DeformationPath, &[f64]),
        fine: &crate::rod::model::Model,
        observer: &mut dyn PlanObserver,
    ) -> Judged {
        let driven = Planner {
            drive: Some(course.clone()),
            ..self.clone()
        };
        let (path, z) = reference;
        driven.judge_path(path, z, false, EarlyStop::Failure, fine, observer)
    }

    /// [`Self::judge_driven`], on twice the contact samples where the equilibria still dip
    /// ([`Self::with_finer_if_dipping`]).
    pub(super) fn judge_course(
        &self,
        course: &Arc<EndCourse>,
        reference: (&DeformationPath, &[f64]),
        fine: &crate::rod::model::Model,
        observer: &mut dyn PlanObserver,
    ) -> Judged {
        self.with_finer_if_dipping(|pl| pl.judge_driven(course, reference, fine, observer))
    }

    /// The equilibria along the straight-line path's end poses (`line` `None`) or along a pose
    /// line, judged (on twice the contact samples where they still dip) and, where they are a
    /// plan, their course optimised in the end's pose space ([`Self::optimised_plan`]).
    pub(super) fn judge_other_course(
        &self,
        line: Option<&Arc<super::pose_line::PoseLine>>,
        fine: &crate::rod::model::Model,
        observer: &mut dyn PlanObserver,
    ) -> Judged {
        let found = self.with_finer_if_dipping(|pl| match line {
            None => pl.judge_straight_trajectory(fine, observer),
            Some(l) => pl.judge_pose_line(l, fine, observer),
        });
        if !found.executable {
            return found;
        }
        let straight = self.path();
        let zero = vec![0.0; straight.n_vars()];
        let course = match line {
            Some(l) => EndCourse::line((**l).clone()),
            None => EndCourse::path(straight.clone(), zero.clone()),
        };
        self.optimised_plan(course, (&straight, &zero), found, fine, observer)
    }

    /// The plan `found` (executable: the equilibria along `course`, whose replay is compared
    /// with the shapes of `reference`) or, where the optimised terms on `course`
    /// ([`Self::optimise_course`]) give a course whose equilibria are a plan too, with a lower
    /// peak energy, that one, reported on the same trajectory.
    pub(super) fn optimised_plan(
        &self,
        course: EndCourse,
        reference: (&DeformationPath, &[f64]),
        found: Judged,
        fine: &crate::rod::model::Model,
        observer: &mut dyn PlanObserver,
    ) -> Judged {
        let Some(e) = found.equilibrium_plan.as_ref().filter(|_| found.executable) else {
            return found;
        };
        // The larger energy of the replayed equilibria at the ends (the goal's, or another
        // equilibrium of the goal pose the course reached): no course peaks lower.
        let steps = &found.replay.steps;
        let Some(bound) = steps
            .first()
            .zip(steps.last())
            .map(|(a, b)| a.u_feasible.max(b.u_feasible))
        else {
            return found;
        };
        let wanted = match self.settings.pose_optimisation {
            PoseOptimisation::Off => false,
            PoseOptimisation::Fallback => e.trajectory != "optimal_path",
            PoseOptimisation::All => true,
        };
        if !wanted || e.u_max <= bound + 1e-9 * bound.abs() || self.stopped() || self.time_up() {
            return found;
        }
        let (before, trajectory) = (e.u_max, e.trajectory);
        let Some(optimised) = self.optimise_course(&course, reference) else {
            return found;
        };
        // The optimised course, and where its equilibria are no plan (most often: they press
        // the rod into an obstacle between contact points), the course half-way to it.
        let half: Vec<[f64; 3]> = optimised
            .terms()
            .iter()
            .map(|t| t.map(|v| 0.5 * v))
            .collect();
        let mut optimised = Arc::new(optimised);
        let mut judged = self.judge_course(&optimised, reference, fine, observer);
        if !judged.executable && !self.stopped() {
            optimised = Arc::new(optimised.with_terms(half));
            judged = self.judge_course(&optimised, reference, fine, observer);
        }
        let after = judged
            .equilibrium_plan
            .as_ref()
            .map_or(f64::NAN, |e| e.u_max);
        if !(judged.executable && after < before) {
            return found;
        }
        if let Some(e) = judged.equilibrium_plan.as_mut() {
            let l = self.base.model.rod.length;
            e.set_trajectory(trajectory, optimised.detour());
            e.pose_terms = Some(optimised.terms().iter().map(|t| t.map(|v| v * l)).collect());
            e.course_u_max = Some(before);
        }
        judged
    }
}

#[cfg(test)]
mod tests {
    use super::{Objective, TERMS, gram, march, smooth_max};
    use crate::planner::Planner;
    use crate::planner::pose_line::Detour;
    use crate::statics::StaticOptions;

    /// A heavy 3D cable resting on a table beside a cup (the suite's table family, seed 1,
    /// problem 4), its end to be dragged across the table.
    fn table_planner() -> Planner {
        let text = r#"{"name": "table_4", "planar": false,
  "rod": {"length": 1.0, "flexural_rigidity": 1.0, "torsional_rigidity": 0.77, "radius": 0.01,
          "weight_per_length": 14.10848753721109},
  "constraints": [{"type": "orientation", "s": 0.0, "theta": 0.0, "phi_plus_psi": 0.0}],
  "obstacles": [
    {"name": "table", "shape": {"type": "half_space", "normal": [1, 0, 0]},
     "position": [-0.11367399962918348, 0, 0]},
    {"name": "cup", "shape": {"type": "cylinder", "half_height": 0.05869232718920485,
     "radius": 0.05161221491319204},
     "position": [-0.05498167243997863, -0.04401287551860211, 0.4112301893153343],
     "rotation": [0, 0, 1.5707963267948966]}],
  "plan": {
    "start": {"position": [-0.052512829796954756, 0.1800041413617223, 0.5566007326170828],
              "tangent": [0, -0.4599895088953481, 0.887924350215837],
              "twist": 0.3233355831249656},
    "goal": {"position": [-0.04147622631718284, -0.29140591959149353, 0.6647061078326625],
             "tangent": [0, 0.45528121787434134, 0.8903476920006343],
             "twist": 0.12398661430536839}}}"#;
        let case = crate::case::parse(text, std::path::Path::new("table_4.json")).expect("a case");
        Planner::from_case(&case).expect("static ends")
    }

    /// The envelope theorem on a heavy cable that rests on a table: along a line lifted 0.5 L
    /// with terms off zero, the derivative of every marched equilibrium's energy with respect
    /// to each term (minus the end's position multipliers, times the term's `k^(m+1) (1 − k)`)
    /// matches central differences of the marched energies (step 1e-3 L) to 1e-4 of the
    /// largest derivative (they agree to about 1e-5, the static solves' tolerance), and so does the objective's gradient (the smoothed maximum and the
    /// travel term). The start shape presses on the table: the contact rows take part.
    #[test]
    fn the_energy_gradient_along_a_pose_line_is_the_end_force() {
        let p = table_planner();
        let pressed = p.held.constraints.iter().enumerate().any(|(i, c)| {
            matches!(c, crate::constraints::Constraint::Obstacle(_))
                && p.start.lambda[p.held.rows_of(i)].iter().any(|&l| l > 1e-3)
        });
        assert!(pressed, "the start shape rests on an obstacle");
        let line = p
            .pose_line(Detour {
                lift: 0.5,
                side: 0.0,
            })
            .expect("a line");
        let path = p.path();
        let z = vec![0.0; path.n_vars()];
        let opts = StaticOptions {
            stability: false,
            balance: false,
            ..p.static_options
        };
        let steps = (p.settings.replay_steps, p.settings.replay_refinements);
        let comps = p.base.model.layout.components().to_vec();
        let n = comps.len();
        assert_eq!(n, 3);
        let x = [0.01, 0.005, 0.01, 0.005, -0.005, 0.005];
        let course = crate::planner::end_course::EndCourse::line(line);
        let objective = Objective {
            course: &course,
            comps,
            beta: 3.0,
            weight: 0.2,
        };
        let run = |x: &[f64]| {
            march(
                &p.held,
                &p.start,
                &objective.course_at(x),
                (&path, &z),
                steps,
                &opts,
            )
            .expect("the march converges without a jump")
        };
        let at = run(&x);
        let mut g = vec![0.0; x.len()];
        objective.value(&x, &at, &mut g);
        let h = 1e-3;
        for v in 0..x.len() {
            let (m, c) = (v / n, objective.comps[v % n]);
            let shifted = |d: f64| {
                let mut y = x.to_vec();
                y[v] += d;
                let mut gy = vec![0.0; x.len()];
                let marched = run(&y);
                let f = objective.value(&y, &marched, &mut gy);
                (marched, f)
            };
            let ((up, fu), (dn, fd)) = (shifted(h), shifted(-h));
            assert_eq!(up.ks, at.ks);
            assert_eq!(dn.ks, at.ks);
            let analytic: Vec<f64> = at
                .ks
                .iter()
                .zip(&at.gradients)
                .map(|(&k, gj)| gj[c] * k.powi(m as i32 + 1) * (1.0 - k))
                .collect();
            let scale = analytic.iter().fold(1e-3_f64, |s, a| s.max(a.abs()));
            for (j, a) in analytic.iter().enumerate() {
                let fdj = (up.energies[j] - dn.energies[j]) / (2.0 * h);
                assert!(
                    (fdj - a).abs() <= 1e-4 * scale,
                    "term {m}, component {c}, k = {}: {fdj} against {a}",
                    at.ks[j]
                );
            }
            let fdf = (fu - fd) / (2.0 * h);
            assert!(
                (fdf - g[v]).abs() <= 1e-4 * g[v].abs().max(scale),
                "objective, term {m}, component {c}: {fdf} against {}",
                g[v]
            );
        }
        assert_eq!(TERMS, 2);
    }

    /// The Gram entries against a midpoint sum of `b_m' b_n'` on 20,000 intervals.
    #[test]
    fn the_gram_entries_are_the_integrals_of_the_derivatives() {
        let db = |m: usize, k: f64| {
            let p = (m + 1) as i32;
            p as f64 * k.powi(p - 1) - (p + 1) as f64 * k.powi(p)
        };
        let n = 20_000;
        for m in 0..3 {
            for q in 0..3 {
                let sum: f64 = (0..n)
                    .map(|i| {
                        let k = (i as f64 + 0.5) / n as f64;
                        db(m, k) * db(q, k)
                    })
                    .sum::<f64>()
                    / n as f64;
                assert!(
                    (sum - gram(m, q)).abs() < 1e-8,
                    "{m} {q}: {sum} {}",
                    gram(m, q)
                );
            }
        }
        assert!((gram(0, 0) - 1.0 / 3.0).abs() < 1e-15);
    }

    /// The smoothed maximum lies between the maximum and the maximum plus `ln n / β`, and its
    /// weights are its derivatives (central differences, step 1e-6).
    #[test]
    fn the_smoothed_maximum_bounds_the_maximum_and_its_weights_are_its_gradient() {
        let u = [1.0, 3.0, 2.9, -4.0, 2.99];
        for beta in [1.0, 10.0, 100.0] {
            let (f, w) = smooth_max(&u, beta);
            assert!(f >= 3.0 && f <= 3.0 + (u.len() as f64).ln() / beta);
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-14);
            for j in 0..u.len() {
                let h = 1e-6;
                let mut up = u;
                up[j] += h;
                let mut dn = u;
                dn[j] -= h;
                let fd = (smooth_max(&up, beta).0 - smooth_max(&dn, beta).0) / (2.0 * h);
                assert!((fd - w[j]).abs() < 1e-8, "β {beta}, j {j}: {fd} {}", w[j]);
            }
        }
    }
}
