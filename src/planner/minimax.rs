//! The planning objective as a nonlinear program over the path unknowns `z`:
//!
//! `J(z) = S_β(U(a(z, k₀)), …, U(a(z, k_K))) + w · mean_j U(a(z, k_j))`
//!
//! where `S_β(u) = u_max + ln Σ exp(β (u_j − u_max)) / β` is the log-sum-exp smoothed maximum
//! (an upper bound on `max u` by at most `ln(K+1)/β`) and `w ≥ 0` weighs the mean energy along
//! the path (it makes the shapes away from the maximum equilibria too; docs/algorithms.md, step 4).
//! With tracking targets `x̄_j` set (the equilibria the controlled end's poses produce, see
//! [`crate::planner::Planner`]), `J` also has `(w_eq/2) · Σ_j mean_b |r_jb|²` with
//! `r_jb = x_b(a(z,k_j)) − x̄_jb`, which pulls every sampled shape onto the equilibrium its own
//! end pose gives; with the targets' slopes set, `r_jb = x_b − x̄_jb − D_jb (P(a) − v_j)`
//! follows the sample's end pose `P(a)` from the pose `v_j` the target was solved at
//! ([`crate::planner::equilibrium_slopes`]).
//! The path constraints (obstacles, self-contact, nonlinear fixed conditions) hold at every
//! interior sample `k_j`: each block's rows are repeated per sample. Energies are dimensionless
//! (`Rf/L`), positions in units of `L`.

use crate::constraints::{Adjoint, Constraint, add_penalty_gauss_newton, add_weighted_curvature};
use crate::kernels::all_zero;
use crate::optim::{Nlp, Sense};
use crate::planner::clear_samples::{ClearSamples, LastRows};
use crate::planner::equilibrium_slopes::Slope;
use crate::planner::path::DeformationPath;
use crate::planner::swept::Swept;
use crate::planner::workers::{JOB_GRADIENT, JOB_HESSIAN, JOB_VALUES, Workers};
use crate::rod::energy::Objective;
use crate::rod::hessian::add_rank_one;
use crate::rod::kinematics::Shape;
use crate::rod::model::Model;

/// The minimax path problem.
#[derive(Debug)]
pub struct MinimaxProblem {
    /// Rod model.
    pub model: Model,
    /// The path.
    pub path: DeformationPath,
    /// Sampled path parameters (including 0 and 1).
    pub ks: Vec<f64>,
    /// Constraint blocks that hold at every interior sample.
    pub blocks: Vec<Constraint>,
    /// Smoothing sharpness `β` (dimensionless energy⁻¹).
    pub beta: f64,
    /// Weight of the mean energy.
    pub mean_weight: f64,
    /// Weight of the controlled end's travel term ([`MinimaxProblem::travel`]).
    pub travel_weight: f64,
    /// Energy minimised.
    pub objective: Objective,
    /// Weight of the equilibrium-tracking term.
    pub track_weight: f64,
    /// Tracking targets: boundary positions (dimensionless) per sample, when set.
    pub targets: Option<Vec<Vec<[f64; 3]>>>,
    /// The targets' slopes with respect to the end pose, per sample, when known: a sample's
    /// target then follows its own end pose ([`crate::planner::equilibrium_slopes`]).
    pub slopes: Option<Vec<Option<Slope>>>,
    /// Swept-clearance rows between consecutive interior samples, when on
    /// ([`MinimaxProblem::set_swept`]).
    swept: Option<Swept>,
    /// Leave out the shapes of samples whose rows are certainly inactive (see
    /// [`MinimaxProblem::set_skip_clear_samples`]).
    skip: Option<ClearSamples>,
    interior: Vec<usize>,
    offsets: Vec<usize>,
    senses: Vec<Sense>,
    a: Vec<Vec<f64>>,
    shapes: Vec<Shape>,
    u: Vec<f64>,
    weights: Vec<f64>,
    /// Per sample: its own results and scratch, written by whichever thread evaluates it.
    work: Vec<SampleWork>,
    /// Threads the samples are split over ([`MinimaxProblem::set_workers`]).
    workers: Workers,
}

/// One sample's results and scratch ([`MinimaxProblem`] evaluates the samples on any number of
/// threads, each into its own slots, and sums them afterwards in sample order).
#[derive(Clone, Debug)]
struct SampleWork {
    /// Interior sample index (its rows start at `index · rows_per_sample`), if interior.
    interior: Option<usize>,
    /// Dimensionless energy.
    u: f64,
    /// Its gradient in the shape's coefficients.
    gu: Vec<f64>,
    /// The sample's rows.
    rows: Vec<f64>,
    /// The sample's share of the objective's gradient, in the shape's coefficients.
    ga: Vec<f64>,
    /// Its projections on the path's admissible directions ([`DeformationPath::project`]).
    proj: Vec<f64>,
    /// The z-gradient of its energy (Hessian only).
    gz: Vec<f64>,
    /// The sample's share of the Hessian in the shape's coefficients (row-major `n×n`).
    ha: Vec<f64>,
    /// Its projection on the path's admissible directions (Hessian only, row-major `r×r`,
    /// [`DeformationPath::project_hessian`]).
    hm: Vec<f64>,
    /// The z-Jacobian of the controlled end's position, row by row (Hessian with the travel
    /// term only).
    end_jac: [Vec<f64>; 3],
    /// The rows' weights (scratch).
    y: Vec<f64>,
    /// Whether its rows at the last evaluation are its last recorded ones (its shape evaluated
    /// all the same; see [`MinimaxProblem::set_skip_clear_samples`]).
    rows_kept: bool,
    /// Whether its shape was left out at the last evaluation (the same).
    left_out: bool,
    /// Its rows at its last evaluated shape, while rows may be kept (the same).
    last: Option<LastRows>,
    adj: Adjoint,
}

impl MinimaxProblem {
    /// Assembles the problem; constraints are enforced at samples with `0 < k < 1`.
    pub fn new(
        model: Model,
        path: DeformationPath,
        ks: Vec<f64>,
        blocks: Vec<Constraint>,
        objective: Objective,
    ) -> Self {
        let interior: Vec<usize> = (0..ks.len())
            .filter(|&j| ks[j] > 0.0 && ks[j] < 1.0)
            .collect();
        let mut offsets = vec![0];
        let mut block_senses = Vec::new();
        for b in &blocks {
            for i in 0..b.rows() {
                block_senses.push(b.sense(i));
            }
            offsets.push(offsets.last().unwrap() + b.rows());
        }
        let senses = interior
            .iter()
            .flat_map(|_| block_senses.iter().copied())
            .collect();
        let n = path.n();
        let nk = ks.len();
        let per = *offsets.last().unwrap();
        let work = (0..nk)
            .map(|j| SampleWork {
                interior: interior.iter().position(|&i| i == j),
                u: 0.0,
                gu: vec![0.0; n],
                rows: vec![0.0; per],
                ga: vec![0.0; n],
                proj: vec![0.0; path.basis.len()],
                gz: Vec::new(),
                ha: Vec::new(),
                hm: Vec::new(),
                end_jac: Default::default(),
                y: vec![0.0; per],
                rows_kept: false,
                left_out: false,
                last: None,
                adj: Adjoint::new(&model),
            })
            .collect();
        MinimaxProblem {
            model,
            path,
            ks,
            blocks,
            beta: 1.0,
            mean_weight: 0.0,
            travel_weight: 0.0,
            objective,
            track_weight: 0.0,
            targets: None,
            slopes: None,
            swept: None,
            skip: None,
            interior,
            offsets,
            senses,
            a: vec![vec![0.0; n]; nk],
            shapes: vec![Shape::default(); nk],
            u: vec![0.0; nk],
            weights: vec![0.0; nk],
            work,
            workers: Workers::serial(),
        }
    }

    /// Splits the samples' evaluations over `workers`' threads (the results are the same bit
    /// for bit on any number).
    pub fn set_workers(&mut self, workers: Workers) {
        self.workers = workers;
    }

    /// The threads the samples are split over.
    pub(crate) fn workers(&self) -> &Workers {
        &self.workers
    }

    /// Rows per interior sample.
    pub fn rows_per_sample(&self) -> usize {
        *self.offsets.last().unwrap()
    }

    /// Adds (or removes) the swept-clearance rows ([`crate::planner::swept`]) between
    /// consecutive interior samples, after the per-sample rows.
    pub fn set_swept(&mut self, on: bool) {
        let per_sample = self.sample_rows();
        self.senses.truncate(per_sample);
        self.swept = if on {
            Swept::new(&self.blocks, self.interior.len())
        } else {
            None
        };
        if let Some(sw) = &self.swept {
            self.senses
                .extend(std::iter::repeat_n(Sense::LessEq, sw.rows()));
        }
    }

    /// Turns on (or off) keeping the rows of samples that certainly keep clear of every
    /// obstacle, and leaving out their shapes where nothing else needs them
    /// (`src/planner/clear_samples.rs`; for a planar, inextensible rod with a fixed base,
    /// obstacle rows only — none of them a triangle mesh — and no swept rows; otherwise it
    /// stays off). A sample qualifies while its rows' multipliers ([`Nlp::set_multipliers`]) are
    /// zero and its largest row at its last evaluated rows, plus the most its positions can
    /// have moved since ([`Model::position_bound_weights`]), stays below −1e-6: it keeps those
    /// rows. Its shape is left out too only on a weightless rod without loads (whose energy
    /// needs no shape) while neither the tracking term nor the travel term is set (they read
    /// every shape). The objective, its gradient, its Hessian and the multiplier method's
    /// steps are the same bit for bit: only work on rows whose penalty is certainly inactive is
    /// left out.
    pub fn set_skip_clear_samples(&mut self, on: bool) {
        let m = &self.model;
        let eligible = on
            && self.swept.is_none()
            && self.blocks.iter().all(|b| match b {
                Constraint::Obstacle(o) => o.obstacle.distance_is_lipschitz(),
                _ => false,
            });
        // The energy needs no shape: the constant quadratic form of a weightless rod.
        let shapes_optional = m.loads.is_empty() && !m.energy_roots.is_empty();
        for w in &mut self.work {
            w.last = None;
        }
        self.skip = match (eligible, m.position_bound_weights()) {
            (true, Some(omega)) => Some(ClearSamples::new(
                omega,
                self.ks.len(),
                self.interior.len(),
                shapes_optional,
            )),
            _ => None,
        };
    }

    /// How many sampled shapes [`MinimaxProblem::values`] has left out so far (0 while leaving
    /// them out is off).
    pub fn shapes_left_out(&self) -> usize {
        self.skip.as_ref().map_or(0, |sk| sk.left_out)
    }

    /// How many samples' rows [`MinimaxProblem::values`] has kept from their last evaluation
    /// (their shapes left out or not) so far.
    pub fn rows_kept(&self) -> usize {
        self.skip.as_ref().map_or(0, |sk| sk.rows_kept)
    }

    /// Evaluates sample `j`'s shape if [`MinimaxProblem::values`] left it out.
    fn ensure_shape(&mut self, j: usize) {
        if let Some(sk) = &mut self.skip
            && sk.stale[j]
        {
            self.model.evaluate_into(&self.a[j], &mut self.shapes[j]);
            sk.stale[j] = false;
        }
    }

    /// Number of per-sample rows (the swept rows follow them).
    pub fn sample_rows(&self) -> usize {
        self.interior.len() * self.rows_per_sample()
    }

    /// Sampled energies at the last evaluated point (dimensionless).
    pub fn energies(&self) -> &[f64] {
        &self.u
    }

    /// Whether the largest sampled energy at the last evaluated point is the first or the
    /// last sample's (`k = 0` or `k = 1`: an end shape's), to rounding
    /// ([`super::verify::attains_end_energy`]).
    pub fn peaks_at_an_end(&self) -> bool {
        let ends = self.u[0].max(self.u[self.u.len() - 1]);
        let top = self.u.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        super::verify::attains_end_energy(top, ends)
    }

    /// Whether the sampled energies at the last evaluated point peak inside the path more
    /// than `fraction` of the larger end energy above it (never where that is not positive).
    pub fn peaks_far_inside(&self, fraction: f64) -> bool {
        let ends = self.u[0].max(self.u[self.u.len() - 1]);
        let top = self.u.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        ends > 0.0 && top > (1.0 + fraction) * ends
    }

    /// Sampled shapes' coefficients at the last evaluated point.
    pub fn sampled(&self) -> &[Vec<f64>] {
        &self.a
    }

    /// Index of the interior sample that row `i` belongs to, and the block.
    pub fn row_owner(&self, i: usize) -> (usize, usize) {
        let per = self.rows_per_sample();
        let j = self.interior[i / per];
        let r = i % per;
        let b = self.offsets.partition_point(|&o| o <= r) - 1;
        (j, b)
    }
}

impl MinimaxProblem {
    /// Largest distance (dimensionless) between a boundary position of the path `z`'s sampled
    /// shapes and the same boundary of `targets` (boundary positions per sample).
    pub fn distance_to(&self, z: &[f64], targets: &[Vec<[f64; 3]>]) -> f64 {
        let mut a = vec![0.0; self.path.n()];
        let mut shape = Shape::default();
        let mut worst: f64 = 0.0;
        for (&k, tj) in self.ks.iter().zip(targets) {
            self.path.shape_at(z, k, &mut a);
            self.model.evaluate_into(&a, &mut shape);
            worst = worst.max(crate::planner::replay::max_distance(&shape.positions, tj));
        }
        worst
    }

    /// The travel term at the last evaluated point: `½ w Σⱼ |x(kⱼ₊₁) − x(kⱼ)|² / (kⱼ₊₁ − kⱼ)`
    /// over the controlled end's positions `x(k)` (dimensionless) at the samples, the discrete
    /// `½ w ∫ |dx/dk|² dk`. By Cauchy–Schwarz it bounds `½ w` times the squared length of the
    /// end's path, and it is least for a straight path at even speed.
    pub fn travel(&self) -> f64 {
        if self.travel_weight == 0.0 {
            return 0.0;
        }
        let end = self.model.mesh.boundaries.len() - 1;
        let mut sum = 0.0;
        for j in 0..self.ks.len().saturating_sub(1) {
            let (x0, x1) = (
                self.shapes[j].positions[end],
                self.shapes[j + 1].positions[end],
            );
            let d2 = (0..3).map(|c| (x1[c] - x0[c]).powi(2)).sum::<f64>();
            sum += d2 / (self.ks[j + 1] - self.ks[j]);
        }
        0.5 * self.travel_weight * sum
    }

    /// The tracking term at the last evaluated point.
    pub fn tracking(&self) -> f64 {
        let Some(t) = &self.targets else { return 0.0 };
        let mut sum = 0.0;
        for (j, (sh, tj)) in self.shapes.iter().zip(t).enumerate() {
            let nb = tj.len() as f64;
            match slope_of(&self.slopes, j) {
                Some(sl) => {
                    for r in sl.residuals(&self.model, &self.a[j], sh, tj) {
                        sum += (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]) / nb;
                    }
                }
                None => {
                    for (x, xb) in sh.positions.iter().zip(tj) {
                        sum += ((x[0] - xb[0]).powi(2)
                            + (x[1] - xb[1]).powi(2)
                            + (x[2] - xb[2]).powi(2))
                            / nb;
                    }
                }
            }
        }
        0.5 * self.track_weight * sum
    }
}

/// `∂(travel)/∂x(kⱼ)` of the travel term with weight `w` ([`MinimaxProblem::travel`]) for
/// sample `j` of `ks`, whose evaluated `shapes` end at boundary `end` (zero at the path's ends,
/// which are fixed).
fn travel_cotangent(w: f64, ks: &[f64], shapes: &[Shape], end: usize, j: usize) -> [f64; 3] {
    if w == 0.0 || j == 0 || j + 1 >= ks.len() {
        return [0.0; 3];
    }
    let x = |i: usize| shapes[i].positions[end];
    let (back, ahead) = (ks[j] - ks[j - 1], ks[j + 1] - ks[j]);
    let (xp, xj, xn) = (x(j - 1), x(j), x(j + 1));
    std::array::from_fn(|c| w * ((xj[c] - xp[c]) / back - (xn[c] - xj[c]) / ahead))
}

/// Adds sample `j`'s cotangents on its positions of the tracking term, towards `target` (its
/// equilibrium's boundary positions, when tracked), and of the travel term to `adj`, with the
/// weights `(track, travel)`; returns the tracking term's weight per point and its number of
/// points (for its Gauss–Newton part), `None` without a target.
#[allow(clippy::too_many_arguments)]
fn add_track_travel(
    adj: &mut Adjoint,
    model: &Model,
    a: &[f64],
    shapes: &[Shape],
    ks: &[f64],
    j: usize,
    target: Option<(&[[f64; 3]], Option<&Slope>)>,
    (track_weight, travel_weight): (f64, f64),
) -> Option<(f64, usize)> {
    let tracked = target.map(|(tj, slope)| {
        let wt = track_weight / tj.len() as f64;
        match slope {
            Some(sl) => sl.add_cotangents(model, a, &shapes[j], tj, wt, adj),
            None => {
                for (b, (x, xb)) in shapes[j].positions.iter().zip(tj).enumerate() {
                    adj.add_pos(b, wt, [x[0] - xb[0], x[1] - xb[1], x[2] - xb[2]]);
                }
            }
        }
        (wt, tj.len())
    });
    if travel_weight != 0.0 {
        let end = shapes[j].positions.len() - 1;
        let d = travel_cotangent(travel_weight, ks, shapes, end, j);
        adj.add_pos(end, 1.0, d);
    }
    tracked
}

/// Sample `j`'s slope in `slopes`, when set.
fn slope_of(slopes: &Option<Vec<Option<Slope>>>, j: usize) -> Option<&Slope> {
    slopes
        .as_ref()
        .and_then(|s| s.get(j))
        .and_then(Option::as_ref)
}

/// The interior samples' shapes in sample order, as the swept rows read them: only they read
/// the shapes as a list, so without swept rows the list is empty.
fn swept_shapes<'a>(
    swept: &Option<Swept>,
    interior: &[usize],
    shapes: &'a [Shape],
) -> Vec<&'a Shape> {
    match swept {
        Some(_) => interior.iter().map(|&j| &shapes[j]).collect(),
        None => Vec::new(),
    }
}

/// `S_β(u)` and its weights `∂S/∂u_j` (a softmax).
pub fn smoothed_max(u: &[f64], beta: f64, weights: &mut [f64]) -> f64 {
    let umax = u.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mut sum = 0.0;
    for (w, &uj) in weights.iter_mut().zip(u) {
        *w = (beta * (uj - umax)).exp();
        sum += *w;
    }
    for w in weights.iter_mut() {
        *w /= sum;
    }
    umax + sum.ln() / beta
}

impl Nlp for MinimaxProblem {
    fn n(&self) -> usize {
        self.path.n_vars()
    }
    fn m(&self) -> usize {
        self.senses.len()
    }
    fn sense(&self, i: usize) -> Sense {
        self.senses[i]
    }
    fn set_multipliers(&mut self, lambda: &[f64]) {
        let per = self.rows_per_sample();
        if let Some(sk) = &mut self.skip {
            sk.set_free(lambda, per);
        }
    }
    fn values(&mut self, z: &[f64], c: &mut [f64]) -> f64 {
        let per = self.rows_per_sample();
        let mut row = 0;
        // Shapes may be left out only while nothing but the rows reads them (no tracking term,
        // no swept rows, which may have been turned on after skipping was, and an energy that
        // needs none); otherwise every shape is evaluated, and the rows of a sample certainly
        // clear of the obstacles are still kept (not while swept rows read them).
        let light = self.targets.is_none()
            && self.swept.is_none()
            && self.travel_weight == 0.0
            && self.skip.as_ref().is_some_and(|sk| sk.shapes_optional);
        let rows_only = !light && self.swept.is_none() && self.skip.is_some();
        // Sample by sample: the coefficients, whether the shape stays left out, the shape, the
        // energy, the rows and, while rows may be kept, their record.
        {
            let (model, blocks, offsets) = (&self.model, &self.blocks, &self.offsets);
            let (path, ks, skip, objective) = (&self.path, &self.ks, &self.skip, self.objective);
            let (a, shapes, work) = (&mut self.a, &mut self.shapes, &mut self.work);
            self.workers
                .for_each_chunk3(JOB_VALUES, a, shapes, work, |j0, a, shapes, work| {
                    for ((i, ai), w) in a.iter_mut().enumerate().zip(work.iter_mut()) {
                        path.shape_at(z, ks[j0 + i], ai);
                        w.left_out = match (skip, w.interior) {
                            (Some(sk), Some(ii)) if light => sk.clear(ii, w.last.as_ref(), ai),
                            (Some(_), None) => light,
                            _ => false,
                        };
                    }
                    model.evaluate_many(a, shapes, |i| !work[i].left_out);
                    for (i, (shape, w)) in shapes.iter().zip(work.iter_mut()).enumerate() {
                        w.gu.iter_mut().for_each(|g| *g = 0.0);
                        let t = model.energy(&a[i], shape, objective, Some(&mut w.gu));
                        w.u = t.value(objective);
                        w.rows_kept = match (skip, w.interior) {
                            (Some(sk), Some(ii)) if rows_only => {
                                sk.clear(ii, w.last.as_ref(), &a[i])
                            }
                            _ => false,
                        };
                        if w.interior.is_some() && !w.rows_kept && !w.left_out {
                            for (b, blk) in blocks.iter().enumerate() {
                                let rows = &mut w.rows[offsets[b]..offsets[b + 1]];
                                blk.values(model, &a[i], shape, rows);
                            }
                            if skip.is_some() {
                                LastRows::record(&mut w.last, &a[i], &w.rows);
                            }
                        }
                    }
                });
        }
        for (j, w) in self.work.iter().enumerate() {
            self.u[j] = w.u;
            if let Some(sk) = &mut self.skip {
                sk.stale[j] = w.left_out;
                sk.left_out += w.left_out as usize;
            }
            if w.interior.is_some() {
                let rows = &mut c[row..row + per];
                match (&mut self.skip, &w.last) {
                    // Kept (or left out): the rows last recorded.
                    (Some(sk), Some(last)) if sk.stale[j] || w.rows_kept => {
                        sk.rows_kept += 1;
                        rows.copy_from_slice(last.rows());
                    }
                    _ => rows.copy_from_slice(&w.rows),
                }
                row += per;
            }
        }
        if let Some(sw) = &self.swept {
            let shapes = swept_shapes(&self.swept, &self.interior, &self.shapes);
            let (rows, swept) = c.split_at_mut(row);
            sw.values(rows, per, &self.offsets, &shapes, swept);
        }
        let s = smoothed_max(&self.u, self.beta, &mut self.weights);
        let mean = self.u.iter().sum::<f64>() / self.u.len() as f64;
        s + self.mean_weight * mean + self.tracking() + self.travel()
    }
    fn gradient(&mut self, z: &[f64], y: &[f64], g: &mut [f64]) {
        let _ = z;
        g.iter_mut().for_each(|v| *v = 0.0);
        let per = self.rows_per_sample();
        // A left-out shape is needed only where some of its rows have a weight.
        if self.skip.is_some() {
            for i in 0..self.interior.len() {
                if !all_zero(&y[i * per..(i + 1) * per]) {
                    self.ensure_shape(self.interior[i]);
                }
            }
        }
        let nk = self.ks.len() as f64;
        let n_sample_rows = self.sample_rows();
        let interior_shapes = swept_shapes(&self.swept, &self.interior, &self.shapes);
        let (model, blocks, offsets) = (&self.model, &self.blocks, &self.offsets);
        let (ks, a, shapes, weights) = (&self.ks, &self.a, &self.shapes, &self.weights);
        let (swept, targets, slopes) = (&self.swept, &self.targets, &self.slopes);
        let tracked = targets.is_some() && self.track_weight > 0.0;
        let (travel_weight, track_weight, mean_weight) =
            (self.travel_weight, self.track_weight, self.mean_weight);
        let travel = travel_weight != 0.0;
        let path = &self.path;
        self.workers
            .for_each_chunk(JOB_GRADIENT, &mut self.work, |j0, work| {
                for (i, w) in work.iter_mut().enumerate() {
                    let j = j0 + i;
                    let wj = weights[j] + mean_weight / nk;
                    for (ga, gu) in w.ga.iter_mut().zip(&w.gu) {
                        *ga = wj * gu;
                    }
                    let Some(ii) = w.interior else { continue };
                    let row = ii * per;
                    w.y.copy_from_slice(&y[row..row + per]);
                    w.adj.clear();
                    let swept_any = swept.as_ref().is_some_and(|sw| {
                        let ys = &y[n_sample_rows..];
                        sw.add_chord_cotangents(ii, ys, &interior_shapes, &mut w.adj);
                        sw.add_sample_weights(ii, ys, offsets, &mut w.y)
                    });
                    if tracked || travel || swept_any || !all_zero(&w.y) {
                        for (b, blk) in blocks.iter().enumerate() {
                            let wb = &w.y[offsets[b]..offsets[b + 1]];
                            if !all_zero(wb) {
                                blk.add_gradient(model, &a[j], &shapes[j], wb, &mut w.adj);
                            }
                        }
                        let target = targets
                            .as_ref()
                            .filter(|_| tracked)
                            .map(|t| (&t[j][..], slope_of(slopes, j)));
                        let weights = (track_weight, travel_weight);
                        add_track_travel(&mut w.adj, model, &a[j], shapes, ks, j, target, weights);
                        w.adj.finish(model, &shapes[j], &mut w.ga);
                    }
                    path.project(&w.ga, &mut w.proj);
                }
            });
        for (w, &k) in self.work.iter().zip(&self.ks) {
            if w.interior.is_some() {
                self.path.add_projected(&w.proj, k, g);
            }
        }
    }
    /// Exact Hessian of the smoothed maximum and the mean (through the energy Hessian of every
    /// sample), the constraints' curvature through the positions, and Gauss–Newton parts for
    /// the tracking term and the penalty; the curvature of the self-contact distance itself is left
    /// out.
    fn has_hessian(&self) -> bool {
        true
    }
    fn hessian(&mut self, z: &[f64], y: &[f64], s: &[f64], h: &mut [f64]) {
        let _ = z;
        for i in 0..self.interior.len() {
            self.ensure_shape(self.interior[i]);
        }
        let nv = self.path.n_vars();
        let per = self.rows_per_sample();
        let nk = self.ks.len() as f64;
        let tracked = self.targets.is_some() && self.track_weight > 0.0;
        // Softmax part: β (Σ w g gᵀ − ḡ ḡᵀ) with g the z-gradients of the samples.
        let mut gbar = vec![0.0; nv];
        let interior_shapes = swept_shapes(&self.swept, &self.interior, &self.shapes);
        let ns = self.sample_rows();
        let n = self.model.n();
        let (model, blocks, offsets, path) = (&self.model, &self.blocks, &self.offsets, &self.path);
        let (ks, a, shapes, weights) = (&self.ks, &self.a, &self.shapes, &self.weights);
        let (swept, targets, objective) = (&self.swept, &self.targets, self.objective);
        let slopes = &self.slopes;
        let (travel_weight, track_weight, mean_weight) =
            (self.travel_weight, self.track_weight, self.mean_weight);
        let r = path.basis.len();
        let end = model.mesh.boundaries.len() - 1;
        self.workers
            .for_each_chunk(JOB_HESSIAN, &mut self.work, |j0, work| {
                for (i, w) in work.iter_mut().enumerate() {
                    let j = j0 + i;
                    let k = ks[j];
                    w.gz.clear();
                    w.gz.resize(nv, 0.0);
                    let Some(ii) = w.interior else { continue };
                    let row = ii * per;
                    path.add_chain(&w.gu, k, &mut w.gz);
                    let ha = &mut w.ha;
                    ha.clear();
                    ha.resize(n * n, 0.0);
                    let wj = weights[j] + mean_weight / nk;
                    let shape = &shapes[j];
                    model.add_energy_hessian(shape, objective, wj, ha);
                    let aj = &a[j];
                    w.y.copy_from_slice(&y[row..row + per]);
                    // The swept rows' share of this sample's obstacle rows, and their chord terms.
                    if let Some(sw) = swept {
                        sw.add_sample_weights(ii, &y[ns..], offsets, &mut w.y);
                    }
                    add_weighted_curvature(blocks, offsets, model, aj, shape, &w.y, &mut w.adj, ha);
                    if let Some(sw) = swept {
                        sw.add_chord_cotangents(ii, &y[ns..], &interior_shapes, &mut w.adj);
                    }
                    let slope = slope_of(slopes, j);
                    let target = targets
                        .as_ref()
                        .filter(|_| tracked)
                        .map(|t| (&t[j][..], slope));
                    let weights = (track_weight, travel_weight);
                    let tracked_at =
                        add_track_travel(&mut w.adj, model, aj, shapes, ks, j, target, weights);
                    if let Some((wt, points)) = tracked_at {
                        model.add_positions_gauss_newton(shape, &vec![wt; points], ha);
                        if let Some(sl) = slope {
                            sl.add_gauss_newton(model, aj, shape, wt, ha);
                        }
                    }
                    w.adj.finish_hessian(model, shape, ha);
                    let sj = &s[row..row + per];
                    add_penalty_gauss_newton(blocks, offsets, model, aj, shape, sj, &mut w.adj, ha);
                    w.hm.resize(r * r, 0.0);
                    path.project_hessian(&w.ha, &mut w.hm);
                    if travel_weight != 0.0 {
                        let rows = model.position_jacobian(shape, end);
                        for (out, r) in w.end_jac.iter_mut().zip(&rows) {
                            out.clear();
                            out.resize(nv, 0.0);
                            path.add_chain(r, k, out);
                        }
                    }
                }
            });
        for (j, w) in self.work.iter().enumerate() {
            if w.interior.is_some() {
                for (b, v) in gbar.iter_mut().zip(&w.gz) {
                    *b += self.weights[j] * v;
                }
                self.path.add_projected_hessian(&w.hm, self.ks[j], 1.0, h);
            }
        }
        if let Some(sw) = &self.swept {
            let kin: Vec<f64> = self.interior.iter().map(|&i| self.ks[i]).collect();
            let a: Vec<&[f64]> = self.interior.iter().map(|&i| &self.a[i][..]).collect();
            sw.add_coupling_hessian(
                &self.model,
                &self.path,
                &self.blocks,
                &kin,
                &a,
                &interior_shapes,
                &y[ns..],
                &s[ns..],
                h,
            );
        }
        // The travel term's Gauss–Newton part: for each interval, `w/Δk DᵀD` with `D` the
        // z-Jacobian of `x(kⱼ₊₁) − x(kⱼ)` (the path's ends are fixed and contribute none).
        // (The z-Jacobians of the end's position at the interior samples, from the chunks.)
        if self.travel_weight != 0.0 {
            let jac = |j: usize| {
                let w = &self.work[j];
                w.interior.is_some().then_some(&w.end_jac)
            };
            for j in 0..self.ks.len().saturating_sub(1) {
                let w = self.travel_weight / (self.ks[j + 1] - self.ks[j]);
                for c in 0..3 {
                    let mut d = vec![0.0; nv];
                    if let Some(r) = jac(j + 1) {
                        d.iter_mut().zip(&r[c]).for_each(|(v, x)| *v += x);
                    }
                    if let Some(r) = jac(j) {
                        d.iter_mut().zip(&r[c]).for_each(|(v, x)| *v -= x);
                    }
                    add_rank_one(h, w, &d);
                }
            }
        }
        for (j, w) in self.work.iter().enumerate() {
            add_rank_one(h, self.beta * self.weights[j], &w.gz);
        }
        add_rank_one(h, -self.beta, &gbar);
    }
}
