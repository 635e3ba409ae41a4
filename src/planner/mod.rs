//! Deformation path planning (paper §7): the minimax-energy path in coefficient space between
//! two static shapes, verified on a finer grid and replayed by the controlled end alone.
//!
//! [`Planner::new`] (or [`Planner::from_case`]) solves the start and goal shapes; [`Planner::run`] optimises, verifies
//! and replays, telling a [`PlanObserver`] every shape it computes.

mod clear_samples;
pub mod contact_samples;
pub mod endpoints;
pub mod equilibrium_plan;
pub mod minimax;
pub mod observer;
pub mod orientation;
pub mod path;
mod reached_goal;
pub mod replay;
pub mod result;
pub mod settings;
mod start;
mod starts;
mod straight_path;
pub mod swept;
mod tracking;
pub mod trajectory;
pub mod verify;
pub mod workers;

use crate::constraints::{Angle, Constraint};
pub use crate::error::SettingsError;
use crate::optim::AlStatus;
use crate::planner::path::DeformationPath;
use crate::rod::kinematics::Shape;
use crate::scene::obstacle::Obstacle;
use crate::statics::problem::StaticProblem;
use crate::statics::{SolveStatus, StaticOptions, StaticSettings, StaticSolution, solve_static};
pub use endpoints::End;
use endpoints::EndPose;
use minimax::MinimaxProblem;
use observer::{PathKind, PlanObserver, RecordedShapes, Recorder, ShapeRecord};
use replay::{EarlyStop, Replay, ReplayOptions, replay};
pub use settings::{Optimiser, PlanSettings, Workspace};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use verify::fine_model;

pub use result::{
    Attempt, ContactRefinement, ContactTry, EndInside, PlanReport, PlanResult, PlanStatus,
    PlanVerdict, ReachedGoal, StartSummary, Timing, VerificationGrid,
};
use start::Verified;
use starts::StartPlan;

/// Depth (a fraction of L) below which a verified clearance counts as a collision.
const COLLISION_TOLERANCE: f64 = 1e-6;

/// How many times finer in s than the verification grid the end shapes are checked for
/// obstacles: a rod that rests on an obstacle bulges into it between the contact points its
/// static solve holds clear (the Ritz shape cannot bend round a concentrated contact force),
/// and a bulge narrower than the verification grid's spacing can lie between its points. Each
/// end is one shape, so a fine grid costs little; every path starts or ends there.
const END_GRID_REFINEMENT: usize = 4;

/// The grid in s on which an end shape resting on an obstacle must be clear
/// ([`END_GRID_REFINEMENT`] times the verification grid's intervals in s,
/// [`Planner::verify_s_intervals`]).
fn end_grid(model: &crate::rod::model::Model, s_intervals: usize) -> crate::rod::model::Model {
    fine_model(model, END_GRID_REFINEMENT * s_intervals, 2)
}

/// Largest margin (a fraction of the coincidence tolerance) by which replayed equilibria that
/// dip between contact points are held off the obstacles.
const CONTACT_MARGIN_CAP: f64 = 0.05;

/// How many times replayed equilibria that still dip into an obstacle between their contact
/// points, held off it, are held off again by twice their new depth more (the first included).
const HOLD_OFF_ROUNDS: usize = 2;

/// The margin (units of L) by which a shape that dips `depth` (case units) into an obstacle
/// between its contacts is solved again held off the obstacles: twice the depth, when that is
/// positive and at most [`CONTACT_MARGIN_CAP`] of `coincide_tolerance` (a fraction of L).
fn hold_off_margin(depth: f64, length: f64, coincide_tolerance: f64) -> Option<f64> {
    let margin = 2.0 * depth / length;
    (margin > 0.0 && margin <= CONTACT_MARGIN_CAP * coincide_tolerance).then_some(margin)
}

/// What to plan: the rod held at its base (its static problem: the fixed conditions,
/// obstacles and self-contact), where its controlled end starts and where it goes.
#[derive(Clone, Debug)]
pub struct PlanProblem {
    /// The static problem without the controlled end's pose.
    pub statics: StaticProblem,
    /// The obstacles (also among the static problem's constraints), for logs and plots.
    pub obstacles: Vec<Arc<Obstacle>>,
    /// Where the controlled end starts: a pose, or a shape.
    pub start: End,
    /// Where it goes.
    pub goal: End,
    /// The shape the start and goal solves begin from (e.g.
    /// [`StaticProblem::natural_start`]).
    pub initial: Vec<f64>,
    /// Settings of the static solves (start, goal, replay); their optimality tolerance is
    /// taken no tighter than 1e-5 and their Newton steps no longer than 0.1.
    pub static_settings: StaticSettings,
}

impl PlanProblem {
    /// A problem from `statics` (the held rod), with its obstacles gathered from its
    /// constraints, the default static settings and the natural start.
    pub fn new(statics: StaticProblem, start: End, goal: End) -> PlanProblem {
        let obstacles = statics.obstacles();
        let initial = statics.natural_start(0.1);
        PlanProblem {
            statics,
            obstacles,
            start,
            goal,
            initial,
            static_settings: StaticSettings::default(),
        }
    }
}

/// Why a plan could not be set up.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PlanSetupError {
    /// A setting is out of range.
    #[error("settings: {0}")]
    Settings(#[from] SettingsError),
    /// The problem cannot be planned (e.g. a free base).
    #[error("{0}")]
    Problem(String),
    /// The start or the goal is ill-posed (e.g. an orientation that is not a rotation).
    #[error("{end}: {message}")]
    End {
        /// `start` or `goal`.
        end: &'static str,
        /// Why.
        message: String,
    },
    /// No static shape reaches the start or the goal under the problem's constraints and
    /// obstacles (or the given shape violates them): there is nothing to plan between.
    #[error("{end}: {message}")]
    Unreachable {
        /// `start` or `goal`.
        end: &'static str,
        /// Why: the obstacle the end lies in, or the constraint most violated.
        message: String,
    },
}

/// A planning problem ready to run: the held end's conditions, the obstacles, and the two
/// solved end shapes.
#[derive(Clone, Debug)]
pub struct Planner {
    /// The static problem without the controlled end (fixed conditions, obstacles,
    /// self-contact).
    pub base: StaticProblem,
    /// Obstacles.
    pub obstacles: Vec<Arc<Obstacle>>,
    /// Settings.
    pub settings: PlanSettings,
    /// Static solver settings (endpoints and replay).
    pub static_options: StaticOptions,
    /// The start shape's solve.
    pub start: StaticSolution,
    /// The goal shape's solve.
    pub goal: StaticSolution,
    /// Rows of the fixed conditions that are linear in the coefficients.
    pub linear_rows: Vec<Vec<f64>>,
    /// `base` as the replays hold the rod: as the start shape is held, with the obstacle
    /// contacts on the chords between the sample points, [`Planner::start_contacts`] off the
    /// obstacles, where the start shape needed that to rest on an obstacle clear of it (its
    /// contacts at the points dipped into it between them on a grid four times finer in s
    /// than the verification grid); else `base` itself. A replay's first solve then starts on
    /// an equilibrium of its own problem.
    pub held: StaticProblem,
    /// How far (units of L) the start shape's contacts are held off the obstacles on the
    /// chords between the sample points, where it needed the chords; `None` where it rests on
    /// its sample points (or touches nothing).
    pub start_contacts: Option<f64>,
    /// Where the planner was made with more contact samples than its case's, because an end
    /// shape dipped into an obstacle between the case's (set by
    /// [`Planner::with_contact_samples`]; reported as [`PlanResult::contact_samples`]).
    pub contact_refinement: Option<ContactRefinement>,
    /// The planners made with more contact samples whose end shapes still dipped, or did not
    /// solve (set by [`Planner::with_contact_samples`]; reported as
    /// [`PlanResult::contact_samples_tried`]).
    pub contact_tries: Vec<ContactTry>,
    /// The count of contact samples (intervals) and `base` with them, twice `base`'s (set by
    /// [`Planner::with_contact_samples`]; `None` where the limits leave no room): where no plan
    /// of the search is executable and replayed equilibria still dip into an obstacle between
    /// the chords of `base`'s sample points, they are replayed again on the chords of these,
    /// whose dips are about a quarter as deep.
    pub finer_contacts: Option<Arc<(usize, StaticProblem)>>,
    /// Set to stop a run (see [`Planner::stop_handle`]).
    stop: Arc<AtomicBool>,
    /// Objective evaluations each start may use (`None`: no limit); set on the attempts after
    /// the case's own ([`PlanSettings::fallback_evaluations`]).
    budget: Option<usize>,
    /// When the search must start nothing new ([`PlanSettings::time_limit`]); set on the
    /// copy of the planner a run with a time limit works on.
    deadline: Option<std::time::Instant>,
    /// Set when the time limit stopped something from starting (that run's own flag).
    timed_out: Arc<AtomicBool>,
    /// The quick first attempt of a planar rod ([`Attempt::Quick`]).
    quick: bool,
    /// The goal was given by its pose alone (no `shape`), and no plan has yet been made again
    /// to an equilibrium of it the gripper's motion reaches ([`PlanSettings::reached_goal`]).
    goal_by_pose: bool,
    /// Judgements replay equilibria that still dip on [`Planner::finer_contacts`]: set on the
    /// copy that judges the search's plans again where none was executable.
    finer_retry: bool,
    /// Threads a start's path optimisation splits its samples over
    /// ([`PlanSettings::threads`]).
    workers: workers::Workers,
    /// The grid the end shapes were checked on ([`end_grid`]), with the verification grid's
    /// intervals in s it was made for ([`Planner::verify_s_intervals`]).
    end_grid: Arc<(usize, crate::rod::model::Model)>,
}

/// Smallest surface gap to any obstacle (case units) of boundary positions `x/L`.
pub fn clearance(p: &StaticProblem, positions: &[[f64; 3]]) -> Option<f64> {
    let l = p.model.rod.length;
    let r = p.model.rod.radius;
    let mut best: Option<f64> = None;
    for con in &p.constraints {
        if let Constraint::Obstacle(ob) = con {
            for x in positions {
                let (d, _) = ob.obstacle.signed_distance(x.map(|v| v * l));
                best = Some(best.map_or(d - r, |b: f64| b.min(d - r)));
            }
            // With chord contacts, the chords the constraint holds.
            if ob.chords {
                for j in 0..ob.samples.len() {
                    let d = ob.witness(positions, j).distance;
                    best = Some(best.map_or(d - r, |b: f64| b.min(d - r)));
                }
            }
        }
    }
    best
}

/// Splits the case's constraints into linear rows (eliminated from the path), blocks that hold
/// at every sampled `k`, and nothing (the fixed base's own position, which is constant).
fn classify(p: &StaticProblem, safety: f64) -> (Vec<Vec<f64>>, Vec<Constraint>) {
    let model = &p.model;
    let n = model.n();
    let mut linear = Vec::new();
    let mut blocks: Vec<Constraint> = Vec::new();
    for con in &p.constraints {
        match con {
            Constraint::Orientation(oc) => {
                for &(ang, _) in &oc.rows {
                    let mut row = vec![0.0; n];
                    for &(f, w) in ang.terms() {
                        let off = model.layout.offset(f).expect("validated field");
                        for (i, e) in oc.e.iter().enumerate() {
                            row[off + i] += w * e;
                        }
                    }
                    linear.push(row);
                }
            }
            Constraint::Linear(lc) => {
                for (r, _) in &lc.rows {
                    let mut row = vec![0.0; n];
                    for &(j, c) in r {
                        row[j] += c;
                    }
                    linear.push(row);
                }
            }
            Constraint::Obstacle(ob) => blocks.push(optimiser_obstacle(ob, safety).into()),
            // x(0) is the fixed base: constant along every path.
            Constraint::Position(pc) if pc.boundary == 0 && !model.layout.free_base => {}
            Constraint::Position(_)
            | Constraint::RelativePosition(_)
            | Constraint::SelfContact(_) => blocks.push(con.clone()),
        }
    }
    (linear, blocks)
}

/// The start or goal shape: `end`'s coefficients as given, or the static solve of its pose,
/// started from its coefficients, else (a 3D end with all three angles) from a shape bent
/// from the held frame `held` (see [`held_frame`]) towards its own, else from the case's
/// initial shape; with how its obstacle contacts are held ([`on_chords_if_dipping`]).
fn end_shape(
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
        if end.shape.is_some() || (converged && !least_energy) {
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
            let key = |s: &StaticSolution| (s.stable != Some(true), s.energy.potential());
            let best = retried
                .filter(|(sol, _)| sol.status == SolveStatus::Converged)
                .min_by(|(a, _), (b, _)| {
                    let (ka, kb) = (key(a), key(b));
                    ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1))
                });
            match best {
                // The first search's shape stays unless another is stable where it is not, or
                // has less energy by more than the solves' last digits (the same equilibrium
                // reached from another start).
                Some(b) if converged => {
                    let (kb, kf) = (key(&b.0), key(&first.0));
                    let lower = kb.1 < kf.1 - 1e-9 * kf.1.abs().max(1.0);
                    let stabler = !kb.0 && kf.0;
                    if stabler || (kb.0 == kf.0 && lower) {
                        b
                    } else {
                        first
                    }
                }
                Some(b) => b,
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
fn solve_warm_from(p: &mut StaticProblem, a: &[f64], opts: &StaticOptions) -> StaticSolution {
    let lambda = crate::statics::evaluate_shape(p, a).lambda;
    crate::statics::solve_static_warm(p, a, &lambda, opts)
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
fn on_chords_if_dipping(
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
    let depth = |a: &[f64]| {
        verify::shape_worst_clearance(fine, obstacles, a).map_or(f64::INFINITY, |w| w.clearance)
    };
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

/// The optimiser's rows of obstacle `ob`: held at the sample points, `safety` (units of L)
/// farther out (the safety margin and the verification grid keep what lies between them
/// clear); the path optimiser and the tracking targets use them.
fn optimiser_obstacle(
    ob: &crate::constraints::ObstacleConstraint,
    safety: f64,
) -> crate::constraints::ObstacleConstraint {
    let mut o = ob.clone();
    o.clearance += safety;
    o.chords = false;
    o
}

/// Checks that the workspace can be held on `model` (its own axes, `y = 0` inside on a planar
/// rod) and that the end shapes' controlled ends lie in it.
fn check_workspace(
    model: &crate::rod::model::Model,
    w: &settings::Workspace,
    ends: [(&'static str, &StaticSolution); 2],
) -> Result<(), PlanSetupError> {
    if model.angle_frame().is_some() {
        return Err(PlanSetupError::Settings(SettingsError::new(
            "workspace",
            "needs the rod's angles measured in the case's own axes (\"angle_frame\": \"case\")",
        )));
    }
    if !model.layout.spatial
        && (w.min[1].is_some_and(|lo| lo > 0.0) || w.max[1].is_some_and(|hi| hi < 0.0))
    {
        return Err(PlanSetupError::Settings(SettingsError::new(
            "workspace",
            "a planar rod lies in y = 0, which the bounds on y exclude",
        )));
    }
    let l = model.rod.length;
    for (which, sol) in ends {
        let x = model.evaluate(&sol.a).positions[model.boundary(1.0)].map(|v| v * l);
        let out = w.excess(x);
        if out > 1e-9 * l {
            return Err(PlanSetupError::End {
                end: which,
                message: format!("the end position {x:?} lies {out:.4e} outside plan.workspace"),
            });
        }
    }
    Ok(())
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
fn held_frame(base: &StaticProblem) -> ([f64; 3], bool) {
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

/// A plan replayed: its replay, its replayed equilibria as a plan where it is not executable
/// as it stands, the shapes both computed (logged if it is chosen) and the seconds they took.
struct Judged {
    replay: Replay,
    equilibrium_plan: Option<equilibrium_plan::EquilibriumPlan>,
    /// The controlled end against the workspace (`None` without one).
    workspace: Option<result::WorkspaceCheck>,
    shapes: RecordedShapes,
    seconds: f64,
    /// The optimal path coincides with its replay (collision-free and converged), or the
    /// replayed equilibria are a plan.
    executable: bool,
    /// The replayed equilibria still dipped between contact points when the retries on the
    /// case's contact samples (chords, held off) had failed: those on twice the samples
    /// ([`Planner::finer_contacts`]) may pass.
    dips_on_case_samples: bool,
}

impl Judged {
    /// Nothing replayed (the run was stopped first).
    fn not_run(tolerance: f64) -> Judged {
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
    fn best_of(&self, runs: &[StartPlan]) -> usize {
        (0..runs.len())
            .max_by(|&i, &j| self.ranked(runs, i, j))
            .expect("at least one start")
    }

    /// How `runs[i]` compares with `runs[j]` in [`Self::best_of`]'s order (greater: better).
    fn ranked(&self, runs: &[StartPlan], i: usize, j: usize) -> std::cmp::Ordering {
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
    fn judge(
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

    /// The replay of `path(z)` from the start shape under `base` (the held problem, or a copy
    /// with other contacts), with the plan's replay settings, ended early by `early_stop`.
    fn replay_under(
        &self,
        base: &StaticProblem,
        path: &DeformationPath,
        z: &[f64],
        early_stop: EarlyStop,
        observer: &mut dyn PlanObserver,
    ) -> Replay {
        replay(
            base,
            &self.start,
            path,
            z,
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
    /// (the replays of the equilibria's retries end at a solve that does not converge).
    fn judge_path(
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
                let again = pl.replay_under(held, path, z, EarlyStop::Unconverged, &mut rec);
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
                        ep.retry_failed(&what, "the start pose's solve did not converge");
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

impl Planner {
    /// Checks `settings` and solves the start and goal shapes of `problem`.
    ///
    /// ```
    /// use dlo_planner::planner::{End, PlanProblem, PlanSettings, Planner};
    /// use dlo_planner::planner::observer::Silent;
    /// use dlo_planner::rod::{Rod, layout::Layout};
    /// use dlo_planner::statics::StaticProblem;
    ///
    /// // The paper's §7.2 strip: clamped at the origin along +z, its end moved from one side
    /// // to the other with its tangent turned by a right angle either way.
    /// let rod = Rod::uniform(1.0, 1.0);
    /// let held = StaticProblem::builder(rod.clone(), Layout::of(&rod, 4))
    ///     .clamp(0.0, [0.0; 3], &[0.0])
    ///     .build()
    ///     .unwrap();
    /// let about_y = |t: f64| [[t.cos(), 0.0, t.sin()], [0.0, 1.0, 0.0], [-t.sin(), 0.0, t.cos()]];
    /// let start = End::pose(&held, [0.4, 0.0, 0.6], about_y(std::f64::consts::FRAC_PI_2));
    /// let goal = End::pose(&held, [-0.4, 0.0, 0.6], about_y(-std::f64::consts::FRAC_PI_2));
    /// let settings = PlanSettings { verify_k_samples: 51, ..PlanSettings::default() };
    /// let planner = Planner::new(PlanProblem::new(held, start, goal), settings).unwrap();
    /// let plan = planner.run(&mut Silent);
    /// assert!(plan.u_max <= plan.u_max_straight * (1.0 + 1e-9));
    /// ```
    pub fn new(problem: PlanProblem, settings: PlanSettings) -> Result<Planner, PlanSetupError> {
        let model = &problem.statics.model;
        settings.validate(model.rod.length)?;
        if model.layout.free_base {
            return Err(PlanSetupError::Problem(
                "planning holds the base fixed (the held end); a free base is not supported".into(),
            ));
        }
        let n = model.layout.len();
        if problem.initial.len() != n || problem.initial.iter().any(|x| !x.is_finite()) {
            return Err(PlanSetupError::Problem(format!(
                "the initial shape must have {n} finite coefficients, got {}",
                problem.initial.len()
            )));
        }
        problem.static_settings.validate()?;
        // Replay and endpoint solves: the problem's settings, with the optimality tolerance no
        // tighter than 1e-5 (replayed shapes are compared at the 1e-3 L level).
        let mut static_options = problem.static_settings.options();
        static_options.al.optimality_tol = static_options.al.optimality_tol.max(1e-5);
        // Newton steps of at most 0.1 per coefficient: replay and tracking solves continue from
        // the previous shape and must stay on its branch of equilibria (unlimited steps let a
        // solve jump to another equilibrium on the mesh case).
        static_options.al.max_step = static_options.al.max_step.min(0.1);
        // Full orientations take the Euler branch that continues from the held end's frame
        // (start) and from the start shape's end (goal).
        let held = held_frame(&problem.statics);
        let resolve = |end: &mut End, which: &'static str, reference: [f64; 3]| {
            end.resolve(model, reference, held.0)
                .map_err(|message| PlanSetupError::End {
                    end: which,
                    message,
                })
        };
        let (mut start_end, mut goal_end) = (problem.start.clone(), problem.goal.clone());
        resolve(&mut start_end, "start", held.0)?;
        // The grid on which an end shape resting on an obstacle must be clear.
        let verify_s = settings.verify_s_for(model.rod.radius, model.rod.length);
        let fine = end_grid(model, verify_s);
        let (start, start_contacts) = end_shape(
            &problem,
            "start",
            &start_end,
            held,
            &fine,
            &static_options,
            &settings,
        )?;
        resolve(&mut goal_end, "goal", model.angles_at(&start.a, 1.0))?;
        let (goal, _) = end_shape(
            &problem,
            "goal",
            &goal_end,
            held,
            &fine,
            &static_options,
            &settings,
        )?;
        if let Some(w) = &settings.workspace {
            check_workspace(model, w, [("start", &start), ("goal", &goal)])?;
        }
        let (linear_rows, _) = classify(&problem.statics, 0.0);
        // The replays hold the rod as the start shape is held, so that their first step
        // starts on an equilibrium of its own problem.
        let held = start_contacts.map_or_else(
            || problem.statics.clone(),
            |margin| equilibrium_plan::held_off(&problem.statics, margin),
        );
        Ok(Planner {
            held,
            start_contacts,
            contact_refinement: None,
            contact_tries: Vec::new(),
            finer_contacts: None,
            base: problem.statics,
            obstacles: problem.obstacles,
            static_options,
            start,
            goal,
            linear_rows,
            stop: Arc::new(AtomicBool::new(false)),
            budget: None,
            deadline: None,
            timed_out: Arc::new(AtomicBool::new(false)),
            quick: false,
            goal_by_pose: problem.goal.is_pose() && problem.goal.shape.is_none(),
            finer_retry: false,
            workers: workers::Workers::new(settings.threads()),
            end_grid: Arc::new((verify_s, fine)),
            settings,
        })
    }

    /// A flag that stops a run of this planner (from another thread, or a signal handler)
    /// when set: the run finishes the phase's current iteration, skips what is left (the
    /// replay among it) and returns with status [`PlanStatus::Interrupted`]. A
    /// [`PlanObserver::stop_requested`] that returns `true` sets it.
    pub fn stop_handle(&self) -> Arc<AtomicBool> {
        self.stop.clone()
    }

    /// Whether the run has been asked to stop.
    pub(crate) fn stopped(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    /// Whether the run's time limit has passed ([`PlanSettings::time_limit`]); asked only
    /// where something new would start, so that `true` is recorded as the limit having ended
    /// the search.
    pub(crate) fn time_up(&self) -> bool {
        let up = self
            .deadline
            .is_some_and(|d| std::time::Instant::now() >= d);
        if up {
            self.timed_out.store(true, Ordering::Relaxed);
        }
        up
    }

    /// Asks `observer` whether to stop, and sets the flag if so (on the run's own thread).
    pub(crate) fn poll(&self, observer: &mut dyn PlanObserver) -> bool {
        observer::poll(observer, &self.stop)
    }

    /// The optimiser's extra clearance from obstacles in units of `L` (see
    /// [`PlanSettings::safety`]).
    pub fn safety(&self) -> f64 {
        self.settings.safety(self.base.model.rod.length)
    }

    /// The start and the goal shape's worst clearances to the obstacles on the end grid
    /// ([`Self::end_check_grid`]), whatever their sign (none without obstacles).
    fn end_clearances(&self) -> Vec<EndInside> {
        let grid = self.end_check_grid();
        let fine = &grid.1;
        [("start", &self.start), ("goal", &self.goal)]
            .into_iter()
            .filter_map(|(end, sol)| {
                let w = verify::shape_worst_clearance(fine, &self.obstacles, &sol.a)?;
                Some(EndInside {
                    end,
                    obstacle: w.obstacle,
                    clearance: w.clearance,
                    s: w.s,
                })
            })
            .collect()
    }

    /// The deepest place where an end shape lies inside an obstacle on a grid four times finer
    /// in s than the verification grid, deeper than the collision tolerance, although its
    /// static solve holds it clear at the contact points (and on their chords, held off, where
    /// it dipped between them): with such an end no path is collision-free
    /// ([`PlanResult::end_inside_obstacle`]).
    pub fn end_dip(&self) -> Option<EndInside> {
        self.end_inside_obstacle(&self.end_clearances())
    }

    /// The grid the end shapes are checked on: the one the planner was made with, or where the
    /// verification grid's intervals in s have changed since, one made for them ([`end_grid`]).
    fn end_check_grid(&self) -> Arc<(usize, crate::rod::model::Model)> {
        let n = self.verify_s_intervals();
        if self.end_grid.0 == n {
            self.end_grid.clone()
        } else {
            Arc::new((n, end_grid(&self.base.model, n)))
        }
    }

    /// The deepest place among the end shapes' clearances `ends` ([`Self::end_clearances`])
    /// where one lies inside an obstacle, deeper than the collision tolerance: an end the
    /// static solve holds clear only at its contact points (see [`on_chords_if_dipping`]).
    fn end_inside_obstacle(&self, ends: &[EndInside]) -> Option<EndInside> {
        let tol = self.collision_tolerance();
        ends.iter()
            .filter(|e| e.clearance < -tol)
            .min_by(|a, b| a.clearance.total_cmp(&b.clearance))
            .cloned()
    }

    /// The verification grid's intervals in s for this rod ([`PlanSettings::verify_s_for`]).
    pub fn verify_s_intervals(&self) -> usize {
        let rod = &self.base.model.rod;
        self.settings.verify_s_for(rod.radius, rod.length)
    }

    /// Depth below which a verified clearance counts as a collision (1e-6 L).
    pub(super) fn collision_tolerance(&self) -> f64 {
        COLLISION_TOLERANCE * self.base.model.rod.length
    }

    /// Whether the case enforces self-contact.
    pub fn has_self_contact(&self) -> bool {
        self.base
            .constraints
            .iter()
            .any(|c| matches!(c, Constraint::SelfContact(_)))
    }

    /// The straight-line path `c = 0` and the path's unknowns' count.
    pub fn path(&self) -> DeformationPath {
        DeformationPath::new(
            self.start.a.clone(),
            self.goal.a.clone(),
            self.settings.path_terms,
            &self.linear_rows,
        )
    }

    /// The optimiser's problem with `blocks` from the case and the safety margin.
    pub fn minimax_problem(&self) -> MinimaxProblem {
        let nk = self.settings.k_samples;
        self.minimax_problem_at((0..nk).map(|j| j as f64 / (nk - 1) as f64).collect())
    }

    /// The optimiser's problem on the samples `ks` (increasing, from 0 to 1).
    pub fn minimax_problem_at(&self, ks: Vec<f64>) -> MinimaxProblem {
        let (_, mut blocks) = classify(&self.base, self.safety());
        if let Some(w) = &self.settings.workspace {
            blocks.push(self.workspace_rows(w).into());
        }
        let mut p = MinimaxProblem::new(
            self.base.model.clone(),
            self.path(),
            ks,
            blocks,
            self.base.objective,
        );
        p.mean_weight = self.settings.mean_weight;
        p.travel_weight = self.settings.travel_weight;
        p.set_swept(self.settings.swept());
        p.set_skip_clear_samples(true);
        p
    }

    /// The workspace as rows on the controlled end's position, held at every sample: the box
    /// shrunk by the safety margin (as obstacles are grown by it, so that the end stays inside
    /// between samples), but never past the start's and goal's own end positions.
    fn workspace_rows(&self, w: &Workspace) -> crate::constraints::PositionConstraint {
        use crate::constraints::Bound;
        let model = &self.base.model;
        let b = model.boundary(1.0);
        let ends = [&self.start.a, &self.goal.a].map(|a| model.evaluate(a).positions[b]);
        let (l, safety) = (model.rod.length, self.safety());
        let axes: &[usize] = if model.layout.spatial {
            &[0, 1, 2]
        } else {
            &[0, 2]
        };
        let mut rows = Vec::new();
        for &i in axes {
            if let Some(lo) = w.min[i] {
                let lowest = ends[0][i].min(ends[1][i]);
                rows.push((i, Bound::AtLeast((lo / l + safety).min(lowest))));
            }
            if let Some(hi) = w.max[i] {
                let highest = ends[0][i].max(ends[1][i]);
                rows.push((i, Bound::AtMost((hi / l - safety).max(highest))));
            }
        }
        crate::constraints::PositionConstraint {
            name: "workspace".into(),
            boundary: b,
            rows,
        }
    }

    /// How far the controlled end of `path(z)` leaves the workspace on the verification grid
    /// in k (case units), where, and whether within the collision tolerance: `None` without a
    /// workspace.
    pub fn workspace_check(
        &self,
        path: &DeformationPath,
        z: &[f64],
    ) -> Option<result::WorkspaceCheck> {
        let w = self.settings.workspace.as_ref()?;
        let model = &self.base.model;
        let (l, b) = (model.rod.length, model.boundary(1.0));
        let nk = self.settings.verify_k_samples;
        let mut a = vec![0.0; path.n()];
        let mut shape = Shape::default();
        let mut worst = (0.0, 0.0);
        for j in 0..nk {
            let k = j as f64 / (nk - 1) as f64;
            path.shape_at(z, k, &mut a);
            model.evaluate_into(&a, &mut shape);
            let e = w.excess(shape.positions[b].map(|v| v * l));
            if e > worst.0 {
                worst = (e, k);
            }
        }
        Some(result::WorkspaceCheck {
            largest_excess: worst.0,
            k: worst.1,
            within: worst.0 <= self.collision_tolerance(),
        })
    }

    /// The shape of `path(z)` at `k` into `a` and `shape`: its energy terms (case units) and
    /// obstacle clearance, as the log records them.
    fn path_shape(
        &self,
        path: &DeformationPath,
        z: &[f64],
        k: f64,
        a: &mut [f64],
        shape: &mut Shape,
    ) -> (crate::rod::energy::EnergyTerms, Option<f64>) {
        let model = &self.base.model;
        path.shape_at(z, k, a);
        model.evaluate_into(a, shape);
        let e = model
            .energy(a, shape, self.base.objective, None)
            .scaled(model.rod.energy_unit());
        (e, clearance(&self.base, &shape.positions))
    }

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
                return false;
            };
            // A quick plan that peaks inside the path cannot end the search: not replayed yet.
            if quick && !runs[best].plan.verification.peaks_at_an_end() {
                return false;
            }
            let j = self.judge(&runs[best], fine, observer);
            let (held, executable) = (j.replay.start_held(), j.executable);
            judged.push((best, j));
            if !held {
                return true;
            }
            // (A quick plan got here only if it attains the lower bound.)
            if quick {
                executable
            } else {
                judged.iter().any(|(_, j)| j.executable)
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
    /// ([`PlanSettings::straight_path_first`]), else the best of the starts. With
    /// [`PlanSettings::time_limit`], the search starts nothing new once the limit has passed
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

    /// The search of [`Planner::run`]: the plan, and its replay's shapes, not yet logged.
    fn search(&self, observer: &mut dyn PlanObserver) -> (PlanResult, RecordedShapes) {
        let model = &self.base.model;
        observer.phase("endpoints");
        for (k, sol) in [(0.0, &self.start), (1.0, &self.goal)] {
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
        // The plan is the equilibria along the straight path's trajectory.
        let mut along_straight = false;
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
                        along_straight = true;
                        (Vec::new(), None, j)
                    }
                    None => {
                        let (runs, best, judged) = self.optimise_and_judge(&fine, observer);
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
            let mut s = self.judge_straight_trajectory(&fine, observer);
            if s.executable {
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
                if let Some(e) = s.equilibrium_plan.as_mut() {
                    e.optimal_path_not_executable = Some(why);
                }
                judged = s;
                along_straight = true;
            } else if let (Some(e), Some(s)) =
                (judged.equilibrium_plan.as_mut(), &s.equilibrium_plan)
            {
                e.retry_failed_as("along the straight path's trajectory", s);
            }
        }
        let t_plan = t0.elapsed().as_secs_f64() - judged.seconds;

        observer.phase("replay");
        // Along the straight path, the replay recorded the straight path's shapes as its
        // optimal ones (logged as the straight path's already): the log's optimal path is the
        // optimiser's.
        if along_straight {
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
        let (traj_path, traj_z) = if along_straight {
            (&straight_path, &straight_z)
        } else {
            (&path, &chosen.z)
        };
        let trajectory = trajectory::Trajectory::along(model, traj_path, traj_z, &ks);
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

/// The planner of the shipped paper case (`planning_cases/plan_paper_planar.json`), for the
/// planner's unit tests.
#[cfg(test)]
pub(crate) fn paper_planner() -> Planner {
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("planning_cases/plan_paper_planar.json");
    let case = crate::case::load(&file).expect("the shipped case loads");
    Planner::from_case(&case).expect("the shipped case plans")
}
