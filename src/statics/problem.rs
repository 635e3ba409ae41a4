//! A static-shape problem as a nonlinear program: minimise the internal energy `V` of eq. (13)
//! over the Ritz coefficients subject to the geometric constraints of §3.2.

use crate::constraints::{Adjoint, Constraint, add_penalty_gauss_newton, add_weighted_curvature};
use crate::optim::{Nlp, Sense};
use crate::rod::energy::{EnergyTerms, Objective};
use crate::rod::kinematics::Shape;
use crate::rod::layout::{Field, Layout};
use crate::rod::model::Model;

/// The rod model plus its constraints.
#[derive(Clone, Debug)]
pub struct StaticProblem {
    /// The rod model.
    pub model: Model,
    /// Constraint blocks, in case-file order.
    pub constraints: Vec<Constraint>,
    /// Which energy is minimised.
    pub objective: Objective,
    offsets: Vec<usize>,
    senses: Vec<Sense>,
    shape: Shape,
    grad_f: Vec<f64>,
    adj: Adjoint,
    terms: EnergyTerms,
}

impl StaticProblem {
    /// Assembles a problem.
    pub fn new(model: Model, constraints: Vec<Constraint>) -> Self {
        let mut offsets = vec![0];
        let mut senses = Vec::new();
        for c in &constraints {
            for i in 0..c.rows() {
                senses.push(c.sense(i));
            }
            offsets.push(offsets.last().unwrap() + c.rows());
        }
        let adj = Adjoint::new(&model);
        let n = model.n();
        StaticProblem {
            model,
            constraints,
            objective: Objective::Internal,
            offsets,
            senses,
            shape: Shape::default(),
            grad_f: vec![0.0; n],
            adj,
            terms: EnergyTerms::default(),
        }
    }

    /// Row range of constraint block `k`.
    pub fn rows_of(&self, k: usize) -> std::ops::Range<usize> {
        self.offsets[k]..self.offsets[k + 1]
    }

    /// Energy terms at the last evaluated point.
    pub fn terms(&self) -> EnergyTerms {
        self.terms
    }

    /// Shape at the last evaluated point.
    pub fn shape(&self) -> &Shape {
        &self.shape
    }

    /// A start for a solve: the natural state (straight along the angles' frame's z) at the
    /// base, bent by a deterministic perturbation of `delta` radians (see [`default_start`]).
    pub fn natural_start(&self, delta: f64) -> Vec<f64> {
        default_start(&self.model.layout, delta, self.model.base)
    }

    /// The obstacles among the constraints, in their order.
    pub fn obstacles(&self) -> Vec<std::sync::Arc<crate::scene::Obstacle>> {
        self.constraints
            .iter()
            .filter_map(|c| match c {
                Constraint::Obstacle(o) => Some(o.obstacle.clone()),
                _ => None,
            })
            .collect()
    }

    /// The constraint block violated most at `a` (label and violation in units of L), if any
    /// is violated by more than `tol`: what keeps a failed solve from its target.
    pub fn most_violated(&mut self, a: &[f64], tol: f64) -> Option<(String, f64)> {
        let mut c = vec![0.0; self.m()];
        self.values(a, &mut c);
        (0..self.constraints.len())
            .map(|k| {
                let worst = self
                    .rows_of(k)
                    .map(|i| match self.senses[i] {
                        Sense::Equal => c[i].abs(),
                        Sense::LessEq => c[i].max(0.0),
                    })
                    .fold(0.0, f64::max);
                (k, worst)
            })
            .filter(|&(_, w)| w > tol)
            .max_by(|x, y| x.1.total_cmp(&y.1))
            .map(|(k, w)| (self.constraints[k].label(), w))
    }
}

impl Nlp for StaticProblem {
    fn n(&self) -> usize {
        self.model.n()
    }
    fn m(&self) -> usize {
        self.senses.len()
    }
    fn sense(&self, i: usize) -> Sense {
        self.senses[i]
    }
    fn values(&mut self, x: &[f64], c: &mut [f64]) -> f64 {
        self.model.evaluate_into(x, &mut self.shape);
        self.grad_f.iter_mut().for_each(|g| *g = 0.0);
        self.terms = self
            .model
            .energy(x, &self.shape, self.objective, Some(&mut self.grad_f));
        for (k, con) in self.constraints.iter().enumerate() {
            con.values(
                &self.model,
                x,
                &self.shape,
                &mut c[self.offsets[k]..self.offsets[k + 1]],
            );
        }
        self.terms.value(self.objective)
    }
    fn gradient(&mut self, x: &[f64], y: &[f64], g: &mut [f64]) {
        g.copy_from_slice(&self.grad_f);
        self.adj.clear();
        for (k, con) in self.constraints.iter().enumerate() {
            let w = &y[self.offsets[k]..self.offsets[k + 1]];
            if !crate::kernels::all_zero(w) {
                con.add_gradient(&self.model, x, &self.shape, w, &mut self.adj);
            }
        }
        self.adj.finish(&self.model, &self.shape, g);
    }
    fn has_hessian(&self) -> bool {
        true
    }
    fn hessian_is_exact(&self, y: &[f64]) -> bool {
        self.constraints.iter().enumerate().all(|(k, con)| {
            !matches!(con, Constraint::SelfContact(_))
                || crate::kernels::all_zero(&y[self.offsets[k]..self.offsets[k + 1]])
        })
    }
    /// The energy's exact Hessian, the constraints' curvature through the positions, and the
    /// Gauss–Newton part of the penalty; the curvature of the self-contact distance itself is left
    /// out.
    fn hessian(&mut self, x: &[f64], y: &[f64], s: &[f64], h: &mut [f64]) {
        let (model, shape) = (&self.model, &self.shape);
        model.add_energy_hessian(shape, self.objective, 1.0, h);
        let (blocks, offsets) = (&self.constraints, &self.offsets);
        add_weighted_curvature(blocks, offsets, model, x, shape, y, &mut self.adj, h);
        self.adj.finish_hessian(model, shape, h);
        add_penalty_gauss_newton(blocks, offsets, model, x, shape, s, &mut self.adj, h);
    }
}

/// The natural state plus a deterministic perturbation of size `delta` radians: a bulge
/// `θ = δ(1 − 2t)` plus small multiples of the other modes, so that no symmetry of the problem
/// survives (a symmetric start converges to a symmetric, possibly unstable, equilibrium).
pub fn default_start(layout: &Layout, delta: f64, base: [f64; 3]) -> Vec<f64> {
    let mut a = vec![0.0; layout.len()];
    let nb = layout.nb();
    a[0] = delta;
    a[1] = -2.0 * delta;
    for (i, ai) in a.iter_mut().enumerate().take(nb).skip(2) {
        *ai = delta * 0.05 * (1.0 + (i as f64 * 0.7).sin());
    }
    if let Some(o) = layout.offset(Field::Phi) {
        a[o] = 0.3;
        for i in 2..nb {
            a[o + i] = delta * 0.05 * (i as f64 * 1.3).cos();
        }
    }
    if let Some(o) = layout.offset(Field::Psi) {
        a[o] = -0.3;
    }
    if let Some(o) = layout.base_offset() {
        for (k, &c) in layout.components().iter().enumerate() {
            a[o + k] = base[c];
        }
    }
    a
}
