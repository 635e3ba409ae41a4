//! The settings of a plan: one struct, with the case file's names (the `plan` section's keys
//! other than `start` and `goal`), defaults and validation. [`super::Planner::new`] takes it.

use super::replay::{EarlyStop, ReplayOptions};
use serde::{Deserialize, Serialize};

/// How a plan is computed: the path's form, the optimiser's samples and continuation, the
/// starts, the verification grid and the replay. Every field is a key of a case file's `plan`
/// section (`docs/case-files.md` documents them); [`Default`] gives the defaults a case file
/// gets.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default, expecting = "an object of plan settings")]
pub struct PlanSettings {
    /// Path terms `m` (paper: 3).
    pub path_terms: usize,
    /// Path-term counts tried in turn, with the same starts, while no plan so far is
    /// executable. Default (absent): `[6, 8]` on a planar rod, none
    /// on a 3D rod (see [`PlanSettings::fallback_terms`]).
    pub fallback_path_terms: Option<Vec<usize>>,
    /// Objective evaluations each start of the planar quick attempt and of an attempt after
    /// the case's own (a lifted plan, a fallback's, or the last one's without the travel term)
    /// may use: its sharpness stages, tracking rounds and sample refinements stop once it has
    /// (checked between them), and its status is then `iteration_limit`. It bounds what a
    /// search that finds nothing spends in those attempts; the plans they found on the
    /// generated suite used less (docs/notes/plan-settings.md).
    pub fallback_evaluations: usize,
    /// Samples of `k` seen by the optimiser, including 0 and 1.
    pub k_samples: usize,
    /// Samples of `k` on the verification grid.
    pub verify_k_samples: usize,
    /// Intervals of `s` on the verification grid of a rod at least [`THIN_ROD`] L thick; a
    /// thinner rod's grid is finer ([`PlanSettings::verify_s_for`]).
    pub verify_s_samples: usize,
    /// Extra clearance (case length units) the optimiser keeps from obstacles, so that the path
    /// between its samples stays clear. Default `L/50` on a planar rod, `L/100` on a 3D one
    /// ([`PlanSettings::safety`]).
    pub safety_margin: Option<f64>,
    /// Weight of the mean energy along the path in the objective (docs/algorithms.md, step 4).
    pub mean_weight: f64,
    /// Weight of the controlled end's travel in the objective, `½ w ∫ |dx/dk|² dk` with `x` in
    /// units of `L` (energies are in `Rf/L`): a tie-break that keeps the gripper's path short
    /// and even among paths of nearly equal peak energy, and near the equilibria their end
    /// poses produce. Default 0.5 (`docs/results.md` gives what other weights do on the
    /// generated suite); 0 is the paper's objective.
    pub travel_weight: f64,
    /// Weight of the equilibrium-tracking term (0 = the paper's objective alone). Default
    /// (absent): 10,000 on a planar rod, 0 on a 3D rod (see [`PlanSettings::tracking_weight`]).
    pub equilibrium_weight: Option<f64>,
    /// Most rounds of equilibrium tracking (replay at the samples, then re-optimise).
    pub equilibrium_rounds: usize,
    /// Tracking stops once the sampled shapes lie within this fraction of
    /// `coincide_tolerance` from their equilibria (0: only the rounds' budget and their
    /// progress stop it). Default (absent): 0.5 on a planar rod, 0.1 on a 3D rod (see
    /// [`PlanSettings::tracking_stop`]).
    pub equilibrium_stop: Option<f64>,
    /// Whether each tracking target follows its sample's own end pose through the slopes of
    /// its equilibrium (`src/planner/equilibrium_slopes.rs`); `false` pulls every sample onto
    /// the equilibrium of the pose it had when the round began (fixed targets). Default
    /// `true`.
    pub equilibrium_slopes: bool,
    /// Continuation of the smoothed maximum's sharpness, in units of `1/U_ref`.
    pub sharpness: Vec<f64>,
    /// Independent optimiser starts (run in parallel, each verified and refined on its own; the
    /// collision-free one with the lowest verified `U_max` wins).
    pub starts: usize,
    /// Starts run side by side in groups of this many; a group runs only when no plan of an
    /// earlier group is executable (default: all starts at once).
    pub parallel_starts: Option<usize>,
    /// Threads a start's path optimisation splits its sampled shapes over (the plan is the same
    /// bit for bit on any number). Default (absent): every core the process may use, at most
    /// 4; set 1 where several plans run side by side (a batch, a process pool). Starts that
    /// run side by side take one each.
    pub threads: Option<usize>,
    /// Seed of the starts' pseudo-random perturbations.
    pub seed: u64,
    /// Size (radians) of the extra starts' perturbations.
    pub start_spread: f64,
    /// Rounds of adding samples where the verification grid finds tunnelling or an energy peak
    /// the samples missed.
    pub sample_refinements: usize,
    /// Relative excess of the verification grid's `U_max` over the optimiser's sampled maximum
    /// beyond which the peak's `k` is added to the samples.
    pub energy_gap_tolerance: f64,
    /// Replay steps in `k` (refined where the replayed shape jumps).
    pub replay_steps: usize,
    /// Largest number of bisections of one replay step.
    pub replay_refinements: usize,
    /// The paths coincide when `max_k d(k) ≤ tolerance · L`.
    pub coincide_tolerance: f64,
    /// Inner minimiser of the path optimisation's multiplier method.
    pub optimiser: Optimiser,
    /// How far the sharpness stages before the sharpest converge ([`EarlyStages`]).
    pub early_stages: EarlyStages,
    /// Keep the chord between consecutive samples' positions of every obstacle sample point
    /// clear (see [`super::swept`]): `Some(true)` in every attempt, `Some(false)` in none, and
    /// `None` (the default) in the attempts after one whose plans all tunnel through an
    /// obstacle between their samples ([`PlanSettings::swept`]).
    pub swept_clearance: Option<bool>,
    /// Where the optimal path's replay departs from it (or the path collides), accept the
    /// replayed equilibria along its trajectory as the plan when they pass their checks (see
    /// [`super::equilibrium_plan`]); `false`: only an optimal path that coincides with its
    /// replay is executable, as in the paper.
    pub equilibrium_plans: bool,
    /// Bounds on the controlled end's position along the plan (a robot's reach), in case
    /// units and axes; absent: none.
    pub workspace: Option<Workspace>,
    /// Before optimising, take the straight-line path `c = 0` as the plan when it already
    /// attains the lower bound on every path's `U_max` — its largest energy on the
    /// verification grid is at an end, and every path passes through both ends — keeps the
    /// safety margin from every obstacle, and coincides with its replay (see
    /// [`super::Planner::run`]); `false`: always optimise, as in the paper.
    pub straight_path_first: bool,
    /// On a planar rod, run the quick attempt first ([`super::Attempt::Quick`]): the first
    /// group of starts with their sharpness stages carrying the optimiser's curvature, whose
    /// plan ends the search only when it is executable and attains the lower bound on `U_max`;
    /// `false`: only the case's own attempt and those after it (no effect on a 3D rod, whose
    /// own stages carry the curvature).
    pub quick_attempt: bool,
    /// Solve each end pose (without a `shape`) also from the rods bent towards it that a pose
    /// the first solve misses is searched from ([`super::endpoints::retry_seeds`]), and take
    /// the stable shape with the least energy of all that converge; `false` (default): the
    /// first solve's shape, where it converges.
    pub least_energy_ends: bool,
    /// A goal given by its pose alone (no `shape`): where no plan to the goal shape its static
    /// solve found is executable, but the gripper's motion along a trajectory of the search
    /// (the best plan's, the straight-line path's or a pose line) brings the rod to another
    /// equilibrium of the goal pose — every solve of its replay converged, stable, clear of
    /// the obstacles, nothing snapping — plan again to that equilibrium, and report the plan
    /// to it where it is executable, else that motion's equilibria where they pass
    /// ([`super::PlanResult::reached_goal`]); `false`: only the end solve's goal shape.
    pub reached_goal: bool,
    /// Where neither an optimised path nor the straight-line path executes by its replayed
    /// equilibria, try the equilibria along lines in the end's pose space, lifted against
    /// gravity by 0, 0.15, 0.3 and 0.5 L mid-way, then on a 3D rod moved aside across the
    /// straight line by 0.3 and 0.5 L either way ([`super::pose_line::DETOURS`]); `false`:
    /// not.
    pub pose_lines: bool,
    /// Which courses of the controlled end whose equilibria are the plan get terms on the
    /// end's position that lower the peak energy of the equilibria the gripper passes through,
    /// taken where their equilibria are a plan with a lower peak
    /// ([`super::pose_optimisation`]).
    pub pose_optimisation: PoseOptimisation,
    /// Lift a converged plan that is collision-free but not executable — the quick attempt's
    /// where it attains the lower bound on `U_max`, the case's own wherever it peaks — to the
    /// first fallback count's path terms and run equilibrium tracking on it again
    /// ([`super::Attempt::Lifted`]), before the next attempt, once per search; `false`: never.
    pub lift: bool,
    /// Wall-clock seconds the search may take, counted from the start of
    /// [`super::Planner::run`] (the end shapes, solved when the planner is made, are not
    /// counted): once they have passed, nothing new starts — no further sharpness stage of a
    /// start (its first always runs), refinement rerun, equilibrium-tracking round, group of
    /// starts or attempt — and the best plan so far is judged by its replay as usual (the
    /// replay is not limited; what is in progress finishes). A start whose sharpness
    /// stages are cut short says `iteration_limit` (one whose tracking or refinement is cut
    /// keeps its stages' status), and [`super::PlanResult::time_limit_reached`] says that the
    /// limit ended the search. A plan under a time limit depends on the machine's speed;
    /// without one (the default) it is the same bit for bit on any machine and number of
    /// threads.
    pub time_limit: Option<f64>,
}

/// An axis-aligned box the controlled end's position must stay in: `min ≤ x(L) ≤ max` per
/// component, in case units and axes; a `null` component is unbounded.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "bounds on the controlled end `{\"min\": [x, y, z], \"max\": [x, y, z]}`"
)]
pub struct Workspace {
    /// Lower bounds (x, y, z).
    #[serde(default)]
    pub min: [Option<f64>; 3],
    /// Upper bounds (x, y, z).
    #[serde(default)]
    pub max: [Option<f64>; 3],
}

impl Workspace {
    /// How far `p` (case units) lies outside the box (0 inside).
    pub fn excess(&self, p: [f64; 3]) -> f64 {
        (0..3)
            .map(|i| {
                let below = self.min[i].map_or(0.0, |lo| lo - p[i]);
                let above = self.max[i].map_or(0.0, |hi| p[i] - hi);
                below.max(above).max(0.0)
            })
            .fold(0.0, f64::max)
    }
}

impl Default for PlanSettings {
    fn default() -> Self {
        PlanSettings {
            path_terms: d_terms(),
            fallback_path_terms: None,
            fallback_evaluations: d_fallback_evaluations(),
            k_samples: d_k(),
            verify_k_samples: d_vk(),
            verify_s_samples: d_vs(),
            safety_margin: None,
            mean_weight: d_mean(),
            travel_weight: d_travel(),
            equilibrium_weight: None,
            equilibrium_rounds: d_rounds(),
            equilibrium_stop: None,
            equilibrium_slopes: true,
            sharpness: d_sharp(),
            starts: d_starts(),
            parallel_starts: None,
            threads: None,
            seed: d_seed(),
            start_spread: d_spread(),
            sample_refinements: d_sample_ref(),
            energy_gap_tolerance: d_energy_gap(),
            replay_steps: d_steps(),
            replay_refinements: d_refine(),
            coincide_tolerance: d_tol(),
            optimiser: Optimiser::Bfgs,
            early_stages: EarlyStages::Loose,
            swept_clearance: d_swept(),
            equilibrium_plans: true,
            workspace: None,
            straight_path_first: true,
            quick_attempt: true,
            least_energy_ends: false,
            reached_goal: true,
            pose_lines: true,
            pose_optimisation: PoseOptimisation::Fallback,
            lift: true,
            time_limit: None,
        }
    }
}

use crate::error::{Num, SettingsError};

/// The largest [`PlanSettings::time_limit`] (seconds): beyond it, leave the limit out.
pub const MAX_TIME_LIMIT: f64 = 1e6;

/// The default safety margin of a planar rod's optimiser, in units of `L`: the samples keep it
/// from the obstacles, and it is what keeps the path clear between them. On the generated
/// suite's planar problems a margin of L/50 instead of L/100 left fewer paths tunnelling
/// between samples, so fewer refinement reruns and fallback attempts ran (99 of 3,900 plans
/// over 0.5 s instead of 168), at the price of routes a little farther from the obstacles
/// (U_max 0.48 % higher on the geometric mean; docs/notes/speed-alternatives.md, *A wider
/// safety margin*).
pub const PLANAR_SAFETY: f64 = 0.02;

/// The default safety margin of a 3D rod's optimiser, in units of `L`. L/50 gained nothing on
/// the generated suite's 3D problems (fewer optimal paths coinciding, no faster; see
/// [`PLANAR_SAFETY`]).
pub const SPATIAL_SAFETY: f64 = 0.01;

/// Checks a [`PlanSettings::time_limit`] of `t` seconds: positive, finite and at most
/// [`MAX_TIME_LIMIT`] (the error's field is `time_limit`; `dlo plan --time-limit` checks its
/// value here too).
pub fn check_time_limit(t: f64) -> Result<f64, SettingsError> {
    if SettingsError::positive("time_limit", t)? > MAX_TIME_LIMIT {
        return Err(bad(
            "time_limit",
            format!(
                "must be at most {} s (a million seconds), got {}",
                Num(MAX_TIME_LIMIT),
                Num(t)
            ),
        ));
    }
    Ok(t)
}

/// The error for `field`.
fn bad(field: impl Into<String>, message: impl Into<String>) -> SettingsError {
    SettingsError::new(field, message)
}

/// The largest `verify_s_samples`, and the most intervals in s a thin rod's verification grid
/// takes ([`PlanSettings::verify_s_for`]).
const MAX_VERIFY_S: usize = 10_000;

/// The most points (`verify_k_samples` × intervals in s) of one verification pass.
const MAX_VERIFY_GRID: usize = 10_000_000;

/// The rod radius (a fraction of its length) down to which `verify_s_samples` is the
/// verification grid's intervals in s ([`PlanSettings::verify_s_for`]).
pub const THIN_ROD: f64 = 0.005;

impl PlanSettings {
    /// The verification grid's intervals in s for a rod of `radius` and `length`:
    /// `verify_s_samples`, and for a rod thinner than [`THIN_ROD`] L that times
    /// `√(0.005 L / radius)`, rounded up, at most 10,000 and `1e7 / verify_k_samples`. A rod
    /// that passes an obstacle's edge or corner between two grid points `h` apart can come up
    /// to about `h² / 8r` closer to it than at either point (its surface is `r` from its centre
    /// line), so a thinner rod needs a finer grid for the same check: this keeps `h² / 8r` that
    /// of a rod 0.005 L thick. On seeds 1–7 of the generated suite with every rod 0.0005 L
    /// thick, the 256 intervals of a thick rod called a 3D plan collision-free that a grid four
    /// times finer found 8.9e-5 L inside the cube mesh (`spatial_2_0`).
    pub fn verify_s_for(&self, radius: f64, length: f64) -> usize {
        let thin = THIN_ROD * length;
        if radius >= thin {
            return self.verify_s_samples;
        }
        let factor = (thin / radius.max(thin * 1e-12)).sqrt();
        let n = (self.verify_s_samples as f64 * factor).ceil();
        let cap = MAX_VERIFY_S
            .min(MAX_VERIFY_GRID / self.verify_k_samples.max(1))
            .max(self.verify_s_samples);
        (n as usize).min(cap)
    }

    /// Checks every setting for a rod of `length` (the safety margin is bounded by it).
    pub fn validate(&self, length: f64) -> Result<(), SettingsError> {
        let (finite, positive) = (SettingsError::finite, SettingsError::positive);
        let l = length;
        let (terms_lo, terms_hi) = PATH_TERMS;
        for (field, val, lo, hi) in [
            ("path_terms", self.path_terms, terms_lo, terms_hi),
            ("k_samples", self.k_samples, 3, 2001),
            ("verify_k_samples", self.verify_k_samples, 3, 100_001),
            ("verify_s_samples", self.verify_s_samples, 2, MAX_VERIFY_S),
            ("starts", self.starts, 1, 64),
            ("replay_steps", self.replay_steps, 1, 100_000),
            ("replay_refinements", self.replay_refinements, 0, 20),
            ("sample_refinements", self.sample_refinements, 0, 20),
            (
                "fallback_evaluations",
                self.fallback_evaluations,
                100,
                100_000_000,
            ),
        ] {
            if !(lo..=hi).contains(&val) {
                return Err(bad(field, format!("must be in {lo}..={hi}, got {val}")));
            }
        }
        for (i, &t) in self.fallback_path_terms.iter().flatten().enumerate() {
            if !(terms_lo..=terms_hi).contains(&t) {
                return Err(bad(
                    format!("fallback_path_terms[{i}]"),
                    format!("must be in {terms_lo}..={terms_hi}, got {t}"),
                ));
            }
        }
        if let Some(t) = self.threads
            && !(1..=256).contains(&t)
        {
            return Err(bad("threads", format!("must be in 1..=256, got {t}")));
        }
        let parallel_starts = self.parallel_starts();
        if !(1..=self.starts).contains(&parallel_starts) {
            return Err(bad(
                "parallel_starts",
                format!(
                    "must be in 1..=plan.starts ({}), got {parallel_starts}",
                    self.starts
                ),
            ));
        }
        // Grid points of one verification pass.
        let grid = self.verify_k_samples.saturating_mul(self.verify_s_samples);
        if grid > MAX_VERIFY_GRID {
            return Err(bad(
                "verify_k_samples",
                format!("verify_k_samples × verify_s_samples = {grid}; at most 1e7"),
            ));
        }
        if self.sharpness.len() > 50
            || self
                .fallback_path_terms
                .as_ref()
                .is_some_and(|f| f.len() > 8)
        {
            return Err(bad(
                if self.sharpness.len() > 50 {
                    "sharpness"
                } else {
                    "fallback_path_terms"
                },
                "at most 50 sharpness stages and 8 fallback path-term counts",
            ));
        }
        // (The defaults lie in range.)
        let safety = self.safety_margin.unwrap_or(0.0);
        if !(0.0..=0.25 * l).contains(&finite("safety_margin", safety)?) {
            return Err(bad(
                "safety_margin",
                format!(
                    "must be in [0, L/4] = [0, {}], got {}",
                    Num(0.25 * l),
                    Num(safety)
                ),
            ));
        }
        if finite("mean_weight", self.mean_weight)? < 0.0 {
            return Err(bad("mean_weight", "must be non-negative"));
        }
        if finite("travel_weight", self.travel_weight)? < 0.0 {
            return Err(bad("travel_weight", "must be non-negative"));
        }
        if let Some(w) = self.equilibrium_weight
            && finite("equilibrium_weight", w)? < 0.0
        {
            return Err(bad("equilibrium_weight", "must be non-negative"));
        }
        if self.equilibrium_rounds > 50 {
            return Err(bad("equilibrium_rounds", "must be at most 50"));
        }
        if let Some(stop) = self.equilibrium_stop
            && !(0.0..1.0).contains(&finite("equilibrium_stop", stop)?)
        {
            return Err(bad(
                "equilibrium_stop",
                format!(
                    "must be in [0, 1) (a fraction of coincide_tolerance), got {}",
                    Num(stop)
                ),
            ));
        }
        if self.sharpness.is_empty() {
            return Err(bad("sharpness", "needs at least one value"));
        }
        for (i, b) in self.sharpness.iter().enumerate() {
            positive(&format!("sharpness[{i}]"), *b)?;
        }
        finite("start_spread", self.start_spread)?;
        if finite("energy_gap_tolerance", self.energy_gap_tolerance)? < 0.0 {
            return Err(bad("energy_gap_tolerance", "must be non-negative"));
        }
        positive("coincide_tolerance", self.coincide_tolerance)?;
        if let Some(t) = self.time_limit {
            check_time_limit(t)?;
        }
        if let Some(w) = &self.workspace {
            for i in 0..3 {
                for (name, v) in [("min", w.min[i]), ("max", w.max[i])] {
                    if let Some(v) = v {
                        finite(&format!("workspace.{name}[{i}]"), v)?;
                    }
                }
                if let (Some(lo), Some(hi)) = (w.min[i], w.max[i])
                    && lo > hi
                {
                    return Err(bad(
                        format!("workspace.min[{i}]"),
                        format!(
                            "must not exceed workspace.max[{i}] ({}), got {}",
                            Num(hi),
                            Num(lo)
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The optimiser's extra clearance from obstacles in units of `L`: `safety_margin`, or
    /// when it is not set [`PLANAR_SAFETY`] on a planar rod and [`SPATIAL_SAFETY`] on a 3D one.
    pub fn safety(&self, length: f64, spatial: bool) -> f64 {
        let default = if spatial {
            SPATIAL_SAFETY
        } else {
            PLANAR_SAFETY
        };
        self.safety_margin.map_or(default, |m| m / length)
    }

    /// The path-term counts tried after `path_terms`: `fallback_path_terms`, or by default
    /// `[6, 8]` on a planar rod and none on a 3D one: more terms let a planar path's shapes
    /// reach their equilibria where three cannot, while on a 3D rod they multiply the plan
    /// time several times over (docs/notes/plan-settings.md).
    pub fn fallback_terms(&self, spatial: bool) -> Vec<usize> {
        match &self.fallback_path_terms {
            Some(terms) => terms.clone(),
            None if spatial => Vec::new(),
            None => vec![6, 8],
        }
    }

    /// Whether the path optimiser holds the swept-clearance rows from the first attempt on
    /// (`swept_clearance: true`). Left unset, they are off until an attempt's plans all tunnel
    /// through an obstacle between their samples, and on in every attempt after it: a thin
    /// obstacle that every attempt's path crosses between samples is then held off, while
    /// plans that do not tunnel keep the routes the rows would make more conservative (always
    /// on, the paper's planar case lands in a plan whose replay departs; `docs/results.md`,
    /// docs/notes/plan-settings.md).
    pub fn swept(&self) -> bool {
        self.swept_clearance == Some(true)
    }

    /// The fraction of `coincide_tolerance` within which tracking stops: `equilibrium_stop`,
    /// or by default 0.5 on a planar rod and 0.1 on a 3D one (where tracking is off unless the
    /// case sets `equilibrium_weight`; the shipped 3D cases that do were measured with 0.1).
    /// The samples' distance to their equilibria estimates the replay's deviation to within
    /// 4e-4 L on every start measured, so a plan stopped at half the tolerance still coincides
    /// with a margin, and sooner than at a tenth of it, with the same verdicts on the
    /// generated suite (docs/notes/plan-settings.md).
    pub fn tracking_stop(&self, spatial: bool) -> f64 {
        match self.equilibrium_stop {
            Some(s) => s,
            None if spatial => 0.1,
            None => 0.5,
        }
    }

    /// The equilibrium-tracking weight: `equilibrium_weight`, or by default 10,000 on a planar
    /// rod and 0 (no tracking) on a 3D one: on the generated suite tracking makes more planar
    /// plans executable, while 3D plans are executable as often without it at a third of the
    /// median time (docs/notes/plan-settings.md).
    pub fn tracking_weight(&self, spatial: bool) -> f64 {
        match self.equilibrium_weight {
            Some(w) => w,
            None if spatial => 0.0,
            None => d_track(),
        }
    }

    /// The replay's settings: `replay_steps`, `replay_refinements`, `coincide_tolerance`.
    pub fn replay(&self) -> ReplayOptions {
        ReplayOptions {
            steps: self.replay_steps,
            refinements: self.replay_refinements,
            tolerance: self.coincide_tolerance,
            early_stop: EarlyStop::Never,
        }
    }

    /// Starts run side by side: `parallel_starts`, or all of them.
    pub fn parallel_starts(&self) -> usize {
        self.parallel_starts.unwrap_or(self.starts)
    }

    /// Threads a start's path optimisation uses: `threads`; else the environment variable
    /// `DLO_THREADS` when it is a number in 1..=256 ([`env_threads`]); else the cores this
    /// process may use, at most 4.
    pub fn threads(&self) -> usize {
        self.threads
            .or_else(|| env_threads().ok().flatten())
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get().min(4)))
    }
}

/// The environment variable `DLO_THREADS`: the default of [`PlanSettings::threads`] where a
/// case or a program does not set it (e.g. 1 for every plan of a job array or a test run
/// that already keeps the cores busy). `Ok(None)` when it is unset; `Err` says why a value is
/// not a number in 1..=256 (the default then ignores it).
pub fn env_threads() -> Result<Option<usize>, String> {
    match std::env::var("DLO_THREADS") {
        Err(std::env::VarError::NotPresent) => Ok(None),
        Err(e) => Err(format!("DLO_THREADS: {e}")),
        Ok(v) => match v.trim().parse::<usize>() {
            Ok(n) if (1..=256).contains(&n) => Ok(Some(n)),
            _ => Err(format!(
                "DLO_THREADS: must be a number in 1..=256, got {v:?}"
            )),
        },
    }
}

/// Inner minimiser of the path optimisation's sharpness stages (docs/notes/speed-alternatives.md
/// says what each finds); the equilibrium-tracking rounds always take Newton steps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Optimiser {
    /// BFGS on the augmented function (the default).
    #[default]
    Bfgs,
    /// Damped Newton with the analytic Hessian: it settles in other local minima, whose shapes
    /// lie farther from the equilibria.
    Newton,
}

/// How far each sharpness stage before the sharpest converges. The sharpest stage converges
/// to an optimality tolerance of 1e-5 (feasibility 1e-6) either way.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EarlyStages {
    /// The stages before the sharpest stop at a looser tolerance, since they only carry the
    /// path to the next one (the default): on a 3D rod at 1e-3, and in a planar rod's own
    /// attempt, whose stages restart the optimiser, at 1e-2 (feasibility a tenth of either).
    /// On the generated suite's planar problems (65 seeds) this took the plans over 0.5 s from
    /// 239 to 171 of 3,900, with 3,880 executable against 3,881 and U_max higher by more than
    /// 1 % on 142 plans and lower on 124 (docs/notes/speed-alternatives.md).
    #[default]
    Loose,
    /// Every stage to the sharpest stage's tolerance. Fully converged restarted stages find
    /// the lowest route of a landscape with many close minima more often: from 32 single
    /// starts of the paper's planar case, 22 plans at U_max 5.2384 (mean 5.264) against 2 of
    /// 32 (mean 5.316) with loose stages.
    Exact,
}

/// Which courses of the controlled end are optimised in its pose space
/// ([`super::pose_optimisation`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PoseOptimisation {
    /// None.
    Off,
    /// The courses tried when no optimised path executes, which nothing optimised: the
    /// straight-line path's end poses and the pose lines (the default).
    #[default]
    Fallback,
    /// Those, and the optimal path's end poses where its equilibria are the plan: on the
    /// generated suite this lowers their peaks by a few per cent at a few tenths of a second.
    All,
}

/// The path-term counts accepted (`plan.path_terms` and each of `plan.fallback_path_terms`).
const PATH_TERMS: (usize, usize) = (1, 12);

fn d_swept() -> Option<bool> {
    None
}

fn d_terms() -> usize {
    3
}
fn d_k() -> usize {
    41
}
fn d_vk() -> usize {
    201
}
fn d_vs() -> usize {
    256
}
fn d_mean() -> f64 {
    1.0
}
fn d_track() -> f64 {
    // A stronger pull, with more rounds, makes more planar plans coincide with their replay
    // (docs/notes/plan-settings.md).
    10_000.0
}
fn d_rounds() -> usize {
    8
}
fn d_travel() -> f64 {
    // Of 0, 0.1, 0.25, 0.5 and 1, the weight that made the most plans of the generated suite
    // executable and coincide (docs/results.md).
    0.5
}
fn d_fallback_evaluations() -> usize {
    10_000
}
fn d_sharp() -> Vec<f64> {
    // Two decades in the R5 preferred-number steps (×≈1.6 per stage): a continuation this fine
    // reaches the paper's coinciding plan from more starts than a coarser one
    // (docs/notes/plan-settings.md).
    vec![
        10.0, 16.0, 25.0, 40.0, 63.0, 100.0, 160.0, 250.0, 400.0, 630.0, 1000.0,
    ]
}
fn d_starts() -> usize {
    1
}
fn d_seed() -> u64 {
    1
}
fn d_spread() -> f64 {
    0.5
}
fn d_sample_ref() -> usize {
    4
}
fn d_energy_gap() -> f64 {
    0.01
}
fn d_steps() -> usize {
    40
}
fn d_refine() -> usize {
    4
}
fn d_tol() -> f64 {
    0.02
}

#[cfg(test)]
mod tests {
    use super::PlanSettings;

    /// The verification grid in s: `verify_s_samples` down to a radius of 0.005 L, finer by
    /// `√(0.005 L / r)` below it (so that `h² / 8r` stays that of a rod 0.005 L thick), in any
    /// units of length, and capped.
    #[test]
    fn thin_rods_get_a_finer_verification_grid() {
        let s = PlanSettings::default();
        for l in [1.0, 100.0] {
            assert_eq!(s.verify_s_for(0.01 * l, l), 256);
            assert_eq!(s.verify_s_for(0.005 * l, l), 256);
            // 256 √10 = 809.55, 256 √5 = 572.43.
            assert_eq!(s.verify_s_for(0.0005 * l, l), 810);
            assert_eq!(s.verify_s_for(0.001 * l, l), 573);
            assert_eq!(s.verify_s_for(0.0, l), 10_000);
        }
        let h = |n: usize| 1.0 / n as f64;
        let dip = |n: usize, r: f64| h(n) * h(n) / (8.0 * r);
        assert!(dip(810, 0.0005) <= dip(256, 0.005));
        let coarse = PlanSettings {
            verify_k_samples: 5_001,
            ..PlanSettings::default()
        };
        assert_eq!(coarse.verify_s_for(0.0, 1.0), 1_999);
    }
}
