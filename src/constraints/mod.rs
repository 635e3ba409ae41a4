//! Geometric constraints of paper §3.2, each a set of rows `c(a) = 0` or `c(a) ≤ 0` in
//! dimensionless units, with analytic gradients.
//!
//! Gradients are accumulated into an [`Adjoint`]: a vector per mesh boundary (contracted with
//! `∂x(b)/∂a` in one backward pass, see [`crate::model::Model::add_positions_vjp`]) plus a direct
//! coefficient-space part. Every constraint kind passes the same finite-difference contract test.

mod linear;
mod obstacle;
mod orientation;
mod position;
mod self_contact;

pub use linear::LinearConstraint;
pub use obstacle::ObstacleConstraint;
pub use orientation::{Angle, OrientationConstraint};
pub use position::{Bound, PositionConstraint, RelativePositionConstraint};
pub use self_contact::{SelfContactConstraint, segment_distance};

use crate::kinematics::Shape;
use crate::model::Model;
use crate::optim::Sense;

/// Gradient accumulator: `pos[b]` multiplies `∂x(b)/∂a`; `coef` is added as is.
#[derive(Clone, Debug, Default)]
pub struct Adjoint {
    /// One vector per mesh boundary.
    pub pos: Vec<[f64; 3]>,
    /// Direct gradient in coefficient space.
    pub coef: Vec<f64>,
}

impl Adjoint {
    /// A zeroed accumulator for `model`.
    pub fn new(model: &Model) -> Adjoint {
        Adjoint {
            pos: vec![[0.0; 3]; model.mesh.boundaries.len()],
            coef: vec![0.0; model.n()],
        }
    }

    /// Zeroes every entry.
    pub fn clear(&mut self) {
        self.pos.iter_mut().for_each(|p| *p = [0.0; 3]);
        self.coef.iter_mut().for_each(|c| *c = 0.0);
    }

    /// Adds `w · v` to the vector at boundary `b`.
    #[inline]
    pub fn add_pos(&mut self, b: usize, w: f64, v: [f64; 3]) {
        for k in 0..3 {
            self.pos[b][k] += w * v[k];
        }
    }

    /// Adds the accumulated gradient to `grad`.
    pub fn finish(&self, model: &Model, shape: &Shape, grad: &mut [f64]) {
        for (g, c) in grad.iter_mut().zip(&self.coef) {
            *g += c;
        }
        model.add_positions_vjp(shape, &self.pos, grad);
    }

    /// Adds the curvature of the accumulated position terms, `Σ_b pos[b] · ∂²x(b)/∂a²`, to the
    /// row-major `n×n` matrix `h` (the `coef` part is linear and has none).
    pub fn finish_hessian(&self, model: &Model, shape: &Shape, h: &mut [f64]) {
        model.add_positions_hessian(shape, &self.pos, h);
    }
}

/// A block of constraint rows.
pub trait Constraint: Send + Sync + std::fmt::Debug {
    /// Human-readable label (used in reports and errors).
    fn label(&self) -> String;
    /// Number of rows.
    fn rows(&self) -> usize;
    /// Sense of row `i`.
    fn sense(&self, i: usize) -> Sense;
    /// Writes the row values.
    fn values(&self, model: &Model, a: &[f64], shape: &Shape, out: &mut [f64]);
    /// Adds `Σᵢ wᵢ ∇cᵢ` to `adj` (rows with `wᵢ = 0` may be skipped).
    fn add_gradient(&self, model: &Model, a: &[f64], shape: &Shape, w: &[f64], adj: &mut Adjoint);
    /// Adds `Σᵢ wᵢ Jᵀ (∂²gᵢ/∂x²) J` to the row-major `n×n` matrix `h`, where a row is
    /// `gᵢ(x)` of positions `x` with Jacobian `J`: the part of `∇²cᵢ` that
    /// [`Adjoint::finish_hessian`] (the positions' own curvature) does not hold. Rows linear in
    /// the positions have none (the default).
    fn add_curvature(&self, model: &Model, a: &[f64], shape: &Shape, w: &[f64], h: &mut [f64]) {
        let _ = (model, a, shape, w, h);
    }
    /// Clones into a box.
    fn boxed_clone(&self) -> Box<dyn Constraint>;
    /// For reports that treat some kinds specially.
    fn as_any(&self) -> &dyn std::any::Any;
}

impl Clone for Box<dyn Constraint> {
    fn clone(&self) -> Self {
        self.boxed_clone()
    }
}
