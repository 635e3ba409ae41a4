//! Speed of the rod model and the static solver (figures quoted in the README).
//!
//! Run: `cargo bench --bench statics`

use criterion::{Criterion, criterion_group, criterion_main};
use dlo_planner::case;
use dlo_planner::energy::Objective;
use dlo_planner::kinematics::Shape;
use dlo_planner::statics::{StaticOptions, solve_static};
use std::hint::black_box;
use std::path::Path;

fn load(name: &str) -> case::Case {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("planning_cases")
        .join(name);
    case::load(&p).expect("shipped case loads")
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
    let no_stab = StaticOptions {
        stability: false,
        ..pinned.options
    };
    c.bench_function("planar pinned buckling solve (l = 0.8L)", |b| {
        b.iter(|| {
            let mut p = pinned.problem.clone();
            solve_static(&mut p, black_box(&pinned.initial), &no_stab)
        })
    });
    let twist = load("kinking_twist_2pi_080.json");
    let opts = StaticOptions {
        stability: false,
        ..twist.options
    };
    c.bench_function("3D twisted clamped solve (30 coefficients)", |b| {
        b.iter(|| {
            let mut p = twist.problem.clone();
            solve_static(&mut p, black_box(&twist.initial), &opts)
        })
    });
    let ext = load("extensible_twist_3d.json");
    let opts = StaticOptions {
        stability: false,
        ..ext.options
    };
    c.bench_function("3D extensible twisted solve (40 coefficients)", |b| {
        b.iter(|| {
            let mut p = ext.problem.clone();
            solve_static(&mut p, black_box(&ext.initial), &opts)
        })
    });
}

criterion_group! {
    name = statics;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(3));
    targets = benches
}
criterion_main!(statics);
