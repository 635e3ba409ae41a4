//! Foxglove scene messages: the rod as a thick line, obstacles as primitives, the controlled
//! end's pose, and the transform that makes gravity point down.
//!
//! Everything is drawn in the frame `rod` (the paper's axes: gravity along −x). The transform
//! `world → rod` maps the paper's x to Foxglove's z (up), its z to Foxglove's x, and its y to
//! −y (a proper rotation: 180° about `(x + z)/√2`).

use crate::output::foxglove::{
    ArrowPrimitive, Color, CubePrimitive, CylinderPrimitive, FrameTransform, LinePrimitive, Point3,
    Pose, PoseInFrame, Quaternion, SceneEntity, SceneUpdate, SpherePrimitive, Timestamp,
    TriangleListPrimitive, Vector3,
};
use crate::scene::obstacle::{Obstacle, ObstacleShape};

/// Frame of everything the planner draws.
pub const ROD_FRAME: &str = "rod";
/// Foxglove's fixed frame.
pub const WORLD_FRAME: &str = "world";

/// Log time (ns after the log's start `t0`) of path parameter `k`: the path spans 10 s of log
/// time.
pub fn time_of_k(k: f64) -> u64 {
    (k.clamp(0.0, 1.0) * 10.0e9).round() as u64
}

/// The wall clock in nanoseconds since the Unix epoch: a log's start time `t0`, so that a
/// viewer's timeline shows when the run happened (0 if the clock is before the epoch).
pub fn wall_clock_ns() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| u64::try_from(d.as_nanos()).unwrap_or(u64::MAX))
}

/// Line thickness (case units) of a rod of `radius` and `length`: its diameter, but at least
/// `length / 250`, so that a thin or zero-radius rod stays visible.
pub fn rod_thickness(radius: f64, length: f64) -> f64 {
    (2.0 * radius).max(length / 250.0)
}

/// Foxglove timestamp of a log time.
pub fn stamp(t: u64) -> Timestamp {
    Timestamp::new((t / 1_000_000_000) as u32, (t % 1_000_000_000) as u32)
}

/// An RGBA colour.
pub fn color(r: f64, g: f64, b: f64, a: f64) -> Color {
    Color { r, g, b, a }
}

fn v3(p: [f64; 3]) -> Vector3 {
    Vector3 {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

fn identity() -> Quaternion {
    Quaternion {
        x: 0.0,
        y: 0.0,
        z: 0.0,
        w: 1.0,
    }
}

/// Quaternion of a rotation matrix (rows).
pub fn quaternion(m: [[f64; 3]; 3]) -> Quaternion {
    let [w, x, y, z] = crate::planner::trajectory::quaternion_of(m);
    Quaternion { x, y, z, w }
}

/// Rotation matrix of an axis–angle vector.
pub fn axis_angle_matrix(r: [f64; 3]) -> [[f64; 3]; 3] {
    let th = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
    if th < 1e-15 {
        return [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    }
    let k = [r[0] / th, r[1] / th, r[2] / th];
    let (s, c) = th.sin_cos();
    let v = 1.0 - c;
    [
        [
            c + k[0] * k[0] * v,
            k[0] * k[1] * v - k[2] * s,
            k[0] * k[2] * v + k[1] * s,
        ],
        [
            k[1] * k[0] * v + k[2] * s,
            c + k[1] * k[1] * v,
            k[1] * k[2] * v - k[0] * s,
        ],
        [
            k[2] * k[0] * v - k[1] * s,
            k[2] * k[1] * v + k[0] * s,
            c + k[2] * k[2] * v,
        ],
    ]
}

fn mat_mul(a: [[f64; 3]; 3], b: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut m = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    m
}

fn apply(m: [[f64; 3]; 3], p: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| m[i][0] * p[0] + m[i][1] * p[1] + m[i][2] * p[2])
}

/// The `world → rod` transform (gravity down in Foxglove).
pub fn gravity_transform(t: u64) -> FrameTransform {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    FrameTransform {
        timestamp: Some(stamp(t)),
        parent_frame_id: WORLD_FRAME.into(),
        child_frame_id: ROD_FRAME.into(),
        translation: Some(v3([0.0; 3])),
        rotation: Some(Quaternion {
            x: h,
            y: 0.0,
            z: h,
            w: 0.0,
        }),
    }
}

/// The rod as a line of `thickness` (case units, see [`rod_thickness`]) through `points` (case
/// units), entity `id`.
pub fn rod_update(t: u64, id: &str, points: &[[f64; 3]], thickness: f64, c: Color) -> SceneUpdate {
    SceneUpdate {
        entities: vec![SceneEntity {
            timestamp: Some(stamp(t)),
            frame_id: ROD_FRAME.into(),
            id: id.into(),
            lines: vec![LinePrimitive {
                r#type: LinePrimitive::LINE_STRIP,
                pose: Some(Pose {
                    position: Some(v3([0.0; 3])),
                    orientation: Some(identity()),
                }),
                thickness,
                points: points
                    .iter()
                    .map(|p| Point3 {
                        x: p[0],
                        y: p[1],
                        z: p[2],
                    })
                    .collect(),
                color: Some(c),
            }],
            ..Default::default()
        }],
    }
}

/// The pose of the rod's cross-section at `position` with frame `frame` (row-major).
pub fn end_pose(t: u64, position: [f64; 3], frame: [[f64; 3]; 3]) -> PoseInFrame {
    PoseInFrame {
        timestamp: Some(stamp(t)),
        frame_id: ROD_FRAME.into(),
        pose: Some(Pose {
            position: Some(v3(position)),
            orientation: Some(quaternion(frame)),
        }),
    }
}

/// Length of a finger's arrow over the rod's length.
pub const FINGER_ARROW: f64 = 0.08;

/// Fingers as red arrows (entity `fingers`): each ends at its contact point and points the way
/// the finger pushes the rod, `FINGER_ARROW · length` long.
pub fn fingers_update(t: u64, fingers: &[([f64; 3], [f64; 3])], length: f64) -> SceneUpdate {
    let len = FINGER_ARROW * length;
    let arrows = fingers
        .iter()
        .map(|(p, n)| {
            // The arrow's +x is the push direction; its tail sits `len` before the contact.
            let z = frame_with_z(*n);
            let m = [0, 1, 2].map(|i| [z[i][2], z[i][0], z[i][1]]);
            let tail = [0, 1, 2].map(|i| p[i] - len * n[i]);
            ArrowPrimitive {
                pose: Some(pose_of(tail, m)),
                shaft_length: 0.7 * len,
                shaft_diameter: 0.12 * len,
                head_length: 0.3 * len,
                head_diameter: 0.3 * len,
                color: Some(color(0.9, 0.2, 0.2, 1.0)),
            }
        })
        .collect();
    SceneUpdate {
        entities: vec![SceneEntity {
            timestamp: Some(stamp(t)),
            frame_id: ROD_FRAME.into(),
            id: "fingers".into(),
            arrows,
            ..Default::default()
        }],
    }
}

fn pose_of(position: [f64; 3], m: [[f64; 3]; 3]) -> Pose {
    Pose {
        position: Some(v3(position)),
        orientation: Some(quaternion(m)),
    }
}

/// Obstacles as one entity each; `length` scales the half-space slab.
pub fn obstacles_update(
    t: u64,
    obstacles: &[std::sync::Arc<Obstacle>],
    length: f64,
) -> SceneUpdate {
    let grey = color(0.55, 0.6, 0.7, 0.6);
    let entities = obstacles
        .iter()
        .map(|o| {
            let rot = axis_angle_matrix(o.rotation());
            let mut e = SceneEntity {
                timestamp: Some(stamp(t)),
                frame_id: ROD_FRAME.into(),
                id: format!("obstacle/{}", o.name),
                ..Default::default()
            };
            match &o.shape {
                ObstacleShape::Cuboid(c) => {
                    let h = c.half_extents;
                    e.cubes.push(CubePrimitive {
                        pose: Some(pose_of(o.position(), rot)),
                        size: Some(v3([2.0 * h.x, 2.0 * h.y, 2.0 * h.z])),
                        color: Some(grey),
                    });
                }
                ObstacleShape::Ball(b) => {
                    let d = 2.0 * b.radius;
                    e.spheres.push(SpherePrimitive {
                        pose: Some(pose_of(o.position(), rot)),
                        size: Some(v3([d, d, d])),
                        color: Some(grey),
                    });
                }
                ObstacleShape::Capsule(c) => {
                    let a = [c.segment.a.x, c.segment.a.y, c.segment.a.z];
                    let b = [c.segment.b.x, c.segment.b.y, c.segment.b.z];
                    let wa = apply(rot, a).map(|v| v);
                    let wb = apply(rot, b);
                    let wa = [0, 1, 2].map(|i| wa[i] + o.position()[i]);
                    let wb = [0, 1, 2].map(|i| wb[i] + o.position()[i]);
                    let d = 2.0 * c.radius;
                    for p in [wa, wb] {
                        e.spheres.push(SpherePrimitive {
                            pose: Some(pose_of(p, rot)),
                            size: Some(v3([d, d, d])),
                            color: Some(grey),
                        });
                    }
                    let axis = [wb[0] - wa[0], wb[1] - wa[1], wb[2] - wa[2]];
                    let len = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
                    if len > 0.0 {
                        let z = axis.map(|v| v / len);
                        let m = frame_with_z(z);
                        e.cylinders.push(CylinderPrimitive {
                            pose: Some(pose_of([0, 1, 2].map(|i| 0.5 * (wa[i] + wb[i])), m)),
                            size: Some(v3([d, d, len])),
                            bottom_scale: 1.0,
                            top_scale: 1.0,
                            color: Some(grey),
                        });
                    }
                }
                ObstacleShape::Cylinder(c) => {
                    // parry's axis is local y; Foxglove's is local z: rotate z onto y.
                    let z_to_y = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]];
                    let d = 2.0 * c.radius;
                    e.cylinders.push(CylinderPrimitive {
                        pose: Some(pose_of(o.position(), mat_mul(rot, z_to_y))),
                        size: Some(v3([d, d, 2.0 * c.half_height])),
                        bottom_scale: 1.0,
                        top_scale: 1.0,
                        color: Some(grey),
                    });
                }
                ObstacleShape::ConvexHull(h) => {
                    let (v, idx) = h.to_trimesh();
                    e.triangles.push(triangles(o, rot, &v, &idx, grey));
                }
                ObstacleShape::TriMesh(m) => {
                    e.triangles
                        .push(triangles(o, rot, m.vertices(), m.indices(), grey));
                }
                ObstacleShape::HalfSpace(n) => {
                    // A slab 4L wide whose top face is the boundary plane.
                    let m = frame_with_z(apply(rot, *n));
                    let th = 0.02 * length;
                    let nz = apply(rot, *n);
                    let c = [0, 1, 2].map(|i| o.position()[i] - 0.5 * th * nz[i]);
                    e.cubes.push(CubePrimitive {
                        pose: Some(pose_of(c, m)),
                        size: Some(v3([4.0 * length, 4.0 * length, th])),
                        color: Some(grey),
                    });
                }
            }
            e
        })
        .collect();
    SceneUpdate { entities }
}

fn triangles(
    o: &Obstacle,
    rot: [[f64; 3]; 3],
    v: &[parry3d_f64::math::Vector],
    idx: &[[u32; 3]],
    c: Color,
) -> TriangleListPrimitive {
    let _ = o;
    TriangleListPrimitive {
        pose: Some(pose_of(o.position(), rot)),
        points: idx
            .iter()
            .flat_map(|t| t.iter().map(|&i| v[i as usize]))
            .map(|p| Point3 {
                x: p.x,
                y: p.y,
                z: p.z,
            })
            .collect(),
        color: Some(c),
    }
}

/// A rotation whose third column is the unit vector `z`.
fn frame_with_z(z: [f64; 3]) -> [[f64; 3]; 3] {
    let helper = if z[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let x = cross(helper, z);
    let nx = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
    let x = x.map(|v| v / nx);
    let y = cross(z, x);
    [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rod::kinematics::rotation;

    #[test]
    fn quaternion_round_trips_a_rotation() {
        let m = rotation(0.3, 1.1, -0.7);
        let q = quaternion(m);
        let n = (q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w).sqrt();
        assert!((n - 1.0).abs() < 1e-12);
        // Rotate e_x with q and compare with m's first column.
        let (x, y, z, w) = (q.x, q.y, q.z, q.w);
        let r00 = 1.0 - 2.0 * (y * y + z * z);
        let r10 = 2.0 * (x * y + z * w);
        let r20 = 2.0 * (x * z - y * w);
        assert!((r00 - m[0][0]).abs() < 1e-12);
        assert!((r10 - m[1][0]).abs() < 1e-12);
        assert!((r20 - m[2][0]).abs() < 1e-12);
    }

    #[test]
    fn axis_angle_matches_quarter_turn() {
        let m = axis_angle_matrix([0.0, 0.0, std::f64::consts::FRAC_PI_2]);
        assert!((apply(m, [1.0, 0.0, 0.0])[1] - 1.0).abs() < 1e-12);
    }
}
