//! The disturbance force margin (paper §6.1–6.2). A disturbance `f n` acts at `P(s_a)`; the
//! basis is split there (two coefficient sets, continuous at `s_a`) and the force does the work
//! `W = f n · (x(s_a) − x0(s_a))`. `F(s_a, n)` is the largest `f` for which every contact holds
//! and every contact force stays in its friction cone; `F_mub = min over s_a, n`.
//!
//! The search along `f` is a continuation (each solve warm-started from the previous `f`) up to
//! `f_max`, followed by bisection of the step where a contact is lost. The friction cone depends
//! on `μ` only through the check, so one sweep serves every `μ`: each finger's normal and
//! tangential forces are interpolated linearly in `f` between steps, and `|f_t| = μ f_n` is
//! solved on that interpolation (exact where the forces are linear in `f`).

use super::fingers::{ContactForce, Finger, contact_forces, fingers, friction_ratio};
use crate::error::{Num, SettingsError};
use crate::statics::builder::{BuildError, StaticProblemBuilder};
use crate::statics::problem::StaticProblem;
use crate::statics::{
    SolveStatus, StaticOptions, StaticSettings, StaticSolution, solve_static, solve_static_warm,
};
use serde::{Deserialize, Serialize};

/// What to rate: the held rod (fingers are its position constraints with one unilateral bound,
/// see [`super::fingers`]) as a recipe, so that the margin can rebuild it with the basis split
/// at each point of action.
#[derive(Clone, Debug)]
pub struct GraspProblem {
    /// The grasped rod's static problem, unbuilt.
    pub statics: StaticProblemBuilder,
    /// The start of the undisturbed solve.
    pub initial: Vec<f64>,
    /// Static solver settings (the disturbed solves use them without stability checks and with
    /// a relative optimality tolerance no tighter than 1e-5).
    pub static_settings: StaticSettings,
}

/// Disturbance directions: a number spread evenly in the x–z plane, or explicit vectors
/// `[n_z, n_x]` (planar, the paper's order) / `[n_x, n_y, n_z]` (3D).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(
    untagged,
    expecting = "expected a count or a list of vectors of numbers"
)]
pub enum Directions {
    /// Evenly spread directions.
    Count(u64),
    /// Explicit vectors (any length).
    Vectors(Vec<Vec<f64>>),
}

/// Settings of a margin computation: the case file's `grasp` section.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(
    deny_unknown_fields,
    default,
    expecting = "an object of grasp settings (`points`, `directions`, …)"
)]
pub struct GraspSettings {
    /// Pinch preload `r0` (case force units); required when the grasp has a pinch.
    pub preload: Option<f64>,
    /// Points of action `s_a` (case length units). Default: nine points `L(j+1)/10`.
    pub points: Option<Vec<f64>>,
    /// Directions: a number of evenly spread directions in the x–z plane, or explicit vectors
    /// `[n_z, n_x]` (planar) / `[n_x, n_y, n_z]` (3D). Default: 9.
    pub directions: Option<Directions>,
    /// Friction coefficients. Default: 0.1, 0.2, …, 1.0.
    pub mu: Option<Vec<f64>>,
    /// Largest disturbance searched (case force units). Default: 5 × the largest initial
    /// contact normal force.
    pub f_max: Option<f64>,
    /// Continuation steps up to `f_max`.
    pub steps: usize,
    /// Bisections of the step where a contact is lost (at most 60 are used).
    pub bisections: usize,
}

impl Default for GraspSettings {
    fn default() -> Self {
        GraspSettings {
            preload: None,
            points: None,
            directions: None,
            mu: None,
            f_max: None,
            steps: 10,
            bisections: 6,
        }
    }
}

/// The most force limits one margin computes (points × directions).
const MAX_LIMITS: usize = 10_000;

/// The points, unit directions (3D vectors) and friction coefficients of [`GraspSettings`],
/// defaults filled in.
struct Resolved {
    points: Vec<f64>,
    directions: Vec<[f64; 3]>,
    mu: Vec<f64>,
}

impl GraspSettings {
    /// Checks the settings that do not depend on the grasp's solve for a rod of `length`,
    /// planar or 3D (`preload` and `f_max` are checked against the solved grasp by
    /// [`Grasp::new`]).
    pub fn validate(&self, length: f64, spatial: bool) -> Result<(), SettingsError> {
        self.resolve(length, spatial).map(|_| ())
    }

    fn resolve(&self, length: f64, spatial: bool) -> Result<Resolved, SettingsError> {
        let err = |f: &str, m: String| SettingsError::new(f, m);
        let l = length;
        let points = self
            .points
            .clone()
            .unwrap_or_else(|| (1..=9).map(|j| l * j as f64 / 10.0).collect());
        if points.is_empty() {
            return Err(err("points", "needs at least one point of action".into()));
        }
        if points.len() > 10_000 {
            return Err(err(
                "points",
                format!("at most 10000 points, got {}", points.len()),
            ));
        }
        for (i, s) in points.iter().enumerate() {
            if !(s.is_finite() && *s > 0.0 && *s < l) {
                return Err(err(
                    &format!("points[{i}]"),
                    format!("must be inside (0, {}), got {}", Num(l), Num(*s)),
                ));
            }
        }
        let directions = match &self.directions {
            None => even_directions(9),
            Some(Directions::Count(n)) => {
                if !(1..=360).contains(n) {
                    return Err(err(
                        "directions",
                        format!("a count must be in 1..=360, got {n}"),
                    ));
                }
                even_directions(*n as usize)
            }
            Some(Directions::Vectors(list)) => {
                if list.len() > 360 {
                    return Err(err(
                        "directions",
                        format!("a list holds at most 360 directions, got {}", list.len()),
                    ));
                }
                let mut out = Vec::new();
                for (i, d) in list.iter().enumerate() {
                    let f = format!("directions[{i}]");
                    let v = d;
                    let v3 = match (spatial, v.len()) {
                        (false, 2) => [v[1], 0.0, v[0]],
                        (true, 3) => [v[0], v[1], v[2]],
                        _ => {
                            return Err(err(
                                &f,
                                if spatial {
                                    "give [n_x, n_y, n_z]".into()
                                } else {
                                    "give [n_z, n_x] (the paper's order)".into()
                                },
                            ));
                        }
                    };
                    // Scaled by its largest component first, so that huge (or tiny) finite
                    // components do not overflow (or underflow) the norm.
                    let big = v3.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
                    if !(big.is_finite() && big > 0.0) {
                        return Err(err(&f, "must be a non-zero finite vector".into()));
                    }
                    let v3 = v3.map(|c| c / big);
                    let norm = (v3[0] * v3[0] + v3[1] * v3[1] + v3[2] * v3[2]).sqrt();
                    out.push(v3.map(|c| c / norm));
                }
                if out.is_empty() {
                    return Err(err("directions", "needs at least one direction".into()));
                }
                out
            }
        };
        // Each (point, direction) pair is a continuation of about 16 solves.
        if points.len() * directions.len() > MAX_LIMITS {
            return Err(err(
                "points",
                format!(
                    "{} points × {} directions = {} force limits; at most {MAX_LIMITS}",
                    points.len(),
                    directions.len(),
                    points.len() * directions.len()
                ),
            ));
        }
        let mu = self
            .mu
            .clone()
            .unwrap_or_else(|| (1..=10).map(|j| j as f64 / 10.0).collect());
        if mu.is_empty() {
            return Err(err("mu", "needs at least one friction coefficient".into()));
        }
        for (i, m) in mu.iter().enumerate() {
            if !(m.is_finite() && *m >= 0.0) {
                return Err(err(
                    &format!("mu[{i}]"),
                    format!("must be finite and ≥ 0, got {}", Num(*m)),
                ));
            }
        }
        if self.steps == 0 || self.steps > 10_000 {
            return Err(err(
                "steps",
                format!("must be in 1..=10000, got {}", self.steps),
            ));
        }
        Ok(Resolved {
            points,
            directions,
            mu,
        })
    }
}

/// A validated grasp problem with its undisturbed solution.
#[derive(Clone, Debug)]
pub struct Grasp {
    /// The problem.
    pub problem: GraspProblem,
    /// Its static problem, built.
    pub base: StaticProblem,
    /// The undisturbed grasp.
    pub initial: StaticSolution,
    /// Its contact forces.
    pub initial_forces: Vec<ContactForce>,
    /// The fingers.
    pub fingers: Vec<Finger>,
    /// Pinch preload.
    pub preload: f64,
    /// Points of action (case units).
    pub points: Vec<f64>,
    /// Unit directions (3D vectors).
    pub directions: Vec<[f64; 3]>,
    /// Friction coefficients.
    pub mu: Vec<f64>,
    /// Search cap.
    pub f_max: f64,
    /// Continuation steps.
    pub steps: usize,
    /// Bisections.
    pub bisections: usize,
    /// Static solver settings.
    pub options: StaticOptions,
}

/// `F(s_a, n)` for one point and direction.
#[derive(Clone, Debug, Serialize)]
pub struct Limit {
    /// Point of action (case units).
    pub s_a: f64,
    /// Direction (3D unit vector `[x, y, z]`).
    pub direction: [f64; 3],
    /// Where a contact is lost (`None`: held up to `f_max`).
    pub f_contact_lost: Option<f64>,
    /// The finger that lets go first.
    pub finger_lost: Option<String>,
    /// `F(s_a, n)` per `μ` (capped at `f_max`).
    pub f_limit: Vec<f64>,
    /// Solves that did not converge on the way (their states count as failures).
    pub unconverged: usize,
    /// The last shape that held (boundary positions, case units), for logs.
    #[serde(skip)]
    pub held_shape: Vec<[f64; 3]>,
}

/// The margin per `μ`.
#[derive(Clone, Debug, Serialize)]
pub struct Margin {
    /// Friction coefficients.
    pub mu: Vec<f64>,
    /// `F_mub` per `μ`.
    pub f_mub: Vec<f64>,
    /// Where it is attained, per `μ`.
    pub s_a: Vec<f64>,
    /// In which direction, per `μ`.
    pub direction: Vec<[f64; 3]>,
    /// Whether `F_mub` is the search cap (nothing failed up to `f_max`).
    pub capped: Vec<bool>,
    /// Search cap.
    pub f_max: f64,
    /// Initial contact forces per finger.
    pub initial_forces: Vec<(String, ContactForce)>,
    /// Every point and direction.
    pub table: Vec<Limit>,
}

/// A margin's report: what `dlo margin --json` prints (and the Python package returns).
#[derive(Clone, Debug, Serialize)]
pub struct MarginReport<'a> {
    /// Case name.
    pub case: &'a str,
    /// The margin.
    #[serde(flatten)]
    pub margin: &'a Margin,
    /// The MCAP log written, if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mcap: Option<String>,
    /// Wall-clock seconds of the margin computation.
    pub timing_s: f64,
}

impl Grasp {
    /// The undisturbed grasp's shape (case units, at the model's mesh boundaries).
    pub fn initial_points(&self) -> Vec<[f64; 3]> {
        let model = &self.base.model;
        let l = model.rod.length;
        model
            .evaluate(&self.initial.a)
            .positions
            .iter()
            .map(|p| p.map(|v| v * l))
            .collect()
    }

    /// Every finger's contact point on the undisturbed grasp (case units) and the unit direction
    /// it pushes the rod in (its normal).
    pub fn finger_contacts(&self) -> Vec<([f64; 3], [f64; 3])> {
        let points = self.initial_points();
        self.fingers
            .iter()
            .map(|f| {
                let mut n = [0.0; 3];
                n[f.normal_component] = f.normal_sign;
                (points[f.boundary], n)
            })
            .collect()
    }

    /// Checks `spec` and solves the undisturbed grasp. An error names a field of `spec`, or
    /// `constraints` for the grasp itself (no fingers, no undisturbed equilibrium).
    pub fn new(problem: GraspProblem, spec: GraspSettings) -> Result<Grasp, SettingsError> {
        let err = |f: &str, m: String| SettingsError::new(f, m);
        let base = problem
            .statics
            .clone()
            .build()
            .map_err(|e| err("constraints", e.to_string()))?;
        let l = base.model.rod.length;
        let fingers = fingers(&base);
        if fingers.is_empty() {
            return Err(err(
                "constraints",
                "no fingers: a finger is a position constraint with exactly one min/max bound (its normal) and equalities".into(),
            ));
        }
        let has_pinch = fingers.iter().any(|f| f.pinch_with.is_some());
        let preload = match (spec.preload, has_pinch) {
            (Some(p), _) if !(p.is_finite() && p >= 0.0) => {
                return Err(err(
                    "preload",
                    format!("must be finite and ≥ 0, got {}", Num(p)),
                ));
            }
            (Some(p), _) => p,
            (None, true) => {
                return Err(err(
                    "preload",
                    "required: the grasp has a pinch, whose squeeze rigid fingers leave undetermined".into(),
                ));
            }
            (None, false) => 0.0,
        };
        let mut p = base.clone();
        let initial = solve_static(&mut p, &problem.initial, &problem.static_settings.options());
        if initial.status != SolveStatus::Converged {
            return Err(err(
                "constraints",
                format!(
                    "the undisturbed grasp does not converge ({:?})",
                    initial.status
                ),
            ));
        }
        let initial_forces = contact_forces(&p, &fingers, &initial.lambda, preload);
        let spatial = base.model.layout.spatial;
        let Resolved {
            points,
            directions,
            mu,
        } = spec.resolve(l, spatial)?;
        let n0 = initial_forces.iter().map(|c| c.normal).fold(0.0, f64::max);
        let f_max = spec.f_max.unwrap_or(5.0 * n0.max(preload));
        if !(f_max.is_finite() && f_max > 0.0) {
            return Err(err(
                "f_max",
                format!("must be positive, got {}", Num(f_max)),
            ));
        }
        // The search bisects [0, f_max]: a cap many decades above the rod's force scale leaves
        // the bisection at that scale's resolution and reports a margin there.
        let fu = base.model.rod.force_unit();
        let f_cap = 1e6 * fu.max(n0).max(preload);
        if f_max > f_cap {
            return Err(err(
                "f_max",
                format!(
                    "{} is more than 10⁶ times the rod's force scale (Rf/L² = {fu:.3e}, the largest initial contact force {n0:.3e}, the preload {preload:.3e}): at most {f_cap:.3e}",
                    Num(f_max)
                ),
            ));
        }
        let static_settings = problem.static_settings.options();
        Ok(Grasp {
            problem,
            base,
            initial,
            initial_forces,
            fingers,
            preload,
            points,
            directions,
            mu,
            f_max,
            steps: spec.steps,
            bisections: spec.bisections.min(60),
            // Contact forces are compared at the 1e-4 level: a relative KKT tolerance of 1e-5
            // suffices, and no stability check is needed along the search.
            options: {
                let mut o = StaticOptions {
                    stability: false,
                    ..static_settings
                };
                o.al.optimality_tol = o.al.optimality_tol.max(1e-5);
                o
            },
        })
    }

    /// The problem with the basis split at `s_a` and a unit disturbance along `n` there, and
    /// the undisturbed shape in its coefficients.
    pub fn disturbed_problem(
        &self,
        s_a: f64,
        n: [f64; 3],
    ) -> Result<(StaticProblem, Vec<f64>), BuildError> {
        let m = &self.base.model;
        let l = m.rod.length;
        let x0 = m.position_at(&self.initial.a, s_a / l).map(|c| c * l);
        let disturbed = self
            .problem
            .statics
            .clone()
            .split_at(s_a)
            .load(s_a, n, x0)
            .build()?;
        // Map the undisturbed coefficients: left set = a, right increment = 0.
        let lay = disturbed.model.layout;
        let old = m.layout;
        let mut a = vec![0.0; lay.len()];
        for f in [
            crate::rod::layout::Field::Theta,
            crate::rod::layout::Field::Phi,
            crate::rod::layout::Field::Psi,
            crate::rod::layout::Field::Eps,
        ] {
            if let (Some(o_new), Some(o_old)) = (lay.offset(f), old.offset(f)) {
                a[o_new..o_new + old.nb()]
                    .copy_from_slice(&self.initial.a[o_old..o_old + old.nb()]);
            }
        }
        if let (Some(bn), Some(bo)) = (lay.base_offset(), old.base_offset()) {
            let k = lay.components().len();
            a[bn..bn + k].copy_from_slice(&self.initial.a[bo..bo + k]);
        }
        Ok((disturbed, a))
    }

    /// Solves the disturbed grasp at magnitude `f` (case force units) from `from`.
    fn solve_at(
        &self,
        p: &mut StaticProblem,
        f: f64,
        n: [f64; 3],
        from: &StaticSolution,
    ) -> StaticSolution {
        let fu = p.model.rod.force_unit();
        let last = p.model.loads.len() - 1;
        p.model.loads[last].force = n.map(|c| c * f / fu);
        let mut sol = if from.lambda.len() == crate::optim::Nlp::m(p) {
            solve_static_warm(p, &from.a, &from.lambda, &self.options)
        } else {
            solve_static(p, &from.a, &self.options)
        };
        if sol.status == SolveStatus::IterationLimit {
            sol = solve_static_warm(p, &sol.a, &sol.lambda, &self.options);
        }
        sol
    }

    /// `F(s_a, n)` for every `μ`.
    pub fn limit(&self, s_a: f64, n: [f64; 3]) -> Result<Limit, BuildError> {
        let (mut p, a0) = self.disturbed_problem(s_a, n)?;
        let scale = self
            .initial_forces
            .iter()
            .map(|c| c.normal)
            .fold(self.preload, f64::max);
        let mut prev = StaticSolution {
            a: a0,
            lambda: Vec::new(),
            ..self.initial.clone()
        };
        prev = self.solve_at(&mut p, 0.0, n, &prev);
        let mut unconverged = 0;
        let state =
            |p: &StaticProblem, sol: &StaticSolution| -> (Vec<ContactForce>, Option<usize>) {
                let forces = contact_forces(p, &self.fingers, &sol.lambda, self.preload);
                let lost = forces.iter().position(|c| c.normal <= 1e-9 * scale);
                (forces, lost)
            };
        let mut samples: Vec<(f64, Vec<ContactForce>)> = vec![(0.0, state(&p, &prev).0)];
        let mut lost_at: Option<(f64, f64, usize)> = None; // (good f, bad f, finger)
        if let (_, Some(i)) = state(&p, &prev) {
            lost_at = Some((0.0, 0.0, i));
        }
        let df = self.f_max / self.steps as f64;
        let mut good = prev.clone();
        if lost_at.is_none() {
            for i in 1..=self.steps {
                let f = df * i as f64;
                let sol = self.solve_at(&mut p, f, n, &good);
                let ok = sol.status == SolveStatus::Converged;
                if !ok {
                    unconverged += 1;
                }
                let (forces, lost) = state(&p, &sol);
                if let (true, None) = (ok, lost) {
                    samples.push((f, forces));
                    good = sol;
                } else {
                    lost_at = Some((f - df, f, lost.unwrap_or(usize::MAX)));
                    break;
                }
            }
        }
        // Bisect the step where a contact is lost.
        if let Some((mut lo, mut hi, mut finger)) = lost_at
            && hi > lo
        {
            let mut base = good.clone();
            for _ in 0..self.bisections {
                let mid = 0.5 * (lo + hi);
                let sol = self.solve_at(&mut p, mid, n, &base);
                let ok = sol.status == SolveStatus::Converged;
                let (forces, lost) = state(&p, &sol);
                if let (true, None) = (ok, lost) {
                    samples.push((mid, forces));
                    lo = mid;
                    base = sol.clone();
                    good = sol;
                } else {
                    if !ok {
                        unconverged += 1;
                    }
                    if let Some(i) = lost {
                        finger = i;
                    }
                    hi = mid;
                }
            }
            lost_at = Some((lo, hi, finger));
        }
        samples.sort_by(|a, b| a.0.total_cmp(&b.0));
        let l = p.model.rod.length;
        let held_shape = p
            .model
            .evaluate(&good.a)
            .positions
            .iter()
            .map(|x| x.map(|c| c * l))
            .collect();
        let f_contact = lost_at.map(|(lo, hi, _)| 0.5 * (lo + hi));
        let f_limit = self
            .mu
            .iter()
            .map(|&mu| {
                if friction_ratio(&samples[0].1, scale) > mu {
                    return 0.0;
                }
                // First f where some finger's |f_t| reaches μ f_n, on the linear interpolation
                // of its forces between consecutive samples.
                for w in samples.windows(2) {
                    let ((f0, c0), (f1, c1)) = (&w[0], &w[1]);
                    let mut first: Option<f64> = None;
                    for (a, b) in c0.iter().zip(c1) {
                        let g0 = a.tangential - mu * a.normal;
                        let g1 = b.tangential - mu * b.normal;
                        if g1 > 0.0 {
                            let s = if g0 >= 0.0 { 0.0 } else { -g0 / (g1 - g0) };
                            let f = f0 + s * (f1 - f0);
                            first = Some(first.map_or(f, |x: f64| x.min(f)));
                        }
                    }
                    if let Some(f) = first {
                        return f;
                    }
                }
                f_contact.unwrap_or(self.f_max)
            })
            .collect();
        Ok(Limit {
            s_a,
            direction: n,
            f_contact_lost: f_contact,
            finger_lost: lost_at.and_then(|(_, _, i)| self.fingers.get(i).map(|f| f.name.clone())),
            f_limit,
            unconverged,
            held_shape,
        })
    }

    /// The margin over every point and direction, in parallel; `progress(done, total)` is called
    /// as limits complete.
    pub fn margin(&self, progress: &(dyn Fn(usize, usize) + Sync)) -> Result<Margin, BuildError> {
        let jobs: Vec<(f64, [f64; 3])> = self
            .points
            .iter()
            .flat_map(|&s| self.directions.iter().map(move |&d| (s, d)))
            .collect();
        let total = jobs.len();
        let done = std::sync::atomic::AtomicUsize::new(0);
        let workers = std::thread::available_parallelism()
            .map_or(1, |n| n.get())
            .min(total.max(1));
        let mut results: Vec<Option<Result<Limit, BuildError>>> =
            (0..total).map(|_| None).collect();
        std::thread::scope(|sc| {
            let handles: Vec<_> = (0..workers)
                .map(|w| {
                    let jobs = &jobs;
                    let done = &done;
                    sc.spawn(move || {
                        (w..jobs.len())
                            .step_by(workers)
                            .map(|i| {
                                let r = self.limit(jobs[i].0, jobs[i].1);
                                let d = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                                progress(d, jobs.len());
                                (i, r)
                            })
                            .collect::<Vec<_>>()
                    })
                })
                .collect();
            for h in handles {
                for (i, r) in h.join().expect("margin worker") {
                    results[i] = Some(r);
                }
            }
        });
        let table: Vec<Limit> = results
            .into_iter()
            .map(|r| r.expect("every job ran"))
            .collect::<Result<_, _>>()?;
        let mut f_mub = Vec::new();
        let mut s_a = Vec::new();
        let mut direction = Vec::new();
        let mut capped = Vec::new();
        for k in 0..self.mu.len() {
            let best = table
                .iter()
                .min_by(|a, b| a.f_limit[k].total_cmp(&b.f_limit[k]))
                .expect("at least one job");
            f_mub.push(best.f_limit[k]);
            s_a.push(best.s_a);
            direction.push(best.direction);
            capped.push(best.f_limit[k] >= self.f_max);
        }
        Ok(Margin {
            mu: self.mu.clone(),
            f_mub,
            s_a,
            direction,
            capped,
            f_max: self.f_max,
            initial_forces: self
                .fingers
                .iter()
                .zip(&self.initial_forces)
                .map(|(f, c)| (f.name.clone(), *c))
                .collect(),
            table,
        })
    }
}

/// `k` unit directions evenly spread over the full circle of the x–z plane.
fn even_directions(k: usize) -> Vec<[f64; 3]> {
    (0..k)
        .map(|j| {
            let a = std::f64::consts::TAU * j as f64 / k as f64;
            [a.sin(), 0.0, a.cos()]
        })
        .collect()
}
