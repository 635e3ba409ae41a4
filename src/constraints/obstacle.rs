//! Non-interference with a rigid obstacle (eq. 16), for a rod of radius `r`:
//! `c = (r + margin)/L − d(x(s))/L ≤ 0` at every sample point, where `d` is the signed distance
//! (negative inside). Its gradient is `−n · ∂x/∂a` with `n` the outward normal. The multiplier
//! `λ ≥ 0` of a row is the contact force magnitude at that sample, pushing along `n`.

use super::{Adjoint, Rows};
use crate::optim::Sense;
use crate::rod::kinematics::Shape;
use crate::rod::model::Model;
use crate::scene::obstacle::Obstacle;
use std::sync::Arc;

/// One obstacle, checked at a set of mesh boundaries.
#[derive(Clone, Debug)]
pub struct ObstacleConstraint {
    /// The obstacle.
    pub obstacle: Arc<Obstacle>,
    /// Sample boundaries.
    pub samples: Vec<usize>,
    /// Required clearance `(r + margin)/L`.
    pub clearance: f64,
    /// Rod length `L` (to convert positions).
    pub length: f64,
}

impl Rows for ObstacleConstraint {
    fn label(&self) -> String {
        format!("obstacle {}", self.obstacle.name)
    }
    fn rows(&self) -> usize {
        self.samples.len()
    }
    fn sense(&self, _i: usize) -> Sense {
        Sense::LessEq
    }
    fn values(&self, _m: &Model, _a: &[f64], shape: &Shape, out: &mut [f64]) {
        clearances(self, &shape.positions, out);
    }
    fn add_gradient(&self, _m: &Model, _a: &[f64], shape: &Shape, w: &[f64], adj: &mut Adjoint) {
        for (&wi, &b) in w.iter().zip(&self.samples) {
            if wi == 0.0 {
                continue;
            }
            let x = shape.positions[b].map(|v| v * self.length);
            let (_, n) = self.obstacle.signed_distance(x);
            adj.add_pos(b, -wi, n);
        }
    }
    /// The distance function's Hessian by central differences of its normal (step `1e-6 L`).
    fn add_curvature(&self, m: &Model, _a: &[f64], shape: &Shape, w: &[f64], h: &mut [f64]) {
        let n = m.n();
        let step = 1e-6 * self.length;
        for (&wi, &b) in w.iter().zip(&self.samples) {
            if wi == 0.0 {
                continue;
            }
            let x = shape.positions[b].map(|v| v * self.length);
            // D = ∂n/∂X (world units); ∇²ₓc = −L D for dimensionless x.
            let mut d = [[0.0; 3]; 3];
            for k in 0..3 {
                let (mut xp, mut xm) = (x, x);
                xp[k] += step;
                xm[k] -= step;
                let (_, np) = self.obstacle.signed_distance(xp);
                let (_, nm) = self.obstacle.signed_distance(xm);
                for r in 0..3 {
                    d[r][k] = (np[r] - nm[r]) / (2.0 * step);
                }
            }
            if d.iter().all(|r| r.iter().all(|v| v.abs() < 1e-9)) {
                continue;
            }
            let jac = m.position_jacobian(shape, b);
            for r in 0..3 {
                for k in 0..3 {
                    let dk = -wi * self.length * 0.5 * (d[r][k] + d[k][r]);
                    if dk == 0.0 {
                        continue;
                    }
                    for i in 0..n {
                        let v = dk * jac[r][i];
                        if v != 0.0 {
                            for (hv, jv) in h[i * n..(i + 1) * n].iter_mut().zip(&jac[k]) {
                                *hv += v * jv;
                            }
                        }
                    }
                }
            }
        }
    }
}

crate::kernels::wide::dispatch! {
    fn clearances(c: &ObstacleConstraint, positions: &[[f64; 3]], out: &mut [f64]) => clearances_body
}

/// The rows' values from the positions (compiled twice, see [`crate::kernels::wide`]).
#[inline(always)]
fn clearances_body(c: &ObstacleConstraint, positions: &[[f64; 3]], out: &mut [f64]) {
    for (o, &b) in out.iter_mut().zip(&c.samples) {
        let x = positions[b].map(|v| v * c.length);
        let d = c.obstacle.signed_distance_value(x);
        *o = c.clearance - d / c.length;
    }
}
