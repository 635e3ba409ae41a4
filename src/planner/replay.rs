//! Feasibility replay (paper §7.2): drive the rod by the optimal path's controlled end pose
//! alone, solving the static shape at each `k` warm-started from the previous one, and compare
//! the result with the optimal path.
//!
//! Where consecutive replayed shapes jump much more than the optimal path moves, or a solve
//! from a converged shape does not converge, the step is bisected (up to a limit): a shorter
//! step starts the solve nearer its answer. A jump that survives every bisection is a
//! snap-through: the end pose alone cannot follow the path there.

use super::end_course::EndCourse;
use super::endpoints::EndPose;
use super::observer::{PathKind, PlanObserver, ShapeRecord};
use crate::planner::path::DeformationPath;
use crate::planner::workers::{JOB_EQUILIBRIA, Workers};
use crate::rod::kinematics::Shape;
use crate::statics::problem::StaticProblem;
use crate::statics::{SolveStatus, StaticOptions, StaticSolution, solve_static_warm};
use serde::Serialize;
use std::sync::atomic::AtomicBool;

/// One replayed shape.
#[derive(Clone, Debug, Serialize)]
pub struct ReplayStep {
    /// Path parameter.
    pub k: f64,
    /// `d(k) = max_s |x_opt(s,k) − x_feas(s,k)|` (case units).
    pub deviation: f64,
    /// Energy of the optimal path's shape (case units).
    pub u_optimal: f64,
    /// Energy of the replayed shape (case units).
    pub u_feasible: f64,
    /// The static solve converged.
    pub converged: bool,
    /// Solver status of the static solve.
    pub status: SolveStatus,
    /// Its KKT residual (dimensionless).
    pub kkt_residual: f64,
    /// Stability of the replayed shape.
    pub stable: Option<bool>,
    /// Neutral modes of its stability check (see [`crate::statics::StaticSolution`]).
    pub neutral_modes: Option<usize>,
    /// Constraint violation of the solve (dimensionless).
    pub violation: f64,
    /// Smallest surface gap `d − r` of the replayed shape to any obstacle at the rod's sample
    /// points (case units; `None` without obstacles). Zero where the shape leans on one.
    pub clearance: Option<f64>,
    /// Total normal force the obstacles exert on the replayed shape (case units): the sum of
    /// its obstacle rows' multipliers. Zero where no obstacle touches it.
    pub contact_force: f64,
    /// Ritz coefficients of the replayed shape.
    #[serde(skip)]
    pub a: Vec<f64>,
    /// Boundary positions of the replayed shape (dimensionless, `x/L`).
    #[serde(skip)]
    pub positions: Vec<[f64; 3]>,
}

/// Summary of a replay.
#[derive(Clone, Debug, Serialize)]
pub struct Replay {
    /// `max_k d(k) / L`.
    pub max_deviation_over_l: f64,
    /// `k` of that maximum.
    pub k_at_max_deviation: f64,
    /// Largest energy along the feasible path (case units), over the solves that converged
    /// (a solve that did not is no equilibrium; over every solve where none converged), as
    /// are `min_clearance` and `max_contact_force`.
    pub u_max: f64,
    /// Every replayed shape is stable.
    pub all_stable: bool,
    /// Every static solve converged.
    pub all_converged: bool,
    /// Smallest [`ReplayStep::clearance`] along the feasible path (`None` without obstacles).
    pub min_clearance: Option<f64>,
    /// Largest [`ReplayStep::contact_force`] along the feasible path.
    pub max_contact_force: f64,
    /// `k` of that largest contact force.
    pub k_at_max_contact_force: f64,
    /// `k` where the replayed shape jumps even after refinement (snap-through).
    pub snaps: Vec<f64>,
    /// Tolerance of the verdict (fraction of `L`).
    pub tolerance: f64,
    /// `max d/L ≤ tolerance`, every solve converged and no snap-through.
    pub coincide: bool,
    /// Deviation at `k = 0` over `L` (the replay reproduces the start).
    pub start_deviation_over_l: f64,
    /// Deviation at `k = 1` over `L` (the replay reproduces the goal).
    pub end_deviation_over_l: f64,
    /// Every step, in increasing `k`.
    pub steps: Vec<ReplayStep>,
}

impl Replay {
    /// Whether the replay stays on the start shape at `k = 0` (within the tolerance), as it
    /// does wherever the start shape is an equilibrium of its end pose. Every path starts on the
    /// start shape, so where the replay leaves it there no path can be executed from it by the
    /// controlled end alone. True for a replay that did not run.
    pub fn start_held(&self) -> bool {
        self.steps.is_empty() || self.start_deviation_over_l <= self.tolerance
    }

    /// The replay of a run stopped before it: no step, no verdict (`coincide` false).
    pub fn not_run(tolerance: f64) -> Replay {
        Replay {
            max_deviation_over_l: 0.0,
            k_at_max_deviation: 0.0,
            u_max: f64::NAN,
            all_stable: false,
            all_converged: false,
            min_clearance: None,
            max_contact_force: 0.0,
            k_at_max_contact_force: 0.0,
            snaps: Vec::new(),
            tolerance,
            coincide: false,
            start_deviation_over_l: 0.0,
            end_deviation_over_l: 0.0,
            steps: Vec::new(),
        }
    }
}

/// Replay settings.
#[derive(Clone, Copy, Debug)]
pub struct ReplayOptions {
    /// Uniform steps in `k`.
    pub steps: usize,
    /// Bisections allowed per step.
    pub refinements: usize,
    /// Coincidence tolerance (fraction of `L`).
    pub tolerance: f64,
    /// What ends the replay before `k = 1`.
    pub early_stop: EarlyStop,
}

/// What ends a replay before `k = 1`, for replays that only decide a question; a replay that
/// stops early has a step with the reason last, and does not coincide.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum EarlyStop {
    /// Nothing: the whole path is replayed (the replay reported with a plan).
    #[default]
    Never,
    /// A static solve that does not converge (whether the replayed equilibria are a plan: they
    /// are not once one solve fails).
    Unconverged,
    /// That, or a snap-through (whether the replayed equilibria are a plan: they are not once
    /// the rod snaps).
    Failure,
    /// That, a snap-through, or a shape farther from the path's than the tolerance (whether the
    /// replay coincides with the path).
    Departure,
}

struct State {
    k: f64,
    sol: StaticSolution,
    positions: Vec<[f64; 3]>,
}

/// Multipliers that warm-start the solve of `p` (the base problem plus an end pose) from `from`:
/// all of `from`'s when its rows are `p`'s; else (`from` is an end shape solved for its own
/// pose rows, such as a position alone, or another spelling of the angles) its base rows' (the
/// case's conditions, obstacles and self-contact come first in both), so that contact forces
/// carry over, and for the pose rows the reactions that balance `from`'s shape with them
/// ([`pose_multipliers`]). A shape solved for a position alone is an equilibrium of the same
/// pose with its end's angles held too, whose moment there is zero: with the end's force set
/// to zero instead, the first Newton steps leave that equilibrium and can settle on another.
fn warm_multipliers(
    base: &StaticProblem,
    from: &StaticSolution,
    p: &mut StaticProblem,
) -> Vec<f64> {
    let m = crate::optim::Nlp::m(p);
    if from.lambda.len() == m {
        return from.lambda.clone();
    }
    let nb = crate::optim::Nlp::m(base).min(from.lambda.len());
    let mut l = vec![0.0; m];
    l[..nb].copy_from_slice(&from.lambda[..nb]);
    if !from.lambda.is_empty() {
        pose_multipliers(p, &from.a, crate::optim::Nlp::m(base), &mut l);
    }
    l
}

/// Sets the multipliers of `p`'s rows from `first` on (its end pose's equalities) to the
/// least-squares solution of `∇V + Jᵀλ = 0` at the shape `a`, the other rows' multipliers
/// held as `lambda` gives them: the end's reactions that balance the shape. Leaves `lambda` as
/// it is where the rows are not independent there.
fn pose_multipliers(p: &mut StaticProblem, a: &[f64], first: usize, lambda: &mut [f64]) {
    use crate::optim::Nlp;
    use nalgebra::{DMatrix, DVector};
    let m = p.m();
    if first >= m {
        return;
    }
    let rows: Vec<usize> = (first..m).collect();
    let (_, jac) = crate::optim::augmented_lagrangian::jacobian_rows(p, a, &rows);
    let mut held = lambda.to_vec();
    held[first..].iter_mut().for_each(|v| *v = 0.0);
    let mut g = vec![0.0; p.n()];
    p.gradient(a, &held, &mut g);
    let jt = DMatrix::from_fn(g.len(), rows.len(), |i, j| jac[j][i]);
    let svd = jt.svd(true, true);
    let smax = svd.singular_values.max();
    // Rows that are not independent at `a` (or a shape with non-finite values): left as given.
    if smax.is_nan() || smax <= 0.0 || svd.singular_values.min() < 1e-9 * smax {
        return;
    }
    if let Ok(sol) = svd.solve(&-DVector::from_column_slice(&g), 0.0)
        && sol.iter().all(|v| v.is_finite())
    {
        lambda[first..].copy_from_slice(sol.as_slice());
    }
}

/// The static shape of `base` held at end pose `pose`, solved from `from`'s shape and
/// multipliers; the problem is returned with it.
/// With `stiff_retry` (the replay's steps), a solve that does not converge runs once more from
/// the same start with a hundred times the starting penalty. The tracking rounds' marches do
/// without: their equilibria are targets, and the optimiser's path follows them.
pub(super) fn solve_held(
    base: &StaticProblem,
    from: &StaticSolution,
    pose: &EndPose,
    opts: &StaticOptions,
    stiff_retry: bool,
) -> (StaticProblem, StaticSolution) {
    let mut p = pose.problem(base);
    let lambda = warm_multipliers(base, from, &mut p);
    let sol = solve_static_warm(&mut p, &from.a, &lambda, opts);
    if sol.status == SolveStatus::Converged || !stiff_retry {
        return (p, sol);
    }
    // Where the rod is pressed hard (large contact and end forces), the Lagrangian curves down
    // steeply across the constraints, and at the starting penalty the augmented function is
    // not convex even next to the equilibrium it starts from: Newton's steps run off the
    // branch. Once more with the penalty a hundred times higher.
    let again = solve_static_warm(&mut p, &from.a, &lambda, &opts.stiffer(100.0));
    if again.status == SolveStatus::Converged {
        (p, again)
    } else {
        (p, sol)
    }
}

/// The end pose of `start` solved under `base`, a problem whose contact rows are not those
/// `start` was solved with (more sample points): from `start`'s shape, the multipliers from
/// zero, once more with a stiffer penalty where that does not converge; `None` where neither
/// does.
pub(super) fn start_under(
    base: &StaticProblem,
    start: &StaticSolution,
    opts: &StaticOptions,
) -> Option<StaticSolution> {
    let positions = base.model.evaluate(&start.a).positions;
    let from = StaticSolution {
        lambda: Vec::new(),
        ..start.clone()
    };
    let pose = EndPose::of(&base.model, &start.a, &positions);
    let (_, sol) = solve_held(base, &from, &pose, opts, true);
    (sol.status == SolveStatus::Converged).then_some(sol)
}

/// Total normal force (case units) the obstacles of `base` exert on a solution of a problem
/// whose first rows are `base`'s: the sum of those obstacle rows' multipliers.
fn contact_force(base: &StaticProblem, sol: &StaticSolution) -> f64 {
    let fu = base.model.rod.force_unit();
    base.constraints
        .iter()
        .enumerate()
        .filter(|(_, c)| matches!(c, crate::constraints::Constraint::Obstacle(_)))
        .flat_map(|(i, _)| sol.lambda[base.rows_of(i)].iter())
        .map(|&l| l.max(0.0) * fu)
        .sum()
}

/// Largest distance between corresponding boundary points (dimensionless).
pub(crate) fn max_distance(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| {
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
        })
        .fold(0.0, f64::max)
}

/// The steps whose shapes are equilibria, with their indices: those whose static solve
/// converged (a solve that did not is no equilibrium), or every step where none did.
pub fn equilibrium_steps(steps: &[ReplayStep]) -> impl Iterator<Item = (usize, &ReplayStep)> {
    let any = steps.iter().any(|s| s.converged);
    steps
        .iter()
        .enumerate()
        .filter(move |(_, s)| s.converged || !any)
}

/// Replays `path(z)` from `start`, the static solve of its start shape (an equilibrium of
/// `base` plus the start pose, whose multipliers warm-start the first step).
#[allow(clippy::too_many_arguments)]
pub fn replay(
    base: &StaticProblem,
    start: &StaticSolution,
    path: &DeformationPath,
    z: &[f64],
    opts: ReplayOptions,
    static_opts: &StaticOptions,
    observer: &mut dyn PlanObserver,
    stop: &AtomicBool,
) -> Replay {
    replay_driven(
        base,
        start,
        path,
        z,
        None,
        opts,
        static_opts,
        observer,
        stop,
    )
}

/// [`replay`] with the end held at the poses of `drive` where it is given (the shapes of
/// `path(z)` are then the reference the replayed ones are compared with), at the end poses of
/// `path(z)`'s shapes otherwise.
#[allow(clippy::too_many_arguments)]
pub fn replay_driven(
    base: &StaticProblem,
    start: &StaticSolution,
    path: &DeformationPath,
    z: &[f64],
    drive: Option<&EndCourse>,
    opts: ReplayOptions,
    static_opts: &StaticOptions,
    observer: &mut dyn PlanObserver,
    stop: &AtomicBool,
) -> Replay {
    let model = &base.model;
    let l = model.rod.length;
    let unit = model.rod.energy_unit();
    let mut shape = Shape::default();
    let mut a = vec![0.0; path.n()];
    let mut optimal_at = |k: f64| -> (Vec<f64>, Vec<[f64; 3]>, f64) {
        path.shape_at(z, k, &mut a);
        model.evaluate_into(&a, &mut shape);
        let u = model.energy(&a, &shape, base.objective, None).scaled(unit);
        let u = u.value(base.objective);
        (a.clone(), shape.positions.clone(), u)
    };
    let solve = |k: f64, from: &State, target: &(Vec<f64>, Vec<[f64; 3]>, f64)| -> State {
        let pose = match drive {
            Some(course) => course.end_pose(model, k),
            None => EndPose::of(model, &target.0, &target.1),
        };
        let (mut p, mut sol) = solve_held(base, &from.sol, &pose, static_opts, true);
        // A solve that ran out of iterations gets one more budget from where it stopped.
        if sol.status == SolveStatus::IterationLimit {
            sol = solve_static_warm(&mut p, &sol.a, &sol.lambda, static_opts);
        }
        let positions = model.evaluate(&sol.a).positions;
        State { k, sol, positions }
    };
    // k = 0: solve from the start shape itself.
    let first_target = optimal_at(0.0);
    let seed = State {
        k: 0.0,
        sol: start.clone(),
        positions: first_target.1.clone(),
    };
    let mut steps: Vec<ReplayStep> = Vec::new();
    let mut snaps = Vec::new();
    let record = |st: &State,
                  target: &(Vec<f64>, Vec<[f64; 3]>, f64),
                  steps: &mut Vec<ReplayStep>,
                  observer: &mut dyn PlanObserver| {
        let d = max_distance(&st.positions, &target.1) * l;
        let clearance = super::clearance(base, &st.positions);
        steps.push(ReplayStep {
            k: st.k,
            deviation: d,
            u_optimal: target.2,
            u_feasible: st.sol.energy.value(base.objective),
            converged: st.sol.status == SolveStatus::Converged,
            status: st.sol.status,
            kkt_residual: st.sol.kkt_residual,
            stable: st.sol.stable,
            neutral_modes: st.sol.neutral_modes,
            violation: st.sol.max_violation,
            clearance,
            contact_force: contact_force(base, &st.sol),
            a: st.sol.a.clone(),
            positions: st.positions.clone(),
        });
        let opt_terms = {
            let mut sh = Shape::default();
            model.evaluate_into(&target.0, &mut sh);
            model
                .energy(&target.0, &sh, base.objective, None)
                .scaled(unit)
        };
        observer.shape(
            model,
            &ShapeRecord {
                kind: PathKind::Optimal,
                k: st.k,
                a: &target.0,
                energy: opt_terms,
                clearance: super::clearance(base, &target.1),
                deviation: None,
                stable: None,
                reactions: &[],
                violation: None,
            },
        );
        observer.shape(
            model,
            &ShapeRecord {
                kind: PathKind::Feasible,
                k: st.k,
                a: &st.sol.a,
                energy: st.sol.energy,
                clearance,
                deviation: Some(d),
                stable: st.sol.stable,
                reactions: &st.sol.reactions,
                violation: Some(st.sol.max_violation),
            },
        );
    };
    // Whether the last step recorded ends the replay ([`EarlyStop`]).
    let ends = |steps: &[ReplayStep], snaps: &[f64]| {
        let last = steps.last().expect("a step");
        match opts.early_stop {
            EarlyStop::Never => false,
            EarlyStop::Unconverged => !last.converged,
            EarlyStop::Failure => !last.converged || !snaps.is_empty(),
            EarlyStop::Departure => {
                !last.converged || !snaps.is_empty() || last.deviation > opts.tolerance * l
            }
        }
    };
    let mut current = solve(0.0, &seed, &first_target);
    record(&current, &first_target, &mut steps, observer);
    let mut interrupted = false;
    let mut stopped_early = ends(&steps, &snaps);
    'steps: for i in 1..=opts.steps {
        if stopped_early {
            break;
        }
        if super::observer::poll(observer, stop) {
            interrupted = true;
            break;
        }
        let k_hi = i as f64 / opts.steps as f64;
        // Advance from current.k to k_hi, bisecting where the replayed shape jumps or the
        // solve does not converge.
        let mut pending = vec![(k_hi, 0usize)];
        while let Some((k, depth)) = pending.pop() {
            let target = optimal_at(k);
            let prev_target = optimal_at(current.k);
            let next = solve(k, &current, &target);
            let jump = max_distance(&next.positions, &current.positions);
            let moved = max_distance(&target.1, &prev_target.1);
            let jumped = jump > (3.0 * moved).max(0.02);
            // Only from a converged shape: from one that did not converge, shorter steps
            // mostly repeat the failure at many times the cost.
            let failed = next.sol.status != SolveStatus::Converged
                && current.sol.status == SolveStatus::Converged;
            if (jumped || failed) && depth < opts.refinements {
                pending.push((k, depth + 1));
                pending.push((0.5 * (current.k + k), depth + 1));
                continue;
            }
            if jumped {
                snaps.push(k);
            }
            record(&next, &target, &mut steps, observer);
            current = next;
            if ends(&steps, &snaps) {
                stopped_early = true;
                break 'steps;
            }
        }
    }
    let all_converged = steps.iter().all(|s| s.converged);
    // The first step with the largest value of `f` (0 if none is positive) among `among`.
    let largest = |f: fn(&ReplayStep) -> f64,
                   among: &mut dyn Iterator<Item = (usize, &ReplayStep)>| {
        among
            .map(|(i, s)| (i, f(s)))
            .fold((0, 0.0), |acc, x| if x.1 > acc.1 { x } else { acc })
    };
    let (imax, dmax) = largest(|s| s.deviation, &mut steps.iter().enumerate());
    let all_stable = steps.iter().all(|s| s.stable != Some(false));
    let max_dev = dmax / l;
    // The energies, clearances and contact forces are those of equilibria.
    let (icf, fmax) = largest(|s| s.contact_force, &mut equilibrium_steps(&steps));
    Replay {
        max_deviation_over_l: max_dev,
        k_at_max_deviation: steps[imax].k,
        u_max: equilibrium_steps(&steps)
            .map(|(_, s)| s.u_feasible)
            .fold(f64::NEG_INFINITY, f64::max),
        all_stable,
        all_converged,
        min_clearance: equilibrium_steps(&steps)
            .filter_map(|(_, s)| s.clearance)
            .reduce(f64::min),
        max_contact_force: fmax,
        k_at_max_contact_force: steps[icf].k,
        coincide: !interrupted
            && !stopped_early
            && max_dev <= opts.tolerance
            && all_converged
            && snaps.is_empty(),
        snaps,
        tolerance: opts.tolerance,
        start_deviation_over_l: steps[0].deviation / l,
        end_deviation_over_l: steps.last().map_or(0.0, |s| s.deviation / l),
        steps,
    }
}

/// Equilibria the controlled end's poses along `path(z)` produce at `ks` (increasing, from 0):
/// one warm-started static solve per `k`, without refinement, marching along `k` from
/// `start`. Returns each one's boundary positions (dimensionless), for the planner's tracking
/// term, and its solution.
pub fn equilibria(
    base: &StaticProblem,
    start: &StaticSolution,
    path: &DeformationPath,
    z: &[f64],
    ks: &[f64],
    static_opts: &StaticOptions,
) -> Vec<(Vec<[f64; 3]>, StaticSolution)> {
    march(base, start, path, z, ks, &tracking_options(static_opts))
}

/// Stretches of `k` that [`equilibria_from`] marches along side by side: fixed, so that the
/// targets are the same on any number of threads.
pub const STRETCHES: usize = 2;

/// [`equilibria`] for a path that has moved a little since `from` (the equilibria an earlier
/// round found at the same `ks`): the samples are cut into [`STRETCHES`] stretches, the first
/// marched from `start` as [`equilibria`] does, each other from `from`'s solution at its first
/// `k`, and `workers` share the stretches out.
#[allow(clippy::too_many_arguments)]
pub fn equilibria_from(
    base: &StaticProblem,
    start: &StaticSolution,
    from: &[StaticSolution],
    path: &DeformationPath,
    z: &[f64],
    ks: &[f64],
    static_opts: &StaticOptions,
    workers: &Workers,
) -> Vec<(Vec<[f64; 3]>, StaticSolution)> {
    debug_assert_eq!(from.len(), ks.len());
    let opts = tracking_options(static_opts);
    let n = ks.len();
    let mut stretches: Vec<Vec<(Vec<[f64; 3]>, StaticSolution)>> = vec![Vec::new(); STRETCHES];
    workers.for_each_chunk(JOB_EQUILIBRIA, &mut stretches, |i, out| {
        let (j0, j1) = (i * n / STRETCHES, (i + 1) * n / STRETCHES);
        let first = if i == 0 { start } else { &from[j0] };
        out[0] = march(base, first, path, z, &ks[j0..j1], &opts);
    });
    stretches.into_iter().flatten().collect()
}

/// The static options of tracking's solves: no stability judgement, no moment balance (only
/// their shapes and multipliers are used).
fn tracking_options(static_opts: &StaticOptions) -> StaticOptions {
    StaticOptions {
        stability: false,
        balance: false,
        ..*static_opts
    }
}

/// The equilibria the end poses of `path(z)` at `ks` produce, each solved from the one before
/// (the first from `first`), with their boundary positions (dimensionless).
fn march(
    base: &StaticProblem,
    first: &StaticSolution,
    path: &DeformationPath,
    z: &[f64],
    ks: &[f64],
    opts: &StaticOptions,
) -> Vec<(Vec<[f64; 3]>, StaticSolution)> {
    let model = &base.model;
    let mut a = vec![0.0; path.n()];
    let mut shape = Shape::default();
    let mut out: Vec<(Vec<[f64; 3]>, StaticSolution)> = Vec::with_capacity(ks.len());
    for &k in ks {
        path.shape_at(z, k, &mut a);
        model.evaluate_into(&a, &mut shape);
        let from = out.last().map_or(first, |(_, sol)| sol);
        let pose = EndPose::of(model, &a, &shape.positions);
        let (_, sol) = solve_held(base, from, &pose, opts, false);
        out.push((model.evaluate(&sol.a).positions, sol));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optim::augmented_lagrangian::kkt_residual;
    use crate::rod::{Rod, layout::Layout};
    use crate::statics::solve_static;

    /// A planar rod clamped along +z with its end held at (0.4, 0, 0.7) L by its position
    /// alone, free to turn: with its angle held too (the replay's and tracking's end pose), the
    /// solved shape balances with the multipliers that warm-start its solve — its own end force
    /// and a zero moment — to the solver's tolerance, where the end's rows set to zero leave it
    /// out of balance by that force.
    #[test]
    fn an_end_solved_for_its_position_alone_warm_starts_with_its_own_reactions() {
        let rod = Rod::uniform(1.0, 1.0);
        let base = StaticProblem::builder(rod.clone(), Layout::of(&rod, 4))
            .clamp(0.0, [0.0; 3], &[0.0])
            .build()
            .expect("a clamped rod");
        let model = &base.model;
        let position = EndPose {
            position: vec![(0, 0.4), (2, 0.7)],
            angles: Vec::new(),
        };
        let mut p0 = position.problem(&base);
        let from = p0.natural_start(0.1);
        let start = solve_static(&mut p0, &from, &StaticOptions::default());
        assert_eq!(start.status, SolveStatus::Converged);
        let force = start.lambda[crate::optim::Nlp::m(&base)..].to_vec();
        assert!(force.iter().any(|f| f.abs() > 0.1), "a bent rod: {force:?}");
        let positions = model.evaluate(&start.a).positions;
        let mut p = EndPose::of(model, &start.a, &positions).problem(&base);
        let m = crate::optim::Nlp::m(&p);
        assert_eq!(m, start.lambda.len() + 1, "the end's angle is one row more");
        let lambda = warm_multipliers(&base, &start, &mut p);
        let nb = crate::optim::Nlp::m(&base);
        // The base rows as solved, the end's force as solved, no moment at the end.
        assert_eq!(lambda[..nb], start.lambda[..nb]);
        for (got, want) in lambda[nb..nb + 2].iter().zip(&force) {
            assert!(
                (got - want).abs() <= 1e-6 * want.abs().max(1.0),
                "{got} vs {want}"
            );
        }
        assert!(lambda[nb + 2].abs() <= 1e-6, "moment {}", lambda[nb + 2]);
        let balanced = kkt_residual(&mut p, &start.a, &lambda);
        assert!(balanced <= 1e-6, "{balanced:.3e}");
        let mut zeroed = lambda.clone();
        zeroed[nb..].iter_mut().for_each(|v| *v = 0.0);
        let unbalanced = kkt_residual(&mut p, &start.a, &zeroed);
        assert!(unbalanced > 1e3 * balanced.max(1e-9), "{unbalanced:.3e}");
    }
}
