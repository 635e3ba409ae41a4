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
    let f = sol
        .reactions
        .iter()
        .find(|r| r.constraint == "right pin")
        .unwrap()
        .force;
    // The base pin carries the opposite force (global balance, no other loads).
    let b = sol
        .reactions
        .iter()
        .find(|r| r.constraint == "base")
        .unwrap()
        .force;
    assert!((b[2] + f[2]).abs() < 1e-12 && (b[0] + f[0]).abs() < 1e-12);
    ((f[0] * f[0] + f[2] * f[2]).sqrt(), sol)
}

#[test]
fn pinned_reaction_matches_elastica_at_default_basis() {
    for ratio in [0.95, 0.80, 0.60] {
        let exact = pinned_elastica_load(ratio) / 100.0_f64.powi(2);
        let (p, sol) = buckle(ratio, 4);
        eprintln!(
            "l/L={ratio}: P={p:.6e} exact={exact:.6e} rel={:.2e} status={:?} viol={:.1e} kkt={:.1e} stable={:?} evals={}",
            (p - exact).abs() / exact,
            sol.status,
            sol.max_violation,
            sol.kkt_residual,
            sol.stable,
            sol.evaluations
        );
        assert!((p - exact).abs() / exact < 1e-3);
    }
}

#[test]
fn reaction_error_falls_as_the_basis_grows() {
    for ratio in [0.95, 0.60] {
        let exact = pinned_elastica_load(ratio) / 100.0_f64.powi(2);
        let errs: Vec<f64> = [1, 2, 3, 4, 6, 8]
            .iter()
            .map(|&pairs| {
                let (p, sol) = buckle(ratio, pairs);
                assert_eq!(sol.status, dlo_planner::statics::SolveStatus::Converged);
                (p - exact).abs() / exact
            })
            .collect();
        eprintln!("l/L = {ratio}: relative errors for 1, 2, 3, 4, 6, 8 pairs: {errs:?}");
        for w in errs.windows(2) {
            assert!(w[1] < w[0], "error must fall as the basis grows: {errs:?}");
        }
        assert!(errs[5] < 1e-4, "{errs:?}");
    }
}

#[test]
fn clamped_load_is_four_times_pinned() {
    // Clamped–clamped elastica of length L = two pinned ones of length L/2 back to back:
    // P_clamped = 4 P_pinned at the same l/L.
    use dlo_planner::constraints::{Bound, Constraint, PositionConstraint};
    let exact = 4.0 * pinned_elastica_load(0.6) / 100.0_f64.powi(2);
    let p0 = pinned_problem(0.6, 4);
    let model = p0.model.clone();
    let c: Vec<Box<dyn Constraint>> = vec![
        clamp(&model, 0.0),
        Box::new(PositionConstraint {
            name: "end".into(),
            boundary: model.boundary(1.0),
            rows: vec![(0, Bound::Equal(0.0)), (2, Bound::Equal(0.6))],
        }),
        clamp(&model, 1.0),
    ];
    let mut p = dlo_planner::problem::StaticProblem::new(model, c);
    let mut a0 = vec![0.0; p.model.n()];
    a0[2] = 0.1;
    let sol = solve_static(&mut p, &a0, &StaticOptions::default());
    let f = sol
        .reactions
        .iter()
        .find(|r| r.constraint == "end")
        .unwrap()
        .force;
    let load = (f[0] * f[0] + f[2] * f[2]).sqrt();
    eprintln!("clamped: {load:.6e} vs {exact:.6e}");
    assert_eq!(sol.status, dlo_planner::statics::SolveStatus::Converged);
    assert!((load - exact).abs() / exact < 1e-3);
}

#[test]
fn grasp_a_contact_forces_match_elastica() {
    // §6.2 grasp (a): unilateral finger contacts at both ends, base free. The contact
    // multipliers are the grasping force r0.
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("planning_cases/grasp_a_080.json");
    let text = std::fs::read_to_string(&path).unwrap();
    for ratio in [0.95, 0.80, 0.60] {
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        v["constraints"][1]["z"]["max"] = serde_json::json!(ratio * 100.0);
        let mut c = dlo_planner::case::parse(&v.to_string(), &path).unwrap();
        let sol = solve_static(&mut c.problem, &c.initial, &c.options);
        let exact = pinned_elastica_load(ratio) / 1e4;
        let (left, right) = (sol.reactions[0].force[2], -sol.reactions[1].force[2]);
        eprintln!(
            "grasp (a) l/L = {ratio}: r0 = {left:.6e} / {right:.6e}, closed form {exact:.6e}"
        );
        assert_eq!(sol.status, dlo_planner::statics::SolveStatus::Converged);
        assert!((left - exact).abs() / exact < 1e-3 && (right - exact).abs() / exact < 1e-3);
    }
}
