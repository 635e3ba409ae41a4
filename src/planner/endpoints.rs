//! The controlled end's pose: constraints that prescribe it, reading it off a shape, and the
//! start and goal static solves (so that both ends of a path are equilibria).

use crate::constraints::{Angle, Bound, Constraint, OrientationConstraint, PositionConstraint};
use crate::rod::layout::Field;
use crate::rod::model::Model;
use crate::statics::problem::StaticProblem;
use crate::statics::{StaticOptions, StaticSolution, solve_static};

/// A full orientation of an end, resolved into Euler angles once its reference frame is known
/// (see [`super::orientation`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EndRotation {
    /// The rotation (row-major, case frame).
    pub matrix: [[f64; 3]; 3],
    /// The `φ` the user wrote, if the rotation came from Euler angles (it breaks the tie
    /// between mirror routes).
    pub written_phi: Option<f64>,
}

/// A validated end: pose rows in dimensionless units plus an optional coefficient vector.
#[derive(Clone, Debug)]
pub struct End {
    /// `(component, x/L)` rows.
    pub position: Vec<(usize, f64)>,
    /// `(field, angle)` rows (filled from `rotation` when that is given).
    pub angles: Vec<(crate::rod::layout::Field, f64)>,
    /// A full orientation whose Euler branch is still to be chosen.
    pub rotation: Option<EndRotation>,
    /// Coefficients (the shape, or the solve's start).
    pub shape: Option<Vec<f64>>,
}

impl End {
    /// Whether the end is a pose (to be solved for), not only coefficients.
    pub fn is_pose(&self) -> bool {
        !self.position.is_empty() || !self.angles.is_empty() || self.rotation.is_some()
    }

    /// Fills in the angles of a full orientation, in the branch that continues from
    /// `reference` (the Euler angles of the frame it continues from; see
    /// [`super::orientation`]); a planar tie goes to the branch nearer `held` (the held end's
    /// angles). Errors name the problem (a planar rod's end turned about another axis than y,
    /// a shape of the wrong size or with a non-finite coefficient).
    pub fn resolve(
        &mut self,
        model: &crate::rod::model::Model,
        reference: [f64; 3],
        held: [f64; 3],
    ) -> Result<(), String> {
        let planar = !model.layout.spatial;
        use crate::rod::layout::Field;
        if let Some(a) = &self.shape {
            let n = model.layout.len();
            if a.len() != n {
                return Err(format!(
                    "the shape has {} coefficients; the problem has {n}",
                    a.len()
                ));
            }
            if let Some(i) = a.iter().position(|x| !x.is_finite()) {
                return Err(format!("coefficient {i} of the shape is not finite"));
            }
        }
        let Some(r) = self.rotation.take() else {
            return Ok(());
        };
        if planar {
            let theta = super::orientation::planar_branch(r.matrix, reference[1], held[1]).ok_or(
                "a planar rod's end turns about y only: the orientation is not a rotation about y",
            )?;
            self.angles = vec![(Field::Theta, theta)];
        } else {
            // In the rod's angles' frame; a written φ is the case's, not the fields'.
            let written_phi = r.written_phi.filter(|_| model.frame.is_none());
            let matrix = model.rotation_to_angles(r.matrix);
            let [phi, theta, psi] =
                super::orientation::euler_branch(matrix, reference, written_phi);
            self.angles = vec![(Field::Phi, phi), (Field::Theta, theta), (Field::Psi, psi)];
        }
        Ok(())
    }

    /// The controlled end at `position` (case units) with orientation `rotation` (row-major,
    /// case axes; on a planar rod a rotation about y), for a rod of `problem`; its Euler branch
    /// is chosen when the plan is set up.
    pub fn pose(problem: &StaticProblem, position: [f64; 3], rotation: [[f64; 3]; 3]) -> End {
        let l = problem.model.rod.length;
        End {
            position: problem
                .model
                .layout
                .components()
                .iter()
                .map(|&k| (k, position[k] / l))
                .collect(),
            angles: Vec::new(),
            rotation: Some(EndRotation {
                matrix: rotation,
                written_phi: None,
            }),
            shape: None,
        }
    }

    /// The controlled end at `position` (case units) with Euler angles `angles` (radians), as
    /// a case file writes them: `[θ]` on a planar rod, kept as written (θ + 2π is another
    /// shape, a loop); `[φ, θ, ψ]` (ZYZ, case axes) on a 3D rod, whose branch is chosen when
    /// the plan is set up, nearest the written φ (equivalent spellings give the same plan).
    /// Errors name the problem (a count of angles that is not the rod's).
    pub fn euler(
        problem: &StaticProblem,
        position: [f64; 3],
        angles: &[f64],
    ) -> Result<End, String> {
        use crate::rod::layout::Field;
        let mut end = End::position(problem, position);
        match (problem.model.layout.spatial, angles) {
            (false, &[theta]) => end.angles = vec![(Field::Theta, theta)],
            (true, &[phi, theta, psi]) => {
                end.rotation = Some(EndRotation {
                    matrix: crate::rod::kinematics::rotation(phi, theta, psi),
                    written_phi: Some(phi),
                });
            }
            (spatial, _) => {
                return Err(format!(
                    "{} Euler angles given; a {} rod's end takes {}",
                    angles.len(),
                    if spatial { "3D" } else { "planar" },
                    if spatial {
                        "3: [phi, theta, psi]"
                    } else {
                        "1: [theta]"
                    }
                ));
            }
        }
        Ok(end)
    }

    /// The controlled end at `position` (case units), its orientation left free (as a case
    /// file's end with a position and no angles), for a rod of `problem`.
    pub fn position(problem: &StaticProblem, position: [f64; 3]) -> End {
        let mut end = End::pose(
            problem,
            position,
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        );
        end.rotation = None;
        end
    }

    /// The shape of coefficients `a` itself, not solved for.
    pub fn shape(a: Vec<f64>) -> End {
        End {
            position: Vec::new(),
            angles: Vec::new(),
            rotation: None,
            shape: Some(a),
        }
    }
}

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
        EndPose::at(
            model,
            positions[model.boundary(1.0)],
            model.angles_at(a, 1.0),
        )
    }

    /// The pose of the end at `position` (units of L) with Euler angles `angles` (`θ` alone
    /// read on a planar rod): the layout's position components and angle fields.
    pub fn at(model: &Model, position: [f64; 3], angles: [f64; 3]) -> EndPose {
        let position = model
            .layout
            .components()
            .iter()
            .map(|&k| (k, position[k]))
            .collect();
        let [phi, theta, psi] = angles;
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

/// Starting shapes for a second search of an end pose whose solve from its first start did
/// not converge (the rod caught on an obstacle it was pulled through on its way): `a0` (the
/// problem's initial shape) where that was not the first start (`first_bent`), then rods bent
/// by [`seed_towards`] from the held frame `held` to end tangents chosen from the end's
/// position `position` (units of L, all the layout's components): the circular arc from the
/// held tangent through the chord to the position, the chord's own direction, and on a planar
/// rod the arc's end tangent turned a quarter turn either way (a rod that goes round an
/// obstacle on the other side); before them, where the end's angles are prescribed (`angles`)
/// and the first start was not already bent to them, a rod bent to those.
pub fn retry_seeds(
    model: &Model,
    a0: &[f64],
    first_bent: bool,
    held: ([f64; 3], bool),
    position: Option<[f64; 3]>,
    angles: Option<[f64; 3]>,
) -> Vec<Vec<f64>> {
    let mut seeds = Vec::new();
    if first_bent {
        seeds.push(a0.to_vec());
    }
    let (h, phi_fixed) = held;
    let bent = |end: [f64; 3]| seed_towards(model, a0, h, phi_fixed, end);
    if let Some(end) = angles.filter(|_| !first_bent) {
        seeds.push(bent(end));
    }
    let Some(x) = position else {
        return distinct(seeds, a0, first_bent);
    };
    let d = model.to_angles(std::array::from_fn(|i| x[i] - model.base[i]));
    let n = d.iter().map(|v| v * v).sum::<f64>().sqrt();
    if n.is_nan() || n <= 1e-9 {
        return distinct(seeds, a0, first_bent);
    }
    let d = d.map(|v| v / n);
    let frame = crate::rod::kinematics::rotation(h[0], h[1], h[2]);
    let t0 = [frame[0][2], frame[1][2], frame[2][2]];
    let dot = (0..3).map(|i| d[i] * t0[i]).sum::<f64>();
    let arc: [f64; 3] = std::array::from_fn(|i| 2.0 * dot * d[i] - t0[i]);
    // Euler angles of an end tangent `t`, without twist about it (φ + ψ held).
    let angles_of = |t: [f64; 3]| -> [f64; 3] {
        if model.layout.spatial {
            let theta = t[2].clamp(-1.0, 1.0).acos();
            let phi = if t[0].hypot(t[1]) > 1e-12 {
                t[1].atan2(t[0])
            } else {
                h[0]
            };
            [phi, theta, h[0] + h[2] - phi]
        } else {
            [0.0, t[0].atan2(t[2]), 0.0]
        }
    };
    let mut ends = vec![angles_of(arc), angles_of(d)];
    if !model.layout.spatial {
        let theta = ends[0][1];
        let quarter = std::f64::consts::FRAC_PI_2;
        ends.push([0.0, theta + quarter, 0.0]);
        ends.push([0.0, theta - quarter, 0.0]);
    }
    seeds.extend(ends.into_iter().map(bent));
    distinct(seeds, a0, first_bent)
}

/// `seeds` each once, without `a0` where that was the first search's start (`!first_bent`): a
/// split basis, which [`seed_towards`] does not bend, gives `a0` back.
fn distinct(seeds: Vec<Vec<f64>>, a0: &[f64], first_bent: bool) -> Vec<Vec<f64>> {
    let mut unique: Vec<Vec<f64>> = Vec::new();
    for a in seeds {
        if !unique.contains(&a) && (first_bent || a != a0) {
            unique.push(a);
        }
    }
    unique
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

#[cfg(test)]
pub(super) mod tests {
    use crate::rod::Rod;
    use crate::rod::layout::Layout;
    use crate::rod::model::{Discretisation, Model};

    /// The model of `rod` on its default layout, 8 panels of 4 Gauss points, no obstacles.
    pub(in crate::planner) fn model(rod: Rod) -> Model {
        let layout = Layout::of(&rod, 4);
        model_with(rod, layout)
    }

    fn model_with(rod: Rod, layout: Layout) -> Model {
        let d = Discretisation {
            panels: 8,
            gauss_points: 4,
        };
        Model::new(rod, layout, d, [0.0; 3], Vec::new(), &[0.0, 1.0])
    }

    /// A planar rod held along +z with its end at (0.5, 0, 0.5) L: the chord runs at 45°, so the
    /// circular arc through it ends at 90°; the seeds' end angles are the arc's, the chord's,
    /// and the arc's a quarter turn either way, after the prescribed angle where one is given.
    #[test]
    fn planar_seeds_end_along_the_arc_the_chord_and_a_quarter_turn_either_way() {
        let m = model(Rod::uniform(1.0, 1.0));
        let a0 = vec![0.0; m.n()];
        let pi = std::f64::consts::PI;
        let seeds = super::retry_seeds(
            &m,
            &a0,
            false,
            ([0.0; 3], false),
            Some([0.5, 0.0, 0.5]),
            Some([0.0, 0.3, 0.0]),
        );
        let ends: Vec<f64> = seeds.iter().map(|a| m.angles_at(a, 1.0)[1]).collect();
        let want = [0.3, pi / 2.0, pi / 4.0, pi, 0.0];
        assert_eq!(ends.len(), want.len());
        for (got, want) in ends.iter().zip(want) {
            assert!((got - want).abs() <= 1e-12, "{ends:?}");
        }
        for a in &seeds {
            assert!(m.angles_at(a, 0.0)[1].abs() <= 1e-12, "held at θ(0) = 0");
        }
    }

    /// A split basis, which [`super::seed_towards`] does not bend, has no other start to give
    /// than the first search's.
    #[test]
    fn a_split_basis_gives_no_second_start() {
        let rod = Rod::uniform(1.0, 1.0);
        let mut layout = Layout::of(&rod, 4);
        layout.basis = crate::rod::basis::Basis::split_at(4, 0.5);
        let m = model_with(rod, layout);
        let a0 = vec![0.0; m.n()];
        let held = ([0.0; 3], false);
        let seeds = super::retry_seeds(&m, &a0, false, held, Some([0.5, 0.0, 0.5]), None);
        assert!(seeds.is_empty());
    }

    /// A 3D rod held along +z with its end at (0, 0.5, 0.5) L: the arc bends in the y–z plane
    /// (φ = 90°) to θ = 90°, the chord's direction is θ = 45°, and φ + ψ stays the held end's
    /// (no twist). The natural start comes first where the first search started bent.
    #[test]
    fn spatial_seeds_bend_in_the_plane_of_the_chord() {
        let m = model(Rod::uniform(1.0, 1.0).with_torsional_rigidity(1.0));
        let a0 = vec![0.0; m.n()];
        let pi = std::f64::consts::PI;
        let seeds = super::retry_seeds(
            &m,
            &a0,
            true,
            ([0.0; 3], false),
            Some([0.0, 0.5, 0.5]),
            None,
        );
        assert_eq!(seeds.len(), 3);
        assert_eq!(seeds[0], a0);
        for (a, theta) in seeds[1..].iter().zip([pi / 2.0, pi / 4.0]) {
            let [phi, t, psi] = m.angles_at(a, 1.0);
            assert!((phi - pi / 2.0).abs() <= 1e-12, "{phi}");
            assert!((t - theta).abs() <= 1e-12, "{t}");
            assert!((phi + psi).abs() <= 1e-12, "{psi}");
        }
    }
}
