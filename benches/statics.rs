//! Speed of the rod model and the static solver (figures quoted in the README).
//!
//! Run: `cargo bench --features bench --bench statics`

use criterion::{Criterion, criterion_group, criterion_main};
use dlo_planner::case;
use dlo_planner::rod::energy::Objective;
use dlo_planner::rod::kinematics::Shape;
use dlo_planner::statics::{StaticOptions, solve_static};
use std::hint::black_box;
use std::path::Path;

fn load(name: &str) -> case::Case {
    load_with(name, serde_json::json!({}))
}

/// A shipped case with its top-level fields replaced by `fields`' (e.g. another
/// `discretisation` or `angle_frame`).
fn load_with(name: &str, fields: serde_json::Value) -> case::Case {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("planning_cases")
        .join(name);
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&p).expect("shipped case")).unwrap();
    for (k, x) in fields.as_object().into_iter().flatten() {
        v[k] = x.clone();
    }
    case::parse(&v.to_string(), &p).expect("shipped case loads")
}

/// Benchmarks `solve_static` of `c` from its own start, without the stability verdict.
fn bench_solve(c: &mut Criterion, label: &str, case: &case::Case) {
    let opts = StaticOptions {
        stability: false,
        ..case.options
    };
    c.bench_function(label, |b| {
        b.iter(|| {
            let mut p = case.problem.clone();
            solve_static(&mut p, black_box(&case.initial), &opts)
        })
    });
}

fn benches(c: &mut Criterion) {
    let pinned = load("pinned_buckling_080.json");
    let m = pinned.problem.model.clone();
    let a: Vec<f64> = (0..m.n()).map(|i| 0.1 * (i as f64).sin()).collect();
    let mut shape = Shape::default();
    let mut g = vec![0.0; m.n()];
    c.bench_function("planar energy+gradient (10 functions)", |b| {
        b.iter(|| m.objective_and_gradient(black_box(&a), Objective::Internal, &mut shape, &mut g))
    });
    bench_solve(c, "planar pinned buckling solve (l = 0.8L)", &pinned);
    let legendre = serde_json::json!({ "discretisation": { "basis": "legendre" } });
    bench_solve(
        c,
        "planar pinned buckling solve, Legendre basis (l = 0.8L)",
        &load_with("pinned_buckling_080.json", legendre),
    );
    bench_solve(
        c,
        "3D twisted clamped solve (30 coefficients)",
        &load("../tests/fixtures/paper_axes/kinking_twist_2pi_080.json"),
    );
    bench_solve(
        c,
        "3D extensible twisted solve (40 coefficients)",
        &load("extensible_twist_3d.json"),
    );
    let case_axes = serde_json::json!({ "angle_frame": "case" });
    bench_solve(
        c,
        "3D extensible twisted solve, the case's axes (40 coefficients)",
        &load_with("extensible_twist_3d.json", case_axes),
    );
    // The loop in the paper's basis of 4 pairs (shipped: Legendre, 16 pairs).
    let paper = || serde_json::json!({ "basis": "paper", "basis_pairs": 4 });
    let case_axes = serde_json::json!({ "angle_frame": "case", "discretisation": paper() });
    bench_solve(
        c,
        "3D crossed loop with self-contact, the case's axes",
        &load_with("self_contact_crossed_loop.json", case_axes),
    );
    bench_solve(
        c,
        "3D crossed loop with self-contact",
        &load_with(
            "self_contact_crossed_loop.json",
            serde_json::json!({ "discretisation": paper() }),
        ),
    );
    bench_solve(
        c,
        "3D crossed loop with self-contact as shipped (Legendre, 16 pairs)",
        &load("self_contact_crossed_loop.json"),
    );
}

criterion_group! {
    name = statics;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(3));
    targets = benches
}
criterion_main!(statics);
