//! The slopes of the equilibria with respect to the controlled end's pose, through which
//! equilibrium tracking's targets follow the samples' own end poses
//! (`dlo_planner::planner::equilibrium_slopes`): against central differences of equilibria
//! solved at nearby poses, with and without an obstacle contact; and the tracking term with
//! slopes in the planner's objective, against differences of its value and gradient.

use crate::common;
use dlo_planner::case;
use dlo_planner::optim::Nlp;
use dlo_planner::planner::Planner;
use dlo_planner::planner::endpoints::EndPose;
use dlo_planner::planner::equilibrium_slopes::Slope;
use dlo_planner::planner::minimax::MinimaxProblem;
use dlo_planner::planner::replay;
use dlo_planner::statics::{SolveStatus, StaticSolution, solve_static_warm};
use std::path::Path;

fn shipped(name: &str) -> Planner {
    let c = case::load(&Path::new("planning_cases").join(name)).unwrap();
    Planner::from_case(&c).unwrap()
}

/// The equilibrium the end pose of the straight path at `k` produces, marched from the start
/// as tracking marches (16 steps), with that pose.
fn equilibrium_at(pl: &Planner, k: f64) -> (EndPose, StaticSolution) {
    let ks: Vec<f64> = (0..=16).map(|j| k * j as f64 / 16.0).collect();
    let p = pl.minimax_problem_at(ks.clone());
    let z = vec![0.0; p.n()];
    let eq = replay::equilibria(&pl.base, &pl.start, &p.path, &z, &ks, &pl.static_options);
    let (_, sol) = eq.last().expect("equilibria").clone();
    assert_eq!(sol.status, SolveStatus::Converged);
    let mut a = vec![0.0; p.path.n()];
    p.path.shape_at(&z, k, &mut a);
    let positions = pl.base.model.evaluate(&a).positions;
    (EndPose::of(&pl.base.model, &a, &positions), sol)
}

/// Active obstacle or self-contact rows of `sol` (multiplier above 1e-8): the rows of `base`
/// that are inequalities.
fn contacts(pl: &Planner, sol: &StaticSolution) -> usize {
    let m = Nlp::m(&pl.base);
    (0..m)
        .filter(|&i| Nlp::sense(&pl.base, i) == dlo_planner::optim::Sense::LessEq)
        .filter(|&i| sol.lambda[i] > 1e-8)
        .count()
}

/// Every slope `∂x_b/∂v_i` against `(x_b(v + h eᵢ) − x_b(v − h eᵢ)) / 2h`, each equilibrium
/// solved from `sol` (h = 1e-4: the solves' tolerances, 1e-9, leave about 1e-5 of the slope);
/// returns the largest error relative to the largest slope of its row.
fn slope_error(pl: &Planner, pose: &EndPose, sol: &StaticSolution) -> f64 {
    let slope = Slope::of(&pl.base, pose, sol).expect("slopes");
    let d = slope.position_slopes();
    let np = pose.position.len();
    assert_eq!(d.len(), np + pose.angles.len());
    let mut opts = pl.static_options;
    opts.stability = false;
    opts.balance = false;
    let h = 1e-4;
    let mut worst: f64 = 0.0;
    for (i, di) in d.iter().enumerate() {
        let solve = |sign: f64| {
            let mut q = pose.clone();
            if i < np {
                q.position[i].1 += sign * h;
            } else {
                q.angles[i - np].1 += sign * h;
            }
            let mut p = q.problem(&pl.base);
            let s = solve_static_warm(&mut p, &sol.a, &sol.lambda, &opts);
            assert_eq!(s.status, SolveStatus::Converged);
            p.model.evaluate(&s.a).positions
        };
        let (xp, xm) = (solve(1.0), solve(-1.0));
        let scale = di.iter().flatten().fold(1e-3_f64, |a, v| a.max(v.abs()));
        for (b, db) in di.iter().enumerate() {
            for c in 0..3 {
                let fd = (xp[b][c] - xm[b][c]) / (2.0 * h);
                worst = worst.max((fd - db[c]).abs() / scale);
            }
        }
    }
    worst
}

/// [`slope_error`] within 1e-4 at the straight path's equilibrium at `k` of each case, each
/// resting on an obstacle or free of contact as `in_contact` says.
fn slopes_match(cases: &[(&str, f64)], in_contact: bool) {
    for &(name, k) in cases {
        let pl = shipped(name);
        let (pose, sol) = equilibrium_at(&pl, k);
        assert_eq!(contacts(&pl, &sol) > 0, in_contact, "{name} at {k}");
        let err = slope_error(&pl, &pose, &sol);
        assert!(err < 1e-4, "{name}: relative error {err:e}");
    }
}

/// Free of contact: the paper's planar case (end position and angle) a fifth of the way
/// along its straight path, and the pillar case's 3D cable (position and three angles) a
/// quarter of the way.
#[test]
fn equilibrium_slopes_match_differences_of_equilibria() {
    slopes_match(
        &[
            ("plan_paper_planar.json", 0.2),
            ("plan_cable_around_pillar.json", 0.25),
        ],
        false,
    );
}

/// Resting on an obstacle (the paper's planar case a quarter of the way, the pillar case's
/// cable at 0.385): the contact rows stay active, and the slopes move the rod along the
/// obstacle's surface.
#[test]
fn equilibrium_slopes_hold_the_contacts_they_rest_on() {
    slopes_match(
        &[
            ("plan_paper_planar.json", 0.25),
            ("plan_cable_around_pillar.json", 0.385),
        ],
        true,
    );
}

/// The planning objective with tracking targets that follow the samples' end poses: targets
/// and slopes of the equilibria of another path `z2`, evaluated at `z`.
fn sloped_problem(pl: &Planner) -> (MinimaxProblem, Vec<f64>) {
    let ks: Vec<f64> = (0..9).map(|j| j as f64 / 8.0).collect();
    let mut p = pl.minimax_problem_at(ks.clone());
    p.beta = 3.0;
    p.mean_weight = 0.7;
    let n = p.n();
    let z: Vec<f64> = (0..n).map(|i| 0.02 * ((i as f64) * 1.7).sin()).collect();
    let z2: Vec<f64> = (0..n).map(|i| 0.01 * ((i as f64) * 0.9).cos()).collect();
    let eq = replay::equilibria(&pl.base, &pl.start, &p.path, &z2, &ks, &pl.static_options);
    let mut a = vec![0.0; p.path.n()];
    let slopes: Vec<Option<Slope>> = ks
        .iter()
        .zip(&eq)
        .map(|(&k, (_, sol))| {
            p.path.shape_at(&z2, k, &mut a);
            let positions = pl.base.model.evaluate(&a).positions;
            let pose = EndPose::of(&pl.base.model, &a, &positions);
            Slope::of(&pl.base, &pose, sol)
        })
        .collect();
    // Most samples have slopes (one near a fold or fork of its branch keeps a fixed target).
    let sloped = slopes.iter().filter(|s| s.is_some()).count();
    assert!(
        2 * sloped >= ks.len(),
        "{sloped} of {} samples sloped",
        ks.len()
    );
    p.targets = Some(eq.into_iter().map(|(x, _)| x).collect());
    p.slopes = Some(slopes);
    p.track_weight = 50.0;
    (p, z)
}

/// Gradient and Hessian of the objective with sloped tracking targets against central
/// differences (relative 1e-6 and 1e-5, as the planner's other terms), planar and 3D.
#[test]
fn sloped_tracking_term_matches_finite_differences() {
    for name in ["plan_paper_planar.json", "plan_cable_around_pillar.json"] {
        let pl = shipped(name);
        let (mut p, z) = sloped_problem(&pl);
        let m = p.m();
        let y: Vec<f64> = (0..m).map(|i| 0.3 * ((i as f64) * 0.37).cos()).collect();
        let mut c = vec![0.0; m];
        let f_sloped = p.values(&z, &mut c);
        let tracked = p.tracking();
        assert!(tracked > 0.0, "{name}: no tracking term");
        // The slopes change the term: without them the targets stay where they were solved.
        let slopes = p.slopes.take();
        let f_plain = p.values(&z, &mut c);
        assert!((f_plain - f_sloped).abs() > 1e-9 * f_sloped.abs(), "{name}");
        p.slopes = slopes;
        let herr = common::hessian_fd_error(&mut p, &z, &y);
        assert!(herr < 1e-5, "{name}: Hessian relative error {herr:e}");
        let (p, z) = sloped_problem(&pl);
        crate::planner_gradients::check_gradient(&format!("{name} (sloped tracking)"), p, &z);
    }
}
