//! What a plan run reports: its status, the chosen plan's numbers, every start, the replay and
//! the timings.

use super::replay::Replay;
use super::verify::Verification;
use crate::optim::AlStatus;
use serde::Serialize;

/// How a plan ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PlanStatus {
    /// The optimiser converged (or the straight-line path attains the lower bound on `U_max`,
    /// [`PlanResult::straight_path_plan`]) and the verification grid is collision-free.
    Planned,
    /// The verification grid finds a collision (e.g. tunnelling between samples).
    Collision,
    /// The controlled end leaves the workspace on the verification grid.
    OutsideWorkspace,
    /// The optimiser did not converge (the path may still be collision-free).
    NotConverged,
    /// The run was stopped ([`super::Planner::stop_handle`]): the plan is the best found so
    /// far, verified; the replay did not run or did not finish.
    Interrupted,
}

impl std::fmt::Display for PlanStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            PlanStatus::Planned => "planned",
            PlanStatus::Collision => "collision",
            PlanStatus::OutsideWorkspace => "outside the workspace",
            PlanStatus::NotConverged => "not converged",
            PlanStatus::Interrupted => "interrupted",
        })
    }
}

/// What a plan run means for a robot: whether moving the controlled end along the plan's
/// trajectory deforms the rod as planned, and if not, why.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PlanVerdict {
    /// Converged, collision-free on the verification grid, and the replay by the controlled
    /// end coincides with the plan: the gripper trajectory executes it.
    Executable,
    /// Converged and collision-free, but the replay departs from the plan by more than the
    /// coincidence tolerance without snapping.
    Departs,
    /// Converged and collision-free, but the replay snaps through (jumps to another
    /// equilibrium) somewhere along the path.
    SnapsThrough,
    /// The verification grid finds the rod inside (or closer than its radius and margin to)
    /// an obstacle.
    ObstacleCollision,
    /// The verification grid finds the rod crossing itself.
    SelfCollision,
    /// The controlled end leaves the workspace (`plan.workspace`) on the verification grid.
    OutsideWorkspace,
    /// The path optimiser did not converge.
    NotConverged,
    /// The run was stopped before it finished.
    Interrupted,
    /// No static shape reaches the start or the goal: nothing was planned
    /// ([`super::PlanSetupError::Unreachable`]; never the verdict of a [`PlanResult`]).
    Unreachable,
}

impl PlanVerdict {
    /// Whether the controlled end's trajectory executes the plan.
    pub fn is_executable(self) -> bool {
        self == PlanVerdict::Executable
    }
}

impl std::fmt::Display for PlanVerdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            PlanVerdict::Executable => "executable",
            PlanVerdict::Departs => "not executable: the replay departs from the plan",
            PlanVerdict::SnapsThrough => "not executable: the replay snaps through",
            PlanVerdict::ObstacleCollision => "collision with an obstacle",
            PlanVerdict::SelfCollision => "the rod crosses itself",
            PlanVerdict::OutsideWorkspace => "the controlled end leaves the workspace",
            PlanVerdict::NotConverged => "the path optimiser did not converge",
            PlanVerdict::Interrupted => "interrupted",
            PlanVerdict::Unreachable => "no static shape reaches the start or the goal",
        })
    }
}

/// The attempt an optimiser start belongs to ([`StartSummary::attempt`]), in the order they
/// run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Attempt {
    /// A planar rod's first attempt: the first group of `parallel_starts` starts, with the
    /// case's path terms and objective, their sharpness stages carrying the optimiser's
    /// curvature and penalty from stage to stage and ending at the first converged stage whose
    /// samples peak at an end shape (or inside the path, more than a quarter above the larger
    /// end energy). Its plan ends the search only when it is executable and attains the lower
    /// bound on `U_max` (the larger end energy).
    Quick,
    /// The case's own path terms and objective (on a planar rod, every stage restarting the
    /// optimiser's curvature and penalty).
    Own,
    /// A `fallback_path_terms` count.
    Fallback,
    /// The case's path terms without the travel term (the paper's objective).
    WithoutTravel,
    /// The case's path terms without the travel term and with tracking's fixed targets
    /// (`equilibrium_slopes` off: every sample pulled onto the equilibrium of the pose it had
    /// when the round began): the last attempt, where the slopes' plans all fail.
    FixedTargets,
    /// A converged plan, collision-free but not executable (the quick attempt's where it
    /// attains the lower bound on `U_max`, or the case's own), lifted to the first fallback count's path
    /// terms (the new terms zero, the same path) and tracked again, with no sharpness stage:
    /// tracking pulls the shapes onto their equilibria with the extra terms' freedom. Its
    /// `status` is its tracking's, or its source's where no tracking round ran.
    Lifted,
}

impl Attempt {
    /// The attempt's name as the JSON report spells it.
    pub fn name(self) -> &'static str {
        match self {
            Attempt::Quick => "quick",
            Attempt::Own => "own",
            Attempt::Fallback => "fallback",
            Attempt::WithoutTravel => "without_travel",
            Attempt::FixedTargets => "fixed_targets",
            Attempt::Lifted => "lifted",
        }
    }
}

/// Summary of one optimiser start.
#[derive(Clone, Debug, Serialize)]
pub struct StartSummary {
    /// Start index, in the order the attempts run: the quick attempt's starts (planar rods),
    /// the case's own, then each fallback path-term count's, then those without the travel
    /// term, a lifted plan's ([`Attempt::Lifted`]) right after the group it was lifted from;
    /// each attempt has `starts` indices, used or not (the quick attempt uses its first
    /// `parallel_starts`, a lifted attempt its first).
    pub start: usize,
    /// The attempt the start belongs to.
    pub attempt: Attempt,
    /// Path terms `m` of the start's path.
    pub path_terms: usize,
    /// Weight of the travel term in the start's objective: the case's `travel_weight`, or 0
    /// for the last fallback's starts (the paper's objective).
    pub travel_weight: f64,
    /// Whether the start's optimiser held the swept-clearance rows: the case's
    /// `swept_clearance`, or on in the attempts after one whose plans all tunnelled through an
    /// obstacle between their samples.
    pub swept_clearance: bool,
    /// Final optimiser status.
    pub status: AlStatus,
    /// Largest sampled energy (case units).
    pub sampled_u_max: f64,
    /// `U_max` of the start's plan on the verification grid (case units).
    pub u_max: f64,
    /// Whether the start's plan keeps clear of every obstacle on the verification grid.
    pub collision_free: bool,
    /// Constraint violation (dimensionless).
    pub violation: f64,
    /// Objective evaluations.
    pub evaluations: usize,
    /// Equilibrium-tracking rounds run (at most `equilibrium_rounds`; fewer when the sampled
    /// shapes already lie on their equilibria or a round stops bringing them closer).
    pub tracking_rounds: usize,
    /// Of those, the rounds whose result the plan keeps: a round that leaves the sampled shapes
    /// farther from their equilibria is undone.
    pub tracking_rounds_kept: usize,
    /// The start's sampled shapes' largest distance to the equilibria their end poses produce,
    /// after tracking (fraction of L): the replay's deviation estimated on the samples, which
    /// decides whether a further group of starts runs (`null` when not measured).
    pub equilibrium_deviation: Option<f64>,
}

/// The outcome of [`super::Planner::run`].
#[derive(Clone, Debug, Serialize)]
pub struct PlanResult {
    /// Overall status.
    pub status: PlanStatus,
    /// Optimiser status of the chosen start (`None` when the plan is the straight-line path,
    /// taken without optimising: [`PlanResult::straight_path_plan`]).
    pub optimiser: Option<AlStatus>,
    /// The plan is the straight-line path `c = 0`, taken before any optimisation because it
    /// attains the lower bound on every path's `U_max` (the larger end energy), keeps the
    /// safety margin from the obstacles and coincides with its replay
    /// ([`super::PlanSettings::straight_path_first`]); `starts` is then empty.
    pub straight_path_plan: bool,
    /// An end shape that lies inside an obstacle on a grid four times finer in s than the
    /// verification grid, deeper than the collision tolerance, although its static solve holds
    /// it clear at the contact points (and on their chords, then held off the obstacles, tried
    /// when it dips): every path starts or ends there, so none is
    /// collision-free, and the planner does not optimise (`starts` is empty, the replay is not
    /// run, the status is `collision`).
    pub end_inside_obstacle: Option<EndInside>,
    /// Where the case's contact samples (`discretisation.samples`) let an end shape dip into an
    /// obstacle between them and the plan was made with more ([`ContactRefinement`]); absent
    /// otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_samples: Option<ContactRefinement>,
    /// The plans made again with more contact samples whose end shape still dipped into an
    /// obstacle between them (or whose end solves failed), in the order tried
    /// ([`ContactTry`]); absent where none was.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub contact_samples_tried: Vec<ContactTry>,
    /// True `U_max` of the plan on the verification grid (case units).
    pub u_max: f64,
    /// `k` where it occurs.
    pub k_at_u_max: f64,
    /// The largest energy on the optimiser's own `k` samples for the plan (case units): the
    /// value it minimised, which `u_max` exceeds where a peak falls between samples.
    pub sampled_u_max: f64,
    /// `U_max` of the straight-line path `c = 0` (case units).
    pub u_max_straight: f64,
    /// Smallest obstacle clearance on the verification grid, optimal path (case units).
    pub min_clearance: Option<f64>,
    /// Smallest obstacle clearance of the straight-line path (case units): on the verification
    /// grid, and between its values only where the path could pass through an obstacle
    /// unseen (the depth of a penetration the grid already sees is not refined there).
    pub min_clearance_straight: Option<f64>,
    /// Largest violation of the optimiser's sampled constraints (dimensionless).
    pub violation: f64,
    /// Verification details of the plan.
    pub verification: Verification,
    /// Every start that ran.
    pub starts: Vec<StartSummary>,
    /// The time limit ([`super::PlanSettings::time_limit`]) ended the search: a sharpness
    /// stage, refinement rerun, tracking round, group of starts or attempt that would have
    /// run did not. The plan is the best one found before it.
    pub time_limit_reached: bool,
    /// Starts of the case's own attempt ([`Attempt::Own`]) that did not run: with
    /// `parallel_starts` below `starts`, a group of starts runs only while no plan replayed so
    /// far is executable, and none runs after an executable quick plan that attains the lower
    /// bound, or once the time limit has passed ([`PlanResult::time_limit_reached`]).
    pub starts_not_run: usize,
    /// Path terms `m` of the plan: the case's `path_terms`, or the fallback count its start
    /// used.
    pub path_terms: usize,
    /// The start the plan comes from: collision-free first, then feasible on the samples, then
    /// estimated to coincide, then the lowest verified `U_max` (`None`: the straight-line
    /// path, no start ran).
    pub chosen_start: Option<usize>,
    /// Path vectors `cᵢ` (coefficient space).
    pub path: Vec<Vec<f64>>,
    /// The unknowns `z` of the plan's path ([`super::Planner::path_of`]).
    #[serde(skip)]
    pub z: Vec<f64>,
    /// Feasibility replay.
    pub replay: Replay,
    /// Where the optimal path is not executable as it stands (its replay departs or snaps,
    /// or it collides): the replayed equilibria along its trajectory as a plan, checked and
    /// confirmed (`null` when the optimal path's replay coincides, or the run was stopped).
    pub equilibrium_plan: Option<super::equilibrium_plan::EquilibriumPlan>,
    /// With `plan.workspace`: how far the controlled end leaves it on the verification grid.
    pub workspace: Option<WorkspaceCheck>,
    /// The controlled end's pose at every replay step (what a robot holding it follows) and
    /// the held end's pose.
    pub trajectory: super::trajectory::Trajectory,
    /// `k` samples added where the verification grid found tunnelling or a missed energy peak.
    pub added_samples: Vec<f64>,
    /// Seconds spent planning (optimise + verify) and replaying.
    pub timing_s: Timing,
    /// Where the plan ends on another equilibrium of the goal pose than the one its static
    /// solve found ([`super::PlanSettings::reached_goal`]): that solve's shape and the one
    /// the plan ends on. Absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reached_goal: Option<ReachedGoal>,
}

/// The goal shape a plan ends on where it is not the one the goal pose's static solve found
/// ([`PlanResult::reached_goal`]): no plan to that one was executable, and the gripper's
/// motion along a trajectory of the search (the best plan's, the straight-line path's or a
/// pose line) brought the rod to this equilibrium of the same pose (stable, clear of the
/// obstacles), so the plan was made again to it, or, where that plan was not executable, that
/// motion's replayed equilibria are the plan ([`ReachedGoal::replanned`]).
#[derive(Clone, Debug, Serialize)]
pub struct ReachedGoal {
    /// Internal energy of the goal shape the static solve found (case units).
    pub solved_energy: f64,
    /// Internal energy of the goal shape the plan ends on (case units).
    pub energy: f64,
    /// Largest distance between the two shapes (fraction of L).
    pub distance_over_l: f64,
    /// Ritz coefficients of the goal shape the plan ends on (where [`ReachedGoal::replanned`],
    /// the plan's path runs from the start shape to it: [`super::Planner::path_of`]).
    pub shape: Vec<f64>,
    /// Why the first plan was not executable: its verdict and what its equilibria met.
    pub first_plan: String,
    /// Where the plan made again to a reached goal shape was not executable: its verdict
    /// (saying so where it was made to another equilibrium the first search reached); the plan
    /// is then replayed equilibria of the first search, which end on this shape (along the
    /// trajectory [`super::equilibrium_plan::EquilibriumPlan::trajectory`] names), and the first plan's path
    /// still ends on the goal shape the static solve found. Absent where the plan is the one
    /// made again ([`ReachedGoal::replanned`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub replan_failed: Option<String>,
    /// Seconds the first plan's search took (in [`PlanResult::timing_s`] too).
    pub first_plan_seconds: f64,
}

impl ReachedGoal {
    /// The plan was made again to this goal shape and is that plan (no
    /// [`ReachedGoal::replan_failed`]).
    pub fn replanned(&self) -> bool {
        self.replan_failed.is_none()
    }
}

impl PlanResult {
    /// What the gripper trajectory executes: `"optimal"`, the optimal path itself (collision-free,
    /// converged, and its replay coincides), else `"equilibria"`, the replayed equilibria along
    /// its trajectory, or along the straight-line path's or a pose line when no optimised path
    /// executes (`equilibrium_plan.trajectory`; see [`super::equilibrium_plan`]), else nothing.
    pub fn executed_path(&self) -> Option<&'static str> {
        if self.workspace.as_ref().is_some_and(|w| !w.within) {
            return None;
        }
        // Along another trajectory, the replay is that trajectory's.
        if self.status == PlanStatus::Planned
            && self.replay.coincide
            && !self.along_other_trajectory()
        {
            Some("optimal")
        } else if self.equilibrium_plan.as_ref().is_some_and(|e| e.executable) {
            Some("equilibria")
        } else {
            None
        }
    }

    /// Whether the replayed equilibria judged as the plan follow the straight-line path's end
    /// poses (`equilibrium_plan.trajectory` is `"straight_path"`).
    pub fn along_straight_trajectory(&self) -> bool {
        self.equilibrium_plan
            .as_ref()
            .is_some_and(|e| e.trajectory == "straight_path")
    }

    /// Whether the replayed equilibria judged as the plan follow a pose line
    /// (`equilibrium_plan.trajectory` is `"pose_line"`, [`super::pose_line`]): how it leaves
    /// the straight line, if so.
    pub fn along_pose_line(&self) -> Option<super::pose_line::Detour> {
        self.equilibrium_plan.as_ref().and_then(|e| e.pose_line())
    }

    /// Whether the replay is not the optimal path's: it followed the straight-line path's end
    /// poses, a pose line, or a course optimised in the end's pose space
    /// ([`super::pose_optimisation`]; the optimal path's end poses with terms added).
    pub fn along_other_trajectory(&self) -> bool {
        self.equilibrium_plan
            .as_ref()
            .is_some_and(|e| e.trajectory != "optimal_path" || e.pose_terms.is_some())
    }

    /// The verdict: executable, or why not.
    pub fn verdict(&self) -> PlanVerdict {
        match self.status {
            PlanStatus::Interrupted => PlanVerdict::Interrupted,
            _ if self.executed_path().is_some() => PlanVerdict::Executable,
            PlanStatus::Collision if self.min_clearance.is_none_or(|c| c >= 0.0) => {
                PlanVerdict::SelfCollision
            }
            PlanStatus::Collision => PlanVerdict::ObstacleCollision,
            PlanStatus::OutsideWorkspace => PlanVerdict::OutsideWorkspace,
            PlanStatus::NotConverged => PlanVerdict::NotConverged,
            PlanStatus::Planned if self.replay.coincide => PlanVerdict::Executable,
            PlanStatus::Planned if !self.replay.snaps.is_empty() => PlanVerdict::SnapsThrough,
            PlanStatus::Planned => PlanVerdict::Departs,
        }
    }
}

/// The contact samples a case's plan was made with where the case's own let an end shape dip
/// into an obstacle between them ([`PlanResult::contact_samples`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ContactRefinement {
    /// The case's `discretisation.samples`.
    pub case_samples: usize,
    /// The samples the plan was made with (twice or four times the case's).
    pub samples: usize,
    /// Where the end shape dipped with the case's samples.
    pub dipped: EndInside,
}

/// A case's plan made again with more contact samples, whose end shape still dipped into an
/// obstacle between them, or whose end solves failed ([`PlanResult::contact_samples_tried`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ContactTry {
    /// The contact samples it was made with.
    pub samples: usize,
    /// Where its end shape dipped deepest; `None` where its start or goal found no static
    /// shape (the last try then).
    pub dipped: Option<EndInside>,
}

/// Where an end shape lies inside an obstacle ([`PlanResult::end_inside_obstacle`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EndInside {
    /// `"start"` or `"goal"`.
    pub end: &'static str,
    /// The obstacle's name.
    pub obstacle: String,
    /// Its clearance there (case units; negative: the depth).
    pub clearance: f64,
    /// Where along the rod (case units).
    pub s: f64,
}

/// The controlled end against the workspace, on the verification grid in k.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct WorkspaceCheck {
    /// The largest distance outside the box (case units; 0 when it stays inside).
    pub largest_excess: f64,
    /// `k` where it occurs.
    pub k: f64,
    /// Within the collision tolerance (1e-6 L).
    pub within: bool,
}

/// Wall-clock times.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Timing {
    /// Start and goal solves.
    pub endpoints: f64,
    /// Optimisation and verification.
    pub plan: f64,
    /// Replay.
    pub replay: f64,
}

/// A plan's report: what `dlo plan --json` prints (and the Python package returns), the
/// result with its verdict, the end shapes' energies and, when the run wrote them, its files.
#[derive(Clone, Debug, Serialize)]
pub struct PlanReport<'a> {
    /// Case name.
    pub case: &'a str,
    /// Executable, or why not.
    pub verdict: PlanVerdict,
    /// What the gripper trajectory executes when executable: `"optimal"` or `"equilibria"`
    /// ([`PlanResult::executed_path`]).
    pub executed_path: Option<&'static str>,
    /// The result.
    #[serde(flatten)]
    pub result: &'a PlanResult,
    /// The verification grid the plan was checked on.
    pub verification_grid: VerificationGrid,
    /// Internal energy of the start shape (case units).
    pub start_energy: f64,
    /// Internal energy of the goal shape (case units): the one the plan ends on
    /// ([`PlanResult::reached_goal`]).
    pub goal_energy: f64,
    /// The MCAP log written.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mcap: Option<String>,
    /// Shapes in that log.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub log_shapes: Option<u64>,
    /// The gripper trajectory's CSV file written.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub trajectory_csv: Option<String>,
}

/// The verification grid of a plan ([`PlanReport::verification_grid`]).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct VerificationGrid {
    /// Uniform samples of `k` (`verify_k_samples`).
    pub k_samples: usize,
    /// Uniform intervals of `s`: `verify_s_samples`, finer for a rod thinner than 0.005 L
    /// ([`super::Planner::verify_s_intervals`]).
    pub s_intervals: usize,
}

impl<'a> PlanReport<'a> {
    /// The report of `result`, planned by `planner`, without files.
    pub fn new(case: &'a str, planner: &super::Planner, result: &'a PlanResult) -> Self {
        PlanReport {
            case,
            verdict: result.verdict(),
            executed_path: result.executed_path(),
            result,
            verification_grid: VerificationGrid {
                k_samples: planner.settings.verify_k_samples,
                s_intervals: planner.verify_s_intervals(),
            },
            start_energy: planner.start.energy.internal(),
            goal_energy: result
                .reached_goal
                .as_ref()
                .map_or(planner.goal.energy.internal(), |g| g.energy),
            mcap: None,
            log_shapes: None,
            trajectory_csv: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Attempt;

    /// Each attempt's name (the CLI's summary) is the JSON report's spelling.
    #[test]
    fn attempt_names_are_the_json_spelling() {
        for a in [
            Attempt::Quick,
            Attempt::Own,
            Attempt::Fallback,
            Attempt::WithoutTravel,
            Attempt::FixedTargets,
            Attempt::Lifted,
        ] {
            assert_eq!(serde_json::to_value(a).expect("serialises"), a.name());
        }
    }
}
