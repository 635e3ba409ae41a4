//! Physical description of a rod: length, rigidities, weight and radius (paper §3.1).

use serde::{Deserialize, Serialize};

/// A material property along the rod: constant, or linear in `s` (the paper's trapezoidal strip,
/// §5.1, has rigidity and weight linear in `s`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(
    untagged,
    expecting = "expected a number, or `{\"start\": a, \"end\": b}` (linear in s)"
)]
pub enum Profile {
    /// The same value everywhere.
    Constant(f64),
    /// `start` at `s = 0`, `end` at `s = L`, linear in between.
    Linear {
        /// Value at `s = 0`.
        start: f64,
        /// Value at `s = L`.
        end: f64,
    },
}

impl Profile {
    /// Value at the dimensionless arc length `t = s/L`.
    pub fn at(&self, t: f64) -> f64 {
        match *self {
            Profile::Constant(v) => v,
            Profile::Linear { start, end } => start + (end - start) * t,
        }
    }

    /// `∫ₜ¹ p(u) du` in the dimensionless arc length.
    pub fn integral_from(&self, t: f64) -> f64 {
        match *self {
            Profile::Constant(v) => v * (1.0 - t),
            Profile::Linear { start, end } => {
                let slope = end - start;
                start * (1.0 - t) + 0.5 * slope * (1.0 - t * t)
            }
        }
    }

    /// Mean value over the rod.
    pub fn mean(&self) -> f64 {
        self.integral_from(0.0)
    }

    /// Smallest value over the rod (profiles are linear, so at an end).
    pub fn min(&self) -> f64 {
        self.at(0.0).min(self.at(1.0))
    }

    /// True when every value is finite.
    pub fn is_finite(&self) -> bool {
        self.at(0.0).is_finite() && self.at(1.0).is_finite()
    }
}

/// The rod's physical properties, in the case's own consistent units.
#[derive(Clone, Debug, PartialEq)]
pub struct Rod {
    /// Natural length `L`.
    pub length: f64,
    /// Flexural rigidity `Rf(s)` (force × length²).
    pub flexural: Profile,
    /// Torsional rigidity `Rt(s)`; required for spatial rods.
    pub torsional: Option<Profile>,
    /// Extensional rigidity `Re(s)` (force); `None` for an inextensible rod (no `ε` field).
    pub extensional: Option<Profile>,
    /// Weight per unit length `D(s)` (force / length); gravity acts along `−x` (the paper's eq. 11
    /// adds `∫ D x ds`, so `x` is "up").
    pub weight: Profile,
    /// Cross-section radius `r`, used by obstacle and self-contact constraints.
    pub radius: f64,
}

impl Rod {
    /// A uniform rod of `length` with flexural rigidity `rf`, as a case file's defaults make it:
    /// no torsional rigidity (planar), inextensible, weightless, of radius `length / 1000`.
    pub fn uniform(length: f64, rf: f64) -> Rod {
        Rod {
            length,
            flexural: Profile::Constant(rf),
            torsional: None,
            extensional: None,
            weight: Profile::Constant(0.0),
            radius: length / 1000.0,
        }
    }

    /// The same rod with torsional rigidity `rt` (needed by a 3D rod).
    pub fn with_torsional_rigidity(mut self, rt: f64) -> Rod {
        self.torsional = Some(Profile::Constant(rt));
        self
    }

    /// The same rod, extensible with rigidity `re`.
    pub fn with_extensional_rigidity(mut self, re: f64) -> Rod {
        self.extensional = Some(Profile::Constant(re));
        self
    }

    /// The same rod with weight `w` per unit length (gravity along `−x`).
    pub fn with_weight(mut self, w: f64) -> Rod {
        self.weight = Profile::Constant(w);
        self
    }

    /// The same rod with cross-section radius `r`.
    pub fn with_radius(mut self, r: f64) -> Rod {
        self.radius = r;
        self
    }

    /// Reference flexural rigidity used for scaling: the mean of `Rf`.
    pub fn rf_ref(&self) -> f64 {
        self.flexural.mean()
    }

    /// Energy unit `Rf/L`: dimensionless energies multiply by this.
    pub fn energy_unit(&self) -> f64 {
        self.rf_ref() / self.length
    }

    /// Force unit `Rf/L²`.
    pub fn force_unit(&self) -> f64 {
        self.rf_ref() / (self.length * self.length)
    }

    /// The paper's `ρt = Rt/Rf` (mean values).
    pub fn rho_t(&self) -> Option<f64> {
        self.torsional.map(|p| p.mean() / self.rf_ref())
    }

    /// The paper's `ρe = Re L²/Rf` (mean values).
    pub fn rho_e(&self) -> Option<f64> {
        self.extensional
            .map(|p| p.mean() * self.length.powi(2) / self.rf_ref())
    }

    /// The paper's `ρg = D L³/Rf` (mean values).
    pub fn rho_g(&self) -> f64 {
        self.weight.mean() * self.length.powi(3) / self.rf_ref()
    }
}
