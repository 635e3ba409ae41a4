//! The controlled end driven along a line in its own pose space, every shape the equilibrium
//! its pose produces: a plan made for the gripper directly, tried where neither the optimal
//! path's end poses nor the straight-line path's execute.
//!
//! The coefficient-space paths (the optimal path, paper §7, and the straight one) move the
//! end as their shapes do, and the end poses of a heavy cable's shapes can press it into a
//! table it rests on, or turn the end the long way round. A pose line moves the end's
//! position along the straight line from the start's to the goal's, raised against gravity by
//! `lift · 4k(1 − k)` or moved across it horizontally by `side · 4k(1 − k)` (units of L: the
//! farthest mid-way; [`Detour`]), and turns its frame along the shortest rotation between the
//! two (a slerp), its Euler angles continued from the start's. Lifted, the cable hangs clear
//! of what it would be dragged over, instead of snapping across it; moved aside, it can keep to
//! one side. The replayed equilibria along it are judged exactly as those along the other
//! trajectories ([`super::equilibrium_plan`]); the lines are tried in the order of
//! [`DETOURS`], and the first that passes is the plan.

use super::Planner;
use super::end_course::EndCourse;
use super::endpoints::EndPose;
use super::judge::Judged;
use super::observer::PlanObserver;
use crate::rod::model::Model;
use nalgebra::{Quaternion, UnitQuaternion};
use std::sync::Arc;

/// How far a pose line leaves the straight line between the end positions mid-way (units of
/// L; `4k(1 − k)` times it at `k`): `lift` against gravity (along `x` on a rod without weight),
/// and `side` across, horizontally, along `up × (goal − start)` (against it where negative).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detour {
    /// Against gravity.
    pub lift: f64,
    /// Horizontally across the straight line.
    pub side: f64,
}

impl Detour {
    /// How the line is described: `"lifted 0.3 L"`, `"moved aside -0.5 L"`, or `""` (the
    /// straight line itself).
    pub fn describe(&self) -> String {
        match (self.lift, self.side) {
            (h, s) if h != 0.0 && s != 0.0 => format!("lifted {h} L and moved aside {s} L"),
            (h, _) if h != 0.0 => format!("lifted {h} L"),
            (_, s) if s != 0.0 => format!("moved aside {s} L"),
            _ => String::new(),
        }
    }

    /// The line's name in a report: `"the end's pose line"`, followed by
    /// [`Detour::describe`] where it leaves the straight line.
    pub fn line_name(&self) -> String {
        match self.describe() {
            d if d.is_empty() => "the end's pose line".into(),
            d => format!("the end's pose line {d}"),
        }
    }
}

/// The pose lines tried, in order: lifted by 0, 0.15, 0.3 and 0.5 L, then, on a 3D rod, moved
/// aside by 0.3 and 0.5 L either way (a heavy cable dragged across a table can snap over
/// wherever the end is lifted, and keep on one side of the line where it is moved aside).
pub const DETOURS: [Detour; 8] = [
    Detour {
        lift: 0.0,
        side: 0.0,
    },
    Detour {
        lift: 0.15,
        side: 0.0,
    },
    Detour {
        lift: 0.3,
        side: 0.0,
    },
    Detour {
        lift: 0.5,
        side: 0.0,
    },
    Detour {
        lift: 0.0,
        side: 0.3,
    },
    Detour {
        lift: 0.0,
        side: -0.3,
    },
    Detour {
        lift: 0.0,
        side: 0.5,
    },
    Detour {
        lift: 0.0,
        side: -0.5,
    },
];

/// Steps of `k` on which the Euler angles are continued from the start's.
const TURN_STEPS: usize = 1024;

/// A line in the controlled end's pose space (see the module documentation).
#[derive(Clone, Debug)]
pub struct PoseLine {
    /// Start and goal positions of the end (units of L, the rod's position frame).
    from: [f64; 3],
    to: [f64; 3],
    /// The position's offset from the straight line mid-way (units of L).
    offset: [f64; 3],
    /// How it leaves the straight line.
    pub detour: Detour,
    turn: Turn,
}

#[derive(Clone, Debug)]
enum Turn {
    /// A planar rod's `θ`, linear from the start's to the goal's.
    Planar(f64, f64),
    /// The shortest rotation between two frames, with its Euler angles at `k = i / TURN_STEPS`
    /// continued from the start's.
    Spatial {
        from: UnitQuaternion<f64>,
        to: UnitQuaternion<f64>,
        angles: Vec<[f64; 3]>,
    },
}

/// The unit quaternion of rotation `m` ([`super::trajectory::quaternion_of`]).
fn quaternion(m: [[f64; 3]; 3]) -> UnitQuaternion<f64> {
    let [w, x, y, z] = super::trajectory::quaternion_of(m);
    UnitQuaternion::new_unchecked(Quaternion::new(w, x, y, z))
}

/// The rotation of `q` ([`super::trajectory::rotation_of_quaternion`]).
fn matrix(q: &UnitQuaternion<f64>) -> [[f64; 3]; 3] {
    super::trajectory::rotation_of_quaternion([q.w, q.i, q.j, q.k])
}

impl PoseLine {
    /// The line from the end pose of shape `start` to that of shape `goal`, leaving the
    /// straight line by `detour` (against gravity, along `x` on a rod without weight, and
    /// across; `None` where it moves aside on a planar rod, or where the straight line is
    /// vertical and has no horizontal across).
    pub fn new(model: &Model, start: &[f64], goal: &[f64], detour: Detour) -> Option<PoseLine> {
        let b = model.boundary(1.0);
        let from = model.evaluate(start).positions[b];
        let to = model.evaluate(goal).positions[b];
        let up = model.up().unwrap_or([1.0, 0.0, 0.0]);
        let chord: [f64; 3] = std::array::from_fn(|i| to[i] - from[i]);
        let across = [
            up[1] * chord[2] - up[2] * chord[1],
            up[2] * chord[0] - up[0] * chord[2],
            up[0] * chord[1] - up[1] * chord[0],
        ];
        let norm = across.iter().map(|v| v * v).sum::<f64>().sqrt();
        let side = if detour.side == 0.0 {
            [0.0; 3]
        } else if !model.layout.spatial || norm <= 1e-9 * model.rod.length {
            return None;
        } else {
            across.map(|v| v / norm)
        };
        let (e0, e1) = (model.angles_at(start, 1.0), model.angles_at(goal, 1.0));
        let turn = if model.layout.spatial {
            let r = |e: [f64; 3]| quaternion(crate::rod::kinematics::rotation(e[0], e[1], e[2]));
            let (q0, q1) = (r(e0), r(e1));
            let mut angles = Vec::with_capacity(TURN_STEPS + 1);
            angles.push(e0);
            for i in 1..=TURN_STEPS {
                let k = i as f64 / TURN_STEPS as f64;
                let prev = angles[i - 1];
                angles.push(super::orientation::euler_branch(
                    matrix(&q0.slerp(&q1, k)),
                    prev,
                    None,
                ));
            }
            Turn::Spatial {
                from: q0,
                to: q1,
                angles,
            }
        } else {
            Turn::Planar(e0[1], e1[1])
        };
        Some(PoseLine {
            from,
            to,
            offset: std::array::from_fn(|i| detour.lift * up[i] + detour.side * side[i]),
            detour,
            turn,
        })
    }

    /// The end's position at `k` (units of L).
    pub fn position(&self, k: f64) -> [f64; 3] {
        let h = 4.0 * k * (1.0 - k);
        std::array::from_fn(|i| (1.0 - k) * self.from[i] + k * self.to[i] + h * self.offset[i])
    }

    /// The end's Euler angles at `k` (`[0, θ, 0]` on a planar rod).
    pub fn angles(&self, k: f64) -> [f64; 3] {
        match &self.turn {
            Turn::Planar(t0, t1) => [0.0, (1.0 - k) * t0 + k * t1, 0.0],
            Turn::Spatial { from, to, angles } => {
                let k = k.clamp(0.0, 1.0);
                let i = ((k * TURN_STEPS as f64).floor() as usize).min(TURN_STEPS);
                if (i as f64 / TURN_STEPS as f64) == k {
                    return angles[i];
                }
                super::orientation::euler_branch(matrix(&from.slerp(to, k)), angles[i], None)
            }
        }
    }

    /// The end pose at `k`, as a replay holds it.
    pub fn end_pose(&self, model: &Model, k: f64) -> EndPose {
        EndPose::at(model, self.position(k), self.angles(k))
    }
}

impl Planner {
    /// The pose line of `detour` between the end shapes ([`PoseLine::new`]; `None` where
    /// there is no such line).
    pub(super) fn pose_line(&self, detour: Detour) -> Option<PoseLine> {
        PoseLine::new(&self.base.model, &self.start.a, &self.goal.a, detour)
    }

    /// The replayed equilibria along the pose line `line`, judged as a plan on the
    /// verification model `fine` ([`Self::judge_path`], with the straight-line path's shapes
    /// as the replay's reference).
    pub(super) fn judge_pose_line(
        &self,
        line: &Arc<PoseLine>,
        fine: &Model,
        observer: &mut dyn PlanObserver,
    ) -> Judged {
        let course = Arc::new(EndCourse::line((**line).clone()));
        let path = self.path();
        let z = vec![0.0; path.n_vars()];
        let mut judged = self.judge_driven(&course, (&path, &z), fine, observer);
        if let Some(e) = judged.equilibrium_plan.as_mut() {
            e.set_trajectory("pose_line", Some(line.detour));
        }
        judged
    }
}

#[cfg(test)]
mod tests {
    use super::{Detour, PoseLine};

    /// Lifted by `lift`, not moved aside.
    fn lifted(lift: f64) -> Detour {
        Detour { lift, side: 0.0 }
    }

    /// A 3D rod without weight (L = 1, Rf = Rt = 1), no obstacles.
    fn spatial_model() -> crate::rod::model::Model {
        let rod = crate::rod::Rod::uniform(1.0, 1.0).with_torsional_rigidity(1.0);
        super::super::endpoints::tests::model(rod)
    }

    /// The line starts and ends on the end poses of its shapes (angles as the shapes have
    /// them), rises by the lift mid-way, and turns along the shortest rotation: its frames at
    /// `k` and the slerp's agree.
    #[test]
    fn a_pose_line_joins_the_end_poses_and_turns_the_short_way() {
        let p = super::super::paper_planner();
        let model = &p.base.model;
        let line = PoseLine::new(model, &p.start.a, &p.goal.a, lifted(0.3)).expect("a line");
        let b = model.boundary(1.0);
        for (k, a) in [(0.0, &p.start.a), (1.0, &p.goal.a)] {
            let x = model.evaluate(a).positions[b];
            let y = line.position(k);
            assert!((0..3).all(|i| (x[i] - y[i]).abs() < 1e-15));
            assert!((line.angles(k)[1] - model.angles_at(a, 1.0)[1]).abs() < 1e-15);
        }
        let (x0, x1, xm) = (line.position(0.0), line.position(1.0), line.position(0.5));
        assert!((xm[0] - (0.5 * (x0[0] + x1[0]) + 0.3)).abs() < 1e-15);
        // A planar rod's end cannot leave its plane.
        let aside = Detour {
            lift: 0.0,
            side: 0.3,
        };
        assert!(PoseLine::new(model, &p.start.a, &p.goal.a, aside).is_none());
    }

    /// A 3D end moved aside by `s`: at every `k` its offset from the straight line is
    /// `s · 4k(1 − k)` long, level (no component along the vertical `x` of a rod without
    /// weight), across the line, and along `x × (goal − start)` for `s > 0`; the other way for
    /// `s < 0`. Where the straight line has no horizontal across (here: the start and goal
    /// ends at the same point), there is no such line.
    #[test]
    fn a_line_moved_aside_stays_level_and_across() {
        let model = spatial_model();
        let a0 = vec![0.0; model.n()];
        let seed = |e| super::super::endpoints::seed_towards(&model, &a0, [0.0; 3], false, e);
        let (start, goal) = (seed([-0.4, 0.5, 0.4]), seed([0.6, 0.4, -0.6]));
        let b = model.boundary(1.0);
        let (x0, x1) = (
            model.evaluate(&start).positions[b],
            model.evaluate(&goal).positions[b],
        );
        let chord: [f64; 3] = std::array::from_fn(|i| x1[i] - x0[i]);
        // x × chord, computed here.
        let across = [0.0, -chord[2], chord[1]];
        for s in [0.3, -0.5] {
            let line = PoseLine::new(&model, &start, &goal, Detour { lift: 0.0, side: s })
                .expect("a line");
            for i in 0..=20 {
                let k = i as f64 / 20.0;
                let x = line.position(k);
                let off: [f64; 3] = std::array::from_fn(|j| x[j] - (x0[j] + k * chord[j]));
                let len = off.iter().map(|v| v * v).sum::<f64>().sqrt();
                assert!(
                    (len - s.abs() * 4.0 * k * (1.0 - k)).abs() < 1e-14,
                    "k = {k}"
                );
                assert!(off[0].abs() < 1e-15, "k = {k}: {off:?}");
                let along: f64 = (0..3).map(|j| off[j] * chord[j]).sum();
                assert!(along.abs() < 1e-14, "k = {k}: {along}");
                let dot: f64 = (0..3).map(|j| off[j] * across[j]).sum();
                assert!(k == 0.0 || k == 1.0 || dot * s > 0.0, "k = {k}");
            }
        }
        let in_place = PoseLine::new(
            &model,
            &start,
            &start,
            Detour {
                lift: 0.0,
                side: 0.3,
            },
        );
        assert!(in_place.is_none());
    }

    /// A 3D end turned from a frame tilted 0.3 rad towards −y to one tilted 0.06 rad towards
    /// +y (φ from −π/2 to π/2, as the end rows of a cable moved across a table hold them):
    /// at every `k` the frame of the line's Euler angles is the slerp's, the angles stay on one
    /// branch, they start on the start shape's own, and near θ = 0 the end pose holds `θ` and
    /// `φ + ψ` only.
    #[test]
    fn a_spatial_pose_line_turns_along_the_slerp_with_continuous_angles() {
        use crate::rod::kinematics::rotation;
        let model = spatial_model();
        let a0 = vec![0.0; model.n()];
        let half = std::f64::consts::FRAC_PI_2;
        let (e0, e1) = ([-half, 0.3, 1.5], [half, 0.06, -1.6]);
        let start = super::super::endpoints::seed_towards(&model, &a0, [0.0; 3], false, e0);
        let goal = super::super::endpoints::seed_towards(&model, &a0, [0.0; 3], false, e1);
        let line = PoseLine::new(&model, &start, &goal, lifted(0.0)).expect("a line");
        let m = |e: [f64; 3]| super::quaternion(rotation(e[0], e[1], e[2]));
        let (q0, q1) = (m(e0), m(e1));
        assert_eq!(line.angles(0.0), model.angles_at(&start, 1.0));
        let mut prev = line.angles(0.0);
        for i in 1..=2000 {
            let k = i as f64 / 2000.0;
            let e = line.angles(k);
            // (Near the pole the angles give the frame back to about 1e-12 rad.)
            let off = q0.slerp(&q1, k).angle_to(&m(e));
            assert!(off < 1e-10, "k = {k}: {off:e} rad");
            // θ and φ + ψ move little; φ alone swings fast where the turn passes near the
            // pole (θ ≈ 0.002 here), but never jumps to another branch.
            let (dt, ds) = (
                (e[1] - prev[1]).abs(),
                (e[0] + e[2] - prev[0] - prev[2]).abs(),
            );
            assert!(dt < 1e-3 && ds < 1e-2, "k = {k}: {prev:?} → {e:?}");
            assert!((e[0] - prev[0]).abs() < 0.5, "k = {k}: {prev:?} → {e:?}");
            prev = e;
        }
        // Near θ = 0 the frame fixes only φ + ψ.
        let pose = super::EndPose::at(&model, [0.0; 3], [0.2, 1e-4, 0.3]);
        assert_eq!(pose.angles.len(), 2);
    }
}
