//! The discretised rod: Ritz basis values at quadrature nodes and the material properties there,
//! precomputed once per problem in dimensionless units.
//!
//! Scaling (paper §4.3–4.5): arc length `t = s/L`, positions `x/L`, energies in `Rf/L`, forces in
//! `Rf/L²`, moments in `Rf/L`, where `Rf` is the mean flexural rigidity. The dimensionless
//! material functions are then `Rf(s)/Rf`, `Rt(s)/Rf` (ρt), `Re(s) L²/Rf` (ρe) and
//! `D(s) L³/Rf` (ρg).

use crate::rod::Rod;
use crate::rod::layout::{Field, Layout};
use crate::rod::quadrature::Mesh;

/// A point force `p` applied at `s` (paper eq. 12): it does work `p · (x(s) − x_ref)`.
#[derive(Clone, Debug, PartialEq)]
pub struct PointLoad {
    /// Dimensionless arc length of the point of application.
    pub t: f64,
    /// Force in units of `Rf/L²`.
    pub force: [f64; 3],
    /// Reference position of the point (dimensionless) from which its displacement is measured.
    pub reference: [f64; 3],
}

/// Discretisation settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Discretisation {
    /// Uniform panels of the composite Gauss–Legendre rule (refined at every needed point).
    pub panels: usize,
    /// Gauss points per panel.
    pub gauss_points: usize,
}

/// Most intervals between the points checked against obstacles and self-contact.
pub const MAX_SAMPLES: usize = 2000;
/// Most `samples` with self-contact (its rows grow as samples²): a case file's bound, and the
/// bound on the samples a plan is made again with.
pub const MAX_SELF_CONTACT_SAMPLES: usize = 400;

/// Checks the sizes a problem is built with against the ranges a case file allows: basis
/// pairs 0..=32, panels 1..=2000, Gauss points 1..=16, sample intervals 1..=2000; the error
/// names the size outside its range (`basis_pairs`, `panels`, `gauss_points`, `samples`).
pub fn check_sizes(
    basis_pairs: usize,
    panels: usize,
    gauss_points: usize,
    samples: usize,
) -> Result<(), crate::error::SettingsError> {
    for (field, value, range) in [
        ("basis_pairs", basis_pairs, 0..=32),
        ("panels", panels, 1..=2000),
        ("gauss_points", gauss_points, 1..=16),
        ("samples", samples, 1..=MAX_SAMPLES),
    ] {
        if !range.contains(&value) {
            return Err(crate::error::SettingsError::new(
                field,
                format!(
                    "must be in {}..={}, got {value}",
                    range.start(),
                    range.end()
                ),
            ));
        }
    }
    Ok(())
}

impl Default for Discretisation {
    fn default() -> Self {
        Discretisation {
            panels: 16,
            gauss_points: 4,
        }
    }
}

/// Most Ritz functions per field for which the positions' vector–Jacobian product keeps its
/// sums in registers (four AVX2 vectors).
pub(crate) const LANES: usize = 16;

/// `rows` (each of length `n`) padded with zeros to [`LANES`], or nothing when `n > LANES`: the
/// form in which the hot loops keep their sums in registers.
pub(crate) fn padded<'a>(rows: impl Iterator<Item = &'a [f64]>, n: usize) -> Vec<[f64; LANES]> {
    if n > LANES {
        return Vec::new();
    }
    rows.map(|row| {
        let mut p = [0.0; LANES];
        p[..n].copy_from_slice(row);
        p
    })
    .collect()
}

/// The rod model, ready to evaluate shapes and energies.
#[derive(Clone, Debug)]
pub struct Model {
    /// Physical rod.
    pub rod: Rod,
    /// Coefficient layout.
    pub layout: Layout,
    /// Quadrature mesh.
    pub mesh: Mesh,
    /// Dimensionless base position `x(0)` used when the base is not free.
    pub base: [f64; 3],
    /// Point loads (eq. 12–13).
    pub loads: Vec<PointLoad>,
    pub(crate) load_boundary: Vec<usize>,
    /// Basis values, node-major (`nodes × nb`).
    pub(crate) e: Vec<f64>,
    /// Basis derivatives `de/dt`, node-major.
    pub(crate) de: Vec<f64>,
    /// Basis values, function-major (`nb × nodes`): a field at every node is a sum of `nb`
    /// scaled rows, which vectorises.
    pub(crate) e_rows: Vec<f64>,
    /// Basis derivatives, function-major.
    pub(crate) de_rows: Vec<f64>,
    /// Basis values, node-major, each node's padded with zeros to [`LANES`] (empty when
    /// `nb > LANES`): the positions' vector–Jacobian product keeps its sums in registers.
    pub(crate) e_lanes: Vec<[f64; LANES]>,
    /// Basis derivatives in [`Model::e_lanes`]'s form: the energy gradient keeps its sums in
    /// registers.
    pub(crate) de_lanes: Vec<[f64; LANES]>,
    /// `w · Rf(t)/Rf`.
    pub(crate) wf: Vec<f64>,
    /// `w · Rt(t)/Rf`.
    pub(crate) wt: Vec<f64>,
    /// `w · Re(t) L²/Rf`.
    pub(crate) we: Vec<f64>,
    /// `w · ∫ₜ¹ D(u) du · L³/Rf`: gravity integrated by parts, `∫ D x ds = x(0)∫D + ∫ ζₓ(t) ∫ₜ¹D`.
    pub(crate) wg: Vec<f64>,
    /// `∫₀¹ D L³/Rf`: the base term of the gravitational energy.
    pub(crate) gravity_total: f64,
    /// The part of the energy Hessian that does not depend on the coefficients (flexure in θ',
    /// torsion in ψ', extension in ε), row-major `n×n`.
    pub(crate) constant_hessian: Vec<f64>,
    /// For a planar rod without gravity, whose energy is the quadratic form `½ aᵀ K a` of
    /// `constant_hessian`: `K` as a sum of squares `Σ_r (R_r · a)²` (empty otherwise).
    pub(crate) energy_roots: Vec<EnergyRoot>,
    /// The angles' reference frame `R` (row-major): the frame of the fields' Euler angles is
    /// `R A(φ, θ, ψ)` and positions are `x(0) + R ∫ (1+ε) ζ`, so the ZYZ pole (`θ = 0, π`)
    /// lies along `R ẑ`. `None` is the identity (the case's own axes, as in the paper).
    pub(crate) frame: Option<[[f64; 3]; 3]>,
}

/// One square-root row of the constant energy Hessian: `√λ v` for an eigenpair `(λ, v)` of its
/// flexure (θ) or extension (ε) block. A sum of squares keeps the rounding of the node sums it
/// replaces; `aᵀ(Ka)` does not where large coefficients cancel (a split basis), and its noise
/// stalled the grasp solves' line searches.
#[derive(Clone, Debug)]
pub(crate) struct EnergyRoot {
    /// Offset of the block's coefficients.
    pub(crate) offset: usize,
    /// Flexure (θ block) rather than extension (ε block).
    pub(crate) flexural: bool,
    /// `√λ v`, one entry per basis function.
    pub(crate) row: Vec<f64>,
}

impl Model {
    /// Builds the model. `points` are dimensionless arc lengths where positions are needed
    /// (constraint points, obstacle samples); they become panel boundaries.
    pub fn new(
        rod: Rod,
        layout: Layout,
        disc: Discretisation,
        base: [f64; 3],
        loads: Vec<PointLoad>,
        points: &[f64],
    ) -> Model {
        let mut all: Vec<f64> = points.to_vec();
        all.extend(loads.iter().map(|l| l.t));
        let mesh = Mesh::new(disc.panels, disc.gauss_points, &all);
        let nb = layout.nb();
        let nn = mesh.nodes.len();
        let mut e = vec![0.0; nn * nb];
        let mut de = vec![0.0; nn * nb];
        let rf_ref = rod.rf_ref();
        let l = rod.length;
        let (mut wf, mut wt, mut we, mut wg) =
            (vec![0.0; nn], vec![0.0; nn], vec![0.0; nn], vec![0.0; nn]);
        for (q, (&t, &w)) in mesh.nodes.iter().zip(&mesh.weights).enumerate() {
            layout.basis.values(t, &mut e[q * nb..(q + 1) * nb]);
            layout.basis.derivatives(t, &mut de[q * nb..(q + 1) * nb]);
            wf[q] = w * rod.flexural.at(t) / rf_ref;
            wt[q] = w * rod.torsional.map_or(0.0, |p| p.at(t)) / rf_ref;
            we[q] = w * rod.extensional.map_or(0.0, |p| p.at(t)) * l * l / rf_ref;
            wg[q] = w * rod.weight.integral_from(t) * l.powi(3) / rf_ref;
        }
        let transpose =
            |m: &[f64]| -> Vec<f64> { (0..nb * nn).map(|k| m[(k % nn) * nb + k / nn]).collect() };
        let (e_rows, de_rows) = (transpose(&e), transpose(&de));
        let e_lanes = padded(e.chunks_exact(nb), nb);
        let de_lanes = padded(de.chunks_exact(nb), nb);
        let gravity_total = rod.weight.integral_from(0.0) * l.powi(3) / rf_ref;
        let load_boundary = loads.iter().map(|ld| mesh.boundary_index(ld.t)).collect();
        let mut model = Model {
            rod,
            layout,
            mesh,
            base,
            loads,
            load_boundary,
            e,
            de,
            e_rows,
            de_rows,
            e_lanes,
            de_lanes,
            wf,
            wt,
            we,
            wg,
            gravity_total,
            constant_hessian: Vec::new(),
            energy_roots: Vec::new(),
            frame: None,
        };
        model.constant_hessian = model.assemble_constant_hessian();
        if !model.layout.spatial && model.gravity_total == 0.0 && model.wg.iter().all(|&w| w == 0.0)
        {
            model.energy_roots = model.constant_hessian_roots();
        }
        model
    }

    /// The square-root rows of the constant Hessian's flexure and extension blocks.
    fn constant_hessian_roots(&self) -> Vec<EnergyRoot> {
        let (n, nb) = (self.n(), self.nb());
        let blocks = [
            Some((0, true)),
            self.layout.offset(Field::Eps).map(|o| (o, false)),
        ];
        let mut roots = Vec::new();
        for (offset, flexural) in blocks.into_iter().flatten() {
            let k = nalgebra::DMatrix::from_fn(nb, nb, |i, j| {
                self.constant_hessian[(offset + i) * n + offset + j]
            });
            let eig = k.symmetric_eigen();
            for (j, &lambda) in eig.eigenvalues.iter().enumerate() {
                if lambda > 0.0 {
                    let s = lambda.sqrt();
                    let row = eig.eigenvectors.column(j).iter().map(|v| s * v).collect();
                    roots.push(EnergyRoot {
                        offset,
                        flexural,
                        row,
                    });
                }
            }
        }
        roots
    }

    /// Sets the angles' reference frame `R` (row-major, a proper rotation): the Euler angles
    /// then describe `Rᵀ` times the case's frames, and the ZYZ pole lies along `R ẑ`. Only a
    /// 3D rod can take one other than the identity; `None` if `R` is refused.
    pub fn with_frame(mut self, r: [[f64; 3]; 3]) -> Option<Model> {
        let identity = crate::rod::kinematics::is_identity(&r);
        if !crate::rod::kinematics::is_rotation(r, 1e-12) || !(self.layout.spatial || identity) {
            return None;
        }
        self.frame = (!identity).then_some(r);
        Some(self)
    }

    /// With a frame, the vertical `x̂` in the angles' frame, `Rᵀ x̂` (the first row of R),
    /// which gravity reads.
    #[inline]
    pub(crate) fn up(&self) -> Option<[f64; 3]> {
        self.frame.map(|r| r[0])
    }

    /// The angles' reference frame `R` if it is not the identity.
    pub fn angle_frame(&self) -> Option<[[f64; 3]; 3]> {
        self.frame
    }

    /// `R v`: a vector of the angles' frame in the case's axes.
    #[inline]
    pub fn to_case(&self, v: [f64; 3]) -> [f64; 3] {
        match &self.frame {
            None => v,
            Some(r) => std::array::from_fn(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2]),
        }
    }

    /// `Rᵀ v`: a vector of the case's axes in the angles' frame.
    #[inline]
    pub fn to_angles(&self, v: [f64; 3]) -> [f64; 3] {
        match &self.frame {
            None => v,
            Some(r) => std::array::from_fn(|i| r[0][i] * v[0] + r[1][i] * v[1] + r[2][i] * v[2]),
        }
    }

    /// `R m`: a rotation written in the angles' frame, in the case's axes.
    pub fn rotation_to_case(&self, m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
        match &self.frame {
            None => m,
            Some(r) => std::array::from_fn(|i| {
                std::array::from_fn(|j| (0..3).map(|k| r[i][k] * m[k][j]).sum())
            }),
        }
    }

    /// `Rᵀ m`: a rotation in the case's axes, written in the angles' frame.
    pub fn rotation_to_angles(&self, m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
        crate::rod::kinematics::in_frame(self.frame.as_ref(), m)
    }

    /// Number of unknowns.
    pub fn n(&self) -> usize {
        self.layout.len()
    }

    /// Number of Ritz functions per field.
    pub fn nb(&self) -> usize {
        self.layout.nb()
    }

    /// Number of quadrature nodes.
    pub fn nodes(&self) -> usize {
        self.mesh.nodes.len()
    }

    /// Basis values at node `q`.
    #[inline]
    pub(crate) fn e_at(&self, q: usize) -> &[f64] {
        let nb = self.nb();
        &self.e[q * nb..(q + 1) * nb]
    }

    /// Basis derivatives at node `q`.
    #[inline]
    pub(crate) fn de_at(&self, q: usize) -> &[f64] {
        let nb = self.nb();
        &self.de[q * nb..(q + 1) * nb]
    }

    /// The boundary index of the mesh point nearest to `t`.
    pub fn boundary(&self, t: f64) -> usize {
        self.mesh.boundary_index(t)
    }
}
