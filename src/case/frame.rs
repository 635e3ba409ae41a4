//! The reference frame of a 3D rod's Euler angles, chosen per case away from the pole.
//!
//! The ZYZ angles are singular where the tangent points along the frame's `±z` (`θ = 0, π`:
//! `φ` and `ψ` enter only as `φ ± ψ`), and there the Ritz fields cannot follow a rotation of the
//! shape: a clamp on the pole acts like a hidden support, and the same problem turned about the
//! vertical gives another energy. A case whose orientations are all written in forms that
//! convert (full frames and tangents) therefore has its angles measured from a frame `R` whose
//! `z` axis is as far as the case lets it be from every direction its rod is known to take —
//! the tangents its constraints and plan ends prescribe and the chords between its fixed points
//! (the gravitational energy reads the vertical in the angles' frame, `Rᵀ x̂`). `R` is built
//! from those directions alone, so a case turned about the vertical (or, without weight, about
//! any axis) is the same problem in its angles: the same energy and the turned shape.
//!
//! The case's orientation constraints are written in its own axes; each becomes rows on the
//! angles of `R`: a full frame `F` the angles of `Rᵀ F`, a tangent `t` the `(φ, θ)` of `Rᵀ t`.
//! Turns are kept: the constraints are taken in the order of `s`, and each one's angles
//! continue those of the one before along the rotation their written angles interpolate, so
//! that a twist of 2π between two clamps stays a twist of 2π.
//!
//! A case that writes Ritz coefficients of the angles (a `shape`, or a plan end's `shape`),
//! partial orientations that are not tangents, or Euler angles to be kept as written, keeps
//! its own axes (`R = I`), as does `"angle_frame": "case"` — the default of a case with a
//! `plan` section: the planner interpolates the angles' coefficients, and on the generated
//! suite its 3D paths replay by the controlled end less often in the frame away from the pole
//! than in the case's axes (where the shipped 3D plans clamp their base on the pole with a free
//! bending direction), so plans keep the case's axes unless they ask for `"auto"`.

use super::plan::{EndSpec, EulerBranch};
use super::{CaseFile, ConstraintSpec};
use crate::constraints::Angle;
use crate::planner::orientation::{Matrix, nearest};
use crate::rod::kinematics::{angles_of, cross, in_frame, is_identity, is_rotation, rotation};
use crate::rod::layout::Field;
use std::f64::consts::PI;

/// How a case's 3D angles are measured (the case file's `angle_frame`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AngleFrame {
    /// From a frame chosen away from the pole where the case allows it (the default, but for
    /// a case with a `plan` section).
    Auto,
    /// In the case's own axes, as the paper writes them (the default of a case with a `plan`
    /// section: the planner's coefficient-space paths are measured to replay better there).
    Case,
}

impl AngleFrame {
    /// What `file` asks for, its default filled in (an explicit matrix counts as `Auto`).
    pub fn of(file: &CaseFile) -> AngleFrame {
        match file.angle_frame {
            Some(AngleFrameSpec::Named(a)) => a,
            Some(AngleFrameSpec::Matrix(_)) => AngleFrame::Auto,
            None if file.plan.is_some() => AngleFrame::Case,
            None => AngleFrame::Auto,
        }
    }
}

/// The case file's `angle_frame`: a name, or the frame itself as a reports gives it (a
/// row-major rotation whose columns are the angles' axes in the case's), so that coefficients
/// copied from a report describe the same shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AngleFrameSpec {
    /// `"auto"` or `"case"`.
    Named(AngleFrame),
    /// An explicit frame.
    Matrix([[f64; 3]; 3]),
}

impl<'de> serde::Deserialize<'de> for AngleFrameSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = serde_json::Value::deserialize(d)?;
        match v.as_str() {
            Some("auto") => return Ok(AngleFrameSpec::Named(AngleFrame::Auto)),
            Some("case") => return Ok(AngleFrameSpec::Named(AngleFrame::Case)),
            _ => {}
        }
        serde_json::from_value::<[[f64; 3]; 3]>(v)
            .map(AngleFrameSpec::Matrix)
            .map_err(|_| {
                serde::de::Error::custom(
                    "expected \"auto\", \"case\" or a 3×3 rotation matrix (three rows of three numbers)",
                )
            })
    }
}

/// An orientation the case prescribes, in its own axes.
#[derive(Clone, Copy, Debug)]
enum Written {
    /// A full frame, with the Euler angles it was written as (for the continuation).
    Frame([f64; 3]),
    /// A tangent direction, with the `(φ, θ)` it was written as.
    Tangent([f64; 2]),
}

impl Written {
    fn tangent(self) -> [f64; 3] {
        let (phi, theta) = match self {
            Written::Frame([f, t, _]) | Written::Tangent([f, t]) => (f, t),
        };
        [
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        ]
    }
}

/// The written orientation of constraint `c`, if it converts; `Err(())` if it does not.
fn written(c: &ConstraintSpec) -> Option<Result<(f64, Written), ()>> {
    let ConstraintSpec::Orientation {
        s,
        phi,
        theta,
        psi,
        phi_plus_psi,
        ..
    } = *c
    else {
        return None;
    };
    let on_pole = |t: f64| t.sin().abs() < 1e-12;
    Some(match (phi, theta, psi, phi_plus_psi) {
        (Some(f), Some(t), Some(p), None) => Ok((s, Written::Frame([f, t, p]))),
        (None, Some(t), None, Some(sum)) if on_pole(t) => Ok((s, Written::Frame([0.0, t, sum]))),
        (Some(f), Some(t), None, None) => Ok((s, Written::Tangent([f, t]))),
        (None, Some(t), None, None) if on_pole(t) => Ok((s, Written::Tangent([0.0, t]))),
        _ => Err(()),
    })
}

/// The frame `R` (row-major; its columns are the angles' axes in the case's) for `file`, or
/// `None` to keep the case's axes; an error names what makes an explicit frame unusable.
pub(crate) fn choose(file: &CaseFile) -> Result<Option<Matrix>, String> {
    let Some(AngleFrameSpec::Matrix(r)) = file.angle_frame else {
        return Ok(auto(file));
    };
    if file.planar {
        return Err("a planar rod's angles are measured in the case's axes: remove it".into());
    }
    if !is_rotation(r, 1e-9) {
        return Err("must be a rotation matrix (rows, orthonormal to 1e-9, determinant +1)".into());
    }
    for (i, c) in file.constraints.iter().enumerate() {
        if let Some(Err(())) = written(c) {
            return Err(format!(
                "constraints[{i}] prescribes angles that cannot be measured from another frame: give phi, theta and psi (a frame), or phi and theta (a tangent)"
            ));
        }
    }
    if let Some(plan) = &file.plan {
        for key in ["start", "goal"] {
            let Some(raw) = plan.get(key) else { continue };
            if let Ok(e) = serde_json::from_value::<EndSpec>(raw.clone()) {
                let some = [e.phi, e.theta, e.psi]
                    .iter()
                    .filter(|a| a.is_some())
                    .count();
                if (some > 0 && some < 3) || e.euler_branch == EulerBranch::AsWritten {
                    return Err(format!(
                        "plan.{key} prescribes Euler angles as written, which are the case's: give a full orientation"
                    ));
                }
            }
        }
    }
    // Orthonormalised exactly (Gram–Schmidt on the columns).
    let col = |j: usize| [r[0][j], r[1][j], r[2][j]];
    let x = unit(col(0)).ok_or("a zero column")?;
    let y = unit(sub(col(1), x.map(|v| v * dot(col(1), x)))).ok_or("dependent columns")?;
    let z = cross(x, y);
    Ok(Some([
        [x[0], y[0], z[0]],
        [x[1], y[1], z[1]],
        [x[2], y[2], z[2]],
    ]))
}

/// The frame `"auto"` chooses for `file`, if it can take one.
fn auto(file: &CaseFile) -> Option<Matrix> {
    if file.planar || AngleFrame::of(file) == AngleFrame::Case || file.shape.is_some() {
        return None;
    }
    let mut lines: Vec<([f64; 3], f64)> = Vec::new();
    let mut orient = Vec::new();
    for c in &file.constraints {
        match written(c) {
            None => {}
            Some(Ok(w)) => orient.push(w),
            Some(Err(())) => return None,
        }
    }
    orient.sort_by(|a, b| a.0.total_cmp(&b.0));
    for &(_, w) in &orient {
        lines.push((w.tangent(), 1.0));
    }
    // Between consecutive prescribed tangents the rod's tangent turns from one to the other:
    // the shortest arc's directions.
    for w in orient.windows(2) {
        arc(&mut lines, w[0].1.tangent(), w[1].1.tangent());
    }
    let held_tangent = orient
        .first()
        .filter(|(s, _)| *s == 0.0)
        .map(|(_, w)| w.tangent());
    // Fixed points, in order of s: the chords between them.
    let mut fixed: Vec<(f64, [f64; 3])> = Vec::new();
    if !file.base.free {
        fixed.push((0.0, file.base.position));
    }
    for c in &file.constraints {
        if let ConstraintSpec::Position { s, x, y, z, .. } = c
            && let (Some(x), Some(y), Some(z)) = (x, y, z)
            && let (
                super::CoordSpec::Equal(x),
                super::CoordSpec::Equal(y),
                super::CoordSpec::Equal(z),
            ) = (x, y, z)
        {
            fixed.push((*s, [*x, *y, *z]));
        }
    }
    // Plan ends: their positions (chords from the base) and orientations.
    if let Some(plan) = &file.plan {
        for key in ["start", "goal"] {
            let Some(raw) = plan.get(key) else { continue };
            let Ok(e) = serde_json::from_value::<EndSpec>(raw.clone()) else {
                return None;
            };
            if e.shape.is_some() || e.euler_branch == EulerBranch::AsWritten {
                return None;
            }
            let pos = e
                .position
                .or_else(|| Some([e.x?, e.y.unwrap_or(0.0), e.z?]));
            if let Some(d) = pos
                .filter(|_| !file.base.free)
                .and_then(|p| unit(std::array::from_fn(|k| p[k] - file.base.position[k])))
            {
                lines.push((d, 1.0));
            }
            let tangent = match (e.quaternion, e.tangent, e.phi, e.theta, e.psi) {
                (Some(q), ..) => {
                    let m = crate::planner::trajectory::rotation_of_quaternion(q);
                    Some([m[0][2], m[1][2], m[2][2]])
                }
                (None, Some(t), ..) => Some(t),
                (None, None, Some(f), Some(t), Some(p)) => {
                    Some(Written::Frame([f, t, p]).tangent())
                }
                (None, None, None, None, None) => None,
                // Partial Euler angles are prescribed as written.
                _ => return None,
            };
            if let Some(t) = tangent.and_then(unit) {
                lines.push((t, 1.0));
                if let Some(h) = held_tangent {
                    arc(&mut lines, h, t);
                }
            }
        }
    }
    fixed.sort_by(|a, b| a.0.total_cmp(&b.0));
    for w in fixed.windows(2) {
        let d = std::array::from_fn(|k| w[1].1[k] - w[0].1[k]);
        if let Some(d) = unit(d) {
            lines.push((d, 1.0));
        }
    }
    if lines.is_empty() {
        return None;
    }
    // All the directions along one line (a straight rod, twisted): every axis perpendicular to
    // it is as far, and the first full frame's η (perpendicular to its tangent and its ξ)
    // decides; else the farthest axis.
    let scatter =
        nalgebra::Matrix3::from_fn(|i, j| lines.iter().map(|(d, w)| w * d[i] * d[j]).sum::<f64>());
    let ev = scatter.symmetric_eigenvalues();
    let mut sorted = [ev[0], ev[1], ev[2]];
    sorted.sort_by(f64::total_cmp);
    let first_eta = orient.iter().find_map(|&(_, w)| match w {
        Written::Frame([f, t, p]) => {
            let m = rotation(f, t, p);
            Some([m[0][1], m[1][1], m[2][1]])
        }
        Written::Tangent(_) => None,
    });
    let n = match first_eta {
        Some(eta) if sorted[1] <= 1e-9 * sorted[2] => eta,
        _ => farthest_on_sphere(&lines),
    };
    let mut n = unit(n)?;
    // The axis's sign, from the directions themselves: the first pair that spans a plane.
    let sign = lines
        .iter()
        .enumerate()
        .flat_map(|(i, a)| lines[i + 1..].iter().map(move |b| cross(a.0, b.0)))
        .map(|c| dot(n, c))
        .find(|d| d.abs() > 1e-9)
        .or_else(|| lines.iter().map(|l| dot(n, l.0)).find(|d| d.abs() > 1e-9))
        .unwrap_or(1.0);
    if sign < 0.0 {
        n = n.map(|v| -v);
    }
    // The angles' x axis: the first direction off the axis (any turn about the axis is a
    // change of φ's constant term, so this choice does not change a solution).
    let x = lines
        .iter()
        .filter_map(|(d, _)| unit(sub(*d, n.map(|v| v * dot(*d, n)))))
        .next()
        .or_else(|| unit(cross(n, [1.0, 0.0, 0.0])))
        .or_else(|| unit(cross(n, [0.0, 1.0, 0.0])))?;
    let y = cross(n, x);
    let r = [[x[0], y[0], n[0]], [x[1], y[1], n[1]], [x[2], y[2], n[2]]];
    Some(r)
}

/// Adds the interior directions of the shortest arc from `a` to `b` (unit vectors), if they
/// are neither the same nor opposite.
fn arc(lines: &mut Vec<([f64; 3], f64)>, a: [f64; 3], b: [f64; 3]) {
    let c = dot(a, b).clamp(-1.0, 1.0);
    let angle = c.acos();
    if angle < 1e-6 || PI - angle < 1e-6 {
        return;
    }
    let steps = 6;
    for k in 1..steps {
        let u = k as f64 / steps as f64;
        let (wa, wb) = (
            ((1.0 - u) * angle).sin() / angle.sin(),
            (u * angle).sin() / angle.sin(),
        );
        if let Some(d) = unit(std::array::from_fn(|i| wa * a[i] + wb * b[i])) {
            lines.push((d, 1.0));
        }
    }
}

/// How far the axis `n` is from the weighted lines: `Σ w ln(sin² ∠(n, d) + 10⁻⁶)`, which is
/// largest where no line is near the axis; and its gradient in `n`.
fn farness(lines: &[([f64; 3], f64)], n: [f64; 3]) -> (f64, [f64; 3]) {
    let mut f = 0.0;
    let mut g = [0.0; 3];
    for (d, w) in lines {
        let c = dot(n, *d);
        let s2 = 1.0 - c * c + 1e-6;
        f += w * s2.ln();
        for k in 0..3 {
            g[k] -= 2.0 * w * c * d[k] / s2;
        }
    }
    (f, g)
}

/// The axis farthest from the lines over all directions: the best of a scan of the sphere,
/// refined to the local maximum.
fn farthest_on_sphere(lines: &[([f64; 3], f64)]) -> [f64; 3] {
    let scan = 4000;
    let golden = PI * (3.0 - 5f64.sqrt());
    let mut best = [0.0, 0.0, 1.0];
    let mut best_f = f64::NEG_INFINITY;
    for k in 0..scan {
        // A Fibonacci lattice of the upper half (an axis and its opposite are one).
        let z = 1.0 - (k as f64 + 0.5) / scan as f64;
        let r = (1.0 - z * z).sqrt();
        let n = [
            r * (golden * k as f64).cos(),
            r * (golden * k as f64).sin(),
            z,
        ];
        let f = farness(lines, n).0;
        if f > best_f {
            best_f = f;
            best = n;
        }
    }
    // Newton in the tangent plane, with a finite-difference Hessian of the exact gradient.
    let mut n = best;
    for _ in 0..60 {
        let u = unit(cross(
            n,
            if n[0].abs() < 0.9 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 1.0, 0.0]
            },
        ))
        .expect("a direction off the axis");
        let v = cross(n, u);
        let point = |a: f64, b: f64| {
            unit(std::array::from_fn(|k| n[k] + a * u[k] + b * v[k])).expect("near a unit vector")
        };
        let grad = |a: f64, b: f64| {
            let (_, g) = farness(lines, point(a, b));
            [dot(g, u), dot(g, v)]
        };
        let h = 1e-6;
        let g0 = grad(0.0, 0.0);
        let (ga, gb) = ([grad(h, 0.0), grad(-h, 0.0)], [grad(0.0, h), grad(0.0, -h)]);
        let hm = [
            [
                (ga[0][0] - ga[1][0]) / (2.0 * h),
                (gb[0][0] - gb[1][0]) / (2.0 * h),
            ],
            [
                (ga[0][1] - ga[1][1]) / (2.0 * h),
                (gb[0][1] - gb[1][1]) / (2.0 * h),
            ],
        ];
        let hs = 0.5 * (hm[0][1] + hm[1][0]);
        let det = hm[0][0] * hm[1][1] - hs * hs;
        // A maximum's Hessian is negative definite; elsewhere a small gradient step.
        let (da, db) = if hm[0][0] < 0.0 && det > 0.0 {
            (
                -(hm[1][1] * g0[0] - hs * g0[1]) / det,
                -(hm[0][0] * g0[1] - hs * g0[0]) / det,
            )
        } else {
            (1e-3 * g0[0], 1e-3 * g0[1])
        };
        let (da, db) = (da.clamp(-0.02, 0.02), db.clamp(-0.02, 0.02));
        n = point(da, db);
        if da.abs().max(db.abs()) < 1e-15 {
            break;
        }
    }
    n
}

/// The case's orientation constraints as rows on the angles of `r` (see the module
/// documentation), in the order of `file.constraints`; `None` for one that is not an
/// orientation.
///
/// With `start` (the written start's angles in `r` at arc length `s`), each orientation takes
/// instead the spelling nearest the start's angles there: the start says which turns the user
/// means (a loop whose tangent circles the angles' axis has `φ(L) = φ(0) − 2π` where the written
/// angles interpolate no turn at all), and a branch the start does not hold would make the
/// solve unwind it.
pub(crate) fn convert(
    file: &CaseFile,
    r: [[f64; 3]; 3],
    start: Option<&dyn Fn(f64) -> [f64; 3]>,
) -> Vec<Option<Vec<(Angle, f64)>>> {
    let frame = (!is_identity(&r)).then_some(r);
    let mut order: Vec<(usize, f64, Written)> = file
        .constraints
        .iter()
        .enumerate()
        .filter_map(|(i, c)| Some((i, written(c)?.ok()?)))
        .map(|(i, (s, w))| (i, s, w))
        .collect();
    order.sort_by(|a, b| a.1.total_cmp(&b.1));
    let mut out = vec![None; file.constraints.len()];
    let local = |a: [f64; 3]| in_frame(frame.as_ref(), rotation(a[0], a[1], a[2]));
    // The written angles (ψ filled in from the previous where a tangent leaves it) and their
    // angles in `r`, of the previous constraint.
    let mut prev: Option<([f64; 3], [f64; 3])> = None;
    for (i, s, w) in order {
        let written = match (w, prev) {
            (Written::Frame(a), _) => a,
            (Written::Tangent([f, t]), Some((p, _))) => [f, t, p[2]],
            (Written::Tangent([f, t]), None) => [f, t, 0.0],
        };
        let angles = match (start, prev) {
            (Some(start), _) => {
                let tangent_only = matches!(w, Written::Tangent(_));
                nearest_branch_of(angles_of(local(written)), start(s), !tangent_only)
            }
            (None, None) => angles_of(local(written)),
            (None, Some((pw, pl))) => {
                // Continue along the written angles' interpolation, step by step.
                let steps = 256;
                let mut cur = pl;
                for k in 1..=steps {
                    let u = k as f64 / steps as f64;
                    let a = std::array::from_fn(|j| pw[j] + u * (written[j] - pw[j]));
                    cur = nearest_branch(angles_of(local(a)), cur);
                }
                cur
            }
        };
        out[i] = Some(match w {
            Written::Frame(_) => vec![
                (Angle::Field(Field::Phi), angles[0]),
                (Angle::Field(Field::Theta), angles[1]),
                (Angle::Field(Field::Psi), angles[2]),
            ],
            Written::Tangent(_) => vec![
                (Angle::Field(Field::Phi), angles[0]),
                (Angle::Field(Field::Theta), angles[1]),
            ],
        });
        prev = Some((written, angles));
    }
    out
}

/// The spelling of the rotation with angles `a` — `(φ, θ, ψ)` or `(φ + π, −θ, ψ + π)`, each
/// angle plus any multiple of 2π — nearest `reference`.
fn nearest_branch(a: [f64; 3], reference: [f64; 3]) -> [f64; 3] {
    nearest_branch_of(a, reference, true)
}

/// [`nearest_branch`], judging the distance on `(φ, θ)` alone unless `with_psi` (a tangent
/// leaves `ψ` free).
fn nearest_branch_of(a: [f64; 3], reference: [f64; 3], with_psi: bool) -> [f64; 3] {
    let dist = |x: [f64; 3]| {
        (0..if with_psi { 3 } else { 2 })
            .map(|j| (x[j] - reference[j]).abs())
            .fold(0.0, f64::max)
    };
    [a, [a[0] + PI, -a[1], a[2] + PI]]
        .map(|b| std::array::from_fn::<f64, 3, _>(|j| nearest(b[j], reference[j])))
        .into_iter()
        .min_by(|x, y| dist(*x).total_cmp(&dist(*y)))
        .expect("two spellings")
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let n = dot(v, v).sqrt();
    (n.is_finite() && n > 1e-9).then(|| v.map(|c| c / n))
}

/// The default start of a rod whose angles have the frame `r`: the natural state turned to
/// lie along the first prescribed orientation at `s = 0` (`held`, in `r`'s angles), or along
/// the angles' `x` axis, with the same small perturbation as in the case's axes.
pub(crate) fn held_angles(rows: &[Option<Vec<(Angle, f64)>>], file: &CaseFile) -> [f64; 3] {
    let mut held = [0.0, 0.5 * PI, 0.0];
    for (c, r) in file.constraints.iter().zip(rows) {
        if let (ConstraintSpec::Orientation { s, .. }, Some(r)) = (c, r)
            && *s == 0.0
        {
            for &(ang, v) in r {
                match ang {
                    Angle::Field(Field::Phi) => held[0] = v,
                    Angle::Field(Field::Theta) => held[1] = v,
                    Angle::Field(Field::Psi) => held[2] = v,
                    _ => {}
                }
            }
        }
    }
    held
}
