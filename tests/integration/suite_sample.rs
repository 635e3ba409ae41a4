//! A fixed sample of the generated suite's problems (`examples/plan_suite.rs`), planned with
//! every setting at its default: the first problems of the planar and of the 3D generator, each
//! started from seed 1, that have static start and goal shapes.

use crate::suite::{Outcome, Rng, planar_problem, run, spatial_problem};

/// The first `n` problems of `generate` (seed 1) with static start and goal shapes, planned.
fn first(generate: fn(&mut Rng, usize) -> String, kind: &str, n: usize) -> Vec<Outcome> {
    let mut rng = Rng(1);
    let none = serde_json::json!({});
    let mut out = Vec::new();
    let mut i = 0;
    while out.len() < n {
        let text = generate(&mut rng, i);
        if let Some(o) = run(&text, &format!("{kind}_{i}"), &none, &none) {
            out.push(o);
        }
        i += 1;
    }
    out
}

/// Every plan of the sample is collision-free, and an independent check on a grid twice as fine
/// in k finds no penetration; no replay that departs by more than the 2 % tolerance, or snaps,
/// is called coinciding. Three of the five coincide with
/// their replay today (`planar_0`, `planar_2`, `spatial_0`), and must keep doing so; the other two
/// depart (by 8 % and 4 % of L): the suite's shortfall that docs/results.md reports.
#[test]
fn a_sample_of_the_generated_suite_plans_with_the_defaults() {
    let planar = first(planar_problem, "planar", 3);
    let spatial = first(spatial_problem, "spatial", 2);
    for o in planar.iter().chain(&spatial) {
        assert!(o.planned, "{}: not collision-free", o.name);
        let (clearance, k) = o.checked_clearance.expect("checked when planned");
        assert!(
            clearance >= -1e-6,
            "{}: called collision-free, but {clearance:.3e} L deep at k = {k}",
            o.name
        );
        // A departure beyond the tolerance, or a snap, is never called coinciding.
        if o.deviation > 0.02 || o.snaps {
            assert!(
                !o.coincide,
                "{}: called coinciding at {:.4} L",
                o.name, o.deviation
            );
        }
    }
    for o in planar.iter().chain(&spatial) {
        if ["planar_0", "planar_2", "spatial_0"].contains(&o.name.as_str()) {
            assert!(o.coincide, "{}: departs by {:.4} L", o.name, o.deviation);
        }
    }
}
