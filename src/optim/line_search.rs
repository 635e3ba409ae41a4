//! Strong-Wolfe line search (Nocedal & Wright, Algorithm 3.5/3.6, with cubic interpolation in
//! the zoom phase).

/// Outcome of a line search.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    /// Accepted step length.
    pub alpha: f64,
    /// Objective at the accepted point.
    pub f: f64,
    /// Directional derivative at the accepted point.
    pub dphi: f64,
    /// True when the strong Wolfe conditions hold.
    pub wolfe: bool,
}

/// Strong-Wolfe parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WolfeParams {
    /// Sufficient decrease constant `c₁`.
    pub c1: f64,
    /// Curvature constant `c₂`.
    pub c2: f64,
    /// Largest step tried.
    pub alpha_max: f64,
    /// Evaluations allowed.
    pub max_evals: usize,
}

impl Default for WolfeParams {
    fn default() -> Self {
        WolfeParams {
            c1: 1e-4,
            c2: 0.9,
            alpha_max: 1e10,
            max_evals: 30,
        }
    }
}

fn cubic_min(a: f64, fa: f64, da: f64, b: f64, fb: f64, db: f64) -> Option<f64> {
    let d1 = da + db - 3.0 * (fa - fb) / (a - b);
    let disc = d1 * d1 - da * db;
    if disc < 0.0 {
        return None;
    }
    let d2 = (b - a).signum() * disc.sqrt();
    let x = b - (b - a) * (db + d2 - d1) / (db - da + 2.0 * d2);
    x.is_finite().then_some(x)
}

/// Searches along a direction. `phi(alpha)` returns `(f, dphi)` at `x + alpha·d` (and may cache
/// the gradient there). `f0`, `d0` are the value and slope at `alpha = 0` (`d0 < 0`).
pub fn strong_wolfe(
    mut phi: impl FnMut(f64) -> (f64, f64),
    f0: f64,
    d0: f64,
    alpha0: f64,
    p: WolfeParams,
) -> Step {
    let (mut a_prev, mut f_prev, mut d_prev) = (0.0, f0, d0);
    let mut alpha = alpha0.min(p.alpha_max);
    let mut evals = 0;
    let mut best = Step {
        alpha: 0.0,
        f: f0,
        dphi: d0,
        wolfe: false,
    };
    loop {
        let (f, d) = phi(alpha);
        evals += 1;
        if f.is_finite() && f < best.f {
            best = Step {
                alpha,
                f,
                dphi: d,
                wolfe: false,
            };
        }
        if !f.is_finite() {
            // Back off from a region where the objective is not defined.
            alpha = 0.5 * (a_prev + alpha);
            if evals >= p.max_evals {
                return best;
            }
            continue;
        }
        if f > f0 + p.c1 * alpha * d0 || (evals > 1 && f >= f_prev) {
            return zoom(
                &mut phi,
                f0,
                d0,
                (a_prev, f_prev, d_prev),
                (alpha, f, d),
                p,
                evals,
                best,
            );
        }
        if d.abs() <= -p.c2 * d0 {
            return Step {
                alpha,
                f,
                dphi: d,
                wolfe: true,
            };
        }
        if d >= 0.0 {
            return zoom(
                &mut phi,
                f0,
                d0,
                (alpha, f, d),
                (a_prev, f_prev, d_prev),
                p,
                evals,
                best,
            );
        }
        if evals >= p.max_evals || alpha >= p.alpha_max {
            return best;
        }
        (a_prev, f_prev, d_prev) = (alpha, f, d);
        alpha = (alpha * 4.0).min(p.alpha_max);
    }
}

#[allow(clippy::too_many_arguments)]
fn zoom(
    phi: &mut impl FnMut(f64) -> (f64, f64),
    f0: f64,
    d0: f64,
    lo: (f64, f64, f64),
    hi: (f64, f64, f64),
    p: WolfeParams,
    mut evals: usize,
    mut best: Step,
) -> Step {
    let (mut lo, mut hi) = (lo, hi);
    loop {
        let (a, b) = (lo.0.min(hi.0), lo.0.max(hi.0));
        let width = b - a;
        let mut alpha = cubic_min(lo.0, lo.1, lo.2, hi.0, hi.1, hi.2).unwrap_or(0.5 * (a + b));
        if !(alpha > a + 0.1 * width && alpha < b - 0.1 * width) {
            alpha = 0.5 * (a + b);
        }
        let (f, d) = phi(alpha);
        evals += 1;
        if f.is_finite() && f < best.f {
            best = Step {
                alpha,
                f,
                dphi: d,
                wolfe: false,
            };
        }
        if !f.is_finite() || f > f0 + p.c1 * alpha * d0 || f >= lo.1 {
            hi = (alpha, f, d);
        } else {
            if d.abs() <= -p.c2 * d0 {
                return Step {
                    alpha,
                    f,
                    dphi: d,
                    wolfe: true,
                };
            }
            if d * (hi.0 - lo.0) >= 0.0 {
                hi = lo;
            }
            lo = (alpha, f, d);
        }
        if evals >= p.max_evals || width < 1e-16 * b.max(1.0) {
            return best;
        }
    }
}
