//! Grasp stability (paper §6.2): initial grasping forces against the closed-form elastica, the
//! paper's Fig. 14 findings, Fig. 15's trends, and the split basis's gradients.

use crate::common;
use dlo_planner::grasp::Grasp;
use dlo_planner::optim::Nlp;
use std::f64::consts::FRAC_1_SQRT_2 as H;

/// Grasp (a) with the fingers `l` apart (l/L given).
fn grasp_a(ratio: f64, extra: &str) -> Grasp {
    let c = common::shipped_variant("grasp_a_080.json", |v| {
        v["constraints"][1]["z"]["max"] = serde_json::json!(100.0 * ratio);
        if !extra.is_empty() {
            v["grasp"] = serde_json::from_str(extra).unwrap();
        }
    });
    Grasp::from_case(&c).unwrap()
}

fn grasp_b(extra: &str) -> Grasp {
    let c = common::shipped_variant("grasp_b_pinch.json", |v| {
        if !extra.is_empty() {
            v["grasp"] = serde_json::from_str(extra).unwrap();
        }
    });
    Grasp::from_case(&c).unwrap()
}

/// The paper's disturbance direction `n = [n_z, n_x] = [−1/√2, 1/√2]` as `[x, y, z]`.
const N_PAPER: [f64; 3] = [H, 0.0, -H];

/// Initial grasping forces of grasp (a), Rf = 1, L = 100, against the closed-form pinned
/// elastica `P = 4K(m)² Rf/L²` with `l/L = 2E/K − 1`: within 1e-3 relative (the paper prints
/// 1.02e-3, 1.10e-3, 1.24e-3; the closed form gives 1.012e-3, 1.098e-3, 1.242e-3).
#[test]
fn initial_grasping_forces_match_the_elastica() {
    for ratio in [0.95, 0.80, 0.60] {
        let g = grasp_a(ratio, "{}");
        let exact = common::pinned_elastica_load(ratio) / (100.0 * 100.0);
        for f in &g.initial_forces {
            let rel = (f.normal - exact).abs() / exact;
            assert!(
                rel < 1e-3,
                "l = {ratio} L: {} vs {exact} ({rel:e})",
                f.normal
            );
            // Symmetric arch: no tangential force, to solver precision.
            assert!(f.tangential < 1e-6 * exact, "{}", f.tangential);
        }
    }
}

/// Fig. 14(a): grasp (a) at r0 = 1.10e-3 (l = 0.8 L), s_a = 0.5 L, n = [−1/√2, 1/√2]: the paper's
/// shapes hold contact at f = 1.4e-3 and have lost it at the right end at 1.7e-3.
#[test]
fn grasp_a_loses_the_right_end_between_1_4_and_1_7_e_minus_3() {
    let g = grasp_a(0.80, "{}");
    let lim = g.limit(50.0, N_PAPER).unwrap();
    let f = lim.f_contact_lost.expect("contact is lost below f_max");
    assert!(f > 1.4e-3 && f < 1.7e-3, "contact lost at {f}");
    assert_eq!(lim.finger_lost.as_deref(), Some("right finger"));
    assert_eq!(lim.unconverged, 0);
}

/// Fig. 14(b): grasp (b) pinching the centre with r0 = 1.10e-3, s_a = 0.75 L, same n: contact
/// holds at f = 2.0e-3.
#[test]
fn pinch_holds_at_2_e_minus_3() {
    let g = grasp_b("{\"preload\": 1.10e-3}");
    let lim = g.limit(75.0, N_PAPER).unwrap();
    assert!(
        lim.f_contact_lost.is_none_or(|f| f > 2.0e-3),
        "{:?}",
        lim.f_contact_lost
    );
}

/// Fig. 15's trends on a 5 × 6 grid: the margin grows with μ; it grows with r0 (grasp (a) at
/// l = 0.95, 0.80, 0.60 L); grasp (b) is more stable than grasp (a) at the same r0.
#[test]
fn margin_grows_with_mu_and_r0_and_pinch_is_more_stable() {
    let grid = r#"{"points": [20, 35, 50, 65, 80], "directions": 6, "mu": [0.2, 0.5, 1.0]}"#;
    let margins: Vec<_> = [0.95, 0.80, 0.60]
        .iter()
        .map(|&r| grasp_a(r, grid).margin(&|_, _| {}).unwrap())
        .collect();
    for m in &margins {
        for w in m.f_mub.windows(2) {
            assert!(w[1] >= w[0], "not monotone in μ: {:?}", m.f_mub);
        }
    }
    for k in 0..3 {
        assert!(
            margins[0].f_mub[k] <= margins[1].f_mub[k]
                && margins[1].f_mub[k] <= margins[2].f_mub[k],
            "μ index {k}: {:?} {:?} {:?}",
            margins[0].f_mub,
            margins[1].f_mub,
            margins[2].f_mub
        );
    }
    let b = grasp_b(&grid.replace("{", "{\"preload\": 1.0985e-3, "))
        .margin(&|_, _| {})
        .unwrap();
    for k in 0..3 {
        assert!(
            b.f_mub[k] > margins[1].f_mub[k],
            "μ = {}: pinch {} vs ends {}",
            b.mu[k],
            b.f_mub[k],
            margins[1].f_mub[k]
        );
    }
}

/// The split basis: the Lagrangian gradient of the disturbed problem (energy, point-load work,
/// finger rows and the continuity rows) matches central differences.
#[test]
fn split_problem_gradient_matches_finite_differences() {
    let g = grasp_a(0.80, "{}");
    let (mut p, a0) = g.disturbed_problem(35.0, N_PAPER).unwrap();
    let fu = p.model.rod.force_unit();
    let last = p.model.loads.len() - 1;
    p.model.loads[last].force = N_PAPER.map(|c| c * 1.3e-3 / fu);
    let n = p.n();
    let m = p.m();
    let a: Vec<f64> = a0
        .iter()
        .enumerate()
        .map(|(i, v)| v + 0.02 * ((i as f64) * 0.7).sin())
        .collect();
    let y: Vec<f64> = (0..m).map(|i| 0.5 + 0.1 * i as f64).collect();
    let lag = |p: &mut dlo_planner::statics::problem::StaticProblem, x: &[f64]| {
        let mut c = vec![0.0; m];
        let f = p.values(x, &mut c);
        f + y.iter().zip(&c).map(|(u, v)| u * v).sum::<f64>()
    };
    let mut c = vec![0.0; m];
    p.values(&a, &mut c);
    let mut grad = vec![0.0; n];
    p.gradient(&a, &y, &mut grad);
    let scale = grad.iter().fold(1e-12_f64, |s, v| s.max(v.abs()));
    let h = 1e-6;
    for i in 0..n {
        let (mut ap, mut am) = (a.clone(), a.clone());
        ap[i] += h;
        am[i] -= h;
        let fd = (lag(&mut p, &ap) - lag(&mut p, &am)) / (2.0 * h);
        assert!(
            (fd - grad[i]).abs() < 1e-6 * scale,
            "coefficient {i}: {fd} vs {}",
            grad[i]
        );
    }
}

/// A split at s_a captures what a point force does to the shape: the moment `Rf θ'` stays
/// continuous across the load point (moment balance of a vanishing segment) while the shear,
/// `Rf θ''`, jumps by the force's component across the tangent, `F · ∂t/∂θ`. The unsplit basis is
/// smooth and can represent no jump at all.
#[test]
fn split_shape_is_continuous_with_a_shear_jump() {
    let g = grasp_a(0.80, "{}");
    let lim = g.limit(50.0, N_PAPER).unwrap();
    assert!(lim.held_shape.len() > 10);
    let (mut p, a0) = g.disturbed_problem(50.0, N_PAPER).unwrap();
    let fu = p.model.rod.force_unit();
    let last = p.model.loads.len() - 1;
    p.model.loads[last].force = N_PAPER.map(|c| c * 1.0e-3 / fu);
    let sol = dlo_planner::statics::solve_static(&mut p, &a0, &g.options);
    assert_eq!(sol.status, dlo_planner::statics::SolveStatus::Converged);
    let basis = p.model.layout.basis;
    let nb = basis.len();
    let half = nb / 2;
    let th = &sol.a[..nb];
    let unsplit = dlo_planner::rod::basis::Basis::new(basis.pairs());
    let left = |t: f64| unsplit.eval(&th[..half], t);
    let right = |t: f64| {
        let r: Vec<f64> = (0..half).map(|i| th[i] + th[half + i]).collect();
        unsplit.eval(&r, t)
    };
    assert!((left(0.5) - right(0.5)).abs() < 1e-8, "θ jumps at s_a");
    // One-sided differences (the fields are smooth on each side).
    let d = 1e-4;
    let kl = (3.0 * left(0.5) - 4.0 * left(0.5 - d) + left(0.5 - 2.0 * d)) / (2.0 * d);
    let kr = (-3.0 * right(0.5) + 4.0 * right(0.5 + d) - right(0.5 + 2.0 * d)) / (2.0 * d);
    assert!(
        (kl - kr).abs() < 2e-3 * kl.abs().max(1.0),
        "moment jumps at s_a: θ' {kl} vs {kr}"
    );
    let ql = (left(0.5) - 2.0 * left(0.5 - d) + left(0.5 - 2.0 * d)) / (d * d);
    let qr = (right(0.5 + 2.0 * d) - 2.0 * right(0.5 + d) + right(0.5)) / (d * d);
    let f = p.model.loads[last].force;
    let tha = left(0.5);
    // Dimensionless: x = ∫ (sin θ, cos θ) in (x, z), so ∂t/∂θ = (cos θ, −sin θ).
    let expected = f[0] * tha.cos() - f[2] * tha.sin();
    // 10 %: four sine/cosine pairs per side resolve θ'' near the split to a few per cent.
    assert!(
        ((qr - ql) - expected).abs() < 0.1 * expected.abs(),
        "shear jump {} vs F·∂t/∂θ = {expected}",
        qr - ql
    );
}

/// Fig. 15's trend on the full default grid (9 points × 9 directions × 10 μ) of grasp (a) at
/// l = 0.8L: F_mub grows with μ at every step (measured: by 6 % or more). A curve that goes flat
/// here came from solves that stalled rather than from a contact lost; such a regression (the
/// energy evaluated as `aᵀ(Ka)`) flattened it from μ = 0.5.
#[test]
fn full_margin_curve_grows_at_every_friction_step() {
    let m = grasp_a(0.80, "{}").margin(&|_, _| {}).unwrap();
    assert_eq!(m.f_mub.len(), 10);
    for w in m.f_mub.windows(2) {
        assert!(
            w[1] > 1.01 * w[0],
            "F_mub not growing with μ: {:?}",
            m.f_mub
        );
    }
}

/// The grasp settings check what does not need the solved grasp, naming the field.
#[test]
fn grasp_settings_name_the_field_they_reject() {
    use dlo_planner::grasp::{Directions, GraspSettings};
    let ok = GraspSettings::default();
    assert_eq!(ok.validate(1.0, false), Ok(()));
    let field = |s: GraspSettings, spatial: bool| s.validate(1.0, spatial).unwrap_err().field;
    let mu = GraspSettings {
        mu: Some(vec![]),
        ..GraspSettings::default()
    };
    assert_eq!(field(mu, false), "mu");
    let point = GraspSettings {
        points: Some(vec![0.5, 1.0]),
        ..GraspSettings::default()
    };
    assert_eq!(field(point, false), "points[1]");
    let planar_vector = GraspSettings {
        directions: Some(Directions::Vectors(vec![vec![1.0, 0.0, 0.0]])),
        ..GraspSettings::default()
    };
    assert_eq!(field(planar_vector.clone(), false), "directions[0]");
    assert_eq!(planar_vector.validate(1.0, true), Ok(()));
    let steps = GraspSettings {
        steps: 0,
        ..GraspSettings::default()
    };
    assert_eq!(field(steps, true), "steps");
}
