//! The controlled end's course in its own pose space, as a replay drives it: a pose line
//! ([`super::pose_line`]) or the end poses of a coefficient-space path (the optimal path's or
//! the straight-line path's), either with position terms added
//! ([`super::pose_optimisation`]).

use super::endpoints::EndPose;
use super::path::DeformationPath;
use super::pose_line::{Detour, PoseLine};
use crate::rod::kinematics::Shape;
use crate::rod::model::Model;
use std::sync::Arc;

/// What the course follows before its terms.
#[derive(Clone, Debug)]
pub enum Course {
    /// A line in the end's pose space.
    Line(PoseLine),
    /// The end poses of the shapes of `path(z)`.
    Path(Arc<(DeformationPath, Vec<f64>)>),
}

/// The end's course: [`Course`] plus terms on its position, the `m`-th times
/// `k^(m+1) (1 − k)` (units of L; none unless optimised).
#[derive(Clone, Debug)]
pub struct EndCourse {
    /// What it follows.
    pub course: Course,
    terms: Vec<[f64; 3]>,
}

impl EndCourse {
    /// Along pose line `line`.
    pub fn line(line: PoseLine) -> EndCourse {
        EndCourse {
            course: Course::Line(line),
            terms: Vec::new(),
        }
    }

    /// Along the end poses of `path(z)`.
    pub fn path(path: DeformationPath, z: Vec<f64>) -> EndCourse {
        EndCourse {
            course: Course::Path(Arc::new((path, z))),
            terms: Vec::new(),
        }
    }

    /// This course with the position terms `terms` (the `m`-th times `k^(m+1) (1 − k)`, units
    /// of L) in place of its own.
    pub fn with_terms(&self, terms: Vec<[f64; 3]>) -> EndCourse {
        EndCourse {
            terms,
            ..self.clone()
        }
    }

    /// The position terms (see [`Self::with_terms`]; empty on a course not optimised).
    pub fn terms(&self) -> &[[f64; 3]] {
        &self.terms
    }

    /// How the pose line leaves the straight line (`None` along a path's end poses).
    pub fn detour(&self) -> Option<Detour> {
        match &self.course {
            Course::Line(l) => Some(l.detour),
            Course::Path(_) => None,
        }
    }

    /// The end's position (units of L) and Euler angles at `k`.
    pub fn pose_at(&self, model: &Model, k: f64) -> ([f64; 3], [f64; 3]) {
        let (mut x, angles) = match &self.course {
            Course::Line(l) => (l.position(k), l.angles(k)),
            Course::Path(pz) => {
                let (path, z) = &**pz;
                let mut a = vec![0.0; path.n()];
                let mut shape = Shape::default();
                path.shape_at(z, k, &mut a);
                model.evaluate_into(&a, &mut shape);
                (
                    shape.positions[model.boundary(1.0)],
                    model.angles_at(&a, 1.0),
                )
            }
        };
        let mut b = 1.0 - k;
        for t in &self.terms {
            b *= k;
            for i in 0..3 {
                x[i] += b * t[i];
            }
        }
        (x, angles)
    }

    /// The end pose at `k`, as a replay holds it.
    pub fn end_pose(&self, model: &Model, k: f64) -> EndPose {
        let (x, angles) = self.pose_at(model, k);
        EndPose::at(model, x, angles)
    }
}
