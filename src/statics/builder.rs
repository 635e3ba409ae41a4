//! Building a [`StaticProblem`] in code: the rod, its discretisation, constraints at arc
//! lengths, obstacles and loads, in the case's units. The builder registers every arc length it
//! is given as a boundary of the quadrature mesh, so each constraint acts at exactly the point
//! asked for, and returns an error, never a silently moved point, for anything it cannot build.
//!
//! ```
//! use dlo_planner::rod::{Discretisation, Rod, layout::Layout};
//! use dlo_planner::optim::AlStatus;
//! use dlo_planner::statics::{StaticProblem, StaticOptions, solve_static};
//!
//! // A planar elastica of length 1 clamped at the origin along +z, its end pushed to x = 0.3,
//! // z = 0.8 and pointing along +x.
//! let rod = Rod::uniform(1.0, 1.0);
//! let problem = StaticProblem::builder(rod.clone(), Layout::of(&rod, 4))
//!     .clamp(0.0, [0.0, 0.0, 0.0], &[0.0])
//!     .clamp(1.0, [0.3, 0.0, 0.8], &[std::f64::consts::FRAC_PI_2])
//!     .build()
//!     .unwrap();
//! let mut problem = problem;
//! let start = problem.natural_start(0.1);
//! let solution = solve_static(&mut problem, &start, &StaticOptions::default());
//! assert_eq!(solution.status, AlStatus::Converged);
//! assert!(solution.max_violation < 1e-8);
//! ```

use super::problem::StaticProblem;
use crate::constraints::{
    Angle, Bound, Constraint, LinearConstraint, ObstacleConstraint, OrientationConstraint,
    PositionConstraint, RelativePositionConstraint, SelfContactConstraint,
};
use crate::rod::Rod;
use crate::rod::basis::Basis;
use crate::rod::layout::{Field, Layout};
use crate::rod::model::{Discretisation, Model, PointLoad};
use crate::scene::Obstacle;
use std::sync::Arc;

/// What a [`StaticProblemBuilder`] could not build: the item (e.g. `constraint 2`) and why.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{item}: {message}")]
pub struct BuildError {
    /// The item, numbered in the order it was added (`constraint 0`, `load 1`, `obstacle 0`,
    /// `rod`, `base`, `samples`).
    pub item: String,
    /// What is wrong.
    pub message: String,
}

/// A constraint as given to the builder, in case units.
#[derive(Clone, Debug)]
enum Item {
    Position {
        name: String,
        s: f64,
        rows: Vec<(usize, Bound)>,
    },
    Relative {
        name: String,
        s_a: f64,
        s_b: f64,
        rows: Vec<(usize, f64)>,
    },
    Orientation {
        name: String,
        s: f64,
        rows: Vec<(Angle, f64)>,
    },
    Linear(LinearConstraint),
    /// An item that could not be formed (reported by `build`).
    Invalid(String),
}

/// Builds a [`StaticProblem`]; see the [module documentation](self) for an example. Lengths,
/// positions and forces are in the case's units (those of [`Rod::length`]), angles in radians.
#[derive(Clone, Debug)]
pub struct StaticProblemBuilder {
    rod: Rod,
    layout: Layout,
    disc: Discretisation,
    samples: usize,
    chord_contacts: bool,
    base: [f64; 3],
    frame: Option<[[f64; 3]; 3]>,
    items: Vec<Item>,
    loads: Vec<(f64, [f64; 3], [f64; 3])>,
    obstacles: Vec<(Arc<Obstacle>, f64)>,
    self_contact: bool,
    extra_points: Vec<f64>,
}

impl StaticProblem {
    /// A builder for a problem on `rod` with the coefficient `layout` (e.g.
    /// [`Layout::of`]).
    pub fn builder(rod: Rod, layout: Layout) -> StaticProblemBuilder {
        StaticProblemBuilder {
            rod,
            layout,
            disc: Discretisation::default(),
            samples: 32,
            chord_contacts: false,
            base: [0.0; 3],
            frame: None,
            items: Vec::new(),
            loads: Vec::new(),
            obstacles: Vec::new(),
            self_contact: false,
            extra_points: Vec::new(),
        }
    }
}

impl StaticProblemBuilder {
    /// The quadrature (default: 16 panels of 4 Gauss points).
    pub fn discretisation(mut self, d: Discretisation) -> Self {
        self.disc = d;
        self
    }

    /// Intervals between the points checked against obstacles and self-contact (default 32).
    pub fn samples(mut self, n: usize) -> Self {
        self.samples = n;
        self
    }

    /// The intervals between the points checked against obstacles and self-contact
    /// ([`Self::samples`]).
    pub fn sample_count(&self) -> usize {
        self.samples
    }

    /// Obstacle contacts held on the chords between sample points, not at the points alone
    /// (see [`crate::constraints::ObstacleConstraint`]; default `false`).
    pub fn chord_contacts(mut self, on: bool) -> Self {
        self.chord_contacts = on;
        self
    }

    /// The base position `x(0)` (default the origin); with a free base, its starting value.
    pub fn base(mut self, p: [f64; 3]) -> Self {
        self.base = p;
        self
    }

    /// The rotation (row-major, case axes) from which a 3D rod's Euler angles are measured, so
    /// that their pole lies along `R ẑ` (default: the case's own axes). Orientation rows are
    /// then prescribed in that frame.
    pub fn angle_frame(mut self, r: [[f64; 3]; 3]) -> Self {
        self.frame = Some(r);
        self
    }

    /// Bounds or fixes coordinates (`0` x, `1` y, `2` z) of the point at arc length `s`.
    pub fn position(mut self, name: impl Into<String>, s: f64, rows: &[(usize, Bound)]) -> Self {
        self.items.push(Item::Position {
            name: name.into(),
            s,
            rows: rows.to_vec(),
        });
        self
    }

    /// Fixes the point at `s` at `p` (on a planar rod, its x and z).
    pub fn fix_point(self, s: f64, p: [f64; 3]) -> Self {
        let rows: Vec<(usize, Bound)> = self
            .layout
            .components()
            .iter()
            .map(|&k| (k, Bound::Equal(p[k])))
            .collect();
        self.position(format!("position at s={s}"), s, &rows)
    }

    /// Fixes coordinates of `x(s_b) − x(s_a)`.
    pub fn relative_position(
        mut self,
        name: impl Into<String>,
        s_a: f64,
        s_b: f64,
        rows: &[(usize, f64)],
    ) -> Self {
        self.items.push(Item::Relative {
            name: name.into(),
            s_a,
            s_b,
            rows: rows.to_vec(),
        });
        self
    }

    /// Prescribes Euler angles (or `φ + ψ`) at `s`.
    pub fn orientation(mut self, name: impl Into<String>, s: f64, rows: &[(Angle, f64)]) -> Self {
        self.items.push(Item::Orientation {
            name: name.into(),
            s,
            rows: rows.to_vec(),
        });
        self
    }

    /// Clamps the rod at `s`: the point at `p` and the angles `angles` — `[θ]` on a planar
    /// rod, `[φ, θ, ψ]` on a 3D one. At `s = 0` of a fixed base the point is the base
    /// position.
    pub fn clamp(self, s: f64, p: [f64; 3], angles: &[f64]) -> Self {
        let fields: &[Field] = if self.layout.spatial {
            &[Field::Phi, Field::Theta, Field::Psi]
        } else {
            &[Field::Theta]
        };
        let rows: Vec<(Angle, f64)> = fields
            .iter()
            .zip(angles)
            .map(|(&f, &v)| (Angle::Field(f), v))
            .collect();
        let mut b = if s == 0.0 && !self.layout.free_base {
            self.base(p)
        } else {
            self.fix_point(s, p)
        };
        if angles.len() != fields.len() {
            b.items.push(Item::Invalid(format!(
                "a clamp of a {} rod takes {} angles, got {}",
                if b.layout.spatial { "3D" } else { "planar" },
                fields.len(),
                angles.len()
            )));
            return b;
        }
        b.orientation(format!("orientation at s={s}"), s, &rows)
    }

    /// Rows linear in the coefficients.
    pub fn linear(mut self, c: LinearConstraint) -> Self {
        self.items.push(Item::Linear(c));
        self
    }

    /// A point force `force` at `s`, doing work `force · (x(s) − reference)`.
    pub fn load(mut self, s: f64, force: [f64; 3], reference: [f64; 3]) -> Self {
        self.loads.push((s, force, reference));
        self
    }

    /// Keeps the rod's surface at least `margin` from `obstacle`.
    pub fn obstacle(mut self, obstacle: Arc<Obstacle>, margin: f64) -> Self {
        self.obstacles.push((obstacle, margin));
        self
    }

    /// Keeps non-adjacent parts of the rod at least a diameter apart.
    pub fn self_contact(mut self, on: bool) -> Self {
        self.self_contact = on;
        self
    }

    /// Splits the basis at `s` into two coefficient sets joined continuously there (a point
    /// load's kink in the curvature), and makes `s` a mesh boundary.
    pub fn split_at(mut self, s: f64) -> Self {
        let basis = self.layout.basis;
        self.layout.basis =
            Basis::split_at(basis.pairs(), s / self.rod.length).of_kind(basis.kind());
        self.register_point(s)
    }

    /// Makes `s` a mesh boundary without constraining it (e.g. a basis split point).
    pub fn register_point(mut self, s: f64) -> Self {
        self.extra_points.push(s);
        self
    }

    /// The problem, or the first item that cannot be built.
    pub fn build(self) -> Result<StaticProblem, BuildError> {
        let l = self.rod.length;
        let err = |item: &str, message: String| BuildError {
            item: item.into(),
            message,
        };
        if !(l.is_finite() && l > 0.0) {
            return Err(err(
                "rod",
                format!("length must be positive, got {}", crate::error::Num(l)),
            ));
        }
        if self.samples == 0 {
            return Err(err("samples", "must be at least 1".into()));
        }
        let comps = self.layout.components();
        let arc = |item: &str, s: f64| -> Result<f64, BuildError> {
            if s.is_finite() && (0.0..=l).contains(&s) {
                Ok(s / l)
            } else {
                Err(err(item, format!("arc length {s} outside [0, {l}]")))
            }
        };
        let finite = |item: &str, what: &str, v: &[f64]| -> Result<(), BuildError> {
            match v.iter().find(|x| !x.is_finite()) {
                Some(x) => Err(err(
                    item,
                    format!("{what} must be finite, got {}", crate::error::Num(*x)),
                )),
                None => Ok(()),
            }
        };
        let in_plane = |item: &str, k: usize| -> Result<(), BuildError> {
            if comps.contains(&k) {
                Ok(())
            } else {
                Err(err(
                    item,
                    format!("component {k}: a planar rod lies in the x–z plane"),
                ))
            }
        };
        finite("base", "the position", &self.base)?;
        if self.layout.spatial && self.rod.torsional.is_none() {
            return Err(err("rod", "a 3D rod needs a torsional rigidity".into()));
        }
        if self.layout.extensible != self.rod.extensional.is_some() {
            return Err(err(
                "rod",
                "the layout is extensible exactly when the rod has an extensional rigidity".into(),
            ));
        }
        if !self.layout.spatial && self.base[1] != 0.0 {
            return Err(err(
                "base",
                "a planar rod lies in the x–z plane: y must be 0".into(),
            ));
        }

        // Every arc length that needs a position becomes a mesh boundary.
        let needs_samples = !self.obstacles.is_empty() || self.self_contact;
        let sample_ts: Vec<f64> = (0..=self.samples)
            .map(|j| j as f64 / self.samples as f64)
            .collect();
        let mut points: Vec<f64> = if needs_samples {
            sample_ts.clone()
        } else {
            vec![0.0, 1.0]
        };
        for &s in &self.extra_points {
            points.push(arc("register_point", s)?);
        }
        for (i, it) in self.items.iter().enumerate() {
            let item = format!("constraint {i}");
            match it {
                Item::Position { s, rows, .. } => {
                    points.push(arc(&item, *s)?);
                    if rows.is_empty() {
                        return Err(err(&item, "needs at least one coordinate".into()));
                    }
                    for &(k, b) in rows {
                        in_plane(&item, k)?;
                        let (Bound::Equal(v) | Bound::AtMost(v) | Bound::AtLeast(v)) = b;
                        finite(&item, "a bound", &[v])?;
                    }
                }
                Item::Relative { s_a, s_b, rows, .. } => {
                    points.push(arc(&item, *s_a)?);
                    points.push(arc(&item, *s_b)?);
                    if rows.is_empty() {
                        return Err(err(&item, "needs at least one coordinate".into()));
                    }
                    for &(k, v) in rows {
                        in_plane(&item, k)?;
                        finite(&item, "a component", &[v])?;
                    }
                }
                Item::Orientation { s, rows, .. } => {
                    arc(&item, *s)?;
                    if rows.is_empty() {
                        let want = if self.layout.spatial { 3 } else { 1 };
                        return Err(err(
                            &item,
                            format!("needs at least one angle (a clamp takes {want})"),
                        ));
                    }
                    for &(a, v) in rows {
                        if !self.layout.spatial && a != Angle::Field(Field::Theta) {
                            return Err(err(&item, "a planar rod has only theta".into()));
                        }
                        finite(&item, "an angle", &[v])?;
                    }
                }
                Item::Invalid(m) => return Err(err(&item, m.clone())),
                Item::Linear(c) => {
                    let n = self.layout.len();
                    if let Some(&(j, _)) = c.rows.iter().flat_map(|r| &r.0).find(|e| e.0 >= n) {
                        return Err(err(&item, format!("coefficient {j} of {n}")));
                    }
                }
            }
        }
        let fu = self.rod.force_unit();
        let mut loads = Vec::new();
        for (i, &(s, force, reference)) in self.loads.iter().enumerate() {
            let item = format!("load {i}");
            let t = arc(&item, s)?;
            finite(&item, "the force", &force)?;
            finite(&item, "the reference", &reference)?;
            if !self.layout.spatial && force[1] != 0.0 {
                return Err(err(&item, "a planar rod cannot take a y force".into()));
            }
            loads.push(PointLoad {
                t,
                force: force.map(|c| c / fu),
                reference: reference.map(|c| c / l),
            });
        }
        for (i, (_, margin)) in self.obstacles.iter().enumerate() {
            if !(margin.is_finite() && *margin >= 0.0) {
                return Err(err(
                    &format!("obstacle {i}"),
                    format!(
                        "margin must be finite and non-negative, got {}",
                        crate::error::Num(*margin)
                    ),
                ));
            }
        }

        let model = Model::new(
            self.rod.clone(),
            self.layout,
            self.disc,
            self.base.map(|c| c / l),
            loads,
            &points,
        );
        let model = match self.frame {
            Some(r) => model.with_frame(r).ok_or_else(|| {
                err(
                    "angle_frame",
                    "must be a rotation (orthonormal, determinant +1)".into(),
                )
            })?,
            None => model,
        };
        // The boundary at `t`, which registration put there.
        let at = |item: &str, t: f64| -> Result<usize, BuildError> {
            let b = model.boundary(t);
            let d = (model.mesh.boundaries[b] - t).abs();
            if d <= 1e-9 {
                Ok(b)
            } else {
                Err(err(
                    item,
                    format!(
                        "s = {} is not a mesh boundary (nearest {d:.3e} L away)",
                        t * l
                    ),
                ))
            }
        };

        let mut constraints: Vec<Constraint> = Vec::new();
        for (i, it) in self.items.into_iter().enumerate() {
            let item = format!("constraint {i}");
            constraints.push(match it {
                Item::Position { name, s, rows } => PositionConstraint {
                    name,
                    boundary: at(&item, s / l)?,
                    rows: rows
                        .into_iter()
                        .map(|(k, b)| {
                            let b = match b {
                                Bound::Equal(v) => Bound::Equal(v / l),
                                Bound::AtMost(v) => Bound::AtMost(v / l),
                                Bound::AtLeast(v) => Bound::AtLeast(v / l),
                            };
                            (k, b)
                        })
                        .collect(),
                }
                .into(),
                Item::Relative {
                    name,
                    s_a,
                    s_b,
                    rows,
                } => RelativePositionConstraint {
                    name,
                    from: at(&item, s_a / l)?,
                    to: at(&item, s_b / l)?,
                    rows: rows.into_iter().map(|(k, v)| (k, v / l)).collect(),
                }
                .into(),
                Item::Orientation { name, s, rows } => {
                    OrientationConstraint::new(&model, name, s / l, rows).into()
                }
                Item::Linear(c) => c.into(),
                Item::Invalid(m) => return Err(err(&item, m)),
            });
        }
        if let Some(row) = self.layout.basis.continuity_row() {
            constraints.push(continuity(&self.layout, &row).into());
        }
        // Sample points are boundaries only where obstacles or self-contact need them.
        let samples = if needs_samples {
            sample_ts
                .iter()
                .map(|&t| at("samples", t))
                .collect::<Result<Vec<usize>, _>>()?
        } else {
            Vec::new()
        };
        for (obstacle, margin) in self.obstacles {
            constraints.push(
                ObstacleConstraint {
                    obstacle,
                    samples: samples.clone(),
                    clearance: (self.rod.radius + margin) / l,
                    length: l,
                    chords: self.chord_contacts,
                }
                .into(),
            );
        }
        if self.self_contact {
            constraints.push(
                SelfContactConstraint::new(samples, &sample_ts, 2.0 * self.rod.radius / l).into(),
            );
        }
        Ok(StaticProblem::new(model, constraints))
    }
}

/// The rows that make every field continuous at a split basis's split point.
fn continuity(layout: &Layout, row: &[f64]) -> LinearConstraint {
    let fields = [Field::Theta, Field::Phi, Field::Psi, Field::Eps];
    let rows = fields
        .iter()
        .filter_map(|&f| layout.offset(f))
        .map(|off| {
            let r: Vec<(usize, f64)> = row
                .iter()
                .enumerate()
                .filter(|(_, c)| **c != 0.0)
                .map(|(i, c)| (off + i, *c))
                .collect();
            (r, 0.0)
        })
        .collect();
    LinearConstraint {
        name: "continuity at the split".into(),
        rows,
    }
}
