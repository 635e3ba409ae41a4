//! The global moment balance of static shapes (`src/statics/balance.rs`): the reactions, loads and
//! gravity the report gives must have zero total moment. Exact (to rounding) for planar rods,
//! whose Ritz space contains every rigid rotation in their plane; for a 3D rod it measures the
//! Ritz truncation and shrinks as the basis grows.

use dlo_planner::case;
use dlo_planner::statics::{SolveStatus, StaticSolution, solve_static};
use std::path::Path;

fn solve(c: &mut case::Case) -> StaticSolution {
    let a0 = c.initial.clone();
    let sol = solve_static(&mut c.problem, &a0, &c.options);
    assert_eq!(sol.status, SolveStatus::Converged, "{}", c.name);
    sol
}

/// Planar shipped cases — clamped and pinned ends, extension, gravity, a loop, and grasp (a),
/// whose base is free, so that its force balance is a test too — balance to rounding (relative
/// 1e-9): the moments of the supports' forces about the base, the clamps' moments and, for the
/// heavy strip, the moment of its weight.
#[test]
fn planar_shapes_balance_to_rounding() {
    for name in [
        "clamped_buckling_060",
        "pinned_buckling_080",
        "grasp_a_080",
        "extension_rho_e_300",
        "gravity_rho_g_050",
        "topology_knot_free_020",
    ] {
        let path = format!("{}/planning_cases/{name}.json", env!("CARGO_MANIFEST_DIR"));
        let mut c = case::load(Path::new(&path)).unwrap();
        let sol = solve(&mut c);
        let b = sol.balance.expect("computed");
        assert!(b.relative <= 1e-9, "{name}: {b:?}");
        // Left out on request (the planner's tracking solves), the shape is the same.
        let opts = dlo_planner::statics::StaticOptions {
            balance: false,
            ..c.options
        };
        let a0 = c.initial.clone();
        let without = dlo_planner::statics::solve_static(&mut c.problem, &a0, &opts);
        assert!(without.balance.is_none(), "{name}");
        assert_eq!(without.a, sol.a, "{name}");
    }
}

/// Every shipped case balances to 1e-6 of its largest moment: read from its `dlo shape` report
/// in `tests/golden/`, which `golden::shipped_reports_match_the_golden_files` recomputes and
/// compares exactly (solving the slow loops once instead of twice).
#[test]
fn every_shipped_case_balances() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut names: Vec<_> = std::fs::read_dir(root.join("planning_cases"))
        .unwrap()
        .filter_map(|e| e.ok()?.path().file_stem()?.to_str().map(String::from))
        .filter(|n| root.join(format!("planning_cases/{n}.json")).is_file())
        .collect();
    names.sort();
    assert!(names.len() >= 19);
    for name in names {
        let file = root.join(format!("tests/golden/{name}.shape.json"));
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
        let relative = report["balance"]["relative"]
            .as_f64()
            .unwrap_or_else(|| panic!("{}: no balance.relative", file.display()));
        assert!(relative <= 1e-6, "{name}: {relative}");
    }
}

/// The kinking and knot loops in the paper's basis and axes (`tests/fixtures/paper_axes`) do not
/// balance: the clamps on the pole hold them (5.0e-2, 1.7e-2 and 8.7e-2 of the largest moment).
/// Shipped, the same loops resolved away from the pole balance to 2e-7 (above); here the
/// paper-axes figures are pinned to 1e-3 relative, so that a change shows.
#[test]
fn the_paper_axes_loops_do_not_balance() {
    for (name, r) in [
        ("kinking_twist_2pi_080", 0.05038),
        ("kinking_twist_4pi_080", 0.017043),
        ("topology_one_knot_020", 0.08739),
    ] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures/paper_axes")
            .join(format!("{name}.json"));
        let mut c = case::load(&path).unwrap();
        let b = solve(&mut c).balance.expect("computed");
        assert!((b.relative - r).abs() < 1e-3 * r, "{name}: {b:?}");
    }
}

/// A heavy cantilever with a point load, resting on a floor (half-space): its weight, the load,
/// the floor's contact forces and the clamp balance to rounding.
#[test]
fn a_cantilever_on_a_floor_balances_to_rounding() {
    let text = r#"{ "name": "sagging", "planar": true,
  "rod": { "length": 1.0, "flexural_rigidity": 1.0, "radius": 0.01, "weight_per_length": 5.0 },
  "constraints": [ { "type": "orientation", "s": 0.0, "theta": 0.0, "name": "clamp" } ],
  "forces": [ { "s": 0.6, "force": [0.0, 0.0, 0.3], "reference": [0.0, 0.0, 0.0] } ],
  "obstacles": [ { "name": "floor", "shape": { "type": "half_space", "normal": [1.0, 0.0, 0.0] },
                   "position": [-0.3, 0.0, 0.0] } ] }"#;
    let mut c = case::parse(text, Path::new("sagging.json")).unwrap();
    let sol = solve(&mut c);
    let floor = sol
        .reactions
        .iter()
        .find(|r| r.constraint == "obstacle floor")
        .unwrap();
    assert!(floor.force[0] > 0.5, "the floor carries the tip: {floor:?}");
    assert!(
        sol.balance.expect("computed").relative <= 1e-9,
        "{:?}",
        sol.balance
    );
}

/// A 3D rod clamped at both ends in a generic pose (tangents away from ±z along the whole rod):
/// the residual is the Ritz truncation. It falls monotonically as the basis grows and the
/// energy falls with it (nested Ritz spaces: a larger basis can only lower the minimum). In the
/// case's own axes (`"angle_frame": "case"`): about 1 % at the paper's 4 sine/cosine pairs,
/// under 0.4 % at 8, under 0.2 % at 16; in the frame chosen away from the pole (the default),
/// 1.4 % at 4, under 0.5 % at 8, under 0.25 % at 16 — the same truncation, seen from other
/// axes.
#[test]
fn a_3d_shape_balances_better_as_the_basis_grows() {
    let text = |pairs: usize, frame: &str| {
        format!(
            r#"{{ "name": "generic", "planar": false, "angle_frame": "{frame}",
  "rod": {{ "length": 100.0, "flexural_rigidity": 1.0, "torsional_rigidity": 0.7 }},
  "discretisation": {{ "basis": "paper", "basis_pairs": {pairs} }},
  "constraints": [
    {{ "type": "orientation", "s": 0.0, "phi": 0.0, "theta": 1.5707963267948966, "psi": 0.0 }},
    {{ "type": "position", "s": 100.0, "x": 60.0, "y": 20.0, "z": 15.0 }},
    {{ "type": "orientation", "s": 100.0, "phi": 0.5, "theta": 1.9707963267948966, "psi": 0.3 }}
  ] }}"#
        )
    };
    for (frame, bounds) in [
        ("case", [0.011, 0.004, 0.002]),
        ("auto", [0.014, 0.005, 0.0025]),
    ] {
        let mut last: Option<(f64, f64)> = None;
        let mut rel = Vec::new();
        for pairs in [2, 4, 8, 16] {
            let mut c = case::parse(&text(pairs, frame), Path::new("generic.json")).unwrap();
            let sol = solve(&mut c);
            let (r, e) = (
                sol.balance.expect("computed").relative,
                sol.energy.potential(),
            );
            if let Some((r0, e0)) = last {
                assert!(r < r0, "{frame}, {pairs} pairs: residual {r} after {r0}");
                assert!(
                    e <= e0 * (1.0 + 1e-9),
                    "{frame}, {pairs} pairs: energy {e} after {e0}"
                );
            }
            last = Some((r, e));
            rel.push(r);
        }
        assert!(rel[1] < bounds[0], "{frame}, 4 pairs: {}", rel[1]);
        assert!(rel[2] < bounds[1], "{frame}, 8 pairs: {}", rel[2]);
        assert!(rel[3] < bounds[2], "{frame}, 16 pairs: {}", rel[3]);
    }
}
