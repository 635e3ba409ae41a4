//! BFGS with a dense inverse-Hessian approximation (O(n²) per step) and a strong-Wolfe line
//! search (Nocedal & Wright, Algorithm 6.1). Intended for the 10–300 unknowns of Ritz problems.

use super::line_search::{WolfeParams, strong_wolfe};

/// Options for [`bfgs`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BfgsOptions {
    /// Stop when `‖∇f‖∞ ≤ grad_tol`.
    pub grad_tol: f64,
    /// Iteration budget.
    pub max_iter: usize,
    /// Stop when the relative decrease of `f` over an iteration falls below this (0 disables).
    pub f_rel_tol: f64,
}

impl Default for BfgsOptions {
    fn default() -> Self {
        BfgsOptions {
            grad_tol: 1e-8,
            max_iter: 500,
            f_rel_tol: 0.0,
        }
    }
}

/// Why BFGS stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BfgsStatus {
    /// The gradient tolerance was met.
    Converged,
    /// The relative decrease tolerance was met.
    Stalled,
    /// The iteration budget ran out.
    IterationLimit,
    /// The line search could not make progress (often: at machine precision).
    LineSearchFailed,
    /// A non-finite value appeared.
    NumericalFailure,
    /// A stationary point with a clearly negative curvature, left where it is because the
    /// caller asked not to step off saddles ([`super::newton::NewtonOptions::escape_saddles`]).
    Saddle,
}

impl BfgsStatus {
    /// The status of a minimiser whose iteration budget ran out at gradient `g`.
    pub(crate) fn at_budget_end(g: &[f64], grad_tol: f64) -> BfgsStatus {
        if inf_norm(g) <= grad_tol {
            BfgsStatus::Converged
        } else {
            BfgsStatus::IterationLimit
        }
    }
}

/// Result of [`bfgs`].
#[derive(Clone, Debug)]
pub struct BfgsOutcome {
    /// Final objective value.
    pub f: f64,
    /// Final `‖∇f‖∞`.
    pub grad_norm: f64,
    /// Iterations taken.
    pub iterations: usize,
    /// Function evaluations.
    pub evaluations: usize,
    /// Termination reason.
    pub status: BfgsStatus,
}

/// `‖v‖∞`.
pub(crate) fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// Minimises `f` from `x` (updated in place). `fg(x, g)` returns `f(x)` and writes `∇f(x)`.
/// `h` is the inverse-Hessian approximation (row-major `n×n`); pass an empty vector to start from
/// a scaled identity, or a previous one to warm-start.
pub fn bfgs(
    mut fg: impl FnMut(&[f64], &mut [f64]) -> f64,
    x: &mut [f64],
    h: &mut Vec<f64>,
    opts: BfgsOptions,
) -> BfgsOutcome {
    let n = x.len();
    let mut g = vec![0.0; n];
    let mut f = fg(x, &mut g);
    let mut evals = 1;
    let fresh = h.len() != n * n;
    if fresh {
        *h = vec![0.0; n * n];
    }
    let mut d = vec![0.0; n];
    let mut xn = vec![0.0; n];
    let mut gn = vec![0.0; n];
    let mut s = vec![0.0; n];
    let mut y = vec![0.0; n];
    let mut hy = vec![0.0; n];
    let mut first = fresh;
    let mut iterations = 0;
    let status = 'outer: {
        if !f.is_finite() || g.iter().any(|v| !v.is_finite()) {
            break 'outer BfgsStatus::NumericalFailure;
        }
        if fresh {
            let scale = 1.0 / inf_norm(&g).max(1.0);
            for i in 0..n {
                h[i * n + i] = scale;
            }
        }
        for _ in 0..opts.max_iter {
            iterations += 1;
            if inf_norm(&g) <= opts.grad_tol {
                break 'outer BfgsStatus::Converged;
            }
            neg_matvec(h, &g, &mut d);
            let mut d0: f64 = d.iter().zip(&g).map(|(a, b)| a * b).sum();
            if d0 >= 0.0 {
                // Not a descent direction: reset to steepest descent.
                h.iter_mut().for_each(|v| *v = 0.0);
                let scale = 1.0 / inf_norm(&g).max(1.0);
                for i in 0..n {
                    h[i * n + i] = scale;
                    d[i] = -scale * g[i];
                }
                d0 = d.iter().zip(&g).map(|(a, b)| a * b).sum();
                first = true;
            }
            // The last trial's point, value and gradient (xn, gn): reused when it is the
            // accepted step, which is the usual case.
            let mut last: Option<(f64, f64)> = None;
            let step = strong_wolfe(
                |alpha| {
                    for i in 0..n {
                        xn[i] = x[i] + alpha * d[i];
                    }
                    let fv = fg(&xn, &mut gn);
                    evals += 1;
                    last = Some((alpha, fv));
                    let dv = gn.iter().zip(&d).map(|(a, b)| a * b).sum();
                    (fv, dv)
                },
                f,
                d0,
                1.0,
                WolfeParams::default(),
            );
            if step.alpha == 0.0 {
                break 'outer BfgsStatus::LineSearchFailed;
            }
            let fnew = match last {
                Some((alpha, fv)) if alpha == step.alpha => fv,
                _ => {
                    // The accepted step was an earlier trial: evaluate it again.
                    for i in 0..n {
                        xn[i] = x[i] + step.alpha * d[i];
                    }
                    evals += 1;
                    fg(&xn, &mut gn)
                }
            };
            for i in 0..n {
                s[i] = xn[i] - x[i];
                y[i] = gn[i] - g[i];
            }
            let sy: f64 = s.iter().zip(&y).map(|(a, b)| a * b).sum();
            let f_old = f;
            x.copy_from_slice(&xn);
            g.copy_from_slice(&gn);
            f = fnew;
            if !f.is_finite() {
                break 'outer BfgsStatus::NumericalFailure;
            }
            if sy > 1e-300 {
                let yy: f64 = y.iter().map(|v| v * v).sum();
                if first {
                    // Nocedal–Wright (6.20): scale the initial matrix before the first update.
                    h.iter_mut().for_each(|v| *v = 0.0);
                    for i in 0..n {
                        h[i * n + i] = sy / yy;
                    }
                    first = false;
                }
                inverse_update(h, &s, &y, sy, &mut hy);
            }
            if opts.f_rel_tol > 0.0 && (f_old - f).abs() <= opts.f_rel_tol * f.abs().max(1.0) {
                break 'outer BfgsStatus::Stalled;
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

crate::kernels::wide::dispatch! {
    fn neg_matvec(h: &[f64], g: &[f64], d: &mut [f64]) => neg_matvec_body
}

/// `d = −H g` for the row-major `n×n` matrix `h`.
#[inline(always)]
fn neg_matvec_body(h: &[f64], g: &[f64], d: &mut [f64]) {
    row_sums(h, g, d);
    d.iter_mut().for_each(|v| *v = -*v);
}

/// `out[i] = Σⱼ m[i n + j] v[j]` for the row-major `n×n` matrix `m`, each row's sum taken in
/// column order from −0 as `Iterator::sum` takes it, four rows side by side (four independent
/// chains of additions instead of one): the same result bit for bit as row by row.
#[inline(always)]
fn row_sums(m: &[f64], v: &[f64], out: &mut [f64]) {
    let n = v.len();
    let mut i = 0;
    while i + 4 <= n {
        let rows: [&[f64]; 4] = std::array::from_fn(|r| &m[(i + r) * n..(i + r + 1) * n]);
        let mut acc = [-0.0_f64; 4];
        for (j, &vj) in v.iter().enumerate() {
            for r in 0..4 {
                acc[r] += rows[r][j] * vj;
            }
        }
        out[i..i + 4].copy_from_slice(&acc);
        i += 4;
    }
    for (k, o) in out.iter_mut().enumerate().take(n).skip(i) {
        *o = (0..n).map(|j| m[k * n + j] * v[j]).sum();
    }
}

crate::kernels::wide::dispatch! {
    fn inverse_update(h: &mut [f64], s: &[f64], y: &[f64], sy: f64, hy: &mut [f64]) => inverse_update_body
}

/// The BFGS update of the inverse-Hessian approximation `h` for the step `s` and gradient change
/// `y` (`sy = sᵀy > 0`); `hy` is scratch.
#[inline(always)]
fn inverse_update_body(h: &mut [f64], s: &[f64], y: &[f64], sy: f64, hy: &mut [f64]) {
    let n = s.len();
    row_sums(h, y, hy);
    let yhy: f64 = y.iter().zip(hy.iter()).map(|(a, b)| a * b).sum();
    let rho = 1.0 / sy;
    let c = (1.0 + rho * yhy) * rho;
    for i in 0..n {
        for j in 0..n {
            h[i * n + j] += c * s[i] * s[j] - rho * (hy[i] * s[j] + s[i] * hy[j]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The row sums four rows at a time equal the row-by-row sums bit for bit (signed zeros
    /// included), for sizes around the four-row blocks.
    #[test]
    fn row_sums_match_the_row_by_row_sums_bit_for_bit() {
        for n in [0usize, 1, 3, 4, 5, 8, 9, 36, 39] {
            let m: Vec<f64> = (0..n * n)
                .map(|k| {
                    ((k as f64 * 0.7).sin() * 1e3).round() / 7.0
                        - if k % 5 == 0 { 0.0 } else { 0.3 }
                })
                .collect();
            let mut v: Vec<f64> = (0..n).map(|k| (k as f64 * 1.3).cos() / 3.0).collect();
            if n > 2 {
                v[1] = -0.0;
            }
            let mut out = vec![0.0; n];
            row_sums(&m, &v, &mut out);
            for i in 0..n {
                let want: f64 = (0..n).map(|j| m[i * n + j] * v[j]).sum();
                assert_eq!(out[i].to_bits(), want.to_bits(), "n = {n}, row {i}");
            }
        }
        // A row of −0 products sums to −0, as `sum` does.
        let mut out = [1.0; 4];
        row_sums(&[0.0; 16], &[-0.0; 4], &mut out);
        assert!(out.iter().all(|v| *v == 0.0 && v.is_sign_negative()));
    }

    fn rosenbrock(x: &[f64], g: &mut [f64]) -> f64 {
        let n = x.len();
        let mut f = 0.0;
        g.iter_mut().for_each(|v| *v = 0.0);
        for i in 0..n - 1 {
            let a = x[i + 1] - x[i] * x[i];
            let b = 1.0 - x[i];
            f += 100.0 * a * a + b * b;
            g[i] += -400.0 * a * x[i] - 2.0 * b;
            g[i + 1] += 200.0 * a;
        }
        f
    }

    #[test]
    fn minimises_rosenbrock() {
        for n in [2, 5, 10] {
            let mut x = vec![-1.2; n];
            let mut h = Vec::new();
            let out = bfgs(rosenbrock, &mut x, &mut h, BfgsOptions::default());
            assert_eq!(out.status, BfgsStatus::Converged, "n={n}");
            for v in &x {
                assert!((v - 1.0).abs() < 1e-6, "n={n} x={x:?}");
            }
            assert!(out.evaluations < 2000);
        }
    }

    #[test]
    fn minimises_quadratic_exactly() {
        // f = ½ xᵀAx − bᵀx with A = diag(1..10): optimum x = b/A.
        let fg = |x: &[f64], g: &mut [f64]| {
            let mut f = 0.0;
            for i in 0..x.len() {
                let a = (i + 1) as f64;
                f += 0.5 * a * x[i] * x[i] - x[i];
                g[i] = a * x[i] - 1.0;
            }
            f
        };
        let mut x = vec![0.0; 10];
        let mut h = Vec::new();
        // ‖∇f‖∞ ≤ 1e-12 bounds the error by 1e-12 / λ_min(A) = 1e-12.
        let opts = BfgsOptions {
            grad_tol: 1e-12,
            ..BfgsOptions::default()
        };
        let out = bfgs(fg, &mut x, &mut h, opts);
        assert_eq!(out.status, BfgsStatus::Converged);
        for (i, v) in x.iter().enumerate() {
            assert!((v - 1.0 / (i + 1) as f64).abs() < 1e-9);
        }
    }
}
