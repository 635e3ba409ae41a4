//! A 3D problem turned about the gravity axis (and, without weight, about any axis) is the same
//! problem: the same energy and the turned shape (`src/case/frame.rs`, the angles' reference
//! frame chosen away from the pole). The cases are written as a user would, with the clamps'
//! frames as Euler angles of the case's axes; the turned copies turn every position and frame.
//! In the case's own axes (`"angle_frame": "case"`) the same problems differ by up to a factor
//! of 10 in energy, which is what the frame removes.

use dlo_planner::case;
use dlo_planner::rod::kinematics::{angles_of, rotation};
use dlo_planner::statics::{SolveStatus, StaticSolution, solve_static};
use serde_json::{Value, json};
use std::f64::consts::PI;
use std::path::Path;

type M = [[f64; 3]; 3];

fn mul(a: M, b: M) -> M {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

fn apply(a: M, v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| (0..3).map(|k| a[i][k] * v[k]).sum())
}

/// The rotation by `angle` about the unit `axis`.
fn turn(axis: [f64; 3], angle: f64) -> M {
    let n = (axis.iter().map(|v| v * v).sum::<f64>()).sqrt();
    let [x, y, z] = axis.map(|v| v / n);
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    [
        [c + x * x * t, x * y * t - z * s, x * z * t + y * s],
        [y * x * t + z * s, c + y * y * t, y * z * t - x * s],
        [z * x * t - y * s, z * y * t + x * s, c + z * z * t],
    ]
}

/// A frame whose tangent (third column) is `t` and whose ξ is `up` made perpendicular to it.
fn frame(t: [f64; 3], up: [f64; 3]) -> M {
    let unit = |v: [f64; 3]| {
        let n = v.iter().map(|c| c * c).sum::<f64>().sqrt();
        v.map(|c| c / n)
    };
    let t = unit(t);
    let d: f64 = (0..3).map(|k| up[k] * t[k]).sum();
    let xi = unit(std::array::from_fn(|k| up[k] - d * t[k]));
    let eta = [
        t[1] * xi[2] - t[2] * xi[1],
        t[2] * xi[0] - t[0] * xi[2],
        t[0] * xi[1] - t[1] * xi[0],
    ];
    std::array::from_fn(|i| [xi[i], eta[i], t[i]])
}

/// The spelling of the rotation with angles `a` — `(φ, θ, ψ)` or `(φ + π, −θ, ψ + π)`, each
/// angle plus any multiple of 2π — nearest `reference`.
fn nearest_branch(a: [f64; 3], reference: [f64; 3]) -> [f64; 3] {
    let near = |x: f64, t: f64| x + 2.0 * PI * ((t - x) / (2.0 * PI)).round();
    let dist = |x: [f64; 3]| {
        (0..3)
            .map(|j| (x[j] - reference[j]).abs())
            .fold(0.0, f64::max)
    };
    [a, [a[0] + PI, -a[1], a[2] + PI]]
        .map(|b| std::array::from_fn::<f64, 3, _>(|j| near(b[j], reference[j])))
        .into_iter()
        .min_by(|x, y| dist(*x).total_cmp(&dist(*y)))
        .unwrap()
}

/// Euler angles of the clamps `e0`, `e1` (as written for the scene before turning) for the
/// scene turned by `q`: the first the principal angles of `q A(e0)`, the second continued
/// from them along `q A(e)` as `e` runs from `e0` to `e1` — the same twist between the clamps,
/// as a user turning the scene writes it.
fn turned_angles(q: M, e0: [f64; 3], e1: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let a = |e: [f64; 3]| mul(q, rotation(e[0], e[1], e[2]));
    let start = angles_of(a(e0));
    let mut cur = start;
    let steps = 2000;
    for k in 1..=steps {
        let u = k as f64 / steps as f64;
        let e = std::array::from_fn(|j| e0[j] + u * (e1[j] - e0[j]));
        cur = nearest_branch(angles_of(a(e)), cur);
    }
    (start, cur)
}

/// A clamped–clamped cable: base at the origin with frame `f0`, the end at `p1` with frame
/// `f1`, all turned by `q`; the clamps' Euler angles as a user writes them: the principal ones
/// of the scene before turning, carried along the turn ([`turned_angles`]).
fn clamped(rod: Value, f0: M, p1: [f64; 3], f1: M, q: M, extra: Value) -> Value {
    spelled(rod, angles_of(f0), p1, angles_of(f1), q, extra)
}

/// [`clamped`] with the clamps' Euler angles `e0`, `e1` of the scene before turning.
fn spelled(rod: Value, e0: [f64; 3], p1: [f64; 3], e1: [f64; 3], q: M, extra: Value) -> Value {
    let (e0, e1) = turned_angles(q, e0, e1);
    let p = apply(q, p1);
    let l = rod["length"].as_f64().unwrap();
    let mut c = json!({
        "name": "turned", "planar": false, "rod": rod,
        "discretisation": { "basis": "paper", "basis_pairs": 8, "panels": 32 },
        "constraints": [
            { "type": "orientation", "s": 0.0, "phi": e0[0], "theta": e0[1], "psi": e0[2] },
            { "type": "position", "s": l, "x": p[0], "y": p[1], "z": p[2] },
            { "type": "orientation", "s": l, "phi": e1[0], "theta": e1[1], "psi": e1[2] }
        ]
    });
    if let (Value::Object(c), Value::Object(x)) = (&mut c, extra) {
        c.extend(x);
    }
    c
}

fn solve(v: &Value) -> (case::Case, StaticSolution) {
    let mut c = case::parse(&v.to_string(), Path::new("turned.json")).unwrap();
    let a0 = c.initial.clone();
    let sol = solve_static(&mut c.problem, &a0, &c.options);
    assert_eq!(sol.status, SolveStatus::Converged, "{v}");
    (c, sol)
}

/// Positions (case units) at every mesh boundary.
fn positions(c: &case::Case, sol: &StaticSolution) -> Vec<[f64; 3]> {
    let m = &c.problem.model;
    let l = m.rod.length;
    m.evaluate(&sol.a)
        .positions
        .iter()
        .map(|x| x.map(|v| v * l))
        .collect()
}

/// Energies equal to 1e-8 relative, shapes equal (the turned copy turned back) to 1e-6 L.
fn assert_same(
    name: &str,
    reference: (&case::Case, &StaticSolution),
    turned: (&case::Case, &StaticSolution),
    q: M,
) {
    let (u0, u1) = (reference.1.energy.potential(), turned.1.energy.potential());
    assert!(
        (u1 - u0).abs() <= 1e-8 * u0.abs().max(1e-12),
        "{name}: energy {u0} turned {u1}"
    );
    let l = reference.0.problem.model.rod.length;
    let (x0, x1) = (
        positions(reference.0, reference.1),
        positions(turned.0, turned.1),
    );
    assert_eq!(x0.len(), x1.len());
    for (a, b) in x0.iter().zip(&x1) {
        let qa = apply(q, *a);
        let d = (0..3).map(|k| (qa[k] - b[k]).powi(2)).sum::<f64>().sqrt();
        assert!(d <= 1e-6 * l, "{name}: turned shape off by {d} at {a:?}");
    }
}

/// The cable of the report: 0.5 m, EI 0.01, GJ 0.008, 0.3 N/m.
fn heavy_cable_rod() -> Value {
    json!({ "length": 0.5, "flexural_rigidity": 0.01, "torsional_rigidity": 0.008,
            "weight_per_length": 0.3, "radius": 0.002 })
}

/// The cable of the report: 0.5 m, EI 0.01, GJ 0.008, 0.3 N/m, clamped 0.3 m apart with the
/// second end's tangent turned 90° about the vertical (x). Turned by any angle about x: the same
/// energy and shape; its moment balance falls as the basis grows. In the case's own axes the
/// same turns give energies from 0.18 to 2.2 J.
#[test]
fn heavy_cable_turned_about_the_vertical_is_the_same() {
    let rod = heavy_cable_rod();
    let (f0, f1) = (
        frame([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
        frame([0.0, 1.0, 0.0], [1.0, 0.0, 0.0]),
    );
    let p1 = [0.0, 0.0, 0.3];
    let id = turn([1.0, 0.0, 0.0], 0.0);
    let base = clamped(rod.clone(), f0, p1, f1, id, json!({}));
    let (c0, s0) = solve(&base);
    // The cable sags (x is up) by about 15 mm, the weight's way.
    let sag = positions(&c0, &s0).iter().map(|x| x[0]).fold(0.0, f64::min);
    assert!((-0.02..-0.01).contains(&sag), "sag {sag}");
    let mut case_axes = Vec::new();
    for angle in [PI / 4.0, -PI / 4.0, PI / 2.0, 2.5, PI] {
        let q = turn([1.0, 0.0, 0.0], angle);
        let v = clamped(rod.clone(), f0, p1, f1, q, json!({}));
        let (c1, s1) = solve(&v);
        assert_same(&format!("turned {angle}"), (&c0, &s0), (&c1, &s1), q);
        let own = clamped(rod.clone(), f0, p1, f1, q, json!({ "angle_frame": "case" }));
        case_axes.push(solve(&own).1.energy.potential());
    }
    let spread = case_axes.iter().fold(0.0f64, |m, u| m.max(*u)) / s0.energy.potential();
    assert!(
        spread > 2.0,
        "in the case's own axes the turns differ: {case_axes:?}"
    );
    // The moment balance falls with the basis (the truncation of the Ritz fields).
    let mut last = f64::INFINITY;
    for pairs in [2, 4, 8, 16] {
        let mut v = base.clone();
        v["discretisation"]["basis_pairs"] = pairs.into();
        let b = solve(&v).1.balance.expect("computed").relative;
        assert!(b < last, "{pairs} pairs: balance {b} after {last}");
        last = b;
    }
    assert!(last < 3e-3, "16 pairs: balance {last}");
}

/// The crossed loop (no weight, self-contact) turned about three generic axes.
#[test]
fn crossed_loop_turned_about_any_axis_is_the_same() {
    let path = format!(
        "{}/planning_cases/self_contact_crossed_loop.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let shipped: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let rod = shipped["rod"].clone();
    // The shipped spelling: θ runs from π/2 to 3π/2, through the apex along −z.
    let (e0, e1) = ([0.0, PI / 2.0, 0.0], [0.0, 1.5 * PI, 0.0]);
    let extra =
        json!({ "self_contact": true, "discretisation": { "basis": "paper", "basis_pairs": 4 } });
    let id = turn([1.0, 0.0, 0.0], 0.0);
    let (c0, s0) = solve(&spelled(
        rod.clone(),
        e0,
        [0.0, 0.0, 10.0],
        e1,
        id,
        extra.clone(),
    ));
    assert!(
        (s0.energy.potential() - 0.2271685).abs() < 1e-6,
        "the shipped loop: {}",
        s0.energy.potential()
    );
    for (axis, angle) in [
        ([1.0, 0.0, 0.0], 0.7),
        ([0.3, -0.5, 0.8], 2.0),
        ([0.0, 1.0, 1.0], -1.2),
    ] {
        let q = turn(axis, angle);
        let v = spelled(rod.clone(), e0, [0.0, 0.0, 10.0], e1, q, extra.clone());
        let (c1, s1) = solve(&v);
        assert_same(&format!("{axis:?} {angle}"), (&c0, &s0), (&c1, &s1), q);
    }
}

/// Generated clamped–clamped cables (fixed seed): random end frames and end positions within
/// reach, with and without weight, each turned about the vertical (weight) or a random axis.
#[test]
fn random_clamped_cables_turned_are_the_same() {
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut rnd = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let unit = |rnd: &mut dyn FnMut() -> f64| loop {
        let v = [2.0 * rnd() - 1.0, 2.0 * rnd() - 1.0, 2.0 * rnd() - 1.0];
        let n = v.iter().map(|c| c * c).sum::<f64>().sqrt();
        if (0.2..1.0).contains(&n) {
            return v.map(|c| c / n);
        }
    };
    for i in 0..12 {
        let heavy = i % 2 == 0;
        let rod = json!({ "length": 1.0, "flexural_rigidity": 1.0, "torsional_rigidity": 0.8,
                          "weight_per_length": if heavy { 2.0 } else { 0.0 }, "radius": 0.005 });
        let f0 = frame(unit(&mut rnd), unit(&mut rnd));
        let f1 = frame(unit(&mut rnd), unit(&mut rnd));
        let p1 = unit(&mut rnd).map(|c| c * (0.4 + 0.3 * rnd()));
        let id = turn([1.0, 0.0, 0.0], 0.0);
        let v0 = clamped(
            rod.clone(),
            f0,
            p1,
            f1,
            id,
            json!({ "discretisation": { "basis_pairs": 4 } }),
        );
        let (c0, s0) = solve(&v0);
        let axis = if heavy {
            [1.0, 0.0, 0.0]
        } else {
            unit(&mut rnd)
        };
        let q = turn(axis, 2.0 * PI * rnd());
        let v1 = clamped(
            rod,
            f0,
            p1,
            f1,
            q,
            json!({ "discretisation": { "basis_pairs": 4 } }),
        );
        let (c1, s1) = solve(&v1);
        assert_same(&format!("cable {i}"), (&c0, &s0), (&c1, &s1), q);
    }
}

/// A report's `coefficients` with its `angle_frame`, written back as a case's `shape` and
/// `angle_frame`, are the same shape: the same energy (1e-12 relative) and positions (1e-12 L).
/// A matrix that is not a rotation is refused, naming the field.
#[test]
fn reported_coefficients_and_frame_round_trip() {
    let path = format!(
        "{}/planning_cases/self_contact_crossed_loop.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap();
    let mut c = case::parse(&text, Path::new("loop.json")).unwrap();
    let a0 = c.initial.clone();
    let sol = solve_static(&mut c.problem, &a0, &c.options);
    assert_eq!(sol.status, SolveStatus::Converged);
    let frame = c
        .problem
        .model
        .angle_frame()
        .expect("the loop's angles have a frame");
    let mut v: Value = serde_json::from_str(&text).unwrap();
    v["shape"] = dlo_planner::statics::report::coefficients_json(&c.problem, &sol.a);
    v["angle_frame"] = json!(frame);
    let mut back = case::parse(&v.to_string(), Path::new("back.json")).unwrap();
    let a = back.initial.clone();
    let ev = dlo_planner::statics::evaluate_shape(&mut back.problem, &a);
    let (u0, u1) = (sol.energy.potential(), ev.energy.potential());
    assert!((u1 - u0).abs() <= 1e-12 * u0, "{u0} {u1}");
    let l = c.problem.model.rod.length;
    let (x0, x1) = (positions(&c, &sol), {
        let m = &back.problem.model;
        m.evaluate(&a)
            .positions
            .iter()
            .map(|x| x.map(|v| v * l))
            .collect::<Vec<_>>()
    });
    for (p, q) in x0.iter().zip(&x1) {
        let d = (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>().sqrt();
        assert!(d <= 1e-12 * l, "{p:?} {q:?}");
    }
    v["angle_frame"] = json!([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0]]);
    let err = case::parse(&v.to_string(), Path::new("bad.json"))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("angle_frame") && err.contains("rotation"),
        "{err}"
    );
}

/// A plan whose angles have a frame (the bar case with `"angle_frame": "auto"`): its end poses,
/// written in the case's axes, are the gripper's first and last poses (position to 1e-6 L,
/// rotation to 1e-6, the end solves' tolerance), every pose of the trajectory is the path's own
/// `R A(φ, θ, ψ)` at `s = L` (1e-12), and the plan is collision-free.
#[test]
fn a_plan_in_a_frame_reaches_the_written_poses() {
    use dlo_planner::planner::observer::Silent;
    use dlo_planner::planner::{PlanStatus, Planner};
    let path = format!(
        "{}/planning_cases/plan_cable_under_bar.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    v["angle_frame"] = json!("auto");
    let c = case::parse(&v.to_string(), Path::new("bar_auto.json")).unwrap();
    assert!(c.problem.model.angle_frame().is_some());
    let p = Planner::from_case(&c).unwrap();
    let r = p.run(&mut Silent);
    assert_eq!(r.status, PlanStatus::Planned);
    let t = &r.trajectory;
    let (first, last) = (&t.poses[0], t.poses.last().unwrap());
    for (pose, key) in [(first, "start"), (last, "goal")] {
        let e = &v["plan"][key];
        let f = |k: &str| e[k].as_f64().unwrap();
        let m = rotation(f("phi"), f("theta"), f("psi"));
        let x = [f("x"), f("y"), f("z")];
        for (got, want) in pose.position.iter().zip(x) {
            assert!((got - want).abs() < 1e-6, "{key}: {:?}", pose.position);
        }
        for (row, mrow) in pose.rotation.iter().zip(&m) {
            for (got, want) in row.iter().zip(mrow) {
                assert!((got - want).abs() < 1e-6, "{key}: {:?}", pose.rotation);
            }
        }
    }
    let model = &p.base.model;
    let path = p.path_of(&r);
    let mut a = vec![0.0; path.n()];
    for pose in &t.poses {
        path.shape_at(&r.z, pose.k, &mut a);
        let m = model.frame_at(&a, 1.0);
        for (row, mrow) in pose.rotation.iter().zip(&m) {
            for (x, y) in row.iter().zip(mrow) {
                assert!((x - y).abs() <= 1e-12, "k = {}", pose.k);
            }
        }
    }
}

/// With the frame away from the pole and the Legendre basis, 3D shapes balance their moments
/// as the basis resolves them: the heavy cable to 1e-6 at 8 pairs (measured 9.4e-8; 3.5e-3 in
/// the paper's basis) and the crossed loop to 1e-5 at 12 pairs (measured 2.4e-6; 1.4e-2 in the
/// paper's basis, 13 % in the case's axes).
#[test]
fn frame_and_legendre_basis_balance_3d_shapes() {
    let rod = heavy_cable_rod();
    let (f0, f1) = (
        frame([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
        frame([0.0, 1.0, 0.0], [1.0, 0.0, 0.0]),
    );
    let q = turn([1.0, 0.0, 0.0], 0.3);
    let legendre = |pairs: usize| json!({ "discretisation": { "basis_pairs": pairs, "panels": 32, "basis": "legendre" } });
    let cable = clamped(rod, f0, [0.0, 0.0, 0.3], f1, q, legendre(8));
    let b = solve(&cable).1.balance.expect("computed").relative;
    assert!(b < 1e-6, "cable: {b}");
    let path = format!(
        "{}/planning_cases/self_contact_crossed_loop.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    v["discretisation"] = legendre(12)["discretisation"].clone();
    let b = solve(&v).1.balance.expect("computed").relative;
    assert!(b < 1e-5, "crossed loop: {b}");
}
