//! From coefficients to geometry: the four fields at the quadrature nodes, the tangent
//! `(1+ε)ζ` (eq. 5), positions by cumulative quadrature (eq. 6), frames (eq. 1), and
//! vector–Jacobian products `Σ_b v_b · ∂x(b)/∂a` computed in one backward pass.

use crate::rod::layout::Field;
use crate::rod::model::{LANES, Model};

/// A shape evaluated at the quadrature nodes, with positions at the mesh boundaries.
#[derive(Clone, Debug, Default)]
pub struct Shape {
    pub(crate) th: Vec<f64>,
    pub(crate) dth: Vec<f64>,
    pub(crate) ph: Vec<f64>,
    pub(crate) dph: Vec<f64>,
    pub(crate) dps: Vec<f64>,
    pub(crate) eps: Vec<f64>,
    pub(crate) sth: Vec<f64>,
    pub(crate) cth: Vec<f64>,
    pub(crate) sph: Vec<f64>,
    pub(crate) cph: Vec<f64>,
    /// Fields (bits in the order of the list in `evaluate_nodes_body`) that hold the constant
    /// an absent field takes (0; 1 for `cos φ`) at every node: they need not be written again.
    constant: u16,
    /// Dimensionless positions `x(b)/L` at the mesh boundaries.
    pub positions: Vec<[f64; 3]>,
}

impl Shape {
    /// `θ` at the quadrature nodes.
    pub fn th(&self) -> &[f64] {
        &self.th
    }
    /// `dθ/dt` at the nodes (zero for a weightless planar rod: its energy is the constant
    /// quadratic form of the model, and nothing else reads the curvature).
    pub fn dth(&self) -> &[f64] {
        &self.dth
    }
    /// `φ` at the nodes (zero for planar rods).
    pub fn ph(&self) -> &[f64] {
        &self.ph
    }
    /// `dφ/dt` at the nodes.
    pub fn dph(&self) -> &[f64] {
        &self.dph
    }
    /// `dψ/dt` at the nodes.
    pub fn dps(&self) -> &[f64] {
        &self.dps
    }
    /// `ε` at the nodes (zero for inextensible rods).
    pub fn eps(&self) -> &[f64] {
        &self.eps
    }
}

impl Model {
    /// Evaluates the shape of coefficients `a` into `shape` (reusing its buffers).
    pub fn evaluate_into(&self, a: &[f64], shape: &mut Shape) {
        evaluate_nodes(self, a, shape);
    }

    /// Evaluates `a[j]` into `shapes[j]` for every `j` that `todo` holds, each bit for bit as
    /// [`Model::evaluate_into`] does; for a rod in the x–z plane, inextensible, the positions'
    /// running sums (a chain of dependent additions per shape, whose latency would bound the
    /// time) of four shapes at a time advance side by side.
    pub fn evaluate_many(
        &self,
        a: &[Vec<f64>],
        shapes: &mut [Shape],
        todo: impl Fn(usize) -> bool,
    ) {
        let mut pending = [0usize; 4];
        let mut np = 0;
        for j in 0..shapes.len() {
            if !todo(j) {
                continue;
            }
            if evaluate_fields(self, &a[j], &mut shapes[j]) {
                pending[np] = j;
                np += 1;
                if np == 4 {
                    let group = shapes.get_disjoint_mut(pending).expect("distinct samples");
                    planar_sums_4(self, group);
                    np = 0;
                }
            }
        }
        for &j in &pending[..np] {
            planar_sums_1(self, [&mut shapes[j]]);
        }
    }

    /// Weights `ωᵢ` such that `|x_b(a) − x_b(a′)| ≤ Σᵢ ωᵢ |aᵢ − a′ᵢ|` at every mesh boundary `b`
    /// (positions in units of L), for a rod whose positions depend on θ alone: in the x–z plane,
    /// inextensible, with a fixed base; `None` for any other rod. A node's tangent
    /// `(sin θ, 0, cos θ)` turns by at most `|Δθ| ≤ Σᵢ |Δaᵢ| maxₙ |eᵢ|` (n over the nodes), and a
    /// position adds the tangents with positive weights that sum to at most `Σₙ wₙ`.
    pub fn position_bound_weights(&self) -> Option<Vec<f64>> {
        let lay = &self.layout;
        if lay.spatial
            || lay.offset(Field::Phi).is_some()
            || lay.offset(Field::Eps).is_some()
            || lay.base_offset().is_some()
            || self.mesh.weights.iter().any(|&w| w < 0.0)
        {
            return None;
        }
        let ot = lay.offset(Field::Theta)?;
        let nb = self.nb();
        let total: f64 = self.mesh.weights.iter().sum();
        let mut w = vec![0.0; self.n()];
        for q in 0..self.nodes() {
            for (wi, e) in w[ot..ot + nb].iter_mut().zip(self.e_at(q)) {
                *wi = f64::max(*wi, total * e.abs());
            }
        }
        Some(w)
    }

    /// Evaluates the shape of coefficients `a`.
    pub fn evaluate(&self, a: &[f64]) -> Shape {
        let mut s = Shape::default();
        self.evaluate_into(a, &mut s);
        s
    }

    /// Dimensionless base position `x(0)/L`: the free unknowns if the base is free, else fixed.
    pub fn base_position(&self, a: &[f64]) -> [f64; 3] {
        let mut b = self.base;
        if let Some(o) = self.layout.base_offset() {
            for (k, &c) in self.layout.components().iter().enumerate() {
                b[c] = a[o + k];
            }
        }
        b
    }

    /// Adds `Σ_b v[b] · ∂x(b)/∂a` to `grad`, for one vector `v[b]` per mesh boundary
    /// (dimensionless). One backward pass over the nodes: a node's tangent enters every
    /// position after it, so it sees the suffix sum of the `v`.
    pub fn add_positions_vjp(&self, shape: &Shape, v: &[[f64; 3]], grad: &mut [f64]) {
        positions_vjp(self, shape, v, grad);
    }

    /// [`Model::add_positions_vjp`]'s loops (compiled twice, see [`crate::kernels::wide`]).
    #[inline(always)]
    fn positions_vjp_body(&self, shape: &Shape, v: &[[f64; 3]], grad: &mut [f64]) {
        let lay = &self.layout;
        let nb = self.nb();
        let ot = 0;
        let op = lay.offset(Field::Phi);
        let oe = lay.offset(Field::Eps);
        let ps = &self.mesh.panel_start;
        let mut suffix = [0.0; 3];
        let total: [f64; 3] = v.iter().fold([0.0; 3], |acc, x| {
            [acc[0] + x[0], acc[1] + x[1], acc[2] + x[2]]
        });
        if let Some(o) = lay.base_offset() {
            for (k, &c) in lay.components().iter().enumerate() {
                grad[o + k] += total[c];
            }
        }
        if !self.e_lanes.is_empty() {
            return self.positions_vjp_lanes(shape, v, grad);
        }
        for j in (0..self.mesh.panels()).rev() {
            let vb = v[j + 1];
            suffix = [suffix[0] + vb[0], suffix[1] + vb[1], suffix[2] + vb[2]];
            if suffix == [0.0; 3] {
                continue;
            }
            // In the angles' frame.
            let suffix = self.to_angles(suffix);
            for q in ps[j]..ps[j + 1] {
                let w = self.mesh.weights[q];
                let one = 1.0 + shape.eps[q];
                let (st, ct, sp, cp) = (shape.sth[q], shape.cth[q], shape.sph[q], shape.cph[q]);
                let e = self.e_at(q);
                // ∂t/∂θ = (1+ε)(cθcφ, cθsφ, −sθ)
                let gth = w * one * (suffix[0] * ct * cp + suffix[1] * ct * sp - suffix[2] * st);
                for i in 0..nb {
                    grad[ot + i] += gth * e[i];
                }
                if let Some(op) = op {
                    // ∂t/∂φ = (1+ε)(−sθsφ, sθcφ, 0)
                    let gph = w * one * (-suffix[0] * st * sp + suffix[1] * st * cp);
                    for i in 0..nb {
                        grad[op + i] += gph * e[i];
                    }
                }
                if let Some(oe) = oe {
                    let gep = w * (suffix[0] * st * cp + suffix[1] * st * sp + suffix[2] * ct);
                    for i in 0..nb {
                        grad[oe + i] += gep * e[i];
                    }
                }
            }
        }
    }

    /// The angle and strain part of [`Model::positions_vjp_body`] for `nb ≤ LANES`: the same
    /// operations in the same order, with each field's sums in fixed-size arrays (registers)
    /// instead of `grad`, so that a node's additions need not wait for the previous node's
    /// stores. Compiled for each set of fields and for three or four vectors of four sums per
    /// field, so that only the sums the layout has are kept.
    #[inline(always)]
    fn positions_vjp_lanes(&self, shape: &Shape, v: &[[f64; 3]], grad: &mut [f64]) {
        let angles = self.layout.offset(Field::Phi).is_some();
        let ext = self.layout.offset(Field::Eps).is_some();
        crate::kernels::wide::by_layout!(
            self.nb() > 12,
            angles,
            ext,
            self.vjp_lanes(shape, v, grad)
        )
    }

    /// [`Model::positions_vjp_lanes`] for `nb ≤ 4 C`, with (`ANGLES`) or without the φ field
    /// and with (`EXT`) or without ε.
    #[inline(always)]
    fn vjp_lanes<const C: usize, const ANGLES: bool, const EXT: bool>(
        &self,
        shape: &Shape,
        v: &[[f64; 3]],
        grad: &mut [f64],
    ) {
        let nb = self.nb();
        let op = self.layout.offset(Field::Phi).filter(|_| ANGLES);
        let oe = self.layout.offset(Field::Eps).filter(|_| EXT);
        let ps = &self.mesh.panel_start;
        let load = |o: Option<usize>, grad: &[f64]| {
            let mut acc = [[0.0; 4]; C];
            if let Some(o) = o {
                for (i, &gi) in grad[o..o + nb].iter().enumerate() {
                    acc[i / 4][i % 4] = gi;
                }
            }
            acc
        };
        let (mut at, mut ap, mut ae) = (load(Some(0), grad), load(op, grad), load(oe, grad));
        #[inline(always)]
        fn add<const C: usize>(acc: &mut [[f64; 4]; C], f: f64, e: &[f64; LANES]) {
            for (c, acc) in acc.iter_mut().enumerate() {
                for (l, a) in acc.iter_mut().enumerate() {
                    *a += f * e[4 * c + l];
                }
            }
        }
        let mut suffix = [0.0; 3];
        for j in (0..self.mesh.panels()).rev() {
            let vb = v[j + 1];
            suffix = [suffix[0] + vb[0], suffix[1] + vb[1], suffix[2] + vb[2]];
            if suffix == [0.0; 3] {
                continue;
            }
            let suffix = self.to_angles(suffix);
            // The panel's nodes as slices: no bounds check per node.
            let r = ps[j]..ps[j + 1];
            let nodes = self.mesh.weights[r.clone()]
                .iter()
                .zip(&shape.eps[r.clone()])
                .zip(&shape.sth[r.clone()])
                .zip(&shape.cth[r.clone()])
                .zip(&shape.sph[r.clone()])
                .zip(&shape.cph[r.clone()])
                .zip(&self.e_lanes[r]);
            for ((((((&w, &eps), &st), &ct), &sp), &cp), e) in nodes {
                let one = 1.0 + eps;
                let gth = w * one * (suffix[0] * ct * cp + suffix[1] * ct * sp - suffix[2] * st);
                add(&mut at, gth, e);
                if ANGLES {
                    let gph = w * one * (-suffix[0] * st * sp + suffix[1] * st * cp);
                    add(&mut ap, gph, e);
                }
                if EXT {
                    let gep = w * (suffix[0] * st * cp + suffix[1] * st * sp + suffix[2] * ct);
                    add(&mut ae, gep, e);
                }
            }
        }
        for (o, acc) in [(Some(0), at), (op, ap), (oe, ae)] {
            if let Some(o) = o {
                for (i, gi) in grad[o..o + nb].iter_mut().enumerate() {
                    *gi = acc[i / 4][i % 4];
                }
            }
        }
    }

    /// Jacobian `∂x(b)/∂a` of the position at boundary `b`: three rows of length `n`.
    pub fn position_jacobian(&self, shape: &Shape, b: usize) -> [Vec<f64>; 3] {
        let n = self.n();
        let mut rows = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let mut v = vec![[0.0; 3]; self.mesh.boundaries.len()];
        for (k, row) in rows.iter_mut().enumerate() {
            v[b] = [0.0; 3];
            v[b][k] = 1.0;
            self.add_positions_vjp(shape, &v, row);
        }
        rows
    }

    /// Euler angles `(φ, θ, ψ)` at dimensionless arc length `t`.
    pub fn angles_at(&self, a: &[f64], t: f64) -> [f64; 3] {
        self.layout.angles_at(a, t)
    }

    /// The cross-section's frame at `t` in the case's axes, `R A(φ, θ, ψ)` (row-major; its
    /// columns are `ξ, η, ζ`).
    pub fn frame_at(&self, a: &[f64], t: f64) -> [[f64; 3]; 3] {
        let [phi, theta, psi] = self.angles_at(a, t);
        self.rotation_to_case(rotation(phi, theta, psi))
    }

    /// Strain `ε` at `t` (zero for inextensible rods).
    pub fn strain_at(&self, a: &[f64], t: f64) -> f64 {
        self.layout
            .field(a, Field::Eps)
            .map_or(0.0, |c| self.layout.basis.eval(c, t))
    }

    /// Position at an arbitrary `t` (dimensionless), by Gauss quadrature of eq. (6) on `[0, t]`.
    pub fn position_at(&self, a: &[f64], t: f64) -> [f64; 3] {
        self.position_at_in(a, &self.evaluate(a), t)
    }

    /// [`Model::position_at`] from `shape`, the evaluated shape of `a`.
    pub fn position_at_in(&self, a: &[f64], shape: &Shape, t: f64) -> [f64; 3] {
        // At a mesh boundary, the position the constraints see there.
        if let Ok(b) = self.mesh.boundaries.binary_search_by(|x| x.total_cmp(&t)) {
            return shape.positions[b];
        }
        let j = self
            .mesh
            .boundaries
            .partition_point(|&b| b <= t)
            .saturating_sub(1);
        let j = j.min(self.mesh.panels() - 1);
        let x0 = shape.positions[j];
        let mut x = if self.frame.is_some() { [0.0; 3] } else { x0 };
        let t0 = self.mesh.boundaries[j];
        let (gx, gw) = crate::rod::quadrature::gauss_legendre_8();
        let h = t - t0;
        for (xi, wi) in gx.iter().zip(gw) {
            let u = t0 + 0.5 * h * (xi + 1.0);
            let [ph, th, _] = self.angles_at(a, u);
            let one = 1.0 + self.strain_at(a, u);
            let w = 0.5 * h * wi * one;
            x[0] += w * th.sin() * ph.cos();
            x[1] += w * th.sin() * ph.sin();
            x[2] += w * th.cos();
        }
        if self.frame.is_some() {
            let d = self.to_case(x);
            return [x0[0] + d[0], x0[1] + d[1], x0[2] + d[2]];
        }
        x
    }
}

crate::kernels::wide::dispatch! {
    fn evaluate_nodes(m: &Model, a: &[f64], shape: &mut Shape) => evaluate_nodes_body
}

crate::kernels::wide::dispatch! {
    fn evaluate_fields(m: &Model, a: &[f64], shape: &mut Shape) -> bool => evaluate_fields_body
}

crate::kernels::wide::dispatch! {
    fn planar_sums_4(m: &Model, shapes: [&mut Shape; 4]) => planar_sums_body
}

crate::kernels::wide::dispatch! {
    fn planar_sums_1(m: &Model, shapes: [&mut Shape; 1]) => planar_sums_body
}

crate::kernels::wide::dispatch! {
    fn positions_vjp(m: &Model, shape: &Shape, v: &[[f64; 3]], grad: &mut [f64]) => Model::positions_vjp_body
}

/// [`Model::evaluate_into`]'s loops (compiled twice, see [`crate::kernels::wide`]).
#[inline(always)]
fn evaluate_nodes_body(m: &Model, a: &[f64], shape: &mut Shape) {
    if evaluate_fields_body(m, a, shape) {
        planar_sums_body(m, [shape]);
    }
}

/// The positions' running sums of a rod in the x–z plane, inextensible, for `N` shapes whose
/// fields [`evaluate_fields_body`] has evaluated, side by side: each shape's additions are the
/// same, in the same order, as one at a time, but the `N` chains of dependent additions
/// advance together instead of one after the other.
#[inline(always)]
fn planar_sums_body<const N: usize>(m: &Model, mut shapes: [&mut Shape; N]) {
    let g = m.mesh.gauss();
    let mut x: [[f64; 3]; N] = std::array::from_fn(|s| shapes[s].positions[0]);
    let mut out: [Vec<[f64; 3]>; N] =
        std::array::from_fn(|s| std::mem::take(&mut shapes[s].positions));
    {
        let st: [&[f64]; N] = std::array::from_fn(|s| &shapes[s].sth[..]);
        let ct: [&[f64]; N] = std::array::from_fn(|s| &shapes[s].cth[..]);
        for (p, w) in m.mesh.weights.chunks_exact(g).enumerate() {
            let nodes = p * g..(p + 1) * g;
            for (q, &w) in nodes.zip(w) {
                for s in 0..N {
                    x[s][0] += w * st[s][q];
                    x[s][2] += w * ct[s][q];
                }
            }
            for s in 0..N {
                out[s][p + 1] = x[s];
            }
        }
    }
    for (shape, pos) in shapes.iter_mut().zip(out) {
        shape.positions = pos;
    }
}

/// [`evaluate_nodes_body`] but the running sums of a rod in the x–z plane, inextensible: for
/// such a rod it leaves them out (positions sized, the base set) and returns true.
#[inline(always)]
fn evaluate_fields_body(m: &Model, a: &[f64], shape: &mut Shape) -> bool {
    let nn = m.nodes();
    let lay = &m.layout;
    let at = lay.field(a, Field::Theta).expect("theta is always present");
    let ap = lay.field(a, Field::Phi);
    let aps = lay.field(a, Field::Psi);
    let ae = lay.field(a, Field::Eps);
    let curvature = m.energy_roots.is_empty();
    // Fields written below only need the right length; the others are zero (cos φ: one),
    // written only when they do not hold that already.
    let mut constant = shape.constant;
    for (bit, (v, present, fill)) in [
        (&mut shape.th, true, 0.0),
        (&mut shape.dth, curvature, 0.0),
        (&mut shape.sth, true, 0.0),
        (&mut shape.cth, true, 0.0),
        (&mut shape.ph, ap.is_some(), 0.0),
        (&mut shape.dph, ap.is_some(), 0.0),
        (&mut shape.sph, ap.is_some(), 0.0),
        (&mut shape.cph, ap.is_some(), 1.0),
        (&mut shape.dps, aps.is_some(), 0.0),
        (&mut shape.eps, ae.is_some(), 0.0),
    ]
    .into_iter()
    .enumerate()
    {
        let mask = 1u16 << bit;
        if present {
            v.resize(nn, 0.0);
            constant &= !mask;
        } else if constant & mask == 0 || v.len() != nn {
            v.clear();
            v.resize(nn, fill);
            constant |= mask;
        }
    }
    shape.constant = constant;
    // Each field at every node: `Σᵢ aᵢ eᵢ(t_q)`, one scaled basis row at a time (a function
    // forced inline, so that the wide copy of this body holds the wide loop).
    #[inline(always)]
    fn rows(nn: usize, c: &[f64], m: &[f64], out: &mut [f64]) {
        let mut rows = c.iter().zip(m.chunks_exact(nn));
        let Some((&c0, row0)) = rows.next() else {
            return out.iter_mut().for_each(|v| *v = 0.0);
        };
        for (v, &r) in out.iter_mut().zip(row0) {
            *v = c0 * r;
        }
        for (&ci, row) in rows {
            for (v, &r) in out.iter_mut().zip(row) {
                *v += ci * r;
            }
        }
    }
    let rows = |c: &[f64], m: &[f64], out: &mut [f64]| rows(nn, c, m, out);
    rows(at, &m.e_rows, &mut shape.th);
    if curvature {
        rows(at, &m.de_rows, &mut shape.dth);
    }
    crate::kernels::trig::sin_cos_slice(&shape.th, &mut shape.sth, &mut shape.cth);
    if let Some(ap) = ap {
        rows(ap, &m.e_rows, &mut shape.ph);
        rows(ap, &m.de_rows, &mut shape.dph);
        crate::kernels::trig::sin_cos_slice(&shape.ph, &mut shape.sph, &mut shape.cph);
    }
    if let Some(aps) = aps {
        rows(aps, &m.de_rows, &mut shape.dps);
    }
    if let Some(ae) = ae {
        rows(ae, &m.e_rows, &mut shape.eps);
    }
    let base = m.base_position(a);
    // Cumulative sums, one panel at a time (every panel has `g` nodes).
    let g = m.mesh.gauss();
    shape.positions.resize(m.mesh.panels() + 1, [0.0; 3]);
    shape.positions[0] = base;
    if ap.is_none() && ae.is_none() {
        // In the x–z plane, inextensible: the same sums without the zero terms
        // ([`planar_sums_body`]).
        return true;
    }
    // With an angles' frame R the sums run in that frame from zero and are turned after.
    let mut x = if m.frame.is_some() { [0.0; 3] } else { base };
    let out = shape.positions[1..].iter_mut();
    let w = m.mesh.weights.chunks_exact(g);
    let (st, ct) = (shape.sth.chunks_exact(g), shape.cth.chunks_exact(g));
    let (sp, cp) = (shape.sph.chunks_exact(g), shape.cph.chunks_exact(g));
    let eps = shape.eps.chunks_exact(g);
    for (((((p, w), st), ct), (sp, cp)), eps) in out.zip(w).zip(st).zip(ct).zip(sp.zip(cp)).zip(eps)
    {
        for q in 0..g {
            let w = w[q] * (1.0 + eps[q]);
            x[0] += w * st[q] * cp[q];
            x[1] += w * st[q] * sp[q];
            x[2] += w * ct[q];
        }
        *p = x;
    }
    if m.frame.is_some() {
        for p in &mut shape.positions[1..] {
            let d = m.to_case(*p);
            *p = [base[0] + d[0], base[1] + d[1], base[2] + d[2]];
        }
    }
    false
}

/// `a × b`.
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Whether `r` is exactly the identity.
pub(crate) fn is_identity(r: &[[f64; 3]; 3]) -> bool {
    (0..3).all(|i| (0..3).all(|j| r[i][j] == f64::from(u8::from(i == j))))
}

/// `Rᵀ m`: rotation `m` of the case's axes written in frame `r` (row-major); `None` is the
/// identity, which leaves `m` as it is.
pub fn in_frame(r: Option<&[[f64; 3]; 3]>, m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    match r {
        None => m,
        Some(r) => std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..3).map(|k| r[k][i] * m[k][j]).sum())
        }),
    }
}

/// Whether `r` (row-major) is a proper rotation: orthonormal columns to `tol` and determinant
/// positive (false for any non-finite entry).
pub fn is_rotation(r: [[f64; 3]; 3], tol: f64) -> bool {
    let ortho = (0..3).all(|i| {
        (0..3).all(|j| {
            let d: f64 = (0..3).map(|k| r[k][i] * r[k][j]).sum();
            (d - f64::from(u8::from(i == j))).abs() < tol
        })
    });
    let col = |j: usize| [r[0][j], r[1][j], r[2][j]];
    let det: f64 = (0..3).map(|k| cross(col(0), col(1))[k] * col(2)[k]).sum();
    ortho && det > 0.0
}

/// Euler angles `(φ, θ, ψ)` of the rotation `m` (row-major) with `θ ∈ [0, π]`, `φ, ψ ∈ (−π, π]`
/// (at the poles, where only `φ ± ψ` is defined, `φ = 0`).
pub fn angles_of(m: [[f64; 3]; 3]) -> [f64; 3] {
    let theta = m[2][2].clamp(-1.0, 1.0).acos();
    if theta.sin() > 1e-12 {
        [m[1][2].atan2(m[0][2]), theta, m[2][1].atan2(-m[2][0])]
    } else if m[2][2] > 0.0 {
        // θ = 0: A = Rz(φ + ψ).
        [0.0, theta, m[1][0].atan2(m[0][0])]
    } else {
        // θ = π: A = Rz(φ) diag(−1, 1, −1) Rz(ψ) depends on φ − ψ only.
        [0.0, theta, -(-m[0][1]).atan2(-m[0][0])]
    }
}

/// The rotation matrix `A(φ, θ, ψ) = Rz(φ) Ry(θ) Rz(ψ)` of eq. (1), row-major; its columns are
/// `ξ, η, ζ`.
pub fn rotation(phi: f64, theta: f64, psi: f64) -> [[f64; 3]; 3] {
    let (sf, cf) = phi.sin_cos();
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = psi.sin_cos();
    [
        [ct * cf * cp - sf * sp, -ct * cf * sp - sf * cp, st * cf],
        [ct * sf * cp + cf * sp, -ct * sf * sp + cf * cp, st * sf],
        [-st * cp, st * sp, ct],
    ]
}
