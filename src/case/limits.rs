//! Bounds that keep a run's time and memory bounded and its arithmetic finite, checked before
//! any work starts, and warnings for values that are legal but probably not what was meant.
//! Each bound is listed in `docs/case-files.md`.

use super::{CaseFile, ShapeSpec, V};
use crate::error::Error;
use crate::rod::Profile;

/// Largest `panels × gauss_points` (quadrature nodes: each Hessian costs nodes × unknowns²).
pub const MAX_NODES: usize = 8000;
pub use crate::rod::model::MAX_SELF_CONTACT_SAMPLES;
/// Largest count of constraints, of forces, of report points.
pub const MAX_ITEMS: usize = 1000;
/// Largest count of obstacles.
pub const MAX_OBSTACLES: usize = 100;
/// Largest `solver.max_outer` and `solver.max_inner`.
pub const MAX_OUTER: usize = 1000;
/// See [`MAX_OUTER`].
pub const MAX_INNER: usize = 10_000;
/// Magnitudes of lengths, rigidities, weights and forces lie in `[1/MAX_MAGNITUDE,
/// MAX_MAGNITUDE]` (zero where zero is allowed): beyond it energies and their second
/// derivatives overflow.
pub const MAX_MAGNITUDE: f64 = 1e100;
/// Largest `|coefficient|` of an explicit shape: beyond it sines and cosines carry no digits.
pub const MAX_COEFFICIENT: f64 = 1e4;
/// Longest case name in bytes (it names files with suffixes of up to 40 bytes).
pub const MAX_NAME_BYTES: usize = 200;
/// Rigidity ratios beyond this are warned about.
pub const WARN_RIGIDITY_RATIO: f64 = 1e12;

/// Fails unless `x` is 0 (where `zero_ok`) or its magnitude lies in the allowed range.
fn magnitude(v: &V, field: &str, x: f64, zero_ok: bool) -> Result<(), Error> {
    let a = x.abs();
    if (a == 0.0 && zero_ok) || ((1.0 / MAX_MAGNITUDE)..=MAX_MAGNITUDE).contains(&a) {
        Ok(())
    } else {
        Err(v.err(
            field,
            format!("{x:e} is outside the magnitudes this tool computes with (1e-100 to 1e100)"),
        ))
    }
}

fn profile(v: &V, field: &str, p: &Profile, zero_ok: bool) -> Result<(), Error> {
    match p {
        Profile::Constant(x) => magnitude(v, field, *x, zero_ok),
        Profile::Linear { start, end } => {
            magnitude(v, &format!("{field}.start"), *start, zero_ok)?;
            magnitude(v, &format!("{field}.end"), *end, zero_ok)
        }
    }
}

fn largest(p: &Profile) -> f64 {
    match p {
        Profile::Constant(x) => x.abs(),
        Profile::Linear { start, end } => start.abs().max(end.abs()),
    }
}

/// Checks the bounds; returns the warnings.
pub(super) fn check(file: &CaseFile, v: &V) -> Result<Vec<String>, Error> {
    let mut warnings = Vec::new();
    if let Some(name) = &file.name {
        if name.len() > MAX_NAME_BYTES {
            return Err(v.err(
                "name",
                format!(
                    "{} bytes; at most {MAX_NAME_BYTES} (it names the log files)",
                    name.len()
                ),
            ));
        }
        if name.chars().any(char::is_control) || name == "." || name == ".." {
            return Err(v.err(
                "name",
                "must not contain control characters or be `.` or `..` (it names the log files)",
            ));
        }
    }
    let r = &file.rod;
    magnitude(v, "rod.length", r.length, false)?;
    profile(v, "rod.flexural_rigidity", &r.flexural_rigidity, false)?;
    if let Some(p) = &r.torsional_rigidity {
        profile(v, "rod.torsional_rigidity", p, false)?;
    }
    if let Some(p) = &r.extensional_rigidity {
        profile(v, "rod.extensional_rigidity", p, false)?;
    }
    if let Some(p) = &r.weight_per_length {
        profile(v, "rod.weight_per_length", p, true)?;
    }
    let d = &file.discretisation;
    let nodes = d.panels.saturating_mul(d.gauss_points);
    if nodes > MAX_NODES {
        return Err(v.err(
            "discretisation.panels",
            format!(
                "panels × gauss_points = {nodes} quadrature nodes; at most {MAX_NODES} \
                 (each Newton step costs nodes × unknowns²)"
            ),
        ));
    }
    if file.self_contact && d.samples > MAX_SELF_CONTACT_SAMPLES {
        return Err(v.err(
            "discretisation.samples",
            format!(
                "{} samples with self-contact; at most {MAX_SELF_CONTACT_SAMPLES} (its rows grow \
                 as samples²)",
                d.samples
            ),
        ));
    }
    for (field, n, max) in [
        ("constraints", file.constraints.len(), MAX_ITEMS),
        ("forces", file.forces.len(), MAX_ITEMS),
        ("obstacles", file.obstacles.len(), MAX_OBSTACLES),
        (
            "report_points",
            file.report_points.as_ref().map_or(0, Vec::len),
            MAX_ITEMS,
        ),
    ] {
        if n > max {
            return Err(v.err(field, format!("{n} entries; at most {max}")));
        }
    }
    for (i, f) in file.forces.iter().enumerate() {
        for (k, c) in f.force.iter().enumerate() {
            magnitude(v, &format!("forces[{i}].force[{k}]"), *c, true)?;
        }
    }
    let s = &file.solver;
    if s.max_outer > MAX_OUTER {
        return Err(v.err(
            "solver.max_outer",
            format!("at most {MAX_OUTER}, got {}", s.max_outer),
        ));
    }
    if s.max_inner > MAX_INNER {
        return Err(v.err(
            "solver.max_inner",
            format!("at most {MAX_INNER}, got {}", s.max_inner),
        ));
    }
    if let Some(shape) = &file.shape {
        coefficients(v, shape)?;
    }
    // Warnings.
    let rf = largest(&r.flexural_rigidity).max(f64::MIN_POSITIVE);
    let l2 = r.length * r.length;
    for (field, other) in [
        (
            "rod.torsional_rigidity",
            r.torsional_rigidity.as_ref().map(largest),
        ),
        (
            "rod.extensional_rigidity",
            r.extensional_rigidity.as_ref().map(|p| largest(p) * l2),
        ),
    ] {
        if let Some(x) = other {
            let ratio = x / rf;
            if !(1.0 / WARN_RIGIDITY_RATIO..=WARN_RIGIDITY_RATIO).contains(&ratio) {
                warnings.push(format!(
                    "{field}: its ratio to the flexural rigidity ({} {ratio:.1e}) is beyond \
                     1e12; the solve is taken as written, but its Hessian is that badly \
                     conditioned",
                    if field.contains("ext") {
                        "Re·L²/Rf ="
                    } else {
                        "Rt/Rf ="
                    }
                ));
            }
        }
    }
    angle_warnings(file, &mut warnings);
    Ok(warnings)
}

fn coefficients(v: &V, shape: &ShapeSpec) -> Result<(), Error> {
    for (name, c) in [
        ("phi", &shape.phi),
        ("theta", &shape.theta),
        ("psi", &shape.psi),
        ("eps", &shape.eps),
    ] {
        for (i, a) in c.iter().flatten().enumerate() {
            if a.abs() > MAX_COEFFICIENT {
                return Err(v.err(
                    format!("shape.{name}[{i}]"),
                    format!("|{a:e}| is above {MAX_COEFFICIENT:e}"),
                ));
            }
        }
    }
    Ok(())
}

/// Direction angles (radians) of more than a turn: probably degrees. Only `θ` and `φ`, which
/// place the tangent: twists (`ψ`, `φ + ψ`, `twist`) of several turns are common.
fn angle_warnings(file: &CaseFile, warnings: &mut Vec<String>) {
    let mut check = |field: String, a: Option<f64>| {
        if let Some(a) = a
            && a.abs() > std::f64::consts::TAU + 1e-9
        {
            warnings.push(format!(
                "{field}: {a} rad is more than a full turn; angles are in radians (taken as \
                 written; {a}° would be {:.6} rad)",
                a.to_radians()
            ));
        }
    };
    for (i, c) in file.constraints.iter().enumerate() {
        if let super::ConstraintSpec::Orientation { phi, theta, .. } = c {
            for (n, a) in [("phi", phi), ("theta", theta)] {
                check(format!("constraints[{i}].{n}"), *a);
            }
        }
    }
    if let Some(plan) = &file.plan {
        for end in ["start", "goal"] {
            for n in ["phi", "theta"] {
                check(format!("plan.{end}.{n}"), plan[end][n].as_f64());
            }
        }
    }
}
