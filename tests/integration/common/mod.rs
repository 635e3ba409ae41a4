//! Shared helpers for integration tests: closed-form references and small problem builders.
#![allow(dead_code)]

use dlo_planner::constraints::{
    Angle, Bound, Constraint, OrientationConstraint, PositionConstraint,
};
use dlo_planner::rod::basis::Basis;
use dlo_planner::rod::layout::{Field, Layout};
use dlo_planner::rod::model::{Discretisation, Model};
use dlo_planner::rod::{Profile, Rod};
use dlo_planner::statics::problem::StaticProblem;

/// Complete elliptic integrals `K(m)`, `E(m)` (parameter `m = k²`) by the arithmetic–geometric
/// mean (Abramowitz & Stegun 17.6).
pub fn ellip_ke(m: f64) -> (f64, f64) {
    let (mut a, mut b) = (1.0_f64, (1.0 - m).sqrt());
    let mut c = m.sqrt();
    let mut sum = 0.5 * c * c;
    let mut pow = 0.5;
    for _ in 0..40 {
        let an = 0.5 * (a + b);
        let bn = (a * b).sqrt();
        c = 0.5 * (a - b);
        pow *= 2.0;
        sum += pow * c * c;
        a = an;
        b = bn;
        if c.abs() < 1e-17 {
            break;
        }
    }
    let k = std::f64::consts::PI / (2.0 * a);
    (k, k * (1.0 - sum))
}

/// Pinned–pinned elastica: for end distance ratio `l/L`, the parameter `m` solving
/// `l/L = 2E(m)/K(m) − 1` (bisection) and the load `P L²/Rf = 4K(m)²`.
pub fn pinned_elastica_load(ratio: f64) -> f64 {
    let (mut lo, mut hi) = (0.0_f64, 1.0 - 1e-15);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        let (k, e) = ellip_ke(mid);
        if 2.0 * e / k - 1.0 > ratio {
            lo = mid
        } else {
            hi = mid
        }
    }
    let (k, _) = ellip_ke(0.5 * (lo + hi));
    4.0 * k * k
}

/// A planar inextensible rod of length `l` with `Rf = 1`.
pub fn planar_rod(length: f64) -> Rod {
    Rod {
        length,
        flexural: Profile::Constant(1.0),
        torsional: None,
        extensional: None,
        weight: Profile::Constant(0.0),
        radius: 0.05,
    }
}

/// Pinned–pinned compression to `ratio·L` with `pairs` basis pairs.
pub fn pinned_problem(ratio: f64, pairs: usize) -> StaticProblem {
    let layout = Layout {
        basis: Basis::new(pairs),
        spatial: false,
        extensible: false,
        free_base: false,
    };
    let model = Model::new(
        planar_rod(100.0),
        layout,
        Discretisation::default(),
        [0.0; 3],
        vec![],
        &[],
    );
    let end = model.boundary(1.0);
    let c: Vec<Constraint> = vec![Constraint::from(PositionConstraint {
        name: "right pin".into(),
        boundary: end,
        rows: vec![(0, Bound::Equal(0.0)), (2, Bound::Equal(ratio))],
    })];
    StaticProblem::new(model, c)
}

/// Clamped at `t = 0` (θ = 0) as an orientation constraint, for tests.
pub fn clamp(model: &Model, t: f64) -> Constraint {
    Constraint::from(OrientationConstraint::new(
        model,
        "clamp".into(),
        t,
        vec![(Angle::Field(Field::Theta), 0.0)],
    ))
}

/// Largest difference between `p`'s Hessian `∇²f + Σ yᵢ∇²cᵢ` at `x` and central differences
/// (step 1e-6) of its gradient, relative to the Hessian's largest entry.
pub fn hessian_fd_error<P: dlo_planner::optim::Nlp>(p: &mut P, x: &[f64], y: &[f64]) -> f64 {
    let (n, m) = (p.n(), p.m());
    let mut c = vec![0.0; m];
    p.values(x, &mut c);
    let mut h = vec![0.0; n * n];
    p.hessian(x, y, &vec![0.0; m], &mut h);
    let step = 1e-6;
    let (mut gp, mut gm) = (vec![0.0; n], vec![0.0; n]);
    let scale = h.iter().fold(1e-8_f64, |s, v| s.max(v.abs()));
    let mut worst: f64 = 0.0;
    for j in 0..n {
        let mut xs = x.to_vec();
        xs[j] += step;
        p.values(&xs, &mut c);
        p.gradient(&xs, y, &mut gp);
        xs[j] -= 2.0 * step;
        p.values(&xs, &mut c);
        p.gradient(&xs, y, &mut gm);
        for i in 0..n {
            let fd = (gp[i] - gm[i]) / (2.0 * step);
            worst = worst.max((fd - h[i * n + j]).abs() / scale);
        }
    }
    worst
}

/// The shipped case `name` (in `planning_cases/`) with its JSON changed by `edit`.
pub fn shipped_variant(
    name: &str,
    edit: impl FnOnce(&mut serde_json::Value),
) -> dlo_planner::case::Case {
    let path = std::path::Path::new("planning_cases").join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    edit(&mut v);
    dlo_planner::case::parse(&v.to_string(), &std::path::Path::new("variant").join(name)).unwrap()
}

/// A free planar strip (base fixed in position only) planned from a spiral that turns by 7 rad
/// tightening towards its tip (θ ≈ 7t², least-squares fit in the Ritz basis: the tip inside
/// the coil) to its mirror in the basis, the spiral loosening towards its tip (θ ≈ 7(1 − (1 −
/// t)²): the tip outside). Halfway along the straight-line path the strip is a circle lapping
/// over itself.
#[allow(dead_code)]
pub fn spiral_case(self_contact: bool) -> dlo_planner::case::Case {
    let inward = [
        -1.166275, 7.0, 0.0, 0.710032, 0.0, 0.178096, 0.0, 0.079589, 0.0, 0.045112,
    ];
    let outward: Vec<f64> = inward
        .iter()
        .enumerate()
        .map(|(i, &v)| if i == 1 { v } else { -v })
        .collect();
    let text = format!(
        r#"{{ "name": "spiral", "self_contact": {self_contact},
  "rod": {{ "length": 1.0, "flexural_rigidity": 1.0, "radius": 0.005 }},
  "plan": {{ "start": {{ "shape": {{ "theta": {inward:?} }} }},
            "goal": {{ "shape": {{ "theta": {outward:?} }} }}, "k_samples": 21 }} }}"#
    );
    dlo_planner::case::parse(&text, std::path::Path::new("spiral.json")).unwrap()
}

/// Removes from a JSON report what differs between runs of one build: timings and file paths
/// (the log, the picture, the trajectory CSV).
pub fn strip(v: &mut serde_json::Value) {
    match v {
        serde_json::Value::Object(map) => {
            map.retain(|k, _| {
                !k.starts_with("timing") && !["mcap", "svg", "trajectory_csv"].contains(&k.as_str())
            });
            map.values_mut().for_each(strip);
        }
        serde_json::Value::Array(items) => items.iter_mut().for_each(strip),
        _ => {}
    }
}

/// Seconds each generated-input test file runs for: `DLO_FUZZ_SECONDS`, or 2 (a quick pass in
/// the test command; `.ci/run` runs them again for 60 s each).
pub fn fuzz_seconds() -> f64 {
    std::env::var("DLO_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .filter(|s: &f64| s.is_finite() && *s >= 0.0)
        .unwrap_or(2.0)
}

/// Runs batches of `cases` proptest cases of `test` on `strategy`, each batch from its own fixed
/// seed (`salt`, batch number), until `budget` has passed (at least one batch); panics naming
/// the batch that fails, so that it can be rerun: `DLO_FUZZ_BATCH=N` runs batch N alone.
/// Returns the cases run.
pub fn run_batches<S: proptest::strategy::Strategy>(
    name: &str,
    salt: u8,
    cases: u32,
    budget: std::time::Duration,
    strategy: S,
    test: impl Fn(S::Value) -> Result<(), proptest::test_runner::TestCaseError>,
) -> u64 {
    use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
    let start = std::time::Instant::now();
    let only: Option<u64> = std::env::var("DLO_FUZZ_BATCH")
        .ok()
        .and_then(|s| s.parse().ok());
    let mut batch = only.unwrap_or(0);
    let mut run = 0u64;
    while run == 0 || (only.is_none() && start.elapsed() < budget) {
        let mut seed = [salt; 32];
        seed[..8].copy_from_slice(&batch.to_le_bytes());
        let config = Config {
            cases,
            failure_persistence: None,
            ..Config::default()
        };
        let mut runner =
            TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &seed));
        if let Err(e) = runner.run(&strategy, &test) {
            panic!("{name}, batch {batch}: {e}");
        }
        batch += 1;
        run += 1;
    }
    run * u64::from(cases)
}

/// The straight-line path of `p` replayed from its start shape with the plan's replay settings,
/// ended early by `early_stop`.
pub fn replay_straight_path(
    p: &dlo_planner::planner::Planner,
    early_stop: dlo_planner::planner::replay::EarlyStop,
) -> dlo_planner::planner::replay::Replay {
    use dlo_planner::planner::replay::{ReplayOptions, replay};
    let path = p.path();
    let z = vec![0.0; path.n_vars()];
    let opts = ReplayOptions {
        early_stop,
        ..p.settings.replay()
    };
    let stop = std::sync::atomic::AtomicBool::new(false);
    let mut silent = dlo_planner::planner::observer::Silent;
    replay(
        &p.base,
        &p.start,
        &path,
        &z,
        opts,
        &p.static_options,
        &mut silent,
        &stop,
    )
}

/// A directory of a test's own under the system's temporary directory (named after `tag`, the
/// process and a counter), removed with everything in it when dropped, whether the test
/// passes or fails.
pub struct Scratch(std::path::PathBuf);

impl Scratch {
    pub fn new(tag: &str) -> Scratch {
        static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        let dir = std::env::temp_dir().join(format!("{tag}-{}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }

    pub fn path(&self) -> std::path::PathBuf {
        self.0.clone()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
