//! Second derivatives in coefficient space: the Hessian of the energy of eq. (7)–(13) and the
//! curvature `Σ_b v_b · ∂²x(b)/∂a²` of positions contracted with one vector per mesh boundary.
//!
//! Every term of the energy is a function of six local quantities at a quadrature node,
//! `u = (θ, θ', φ, φ', ψ', ε)`, each linear in the coefficients through the basis values `e(t)`
//! or derivatives `e'(t)`; a position is a cumulative sum of tangents `(1+ε)(sθcφ, sθsφ, cθ)`.
//! The Hessian is therefore `Σ_q Bqᵀ Hq Bq` with a 6×6 local `Hq` per node, assembled here.
//! Together with [`crate::constraints::Adjoint`] this gives the Hessian of a Lagrangian up to
//! the curvature of the obstacle distance functions themselves (treated as locally flat).

use crate::rod::energy::Objective;
use crate::rod::kinematics::Shape;
use crate::rod::layout::Field;
use crate::rod::model::{LANES, Model};

/// Local quantities at a node.
const TH: usize = 0;
const DTH: usize = 1;
const PH: usize = 2;
const DPH: usize = 3;
const DPS: usize = 4;
const EPS: usize = 5;

/// Where each local quantity comes from: `(offset of the field, derivative?)`.
fn sources(model: &Model) -> [Option<(usize, bool)>; 6] {
    let lay = &model.layout;
    let op = lay.offset(Field::Phi);
    let ops = lay.offset(Field::Psi);
    let oe = lay.offset(Field::Eps);
    [
        Some((0, false)),
        Some((0, true)),
        op.map(|o| (o, false)),
        op.map(|o| (o, true)),
        ops.map(|o| (o, true)),
        oe.map(|o| (o, false)),
    ]
}

impl Model {
    /// Adds `Σ_q Bqᵀ Hq Bq` to the row-major `n×n` matrix `h`, where `local(q, hq)` fills the
    /// upper triangle of node `q`'s 6×6 local Hessian (entries of absent fields are ignored).
    #[inline(always)]
    fn assemble_local(&self, h: &mut [f64], mut local: impl FnMut(usize, &mut [[f64; 6]; 6])) {
        let n = self.n();
        let nb = self.nb();
        let src = sources(self);
        let mut hq = [[0.0; 6]; 6];
        for q in 0..self.nodes() {
            hq.iter_mut().for_each(|r| *r = [0.0; 6]);
            local(q, &mut hq);
            let (e, de) = (self.e_at(q), self.de_at(q));
            for al in 0..6 {
                let Some((oa, da)) = src[al] else { continue };
                let va = if da { de } else { e };
                for be in al..6 {
                    let w = hq[al][be];
                    if w == 0.0 {
                        continue;
                    }
                    let Some((ob, db)) = src[be] else { continue };
                    let vb = if db { de } else { e };
                    for i in 0..nb {
                        let wi = w * va[i];
                        let row = &mut h[(oa + i) * n + ob..(oa + i) * n + ob + nb];
                        for (r, v) in row.iter_mut().zip(vb) {
                            *r += wi * v;
                        }
                    }
                    if al != be {
                        for i in 0..nb {
                            let wi = w * vb[i];
                            let row = &mut h[(ob + i) * n + oa..(ob + i) * n + oa + nb];
                            for (r, v) in row.iter_mut().zip(va) {
                                *r += wi * v;
                            }
                        }
                    }
                }
            }
        }
    }

    /// Adds `Σ w e(t_q) e(t_q)ᵀ` over `terms = [(q, w)]` (in their order) to the θθ block of `h`
    /// (row-major `n×n`): every entry the same sums, in the same order, as [`Model::assemble_local`]
    /// with only a θθ entry.
    #[inline(always)]
    fn add_theta_outer(&self, terms: &[(usize, f64)], h: &mut [f64]) {
        let (n, nb) = (self.n(), self.nb());
        if self.e_lanes.is_empty() {
            for &(q, w) in terms {
                let e = self.e_at(q);
                for i in 0..nb {
                    let wi = w * e[i];
                    for (r, v) in h[i * n..i * n + nb].iter_mut().zip(e) {
                        *r += wi * v;
                    }
                }
            }
        } else {
            // Row by row, each row's sums in a fixed-size array (registers) across the
            // nodes: every entry still adds the same terms in node order.
            for i in 0..nb {
                let row = &mut h[i * n..i * n + nb];
                let mut acc = [0.0; LANES];
                acc[..nb].copy_from_slice(row);
                for &(q, w) in terms {
                    let e = &self.e_lanes[q];
                    let wi = w * e[i];
                    for (a, &v) in acc.iter_mut().zip(e) {
                        *a += wi * v;
                    }
                }
                row.copy_from_slice(&acc[..nb]);
            }
        }
    }

    /// Gravity's θθ entry of node `q`'s local Hessian: `−wg (1+ε) sθ cφ`, or `−wg (1+ε) u·ζ`
    /// for the vertical `u` of an angles' frame.
    #[inline(always)]
    fn gravity_theta_theta(&self, shape: &Shape, q: usize, up: Option<[f64; 3]>) -> f64 {
        let (st, ct, sp, cp) = (shape.sth[q], shape.cth[q], shape.sph[q], shape.cph[q]);
        let one = 1.0 + shape.eps[q];
        let wg = self.wg[q];
        match up {
            Some(u) => -wg * one * (u[0] * st * cp + u[1] * st * sp + u[2] * ct),
            None => -wg * one * st * cp,
        }
    }

    /// The constant part of the energy Hessian: `Σ_q wf θ'θ' + wt ψ'ψ' + we εε` terms.
    pub(crate) fn assemble_constant_hessian(&self) -> Vec<f64> {
        let n = self.n();
        let mut h = vec![0.0; n * n];
        let spatial = self.layout.spatial;
        self.assemble_local(&mut h, |q, hq| {
            hq[DTH][DTH] = self.wf[q];
            hq[EPS][EPS] = self.we[q];
            if spatial {
                hq[DPS][DPS] = self.wt[q];
            }
        });
        h
    }

    /// Adds `scale · ∇²E` to `h` (row-major `n×n`), where `E` is the objective's energy
    /// (dimensionless) of the evaluated `shape`. For [`Objective::Internal`] the work of point
    /// loads is included (its curvature comes from the positions').
    pub fn add_energy_hessian(
        &self,
        shape: &Shape,
        objective: Objective,
        scale: f64,
        h: &mut [f64],
    ) {
        energy_hessian(self, shape, objective, scale, h);
    }

    /// [`Model::add_energy_hessian`]'s loops (compiled twice, see [`crate::kernels::wide`]).
    #[inline(always)]
    fn energy_hessian_body(&self, shape: &Shape, objective: Objective, scale: f64, h: &mut [f64]) {
        let spatial = self.layout.spatial;
        for (hv, kv) in h.iter_mut().zip(&self.constant_hessian) {
            *hv += scale * kv;
        }
        // A weightless planar rod (the energy is the quadratic form): every local entry below
        // is zero, and the assembly would skip them all.
        let quadratic = !self.energy_roots.is_empty();
        let lay = &self.layout;
        let theta_only = [Field::Phi, Field::Psi, Field::Eps]
            .iter()
            .all(|&f| lay.offset(f).is_none());
        if !quadratic && theta_only {
            // A weighted rod whose only field is θ: gravity's θθ entry is the only local one
            // (the same value, and the same sums in node order, as the assembly below).
            let up = self.up();
            let terms: Vec<(usize, f64)> = (0..self.nodes())
                .map(|q| (q, self.gravity_theta_theta(shape, q, up) * scale))
                .filter(|&(_, w)| w != 0.0)
                .collect();
            self.add_theta_outer(&terms, h);
        } else if !quadratic {
            let up = self.up();
            self.assemble_local(h, |q, hq| {
                let (st, ct, sp, cp) = (shape.sth[q], shape.cth[q], shape.sph[q], shape.cph[q]);
                let (dph, dps, _eps) = (shape.dph[q], shape.dps[q], shape.eps[q]);
                let one = 1.0 + shape.eps[q];
                let (wf, wt, wg) = (self.wf[q], self.wt[q], self.wg[q]);
                let omega = dph * ct + dps;
                // Gravity: wg (1+ε) sθ cφ; wg (1+ε) u·ζ for the vertical `u` of an angles' frame.
                hq[TH][TH] = self.gravity_theta_theta(shape, q, up);
                if let Some(u) = up {
                    hq[TH][PH] = wg * one * (-u[0] * ct * sp + u[1] * ct * cp);
                    hq[PH][PH] = -wg * one * (u[0] * st * cp + u[1] * st * sp);
                    hq[TH][EPS] = wg * (u[0] * ct * cp + u[1] * ct * sp - u[2] * st);
                    hq[PH][EPS] = wg * (-u[0] * st * sp + u[1] * st * cp);
                } else {
                    hq[TH][PH] = -wg * one * ct * sp;
                    hq[PH][PH] = -wg * one * st * cp;
                    hq[TH][EPS] = wg * ct * cp;
                    hq[PH][EPS] = -wg * st * sp;
                }
                // Flexure: ½ wf (θ'² + φ'² sθ²); its θ'θ' part, torsion's ψ'ψ' and extension's εε
                // are constant (in `constant_hessian`).
                if spatial {
                    let c2 = ct * ct - st * st;
                    hq[TH][TH] +=
                        wf * dph * dph * c2 + wt * dph * dph * st * st - wt * omega * dph * ct;
                    hq[TH][DPH] = 2.0 * wf * dph * st * ct - wt * dph * st * ct - wt * omega * st;
                    hq[TH][DPS] = -wt * dph * st;
                    hq[DPH][DPH] = wf * st * st + wt * ct * ct;
                    hq[DPH][DPS] = wt * ct;
                }
                for r in hq.iter_mut() {
                    for v in r.iter_mut() {
                        *v *= scale;
                    }
                }
            });
        }
        if objective == Objective::Internal && !self.loads.is_empty() {
            let mut v = vec![[0.0; 3]; self.mesh.boundaries.len()];
            for (ld, &b) in self.loads.iter().zip(&self.load_boundary) {
                for (vk, fk) in v[b].iter_mut().zip(ld.force) {
                    *vk -= scale * fk;
                }
            }
            self.add_positions_hessian(shape, &v, h);
        }
    }

    /// Adds `Σ_b v[b] · ∂²x(b)/∂a²` to `h` (row-major `n×n`), one vector per mesh boundary.
    pub fn add_positions_hessian(&self, shape: &Shape, v: &[[f64; 3]], h: &mut [f64]) {
        positions_hessian(self, shape, v, h);
    }

    /// [`Model::add_positions_hessian`]'s loops (compiled twice, see [`crate::kernels::wide`]).
    #[inline(always)]
    fn positions_hessian_body(&self, shape: &Shape, v: &[[f64; 3]], h: &mut [f64]) {
        // Suffix sums: a node of panel j enters every position after it.
        let panels = self.mesh.panels();
        let mut suffix = vec![[0.0; 3]; panels];
        let mut acc = [0.0; 3];
        for j in (0..panels).rev() {
            for k in 0..3 {
                acc[k] += v[j + 1][k];
            }
            // In the angles' frame.
            suffix[j] = self.to_angles(acc);
        }
        if suffix.iter().all(|s| *s == [0.0; 3]) {
            return;
        }
        let ps = &self.mesh.panel_start;
        if self.layout.offset(Field::Phi).is_none() && self.layout.offset(Field::Eps).is_none() {
            // Planar and inextensible: only the θθ entry, `−w (S₀ sθ + S₂ cθ) e eᵀ`, the same
            // sums the general assembly does for it, without the absent quantities.
            // The nodes that contribute, in node order, with their weights.
            let mut terms = Vec::with_capacity(self.nodes());
            for (j, s) in suffix.iter().enumerate() {
                if *s == [0.0; 3] {
                    continue;
                }
                for q in ps[j]..ps[j + 1] {
                    let (st, ct) = (shape.sth[q], shape.cth[q]);
                    let f = s[0] * st * shape.cph[q] + s[1] * st * shape.sph[q] + s[2] * ct;
                    let w = -self.mesh.weights[q] * (1.0 + shape.eps[q]) * f;
                    if w != 0.0 {
                        terms.push((q, w));
                    }
                }
            }
            self.add_theta_outer(&terms, h);
            return;
        }
        let mut panel_of = vec![0; self.nodes()];
        for j in 0..panels {
            for p in &mut panel_of[ps[j]..ps[j + 1]] {
                *p = j;
            }
        }
        self.assemble_local(h, |q, hq| {
            let s = suffix[panel_of[q]];
            if s == [0.0; 3] {
                return;
            }
            let w = self.mesh.weights[q];
            let one = 1.0 + shape.eps[q];
            let (st, ct, sp, cp) = (shape.sth[q], shape.cth[q], shape.sph[q], shape.cph[q]);
            // S · t = (1+ε) (S₀ sθcφ + S₁ sθsφ + S₂ cθ).
            let f = s[0] * st * cp + s[1] * st * sp + s[2] * ct;
            let f_th = s[0] * ct * cp + s[1] * ct * sp - s[2] * st;
            let f_ph = -s[0] * st * sp + s[1] * st * cp;
            hq[TH][TH] = -w * one * f;
            hq[TH][PH] = w * one * (-s[0] * ct * sp + s[1] * ct * cp);
            hq[PH][PH] = -w * one * (s[0] * st * cp + s[1] * st * sp);
            hq[TH][EPS] = w * f_th;
            hq[PH][EPS] = w * f_ph;
        });
    }
}

impl Model {
    /// Adds `Σ_b c[b] · J_bᵀ J_b` to `h` (row-major `n×n`), where `J_b = ∂x(b)/∂a` is the 3×n
    /// Jacobian of the position at mesh boundary `b`: the Gauss–Newton Hessian of
    /// `½ Σ_b c[b] |x(b) − x̄_b|²`.
    pub fn add_positions_gauss_newton(&self, shape: &Shape, c: &[f64], h: &mut [f64]) {
        let lay = &self.layout;
        if lay.offset(Field::Phi).is_none()
            && lay.offset(Field::Eps).is_none()
            && lay.base_offset().is_none()
        {
            planar_gauss_newton(self, shape, c, h);
            return;
        }
        let n = self.n();
        let nb = self.nb();
        let op = lay.offset(Field::Phi);
        let oe = lay.offset(Field::Eps);
        let mut jac = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        // Rows in the angles' frame (`Jᵀ J` is the same in any axes): the base's rows are `Rᵀ`.
        if let Some(o) = lay.base_offset() {
            for (k, &comp) in lay.components().iter().enumerate() {
                let mut unit = [0.0; 3];
                unit[comp] = 1.0;
                let local = self.to_angles(unit);
                for (row, v) in jac.iter_mut().zip(local) {
                    row[o + k] = v;
                }
            }
        }
        let ps = &self.mesh.panel_start;
        let add = |jac: &[Vec<f64>; 3], w: f64, h: &mut [f64]| {
            if w == 0.0 {
                return;
            }
            for row in jac {
                add_rank_one(h, w, row);
            }
        };
        add(&jac, c[0], h);
        for j in 0..self.mesh.panels() {
            for q in ps[j]..ps[j + 1] {
                let w = self.mesh.weights[q];
                let one = 1.0 + shape.eps[q];
                let (st, ct, sp, cp) = (shape.sth[q], shape.cth[q], shape.sph[q], shape.cph[q]);
                let e = self.e_at(q);
                let dth = [one * ct * cp, one * ct * sp, -one * st];
                let dph = [-one * st * sp, one * st * cp, 0.0];
                let dep = [st * cp, st * sp, ct];
                for k in 0..3 {
                    for i in 0..nb {
                        jac[k][i] += w * dth[k] * e[i];
                    }
                    if let Some(op) = op {
                        for i in 0..nb {
                            jac[k][op + i] += w * dph[k] * e[i];
                        }
                    }
                    if let Some(oe) = oe {
                        for i in 0..nb {
                            jac[k][oe + i] += w * dep[k] * e[i];
                        }
                    }
                }
            }
            add(&jac, c[j + 1], h);
        }
    }
}

impl Model {
    /// [`Model::add_positions_gauss_newton`] for a planar inextensible rod with a fixed base
    /// (compiled twice, see [`crate::kernels::wide`]): there `sin φ = 0`, `cos φ = 1` and `ε = 0`, so
    /// the Jacobian's y row is zero and its x and z rows gain `w cos θ eᵢ` and `−w sin θ eᵢ` per
    /// node — the general assembly's products, which it computes as `(w · (1 · cos θ · 1)) eᵢ`
    /// and `(w · (−1 · sin θ)) eᵢ`, the same numbers — and the rank-one updates add the x row's
    /// terms, then the z row's, as it does (its zero y row adds nothing).
    #[inline(always)]
    fn planar_gauss_newton_body(&self, shape: &Shape, c: &[f64], h: &mut [f64]) {
        let n = self.n();
        let nb = self.nb();
        let ps = &self.mesh.panel_start;
        // (`n = nb`: a planar inextensible rod with a fixed base has θ's coefficients only.)
        if !self.e_lanes.is_empty() {
            return self.planar_gauss_newton_rows(shape, c, h);
        }
        let mut jx = vec![0.0; n];
        let mut jz = vec![0.0; n];
        // The base's Jacobian is zero: `c[0]` adds nothing.
        for j in 0..self.mesh.panels() {
            for q in ps[j]..ps[j + 1] {
                let w = self.mesh.weights[q];
                let (wx, wz) = (w * shape.cth[q], w * -shape.sth[q]);
                let e = self.e_at(q);
                for ((x, z), ei) in jx[..nb].iter_mut().zip(&mut jz[..nb]).zip(e) {
                    *x += wx * ei;
                    *z += wz * ei;
                }
            }
            let cj = c[j + 1];
            if cj != 0.0 {
                add_rank_one(h, cj, &jx);
                add_rank_one(h, cj, &jz);
            }
        }
    }

    /// [`Model::planar_gauss_newton_body`] with the boundaries' Jacobian rows gathered first,
    /// then added row by row of `h` with each row's sums in a fixed-size array (registers):
    /// every entry adds the same terms in the same order, skipping the same zero weights.
    #[inline(always)]
    fn planar_gauss_newton_rows(&self, shape: &Shape, c: &[f64], h: &mut [f64]) {
        let n = self.n();
        let ps = &self.mesh.panel_start;
        // Per boundary with a weight: the weight, then the x and z rows (zero past `nb`).
        let mut rows: Vec<(f64, [f64; LANES], [f64; LANES])> =
            Vec::with_capacity(self.mesh.panels());
        let (mut jx, mut jz) = ([0.0; LANES], [0.0; LANES]);
        for j in 0..self.mesh.panels() {
            for q in ps[j]..ps[j + 1] {
                let w = self.mesh.weights[q];
                let (wx, wz) = (w * shape.cth[q], w * -shape.sth[q]);
                let e = &self.e_lanes[q];
                for ((x, z), ei) in jx.iter_mut().zip(&mut jz).zip(e) {
                    *x += wx * ei;
                    *z += wz * ei;
                }
            }
            let cj = c[j + 1];
            if cj != 0.0 {
                rows.push((cj, jx, jz));
            }
        }
        for a in 0..n {
            let row = &mut h[a * n..(a + 1) * n];
            let mut acc = [0.0; LANES];
            acc[..n].copy_from_slice(row);
            for (cj, jx, jz) in &rows {
                for g in [jx, jz] {
                    let wa = cj * g[a];
                    if wa != 0.0 {
                        for (v, gb) in acc.iter_mut().zip(g) {
                            *v += wa * gb;
                        }
                    }
                }
            }
            row.copy_from_slice(&acc[..n]);
        }
    }
}

crate::kernels::wide::dispatch! {
    fn planar_gauss_newton(m: &Model, shape: &Shape, c: &[f64], h: &mut [f64]) => Model::planar_gauss_newton_body
}

/// Adds `w · g gᵀ` to the row-major `n×n` matrix `h` (`n = g.len()`); rows where `w gₐ = 0`
/// are skipped.
pub fn add_rank_one(h: &mut [f64], w: f64, g: &[f64]) {
    let n = g.len();
    for (a, &ga) in g.iter().enumerate() {
        let wa = w * ga;
        if wa != 0.0 {
            for (hv, gb) in h[a * n..(a + 1) * n].iter_mut().zip(g) {
                *hv += wa * gb;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::rod::basis::Basis;
    use crate::rod::energy::Objective;
    use crate::rod::layout::Layout;
    use crate::rod::model::{Discretisation, Model, PointLoad};
    use crate::rod::{Profile, Rod};

    fn model(spatial: bool, extensible: bool) -> Model {
        let rod = Rod {
            length: 1.3,
            flexural: Profile::Linear {
                start: 1.0,
                end: 0.6,
            },
            torsional: spatial.then_some(Profile::Constant(0.7)),
            extensional: extensible.then_some(Profile::Constant(40.0)),
            weight: Profile::Constant(0.8),
            radius: 0.01,
        };
        let layout = Layout {
            basis: Basis::new(2),
            spatial,
            extensible,
            free_base: false,
        };
        let loads = vec![PointLoad {
            t: 0.6,
            force: [0.3, -0.2, 0.5],
            reference: [0.0; 3],
        }];
        Model::new(
            rod,
            layout,
            Discretisation {
                panels: 6,
                gauss_points: 3,
            },
            [0.0; 3],
            loads,
            &[],
        )
    }

    /// A 3D, extensible, heavy rod with a free base and a point load (the base at
    /// `[0.1, −0.2, 0.3]`).
    fn free_based() -> Model {
        let mut m = model(true, true);
        m.layout.free_base = true;
        Model::new(
            m.rod.clone(),
            m.layout,
            Discretisation {
                panels: 6,
                gauss_points: 3,
            },
            [0.1, -0.2, 0.3],
            m.loads.clone(),
            &[],
        )
    }

    /// [`free_based`] with its angles measured from a generic frame (so that gravity reads all
    /// three components of the tangent).
    fn framed() -> Model {
        free_based()
            .with_frame(crate::rod::kinematics::rotation(0.4, 1.1, -0.7))
            .expect("a rotation")
    }

    /// The framed model's energy gradient and positions' vector–Jacobian product against
    /// central differences (its Hessians are in the tests below), and its positions: the
    /// unframed model's turned by the frame about the base.
    #[test]
    fn framed_derivatives_match_finite_differences() {
        let m = framed();
        let n = m.n();
        let a = coefficients(n);
        let step = 1e-6;
        let close = |x: f64, y: f64, scale: f64, what: &str| {
            assert!((x - y).abs() < 1e-6 * scale.max(1.0), "{what}: {x} vs {y}");
        };
        for objective in [Objective::Internal, Objective::Potential] {
            let mut sh = m.evaluate(&a);
            let mut g = vec![0.0; n];
            m.objective_and_gradient(&a, objective, &mut sh, &mut g);
            let mut g2 = vec![0.0; n];
            for j in 0..n {
                let mut x = a.clone();
                x[j] += step;
                let fp = m.objective_and_gradient(&x, objective, &mut sh, &mut g2);
                x[j] -= 2.0 * step;
                let fm = m.objective_and_gradient(&x, objective, &mut sh, &mut g2);
                close(
                    g[j],
                    (fp - fm) / (2.0 * step),
                    g[j].abs(),
                    "energy gradient",
                );
            }
        }
        // Positions: v · ∂x/∂a against differences of v · x.
        let nbd = m.mesh.boundaries.len();
        let v: Vec<[f64; 3]> = (0..nbd)
            .map(|b| {
                let t = b as f64;
                [(0.9 * t).sin(), (1.3 * t).cos(), 0.4 - 0.1 * t]
            })
            .collect();
        let dot = |x: &[f64]| -> f64 {
            let p = m.evaluate(x).positions;
            p.iter()
                .zip(&v)
                .map(|(p, v)| p[0] * v[0] + p[1] * v[1] + p[2] * v[2])
                .sum()
        };
        let mut g = vec![0.0; n];
        m.add_positions_vjp(&m.evaluate(&a), &v, &mut g);
        for j in 0..n {
            let mut x = a.clone();
            x[j] += step;
            let fp = dot(&x);
            x[j] -= 2.0 * step;
            let fm = dot(&x);
            close(g[j], (fp - fm) / (2.0 * step), g[j].abs(), "positions' VJP");
        }
        let sh = m.evaluate(&a);
        // The frame turns the shape: the same coefficients without it give the positions
        // turned back.
        let plain = free_based();
        let (p, q) = (plain.evaluate(&a).positions, sh.positions.clone());
        let base = m.base_position(&a);
        for (p, q) in p.iter().zip(&q) {
            let d = m.to_case(std::array::from_fn(|k| p[k] - base[k]));
            for k in 0..3 {
                assert!((base[k] + d[k] - q[k]).abs() < 1e-14, "{p:?} {q:?}");
            }
        }
    }

    fn coefficients(n: usize) -> Vec<f64> {
        (0..n)
            .map(|i| 0.3 * ((i as f64) * 1.7).sin() + 0.1)
            .collect()
    }

    /// Central differences of the analytic gradient.
    fn fd_hessian(n: usize, mut grad: impl FnMut(&[f64], &mut [f64]), a: &[f64]) -> Vec<f64> {
        let step = 1e-6;
        let mut h = vec![0.0; n * n];
        let (mut gp, mut gm) = (vec![0.0; n], vec![0.0; n]);
        let mut x = a.to_vec();
        for j in 0..n {
            x[j] = a[j] + step;
            grad(&x, &mut gp);
            x[j] = a[j] - step;
            grad(&x, &mut gm);
            x[j] = a[j];
            for i in 0..n {
                h[i * n + j] = (gp[i] - gm[i]) / (2.0 * step);
            }
        }
        h
    }

    fn assert_close(h: &[f64], fd: &[f64]) {
        let scale = fd.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
        for (i, (x, y)) in h.iter().zip(fd).enumerate() {
            assert!((x - y).abs() < 1e-6 * scale, "entry {i}: {x} vs {y}");
        }
    }

    #[test]
    fn energy_hessian_matches_finite_differences() {
        let models = [(false, false), (false, true), (true, false), (true, true)]
            .map(|(spatial, extensible)| model(spatial, extensible));
        for m in models.into_iter().chain([framed()]) {
            let n = m.n();
            let a = coefficients(n);
            for objective in [Objective::Internal, Objective::Potential] {
                let mut sh = m.evaluate(&a);
                let mut h = vec![0.0; n * n];
                m.add_energy_hessian(&sh, objective, 1.0, &mut h);
                let fd = fd_hessian(
                    n,
                    |x, g| {
                        m.objective_and_gradient(x, objective, &mut sh, g);
                    },
                    &a,
                );
                assert_close(&h, &fd);
            }
        }
    }

    #[test]
    fn weighted_theta_rod_hessian_is_the_assembly_to_the_bit() {
        // A weighted planar inextensible rod takes its own θθ loop; the general assembly of
        // the same local entry must give the same bits.
        let m = model(false, false);
        assert!(m.energy_roots.is_empty(), "the test rod has weight");
        let n = m.n();
        let sh = m.evaluate(&coefficients(n));
        let scale = 0.7;
        let mut h = vec![0.0; n * n];
        m.add_energy_hessian(&sh, Objective::Potential, scale, &mut h);
        let mut expect = vec![0.0; n * n];
        for (e, k) in expect.iter_mut().zip(&m.constant_hessian) {
            *e += scale * k;
        }
        m.assemble_local(&mut expect, |q, hq| {
            hq[super::TH][super::TH] = -m.wg[q] * (1.0 + sh.eps[q]) * sh.sth[q] * sh.cph[q];
            hq[super::TH][super::TH] *= scale;
        });
        assert!(h.iter().any(|v| *v != 0.0));
        for (i, (x, y)) in h.iter().zip(&expect).enumerate() {
            assert_eq!(x.to_bits(), y.to_bits(), "entry {i}: {x} vs {y}");
        }
    }

    #[test]
    fn planar_gauss_newton_rows_are_the_rank_ones_to_the_bit() {
        // The planar inextensible Gauss–Newton Hessian adds its boundaries' rows in registers;
        // one rank-one update per boundary row and weight (zero weights skipped) gives the
        // same bits.
        let m = model(false, false);
        let n = m.n();
        assert_eq!(n, m.nb());
        let sh = m.evaluate(&coefficients(n));
        let nbd = m.mesh.boundaries.len();
        let c: Vec<f64> = (0..nbd)
            .map(|b| {
                if b % 3 == 2 {
                    0.0
                } else {
                    0.5 + 0.1 * b as f64
                }
            })
            .collect();
        let start: Vec<f64> = (0..n * n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut h = start.clone();
        m.add_positions_gauss_newton(&sh, &c, &mut h);
        let mut expect = start;
        let (mut jx, mut jz) = (vec![0.0; n], vec![0.0; n]);
        let ps = &m.mesh.panel_start;
        for j in 0..m.mesh.panels() {
            for q in ps[j]..ps[j + 1] {
                let w = m.mesh.weights[q];
                for (i, ei) in m.e_at(q).iter().enumerate() {
                    jx[i] += w * sh.cth[q] * ei;
                    jz[i] += w * -sh.sth[q] * ei;
                }
            }
            if c[j + 1] != 0.0 {
                super::add_rank_one(&mut expect, c[j + 1], &jx);
                super::add_rank_one(&mut expect, c[j + 1], &jz);
            }
        }
        for (i, (x, y)) in h.iter().zip(&expect).enumerate() {
            assert_eq!(x.to_bits(), y.to_bits(), "entry {i}: {x} vs {y}");
        }
    }

    #[test]
    fn position_curvature_matches_finite_differences() {
        let models = [(false, true), (true, false), (true, true)]
            .map(|(spatial, extensible)| model(spatial, extensible));
        for m in models.into_iter().chain([framed()]) {
            let n = m.n();
            let a = coefficients(n);
            let nb = m.mesh.boundaries.len();
            let v: Vec<[f64; 3]> = (0..nb)
                .map(|b| {
                    let t = b as f64;
                    [(0.9 * t).sin(), (1.3 * t).cos(), 0.4 - 0.1 * t]
                })
                .collect();
            let sh = m.evaluate(&a);
            let mut h = vec![0.0; n * n];
            m.add_positions_hessian(&sh, &v, &mut h);
            let fd = fd_hessian(
                n,
                |x, g| {
                    g.iter_mut().for_each(|v| *v = 0.0);
                    m.add_positions_vjp(&m.evaluate(x), &v, g);
                },
                &a,
            );
            assert_close(&h, &fd);
        }
    }

    #[test]
    fn positions_gauss_newton_matches_jacobians() {
        // (false, false): the planar inextensible assembly.
        let models = [(false, false), (false, true), (true, true)]
            .map(|(spatial, extensible)| model(spatial, extensible));
        for m in models.into_iter().chain([framed()]) {
            let n = m.n();
            let sh = m.evaluate(&coefficients(n));
            let nbd = m.mesh.boundaries.len();
            let c: Vec<f64> = (0..nbd).map(|b| 0.5 + 0.1 * b as f64).collect();
            let mut h = vec![0.0; n * n];
            m.add_positions_gauss_newton(&sh, &c, &mut h);
            let mut expect = vec![0.0; n * n];
            for (b, &cb) in c.iter().enumerate() {
                let jb = m.position_jacobian(&sh, b);
                for row in &jb {
                    for i in 0..n {
                        for j in 0..n {
                            expect[i * n + j] += cb * row[i] * row[j];
                        }
                    }
                }
            }
            assert_close(&h, &expect);
        }
    }
}

crate::kernels::wide::dispatch! {
    fn positions_hessian(m: &Model, shape: &Shape, v: &[[f64; 3]], h: &mut [f64]) => Model::positions_hessian_body
}

crate::kernels::wide::dispatch! {
    fn energy_hessian(m: &Model, shape: &Shape, objective: Objective, scale: f64, h: &mut [f64]) => Model::energy_hessian_body
}
