//! The library without case files: a static shape and a plan, built in code.
//!
//! ```sh
//! cargo run --release --example library
//! ```
//!
//! 1. A 3D cable (0.5 m, EI 0.01 N m², GJ 0.008 N m², 0.3 N/m) clamped at both ends 0.4 m
//!    apart, both ends horizontal, sagging onto a ball: its static shape, the reactions (the
//!    ball's among them) and the stability verdict.
//! 2. A planar strip clamped at the origin along +z, its end swung from one side to the other
//!    under a block that the straight-line path runs through, planned with the default
//!    settings and checked by replaying it from the controlled end.

use dlo_planner::optim::AlStatus;
use dlo_planner::planner::observer::Silent;
use dlo_planner::planner::{End, PlanProblem, PlanSettings, Planner};
use dlo_planner::rod::{Rod, layout::Layout};
use dlo_planner::scene::Obstacle;
use dlo_planner::scene::obstacle::ObstacleShape;
use dlo_planner::statics::{StaticOptions, StaticProblem, solve_static};
use std::f64::consts::FRAC_PI_2;
use std::sync::Arc;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // 1. A static shape. Gravity acts along −x: x is up. Both ends point along +y
    //    (φ = θ = π/2): the tangent keeps away from z, the Euler angles' pole.
    let cable = Rod::uniform(0.5, 0.01)
        .with_torsional_rigidity(0.008)
        .with_weight(0.3)
        .with_radius(0.004);
    let ball = Arc::new(Obstacle::new(
        "ball".into(),
        ObstacleShape::ball(0.05),
        [-0.16, 0.2, 0.0],
        [0.0; 3],
    ));
    let along_y = [FRAC_PI_2, FRAC_PI_2, 0.0];
    let mut problem = StaticProblem::builder(cable.clone(), Layout::of(&cable, 6))
        .clamp(0.0, [0.0; 3], &along_y)
        .clamp(0.5, [0.0, 0.4, 0.0], &along_y)
        .obstacle(ball, 0.0)
        .build()?;
    let start = problem.natural_start(0.1);
    let shape = solve_static(&mut problem, &start, &StaticOptions::default());
    let sag = problem
        .model
        .evaluate(&shape.a)
        .positions
        .iter()
        .map(|p| p[0] * cable.length)
        .fold(f64::INFINITY, f64::min);
    println!(
        "cable: {}, U = {:.5} J, lowest point x = {:.4} m, {}, moment balance {}",
        shape.status,
        shape.energy.potential(),
        sag,
        shape
            .stability
            .map_or("stability not computed".into(), |v| v.to_string()),
        shape
            .balance
            .map_or("not computed".into(), |b| format!("{:.1e}", b.relative)),
    );
    for r in &shape.reactions {
        println!("  reaction at {:<24} force {:?} N", r.constraint, r.force);
    }
    if shape.status != AlStatus::Converged {
        return Err("the cable's static solve did not converge".into());
    }

    // 2. A plan. The block fills −0.1 ≤ x ≤ 0.1, z ≥ 0.85; the straight-line path between
    //    the mirror-image start and goal passes through the straight rod, inside it.
    let strip = Rod::uniform(1.0, 1.0).with_radius(0.005);
    let block = Arc::new(Obstacle::new(
        "block".into(),
        ObstacleShape::cuboid([0.1, 0.5, 0.25]),
        [0.0, 0.0, 1.1],
        [0.0; 3],
    ));
    let builder = StaticProblem::builder(strip.clone(), Layout::of(&strip, 4))
        .clamp(0.0, [0.0; 3], &[0.0])
        .obstacle(block, 0.0);
    let held = builder.clone().build()?;
    let about_y = |t: f64| {
        [
            [t.cos(), 0.0, t.sin()],
            [0.0, 1.0, 0.0],
            [-t.sin(), 0.0, t.cos()],
        ]
    };
    let start = End::pose(&held, [0.5, 0.0, 0.6], about_y(FRAC_PI_2));
    let goal = End::pose(&held, [-0.5, 0.0, 0.6], about_y(-FRAC_PI_2));
    // As `dlo plan` makes it: with more contact samples where an end shape dips between the
    // problem's (`Planner::new` keeps them).
    let problem = PlanProblem::new(held, start, goal);
    let planner = Planner::with_contact_samples(&builder, problem, PlanSettings::default())?;
    let plan = planner.run(&mut Silent);
    println!(
        "plan: {} ({}), U_max {:.4} (straight path {:.4}), clearance {:.4} (straight path {:.4}), the optimal path's replay {} (largest deviation {:.2e} L)",
        plan.verdict(),
        match plan.executed_path() {
            Some(p) => format!("executed: {p}"),
            None => "nothing to execute".into(),
        },
        plan.u_max,
        plan.u_max_straight,
        plan.min_clearance.unwrap_or(f64::NAN),
        plan.min_clearance_straight.unwrap_or(f64::NAN),
        if plan.replay.coincide {
            "coincides"
        } else {
            "departs"
        },
        plan.replay.max_deviation_over_l,
    );
    Ok(())
}
