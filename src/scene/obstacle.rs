//! Rigid obstacles as parry3d-f64 shapes with poses, and the signed distance from a point with
//! its gradient (the outward normal), in the case's units.
//!
//! parry's `distance` is 0 once shapes touch and has no gradient inside, so the signed distance
//! uses point projection with the inside flag. Half-spaces are evaluated analytically (parry's
//! contact query mishandles a half-space as second shape). A triangle mesh must be closed and
//! consistently oriented (built with `ORIENTED`) for inside points to be recognised;
//! [`crate::scene::mesh::check_solid`] checks that.

use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::{Ball, Capsule, ConvexPolyhedron, Cuboid, Cylinder, TriMesh};
use std::sync::Arc;

mod lanes;
pub(crate) use lanes::BATCH;

/// Geometry of an obstacle in its local frame.
#[derive(Clone)]
pub enum ObstacleShape {
    /// Box with half extents.
    Cuboid(Cuboid),
    /// Sphere.
    Ball(Ball),
    /// Capsule between two local points.
    Capsule(Capsule),
    /// Cylinder with its axis along local y (parry's convention).
    Cylinder(Cylinder),
    /// Convex hull of points.
    ConvexHull(Arc<ConvexPolyhedron>),
    /// Closed triangle mesh.
    TriMesh(Arc<TriMesh>),
    /// The solid `n · p ≤ 0` in the local frame (`n` the unit outward normal).
    HalfSpace([f64; 3]),
}

impl ObstacleShape {
    /// A sphere of `radius`.
    pub fn ball(radius: f64) -> ObstacleShape {
        ObstacleShape::Ball(Ball::new(radius))
    }

    /// A box with `half_extents` along its local x, y, z.
    pub fn cuboid(half_extents: [f64; 3]) -> ObstacleShape {
        ObstacleShape::Cuboid(Cuboid::new(half_extents.into()))
    }

    /// A cylinder of `radius` whose axis runs along its local y, `half_height` either way.
    pub fn cylinder(half_height: f64, radius: f64) -> ObstacleShape {
        ObstacleShape::Cylinder(Cylinder::new(half_height, radius))
    }

    /// A capsule: the points within `radius` of the segment from `a` to `b`.
    pub fn capsule(a: [f64; 3], b: [f64; 3], radius: f64) -> ObstacleShape {
        let v = |p: [f64; 3]| Vector::new(p[0], p[1], p[2]);
        ObstacleShape::Capsule(Capsule::new(v(a), v(b), radius))
    }

    /// The convex hull of `points`; `Err` when there are fewer than 4 or they span no volume.
    pub fn convex_hull(points: &[[f64; 3]]) -> Result<ObstacleShape, String> {
        if points.len() < 4 {
            return Err("a convex hull needs at least 4 points".into());
        }
        const DEGENERATE: &str = "points are degenerate (coplanar or collinear): no convex hull";
        if !spans_volume(points) {
            return Err(DEGENERATE.into());
        }
        let pts: Vec<Vector> = points
            .iter()
            .map(|p| Vector::new(p[0], p[1], p[2]))
            .collect();
        let hull = ConvexPolyhedron::from_convex_hull(&pts).ok_or(DEGENERATE)?;
        Ok(ObstacleShape::ConvexHull(Arc::new(hull)))
    }

    /// The half-space `n · p ≤ 0` (local frame) with outward normal along `normal`; `Err`
    /// when it is (nearly) zero.
    pub fn half_space(normal: [f64; 3]) -> Result<ObstacleShape, String> {
        if normal.iter().any(|c| !c.is_finite()) {
            return Err("must be finite".into());
        }
        let len = (normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]).sqrt();
        if len < 1e-12 {
            return Err("must be non-zero".into());
        }
        Ok(ObstacleShape::HalfSpace(normal.map(|c| c / len)))
    }

    /// A closed triangle mesh whose faces wind counter-clockwise seen from outside; `Err` says
    /// what is wrong with it (an index out of range, a hole, inside-out, flat, …), naming
    /// triangles by their index.
    pub fn triangle_mesh(
        vertices: &[[f64; 3]],
        triangles: &[[u32; 3]],
    ) -> Result<ObstacleShape, String> {
        if let Some(t) = triangles
            .iter()
            .position(|t| t.iter().any(|&i| i as usize >= vertices.len()))
        {
            return Err(format!(
                "triangle {t} refers to a vertex beyond the {} given",
                vertices.len()
            ));
        }
        crate::scene::mesh::check_solid(vertices, triangles)
            .map_err(|d| d.describe(|t| format!("triangle {t}")))?;
        Self::checked_triangle_mesh(vertices, triangles.to_vec())
    }

    /// The parry mesh of a mesh that [`crate::scene::mesh::check_solid`] accepted.
    pub(crate) fn checked_triangle_mesh(
        vertices: &[[f64; 3]],
        triangles: Vec<[u32; 3]>,
    ) -> Result<ObstacleShape, String> {
        use parry3d_f64::shape::TriMeshFlags;
        let verts = vertices.iter().map(|p| Vector::new(p[0], p[1], p[2]));
        let mesh = TriMesh::with_flags(
            verts.collect(),
            triangles,
            TriMeshFlags::ORIENTED
                | TriMeshFlags::MERGE_DUPLICATE_VERTICES
                | TriMeshFlags::FIX_INTERNAL_EDGES,
        )
        .map_err(|e| format!("invalid mesh: {e:?}"))?;
        Ok(ObstacleShape::TriMesh(Arc::new(mesh)))
    }
}

impl std::fmt::Debug for ObstacleShape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let name = match self {
            ObstacleShape::Cuboid(_) => "cuboid",
            ObstacleShape::Ball(_) => "ball",
            ObstacleShape::Capsule(_) => "capsule",
            ObstacleShape::Cylinder(_) => "cylinder",
            ObstacleShape::ConvexHull(_) => "convex_hull",
            ObstacleShape::TriMesh(_) => "triangle_mesh",
            ObstacleShape::HalfSpace(_) => "half_space",
        };
        f.write_str(name)
    }
}

/// An obstacle placed in the world.
#[derive(Clone, Debug)]
pub struct Obstacle {
    /// Name from the case file.
    pub name: String,
    /// Local geometry.
    pub shape: ObstacleShape,
    position: [f64; 3],
    rotation: [f64; 3],
    pose: Pose,
    rotated: bool,
}

fn v3(p: [f64; 3]) -> Vector {
    Vector::new(p[0], p[1], p[2])
}

impl Obstacle {
    /// `shape` placed with its local origin at `position`, rotated by the axis–angle vector
    /// `rotation` (radians).
    pub fn new(name: String, shape: ObstacleShape, position: [f64; 3], rotation: [f64; 3]) -> Self {
        Obstacle {
            name,
            shape,
            position,
            rotation,
            pose: Pose::new(v3(position), v3(rotation)),
            rotated: rotation != [0.0; 3],
        }
    }

    /// World position of the local origin.
    pub fn position(&self) -> [f64; 3] {
        self.position
    }

    /// Rotation as an axis–angle vector (radians).
    pub fn rotation(&self) -> [f64; 3] {
        self.rotation
    }

    /// The parry pose of the obstacle.
    pub fn pose(&self) -> Pose {
        self.pose
    }

    /// World point `pv` in the obstacle's frame.
    #[inline(always)]
    fn to_local(&self, pv: Vector) -> Vector {
        if self.rotated {
            self.pose.inverse_transform_point(pv)
        } else {
            pv - self.pose.translation
        }
    }

    /// Projection of the local point `pl` onto the surface, in the local frame (`None` for a
    /// half-space).
    #[inline(always)]
    fn project_local(&self, pl: Vector) -> Option<parry3d_f64::query::PointProjection> {
        Some(match &self.shape {
            ObstacleShape::HalfSpace(_) => return None,
            ObstacleShape::Cuboid(s) => project_cuboid(s.half_extents, pl),
            ObstacleShape::Ball(s) => s.project_local_point(pl, false),
            ObstacleShape::Capsule(s) => project_capsule(s, pl),
            ObstacleShape::Cylinder(s) => s.project_local_point(pl, false),
            ObstacleShape::ConvexHull(s) => s.project_local_point(pl, false),
            ObstacleShape::TriMesh(s) => s.project_local_point(pl, false),
        })
    }

    /// Signed distance from world point `p` to the obstacle's surface (negative inside) and its
    /// gradient with respect to `p` (unit, pointing away from the obstacle).
    pub fn signed_distance(&self, p: [f64; 3]) -> (f64, [f64; 3]) {
        let pose = &self.pose;
        let pv = v3(p);
        // In the obstacle's frame: one transform in, the normal rotated out.
        let pl = self.to_local(pv);
        let Some(proj) = self.project_local(pl) else {
            let ObstacleShape::HalfSpace(n) = &self.shape else {
                unreachable!()
            };
            let nw = pose.rotation * v3(*n);
            let d = (pv - pose.translation).dot(nw);
            return (d, [nw.x, nw.y, nw.z]);
        };
        let diff = pl - proj.point;
        let dist = diff.length();
        if dist < 1e-14 {
            // On the surface: the gradient of the signed distance by central differences.
            return (0.0, self.fallback_normal(p));
        }
        let n = if self.rotated {
            pose.rotation * (diff / dist)
        } else {
            diff / dist
        };
        if proj.is_inside {
            (-dist, [-n.x, -n.y, -n.z])
        } else {
            (dist, [n.x, n.y, n.z])
        }
    }

    fn fallback_normal(&self, p: [f64; 3]) -> [f64; 3] {
        let h = 1e-7;
        let mut g = [0.0; 3];
        for k in 0..3 {
            let (mut a, mut b) = (p, p);
            a[k] += h;
            b[k] -= h;
            g[k] = (self.signed_distance_value(a) - self.signed_distance_value(b)) / (2.0 * h);
        }
        let n = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt().max(1e-300);
        [g[0] / n, g[1] / n, g[2] / n]
    }

    /// Whether the signed distance changes by at most `|p − q|` between any two points (true of
    /// the solids' exact signed distance; a triangle mesh's sign comes from a point-in-mesh
    /// test, which is not guaranteed to be consistent, so it does not count).
    pub fn distance_is_lipschitz(&self) -> bool {
        !matches!(self.shape, ObstacleShape::TriMesh(_))
    }

    /// Signed distance only (no normal): the value of [`Obstacle::signed_distance`].
    #[inline(always)]
    pub fn signed_distance_value(&self, p: [f64; 3]) -> f64 {
        let pl = self.to_local(v3(p));
        match self.project_local(pl) {
            None => self.signed_distance(p).0,
            Some(proj) => {
                let d = (pl - proj.point).length();
                if d < 1e-14 {
                    0.0
                } else if proj.is_inside {
                    -d
                } else {
                    d
                }
            }
        }
    }
}

/// parry's projection of the local point `pt` onto the surface of the box with half extents
/// `h` (`Aabb::do_project_local_point` of `Cuboid::project_local_point`, not solid), operation
/// for operation so that the result is the same to the bit, but inlined: parry's is a call
/// into another crate that the obstacle rows made for every point.
#[inline(always)]
fn project_cuboid(h: Vector, pt: Vector) -> parry3d_f64::query::PointProjection {
    let mins_pt = -h - pt;
    let pt_maxs = pt - h;
    let shift = mins_pt.max(Vector::ZERO) - pt_maxs.max(Vector::ZERO);
    if shift != Vector::ZERO {
        return parry3d_f64::query::PointProjection::new(false, pt + shift);
    }
    // Inside: push the point out through the nearest face (ties: x, then y, then z; a zero
    // coordinate counts as negative, as in parry). The box's centre is the origin, so the
    // centred point is `pt` and `sign · pt` is `|pt|`.
    let sgn = Vector::ONE.copysign(pt);
    let diff = h - sgn * pt;
    let shift = if diff.x <= diff.y && diff.x <= diff.z {
        Vector::new(diff.x * sgn.x, 0.0, 0.0)
    } else if diff.y <= diff.x && diff.y <= diff.z {
        Vector::new(0.0, diff.y * sgn.y, 0.0)
    } else {
        Vector::new(0.0, 0.0, diff.z * sgn.z)
    };
    parry3d_f64::query::PointProjection::new(true, pt + shift)
}

/// parry's projection of the local point `pt` onto the surface of the capsule `c`
/// (`Capsule::project_local_point`, not solid, with the segment projection it calls), operation
/// for operation so that the result is the same to the bit, but inlined and without the
/// segment's "inside" test, which the capsule does not read: parry's took a third of a planar
/// plan's time. A point on the capsule's axis (a direction parry chooses) is left to parry.
#[inline(always)]
fn project_capsule(c: &Capsule, pt: Vector) -> parry3d_f64::query::PointProjection {
    let (a, b) = (c.segment.a, c.segment.b);
    let ab = b - a;
    let ab_ap = ab.dot(pt - a);
    let sqnab = ab.length_squared();
    let on_axis = if ab_ap <= 0.0 {
        a
    } else if ab_ap >= sqnab {
        b
    } else {
        a + ab * (ab_ap / sqnab)
    };
    let (dir, dist) = (pt - on_axis).normalize_and_length();
    if dist >= f64::EPSILON {
        parry3d_f64::query::PointProjection::new(dist <= c.radius, on_axis + dir * c.radius)
    } else {
        c.project_local_point(pt, false)
    }
}

/// True when the points are not all (nearly) coplanar: the covariance has three non-negligible
/// eigenvalues.
fn spans_volume(points: &[[f64; 3]]) -> bool {
    let n = points.len() as f64;
    let mean: Vec<f64> = (0..3)
        .map(|k| points.iter().map(|p| p[k]).sum::<f64>() / n)
        .collect();
    let cov = nalgebra::Matrix3::from_fn(|i, j| {
        points
            .iter()
            .map(|p| (p[i] - mean[i]) * (p[j] - mean[j]))
            .sum::<f64>()
            / n
    });
    let ev = cov.symmetric_eigenvalues();
    ev.min() > 1e-12 * ev.max().max(1e-300)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Numbers uniform in [−1, 1) from the xorshift* generator seeded with `seed`.
    fn uniform(seed: u64) -> impl FnMut() -> f64 {
        let mut s = seed;
        move || {
            s ^= s >> 12;
            s ^= s << 25;
            s ^= s >> 27;
            2.0 * ((s.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64) - 1.0
        }
    }

    /// The inlined box projection is parry's, to the bit: points inside, outside, on faces,
    /// edges and corners, at the centre, with zero and negative-zero coordinates and with ties
    /// between faces.
    #[test]
    fn cuboid_projection_is_parrys_to_the_bit() {
        let mut next = uniform(0x2545_F491_4F6C_DD1D);
        let specials = [0.0, -0.0, 0.2, -0.2, 0.5, -0.5, 0.1, -0.1, 1e-300, 0.7];
        for he in [[0.2, 0.5, 0.5], [0.3, 0.3, 0.3], [1e-3, 2.0, 0.7]] {
            let cub = Cuboid::new(Vector::new(he[0], he[1], he[2]));
            let mut points: Vec<Vector> = (0..20_000)
                .map(|_| Vector::new(next(), next(), next()) * 0.8)
                .collect();
            for &a in &specials {
                for &b in &specials {
                    for &c in &specials {
                        points.push(Vector::new(a, b, c));
                    }
                }
            }
            for pt in points {
                let ours = project_cuboid(cub.half_extents, pt);
                let theirs = cub.project_local_point(pt, false);
                assert_eq!(ours.is_inside, theirs.is_inside, "{pt:?}");
                for k in 0..3 {
                    assert_eq!(
                        ours.point[k].to_bits(),
                        theirs.point[k].to_bits(),
                        "{he:?} {pt:?}"
                    );
                }
            }
        }
    }

    /// The inlined capsule projection is parry's, to the bit: points inside and outside, beyond
    /// either end cap, on the axis (left to parry) and at the end points, for capsules along an
    /// axis, slanted and degenerate (a ball).
    #[test]
    fn capsule_projection_is_parrys_to_the_bit() {
        let mut next = uniform(0x9E37_79B9_7F4A_7C15);
        let capsules = [
            ([0.0, -0.3, 0.0], [0.0, 0.3, 0.0], 0.1),
            ([-0.2, 0.1, 0.3], [0.4, -0.2, -0.1], 0.05),
            ([0.1, 0.1, 0.1], [0.1, 0.1, 0.1], 0.2),
        ];
        for (a, b, r) in capsules {
            let (a, b) = (Vector::new(a[0], a[1], a[2]), Vector::new(b[0], b[1], b[2]));
            let cap = Capsule::new(a, b, r);
            let mut points: Vec<Vector> = (0..20_000)
                .map(|_| Vector::new(next(), next(), next()) * 0.6)
                .collect();
            points.extend([a, b, (a + b) * 0.5, a * 0.25 + b * 0.75, Vector::ZERO]);
            for pt in points {
                let ours = project_capsule(&cap, pt);
                let theirs = cap.project_local_point(pt, false);
                assert_eq!(ours.is_inside, theirs.is_inside, "{pt:?}");
                for k in 0..3 {
                    assert_eq!(ours.point[k].to_bits(), theirs.point[k].to_bits(), "{pt:?}");
                }
            }
        }
    }
}
