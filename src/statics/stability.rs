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
//!
//! A symmetry of the problem is removed too: when a weightless 3D rod, loaded by nothing but its
//! constraints, is held only at points on one line (positions on it, clamps whose tangent lies
//! along it) and touches nothing but itself, turning the whole rod about that line — the material
//! frame turned back about the tangent so that every clamped frame is unchanged — is a family of
//! equilibria of equal energy. Its direction is neutral in the continuum, and the Ritz fields
//! hold it only up to their resolution, so its eigenvalue is rounding of either sign: it is
//! taken out, and the shape is judged on the rest (see `rotation_symmetry` in this file).
//! Angles measured from the case's axes with a clamp on their pole do not hold this symmetry
//! (the clamp's rows on `φ` and `ψ` act as a hidden support), and there nothing is removed.

use crate::optim::second_order::{lagrangian_hessian_and_tangents, null_space};
use crate::rod::layout::Field;
use crate::rod::model::Model;
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

/// The basis's Gram matrix `∫₀¹ eᵢ eⱼ dt` over the model's quadrature.
fn gram(m: &Model) -> DMatrix<f64> {
    let nb = m.nb();
    let mut g = DMatrix::<f64>::zeros(nb, nb);
    for (q, &w) in m.mesh.weights.iter().enumerate() {
        let e = m.e_at(q);
        for i in 0..nb {
            for j in 0..nb {
                g[(i, j)] += w * e[i] * e[j];
            }
        }
    }
    g
}

/// The Gram matrix of the unknowns' perturbations: per field the basis's `g` ([`gram`]); the
/// identity on base-position unknowns.
fn metric(p: &StaticProblem, g: &DMatrix<f64>) -> DMatrix<f64> {
    let m = &p.model;
    let (n, nb) = (m.n(), m.nb());
    let mut out = DMatrix::<f64>::identity(n, n);
    for f in [Field::Theta, Field::Phi, Field::Psi, Field::Eps] {
        if let Some(o) = m.layout.offset(f) {
            out.view_mut((o, o), (nb, nb)).copy_from(g);
        }
    }
    out
}

/// The coefficients of the constant function 1 in the basis (least squares on the Gram
/// matrix `g`: exact for bases that hold the constant).
fn constant_coefficients(p: &StaticProblem, g: &DMatrix<f64>) -> DVector<f64> {
    let m = &p.model;
    let nb = m.nb();
    let mut b = DVector::<f64>::zeros(nb);
    for (q, &w) in m.mesh.weights.iter().enumerate() {
        let e = m.e_at(q);
        for i in 0..nb {
            b[i] += w * e[i];
        }
    }
    g.clone()
        .svd(true, true)
        .solve(&b, 1e-12)
        .unwrap_or_else(|_| DVector::zeros(nb))
}

/// The axis of a rotation symmetry of `p` at its solution `a`: a point on it and its unit
/// direction, in the case's axes (dimensionless).
///
/// The problem must be 3D and weightless with no point loads, and every constraint must be a
/// position on the line through `x(0)` along the tangent `ζ(0)`, an orientation where the
/// tangent lies along that line, or self-contact. Obstacles, relative positions and rows on the
/// coefficients break the symmetry. Points and tangents are judged on the solved shape, to
/// `1e-7`.
fn symmetry_axis(p: &StaticProblem, a: &[f64]) -> Option<([f64; 3], [f64; 3])> {
    use crate::constraints::Constraint;
    use crate::rod::material::Profile;
    let m = &p.model;
    let weightless = match m.rod.weight {
        Profile::Constant(w) => w == 0.0,
        Profile::Linear { start, end } => start == 0.0 && end == 0.0,
    };
    if !m.layout.spatial || !weightless || !m.loads.is_empty() {
        return None;
    }
    let tangent = |t: f64| {
        let f = m.frame_at(a, t);
        [f[0][2], f[1][2], f[2][2]]
    };
    let shape = m.evaluate(a);
    let origin = shape.positions[0];
    let u = tangent(0.0);
    let tol = 1e-7;
    let on_axis = |x: [f64; 3]| {
        let d = [x[0] - origin[0], x[1] - origin[1], x[2] - origin[2]];
        crate::rod::kinematics::cross(d, u)
            .iter()
            .all(|c| c.abs() <= tol)
    };
    let along = |t: f64| {
        crate::rod::kinematics::cross(tangent(t), u)
            .iter()
            .all(|c| c.abs() <= tol)
    };
    for c in &p.constraints {
        let ok = match c {
            Constraint::Position(k) => on_axis(shape.positions[k.boundary]),
            Constraint::Orientation(k) => along(k.t),
            Constraint::SelfContact(_) => true,
            Constraint::RelativePosition(_) | Constraint::Linear(_) | Constraint::Obstacle(_) => {
                false
            }
        };
        if !ok {
            return None;
        }
    }
    Some((origin, u))
}

/// The coefficient-space direction of the rotation symmetry of `p` at `a` ([`symmetry_axis`]),
/// if it has one: the whole rod turned about the axis `u` and its material frame turned back
/// about the tangent, `δA = [u]× A − A [ẑ]× = [u − ζ]× A`, written as changes of the Euler angles
/// at the quadrature nodes,
///
/// `δθ = u·n`, `δψ = u·m / sin θ − 1`, `δφ = u_z − (u·m) cos θ / sin θ`,
///
/// with `m = (cos φ, sin φ, 0)`, `n = (−sin φ, cos φ, 0)` and `u` in the angles' frame, and
/// projected on the basis in `L²` (Gram matrix `g`). `None` where a node lies on the pole (`sin θ < 1e-6`): there
/// the angles cannot carry the rotation, and the pole's own gauges apply; `None` too for a rod
/// that lies along the axis, which the rotation does not move.
fn rotation_symmetry(p: &StaticProblem, a: &[f64], g: &DMatrix<f64>) -> Option<DVector<f64>> {
    let (_, u) = symmetry_axis(p, a)?;
    let m = &p.model;
    let lay = m.layout;
    let (op, ot) = (lay.offset(Field::Phi)?, lay.offset(Field::Theta)?);
    let os = lay.offset(Field::Psi);
    let u = m.to_angles(u);
    let nb = m.nb();
    let mut rhs = DMatrix::<f64>::zeros(nb, 3);
    let mut size = 0.0;
    for (q, (&t, &w)) in m.mesh.nodes.iter().zip(&m.mesh.weights).enumerate() {
        let [phi, theta, _] = m.angles_at(a, t);
        let (sf, cf) = phi.sin_cos();
        let (st, ct) = theta.sin_cos();
        if st.abs() < 1e-6 {
            return None;
        }
        let um = u[0] * cf + u[1] * sf;
        let d = [u[2] - um * ct / st, -u[0] * sf + u[1] * cf, um / st - 1.0];
        size += w * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        let e = m.e_at(q);
        for i in 0..nb {
            for (k, dk) in d.iter().enumerate() {
                rhs[(i, k)] += w * e[i] * dk;
            }
        }
    }
    // A straight rod turned about its own axis does not move: no direction to remove.
    if size.sqrt() < 1e-8 {
        return None;
    }
    let x = g.clone().svd(true, true).solve(&rhs, 1e-12).ok()?;
    let mut dir = DVector::<f64>::zeros(a.len());
    dir.rows_mut(op, nb).copy_from(&x.column(0));
    dir.rows_mut(ot, nb).copy_from(&x.column(1));
    if let Some(os) = os {
        dir.rows_mut(os, nb).copy_from(&x.column(2));
    }
    (dir.norm() > 0.0).then_some(dir)
}

/// Judges the static solution `(a, lambda)` of `p`.
pub fn judge(p: &mut StaticProblem, a: &[f64], lambda: &[f64]) -> Stability {
    let (hess, exact, z) = lagrangian_hessian_and_tangents(p, a, lambda, 1e-8);
    let basis_gram = gram(&p.model);
    let n = a.len();
    let hmax = hess.amax().max(1e-300);
    // Gauge candidates: ψ + const, and φ_i − ψ_i for every basis function (the pole).
    let mut psi_shift = Vec::new();
    let mut pole = Vec::new();
    let lay = p.model.layout;
    if let (Some(op), Some(os)) = (lay.offset(Field::Phi), lay.offset(Field::Psi)) {
        let c = constant_coefficients(p, &basis_gram);
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
    let symmetry = if on_pole {
        None
    } else {
        // Only where the discrete constraints hold the symmetry too: separate rows on `φ` and
        // `ψ` at a clamp on the pole forbid it (a resolved shape leaves about 1e-5 of the
        // direction outside the tangent space, such a clamp about 0.4).
        rotation_symmetry(p, a, &basis_gram)
            .filter(|g| (g - &z * (z.transpose() * g)).norm() <= 1e-3 * g.norm())
    };
    // The tangent basis with the gauge span taken out.
    let zg = if z.ncols() == 0 {
        z.clone()
    } else {
        let gs: Vec<DVector<f64>> = gauges_psi
            .iter()
            .chain(&gauges_pole)
            .copied()
            .chain(symmetry.as_ref())
            .map(|g| z.transpose() * g)
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
    let b_red = zg.transpose() * metric(p, &basis_gram) * &zg;
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
