//! The computational examples of the paper's §4.3–4.5, checked for the trends it reports.

use dlo_planner::case;
use dlo_planner::statics::{SolveStatus, StaticSolution, solve_static};
use std::path::Path;

fn solve_json(text: &str, start: Option<Vec<f64>>) -> (case::Case, StaticSolution) {
    let mut c = case::parse(text, Path::new("inline.json")).expect("valid case");
    let a0 = start.unwrap_or_else(|| c.initial.clone());
    let sol = solve_static(&mut c.problem, &a0, &c.options);
    (c, sol)
}

fn clamped(l_over_len: f64, rod_extra: &str) -> String {
    format!(
        r#"{{"rod": {{"length": 100.0, "flexural_rigidity": 1.0 {rod_extra}}},
           "constraints": [
             {{"type": "orientation", "s": 0.0, "theta": 0.0}},
             {{"type": "position", "s": 100.0, "x": 0.0, "z": {z}}},
             {{"type": "orientation", "s": 100.0, "theta": 0.0}}]}}"#,
        z = l_over_len * 100.0
    )
}

/// Positions at `n+1` equally spaced points.
fn profile(c: &case::Case, a: &[f64], n: usize) -> Vec<[f64; 3]> {
    let m = &c.problem.model;
    (0..=n).map(|j| m.position_at(a, j as f64 / n as f64).map(|v| v * m.rod.length)).collect()
}

fn asymmetry(c: &case::Case, a: &[f64]) -> f64 {
    let p = profile(c, a, 40);
    (0..=20).map(|j| (p[j][0] - p[40 - j][0]).abs()).fold(0.0, f64::max)
}

#[test]
fn extension_lowers_height_and_length_as_rho_e_falls() {
    // §4.4: clamped ends at 0.6 L; rho_e = Re L²/Rf = ∞, 500, 300, 200, 100.
    let mut prev: Option<(f64, f64)> = None;
    for rho_e in [f64::INFINITY, 500.0, 300.0, 200.0, 100.0] {
        let extra = if rho_e.is_finite() { format!(r#", "extensional_rigidity": {}"#, rho_e / 1e4) } else { String::new() };
        let (c, sol) = solve_json(&clamped(0.6, &extra), None);
        assert_eq!(sol.status, SolveStatus::Converged, "rho_e={rho_e}");
        let m = &c.problem.model;
        let height = profile(&c, &sol.a, 80).iter().map(|p| p[0].abs()).fold(0.0, f64::max);
        let length: f64 = (0..m.mesh.nodes.len())
            .map(|q| m.mesh.weights[q] * (1.0 + m.strain_at(&sol.a, m.mesh.nodes[q])))
            .sum::<f64>()
            * 100.0;
        eprintln!("rho_e = {rho_e}: height {height:.3}, length {length:.3}, U = {:.5}", sol.energy.potential());
        if let Some((h, l)) = prev {
            assert!(height < h && length < l, "height and length must fall as rho_e falls");
        }
        prev = Some((height, length));
    }
}

#[test]
fn gravity_lowers_the_clamped_arch_until_it_snaps_to_a_hanging_shape() {
    // §4.5 with the boundary conditions we use (the paper does not state its own): both ends
    // clamped along z (θ = 0), end distance 0.85 L, an upward arch as start. What holds: the
    // shape is symmetric at ρg = 0, its height falls as ρg grows, and the arch collapses into a
    // hanging shape between ρg = 50 and 100. What does not: the paper's asymmetric minimum above
    // ρg ≈ 100 (the symmetric shapes found here stay stable; see the README).
    let mut heights = Vec::new();
    for rho_g in [0.0, 20.0, 50.0, 100.0, 200.0] {
        let extra = format!(r#", "weight_per_length": {}"#, rho_g / 1e6);
        let text = clamped(0.85, &extra);
        let mut a0 = vec![0.0; 10];
        a0[2] = 0.5; // θ = 0.5 sin(2πt): the symmetric upward arch
        a0[0] = 0.01; // plus a symmetry-breaking nudge
        let (c, sol) = solve_json(&text, Some(a0));
        assert_eq!(sol.status, SolveStatus::Converged);
        assert_eq!(sol.stable, Some(true));
        let p = profile(&c, &sol.a, 40);
        let mid = p[20][0];
        eprintln!("rho_g = {rho_g}: U = {:.5}, mid-span height {mid:.3}, asymmetry {:.2e}", sol.energy.potential(), asymmetry(&c, &sol.a));
        heights.push(mid);
        if rho_g == 0.0 {
            assert!(asymmetry(&c, &sol.a) < 1e-6);
        }
    }
    assert!(heights[0] > heights[1] && heights[1] > heights[2] && heights[2] > 0.0, "{heights:?}");
    assert!(heights[3] < 0.0 && heights[4] < 0.0, "snapped to hanging: {heights:?}");
}
