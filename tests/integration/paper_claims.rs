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
           "discretisation": {{"basis": "paper"}},
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
    (0..=n)
        .map(|j| {
            m.position_at(a, j as f64 / n as f64)
                .map(|v| v * m.rod.length)
        })
        .collect()
}

fn asymmetry(c: &case::Case, a: &[f64]) -> f64 {
    let p = profile(c, a, 40);
    (0..=20)
        .map(|j| (p[j][0] - p[40 - j][0]).abs())
        .fold(0.0, f64::max)
}

#[test]
fn extension_lowers_height_and_length_as_rho_e_falls() {
    // §4.4: clamped ends at 0.6 L; rho_e = Re L²/Rf = ∞, 500, 300, 200, 100.
    let mut prev: Option<(f64, f64)> = None;
    for rho_e in [f64::INFINITY, 500.0, 300.0, 200.0, 100.0] {
        let extra = if rho_e.is_finite() {
            format!(r#", "extensional_rigidity": {}"#, rho_e / 1e4)
        } else {
            String::new()
        };
        let (c, sol) = solve_json(&clamped(0.6, &extra), None);
        assert_eq!(sol.status, SolveStatus::Converged, "rho_e={rho_e}");
        let m = &c.problem.model;
        let height = profile(&c, &sol.a, 80)
            .iter()
            .map(|p| p[0].abs())
            .fold(0.0, f64::max);
        let length: f64 = (0..m.mesh.nodes.len())
            .map(|q| m.mesh.weights[q] * (1.0 + m.strain_at(&sol.a, m.mesh.nodes[q])))
            .sum::<f64>()
            * 100.0;
        eprintln!(
            "rho_e = {rho_e}: height {height:.3}, length {length:.3}, U = {:.5}",
            sol.energy.potential()
        );
        if let Some((h, l)) = prev {
            assert!(
                height < h && length < l,
                "height and length must fall as rho_e falls"
            );
        }
        prev = Some((height, length));
    }
}

#[test]
fn gravity_lowers_the_clamped_arch_until_it_snaps_to_a_hanging_shape() {
    // §4.5 with the boundary conditions we use (the paper does not state its own): both ends
    // clamped along z (θ = 0), end distance 0.85 L, an upward arch as start. What holds: the
    // shape is symmetric at ρg = 0, its height falls as ρg grows, and the arch collapses into a
    // hanging shape between ρg = 50 and 100 (at ρg ≈ 62.7, see the next test). What does not:
    // the paper's asymmetric minimum above ρg ≈ 100 (see the README).
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
        eprintln!(
            "rho_g = {rho_g}: U = {:.5}, mid-span height {mid:.3}, asymmetry {:.2e}",
            sol.energy.potential(),
            asymmetry(&c, &sol.a)
        );
        heights.push(mid);
        if rho_g == 0.0 {
            assert!(asymmetry(&c, &sol.a) < 1e-6);
        }
    }
    assert!(
        heights[0] > heights[1] && heights[1] > heights[2] && heights[2] > 0.0,
        "{heights:?}"
    );
    assert!(
        heights[3] < 0.0 && heights[4] < 0.0,
        "snapped to hanging: {heights:?}"
    );
}

/// Where the §4.5 arch stops being a minimum. Held at mid-span at the height `h` where the
/// holding force vanishes (bisection on `x(L/2) = h`), the upward arch is a symmetric
/// equilibrium of the free problem. At ρg = 60, 80 and 100 it is a stable one — the reduced
/// Hessian's smallest eigenvalue is positive and falls as ρg grows (14.7, 10.1, 5.4) — and a
/// solve released from it stays there. By ρg = 120 no height between 21.8 and 23.5 gives a
/// vanishing holding force (the eigenvalue's trend reaches zero near ρg ≈ 120), and released
/// from the held shape the rod falls into the hanging shape. The paper loses symmetry near ρg ≈ 100; its asymmetric minimum has no
/// counterpart here (docs/validation.md).
#[test]
fn gravity_arch_stays_a_minimum_up_to_rho_g_100_and_is_gone_by_120() {
    let held = |rho_g: f64, h: f64| {
        let text = clamped(0.85, &format!(r#", "weight_per_length": {}"#, rho_g / 1e6)).replace(
            r#"{"type": "orientation", "s": 100.0, "theta": 0.0}]"#,
            &format!(
                r#"{{"type": "orientation", "s": 100.0, "theta": 0.0}},
                   {{"type": "position", "s": 50.0, "x": {h}, "z": 42.5, "name": "mid"}}]"#
            ),
        );
        let mut a0 = vec![0.0; 10];
        a0[2] = 0.5;
        let (c, sol) = solve_json(&text, Some(a0));
        assert_eq!(sol.status, SolveStatus::Converged, "rho_g {rho_g}, h {h}");
        let f = sol
            .reactions
            .iter()
            .find(|r| r.constraint == "mid")
            .expect("mid reaction")
            .force;
        (c, sol, f)
    };
    let mut smallest = f64::INFINITY;
    for (rho_g, exists) in [(60.0, true), (80.0, true), (100.0, true), (120.0, false)] {
        let (mut lo, mut hi) = (21.8, 23.5);
        for _ in 0..30 {
            let mid = 0.5 * (lo + hi);
            if held(rho_g, mid).2[0] < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let h = 0.5 * (lo + hi);
        let (c, sol, f) = held(rho_g, h);
        let free = clamped(0.85, &format!(r#", "weight_per_length": {}"#, rho_g / 1e6));
        let (c2, released) = solve_json(&free, Some(sol.a.clone()));
        assert_eq!(released.status, SolveStatus::Converged);
        let mid = profile(&c2, &released.a, 40)[20][0];
        eprintln!(
            "rho_g = {rho_g}: held at h = {h:.4} (U = {:.5}, holding force {:.1e}); released: \
             mid-span height {mid:.3}, U = {:.5}, smallest reduced eigenvalue {:?}",
            sol.energy.potential(),
            f[0],
            released.energy.potential(),
            released.min_reduced_eigenvalue
        );
        if exists {
            // A free equilibrium: the holding force vanishes (the rod weighs 6e-3 to 1e-2 in
            // all), and the shape is symmetric.
            assert!(
                f[0].abs() < 1e-8 && f[2].abs() < 1e-8,
                "holding force {f:?}"
            );
            assert!(asymmetry(&c, &sol.a) < 1e-6);
            assert!((mid - h).abs() < 1e-3, "stays up: {mid} vs {h}");
            assert_eq!(released.stable, Some(true));
            let lmin = released.min_reduced_eigenvalue.unwrap();
            assert!(lmin > 0.0 && lmin < smallest, "{lmin} after {smallest}");
            smallest = lmin;
        } else {
            assert!(f[0].abs() > 1e-4, "no free arch: holding force {f:?}");
            assert!(mid < -20.0, "falls into the hanging shape: {mid}");
        }
    }
}

/// The text of case file `name` in the folder `dir` of the repository.
fn case_text(dir: &str, name: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(dir).join(name)).unwrap()
}

fn shipped(name: &str) -> String {
    case_text("planning_cases", name)
}

/// The paper's kinking and knot cases in its basis and axes (`tests/fixtures/paper_axes`: the
/// shipped ones are resolved away from the Euler angles' pole).
fn paper_axes(name: &str) -> String {
    case_text("tests/fixtures/paper_axes", name)
}

/// The §4.3 cases with the end distance replaced: the paper-axes loops, the shipped knot-free
/// shape.
fn at_distance(name: &str, l: f64) -> String {
    let text = if name.starts_with("kinking") || name.starts_with("topology_one_knot") {
        paper_axes(name)
    } else {
        shipped(name)
    };
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["constraints"][1]["z"] = serde_json::json!(l * 100.0);
    v.to_string()
}

#[test]
fn knot_free_and_one_knot_energies_cross_near_three_tenths() {
    // §4.3, ρt = 0.77: flexure-only planar shape vs one-knot (flexure + torsion) shape.
    let ls = [0.1, 0.2, 0.3, 0.4, 0.5];
    let mut diff = Vec::new();
    for &l in &ls {
        let (_, free) = solve_json(&at_distance("topology_knot_free_020.json", l), None);
        let (_, knot) = solve_json(&at_distance("topology_one_knot_020.json", l), None);
        for s in [&free, &knot] {
            assert_eq!(s.status, SolveStatus::Converged, "l/L = {l}");
        }
        let (uf, uk) = (free.energy.potential(), knot.energy.potential());
        eprintln!(
            "l/L = {l}: knot-free U = {uf:.4}, one-knot U = {uk:.4} (torsional {:.4})",
            knot.energy.torsional
        );
        assert!(
            knot.energy.torsional > 0.01 * uk,
            "the one-knot shape is twisted"
        );
        diff.push(uk - uf);
    }
    // One sign change, between consecutive samples; interpolate the crossing.
    let j = diff
        .windows(2)
        .position(|w| w[0] < 0.0 && w[1] > 0.0)
        .expect("energies cross");
    assert!(diff[..=j].iter().all(|d| *d < 0.0) && diff[j + 1..].iter().all(|d| *d > 0.0));
    let cross = ls[j] + (ls[j + 1] - ls[j]) * (-diff[j]) / (diff[j + 1] - diff[j]);
    eprintln!("crossing at l/L = {cross:.3}");
    assert!((0.2..=0.35).contains(&cross), "paper: ≈ 0.3; got {cross}");
}

#[test]
fn twisted_rod_kinks_into_a_loop_when_shortened() {
    // §4.3 kinking: twist 2π, then shorten. A looped (knotted) shape, with φ winding about once
    // and less torsional energy than the straight twisted rod (½ Rt (2π)²/L), is found at every
    // l, with lower energy than the unlooped shape the default start reaches.
    let straight_twist = 0.5 * 0.77 * (2.0 * std::f64::consts::PI).powi(2) / 100.0;
    for l in [0.8, 0.6, 0.4, 0.2] {
        let text = at_distance("kinking_twist_2pi_080.json", l);
        let (c, loop_sol) = solve_json(&text, None);
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        v.as_object_mut().unwrap().remove("shape");
        let (_, plain) = solve_json(&v.to_string(), None);
        let winding = c.problem.model.angles_at(&loop_sol.a, 1.0)[0];
        eprintln!(
            "l/L = {l}: looped U = {:.4} (torsional {:.4}, φ(L) = {winding:.2}); default start U = {:.4}",
            loop_sol.energy.potential(),
            loop_sol.energy.torsional,
            plain.energy.potential()
        );
        assert_eq!(loop_sol.status, SolveStatus::Converged);
        assert_eq!(loop_sol.stable, Some(true));
        assert!(winding > 4.0, "a loop: φ winds by about 2π");
        assert!(loop_sol.energy.torsional < straight_twist);
        assert!(loop_sol.energy.potential() <= plain.energy.potential() + 1e-9);
    }
}

/// `solver.second_order_multipliers`: both multiplier updates reach the same clamped-clamped
/// elastica (energy to 1e-9 relative, shape to 1e-7 L), the second-order one in fewer outer
/// iterations.
/// §4.3 kinking as the paper's Fig. 4–5 run it: twist by 2π, then 4π, then shorten to
/// l = 0.8, 0.6, 0.4, 0.2 L. Twisting raises the energy (the straight twisted rod,
/// `½ Rt ω0²/L`: 0.152 at 2π, 0.608 at 4π, closed form) and shortening lowers it, strictly, as
/// twist turns into writhe: the looped shapes are bent (flexure > 0.1) and hold less torsional
/// energy than the straight rod. Every shape converged and is stable; the straight twisted rods
/// report neutral modes instead of a stability verdict.
#[test]
fn kinking_energy_falls_as_the_twisted_rod_is_shortened() {
    let rt = 0.77;
    let twisted = |w: f64| 0.5 * rt * w * w / 100.0;
    let four_pi = 4.0 * std::f64::consts::PI;
    let straight = |w: f64| {
        let mut v: serde_json::Value =
            serde_json::from_str(&paper_axes("kinking_twist_4pi_080.json")).unwrap();
        v["constraints"][1]["z"] = serde_json::json!(100.0);
        v["constraints"][2]["phi_plus_psi"] = serde_json::json!(w);
        v.as_object_mut().unwrap().remove("shape");
        let (_, sol) = solve_json(&v.to_string(), None);
        assert_eq!(sol.status, SolveStatus::Converged);
        // θ ≡ 0 is the Euler angles' singularity: the second-order check cannot decide there
        // (Greenhill's helical mode, unstable at 4π: 0.77 · 4π = 9.68 > 8.99 Rf/L, is not a
        // small change of the angles), and says so: opposite changes of φ and ψ are gauge
        // directions there, and the verdict is marginal.
        assert!(
            sol.gauge_modes.is_some_and(|n| n > 0),
            "{:?}",
            sol.gauge_modes
        );
        assert_eq!(
            sol.stability,
            Some(dlo_planner::statics::stability::Verdict::Marginal)
        );
        assert_eq!(sol.stable, None);
        sol.energy.potential()
    };
    let mut energies = Vec::new();
    for w in [0.5 * four_pi, four_pi] {
        let u = straight(w);
        assert!(
            (u - twisted(w)).abs() <= 1e-6 * twisted(w),
            "{u} vs {}",
            twisted(w)
        );
        energies.push(u);
    }
    for l in [0.8, 0.6, 0.4, 0.2] {
        let (_, sol) = solve_json(&at_distance("kinking_twist_4pi_080.json", l), None);
        eprintln!(
            "l/L = {l}: U = {:.4} (flexural {:.4}, torsional {:.4})",
            sol.energy.potential(),
            sol.energy.flexural,
            sol.energy.torsional
        );
        assert_eq!(sol.status, SolveStatus::Converged);
        assert_eq!(sol.stable, Some(true));
        assert!(sol.energy.flexural > 0.1 && sol.energy.torsional < twisted(four_pi));
        energies.push(sol.energy.potential());
    }
    assert!(energies[1] > energies[0], "twisting raises U: {energies:?}");
    assert!(
        energies[1..].windows(2).all(|w| w[1] < w[0]),
        "shortening lowers U: {energies:?}"
    );
}

#[test]
fn both_multiplier_updates_reach_the_same_shape() {
    let text = clamped(0.6, "");
    let first_order = format!(
        "{}, \"solver\": {{\"second_order_multipliers\": false}}}}",
        text.trim_end().trim_end_matches('}')
    );
    let (c2, s2) = solve_json(&text, None);
    let (_, s1) = solve_json(&first_order, None);
    assert_eq!(s2.status, SolveStatus::Converged);
    assert_eq!(s1.status, SolveStatus::Converged);
    let (u1, u2) = (s1.energy.flexural, s2.energy.flexural);
    assert!((u1 - u2).abs() <= 1e-9 * u2.abs(), "{u1} vs {u2}");
    let (x1, x2) = (profile(&c2, &s1.a, 20), profile(&c2, &s2.a, 20));
    let d = x1
        .iter()
        .zip(&x2)
        .flat_map(|(p, q)| (0..3).map(move |k| (p[k] - q[k]).abs()))
        .fold(0.0, f64::max);
    assert!(d <= 1e-7, "{d}");
    assert!(
        s2.outer_iterations < s1.outer_iterations,
        "{} vs {}",
        s2.outer_iterations,
        s1.outer_iterations
    );
}
