//! A smooth nonlinear program `min f(x)` subject to `cᵢ(x) = 0` or `cᵢ(x) ≤ 0`.

/// The sense of one constraint row.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sense {
    /// `c(x) = 0`.
    Equal,
    /// `c(x) ≤ 0`.
    LessEq,
}

/// A nonlinear program. Implementations may cache work between [`Nlp::values`] and
/// [`Nlp::gradient`] at the same `x`.
pub trait Nlp {
    /// Number of unknowns.
    fn n(&self) -> usize;
    /// Number of constraint rows.
    fn m(&self) -> usize;
    /// Sense of row `i`.
    fn sense(&self, i: usize) -> Sense;
    /// Objective `f(x)`; writes `c(x)` into `c`.
    fn values(&mut self, x: &[f64], c: &mut [f64]) -> f64;
    /// Writes `∇f(x) + Σᵢ yᵢ ∇cᵢ(x)` into `g`, at the `x` of the last [`Nlp::values`] call.
    /// Rows with `yᵢ = 0` may be skipped.
    fn gradient(&mut self, x: &[f64], y: &[f64], g: &mut [f64]);
    /// The multipliers of the augmented function that the next evaluations serve (the
    /// multiplier method calls this before each inner minimisation). A problem may use them to
    /// skip work on inequality rows whose penalty is certainly inactive — zero multiplier and a
    /// value certainly below zero — writing for such a row any value it knows to lie below zero
    /// by the same margin: the augmented function, its gradient and the multiplier update are
    /// then the same bit for bit. The default ignores them.
    fn set_multipliers(&mut self, lambda: &[f64]) {
        let _ = lambda;
    }
    /// Whether the problem provides second derivatives ([`Nlp::hessian`]).
    fn has_hessian(&self) -> bool {
        false
    }
    /// Adds `∇²f + Σᵢ yᵢ ∇²cᵢ + Σᵢ sᵢ ∇cᵢ ∇cᵢᵀ` (row-major `n×n`) to `h` at the `x` of the last
    /// [`Nlp::values`] call, when [`Nlp::has_hessian`] says so (the default adds nothing).
    /// Curvature an implementation leaves out must be documented.
    fn hessian(&mut self, x: &[f64], y: &[f64], s: &[f64], h: &mut [f64]) {
        let _ = (x, y, s, h);
    }
    /// Whether [`Nlp::hessian`] with weights `y` (and `s = 0`) is the exact Hessian of the
    /// Lagrangian, so that second-order checks may use it instead of differences.
    fn hessian_is_exact(&self, y: &[f64]) -> bool {
        let _ = y;
        false
    }
}
