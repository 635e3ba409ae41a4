//! Finite-difference checks of every energy term's gradient and every constraint kind's
//! Jacobian, on random coefficients, planar and 3D (the contract every constraint must pass).

use crate::common;
use dlo_planner::constraints::*;
use dlo_planner::optim::Nlp;
use dlo_planner::rod::basis::Basis;
use dlo_planner::rod::energy::Objective;
use dlo_planner::rod::kinematics::Shape;
use dlo_planner::rod::layout::{Field, Layout};
use dlo_planner::rod::model::{Discretisation, Model, PointLoad};
use dlo_planner::rod::{Profile, Rod};
use dlo_planner::scene::mesh::read_obj;
use dlo_planner::scene::obstacle::{Obstacle, ObstacleShape};
use dlo_planner::statics::problem::StaticProblem;
use parry3d_f64::math::Vector;
use parry3d_f64::shape::*;
use std::sync::Arc;

/// Deterministic pseudo-random numbers in [-1, 1] (64-bit LCG).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

fn rod(spatial: bool, extensible: bool) -> Rod {
    Rod {
        length: 2.0,
        flexural: Profile::Linear {
            start: 1.0,
            end: 0.5,
        },
        torsional: spatial.then_some(Profile::Linear {
            start: 0.7,
            end: 0.9,
        }),
        extensional: extensible.then_some(Profile::Constant(80.0)),
        weight: Profile::Linear {
            start: 3.0,
            end: 1.0,
        },
        radius: 0.02,
    }
}

fn model(spatial: bool, extensible: bool, free_base: bool) -> Model {
    let layout = Layout {
        basis: Basis::new(3),
        spatial,
        extensible,
        free_base,
    };
    let loads = vec![PointLoad {
        t: 0.37,
        force: [0.3, if spatial { -0.2 } else { 0.0 }, 0.5],
        reference: [0.1, 0.0, 0.2],
    }];
    let samples: Vec<f64> = (0..=16).map(|j| j as f64 / 16.0).collect();
    let mut pts = samples.clone();
    pts.extend([0.25, 0.6, 1.0]);
    Model::new(
        rod(spatial, extensible),
        layout,
        Discretisation {
            panels: 8,
            gauss_points: 4,
        },
        [0.05, 0.0, -0.1],
        loads,
        &pts,
    )
}

fn random_a(m: &Model, rng: &mut Lcg, scale: f64) -> Vec<f64> {
    (0..m.n()).map(|_| scale * rng.next()).collect()
}

const CONFIGS: [(bool, bool, bool); 5] = [
    (false, false, false),
    (false, true, true),
    (true, false, false),
    (true, true, false),
    (true, true, true),
];

fn fd_check(f: &mut dyn FnMut(&[f64]) -> f64, a: &[f64], g: &[f64], what: &str) {
    let h = 1e-6;
    let scale = g.iter().fold(1e-3_f64, |m, v| m.max(v.abs()));
    for j in 0..a.len() {
        let mut ap = a.to_vec();
        let mut am = a.to_vec();
        ap[j] += h;
        am[j] -= h;
        let fd = (f(&ap) - f(&am)) / (2.0 * h);
        assert!(
            (fd - g[j]).abs() <= 1e-6 * scale,
            "{what}: d/da[{j}] analytic {} vs finite difference {fd}",
            g[j]
        );
    }
}

#[test]
fn energy_gradient_matches_finite_differences() {
    let mut rng = Lcg(7);
    for (spatial, ext, free) in CONFIGS {
        let m = model(spatial, ext, free);
        for trial in 0..4 {
            let a = random_a(&m, &mut rng, 0.6);
            for obj in [Objective::Internal, Objective::Potential] {
                let mut shape = Shape::default();
                let mut g = vec![0.0; m.n()];
                m.objective_and_gradient(&a, obj, &mut shape, &mut g);
                let mut f = |x: &[f64]| {
                    let mut s = Shape::default();
                    let mut gg = vec![0.0; m.n()];
                    m.objective_and_gradient(x, obj, &mut s, &mut gg)
                };
                fd_check(
                    &mut f,
                    &a,
                    &g,
                    &format!(
                        "energy {obj:?} spatial={spatial} ext={ext} free={free} trial={trial}"
                    ),
                );
            }
        }
    }
}

/// A weightless planar rod's energy is a quadratic form in the coefficients (flexure in θ',
/// extension in ε), evaluated as such: its terms against the model's own node sums
/// (1e-12 relative) and an independent composite Simpson integration of `½∫ Rf θ'²` and
/// `½∫ Re ε²` (20,000 intervals; 1e-8 relative, the 16 × 4-point Gauss rule's own error on
/// these integrands is ≈ 2e-9), and its gradient against finite differences.
#[test]
fn weightless_planar_energy_is_its_quadratic_form() {
    let mut rng = Lcg(5);
    for (ext, free) in [(false, false), (true, false), (true, true)] {
        let r = Rod {
            weight: Profile::Constant(0.0),
            ..rod(false, ext)
        };
        let layout = Layout {
            basis: Basis::new(3),
            spatial: false,
            extensible: ext,
            free_base: free,
        };
        let m = Model::new(
            r.clone(),
            layout,
            Discretisation::default(),
            [0.0; 3],
            vec![],
            &[],
        );
        let a = random_a(&m, &mut rng, 0.8);
        let shape = m.evaluate(&a);
        let terms = m.energy(&a, &shape, Objective::Potential, None);
        let nb = layout.basis.len();
        let th = &a[..nb];
        let eps = layout.offset(Field::Eps).map(|o| &a[o..o + nb]);
        let (rf, l) = (r.rf_ref(), r.length);
        let intervals = 20_000;
        let (mut flex, mut ext_e) = (0.0, 0.0);
        let mut d = vec![0.0; nb];
        for i in 0..=intervals {
            let t = i as f64 / intervals as f64;
            let w = if i == 0 || i == intervals {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            } / (3.0 * intervals as f64);
            layout.basis.derivatives(t, &mut d);
            let dth: f64 = th.iter().zip(&d).map(|(c, e)| c * e).sum();
            flex += w * 0.5 * r.flexural.at(t) / rf * dth * dth;
            if let Some(eps) = eps {
                let e = layout.basis.eval(eps, t);
                ext_e += w * 0.5 * r.extensional.unwrap().at(t) * l * l / rf * e * e;
            }
        }
        let (mut flex_q, mut ext_q) = (0.0, 0.0);
        for (q, (&t, &w)) in m.mesh.nodes.iter().zip(&m.mesh.weights).enumerate() {
            layout.basis.derivatives(t, &mut d);
            let dth: f64 = th.iter().zip(&d).map(|(c, e)| c * e).sum();
            flex_q += 0.5 * w * r.flexural.at(t) / rf * dth * dth;
            if ext {
                let e = shape.eps()[q];
                ext_q += 0.5 * w * r.extensional.unwrap().at(t) * l * l / rf * e * e;
            }
        }
        let close = |got: f64, want: f64, rel: f64, what: &str| {
            assert!(
                (got - want).abs() <= rel * want.abs().max(1e-300),
                "{what}: {got} vs {want}"
            )
        };
        close(terms.flexural, flex_q, 1e-12, "flexure vs node sum");
        close(terms.extensional, ext_q, 1e-12, "extension vs node sum");
        close(terms.flexural, flex, 1e-8, "flexure vs Simpson");
        close(terms.extensional, ext_e, 1e-8, "extension vs Simpson");
        assert_eq!(terms.gravitational, 0.0);
        let mut g = vec![0.0; m.n()];
        let mut sh = Shape::default();
        m.objective_and_gradient(&a, Objective::Potential, &mut sh, &mut g);
        let mut f = |x: &[f64]| {
            let mut s = Shape::default();
            let mut gg = vec![0.0; m.n()];
            m.objective_and_gradient(x, Objective::Potential, &mut s, &mut gg)
        };
        fd_check(
            &mut f,
            &a,
            &g,
            &format!("weightless planar ext={ext} free={free}"),
        );
    }
}

/// Each energy term separately, by switching the others off.
#[test]
fn each_energy_term_gradient_matches_finite_differences() {
    let mut rng = Lcg(11);
    let base = rod(true, true);
    let zero = Profile::Constant(1e-300);
    let variants = [
        (
            "flexure",
            Rod {
                torsional: Some(zero),
                extensional: Some(zero),
                weight: Profile::Constant(0.0),
                ..base.clone()
            },
        ),
        (
            "torsion",
            Rod {
                extensional: Some(zero),
                weight: Profile::Constant(0.0),
                ..base.clone()
            },
        ),
        (
            "extension",
            Rod {
                torsional: Some(zero),
                weight: Profile::Constant(0.0),
                ..base.clone()
            },
        ),
        (
            "gravity",
            Rod {
                torsional: Some(zero),
                extensional: Some(zero),
                ..base.clone()
            },
        ),
    ];
    for (name, r) in variants {
        let layout = Layout {
            basis: Basis::new(4),
            spatial: true,
            extensible: true,
            free_base: true,
        };
        let m = Model::new(r, layout, Discretisation::default(), [0.0; 3], vec![], &[]);
        let a = random_a(&m, &mut rng, 0.5);
        let mut shape = Shape::default();
        let mut g = vec![0.0; m.n()];
        m.objective_and_gradient(&a, Objective::Internal, &mut shape, &mut g);
        let mut f = |x: &[f64]| {
            let mut s = Shape::default();
            let mut gg = vec![0.0; m.n()];
            m.objective_and_gradient(x, Objective::Internal, &mut s, &mut gg)
        };
        fd_check(&mut f, &a, &g, name);
    }
}

fn obstacle(name: &str, shape: ObstacleShape, position: [f64; 3]) -> Arc<Obstacle> {
    Arc::new(Obstacle::new(
        name.into(),
        shape,
        position,
        [0.3, -0.2, 0.5],
    ))
}

fn all_constraints(m: &Model) -> Vec<Constraint> {
    let v = |x: f64, y: f64, z: f64| Vector::new(x, y, z);
    let spatial = m.layout.spatial;
    let (verts, faces) = read_obj(include_str!("../../planning_cases/meshes/cube.obj")).unwrap();
    let mesh = TriMesh::with_flags(
        verts
            .iter()
            .map(|p| v(p[0] * 1.2, p[1] * 1.2, p[2] * 1.2))
            .collect(),
        faces,
        TriMeshFlags::ORIENTED | TriMeshFlags::MERGE_DUPLICATE_VERTICES,
    )
    .unwrap();
    let hull = ConvexPolyhedron::from_convex_hull(&[
        v(0.0, 0.0, 0.0),
        v(0.6, 0.0, 0.1),
        v(0.0, 0.5, 0.0),
        v(0.1, 0.1, 0.7),
        v(0.4, 0.4, 0.4),
    ])
    .unwrap();
    let shapes = vec![
        obstacle(
            "cuboid",
            ObstacleShape::Cuboid(Cuboid::new(v(0.3, 0.4, 0.25))),
            [0.2, 0.0, 0.9],
        ),
        obstacle(
            "ball",
            ObstacleShape::Ball(Ball::new(0.35)),
            [0.3, 0.1, 1.2],
        ),
        obstacle(
            "capsule",
            ObstacleShape::Capsule(Capsule::new(v(-0.3, 0.0, 0.0), v(0.4, 0.1, 0.2), 0.2)),
            [0.0, 0.0, 0.7],
        ),
        obstacle(
            "cylinder",
            ObstacleShape::Cylinder(Cylinder::new(0.5, 0.3)),
            [0.3, 0.0, 1.3],
        ),
        obstacle(
            "hull",
            ObstacleShape::ConvexHull(Arc::new(hull)),
            [0.0, -0.2, 0.6],
        ),
        obstacle(
            "mesh",
            ObstacleShape::TriMesh(Arc::new(mesh)),
            [0.1, 0.0, 1.0],
        ),
        obstacle(
            "half space",
            ObstacleShape::HalfSpace([0.6, 0.0, 0.8]),
            [0.0, 0.0, 1.0],
        ),
    ];
    let samples: Vec<usize> = (0..=16).map(|j| m.boundary(j as f64 / 16.0)).collect();
    let ts: Vec<f64> = (0..=16).map(|j| j as f64 / 16.0).collect();
    let mut out: Vec<Constraint> = vec![
        Constraint::from(PositionConstraint {
            name: "pos".into(),
            boundary: m.boundary(1.0),
            rows: vec![
                (0, Bound::Equal(0.1)),
                (2, Bound::AtMost(0.5)),
                (2, Bound::AtLeast(0.2)),
            ],
        }),
        Constraint::from(RelativePositionConstraint {
            name: "rel".into(),
            from: m.boundary(0.25),
            to: m.boundary(0.6),
            rows: vec![(0, 0.1), (2, 0.3)],
        }),
        Constraint::from(OrientationConstraint::new(
            m,
            "ori".into(),
            0.6,
            if spatial {
                vec![
                    (Angle::Field(Field::Phi), 0.1),
                    (Angle::Field(Field::Theta), 0.2),
                    (Angle::PhiPlusPsi, -0.3),
                ]
            } else {
                vec![(Angle::Field(Field::Theta), 0.2)]
            },
        )),
        Constraint::from(LinearConstraint {
            name: "lin".into(),
            rows: vec![(vec![(0, 1.0), (3, -2.0)], 0.5)],
        }),
        Constraint::from(SelfContactConstraint::new(samples.clone(), &ts, 0.9)),
    ];
    for o in shapes {
        // Rows at the points alone, and with their half-chords; a clearance large enough that
        // the half-chords are searched.
        for (chords, clearance) in [(false, 0.01), (true, 0.6)] {
            out.push(Constraint::from(ObstacleConstraint {
                obstacle: o.clone(),
                samples: samples.clone(),
                clearance,
                length: 2.0,
                chords,
            }));
        }
    }
    out
}

#[test]
fn every_constraint_jacobian_matches_finite_differences() {
    let mut rng = Lcg(3);
    let (mut checked, mut skipped) = (0, 0);
    for (spatial, ext, free) in CONFIGS {
        let m = model(spatial, ext, free);
        for con in all_constraints(&m) {
            let label = con.label();
            let mut p = StaticProblem::new(m.clone(), vec![con]);
            let rows = p.m();
            for trial in 0..3 {
                let a = random_a(&m, &mut rng, 0.8);
                let mut c = vec![0.0; rows];
                p.values(&a, &mut c);
                let mut g0 = vec![0.0; m.n()];
                p.gradient(&a, &vec![0.0; rows], &mut g0);
                for r in 0..rows {
                    let mut y = vec![0.0; rows];
                    y[r] = 1.0;
                    let mut g = vec![0.0; m.n()];
                    p.values(&a, &mut c);
                    p.gradient(&a, &y, &mut g);
                    let jac: Vec<f64> = g.iter().zip(&g0).map(|(x, y)| x - y).collect();
                    let mut f = |x: &[f64]| {
                        let mut cc = vec![0.0; rows];
                        p.values(x, &mut cc);
                        cc[r]
                    };
                    let mut ok = true;
                    // Skip rows sitting on a kink of the distance field (closest feature changes
                    // within the difference step): detected by one-sided differences disagreeing.
                    let h = 1e-6;
                    for j in 0..a.len() {
                        let (mut ap, mut am) = (a.clone(), a.clone());
                        ap[j] += h;
                        am[j] -= h;
                        let f0 = f(&a);
                        let (fp, fm) = (f(&ap), f(&am));
                        if ((fp - f0) - (f0 - fm)).abs() > 1e-4 * h {
                            ok = false;
                        }
                    }
                    if !ok {
                        skipped += 1;
                    } else {
                        checked += 1;
                        fd_check(
                            &mut f,
                            &a,
                            &jac,
                            &format!(
                                "{label} row {r} spatial={spatial} ext={ext} free={free} trial={trial}"
                            ),
                        );
                    }
                }
            }
        }
    }
    assert!(
        skipped * 20 < checked,
        "too many rows on kinks: {skipped} skipped, {checked} checked"
    );
}

#[test]
fn obstacle_signed_distance_is_negative_inside_and_exact_for_a_ball() {
    let b = obstacle("ball", ObstacleShape::Ball(Ball::new(0.5)), [1.0, 2.0, 3.0]);
    let (d, n) = b.signed_distance([1.0, 2.0, 3.2]);
    assert!((d + 0.3).abs() < 1e-12 && (n[2] - 1.0).abs() < 1e-12);
    let (d, _) = b.signed_distance([1.0, 2.0, 4.0]);
    assert!((d - 0.5).abs() < 1e-12);
    let h = obstacle(
        "hs",
        ObstacleShape::HalfSpace([0.0, 0.0, 1.0]),
        [0.0, 0.0, 0.8],
    );
    let h = Obstacle::new(h.name.clone(), h.shape.clone(), h.position(), [0.0; 3]);
    assert!((h.signed_distance([0.0, 0.0, 1.3]).0 - 0.5).abs() < 1e-12);
    assert!((h.signed_distance([5.0, 1.0, 0.3]).0 + 0.5).abs() < 1e-12);
    // A point deep inside a closed oriented mesh is recognised as inside.
    let (verts, faces) = read_obj(include_str!("../../planning_cases/meshes/cube.obj")).unwrap();
    let mesh = TriMesh::with_flags(
        verts
            .iter()
            .map(|p| Vector::new(p[0], p[1], p[2]))
            .collect(),
        faces,
        TriMeshFlags::ORIENTED,
    )
    .unwrap();
    let mo = Obstacle::new(
        "m".into(),
        ObstacleShape::TriMesh(Arc::new(mesh)),
        [0.0; 3],
        [0.0; 3],
    );
    assert!((mo.signed_distance([0.1, 0.0, 0.0]).0 + 0.4).abs() < 1e-12);
    assert!((mo.signed_distance([0.0, 0.0, 0.9]).0 - 0.4).abs() < 1e-12);
}

/// The static problem's Hessian (`∇²V + Σ yᵢ∇²cᵢ`, with the obstacle distance's own curvature)
/// against central differences of its analytic gradient, on shipped cases covering point loads
/// and fingers with a free base, a 3D extensible twisted rod, gravity, and a cylinder obstacle,
/// held at points and on chords (whose witnesses move along their chords).
#[test]
fn static_hessian_matches_finite_differences() {
    for (name, contact) in [
        ("grasp_a_080.json", "points"),
        ("extensible_twist_3d.json", "points"),
        ("gravity_rho_g_050.json", "points"),
        ("plan_cable_around_pillar.json", "points"),
        ("plan_cable_around_pillar.json", "chords"),
    ] {
        let case = common::shipped_variant(name, |v| {
            v["discretisation"]["contact"] = contact.into();
        });
        let mut p = case.problem.clone();
        let m = p.m();
        let mut rng = Lcg(7);
        let a: Vec<f64> = case.initial.iter().map(|v| v + 0.2 * rng.next()).collect();
        let y: Vec<f64> = (0..m).map(|_| rng.next()).collect();
        assert!(p.has_hessian() && p.hessian_is_exact(&y));
        let worst = common::hessian_fd_error(&mut p, &a, &y);
        assert!(
            worst < 1e-5,
            "{name} ({contact}): Hessian relative error {worst:e}"
        );
    }
}
