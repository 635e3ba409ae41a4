//! Geometric constraints of paper §3.2, each a set of rows `c(a) = 0` or `c(a) ≤ 0` in
//! dimensionless units, with analytic gradients.
//!
//! Gradients are accumulated into an [`Adjoint`]: a vector per mesh boundary (contracted with
//! `∂x(b)/∂a` in one backward pass, see [`crate::rod::model::Model::add_positions_vjp`]) plus a direct
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

use crate::optim::Sense;
use crate::rod::kinematics::Shape;
use crate::rod::model::Model;

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
        for (p, vk) in self.pos[b].iter_mut().zip(v) {
            *p += w * vk;
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

/// The rows of one constraint kind: what every kind implements, and what [`Constraint`]
/// dispatches to.
pub(crate) trait Rows {
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
    /// See [`Constraint::add_curvature`]; rows linear in the positions have none (the default).
    fn add_curvature(&self, model: &Model, a: &[f64], shape: &Shape, w: &[f64], h: &mut [f64]) {
        let _ = (model, a, shape, w, h);
    }
}

/// A block of constraint rows: one of the kinds of §3.2. The set is closed, so code that treats
/// some kinds specially (reactions, the planner's linear rows, the grasp's fingers) matches on
/// it exhaustively.
#[derive(Clone, Debug)]
pub enum Constraint {
    /// Coordinates of `x(s)` fixed or bounded.
    Position(PositionConstraint),
    /// Coordinates of `x(s₁) − x(s₀)` fixed.
    RelativePosition(RelativePositionConstraint),
    /// Euler angles (or sums of them) fixed at `s`.
    Orientation(OrientationConstraint),
    /// Rows linear in the coefficients.
    Linear(LinearConstraint),
    /// Clearance from an obstacle at sample points.
    Obstacle(ObstacleConstraint),
    /// Clearance between non-adjacent segments of the rod.
    SelfContact(SelfContactConstraint),
}

macro_rules! each_kind {
    ($c:expr, $k:ident => $e:expr) => {
        match $c {
            Constraint::Position($k) => $e,
            Constraint::RelativePosition($k) => $e,
            Constraint::Orientation($k) => $e,
            Constraint::Linear($k) => $e,
            Constraint::Obstacle($k) => $e,
            Constraint::SelfContact($k) => $e,
        }
    };
}

impl Constraint {
    /// Human-readable label (used in reports and errors).
    pub fn label(&self) -> String {
        each_kind!(self, k => k.label())
    }
    /// Number of rows.
    pub fn rows(&self) -> usize {
        each_kind!(self, k => k.rows())
    }
    /// Sense of row `i`.
    pub fn sense(&self, i: usize) -> Sense {
        each_kind!(self, k => k.sense(i))
    }
    /// Writes the row values.
    pub fn values(&self, model: &Model, a: &[f64], shape: &Shape, out: &mut [f64]) {
        each_kind!(self, k => k.values(model, a, shape, out))
    }
    /// Adds `Σᵢ wᵢ ∇cᵢ` to `adj` (rows with `wᵢ = 0` may be skipped).
    pub fn add_gradient(
        &self,
        model: &Model,
        a: &[f64],
        shape: &Shape,
        w: &[f64],
        adj: &mut Adjoint,
    ) {
        each_kind!(self, k => k.add_gradient(model, a, shape, w, adj))
    }
    /// Adds `Σᵢ wᵢ Jᵀ (∂²gᵢ/∂x²) J` to the row-major `n×n` matrix `h`, where a row is
    /// `gᵢ(x)` of positions `x` with Jacobian `J`: the part of `∇²cᵢ` that
    /// [`Adjoint::finish_hessian`] (the positions' own curvature) does not hold. Rows linear in
    /// the positions have none.
    pub fn add_curvature(&self, model: &Model, a: &[f64], shape: &Shape, w: &[f64], h: &mut [f64]) {
        each_kind!(self, k => k.add_curvature(model, a, shape, w, h))
    }
}

macro_rules! from_kind {
    ($($kind:ident($t:ty)),*) => {$(
        impl From<$t> for Constraint {
            fn from(c: $t) -> Constraint {
                Constraint::$kind(c)
            }
        }
    )*};
}
from_kind!(
    Position(PositionConstraint),
    RelativePosition(RelativePositionConstraint),
    Orientation(OrientationConstraint),
    Linear(LinearConstraint),
    Obstacle(ObstacleConstraint),
    SelfContact(SelfContactConstraint)
);

/// For constraint `blocks` whose rows sit at `offsets` (`offsets[b]..offsets[b + 1]`) in `y`:
/// collects the position cotangents of `Σ yᵢ∇cᵢ` in `adj` (cleared first) and adds the blocks'
/// own curvature ([`Constraint::add_curvature`]) to `h`. The positions' curvature follows from
/// [`Adjoint::finish_hessian`], once the caller has added any other position terms.
#[allow(clippy::too_many_arguments)]
pub fn add_weighted_curvature(
    blocks: &[Constraint],
    offsets: &[usize],
    model: &Model,
    a: &[f64],
    shape: &Shape,
    y: &[f64],
    adj: &mut Adjoint,
    h: &mut [f64],
) {
    adj.clear();
    for (b, blk) in blocks.iter().enumerate() {
        let w = &y[offsets[b]..offsets[b + 1]];
        if !crate::kernels::all_zero(w) {
            blk.add_gradient(model, a, shape, w, adj);
            blk.add_curvature(model, a, shape, w, h);
        }
    }
}

/// Adds `Σ sᵢ ∇cᵢ∇cᵢᵀ` over the rows with `sᵢ ≠ 0` (the Gauss–Newton part of a penalty) to the
/// row-major `n×n` matrix `h`; rows laid out as in [`add_weighted_curvature`], `adj` is scratch.
#[allow(clippy::too_many_arguments)]
pub fn add_penalty_gauss_newton(
    blocks: &[Constraint],
    offsets: &[usize],
    model: &Model,
    a: &[f64],
    shape: &Shape,
    s: &[f64],
    adj: &mut Adjoint,
    h: &mut [f64],
) {
    let mut unit = Vec::new();
    let mut gi = vec![0.0; model.n()];
    for (b, blk) in blocks.iter().enumerate() {
        let rows = offsets[b]..offsets[b + 1];
        for (r, i) in rows.clone().enumerate() {
            if s[i] == 0.0 {
                continue;
            }
            unit.clear();
            unit.resize(rows.len(), 0.0);
            unit[r] = 1.0;
            adj.clear();
            blk.add_gradient(model, a, shape, &unit, adj);
            gi.iter_mut().for_each(|v| *v = 0.0);
            adj.finish(model, shape, &mut gi);
            crate::rod::hessian::add_rank_one(h, s[i], &gi);
        }
    }
}
