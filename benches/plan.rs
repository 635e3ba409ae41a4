//! Speed of planning and replay on the paper's planar example and the three 3D cases, and the
//! cost of the MCAP log (figures quoted in the README).
//!
//! Run: `cargo bench --features bench --bench plan`

use criterion::{Criterion, criterion_group, criterion_main};
use dlo_planner::case;
use dlo_planner::output::mcap_log::{McapWriter, PlanLog, SharedWriter};
use dlo_planner::planner::Planner;
use dlo_planner::planner::observer::Silent;
use dlo_planner::planner::replay::replay;
use std::path::Path;
use std::sync::{Arc, Mutex};

fn planner(name: &str) -> (case::Case, Planner) {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("planning_cases")
        .join(name);
    let c = case::load(&p).expect("shipped case loads");
    let pl = Planner::from_case(&c).expect("plan section is valid");
    (c, pl)
}

fn benches(c: &mut Criterion) {
    let (case, pl) = planner("plan_paper_planar.json");
    let mut g = c.benchmark_group("paper planar");
    g.sample_size(10);
    g.bench_function("plan + verify + replay, no log", |b| {
        b.iter(|| pl.run(&mut Silent))
    });
    let dir = std::env::temp_dir().join("dlo-bench");
    std::fs::create_dir_all(&dir).unwrap();
    g.bench_function("plan + verify + replay, MCAP log", |b| {
        b.iter(|| {
            let w: SharedWriter = Arc::new(Mutex::new(
                McapWriter::create(&dir.join("bench.mcap")).unwrap(),
            ));
            let mut log = PlanLog::new(w.clone(), case.obstacles.clone());
            let r = pl.run(&mut log);
            w.lock().unwrap().finish().unwrap();
            r
        })
    });
    let r = pl.run(&mut Silent);
    let path = pl.with_terms(r.path_terms).path();
    let opts = pl.settings.replay();
    g.bench_function("replay (41 steps)", |b| {
        b.iter(|| {
            replay(
                &pl.base,
                &pl.start,
                &path,
                &r.z,
                opts,
                &pl.static_options,
                &mut Silent,
                &std::sync::atomic::AtomicBool::new(false),
            )
        })
    });
    g.finish();
    let mut g = c.benchmark_group("3D cases");
    g.sample_size(10);
    for name in [
        "plan_cable_under_bar",
        "plan_cable_around_pillar",
        "plan_cable_past_mesh",
    ] {
        let (_, pl) = planner(&format!("{name}.json"));
        g.bench_function(format!("{name}: plan + verify + replay, no log"), |b| {
            b.iter(|| pl.run(&mut Silent))
        });
    }
    g.finish();
}

criterion_group!(plan, benches);
criterion_main!(plan);
