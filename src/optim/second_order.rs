//! Second-order check of a KKT point: the Hessian of the Lagrangian (analytic where the problem
//! says its Hessian is exact, else central differences of analytic gradients), reduced to the
//! tangent space of the strongly active constraints.

use super::augmented_lagrangian::jacobian_rows_at;
use super::nlp::{Nlp, Sense};
use nalgebra::DMatrix;

/// The Hessian of the Lagrangian at `(x, lambda)` (symmetrised; analytic where the problem says
/// it is exact, else central differences of analytic gradients), whether it is analytic, and an
/// orthonormal basis `Z` of the null space of the Jacobian of the equality rows and of the
/// inequality rows with `λ > lambda_tol` (`n × 0` when the constraints leave no freedom).
pub fn lagrangian_hessian_and_tangents<P: Nlp>(
    p: &mut P,
    x: &[f64],
    lambda: &[f64],
    lambda_tol: f64,
) -> (DMatrix<f64>, bool, DMatrix<f64>) {
    let (hess, exact, active) = lagrangian_hessian_and_active_rows(p, x, lambda, lambda_tol);
    let z = match active {
        None => DMatrix::identity(p.n(), p.n()),
        Some((_, j)) => null_space(&j),
    };
    (hess, exact, z)
}

/// [`lagrangian_hessian_and_tangents`] with the active rows themselves instead of their null
/// space: the Hessian, whether it is analytic, and (unless no row is active) the indices of the
/// equality rows and of the inequality rows with `λ > lambda_tol`, in order, with their
/// Jacobian (one row each).
#[allow(clippy::type_complexity)]
pub fn lagrangian_hessian_and_active_rows<P: Nlp>(
    p: &mut P,
    x: &[f64],
    lambda: &[f64],
    lambda_tol: f64,
) -> (DMatrix<f64>, bool, Option<(Vec<usize>, DMatrix<f64>)>) {
    let (n, m) = (p.n(), p.m());
    let mut c = vec![0.0; m];
    let mut hess = DMatrix::<f64>::zeros(n, n);
    let mut analytic = vec![0.0; n * n];
    p.values(x, &mut c);
    let exact = p.has_hessian() && p.hessian_is_exact(lambda);
    if exact {
        p.hessian(x, lambda, &vec![0.0; m], &mut analytic);
        hess = DMatrix::from_row_slice(n, n, &analytic);
    } else {
        let step = 1e-5;
        let mut xp = x.to_vec();
        let (mut gp, mut gm) = (vec![0.0; n], vec![0.0; n]);
        for j in 0..n {
            xp[j] = x[j] + step;
            p.values(&xp, &mut c);
            p.gradient(&xp, lambda, &mut gp);
            xp[j] = x[j] - step;
            p.values(&xp, &mut c);
            p.gradient(&xp, lambda, &mut gm);
            xp[j] = x[j];
            for i in 0..n {
                hess[(i, j)] = (gp[i] - gm[i]) / (2.0 * step);
            }
        }
        // Back to x for the constraint rows below.
        p.values(x, &mut c);
    }
    let hess = 0.5 * (&hess + hess.transpose());
    let rows: Vec<usize> = (0..m)
        .filter(|&i| p.sense(i) == Sense::Equal || lambda[i] > lambda_tol)
        .collect();
    let active = (!rows.is_empty()).then(|| {
        let (_, jr) = jacobian_rows_at(p, x, &rows);
        let j = DMatrix::from_fn(rows.len(), n, |r, k| jr[r][k]);
        (rows, j)
    });
    (hess, exact, active)
}

/// Eigenvalues of the reduced Hessian `Zᵀ ∇²ℒ Z` (ascending), where `Z` spans the null space of
/// the Jacobian of the equality rows and of the inequality rows with `λ > lambda_tol`.
/// Empty when the tangent space is trivial.
pub fn reduced_hessian_eigenvalues<P: Nlp>(
    p: &mut P,
    x: &[f64],
    lambda: &[f64],
    lambda_tol: f64,
) -> Vec<f64> {
    let (hess, _, z) = lagrangian_hessian_and_tangents(p, x, lambda, lambda_tol);
    if z.ncols() == 0 {
        return Vec::new();
    }
    let red = z.transpose() * hess * &z;
    let mut ev: Vec<f64> = red.symmetric_eigenvalues().iter().copied().collect();
    ev.sort_by(f64::total_cmp);
    ev
}

/// Orthonormal basis of the null space of `j` (via the SVD of `jᵀj`'s eigenvectors).
pub fn null_space(j: &DMatrix<f64>) -> DMatrix<f64> {
    let n = j.ncols();
    let jtj = j.transpose() * j;
    let eig = jtj.symmetric_eigen();
    let smax = eig.eigenvalues.amax().max(1e-300);
    let cols: Vec<usize> = (0..n)
        .filter(|&i| eig.eigenvalues[i] <= 1e-12 * smax)
        .collect();
    DMatrix::from_fn(n, cols.len(), |r, k| eig.eigenvectors[(r, cols[k])])
}
