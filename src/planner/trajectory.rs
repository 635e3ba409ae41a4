//! The gripper trajectory: the controlled end's pose (position and orientation of the `s = L`
//! cross-section) at every replay step of the plan, which is what a robot holding that end
//! follows, and the held end's fixed pose.
//!
//! Poses are in the case's frame (gravity along −x, so x is up; the natural state lies along
//! +z). The orientation is the frame `A(φ, θ, ψ)` of eq. (1) at the end: its columns are `ξ`,
//! `η` and the tangent `ζ`. A robot whose base frame `B` sees the case frame at rotation `R_B`
//! and origin `t_B` commands `p_B = R_B p + t_B` and `q_B = q(R_B) ⊗ q`.

use crate::planner::path::DeformationPath;
use crate::rod::kinematics::Shape;
use crate::rod::model::Model;
use serde::Serialize;

/// One pose of an end of the rod.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct GripperPose {
    /// Path parameter.
    pub k: f64,
    /// Position (case units, case frame).
    pub position: [f64; 3],
    /// Orientation as a unit quaternion `(w, x, y, z)`, `w ≥ 0` at the first pose and
    /// continuous along the trajectory (never flips sign between steps).
    pub quaternion: [f64; 4],
    /// Orientation as a rotation matrix (row-major; columns `ξ, η, ζ`, `ζ` the tangent).
    pub rotation: [[f64; 3]; 3],
    /// Time (s) from the start of the motion when the trajectory was time-parameterised
    /// ([`Trajectory::time_parameterise`]); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_s: Option<f64>,
}

/// The controlled end's trajectory along a plan.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Trajectory {
    /// The frame of every pose.
    pub frame: &'static str,
    /// The held end's pose (`s = 0`), fixed along the path.
    pub held: GripperPose,
    /// The controlled end's pose at every replay step, in increasing `k`.
    pub poses: Vec<GripperPose>,
    /// Length of the controlled end's path (case units): the sum of the steps between poses.
    pub path_length: f64,
    /// The straight-line distance between its first and last positions (case units).
    pub straight_distance: f64,
    /// The largest step between consecutive poses (case units).
    pub largest_step: f64,
    /// The total angle the end turns through (radians): the sum of the rotation angles
    /// between consecutive poses.
    pub rotation_angle: f64,
    /// The largest rotation between consecutive poses (radians).
    pub largest_rotation_step: f64,
    /// The speed limits a time parameterisation used (`[length/s, rad/s]`; absent without).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub speed_limits: Option<[f64; 2]>,
    /// Duration (s) of the time-parameterised motion (absent without).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub duration_s: Option<f64>,
}

/// The speed limits of a time parameterisation ([`Trajectory::time_parameterise`]), checked:
/// `max_speed` positive and finite (`None`: no time parameterisation), `max_angular_speed`
/// positive (default unlimited).
pub fn speed_limits(
    max_speed: Option<f64>,
    max_angular_speed: Option<f64>,
) -> Result<Option<[f64; 2]>, crate::error::SettingsError> {
    use crate::error::SettingsError;
    let Some(v) = max_speed else { return Ok(None) };
    let w = max_angular_speed.unwrap_or(f64::INFINITY);
    for (field, x, inf_ok) in [("max_speed", v, false), ("max_angular_speed", w, true)] {
        if !(x > 0.0 && (inf_ok || x.is_finite())) {
            return Err(SettingsError::new(
                field,
                format!(
                    "must be a positive finite number, got {}",
                    crate::error::Num(x)
                ),
            ));
        }
    }
    Ok(Some([v, w]))
}

/// How far from 1 the squared norm of a quaternion written as an orientation may be
/// ([`rotation_of_unit_quaternion`]): a quaternion written by hand to two or three decimals,
/// such as `[0.98, 0, -0.2, 0]` (squared norm 1.0004) or `[0.707, 0, 0.707, 0]` (0.9997), is
/// meant as the unit quaternion it rounds, and is normalised; one farther off is taken for a
/// mistake. (RViz's check of the quaternions it is given uses the same bound.)
pub const QUATERNION_NORM_TOLERANCE: f64 = 1e-2;

/// The rotation of a unit quaternion `(w, x, y, z)`, normalised first; `Err` names what is
/// wrong when a component is not finite or the squared norm is not 1 to
/// [`QUATERNION_NORM_TOLERANCE`].
pub fn rotation_of_unit_quaternion(q: [f64; 4]) -> Result<[[f64; 3]; 3], String> {
    if let Some(i) = q.iter().position(|c| !c.is_finite()) {
        return Err(format!(
            "component {i} must be finite, got {}",
            crate::error::Num(q[i])
        ));
    }
    let n2 = q.iter().map(|c| c * c).sum::<f64>();
    if (n2 - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
        return Err(format!(
            "must be a unit quaternion [w, x, y, z] (its squared norm within \
             {QUATERNION_NORM_TOLERANCE} of 1; it is normalised): its norm is {}",
            n2.sqrt()
        ));
    }
    Ok(rotation_of_quaternion(q))
}

/// Unit quaternion `(w, x, y, z)` of a rotation matrix (rows).
pub fn quaternion_of(m: [[f64; 3]; 3]) -> [f64; 4] {
    let tr = m[0][0] + m[1][1] + m[2][2];
    let q = if tr > 0.0 {
        let s = (tr + 1.0).sqrt() * 2.0;
        [
            0.25 * s,
            (m[2][1] - m[1][2]) / s,
            (m[0][2] - m[2][0]) / s,
            (m[1][0] - m[0][1]) / s,
        ]
    } else if m[0][0] > m[1][1] && m[0][0] > m[2][2] {
        let s = (1.0 + m[0][0] - m[1][1] - m[2][2]).sqrt() * 2.0;
        [
            (m[2][1] - m[1][2]) / s,
            0.25 * s,
            (m[0][1] + m[1][0]) / s,
            (m[0][2] + m[2][0]) / s,
        ]
    } else if m[1][1] > m[2][2] {
        let s = (1.0 + m[1][1] - m[0][0] - m[2][2]).sqrt() * 2.0;
        [
            (m[0][2] - m[2][0]) / s,
            (m[0][1] + m[1][0]) / s,
            0.25 * s,
            (m[1][2] + m[2][1]) / s,
        ]
    } else {
        let s = (1.0 + m[2][2] - m[0][0] - m[1][1]).sqrt() * 2.0;
        [
            (m[1][0] - m[0][1]) / s,
            (m[0][2] + m[2][0]) / s,
            (m[1][2] + m[2][1]) / s,
            0.25 * s,
        ]
    };
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    q.map(|v| v / n)
}

/// Rotation matrix (rows) of a unit quaternion `(w, x, y, z)` (normalised first).
pub fn rotation_of_quaternion(q: [f64; 4]) -> [[f64; 3]; 3] {
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    let [w, x, y, z] = q.map(|v| v / n);
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// The angle (radians) of the rotation between two unit quaternions.
fn angle_between(a: [f64; 4], b: [f64; 4]) -> f64 {
    let d: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
    2.0 * d.abs().min(1.0).acos()
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The pose of the cross-section at dimensionless arc length `t` of shape `a` (evaluated as
/// `shape`), in case units.
fn pose_at(model: &Model, a: &[f64], shape: &Shape, t: f64, k: f64) -> GripperPose {
    let l = model.rod.length;
    let b = model.boundary(t);
    let position = shape.positions[b].map(|v| v * l);
    let m = model.frame_at(a, t);
    let mut q = quaternion_of(m);
    if q[0] < 0.0 {
        q = q.map(|v| -v);
    }
    GripperPose {
        k,
        position,
        quaternion: q,
        rotation: m,
        time_s: None,
    }
}

impl Trajectory {
    /// The trajectory of the controlled end along `path(z)` at the path parameters `ks`
    /// (increasing; the replay's steps), with the held end's pose from the path's start.
    pub fn along(model: &Model, path: &DeformationPath, z: &[f64], ks: &[f64]) -> Trajectory {
        let shape_at = |k: f64| {
            let mut a = vec![0.0; path.n()];
            path.shape_at(z, k, &mut a);
            a
        };
        let shapes: Vec<(f64, Vec<f64>)> = ks.iter().map(|&k| (k, shape_at(k))).collect();
        Self::of_shapes(model, &shape_at(0.0), &shapes)
    }

    /// The trajectory of the controlled end of a replay's shapes, with the held end's pose from
    /// shape `first`: the end poses that hold the replayed equilibria, which the gripper
    /// follows along a pose line or an optimised course.
    pub fn of_replay(model: &Model, first: &[f64], replay: &super::replay::Replay) -> Trajectory {
        let shapes: Vec<(f64, Vec<f64>)> =
            replay.steps.iter().map(|s| (s.k, s.a.clone())).collect();
        Self::of_shapes(model, first, &shapes)
    }

    /// The trajectory of the controlled end of the shapes `(k, a)` (increasing `k`), with the
    /// held end's pose from shape `first`.
    pub fn of_shapes(model: &Model, first: &[f64], shapes: &[(f64, Vec<f64>)]) -> Trajectory {
        let mut shape = Shape::default();
        model.evaluate_into(first, &mut shape);
        let held = pose_at(model, first, &shape, 0.0, 0.0);
        let mut poses: Vec<GripperPose> = Vec::with_capacity(shapes.len());
        for (k, a) in shapes {
            model.evaluate_into(a, &mut shape);
            let mut p = pose_at(model, a, &shape, 1.0, *k);
            // Keep the quaternion in the previous one's hemisphere: q and −q are the same
            // rotation, and a controller interpolating between them would turn the long way.
            if let Some(prev) = poses.last() {
                let d: f64 = prev
                    .quaternion
                    .iter()
                    .zip(&p.quaternion)
                    .map(|(x, y)| x * y)
                    .sum();
                if d < 0.0 {
                    p.quaternion = p.quaternion.map(|v| -v);
                }
            }
            poses.push(p);
        }
        Self::from_poses(held, poses)
    }

    /// A trajectory of the given poses, with its lengths and angles measured.
    pub fn from_poses(held: GripperPose, poses: Vec<GripperPose>) -> Trajectory {
        let (mut length, mut largest, mut angle, mut largest_angle) = (0.0, 0.0_f64, 0.0, 0.0_f64);
        for w in poses.windows(2) {
            let d = distance(w[0].position, w[1].position);
            let r = angle_between(w[0].quaternion, w[1].quaternion);
            length += d;
            largest = largest.max(d);
            angle += r;
            largest_angle = largest_angle.max(r);
        }
        let straight = match (poses.first(), poses.last()) {
            (Some(a), Some(b)) => distance(a.position, b.position),
            _ => 0.0,
        };
        Trajectory {
            frame: "case (x up, against gravity; the natural state along +z)",
            held,
            poses,
            path_length: length,
            straight_distance: straight,
            largest_step: largest,
            rotation_angle: angle,
            largest_rotation_step: largest_angle,
            speed_limits: None,
            duration_s: None,
        }
    }

    /// Times every pose for an end that moves at most `max_speed` (case length units per
    /// second) and turns at most `max_angular_speed` (rad/s): each step takes the longer of
    /// its distance over `max_speed` and its rotation angle over `max_angular_speed`, the end
    /// moving at constant velocity within a step. Both limits must be positive and finite.
    pub fn time_parameterise(&mut self, max_speed: f64, max_angular_speed: f64) {
        let mut t = 0.0;
        let mut prev: Option<GripperPose> = None;
        for p in &mut self.poses {
            if let Some(q) = prev {
                let d = distance(q.position, p.position) / max_speed;
                let r = angle_between(q.quaternion, p.quaternion) / max_angular_speed;
                t += d.max(r);
            }
            p.time_s = Some(t);
            prev = Some(*p);
        }
        self.speed_limits = Some([max_speed, max_angular_speed]);
        self.duration_s = Some(t);
    }

    /// The trajectory as CSV: a header row that names the unit and frame of every column, then
    /// one row per pose of the controlled end (`k`, the time when parameterised, position,
    /// quaternion `w, x, y, z`, rotation matrix row by row).
    pub fn to_csv(&self) -> String {
        use std::fmt::Write;
        let timed = self.duration_s.is_some();
        let mut o = String::from("k");
        if timed {
            o.push_str(",t [s]");
        }
        for c in ["x", "y", "z"] {
            let _ = write!(o, ",{c} [case length unit; case frame: x up]");
        }
        for c in ["qw", "qx", "qy", "qz"] {
            let _ = write!(o, ",{c}");
        }
        for i in 0..3 {
            for j in 0..3 {
                let _ = write!(o, ",r{i}{j}");
            }
        }
        o.push('\n');
        for p in &self.poses {
            // `{:?}` round-trips every double; `+ 0.0` writes −0 as 0.
            let _ = write!(o, "{:?}", p.k + 0.0);
            if timed {
                let _ = write!(o, ",{:?}", p.time_s.unwrap_or(0.0) + 0.0);
            }
            for v in p.position.iter().chain(&p.quaternion) {
                let _ = write!(o, ",{:?}", v + 0.0);
            }
            for row in &p.rotation {
                for v in row {
                    let _ = write!(o, ",{:?}", v + 0.0);
                }
            }
            o.push('\n');
        }
        o
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rod::kinematics::rotation;

    /// A quaternion written to three decimals is the rotation of the unit quaternion it
    /// rounds; one whose squared norm is off by more than the tolerance is refused.
    #[test]
    fn quaternions_written_to_a_few_decimals_are_normalised() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let exact = rotation_of_quaternion([h, 0.0, h, 0.0]);
        let rounded = rotation_of_unit_quaternion([0.707, 0.0, 0.707, 0.0]).unwrap();
        for (a, b) in exact.iter().flatten().zip(rounded.iter().flatten()) {
            assert!((a - b).abs() < 1e-15, "{rounded:?}");
        }
        // Squared norms 0.9901 and 1.0099 pass; 0.98 and 1.0201 do not.
        for (q, ok) in [
            ([0.99504, 0.0, 0.0, 0.0], true),
            ([1.00494, 0.0, 0.0, 0.0], true),
            ([0.98995, 0.0, 0.0, 0.0], false),
            ([1.01, 0.0, 0.0, 0.0], false),
        ] {
            assert_eq!(rotation_of_unit_quaternion(q).is_ok(), ok, "{q:?}");
        }
        let err = rotation_of_unit_quaternion([0.0, 0.0, 1.01, 0.0]).unwrap_err();
        assert!(err.contains("its norm is 1.01"), "{err}");
    }

    #[test]
    fn quaternion_and_matrix_round_trip() {
        for (f, t, s) in [
            (0.3, 1.1, -0.7),
            (3.0, 0.01, -2.0),
            (-1.0, 3.1, 0.4),
            (0.0, 0.0, 0.0),
        ] {
            let m = rotation(f, t, s);
            let q = quaternion_of(m);
            assert!((q.iter().map(|v| v * v).sum::<f64>() - 1.0).abs() < 1e-14);
            let back = rotation_of_quaternion(q);
            for i in 0..3 {
                for j in 0..3 {
                    assert!((back[i][j] - m[i][j]).abs() < 1e-14, "{f} {t} {s}");
                }
            }
        }
    }

    #[test]
    fn time_parameterisation_takes_the_slower_limit() {
        let pose = |k: f64, x: f64, q: [f64; 4]| GripperPose {
            k,
            position: [x, 0.0, 0.0],
            quaternion: q,
            rotation: rotation_of_quaternion(q),
            time_s: None,
        };
        let h = std::f64::consts::FRAC_1_SQRT_2;
        // 0.2 m straight, then a quarter turn about z in place.
        let poses = vec![
            pose(0.0, 0.0, [1.0, 0.0, 0.0, 0.0]),
            pose(0.5, 0.2, [1.0, 0.0, 0.0, 0.0]),
            pose(1.0, 0.2, [h, 0.0, 0.0, h]),
        ];
        let mut t = Trajectory::from_poses(poses[0], poses);
        assert!((t.path_length - 0.2).abs() < 1e-15);
        assert!((t.rotation_angle - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        t.time_parameterise(0.1, 1.0);
        assert!((t.poses[1].time_s.unwrap() - 2.0).abs() < 1e-12);
        let d = t.duration_s.unwrap();
        assert!((d - 2.0 - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }
}
