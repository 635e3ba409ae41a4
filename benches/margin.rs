//! Speed of the disturbance force margin: a full F_mub–μ curve (9 points × 9 directions × 10
//! values of μ) on grasp (a) and grasp (b) (figures quoted in the README).
//!
//! Run: `cargo bench --features bench --bench margin`

use criterion::{Criterion, criterion_group, criterion_main};
use dlo_planner::case;
use dlo_planner::grasp::Grasp;
use std::path::Path;

fn grasp(name: &str) -> Grasp {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("planning_cases")
        .join(name);
    Grasp::from_case(&case::load(&p).expect("shipped case loads")).expect("grasp section is valid")
}

fn benches(c: &mut Criterion) {
    let mut g = c.benchmark_group("margin curve, 81 points x directions, 10 mu");
    g.sample_size(10);
    for name in ["grasp_a_080.json", "grasp_b_pinch.json"] {
        let gr = grasp(name);
        g.bench_function(name, |b| b.iter(|| gr.margin(&|_, _| {}).unwrap()));
    }
    g.finish();
}

criterion_group!(margin, benches);
criterion_main!(margin);
