//! The settings of a static solve: one struct, with the case file's names (its `solver`
//! section), defaults and validation; [`StaticSettings::options`] gives the solver's options.

use super::StaticOptions;
use crate::error::SettingsError;
use crate::optim::AlOptions;
use serde::{Deserialize, Serialize};

/// Settings of a static solve: the case file's `solver` section.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(
    deny_unknown_fields,
    default,
    expecting = "an object of solver settings (`feasibility_tol`, `max_outer`, …)"
)]
pub struct StaticSettings {
    /// Constraint violation tolerance (positions in units of `L`).
    pub feasibility_tol: f64,
    /// KKT residual tolerance (energies in units of `Rf/L`).
    pub optimality_tol: f64,
    /// Initial penalty (dimensionless).
    pub rho_initial: f64,
    /// Penalty cap.
    pub rho_max: f64,
    /// Outer iterations.
    pub max_outer: usize,
    /// Inner (Newton) iterations per outer iteration.
    pub max_inner: usize,
    /// Size (radians) of the deterministic perturbation added to the natural state when no
    /// `shape` is given (the straight rod is stationary).
    pub perturbation: f64,
    /// Compute the stability verdict.
    pub stability: bool,
    /// Second-order (dual Newton) multiplier updates instead of `λ + ρc`.
    pub second_order_multipliers: bool,
}

impl Default for StaticSettings {
    fn default() -> Self {
        let al = AlOptions::default();
        StaticSettings {
            feasibility_tol: al.feasibility_tol,
            optimality_tol: al.optimality_tol,
            rho_initial: al.rho_initial,
            rho_max: al.rho_max,
            max_outer: al.max_outer,
            max_inner: al.max_inner,
            perturbation: 0.1,
            stability: true,
            second_order_multipliers: al.newton_multipliers,
        }
    }
}

impl StaticSettings {
    /// Checks every setting.
    pub fn validate(&self) -> Result<(), SettingsError> {
        let bad = SettingsError::new;
        for (field, v) in [
            ("feasibility_tol", self.feasibility_tol),
            ("optimality_tol", self.optimality_tol),
            ("rho_initial", self.rho_initial),
            ("rho_max", self.rho_max),
        ] {
            SettingsError::positive(field, v)?;
        }
        SettingsError::finite("perturbation", self.perturbation)?;
        if self.rho_max < self.rho_initial {
            return Err(bad("rho_max", "must be at least solver.rho_initial"));
        }
        if self.max_outer == 0 || self.max_inner == 0 {
            return Err(bad("max_outer", "iteration budgets must be positive"));
        }
        Ok(())
    }

    /// The solver's options.
    pub fn options(&self) -> StaticOptions {
        StaticOptions {
            al: AlOptions {
                feasibility_tol: self.feasibility_tol,
                optimality_tol: self.optimality_tol,
                rho_initial: self.rho_initial,
                rho_max: self.rho_max,
                max_outer: self.max_outer,
                max_inner: self.max_inner,
                newton_multipliers: self.second_order_multipliers,
                ..AlOptions::default()
            },
            stability: self.stability,
            balance: true,
        }
    }
}
