//! Potential energy of eq. (7)–(11) and the work of point loads (eq. 12–13), with analytic
//! gradients. All values are dimensionless (units of `Rf/L`).
//!
//! - flexure  `½∫ Rf κ²`, `κ² = θ'² + φ'² sin²θ` (eq. 3, 8)
//! - torsion  `½∫ Rt ω²`, `ω = φ' cosθ + ψ'` (eq. 4, 9)
//! - extension `½∫ Re ε²` (eq. 10)
//! - gravity  `∫ D x ds` (eq. 11), evaluated by parts as `x(0)·∫D + ∫ (1+ε) ζₓ(t) ∫ₜᴸ D`.

use crate::rod::kinematics::Shape;
use crate::rod::layout::Field;
use crate::rod::model::Model;
use serde::Serialize;

/// The energy terms of one shape.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct EnergyTerms {
    /// Flexural energy `U_flex`.
    pub flexural: f64,
    /// Torsional energy `U_tor`.
    pub torsional: f64,
    /// Extensional energy `U_ext`.
    pub extensional: f64,
    /// Gravitational energy `U_grav`.
    pub gravitational: f64,
    /// Work `ΣW` done by point loads.
    pub work: f64,
}

impl EnergyTerms {
    /// The energy `objective` names: `V` or `U`.
    pub fn value(&self, objective: Objective) -> f64 {
        match objective {
            Objective::Internal => self.internal(),
            Objective::Potential => self.potential(),
        }
    }

    /// Potential energy `U` (eq. 7).
    pub fn potential(&self) -> f64 {
        self.flexural + self.torsional + self.extensional + self.gravitational
    }

    /// Internal energy `V = U − ΣW` (eq. 13): what statics minimises.
    pub fn internal(&self) -> f64 {
        self.potential() - self.work
    }

    /// The terms multiplied by `unit` (to convert to the case's units).
    pub fn scaled(&self, unit: f64) -> EnergyTerms {
        EnergyTerms {
            flexural: self.flexural * unit,
            torsional: self.torsional * unit,
            extensional: self.extensional * unit,
            gravitational: self.gravitational * unit,
            work: self.work * unit,
        }
    }
}

/// Which energy terms enter an objective.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Objective {
    /// `V = U − ΣW` (statics).
    Internal,
    /// `U` alone (path planning).
    Potential,
}

impl Model {
    /// Energy terms of an evaluated shape, and, if `grad` is given, the gradient of the
    /// objective (`V` or `U`) added to it.
    pub fn energy(
        &self,
        a: &[f64],
        shape: &Shape,
        objective: Objective,
        grad: Option<&mut [f64]>,
    ) -> EnergyTerms {
        energy_terms(self, a, shape, objective, grad)
    }

    /// [`Model::energy`]'s loops (compiled twice, see [`crate::kernels::wide`]).
    #[inline(always)]
    fn energy_body(
        &self,
        a: &[f64],
        shape: &Shape,
        objective: Objective,
        grad: Option<&mut [f64]>,
    ) -> EnergyTerms {
        let lay = &self.layout;
        let oe = lay.offset(Field::Eps);
        let spatial = lay.spatial;
        let mut t = EnergyTerms::default();
        let mut grad = grad;
        let quadratic = !self.energy_roots.is_empty();
        if quadratic {
            self.quadratic_terms(a, &mut t, grad.as_deref_mut());
        }
        let up = self.up();
        // The node sums below, unless the quadratic form has already given them.
        let nodes = if quadratic { 0 } else { self.nodes() };
        if nodes > 0 {
            if self.de_lanes.is_empty() {
                // More than `LANES` basis functions: the factors first, then their sums.
                let mut factors = Vec::with_capacity(if grad.is_some() { nodes } else { 0 });
                for q in 0..nodes {
                    let (terms, f) = self.node_values(shape, q, spatial, up);
                    Self::add_terms(&mut t, &terms, spatial, oe.is_some());
                    if grad.is_some() {
                        factors.push(f);
                    }
                }
                if let Some(g) = grad.as_deref_mut() {
                    self.add_node_sums(&factors, g);
                }
            } else if !spatial && oe.is_none() && up.is_none() {
                // A planar, inextensible rod in the case's axes: without the zero terms.
                self.planar_node_terms(shape, &mut t, grad.as_deref_mut());
            } else {
                let (g, t) = (grad.as_deref_mut(), &mut t);
                crate::kernels::wide::by_layout!(
                    self.nb() > 12,
                    spatial,
                    oe.is_some(),
                    self.fused_node_sums(shape, t, g)
                )
            }
        }
        let base = self.base_position(a);
        t.gravitational += self.gravity_total * base[0];
        if let Some(g) = grad.as_deref_mut()
            && let Some(o) = lay.base_offset()
        {
            g[o] += self.gravity_total;
        }
        if !self.loads.is_empty() {
            let mut v = vec![[0.0; 3]; self.mesh.boundaries.len()];
            for (ld, &b) in self.loads.iter().zip(&self.load_boundary) {
                let x = shape.positions[b];
                t.work += (0..3)
                    .map(|k| ld.force[k] * (x[k] - ld.reference[k]))
                    .sum::<f64>();
                for (vk, fk) in v[b].iter_mut().zip(ld.force) {
                    *vk -= fk;
                }
            }
            if objective == Objective::Internal
                && let Some(g) = grad
            {
                self.add_positions_vjp(shape, &v, g);
            }
        }
        t
    }

    /// Node `q`'s terms (flexure, torsion, extension, gravity; only those the layout has are
    /// added up) and its factors of the basis rows in the gradient (d/dθ, d/dθ', d/dφ, d/dφ',
    /// d/dψ', d/dε), which [`Model::add_node_sums`] or [`Model::fused_node_sums`] add up over
    /// the nodes.
    #[inline(always)]
    fn node_values(
        &self,
        shape: &Shape,
        q: usize,
        spatial: bool,
        up: Option<[f64; 3]>,
    ) -> ([f64; 4], [f64; 6]) {
        let (st, ct, sp, cp) = (shape.sth[q], shape.cth[q], shape.sph[q], shape.cph[q]);
        let (dth, dph, dps, eps) = (shape.dth[q], shape.dph[q], shape.dps[q], shape.eps[q]);
        let one = 1.0 + eps;
        let (wf, wt, we, wg) = (self.wf[q], self.wt[q], self.we[q], self.wg[q]);
        let omega = dph * ct + dps;
        // Gravity `wg (1+ε) h` for the tangent's height `h = ζ·x̂` (`sθcφ` in the case's
        // axes, `u·ζ` for the vertical `u` of an angles' frame): its value and its θ, φ
        // and ε derivatives.
        let (grav, grav_th, grav_ph, grav_e) = match up {
            None => (
                wg * one * st * cp,
                wg * one * ct * cp,
                -wg * one * st * sp,
                wg * st * cp,
            ),
            Some(u) => {
                let h = u[0] * st * cp + u[1] * st * sp + u[2] * ct;
                let h_th = u[0] * ct * cp + u[1] * ct * sp - u[2] * st;
                let h_ph = -u[0] * st * sp + u[1] * st * cp;
                (wg * one * h, wg * one * h_th, wg * one * h_ph, wg * h)
            }
        };
        let terms = [
            0.5 * wf * (dth * dth + dph * dph * st * st),
            0.5 * wt * omega * omega,
            0.5 * we * eps * eps,
            grav,
        ];
        let mut g_th = grav_th;
        if spatial {
            g_th += wf * dph * dph * st * ct - wt * omega * dph * st;
        }
        let g_dph = wf * dph * st * st + wt * omega * ct;
        let factors = [
            g_th,
            wf * dth,
            grav_ph,
            g_dph,
            wt * omega,
            we * eps + grav_e,
        ];
        (terms, factors)
    }

    /// Adds a node's `terms` ([`Model::node_values`]) to `t`: torsion only on a 3D rod,
    /// extension only on an extensible one.
    #[inline(always)]
    fn add_terms(t: &mut EnergyTerms, terms: &[f64; 4], spatial: bool, ext: bool) {
        t.flexural += terms[0];
        if spatial {
            t.torsional += terms[1];
        }
        if ext {
            t.extensional += terms[2];
        }
        t.gravitational += terms[3];
    }

    /// The node terms and, with `grad`, their sums for `nb ≤ 4 C` basis functions, with
    /// (`SPATIAL`) or without the φ and ψ fields and with (`EXT`) or without ε (a planar rod
    /// here is extensible or has an angles' frame). The same operations in the same order as
    /// the loop over [`Model::node_values`] and [`Model::add_node_sums`], so the same result
    /// bit for bit, but a block of nodes at a time: first every node's terms and factors side
    /// by side (no node waits for another, so the loop runs on vectors), then the energies
    /// added up in node order, then the factors into sums kept in registers.
    #[inline(always)]
    fn fused_node_sums<const C: usize, const SPATIAL: bool, const EXT: bool>(
        &self,
        shape: &Shape,
        t: &mut EnergyTerms,
        grad: Option<&mut [f64]>,
    ) {
        const BLOCK: usize = 32;
        let up = self.up();
        let nodes = self.nodes();
        let lay = &self.layout;
        let nb = self.nb();
        let offsets = [
            Some(0),
            lay.offset(Field::Phi).filter(|_| SPATIAL),
            lay.offset(Field::Psi).filter(|_| SPATIAL),
            lay.offset(Field::Eps).filter(|_| EXT),
        ];
        let mut acc = [[[0.0; 4]; C]; 4];
        if let Some(g) = grad.as_deref() {
            for (o, acc) in offsets.iter().zip(acc.iter_mut()) {
                if let Some(o) = *o {
                    for (i, &gi) in g[o..o + nb].iter().enumerate() {
                        acc[i / 4][i % 4] = gi;
                    }
                }
            }
        }
        let mut start = 0;
        while start < nodes {
            let len = (nodes - start).min(BLOCK);
            let r = start..start + len;
            // Each node's energies (flexure, torsion, extension, gravity) and factors.
            let mut en = [[0.0; BLOCK]; 4];
            let mut f = [[0.0; BLOCK]; 6];
            for (i, q) in r.clone().enumerate() {
                let (terms, factors) = self.node_values(shape, q, SPATIAL, up);
                for (en, v) in en.iter_mut().zip(terms) {
                    en[i] = v;
                }
                for (f, v) in f.iter_mut().zip(factors) {
                    f[i] = v;
                }
            }
            let [fl, to, ex, gr] = &en;
            for (((&fl, &to), &ex), &gr) in fl[..len].iter().zip(to).zip(ex).zip(gr) {
                Self::add_terms(t, &[fl, to, ex, gr], SPATIAL, EXT);
            }
            if grad.is_some() {
                // Four basis functions at a time, their four fields' sums in registers.
                let (e_lanes, de_lanes) = (&self.e_lanes[r.clone()], &self.de_lanes[r]);
                for c in 0..C {
                    let (mut th, mut ph) = (acc[0][c], acc[1][c]);
                    let (mut ps, mut ep) = (acc[2][c], acc[3][c]);
                    for (i, (e, de)) in e_lanes.iter().zip(de_lanes).enumerate() {
                        for l in 0..4 {
                            let (e, de) = (e[4 * c + l], de[4 * c + l]);
                            th[l] += f[0][i] * e + f[1][i] * de;
                            if SPATIAL {
                                ph[l] += f[2][i] * e + f[3][i] * de;
                                ps[l] += f[4][i] * de;
                            }
                            if EXT {
                                ep[l] += f[5][i] * e;
                            }
                        }
                    }
                    (acc[0][c], acc[1][c], acc[2][c], acc[3][c]) = (th, ph, ps, ep);
                }
            }
            start += len;
        }
        if let Some(g) = grad {
            for (o, acc) in offsets.iter().zip(acc.iter()) {
                if let Some(o) = *o {
                    for (i, gi) in g[o..o + nb].iter_mut().enumerate() {
                        *gi = acc[i / 4][i % 4];
                    }
                }
            }
        }
    }

    /// The node sums of a planar, inextensible rod in the case's axes (`φ = ψ = ε = 0`, so
    /// `cos φ = 1 + ε = 1`): flexure `½ wf θ'²` and gravity `wg sin θ` at each node, and with
    /// `grad` the sums `Σ_q (wg cos θ e_i + wf θ' e'_i)` added to θ's coefficients. The same
    /// operations in the same order as the general loop and [`Model::add_node_sums`] (whose
    /// zero terms add exact zeros), so the same result bit for bit, but every basis function's
    /// sum advances in one pass over the nodes, in registers.
    #[inline(always)]
    fn planar_node_terms(&self, shape: &Shape, t: &mut EnergyTerms, grad: Option<&mut [f64]>) {
        let nodes = self
            .wf
            .iter()
            .zip(&self.wg)
            .zip(shape.dth.iter().zip(&shape.sth));
        let Some(g) = grad else {
            for ((&wf, &wg), (&dth, &st)) in nodes {
                t.flexural += 0.5 * wf * (dth * dth);
                t.gravitational += wg * st;
            }
            return;
        };
        match self.nb().div_ceil(4) {
            1 => self.planar_sums::<1>(shape, t, g),
            2 => self.planar_sums::<2>(shape, t, g),
            3 => self.planar_sums::<3>(shape, t, g),
            _ => self.planar_sums::<4>(shape, t, g),
        }
    }

    /// [`Model::planar_node_terms`] with its gradient, for at most `4 C` basis functions.
    #[inline(always)]
    fn planar_sums<const C: usize>(&self, shape: &Shape, t: &mut EnergyTerms, g: &mut [f64]) {
        let nb = self.nb();
        let mut acc = [[0.0; 4]; C];
        for (i, &gi) in g[..nb].iter().enumerate() {
            acc[i / 4][i % 4] = gi;
        }
        let fields = shape.dth.iter().zip(&shape.sth).zip(&shape.cth);
        let weights = self.wf.iter().zip(&self.wg);
        let lanes = self.e_lanes.iter().zip(&self.de_lanes);
        for (((&wf, &wg), ((&dth, &st), &ct)), (e, de)) in weights.zip(fields).zip(lanes) {
            t.flexural += 0.5 * wf * (dth * dth);
            t.gravitational += wg * st;
            let (f0, f1) = (wg * ct, wf * dth);
            for (c, acc) in acc.iter_mut().enumerate() {
                for (l, v) in acc.iter_mut().enumerate() {
                    *v += f0 * e[4 * c + l] + f1 * de[4 * c + l];
                }
            }
        }
        for (i, gi) in g[..nb].iter_mut().enumerate() {
            *gi = acc[i / 4][i % 4];
        }
    }

    /// Flexure and extension of a planar rod without gravity, `½ aᵀ K a` with the constant
    /// Hessian `K`, as the sum of squares `½ Σ_r (R_r · a)²` of its square-root rows, and the
    /// gradient `K a = Σ_r (R_r · a) R_r` added to `grad`: the node sums' value in `n²`
    /// operations instead of `nodes · n`.
    #[inline(always)]
    fn quadratic_terms(&self, a: &[f64], t: &mut EnergyTerms, grad: Option<&mut [f64]>) {
        let mut grad = grad;
        for r in &self.energy_roots {
            let ab = &a[r.offset..r.offset + r.row.len()];
            let v = crate::rod::basis::dot(&r.row, ab);
            if r.flexural {
                t.flexural += 0.5 * v * v;
            } else {
                t.extensional += 0.5 * v * v;
            }
            if let Some(g) = grad.as_deref_mut() {
                for (gi, ri) in g[r.offset..r.offset + r.row.len()].iter_mut().zip(&r.row) {
                    *gi += v * ri;
                }
            }
        }
    }

    /// Adds the node sums of the energy gradient to `g`: for each basis function `i`,
    /// `Σ_q (f_θ e_i + f_θ' e'_i)` to θ's coefficient, `Σ_q (f_φ e_i + f_φ' e'_i)` to φ's,
    /// `Σ_q f_ψ' e'_i` to ψ's and `Σ_q f_ε e_i` to ε's, with the node factors `f` of
    /// `factors` (in `energy_body`'s order). Four basis functions at a time, each sum kept in
    /// a register across the nodes, and each added in node order exactly as one node at a
    /// time would (the same result bit for bit).
    #[inline(always)]
    fn add_node_sums(&self, factors: &[[f64; 6]], g: &mut [f64]) {
        let lay = &self.layout;
        let nb = self.nb();
        let (op, ops, oe) = (
            lay.offset(Field::Phi),
            lay.offset(Field::Psi),
            lay.offset(Field::Eps),
        );
        let angles = op.zip(ops);
        let mut i0 = 0;
        while i0 < nb {
            let w = (nb - i0).min(4);
            let mut th = [0.0; 4];
            let mut ph = [0.0; 4];
            let mut ps = [0.0; 4];
            let mut ep = [0.0; 4];
            for l in 0..w {
                th[l] = g[i0 + l];
                if let Some((op, ops)) = angles {
                    ph[l] = g[op + i0 + l];
                    ps[l] = g[ops + i0 + l];
                }
                if let Some(oe) = oe {
                    ep[l] = g[oe + i0 + l];
                }
            }
            let rows = self.e.chunks_exact(nb).zip(self.de.chunks_exact(nb));
            if w == 4 {
                for (f, (e, de)) in factors.iter().zip(rows) {
                    let ev: &[f64; 4] = e[i0..i0 + 4].try_into().expect("four");
                    let dv: &[f64; 4] = de[i0..i0 + 4].try_into().expect("four");
                    node_terms(
                        f,
                        ev,
                        dv,
                        angles.is_some(),
                        oe.is_some(),
                        [&mut th, &mut ph, &mut ps, &mut ep],
                    );
                }
            } else {
                // The last basis functions, fewer than four: the lanes past them add zeros
                // and are not written back.
                for (f, (e, de)) in factors.iter().zip(rows) {
                    let (mut ev, mut dv) = ([0.0; 4], [0.0; 4]);
                    for l in 0..w {
                        (ev[l], dv[l]) = (e[i0 + l], de[i0 + l]);
                    }
                    node_terms(
                        f,
                        &ev,
                        &dv,
                        angles.is_some(),
                        oe.is_some(),
                        [&mut th, &mut ph, &mut ps, &mut ep],
                    );
                }
            }
            for l in 0..w {
                g[i0 + l] = th[l];
                if let Some((op, ops)) = angles {
                    g[op + i0 + l] = ph[l];
                    g[ops + i0 + l] = ps[l];
                }
                if let Some(oe) = oe {
                    g[oe + i0 + l] = ep[l];
                }
            }
            i0 += w;
        }
    }

    /// Objective value and gradient (overwritten) at `a`; convenience for tests and solvers.
    pub fn objective_and_gradient(
        &self,
        a: &[f64],
        objective: Objective,
        shape: &mut Shape,
        grad: &mut [f64],
    ) -> f64 {
        self.evaluate_into(a, shape);
        grad.iter_mut().for_each(|g| *g = 0.0);
        self.energy(a, shape, objective, Some(grad))
            .value(objective)
    }
}

/// One node's terms of [`Model::add_node_sums`] for four basis functions at once.
#[inline(always)]
fn node_terms(
    f: &[f64; 6],
    e: &[f64; 4],
    de: &[f64; 4],
    angles: bool,
    extensible: bool,
    [th, ph, ps, ep]: [&mut [f64; 4]; 4],
) {
    for l in 0..4 {
        th[l] += f[0] * e[l] + f[1] * de[l];
    }
    if angles {
        for l in 0..4 {
            ph[l] += f[2] * e[l] + f[3] * de[l];
            ps[l] += f[4] * de[l];
        }
    }
    if extensible {
        for l in 0..4 {
            ep[l] += f[5] * e[l];
        }
    }
}

crate::kernels::wide::dispatch! {
    fn energy_terms(
        m: &Model,
        a: &[f64],
        shape: &Shape,
        objective: Objective,
        grad: Option<&mut [f64]>,
    ) -> EnergyTerms => Model::energy_body
}
