//! Finite-difference checks of the planner's analytic gradients: the smoothed maximum, the mean
//! energy, the equilibrium-tracking term and the sampled path constraints, all chained through
//! the path parameterisation and the null space of the fixed conditions.

use crate::common;
use dlo_planner::case;
use dlo_planner::optim::Nlp;
use dlo_planner::planner::Planner;
use dlo_planner::planner::minimax::MinimaxProblem;
use std::path::Path;

/// The planning problem of case `name` on 9 samples with test weights, a point `z` off the
/// straight path, and (with `tracking`) targets: the sampled shapes of another path.
/// With `swept`, the swept-clearance rows between consecutive samples follow the sampled rows.
fn setup_with(name: &str, tracking: bool, swept: bool) -> (MinimaxProblem, Vec<f64>) {
    let c = case::load(&Path::new("planning_cases").join(name)).unwrap();
    let pl = Planner::from_case(&c).unwrap();
    let ks: Vec<f64> = (0..9).map(|j| j as f64 / 8.0).collect();
    let mut p = pl.minimax_problem_at(ks);
    p.set_swept(swept);
    p.beta = 3.0;
    p.mean_weight = 0.7;
    let (n, m) = (p.n(), p.m());
    let z: Vec<f64> = (0..n).map(|i| 0.05 * ((i as f64) * 1.7).sin()).collect();
    if tracking {
        let z2: Vec<f64> = (0..n).map(|i| 0.04 * ((i as f64) * 0.9).cos()).collect();
        let mut c = vec![0.0; m];
        p.values(&z2, &mut c);
        let targets: Vec<Vec<[f64; 3]>> = p
            .sampled()
            .iter()
            .map(|a| p.model.evaluate(a).positions)
            .collect();
        p.targets = Some(targets);
        p.track_weight = 50.0;
    }
    (p, z)
}

fn check(name: &str, tracking: bool) {
    check_with(name, tracking, false);
}

fn check_with(name: &str, tracking: bool, swept: bool) {
    let (p, z) = setup_with(name, tracking, swept);
    if swept {
        assert!(p.m() > p.sample_rows(), "{name}: no swept rows");
    }
    check_gradient(&format!("{name} (tracking {tracking})"), p, &z);
}

/// The gradient of `f + Σ yᵢcᵢ` against central differences (relative 1e-6).
pub(crate) fn check_gradient(name: &str, mut p: MinimaxProblem, z: &[f64]) {
    let z = z.to_vec();
    let (n, m) = (p.n(), p.m());
    let y: Vec<f64> = (0..m).map(|i| 0.3 * ((i as f64) * 0.37).cos()).collect();
    let mut c = vec![0.0; m];
    let phi = |p: &mut MinimaxProblem, x: &[f64]| {
        let mut c = vec![0.0; m];
        let f = p.values(x, &mut c);
        f + y.iter().zip(&c).map(|(a, b)| a * b).sum::<f64>()
    };
    p.values(&z, &mut c);
    let mut g = vec![0.0; n];
    p.gradient(&z, &y, &mut g);
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for i in 0..n {
        let mut zp = z.clone();
        zp[i] += h;
        let mut zm = z.clone();
        zm[i] -= h;
        let fd = (phi(&mut p, &zp) - phi(&mut p, &zm)) / (2.0 * h);
        let scale = g.iter().fold(1e-8_f64, |a, v| a.max(v.abs()));
        worst = worst.max((fd - g[i]).abs() / scale);
    }
    assert!(worst < 1e-6, "{name}: relative error {worst:e}");
}

/// The self-contact rows at every sample, chained through the path: a strip curled into a
/// spiral (`common::spiral_case`), on a path whose middle samples bring the coil close to
/// itself.
#[test]
fn minimax_gradient_with_self_contact_matches_finite_differences() {
    let pl = Planner::from_case(&common::spiral_case(true)).unwrap();
    let ks: Vec<f64> = (0..9).map(|j| j as f64 / 8.0).collect();
    let mut p = pl.minimax_problem_at(ks);
    p.beta = 3.0;
    p.mean_weight = 0.7;
    assert!(p.rows_per_sample() > 0, "no self-contact rows");
    let z: Vec<f64> = (0..p.n())
        .map(|i| 0.05 * ((i as f64) * 1.7).sin())
        .collect();
    check_gradient("spiral with self-contact", p, &z);
}

#[test]
fn planar_minimax_gradient_matches_finite_differences() {
    check("plan_paper_planar.json", false);
}

#[test]
fn planar_minimax_gradient_with_tracking_matches_finite_differences() {
    check("plan_paper_planar.json", true);
}

#[test]
fn spatial_minimax_gradient_matches_finite_differences() {
    check("plan_cable_around_pillar.json", true);
}

#[test]
fn path_ends_on_its_shapes_and_keeps_linear_conditions() {
    use dlo_planner::planner::path::DeformationPath;
    let a0 = vec![0.0, 1.0, 0.5, -0.2];
    let a1 = vec![0.3, -1.0, 0.1, 0.4];
    // A linear condition on a[1] + a[2]: every path vector must satisfy C cᵢ = 0.
    let row = vec![0.0, 1.0, 1.0, 0.0];
    let path = DeformationPath::new(a0.clone(), a1.clone(), 3, std::slice::from_ref(&row));
    assert_eq!(path.basis.len(), 3);
    let z: Vec<f64> = (0..path.n_vars()).map(|i| (i as f64).sin()).collect();
    let mut a = vec![0.0; 4];
    path.shape_at(&z, 0.0, &mut a);
    assert_eq!(a, a0);
    path.shape_at(&z, 1.0, &mut a);
    for (x, y) in a.iter().zip(&a1) {
        assert!((x - y).abs() < 1e-15);
    }
    for c in path.c_vectors(&z) {
        let r: f64 = c.iter().zip(&row).map(|(u, v)| u * v).sum();
        assert!(r.abs() < 1e-12, "C c = {r}");
    }
}

#[test]
fn smoothed_max_brackets_the_max() {
    use dlo_planner::planner::minimax::smoothed_max;
    let u = [1.0, 3.0, 2.5, 3.0, -1.0];
    let mut w = [0.0; 5];
    for beta in [1.0, 10.0, 1000.0] {
        let s = smoothed_max(&u, beta, &mut w);
        assert!(
            s >= 3.0 && s <= 3.0 + (5.0_f64).ln() / beta + 1e-12,
            "{beta}: {s}"
        );
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    }
}

/// The verification grid checks self-contact: a planar curl turning by 7 rad (more than a full
/// circle) crosses itself; one turning by 3 rad does not.
#[test]
fn verification_finds_a_rod_crossing_itself() {
    use dlo_planner::planner::path::DeformationPath;
    use dlo_planner::planner::verify::{fine_model, verify_with};
    use dlo_planner::rod::energy::Objective;
    let text = r#"{ "rod": { "length": 1.0, "flexural_rigidity": 1.0, "radius": 0.005 },
                    "self_contact": true }"#;
    let c = case::parse(text, Path::new("curl.json")).unwrap();
    let fine = fine_model(&c.problem.model, 256, 4);
    let curl = |turn: f64| {
        let mut a = vec![0.0; c.problem.model.n()];
        a[1] = turn;
        a
    };
    for (turn, crosses) in [(7.0, true), (3.0, false)] {
        let path = DeformationPath::new(curl(turn), curl(turn), 1, &[]);
        let z = vec![0.0; path.n_vars()];
        let v = verify_with(&fine, &path, &z, 3, &[], Objective::Internal, true);
        let (gap, _) = v.self_contact.unwrap();
        assert_eq!(gap < 0.0, crosses, "turn {turn}: gap {gap}");
        assert_eq!(v.collision_free(1e-9), !crosses);
    }
}

/// The Hessian of `f + Σ yᵢcᵢ` against central differences of the analytic gradient (with the
/// obstacle distance's own curvature), and its penalty part `Σ sᵢ∇cᵢ∇cᵢᵀ` against
/// gradient-differenced constraint rows.
fn check_hessian(name: &str, tracking: bool) {
    check_hessian_with(name, tracking, false);
}

fn check_hessian_with(name: &str, tracking: bool, swept: bool) {
    let (mut p, z) = setup_with(name, tracking, swept);
    let (n, m) = (p.n(), p.m());
    let y: Vec<f64> = (0..m).map(|i| 0.3 * ((i as f64) * 0.37).cos()).collect();
    assert!(p.has_hessian());
    let worst = common::hessian_fd_error(&mut p, &z, &y);
    assert!(worst < 1e-5, "{name}: Hessian relative error {worst:e}");
    // Penalty part: two rows with weights s (with swept rows: the last sample's and the last
    // pair's row at the free end).
    let mut s = vec![0.0; m];
    let ns = p.sample_rows();
    let rows = if swept {
        [ns - 1, m - 1]
    } else {
        [m / 3, m / 2]
    };
    for &r in &rows {
        s[r] = 2.0 + r as f64;
    }
    let mut c = vec![0.0; m];
    p.values(&z, &mut c);
    let mut h = vec![0.0; n * n];
    p.hessian(&z, &y, &vec![0.0; m], &mut h);
    let mut h2 = vec![0.0; n * n];
    p.hessian(&z, &y, &s, &mut h2);
    let (_, jr) = dlo_planner::optim::augmented_lagrangian::jacobian_rows(&mut p, &z, &rows);
    for (r, g) in rows.iter().zip(&jr) {
        assert!(
            g.iter().any(|v| v.abs() > 1e-3),
            "{name}: row {r} has no gradient"
        );
    }
    let scale2 = h2.iter().fold(1e-8_f64, |a, v| a.max(v.abs()));
    let mut worst2: f64 = 0.0;
    for i in 0..n {
        for j in 0..n {
            let expect: f64 = rows.iter().zip(&jr).map(|(&r, g)| s[r] * g[i] * g[j]).sum();
            worst2 = worst2.max((h2[i * n + j] - h[i * n + j] - expect).abs() / scale2);
        }
    }
    assert!(
        worst2 < 1e-9,
        "{name}: penalty part relative error {worst2:e}"
    );
}

#[test]
fn planar_minimax_hessian_matches_finite_differences() {
    check_hessian("plan_paper_planar.json", true);
}

#[test]
fn spatial_minimax_hessian_matches_finite_differences() {
    check_hessian("plan_cable_around_pillar.json", true);
}

/// The swept-clearance rows (chord between consecutive samples kept clear, see
/// `dlo_planner::planner::swept`): gradient and Hessian against differences, planar and 3D.
#[test]
fn swept_clearance_rows_match_finite_differences() {
    check_with("plan_paper_planar.json", false, true);
    check_with("plan_cable_around_pillar.json", true, true);
    check_hessian_with("plan_paper_planar.json", true, true);
    check_hessian_with("plan_cable_around_pillar.json", true, true);
}

/// The controlled end's travel term (`plan.travel_weight`): the value is the discrete
/// `½ w ∫ |dx/dk|² dk` of the end's positions at the samples (checked against positions read
/// independently), and its gradient and Hessian (exact: the positions' curvature and the
/// Gauss–Newton part coupling consecutive samples) match central differences, planar and 3D,
/// with tracking on.
#[test]
fn travel_term_matches_its_definition_and_finite_differences() {
    for name in ["plan_paper_planar.json", "plan_cable_around_pillar.json"] {
        let (mut p, z) = setup_with(name, true, false);
        p.travel_weight = 0.8;
        let m = p.m();
        let mut c = vec![0.0; m];
        p.values(&z, &mut c);
        let ends: Vec<[f64; 3]> = p
            .sampled()
            .iter()
            .map(|a| p.model.position_at(a, 1.0))
            .collect();
        let expect: f64 = (0..p.ks.len() - 1)
            .map(|j| {
                let d2: f64 = (0..3).map(|i| (ends[j + 1][i] - ends[j][i]).powi(2)).sum();
                0.5 * 0.8 * d2 / (p.ks[j + 1] - p.ks[j])
            })
            .sum();
        assert!(expect > 1e-3, "{name}: the end moves");
        assert!(
            (p.travel() - expect).abs() < 1e-12 * expect,
            "{name}: {} vs {expect}",
            p.travel()
        );
        let y: Vec<f64> = (0..m).map(|i| 0.3 * ((i as f64) * 0.37).cos()).collect();
        let worst = common::hessian_fd_error(&mut p, &z, &y);
        assert!(worst < 1e-5, "{name}: Hessian relative error {worst:e}");
        check_gradient(&format!("{name} with travel"), p, &z);
    }
}
