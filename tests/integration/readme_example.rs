//! The README's example case file, as a user copies it: it loads, plans and reaches the poses
//! it writes (its goal a quaternion written to two decimals, normalised).

use dlo_planner::case;
use dlo_planner::planner::PlanVerdict;
use dlo_planner::planner::observer::Silent;
use dlo_planner::planner::trajectory::rotation_of_quaternion;
use std::path::Path;

/// The first JSON block of the README.
fn readme_case_text() -> String {
    let readme = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md"))
        .expect("the README reads");
    let start = readme
        .find("```json\n")
        .expect("the README has a JSON block")
        + 8;
    let len = readme[start..].find("```").expect("the JSON block ends");
    readme[start..start + len].to_string()
}

#[test]
fn the_readmes_case_file_plans_to_the_poses_it_writes() {
    let text = readme_case_text();
    let c = case::parse(&text, Path::new("README.md")).expect("the README's case file loads");
    let planner = dlo_planner::planner::Planner::from_case(&c).expect("its end shapes solve");
    let plan = planner.run(&mut Silent);
    assert_eq!(
        plan.verdict(),
        PlanVerdict::Executable,
        "{}",
        plan.verdict()
    );
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let written = |end: &str, key: &str| -> Vec<f64> {
        json["plan"][end][key]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    let poses = &plan.trajectory.poses;
    let (first, last) = (&poses[0], poses.last().unwrap());
    // The gripper starts and ends at the written positions (to the static solves'
    // feasibility, 1e-9 L).
    for (pose, end) in [(first, "start"), (last, "goal")] {
        for (c, w) in pose.position.iter().zip(written(end, "position")) {
            assert!((c - w).abs() < 1e-8, "{end}: {:?}", pose.position);
        }
    }
    // The start's tangent is the written one, normalised (the frame's third column).
    let t = written("start", "tangent");
    let n = t.iter().map(|v| v * v).sum::<f64>().sqrt();
    let m = rotation_of_quaternion(first.quaternion);
    for (r, tv) in m.iter().zip(&t) {
        assert!((r[2] - tv / n).abs() < 1e-8, "start frame {m:?}");
    }
    // The goal's frame is the written quaternion's rotation, normalised.
    let q = written("goal", "quaternion");
    let want = rotation_of_quaternion([q[0], q[1], q[2], q[3]]);
    let got = rotation_of_quaternion(last.quaternion);
    for (a, b) in want.iter().flatten().zip(got.iter().flatten()) {
        assert!((a - b).abs() < 1e-8, "goal frame {got:?}, written {want:?}");
    }
}

/// A quaternion whose squared norm is 1.02 (not a rounding of a unit quaternion) is refused,
/// naming the field and the norm.
#[test]
fn a_quaternion_far_from_unit_norm_is_refused() {
    let text = readme_case_text().replace("[0.98, 0.0, -0.2, 0.0]", "[1.0, 0.0, -0.1414, 0.0]");
    let c = case::parse(&text, Path::new("README.md")).expect("the JSON parses");
    let Err(err) = dlo_planner::planner::Planner::from_case(&c) else {
        panic!("a squared norm of 1.02 is accepted");
    };
    let err = err.to_string();
    assert!(
        err.contains("plan.goal.quaternion") && err.contains("norm is 1.00994"),
        "{err}"
    );
}
