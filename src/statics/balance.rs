//! The global moment balance of a static shape: a check of its reactions.
//!
//! Everything that acts on the rod from outside — supports (position, relative-position and
//! orientation constraints, the fixed base), obstacle contacts, point loads and gravity — must
//! have zero total force and moment. A fixed base's force is defined to close the force balance
//! ([`crate::statics::reactions()`]), so there the moment is what tests the reactions; with a
//! free base the force balance is a test too. Self-contact
//! forces come in equal, opposite and collinear pairs and cancel; they are left out.
//!
//! The residual is zero, up to rounding, wherever every rigid rotation of the rod is a change of
//! its Ritz coefficients: for planar rods. For a 3D rod the Ritz space of the Euler angles is not
//! closed under rotations about axes other than z, so the residual measures how far the
//! discrete shape is from a full equilibrium; it shrinks as the basis grows. It does not shrink
//! where the rod's tangent passes through ±z between its ends (θ = 0 or π, where φ and ψ enter
//! only as φ ∓ ψ): the parametrisation holds the tangent at the pole like a hidden support.

use crate::rod::kinematics::{Shape, cross};
use crate::statics::problem::StaticProblem;
use crate::statics::reactions::{Reaction, point_forces};
use serde::Serialize;

/// The total force and moment on the rod (moments about its base point `x(0)`), in case units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Balance {
    /// `Σ F` over supports, contacts, loads and gravity: zero by construction with a fixed base
    /// (its force closes the sum), a check with a free one.
    pub force_residual: [f64; 3],
    /// `Σ (x − x(0)) × F + Σ M` over supports, contacts, loads and gravity.
    pub moment_residual: [f64; 3],
    /// `max(|moment_residual|, |force_residual| · L)` over the largest moment in the sum, but at
    /// least `10⁻³ · |F| · L` for the largest force `F` and `10⁻¹² · Rf/L`, so that a rod loaded
    /// only along its supports' arms, or not at all, gives rounding, not 1.
    pub relative: f64,
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// The balance of the shape `a` (evaluated: `shape`) with multipliers `lambda` and its
/// `reactions` ([`crate::statics::reactions()`]).
pub fn balance(
    p: &StaticProblem,
    a: &[f64],
    shape: &Shape,
    lambda: &[f64],
    reactions: &[Reaction],
) -> Balance {
    let m = &p.model;
    let l = m.rod.length;
    let fu = m.rod.force_unit();
    let at = |b: usize| shape.positions[b].map(|v| v * l);
    let x0 = at(0);
    let arm = |x: [f64; 3]| [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]];
    let (mut sum, mut total) = ([0.0; 3], [0.0; 3]);
    let (mut largest, mut largest_force) = (0.0_f64, 0.0_f64);
    // A moment and the force it comes from (zero for a couple); `counted`: the force is in the
    // force sum already.
    let mut add = |mo: [f64; 3], f: [f64; 3], counted: bool| {
        for (s, v) in sum.iter_mut().zip(mo) {
            *s += v;
        }
        if !counted {
            for (s, v) in total.iter_mut().zip(f) {
                *s += v;
            }
        }
        largest = largest.max(norm(mo));
        largest_force = largest_force.max(norm(f));
    };
    // The reactions' forces enter the force sum here (obstacles report their total); their
    // moments below, from the points where they act. Orientation constraints carry their
    // moment in the reaction; the base's force acts at x(0) and has no arm.
    for r in reactions {
        add(r.moment, r.force, false);
    }
    // Orientation constraints are in the reactions; self-contact pairs cancel; linear
    // conditions join the pieces of a split basis.
    for (k, con) in p.constraints.iter().enumerate() {
        let lam = &lambda[p.rows_of(k)];
        for (b, f, reported) in point_forces(m, shape, con, lam).unwrap_or_default() {
            add(cross(arm(at(b)), f), f, reported);
        }
    }
    for ld in &m.loads {
        let x = m.position_at_in(a, shape, ld.t).map(|v| v * l);
        let f = ld.force.map(|v| v * fu);
        add(cross(arm(x), f), f, false);
    }
    // Gravity: −D(s) x̂ per unit length, over the quadrature nodes.
    if m.rod.weight.mean() != 0.0 {
        let mut g = [0.0; 3];
        for (&t, &w) in m.mesh.nodes.iter().zip(&m.mesh.weights) {
            let x = m.position_at_in(a, shape, t).map(|v| v * l);
            let mo = cross(arm(x), [-m.rod.weight.at(t) * w * l, 0.0, 0.0]);
            for (gc, v) in g.iter_mut().zip(mo) {
                *gc += v;
            }
        }
        add(g, [-m.rod.weight.mean() * l, 0.0, 0.0], false);
    }
    let residual = norm(sum).max(norm(total) * l);
    let scale = largest
        .max(1e-3 * largest_force * l)
        .max(1e-12 * m.rod.energy_unit());
    Balance {
        force_residual: total,
        moment_residual: sum,
        relative: if scale > 0.0 { residual / scale } else { 0.0 },
    }
}
