//! The start and goal shapes a planner is built on: each end's pose solved as a static shape
//! (again from rods bent towards it where the solve fails), held on the chords between the
//! contact points or off the obstacles where it dips into one, and checked against the
//! obstacles.

use super::endpoints::{self, End, EndPose};
use super::verify::{self, fine_model};
use super::{
    COLLISION_TOLERANCE, PlanProblem, PlanSettings, PlanSetupError, equilibrium_plan,
    hold_off_margin,
};
use crate::constraints::{Angle, Constraint};
use crate::scene::obstacle::Obstacle;
use crate::statics::problem::StaticProblem;
use crate::statics::{SolveStatus, StaticOptions, StaticSolution, solve_static};
use std::sync::Arc;

/// How many times finer in s than the verification grid the end shapes are checked for
/// obstacles: a rod that rests on an obstacle bulges into it between the contact points its
/// static solve holds clear (the Ritz shape cannot bend round a concentrated contact force),
/// and a bulge narrower than the verification grid's spacing can lie between its points. Each
/// end is one shape, so a fine grid costs little; every path starts or ends there.
const END_GRID_REFINEMENT: usize = 4;

/// The grid in s on which an end shape resting on an obstacle must be clear
/// ([`END_GRID_REFINEMENT`] times the verification grid's intervals in s,
/// [`Planner::verify_s_intervals`](super::Planner::verify_s_intervals)).
pub(super) fn end_grid(
    model: &crate::rod::model::Model,
    s_intervals: usize,
) -> crate::rod::model::Model {
    fine_model(model, END_GRID_REFINEMENT * s_intervals, 2)
}

/// Bending and twisting energy (units of `Rf/L`) above which an end shape solved from its first
/// start is searched again from the other starts, as where that solve does not converge, and
/// the lowest stable shape kept: `4π²`, twice that of a rod bent into one full circle. A local
/// solve from the natural state can settle in a shape wound or rippled far beyond what the
/// pose needs (on the generated suite, 577 where a stable shape of 5.3 holds the same pose),
/// and every plan from it peaks at least that high; shapes bent this much are a few in a
/// hundred, so the other starts' solves cost little ([`PlanSettings::least_energy_ends`]
/// searches every end so).
pub(super) const WOUND_ENERGY: f64 = 4.0 * std::f64::consts::PI * std::f64::consts::PI;

/// Whether `sol`'s bending and twisting energy is above [`WOUND_ENERGY`].
fn wound(sol: &StaticSolution) -> bool {
    sol.energy_scaled.flexural + sol.energy_scaled.torsional > WOUND_ENERGY
}

/// The start or goal shape: `end`'s coefficients as given, or the static solve of its pose,
/// started from its coefficients, else (a 3D end with all three angles) from a shape bent
/// from the held frame `held` (see [`held_frame`]) towards its own, else from the case's
/// initial shape; with how its obstacle contacts are held ([`on_chords_if_dipping`]).
pub(super) fn end_shape(
    problem: &PlanProblem,
    which: &'static str,
    end: &End,
    held: ([f64; 3], bool),
    fine: &crate::rod::model::Model,
    opts: &StaticOptions,
    settings: &PlanSettings,
) -> Result<(StaticSolution, Option<f64>), PlanSetupError> {
    let (coincide_tolerance, least_energy) =
        (settings.coincide_tolerance, settings.least_energy_ends);
    let seed = end_angles(end)
        .filter(|_| problem.statics.model.layout.spatial)
        .map(|e| (held, e));
    let base = &problem.statics;
    let pose = EndPose {
        position: end.position.clone(),
        angles: end
            .angles
            .iter()
            .map(|&(f, v)| (Angle::Field(f), v))
            .collect(),
    };
    let (sol, contacts) = if !end.is_pose() {
        let a = end.shape.clone().expect("validated: shape or pose");
        // Held at its own end pose, as the replay holds it: the least-squares multipliers then
        // include the end's reactions, and they warm-start the replay's first solve row for row.
        let held = EndPose::of(&base.model, &a, &base.model.evaluate(&a).positions);
        let mut p = held.problem(base);
        let ev = crate::statics::evaluate_shape(&mut p, &a);
        let viol = ev.max_violation;
        let sol = StaticSolution {
            balance: Some(ev.balance),
            self_contacts: ev.self_contacts,
            energy_scaled: ev.energy.scaled(1.0 / base.model.rod.energy_unit()),
            energy: ev.energy,
            status: if viol <= 1e-6 {
                SolveStatus::Converged
            } else {
                SolveStatus::Infeasible
            },
            // The multipliers the shape needs, so that a solve warm-started from it (the
            // replay's first step) starts with its contact forces, not without them.
            lambda: ev.lambda,
            max_violation: viol,
            kkt_residual: ev.kkt_residual,
            reactions: ev.reactions,
            stable: None,
            stability: None,
            min_reduced_eigenvalue: None,
            neutral_modes: None,
            gauge_modes: None,
            outer_iterations: 0,
            evaluations: 1,
            a,
        };
        (sol, None)
    } else {
        let a0 = match (&end.shape, seed) {
            (Some(a), _) => a.clone(),
            (None, Some(((held, phi_fixed), target))) => {
                endpoints::seed_towards(&base.model, &problem.initial, held, phi_fixed, target)
            }
            (None, None) => problem.initial.clone(),
        };
        // The pose solved from `a`, on the chords where it dips.
        let solved = |a: &[f64]| {
            let sol = solve_from(pose.problem(base), a, opts);
            let obstacles = &problem.obstacles;
            on_chords_if_dipping(
                base,
                obstacles,
                &pose,
                sol,
                fine,
                opts,
                coincide_tolerance,
                false,
            )
        };
        let first = solved(&a0);
        let converged = first.0.status == SolveStatus::Converged;
        if end.shape.is_some() || (converged && !least_energy && !wound(&first.0)) {
            first
        } else {
            // Searched again from rods bent other ways: the lowest-energy shape that converges
            // (stable ones first; the first search's among them when it converged), else the
            // first search's.
            let position = full_position(&base.model, end);
            let angles = if base.model.layout.spatial {
                end_angles(end)
            } else {
                use crate::rod::layout::Field;
                let theta = end.angles.iter().find(|(f, _)| *f == Field::Theta);
                theta.map(|&(_, t)| [0.0, t, 0.0])
            };
            let retried = endpoints::retry_seeds(
                &base.model,
                &problem.initial,
                seed.is_some(),
                held,
                position,
                angles,
            )
            .into_iter()
            .map(|a| solved(&a));
            // Shapes clear of the obstacles on the end grid first (one that dips between its
            // contact points ends every path inside the obstacle), then stable ones, then the
            // least energy.
            let tol = COLLISION_TOLERANCE * base.model.rod.length;
            let key = |s: &StaticSolution| {
                let dips = end_clearance(fine, &problem.obstacles, &s.a) < -tol;
                (dips, s.stable != Some(true), s.energy.potential())
            };
            let best = retried
                .filter(|(sol, _)| sol.status == SolveStatus::Converged)
                .map(|r| (key(&r.0), r))
                .min_by(|(ka, _), (kb, _)| {
                    (ka.0, ka.1).cmp(&(kb.0, kb.1)).then(ka.2.total_cmp(&kb.2))
                });
            match best {
                // The first search's shape stays unless another is clear where it dips,
                // stable where it is not, or has less energy by more than the solves' last
                // digits (the same equilibrium reached from another start).
                Some((kb, b)) if converged => {
                    let kf = key(&first.0);
                    let lower = kb.2 < kf.2 - 1e-9 * kf.2.abs().max(1.0);
                    if (kb.0, kb.1) < (kf.0, kf.1) || ((kb.0, kb.1) == (kf.0, kf.1) && lower) {
                        b
                    } else {
                        first
                    }
                }
                Some((_, b)) => b,
                None => first,
            }
        }
    };
    if sol.status != SolveStatus::Converged {
        let msg = if !end.is_pose() {
            format!(
                "the given shape violates the case's constraints or obstacles by {:.3e} (units of L)",
                sol.max_violation
            )
        } else if let Some(inside) = end_inside_obstacle(base, end) {
            inside
        } else {
            let blocking = pose
                .problem(base)
                .most_violated(&sol.a, opts.al.feasibility_tol)
                .map_or(String::new(), |(label, w)| {
                    format!("; the most violated constraint is {label} (by {w:.3e} L)")
                });
            let from = if end.shape.is_some() {
                "the end's `shape`"
            } else if full_position(&base.model, end).is_some() {
                "the natural state and from rods bent from the held end towards the pose (along the arc and the chord to its position, with the end's angles where they are given; on a planar rod also a quarter turn either way of the arc)"
            } else if seed.is_some() {
                "a shape bent from the held end's frame towards the pose's and from the natural state"
            } else if !base.model.layout.spatial && !end.angles.is_empty() {
                "the natural state and from a rod bent from the held end to the end's angle"
            } else {
                "the natural state"
            };
            format!(
                "the static solve found no shape that reaches this pose under the case's constraints and obstacles (solver: {:?}, violation {:.3e} in units of L){blocking}; it searches from {from}, at three starting penalties each: a shape that goes round the obstacles another way may still exist, and a `shape` near it given to this end would start the solve there",
                sol.status, sol.max_violation
            )
        };
        return Err(PlanSetupError::Unreachable {
            end: which,
            message: msg,
        });
    }
    Ok((sol, contacts))
}

/// The static solve of `p` from `a0`, and where it does not converge, again from `a0` with ten
/// and then a hundred times the starting penalty (the first that converges). From the natural
/// state, a penalty too small for the obstacles lets the first inner solves pull the rod
/// through one on its way to the pose, where it stays caught; a stiffer one keeps it outside
/// from the start.
fn solve_from(mut p: StaticProblem, a0: &[f64], opts: &StaticOptions) -> StaticSolution {
    let mut sol = solve_static(&mut p, a0, opts);
    for factor in [10.0, 100.0] {
        if sol.status == SolveStatus::Converged {
            break;
        }
        let again = solve_static(&mut p, a0, &opts.stiffer(factor));
        if again.status == SolveStatus::Converged {
            sol = again;
        }
    }
    sol
}

/// The static solve of `p` from `a` and the multipliers `a` needs (least squares): it stays on
/// the equilibrium it starts from, where one from zero multipliers can leave it.
pub(super) fn solve_warm_from(
    p: &mut StaticProblem,
    a: &[f64],
    opts: &StaticOptions,
) -> StaticSolution {
    let lambda = crate::statics::evaluate_shape(p, a).lambda;
    crate::statics::solve_static_warm(p, a, &lambda, opts)
}

/// The smallest clearance (case units) of the shape `a` from `obstacles` on the end grid
/// `fine` ([`end_grid`]); infinite where there is no obstacle.
fn end_clearance(fine: &crate::rod::model::Model, obstacles: &[Arc<Obstacle>], a: &[f64]) -> f64 {
    verify::shape_worst_clearance(fine, obstacles, a).map_or(f64::INFINITY, |w| w.clearance)
}

/// An end shape `sol` solved at `pose` with its obstacle contacts at the sample points, or,
/// where it dips into an obstacle between them on the end grid `fine` ([`end_grid`]; by more
/// than the collision tolerance, 1e-6 L) and the same pose solved with the contacts on the
/// chords between the points converges clear of the obstacles there, that shape; where that one
/// still dips (the rod bulges into the obstacle between the points), the pose solved on the
/// chords held off the obstacles by [`hold_off_margin`] (of the plan's `coincide_tolerance`),
/// when that converges clear. An end resting on an obstacle is a legal end of a path only when
/// the end grid finds it clear. Returned with how its contacts are held: `None` at the
/// sample points, `Some(margin)` on the chords, `margin` (units of L) off the obstacles. With
/// `warm`, each solve starts from the multipliers its starting shape needs (least squares), so
/// that it stays on that shape's equilibrium; else from zero.
#[allow(clippy::too_many_arguments)]
pub(super) fn on_chords_if_dipping(
    statics: &StaticProblem,
    obstacles: &[Arc<Obstacle>],
    pose: &EndPose,
    sol: StaticSolution,
    fine: &crate::rod::model::Model,
    opts: &StaticOptions,
    coincide_tolerance: f64,
    warm: bool,
) -> (StaticSolution, Option<f64>) {
    let solve = |p: &mut StaticProblem, a: &[f64]| {
        if warm {
            solve_warm_from(p, a, opts)
        } else {
            solve_static(p, a, opts)
        }
    };
    let tol = COLLISION_TOLERANCE * statics.model.rod.length;
    let depth = |a: &[f64]| end_clearance(fine, obstacles, a);
    if sol.status != SolveStatus::Converged || depth(&sol.a) >= -tol {
        return (sol, None);
    }
    let Some(chords) = equilibrium_plan::on_chords(statics) else {
        return (sol, None);
    };
    let again = solve(&mut pose.problem(&chords), &sol.a);
    if again.status != SolveStatus::Converged {
        return (sol, None);
    }
    let d = depth(&again.a);
    if d >= -tol {
        return (again, Some(0.0));
    }
    // Still inside (the rod bulges into the obstacle between the points): held off it by
    // twice that depth, as the replayed equilibria are ([`Planner::judge_path`]).
    let length = statics.model.rod.length;
    let Some(margin) = hold_off_margin(-d, length, coincide_tolerance) else {
        return (sol, None);
    };
    let held = equilibrium_plan::held_off(statics, margin);
    let off = solve(&mut pose.problem(&held), &again.a);
    if off.status == SolveStatus::Converged && depth(&off.a) >= -tol {
        (off, Some(margin))
    } else {
        (sol, None)
    }
}

/// Whether the end's position (when every component is given) lies inside an obstacle or
/// closer to it than the rod's radius and the obstacle's margin allow; says which.
fn end_inside_obstacle(base: &StaticProblem, end: &End) -> Option<String> {
    let model = &base.model;
    let l = model.rod.length;
    let comps = if model.layout.spatial { 3 } else { 2 };
    if end.position.len() < comps {
        return None;
    }
    let mut p = [0.0; 3];
    for &(k, x) in &end.position {
        p[k] = x * l;
    }
    base.constraints.iter().find_map(|c| {
        let Constraint::Obstacle(oc) = c else {
            return None;
        };
        let d = oc.obstacle.signed_distance_value(p);
        let need = oc.clearance * l;
        (d < need).then(|| {
            format!(
                "the end position {p:?} lies {} obstacle '{}' (signed distance {d:.4e}, the rod \
                 needs {need:.4e}: its radius plus the obstacle's margin)",
                if d < 0.0 { "inside" } else { "too close to" },
                oc.obstacle.name
            )
        })
    })
}

/// An end's position (units of L, case axes), when its pose gives every component the layout
/// has.
fn full_position(model: &crate::rod::model::Model, end: &End) -> Option<[f64; 3]> {
    let components = model.layout.components();
    let mut x = [0.0; 3];
    for &k in components {
        x[k] = end.position.iter().find(|(j, _)| *j == k)?.1;
    }
    Some(x)
}

/// All three Euler angles of an end, when its pose gives them.
fn end_angles(end: &End) -> Option<[f64; 3]> {
    use crate::rod::layout::Field;
    let get = |f| end.angles.iter().find(|(g, _)| *g == f).map(|x| x.1);
    Some([get(Field::Phi)?, get(Field::Theta)?, get(Field::Psi)?])
}

/// The Euler angles of the held end's frame as the case prescribes it: the orientation
/// constraints at `s = 0` (a prescribed `φ + ψ` counts as `ψ`), zero where nothing is
/// prescribed (the natural state's frame); and whether `φ(0)` itself is prescribed.
pub(super) fn held_frame(base: &StaticProblem) -> ([f64; 3], bool) {
    use crate::constraints::Angle;
    use crate::rod::layout::Field;
    let mut angles = [0.0; 3];
    let mut phi_fixed = false;
    // The rows the problem holds (in the rod's angles' frame, which may not be the case's).
    for c in &base.constraints {
        let Constraint::Orientation(oc) = c else {
            continue;
        };
        if oc.t != 0.0 {
            continue;
        }
        let mut sum = None;
        for &(ang, v) in &oc.rows {
            match ang {
                Angle::Field(Field::Phi) => {
                    angles[0] = v;
                    phi_fixed = true;
                }
                Angle::Field(Field::Theta) => angles[1] = v,
                Angle::Field(Field::Psi) => angles[2] = v,
                Angle::PhiPlusPsi => sum = Some(v),
                Angle::Field(Field::Eps) => {}
            }
        }
        if let Some(sum) = sum {
            angles[2] = sum - angles[0];
        }
    }
    (angles, phi_fixed)
}
