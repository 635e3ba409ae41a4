//! Position of a point (fixed supports, fingers) and relative position of two points (eq. 14).

use super::{Adjoint, Rows};
use crate::optim::Sense;
use crate::rod::kinematics::Shape;
use crate::rod::model::Model;

/// One row of a point constraint on a coordinate (dimensionless, `x/L`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bound {
    /// `x_k = v`.
    Equal(f64),
    /// `x_k ≤ v` (a unilateral contact pushing towards −k).
    AtMost(f64),
    /// `x_k ≥ v` (a unilateral contact pushing towards +k).
    AtLeast(f64),
}

/// Constraints on coordinates of the point at boundary `b`.
#[derive(Clone, Debug)]
pub struct PositionConstraint {
    /// Label used in reports.
    pub name: String,
    /// Mesh boundary of the point.
    pub boundary: usize,
    /// `(component, bound)` rows.
    pub rows: Vec<(usize, Bound)>,
}

impl Rows for PositionConstraint {
    fn label(&self) -> String {
        self.name.clone()
    }
    fn rows(&self) -> usize {
        self.rows.len()
    }
    fn sense(&self, i: usize) -> Sense {
        match self.rows[i].1 {
            Bound::Equal(_) => Sense::Equal,
            _ => Sense::LessEq,
        }
    }
    fn values(&self, _m: &Model, _a: &[f64], shape: &Shape, out: &mut [f64]) {
        let x = shape.positions[self.boundary];
        for (o, &(k, b)) in out.iter_mut().zip(&self.rows) {
            *o = match b {
                Bound::Equal(v) | Bound::AtMost(v) => x[k] - v,
                Bound::AtLeast(v) => v - x[k],
            };
        }
    }
    fn add_gradient(&self, _m: &Model, _a: &[f64], _s: &Shape, w: &[f64], adj: &mut Adjoint) {
        for (&wi, &(k, b)) in w.iter().zip(&self.rows) {
            let sign = if matches!(b, Bound::AtLeast(_)) {
                -1.0
            } else {
                1.0
            };
            let mut v = [0.0; 3];
            v[k] = sign;
            adj.add_pos(self.boundary, wi, v);
        }
    }
}

/// `x_k(b) − x_k(a) = l_k` for the listed components (eq. 14).
#[derive(Clone, Debug)]
pub struct RelativePositionConstraint {
    /// Label used in reports.
    pub name: String,
    /// Boundary of the first point `P(s_a)`.
    pub from: usize,
    /// Boundary of the second point `P(s_b)`.
    pub to: usize,
    /// `(component, l_k)` rows (dimensionless).
    pub rows: Vec<(usize, f64)>,
}

impl Rows for RelativePositionConstraint {
    fn label(&self) -> String {
        self.name.clone()
    }
    fn rows(&self) -> usize {
        self.rows.len()
    }
    fn sense(&self, _i: usize) -> Sense {
        Sense::Equal
    }
    fn values(&self, _m: &Model, _a: &[f64], shape: &Shape, out: &mut [f64]) {
        let (xa, xb) = (shape.positions[self.from], shape.positions[self.to]);
        for (o, &(k, l)) in out.iter_mut().zip(&self.rows) {
            *o = xb[k] - xa[k] - l;
        }
    }
    fn add_gradient(&self, _m: &Model, _a: &[f64], _s: &Shape, w: &[f64], adj: &mut Adjoint) {
        for (&wi, &(k, _)) in w.iter().zip(&self.rows) {
            let mut v = [0.0; 3];
            v[k] = 1.0;
            adj.add_pos(self.to, wi, v);
            adj.add_pos(self.from, -wi, v);
        }
    }
}
