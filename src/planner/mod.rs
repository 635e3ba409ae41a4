//! Deformation path planning (paper §7): the minimax-energy path in coefficient space between
//! two static shapes, verified on a finer grid and replayed by the controlled end alone.
//!
//! [`Planner::new`] (or [`Planner::from_case`]) solves the start and goal shapes; [`Planner::run`] optimises, verifies
//! and replays, telling a [`PlanObserver`] every shape it computes.

mod clear_samples;
pub mod contact_samples;
pub mod end_course;
mod end_shapes;
pub mod endpoints;
pub mod equilibrium_plan;
pub mod equilibrium_slopes;
mod judge;
pub mod minimax;
pub mod observer;
pub mod orientation;
pub mod path;
pub mod pose_line;
pub mod pose_optimisation;
mod reached_goal;
pub mod replay;
pub mod result;
mod search;
pub mod settings;
mod start;
mod starts;
mod straight_path;
pub mod swept;
mod tracking;
pub mod trajectory;
pub mod verify;
pub mod workers;

use crate::constraints::Constraint;
pub use crate::error::SettingsError;
use crate::planner::path::DeformationPath;
use crate::rod::kinematics::Shape;
use crate::scene::obstacle::Obstacle;
use crate::statics::problem::StaticProblem;
use crate::statics::{StaticOptions, StaticSettings, StaticSolution};
use end_shapes::{end_grid, end_shape, held_frame};
pub use endpoints::End;
use minimax::MinimaxProblem;
use observer::PlanObserver;
pub use settings::{EarlyStages, Optimiser, PlanSettings, PoseOptimisation, Workspace};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

pub use result::{
    Attempt, ContactRefinement, ContactTry, EndInside, PlanReport, PlanResult, PlanStatus,
    PlanVerdict, ReachedGoal, StartSummary, Timing, VerificationGrid,
};

/// Depth (a fraction of L) below which a verified clearance counts as a collision.
const COLLISION_TOLERANCE: f64 = 1e-6;

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
    /// Positions (units of L) of an equilibrium of the goal pose, other than the goal shape,
    /// on which replayed equilibria may end: set on the copy that judges a plan's equilibria
    /// again where the gripper's motion reaches that equilibrium and no plan to it executes
    /// ([`PlanSettings::reached_goal`]).
    ends_on: Option<Arc<Vec<[f64; 3]>>>,
    /// The course the replays hold the end on instead of the end poses of the path they
    /// replay (a pose line, or a path's end poses with optimised terms): set on the copy that
    /// judges the equilibria along it ([`pose_line`], [`pose_optimisation`]).
    drive: Option<Arc<end_course::EndCourse>>,
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
            ends_on: None,
            drive: None,
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
        let model = &self.base.model;
        self.settings.safety(model.rod.length, model.layout.spatial)
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
    /// static solve holds clear only at its contact points (see [`on_chords_if_dipping`](end_shapes::on_chords_if_dipping)).
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

    /// How far the controlled end of `path(z)` (of the pose line this planner drives the end
    /// on, if any) leaves the workspace on the verification grid in k (case units), where, and
    /// whether within the collision tolerance: `None` without a workspace.
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
            let x = match &self.drive {
                Some(course) => course.pose_at(model, k).0,
                None => {
                    path.shape_at(z, k, &mut a);
                    model.evaluate_into(&a, &mut shape);
                    shape.positions[b]
                }
            };
            let e = w.excess(x.map(|v| v * l));
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
