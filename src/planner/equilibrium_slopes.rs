//! How an equilibrium moves with the controlled end's pose: the slopes that let equilibrium
//! tracking pull a sampled shape onto the equilibrium of the pose the shape itself has, not of
//! the pose it had when the targets were solved (docs/algorithms.md, step 4).
//!
//! At an equilibrium `a*` of the end pose `v` (`ℒ = V + Σ λ c`, the pose rows `c(a) − v = 0`),
//! the equality rows and the inequality rows with a positive multiplier stay active under a
//! small change of `v`, and the KKT conditions give the change of the shape:
//!
//! `∇²ℒ δa + J_Aᵀ δλ = 0`, `J_A δa = δv` (zero on the rows other than the pose's),
//!
//! solved as `δa = J_A⁺ δv + Z w` with `Z` spanning the null space of `J_A` and
//! `Zᵀ∇²ℒZ w = −Zᵀ∇²ℒ J_A⁺ δv`. The boundary positions then move by `∂x_b/∂a δa`. Tracking's
//! target for a sampled shape `a` becomes `x̄_b + D_b (P(a) − v)`, with `P(a)` the shape's own
//! end pose and `D_b` those slopes: to first order, the equilibrium of the pose the shape has.

use super::endpoints::EndPose;
use crate::constraints::{Adjoint, Constraint};
use crate::optim::Nlp;
use crate::optim::second_order::{lagrangian_hessian_and_active_rows, null_space};
use crate::rod::kinematics::Shape;
use crate::rod::model::Model;
use crate::statics::StaticSolution;
use crate::statics::problem::StaticProblem;
use nalgebra::DVector;

/// Inequality rows whose multiplier exceeds this are held active.
const ACTIVE: f64 = 1e-8;

/// Singular values of the active rows' Jacobian below this fraction of the largest are taken
/// as zero (dependent rows).
const RANK: f64 = 1e-10;

/// Slopes steeper than this (units of L per unit of a pose row: L per L of the end's position,
/// L per radian of its angles) are not used: the equilibrium is near a fold or a fork of its
/// branch (a strip about to snap, or to buckle either way), where a small change of the pose
/// moves the shape far or onto another branch. On the generated suite's planar problems 99 %
/// of the slopes are below 3.1; at the fork of two mirror-image S-shapes they reach 137.
const STEEPEST: f64 = 10.0;

/// An equilibrium's slopes with respect to its end pose.
#[derive(Clone, Debug)]
pub struct Slope {
    /// The constraint blocks prescribing the pose the equilibrium was solved at: their values
    /// at a shape are that shape's end pose minus it.
    pose: Vec<Constraint>,
    /// `d[i][b]`: the derivative of boundary `b`'s position (units of L) with respect to the
    /// value of the pose's row `i`.
    d: Vec<Vec<[f64; 3]>>,
}

impl Slope {
    /// The slopes of `sol`, the equilibrium of `base` held at `pose`; `None` where the reduced
    /// Hessian is singular (the equilibrium is a fold of its branch), where a slope is steeper
    /// than 10 L per unit of the pose, or where the solve left no multipliers.
    pub fn of(base: &StaticProblem, pose: &EndPose, sol: &StaticSolution) -> Option<Slope> {
        let mut p = pose.problem(base);
        let m = Nlp::m(&p);
        let m0 = Nlp::m(base);
        if sol.lambda.len() != m || m == m0 {
            return None;
        }
        let (a, lambda) = (&sol.a[..], &sol.lambda[..]);
        // The pose rows are equalities, so some row is always active.
        let (hess, _, active) = lagrangian_hessian_and_active_rows(&mut p, a, lambda, ACTIVE);
        let (rows, j) = active?;
        let z = null_space(&j);
        let svd = j.svd(true, true);
        let smax = svd.singular_values.max();
        let pinv = svd.pseudo_inverse(RANK * smax.max(1e-300)).ok()?;
        let reduced = if z.ncols() > 0 {
            Some((z.transpose() * &hess * &z).lu())
        } else {
            None
        };
        let model = &p.model;
        let shape = model.evaluate(a);
        let jac: Vec<[Vec<f64>; 3]> = (0..model.mesh.boundaries.len())
            .map(|b| model.position_jacobian(&shape, b))
            .collect();
        let mut d = Vec::with_capacity(m - m0);
        for row in m0..m {
            let r = rows.iter().position(|&i| i == row)?;
            let da_p: DVector<f64> = pinv.column(r).into_owned();
            let da = match &reduced {
                Some(lu) => {
                    let rhs = -(z.transpose() * (&hess * &da_p));
                    let w = lu.solve(&rhs)?;
                    da_p + &z * w
                }
                None => da_p,
            };
            if !da.iter().all(|v| v.is_finite()) {
                return None;
            }
            let db: Vec<[f64; 3]> = jac
                .iter()
                .map(|rows3| std::array::from_fn(|k| dot(&rows3[k], da.as_slice())))
                .collect();
            d.push(db);
        }
        // Near a fold or a fork of the branch the slopes grow without bound, and the
        // linearised target is no guide to the equilibrium a nearby pose produces.
        let steepest = d
            .iter()
            .flatten()
            .flatten()
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        if steepest > STEEPEST {
            return None;
        }
        Some(Slope {
            pose: pose.constraints(&base.model),
            d,
        })
    }

    /// `∂x_b/∂v_i`: the derivative of each boundary position (units of L) with respect to the
    /// value of each of the pose's rows (position components first, then angles, as
    /// [`EndPose::constraints`] lays them out).
    pub fn position_slopes(&self) -> &[Vec<[f64; 3]>] {
        &self.d
    }

    /// The end pose of shape `a` minus the pose the equilibrium was solved at, row by row.
    fn pose_offset(&self, model: &Model, a: &[f64], shape: &Shape) -> Vec<f64> {
        let mut out = vec![0.0; self.d.len()];
        let mut row = 0;
        for blk in &self.pose {
            let r = blk.rows();
            blk.values(model, a, shape, &mut out[row..row + r]);
            row += r;
        }
        out
    }

    /// The residuals `x_b − x̄_b − D_b (P(a) − v)` of shape `a` (evaluated in `shape`) against
    /// the equilibrium's boundary positions `target`.
    pub fn residuals(
        &self,
        model: &Model,
        a: &[f64],
        shape: &Shape,
        target: &[[f64; 3]],
    ) -> Vec<[f64; 3]> {
        let off = self.pose_offset(model, a, shape);
        shape
            .positions
            .iter()
            .zip(target)
            .enumerate()
            .map(|(b, (x, xb))| {
                std::array::from_fn(|k| {
                    x[k] - xb[k]
                        - off
                            .iter()
                            .zip(&self.d)
                            .map(|(o, d)| o * d[b][k])
                            .sum::<f64>()
                })
            })
            .collect()
    }

    /// Adds the cotangents of `½ wt Σ_b |r_b|²` (the residuals of [`Slope::residuals`]) to
    /// `adj`: `wt r_b` on the positions, and through the end pose's rows.
    pub fn add_cotangents(
        &self,
        model: &Model,
        a: &[f64],
        shape: &Shape,
        target: &[[f64; 3]],
        wt: f64,
        adj: &mut Adjoint,
    ) {
        let r = self.residuals(model, a, shape, target);
        for (b, rb) in r.iter().enumerate() {
            adj.add_pos(b, wt, *rb);
        }
        let mu: Vec<f64> = self
            .d
            .iter()
            .map(|d| -wt * d.iter().zip(&r).map(|(u, v)| dot3(u, v)).sum::<f64>())
            .collect();
        self.add_pose_gradient(model, a, shape, &mu, adj);
    }

    /// Adds `Σ_i w_i ∇(P_i(a))` (the end pose's rows weighted by `w`) to `adj`.
    fn add_pose_gradient(
        &self,
        model: &Model,
        a: &[f64],
        shape: &Shape,
        w: &[f64],
        adj: &mut Adjoint,
    ) {
        let mut row = 0;
        for blk in &self.pose {
            let r = blk.rows();
            blk.add_gradient(model, a, shape, &w[row..row + r], adj);
            row += r;
        }
    }

    /// Adds to the row-major `n×n` matrix `h` what the slopes add to the Gauss–Newton part of
    /// `½ wt Σ_b |r_b|²` beyond `wt Σ_b J_bᵀJ_b` (which the caller adds, `J_b = ∂x_b/∂a`):
    /// with `R_b = J_b − Σ_i D_ib ∇P_iᵀ`, `wt (Σ_b R_bᵀR_b − Σ_b J_bᵀJ_b)`.
    pub fn add_gauss_newton(
        &self,
        model: &Model,
        a: &[f64],
        shape: &Shape,
        wt: f64,
        h: &mut [f64],
    ) {
        let n = model.n();
        let mp = self.d.len();
        let mut adj = Adjoint::new(model);
        let mut unit = vec![0.0; mp];
        let mut jc = vec![vec![0.0; n]; mp];
        let mut g = vec![vec![0.0; n]; mp];
        for i in 0..mp {
            unit[i] = 1.0;
            adj.clear();
            self.add_pose_gradient(model, a, shape, &unit, &mut adj);
            adj.finish(model, shape, &mut jc[i]);
            unit[i] = 0.0;
            model.add_positions_vjp(shape, &self.d[i], &mut g[i]);
        }
        for i in 0..mp {
            for r in 0..n {
                let (gi, ci) = (g[i][r], jc[i][r]);
                let row = &mut h[r * n..(r + 1) * n];
                for (c, hv) in row.iter_mut().enumerate() {
                    *hv -= wt * (gi * jc[i][c] + ci * g[i][c]);
                }
            }
            for l in 0..mp {
                let mil: f64 = self.d[i]
                    .iter()
                    .zip(&self.d[l])
                    .map(|(u, v)| dot3(u, v))
                    .sum();
                for r in 0..n {
                    let f = wt * mil * jc[i][r];
                    if f != 0.0 {
                        let row = &mut h[r * n..(r + 1) * n];
                        for (hv, cl) in row.iter_mut().zip(&jc[l]) {
                            *hv += f * cl;
                        }
                    }
                }
            }
        }
    }
}

fn dot(u: &[f64], v: &[f64]) -> f64 {
    u.iter().zip(v).map(|(x, y)| x * y).sum()
}

fn dot3(u: &[f64; 3], v: &[f64; 3]) -> f64 {
    u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
}
