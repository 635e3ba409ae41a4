//! The domain types: a rod, obstacles, a static problem (a builder held open so that Python
//! code can add to it), and the controlled end's start and goal.

use crate::errors::{build_error, input_error, settings_error};
use dlo_planner::error::SettingsError;
use dlo_planner::rod::basis::BasisKind;
use dlo_planner::rod::layout::Layout;
use dlo_planner::rod::model::Discretisation;
use dlo_planner::scene::obstacle::ObstacleShape;
use dlo_planner::statics::{StaticProblemBuilder, StaticSettings};
use pyo3::prelude::*;
use std::sync::Arc;

fn finite(field: &str, x: f64) -> PyResult<f64> {
    SettingsError::finite(field, x).map_err(settings_error)
}

fn positive(field: &str, x: f64) -> PyResult<f64> {
    SettingsError::positive(field, x).map_err(settings_error)
}

fn vec3(field: &str, v: [f64; 3]) -> PyResult<[f64; 3]> {
    for (k, c) in v.iter().enumerate() {
        finite(&format!("{field}[{k}]"), *c)?;
    }
    Ok(v)
}

/// A uniform rod: length, rigidities (flexural; torsional for a 3D rod, absent for a planar
/// one; extensional for an extensible one), weight per length and radius, in consistent units.
#[pyclass(frozen, module = "dlo_planner")]
#[derive(Clone)]
pub struct Rod {
    pub(crate) inner: dlo_planner::rod::Rod,
}

#[pymethods]
impl Rod {
    #[new]
    #[pyo3(signature = (length, flexural_rigidity, torsional_rigidity=None, extensional_rigidity=None, weight_per_length=0.0, radius=None))]
    fn new(
        length: f64,
        flexural_rigidity: f64,
        torsional_rigidity: Option<f64>,
        extensional_rigidity: Option<f64>,
        weight_per_length: f64,
        radius: Option<f64>,
    ) -> PyResult<Self> {
        let l = positive("length", length)?;
        let mut rod =
            dlo_planner::rod::Rod::uniform(l, positive("flexural_rigidity", flexural_rigidity)?);
        if let Some(rt) = torsional_rigidity {
            rod = rod.with_torsional_rigidity(positive("torsional_rigidity", rt)?);
        }
        if let Some(re) = extensional_rigidity {
            rod = rod.with_extensional_rigidity(positive("extensional_rigidity", re)?);
        }
        if finite("weight_per_length", weight_per_length)? < 0.0 {
            return Err(input_error(
                Some("weight_per_length"),
                "must be non-negative",
            ));
        }
        let radius = finite("radius", radius.unwrap_or(l / 1000.0))?;
        if !(0.0..0.5 * l).contains(&radius) {
            return Err(input_error(
                Some("radius"),
                format!("must be in [0, length/2), got {radius}"),
            ));
        }
        Ok(Rod {
            inner: rod.with_weight(weight_per_length).with_radius(radius),
        })
    }

    /// Length `L`.
    #[getter]
    fn length(&self) -> f64 {
        self.inner.length
    }

    /// Whether the rod is 3D (it has a torsional rigidity).
    #[getter]
    fn spatial(&self) -> bool {
        self.inner.torsional.is_some()
    }

    /// Cross-section radius.
    #[getter]
    fn radius(&self) -> f64 {
        self.inner.radius
    }

    fn __repr__(&self) -> String {
        let r = &self.inner;
        format!(
            "Rod(length={}, flexural_rigidity={}, torsional_rigidity={}, extensional_rigidity={}, weight_per_length={}, radius={})",
            r.length,
            r.flexural.mean(),
            r.torsional.map_or("None".into(), |p| p.mean().to_string()),
            r.extensional
                .map_or("None".into(), |p| p.mean().to_string()),
            r.weight.mean(),
            r.radius
        )
    }
}

/// A rigid obstacle: a shape placed at `position`, turned by the axis-angle vector `rotation`
/// (radians).
#[pyclass(frozen, module = "dlo_planner")]
#[derive(Clone)]
pub struct Obstacle {
    pub(crate) inner: Arc<dlo_planner::scene::Obstacle>,
}

impl Obstacle {
    fn placed(
        name: String,
        shape: ObstacleShape,
        position: [f64; 3],
        rotation: [f64; 3],
    ) -> PyResult<Self> {
        let (p, r) = (vec3("position", position)?, vec3("rotation", rotation)?);
        Ok(Obstacle {
            inner: Arc::new(dlo_planner::scene::Obstacle::new(name, shape, p, r)),
        })
    }
}

#[pymethods]
impl Obstacle {
    /// A sphere.
    #[staticmethod]
    #[pyo3(signature = (name, radius, position, rotation=[0.0; 3]))]
    fn ball(name: String, radius: f64, position: [f64; 3], rotation: [f64; 3]) -> PyResult<Self> {
        let shape = ObstacleShape::ball(positive("radius", radius)?);
        Self::placed(name, shape, position, rotation)
    }

    /// A box with half extents along its local x, y, z.
    #[staticmethod]
    #[pyo3(signature = (name, half_extents, position, rotation=[0.0; 3]))]
    fn cuboid(
        name: String,
        half_extents: [f64; 3],
        position: [f64; 3],
        rotation: [f64; 3],
    ) -> PyResult<Self> {
        for (k, h) in half_extents.iter().enumerate() {
            positive(&format!("half_extents[{k}]"), *h)?;
        }
        Self::placed(
            name,
            ObstacleShape::cuboid(half_extents),
            position,
            rotation,
        )
    }

    /// A cylinder whose axis runs along its local y.
    #[staticmethod]
    #[pyo3(signature = (name, half_height, radius, position, rotation=[0.0; 3]))]
    fn cylinder(
        name: String,
        half_height: f64,
        radius: f64,
        position: [f64; 3],
        rotation: [f64; 3],
    ) -> PyResult<Self> {
        let shape = ObstacleShape::cylinder(
            positive("half_height", half_height)?,
            positive("radius", radius)?,
        );
        Self::placed(name, shape, position, rotation)
    }

    /// A capsule: the points within `radius` of the segment from `a` to `b` (local frame).
    #[staticmethod]
    #[pyo3(signature = (name, a, b, radius, position=[0.0; 3], rotation=[0.0; 3]))]
    fn capsule(
        name: String,
        a: [f64; 3],
        b: [f64; 3],
        radius: f64,
        position: [f64; 3],
        rotation: [f64; 3],
    ) -> PyResult<Self> {
        let shape =
            ObstacleShape::capsule(vec3("a", a)?, vec3("b", b)?, positive("radius", radius)?);
        Self::placed(name, shape, position, rotation)
    }

    /// The convex hull of `points` (n × 3, at least 4 spanning a volume).
    #[staticmethod]
    #[pyo3(signature = (name, points, position=[0.0; 3], rotation=[0.0; 3]))]
    fn convex_hull(
        name: String,
        points: Vec<[f64; 3]>,
        position: [f64; 3],
        rotation: [f64; 3],
    ) -> PyResult<Self> {
        for (i, p) in points.iter().enumerate() {
            vec3(&format!("points[{i}]"), *p)?;
        }
        let shape =
            ObstacleShape::convex_hull(&points).map_err(|m| input_error(Some("points"), m))?;
        Self::placed(name, shape, position, rotation)
    }

    /// The half-space behind a plane through `position`: the points `p` with
    /// `normal · (p − position) ≤ 0` (before `rotation`), e.g. a table.
    #[staticmethod]
    #[pyo3(signature = (name, normal, position=[0.0; 3], rotation=[0.0; 3]))]
    fn half_space(
        name: String,
        normal: [f64; 3],
        position: [f64; 3],
        rotation: [f64; 3],
    ) -> PyResult<Self> {
        let shape =
            ObstacleShape::half_space(normal).map_err(|m| input_error(Some("normal"), m))?;
        Self::placed(name, shape, position, rotation)
    }

    /// A closed triangle mesh: `vertices` (n × 3) and `triangles` (m × 3 vertex indices,
    /// counter-clockwise seen from outside), e.g. NumPy arrays.
    #[staticmethod]
    #[pyo3(signature = (name, vertices, triangles, position=[0.0; 3], rotation=[0.0; 3]))]
    fn mesh(
        name: String,
        vertices: Vec<[f64; 3]>,
        triangles: Vec<[u32; 3]>,
        position: [f64; 3],
        rotation: [f64; 3],
    ) -> PyResult<Self> {
        let shape = ObstacleShape::triangle_mesh(&vertices, &triangles)
            .map_err(|m| input_error(Some("triangles"), m))?;
        Self::placed(name, shape, position, rotation)
    }

    /// Name.
    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }

    /// The signed distance from `point` to the surface (negative inside) and the outward
    /// normal there.
    fn signed_distance(&self, point: [f64; 3]) -> ([f64; 3], f64) {
        let (d, n) = self.inner.signed_distance(point);
        (n, d)
    }

    fn __repr__(&self) -> String {
        format!(
            "Obstacle({:?}, {:?}, position={:?})",
            self.inner.name,
            self.inner.shape,
            self.inner.position()
        )
    }
}

/// A static problem: the rod, its discretisation, the conditions at arc lengths, loads,
/// obstacles and self-contact. Methods that add to it return the problem, so calls chain.
#[pyclass(module = "dlo_planner")]
#[derive(Clone)]
pub struct StaticProblem {
    pub(crate) builder: StaticProblemBuilder,
    /// The built problem, kept until the next change.
    pub(crate) built: std::sync::OnceLock<dlo_planner::statics::StaticProblem>,
    pub(crate) spatial: bool,
    pub(crate) length: f64,
}

#[pymethods]
impl StaticProblem {
    #[new]
    #[pyo3(signature = (rod, basis_pairs=4, basis="legendre", panels=16, gauss_points=4, samples=32, base=[0.0; 3], free_base=false, contact="points"))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        rod: &Rod,
        basis_pairs: usize,
        basis: &str,
        panels: usize,
        gauss_points: usize,
        samples: usize,
        base: [f64; 3],
        free_base: bool,
        contact: &str,
    ) -> PyResult<Self> {
        let chords = match contact {
            "points" => false,
            "chords" => true,
            other => {
                return Err(input_error(
                    Some("contact"),
                    format!("must be \"points\" or \"chords\", got {other:?}"),
                ));
            }
        };
        dlo_planner::rod::model::check_sizes(basis_pairs, panels, gauss_points, samples)
            .map_err(settings_error)?;
        let kind = match basis {
            "paper" => BasisKind::Paper,
            "legendre" => BasisKind::Legendre,
            other => {
                return Err(input_error(
                    Some("basis"),
                    format!("must be \"paper\" or \"legendre\", got {other:?}"),
                ));
            }
        };
        let mut layout = Layout::of(&rod.inner, basis_pairs);
        layout.basis = layout.basis.of_kind(kind);
        layout.free_base = free_base;
        let builder = dlo_planner::statics::StaticProblem::builder(rod.inner.clone(), layout)
            .discretisation(Discretisation {
                panels,
                gauss_points,
            })
            .samples(samples)
            .chord_contacts(chords)
            .base(vec3("base", base)?);
        Ok(StaticProblem {
            builder,
            built: Default::default(),
            spatial: rod.spatial(),
            length: rod.inner.length,
        })
    }

    /// Clamps the rod at arc length `s`: the point at `position` and the Euler angles
    /// `angles` — `[θ]` on a planar rod, `[φ, θ, ψ]` (ZYZ) on a 3D one.
    fn clamp(
        mut slf: PyRefMut<'_, Self>,
        s: f64,
        position: [f64; 3],
        angles: Vec<f64>,
    ) -> PyRefMut<'_, Self> {
        slf.builder = slf.builder.clone().clamp(s, position, &angles);
        slf.built = Default::default();
        slf
    }

    /// Fixes the point at arc length `s` at `position`.
    fn fix_point(mut slf: PyRefMut<'_, Self>, s: f64, position: [f64; 3]) -> PyRefMut<'_, Self> {
        slf.builder = slf.builder.clone().fix_point(s, position);
        slf.built = Default::default();
        slf
    }

    /// Conditions on the position of the point at arc length `s`: `equal`, `at_least` and
    /// `at_most` map axes (`"x"`, `"y"`, `"z"`) to values. A finger of a grasp is a position
    /// with one bound, e.g. `at_least={"x": 0.02}`.
    #[pyo3(signature = (s, name=None, equal=None, at_least=None, at_most=None))]
    fn position(
        mut slf: PyRefMut<'_, Self>,
        s: f64,
        name: Option<String>,
        equal: Option<std::collections::BTreeMap<String, f64>>,
        at_least: Option<std::collections::BTreeMap<String, f64>>,
        at_most: Option<std::collections::BTreeMap<String, f64>>,
    ) -> PyResult<PyRefMut<'_, Self>> {
        use dlo_planner::constraints::Bound;
        let mut rows = Vec::new();
        for (field, given, bound) in [
            ("equal", equal, Bound::Equal as fn(f64) -> Bound),
            ("at_least", at_least, Bound::AtLeast),
            ("at_most", at_most, Bound::AtMost),
        ] {
            for (axis, v) in given.unwrap_or_default() {
                let k = match axis.as_str() {
                    "x" => 0,
                    "y" => 1,
                    "z" => 2,
                    _ => {
                        return Err(input_error(
                            Some(&format!("{field}.{axis}")),
                            "axes are \"x\", \"y\" and \"z\"",
                        ));
                    }
                };
                rows.push((k, bound(finite(&format!("{field}.{axis}"), v)?)));
            }
        }
        let name = name.unwrap_or_else(|| format!("position at s={s}"));
        slf.builder = slf.builder.clone().position(name, s, &rows);
        slf.built = Default::default();
        Ok(slf)
    }

    /// Prescribes some Euler angles (radians) of the frame at arc length `s`.
    #[pyo3(signature = (s, phi=None, theta=None, psi=None))]
    fn orientation(
        mut slf: PyRefMut<'_, Self>,
        s: f64,
        phi: Option<f64>,
        theta: Option<f64>,
        psi: Option<f64>,
    ) -> PyRefMut<'_, Self> {
        use dlo_planner::constraints::Angle;
        use dlo_planner::rod::layout::Field;
        let rows: Vec<(Angle, f64)> = [(Field::Phi, phi), (Field::Theta, theta), (Field::Psi, psi)]
            .into_iter()
            .filter_map(|(f, v)| v.map(|v| (Angle::Field(f), v)))
            .collect();
        let name = format!("orientation at s={s}");
        slf.builder = slf.builder.clone().orientation(name, s, &rows);
        slf.built = Default::default();
        slf
    }

    /// A dead load `force` at arc length `s`; its moment is taken about `reference`.
    #[pyo3(signature = (s, force, reference=[0.0; 3]))]
    fn load(
        mut slf: PyRefMut<'_, Self>,
        s: f64,
        force: [f64; 3],
        reference: [f64; 3],
    ) -> PyRefMut<'_, Self> {
        slf.builder = slf.builder.clone().load(s, force, reference);
        slf.built = Default::default();
        slf
    }

    /// An obstacle the rod must stay `margin` clear of.
    #[pyo3(signature = (obstacle, margin=0.0))]
    fn obstacle<'a>(
        mut slf: PyRefMut<'a, Self>,
        obstacle: &Obstacle,
        margin: f64,
    ) -> PyRefMut<'a, Self> {
        slf.builder = slf.builder.clone().obstacle(obstacle.inner.clone(), margin);
        slf.built = Default::default();
        slf
    }

    /// Whether the rod may not pass through itself.
    #[pyo3(signature = (on=true))]
    fn self_contact(mut slf: PyRefMut<'_, Self>, on: bool) -> PyRefMut<'_, Self> {
        slf.builder = slf.builder.clone().self_contact(on);
        slf.built = Default::default();
        slf
    }

    /// Whether the rod is 3D.
    #[getter]
    fn spatial(&self) -> bool {
        self.spatial
    }

    /// Number of Ritz coefficients.
    #[getter]
    fn coefficients(&self) -> PyResult<usize> {
        Ok(self.build()?.model.layout.len())
    }

    /// Solves the static shape (see `dlo_planner.StaticProblem.solve`).
    #[pyo3(signature = (initial=None, settings=None, report_points=None, points=None, log_dir=None, name="shape"))]
    #[allow(clippy::too_many_arguments)]
    fn solve(
        &self,
        py: Python<'_>,
        initial: Option<Vec<f64>>,
        settings: Option<&Bound<'_, PyAny>>,
        report_points: Option<Vec<f64>>,
        points: Option<usize>,
        log_dir: Option<std::path::PathBuf>,
        name: &str,
    ) -> PyResult<Py<PyAny>> {
        let problem = self.build()?;
        let settings = static_settings(settings)?;
        let initial = self.initial(&problem, initial, settings.perturbation)?;
        let job = crate::shape::Job {
            name: name.to_string(),
            problem,
            initial,
            options: settings.options(),
            report_points: report_points.unwrap_or_default(),
            points,
        };
        crate::shape::solve(py, job, log_dir.as_deref())
    }

    /// Evaluates the given coefficients without optimising (see `dlo energy`).
    #[pyo3(signature = (coefficients, report_points=None, points=None, name="shape"))]
    fn evaluate(
        &self,
        py: Python<'_>,
        coefficients: Vec<f64>,
        report_points: Option<Vec<f64>>,
        points: Option<usize>,
        name: &str,
    ) -> PyResult<Py<PyAny>> {
        let problem = self.build()?;
        let a = self.initial(&problem, Some(coefficients), 0.0)?;
        crate::shape::evaluate(
            py,
            name,
            problem,
            a,
            report_points.unwrap_or_default(),
            points,
        )
    }

    fn __repr__(&self) -> String {
        format!(
            "StaticProblem({} rod of length {})",
            if self.spatial { "3D" } else { "planar" },
            self.length
        )
    }
}

impl StaticProblem {
    /// The problem, or the builder's error.
    pub(crate) fn build(&self) -> PyResult<dlo_planner::statics::StaticProblem> {
        if let Some(p) = self.built.get() {
            return Ok(p.clone());
        }
        let p = self.builder.clone().build().map_err(build_error)?;
        Ok(self.built.get_or_init(|| p).clone())
    }

    /// `given` checked against the problem's size, or the natural start perturbed by `delta`.
    pub(crate) fn initial(
        &self,
        problem: &dlo_planner::statics::StaticProblem,
        given: Option<Vec<f64>>,
        delta: f64,
    ) -> PyResult<Vec<f64>> {
        let n = problem.model.layout.len();
        match given {
            None => Ok(problem.natural_start(delta)),
            Some(a) if a.len() != n => Err(input_error(
                Some("initial"),
                format!("the problem has {n} coefficients, got {}", a.len()),
            )),
            Some(a) => {
                for (i, x) in a.iter().enumerate() {
                    finite(&format!("initial[{i}]"), *x)?;
                }
                Ok(a)
            }
        }
    }
}

/// Static solver settings from a dict with the case file's `solver` names.
pub(crate) fn static_settings(given: Option<&Bound<'_, PyAny>>) -> PyResult<StaticSettings> {
    let s: StaticSettings = crate::settings::merged(given, "solver")?;
    s.validate().map_err(crate::errors::settings_error)?;
    Ok(s)
}

/// Where the controlled end starts or goes: a pose (solved for its static shape) or a shape
/// given by its coefficients.
#[pyclass(frozen, module = "dlo_planner")]
#[derive(Clone)]
pub struct End {
    pub(crate) position: Option<[f64; 3]>,
    pub(crate) rotation: Option<[[f64; 3]; 3]>,
    /// Euler angles as a case file writes them (`[θ]` planar, `[φ, θ, ψ]` 3D).
    pub(crate) angles: Option<Vec<f64>>,
    pub(crate) shape: Option<Vec<f64>>,
}

#[pymethods]
impl End {
    /// The pose of the `s = L` cross-section: `position` and its orientation, as a rotation
    /// matrix (rows; columns ξ, η and the tangent ζ), a unit quaternion `(w, x, y, z)` or Euler
    /// angles as a case file writes them (`[θ]` on a planar rod, `[φ, θ, ψ]` on a 3D one);
    /// with none, the orientation is left free (the static shape that holds the end there).
    #[staticmethod]
    #[pyo3(signature = (position, rotation=None, quaternion=None, angles=None))]
    fn pose(
        position: [f64; 3],
        rotation: Option<[[f64; 3]; 3]>,
        quaternion: Option<[f64; 4]>,
        angles: Option<Vec<f64>>,
    ) -> PyResult<Self> {
        let position = vec3("position", position)?;
        if let Some(angles) = angles {
            if rotation.is_some() || quaternion.is_some() {
                return Err(input_error(
                    Some("angles"),
                    "give one orientation: a rotation matrix, a quaternion or Euler angles",
                ));
            }
            for (i, x) in angles.iter().enumerate() {
                finite(&format!("angles[{i}]"), *x)?;
            }
            return Ok(End {
                position: Some(position),
                rotation: None,
                angles: Some(angles),
                shape: None,
            });
        }
        let rotation = match (rotation, quaternion) {
            (Some(r), None) => {
                for (i, row) in r.iter().enumerate() {
                    vec3(&format!("rotation[{i}]"), *row)?;
                }
                if !dlo_planner::rod::kinematics::is_rotation(r, 1e-6) {
                    return Err(input_error(Some("rotation"), "not a rotation matrix"));
                }
                r
            }
            (None, Some(q)) => rotation_of(q)?,
            (None, None) => {
                return Ok(End {
                    position: Some(position),
                    rotation: None,
                    angles: None,
                    shape: None,
                });
            }
            (Some(_), Some(_)) => {
                return Err(input_error(
                    Some("rotation"),
                    "give a rotation matrix or a quaternion, not both",
                ));
            }
        };
        Ok(End {
            position: Some(position),
            rotation: Some(rotation),
            angles: None,
            shape: None,
        })
    }

    /// A shape given by its Ritz coefficients (as a solve returns them).
    #[staticmethod]
    fn shape(coefficients: Vec<f64>) -> PyResult<Self> {
        for (i, x) in coefficients.iter().enumerate() {
            finite(&format!("coefficients[{i}]"), *x)?;
        }
        Ok(End {
            position: None,
            rotation: None,
            angles: None,
            shape: Some(coefficients),
        })
    }

    fn __repr__(&self) -> String {
        match (&self.position, &self.shape) {
            (Some(p), None) if let Some(angles) = &self.angles => {
                format!("End.pose(position={p:?}, angles={angles:?})")
            }
            (Some(p), None) if self.rotation.is_none() => format!("End.pose(position={p:?})"),
            (Some(p), _) => format!("End.pose(position={p:?}, rotation={:?})", self.rotation),
            (None, Some(a)) => format!("End.shape({} coefficients)", a.len()),
            _ => "End()".into(),
        }
    }
}

impl End {
    /// The library's end on `held`; an error names `angles` where their count is not the
    /// rod's.
    pub(crate) fn resolve(
        &self,
        held: &dlo_planner::statics::StaticProblem,
    ) -> PyResult<dlo_planner::planner::End> {
        use dlo_planner::planner::End as Lib;
        Ok(match (&self.position, &self.rotation, &self.shape) {
            (Some(p), _, _) if self.angles.is_some() => {
                let angles = self.angles.as_deref().unwrap_or_default();
                Lib::euler(held, *p, angles).map_err(|m| input_error(Some("angles"), m))?
            }
            (Some(p), Some(r), _) => Lib::pose(held, *p, *r),
            (Some(p), None, _) => Lib::position(held, *p),
            (_, _, Some(a)) => Lib::shape(a.clone()),
            _ => unreachable!("an End is built by `pose` or `shape`"),
        })
    }
}

/// The rotation matrix of a unit quaternion `(w, x, y, z)`: its squared norm 1 to 1e-2, then
/// normalised, as in a case file.
fn rotation_of(q: [f64; 4]) -> PyResult<[[f64; 3]; 3]> {
    dlo_planner::planner::trajectory::rotation_of_unit_quaternion(q)
        .map_err(|m| input_error(Some("quaternion"), m))
}
