//! Self-contact in a static solve (eq. 17): a loop whose clamps force it to cross itself.

use dlo_planner::case;
use dlo_planner::constraints::segment_distance;
use dlo_planner::planner::observer::Silent;
use dlo_planner::planner::verify::{fine_model, verify_with};
use dlo_planner::planner::{PlanStatus, Planner};
use dlo_planner::rod::layout::Field;
use dlo_planner::statics::{SolveStatus, StaticSolution, solve_static};
use serde_json::{Value, json};
use std::path::Path;

/// `planning_cases/self_contact_crossed_loop.json` (a 3D rod, L = 100, r = 0.5, clamped at the
/// origin along +x and at (0, 0, 10) along −x, turned by +π in between: in the x–z plane the
/// loop can only reach its second clamp by crossing its first leg), with or without
/// self-contact, in the paper's basis of 4 pairs (the discretisation `plan_loop_flip` writes its
/// shapes in).
fn crossed_loop(self_contact: bool) -> (case::Case, StaticSolution) {
    crossed_loop_in(
        self_contact,
        "auto",
        Some(json!({ "basis": "paper", "basis_pairs": 4 })),
    )
}

/// The crossed loop with its angles measured as `angle_frame` says, discretised as given
/// (`None`: as shipped).
fn crossed_loop_in(
    self_contact: bool,
    angle_frame: &str,
    discretisation: Option<Value>,
) -> (case::Case, StaticSolution) {
    let mut v: Value = serde_json::from_str(&shipped("self_contact_crossed_loop")).unwrap();
    v["self_contact"] = json!(self_contact);
    v["angle_frame"] = json!(angle_frame);
    if let Some(d) = discretisation {
        v["discretisation"] = d;
    }
    let mut c = case::parse(&v.to_string(), Path::new("crossed_loop.json")).unwrap();
    let a0 = c.initial.clone();
    let sol = solve_static(&mut c.problem, &a0, &c.options);
    assert_eq!(
        sol.status,
        SolveStatus::Converged,
        "self_contact {self_contact}"
    );
    (c, sol)
}

fn shipped(name: &str) -> String {
    let path = format!("{}/planning_cases/{name}.json", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(path).unwrap()
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
    assert!(
        held.max_violation < 1e-8,
        "violation {}",
        held.max_violation
    );
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
    assert!(
        f[1].abs() > 0.99 * size,
        "contact force not across the plane: {f:?}"
    );
}

/// The loop as shipped, in Legendre polynomials of degree 33 per angle from the frame away from
/// the pole: resolved, its moments balance (reactions and the contact pair) to 1e-6 of the
/// largest, and it still touches itself at one pair s, L − s, pressed across the plane; its
/// energy and contact force hold when the contact samples double (1e-6 and 1e-2 relative). The
/// paper's basis of 4 pairs overstates the force about twelvefold (1.6e-3 against 1.3e-4).
#[test]
fn the_resolved_loop_touches_itself_and_balances() {
    let (_, held) = crossed_loop_in(true, "auto", None);
    assert!(
        held.balance.expect("computed").relative <= 1e-6,
        "{:?}",
        held.balance
    );
    assert_eq!(held.stable, Some(true));
    let (_, free) = crossed_loop_in(false, "auto", None);
    assert!(held.energy.potential() > free.energy.potential());
    let force = |sol: &StaticSolution| {
        assert_eq!(sol.self_contacts.len(), 1, "{:?}", sol.self_contacts);
        let contact = &sol.self_contacts[0];
        let [sa, sb] = contact.s;
        assert!((sa + sb - 100.0).abs() < 1e-5, "contact at s = {sa}, {sb}");
        let f = contact.force;
        let size = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
        assert!(f[1].abs() > 0.99 * size, "not across the plane: {f:?}");
        size
    };
    let f32 = force(&held);
    let disc = json!({ "basis": "legendre", "basis_pairs": 16, "panels": 64, "samples": 64 });
    let (_, fine) = crossed_loop_in(true, "auto", Some(disc));
    let f64_ = force(&fine);
    assert!((f32 - f64_).abs() <= 1e-2 * f64_, "{f32} vs {f64_}");
    let (e32, e64) = (held.energy.potential(), fine.energy.potential());
    assert!((e32 - e64).abs() <= 1e-6 * e64, "{e32} vs {e64}");
}

/// Self-contact rows that decide a plan (`planning_cases/plan_loop_flip.json`). Start: the
/// crossed loop of [`a_loop_that_would_cross_itself_touches_itself_instead`] (held at s = L by
/// the controlled end), its first leg passing over the second; goal: its mirror image in the
/// x–z plane (φ, ψ → −φ, −ψ), the first leg passing under. The straight-line path takes the
/// legs through each other (the gap d − 2r between chords is −2r halfway: they intersect), and
/// so does the plan made without self-contact rows. With them, the plan keeps every pair of
/// chords 2r apart on the verification grid, which it never saw, at the same U_max (the end
/// shapes' energy), and the end pose alone reproduces it, from the start shape itself at k = 0
/// (its first solve starts from the start shape's contact forces; started without them, it
/// passed the legs through each other into the mirror image, 0.012 L away) to the goal. The
/// flip case writes its shapes as coefficients, so its angles are the case's own
/// (`src/case/frame.rs`), and so are this test's.
#[test]
fn a_plan_flips_a_crossing_without_passing_the_rod_through_itself() {
    // The flip case writes its end shapes as coefficients of the case's own angles.
    let paper = json!({ "basis": "paper", "basis_pairs": 4 });
    let (c, held) = crossed_loop_in(true, "case", Some(paper));
    // The shipped start is this solve's shape.
    let lay = &c.problem.model.layout;
    let flip = case::parse(&shipped("plan_loop_flip"), Path::new("flip.json")).unwrap();
    let start = Planner::from_case(&flip).unwrap().start.a.clone();
    for f in [Field::Phi, Field::Theta, Field::Psi] {
        let (a, b) = (
            lay.field(&held.a, f).unwrap(),
            lay.field(&start, f).unwrap(),
        );
        assert!(
            a.iter()
                .zip(b)
                .all(|(x, y)| (x - y).abs() <= 1e-12 * (1.0 + x.abs()))
        );
    }
    let plan = |self_contact: bool| {
        let text = shipped("plan_loop_flip").replace(
            r#""self_contact": true"#,
            &format!(r#""self_contact": {self_contact}"#),
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
        let planned = gap(&r.z);
        (r, straight, planned)
    };
    let (r0, straight, (g0, k0)) = plan(false);
    let (r1, _, (g1, k1)) = plan(true);
    let r = c.problem.model.rod.radius;
    assert!(
        straight.0 < -1.9 * r,
        "straight-line path: gap {straight:?}"
    );
    assert_eq!(r0.status, PlanStatus::Planned);
    assert!(g0 < -r, "plan without the rows: gap {g0} at k = {k0}");
    assert_eq!(r1.status, PlanStatus::Planned);
    assert!(g1 >= 0.0, "plan with the rows: gap {g1} at k = {k1}");
    assert!(
        (r1.u_max - r0.u_max).abs() <= 1e-6 * r0.u_max,
        "U_max {} with the rows, {} without",
        r1.u_max,
        r0.u_max
    );
    let rep = &r1.replay;
    assert!(
        rep.coincide,
        "the end pose does not reproduce the plan: {rep:?}"
    );
    assert!(
        rep.start_deviation_over_l < 1e-3 && rep.end_deviation_over_l < 1e-3,
        "the replay does not reproduce the ends: {} and {} L",
        rep.start_deviation_over_l,
        rep.end_deviation_over_l
    );
}
