//! The second-order verdict on a static solution: stable, unstable or marginal.
//!
//! The reduced Hessian `Zᵀ∇²ℒZ` of the multiplier method lives in coefficient space, where the
//! stiffness of a basis function grows with its wavenumber: its largest eigenvalue grows with
//! the basis, and a band relative to it cannot decide near a threshold. The verdict instead
//! solves the generalized eigenproblem `Zᵀ∇²ℒZ v = λ ZᵀMZ v` with `M` the Gram matrix of the
//! fields' perturbations (`∫₀¹ δf² dt` per field, dimensionless base shifts as they are): its
//! smallest eigenvalues approximate the continuum's and converge as the basis grows, in units
//! of the energy unit `Rf/L`.
//!
//! Exact gauge directions are removed first: a constant added to `ψ` (the material frame turned
//! about the tangent everywhere, when nothing fixes it), and, where the tangent lies on the
//! Euler angles' pole (`θ = 0` or `π`) over a stretch, opposite changes of `φ` and `ψ`, which
//! move nothing. Such a pole stretch also hides bending perturbations the angles cannot express,
//! so a shape with one is never called stable.

use crate::optim::second_order::{lagrangian_hessian_and_tangents, null_space};
use crate::rod::layout::Field;
use crate::statics::problem::StaticProblem;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// The verdict.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// Every admissible perturbation raises the energy.
    Stable,
    /// Some admissible perturbation lowers it.
    Unstable,
    /// The smallest eigenvalue is within the resolution of zero, or the shape lies on the
    /// Euler angles' pole over a stretch: the second-order check cannot decide.
    Marginal,
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Verdict::Stable => "stable",
            Verdict::Unstable => "unstable",
            Verdict::Marginal => "marginal (undecided)",
        })
    }
}

/// The verdict with its numbers.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Stability {
    /// Stable, unstable or marginal.
    pub verdict: Verdict,
    /// Smallest generalized eigenvalue (units of `Rf/L`), `None` when the constraints leave no
    /// freedom.
    pub min_eigenvalue: Option<f64>,
    /// Eigenvalues within the resolution of zero.
    pub neutral_modes: usize,
    /// Exact gauge directions removed before judging.
    pub gauge_modes: usize,
    /// The resolution used: eigenvalues within `±resolution` of zero are undecided.
    pub resolution: f64,
}

/// The Gram matrix of the unknowns' perturbations: per field `∫₀¹ eᵢ eⱼ dt` over the model's
/// quadrature; the identity on base-position unknowns.
fn metric(p: &StaticProblem) -> DMatrix<f64> {
    let m = &p.model;
    let (n, nb) = (m.n(), m.nb());
    let mut g = DMatrix::<f64>::zeros(nb, nb);
    for (q, &w) in m.mesh.weights.iter().enumerate() {
        let e = m.e_at(q);
        for i in 0..nb {
            for j in 0..nb {
                g[(i, j)] += w * e[i] * e[j];
            }
        }
    }
    let mut out = DMatrix::<f64>::identity(n, n);
    for f in [Field::Theta, Field::Phi, Field::Psi, Field::Eps] {
        if let Some(o) = m.layout.offset(f) {
            out.view_mut((o, o), (nb, nb)).copy_from(&g);
        }
    }
    out
}

/// The coefficients of the constant function 1 in the basis (least squares on the Gram
/// matrix: exact for bases that hold the constant).
fn constant_coefficients(p: &StaticProblem) -> DVector<f64> {
    let m = &p.model;
    let nb = m.nb();
    let mut g = DMatrix::<f64>::zeros(nb, nb);
    let mut b = DVector::<f64>::zeros(nb);
    for (q, &w) in m.mesh.weights.iter().enumerate() {
        let e = m.e_at(q);
        for i in 0..nb {
            b[i] += w * e[i];
            for j in 0..nb {
                g[(i, j)] += w * e[i] * e[j];
            }
        }
    }
    g.svd(true, true)
        .solve(&b, 1e-12)
        .unwrap_or_else(|_| DVector::zeros(nb))
}

/// Judges the static solution `(a, lambda)` of `p`.
pub fn judge(p: &mut StaticProblem, a: &[f64], lambda: &[f64]) -> Stability {
    let (hess, exact, z) = lagrangian_hessian_and_tangents(p, a, lambda, 1e-8);
    let n = a.len();
    let hmax = hess.amax().max(1e-300);
    // Gauge candidates: ψ + const, and φ_i − ψ_i for every basis function (the pole).
    let mut psi_shift = Vec::new();
    let mut pole = Vec::new();
    let lay = p.model.layout;
    if let (Some(op), Some(os)) = (lay.offset(Field::Phi), lay.offset(Field::Psi)) {
        let c = constant_coefficients(p);
        let mut g = DVector::<f64>::zeros(n);
        g.rows_mut(os, c.len()).copy_from(&c);
        psi_shift.push(g);
        for i in 0..lay.nb() {
            let mut g = DVector::<f64>::zeros(n);
            g[op + i] = 1.0;
            g[os + i] = -1.0;
            pole.push(g);
        }
    }
    let in_tangent = |g: &DVector<f64>| {
        let proj = &z * (z.transpose() * g);
        (g - proj).norm() <= 1e-9 * g.norm()
    };
    let is_gauge = |g: &DVector<f64>| (&hess * g).norm() <= 1e-9 * hmax * g.norm() && in_tangent(g);
    let gauges_psi: Vec<&DVector<f64>> = psi_shift.iter().filter(|g| is_gauge(g)).collect();
    let gauges_pole: Vec<&DVector<f64>> = pole.iter().filter(|g| is_gauge(g)).collect();
    let on_pole = !gauges_pole.is_empty();
    // The tangent basis with the gauge span taken out.
    let zg = if z.ncols() == 0 {
        z.clone()
    } else {
        let gs: Vec<DVector<f64>> = gauges_psi
            .iter()
            .chain(&gauges_pole)
            .map(|g| z.transpose() * *g)
            .collect();
        if gs.is_empty() {
            z.clone()
        } else {
            let gmat = DMatrix::from_columns(&gs);
            &z * null_space(&gmat.transpose())
        }
    };
    let gauge_modes = z.ncols() - zg.ncols();
    // Rounding of an analytic Hessian is about 1e-13 of its largest entry; central differences
    // with step 1e-5 leave about 1e-8 of it.
    let (floor, relative) = if exact { (1e-9, 1e-11) } else { (1e-6, 1e-7) };
    if zg.ncols() == 0 {
        return Stability {
            verdict: if on_pole {
                Verdict::Marginal
            } else {
                Verdict::Stable
            },
            min_eigenvalue: None,
            neutral_modes: 0,
            gauge_modes,
            resolution: floor,
        };
    }
    let a_red = zg.transpose() * &hess * &zg;
    let a_red = 0.5 * (&a_red + a_red.transpose());
    let b_red = zg.transpose() * metric(p) * &zg;
    let b_red = 0.5 * (&b_red + b_red.transpose());
    let ev: Vec<f64> = match b_red.clone().cholesky() {
        Some(ch) => {
            let l = ch.l();
            let li = l
                .clone()
                .try_inverse()
                .unwrap_or_else(|| DMatrix::identity(l.nrows(), l.nrows()));
            let c = &li * a_red * li.transpose();
            let c = 0.5 * (&c + c.transpose());
            let mut ev: Vec<f64> = c.symmetric_eigenvalues().iter().copied().collect();
            ev.sort_by(f64::total_cmp);
            ev
        }
        None => {
            let mut ev: Vec<f64> = a_red.symmetric_eigenvalues().iter().copied().collect();
            ev.sort_by(f64::total_cmp);
            ev
        }
    };
    let largest = ev.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let resolution = floor.max(relative * largest);
    let lo = ev[0];
    let neutral_modes = ev.iter().filter(|v| v.abs() <= resolution).count();
    let verdict = if lo < -resolution {
        Verdict::Unstable
    } else if lo > resolution && !on_pole {
        Verdict::Stable
    } else {
        Verdict::Marginal
    };
    Stability {
        verdict,
        min_eigenvalue: Some(lo),
        neutral_modes,
        gauge_modes,
        resolution,
    }
}
