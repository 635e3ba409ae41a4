//! Pinned–pinned compression against the closed-form elastica (complete elliptic integrals).

use crate::common::*;
use dlo_planner::statics::{StaticOptions, solve_static};

/// The size of the force (x–z plane) the constraint `name` exerts on the rod.
fn reaction(sol: &dlo_planner::statics::StaticSolution, name: &str) -> f64 {
    let f = sol
        .reactions
        .iter()
        .find(|r| r.constraint == name)
        .unwrap()
        .force;
    (f[0] * f[0] + f[2] * f[2]).sqrt()
}

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
    let c: Vec<Constraint> = vec![
        clamp(&model, 0.0),
        Constraint::from(PositionConstraint {
            name: "end".into(),
            boundary: model.boundary(1.0),
            rows: vec![(0, Bound::Equal(0.0)), (2, Bound::Equal(0.6))],
        }),
        clamp(&model, 1.0),
    ];
    let mut p = dlo_planner::statics::problem::StaticProblem::new(model, c);
    let mut a0 = vec![0.0; p.model.n()];
    a0[2] = 0.1;
    let sol = solve_static(&mut p, &a0, &StaticOptions::default());
    let load = reaction(&sol, "end");
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

/// The shipped pinned case in the Legendre basis (`"basis": "legendre"`) against the closed
/// form: within 1e-6 at 5 pairs (12 functions) at l/L = 0.95, 0.80, 0.60 (measured 4e-14,
/// 1e-10, 3e-9; the paper's basis at 5 pairs: 1.9e-4, 1.7e-4, 1.3e-4), and within 2e-4 at 3
/// pairs (8 functions; measured 2e-8, 5e-7, 4.7e-6).
#[test]
fn legendre_basis_converges_spectrally_on_the_pinned_elastica() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("planning_cases/pinned_buckling_080.json");
    let text = std::fs::read_to_string(&path).unwrap();
    for (pairs, tol) in [(3, 1e-5), (5, 1e-6)] {
        for ratio in [0.95, 0.80, 0.60] {
            let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
            v["constraints"][0]["z"] = serde_json::json!(ratio * 100.0);
            v["discretisation"] = serde_json::json!({ "basis_pairs": pairs, "basis": "legendre" });
            let mut c = dlo_planner::case::parse(&v.to_string(), &path).unwrap();
            let sol = solve_static(&mut c.problem, &c.initial, &c.options);
            assert_eq!(sol.status, dlo_planner::statics::SolveStatus::Converged);
            let p = reaction(&sol, "right pin");
            let exact = pinned_elastica_load(ratio) / 1e4;
            let rel = (p - exact).abs() / exact;
            eprintln!("legendre {pairs} pairs, l/L = {ratio}: relative error {rel:.2e}");
            assert!(rel < tol, "{pairs} pairs, l/L = {ratio}: {rel:e}");
        }
    }
}

/// A cantilever under a dead tip load perpendicular to it (`α = F L²/Rf`), by shooting:
/// `θ'' = α cos θ`, `θ(0) = 0`, `θ'(1) = 0` (the load along −x), classical RK4 on 20,000 steps
/// (error below 1e-13 here) with bisection on `θ'(0)`. Returns the tip angle, tip
/// position `(x, z)` and the flexural energy `½∫θ'²`.
fn cantilever_by_shooting(alpha: f64) -> (f64, [f64; 2], f64) {
    let run = |c: f64| {
        let n = 20_000;
        let h = 1.0 / n as f64;
        // (θ, θ', x, z, U)
        let f = |y: [f64; 5]| {
            [
                y[1],
                alpha * y[0].cos(),
                y[0].sin(),
                y[0].cos(),
                0.5 * y[1] * y[1],
            ]
        };
        let mut y = [0.0, c, 0.0, 0.0, 0.0];
        for _ in 0..n {
            let k1 = f(y);
            let k2 = f(std::array::from_fn(|i| y[i] + 0.5 * h * k1[i]));
            let k3 = f(std::array::from_fn(|i| y[i] + 0.5 * h * k2[i]));
            let k4 = f(std::array::from_fn(|i| y[i] + h * k3[i]));
            y = std::array::from_fn(|i| {
                y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
        }
        y
    };
    // θ'(1) is positive at θ'(0) = 0 and negative at −α (the clamp's moment is at most
    // F L): bisection on the branch between them.
    let (mut lo, mut hi) = (-alpha, 0.0);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if run(mid)[1] > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let c1 = 0.5 * (lo + hi);
    let y = run(c1);
    (y[0], [y[2], y[3]], y[4])
}

/// Bisshopp–Drucker's cantilever (α = 1, 2, 5, 10) in the Legendre basis at 7 pairs (16
/// functions): tip angle, tip position and flexural energy within 1e-6 relative of the
/// shooting solution (measured 2e-11 or better); the paper's basis at 7 pairs is 0.2–2 % off.
#[test]
fn legendre_basis_matches_the_cantilever_under_a_tip_load() {
    for alpha in [1.0, 2.0, 5.0, 10.0] {
        let (angle, tip, flexural) = cantilever_by_shooting(alpha);
        let text = format!(
            r#"{{ "name": "cantilever", "planar": true,
  "rod": {{ "length": 1.0, "flexural_rigidity": 1.0, "radius": 0.001 }},
  "discretisation": {{ "basis_pairs": 7, "basis": "legendre" }},
  "constraints": [ {{ "type": "orientation", "s": 0.0, "theta": 0.0 }} ],
  "forces": [ {{ "s": 1.0, "force": [{}, 0.0, 0.0] }} ] }}"#,
            -alpha
        );
        let mut c =
            dlo_planner::case::parse(&text, std::path::Path::new("cantilever.json")).unwrap();
        let sol = solve_static(&mut c.problem, &c.initial, &c.options);
        assert_eq!(sol.status, dlo_planner::statics::SolveStatus::Converged);
        let m = &c.problem.model;
        let got_angle = m.angles_at(&sol.a, 1.0)[1];
        let x = m.position_at(&sol.a, 1.0);
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
        eprintln!(
            "α = {alpha}: angle {:.1e}, x {:.1e}, z {:.1e}, energy {:.1e}",
            rel(got_angle, angle),
            rel(x[0], tip[0]),
            rel(x[2], tip[1]),
            rel(sol.energy.flexural, flexural)
        );
        assert!(
            rel(got_angle, angle) < 1e-6,
            "α = {alpha}: tip angle {got_angle} vs {angle}"
        );
        assert!(
            rel(x[0], tip[0]) < 1e-6 && rel(x[2], tip[1]) < 1e-6,
            "α = {alpha}: tip {x:?} vs {tip:?}"
        );
        assert!(
            rel(sol.energy.flexural, flexural) < 1e-6,
            "α = {alpha}: energy"
        );
    }
}

/// The case file's default basis is Legendre: the pinned elastica at l = 0.8 L written with no
/// `discretisation` gives the closed-form reaction to 1e-8 (7e-9; the paper's basis of the same size,
/// named, to 2e-4 only). Ritz coefficients written without naming a basis are read in the
/// paper's, as they were written: the paper-basis solution's coefficients, given as `shape`,
/// evaluate to its energy to 1e-12.
#[test]
fn the_default_basis_is_legendre_but_written_coefficients_read_in_the_papers() {
    use dlo_planner::case;
    use dlo_planner::rod::basis::BasisKind;
    use std::path::Path;
    let exact = pinned_elastica_load(0.8) / 100.0_f64.powi(2);
    let text = |extra: &str| {
        format!(
            r#"{{ "rod": {{ "length": 100.0, "flexural_rigidity": 1.0 }}, "planar": true{extra},
  "constraints": [ {{ "type": "position", "s": 100.0, "x": 0.0, "z": 80.0, "name": "pin" }} ] }}"#
        )
    };
    let solve = |extra: &str| {
        let mut c = case::parse(&text(extra), Path::new("pinned.json")).unwrap();
        let sol = solve_static(&mut c.problem, &c.initial, &c.options);
        assert_eq!(sol.status, dlo_planner::statics::SolveStatus::Converged);
        (c, sol)
    };
    let (c, sol) = solve("");
    assert_eq!(c.problem.model.layout.basis.kind(), BasisKind::Legendre);
    let p = reaction(&sol, "pin");
    assert!((p - exact).abs() < 1e-8 * exact, "{p} vs {exact}");
    let (c, paper) = solve(r#", "discretisation": { "basis": "paper" }"#);
    assert_eq!(c.problem.model.layout.basis.kind(), BasisKind::Paper);
    let pp = reaction(&paper, "pin");
    assert!((pp - exact).abs() > 1e-4 * exact, "{pp} vs {exact}");
    let theta = serde_json::to_string(&paper.a).unwrap();
    let (c, _) = solve(&format!(r#", "shape": {{ "theta": {theta} }}"#));
    assert_eq!(c.problem.model.layout.basis.kind(), BasisKind::Paper);
    let mut p2 = c.problem.clone();
    let written = dlo_planner::statics::evaluate_shape(&mut p2, &c.initial);
    assert!(
        (written.energy.potential() - paper.energy.potential()).abs()
            < 1e-12 * paper.energy.potential()
    );
}
