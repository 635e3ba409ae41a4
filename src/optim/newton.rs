//! Damped Newton with a backtracking (Armijo) line search, for problems that provide a Hessian
//! (or a positive semi-definite approximation of one).
//!
//! Each step solves `(H + δI) d = −g` by Cholesky; `δ` starts at zero and grows ×10 from a small
//! multiple of `H`'s largest diagonal entry until the factorisation succeeds (a Levenberg–
//! Marquardt shift), and is remembered, divided by 10, for the next step. Near a minimum with a
//! positive definite Hessian the steps are pure Newton steps and converge quadratically.

use super::bfgs::{BfgsOutcome, BfgsStatus, inf_norm};
use nalgebra::{DMatrix, DVector};

/// Options for [`newton`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonOptions {
    /// Stop when `‖∇f‖∞ ≤ grad_tol`.
    pub grad_tol: f64,
    /// Iteration budget.
    pub max_iter: usize,
    /// Largest step `‖d‖∞` (a longer Newton step is scaled back to it).
    pub max_step: f64,
    /// Steps taken even when the gradient is already below `grad_tol` (a multiplier update that
    /// moves the minimiser by less than the tolerance still moves it).
    pub min_iter: usize,
    /// At a stationary point with a clearly negative curvature, step along it while `f` falls
    /// (else stop there with [`BfgsStatus::Saddle`]).
    pub escape_saddles: bool,
}

/// Minimises `f` from `x` (updated in place). `eval(x, g)` returns `f(x)` and, when `g` is given,
/// writes `∇f(x)`; `hess(x, h)` writes the (row-major `n×n`) Hessian at `x`. Every `hess` call
/// comes right after an `eval` at the same `x` that asked for a gradient, with no `eval` between,
/// so a problem may reuse the state of that evaluation.
pub fn newton(
    mut eval: impl FnMut(&[f64], Option<&mut [f64]>) -> f64,
    mut hess: impl FnMut(&[f64], &mut [f64]),
    x: &mut [f64],
    opts: NewtonOptions,
) -> BfgsOutcome {
    let n = x.len();
    let mut g = vec![0.0; n];
    let mut f = eval(x, Some(&mut g));
    let mut evals = 1;
    let mut h = vec![0.0; n * n];
    let mut xn = vec![0.0; n];
    let mut gt = vec![0.0; n];
    let mut shift = 0.0_f64;
    let mut iterations = 0;
    let mut stalled = 0;
    let status =
        'outer: {
            if !f.is_finite() || g.iter().any(|v| !v.is_finite()) {
                break 'outer BfgsStatus::NumericalFailure;
            }
            for _ in 0..opts.max_iter {
                h.iter_mut().for_each(|v| *v = 0.0);
                hess(x, &mut h);
                if h.iter().any(|v| !v.is_finite()) {
                    break 'outer BfgsStatus::NumericalFailure;
                }
                let hm = DMatrix::from_row_slice(n, n, &h);
                let dmax = (0..n)
                    .fold(0.0_f64, |m, i| m.max(hm[(i, i)].abs()))
                    .max(1e-12);
                if inf_norm(&g) <= opts.grad_tol && iterations >= opts.min_iter {
                    // A stationary point: a minimum unless the Hessian has a clearly negative
                    // eigenvalue (a saddle, e.g. a straight rod under compression by symmetry);
                    // then step along that direction while it lowers f. A Hessian whose
                    // Cholesky factorisation succeeds with a shift of half the threshold has
                    // no eigenvalue below it (the factorisation's backward error is of order
                    // n·ε·‖H‖, far below 1e-8 ‖H‖): the eigendecomposition, which costs about
                    // ten times as much, is needed only when it fails.
                    let mut shifted = hm.clone();
                    for i in 0..n {
                        shifted[(i, i)] += 0.5e-8 * dmax;
                    }
                    if shifted.cholesky().is_some() {
                        break 'outer BfgsStatus::Converged;
                    }
                    let eig = hm.clone().symmetric_eigen();
                    let (imin, lmin) = eig.eigenvalues.iter().enumerate().fold(
                        (0, f64::INFINITY),
                        |a, (i, &v)| if v < a.1 { (i, v) } else { a },
                    );
                    if lmin >= -1e-8 * dmax {
                        break 'outer BfgsStatus::Converged;
                    }
                    if !opts.escape_saddles {
                        break 'outer BfgsStatus::Saddle;
                    }
                    let v = eig.eigenvectors.column(imin);
                    let mut escaped = false;
                    let mut alpha = 1.0;
                    'search: for _ in 0..30 {
                        for sign in [1.0, -1.0] {
                            for i in 0..n {
                                xn[i] = x[i] + sign * alpha * v[i];
                            }
                            let fv = eval(&xn, None);
                            evals += 1;
                            if fv.is_finite() && fv < f + 0.25 * lmin * alpha * alpha {
                                escaped = true;
                                break 'search;
                            }
                        }
                        alpha *= 0.5;
                    }
                    if !escaped {
                        break 'outer BfgsStatus::Converged;
                    }
                    iterations += 1;
                    x.copy_from_slice(&xn);
                    f = eval(x, Some(&mut g));
                    evals += 1;
                    continue;
                }
                iterations += 1;
                let rhs = -DVector::from_column_slice(&g);
                let mut d = None;
                for _ in 0..40 {
                    let mut shifted = hm.clone();
                    for i in 0..n {
                        shifted[(i, i)] += shift;
                    }
                    if let Some(ch) = shifted.cholesky() {
                        d = Some(ch.solve(&rhs));
                        break;
                    }
                    shift = (shift * 10.0).max(1e-8 * dmax);
                }
                let Some(d) = d else {
                    break 'outer BfgsStatus::NumericalFailure;
                };
                shift *= 0.1;
                if shift < 1e-12 * dmax {
                    shift = 0.0;
                }
                let mut d = d;
                let dn = inf_norm(d.as_slice());
                if dn > opts.max_step {
                    d *= opts.max_step / dn;
                }
                let slope: f64 = d.iter().zip(&g).map(|(a, b)| a * b).sum();
                if slope >= 0.0 {
                    break 'outer BfgsStatus::LineSearchFailed;
                }
                // Backtracking: full step first. Near a minimum the predicted decrease falls below
                // what f can resolve; there a step that lowers the gradient norm is taken instead.
                let mut alpha = 1.0;
                // Some(f at the step), plus whether its gradient is already in `gt`.
                let mut accepted = None;
                let g_norm = inf_norm(&g);
                // Down to α ≈ 2e-4: a Newton direction that needs shorter steps is not worth
                // following (the caller sees a failed line search, as at the precision floor).
                for _ in 0..13 {
                    for i in 0..n {
                        xn[i] = x[i] + alpha * d[i];
                    }
                    // The full step usually succeeds: its gradient comes with it.
                    let full = alpha == 1.0;
                    let fv = eval(&xn, if full { Some(&mut gt) } else { None });
                    evals += 1;
                    if fv.is_finite() && fv <= f + 1e-4 * alpha * slope {
                        accepted = Some((fv, full));
                        break;
                    }
                    if fv.is_finite() && (fv - f).abs() <= 1e-12 * f.abs().max(1.0) {
                        let fg = if full {
                            fv
                        } else {
                            evals += 1;
                            eval(&xn, Some(&mut gt))
                        };
                        if inf_norm(&gt) < 0.5 * g_norm {
                            accepted = Some((fg, true));
                            break;
                        }
                    }
                    alpha *= if fv.is_finite() { 0.5 } else { 0.1 };
                }
                let Some((f_step, have_gradient)) = accepted else {
                    break 'outer BfgsStatus::LineSearchFailed;
                };
                // A step that is not a full one hints at a poor model: shift more next time.
                if alpha < 1.0 {
                    shift = shift.max(1e-6 * dmax);
                }
                x.copy_from_slice(&xn);
                let f_old = f;
                if have_gradient {
                    f = f_step;
                    g.copy_from_slice(&gt);
                } else {
                    f = eval(x, Some(&mut g));
                    evals += 1;
                }
                if !f.is_finite() {
                    break 'outer BfgsStatus::NumericalFailure;
                }
                // At the precision floor f no longer moves: three such steps in a row end it.
                if (f_old - f).abs() <= 1e-14 * f.abs().max(1.0) {
                    stalled += 1;
                    if stalled >= 3 {
                        break 'outer BfgsStatus::Stalled;
                    }
                } else {
                    stalled = 0;
                }
            }
            BfgsStatus::at_budget_end(&g, opts.grad_tol)
        };
    BfgsOutcome {
        f,
        grad_norm: inf_norm(&g),
        iterations,
        evaluations: evals,
        status,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimises_rosenbrock_with_exact_hessian() {
        let eval = |x: &[f64], g: Option<&mut [f64]>| {
            let (a, b) = (x[1] - x[0] * x[0], 1.0 - x[0]);
            if let Some(g) = g {
                g[0] = -400.0 * a * x[0] - 2.0 * b;
                g[1] = 200.0 * a;
            }
            100.0 * a * a + b * b
        };
        let mut x = vec![-1.2, 1.0];
        let out = newton(
            eval,
            |x, h| {
                h[0] = 1200.0 * x[0] * x[0] - 400.0 * x[1] + 2.0;
                h[1] = -400.0 * x[0];
                h[2] = -400.0 * x[0];
                h[3] = 200.0;
            },
            &mut x,
            NewtonOptions {
                grad_tol: 1e-10,
                max_iter: 100,
                max_step: f64::INFINITY,
                min_iter: 0,
                escape_saddles: true,
            },
        );
        assert_eq!(out.status, BfgsStatus::Converged);
        assert!(
            (x[0] - 1.0).abs() < 1e-9 && (x[1] - 1.0).abs() < 1e-9,
            "{x:?}"
        );
        // Newton needs a few dozen steps here, not hundreds.
        assert!(out.iterations < 40, "{}", out.iterations);
    }
}
