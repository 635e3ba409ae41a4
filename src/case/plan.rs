//! The `plan` section of a case file: start and goal as written, turned into the planner's
//! [`End`]s, and the settings ([`PlanSettings`], whose keys are the section's other keys).

use crate::case::{Case, ShapeSpec, V, coefficients};
use crate::error::Error;
use crate::planner::endpoints::{End, EndRotation};
use crate::planner::settings::PlanSettings;
use serde::Deserialize;

/// A start or goal: the controlled end's pose (solved as a static shape), or coefficients.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "an object: the end's pose (`position` or `x`, `y`, `z`, and its orientation) or its `shape`"
)]
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
        let matrix = crate::planner::trajectory::rotation_of_unit_quaternion(q)
            .map_err(|m| v.err(f("quaternion"), m))?;
        return Ok(Some(EndRotation {
            matrix,
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
            matrix: crate::planner::orientation::tangent_twist(t, twist),
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

/// Reads and validates the case's `plan` section: the start, the goal and the settings.
pub fn plan_section(case: &Case) -> Result<(End, End, PlanSettings), Error> {
    let v = V { path: &case.path };
    let raw = case
        .plan
        .clone()
        .ok_or_else(|| v.err("plan", "missing: `dlo plan` needs a `plan` section"))?;
    let (start, goal, settings) =
        split(raw).map_err(|(field, e)| v.err(super::field_path::join("plan", &field), e))?;
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
    let start = end("start", &start)?;
    let goal = end("goal", &goal)?;
    settings
        .validate(l)
        .map_err(|e| v.err(format!("plan.{}", e.field), e.message))?;
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
    Ok((start, goal, settings))
}

/// The section's `start` and `goal`, and its other keys as settings; an error names the field
/// inside the section it is at (empty: the section itself).
fn split(raw: serde_json::Value) -> Result<(EndSpec, EndSpec, PlanSettings), (String, String)> {
    use super::field_path::read_in;
    let serde_json::Value::Object(mut map) = raw else {
        return Err((String::new(), "must be an object".into()));
    };
    let mut take = |key: &str| -> Result<EndSpec, (String, String)> {
        let value = map
            .remove(key)
            .ok_or_else(|| (String::new(), format!("missing field `{key}`")))?;
        read_in(key, value)
    };
    let start = take("start")?;
    let goal = take("goal")?;
    let settings = read_in("", serde_json::Value::Object(map))?;
    Ok((start, goal, settings))
}

/// The case's `plan` section as a [`PlanProblem`](crate::planner::PlanProblem) and
/// [`PlanSettings`] for [`Planner::new`](crate::planner::Planner::new).
pub fn plan_problem(case: &Case) -> Result<(crate::planner::PlanProblem, PlanSettings), Error> {
    let (start, goal, settings) = plan_section(case)?;
    let problem = crate::planner::PlanProblem {
        statics: case.problem.clone(),
        obstacles: case.obstacles.clone(),
        start,
        goal,
        initial: case.initial.clone(),
        static_settings: case.file.solver,
    };
    Ok((problem, settings))
}

/// A [`Planner::new`](crate::planner::Planner::new) error in the case file's terms (the
/// field of its `plan` section).
pub fn setup_error(case: &Case, e: crate::planner::PlanSetupError) -> Error {
    use crate::planner::PlanSetupError;
    match e {
        PlanSetupError::Settings(s) => {
            Error::invalid(&case.path, format!("plan.{}", s.field), s.message)
        }
        PlanSetupError::Problem(m) => Error::invalid(&case.path, "base.free", m),
        PlanSetupError::End { end, message } | PlanSetupError::Unreachable { end, message } => {
            Error::invalid(&case.path, format!("plan.{end}"), message)
        }
    }
}

impl crate::planner::Planner {
    /// Validates the case's `plan` section and solves the start and goal shapes
    /// ([`plan_problem`], then [`planner`]).
    pub fn from_case(case: &Case) -> Result<crate::planner::Planner, Error> {
        let (problem, settings) = plan_problem(case)?;
        planner(case, problem, settings).map_err(|e| setup_error(case, e))
    }
}

/// The planner of `case`'s `problem` ([`plan_problem`]) with `settings`, made with more
/// contact samples where an end shape dips between the case's
/// ([`Planner::with_contact_samples`](crate::planner::Planner::with_contact_samples)).
pub fn planner(
    case: &Case,
    problem: crate::planner::PlanProblem,
    settings: PlanSettings,
) -> Result<crate::planner::Planner, crate::planner::PlanSetupError> {
    crate::planner::Planner::with_contact_samples(&case.builder, problem, settings)
}
