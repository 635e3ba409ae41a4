//! The controlled end's pose: constraints that prescribe it, reading it off a shape, and the
//! start and goal static solves (so that both ends of a path are equilibria).

use crate::constraints::{Angle, Bound, Constraint, OrientationConstraint, PositionConstraint};
use crate::rod::layout::Field;
use crate::rod::model::Model;
use crate::statics::problem::StaticProblem;
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
    pub fn constraints(&self, model: &Model) -> Vec<Constraint> {
        let mut out: Vec<Constraint> = Vec::new();
        if !self.position.is_empty() {
            out.push(Constraint::from(PositionConstraint {
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
            out.push(Constraint::from(OrientationConstraint::new(
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

/// A starting shape for the solve of an end whose orientation is fully given: `a0` (the natural
/// state with its small perturbation) with each angle field's constant and linear terms set so
/// that the field runs linearly from the held end's angle `held` at `s = 0` to the end's angle
/// `end` at `s = L` — a rod already bent and twisted towards its target frame, instead of the
/// straight rod that must find its way to `φ(L) = π` on its own. Unless the held end fixes
/// `φ(0)` itself (`phi_fixed`), `φ` starts constant at the end's value (under a `φ + ψ` clamp
/// the bend's direction is free at the base), and `ψ(0)` keeps the held end's `φ + ψ`.
pub fn seed_towards(
    model: &Model,
    a0: &[f64],
    held: [f64; 3],
    phi_fixed: bool,
    end: [f64; 3],
) -> Vec<f64> {
    let mut a = a0.to_vec();
    let basis = &model.layout.basis;
    if basis.split().is_some() {
        return a;
    }
    let phi0 = if phi_fixed { held[0] } else { end[0] };
    let held = [phi0, held[1], held[0] + held[2] - phi0];
    for (i, field) in [Field::Phi, Field::Theta, Field::Psi]
        .into_iter()
        .enumerate()
    {
        let Some(off) = model.layout.offset(field) else {
            continue;
        };
        let n = model.layout.field(&a, field).map_or(0, <[f64]>::len);
        if n < 2 {
            continue;
        }
        // The perturbation's own values at the ends, so that the seed meets both exactly.
        a[off] = 0.0;
        a[off + 1] = 0.0;
        let c = &a[off..off + n];
        let (p0, p1) = (basis.eval(c, 0.0), basis.eval(c, 1.0));
        a[off] = held[i] - p0;
        a[off + 1] = (end[i] - p1) - (held[i] - p0);
    }
    a
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
