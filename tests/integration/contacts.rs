//! Where a static solve holds obstacle contacts: at the sample points (the default) or on the
//! chords between them (`"discretisation": {"contact": "chords"}`).

use crate::common::shipped_variant;
use dlo_planner::statics::{SolveStatus, solve_static};

/// The smallest surface gap `d − r` (units of L) of the polyline through the boundary
/// `positions`, sampled 20 times per chord, to the case's obstacles.
fn polyline_gap(c: &dlo_planner::case::Case, positions: &[[f64; 3]]) -> f64 {
    let model = &c.problem.model;
    let (l, r) = (model.rod.length, model.rod.radius);
    let mut worst = f64::INFINITY;
    for w in positions.windows(2) {
        for i in 0..=20 {
            let t = i as f64 / 20.0;
            let x: [f64; 3] = std::array::from_fn(|k| (w[0][k] + t * (w[1][k] - w[0][k])) * l);
            for o in c.problem.obstacles() {
                worst = worst.min((o.signed_distance_value(x) - r) / l);
            }
        }
    }
    worst
}

/// The paper's planar strip at its case's own pose leans on the block's corner. Held at its
/// sample points, it keeps the rod's radius there, but the polyline through them comes
/// 4.7e-3 L inside the block (measured), past the corner; held on the chords, the polyline keeps
/// the radius to 1e-9 L, the rod rests on the corner (measured 3.6e-7 L on the sampled chords),
/// its energy rises (0.1128 → 0.1185), and the moments of its reactions and contact forces,
/// which act at the corner, still balance to rounding.
#[test]
fn chord_contacts_keep_a_rod_on_a_corner_out_of_the_obstacle() {
    let solve = |contact: &str| {
        let mut c = shipped_variant("plan_paper_planar.json", |v| {
            v["discretisation"] = serde_json::json!({ "contact": contact });
        });
        let a0 = c.initial.clone();
        let sol = solve_static(&mut c.problem, &a0, &c.options);
        assert_eq!(sol.status, SolveStatus::Converged, "{contact}");
        let x = c.problem.model.evaluate(&sol.a).positions;
        (polyline_gap(&c, &x), sol)
    };
    let (points_gap, points) = solve("points");
    let (chords_gap, chords) = solve("chords");
    assert!(points_gap < -4e-3, "{points_gap}");
    assert!(chords_gap >= -1e-9, "{chords_gap}");
    // Resting on the corner: the chords sampled every 1/640 L find it to within about 6e-5 L
    // (the distance to a corner grows quadratically along a chord, by s²/2r).
    assert!(
        chords_gap <= 1e-4,
        "the rod no longer touches: {chords_gap}"
    );
    assert!(
        chords.energy.potential() > points.energy.potential(),
        "{} vs {}",
        chords.energy.potential(),
        points.energy.potential()
    );
    let rel = chords.balance.expect("computed").relative;
    assert!(rel <= 1e-9, "moment balance {rel}");
}
