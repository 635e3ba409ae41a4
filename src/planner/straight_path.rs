//! The straight-line path as the plan, before any optimisation, where it provably cannot be
//! beaten: every path passes through the start and goal shapes, so no path's `U_max` is below
//! the larger of their energies. When the straight path `c = 0` peaks at an end on the
//! verification grid, it attains that bound; when it also keeps the optimiser's safety margin
//! from every obstacle (and clear of itself, and inside the workspace) and coincides with its
//! replay by the controlled end, it is an optimal, executable plan, and the path optimiser has
//! nothing left to win on the paper's objective ([`super::PlanSettings::straight_path_first`]).
//!
//! The optimiser's tie-breaks (the mean energy along the path, the gripper's travel) are not
//! weighed against it; `docs/results.md` compares its gripper travel with the optimised plans'.

use super::Planner;
use super::judge::Judged;
use super::observer::{PlanObserver, Recorder};
use super::replay::EarlyStop;
use super::result::EndInside;
use super::verify::{Verification, attains_end_energy};
use crate::constraints::Constraint;

/// Largest difference of any coefficient (angles in radians, strains) between the start and
/// goal shapes for which the straight-line path counts as holding one shape: a goal solved at
/// the start's own pose lands on its shape to the last bits.
const STATIONARY: f64 = 1e-12;

/// Largest gripper path, over the straight-line distance between its start and goal
/// positions, for which the equilibria along a straight path that departs from its replay are
/// taken before optimising (the generated suite's target for the median plan).
const STRAIGHT_ROUTE_TRAVEL: f64 = 3.0;

impl Planner {
    /// Whether the straight path `straight` (its verification) attains the lower bound on
    /// `U_max` and keeps the optimiser's clearances, so that it is worth replaying as the plan:
    /// the grid's largest energy is at `k = 0` or `k = 1`, every obstacle stays at least the
    /// safety margin away, the rod keeps clear of itself, and the case holds no condition the
    /// straight path could break between its ends (a point held along the rod, or the
    /// workspace, which the replay checks).
    pub(super) fn straight_path_attains_bound(&self, straight: &Verification) -> bool {
        let l = self.base.model.rod.length;
        let at_end = straight.peaks_at_an_end();
        // A path that holds one shape throughout (a goal at the start's own pose, solved to the
        // same shape) moves nothing: its clearance is that end shape's, which may rest on an
        // obstacle, and needs no safety margin.
        let clearance = if self.is_stationary() {
            -self.collision_tolerance()
        } else {
            self.safety() * l
        };
        let clear = straight.min_clearance.is_none_or(|c| c >= clearance)
            && straight
                .self_contact
                .is_none_or(|(g, _)| g >= -self.collision_tolerance());
        // Conditions the optimiser holds at its samples besides obstacles and self-contact: a
        // position along the rod (other than the fixed base) is not linear in the
        // coefficients, so the straight path need not keep it between its ends.
        let only_contacts = self.base.constraints.iter().all(|c| match c {
            Constraint::Position(pc) => pc.boundary == 0,
            Constraint::RelativePosition(_) => false,
            Constraint::Orientation(_)
            | Constraint::Linear(_)
            | Constraint::Obstacle(_)
            | Constraint::SelfContact(_) => true,
        });
        self.settings.straight_path_first && at_end && clear && only_contacts
    }

    /// Whether the start and goal shapes are the same, to [`STATIONARY`] in every coefficient:
    /// the straight-line path then holds that shape at every `k`.
    fn is_stationary(&self) -> bool {
        self.start.a.len() == self.goal.a.len()
            && self
                .start
                .a
                .iter()
                .zip(&self.goal.a)
                .all(|(a, b)| (a - b).abs() <= STATIONARY)
    }

    /// The equilibria along the straight path's trajectory (the end moved through the straight
    /// path's end poses), judged as the plan before any optimisation when they are executable
    /// and peak within `energy_gap_tolerance` of the lower bound on `U_max` (the larger end
    /// energy): no path peaks lower by more than that, and the gripper follows the straight
    /// path's end poses. Tried where the straight path peaks at an end shape and either
    ///
    /// - an end shape rests on an obstacle (closer to it than the safety margin, which no path
    ///   can then keep next to that end) and the straight path does not keep the margin: the
    ///   rod slides over the obstacle; or
    /// - the straight path keeps every clearance ([`Self::straight_path_attains_bound`]) but
    ///   departs from its replay (a heavy cable, whose interpolated shapes are not the
    ///   equilibria its end poses produce): the equilibria must then keep the safety margin
    ///   from every obstacle too, as the optimiser's shapes would, and the gripper's route
    ///   along them be short ([`Self::straight_route_is_short`]).
    ///
    /// `None` otherwise (the replay's shapes are then dropped, not logged).
    pub(super) fn straight_trajectory_plan(
        &self,
        straight: &Verification,
        ends: &[EndInside],
        fine: &crate::rod::model::Model,
        observer: &mut dyn PlanObserver,
    ) -> Option<Judged> {
        let s = &self.settings;
        if !(s.straight_path_first && s.equilibrium_plans && straight.peaks_at_an_end())
            || self.stopped()
        {
            return None;
        }
        // The end shapes' clearances ([`Planner::end_clearances`]).
        let margin = self.safety() * self.base.model.rod.length;
        let resting = ends.iter().any(|e| e.clearance < margin);
        if !resting && !self.straight_path_attains_bound(straight) {
            return None;
        }
        let mut judged = self.judge_straight_trajectory(fine, observer);
        let bound = self
            .start
            .energy
            .internal()
            .max(self.goal.energy.internal());
        let e = judged.equilibrium_plan.as_ref()?;
        let near = bound + self.settings.energy_gap_tolerance * bound.abs();
        let keeps_margin = e.min_clearance.is_none_or(|c| c >= margin);
        if !(judged.executable
            && (attains_end_energy(e.u_max, bound) || e.u_max <= near)
            && (resting || (keeps_margin && self.straight_route_is_short(&judged))))
        {
            return None;
        }
        let e = judged.equilibrium_plan.as_mut()?;
        e.optimal_path_not_executable = Some(if resting {
            "the straight-line path comes within the safety margin of an obstacle an end shape \
             rests on; the optimiser did not run"
                .into()
        } else {
            "the straight-line path attains the lower bound on U_max but departs from its \
             replay, whose equilibria attain it too and keep the safety margin; the optimiser \
             did not run"
                .into()
        });
        Some(judged)
    }

    /// Whether the gripper's path along the straight path's end poses, at the steps of
    /// `judged`'s replay, is at most [`STRAIGHT_ROUTE_TRAVEL`] times the straight-line
    /// distance between its start and goal positions: a route a robot would run. (The
    /// coefficients' straight line can swing the end far round; the optimiser's travel term
    /// then usually finds a shorter route at the same peak.)
    fn straight_route_is_short(&self, judged: &Judged) -> bool {
        let path = self.path();
        let z = vec![0.0; path.n_vars()];
        let ks: Vec<f64> = judged.replay.steps.iter().map(|s| s.k).collect();
        let t = super::trajectory::Trajectory::along(&self.base.model, &path, &z, &ks);
        t.path_length <= STRAIGHT_ROUTE_TRAVEL * t.straight_distance
    }

    /// The equilibria along the straight path's trajectory judged as the plan
    /// ([`Self::judge_path`] with `trajectory` `"straight_path"`): only its equilibria can be
    /// the plan, so its replay ends where a solve fails.
    pub(super) fn judge_straight_trajectory(
        &self,
        fine: &crate::rod::model::Model,
        observer: &mut dyn PlanObserver,
    ) -> Judged {
        let path = self.path();
        let z = vec![0.0; path.n_vars()];
        let mut judged = self.judge_path(&path, &z, false, EarlyStop::Failure, fine, observer);
        if let Some(e) = judged.equilibrium_plan.as_mut() {
            e.set_trajectory("straight_path", None);
        }
        judged
    }

    /// The straight path judged as the plan when it attains the lower bound
    /// ([`Self::straight_path_attains_bound`]) and coincides with its replay inside the
    /// workspace; `None` otherwise (the replay's shapes are then dropped, not logged).
    pub(super) fn straight_path_plan(
        &self,
        straight: &Verification,
        observer: &mut dyn PlanObserver,
    ) -> Option<Judged> {
        if !self.straight_path_attains_bound(straight) || self.stopped() {
            return None;
        }
        let t = std::time::Instant::now();
        let path = self.path();
        let z = vec![0.0; path.n_vars()];
        let mut rec = Recorder::new(observer);
        // Only a replay that coincides makes it the plan: it ends where it departs.
        let replay = self.replay_under(&self.held, &path, &z, EarlyStop::Departure, &mut rec);
        let workspace = self.workspace_check(&path, &z);
        let within = workspace.is_none_or(|w| w.within);
        (replay.coincide && within && !self.stopped()).then(|| Judged {
            replay,
            equilibrium_plan: None,
            workspace,
            shapes: rec.into_shapes(),
            seconds: t.elapsed().as_secs_f64(),
            executable: true,
            dips_on_case_samples: false,
        })
    }
}
