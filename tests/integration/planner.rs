//! Deformation path planning (paper §7) on the shipped planar case and on cases built in the
//! test: collision avoidance checked on an independent grid, optimality against hand-made
//! paths, the replay's agreement with the plan where it holds, and a negative verdict where
//! one end cannot suffice.

use crate::common::{self, shipped_variant};
use dlo_planner::case;
use dlo_planner::planner::observer::Silent;
use dlo_planner::planner::path::DeformationPath;
use dlo_planner::planner::verify::{fine_model, verify};
use dlo_planner::planner::{Attempt, PlanStatus, Planner};
use std::path::Path;
use std::sync::OnceLock;

fn paper() -> &'static (Planner, dlo_planner::planner::PlanResult) {
    static R: OnceLock<(Planner, dlo_planner::planner::PlanResult)> = OnceLock::new();
    R.get_or_init(|| {
        let c = case::load(Path::new("planning_cases/plan_paper_planar.json")).unwrap();
        let p = Planner::from_case(&c).unwrap();
        let r = p.run(&mut Silent);
        (p, r)
    })
}

/// The paper's case with `plan` fields replaced, planned and replayed, with the case's own
/// path terms only (no `fallback_path_terms` unless `fields` sets them), so that each test's
/// scenario keeps its path basis whatever the verdict.
fn paper_with(fields: serde_json::Value) -> dlo_planner::planner::PlanResult {
    let c = shipped_variant("plan_paper_planar.json", |v| {
        v["plan"]["fallback_path_terms"] = serde_json::json!([]);
        for (key, val) in fields.as_object().unwrap() {
            v["plan"][key] = val.clone();
        }
    });
    Planner::from_case(&c).unwrap().run(&mut Silent)
}

/// The starts of `r` after its quick attempt's (one quick start runs first on a planar rod),
/// and the chosen start's position among them.
fn after_quick(
    r: &dlo_planner::planner::PlanResult,
) -> (Vec<&dlo_planner::planner::StartSummary>, Option<usize>) {
    let quick = r
        .starts
        .iter()
        .take_while(|s| s.attempt == Attempt::Quick)
        .count();
    assert!(
        r.starts[quick..]
            .iter()
            .all(|s| s.attempt != Attempt::Quick)
    );
    let later: Vec<_> = r.starts[quick..].iter().collect();
    let chosen = r
        .chosen_start
        .and_then(|c| later.iter().position(|s| s.start == c));
    (later, chosen)
}

/// The attempts after the case's own have an evaluation budget (so has the quick attempt before
/// it): on the paper's case with its three path terms and fixed tracking targets
/// (`"equilibrium_slopes": false`, under which its first start does not coincide), no
/// equilibrium plans and no lift of the own plan (which would run before the fallback), the
/// six-term fallback stops its sharpness stages once it has used `fallback_evaluations` (checked
/// between stages, so it may exceed it by one stage: with a budget of 100 it runs its first
/// stage only), says `iteration_limit`, and its plan is still verified and reported; without
/// the budget the same fallback runs every stage to convergence.
#[test]
fn fallback_attempts_stop_at_their_evaluation_budget() {
    use dlo_planner::planner::observer::{PlanObserver, Progress};
    use dlo_planner::rod::model::Model;
    /// Each start's last sharpness stage reported.
    struct Stages(std::collections::BTreeMap<usize, usize>);
    impl PlanObserver for Stages {
        fn progress(&mut self, _: &Model, p: &Progress, _: &[f64]) {
            let last = self.0.entry(p.start).or_insert(0);
            *last = (*last).max(p.stage);
        }
    }
    let run = |budget: usize| {
        let c = shipped_variant("plan_paper_planar.json", |v| {
            let fields = serde_json::json!({
                "path_terms": 3, "safety_margin": 0.01, "starts": 1, "fallback_path_terms": [6],
                "equilibrium_plans": false, "fallback_evaluations": budget, "lift": false,
                "equilibrium_slopes": false
            });
            for (key, val) in fields.as_object().unwrap() {
                v["plan"][key] = val.clone();
            }
        });
        let mut stages = Stages(Default::default());
        let r = Planner::from_case(&c).unwrap().run(&mut stages);
        (r, stages.0)
    };
    let (limited, limited_stages) = run(100);
    let (free, free_stages) = run(100_000_000);
    // The quick attempt (budgeted too), the case's own, the fallback.
    let attempts: Vec<Attempt> = limited.starts.iter().map(|s| s.attempt).collect();
    assert_eq!(attempts, [Attempt::Quick, Attempt::Own, Attempt::Fallback]);
    let (first, fallback) = (&limited.starts[1], &limited.starts[2]);
    assert_eq!(first.path_terms, 3);
    assert_eq!(fallback.path_terms, 6);
    assert_eq!(
        fallback.status,
        dlo_planner::optim::AlStatus::IterationLimit
    );
    assert!(fallback.u_max.is_finite());
    let sharpest = dlo_planner::planner::PlanSettings::default()
        .sharpness
        .len()
        - 1;
    assert_eq!(limited_stages.get(&fallback.start), Some(&0));
    // The first attempt is the same with either budget; the unlimited fallback runs every stage,
    // converges and uses more evaluations than the budget allowed.
    let free_fallback = free.starts.last().expect("the fallback ran");
    assert_eq!(free_fallback.attempt, Attempt::Fallback);
    assert_eq!(free.starts[1].attempt, Attempt::Own);
    assert_eq!(free.starts[1].evaluations, first.evaluations);
    assert_eq!(free_stages.get(&free_fallback.start), Some(&sharpest));
    assert_eq!(
        free_fallback.status,
        dlo_planner::optim::AlStatus::Converged
    );
    assert!(
        free_fallback.evaluations > fallback.evaluations,
        "{} {}",
        free_fallback.evaluations,
        fallback.evaluations
    );
}

/// Equilibrium tracking's strength matters away from the shipped poses: one of the 24 random
/// start and goal poses of the README's study (the shipped case otherwise, two starts) holds
/// U_max = its goal shape's energy, so the minimax objective leaves the interior free and tracking
/// alone pulls it onto the equilibria. With the default tracking (weight 10,000, up to eight
/// rounds, stopped at the shipped 80 % of the tolerance) the replay coincides (measured 1.53 %
/// of L after four rounds; 1.29 % after six with the default stop at a tenth); with the earlier weight 1000 and three
/// rounds, and fixed targets (`"equilibrium_slopes": false`), it departs by more than the 2 %
/// tolerance (measured 2.82 %), from the same sharpness stages.
#[test]
fn stronger_tracking_makes_a_moved_pose_coincide() {
    let run = |extra: serde_json::Value| {
        let c = shipped_variant("plan_paper_planar.json", |v| {
            // Both tracking settings on the four-term stages.
            v["plan"]["fallback_path_terms"] = serde_json::json!([]);
            v["plan"]["start"] = serde_json::json!({ "x": 0.332, "z": 0.645, "theta": 0.614 });
            v["plan"]["goal"] = serde_json::json!({ "x": -0.348, "z": 0.644, "theta": 0.044 });
            for (key, val) in extra.as_object().unwrap() {
                v["plan"][key] = val.clone();
            }
        });
        Planner::from_case(&c).unwrap().run(&mut Silent)
    };
    let strong = run(serde_json::json!({}));
    let weak = run(serde_json::json!({
        "equilibrium_weight": 1000.0, "equilibrium_rounds": 3, "equilibrium_slopes": false
    }));
    for r in [&strong, &weak] {
        assert_eq!(r.status, PlanStatus::Planned);
        assert!(r.replay.all_converged && r.replay.all_stable);
    }
    let tol = strong.replay.tolerance;
    assert!(
        strong.replay.coincide && strong.replay.max_deviation_over_l <= tol,
        "default tracking: {}",
        strong.replay.max_deviation_over_l
    );
    assert!(
        !weak.replay.coincide && weak.replay.max_deviation_over_l > tol,
        "earlier tracking: {}",
        weak.replay.max_deviation_over_l
    );
    // Both plans peak at the goal shape's energy: tracking moves the interior, not the peak.
    assert!((strong.u_max - weak.u_max).abs() <= 1e-6 * strong.u_max);
}

/// The replay's largest deviation (units of L) at `k ≤ k_max`.
fn deviation_up_to(r: &dlo_planner::planner::PlanResult, k_max: f64) -> f64 {
    r.replay
        .steps
        .iter()
        .filter(|s| s.k <= k_max)
        .map(|s| s.deviation)
        .fold(0.0, f64::max)
}

/// The straight-line path `c = 0` goes through the block; the plan clears it on a grid of
/// 201 × 257 points the optimiser never saw.
#[test]
fn colliding_straight_path_becomes_collision_free() {
    let (_, r) = paper();
    assert!(
        r.min_clearance_straight.unwrap() < -0.1,
        "{:?}",
        r.min_clearance_straight
    );
    assert_eq!(r.status, PlanStatus::Planned);
    assert!(r.min_clearance.unwrap() >= 0.0, "{:?}", r.min_clearance);
}

/// The plan's `U_max` is below that of every collision-free path of a hand-made family:
/// `a(k) = (1−k)a0 + k a1 + 4k(1−k)·b(β, γ)`, where `b` adds the bend
/// `θ = β s/L + γ sin(2πs/L)` at `k = 1/2` (the way a person would lift the strip around the block).
/// The members are checked on every other k of the verification grid (101 values, with its
/// bisection between them): a member's U_max there is at most its value on the full grid, so
/// the plan must beat each by at least as much.
#[test]
fn plan_beats_hand_made_collision_free_paths() {
    let (p, r) = paper();
    let fine = fine_model(&p.base.model, 256, 4);
    let n = p.start.a.len();
    let mut best_hand = f64::INFINITY;
    let mut clear = 0;
    for i in 0..=48 {
        for j in 0..=12 {
            let beta = -12.0 + 0.5 * i as f64;
            let gamma = -3.0 + 0.5 * j as f64;
            // θ coefficients: [constant, t, sin, cos, …]; the curl adds β·t + γ·sin(2πt).
            let mut b = vec![0.0; n];
            b[1] = beta;
            b[2] = gamma;
            // Keep θ(0) = 0: the path's constant stays that of the straight-line path.
            let path = DeformationPath::new(p.start.a.clone(), p.goal.a.clone(), 1, &[]);
            let z: Vec<f64> = b.iter().map(|v| 4.0 * v).collect();
            let v = verify(&fine, &path, &z, 101, &p.obstacles, p.base.objective);
            if v.collision_free(0.0) {
                clear += 1;
                best_hand = best_hand.min(v.u_max);
            }
        }
    }
    assert!(
        clear > 0,
        "the hand-made family has no collision-free member"
    );
    assert!(
        r.u_max < best_hand,
        "plan U_max {} vs best hand-made {}",
        r.u_max,
        best_hand
    );
}

/// A replay that only decides a question ends at its answer: on the paper's straight path
/// (which runs through the block, so the replayed equilibria leave it), the replays that stop
/// at a departure, at a solve that does not converge, and at that or a snap-through, are the
/// full replay's first steps bit for bit, up to and including the first step that answers,
/// and none coincides when it stopped.
#[test]
fn a_replay_stopped_early_is_the_start_of_the_full_replay() {
    use dlo_planner::planner::replay::EarlyStop;
    let (p, _) = paper();
    let run = |early_stop| common::replay_straight_path(p, early_stop);
    let full = run(EarlyStop::Never);
    let tol = full.tolerance * p.base.model.rod.length;
    let departs = |s: &dlo_planner::planner::replay::ReplayStep| {
        !s.converged || s.deviation > tol || full.snaps.contains(&s.k)
    };
    let first_departure = full.steps.iter().position(departs);
    assert!(
        first_departure.is_some_and(|i| i > 0 && i + 1 < full.steps.len()),
        "the straight path departs inside (0, 1): {first_departure:?} of {}",
        full.steps.len()
    );
    let first_unconverged = full.steps.iter().position(|s| !s.converged);
    let first_failure = full
        .steps
        .iter()
        .position(|s| !s.converged || full.snaps.contains(&s.k));
    for (mode, answer) in [
        (EarlyStop::Departure, first_departure),
        (EarlyStop::Unconverged, first_unconverged),
        (EarlyStop::Failure, first_failure),
    ] {
        let early = run(mode);
        let n = answer.map_or(full.steps.len(), |i| i + 1);
        assert_eq!(early.steps.len(), n, "{mode:?}");
        for (a, b) in early.steps.iter().zip(&full.steps) {
            assert_eq!(a.k.to_bits(), b.k.to_bits(), "{mode:?}");
            assert_eq!(a.deviation.to_bits(), b.deviation.to_bits(), "{mode:?}");
            assert!(
                a.a.iter()
                    .zip(&b.a)
                    .all(|(x, y)| x.to_bits() == y.to_bits())
            );
        }
        assert!(answer.is_none() || !early.coincide, "{mode:?}");
    }
    assert!(!full.coincide);
}

/// The replay starts on `a0` and ends on `a1`.
#[test]
fn replay_reproduces_start_and_goal() {
    let (_, r) = paper();
    assert!(
        r.replay.start_deviation_over_l < 1e-6,
        "{}",
        r.replay.start_deviation_over_l
    );
    assert!(
        r.replay.end_deviation_over_l < 1e-6,
        "{}",
        r.replay.end_deviation_over_l
    );
    assert!(r.replay.all_stable);
}

/// On the paper's example (with four path terms) the replay by the end pose coincides with the
/// plan within the 2 % tolerance, every replayed shape stable (without neutral modes) and every
/// solve converged.
#[test]
fn paper_replay_coincides() {
    let (_, r) = paper();
    assert!(r.replay.all_converged && r.replay.snaps.is_empty());
    assert!(r.replay.steps.iter().all(|st| st.neutral_modes == Some(0)));
    assert!(
        r.replay.max_deviation_over_l <= 0.02,
        "{}",
        r.replay.max_deviation_over_l
    );
    assert!(r.replay.coincide);
    // Up to the last swing (k ≤ 0.95) within 1 % of L, the level the independent
    // implementation reached outside its middle swing (measured 0.63 %, at k = 0.525).
    let before_last_swing = deviation_up_to(r, 0.95);
    assert!(before_last_swing < 0.01, "{before_last_swing}");
}

/// Without a safety margin the plan grazes the block, and the end pose alone presses the
/// replayed strip against it. The replay says where: a step with a contact force has zero
/// clearance, a step with clearance has no contact force (complementarity, to 1e-6 L), and the
/// largest contact force is the one a fresh static solve at that end pose (from the plan's
/// shape, without the replay's multipliers) needs: its moments balance to rounding with it
/// (here 8.04 Rf/L², the block's side pushing the strip along +x at k = 0.1).
#[test]
fn replay_reports_where_it_leans_on_obstacles() {
    let c = shipped_variant("plan_paper_planar.json", |v| {
        v["plan"]["safety_margin"] = serde_json::json!(0.0);
        v["plan"]["starts"] = serde_json::json!(1);
        // The four-term plan that grazes the block, whatever its replay's verdict, and the
        // report's replay its own (not replayed equilibria held off the block).
        v["plan"]["fallback_path_terms"] = serde_json::json!([]);
        v["plan"]["equilibrium_plans"] = serde_json::json!(false);
        // The fixed tracking targets the scenario was built with (with the slopes the
        // replay keeps off the block).
        v["plan"]["equilibrium_slopes"] = serde_json::json!(false);
        // Forces in units of Rf/L² = 3, so that a force missing its unit shows.
        v["rod"]["flexural_rigidity"] = serde_json::json!(3.0);
    });
    let p = Planner::from_case(&c).unwrap();
    let r = p.run(&mut Silent);
    let rp = &r.replay;
    assert!(
        rp.max_contact_force > 0.0,
        "the replay never leans on the block"
    );
    for st in &rp.steps {
        let gap = st.clearance.expect("the case has an obstacle");
        assert!(gap > -1e-6, "k = {}: clearance {gap}", st.k);
        if st.contact_force > 0.0 {
            assert!(
                gap < 1e-6,
                "k = {}: force {} at clearance {gap}",
                st.k,
                st.contact_force
            );
        }
        if gap > 1e-6 {
            assert_eq!(st.contact_force, 0.0, "k = {}", st.k);
        }
    }
    // The smallest clearance is that of the equilibria: over the steps whose solves converged.
    let smallest = rp
        .steps
        .iter()
        .filter(|s| s.converged)
        .filter_map(|s| s.clearance)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(rp.min_clearance, Some(smallest));
    let k = rp.k_at_max_contact_force;
    let model = &p.base.model;
    let path = p.path();
    let mut a = vec![0.0; path.n()];
    path.shape_at(&r.z, k, &mut a);
    let pose =
        dlo_planner::planner::endpoints::EndPose::of(model, &a, &model.evaluate(&a).positions);
    let sol = dlo_planner::statics::solve_static(&mut pose.problem(&p.base), &a, &p.static_options);
    assert_eq!(sol.status, dlo_planner::statics::SolveStatus::Converged);
    assert!(
        sol.balance.expect("computed").relative < 1e-9,
        "{:?}",
        sol.balance
    );
    let block = sol
        .reactions
        .iter()
        .find(|x| x.constraint == "obstacle block")
        .expect("obstacle reaction");
    let f = block.force.iter().map(|v| v * v).sum::<f64>().sqrt();
    // Both solves stop at the optimality tolerance 1e-5 (dimensionless: forces in Rf/L²),
    // which bounds how well their multipliers agree.
    let unit = model.rod.force_unit();
    let tol = 1e-5 * unit * (1.0 + f / unit);
    assert!(
        (f - rp.max_contact_force).abs() <= tol,
        "{f} vs {}",
        rp.max_contact_force
    );
}

/// The verdict is not one lucky start's: single starts reach several local minima, and only
/// the lower ones coincide (README); the fine sharpness continuation reaches one from most
/// starts, and the case takes two. Two other starts (seeds 5–6 instead of 1–2) reach a
/// coinciding plan too.
#[test]
fn paper_replay_coincides_from_other_starts() {
    let r = paper_with(serde_json::json!({ "seed": 5 }));
    assert_eq!(r.status, PlanStatus::Planned);
    assert!(
        r.replay.coincide && r.replay.max_deviation_over_l <= 0.02,
        "{}",
        r.replay.max_deviation_over_l
    );
}

/// The shipped case runs its two starts one at a time (`"parallel_starts": 1`): the second
/// runs only when the first plan's sampled shapes lie farther than the coincidence tolerance
/// from the equilibria their end poses produce (the replay's deviation estimated on the samples
/// by the last equilibrium-tracking pass). With seed 1 the first start's estimate is 1.46 % of
/// L, the second start does not run, and the replay confirms the estimate (measured equal to
/// 1e-15: the replay takes the same 41 steps, and the strip stays clear of the block). With
/// seed 14 the first start's plan is estimated at 2.48 %, so the second start (seed 15) runs and
/// is chosen; it is the single start of seed 15 bit for bit — when only an optimal path that
/// coincides counts (`"equilibrium_plans": false`). By default the first start's replayed
/// equilibria are a plan, and the second start does not run; with the fallback counts, the
/// quick plan, lower than the first start's, is then lifted and tracked, and is the plan.
/// (A quick start runs before them on a planar rod; on this case its plan peaks inside the
/// path, so it is not replayed and does not count.)
#[test]
fn paper_second_start_runs_only_when_the_first_does_not_coincide() {
    let (p, r) = paper();
    assert_eq!(p.settings.parallel_starts(), 1);
    let (own, chosen) = after_quick(r);
    assert_eq!((own.len(), r.starts_not_run, chosen), (1, 1, Some(0)));
    let est = own[0].equilibrium_deviation.expect("tracking measured it");
    assert!(est <= p.settings.coincide_tolerance, "{est}");
    assert!(
        (est - r.replay.max_deviation_over_l).abs() < 1e-6,
        "estimate {est}, replay {}",
        r.replay.max_deviation_over_l
    );

    // Seed 14 with fixed tracking targets (`"equilibrium_slopes": false`; with the slopes
    // the first start's plan coincides): the first start's plan departs from its replay,
    // whose equilibria are a plan; the second start does not run.
    let eq = paper_with(serde_json::json!({ "seed": 14, "equilibrium_slopes": false }));
    assert_eq!((after_quick(&eq).0.len(), eq.starts_not_run), (1, 1));
    assert!(!eq.replay.coincide);
    assert_eq!(eq.executed_path(), Some("equilibria"));
    // With the default fallback counts (6 and 8 path terms; left out above), the quick plan,
    // which peaks inside the path below the own plan (5.28 against 5.39 measured) and so was
    // neither tracked nor replayed, is then lifted to six path terms and tracked: it
    // coincides with its replay at a lower U_max, and is the plan.
    let lq = paper_with(serde_json::json!({
        "seed": 14, "fallback_path_terms": [6, 8], "equilibrium_slopes": false
    }));
    let kinds: Vec<Attempt> = lq.starts.iter().map(|s| s.attempt).collect();
    assert_eq!(kinds, [Attempt::Quick, Attempt::Own, Attempt::Lifted]);
    assert_eq!(lq.chosen_start, Some(lq.starts[2].start));
    assert!(lq.replay.coincide);
    assert_eq!(lq.executed_path(), Some("optimal"));
    assert!(lq.u_max < eq.u_max, "{} vs {}", lq.u_max, eq.u_max);
    // Only the optimal path as planned counts (`"equilibrium_plans": false`): the second runs.
    let r5 = paper_with(serde_json::json!({
        "seed": 14, "equilibrium_plans": false, "equilibrium_slopes": false
    }));
    let (own5, chosen5) = after_quick(&r5);
    assert_eq!((own5.len(), r5.starts_not_run, chosen5), (2, 0, Some(1)));
    assert_eq!(r5.executed_path(), Some("optimal"));
    let first = own5[0].equilibrium_deviation.expect("measured");
    assert!(first > 0.02, "{first}");
    assert!(own5[1].equilibrium_deviation.expect("measured") <= 0.02);
    assert!(r5.replay.coincide);
    let six = paper_with(serde_json::json!({
        "seed": 15, "starts": 1, "parallel_starts": 1, "equilibrium_plans": false,
        "equilibrium_slopes": false
    }));
    assert_eq!(six.path, r5.path);
    assert_eq!(six.u_max.to_bits(), r5.u_max.to_bits());
}

/// The shipped case stops equilibrium tracking once the samples lie within 80 % of the
/// tolerance from their equilibria (`"equilibrium_stop": 0.8`): its first start's samples do
/// after the sharpness stages (measured 1.46 % of L), so it runs no round. With a stop at a
/// tenth of the tolerance (the 3D default) rounds run, and the plan keeps them: following the
/// slopes of the equilibria, they bring the samples closer (measured two rounds, 0.77 % of
/// L), and the replay coincides more closely, at a peak 0.4 % higher (5.260 against 5.238).
#[test]
fn paper_tracking_stops_once_the_samples_are_within_the_stop() {
    let (p, r) = paper();
    assert_eq!(p.settings.equilibrium_stop, Some(0.8));
    let s = after_quick(r).0[0];
    assert_eq!((s.tracking_rounds, s.tracking_rounds_kept), (0, 0));
    let est = s.equilibrium_deviation.expect("measured");
    assert!(est <= 0.8 * p.settings.coincide_tolerance, "{est}");
    let tenth = paper_with(serde_json::json!({ "equilibrium_stop": 0.1 }));
    let t = after_quick(&tenth).0[0];
    assert!(t.tracking_rounds_kept > 0, "{t:?}");
    let closer = t.equilibrium_deviation.expect("measured");
    assert!(closer < est, "{closer} against {est}");
    assert!(
        tenth.replay.coincide && tenth.replay.max_deviation_over_l < r.replay.max_deviation_over_l,
        "{} against {}",
        tenth.replay.max_deviation_over_l,
        r.replay.max_deviation_over_l
    );
}

/// Where no start's plan coincides with the case's path terms, the shipped case tries six,
/// then eight (`"fallback_path_terms": [6, 8]`). One of the 24 random poses of the README's
/// study: with four terms both starts' plans depart from their replays by 4.8 % of L (their
/// samples lie that far from their equilibria), so the first start with six terms runs, its
/// plan is estimated at 1.4 % and coincides (measured 1.39 %), and it is the plan. Without the
/// fallback the verdict is negative. (Only an optimal path that coincides counts here,
/// `"equilibrium_plans": false`; by default the quick start's plan, which peaks at the goal
/// shape, departs from its replay but its replayed equilibria are a plan, and no other start
/// runs. The scenario is the case's own attempt's, so the lift of the quick plan, which
/// attains the lower bound and departs by 5.1 %, is left out, `"lift": false`; with it, the
/// lift runs once, with six terms, right after the quick attempt, and every start keeps its
/// own index, in the order the starts ran.) The scenario keeps the fixed tracking targets it
/// was built with (`"equilibrium_slopes": false`); with the slopes the first start's four-term
/// plan coincides.
#[test]
fn fallback_path_terms_make_a_moved_pose_coincide() {
    let run = |extra: serde_json::Value| {
        let c = shipped_variant("plan_paper_planar.json", |v| {
            v["plan"]["equilibrium_slopes"] = serde_json::json!(false);
            v["plan"]["start"] = serde_json::json!({ "x": 0.358, "z": 0.745, "theta": 0.33 });
            v["plan"]["goal"] = serde_json::json!({ "x": -0.484, "z": 0.601, "theta": -0.323 });
            for (key, val) in extra.as_object().unwrap() {
                v["plan"][key] = val.clone();
            }
        });
        Planner::from_case(&c).unwrap().run(&mut Silent)
    };
    // By default the quick start's plan peaks at the goal shape and its replayed equilibria
    // are a plan: nothing else runs.
    let by_default = run(serde_json::json!({}));
    assert_eq!(by_default.starts.len(), 1);
    assert_eq!(by_default.starts[0].attempt, Attempt::Quick);
    assert_eq!(by_default.k_at_u_max, 1.0);
    assert_eq!(by_default.executed_path(), Some("equilibria"));
    // With the lift, the quick plan is lifted to six terms right after the quick attempt,
    // and every start that runs has its own index, in the order the starts ran.
    let lifted = run(serde_json::json!({ "equilibrium_plans": false }));
    assert_eq!(lifted.starts[0].attempt, Attempt::Quick);
    assert_eq!(lifted.starts[1].attempt, Attempt::Lifted);
    assert_eq!(lifted.starts[1].path_terms, 6);
    assert!(lifted.starts.windows(2).all(|w| w[0].start < w[1].start));
    assert_eq!(
        lifted
            .starts
            .iter()
            .filter(|s| s.attempt == Attempt::Lifted)
            .count(),
        1
    );
    let r = run(serde_json::json!({ "equilibrium_plans": false, "lift": false }));
    assert_eq!(r.status, PlanStatus::Planned);
    let (later, chosen) = after_quick(&r);
    let terms: Vec<usize> = later.iter().map(|s| s.path_terms).collect();
    assert_eq!(terms, [4, 4, 6]);
    for s in &later[..2] {
        assert!(s.equilibrium_deviation.expect("measured") > 0.02);
    }
    assert_eq!((chosen, r.path_terms, r.path.len()), (Some(2), 6, 6));
    assert!(later[2].equilibrium_deviation.expect("measured") <= 0.02);
    assert!(
        r.replay.coincide && r.replay.max_deviation_over_l <= 0.02,
        "{}",
        r.replay.max_deviation_over_l
    );
    assert!(r.replay.all_converged && r.replay.all_stable);
    assert!(r.replay.start_deviation_over_l < 1e-6 && r.replay.end_deviation_over_l < 1e-6);

    let without = run(serde_json::json!({
        "fallback_path_terms": [], "equilibrium_plans": false, "lift": false
    }));
    assert_eq!(after_quick(&without).0.len(), 2);
    assert!(
        !without.replay.coincide,
        "{}",
        without.replay.max_deviation_over_l
    );
}

/// Each start is verified and refined before the starts compete, so two starts are as good as
/// the better of them: with seeds 16–17, start 16's refined plan peaks at 5.39 and is estimated
/// to depart from its replay (2.48 % of L), while start 17's refined plan peaks at 5.24 and
/// coincides. The pair keeps start 17's (when only an optimal path that coincides counts:
/// by default start 16's replayed equilibria are a plan, and start 17 does not run), with
/// fixed tracking targets (`"equilibrium_slopes": false`; with the slopes start 16's plan
/// coincides).
#[test]
fn paper_two_starts_keep_the_better_verified_plan() {
    let r = paper_with(serde_json::json!({
        "seed": 16, "equilibrium_plans": false, "equilibrium_slopes": false
    }));
    assert_eq!(r.status, PlanStatus::Planned);
    let (own, chosen) = after_quick(&r);
    assert_eq!(own.len(), 2);
    assert!(own.iter().all(|s| s.collision_free));
    assert!(
        own[0].u_max > own[1].u_max + 0.05,
        "{} {}",
        own[0].u_max,
        own[1].u_max
    );
    assert_eq!(chosen, Some(1));
    assert_eq!(r.u_max.to_bits(), own[1].u_max.to_bits());
    assert!(
        r.replay.coincide && r.replay.max_deviation_over_l <= 0.02,
        "{}",
        r.replay.max_deviation_over_l
    );
}

/// With the paper's three path terms the replay follows the plan within 2 % of L up to
/// k = 0.9; in the last swing past the block's corner it departs by up to 2.6 % from most of
/// the local minima the optimiser reaches (the README discusses it): the verdict depends on
/// the minimum, so both bounds are asserted.
#[test]
fn paper_three_terms_depart_only_in_the_last_swing() {
    let r = paper_with(serde_json::json!({ "path_terms": 3, "safety_margin": 0.01 }));
    assert_eq!(r.status, PlanStatus::Planned);
    let away = deviation_up_to(&r, 0.9);
    assert!(away < 0.02, "max deviation for k ≤ 0.9: {away}");
    assert!(
        r.replay.max_deviation_over_l < 0.05,
        "{}",
        r.replay.max_deviation_over_l
    );
}

/// The optimiser minimises the energy at its own samples of `k`; on 21 samples the path's true
/// maximum (on the 201-point verification grid) can fall between them. Refinement adds the
/// peak's `k` to the samples until the true `U_max` is within the 1 % tolerance of the sampled
/// one; without it (tolerance 1e9) the same start keeps a plan whose peak the samples miss by
/// more than that, at a higher true `U_max`. (The scenario keeps the objective and equilibrium
/// tracking the planner had when it was built — no travel term, weight 1000 and three rounds:
/// the default's stronger tracking also closes this start's gap.)
#[test]
fn energy_peaks_between_samples_are_refined() {
    let run = |gap: f64| {
        paper_with(serde_json::json!({
            "k_samples": 21, "starts": 1, "seed": 1, "energy_gap_tolerance": gap,
            "equilibrium_weight": 1000.0, "equilibrium_rounds": 3, "travel_weight": 0
        }))
    };
    let off = run(1e9);
    let on = run(0.01);
    assert_eq!(off.status, PlanStatus::Planned);
    assert_eq!(on.status, PlanStatus::Planned);
    let gap = |r: &dlo_planner::planner::PlanResult| (r.u_max - r.sampled_u_max) / r.u_max;
    assert!(gap(&off) > 0.01, "without refinement: {}", gap(&off));
    assert!(gap(&on) <= 0.01, "with refinement: {}", gap(&on));
    assert!(on.u_max < off.u_max, "{} vs {}", on.u_max, off.u_max);
    // The refined samples include the peak the unrefined plan missed.
    assert!(on.added_samples.len() > off.added_samples.len());
}

/// A clamped strip swung from bent up to bent down, with no obstacle.
fn free_swing_text() -> String {
    plan_text(
        r#"{ "x": 0.3, "z": 0.9, "theta": 0.6 }"#,
        r#"{ "x": -0.25, "z": 0.85, "theta": -0.8 }"#,
        "",
    )
}

fn plan_text(start: &str, goal: &str, obstacles: &str) -> String {
    format!(
        r#"{{
  "name": "t",
  "rod": {{ "length": 1.0, "flexural_rigidity": 1.0, "radius": 0.005 }},
  "constraints": [ {{ "type": "orientation", "s": 0.0, "theta": 0.0 }} ],
  "obstacles": [{obstacles}],
  "plan": {{ "start": {start}, "goal": {goal}, "k_samples": 21 }}
}}"#
    )
}

/// Without obstacles, swinging a clamped strip from bent up to bent down. With the paper's
/// objective (no travel term) the optimiser's plan is the equilibria's own path: the replay by
/// the end pose follows it within 1e-3 L everywhere. With the default travel term the gripper's
/// path is shorter by more than a fifth (0.62 against 0.86 L, at the same peak energy), and its
/// shapes are equilibria only to within the coincidence tolerance (1.3e-2 L). With the defaults
/// the optimiser does not run: the straight-line path peaks at an end shape, which every path
/// passes through, and coincides with its replay, so it is the plan; neither optimised plan's
/// peak is lower (the bound is the larger end energy, to 1e-9), and its gripper path is no
/// longer than theirs (measured: the same 0.62 L as with the travel term).
#[test]
fn free_swing_coincides() {
    let plan = |extra: &str| {
        let text =
            free_swing_text().replace(r#""k_samples": 21"#, &format!(r#""k_samples": 21{extra}"#));
        let c = case::parse(&text, Path::new("free_swing.json")).unwrap();
        let p = Planner::from_case(&c).unwrap();
        let r = p.run(&mut Silent);
        assert_eq!(r.status, PlanStatus::Planned);
        assert!(r.replay.all_converged);
        assert!(r.replay.coincide, "{}", r.replay.max_deviation_over_l);
        (p, r)
    };
    let run = |extra: &str| plan(&format!(r#", "straight_path_first": false{extra}"#)).1;
    let paper = run(r#", "travel_weight": 0"#);
    assert!(
        paper.replay.max_deviation_over_l < 1e-3,
        "{}",
        paper.replay.max_deviation_over_l
    );
    let short = run("");
    let (l0, l1) = (paper.trajectory.path_length, short.trajectory.path_length);
    assert!(
        l1 < 0.8 * l0,
        "gripper travel {l1} with the travel term, {l0} without"
    );
    assert!((short.u_max - paper.u_max).abs() <= 1e-9 * paper.u_max);
    let (p, straight) = plan("");
    assert!(straight.straight_path_plan && straight.optimiser.is_none());
    assert!(straight.starts.is_empty() && straight.chosen_start.is_none());
    assert_eq!(straight.executed_path(), Some("optimal"));
    assert!(straight.path.iter().flatten().all(|&c| c == 0.0));
    let bound = p.start.energy.internal().max(p.goal.energy.internal());
    assert!(
        (straight.u_max - bound).abs() <= 1e-9 * bound,
        "{} vs {bound}",
        straight.u_max
    );
    for optimised in [&paper, &short] {
        assert!(optimised.u_max >= bound * (1.0 - 1e-9));
    }
    let l2 = straight.trajectory.path_length;
    assert!(
        l2 <= l1,
        "gripper travel {l2} along the straight path, {l1} optimised"
    );
}

/// A goal at the start's own pose is planned without moving the end. The straight-line path
/// then holds the start shape at every `k`, and its energies inside the path equal the end
/// shapes' to rounding, so it attains the lower bound on U_max and is the plan. (Before, the
/// last bits of those energies read as a peak inside the path, and the optimiser moved the end
/// away and back: 0.45 L on the paper's case, 0.35 L on a default planar case, 0.24 L and
/// 1.5 rad on the bar case.) On the bar case a goal whose φ is written a turn past the start's,
/// with ψ a turn back (the same frame), is the same plan, not a swing of the cable about the
/// clamp's axis (3.2 L of gripper travel and 7.5 rad of turning before).
#[test]
fn a_goal_at_the_start_pose_is_planned_without_moving() {
    let still = |name: &str, c: &case::Case| {
        let p = Planner::from_case(c).unwrap();
        let r = p.run(&mut Silent);
        assert_eq!(r.status, PlanStatus::Planned, "{name}");
        assert!(r.straight_path_plan && r.optimiser.is_none(), "{name}");
        assert!(r.starts.is_empty(), "{name}");
        assert_eq!(r.executed_path(), Some("optimal"), "{name}");
        let l = p.base.model.rod.length;
        assert!(
            r.trajectory.path_length <= 1e-12 * l,
            "{name}: the end travels {}",
            r.trajectory.path_length
        );
        let bound = p.start.energy.internal().max(p.goal.energy.internal());
        assert!(
            (r.u_max - bound).abs() <= 1e-9 * bound,
            "{name}: {} vs {bound}",
            r.u_max
        );
    };
    still(
        "paper",
        &shipped_variant("plan_paper_planar.json", |v| {
            v["plan"]["goal"] = v["plan"]["start"].clone();
        }),
    );
    let block = r#"{ "shape": { "type": "cuboid", "half_extents": [0.2, 0.5, 0.5] },
                    "position": [0.0, 0.0, 1.3] }"#;
    let pose = r#"{ "x": 0.4, "z": 0.8, "theta": 0.5 }"#;
    let text = plan_text(pose, pose, block).replace(r#", "k_samples": 21"#, "");
    still(
        "planar defaults",
        &case::parse(&text, Path::new("still.json")).unwrap(),
    );
    let tau = std::f64::consts::TAU;
    for turns in [0.0, 1.0, -2.0] {
        still(
            &format!("bar, φ {turns} turns on"),
            &shipped_variant("plan_cable_under_bar.json", |v| {
                let mut g = v["plan"]["start"].clone();
                let (phi, psi) = (g["phi"].as_f64().unwrap(), g["psi"].as_f64().unwrap());
                g["phi"] = (phi + turns * tau).into();
                g["psi"] = (psi - turns * tau).into();
                v["plan"]["goal"] = g;
            }),
        );
    }
}

/// Start and goal share the end pose but are the two mirror-image S-shapes `θ(s)` and
/// `θ(L − s)`, both stable. With the paper's objective alone (no tracking, no travel term) the
/// planner's path turns one into the other through shapes no end pose produces, and the verdict
/// says the end cannot execute it. With tracking (the default; its travel term and its slopes
/// are dropped in the last fallback: the plans with them pass the fork where the straight strip
/// buckles either way, and their replays end in the other S) it finds the route a person would
/// take — pull the end out until the
/// strip is nearly straight, then push it back into the other S — and the replay follows.
#[test]
fn twin_shapes_need_the_end_pulled_straight() {
    let pose = r#"{ "x": 0.45, "z": 0.8, "theta": 0.0 }"#;
    // In the paper's basis, where θ(L − s) has the coefficients below.
    let in_paper_basis = |t: String| {
        t.replace(
            r#""constraints""#,
            r#""discretisation": { "basis": "paper" }, "constraints""#,
        )
    };
    let text = in_paper_basis(plan_text(pose, pose, ""));
    let c = case::parse(&text, Path::new("twin.json")).unwrap();
    let p = Planner::from_case(&c).unwrap();
    // θ(L − s): [a0 + a1, −a1, −b_i, c_i] in the basis 1, t, sin 2πit, cos 2πit.
    let a = &p.start.a;
    let mut twin = a.clone();
    twin[0] = a[0] + a[1];
    twin[1] = -a[1];
    for i in 0..(a.len() - 2) / 2 {
        twin[2 + 2 * i] = -a[2 + 2 * i];
    }
    let goal = format!(
        r#"{{ "shape": {{ "theta": {} }} }}"#,
        serde_json::to_string(&twin).unwrap()
    );
    let run = |extra: &str| {
        let text = in_paper_basis(plan_text(pose, &goal, ""))
            .replace(r#""k_samples": 21"#, &format!(r#""k_samples": 21{extra}"#));
        let c = case::parse(&text, Path::new("twin.json")).unwrap();
        let p = Planner::from_case(&c).unwrap();
        let d_shapes = {
            let m = &p.base.model;
            let (x0, x1) = (m.evaluate(&p.start.a), m.evaluate(&p.goal.a));
            x0.positions
                .iter()
                .zip(&x1.positions)
                .map(|(u, v)| ((u[0] - v[0]).powi(2) + (u[2] - v[2]).powi(2)).sqrt())
                .fold(0.0, f64::max)
        };
        assert!(d_shapes > 0.1, "the twins differ by {d_shapes}");
        p.run(&mut Silent)
    };
    let untracked = run(r#", "equilibrium_weight": 0, "travel_weight": 0"#);
    assert!(!untracked.replay.coincide);
    // The departure lies in the swing (0.2 ≤ k ≤ 0.8), where the plan's shapes are no end
    // pose's equilibria. Near k = 0.85 the strip is nearly straight, and which S the replay
    // buckles into there is the solver's choice at a pitchfork; the swing's departure is not.
    let swing = untracked
        .replay
        .steps
        .iter()
        .filter(|s| (0.2..=0.8).contains(&s.k))
        .map(|s| s.deviation)
        .fold(0.0, f64::max);
    assert!(swing > untracked.replay.tolerance, "{swing}");
    // By default the travel term argues against pulling the end out: no plan with it is
    // executable, and the last fallback, the paper's objective with tracking's fixed targets,
    // is the plan.
    let tracked = run("");
    assert_eq!(
        tracked.starts[tracked.chosen_start.unwrap()].travel_weight,
        0.0
    );
    assert!(tracked.starts.iter().any(|s| s.travel_weight > 0.0));
    assert!(
        tracked.replay.coincide,
        "{}",
        tracked.replay.max_deviation_over_l
    );
    assert!(tracked.replay.all_stable);
    // Nearly straight on the way: the smallest energy along the replay is a tiny fraction of
    // the S-shapes' (3.31).
    let u_min = tracked
        .replay
        .steps
        .iter()
        .map(|s| s.u_feasible)
        .fold(f64::INFINITY, f64::min);
    assert!(u_min < 0.01 * tracked.replay.steps[0].u_feasible, "{u_min}");
}

/// Records the replayed shapes' coefficients.
#[derive(Default)]
struct Feasible(Vec<(f64, Vec<f64>)>);

impl dlo_planner::planner::observer::PlanObserver for Feasible {
    fn shape(
        &mut self,
        _model: &dlo_planner::rod::model::Model,
        r: &dlo_planner::planner::observer::ShapeRecord,
    ) {
        if r.kind == dlo_planner::planner::observer::PathKind::Feasible {
            self.0.push((r.k, r.a.to_vec()));
        }
    }
}

/// A clamped strip buckled into an arch (end at 0.8 L, θ(L) = 0), planned to a shape with the
/// end turned by 0.8 rad. Driven by the end pose alone, the replay stays on a branch of
/// equilibria the plan leaves, until that branch ends and the strip snaps onto the plan's. The
/// snap survives every bisection of its step: the replay reports it and the verdict is
/// negative. Each snap is a real one: between two replayed equilibria (both converged and
/// stable) at most 1/640 apart in k the shape jumps by more than 0.02 L and the energy drops —
/// the strip releases energy — while the plan's own energy hardly changes. The scenario keeps
/// the objective and equilibrium tracking it was built with (no travel term, weight 1000, the
/// one round the planner ran on it then, and fixed targets: `"equilibrium_slopes": false`).
/// With the default tracking the plan differs, and its replay snaps elsewhere (the CLI's test
/// of exit code 5 plans it so); with no tracking, or with a round undone, the plan's energy
/// changes by 2.0 % at the first snap.
#[test]
fn replay_reports_snap_through() {
    let arch = |sign: f64| format!("[0, 0, {}, 0, 0, 0, 0, 0, 0, 0]", 1.2 * sign);
    let text = plan_text(
        &format!(
            r#"{{ "x": 0.0, "z": 0.8, "theta": 0.0, "shape": {{ "theta": {} }} }}"#,
            arch(1.0)
        ),
        &format!(
            r#"{{ "x": 0.0, "z": 0.8, "theta": 0.8, "shape": {{ "theta": {} }} }}"#,
            arch(-1.0)
        ),
        "",
    )
    .replace(
        r#""k_samples": 21"#,
        r#""k_samples": 21, "equilibrium_weight": 1000.0, "equilibrium_rounds": 1, "equilibrium_slopes": false, "fallback_path_terms": [], "travel_weight": 0"#,
    );
    let c = case::parse(&text, Path::new("snap.json")).unwrap();
    let p = Planner::from_case(&c).unwrap();
    let mut rec = Feasible::default();
    let r = p.run(&mut rec);
    assert_eq!(r.status, PlanStatus::Planned);
    assert!(!r.replay.snaps.is_empty());
    assert!(!r.replay.coincide);
    let model = &p.base.model;
    let finest =
        1.0 / (p.settings.replay_steps as f64 * 2f64.powi(p.settings.replay_refinements as i32));
    for &k in &r.replay.snaps {
        let i = r.replay.steps.iter().position(|s| s.k == k).unwrap();
        let (before, after) = (&r.replay.steps[i - 1], &r.replay.steps[i]);
        assert!(
            k - before.k <= finest * (1.0 + 1e-9),
            "snap at {k}: step {}",
            k - before.k
        );
        for s in [before, after] {
            assert!(s.converged && s.stable == Some(true), "k = {}", s.k);
        }
        let released = (before.u_feasible - after.u_feasible) / before.u_feasible;
        assert!(
            released > 0.1,
            "snap at {k}: energy {} -> {}",
            before.u_feasible,
            after.u_feasible
        );
        let plan_change = (before.u_optimal - after.u_optimal).abs() / before.u_optimal;
        assert!(
            plan_change < 0.02,
            "snap at {k}: the plan's energy changes by {plan_change}"
        );
        let shape_at = |kk: f64| {
            let a = &rec.0.iter().find(|(q, _)| *q == kk).unwrap().1;
            model.evaluate(a).positions
        };
        let jump = shape_at(before.k)
            .iter()
            .zip(shape_at(k))
            .map(|(u, v)| ((u[0] - v[0]).powi(2) + (u[2] - v[2]).powi(2)).sqrt())
            .fold(0.0, f64::max);
        assert!(jump > 0.02, "snap at {k}: the shape moves {jump} L");
    }
}

/// Self-contact along a plan: on the straight-line path of `common::spiral_case` the tip passes
/// through the coil (the verification grid finds the strip crossing itself); the plan, with
/// the self-contact rows at its samples, keeps every pair of chords 2r apart on the
/// verification grid, which it never saw. (Here the plan uncurls the strip on the way, so the
/// rows need not push: planned without them it stays clear too.)
#[test]
fn plan_keeps_the_rod_from_crossing_itself() {
    use dlo_planner::planner::verify::verify_with;
    let p = Planner::from_case(&common::spiral_case(true)).unwrap();
    let path = p.path();
    let fine = fine_model(&p.base.model, 256, 4);
    let gap = |path: &DeformationPath, z: &[f64]| {
        let v = verify_with(&fine, path, z, 201, &[], p.base.objective, true);
        v.self_contact.unwrap().0
    };
    let straight = gap(&path, &vec![0.0; path.n_vars()]);
    assert!(straight < -0.005, "straight-line path: gap {straight}");
    let r = p.run(&mut Silent);
    assert_eq!(r.status, PlanStatus::Planned);
    // The plan's own path (a fallback's when one was chosen).
    let planned = gap(&p.path_of(&r), &r.z);
    assert!(planned >= 0.0, "plan: gap {planned}");
    assert_eq!(
        r.verification.self_contact.map(|(g, _)| g >= 0.0),
        Some(true)
    );
}

/// Relative residual of the planar elastica's equilibrium equation `θ'' = p sin θ + q cos θ`
/// (a weightless, inextensible strip loaded at its ends only: a constant force), least-squares
/// fitted over `p` and `q` on the interior of the shape `a`: near 0 for an equilibrium, near 1
/// for a shape no end force holds.
fn elastica_residual(model: &dlo_planner::rod::model::Model, a: &[f64]) -> f64 {
    let theta = |t: f64| model.layout.angles_at(a, t)[1];
    let h = 1e-4;
    let (mut ss, mut sc, mut cc, mut sy, mut cy, mut yy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let pts: Vec<(f64, f64, f64)> = (1..100)
        .map(|i| {
            let t = i as f64 / 100.0;
            let d2 = (theta(t + h) - 2.0 * theta(t) + theta(t - h)) / (h * h);
            (theta(t).sin(), theta(t).cos(), d2)
        })
        .collect();
    for &(s, c, y) in &pts {
        (ss, sc, cc) = (ss + s * s, sc + s * c, cc + c * c);
        (sy, cy, yy) = (sy + s * y, cy + c * y, yy + y * y);
    }
    let det = ss * cc - sc * sc;
    let (p, q) = ((sy * cc - cy * sc) / det, (cy * ss - sy * sc) / det);
    let res: f64 = pts
        .iter()
        .map(|&(s, c, y)| (y - p * s - q * c).powi(2))
        .sum();
    (res / yy).sqrt()
}

/// A start shape that its end pose does not hold: the spiral of `common::spiral_case` (no end
/// force holds it: the elastica's equation leaves most of its curvature unexplained) is left by
/// the replay at k = 0, which no path changes, so the planner stops after its first attempt
/// instead of running its fallbacks, and the verdict says why.
#[test]
fn a_start_shape_its_pose_does_not_hold_ends_the_attempts() {
    let p = Planner::from_case(&common::spiral_case(true)).unwrap();
    let residual = elastica_residual(&p.base.model, &p.start.a);
    assert!(residual > 0.5, "elastica residual of the start {residual}");
    let r = p.run(&mut Silent);
    assert!(!r.replay.start_held());
    assert!(r.replay.start_deviation_over_l > r.replay.tolerance);
    // The first plan replayed ends the search: the quick start's where it attains the lower
    // bound on U_max (as it does here), else the case's own; no fallback runs.
    let attempts: Vec<Attempt> = r.starts.iter().map(|s| s.attempt).collect();
    assert!(
        attempts == [Attempt::Quick] || attempts == [Attempt::Quick, Attempt::Own],
        "attempts: {:?}",
        r.starts
    );
    assert!(
        r.equilibrium_plan
            .as_ref()
            .is_none_or(|e| e.trajectory != "straight_path")
    );
    // The paper's start, solved from its pose, is an equilibrium (the residual is that of the
    // Ritz approximation: small in the Legendre basis) and the replay stays on it.
    let legendre = shipped_variant("plan_paper_planar.json", |v| {
        v["discretisation"]["basis"] = serde_json::json!("legendre");
    });
    let pl = Planner::from_case(&legendre).unwrap();
    let held = elastica_residual(&pl.base.model, &pl.start.a);
    eprintln!("elastica residuals: spiral {residual}, paper's start {held}");
    assert!(held < 0.05, "elastica residual of the paper's start {held}");
    assert!(paper().1.replay.start_held());
}

/// Bad planning inputs are errors that name the field.
#[test]
fn bad_planning_inputs_name_the_field() {
    // A swing between two poses with one more `plan` field.
    let swing_with = |field: &str| {
        plan_text(
            r#"{ "x": 0.3, "z": 0.9 }"#,
            r#"{ "x": -0.3, "z": 0.9 }"#,
            "",
        )
        .replace(
            r#""k_samples": 21"#,
            &format!(r#""k_samples": 21, {field}"#),
        )
    };
    let cases = [
        (swing_with(r#""path_terms": 0"#), "plan.path_terms"),
        (
            swing_with(r#""starts": 2, "parallel_starts": 3"#),
            "plan.parallel_starts",
        ),
        (
            swing_with(r#""parallel_starts": 0"#),
            "plan.parallel_starts",
        ),
        (
            plan_text(r#"{ "x": 0.3, "z": 0.9 }"#, r#"{ "x": 1.5, "z": 0.9 }"#, ""),
            "plan.goal",
        ),
        (
            plan_text(
                r#"{ "x": 0.3, "z": 0.9 }"#,
                r#"{ "x": 0.0, "z": 0.95 }"#,
                r#"{ "shape": { "type": "ball", "radius": 0.2 }, "position": [0.0, 0.0, 0.9] }"#,
            ),
            "plan.goal",
        ),
        (
            plan_text(r#"{ }"#, r#"{ "x": 0.3, "z": 0.9 }"#, ""),
            "plan.start",
        ),
        (
            plan_text(
                r#"{ "x": 0.3, "y": 0.1, "z": 0.9 }"#,
                r#"{ "x": 0.3, "z": 0.9 }"#,
                "",
            ),
            "plan.start.y",
        ),
        (
            plan_text(r#"{ "x": 0.3, "z": 0.9 }"#, r#"{ "x": 0.3, "z": 0.9 }"#, "")
                .replace(r#""k_samples": 21"#, r#""k_samples": 21, "bogus": 1"#),
            "plan",
        ),
        (
            swing_with(r#""energy_gap_tolerance": -0.1"#),
            "plan.energy_gap_tolerance",
        ),
        (
            swing_with(r#""equilibrium_stop": 1.5"#),
            "plan.equilibrium_stop",
        ),
    ];
    for (text, field) in cases {
        let c = case::parse(&text, Path::new("bad.json")).unwrap();
        let Err(e) = Planner::from_case(&c) else {
            panic!("{field}: must be rejected")
        };
        let msg = e.to_string();
        assert!(
            msg.contains(&format!("field `{field}")) && msg.contains("bad.json"),
            "{field}: {msg}"
        );
    }
    let no_plan = r#"{ "rod": { "length": 1.0, "flexural_rigidity": 1.0 } }"#;
    let c = case::parse(no_plan, Path::new("bad.json")).unwrap();
    assert!(
        Planner::from_case(&c)
            .err()
            .unwrap()
            .to_string()
            .contains("field `plan`")
    );
}

/// Several starts run in parallel; every start is reported with its verified plan, the chosen
/// plan is the collision-free one with the lowest verified U_max, and the run is reproducible.
#[test]
fn multi_start_reports_every_start_keeps_the_best_and_reproduces() {
    let text = free_swing_text().replace(
        r#""k_samples": 21"#,
        r#""k_samples": 21, "starts": 3, "seed": 7, "travel_weight": 0, "straight_path_first": false"#,
    );
    let c = case::parse(&text, Path::new("multi.json")).unwrap();
    let p = Planner::from_case(&c).unwrap();
    let r = p.run(&mut Silent);
    assert_eq!(r.starts.len(), 3);
    let best = r
        .starts
        .iter()
        .filter(|s| s.violation <= 1e-6 && s.collision_free)
        .map(|s| s.u_max)
        .fold(f64::INFINITY, f64::min);
    let chosen = &r.starts[r.chosen_start.unwrap()];
    assert!(best.is_finite());
    assert!(chosen.violation <= 1e-6 && chosen.collision_free);
    assert_eq!(chosen.u_max, best);
    assert_eq!(r.u_max.to_bits(), chosen.u_max.to_bits());
    // Reproducible: the three starts run on parallel threads, and a second run gives the same
    // plan bit for bit; a single start with the same seed is the first of them.
    let again = p.run(&mut Silent);
    assert_eq!(again.z, r.z);
    assert_eq!(again.u_max.to_bits(), r.u_max.to_bits());
    for (a, b) in again.starts.iter().zip(&r.starts) {
        assert_eq!(a.sampled_u_max.to_bits(), b.sampled_u_max.to_bits());
        assert_eq!(a.evaluations, b.evaluations);
    }
    let single = Planner::from_case(
        &case::parse(
            &text.replace(r#""starts": 3"#, r#""starts": 1"#),
            Path::new("single.json"),
        )
        .unwrap(),
    )
    .unwrap()
    .run(&mut Silent);
    assert_eq!(
        single.starts[0].sampled_u_max.to_bits(),
        r.starts[0].sampled_u_max.to_bits()
    );
    assert_eq!(single.starts[0].evaluations, r.starts[0].evaluations);
}

/// Records when the optimiser's progress and the phases arrive.
#[derive(Default)]
struct Timeline {
    phases: Vec<(String, std::time::Instant)>,
    progress: Vec<(usize, std::time::Instant)>,
}

impl dlo_planner::planner::observer::PlanObserver for Timeline {
    fn phase(&mut self, name: &str) {
        self.phases
            .push((name.to_string(), std::time::Instant::now()));
    }
    fn progress(
        &mut self,
        _model: &dlo_planner::rod::model::Model,
        p: &dlo_planner::planner::observer::Progress,
        _worst: &[f64],
    ) {
        self.progress.push((p.start, std::time::Instant::now()));
    }
}

/// Progress is live: with starts on parallel threads, the observer hears of each outer
/// iteration while the starts run, not when they have all finished. On the paper's case (three
/// starts side by side, 21 samples of k) the first report arrives within the first half of the
/// optimisation (it follows the first of some sixty outer iterations of its start), and every
/// start reports. (A free swing without obstacles, which this test used before, spends most of
/// a start in its first outer iteration: there the first report came after about half of a
/// start, and once the planner took 8 ms for it, thread start-up alone made that more than
/// half of the run.)
#[test]
fn multi_start_progress_arrives_while_the_starts_run() {
    let c = shipped_variant("plan_paper_planar.json", |v| {
        v["plan"]["starts"] = serde_json::json!(3);
        v["plan"]["parallel_starts"] = serde_json::json!(3);
        v["plan"]["k_samples"] = serde_json::json!(21);
        v["plan"]["fallback_path_terms"] = serde_json::json!([]);
    });
    let p = Planner::from_case(&c).unwrap();
    let mut t = Timeline::default();
    p.run(&mut t);
    let at = |name: &str| t.phases.iter().find(|(n, _)| n == name).unwrap().1;
    let (begin, end) = (at("optimise"), at("select"));
    let first = t.progress.first().unwrap().1;
    let whole = (end - begin).as_secs_f64();
    let waited = (first - begin).as_secs_f64();
    assert!(
        waited < 0.5 * whole,
        "first report after {waited} s of {whole} s"
    );
    for s in 0..3 {
        assert!(
            t.progress.iter().any(|(i, _)| *i == s),
            "start {s} reported nothing"
        );
    }
}

/// A shipped case's planner and its plan.
fn planned(name: &str) -> (Planner, dlo_planner::planner::PlanResult) {
    let c = case::load(&Path::new("planning_cases").join(name)).unwrap();
    let p = Planner::from_case(&c).unwrap();
    let r = p.run(&mut Silent);
    (p, r)
}

/// The bar case, planned once for the tests that look at it.
fn bar() -> &'static (Planner, dlo_planner::planner::PlanResult) {
    static R: OnceLock<(Planner, dlo_planner::planner::PlanResult)> = OnceLock::new();
    R.get_or_init(|| planned("plan_cable_under_bar.json"))
}

/// Asserts what every shipped 3D case's plan must show: planned, collision-free on the
/// verification grid, every replayed shape converged and stable with no neutral mode, and the
/// replay within the 2 % tolerance of the plan; with `straight_below`, the straight-line path
/// penetrates the obstacle by more than that (units of L).
fn assert_3d_plan_coincides(
    name: &str,
    r: &dlo_planner::planner::PlanResult,
    straight_below: Option<f64>,
) {
    assert_eq!(r.status, PlanStatus::Planned, "{name}");
    assert!(
        r.min_clearance.unwrap() >= 0.0,
        "{name}: {:?}",
        r.min_clearance
    );
    assert!(r.replay.all_converged && r.replay.all_stable, "{name}");
    // Decided stability: no replayed shape has a neutral mode.
    assert!(
        r.replay.steps.iter().all(|st| st.neutral_modes == Some(0)),
        "{name}"
    );
    assert!(
        r.replay.max_deviation_over_l <= 0.02,
        "{name}: {}",
        r.replay.max_deviation_over_l
    );
    assert!(r.replay.coincide, "{name}");
    if let Some(depth) = straight_below {
        let straight = r.min_clearance_straight.unwrap();
        assert!(
            straight < -depth,
            "{name}: straight path clearance {straight}"
        );
    }
}

/// Every path between two shapes peaks at least at the larger of their energies; a plan that
/// peaks there (within 1e-6 relative, on the verification grid) is a minimax path.
fn assert_peaks_at_the_ends(name: &str, p: &Planner, r: &dlo_planner::planner::PlanResult) {
    let ends = p.start.energy.potential().max(p.goal.energy.potential());
    assert!(
        (r.u_max - ends).abs() <= 1e-6 * ends,
        "{name}: U_max {} vs ends {ends}",
        r.u_max
    );
}

/// A 3D case with torsion and a triangle-mesh obstacle; the block decides the route but not
/// the maximum, which the goal shape holds.
#[test]
fn mesh_case_3d_coincides() {
    let name = "plan_cable_past_mesh.json";
    let (p, r) = planned(name);
    assert_3d_plan_coincides(name, &r, None);
    assert_peaks_at_the_ends(name, &p, &r);
}

/// A cable swung under a bar its straight-line path runs through: the bar, not the end shapes,
/// sets the plan's U_max (more than 1.5 times the end energies, at an interior k).
#[test]
fn bar_case_3d_coincides() {
    let (p, r) = bar();
    assert_3d_plan_coincides("plan_cable_under_bar.json", r, Some(0.05));
    let ends = p.start.energy.potential().max(p.goal.energy.potential());
    assert!(r.u_max > 1.5 * ends, "U_max {} vs ends {ends}", r.u_max);
    assert!(r.k_at_u_max > 0.1 && r.k_at_u_max < 0.9, "{}", r.k_at_u_max);
    // The sharpness stages already leave every sampled shape within a tenth of the tolerance
    // of its equilibrium, so no tracking round runs; the replay confirms that estimate.
    assert_eq!(r.starts[r.chosen_start.unwrap()].tracking_rounds, 0);
    let tenth = 0.1 * r.replay.tolerance;
    assert!(
        r.replay.max_deviation_over_l < tenth,
        "{} vs {tenth}",
        r.replay.max_deviation_over_l
    );
    // The clamp is the base frame, θ(0) = 0 and φ(0) + ψ(0) = 0: the planner eliminates the
    // second row as a linear condition on the path terms, so it holds at every k.
    let path = p.path();
    let model = &p.base.model;
    let offset = |f| model.layout.offset(f).unwrap();
    let (op, os) = (
        offset(dlo_planner::rod::layout::Field::Phi),
        offset(dlo_planner::rod::layout::Field::Psi),
    );
    let nb = model.layout.nb();
    let mut a = vec![0.0; path.n()];
    for i in 0..=20 {
        let k = i as f64 / 20.0;
        path.shape_at(&r.z, k, &mut a);
        let at0 = |o: usize| model.layout.basis.eval(&a[o..o + nb], 0.0);
        assert!((at0(op) + at0(os)).abs() < 1e-9, "k = {k}");
    }
}

/// `equilibrium_stop: 0` turns off the stop at a tenth of the tolerance: the bar case then
/// runs tracking rounds until they stop helping, and its replay follows the plan more closely
/// than the default plan's, which runs none.
#[test]
fn bar_case_tracks_when_asked() {
    let name = "plan_cable_under_bar.json";
    let c = shipped_variant(name, |v| v["plan"]["equilibrium_stop"] = 0.0.into());
    let r = Planner::from_case(&c).unwrap().run(&mut Silent);
    assert_3d_plan_coincides(name, &r, Some(0.05));
    assert!(r.starts[0].tracking_rounds >= 1);
    let default = &bar().1;
    assert!(
        r.replay.max_deviation_over_l < default.replay.max_deviation_over_l,
        "{} vs {}",
        r.replay.max_deviation_over_l,
        default.replay.max_deviation_over_l
    );
}

/// A cable routed around a pillar its straight-line path runs through (by more than 0.1 L).
#[test]
fn pillar_case_3d_coincides() {
    let name = "plan_cable_around_pillar.json";
    let (p, r) = planned(name);
    assert_3d_plan_coincides(name, &r, Some(0.1));
    assert_peaks_at_the_ends(name, &p, &r);
    // The swept rows leave no crossing for refinement to chase.
    assert!(r.added_samples.is_empty(), "{:?}", r.added_samples);
    // Tracking stops before its budget: after one round the samples lie within the stop (a
    // tenth of the coincidence tolerance) of their equilibria (measured 9.5e-4 L), so a budget
    // of one round gives the same plan bit for bit.
    assert_eq!(r.starts[0].tracking_rounds, 1);
    assert_eq!(r.starts[0].tracking_rounds_kept, 1);
    let est = r.starts[0].equilibrium_deviation.expect("measured");
    assert!(
        est <= p.settings.tracking_stop(true) * p.settings.coincide_tolerance,
        "{est}"
    );
    let c = shipped_variant(name, |v| v["plan"]["equilibrium_rounds"] = 1.into());
    let one = Planner::from_case(&c).unwrap().run(&mut Silent);
    assert_eq!(one.z, r.z);
    assert_eq!(
        one.replay.max_deviation_over_l,
        r.replay.max_deviation_over_l
    );
}

/// Without the swept-clearance rows, and with the paper's objective (no travel term, which
/// keeps this route from crossing), the pillar case's optimiser moves the cable through the
/// pillar between two samples. The verification finds the crossing between its own grid
/// values (where the chord bound is negative it bisects), sample refinement adds the k it
/// finds, and the refined plan clears the pillar (measured +6.1e-3 after 15 added samples, six
/// of them between the verification's grid values) and coincides with its replay. (When
/// the verification looked only at its 201 grid values, each round moved the crossing into
/// another gap and the plan ended in a collision.)
#[test]
fn pillar_case_tunnels_without_swept_clearance() {
    let c = shipped_variant("plan_cable_around_pillar.json", |v| {
        v["plan"]["swept_clearance"] = serde_json::json!(false);
        v["plan"]["travel_weight"] = serde_json::json!(0);
    });
    let r = Planner::from_case(&c).unwrap().run(&mut Silent);
    assert_eq!(r.status, PlanStatus::Planned);
    assert!(r.min_clearance.unwrap() >= 0.0, "{:?}", r.min_clearance);
    assert!(r.replay.coincide);
    let off_grid = r
        .added_samples
        .iter()
        .filter(|k| ((*k * 200.0).round() - *k * 200.0).abs() > 1e-9)
        .count();
    assert!(off_grid > 0, "{:?}", r.added_samples);
    assert!(!r.added_samples.is_empty());
}

/// The bar case with its clamp given either as the base frame (θ(0) = 0, φ(0) + ψ(0) = 0, as
/// shipped) or as separate rows φ(0) = ψ(0) = 0 with θ(0) = 0; the goal solve starts from
/// φ ≡ π, ψ ≡ −π (the start shape's mirror image) either way. (The shipped case solves its goal
/// from a shape bent towards the goal frame instead; under the separate rows, started with φ
/// running from 0 to π, it finds another equilibrium at U = 0.352, where φ turns near the base.)
fn bar_case(phi_plus_psi: bool) -> case::Case {
    shipped_variant("plan_cable_under_bar.json", |v| {
        let pi = std::f64::consts::PI;
        v["plan"]["goal"]["shape"] = serde_json::json!({
            "phi": [pi, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            "psi": [-pi, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        });
        v["constraints"][0] = if phi_plus_psi {
            serde_json::json!({"type": "orientation", "s": 0.0, "theta": 0.0, "phi_plus_psi": 0.0})
        } else {
            serde_json::json!({"type": "orientation", "s": 0.0, "phi": 0.0, "theta": 0.0, "psi": 0.0})
        };
    })
}

/// Start and goal of the bar case are mirror images (x → −x), so their equilibria hold the same
/// energy — when the clamp fixes only what it physically fixes. Where θ(0) = 0 the frame at
/// the base is `Rz(φ + ψ)`; prescribing φ(0) = 0 and ψ(0) = 0 separately also fixes φ(0), the
/// direction in which the rod starts to bend, to the x–z plane, and the mirror shape, which
/// bends the other way (φ = π), pays for turning φ near the base.
#[test]
fn clamp_by_phi_plus_psi_gives_mirror_images_equal_energy() {
    let separate = Planner::from_case(&bar_case(false)).unwrap();
    let (s0, g0) = (
        separate.start.energy.potential(),
        separate.goal.energy.potential(),
    );
    // Separate φ(0), ψ(0) rows: the mirror goal costs more than five times the start (measured
    // 2.461 against 0.3256).
    assert!(g0 > 5.0 * s0, "start {s0}, goal {g0}");

    let frame = Planner::from_case(&bar_case(true)).unwrap();
    let (s1, g1) = (
        frame.start.energy.potential(),
        frame.goal.energy.potential(),
    );
    assert!((s1 - g1).abs() <= 1e-6 * s1, "start {s1}, goal {g1}");
    // One condition fewer: the start's minimum can only fall.
    assert!(s1 <= s0 * (1.0 + 1e-9), "{s1} vs {s0}");
}

/// The bar case's plan against a hand-made family that bends the cable further on the way, the
/// way a person would take it under the bar: `a(k) = (1−k)a0 + k a1 + 4k(1−k)·b(β, γ)` with
/// `b` adding `θ = β s/L + γ sin(2πs/L)` at `k = 1/2` (θ(0) and φ(0) + ψ(0) stay 0), 697
/// members. Among those that keep the case's safety margin (clearance ≥ 0.01 L on 51 × 257
/// points, a coarser k grid than the plan's verification, which favours the hand-made paths: 485
/// members keep it) the best peaks at 0.749, above the plan's 0.730. Members that merely clear the bar reach 0.690:
/// the margin, kept along the chords between samples, costs the plan that much.
#[test]
fn bar_plan_beats_hand_made_paths_with_its_margin() {
    let (p, r) = bar();
    let fine = fine_model(&p.base.model, 256, 4);
    let n = p.start.a.len();
    let path = DeformationPath::new(p.start.a.clone(), p.goal.a.clone(), 1, &[]);
    let margin = p.safety() * p.base.model.rod.length;
    let mut best = f64::INFINITY;
    let mut kept = 0;
    for i in 0..=40 {
        for j in 0..=16 {
            let beta = 0.05 * i as f64;
            let gamma = -0.8 + 0.1 * j as f64;
            let mut b = vec![0.0; n];
            b[1] = beta;
            b[2] = gamma;
            let z: Vec<f64> = b.iter().map(|v| 4.0 * v).collect();
            let v = verify(&fine, &path, &z, 51, &p.obstacles, p.base.objective);
            if v.min_clearance.unwrap() >= margin {
                kept += 1;
                best = best.min(v.u_max);
            }
        }
    }
    assert!(kept > 0, "no hand-made path keeps the margin");
    assert!(
        r.u_max < best,
        "plan U_max {} vs best hand-made {best}",
        r.u_max
    );
}

/// The gripper trajectory is the plan's own end pose: at every replay step, its position equals
/// the plan's shape's `x(L)` as the replay's end-position rows prescribe it (the model's
/// quadrature, evaluated afresh from the path at that step's k) to 1e-12 L, and to 1e-10 L the
/// same point integrated by another quadrature (8-point Gauss on the last panel: the two
/// quadratures differ by up to 1.0e-12 L on the bar case); its rotation matrix equals
/// `A(φ, θ, ψ)` at `s = L` and its quaternion turns into the same matrix (1e-12); the quaternion
/// never flips hemisphere between steps; the held end sits at the base, and the path length is
/// the sum of the steps, at least the straight-line distance.
#[test]
fn trajectory_reproduces_the_plans_end_pose() {
    use dlo_planner::planner::trajectory::rotation_of_quaternion;
    use dlo_planner::rod::kinematics::rotation;
    for (p, r) in [paper(), bar()] {
        let model = &p.base.model;
        let l = model.rod.length;
        let path = p.with_terms(r.path_terms).path();
        let t = &r.trajectory;
        assert_eq!(t.poses.len(), r.replay.steps.len());
        let mut a = vec![0.0; path.n()];
        let mut length = 0.0;
        for (i, (pose, step)) in t.poses.iter().zip(&r.replay.steps).enumerate() {
            assert_eq!(pose.k, step.k);
            path.shape_at(&r.z, pose.k, &mut a);
            let x = model.evaluate(&a).positions[model.boundary(1.0)].map(|v| v * l);
            let x8 = model.position_at(&a, 1.0).map(|v| v * l);
            for c in 0..3 {
                assert!(
                    (pose.position[c] - x[c]).abs() <= 1e-12 * l,
                    "k = {}: {:?} vs {x:?}",
                    pose.k,
                    pose.position
                );
                assert!((pose.position[c] - x8[c]).abs() <= 1e-10 * l);
            }
            let [f, th, ps] = model.angles_at(&a, 1.0);
            let m = rotation(f, th, ps);
            let mq = rotation_of_quaternion(pose.quaternion);
            for row in 0..3 {
                for col in 0..3 {
                    assert!((pose.rotation[row][col] - m[row][col]).abs() <= 1e-12);
                    assert!((mq[row][col] - m[row][col]).abs() <= 1e-12);
                }
            }
            if i > 0 {
                let prev = &t.poses[i - 1];
                let dot: f64 = prev
                    .quaternion
                    .iter()
                    .zip(&pose.quaternion)
                    .map(|(x, y)| x * y)
                    .sum();
                assert!(dot >= 0.0, "quaternion flips at k = {}", pose.k);
                length += (0..3)
                    .map(|c| (pose.position[c] - prev.position[c]).powi(2))
                    .sum::<f64>()
                    .sqrt();
            }
        }
        assert!((t.path_length - length).abs() <= 1e-12 * l);
        assert!(t.path_length >= t.straight_distance);
        let base = model.base.map(|v| v * l);
        for (c, b) in base.iter().enumerate() {
            assert!((t.held.position[c] - b).abs() <= 1e-12 * l);
        }
    }
}

/// The bar case's goal, the shipped Euler angles (φ = π, θ = 0.4, ψ = −π − 0.5), spelled three
/// other ways: as a unit quaternion, as the other Euler branch (0, −0.4, −0.5), and as its
/// tangent with a twist of −0.5 about it; the paper's case with its start and goal as
/// quaternions about y and as tangents. Each spelling gives the shipped plan: the same status
/// and verdict, U_max within 5e-5 relative and the gripper trajectory within 2e-3 L at every
/// step. They are the same plan up to where the path optimiser stops: the spellings' angles
/// differ in the last bits (the quaternion and the other branch gave the shipped plan bit for
/// bit; the tangent 3.1e-6 in U_max and 1.0e-5 L in the trajectory; the planar spellings
/// 8.8e-6 and 8.3e-4 L, with path vectors up to 0.63 apart: the minimax objective leaves the
/// path's interior nearly free). Bad orientations name the field.
#[test]
fn equivalent_pose_spellings_give_the_same_plan() {
    use dlo_planner::planner::trajectory::quaternion_of;
    use dlo_planner::rod::kinematics::rotation;
    let same =
        |name: &str, a: &dlo_planner::planner::PlanResult, b: &dlo_planner::planner::PlanResult| {
            assert_eq!(a.status, b.status, "{name}");
            assert_eq!(a.replay.coincide, b.replay.coincide, "{name}");
            let du = (a.u_max - b.u_max).abs() / a.u_max;
            assert!(du <= 5e-5, "{name}: U_max {} vs {}", a.u_max, b.u_max);
            assert_eq!(a.trajectory.poses.len(), b.trajectory.poses.len(), "{name}");
            for (p, q) in a.trajectory.poses.iter().zip(&b.trajectory.poses) {
                let d = (0..3)
                    .map(|c| (p.position[c] - q.position[c]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                assert!(d <= 2e-3, "{name}: gripper {d} apart at k = {}", p.k);
            }
        };
    let with_goal = |f: &dyn Fn(&mut serde_json::Value)| {
        let c = shipped_variant("plan_cable_under_bar.json", |v| {
            let g = v["plan"]["goal"].as_object_mut().unwrap();
            for k in ["phi", "theta", "psi"] {
                g.remove(k);
            }
            f(&mut v["plan"]["goal"]);
        });
        Planner::from_case(&c).unwrap().run(&mut Silent)
    };
    let pi = std::f64::consts::PI;
    let m = rotation(pi, 0.4, -pi - 0.5);
    let q = quaternion_of(m);
    let shipped = &bar().1;
    same(
        "quaternion",
        shipped,
        &with_goal(&|g| g["quaternion"] = serde_json::json!(q)),
    );
    same(
        "other branch",
        shipped,
        &with_goal(&|g| {
            g["phi"] = 0.0.into();
            g["theta"] = (-0.4).into();
            g["psi"] = (-0.5).into();
        }),
    );
    same(
        "tangent",
        shipped,
        &with_goal(&|g| {
            g["tangent"] = serde_json::json!([m[0][2], m[1][2], m[2][2]]);
            g["twist"] = (-0.5).into();
        }),
    );
    // Planar: quaternions about y and tangents in the x–z plane.
    let paper_as = |f: &dyn Fn(f64) -> serde_json::Value| {
        let c = shipped_variant("plan_paper_planar.json", |v| {
            for (end, theta) in [("start", 0.5), ("goal", -0.5)] {
                v["plan"][end].as_object_mut().unwrap().remove("theta");
                let extra = f(theta);
                for (k, val) in extra.as_object().unwrap() {
                    v["plan"][end][k] = val.clone();
                }
            }
        });
        Planner::from_case(&c).unwrap().run(&mut Silent)
    };
    let shipped = &paper().1;
    same(
        "planar quaternion",
        shipped,
        &paper_as(
            &|t: f64| serde_json::json!({"quaternion": [(0.5 * t).cos(), 0.0, (0.5 * t).sin(), 0.0]}),
        ),
    );
    same(
        "planar tangent",
        shipped,
        &paper_as(&|t: f64| serde_json::json!({"tangent": [t.sin(), 0.0, t.cos()]})),
    );
    // Bad orientations: the field is named.
    for (goal, field, words) in [
        (
            serde_json::json!({"quaternion": [1.0, 0.0, 0.1, 0.0]}),
            "plan.goal.quaternion",
            "unit quaternion",
        ),
        (
            serde_json::json!({"quaternion": [1.0, 0.0, 0.0, 0.0], "theta": 0.1}),
            "plan.goal",
            "one orientation",
        ),
        (
            serde_json::json!({"twist": 0.3}),
            "plan.goal.twist",
            "tangent",
        ),
        (
            serde_json::json!({"tangent": [0.0, 0.0, 0.0]}),
            "plan.goal.tangent",
            "non-zero",
        ),
    ] {
        let c = shipped_variant("plan_cable_under_bar.json", |v| {
            let g = v["plan"]["goal"].as_object_mut().unwrap();
            for k in ["phi", "theta", "psi"] {
                g.remove(k);
            }
            for (k, val) in goal.as_object().unwrap() {
                g.insert(k.clone(), val.clone());
            }
        });
        let e = Planner::from_case(&c).unwrap_err().to_string();
        assert!(e.contains(field) && e.contains(words), "{e}");
    }
    // A planar rod's end turned about x.
    let c = shipped_variant("plan_paper_planar.json", |v| {
        v["plan"]["goal"].as_object_mut().unwrap().remove("theta");
        let h = std::f64::consts::FRAC_1_SQRT_2;
        v["plan"]["goal"]["quaternion"] = serde_json::json!([h, h, 0.0, 0.0]);
    });
    let e = Planner::from_case(&c).unwrap_err().to_string();
    assert!(e.contains("plan.goal") && e.contains("about y only"), "{e}");
}

/// A 3D problem written as a user would, with no starting shapes and poses as positions and
/// tangents: a cable clamped along z swung from one side (end at x = +0.3, tangent tilted
/// towards +x) to its mirror image past a ball beside the swing. Both end shapes are solved from
/// the pose alone (bent from the clamp's frame towards the end frame), they are mirror images
/// (equal energy to 1e-9 relative), and the plan is collision-free and coincides with its
/// replay. (Started from the straight rod instead, the goal solve reached another equilibrium,
/// U = 3.61 against the start's 0.966, and the replay departed by 11 % of L.)
#[test]
fn a_3d_cable_plans_from_its_poses_alone() {
    let text = r#"{ "name": "tangent_poses", "planar": false,
      "rod": { "length": 1.0, "flexural_rigidity": 1.0, "torsional_rigidity": 0.77, "radius": 0.01 },
      "constraints": [ { "type": "orientation", "s": 0.0, "theta": 0.0, "phi_plus_psi": 0.0 } ],
      "obstacles": [ { "name": "post", "shape": { "type": "ball", "radius": 0.1 }, "position": [0, 0.3, 0.7] } ],
      "plan": { "start": { "position": [0.3, 0.0, 0.9], "tangent": [0.5, 0, 1] },
                "goal":  { "position": [-0.3, 0.0, 0.9], "tangent": [-0.5, 0, 1] } } }"#;
    let c = case::parse(text, Path::new("tangent_poses.json")).unwrap();
    let p = Planner::from_case(&c).unwrap();
    let (us, ug) = (p.start.energy.potential(), p.goal.energy.potential());
    assert!((us - ug).abs() <= 1e-9 * us, "start {us}, goal {ug}");
    let r = p.run(&mut Silent);
    assert_eq!(r.status, PlanStatus::Planned);
    assert!(r.min_clearance.unwrap() >= 0.0);
    assert!(r.replay.coincide, "{}", r.replay.max_deviation_over_l);
}

/// The verification checks between its grid values: the paper's straight-line path, which runs
/// 0.205 L deep into the block halfway, verified on a grid of only k = 0 and k = 1 (both end
/// shapes clear of the block): the chord bound between them is negative, so the interval is
/// bisected and the penetration found (the first midpoint is k = 0.5, where the grid of 201
/// finds −0.205 L as well).
#[test]
fn verification_finds_tunnelling_between_its_grid_values() {
    let (p, _) = paper();
    let fine = fine_model(&p.base.model, 256, 4);
    let path = p.path();
    let z = vec![0.0; path.n_vars()];
    let full = verify(&fine, &path, &z, 201, &p.obstacles, p.base.objective);
    let sparse = verify(&fine, &path, &z, 2, &p.obstacles, p.base.objective);
    let (cf, cs) = (full.min_clearance.unwrap(), sparse.min_clearance.unwrap());
    assert!(cf < -0.2, "{cf}");
    assert!(cs <= cf + 1e-12, "two grid values find {cs}, 201 find {cf}");
    assert!(!sparse.collision_free(1e-6));
}

/// An observer that asks the run to stop at its third progress report, and counts what it
/// hears after that.
#[derive(Default)]
struct StopAtThird {
    progress: usize,
    after_stop: usize,
    replay_shapes: usize,
    in_replay: bool,
}

impl dlo_planner::planner::observer::PlanObserver for StopAtThird {
    fn phase(&mut self, name: &str) {
        self.in_replay = name == "replay";
    }
    fn shape(
        &mut self,
        _m: &dlo_planner::rod::model::Model,
        _r: &dlo_planner::planner::observer::ShapeRecord,
    ) {
        if self.in_replay {
            self.replay_shapes += 1;
        }
    }
    fn progress(
        &mut self,
        _m: &dlo_planner::rod::model::Model,
        _p: &dlo_planner::planner::observer::Progress,
        _w: &[f64],
    ) {
        self.progress += 1;
        if self.progress > 3 {
            self.after_stop += 1;
        }
    }
    fn stop_requested(&mut self) -> bool {
        self.progress >= 3
    }
}

/// An observer stops a plan: the optimiser stops at the iteration it is asked at, nothing is
/// replayed, and the result says `interrupted` (the CLI's Ctrl-C goes this way).
#[test]
fn an_observer_stops_a_plan_and_the_result_says_interrupted() {
    let c = case::load(Path::new("planning_cases/plan_paper_planar.json")).unwrap();
    let planner = Planner::from_case(&c).unwrap();
    let mut obs = StopAtThird::default();
    let r = planner.run(&mut obs);
    assert_eq!(r.status, PlanStatus::Interrupted);
    assert_eq!(r.verdict(), dlo_planner::planner::PlanVerdict::Interrupted);
    assert_eq!(r.optimiser, Some(dlo_planner::optim::AlStatus::Interrupted));
    assert_eq!(obs.progress, 3, "no outer iteration after the stop");
    assert_eq!(obs.after_stop, 0);
    assert_eq!(obs.replay_shapes, 0, "the replay does not run");
    assert!(r.replay.steps.is_empty() && !r.replay.coincide);
    // The plan so far is still verified on the grid.
    assert!(r.u_max.is_finite() && r.u_max > 0.0);
    // The flag can be set from outside too: a planner whose handle is set stops at once.
    let p2 = Planner::from_case(&c).unwrap();
    p2.stop_handle()
        .store(true, std::sync::atomic::Ordering::SeqCst);
    let r2 = p2.run(&mut Silent);
    assert_eq!(r2.status, PlanStatus::Interrupted);
}

/// `Planner::new` refuses ill-formed problems built in code with an error naming the end or
/// the problem, never a panic: a shape of the wrong size or with a NaN, a wrong-sized
/// initial shape, bad static settings.
#[test]
fn planner_new_refuses_ill_formed_problems_built_in_code() {
    use dlo_planner::planner::{End, PlanProblem, PlanSettings, PlanSetupError};
    use dlo_planner::rod::{Rod, layout::Layout};
    use dlo_planner::statics::StaticProblem;
    let rod = Rod::uniform(1.0, 1.0);
    let held = StaticProblem::builder(rod.clone(), Layout::of(&rod, 4))
        .clamp(0.0, [0.0; 3], &[0.0])
        .build()
        .unwrap();
    let goal = End::pose(
        &held,
        [-0.5, 0.0, 0.7],
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    );
    let plan = |start: End, edit: &dyn Fn(&mut PlanProblem)| {
        let mut p = PlanProblem::new(held.clone(), start, goal.clone());
        edit(&mut p);
        Planner::new(p, PlanSettings::default()).err()
    };
    let end_error = |e: Option<PlanSetupError>| match e {
        Some(PlanSetupError::End { end, message }) => format!("{end}: {message}"),
        other => panic!("expected an end error, got {other:?}"),
    };
    let short = end_error(plan(End::shape(vec![0.0; 3]), &|_| {}));
    assert!(
        short.contains("start") && short.contains("has 3 coefficients"),
        "{short}"
    );
    let nan = end_error(plan(End::shape(vec![f64::NAN; 10]), &|_| {}));
    assert!(nan.contains("not finite"), "{nan}");
    let ok_start = End::shape(held.natural_start(0.0));
    assert!(matches!(
        plan(ok_start.clone(), &|p| p.initial.truncate(2)),
        Some(PlanSetupError::Problem(m)) if m.contains("initial shape")
    ));
    assert!(matches!(
        plan(ok_start, &|p| p.static_settings.rho_initial = -1.0),
        Some(PlanSetupError::Settings(s)) if s.field == "rho_initial"
    ));
}

/// `plan.workspace` bounds the controlled end's position: the shipped planar plan swings the
/// strip's end out to x = 0.62 on its way round the block; bounded to |x| ≤ 0.45 (the start and
/// goal sit at ±0.4) the plan keeps every gripper pose inside, to 1e-6 L, and its verification
/// grid says so. A box that excludes the start, or whose bounds cross, is refused, naming it.
#[test]
fn workspace_bounds_keep_the_gripper_inside() {
    let (_, free) = paper();
    let widest = free
        .trajectory
        .poses
        .iter()
        .map(|p| p.position[0].abs())
        .fold(0.0, f64::max);
    assert!(widest > 0.6, "{widest}");
    let bounded = |w: serde_json::Value| {
        let c = shipped_variant("plan_paper_planar.json", |v| v["plan"]["workspace"] = w);
        Planner::from_case(&c)
    };
    let box_x = serde_json::json!({ "min": [-0.45, null, null], "max": [0.45, null, null] });
    let r = bounded(box_x)
        .expect("start and goal inside")
        .run(&mut Silent);
    assert!(r.verdict().is_executable(), "{}", r.verdict());
    let w = r.workspace.expect("checked");
    assert!(w.within && w.largest_excess <= 1e-6, "{w:?}");
    for p in &r.trajectory.poses {
        assert!(
            p.position[0].abs() <= 0.45 + 1e-6,
            "k = {}: {:?}",
            p.k,
            p.position
        );
    }
    // The start (x = 0.4) outside the box.
    let narrow = serde_json::json!({ "max": [0.3, null, null] });
    let err = bounded(narrow)
        .expect_err("the start lies outside")
        .to_string();
    assert!(err.contains("start") && err.contains("workspace"), "{err}");
    let crossed = serde_json::json!({ "min": [0.5, null, null], "max": [0.45, null, null] });
    let err = bounded(crossed).expect_err("crossed bounds").to_string();
    assert!(err.contains("workspace.min[0]"), "{err}");
}

/// A replay step whose solve does not converge is bisected like one that jumps: the paper's
/// optimal path replayed on 4 steps by solves limited to 3 multiplier updates of 6 Newton steps
/// each (and one more such budget, as every replay solve gets) cannot reach k = 0.25 in one
/// step, and without bisections reports unconverged solves; with the default 4 bisections
/// every solve converges, and the shapes at k = 0.25, 0.5, 0.75 and 1 are the default replay's
/// (40 steps, full solves) within 1e-6 L.
#[test]
fn a_replay_step_that_does_not_converge_is_bisected() {
    use dlo_planner::planner::replay::{ReplayOptions, replay};
    let (p, r) = paper();
    let path = p.with_terms(r.path_terms).path();
    let mut weak = p.static_options;
    weak.al.max_outer = 3;
    weak.al.max_inner = 6;
    let run = |refinements: usize| {
        let opts = ReplayOptions {
            steps: 4,
            refinements,
            ..p.settings.replay()
        };
        let stop = std::sync::atomic::AtomicBool::new(false);
        replay(
            &p.base,
            &p.start,
            &path,
            &r.z,
            opts,
            &weak,
            &mut Silent,
            &stop,
        )
    };
    let plain = run(0);
    assert!(
        !plain.all_converged,
        "every solve converged without bisection"
    );
    let bisected = run(4);
    assert!(bisected.all_converged && bisected.snaps.is_empty());
    assert!(bisected.steps.len() > 5, "no step was bisected");
    for k in [0.25, 0.5, 0.75, 1.0] {
        let at = |steps: &[dlo_planner::planner::replay::ReplayStep]| {
            steps
                .iter()
                .find(|s| (s.k - k).abs() < 1e-12)
                .expect("a step at k")
                .positions
                .clone()
        };
        let (a, b) = (at(&bisected.steps), at(&r.replay.steps));
        let d = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (0..3).map(|i| (x[i] - y[i]).powi(2)).sum::<f64>().sqrt())
            .fold(0.0, f64::max);
        assert!(d <= 1e-6, "k = {k}: {d} L apart");
    }
}

/// Equilibrium tracking's later rounds march along two stretches of the samples side by side,
/// the second started from the round before's equilibrium at its first `k`. Along the paper's
/// plan, started from the marched equilibria themselves, the stretches reach the same
/// equilibria: boundary points within 1e-8 L of the march's at all 41 samples; and they are the
/// same bit for bit on one thread and on two.
#[test]
fn tracking_stretches_reach_the_marched_equilibria() {
    use dlo_planner::planner::replay::{equilibria, equilibria_from};
    use dlo_planner::planner::workers::Workers;
    let (p, r) = paper();
    let path = p.with_terms(r.path_terms).path();
    let ks: Vec<f64> = (0..41).map(|j| j as f64 / 40.0).collect();
    let marched = equilibria(&p.base, &p.start, &path, &r.z, &ks, &p.static_options);
    let from: Vec<_> = marched.iter().map(|(_, s)| s.clone()).collect();
    let stretched = |w: &Workers| {
        equilibria_from(
            &p.base,
            &p.start,
            &from,
            &path,
            &r.z,
            &ks,
            &p.static_options,
            w,
        )
    };
    let one = stretched(&Workers::serial());
    let two = stretched(&Workers::new(2));
    assert_eq!(one.len(), ks.len());
    let mut worst: f64 = 0.0;
    for ((m, _), ((a, sa), (b, sb))) in marched.iter().zip(one.iter().zip(&two)) {
        assert_eq!(a, b);
        assert_eq!(sa.a, sb.a);
        for (u, v) in m.iter().zip(a) {
            worst = (0..3).map(|i| (u[i] - v[i]).abs()).fold(worst, f64::max);
        }
    }
    assert!(worst <= 1e-8, "largest difference {worst} L");
}
