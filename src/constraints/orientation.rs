//! Orientation at a point (eq. 15), prescribed through the Euler angles themselves:
//! `φ(s_c) = φ_c`, `θ(s_c) = θ_c`, `ψ(s_c) = ψ_c`, any subset (e.g. only `θ(0) = 0`, as in the
//! paper's §7.2). Each row is linear in the coefficients: `a_field · e(t_c) − value = 0`.
//!
//! Prescribing the angles (rather than the rotation matrix) follows the paper; it also fixes the
//! `φ + ψ` gauge where `θ = 0`, and lets a twist of `2π` be told from none (§4.3 kinking).
//! Where `θ = 0` the frame depends on `φ + ψ` only: prescribing that sum (one row) instead of
//! `φ` and `ψ` separately fixes the same rotation while letting twist turn into writhe (a loop
//! forms by `φ` winding while `ψ` unwinds), which kinking needs.

use super::{Adjoint, Rows};
use crate::optim::Sense;
use crate::rod::kinematics::Shape;
use crate::rod::layout::Field;
use crate::rod::model::Model;

/// One prescribed angle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Angle {
    /// A single Euler angle field.
    Field(Field),
    /// `φ + ψ` (the rotation about z when `θ = 0`).
    PhiPlusPsi,
}

impl Angle {
    /// The fields and their weights in the row.
    pub fn terms(self) -> &'static [(Field, f64)] {
        match self {
            Angle::Field(Field::Phi) => &[(Field::Phi, 1.0)],
            Angle::Field(Field::Theta) => &[(Field::Theta, 1.0)],
            Angle::Field(Field::Psi) => &[(Field::Psi, 1.0)],
            Angle::Field(Field::Eps) => &[(Field::Eps, 1.0)],
            Angle::PhiPlusPsi => &[(Field::Phi, 1.0), (Field::Psi, 1.0)],
        }
    }
}

/// Prescribed Euler angles at one point.
#[derive(Clone, Debug)]
pub struct OrientationConstraint {
    /// Label used in reports.
    pub name: String,
    /// Dimensionless arc length of the point.
    pub t: f64,
    /// `(angle, value)` rows, radians.
    pub rows: Vec<(Angle, f64)>,
    /// Basis values at `t`.
    pub(crate) e: Vec<f64>,
}

impl OrientationConstraint {
    /// Angles `rows` prescribed at `t` for `model`'s basis.
    pub fn new(model: &Model, name: String, t: f64, rows: Vec<(Angle, f64)>) -> Self {
        let mut e = vec![0.0; model.nb()];
        model.layout.basis.values(t, &mut e);
        OrientationConstraint { name, t, rows, e }
    }
}

impl Rows for OrientationConstraint {
    fn label(&self) -> String {
        self.name.clone()
    }
    fn rows(&self) -> usize {
        self.rows.len()
    }
    fn sense(&self, _i: usize) -> Sense {
        Sense::Equal
    }
    fn values(&self, m: &Model, a: &[f64], _s: &Shape, out: &mut [f64]) {
        for (o, &(ang, v)) in out.iter_mut().zip(&self.rows) {
            *o = -v;
            for &(f, w) in ang.terms() {
                let off = m.layout.offset(f).expect("validated field");
                *o += w * crate::rod::basis::dot(&a[off..off + self.e.len()], &self.e);
            }
        }
    }
    fn add_gradient(&self, m: &Model, _a: &[f64], _s: &Shape, w: &[f64], adj: &mut Adjoint) {
        for (&wi, &(ang, _)) in w.iter().zip(&self.rows) {
            for &(f, fw) in ang.terms() {
                let off = m.layout.offset(f).expect("validated field");
                for (i, e) in self.e.iter().enumerate() {
                    adj.coef[off + i] += wi * fw * e;
                }
            }
        }
    }
}
