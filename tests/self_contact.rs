//! Self-contact in a static solve (eq. 17): a loop whose clamps force it to cross itself.

use dlo_planner::case;
use dlo_planner::constraints::segment_distance;
use dlo_planner::layout::Field;
use dlo_planner::planner::observer::Silent;
use dlo_planner::planner::verify::{fine_model, verify_with};
use dlo_planner::planner::{PlanStatus, Planner};
use dlo_planner::statics::{SolveStatus, StaticSolution, solve_static};
use std::path::Path;

/// A 3D rod (L = 100, r = 0.5) clamped at the origin along +x and at (0, 0, 10) along −x,
/// turned by +π in between: in the x–z plane the loop can only reach its second clamp by
/// crossing its first leg.
fn crossed_loop(self_contact: bool) -> (case::Case, StaticSolution) {
    let text = format!(
        r#"{{ "name": "crossed_loop", "planar": false, "self_contact": {self_contact},
  "rod": {{ "length": 100.0, "flexural_rigidity": 1.0, "torsional_rigidity": 1.0, "radius": 0.5 }},
  "constraints": [
    {{ "type": "orientation", "s": 0.0, "phi": 0.0, "theta": 1.5707963267948966, "psi": 0.0 }},
    {{ "type": "position", "s": 100.0, "x": 0.0, "y": 0.0, "z": 10.0 }},
    {{ "type": "orientation", "s": 100.0, "phi": 0.0, "theta": 4.71238898038469, "psi": 0.0 }}
  ] }}"#
    );
    let mut c = case::parse(&text, Path::new("crossed_loop.json")).unwrap();
    let a0 = c.initial.clone();
    let sol = solve_static(&mut c.problem, &a0, &c.options);
    assert_eq!(sol.status, SolveStatus::Converged, "self_contact {self_contact}");
    (c, sol)
}

/// Smallest distance (case units) between the chords joining consecutive mesh boundaries that
/// are at least `2r` apart along the rod, and the largest |y|.
fn gap_and_lift(c: &case::Case, a: &[f64]) -> (f64, f64) {
    let m = &c.problem.model;
    let l = m.rod.length;
    let x: Vec<[f64; 3]> = m
        .evaluate(a)
        .positions
        .iter()
        .map(|p| p.map(|v| v * l))
        .collect();
    let t = &m.mesh.boundaries;
    let mut gap = f64::INFINITY;
    for i in 0..x.len() - 1 {
        for j in i + 1..x.len() - 1 {
            if (t[j] - t[i + 1]) * l >= 2.0 * m.rod.radius {
                gap = gap.min(segment_distance(x[i], x[i + 1], x[j], x[j + 1]).2);
            }
        }
    }
    (gap, x.iter().map(|p| p[1].abs()).fold(0.0, f64::max))
}

/// Without self-contact the equilibrium lies in the x–z plane and its legs pass through each
/// other. With it, the legs pass over each other: they lift out of the plane, touch at one pair
/// of points s and L − s (the problem is symmetric under s → L − s), 2r apart, pressed by a
/// force across the plane; the shape stays stable and its energy rises.
#[test]
fn a_loop_that_would_cross_itself_touches_itself_instead() {
    let (c0, free) = crossed_loop(false);
    let (c1, held) = crossed_loop(true);
    let r = c1.problem.model.rod.radius;
    let (gap0, lift0) = gap_and_lift(&c0, &free.a);
    assert!(lift0 < 1e-9, "free loop leaves the plane by {lift0}");
    assert!(gap0 < 0.1 * r, "free loop: legs {gap0} apart");
    assert!(free.self_contacts.is_empty());

    let (gap1, lift1) = gap_and_lift(&c1, &held.a);
    assert!(held.max_violation < 1e-8, "violation {}", held.max_violation);
    assert!(gap1 > 1.9 * r, "legs {gap1} apart, 2r = {}", 2.0 * r);
    assert!(lift1 > r, "the loop stays in the plane ({lift1})");
    assert_eq!(held.stable, Some(true));
    assert!(
        held.energy.potential() > free.energy.potential(),
        "{} vs {}",
        held.energy.potential(),
        free.energy.potential()
    );
    let contact = held.self_contacts.first().expect("a contact");
    let [sa, sb] = contact.s;
    assert!((sa + sb - 100.0).abs() < 1e-6, "contact at s = {sa}, {sb}");
    let f = contact.force;
    let size = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
    assert!(size > 1e-4, "contact force {f:?}");
    assert!(f[1].abs() > 0.99 * size, "contact force not across the plane: {f:?}");
}

/// Self-contact rows that decide a plan. Start: the crossed loop of
/// [`a_loop_that_would_cross_itself_touches_itself_instead`] (held at s = L by the controlled
/// end), its first leg passing over the second; goal: its mirror image in the x–z plane
/// (φ, ψ → −φ, −ψ), the first leg passing under. The straight-line path takes the legs through
/// each other (the gap d − 2r between chords is −2r halfway: they intersect), and so does the
/// plan made without self-contact rows. With them, the plan keeps every pair of chords 2r apart
/// on the verification grid, which it never saw, at the same U_max (the end shapes' energy), and
/// the end pose alone reproduces it.
#[test]
fn a_plan_flips_a_crossing_without_passing_the_rod_through_itself() {
    let (c, held) = crossed_loop(true);
    let lay = &c.problem.model.layout;
    let field = |f: Field, sign: f64| -> Vec<f64> {
        lay.field(&held.a, f).unwrap().iter().map(|v| sign * v).collect()
    };
    let (phi, theta, psi) = (
        field(Field::Phi, 1.0),
        field(Field::Theta, 1.0),
        field(Field::Psi, 1.0),
    );
    let (phi_m, psi_m) = (field(Field::Phi, -1.0), field(Field::Psi, -1.0));
    let plan = |self_contact: bool| {
        let text = format!(
            r#"{{ "name": "flip", "planar": false, "self_contact": {self_contact},
  "rod": {{ "length": 100.0, "flexural_rigidity": 1.0, "torsional_rigidity": 1.0, "radius": 0.5 }},
  "constraints": [
    {{ "type": "orientation", "s": 0.0, "phi": 0.0, "theta": 1.5707963267948966, "psi": 0.0 }}
  ],
  "plan": {{
    "start": {{ "shape": {{ "phi": {phi:?}, "theta": {theta:?}, "psi": {psi:?} }} }},
    "goal": {{ "shape": {{ "phi": {phi_m:?}, "theta": {theta:?}, "psi": {psi_m:?} }} }},
    "k_samples": 21 }} }}"#
        );
        let c = case::parse(&text, Path::new("flip.json")).unwrap();
        let p = Planner::from_case(&c).unwrap();
        let r = p.run(&mut Silent);
        let fine = fine_model(&p.base.model, 256, 4);
        let path = p.path();
        let gap = |z: &[f64]| {
            verify_with(&fine, &path, z, 201, &[], p.base.objective, true)
                .self_contact
                .unwrap()
        };
        let straight = gap(&vec![0.0; path.n_vars()]);
        (r.status, r.u_max, r.replay.coincide, straight, gap(&r.z))
    };
    let (status0, u0, _, straight, (g0, k0)) = plan(false);
    let (status1, u1, coincide1, _, (g1, k1)) = plan(true);
    let r = c.problem.model.rod.radius;
    assert!(straight.0 < -1.9 * r, "straight-line path: gap {straight:?}");
    assert_eq!(status0, PlanStatus::Planned);
    assert!(g0 < -r, "plan without the rows: gap {g0} at k = {k0}");
    assert_eq!(status1, PlanStatus::Planned);
    assert!(g1 >= 0.0, "plan with the rows: gap {g1} at k = {k1}");
    assert!((u1 - u0).abs() <= 1e-6 * u0, "U_max {u1} with the rows, {u0} without");
    assert!(coincide1, "the end pose does not reproduce the plan with the rows");
}
