//! The multiplier method (augmented Lagrangian, Powell–Hestenes–Rockafellar form) around damped
//! Newton steps (BFGS for problems without a Hessian).
//!
//! Convention: the Lagrangian is `ℒ(x, λ) = f(x) + Σᵢ λᵢ cᵢ(x)`, so at a KKT point
//! `∇f + Σ λᵢ ∇cᵢ = 0` with `λᵢ ≥ 0` for inequality rows `cᵢ ≤ 0`. The augmented function is
//!
//! `Φ(x) = f + Σ_eq (λc + ρc²/2) + Σ_ineq (max(0, μ + ρc)² − μ²)/(2ρ)`
//!
//! and the updates are `λ ← λ + ρc`, `μ ← max(0, μ + ρc)`, or, with Newton inner steps and
//! [`AlOptions::newton_multipliers`], a Newton step on the dual function. The penalty `ρ` starts at
//! [`AlOptions::rho_initial`] (high: a small penalty lets a compressed straight rod sit at its
//! stationary point), grows ×10 when the violation does not fall to a quarter, and is capped at
//! [`AlOptions::rho_max`] (beyond it multiplier updates become noise). A final least-squares
//! estimate of the multipliers from `∇f = −Jᵀλ` on the active set polishes them.

use super::bfgs::{BfgsOptions, BfgsStatus, bfgs, inf_norm};
use super::newton::{NewtonOptions, newton};
use super::nlp::{Nlp, Sense};
use nalgebra::{DMatrix, DVector};

/// Options of the multiplier method (all tolerances in the problem's own, dimensionless units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlOptions {
    /// Required constraint violation `max(|c_eq|, max(0, c_ineq))`.
    pub feasibility_tol: f64,
    /// Required KKT residual, relative: `‖∇f + Jᵀλ‖∞ ≤ optimality_tol · max(1, ‖∇f‖∞)`.
    pub optimality_tol: f64,
    /// Initial penalty.
    pub rho_initial: f64,
    /// Penalty cap.
    pub rho_max: f64,
    /// Outer iteration budget.
    pub max_outer: usize,
    /// Inner BFGS iteration budget per outer iteration.
    pub max_inner: usize,
    /// An inequality row counts as active when `c > −active_tol` or its multiplier is positive.
    pub active_tol: f64,
    /// Minimise the augmented function by damped Newton steps when the problem provides a
    /// Hessian ([`Nlp::hessian`]); BFGS otherwise.
    pub second_order: bool,
    /// Largest Newton step `‖Δx‖∞` (keeps continuation on its branch).
    pub max_step: f64,
    /// With Newton inner steps, update the multipliers of the active rows by a Newton step on
    /// the dual function, `λ ← λ + (J ∇²Φ⁻¹ Jᵀ)⁻¹ c` (Bertsekas's second-order multiplier
    /// iteration), instead of `λ ← λ + ρc`: the violation then falls superlinearly instead of
    /// by a constant factor per outer iteration.
    pub newton_multipliers: bool,
    /// Raise the penalty only while the violation is above `feasibility_tol`: a run
    /// warm-started on a feasible point (a continuation step) then keeps the penalty it was
    /// given instead of raising it tenfold per outer iteration that cannot cut a violation
    /// already within tolerance by the usual factor.
    pub hold_penalty_when_feasible: bool,
}

impl Default for AlOptions {
    fn default() -> Self {
        AlOptions {
            feasibility_tol: 1e-9,
            optimality_tol: 1e-6,
            rho_initial: 1e3,
            rho_max: 1e8,
            max_outer: 40,
            max_inner: 400,
            active_tol: 1e-7,
            second_order: true,
            max_step: f64::INFINITY,
            newton_multipliers: true,
            hold_penalty_when_feasible: false,
        }
    }
}

/// How the multiplier method ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AlStatus {
    /// Feasible and stationary within tolerance.
    Converged,
    /// Budget exhausted before the tolerances were met.
    IterationLimit,
    /// The penalty reached its cap and the constraints are still violated.
    Infeasible,
    /// A non-finite value appeared.
    NumericalFailure,
    /// The caller stopped the run.
    Interrupted,
}

impl std::fmt::Display for AlStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            AlStatus::Converged => "converged",
            AlStatus::IterationLimit => "iteration limit reached",
            AlStatus::Infeasible => "infeasible",
            AlStatus::NumericalFailure => "numerical failure",
            AlStatus::Interrupted => "interrupted",
        })
    }
}

/// Result of [`augmented_lagrangian`].
#[derive(Clone, Debug)]
pub struct AlOutcome {
    /// Termination status.
    pub status: AlStatus,
    /// Objective at the solution.
    pub f: f64,
    /// Multipliers (`λᵢ ≥ 0` on inequality rows).
    pub lambda: Vec<f64>,
    /// Constraint values at the solution.
    pub c: Vec<f64>,
    /// `max(|c_eq|, max(0, c_ineq))`.
    pub max_violation: f64,
    /// `‖∇f + Jᵀλ‖∞` after the multiplier polish.
    pub kkt_residual: f64,
    /// Outer iterations.
    pub outer_iterations: usize,
    /// Inner BFGS iterations in total.
    pub inner_iterations: usize,
    /// Objective/gradient evaluations in total.
    pub evaluations: usize,
    /// Final penalty.
    pub rho: f64,
    /// Whether [`AlOptions::hold_penalty_when_feasible`] kept the penalty at some outer
    /// iteration that would otherwise have raised it (false: the run is the same bit for bit
    /// as without that option).
    pub penalty_held: bool,
}

/// Constraint violation of values `c`.
pub fn violation(p: &impl Nlp, c: &[f64]) -> f64 {
    c.iter()
        .enumerate()
        .fold(0.0, |m, (i, &v)| match p.sense(i) {
            Sense::Equal => m.max(v.abs()),
            Sense::LessEq => m.max(v),
        })
}

/// State after one outer iteration, handed to the observer of [`augmented_lagrangian_observed`].
#[derive(Clone, Copy, Debug)]
pub struct OuterIterate<'a> {
    /// Outer iteration number (from 1).
    pub outer: usize,
    /// Objective `f(x)`.
    pub f: f64,
    /// Constraint violation (complementarity-aware) after the multiplier update.
    pub violation: f64,
    /// Penalty used in this iteration.
    pub rho: f64,
    /// The iterate.
    pub x: &'a [f64],
}

/// Width (in the rows' own units, dimensionless lengths) of the band around an inequality's
/// boundary where its penalty curvature enters `∇²Φ`.
const BOUNDARY_BAND: f64 = 1e-9;

crate::kernels::wide::dispatch! {
    /// The augmented function `Φ` from `f` and the row values `c`; writes the multiplier
    /// estimates `y` (the weights of `∇Φ = ∇f + Σ yᵢ∇cᵢ`) and the penalty weights `s` of the rows
    /// whose penalty is active or on its boundary (`ρ`, else 0), which make the Gauss–Newton
    /// part `Σ sᵢ∇cᵢ∇cᵢᵀ` of `∇²Φ`. The rows' `senses` are empty when every row is an
    /// inequality; `s` is empty when the weights are not wanted (BFGS's runs).
    fn augment(
        f: f64,
        c: &[f64],
        lam: &[f64],
        rho: f64,
        senses: &[Sense],
        y: &mut [f64],
        s: &mut [f64],
    ) -> f64 => augment_body
}

/// [`augment`]'s loop (compiled twice, see [`crate::kernels::wide`]).
#[inline(always)]
fn augment_body(
    f: f64,
    c: &[f64],
    lam: &[f64],
    rho: f64,
    senses: &[Sense],
    y: &mut [f64],
    s: &mut [f64],
) -> f64 {
    if senses.is_empty() {
        return augment_inequalities(f, c, lam, rho, y, s);
    }
    let mut phi = f;
    for i in 0..c.len() {
        match senses[i] {
            Sense::Equal => {
                phi += lam[i] * c[i] + 0.5 * rho * c[i] * c[i];
                y[i] = lam[i] + rho * c[i];
                if let Some(si) = s.get_mut(i) {
                    *si = rho;
                }
            }
            Sense::LessEq => {
                let v = lam[i] + rho * c[i];
                let t = v.max(0.0);
                phi += (t * t - lam[i] * lam[i]) / (2.0 * rho);
                y[i] = t;
                if let Some(si) = s.get_mut(i) {
                    *si = less_eq_weight(v, rho);
                }
            }
        }
    }
    phi
}

/// The penalty weight of an inequality row with `λ + ρc = v`. The penalty's curvature also
/// counts for a row that sits on its boundary to within rounding (`v` in (−ρ·1e-9, 0]): there
/// `Φ` has a kink in its second derivative, and a Hessian without the row lets a Newton step
/// cross the boundary by far more than the quadratic penalty allows (the line search then fails
/// at a contact the start shape already touches).
#[inline(always)]
fn less_eq_weight(v: f64, rho: f64) -> f64 {
    if v > -rho * BOUNDARY_BAND { rho } else { 0.0 }
}

/// [`augment_body`] for inequality rows only, in two passes: the multiplier estimates and
/// weights row by row (vectorised), then `Φ`'s sum in row order over the rows that add to it.
/// A row with `λ = 0` whose penalty is inactive adds exactly +0, which leaves the sum as it is
/// (most rows are such): the result is the same bit for bit as adding every row.
#[inline(always)]
fn augment_inequalities(
    f: f64,
    c: &[f64],
    lam: &[f64],
    rho: f64,
    y: &mut [f64],
    s: &mut [f64],
) -> f64 {
    let m = c.len();
    let (c, lam, y) = (&c[..m], &lam[..m], &mut y[..m]);
    if s.is_empty() {
        for i in 0..m {
            y[i] = (lam[i] + rho * c[i]).max(0.0);
        }
    } else {
        let s = &mut s[..m];
        for i in 0..m {
            let v = lam[i] + rho * c[i];
            y[i] = v.max(0.0);
            s[i] = less_eq_weight(v, rho);
        }
    }
    let mut phi = f;
    const BLOCK: usize = 8;
    let (y, lam) = (&y[..m], &lam[..m]);
    for (yb, lb) in y.chunks(BLOCK).zip(lam.chunks(BLOCK)) {
        if crate::kernels::all_zero(yb) && crate::kernels::all_zero(lb) {
            continue;
        }
        for (&t, &l) in yb.iter().zip(lb) {
            if t != 0.0 || l != 0.0 {
                phi += (t * t - l * l) / (2.0 * rho);
            }
        }
    }
    // Adding +0 turns −0 into +0: the same sum as with every row added.
    if phi == 0.0 && m > 0 {
        phi = 0.0;
    }
    phi
}

/// The point and objective of the last [`Nlp::values`] call of one multiplier-method run. The
/// run asks for the values at the inner minimiser's final point again — for the multiplier
/// update and the observer, for the next inner minimisation's first step (only the multipliers
/// and the penalty change, and they enter through [`augment`]) and for the report — and
/// `p`'s rows, objective and state there are still those of that call, so it is not repeated.
#[derive(Default)]
struct LastValues {
    x: Vec<f64>,
    f: f64,
    /// Calls of [`Nlp::values`] made.
    calls: usize,
}

impl LastValues {
    /// `p.values(x, c)`, or the last call's objective when it was at `x` (bit for bit; `c`
    /// then still holds its rows).
    fn at<P: Nlp>(&mut self, p: &mut P, x: &[f64], c: &mut [f64]) -> f64 {
        let same = self.calls > 0
            && self.x.len() == x.len()
            && self
                .x
                .iter()
                .zip(x)
                .all(|(a, b)| a.to_bits() == b.to_bits());
        if !same {
            self.f = p.values(x, c);
            self.x.clear();
            self.x.extend_from_slice(x);
            self.calls += 1;
        }
        self.f
    }
}

/// Solves `p` from `x` (updated in place), warm-starting the multipliers from `lambda0` if given.
pub fn augmented_lagrangian<P: Nlp>(
    p: &mut P,
    x: &mut [f64],
    lambda0: Option<&[f64]>,
    opts: AlOptions,
) -> AlOutcome {
    augmented_lagrangian_observed(p, x, lambda0, opts, &mut |_, _| true)
}

/// [`augmented_lagrangian`], calling `on_outer` after every outer iteration; the run stops with
/// [`AlStatus::Interrupted`] when it returns `false`.
pub fn augmented_lagrangian_observed<P: Nlp>(
    p: &mut P,
    x: &mut [f64],
    lambda0: Option<&[f64]>,
    opts: AlOptions,
    on_outer: &mut dyn FnMut(&OuterIterate, &P) -> bool,
) -> AlOutcome {
    augmented_lagrangian_warm(p, x, lambda0, opts, &mut Vec::new(), on_outer)
}

/// [`augmented_lagrangian_observed`] with BFGS's inverse-Hessian approximation `h` taken in
/// (empty: a scaled identity) and handed back, for a continuation of related problems.
pub fn augmented_lagrangian_warm<P: Nlp>(
    p: &mut P,
    x: &mut [f64],
    lambda0: Option<&[f64]>,
    opts: AlOptions,
    h: &mut Vec<f64>,
    on_outer: &mut dyn FnMut(&OuterIterate, &P) -> bool,
) -> AlOutcome {
    let (n, m) = (p.n(), p.m());
    let use_newton = opts.second_order && p.has_hessian();
    // A run started on a stable equilibrium holds on to it: without multipliers, where the
    // least-squares ones make it one; with them (Newton's runs, the only ones that meet
    // saddles), where they do.
    let seeded = lambda0
        .is_none()
        .then(|| equilibrium_multipliers(p, x, &opts))
        .flatten();
    let on_equilibrium = seeded.is_some()
        || (use_newton && lambda0.is_some_and(|l| on_stable_equilibrium(p, x, l, &opts)));
    let mut lambda = match (lambda0, seeded) {
        (Some(l), _) => l.to_vec(),
        (None, Some(l)) => l,
        (None, None) => vec![0.0; m],
    };
    let mut rho = opts.rho_initial;
    let mut c = vec![0.0; m];
    let mut y = vec![0.0; m];
    let mut inner_iterations = 0;
    let mut last = LastValues::default();
    let mut viol_prev = f64::INFINITY;
    let mut status = AlStatus::IterationLimit;
    let mut penalty_held = false;
    let mut outer = 0;
    let senses: Vec<Sense> = (0..m).map(|i| p.sense(i)).collect();
    // For `augment`: empty when every row is an inequality.
    let row_senses: &[Sense] = if senses.iter().all(|&s| s == Sense::LessEq) {
        &[]
    } else {
        &senses
    };
    let mut inner_tol = 1e-3_f64.max(opts.optimality_tol);
    let mut sw = vec![0.0; m];
    // Second-order multiplier steps until one outer iteration fails to cut the violation enough
    // (inconsistent constraints make the dual unbounded, and its Newton steps diverge).
    let mut dual_ok = use_newton && opts.newton_multipliers;
    // The point and ∇²Φ of Newton's last Hessian.
    let mut last_hessian: (Vec<f64>, Vec<f64>) = (Vec::new(), Vec::new());
    // The last outer iteration took a second-order multiplier step.
    let mut dual_stepped = false;
    // Step off saddles of Φ (set once one is found to be the problem's, not the penalty's).
    let mut escape = false;
    while outer < opts.max_outer {
        outer += 1;
        p.set_multipliers(&lambda);
        let out = if use_newton {
            let lam = &lambda;
            let senses = row_senses;
            // `eval` and `hess` share the problem and the buffers; they run one after the other,
            // and `hess` comes right after an `eval` at its point (the problem's state, `y` and
            // the penalty weights are that evaluation's).
            let state = std::cell::RefCell::new((&mut *p, &mut c, &mut y, &mut sw));
            let last_h = std::cell::RefCell::new(&mut last_hessian);
            let last = &mut last;
            newton(
                |xv, g| {
                    let mut st = state.borrow_mut();
                    let (p, c, y, sw) = &mut *st;
                    let f = last.at(*p, xv, c);
                    let phi = augment(f, c, lam, rho, senses, y, sw);
                    if let Some(g) = g {
                        p.gradient(xv, y, g);
                    }
                    phi
                },
                |xv, h| {
                    let mut st = state.borrow_mut();
                    let (p, _, y, sw) = &mut *st;
                    p.hessian(xv, y, sw, h);
                    if dual_ok {
                        // Kept for the multiplier step, which needs ∇²Φ at the final point.
                        let mut l = last_h.borrow_mut();
                        l.0.clear();
                        l.0.extend_from_slice(xv);
                        l.1.clear();
                        l.1.extend_from_slice(h);
                    }
                },
                x,
                NewtonOptions {
                    grad_tol: inner_tol,
                    max_iter: opts.max_inner,
                    max_step: opts.max_step,
                    min_iter: usize::from(dual_stepped),
                    // A negative curvature of Φ at a stationary point may be the penalty's
                    // (too small to hold the constraints) rather than the problem's: the
                    // saddle is left only once the reduced Hessian says it is the problem's.
                    escape_saddles: escape || rho >= opts.rho_max,
                },
            )
        } else {
            let lam = &lambda;
            let c = &mut c;
            let y = &mut y;
            let p = &mut *p;
            let senses = row_senses;
            let last = &mut last;
            bfgs(
                |xv, g| {
                    let f = last.at(p, xv, c);
                    // BFGS needs no penalty weights.
                    let phi = augment(f, c, lam, rho, senses, y, &mut []);
                    p.gradient(xv, y, g);
                    phi
                },
                x,
                h,
                BfgsOptions {
                    grad_tol: inner_tol,
                    max_iter: opts.max_inner,
                    f_rel_tol: 0.0,
                },
            )
        };
        inner_iterations += out.iterations;
        if out.status == BfgsStatus::Saddle {
            // In a run started on a stable equilibrium, where the problem itself curves up
            // clearly along the constraints, the negative curvature of Φ is the penalty's (too
            // small to hold the constraints) and the stationary point stands: the run stays on
            // the equilibrium it was started on. Otherwise (a saddle of the problem, one it
            // cannot tell from neutral such as a pitchfork, or a warm-started continuation
            // step) minimise again from here, stepping off it.
            if !on_equilibrium || !clearly_stable_along_constraints(p, x, &lambda) {
                escape = true;
                continue;
            }
        }
        if out.status == BfgsStatus::NumericalFailure {
            status = AlStatus::NumericalFailure;
            break;
        }
        let f_now = last.at(p, x, &mut c);
        let dual_step = if dual_ok && m > 0 {
            augment(f_now, &c, &lambda, rho, row_senses, &mut y, &mut sw);
            // Newton's Hessian at x used these multipliers and this penalty: it is ∇²Φ here.
            if last_hessian.0.as_slice() != &x[..] {
                last_hessian.1 = vec![0.0; n * n];
                p.hessian(x, &y, &sw, &mut last_hessian.1);
            }
            dual_newton_multipliers(p, x, &c, &lambda, &sw, rho, &last_hessian.1)
        } else {
            None
        };
        let mut viol: f64 = 0.0;
        for i in 0..m {
            match senses[i] {
                Sense::Equal => {
                    viol = viol.max(c[i].abs());
                    lambda[i] += rho * c[i];
                }
                Sense::LessEq => {
                    viol = viol.max(c[i].max(-lambda[i] / rho).abs());
                    lambda[i] = (lambda[i] + rho * c[i]).max(0.0);
                }
            }
        }
        dual_stepped = dual_step.is_some();
        if let Some(l) = dual_step {
            lambda = l;
        }
        let go_on = on_outer(
            &OuterIterate {
                outer,
                f: f_now,
                violation: viol,
                rho,
                x,
            },
            p,
        );
        if !go_on {
            status = AlStatus::Interrupted;
            break;
        }
        let inner_ok = out.grad_norm <= opts.optimality_tol
            || matches!(
                out.status,
                BfgsStatus::LineSearchFailed | BfgsStatus::Stalled
            );
        if viol <= opts.feasibility_tol && inner_ok && inner_tol <= opts.optimality_tol {
            status = AlStatus::Converged;
            break;
        }
        let slow = viol > 0.25 * viol_prev;
        let hold = opts.hold_penalty_when_feasible && viol <= opts.feasibility_tol;
        penalty_held |= slow && hold;
        if slow && !hold {
            dual_ok = false;
            if rho >= opts.rho_max && viol > opts.feasibility_tol && outer > 5 {
                status = AlStatus::Infeasible;
                break;
            }
            // BFGS keeps its curvature: the penalty's share of it grows, and the updates
            // follow (clearing it here cost the planner twice the evaluations).
            rho = (rho * 10.0).min(opts.rho_max);
        }
        viol_prev = viol;
        inner_tol = (inner_tol * 0.1).max(opts.optimality_tol);
    }
    // Everything below is evaluated at x: one evaluation serves every gradient.
    let f = last.at(p, x, &mut c);
    let evaluations = last.calls;
    let polished = least_squares_multipliers_at(p, x, &c, &lambda, opts.active_tol);
    let mut g = vec![0.0; n];
    p.gradient(x, &lambda, &mut g);
    let kkt_now = inf_norm(&g);
    let (lambda, kkt) = match polished {
        Some((l, r)) if r <= kkt_now => (l, r),
        _ => (lambda, kkt_now),
    };
    let max_violation = violation(p, &c);
    let grad_scale = {
        p.gradient(x, &vec![0.0; m], &mut g);
        g.iter().fold(1.0_f64, |acc, v| acc.max(v.abs()))
    };
    let kkt_ok = kkt <= opts.optimality_tol * grad_scale;
    if !f.is_finite() {
        status = AlStatus::NumericalFailure;
    } else if status == AlStatus::Converged && (!kkt_ok || max_violation > opts.feasibility_tol) {
        status = AlStatus::IterationLimit;
    } else if status == AlStatus::IterationLimit && max_violation <= opts.feasibility_tol && kkt_ok
    {
        status = AlStatus::Converged;
    }
    AlOutcome {
        status,
        f,
        lambda,
        c,
        max_violation,
        kkt_residual: kkt,
        outer_iterations: outer,
        inner_iterations,
        evaluations,
        rho,
        penalty_held,
    }
}

/// `‖∇f + Jᵀλ‖∞` at `x`.
pub fn kkt_residual<P: Nlp>(p: &mut P, x: &[f64], lambda: &[f64]) -> f64 {
    let mut c = vec![0.0; p.m()];
    p.values(x, &mut c);
    let mut g = vec![0.0; p.n()];
    p.gradient(x, lambda, &mut g);
    g.iter().fold(0.0, |m, v| m.max(v.abs()))
}

/// How close to stationary a feasible start must be for [`equilibrium_multipliers`] to seed
/// the multipliers: `‖∇f + Jᵀλ‖∞ ≤ NEAR_EQUILIBRIUM · max(1, ‖∇f‖∞)`.
const NEAR_EQUILIBRIUM: f64 = 1e-2;

/// The multipliers a run starts with when none are given, if `x` is (near) a KKT point: the
/// least-squares multipliers there, when `x` is feasible and they leave a small residual.
/// Started from zero multipliers, the first inner minimisation would see a start on an
/// equilibrium as far from stationary (the reactions it needs are missing) and could leave it
/// for another branch; with them, Newton's first step stays (or stays near). `None` elsewhere:
/// a start far from equilibrium keeps zero multipliers.
fn equilibrium_multipliers<P: Nlp>(p: &mut P, x: &[f64], opts: &AlOptions) -> Option<Vec<f64>> {
    let (c, scale) = feasible_with_scale(p, x, opts)?;
    let zero = vec![0.0; c.len()];
    let (lam, residual) = least_squares_multipliers_at(p, x, &c, &zero, opts.active_tol)?;
    if residual > NEAR_EQUILIBRIUM * scale {
        return None;
    }
    // Only a stable (or neutral) equilibrium is held on to: from an unstable one the run sets
    // out with zero multipliers, as from anywhere else, and falls off it.
    if unstable_along_constraints(p, x, &lam) {
        return None;
    }
    Some(lam)
}

/// Whether `x` with the multipliers `lambda` is a stable (or neutral) equilibrium within the
/// tolerances [`equilibrium_multipliers`] takes: feasible, `‖∇f + Jᵀλ‖∞ ≤ NEAR_EQUILIBRIUM ·
/// max(1, ‖∇f‖∞)`, and not curving down along the constraints. A warm start from a converged
/// solve of the same problem (a replay's first step, on the start shape) is one.
fn on_stable_equilibrium<P: Nlp>(p: &mut P, x: &[f64], lambda: &[f64], opts: &AlOptions) -> bool {
    if lambda.len() != p.m() {
        return false;
    }
    let Some((_, scale)) = feasible_with_scale(p, x, opts) else {
        return false;
    };
    let mut g = vec![0.0; p.n()];
    p.gradient(x, lambda, &mut g);
    inf_norm(&g) <= NEAR_EQUILIBRIUM * scale && !unstable_along_constraints(p, x, lambda)
}

/// At a feasible `x` of a problem with constraints: the row values (the last [`Nlp::values`]
/// call is at `x`) and `max(1, ‖∇f‖∞)`, the scale of a KKT residual there; `None` elsewhere.
fn feasible_with_scale<P: Nlp>(p: &mut P, x: &[f64], opts: &AlOptions) -> Option<(Vec<f64>, f64)> {
    let m = p.m();
    if m == 0 {
        return None;
    }
    let mut c = vec![0.0; m];
    p.values(x, &mut c);
    if violation(p, &c) > opts.feasibility_tol {
        return None;
    }
    let mut g = vec![0.0; p.n()];
    p.gradient(x, &vec![0.0; m], &mut g);
    Some((c, inf_norm(&g).max(1.0)))
}

/// The reduced Hessian's smallest eigenvalue over its largest magnitude (at least 1) at
/// `(x, lambda)`: how the Lagrangian curves along the constraints; `None` when they leave no
/// freedom.
fn reduced_curvature<P: Nlp>(p: &mut P, x: &[f64], lambda: &[f64]) -> Option<f64> {
    let reduced = super::second_order::reduced_hessian_eigenvalues(p, x, lambda, 1e-8);
    let scale = reduced.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
    reduced.first().map(|&l| l / scale)
}

/// Whether the Lagrangian curves down along the constraints at `(x, lambda)`, beyond the
/// rounding of an exact Hessian (about 1e-13 of its largest eigenvalue).
fn unstable_along_constraints<P: Nlp>(p: &mut P, x: &[f64], lambda: &[f64]) -> bool {
    reduced_curvature(p, x, lambda).is_some_and(|r| r < -1e-10)
}

/// Whether it curves up clearly (by more than 1e-6 of its largest eigenvalue) in every
/// direction the constraints leave free.
fn clearly_stable_along_constraints<P: Nlp>(p: &mut P, x: &[f64], lambda: &[f64]) -> bool {
    reduced_curvature(p, x, lambda).is_none_or(|r| r > 1e-6)
}

/// Largest dual Newton step, in first-order steps `ρ‖c_A‖∞`.
const DUAL_STEP_CAP: f64 = 10.0;

/// The second-order multiplier update at `x`, the minimiser of `Φ` for multipliers `lambda`
/// (`c` its row values, `s` the penalty weights [`augment`] wrote there, `hessian` = `∇²Φ(x)`,
/// the last [`Nlp::values`] call at `x`): a Newton step on the
/// dual function, whose gradient is `c_A` and whose Hessian is `−J_A ∇²Φ⁻¹ J_Aᵀ` on the rows
/// `A` with an active penalty. Inequality multipliers are clipped at zero, inactive ones are
/// zero. `None` when `∇²Φ` is not positive definite or the dual Hessian is singular (the caller
/// falls back to `λ + ρc`).
fn dual_newton_multipliers<P: Nlp>(
    p: &mut P,
    x: &[f64],
    c: &[f64],
    lambda: &[f64],
    s: &[f64],
    rho: f64,
    hessian: &[f64],
) -> Option<Vec<f64>> {
    let (n, m) = (p.n(), p.m());
    let active: Vec<usize> = (0..m).filter(|&i| s[i] > 0.0).collect();
    if active.is_empty() {
        return None;
    }
    let ch = DMatrix::from_row_slice(n, n, hessian).cholesky()?;
    let (_, rows) = jacobian_rows_at(p, x, &active);
    let k = active.len();
    let jt = DMatrix::from_fn(n, k, |i, j| rows[j][i]);
    let hinv_jt = ch.solve(&jt);
    let dual = jt.transpose() * hinv_jt;
    let ca = DVector::from_fn(k, |j, _| c[active[j]]);
    let mut step = dual.cholesky()?.solve(&ca);
    if step.iter().any(|v| !v.is_finite()) {
        return None;
    }
    // Near-singular dual Hessians (nearly dependent or inconsistent rows) give huge steps: keep
    // the step within a few first-order steps `ρc`.
    let cap = DUAL_STEP_CAP * rho * ca.amax();
    let size = step.amax();
    if size > cap {
        step *= cap / size;
    }
    let mut out = vec![0.0; m];
    for (j, &i) in active.iter().enumerate() {
        let l = lambda[i] + step[j];
        out[i] = match p.sense(i) {
            Sense::Equal => l,
            Sense::LessEq => l.max(0.0),
        };
    }
    Some(out)
}

/// Rows of the constraint Jacobian, by differencing `gradient` with unit weights.
pub fn jacobian_rows<P: Nlp>(p: &mut P, x: &[f64], rows: &[usize]) -> (Vec<f64>, Vec<Vec<f64>>) {
    let mut c = vec![0.0; p.m()];
    p.values(x, &mut c);
    jacobian_rows_at(p, x, rows)
}

/// [`jacobian_rows`] when the last [`Nlp::values`] call was at `x`.
pub(crate) fn jacobian_rows_at<P: Nlp>(
    p: &mut P,
    x: &[f64],
    rows: &[usize],
) -> (Vec<f64>, Vec<Vec<f64>>) {
    let (n, m) = (p.n(), p.m());
    let mut g0 = vec![0.0; n];
    let zero = vec![0.0; m];
    p.gradient(x, &zero, &mut g0);
    let mut y = vec![0.0; m];
    let mut out = Vec::with_capacity(rows.len());
    for &r in rows {
        y[r] = 1.0;
        let mut g = vec![0.0; n];
        p.gradient(x, &y, &mut g);
        y[r] = 0.0;
        out.push(g.iter().zip(&g0).map(|(a, b)| a - b).collect());
    }
    (g0, out)
}

/// Active rows: every equality row, and inequality rows with `c > −tol` or `λ > 0`.
pub fn active_rows<P: Nlp>(p: &P, c: &[f64], lambda: &[f64], tol: f64) -> Vec<usize> {
    (0..p.m())
        .filter(|&i| match p.sense(i) {
            Sense::Equal => true,
            Sense::LessEq => c[i] > -tol || lambda[i] > 0.0,
        })
        .collect()
}

/// Least-squares multipliers `argmin ‖∇f + J_Aᵀλ_A‖` on the active set, dropping inequality rows
/// whose multiplier comes out negative. Returns the multipliers and the KKT residual, `None` when
/// there are no constraints.
pub fn least_squares_multipliers<P: Nlp>(
    p: &mut P,
    x: &[f64],
    c: &[f64],
    lambda: &[f64],
    tol: f64,
) -> Option<(Vec<f64>, f64)> {
    let mut cv = vec![0.0; p.m()];
    p.values(x, &mut cv);
    least_squares_multipliers_at(p, x, c, lambda, tol)
}

/// [`least_squares_multipliers`] when the last [`Nlp::values`] call was at `x`.
fn least_squares_multipliers_at<P: Nlp>(
    p: &mut P,
    x: &[f64],
    c: &[f64],
    lambda: &[f64],
    tol: f64,
) -> Option<(Vec<f64>, f64)> {
    let m = p.m();
    if m == 0 {
        return None;
    }
    let mut active = active_rows(p, c, lambda, tol);
    let (g0, rows_all) = jacobian_rows_at(p, x, &active);
    let n = g0.len();
    let mut rows: Vec<(usize, Vec<f64>)> = active.drain(..).zip(rows_all).collect();
    for _ in 0..rows.len() + 1 {
        if rows.is_empty() {
            break;
        }
        let k = rows.len();
        let jt = DMatrix::from_fn(n, k, |i, j| rows[j].1[i]);
        let rhs = -DVector::from_column_slice(&g0);
        let svd = jt.clone().svd(true, true);
        let sol = svd
            .solve(&rhs, 1e-12 * svd.singular_values.max().max(1e-300))
            .ok()?;
        let worst = (0..k)
            .filter(|&j| p.sense(rows[j].0) == Sense::LessEq && sol[j] < 0.0)
            .min_by(|&a, &b| sol[a].total_cmp(&sol[b]));
        if let Some(j) = worst {
            rows.remove(j);
            continue;
        }
        let mut lam = vec![0.0; m];
        for (j, (r, _)) in rows.iter().enumerate() {
            lam[*r] = sol[j];
        }
        let res = &jt * &sol + DVector::from_column_slice(&g0);
        return Some((lam, res.amax()));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// min x² + y² s.t. x + y = 1 (λ = −1), and x ≥ 0.8 as −x + 0.8 ≤ 0.
    struct Toy {
        with_ineq: bool,
    }
    impl Nlp for Toy {
        fn n(&self) -> usize {
            2
        }
        fn m(&self) -> usize {
            if self.with_ineq { 2 } else { 1 }
        }
        fn sense(&self, i: usize) -> Sense {
            if i == 0 { Sense::Equal } else { Sense::LessEq }
        }
        fn values(&mut self, x: &[f64], c: &mut [f64]) -> f64 {
            c[0] = x[0] + x[1] - 1.0;
            if self.with_ineq {
                c[1] = 0.8 - x[0];
            }
            x[0] * x[0] + x[1] * x[1]
        }
        fn gradient(&mut self, x: &[f64], y: &[f64], g: &mut [f64]) {
            g[0] = 2.0 * x[0] + y[0];
            g[1] = 2.0 * x[1] + y[0];
            if self.with_ineq {
                g[0] -= y[1];
            }
        }
    }

    #[test]
    fn equality_multiplier_matches_closed_form() {
        let mut p = Toy { with_ineq: false };
        let mut x = vec![0.0, 0.0];
        let out = augmented_lagrangian(&mut p, &mut x, None, AlOptions::default());
        assert_eq!(out.status, AlStatus::Converged);
        assert!((x[0] - 0.5).abs() < 1e-8 && (x[1] - 0.5).abs() < 1e-8);
        assert!((out.lambda[0] + 1.0).abs() < 1e-8, "{:?}", out.lambda);
    }

    #[test]
    fn active_inequality_multiplier_is_positive() {
        // Solution x = (0.8, 0.2): ∇f = (1.6, 0.4); 1.6 + λ₀ − λ₁ = 0, 0.4 + λ₀ = 0.
        let mut p = Toy { with_ineq: true };
        let mut x = vec![0.0, 0.0];
        let out = augmented_lagrangian(&mut p, &mut x, None, AlOptions::default());
        assert_eq!(out.status, AlStatus::Converged);
        assert!((x[0] - 0.8).abs() < 1e-8, "{x:?}");
        assert!((out.lambda[0] + 0.4).abs() < 1e-7 && (out.lambda[1] - 1.2).abs() < 1e-7);
    }

    /// min q x² + a x + b y on the unit circle x² + y² = 1, with the exact Hessian, so the
    /// multiplier method runs Newton inner steps.
    struct OnCircle {
        q: f64,
        a: f64,
        b: f64,
    }
    impl Nlp for OnCircle {
        fn n(&self) -> usize {
            2
        }
        fn m(&self) -> usize {
            1
        }
        fn sense(&self, _i: usize) -> Sense {
            Sense::Equal
        }
        fn values(&mut self, x: &[f64], c: &mut [f64]) -> f64 {
            c[0] = x[0] * x[0] + x[1] * x[1] - 1.0;
            self.q * x[0] * x[0] + self.a * x[0] + self.b * x[1]
        }
        fn gradient(&mut self, x: &[f64], y: &[f64], g: &mut [f64]) {
            g[0] = 2.0 * self.q * x[0] + self.a + 2.0 * y[0] * x[0];
            g[1] = self.b + 2.0 * y[0] * x[1];
        }
        fn has_hessian(&self) -> bool {
            true
        }
        fn hessian(&mut self, x: &[f64], y: &[f64], s: &[f64], h: &mut [f64]) {
            let j = [2.0 * x[0], 2.0 * x[1]];
            for a in 0..2 {
                h[3 * a] += 2.0 * y[0] + if a == 0 { 2.0 * self.q } else { 0.0 };
                for b in 0..2 {
                    h[2 * a + b] += s[0] * j[a] * j[b];
                }
            }
        }
    }

    /// min x + 2y on the unit circle: x* = −(1, 2)/√5, λ* = √5/2.
    fn circle() -> OnCircle {
        OnCircle {
            q: 0.0,
            a: 1.0,
            b: 2.0,
        }
    }

    /// The dual Newton update reaches the multiplier in fewer outer iterations than `λ + ρc`
    /// from a low penalty, and both reach the closed form.
    #[test]
    fn second_order_multipliers_converge_faster() {
        let run = |newton_multipliers: bool| {
            let mut x = vec![-0.3, -0.8];
            let opts = AlOptions {
                rho_initial: 1.0,
                newton_multipliers,
                ..AlOptions::default()
            };
            let out = augmented_lagrangian(&mut circle(), &mut x, None, opts);
            assert_eq!(out.status, AlStatus::Converged);
            let r5 = 5.0_f64.sqrt();
            assert!(
                (x[0] + 1.0 / r5).abs() < 1e-8 && (x[1] + 2.0 / r5).abs() < 1e-8,
                "{x:?}"
            );
            assert!((out.lambda[0] - r5 / 2.0).abs() < 1e-8, "{:?}", out.lambda);
            out.outer_iterations
        };
        let (second, first) = (run(true), run(false));
        assert!(second < first, "{second} vs {first}");
    }

    /// min Σ dᵢ (xᵢ − tᵢ)² subject to Σ xᵢ = S, with stiffnesses dᵢ over three decades (the
    /// spread of a Ritz basis): xᵢ* = tᵢ − λ*/(2dᵢ), λ* = 2(Σ tᵢ − S)/Σ 1/dᵢ.
    struct Spread {
        t: [f64; 6],
    }
    const SPREAD: [f64; 6] = [1.0, 4.0, 20.0, 90.0, 300.0, 1000.0];
    const SPREAD_SUM: f64 = 2.0;
    impl Spread {
        fn uniform(t: f64) -> Spread {
            Spread { t: [t; 6] }
        }
        fn solution(&self) -> (Vec<f64>, f64) {
            let inv: f64 = SPREAD.iter().map(|d| 1.0 / d).sum();
            let lambda = 2.0 * (self.t.iter().sum::<f64>() - SPREAD_SUM) / inv;
            let x = SPREAD
                .iter()
                .zip(self.t)
                .map(|(d, t)| t - lambda / (2.0 * d))
                .collect();
            (x, lambda)
        }
    }
    impl Nlp for Spread {
        fn n(&self) -> usize {
            SPREAD.len()
        }
        fn m(&self) -> usize {
            1
        }
        fn sense(&self, _i: usize) -> Sense {
            Sense::Equal
        }
        fn values(&mut self, x: &[f64], c: &mut [f64]) -> f64 {
            c[0] = x.iter().sum::<f64>() - SPREAD_SUM;
            (0..SPREAD.len())
                .map(|i| SPREAD[i] * (x[i] - self.t[i]).powi(2))
                .sum()
        }
        fn gradient(&mut self, x: &[f64], y: &[f64], g: &mut [f64]) {
            for i in 0..SPREAD.len() {
                g[i] = 2.0 * SPREAD[i] * (x[i] - self.t[i]) + y[0];
            }
        }
    }

    fn assert_spread_solved(p: &Spread, x: &[f64], out: &AlOutcome) {
        let (xs, ls) = p.solution();
        assert_eq!(out.status, AlStatus::Converged);
        for (a, b) in x.iter().zip(&xs) {
            assert!((a - b).abs() < 1e-5, "{x:?} vs {xs:?}");
        }
        assert!(
            (out.lambda[0] - ls).abs() < 1e-4 * ls.abs(),
            "{:?} vs {ls}",
            out.lambda
        );
    }

    /// A continuation step (t = 1 → 1.2) warm-started with the BFGS curvature the step before
    /// ended with reaches the closed form in fewer evaluations than from a scaled identity.
    #[test]
    fn warm_curvature_takes_a_continuation_step_in_fewer_evaluations() {
        let opts = AlOptions {
            second_order: false,
            feasibility_tol: 1e-8,
            optimality_tol: 1e-7,
            ..AlOptions::default()
        };
        let mut first = Spread::uniform(1.0);
        let mut x = vec![0.0; SPREAD.len()];
        let mut h = Vec::new();
        let out =
            augmented_lagrangian_warm(&mut first, &mut x, None, opts, &mut h, &mut |_, _| true);
        assert_spread_solved(&first, &x, &out);
        assert_eq!(h.len(), SPREAD.len() * SPREAD.len());
        let step = |mut h: Vec<f64>| {
            let mut p = Spread::uniform(1.2);
            let mut xs = x.clone();
            let o = augmented_lagrangian_warm(
                &mut p,
                &mut xs,
                Some(&out.lambda),
                opts,
                &mut h,
                &mut |_, _| true,
            );
            assert_spread_solved(&p, &xs, &o);
            o.evaluations
        };
        let (warm, cold) = (step(h.clone()), step(Vec::new()));
        assert!(warm < cold, "warm {warm} vs cold {cold} evaluations");
    }

    /// A continuation step that moves the solution along the constraint (t₀ + 0.05, t₁ − 0.05:
    /// the same multiplier), started from the last solution and multiplier, is feasible
    /// throughout: a run that holds the penalty while feasible ends with the penalty it was
    /// given; one that does not raises it tenfold per outer iteration that cannot cut the
    /// (negligible) violation by 4. Both reach the closed form.
    #[test]
    fn a_feasible_start_keeps_its_penalty_when_told_to() {
        let (xs, ls) = Spread::uniform(1.0).solution();
        let opts = |hold: bool| AlOptions {
            second_order: false,
            rho_initial: 1e2,
            feasibility_tol: 1e-6,
            optimality_tol: 1e-5,
            hold_penalty_when_feasible: hold,
            ..AlOptions::default()
        };
        let run = |hold: bool| {
            let mut t = [1.0; 6];
            t[0] += 0.05;
            t[1] -= 0.05;
            let mut q = Spread { t };
            let mut x = xs.clone();
            let out = augmented_lagrangian(&mut q, &mut x, Some(&[ls]), opts(hold));
            assert_spread_solved(&q, &x, &out);
            (out.rho, out.outer_iterations, out.penalty_held)
        };
        let (held, raised) = (run(true), run(false));
        assert_eq!(held.0, 1e2);
        assert!(raised.0 >= 1e3, "{raised:?}");
        // The outcome says whether the hold took effect.
        assert!(held.2 && !raised.2);
        // A run from far away, which the hold never changes, says so and matches the run
        // without it to the bit.
        let cold = |hold: bool| {
            let mut q = Spread::uniform(1.0);
            let mut x = vec![0.0; 6];
            let out = augmented_lagrangian(&mut q, &mut x, None, opts(hold));
            (x, out)
        };
        let ((xh, oh), (xr, or)) = (cold(true), cold(false));
        assert!(!oh.penalty_held && !or.penalty_held);
        assert_eq!(xh, xr);
        assert_eq!((oh.rho, oh.evaluations), (or.rho, or.evaluations));
        assert_eq!(oh.lambda, or.lambda);
    }

    /// min −2x² + 0.3x + y on the unit circle: a stable minimum P near (0.96, −0.27) where the
    /// Lagrangian curves down across the circle (−4 + 2λ < 0 along x), and a lower one Q near
    /// (−0.97, −0.23).
    fn bent() -> OnCircle {
        OnCircle {
            q: -2.0,
            a: 0.3,
            b: 1.0,
        }
    }

    /// A run warm-started on a converged stable minimum with its own multiplier (a replay's
    /// first step on its start shape) returns it unchanged, even where the penalty is far too
    /// small to make Φ convex there (Φ has a saddle at P): the problem curves up along the
    /// circle, so the negative curvature is the penalty's. P itself is checked against the
    /// stationarity of f(cos t, sin t): cos t (4 sin t + 1) − 0.3 sin t = 0.
    #[test]
    fn a_warm_start_on_a_stable_minimum_stays_there() {
        let mut x = vec![0.95, -0.3];
        let out = augmented_lagrangian(&mut bent(), &mut x, None, AlOptions::default());
        assert_eq!(out.status, AlStatus::Converged);
        let t = x[1].atan2(x[0]);
        let dfdt = t.cos() * (4.0 * t.sin() + 1.0) - 0.3 * t.sin();
        assert!(
            dfdt.abs() < 1e-7 && (x[0] - 0.9625).abs() < 1e-3,
            "{x:?} {dfdt}"
        );
        // −4 + 2λ < 0: with ρ = 0.01 Φ curves down across the circle at P.
        let lambda = out.lambda.clone();
        assert!(
            -4.0 + 2.0 * lambda[0] + 0.01 * 4.0 * x[0] * x[0] < 0.0,
            "{lambda:?}"
        );
        let opts = AlOptions {
            rho_initial: 0.01,
            ..AlOptions::default()
        };
        let mut y = x.clone();
        let again = augmented_lagrangian(&mut bent(), &mut y, Some(&lambda), opts);
        assert_eq!(again.status, AlStatus::Converged);
        assert_eq!(y, x);
        // From the same point without the multiplier the run starts off equilibrium and
        // leaves P for the lower minimum Q.
        let mut z = x.clone();
        let off = augmented_lagrangian(&mut bent(), &mut z, Some(&[0.0]), opts);
        assert!(z[0] < -0.9, "{z:?} {off:?}");
    }
}
