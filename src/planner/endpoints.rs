//! The controlled end's pose: constraints that prescribe it, reading it off a shape, and the
//! start and goal static solves (so that both ends of a path are equilibria).

use crate::constraints::{Angle, Bound, Constraint, OrientationConstraint, PositionConstraint};
use crate::layout::Field;
use crate::model::Model;
use crate::problem::StaticProblem;
use crate::statics::{StaticOptions, StaticSolution, solve_static};

/// Pose of `P(L)`: position rows `(component, x/L)` and Euler-angle rows.
#[derive(Clone, Debug, PartialEq)]
pub struct EndPose {
    /// Prescribed coordinates (dimensionless).
    pub position: Vec<(usize, f64)>,
    /// Prescribed angles (radians).
    pub angles: Vec<(Angle, f64)>,
}

/// Below this `|sin θ(L)|` the frame at `L` depends on `φ + ψ` only, and the replay prescribes
/// that sum instead of `φ` and `ψ` separately.
const GIMBAL: f64 = 1e-3;

impl EndPose {
    /// The full pose of shape `a` at `s = L`: every position component and every angle field
    /// of the layout.
    pub fn of(model: &Model, a: &[f64], positions: &[[f64; 3]]) -> EndPose {
        let b = model.boundary(1.0);
        let position = model
            .layout
            .components()
            .iter()
            .map(|&k| (k, positions[b][k]))
            .collect();
        let [phi, theta, psi] = model.angles_at(a, 1.0);
        let angles = if model.layout.spatial {
            if theta.sin().abs() < GIMBAL {
                vec![
                    (Angle::Field(Field::Theta), theta),
                    (Angle::PhiPlusPsi, phi + psi),
                ]
            } else {
                vec![
                    (Angle::Field(Field::Phi), phi),
                    (Angle::Field(Field::Theta), theta),
                    (Angle::Field(Field::Psi), psi),
                ]
            }
        } else {
            vec![(Angle::Field(Field::Theta), theta)]
        };
        EndPose { position, angles }
    }

    /// Constraint blocks prescribing this pose.
    pub fn constraints(&self, model: &Model) -> Vec<Box<dyn Constraint>> {
        let mut out: Vec<Box<dyn Constraint>> = Vec::new();
        if !self.position.is_empty() {
            out.push(Box::new(PositionConstraint {
                name: "controlled end position".into(),
                boundary: model.boundary(1.0),
                rows: self
                    .position
                    .iter()
                    .map(|&(k, v)| (k, Bound::Equal(v)))
                    .collect(),
            }));
        }
        if !self.angles.is_empty() {
            out.push(Box::new(OrientationConstraint::new(
                model,
                "controlled end orientation".into(),
                1.0,
                self.angles.clone(),
            )));
        }
        out
    }

    /// `base` (the case's fixed conditions and obstacles) plus this pose.
    pub fn problem(&self, base: &StaticProblem) -> StaticProblem {
        let mut cons = base.constraints.clone();
        cons.extend(self.constraints(&base.model));
        let mut p = StaticProblem::new(base.model.clone(), cons);
        p.objective = base.objective;
        p
    }
}

/// Solves the static shape for `pose` from `a_start`.
pub fn solve_end(
    base: &StaticProblem,
    pose: &EndPose,
    a_start: &[f64],
    opts: &StaticOptions,
) -> StaticSolution {
    let mut p = pose.problem(base);
    solve_static(&mut p, a_start, opts)
}
