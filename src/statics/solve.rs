//! The static solve: the multiplier method on a [`StaticProblem`], its multipliers turned into
//! reactions ([`super::reactions`](mod@super::reactions)), the moment balance and a stability verdict.

use crate::optim::augmented_lagrangian::{AlOptions, AlStatus, augmented_lagrangian};
use crate::rod::energy::EnergyTerms;
use crate::statics::problem::StaticProblem;
use crate::statics::reactions::{Reaction, SelfContactForce, reactions, self_contacts};

/// How a static solve ended.
pub type SolveStatus = AlStatus;

/// Solver settings of a static solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StaticOptions {
    /// Multiplier-method settings.
    pub al: AlOptions,
    /// Whether to compute the stability verdict (one Hessian: analytic where exact, else `2n`
    /// gradient evaluations; see [`crate::statics::stability`]).
    pub stability: bool,
    /// Whether to compute the global moment balance ([`StaticSolution::balance`]; on a weighted
    /// rod it integrates the positions at every quadrature node again).
    pub balance: bool,
}

impl Default for StaticOptions {
    fn default() -> Self {
        StaticOptions {
            al: AlOptions::default(),
            stability: true,
            balance: true,
        }
    }
}

impl StaticOptions {
    /// These options with the starting penalty `factor` times higher (at most the cap): a
    /// solve that did not converge from the usual penalty tries again with it.
    pub fn stiffer(&self, factor: f64) -> StaticOptions {
        StaticOptions {
            al: AlOptions {
                rho_initial: (self.al.rho_initial * factor).min(self.al.rho_max),
                ..self.al
            },
            ..*self
        }
    }
}

/// A solved static shape.
#[derive(Clone, Debug)]
pub struct StaticSolution {
    /// Ritz coefficients.
    pub a: Vec<f64>,
    /// Solver status.
    pub status: SolveStatus,
    /// Energy terms in the case's units.
    pub energy: EnergyTerms,
    /// Energy terms, dimensionless (`Rf/L`).
    pub energy_scaled: EnergyTerms,
    /// Multipliers per constraint row (dimensionless, `ℒ = V + Σλc`).
    pub lambda: Vec<f64>,
    /// Largest constraint violation (dimensionless; positions in units of `L`).
    pub max_violation: f64,
    /// KKT residual `‖∇V + Jᵀλ‖∞` (dimensionless).
    pub kkt_residual: f64,
    /// Reactions at each constraint.
    pub reactions: Vec<Reaction>,
    /// The global moment balance of the reactions, loads and gravity (`None` when not
    /// computed: [`StaticOptions::balance`]).
    pub balance: Option<crate::statics::balance::Balance>,
    /// Where the rod touches itself and how hard (largest first; empty without self-contact).
    pub self_contacts: Vec<SelfContactForce>,
    /// `Some(true)` stable, `Some(false)` unstable, `None` marginal or not computed (see
    /// [`StaticSolution::stability`]).
    pub stable: Option<bool>,
    /// The verdict: stable, unstable or marginal (`None` if not computed).
    pub stability: Option<crate::statics::stability::Verdict>,
    /// Smallest eigenvalue of the reduced Hessian against the fields' Gram matrix (units of
    /// `Rf/L`; see [`crate::statics::stability`]), if computed.
    pub min_reduced_eigenvalue: Option<f64>,
    /// Eigenvalues within the verdict's resolution of zero: directions along which the
    /// second-order check cannot decide.
    pub neutral_modes: Option<usize>,
    /// Exact gauge directions removed before judging (a free constant in ψ; φ−ψ on the pole).
    pub gauge_modes: Option<usize>,
    /// Outer iterations of the multiplier method.
    pub outer_iterations: usize,
    /// Objective evaluations.
    pub evaluations: usize,
}

/// Solves the static shape of `p` starting from `a0`.
pub fn solve_static(p: &mut StaticProblem, a0: &[f64], opts: &StaticOptions) -> StaticSolution {
    let mut a = a0.to_vec();
    let out = augmented_lagrangian(p, &mut a, None, opts.al);
    finish(p, a, out, opts)
}

/// Solves with multipliers warm-started from a previous solution (continuation).
pub fn solve_static_warm(
    p: &mut StaticProblem,
    a0: &[f64],
    lambda0: &[f64],
    opts: &StaticOptions,
) -> StaticSolution {
    let mut a = a0.to_vec();
    let out = augmented_lagrangian(p, &mut a, Some(lambda0), opts.al);
    finish(p, a, out, opts)
}

fn finish(
    p: &mut StaticProblem,
    a: Vec<f64>,
    out: crate::optim::AlOutcome,
    opts: &StaticOptions,
) -> StaticSolution {
    let judged = (opts.stability && out.status != AlStatus::NumericalFailure)
        .then(|| crate::statics::stability::judge(p, &a, &out.lambda));
    let verdict = judged.map(|j| j.verdict);
    let stable = match verdict {
        Some(crate::statics::stability::Verdict::Stable) => Some(true),
        Some(crate::statics::stability::Verdict::Unstable) => Some(false),
        _ => None,
    };
    let mut c = vec![0.0; crate::optim::Nlp::m(p)];
    crate::optim::Nlp::values(p, &a, &mut c);
    let energy_scaled = p.terms();
    let shape = p.model.evaluate(&a);
    let reactions = reactions(p, &a, &shape, &out.lambda);
    let balance = opts
        .balance
        .then(|| crate::statics::balance::balance(p, &a, &shape, &out.lambda, &reactions));
    let self_contacts = self_contacts(p, &shape, &out.lambda);
    StaticSolution {
        balance,
        self_contacts,
        energy: energy_scaled.scaled(p.model.rod.energy_unit()),
        energy_scaled,
        status: out.status,
        lambda: out.lambda,
        max_violation: out.max_violation,
        kkt_residual: out.kkt_residual,
        reactions,
        stable,
        stability: verdict,
        min_reduced_eigenvalue: judged.and_then(|j| j.min_eigenvalue),
        neutral_modes: judged.map(|j| j.neutral_modes),
        gauge_modes: judged.map(|j| j.gauge_modes),
        outer_iterations: out.outer_iterations,
        evaluations: out.evaluations,
        a,
    }
}

/// Evaluates the given coefficients without optimising: energy terms, constraint violation, and
/// the least-squares multipliers `argmin ‖∇V + Jᵀλ‖` (the reactions the shape would need if it
/// were an equilibrium; the returned KKT residual says how far it is from one).
pub fn evaluate_shape(p: &mut StaticProblem, a: &[f64]) -> Evaluation {
    use crate::optim::Nlp;
    use crate::optim::augmented_lagrangian::{kkt_residual, least_squares_multipliers, violation};
    let mut c = vec![0.0; p.m()];
    p.values(a, &mut c);
    let terms = p.terms();
    let viol = violation(p, &c);
    let zero = vec![0.0; p.m()];
    let (lambda, kkt) = least_squares_multipliers(p, a, &c, &zero, 1e-7)
        .unwrap_or_else(|| (zero.clone(), kkt_residual(p, a, &zero)));
    let shape = p.model.evaluate(a);
    let reactions = reactions(p, a, &shape, &lambda);
    Evaluation {
        lambda: lambda.clone(),
        energy: terms.scaled(p.model.rod.energy_unit()),
        max_violation: viol,
        balance: crate::statics::balance::balance(p, a, &shape, &lambda, &reactions),
        self_contacts: self_contacts(p, &shape, &lambda),
        reactions,
        kkt_residual: kkt,
    }
}

/// What [`evaluate_shape`] finds, with the least-squares multipliers standing for the
/// reactions the shape would need.
#[derive(Clone, Debug)]
pub struct Evaluation {
    /// Energy terms in the case's units.
    pub energy: EnergyTerms,
    /// Largest constraint violation (dimensionless).
    pub max_violation: f64,
    /// Reactions at each constraint.
    pub reactions: Vec<Reaction>,
    /// KKT residual (dimensionless).
    pub kkt_residual: f64,
    /// Global moment balance.
    pub balance: crate::statics::balance::Balance,
    /// Self-contact forces, largest first.
    pub self_contacts: Vec<SelfContactForce>,
    /// The least-squares multipliers (dimensionless, one per constraint row).
    pub lambda: Vec<f64>,
}
