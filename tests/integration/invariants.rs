//! Invariants of the model: a straight rod stores no elastic energy, and elastic energy does
//! not change under a rigid motion of the base.

use dlo_planner::rod::basis::Basis;
use dlo_planner::rod::energy::Objective;
use dlo_planner::rod::layout::{Field, Layout};
use dlo_planner::rod::model::{Discretisation, Model};
use dlo_planner::rod::{Profile, Rod};

fn rod() -> Rod {
    Rod {
        length: 3.0,
        flexural: Profile::Linear {
            start: 2.0,
            end: 1.0,
        },
        torsional: Some(Profile::Constant(0.8)),
        extensional: Some(Profile::Constant(50.0)),
        weight: Profile::Constant(0.0),
        radius: 0.01,
    }
}

fn model(base: [f64; 3]) -> Model {
    let layout = Layout {
        basis: Basis::new(4),
        spatial: true,
        extensible: true,
        free_base: false,
    };
    Model::new(rod(), layout, Discretisation::default(), base, vec![], &[])
}

#[test]
fn straight_rod_has_zero_elastic_energy() {
    let m = model([0.0; 3]);
    let lay = m.layout;
    for (phi, theta, psi) in [(0.0, 0.0, 0.0), (0.4, 1.1, -2.0), (-3.0, 2.5, 7.0)] {
        let mut a = vec![0.0; m.n()];
        a[lay.offset(Field::Phi).unwrap()] = phi;
        a[lay.offset(Field::Theta).unwrap()] = theta;
        a[lay.offset(Field::Psi).unwrap()] = psi;
        let t = m.energy(&a, &m.evaluate(&a), Objective::Potential, None);
        assert!(
            t.flexural.abs() < 1e-14 && t.torsional.abs() < 1e-14 && t.extensional.abs() < 1e-14,
            "{t:?}"
        );
        // And it is straight: |x(L) − x(0)| = L.
        let s = m.evaluate(&a);
        let e = s.positions.last().unwrap();
        assert!(((e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt() - 1.0).abs() < 1e-13);
    }
}

#[test]
fn elastic_energy_is_invariant_under_rigid_motion_of_the_base() {
    let m0 = model([0.0; 3]);
    let m1 = model([0.3, -1.2, 4.0]);
    let lay = m0.layout;
    let a: Vec<f64> = (0..m0.n())
        .map(|i| 0.3 * ((i * 7 % 11) as f64 - 5.0) / 5.0)
        .collect();
    let elastic = |m: &Model, a: &[f64]| {
        let t = m.energy(a, &m.evaluate(a), Objective::Potential, None);
        (t.flexural, t.torsional, t.extensional)
    };
    let e0 = elastic(&m0, &a);
    // Translation.
    let e1 = elastic(&m1, &a);
    // Rotation about z by 0.9 rad: φ → φ + 0.9.
    let mut ar = a.clone();
    ar[lay.offset(Field::Phi).unwrap()] += 0.9;
    let e2 = elastic(&m0, &ar);
    for e in [e1, e2] {
        assert!((e.0 - e0.0).abs() < 1e-12 * e0.0.abs().max(1.0));
        assert!((e.1 - e0.1).abs() < 1e-12 * e0.1.abs().max(1.0));
        assert!((e.2 - e0.2).abs() < 1e-12 * e0.2.abs().max(1.0));
    }
    // The shape moved rigidly: end point rotated about z.
    let (s0, s2) = (m0.evaluate(&a), m0.evaluate(&ar));
    let (p, q) = (s0.positions.last().unwrap(), s2.positions.last().unwrap());
    let (c, s) = (0.9f64.cos(), 0.9f64.sin());
    assert!((q[0] - (c * p[0] - s * p[1])).abs() < 1e-12 && (q[2] - p[2]).abs() < 1e-12);
}

#[test]
fn planar_flexure_is_invariant_under_rotation_in_the_plane() {
    let layout = Layout {
        basis: Basis::new(4),
        spatial: false,
        extensible: false,
        free_base: false,
    };
    let m = Model::new(
        rod(),
        layout,
        Discretisation::default(),
        [0.0; 3],
        vec![],
        &[],
    );
    let a: Vec<f64> = (0..m.n()).map(|i| 0.2 * (i as f64).cos()).collect();
    let mut b = a.clone();
    b[0] += 1.3;
    let f = |a: &[f64]| {
        m.energy(a, &m.evaluate(a), Objective::Potential, None)
            .flexural
    };
    assert!((f(&a) - f(&b)).abs() < 1e-12);
}

/// A constant added to ψ changes neither the energy (torsion sees ψ' only) nor any position, so
/// where no condition fixes ψ it is an exact gauge direction: the verdict removes it (one gauge
/// mode) and judges the rest, stable with no neutral mode. Fixing ψ(0) leaves no gauge.
#[test]
fn a_free_twist_angle_is_removed_as_one_gauge_mode() {
    let text = |psi: &str| {
        format!(
            r#"{{
  "name": "neutral", "planar": false,
  "rod": {{ "length": 1.0, "flexural_rigidity": 1.0, "torsional_rigidity": 0.7, "radius": 0.01 }},
  "constraints": [
    {{ "type": "orientation", "s": 0.0, "phi": 0.0, "theta": 0.4{psi} }},
    {{ "type": "position", "s": 1.0, "x": 0.3, "y": 0.2, "z": 0.7 }}
  ]
}}"#
        )
    };
    let mut neutral = Vec::new();
    for psi in ["", r#", "psi": 0.0"#] {
        let mut c =
            dlo_planner::case::parse(&text(psi), std::path::Path::new("neutral.json")).unwrap();
        let a0 = c.initial.clone();
        let sol = dlo_planner::statics::solve_static(&mut c.problem, &a0, &c.options);
        assert_eq!(sol.status, dlo_planner::statics::SolveStatus::Converged);
        assert_eq!(sol.stable, Some(true));
        assert_eq!(sol.neutral_modes, Some(0));
        neutral.push(sol.gauge_modes);
    }
    assert_eq!(neutral, [Some(1), Some(0)]);
}

/// `Model::evaluate_many` (the path optimisation's sampled shapes, four planar position sums
/// side by side) gives every shape it evaluates bit for bit as `Model::evaluate_into` does,
/// leaves the others untouched, and handles counts that are not a multiple of four: planar
/// inextensible and 3D extensible rods, shapes reused from other coefficients.
#[test]
fn evaluate_many_matches_evaluate_into_bit_for_bit() {
    use dlo_planner::rod::kinematics::Shape;
    let planar = Model::new(
        rod(),
        Layout {
            basis: Basis::new(4),
            spatial: false,
            extensible: false,
            free_base: false,
        },
        Discretisation::default(),
        [0.1, 0.0, -0.2],
        vec![],
        &[],
    );
    for m in [planar, model([0.3, -0.1, 0.2])] {
        let n = m.n();
        let coefs = |seed: f64| -> Vec<Vec<f64>> {
            (0..7)
                .map(|j| {
                    (0..n)
                        .map(|i| 0.3 * ((seed + 1.7 * j as f64 + 0.9 * i as f64).sin()))
                        .collect()
                })
                .collect()
        };
        let (old, a) = (coefs(0.4), coefs(2.1));
        let todo = |j: usize| j != 2;
        let mut many: Vec<Shape> = old.iter().map(|a| m.evaluate(a)).collect();
        m.evaluate_many(&a, &mut many, todo);
        for (j, sh) in many.iter().enumerate() {
            let want = m.evaluate(if todo(j) { &a[j] } else { &old[j] });
            let bits = |s: &Shape| -> Vec<u64> {
                let fields = [s.th(), s.dth(), s.ph(), s.dph(), s.dps(), s.eps()];
                let flat = s.positions.iter().flatten();
                fields
                    .into_iter()
                    .flatten()
                    .chain(flat)
                    .map(|v| v.to_bits())
                    .collect()
            };
            assert_eq!(bits(sh), bits(&want), "shape {j}");
            assert_eq!(sh.positions.len(), m.mesh.panels() + 1);
        }
    }
}

/// The reported end pose is the position the constraint that fixes it sees (the same
/// quadrature), so it meets the constraint as exactly as the solve does; and `"y": 0` on a
/// planar rod is accepted as the plane it lies in.
#[test]
fn reported_end_pose_meets_its_constraint_and_planar_y_zero_is_accepted() {
    let path = std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/planning_cases/pinned_buckling_080.json"
    ));
    let text = std::fs::read_to_string(path).unwrap();
    let with_y = text.replace(r#""x": 0.0, "z": 80.0"#, r#""x": 0.0, "y": 0, "z": 80.0"#);
    assert_ne!(with_y, text);
    let mut reports = Vec::new();
    for t in [&text, &with_y] {
        let mut c = dlo_planner::case::parse(t, path).unwrap();
        let a0 = c.initial.clone();
        let sol = dlo_planner::statics::solve_static(&mut c.problem, &a0, &c.options);
        assert!(sol.max_violation < 1e-12);
        let r = dlo_planner::statics::report::ShapeReport::solved(
            &c.name,
            &c.problem,
            &sol,
            &c.report_points,
            0.0,
        );
        let end = r.points.last().unwrap().position;
        assert!(
            (end[2] - 80.0).abs() <= 1e-12 * 100.0 && end[0].abs() <= 1e-12 * 100.0,
            "{end:?}"
        );
        reports.push(serde_json::to_string(&r.coefficients).unwrap());
    }
    assert_eq!(reports[0], reports[1], "y: 0 changes nothing");
}
