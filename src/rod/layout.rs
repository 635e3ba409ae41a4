//! Where each field's Ritz coefficients live in the optimisation vector.
//!
//! Order: `θ`, then `φ` and `ψ` (spatial rods only), then `ε` (extensible rods only), then the
//! base position `x(0)` when it is free (`x, z` for planar rods, `x, y, z` for spatial ones).
//! A planar rod (`φ = ψ = 0`) carries only the `θ` coefficients.

use crate::rod::basis::Basis;

/// One of the four functions of arc length that describe a shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    /// Euler angle `φ` (rotation about global z).
    Phi,
    /// Euler angle `θ` (tilt of the tangent away from z).
    Theta,
    /// Euler angle `ψ` (spin about the tangent).
    Psi,
    /// Extensional strain `ε`.
    Eps,
}

/// Coefficient layout of a problem.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layout {
    /// The Ritz basis shared by every field.
    pub basis: Basis,
    /// True for 3D rods with `φ, ψ` fields; false for planar rods in the x–z plane.
    pub spatial: bool,
    /// True when the rod has an `ε` field.
    pub extensible: bool,
    /// True when the base position `x(0)` is an unknown.
    pub free_base: bool,
}

impl Layout {
    /// The layout for `rod` with `2 + 2·pairs` Legendre polynomials per field (the default
    /// basis, as in case files; `layout.basis = Basis::new(pairs)` gives the paper's `pairs`
    /// sine–cosine pairs instead): 3D when the rod has a torsional rigidity, extensible when it
    /// has an extensional one, base fixed.
    pub fn of(rod: &crate::rod::Rod, pairs: usize) -> Layout {
        Layout {
            basis: Basis::new(pairs).of_kind(crate::rod::basis::BasisKind::Legendre),
            spatial: rod.torsional.is_some(),
            extensible: rod.extensional.is_some(),
            free_base: false,
        }
    }

    /// Number of coefficients of one field.
    pub fn nb(&self) -> usize {
        self.basis.len()
    }

    /// Offset of a field's coefficients, `None` when the layout has no such field.
    pub fn offset(&self, field: Field) -> Option<usize> {
        let nb = self.nb();
        match field {
            Field::Theta => Some(0),
            Field::Phi => self.spatial.then_some(nb),
            Field::Psi => self.spatial.then_some(2 * nb),
            Field::Eps => self
                .extensible
                .then_some(if self.spatial { 3 * nb } else { nb }),
        }
    }

    /// Number of field coefficients (without the base position).
    pub fn n_fields(&self) -> usize {
        let mut n = 1;
        if self.spatial {
            n += 2;
        }
        if self.extensible {
            n += 1;
        }
        n * self.nb()
    }

    /// Spatial components a position has in this layout: `[0, 2]` (x, z) planar, `[0, 1, 2]` spatial.
    pub fn components(&self) -> &'static [usize] {
        if self.spatial { &[0, 1, 2] } else { &[0, 2] }
    }

    /// Offset of the base position unknowns, if free.
    pub fn base_offset(&self) -> Option<usize> {
        self.free_base.then_some(self.n_fields())
    }

    /// Total number of unknowns.
    pub fn len(&self) -> usize {
        self.n_fields()
            + if self.free_base {
                self.components().len()
            } else {
                0
            }
    }

    /// Always false: every layout has `θ`.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// A field's coefficient slice of `a`, if present.
    pub fn field<'a>(&self, a: &'a [f64], field: Field) -> Option<&'a [f64]> {
        self.offset(field).map(|o| &a[o..o + self.nb()])
    }

    /// Euler angles `(φ, θ, ψ)` of coefficients `a` at dimensionless arc length `t` (zero for a
    /// field the layout does not have).
    pub fn angles_at(&self, a: &[f64], t: f64) -> [f64; 3] {
        let f = |field| self.field(a, field).map_or(0.0, |c| self.basis.eval(c, t));
        [f(Field::Phi), f(Field::Theta), f(Field::Psi)]
    }
}
