//! The `plan` section of a case file: start and goal, and the planner's settings. Parsed with
//! serde (`deny_unknown_fields`) and validated into [`PlanOptions`]; every field is documented
//! in the README.

use crate::case::{Case, ShapeSpec, V, coefficients};
use crate::error::Error;
use serde::Deserialize;

/// The `plan` section as written.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanSpec {
    /// Initial shape.
    pub start: EndSpec,
    /// Goal shape.
    pub goal: EndSpec,
    /// Path terms `m` (paper: 3).
    #[serde(default = "d_terms")]
    pub path_terms: usize,
    /// Path-term counts tried in turn, with the same starts, while no plan so far is estimated
    /// to coincide with its replay (default: none).
    #[serde(default)]
    pub fallback_path_terms: Vec<usize>,
    /// Samples of `k` seen by the optimiser, including 0 and 1.
    #[serde(default = "d_k")]
    pub k_samples: usize,
    /// Samples of `k` on the verification grid.
    #[serde(default = "d_vk")]
    pub verify_k_samples: usize,
    /// Intervals of `s` on the verification grid.
    #[serde(default = "d_vs")]
    pub verify_s_samples: usize,
    /// Extra clearance (case length units) the optimiser keeps from obstacles, so that the path
    /// between its samples stays clear. Default `L/100`.
    pub safety_margin: Option<f64>,
    /// Weight of the mean energy along the path in the objective (see the README).
    #[serde(default = "d_mean")]
    pub mean_weight: f64,
    /// Weight of the equilibrium-tracking term (0 = the paper's objective alone).
    #[serde(default = "d_track")]
    pub equilibrium_weight: f64,
    /// Most rounds of equilibrium tracking (replay at the samples, then re-optimise).
    #[serde(default = "d_rounds")]
    pub equilibrium_rounds: usize,
    /// Tracking stops once the sampled shapes lie within this fraction of
    /// `coincide_tolerance` from their equilibria (0: only the rounds' budget and their
    /// progress stop it).
    #[serde(default = "d_track_stop")]
    pub equilibrium_stop: f64,
    /// Continuation of the smoothed maximum's sharpness, in units of `1/U_ref`.
    #[serde(default = "d_sharp")]
    pub sharpness: Vec<f64>,
    /// Independent optimiser starts (run in parallel, each verified and refined on its own; the
    /// collision-free one with the lowest verified `U_max` wins).
    #[serde(default = "d_starts")]
    pub starts: usize,
    /// Starts run side by side in groups of this many; a group runs only when no plan of an
    /// earlier group is estimated to coincide with its replay (default: all starts at once).
    pub parallel_starts: Option<usize>,
    /// Seed of the starts' pseudo-random perturbations.
    #[serde(default = "d_seed")]
    pub seed: u64,
    /// Size (radians) of the extra starts' perturbations.
    #[serde(default = "d_spread")]
    pub start_spread: f64,
    /// Rounds of adding samples where the verification grid finds tunnelling or an energy peak
    /// the samples missed.
    #[serde(default = "d_sample_ref")]
    pub sample_refinements: usize,
    /// Relative excess of the verification grid's `U_max` over the optimiser's sampled maximum
    /// beyond which the peak's `k` is added to the samples.
    #[serde(default = "d_energy_gap")]
    pub energy_gap_tolerance: f64,
    /// Replay steps in `k` (refined where the replayed shape jumps).
    #[serde(default = "d_steps")]
    pub replay_steps: usize,
    /// Largest number of bisections of one replay step.
    #[serde(default = "d_refine")]
    pub replay_refinements: usize,
    /// The paths coincide when `max_k d(k) ≤ tolerance · L`.
    #[serde(default = "d_tol")]
    pub coincide_tolerance: f64,
    /// Inner minimiser of the path optimisation's multiplier method.
    #[serde(default)]
    pub optimiser: Optimiser,
    /// Keep the chord between consecutive samples' positions of every obstacle sample point
    /// clear (see [`crate::planner::swept`]).
    #[serde(default = "d_swept")]
    pub swept_clearance: bool,
}

/// Inner minimiser of the path optimisation's sharpness stages (see the README for what each
/// finds); the equilibrium-tracking rounds always take Newton steps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Optimiser {
    /// BFGS on the augmented function (the default).
    #[default]
    Bfgs,
    /// Damped Newton with the analytic Hessian: it settles in other local minima, whose shapes
    /// lie farther from the equilibria.
    Newton,
}

/// The path-term counts accepted (`plan.path_terms` and each of `plan.fallback_path_terms`).
const PATH_TERMS: (usize, usize) = (1, 12);

fn d_swept() -> bool {
    false
}

fn d_terms() -> usize {
    3
}
fn d_k() -> usize {
    41
}
fn d_vk() -> usize {
    201
}
fn d_vs() -> usize {
    256
}
fn d_mean() -> f64 {
    1.0
}
fn d_track() -> f64 {
    // With 1000 and three rounds, 7 of 24 random planar start–goal pairs coincided; with this
    // and eight, 14 (every one of the 7 among them; see the README).
    10_000.0
}
fn d_rounds() -> usize {
    8
}
fn d_track_stop() -> f64 {
    0.1
}
fn d_sharp() -> Vec<f64> {
    // Two decades in the R5 preferred-number steps (×≈1.6 per stage): a continuation this fine
    // reaches the paper's coinciding plan from 29 of 32 starts, [10, 100, 1000] from 3 of 16.
    vec![
        10.0, 16.0, 25.0, 40.0, 63.0, 100.0, 160.0, 250.0, 400.0, 630.0, 1000.0,
    ]
}
fn d_starts() -> usize {
    1
}
fn d_seed() -> u64 {
    1
}
fn d_spread() -> f64 {
    0.5
}
fn d_sample_ref() -> usize {
    4
}
fn d_energy_gap() -> f64 {
    0.01
}
fn d_steps() -> usize {
    40
}
fn d_refine() -> usize {
    4
}
fn d_tol() -> f64 {
    0.02
}

/// A start or goal: the controlled end's pose (solved as a static shape), or coefficients.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EndSpec {
    /// x of `P(L)`.
    pub x: Option<f64>,
    /// y of `P(L)` (spatial rods).
    pub y: Option<f64>,
    /// z of `P(L)`.
    pub z: Option<f64>,
    /// φ at `s = L` (spatial rods).
    pub phi: Option<f64>,
    /// θ at `s = L`.
    pub theta: Option<f64>,
    /// ψ at `s = L` (spatial rods).
    pub psi: Option<f64>,
    /// `[x, y, z]` of `P(L)`, instead of `x`, `y`, `z` (`y` must be 0 on a planar rod).
    pub position: Option<[f64; 3]>,
    /// The end's orientation as a unit quaternion `[w, x, y, z]` (case frame), instead of Euler
    /// angles.
    pub quaternion: Option<[f64; 4]>,
    /// The end's tangent direction (any length), instead of Euler angles; with `twist`.
    pub tangent: Option<[f64; 3]>,
    /// With `tangent`: the turn (radians) about the tangent from the twist-free frame (the
    /// shortest-arc rotation of the natural state's +z onto the tangent). Default 0.
    pub twist: Option<f64>,
    /// How a full orientation (all three Euler angles, a quaternion or a tangent) becomes the
    /// rod's angles: `"nearest"` (default) picks the branch that continues from the held end
    /// (start) or the start shape (goal), so equivalent spellings give the same plan;
    /// `"as_written"` keeps Euler angles exactly as written (e.g. to ask for an extra turn of
    /// twist).
    #[serde(default)]
    pub euler_branch: EulerBranch,
    /// Explicit coefficients: the shape itself when no pose is given, else the solve's start.
    pub shape: Option<ShapeSpec>,
}

/// See [`EndSpec::euler_branch`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EulerBranch {
    /// The branch continuing from the reference frame.
    #[default]
    Nearest,
    /// Euler angles exactly as written.
    AsWritten,
}

impl EndSpec {
    /// Whether any pose component is given.
    pub fn has_pose(&self) -> bool {
        [self.x, self.y, self.z, self.phi, self.theta, self.psi]
            .iter()
            .any(Option::is_some)
            || self.position.is_some()
            || self.quaternion.is_some()
            || self.tangent.is_some()
    }
}

/// A full orientation of an end, resolved into Euler angles once its reference frame is known
/// (see [`super::orientation`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EndRotation {
    /// The rotation (row-major, case frame).
    pub matrix: [[f64; 3]; 3],
    /// The `φ` the user wrote, if the rotation came from Euler angles (it breaks the tie
    /// between mirror routes).
    pub written_phi: Option<f64>,
}

/// A validated end: pose rows in dimensionless units plus an optional coefficient vector.
#[derive(Clone, Debug)]
pub struct End {
    /// `(component, x/L)` rows.
    pub position: Vec<(usize, f64)>,
    /// `(field, angle)` rows (filled from `rotation` when that is given).
    pub angles: Vec<(crate::rod::layout::Field, f64)>,
    /// A full orientation whose Euler branch is still to be chosen.
    pub rotation: Option<EndRotation>,
    /// Coefficients (the shape, or the solve's start).
    pub shape: Option<Vec<f64>>,
}

impl End {
    /// Whether the end is a pose (to be solved for), not only coefficients.
    pub fn is_pose(&self) -> bool {
        !self.position.is_empty() || !self.angles.is_empty() || self.rotation.is_some()
    }

    /// Fills in the angles of a full orientation, in the branch that continues from
    /// `reference` (the Euler angles of the frame it continues from; see
    /// [`super::orientation`]). Errors name the problem (a planar rod's end turned about
    /// another axis than y).
    pub fn resolve(
        &mut self,
        model: &crate::rod::model::Model,
        reference: [f64; 3],
    ) -> Result<(), String> {
        let planar = !model.layout.spatial;
        use crate::rod::layout::Field;
        let Some(r) = self.rotation.take() else {
            return Ok(());
        };
        if planar {
            let theta = super::orientation::planar_branch(r.matrix, reference[1]).ok_or(
                "a planar rod's end turns about y only: the orientation is not a rotation about y",
            )?;
            self.angles = vec![(Field::Theta, theta)];
        } else {
            // In the rod's angles' frame; a written φ is the case's, not the fields'.
            let written_phi = r.written_phi.filter(|_| model.frame.is_none());
            let matrix = model.rotation_to_angles(r.matrix);
            let [phi, theta, psi] =
                super::orientation::euler_branch(matrix, reference, written_phi);
            self.angles = vec![(Field::Phi, phi), (Field::Theta, theta), (Field::Psi, psi)];
        }
        Ok(())
    }
}

/// Validated planner settings.
#[derive(Clone, Debug)]
pub struct PlanOptions {
    /// Start.
    pub start: End,
    /// Goal.
    pub goal: End,
    /// Path terms `m`.
    pub terms: usize,
    /// Path-term counts tried in turn while no plan is estimated to coincide.
    pub fallback_terms: Vec<usize>,
    /// Optimiser `k` samples (including ends).
    pub k_samples: usize,
    /// Verification `k` samples.
    pub verify_k: usize,
    /// Verification `s` intervals.
    pub verify_s: usize,
    /// Safety margin (dimensionless, units of `L`).
    pub safety: f64,
    /// Mean-energy weight.
    pub mean_weight: f64,
    /// Equilibrium-tracking weight.
    pub track_weight: f64,
    /// Most equilibrium-tracking rounds.
    pub track_rounds: usize,
    /// Tracking stops below this fraction of the coincidence tolerance.
    pub track_stop: f64,
    /// Sharpness stages.
    pub sharpness: Vec<f64>,
    /// Number of starts.
    pub starts: usize,
    /// Starts run side by side; the next group only when no earlier plan is estimated to
    /// coincide.
    pub parallel_starts: usize,
    /// Seed.
    pub seed: u64,
    /// Perturbation of extra starts (radians).
    pub spread: f64,
    /// Rounds of sample refinement against tunnelling and missed energy peaks.
    pub sample_refinements: usize,
    /// Relative energy excess that triggers a refinement.
    pub energy_gap: f64,
    /// Replay steps.
    pub replay_steps: usize,
    /// Bisections per replay step.
    pub refinements: usize,
    /// Coincidence tolerance (fraction of `L`).
    pub tolerance: f64,
    /// Inner minimiser of the path optimisation.
    pub optimiser: Optimiser,
    /// Swept-clearance rows between consecutive samples.
    pub swept: bool,
}

/// The full orientation of an end, if it has one: its quaternion, its tangent and twist, or
/// (on a 3D rod, unless `euler_branch` is `as_written`) all three of its Euler angles, which
/// are then taken out of `angles` to be resolved later.
fn end_rotation(
    v: &V,
    name: &str,
    e: &EndSpec,
    angles: &mut Vec<(crate::rod::layout::Field, f64)>,
    spatial: bool,
) -> Result<Option<EndRotation>, Error> {
    let f = |x: &str| format!("plan.{name}.{x}");
    let forms = [
        ("quaternion", e.quaternion.is_some()),
        ("tangent", e.tangent.is_some()),
        ("phi/theta/psi", !angles.is_empty()),
    ];
    let given: Vec<&str> = forms.iter().filter(|g| g.1).map(|g| g.0).collect();
    if given.len() > 1 {
        return Err(v.err(
            f(given[1].split('/').next().unwrap_or("quaternion")),
            format!(
                "give one orientation: {} and {} are both given",
                given[0], given[1]
            ),
        ));
    }
    if e.twist.is_some() && e.tangent.is_none() {
        return Err(v.err(
            f("twist"),
            "`twist` turns the end about its `tangent`: give `tangent` too",
        ));
    }
    if let Some(q) = e.quaternion {
        for (i, c) in q.iter().enumerate() {
            v.finite(&format!("plan.{name}.quaternion[{i}]"), *c)?;
        }
        let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
        if (n - 1.0).abs() > 1e-6 {
            return Err(v.err(
                f("quaternion"),
                format!("must be a unit quaternion [w, x, y, z]: its norm is {n}"),
            ));
        }
        return Ok(Some(EndRotation {
            matrix: super::trajectory::rotation_of_quaternion(q),
            written_phi: None,
        }));
    }
    if let Some(t) = e.tangent {
        for (i, c) in t.iter().enumerate() {
            v.finite(&format!("plan.{name}.tangent[{i}]"), *c)?;
        }
        let n = t.iter().map(|c| c * c).sum::<f64>().sqrt();
        if !n.is_finite() || n <= 0.0 {
            return Err(v.err(f("tangent"), "must be a non-zero direction"));
        }
        let twist = v.finite(&f("twist"), e.twist.unwrap_or(0.0))?;
        if !spatial && (t[1] != 0.0 || twist != 0.0) {
            return Err(v.err(
                f(if t[1] != 0.0 { "tangent" } else { "twist" }),
                "a planar rod's tangent lies in the x–z plane (y = 0) and has no twist",
            ));
        }
        return Ok(Some(EndRotation {
            matrix: super::orientation::tangent_twist(t, twist),
            written_phi: None,
        }));
    }
    if e.euler_branch == EulerBranch::AsWritten {
        return Ok(None);
    }
    use crate::rod::layout::Field;
    let get = |fld| angles.iter().find(|(g, _)| *g == fld).map(|x| x.1);
    let full = if spatial {
        match (get(Field::Phi), get(Field::Theta), get(Field::Psi)) {
            (Some(phi), Some(theta), Some(psi)) => {
                Some((crate::rod::kinematics::rotation(phi, theta, psi), Some(phi)))
            }
            _ => None,
        }
    } else {
        // A planar θ has one spelling per shape (θ + 2π is another shape: a loop): as written.
        None
    };
    Ok(full.map(|(matrix, written_phi)| {
        angles.clear();
        EndRotation {
            matrix,
            written_phi,
        }
    }))
}

/// Reads and validates the case's `plan` section.
pub fn plan_options(case: &Case) -> Result<PlanOptions, Error> {
    let v = V { path: &case.path };
    let raw = case
        .plan
        .clone()
        .ok_or_else(|| v.err("plan", "missing: `dlo plan` needs a `plan` section"))?;
    let spec: PlanSpec = serde_json::from_value(raw).map_err(|e| v.err("plan", e.to_string()))?;
    let model = &case.problem.model;
    let layout = model.layout;
    if layout.free_base {
        return Err(v.err(
            "base.free",
            "planning holds the base fixed (the held end); a free base is not supported",
        ));
    }
    let l = model.rod.length;
    let end = |name: &str, e: &EndSpec| -> Result<End, Error> {
        let f = |x: &str| format!("plan.{name}.{x}");
        let mut position = Vec::new();
        let xyz = [("x", e.x), ("y", e.y), ("z", e.z)];
        if let Some(p) = e.position {
            if let Some((nm, _)) = xyz.iter().find(|(_, val)| val.is_some()) {
                return Err(v.err(
                    f(nm),
                    "give the position as `position` or as x, y, z, not both",
                ));
            }
            for (k, val) in p.into_iter().enumerate() {
                let val = v.finite(&format!("plan.{name}.position[{k}]"), val)?;
                if layout.components().contains(&k) {
                    position.push((k, val / l));
                } else if val != 0.0 {
                    return Err(v.err(
                        format!("plan.{name}.position[1]"),
                        "a planar rod lies in the x–z plane: y must be 0",
                    ));
                }
            }
        }
        for (k, (nm, val)) in xyz.into_iter().enumerate() {
            let Some(val) = val else { continue };
            if !layout.components().contains(&k) {
                if val == 0.0 {
                    continue;
                }
                return Err(v.err(
                    f(nm),
                    "a planar rod lies in the x–z plane: y must be 0 or absent",
                ));
            }
            position.push((k, v.finite(&f(nm), val)? / l));
        }
        let mut angles = Vec::new();
        for (nm, fld, val) in [
            ("phi", crate::rod::layout::Field::Phi, e.phi),
            ("theta", crate::rod::layout::Field::Theta, e.theta),
            ("psi", crate::rod::layout::Field::Psi, e.psi),
        ] {
            let Some(val) = val else { continue };
            if layout.offset(fld).is_none() {
                return Err(v.err(f(nm), "a planar rod has only theta"));
            }
            angles.push((fld, v.finite(&f(nm), val)?));
        }
        let rotation = end_rotation(&v, name, e, &mut angles, layout.spatial)?;
        if !position.is_empty() && !layout.extensible {
            let d2: f64 = position.iter().map(|(_, x)| x * x).sum::<f64>();
            let base = model.base;
            let full = position.len() == layout.components().len();
            let d = if full {
                position
                    .iter()
                    .map(|&(k, x)| (x - base[k]).powi(2))
                    .sum::<f64>()
                    .sqrt()
            } else {
                0.0
            };
            let _ = d2;
            if d > 1.0 + 1e-12 {
                return Err(v.err(
                    format!("plan.{name}"),
                    format!(
                        "unreachable: the end is {} from the base but the inextensible rod is only {l} long",
                        d * l
                    ),
                ));
            }
        }
        let shape = match &e.shape {
            Some(sh) => Some(coefficients(
                &v,
                &format!("plan.{name}.shape"),
                sh,
                &layout,
                model.base,
            )?),
            None => None,
        };
        if position.is_empty() && angles.is_empty() && rotation.is_none() && shape.is_none() {
            return Err(v.err(
                format!("plan.{name}"),
                "give the end pose (x, y, z or position; phi, theta, psi or quaternion or tangent) or `shape` coefficients",
            ));
        }
        Ok(End {
            position,
            angles,
            rotation,
            shape,
        })
    };
    let start = end("start", &spec.start)?;
    let goal = end("goal", &spec.goal)?;
    let (terms_lo, terms_hi) = PATH_TERMS;
    for (field, val, lo, hi) in [
        ("plan.path_terms", spec.path_terms, terms_lo, terms_hi),
        ("plan.k_samples", spec.k_samples, 3, 2001),
        ("plan.verify_k_samples", spec.verify_k_samples, 3, 100_001),
        ("plan.verify_s_samples", spec.verify_s_samples, 2, 10_000),
        ("plan.starts", spec.starts, 1, 64),
        ("plan.replay_steps", spec.replay_steps, 1, 100_000),
        ("plan.replay_refinements", spec.replay_refinements, 0, 20),
        ("plan.sample_refinements", spec.sample_refinements, 0, 20),
    ] {
        if !(lo..=hi).contains(&val) {
            return Err(v.err(field, format!("must be in {lo}..={hi}, got {val}")));
        }
    }
    for (i, &t) in spec.fallback_path_terms.iter().enumerate() {
        if !(terms_lo..=terms_hi).contains(&t) {
            return Err(v.err(
                format!("plan.fallback_path_terms[{i}]"),
                format!("must be in {terms_lo}..={terms_hi}, got {t}"),
            ));
        }
    }
    let parallel_starts = spec.parallel_starts.unwrap_or(spec.starts);
    if !(1..=spec.starts).contains(&parallel_starts) {
        return Err(v.err(
            "plan.parallel_starts",
            format!(
                "must be in 1..=plan.starts ({}), got {parallel_starts}",
                spec.starts
            ),
        ));
    }
    // Grid points of one verification pass.
    let grid = spec.verify_k_samples.saturating_mul(spec.verify_s_samples);
    if grid > 10_000_000 {
        return Err(v.err(
            "plan.verify_k_samples",
            format!("verify_k_samples × verify_s_samples = {grid}; at most 1e7"),
        ));
    }
    if spec.sharpness.len() > 50 || spec.fallback_path_terms.len() > 8 {
        return Err(v.err(
            if spec.sharpness.len() > 50 {
                "plan.sharpness"
            } else {
                "plan.fallback_path_terms"
            },
            "at most 50 sharpness stages and 8 fallback path-term counts",
        ));
    }
    let safety = spec.safety_margin.unwrap_or(l / 100.0);
    if !(0.0..=0.25 * l).contains(&v.finite("plan.safety_margin", safety)?) {
        return Err(v.err(
            "plan.safety_margin",
            format!("must be in [0, L/4] = [0, {}], got {safety}", 0.25 * l),
        ));
    }
    if v.finite("plan.mean_weight", spec.mean_weight)? < 0.0 {
        return Err(v.err("plan.mean_weight", "must be non-negative"));
    }
    if v.finite("plan.equilibrium_weight", spec.equilibrium_weight)? < 0.0 {
        return Err(v.err("plan.equilibrium_weight", "must be non-negative"));
    }
    if spec.equilibrium_rounds > 50 {
        return Err(v.err("plan.equilibrium_rounds", "must be at most 50"));
    }
    let stop = v.finite("plan.equilibrium_stop", spec.equilibrium_stop)?;
    if !(0.0..1.0).contains(&stop) {
        return Err(v.err(
            "plan.equilibrium_stop",
            format!("must be in [0, 1) (a fraction of coincide_tolerance), got {stop}"),
        ));
    }
    if spec.sharpness.is_empty() {
        return Err(v.err("plan.sharpness", "needs at least one value"));
    }
    for (i, b) in spec.sharpness.iter().enumerate() {
        v.positive(&format!("plan.sharpness[{i}]"), *b)?;
    }
    v.finite("plan.start_spread", spec.start_spread)?;
    if v.finite("plan.energy_gap_tolerance", spec.energy_gap_tolerance)? < 0.0 {
        return Err(v.err("plan.energy_gap_tolerance", "must be non-negative"));
    }
    v.positive("plan.coincide_tolerance", spec.coincide_tolerance)?;
    // Fixed conditions may not sit on the controlled end.
    for (i, c) in case.file.constraints.iter().enumerate() {
        use crate::case::ConstraintSpec as C;
        let s = match c {
            C::Position { s, .. } | C::Orientation { s, .. } => *s,
            C::RelativePosition { s_a, s_b, .. } => s_a.max(*s_b),
        };
        if (s - l).abs() <= 1e-12 * l {
            return Err(v.err(
                format!("constraints[{i}].s"),
                "in a plan s = L is the controlled end: its pose comes from plan.start/goal, not from a fixed constraint",
            ));
        }
    }
    Ok(PlanOptions {
        start,
        goal,
        terms: spec.path_terms,
        fallback_terms: spec.fallback_path_terms,
        k_samples: spec.k_samples,
        verify_k: spec.verify_k_samples,
        verify_s: spec.verify_s_samples,
        safety: safety / l,
        mean_weight: spec.mean_weight,
        track_weight: spec.equilibrium_weight,
        track_rounds: spec.equilibrium_rounds,
        track_stop: stop,
        sharpness: spec.sharpness,
        starts: spec.starts,
        parallel_starts,
        seed: spec.seed,
        spread: spec.start_spread,
        sample_refinements: spec.sample_refinements,
        energy_gap: spec.energy_gap_tolerance,
        replay_steps: spec.replay_steps,
        refinements: spec.replay_refinements,
        tolerance: spec.coincide_tolerance,
        optimiser: spec.optimiser,
        swept: spec.swept_clearance,
    })
}
