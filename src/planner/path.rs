//! Deformation paths in coefficient space (paper §7.1, eq. 18):
//! `a(c, k) = (1 − k) a0 + k a1 + Σᵢ₌₁..m cᵢ kⁱ (1 − k)`, `k ∈ [0, 1]`.
//!
//! Fixed conditions that are linear in the coefficients (e.g. `θ(0, k) = 0`) hold at both ends,
//! so along the whole path they reduce to `C cᵢ = 0`. The path stores an orthonormal basis `N`
//! of that null space and takes `cᵢ = N zᵢ`: the unknowns `z` satisfy the conditions exactly,
//! with no multipliers and no drift.

use crate::rod::model::LANES;

/// A deformation path between two shapes, parameterised by `z` (`m` blocks of `r` numbers).
#[derive(Clone, Debug)]
pub struct DeformationPath {
    /// Initial shape `a(c, 0)`.
    pub a0: Vec<f64>,
    /// Goal shape `a(c, 1)`.
    pub a1: Vec<f64>,
    /// Number of path terms `m` (paper: 3).
    pub terms: usize,
    /// Orthonormal basis of the admissible directions, `r` columns of length `n`.
    pub basis: Vec<Vec<f64>>,
    /// The columns padded with zeros to [`LANES`] (empty when `n > LANES`), so that
    /// [`DeformationPath::shape_at`] keeps its sums in registers.
    lanes: Vec<[f64; LANES]>,
}

impl DeformationPath {
    /// A path with admissible directions orthogonal to every row of `linear_rows`
    /// (all directions when there are none).
    pub fn new(a0: Vec<f64>, a1: Vec<f64>, terms: usize, linear_rows: &[Vec<f64>]) -> Self {
        let n = a0.len();
        let basis: Vec<Vec<f64>> = if linear_rows.is_empty() {
            (0..n)
                .map(|j| (0..n).map(|i| f64::from(u8::from(i == j))).collect())
                .collect()
        } else {
            let c = nalgebra::DMatrix::from_fn(linear_rows.len(), n, |r, j| linear_rows[r][j]);
            let ns = crate::optim::second_order::null_space(&c);
            (0..ns.ncols())
                .map(|q| ns.column(q).iter().copied().collect())
                .collect()
        };
        let lanes = crate::rod::model::padded(basis.iter().map(Vec::as_slice), n);
        DeformationPath {
            a0,
            a1,
            terms,
            basis,
            lanes,
        }
    }

    /// Number of coefficients per shape.
    pub fn n(&self) -> usize {
        self.a0.len()
    }

    /// Number of unknowns `m · r`.
    pub fn n_vars(&self) -> usize {
        self.terms * self.basis.len()
    }

    /// The unknowns of path `z` (`terms` blocks `zᵢ`) with `to` terms: the blocks of the new
    /// terms zero, so that the path, with the same basis, is the same (`to ≥ terms`).
    pub fn lift(z: &[f64], terms: usize, to: usize) -> Vec<f64> {
        let mut lifted = z.to_vec();
        lifted.resize(z.len() / terms * to, 0.0);
        lifted
    }

    /// Weight `kⁱ (1 − k)` of term `i` (from 1).
    pub fn weight(i: usize, k: f64) -> f64 {
        k.powi(i as i32) * (1.0 - k)
    }

    /// The path vectors `cᵢ = N zᵢ` in coefficient space.
    pub fn c_vectors(&self, z: &[f64]) -> Vec<Vec<f64>> {
        let r = self.basis.len();
        (0..self.terms)
            .map(|i| {
                let mut c = vec![0.0; self.n()];
                for (q, col) in self.basis.iter().enumerate() {
                    let zq = z[i * r + q];
                    if zq != 0.0 {
                        for (cj, bj) in c.iter_mut().zip(col) {
                            *cj += zq * bj;
                        }
                    }
                }
                c
            })
            .collect()
    }

    /// Writes `a(z, k)` into `out`.
    pub fn shape_at(&self, z: &[f64], k: f64, out: &mut [f64]) {
        shape_at(self, z, k, out);
    }

    /// [`DeformationPath::shape_at`]'s loops (compiled twice, see [`crate::kernels::wide`]).
    #[inline(always)]
    fn shape_at_body(&self, z: &[f64], k: f64, out: &mut [f64]) {
        if self.lanes.is_empty() {
            return self.sum_terms(&self.basis, z, k, out);
        }
        // The same operations in the same order, the sums in a fixed-size array (registers).
        let mut acc = [0.0; LANES];
        self.sum_terms(&self.lanes, z, k, &mut acc);
        out.copy_from_slice(&acc[..out.len()]);
    }

    /// `out = (1 − k) a0 + k a1 + Σᵢ kⁱ(1 − k) Σ_q z_iq col_q` over the basis columns `cols`.
    #[inline(always)]
    fn sum_terms<C: AsRef<[f64]>>(&self, cols: &[C], z: &[f64], k: f64, out: &mut [f64]) {
        for ((o, &x0), &x1) in out.iter_mut().zip(&self.a0).zip(&self.a1) {
            *o = (1.0 - k) * x0 + k * x1;
        }
        let r = cols.len();
        for i in 0..self.terms {
            let w = Self::weight(i + 1, k);
            for (q, col) in cols.iter().enumerate() {
                let zq = w * z[i * r + q];
                if zq != 0.0 {
                    for (o, bj) in out.iter_mut().zip(col.as_ref()) {
                        *o += zq * bj;
                    }
                }
            }
        }
    }

    /// Adds the chain rule `∂a(z, k)/∂z ᵀ · grad_a` to `grad_z`.
    pub fn add_chain(&self, grad_a: &[f64], k: f64, grad_z: &mut [f64]) {
        let r = self.basis.len();
        // The projections, on the stack for up to 32 unknowns per path term.
        let mut stack = [0.0; 32];
        let mut heap = Vec::new();
        let proj: &mut [f64] = if r <= stack.len() {
            &mut stack[..r]
        } else {
            heap.resize(r, 0.0);
            &mut heap
        };
        self.project(grad_a, proj);
        self.add_projected(proj, k, grad_z);
    }

    /// The projections `Nᵀ grad_a` of a gradient in coefficient space on the admissible
    /// directions (`r` numbers): the first half of [`DeformationPath::add_chain`], which may run
    /// on another thread than the second.
    pub fn project(&self, grad_a: &[f64], proj: &mut [f64]) {
        for (p, col) in proj.iter_mut().zip(&self.basis) {
            *p = crate::rod::basis::dot(col, grad_a);
        }
    }

    /// Adds the chain rule at `k` for projections `proj` ([`DeformationPath::project`]) to
    /// `grad_z`.
    pub fn add_projected(&self, proj: &[f64], k: f64, grad_z: &mut [f64]) {
        let r = self.basis.len();
        for i in 0..self.terms {
            let w = Self::weight(i + 1, k);
            for q in 0..r {
                grad_z[i * r + q] += w * proj[q];
            }
        }
    }

    /// Adds `scale · ∂a/∂zᵀ · H · ∂a/∂z` at `k` to `h_z` (row-major `n_vars²`), for a row-major
    /// `n×n` matrix `h_a` in coefficient space.
    pub fn add_chain_hessian(&self, h_a: &[f64], k: f64, scale: f64, h_z: &mut [f64]) {
        let r = self.basis.len();
        let mut m = vec![0.0; r * r];
        self.project_hessian(h_a, &mut m);
        self.add_projected_hessian(&m, k, scale, h_z);
    }

    /// The projection `M = Nᵀ H N` (row-major `r×r`) of a row-major `n×n` matrix `h_a` in
    /// coefficient space on the admissible directions: the first half of
    /// [`DeformationPath::add_chain_hessian`], which may run on another thread than the second.
    pub fn project_hessian(&self, h_a: &[f64], m: &mut [f64]) {
        let n = self.n();
        let r = self.basis.len();
        let mut hn = vec![0.0; n * r];
        for (q, col) in self.basis.iter().enumerate() {
            for a in 0..n {
                hn[a * r + q] = crate::rod::basis::dot(&h_a[a * n..(a + 1) * n], col);
            }
        }
        for (p, col) in self.basis.iter().enumerate() {
            for q in 0..r {
                m[p * r + q] = (0..n).map(|a| col[a] * hn[a * r + q]).sum();
            }
        }
    }

    /// Adds the chain rule at `k` for a projected matrix `m` ([`DeformationPath::project_hessian`]),
    /// times `scale`, to `h_z`.
    pub fn add_projected_hessian(&self, m: &[f64], k: f64, scale: f64, h_z: &mut [f64]) {
        let r = self.basis.len();
        let nv = self.n_vars();
        for i in 0..self.terms {
            let wi = scale * Self::weight(i + 1, k);
            for i2 in 0..self.terms {
                let w = wi * Self::weight(i2 + 1, k);
                for p in 0..r {
                    let row = &mut h_z[(i * r + p) * nv + i2 * r..(i * r + p) * nv + i2 * r + r];
                    for (hv, mv) in row.iter_mut().zip(&m[p * r..(p + 1) * r]) {
                        *hv += w * mv;
                    }
                }
            }
        }
    }
}

crate::kernels::wide::dispatch! {
    fn shape_at(p: &DeformationPath, z: &[f64], k: f64, out: &mut [f64]) => DeformationPath::shape_at_body
}
