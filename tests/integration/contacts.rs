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

/// A generated 3D problem (the suite's generator, seed 41, ten 3D problems after twenty planar
/// ones: `spatial_2`) whose start pose presses the cable onto the mesh cube: held at its sample
/// points the start shape dips into the cube between them, so it is solved with the contacts on
/// the chords, where it rests on the cube (clearance 4e-5 L on the verification grid). The
/// replays hold the rod the same way, and the replay's first step, solved from the start shape
/// and its own multipliers at its own end pose, stays on it. With the contacts at the points
/// (measured: the replay under `p.base`), and on the chords when a warm-started solve still
/// stepped off every saddle of the augmented function, the first step went to another
/// equilibrium (U 14.33 and 5.83 instead of 8.36, 0.26 L away at k = 0), and the verdict called
/// the start shape one its end pose does not hold.
#[test]
fn a_start_resting_on_an_obstacle_is_where_the_replay_starts() {
    use dlo_planner::optim::Nlp;
    use dlo_planner::planner::Planner;
    use dlo_planner::planner::endpoints::EndPose;
    use dlo_planner::statics::solve_static_warm;
    let text = r#"{"name": "spatial_41_2", "planar": false,
      "rod": {"length": 1.0, "flexural_rigidity": 1.0, "torsional_rigidity": 0.77, "radius": 0.01},
      "constraints": [{"type": "orientation", "s": 0.0, "theta": 0.0, "phi_plus_psi": 0.0}],
      "obstacles": [{"name": "o0", "shape": {"type": "triangle_mesh", "obj": "meshes/cube.obj", "scale": 0.25590206247483466}, "position": [-0.05051621964152547, 0.046029931293506327, 0.7620766829118648]}],
      "plan": {"start": {"position": [-0.2270934885855953, -0.11898475530026731, 0.7327632042096668], "tangent": [-0.6568973928145647, -0.3441788491085004, 0.6708403201506119], "twist": 0.34531151489530787},
               "goal": {"position": [0.24454164804529685, 0.24291432476232083, 0.5194825293426226], "tangent": [0.6159470151547449, 0.6118481431349766, 0.49623696382297205], "twist": -0.388309232086258}}}"#;
    let root = env!("CARGO_MANIFEST_DIR");
    let path = std::path::Path::new(root).join("planning_cases/spatial_41_2.json");
    let c = dlo_planner::case::parse(text, &path).unwrap();
    let p = Planner::from_case(&c).unwrap();
    // The start rests on the chords, not held off them.
    assert_eq!(p.start_contacts, Some(0.0));
    let start = &p.start;
    assert_eq!(start.status, SolveStatus::Converged);
    assert_eq!(start.stable, Some(true));
    // Its own end pose on the replays' problem, solved from it with its multipliers: the same
    // shape to the bit, the same energy.
    let shape = p.base.model.evaluate(&start.a);
    let mut held = EndPose::of(&p.base.model, &start.a, &shape.positions).problem(&p.held);
    assert_eq!(held.m(), start.lambda.len());
    let again = solve_static_warm(&mut held, &start.a, &start.lambda, &p.static_options);
    assert_eq!(again.status, SolveStatus::Converged);
    assert_eq!(again.a, start.a);
    // The replay of the straight path (stopped where it departs) starts on the start shape.
    let path = p.path();
    let z = vec![0.0; path.n_vars()];
    let replay = |base| {
        dlo_planner::planner::replay::replay(
            base,
            start,
            &path,
            &z,
            dlo_planner::planner::replay::ReplayOptions {
                early_stop: dlo_planner::planner::replay::EarlyStop::Departure,
                ..p.settings.replay()
            },
            &p.static_options,
            &mut dlo_planner::planner::observer::Silent,
            &std::sync::atomic::AtomicBool::new(false),
        )
    };
    let rep = replay(&p.held);
    assert!(rep.start_held());
    assert!(
        rep.start_deviation_over_l < 1e-9,
        "{}",
        rep.start_deviation_over_l
    );
}

/// A generated 3D problem in the paper's basis (the suite's generator, seed 8, its 3D problems
/// only, `"discretisation": {"basis": "paper"}`: `spatial_13`) whose start pose presses the
/// cable onto a capsule with 288 (units of Rf/L²), held by end forces of the same size. Started
/// from that equilibrium with its multipliers at the penalty the static solves start with
/// (1e3), the solve of a pose moved by k = 0.0005 along the straight path ran off it (measured:
/// infeasible, violation 0.087, 5.0 away in the coefficients): the augmented function is not
/// convex there at that penalty. The replay's steps try once more with a hundred times the
/// penalty; its first step then converges to the equilibrium a solve started at that penalty
/// finds, next to the start.
#[test]
fn a_replay_step_from_a_hard_pressed_start_stays_on_its_branch() {
    use dlo_planner::planner::Planner;
    use dlo_planner::planner::endpoints::EndPose;
    use dlo_planner::planner::replay::{EarlyStop, ReplayOptions, replay};
    use dlo_planner::statics::{StaticOptions, solve_static_warm};
    let text = r#"{"name": "spatial_8_13", "planar": false,
      "rod": {"length": 1.0, "flexural_rigidity": 1.0, "torsional_rigidity": 0.77, "radius": 0.01},
      "discretisation": {"basis": "paper"},
      "constraints": [{"type": "orientation", "s": 0.0, "theta": 0.0, "phi_plus_psi": 0.0}],
      "obstacles": [{"name": "o0", "shape": {"type": "cuboid", "half_extents": [0.0416809713178576, 0.051046019552126135, 0.07314177641244257]}, "position": [0.09273376101350067, -0.06541263473750056, 1.0803039840007889]},
                    {"name": "o1", "shape": {"type": "capsule", "a": [0, -1, 0], "b": [0, 1, 0], "radius": 0.09822237499569735}, "rotation": [0, 0, 2.444272655591042], "position": [-0.11294322312193135, 0.023118939926305815, 0.7944184656228619]}],
      "plan": {"start": {"position": [-0.3033130029835817, -0.006076439870102338, 0.7989195046552738], "tangent": [-0.783861882642939, -0.0157035456755636, 0.6207366169259574], "twist": -0.23543873561215822},
               "goal": {"position": [0.34910751991515376, -0.11847457869833107, 0.6468145129440668], "tangent": [0.8058820018895145, -0.2734874650584217, 0.5251274183343191], "twist": 0.04092343004332555}}}"#;
    let c = dlo_planner::case::parse(text, std::path::Path::new("spatial_8_13.json")).unwrap();
    let p = Planner::from_case(&c).unwrap();
    let start = &p.start;
    let force: f64 = start.lambda.iter().fold(0.0, |m, l| m.max(*l));
    assert!(force > 200.0, "{force}");
    let path = p.path();
    let z = vec![0.0; path.n_vars()];
    let rep = replay(
        &p.held,
        start,
        &path,
        &z,
        ReplayOptions {
            early_stop: EarlyStop::Departure,
            ..p.settings.replay()
        },
        &p.static_options,
        &mut dlo_planner::planner::observer::Silent,
        &std::sync::atomic::AtomicBool::new(false),
    );
    assert!(rep.steps.len() >= 2);
    let first = &rep.steps[1];
    assert!(first.converged, "{:?}", first.status);
    // The reference: the same pose solved from the start at a penalty of 1e4 from the outset.
    let mut a = vec![0.0; path.n()];
    path.shape_at(&z, first.k, &mut a);
    let shape = p.base.model.evaluate(&a);
    let mut held = EndPose::of(&p.base.model, &a, &shape.positions).problem(&p.held);
    let mut opts: StaticOptions = p.static_options;
    opts.al.rho_initial = 1e4;
    let reference = solve_static_warm(&mut held, &start.a, &start.lambda, &opts);
    assert_eq!(reference.status, SolveStatus::Converged);
    let d = first
        .a
        .iter()
        .zip(&reference.a)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(d < 1e-6, "{d}");
    let moved = first
        .a
        .iter()
        .zip(&start.a)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(moved < 0.5, "{moved}");
}
