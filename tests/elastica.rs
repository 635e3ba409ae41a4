//! Pinned–pinned compression against the closed-form elastica (complete elliptic integrals).

mod common;
use common::*;
use dlo_planner::statics::{StaticOptions, solve_static};

fn buckle(ratio: f64, pairs: usize) -> (f64, dlo_planner::statics::StaticSolution) {
    let mut p = pinned_problem(ratio, pairs);
    let mut a0 = vec![0.0; p.model.n()];
    a0[1] = -0.2; // θ = 0.1(1 − 2t): a bulge towards +x
    a0[0] = 0.1;
    let sol = solve_static(&mut p, &a0, &StaticOptions::default());
    let f = sol.reactions[0].force;
    ((f[0] * f[0] + f[2] * f[2]).sqrt(), sol)
}

#[test]
fn pinned_reaction_matches_elastica_at_default_basis() {
    for ratio in [0.95, 0.80, 0.60] {
        let exact = pinned_elastica_load(ratio) / 100.0_f64.powi(2);
        let (p, sol) = buckle(ratio, 4);
        eprintln!("l/L={ratio}: P={p:.6e} exact={exact:.6e} rel={:.2e} status={:?} viol={:.1e} kkt={:.1e} stable={:?} evals={}", (p-exact).abs()/exact, sol.status, sol.max_violation, sol.kkt_residual, sol.stable, sol.evaluations);
        assert!((p - exact).abs() / exact < 1e-3);
    }
}
