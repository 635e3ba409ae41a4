//! Case files: JSON parsed with serde into typed values (`deny_unknown_fields`), then validated
//! once into a [`Case`] holding a ready [`StaticProblem`]. Every field is documented in
//! docs/case-files.md with its units and default. Lengths, forces and rigidities are in any one
//! consistent unit system; angles in radians.

mod field_path;
pub mod frame;
pub mod grasp;
mod limits;
pub mod plan;
mod strict_json;

pub use limits::*;

use crate::constraints::{Angle, Bound};
use crate::error::Error;
use crate::rod::basis::Basis;
use crate::rod::layout::{Field, Layout};
use crate::rod::model::Discretisation;
use crate::rod::{Profile, Rod};
use crate::scene::obstacle::{Obstacle, ObstacleShape};
use crate::statics::StaticOptions;
use crate::statics::problem::StaticProblem;
use crate::statics::{StaticProblemBuilder, StaticSettings};
use parry3d_f64::math::Vector;
use parry3d_f64::shape::{Ball, Cuboid, Cylinder};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The case file as written.
#[derive(Clone, Debug, Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a case file: an object with the `rod` and what else the case has"
)]
pub struct CaseFile {
    /// Case name (default: the file stem); names the log file.
    pub name: Option<String>,
    /// Free text.
    #[serde(default)]
    pub description: String,
    /// The rod.
    pub rod: RodSpec,
    /// Planar rod in the x–z plane (`φ = ψ = 0`); default `true`.
    #[serde(default = "yes")]
    pub planar: bool,
    /// Discretisation.
    #[serde(default)]
    pub discretisation: DiscretisationSpec,
    /// Base (`s = 0`) position.
    #[serde(default)]
    pub base: BaseSpec,
    /// Geometric constraints.
    #[serde(default)]
    pub constraints: Vec<ConstraintSpec>,
    /// Point loads.
    #[serde(default)]
    pub forces: Vec<ForceSpec>,
    /// Obstacles.
    #[serde(default)]
    pub obstacles: Vec<ObstacleSpec>,
    /// Enforce self-contact (eq. 17).
    #[serde(default)]
    pub self_contact: bool,
    /// Explicit Ritz coefficients: evaluated by `dlo energy`, the start of `dlo shape`.
    pub shape: Option<ShapeSpec>,
    /// How a 3D rod's Euler angles are measured: `"auto"` from a frame chosen away from the
    /// pole, `"case"` in the case's own axes, or an explicit frame (see [`frame`]). Default:
    /// `"auto"`, but `"case"` in a case with a `plan` section.
    #[serde(default)]
    pub angle_frame: Option<frame::AngleFrameSpec>,
    /// Arc lengths at which `dlo energy`/`dlo shape` report positions (default: 0, L/4, …, L).
    pub report_points: Option<Vec<f64>>,
    /// Solver settings.
    #[serde(default)]
    pub solver: StaticSettings,
    /// Path-planning settings (read by `dlo plan`).
    #[serde(default, deserialize_with = "strict_json::optional")]
    pub plan: Option<serde_json::Value>,
    /// Grasp-stability settings (read by `dlo margin`).
    #[serde(default, deserialize_with = "strict_json::optional")]
    pub grasp: Option<serde_json::Value>,
}

fn yes() -> bool {
    true
}

/// `rod` section.
#[derive(Clone, Debug, Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "an object with the rod's `length`, `flexural_rigidity` and the other properties it has"
)]
pub struct RodSpec {
    /// Natural length `L` (> 0).
    pub length: f64,
    /// `Rf`: number or `{"start", "end"}` (> 0).
    pub flexural_rigidity: Profile,
    /// `Rt` (> 0); required when `planar` is false, not allowed when true.
    pub torsional_rigidity: Option<Profile>,
    /// `Re` (> 0); absent for an inextensible rod.
    pub extensional_rigidity: Option<Profile>,
    /// `D` (≥ 0), weight per unit length; gravity points along −x. Default 0.
    pub weight_per_length: Option<Profile>,
    /// Cross-section radius (≥ 0). Default `L/1000`.
    pub radius: Option<f64>,
}

/// `discretisation` section.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(
    deny_unknown_fields,
    default,
    expecting = "an object of discretisation settings (`basis_pairs`, `panels`, …)"
)]
pub struct DiscretisationSpec {
    /// Sine/cosine pairs per field (paper: 4, i.e. 10 functions).
    pub basis_pairs: usize,
    /// The functions: `"legendre"` or `"paper"`. Unnamed: `"legendre"`, but for a case that
    /// writes Ritz coefficients (a `shape`, top level or in a plan end), which are read in the
    /// paper's basis as they always were.
    pub basis: Option<crate::rod::basis::BasisKind>,
    /// Uniform quadrature panels.
    pub panels: usize,
    /// Gauss points per panel.
    pub gauss_points: usize,
    /// Intervals between obstacle/self-contact sample points.
    pub samples: usize,
    /// Where obstacle contacts are held: `"points"` (the sample points, default) or
    /// `"chords"` (the polyline through them).
    pub contact: ContactModel,
}

/// Where a static solve holds obstacle contacts (`discretisation.contact`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactModel {
    /// At the sample points: a rod pressed on a corner can dip between them.
    #[default]
    Points,
    /// On the chords between the sample points.
    Chords,
}

impl Default for DiscretisationSpec {
    fn default() -> Self {
        DiscretisationSpec {
            basis_pairs: 4,
            basis: None,
            panels: 16,
            gauss_points: 4,
            samples: 32,
            contact: ContactModel::Points,
        }
    }
}

/// `base` section.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(
    deny_unknown_fields,
    default,
    expecting = "an object `{\"position\": [x, y, z], \"free\": false}`"
)]
pub struct BaseSpec {
    /// Position of `P(0)` (the start when free).
    pub position: [f64; 3],
    /// When true the base position is an unknown (e.g. a finger that lets the end slide).
    pub free: bool,
}

impl Default for BaseSpec {
    fn default() -> Self {
        BaseSpec {
            position: [0.0; 3],
            free: false,
        }
    }
}

/// One coordinate of a position constraint: a number means equality.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(
    untagged,
    expecting = "expected a number (equality) or bounds `{\"min\": a, \"max\": b}` (either may be left out)"
)]
pub enum CoordSpec {
    /// `x_k = v`.
    Equal(f64),
    /// Bounds.
    Range(RangeSpec),
}

/// One-sided bounds on a coordinate.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields, expecting = "bounds `{\"min\": a, \"max\": b}`")]
pub struct RangeSpec {
    /// `x_k ≥ min`.
    pub min: Option<f64>,
    /// `x_k ≤ max`.
    pub max: Option<f64>,
}

/// A constraint entry.
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ConstraintSpec {
    /// Position of `P(s)`; omitted coordinates are free.
    Position {
        /// Arc length.
        s: f64,
        /// x coordinate.
        x: Option<CoordSpec>,
        /// y coordinate (spatial rods only).
        y: Option<CoordSpec>,
        /// z coordinate.
        z: Option<CoordSpec>,
        /// Label in reports.
        name: Option<String>,
    },
    /// `x(s_b) − x(s_a) = l` (eq. 14) for the given components.
    RelativePosition {
        /// First point.
        s_a: f64,
        /// Second point.
        s_b: f64,
        /// `l_x`.
        x: Option<f64>,
        /// `l_y`.
        y: Option<f64>,
        /// `l_z`.
        z: Option<f64>,
        /// Label in reports.
        name: Option<String>,
    },
    /// Euler angles at `P(s)` (eq. 15); omitted angles are free.
    Orientation {
        /// Arc length.
        s: f64,
        /// φ (spatial only).
        phi: Option<f64>,
        /// θ.
        theta: Option<f64>,
        /// ψ (spatial only).
        psi: Option<f64>,
        /// φ + ψ (spatial only; instead of φ and ψ, see docs/case-files.md).
        phi_plus_psi: Option<f64>,
        /// Label in reports.
        name: Option<String>,
    },
}

/// A point force.
#[derive(Clone, Debug, Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a point load `{\"s\": s, \"force\": [fx, fy, fz], \"reference\": [x, y, z]}`"
)]
pub struct ForceSpec {
    /// Arc length of the point of application.
    pub s: f64,
    /// Force vector.
    pub force: [f64; 3],
    /// Position from which the displacement in `W = p·δq` is measured (default: origin).
    #[serde(default)]
    pub reference: [f64; 3],
}

/// An obstacle entry.
#[derive(Clone, Debug, Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "an obstacle: an object with its `shape` (and `name`, `position`, `rotation`)"
)]
pub struct ObstacleSpec {
    /// Name in reports and logs.
    pub name: Option<String>,
    /// Geometry in the local frame.
    pub shape: ShapeKind,
    /// World position of the local origin.
    #[serde(default)]
    pub position: [f64; 3],
    /// Axis–angle rotation vector (radians).
    #[serde(default)]
    pub rotation: [f64; 3],
    /// Extra clearance beyond the rod radius.
    #[serde(default)]
    pub margin: f64,
}

/// Obstacle geometry.
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ShapeKind {
    /// Box.
    Cuboid {
        /// Half extents.
        half_extents: [f64; 3],
    },
    /// Sphere.
    Ball {
        /// Radius.
        radius: f64,
    },
    /// Capsule from `a` to `b`.
    Capsule {
        /// Segment start.
        a: [f64; 3],
        /// Segment end.
        b: [f64; 3],
        /// Radius.
        radius: f64,
    },
    /// Cylinder along local y.
    Cylinder {
        /// Half height.
        half_height: f64,
        /// Radius.
        radius: f64,
    },
    /// Convex hull of points.
    ConvexHull {
        /// Points (at least 4, not coplanar).
        points: Vec<[f64; 3]>,
    },
    /// Closed triangle mesh from an OBJ file (path relative to the case file).
    TriangleMesh {
        /// OBJ path.
        obj: PathBuf,
        /// Uniform scale applied to the vertices.
        #[serde(default = "one")]
        scale: f64,
    },
    /// Half-space `n·p ≤ 0` (local frame), `n` the outward normal.
    HalfSpace {
        /// Outward normal (normalised on load).
        normal: [f64; 3],
    },
}

fn one() -> f64 {
    1.0
}

/// Explicit Ritz coefficients (basis `1, s/L, sin(2πis/L), cos(2πis/L)`).
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "Ritz coefficients `{\"theta\": [...], \"phi\": [...], \"psi\": [...], \"eps\": [...]}`"
)]
pub struct ShapeSpec {
    /// φ coefficients.
    pub phi: Option<Vec<f64>>,
    /// θ coefficients.
    pub theta: Option<Vec<f64>>,
    /// ψ coefficients.
    pub psi: Option<Vec<f64>>,
    /// ε coefficients.
    pub eps: Option<Vec<f64>>,
}

/// A validated case.
#[derive(Clone, Debug)]
pub struct Case {
    /// Case name.
    pub name: String,
    /// Description.
    pub description: String,
    /// The file it came from.
    pub path: PathBuf,
    /// The static problem.
    pub problem: StaticProblem,
    /// How it is built (the grasp margin rebuilds it with a split basis and a disturbance).
    pub builder: StaticProblemBuilder,
    /// Obstacles (also inside the problem's constraints).
    pub obstacles: Vec<Arc<Obstacle>>,
    /// Start of the solve, or the shape to evaluate.
    pub initial: Vec<f64>,
    /// Whether `initial` came from explicit coefficients.
    pub explicit_shape: bool,
    /// Report points (case units).
    pub report_points: Vec<f64>,
    /// Static solver options.
    pub options: StaticOptions,
    /// Raw `plan` section.
    pub plan: Option<serde_json::Value>,
    /// Raw `grasp` section.
    pub grasp: Option<serde_json::Value>,
    /// The parsed file.
    pub file: CaseFile,
    /// Legal but suspicious values, each with what was assumed (the CLI prints them).
    pub warnings: Vec<String>,
}

/// The largest case file read (bytes): far above any real case, small enough that a path to
/// `/dev/zero` or a huge file fails at once instead of filling the memory.
pub const MAX_CASE_BYTES: u64 = 64 << 20;
/// The largest OBJ mesh read (bytes).
pub const MAX_MESH_BYTES: u64 = 256 << 20;

/// Reads at most `cap` bytes of `path`; a longer file (or an endless one such as `/dev/zero`)
/// is an error that says so.
pub fn read_capped(path: &Path, cap: u64) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let file = std::fs::File::open(path)?;
    let meta = file.metadata()?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_char_device() || t.is_block_device() {
            return Err(std::io::Error::other("a device, not a file"));
        }
    }
    if meta.is_dir() {
        return Err(std::io::Error::other("a folder, not a file"));
    }
    if meta.is_file() && meta.len() > cap {
        return Err(std::io::Error::other(format!(
            "{} MiB, larger than the {} MiB this tool reads",
            meta.len() >> 20,
            cap >> 20
        )));
    }
    let mut bytes = Vec::new();
    file.take(cap + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > cap {
        return Err(std::io::Error::other(format!(
            "larger than the {} MiB this tool reads",
            cap >> 20
        )));
    }
    Ok(bytes)
}

/// [`read_capped`] as UTF-8 text.
pub fn read_text_capped(path: &Path, cap: u64) -> std::io::Result<String> {
    String::from_utf8(read_capped(path, cap)?)
        .map_err(|_| std::io::Error::new(std::io::ErrorKind::InvalidData, "not UTF-8 text"))
}

/// Reads and validates a case file.
pub fn load(path: &Path) -> Result<Case, Error> {
    let text = read_text_capped(path, MAX_CASE_BYTES).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        source: e,
    })?;
    parse(&text, path)
}

/// Parses and validates case text; `path` names it in errors and anchors relative paths.
pub fn parse(text: &str, path: &Path) -> Result<Case, Error> {
    let mut de = serde_json::Deserializer::from_str(text);
    let file: CaseFile = field_path::read(&mut de)
        .and_then(|file| de.end().map(|()| file).map_err(|e| (String::new(), e)))
        .map_err(|(field, e)| field_path::file_error(text, path, field, e))?;
    build(file, path)
}

pub(crate) struct V<'a> {
    pub(crate) path: &'a Path,
}

impl V<'_> {
    pub(crate) fn err(&self, field: impl Into<String>, msg: impl Into<String>) -> Error {
        Error::invalid(self.path, field, msg)
    }
    pub(crate) fn finite(&self, field: &str, v: f64) -> Result<f64, Error> {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.err(
                field,
                format!("must be finite, got {}", crate::error::Num(v)),
            ))
        }
    }
    pub(crate) fn positive(&self, field: &str, v: f64) -> Result<f64, Error> {
        self.finite(field, v)?;
        if v > 0.0 {
            Ok(v)
        } else {
            Err(self.err(
                field,
                format!("must be positive, got {}", crate::error::Num(v)),
            ))
        }
    }
    fn profile_positive(&self, field: &str, p: &Profile) -> Result<(), Error> {
        if !p.is_finite() {
            return Err(self.err(field, "must be finite"));
        }
        if p.min() <= 0.0 {
            return Err(self.err(
                field,
                format!("must be positive along the rod, got minimum {}", p.min()),
            ));
        }
        Ok(())
    }
    fn vec3(&self, field: &str, v: [f64; 3]) -> Result<[f64; 3], Error> {
        for (k, c) in v.iter().enumerate() {
            self.finite(&format!("{field}[{k}]"), *c)?;
        }
        Ok(v)
    }
    fn arc(&self, field: &str, s: f64, l: f64) -> Result<f64, Error> {
        self.finite(field, s)?;
        if !(0.0..=l).contains(&s) {
            return Err(self.err(field, format!("arc length {s} outside [0, {l}]")));
        }
        Ok(s / l)
    }
}

fn build(file: CaseFile, path: &Path) -> Result<Case, Error> {
    let v = V { path };
    let r = &file.rod;
    let l = v.positive("rod.length", r.length)?;
    v.profile_positive("rod.flexural_rigidity", &r.flexural_rigidity)?;
    if let Some(p) = &r.torsional_rigidity {
        if file.planar {
            return Err(v.err(
                "rod.torsional_rigidity",
                "not used by a planar rod: remove it or set \"planar\": false",
            ));
        }
        v.profile_positive("rod.torsional_rigidity", p)?;
    } else if !file.planar {
        return Err(v.err(
            "rod.torsional_rigidity",
            "required for a spatial rod (\"planar\": false)",
        ));
    }
    if let Some(p) = &r.extensional_rigidity {
        v.profile_positive("rod.extensional_rigidity", p)?;
    }
    let weight = r.weight_per_length.unwrap_or(Profile::Constant(0.0));
    if !weight.is_finite() || weight.min() < 0.0 {
        return Err(v.err("rod.weight_per_length", "must be finite and non-negative"));
    }
    let radius = r.radius.unwrap_or(l / 1000.0);
    v.finite("rod.radius", radius)?;
    if radius < 0.0 || radius >= 0.5 * l {
        return Err(v.err(
            "rod.radius",
            format!("must be in [0, L/2), got {}", crate::error::Num(radius)),
        ));
    }
    let d = file.discretisation;
    crate::rod::model::check_sizes(d.basis_pairs, d.panels, d.gauss_points, d.samples)
        .map_err(|e| v.err(format!("discretisation.{}", e.field), e.message))?;
    let warnings = limits::check(&file, &v)?;
    let rod = Rod {
        length: l,
        flexural: r.flexural_rigidity,
        torsional: r.torsional_rigidity,
        extensional: r.extensional_rigidity,
        weight,
        radius,
    };
    let layout = Layout {
        basis: Basis::new(d.basis_pairs).of_kind(basis_of(&file)),
        spatial: !file.planar,
        extensible: r.extensional_rigidity.is_some(),
        free_base: file.base.free,
    };
    let base = v.vec3("base.position", file.base.position)?;
    if file.planar && base[1] != 0.0 {
        return Err(v.err(
            "base.position[1]",
            "a planar rod lies in the x–z plane: y must be 0",
        ));
    }

    // Arc lengths first, then loads, then each constraint's content.
    for (i, c) in file.constraints.iter().enumerate() {
        match c {
            ConstraintSpec::Position { s, .. } | ConstraintSpec::Orientation { s, .. } => {
                v.arc(&format!("constraints[{i}].s"), *s, l)?;
            }
            ConstraintSpec::RelativePosition { s_a, s_b, .. } => {
                v.arc(&format!("constraints[{i}].s_a"), *s_a, l)?;
                v.arc(&format!("constraints[{i}].s_b"), *s_b, l)?;
            }
        }
    }
    let mut builder = StaticProblem::builder(rod.clone(), layout)
        .discretisation(Discretisation {
            panels: d.panels,
            gauss_points: d.gauss_points,
        })
        .samples(d.samples)
        .chord_contacts(d.contact == ContactModel::Chords)
        .base(base)
        .self_contact(file.self_contact);
    for (i, f) in file.forces.iter().enumerate() {
        v.arc(&format!("forces[{i}].s"), f.s, l)?;
        let force = v.vec3(&format!("forces[{i}].force"), f.force)?;
        let reference = v.vec3(&format!("forces[{i}].reference"), f.reference)?;
        if file.planar && force[1] != 0.0 {
            return Err(v.err(
                format!("forces[{i}].force[1]"),
                "a planar rod cannot take a y force",
            ));
        }
        builder = builder.load(f.s, force, reference);
    }
    // The angles' reference frame, away from the pole where the case allows it, and the
    // orientation constraints written in it.
    let angle_frame = frame::choose(&file).map_err(|m| v.err("angle_frame", m))?;
    let start = match &file.shape {
        Some(sh) => Some(coefficients(&v, "shape", sh, &layout, base.map(|c| c / l))?),
        None => None,
    };
    // A written start's angles at `s` pick the branch of each converted orientation.
    let start_angles = start.as_ref().map(|a| {
        let layout = &layout;
        move |s: f64| layout.angles_at(a, s / l)
    });
    let converted = angle_frame.map(|r| {
        builder = builder.clone().angle_frame(r);
        frame::convert(
            &file,
            r,
            start_angles.as_ref().map(|f| f as &dyn Fn(f64) -> [f64; 3]),
        )
    });

    // Fixed points for the reachability check: (t, position, all components fixed).
    let mut fixed: Vec<(f64, [f64; 3])> = Vec::new();
    if !file.base.free {
        fixed.push((0.0, base));
    }
    let comps = layout.components();
    for (i, c) in file.constraints.iter().enumerate() {
        let field = |f: &str| format!("constraints[{i}].{f}");
        match c {
            ConstraintSpec::Position { s, x, y, z, name } => {
                let t = s / l;
                let mut rows = Vec::new();
                let mut fixed_pos = [0.0; 3];
                let mut all_fixed = true;
                for (k, (nm, cs)) in [("x", x), ("y", y), ("z", z)].into_iter().enumerate() {
                    let Some(cs) = cs else {
                        if comps.contains(&k) {
                            all_fixed = false;
                        }
                        continue;
                    };
                    if !comps.contains(&k) {
                        // `"y": 0` says what a planar rod does anyway.
                        if matches!(*cs, CoordSpec::Equal(val) if val == 0.0) {
                            continue;
                        }
                        return Err(v.err(
                            field(nm),
                            "a planar rod lies in the x–z plane: y must be 0 or absent",
                        ));
                    }
                    match *cs {
                        CoordSpec::Equal(val) => {
                            v.finite(&field(nm), val)?;
                            rows.push((k, Bound::Equal(val)));
                            fixed_pos[k] = val;
                        }
                        CoordSpec::Range(RangeSpec { min, max }) => {
                            all_fixed = false;
                            if min.is_none() && max.is_none() {
                                return Err(
                                    v.err(field(nm), "give a number, or \"min\" and/or \"max\"")
                                );
                            }
                            if let Some(mn) = min {
                                v.finite(&format!("{}.min", field(nm)), mn)?;
                                rows.push((k, Bound::AtLeast(mn)));
                            }
                            if let Some(mx) = max {
                                v.finite(&format!("{}.max", field(nm)), mx)?;
                                rows.push((k, Bound::AtMost(mx)));
                            }
                            if let (Some(mn), Some(mx)) = (min, max)
                                && mn > mx
                            {
                                return Err(v.err(field(nm), format!("min {mn} exceeds max {mx}")));
                            }
                        }
                    }
                }
                if rows.is_empty() {
                    return Err(v.err(
                        format!("constraints[{i}]"),
                        "a position constraint needs at least one of x, y, z",
                    ));
                }
                if all_fixed {
                    fixed.push((t, fixed_pos));
                }
                let name = name.clone().unwrap_or_else(|| format!("position at s={s}"));
                builder = builder.position(name, *s, &rows);
            }
            ConstraintSpec::RelativePosition {
                s_a,
                s_b,
                x,
                y,
                z,
                name,
            } => {
                let mut rows = Vec::new();
                let mut vec = [0.0; 3];
                for (k, (nm, val)) in [("x", x), ("y", y), ("z", z)].into_iter().enumerate() {
                    let Some(val) = val else { continue };
                    if !comps.contains(&k) {
                        if *val == 0.0 {
                            continue;
                        }
                        return Err(v.err(
                            field(nm),
                            "a planar rod lies in the x–z plane: y must be 0 or absent",
                        ));
                    }
                    v.finite(&field(nm), *val)?;
                    rows.push((k, *val));
                    vec[k] = *val;
                }
                if rows.is_empty() {
                    return Err(v.err(
                        format!("constraints[{i}]"),
                        "a relative position needs at least one of x, y, z",
                    ));
                }
                if rows.len() == comps.len() && !layout.extensible {
                    let dist = vec.iter().map(|c| c * c).sum::<f64>().sqrt();
                    if dist > (s_b - s_a).abs() * (1.0 + 1e-12) {
                        return Err(v.err(format!("constraints[{i}]"), format!(
                            "unreachable: points {} apart along an inextensible rod cannot be {dist} apart",
                            (s_b - s_a).abs()
                        )));
                    }
                }
                let name = name
                    .clone()
                    .unwrap_or_else(|| format!("relative position {s_a}→{s_b}"));
                builder = builder.relative_position(name, *s_a, *s_b, &rows);
            }
            ConstraintSpec::Orientation {
                s,
                phi,
                theta,
                psi,
                phi_plus_psi,
                name,
            } => {
                let mut rows = Vec::new();
                if phi_plus_psi.is_some() && (phi.is_some() || psi.is_some()) {
                    return Err(v.err(
                        field("phi_plus_psi"),
                        "give either phi_plus_psi or phi/psi, not both",
                    ));
                }
                for (nm, ang, val) in [
                    ("phi", Angle::Field(Field::Phi), phi),
                    ("theta", Angle::Field(Field::Theta), theta),
                    ("psi", Angle::Field(Field::Psi), psi),
                    ("phi_plus_psi", Angle::PhiPlusPsi, phi_plus_psi),
                ] {
                    let Some(val) = val else { continue };
                    if ang != Angle::Field(Field::Theta) && !layout.spatial {
                        return Err(v.err(field(nm), "a planar rod has only theta"));
                    }
                    v.finite(&field(nm), *val)?;
                    rows.push((ang, *val));
                }
                if rows.is_empty() {
                    return Err(v.err(
                        format!("constraints[{i}]"),
                        "an orientation constraint needs at least one angle",
                    ));
                }
                // In the angles' frame, if the rod has one.
                if let Some(Some(local)) = converted.as_ref().map(|c| c[i].clone()) {
                    rows = local;
                }
                let name = name
                    .clone()
                    .unwrap_or_else(|| format!("orientation at s={s}"));
                builder = builder.orientation(name, *s, &rows);
            }
        }
    }
    if !layout.extensible {
        for (i, (ta, pa)) in fixed.iter().enumerate() {
            for (tb, pb) in &fixed[i + 1..] {
                let dist = (0..3).map(|k| (pa[k] - pb[k]).powi(2)).sum::<f64>().sqrt();
                let arc = (tb - ta).abs() * l;
                if dist > arc * (1.0 + 1e-12) + 1e-12 * l {
                    return Err(v.err("constraints", format!(
                        "unreachable: the points at s={} and s={} are {dist} apart but only {arc} of inextensible rod joins them",
                        ta * l, tb * l
                    )));
                }
            }
        }
    }

    let mut obstacles = Vec::new();
    for (i, o) in file.obstacles.iter().enumerate() {
        let f = |x: &str| format!("obstacles[{i}].{x}");
        let shape = build_shape(&v, &o.shape, &f("shape"), path)?;
        let position = v.vec3(&f("position"), o.position)?;
        let rotation = v.vec3(&f("rotation"), o.rotation)?;
        let margin = v.finite(&f("margin"), o.margin)?;
        if margin < 0.0 {
            return Err(v.err(f("margin"), "must be non-negative"));
        }
        let ob = Arc::new(Obstacle::new(
            o.name.clone().unwrap_or_else(|| format!("obstacle{i}")),
            shape,
            position,
            rotation,
        ));
        obstacles.push(ob.clone());
        builder = builder.obstacle(ob, margin);
    }
    let problem = builder
        .clone()
        .build()
        .map_err(|e| v.err("constraints", e.to_string()))?;
    let (initial, explicit_shape) = match start {
        Some(a) => (a, true),
        None => {
            let mut a = default_start(&layout, file.solver.perturbation, base.map(|c| c / l));
            // Along the held end's orientation in the angles' frame.
            if let Some(rows) = &converted {
                let held = frame::held_angles(rows, &file);
                for (f, v) in [
                    (Field::Phi, held[0]),
                    (Field::Theta, held[1]),
                    (Field::Psi, held[2]),
                ] {
                    if let Some(o) = layout.offset(f) {
                        a[o] += v;
                    }
                }
            }
            (a, false)
        }
    };
    let report_points = match &file.report_points {
        Some(p) => {
            for (i, s) in p.iter().enumerate() {
                v.arc(&format!("report_points[{i}]"), *s, l)?;
            }
            p.clone()
        }
        None => (0..=4).map(|j| j as f64 * l / 4.0).collect(),
    };
    file.solver
        .validate()
        .map_err(|e| v.err(format!("solver.{}", e.field), e.message))?;
    let options = file.solver.options();
    let name = file.name.clone().unwrap_or_else(|| {
        path.file_stem()
            .map_or("case".into(), |s| s.to_string_lossy().into_owned())
    });
    if name.is_empty() || name.contains(['/', '\\']) {
        return Err(v.err("name", "must be non-empty and contain no path separators"));
    }
    Ok(Case {
        name,
        description: file.description.clone(),
        path: path.to_path_buf(),
        problem,
        builder,
        obstacles,
        initial,
        explicit_shape,
        report_points,
        options,
        plan: file.plan.clone(),
        grasp: file.grasp.clone(),
        file,
        warnings,
    })
}

fn build_shape(
    v: &V,
    s: &ShapeKind,
    field: &str,
    case_path: &Path,
) -> Result<ObstacleShape, Error> {
    let vv = |p: [f64; 3]| Vector::new(p[0], p[1], p[2]);
    Ok(match s {
        ShapeKind::Cuboid { half_extents } => {
            for (k, h) in half_extents.iter().enumerate() {
                v.positive(&format!("{field}.half_extents[{k}]"), *h)?;
            }
            ObstacleShape::Cuboid(Cuboid::new(vv(*half_extents)))
        }
        ShapeKind::Ball { radius } => {
            ObstacleShape::Ball(Ball::new(v.positive(&format!("{field}.radius"), *radius)?))
        }
        ShapeKind::Capsule { a, b, radius } => {
            v.vec3(&format!("{field}.a"), *a)?;
            v.vec3(&format!("{field}.b"), *b)?;
            let r = v.positive(&format!("{field}.radius"), *radius)?;
            ObstacleShape::capsule(*a, *b, r)
        }
        ShapeKind::Cylinder {
            half_height,
            radius,
        } => {
            let h = v.positive(&format!("{field}.half_height"), *half_height)?;
            let r = v.positive(&format!("{field}.radius"), *radius)?;
            ObstacleShape::Cylinder(Cylinder::new(h, r))
        }
        ShapeKind::ConvexHull { points } => {
            for (i, p) in points.iter().enumerate() {
                v.vec3(&format!("{field}.points[{i}]"), *p)?;
            }
            ObstacleShape::convex_hull(points).map_err(|m| v.err(format!("{field}.points"), m))?
        }
        ShapeKind::TriangleMesh { obj, scale } => {
            let sc = v.positive(&format!("{field}.scale"), *scale)?;
            let full = case_path.parent().unwrap_or(Path::new(".")).join(obj);
            let text = read_text_capped(&full, MAX_MESH_BYTES).map_err(|e| {
                v.err(
                    format!("{field}.obj"),
                    format!("cannot read {}: {e}", full.display()),
                )
            })?;
            let obj = crate::scene::mesh::parse_obj(&text)
                .map_err(|e| v.err(format!("{field}.obj"), format!("{}: {e}", full.display())))?;
            let verts: Vec<[f64; 3]> = obj.vertices.iter().map(|p| p.map(|c| c * sc)).collect();
            crate::scene::mesh::check_solid(&verts, &obj.triangles).map_err(|d| {
                let what = d.describe(|t| format!("line {}", obj.lines[t]));
                match d {
                    crate::scene::mesh::MeshDefect::NotFinite { .. }
                    | crate::scene::mesh::MeshDefect::TooLarge => v.err(
                        format!("{field}.scale"),
                        format!("{}: {what}", full.display()),
                    ),
                    _ => v.err(
                        format!("{field}.obj"),
                        format!("{}: {what}", full.display()),
                    ),
                }
            })?;
            ObstacleShape::checked_triangle_mesh(&verts, obj.triangles)
                .map_err(|e| v.err(format!("{field}.obj"), format!("{}: {e}", full.display())))?
        }
        ShapeKind::HalfSpace { normal } => {
            let n = v.vec3(&format!("{field}.normal"), *normal)?;
            ObstacleShape::half_space(n).map_err(|m| v.err(format!("{field}.normal"), m))?
        }
    })
}

/// The basis `file` names, or its default: Legendre polynomials, but the paper's functions for
/// a case that writes Ritz coefficients without naming their basis.
pub(crate) fn basis_of(file: &CaseFile) -> crate::rod::basis::BasisKind {
    use crate::rod::basis::BasisKind;
    let writes = file.shape.is_some()
        || file.plan.as_ref().is_some_and(|p| {
            ["start", "goal"]
                .iter()
                .any(|k| p.get(*k).is_some_and(|e| e.get("shape").is_some()))
        });
    file.discretisation.basis.unwrap_or(if writes {
        BasisKind::Paper
    } else {
        BasisKind::Legendre
    })
}

pub(crate) fn coefficients(
    v: &V,
    prefix: &str,
    sh: &ShapeSpec,
    layout: &Layout,
    base: [f64; 3],
) -> Result<Vec<f64>, Error> {
    let mut a = vec![0.0; layout.len()];
    let nb = layout.nb();
    for (nm, f, vals) in [
        ("phi", Field::Phi, &sh.phi),
        ("theta", Field::Theta, &sh.theta),
        ("psi", Field::Psi, &sh.psi),
        ("eps", Field::Eps, &sh.eps),
    ] {
        let Some(vals) = vals else { continue };
        let field = format!("{prefix}.{nm}");
        let off = layout.offset(f).ok_or_else(|| {
            v.err(
                &field,
                if f == Field::Eps {
                    "the rod is inextensible (no extensional_rigidity)"
                } else {
                    "a planar rod has only theta (and eps)"
                },
            )
        })?;
        if vals.len() != nb {
            return Err(v.err(
                &field,
                format!(
                    "expected {nb} coefficients (2 + 2·basis_pairs), got {}",
                    vals.len()
                ),
            ));
        }
        for (i, c) in vals.iter().enumerate() {
            a[off + i] = v.finite(&format!("{field}[{i}]"), *c)?;
        }
    }
    if let Some(o) = layout.base_offset() {
        for (k, &c) in layout.components().iter().enumerate() {
            a[o + k] = base[c];
        }
    }
    Ok(a)
}

pub use crate::statics::problem::default_start;
