//! Reaction forces and moments from a solve's multipliers: what each support, contact and
//! the rod itself (self-contact) exert on the rod, in the case's units.

use crate::constraints::Angle;
use crate::rod::kinematics::{Shape, rotation};
use crate::rod::layout::Field;
use crate::statics::problem::StaticProblem;
use serde::Serialize;

/// The reaction at one constraint, in the case's units: the force (and moment) the support or
/// contact exerts **on the rod**.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Reaction {
    /// Constraint label.
    pub constraint: String,
    /// Arc length of the point where it acts (case units), when it acts at one point.
    pub s: Option<f64>,
    /// Force on the rod.
    pub force: [f64; 3],
    /// Moment on the rod (least-squares from the prescribed angles' generalized torques; zero
    /// for position constraints).
    pub moment: [f64; 3],
    /// Generalized torques `(τ_φ, τ_θ, τ_ψ)` conjugate to prescribed Euler angles (zero where the
    /// angle is free).
    pub angle_torques: [f64; 3],
}

/// A contact of the rod with itself: the force the strand at `s[0]` takes from the strand at
/// `s[1]` (which takes the opposite), in case units.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SelfContactForce {
    /// Arc lengths of the two closest points, `s[0] < s[1]`.
    pub s: [f64; 2],
    /// Force on the strand at `s[0]`.
    pub force: [f64; 3],
}

/// The self-contact forces of multipliers `lambda` on the evaluated `shape`, largest first.
pub fn self_contacts(p: &StaticProblem, shape: &Shape, lambda: &[f64]) -> Vec<SelfContactForce> {
    let m = &p.model;
    let (l, fu) = (m.rod.length, m.rod.force_unit());
    let mut out = Vec::new();
    for (k, con) in p.constraints.iter().enumerate() {
        if let crate::constraints::Constraint::SelfContact(sc) = con {
            for (t, f) in sc.contacts(m, shape, &lambda[p.rows_of(k)]) {
                out.push(SelfContactForce {
                    s: t.map(|v| v * l),
                    force: f.map(|v| v * fu),
                });
            }
        }
    }
    let size = |c: &SelfContactForce| c.force.iter().map(|v| v * v).sum::<f64>();
    out.sort_by(|a, b| size(b).total_cmp(&size(a)));
    out
}

/// The forces on the rod (case units) that the multipliers `lam` of one constraint apply at
/// mesh boundaries, for the kinds that act through forces at points (positions, relative
/// positions, obstacles; `None` for the others): `(boundary, force, reported)`, where
/// `reported` says whether the constraint's [`Reaction`] counts the force (a relative-position
/// reaction is its force at the second point; the opposite force at the first is not).
pub(crate) fn point_forces(
    m: &crate::rod::model::Model,
    shape: &Shape,
    con: &crate::constraints::Constraint,
    lam: &[f64],
) -> Option<Vec<(usize, [f64; 3], bool)>> {
    use crate::constraints::*;
    let fu = m.rod.force_unit();
    match con {
        Constraint::Position(pc) => {
            let mut f = [0.0; 3];
            for (&li, &(comp, b)) in lam.iter().zip(&pc.rows) {
                let sign = if matches!(b, Bound::AtLeast(_)) {
                    1.0
                } else {
                    -1.0
                };
                f[comp] += sign * li * fu;
            }
            Some(vec![(pc.boundary, f, true)])
        }
        Constraint::RelativePosition(rc) => {
            let mut f = [0.0; 3];
            for (&li, &(comp, _)) in lam.iter().zip(&rc.rows) {
                f[comp] -= li * fu;
            }
            Some(vec![(rc.to, f, true), (rc.from, f.map(|v| -v), false)])
        }
        Constraint::Obstacle(ob) => {
            let mut out = Vec::new();
            // At the row's witness: split between its two sample points in proportion.
            for (j, (&li, &b)) in lam.iter().zip(&ob.samples).enumerate() {
                if li > 0.0 {
                    let w = ob.witness(&shape.positions, j);
                    out.push((b, w.normal.map(|nc| (1.0 - w.t) * li * nc * fu), true));
                    if w.t > 0.0 {
                        out.push((w.towards, w.normal.map(|nc| w.t * li * nc * fu), true));
                    }
                }
            }
            Some(out)
        }
        Constraint::Orientation(_) | Constraint::Linear(_) | Constraint::SelfContact(_) => None,
    }
}

/// Converts multipliers into reactions (see [`Reaction`]); `shape` is the evaluated shape `a`.
pub fn reactions(p: &StaticProblem, a: &[f64], shape: &Shape, lambda: &[f64]) -> Vec<Reaction> {
    use crate::constraints::*;

    let m = &p.model;
    let fu = m.rod.force_unit();
    let mu = m.rod.energy_unit();
    let l = m.rod.length;
    let mut out = Vec::new();
    for (k, con) in p.constraints.iter().enumerate() {
        let lam = &lambda[p.rows_of(k)];
        let label = con.label();
        let mut r = Reaction {
            constraint: label,
            s: None,
            force: [0.0; 3],
            moment: [0.0; 3],
            angle_torques: [0.0; 3],
        };
        if let Some(forces) = point_forces(m, shape, con, lam) {
            // A single point's reaction says where it acts; an obstacle's is its total.
            let at_point = !matches!(con, Constraint::Obstacle(_));
            if let (true, Some(&(b, _, _))) = (at_point, forces.first()) {
                r.s = Some(m.mesh.boundaries[b] * l);
            }
            for (_, f, _) in forces.iter().filter(|e| e.2) {
                for (rc, fc) in r.force.iter_mut().zip(f) {
                    *rc += fc;
                }
            }
        } else if let Constraint::Orientation(oc) = con {
            r.s = Some(oc.t * l);
            // Generalized torques conjugate to each prescribed angle row; a φ+ψ row acts on
            // both (its torque is about z = ζ where θ = 0).
            let mut torques = [0.0; 3];
            for (&li, &(ang, _)) in lam.iter().zip(&oc.rows) {
                for &(f, w) in ang.terms() {
                    match f {
                        Field::Phi if ang == Angle::PhiPlusPsi => {}
                        Field::Phi => torques[0] -= li * w,
                        Field::Theta => torques[1] -= li * w,
                        Field::Psi => torques[2] -= li * w,
                        Field::Eps => {}
                    }
                }
            }
            r.angle_torques = torques.map(|v| v * mu);
            r.moment = least_squares_moment(m, a, oc, torques).map(|v| v * mu);
        } else {
            continue;
        }
        out.push(r);
    }
    if !m.layout.free_base {
        // The fixed base P(0) is a pin: its force closes the global force balance
        // F_base + Σ F_constraints + Σ p_loads − (∫D ds) x̂ = 0 (gravity along −x).
        let mut f = [0.0; 3];
        for r in &out {
            for (fc, rc) in f.iter_mut().zip(r.force) {
                *fc -= rc;
            }
        }
        for ld in &m.loads {
            for (fc, lc) in f.iter_mut().zip(ld.force) {
                *fc -= lc * fu;
            }
        }
        f[0] += m.rod.weight.mean() * l;
        out.insert(
            0,
            Reaction {
                constraint: "base".into(),
                s: Some(0.0),
                force: f,
                moment: [0.0; 3],
                angle_torques: [0.0; 3],
            },
        );
    }
    out
}

/// Minimum-norm moment `M` with `M·z = τ_φ`, `M·(Rz(φ)ŷ) = τ_θ`, `M·ζ = τ_ψ` for the prescribed
/// angles (the axes about which each Euler angle rotates the frame).
fn least_squares_moment(
    m: &crate::rod::model::Model,
    a: &[f64],
    oc: &crate::constraints::OrientationConstraint,
    torques: [f64; 3],
) -> [f64; 3] {
    use nalgebra::{DMatrix, DVector};
    let [phi, theta, psi] = m.angles_at(a, oc.t);
    let rot = rotation(phi, theta, psi);
    let zeta = [rot[0][2], rot[1][2], rot[2][2]];
    let axes = [[0.0, 0.0, 1.0], [-phi.sin(), phi.cos(), 0.0], zeta];
    let rows: Vec<usize> = oc
        .rows
        .iter()
        .filter_map(|(ang, _)| match ang {
            Angle::Field(Field::Phi) => Some(0),
            Angle::Field(Field::Theta) => Some(1),
            Angle::Field(Field::Psi) | Angle::PhiPlusPsi => Some(2),
            Angle::Field(Field::Eps) => None,
        })
        .collect();
    if rows.is_empty() {
        return [0.0; 3];
    }
    let amat = DMatrix::from_fn(rows.len(), 3, |i, j| axes[rows[i]][j]);
    let b = DVector::from_iterator(rows.len(), rows.iter().map(|&r| torques[r]));
    let svd = amat.svd(true, true);
    // The axes are the angles' frame's: the moment in the case's axes is `R M`.
    match svd.solve(&b, 1e-9) {
        Ok(x) => m.to_case([x[0], x[1], x[2]]),
        Err(_) => [0.0; 3],
    }
}
