//! General linear rows `Σ cⱼ aⱼ = rhs` in coefficient space (e.g. the planner's fixed
//! conditions on path coefficients).

use super::{Adjoint, Rows};
use crate::optim::Sense;
use crate::rod::kinematics::Shape;
use crate::rod::model::Model;

/// Linear equality rows on the unknowns.
#[derive(Clone, Debug)]
pub struct LinearConstraint {
    /// Label used in reports.
    pub name: String,
    /// `(sparse coefficients, rhs)` per row.
    pub rows: Vec<(Vec<(usize, f64)>, f64)>,
}

impl Rows for LinearConstraint {
    fn label(&self) -> String {
        self.name.clone()
    }
    fn rows(&self) -> usize {
        self.rows.len()
    }
    fn sense(&self, _i: usize) -> Sense {
        Sense::Equal
    }
    fn values(&self, _m: &Model, a: &[f64], _s: &Shape, out: &mut [f64]) {
        for (o, (row, rhs)) in out.iter_mut().zip(&self.rows) {
            *o = row.iter().map(|&(j, c)| c * a[j]).sum::<f64>() - rhs;
        }
    }
    fn add_gradient(&self, _m: &Model, _a: &[f64], _s: &Shape, w: &[f64], adj: &mut Adjoint) {
        for (&wi, (row, _)) in w.iter().zip(&self.rows) {
            for &(j, c) in row {
                adj.coef[j] += wi * c;
            }
        }
    }
}
