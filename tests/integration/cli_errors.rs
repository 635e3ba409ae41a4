//! Malformed and physically invalid case files: each gives exit code 2 with a message that names
//! the file and the field, and never a panic.

use std::process::Command;

fn run(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_dlo"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Asserts that the JSON object `v` (at `path`, for the message) has every one of `keys`.
fn assert_has_keys(v: &serde_json::Value, path: &str, keys: &[&str]) {
    for key in keys {
        assert!(v.get(key).is_some(), "missing {path}{key}");
    }
}

const GOOD_ROD: &str = r#""rod": {"length": 100.0, "flexural_rigidity": 1.0}"#;

/// (label, case text, text the error must contain)
fn bad_cases() -> Vec<(&'static str, String, &'static str)> {
    let c = |body: &str| format!("{{{body}}}");
    vec![
        ("not json", "this is not json".into(), "line 1 column"),
        ("empty file", "".into(), "EOF"),
        (
            "top-level array",
            "[]".into(),
            "a case file is a JSON object",
        ),
        (
            "top-level number",
            " 1.5".into(),
            "this one starts with `1`",
        ),
        ("missing rod", c(r#""planar": true"#), "missing field `rod`"),
        (
            "missing length",
            c(r#""rod": {"flexural_rigidity": 1.0}"#),
            "missing field `length`",
        ),
        (
            "unknown top-level field",
            c(&format!(r#"{GOOD_ROD}, "colour": "red""#)),
            "unknown field `colour`",
        ),
        (
            "unknown rod field",
            c(r#""rod": {"length": 1.0, "flexural_rigidity": 1.0, "stiffness": 2}"#),
            "unknown field `stiffness`",
        ),
        (
            "wrong type",
            c(r#""rod": {"length": "long", "flexural_rigidity": 1.0}"#),
            "field `rod.length`: invalid type: string \"long\", expected f64 at line 1",
        ),
        (
            "rod of the wrong kind",
            c(r#""rod": null"#),
            "field `rod`: invalid type: null, expected an object with the rod's `length`",
        ),
        (
            "name of the wrong kind",
            c(&format!(r#"{GOOD_ROD}, "discretisation": {{"basis": []}}"#)),
            "field `discretisation.basis`: expected a name (a string), got a value of another kind",
        ),
        (
            "list too long",
            c(&format!(
                r#"{GOOD_ROD}, "base": {{"position": [0, 0, 0, 1]}}"#
            )),
            "field `base.position`: more items than this field takes at line 1",
        ),
        (
            "profile of the wrong kind",
            c(r#""rod": {"length": 1.0, "flexural_rigidity": [1.0, 2.0]}"#),
            "field `rod.flexural_rigidity`: expected a number, or `{\"start\": a, \"end\": b}`",
        ),
        (
            "coordinate of the wrong kind",
            c(&format!(
                r#"{GOOD_ROD}, "constraints": [{{"type": "position", "s": 0.0, "x": "left"}}]"#
            )),
            "field `constraints[0].x`: expected a number (equality) or bounds `{\"min\": a, \"max\": b}`",
        ),
        (
            "constraint without its arc length",
            c(&format!(
                r#"{GOOD_ROD}, "constraints": [{{"type": "position", "x": 0.0}}]"#
            )),
            "field `constraints[0]`: missing field `s`",
        ),
        (
            "obstacle shape field of the wrong kind",
            c(&format!(
                r#"{GOOD_ROD}, "obstacles": [{{"shape": {{"type": "ball", "radius": [1]}}}}]"#
            )),
            "field `obstacles[0].shape.radius`: invalid type: sequence, expected f64",
        ),
        (
            "negative length",
            c(r#""rod": {"length": -1.0, "flexural_rigidity": 1.0}"#),
            "rod.length",
        ),
        (
            "zero rigidity",
            c(r#""rod": {"length": 1.0, "flexural_rigidity": 0.0}"#),
            "rod.flexural_rigidity",
        ),
        (
            "negative linear rigidity",
            c(r#""rod": {"length": 1.0, "flexural_rigidity": {"start": 1.0, "end": -0.5}}"#),
            "rod.flexural_rigidity",
        ),
        (
            "NaN literal",
            c(r#""rod": {"length": NaN, "flexural_rigidity": 1.0}"#),
            "expected value",
        ),
        (
            "overflowing number",
            c(r#""rod": {"length": 1e999, "flexural_rigidity": 1.0}"#),
            "number out of range",
        ),
        (
            "torsion on planar rod",
            c(r#""rod": {"length": 1.0, "flexural_rigidity": 1.0, "torsional_rigidity": 0.7}"#),
            "rod.torsional_rigidity",
        ),
        (
            "spatial rod without torsion",
            c(&format!(r#"{GOOD_ROD}, "planar": false"#)),
            "rod.torsional_rigidity",
        ),
        (
            "negative weight",
            c(r#""rod": {"length": 1.0, "flexural_rigidity": 1.0, "weight_per_length": -2.0}"#),
            "rod.weight_per_length",
        ),
        (
            "radius too large",
            c(r#""rod": {"length": 1.0, "flexural_rigidity": 1.0, "radius": 0.7}"#),
            "rod.radius",
        ),
        (
            "s beyond length",
            c(&format!(
                r#"{GOOD_ROD}, "constraints": [{{"type": "position", "s": 150.0, "x": 0.0}}]"#
            )),
            "constraints[0].s",
        ),
        (
            "unknown constraint type",
            c(&format!(
                r#"{GOOD_ROD}, "constraints": [{{"type": "glue", "s": 1.0}}]"#
            )),
            "field `constraints[0].type`: unknown variant `glue`",
        ),
        (
            "y on planar rod",
            c(&format!(
                r#"{GOOD_ROD}, "constraints": [{{"type": "position", "s": 100.0, "y": 1.0}}]"#
            )),
            "constraints[0].y",
        ),
        (
            "empty position",
            c(&format!(
                r#"{GOOD_ROD}, "constraints": [{{"type": "position", "s": 100.0}}]"#
            )),
            "constraints[0]",
        ),
        (
            "phi on planar rod",
            c(&format!(
                r#"{GOOD_ROD}, "constraints": [{{"type": "orientation", "s": 0.0, "phi": 0.0}}]"#
            )),
            "constraints[0].phi",
        ),
        (
            "unreachable end distance",
            c(&format!(
                r#"{GOOD_ROD}, "constraints": [{{"type": "position", "s": 100.0, "x": 0.0, "z": 120.0}}]"#
            )),
            "unreachable",
        ),
        (
            "unreachable relative position",
            c(&format!(
                r#"{GOOD_ROD}, "constraints": [{{"type": "relative_position", "s_a": 10.0, "s_b": 30.0, "x": 15.0, "z": 15.0}}]"#
            )),
            "unreachable",
        ),
        (
            "min above max",
            c(&format!(
                r#"{GOOD_ROD}, "constraints": [{{"type": "position", "s": 0.0, "z": {{"min": 2.0, "max": 1.0}}}}]"#
            )),
            "exceeds max",
        ),
        (
            "basis too large",
            c(&format!(
                r#"{GOOD_ROD}, "discretisation": {{"basis_pairs": 99}}"#
            )),
            "discretisation.basis_pairs",
        ),
        (
            "zero panels",
            c(&format!(r#"{GOOD_ROD}, "discretisation": {{"panels": 0}}"#)),
            "discretisation.panels",
        ),
        (
            "bad ball radius",
            c(&format!(
                r#"{GOOD_ROD}, "obstacles": [{{"shape": {{"type": "ball", "radius": -1.0}}}}]"#
            )),
            "obstacles[0].shape.radius",
        ),
        (
            "unknown shape",
            c(&format!(
                r#"{GOOD_ROD}, "obstacles": [{{"shape": {{"type": "torus", "radius": 1.0}}}}]"#
            )),
            "field `obstacles[0].shape.type`: unknown variant `torus`",
        ),
        (
            "zero half-space normal",
            c(&format!(
                r#"{GOOD_ROD}, "obstacles": [{{"shape": {{"type": "half_space", "normal": [0, 0, 0]}}}}]"#
            )),
            "obstacles[0].shape.normal",
        ),
        (
            "degenerate hull",
            c(&format!(
                r#"{GOOD_ROD}, "obstacles": [{{"shape": {{"type": "convex_hull", "points": [[0,0,0],[1,0,0],[0,1,0],[1,1,0]]}}}}]"#
            )),
            "obstacles[0].shape.points",
        ),
        (
            "missing mesh file",
            c(&format!(
                r#"{GOOD_ROD}, "obstacles": [{{"shape": {{"type": "triangle_mesh", "obj": "nope.obj"}}}}]"#
            )),
            "obstacles[0].shape.obj",
        ),
        (
            "empty mesh",
            c(&format!(
                r#"{GOOD_ROD}, "obstacles": [{{"shape": {{"type": "triangle_mesh", "obj": "empty.obj"}}}}]"#
            )),
            "no triangles",
        ),
        (
            "wrong coefficient count",
            c(&format!(r#"{GOOD_ROD}, "shape": {{"theta": [0.0, 1.0]}}"#)),
            "shape.theta",
        ),
        (
            "eps on inextensible rod",
            c(&format!(
                r#"{GOOD_ROD}, "shape": {{"eps": [0,0,0,0,0,0,0,0,0,0]}}"#
            )),
            "shape.eps",
        ),
        (
            "negative tolerance",
            c(&format!(
                r#"{GOOD_ROD}, "solver": {{"feasibility_tol": -1.0}}"#
            )),
            "solver.feasibility_tol",
        ),
        (
            "force on y of planar rod",
            c(&format!(
                r#"{GOOD_ROD}, "forces": [{{"s": 50.0, "force": [0.0, 1.0, 0.0]}}]"#
            )),
            "forces[0].force[1]",
        ),
        (
            "unknown angle frame",
            c(&format!(r#"{GOOD_ROD}, "angle_frame": "sideways""#)),
            "field `angle_frame`: expected \"auto\", \"case\" or a 3×3 rotation matrix",
        ),
        (
            "angle frame not a rotation",
            c(
                r#""rod": {"length": 1.0, "flexural_rigidity": 1.0, "torsional_rigidity": 1.0}, "planar": false, "angle_frame": [[1, 0, 0], [0, 1, 0], [0, 0, 2]]"#,
            ),
            "field `angle_frame`: must be a rotation matrix",
        ),
        (
            "angle frame on a planar rod",
            c(&format!(
                r#"{GOOD_ROD}, "angle_frame": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]"#
            )),
            "field `angle_frame`: a planar rod's angles",
        ),
        (
            "angle frame with a partial orientation",
            c(
                r#""rod": {"length": 1.0, "flexural_rigidity": 1.0, "torsional_rigidity": 1.0}, "planar": false, "angle_frame": [[0, 0, 1], [1, 0, 0], [0, 1, 0]], "constraints": [{"type": "orientation", "s": 0.0, "psi": 0.3}]"#,
            ),
            "constraints[0] prescribes angles that cannot be measured from another frame",
        ),
        (
            "unknown basis",
            c(&format!(
                r#"{GOOD_ROD}, "discretisation": {{"basis": "chebyshev"}}"#
            )),
            "field `discretisation.basis`: unknown variant `chebyshev`, expected `paper` or `legendre`",
        ),
    ]
}

#[test]
fn malformed_cases_give_exit_code_2_and_name_the_problem() {
    let scratch = crate::common::Scratch::new("dlo_bad_cases");
    let dir = scratch.path();
    std::fs::write(dir.join("empty.obj"), "# nothing here\n").unwrap();
    let cases = bad_cases();
    assert!(cases.len() >= 20);
    for (i, (label, text, needle)) in cases.iter().enumerate() {
        let path = dir.join(format!("bad_{i}.json"));
        std::fs::write(&path, text).unwrap();
        for cmd in ["shape", "energy"] {
            let (code, stdout, stderr) = run(&[cmd, path.to_str().unwrap(), "--json"]);
            assert_eq!(code, 2, "{label}: exit code {code}, stderr: {stderr}");
            assert!(
                stderr.contains(&format!("bad_{i}.json")),
                "{label}: file not named: {stderr}"
            );
            assert!(
                stderr.contains(needle),
                "{label}: expected '{needle}' in: {stderr}"
            );
            assert!(!stderr.contains("panicked"), "{label}: panic: {stderr}");
            assert!(stdout.is_empty(), "{label}: half-written output: {stdout}");
        }
    }
}

#[test]
fn missing_file_and_bad_usage_are_bad_input() {
    let (code, _, stderr) = run(&["shape", "/nonexistent/case.json"]);
    assert_eq!(code, 2);
    assert!(stderr.contains("/nonexistent/case.json") && stderr.contains("cannot read"));
    let (code, _, _) = run(&["frobnicate"]);
    assert_eq!(code, 2);
}

#[test]
fn energy_without_explicit_shape_is_bad_input() {
    let (code, _, stderr) = run(&[
        "energy",
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/planning_cases/pinned_buckling_095.json"
        ),
    ]);
    assert_eq!(code, 2);
    assert!(stderr.contains("`shape`"));
}

#[test]
fn shipped_pinned_case_prints_documented_json() {
    let (code, stdout, _) = run(&[
        "shape",
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/planning_cases/pinned_buckling_080.json"
        ),
        "--json",
    ]);
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let keys = [
        "status",
        "energy",
        "reactions",
        "max_violation",
        "stable",
        "end_pose",
        "timing_s",
    ];
    assert_has_keys(&v, "", &keys);
    for key in [
        "total",
        "flexural",
        "torsional",
        "extensional",
        "gravitational",
    ] {
        assert!(v["energy"][key].is_number(), "missing energy.{key}");
    }
    assert_eq!(v["status"], "converged");
    assert_eq!(v["stable"], true);
    let pin = v["reactions"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["constraint"] == "right pin")
        .unwrap();
    let fz = pin["force"][2].as_f64().unwrap();
    assert!((fz + 1.0982e-3).abs() < 2e-6, "{fz}");
    let r = &v["end_pose"]["rotation"];
    assert_eq!(r.as_array().unwrap().len(), 3);
}

/// The planning, margin and log commands: bad input is exit code 2 with the file and the field
/// named, and no log is written for a case that fails validation.
#[test]
fn plan_margin_and_log_commands_reject_bad_input() {
    let scratch = crate::common::Scratch::new("dlo-cli");
    let dir = scratch.path();
    let no_plan = dir.join("no_plan.json");
    std::fs::write(&no_plan, format!("{{{GOOD_ROD}}}")).unwrap();
    let logs = dir.join("logs");
    let logs_s = logs.to_str().unwrap();
    let (code, out, err) = run(&["plan", no_plan.to_str().unwrap(), "--log-dir", logs_s]);
    assert_eq!(code, 2, "{err}");
    assert!(out.is_empty());
    assert!(
        err.contains("no_plan.json") && err.contains("field `plan`"),
        "{err}"
    );
    assert!(
        !logs.join("no_plan.mcap").exists(),
        "no log for invalid input"
    );
    let (code, _, err) = run(&["margin", no_plan.to_str().unwrap(), "--log-dir", logs_s]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("field `grasp`"), "{err}");
    // A value of the wrong kind inside the plan and grasp sections is reported at its field.
    let held = r#""rod": {"length": 1.0, "flexural_rigidity": 1.0},
        "constraints": [{"type": "orientation", "s": 0.0, "theta": 0.0}]"#;
    for (section, needle) in [
        (
            r#""plan": {"start": {"x": 0.3, "z": 0.9}, "goal": "up"}"#,
            "field `plan.goal`: invalid type: string \"up\", expected an object: the end's pose",
        ),
        (
            r#""plan": {"start": {"position": [0.3, 0, "high"]}, "goal": {"x": -0.3, "z": 0.9}}"#,
            "field `plan.start.position[2]`: invalid type: string \"high\"",
        ),
        (
            r#""plan": {"start": {"x": 0.3, "z": 0.9}, "goal": {"x": -0.3, "z": 0.9}, "sharpness": [10, "x"]}"#,
            "field `plan.sharpness[1]`: invalid type: string \"x\"",
        ),
        (
            r#""grasp": {"directions": "all"}"#,
            "field `grasp.directions`: expected a count or a list of vectors of numbers",
        ),
    ] {
        let case = dir.join("wrong_kind.json");
        std::fs::write(&case, format!("{{{held}, {section}}}")).unwrap();
        let cmd = if section.contains("grasp") {
            "margin"
        } else {
            "plan"
        };
        let (code, out, err) = run(&[cmd, case.to_str().unwrap(), "--log-dir", logs_s]);
        assert_eq!(code, 2, "{err}");
        assert!(out.is_empty(), "{out}");
        assert!(
            err.contains("wrong_kind.json") && err.contains(needle),
            "{needle}: {err}"
        );
    }
    let m0 = dir.join("m0.json");
    std::fs::write(
        &m0,
        r#"{"rod": {"length": 1.0, "flexural_rigidity": 1.0},
            "constraints": [{"type": "orientation", "s": 0.0, "theta": 0.0}],
            "plan": {"start": {"x": 0.3, "z": 0.9}, "goal": {"x": -0.3, "z": 0.9}, "path_terms": 0}}"#,
    )
    .unwrap();
    let (code, _, err) = run(&["plan", m0.to_str().unwrap(), "--log-dir", logs_s]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("plan.path_terms") && err.contains("got 0"),
        "{err}"
    );
    let not_mcap = dir.join("not.mcap");
    std::fs::write(&not_mcap, "hello").unwrap();
    for args in [
        vec!["inspect", not_mcap.to_str().unwrap()],
        vec![
            "recover",
            not_mcap.to_str().unwrap(),
            dir.join("fixed.mcap").to_str().unwrap(),
        ],
        vec!["plot", not_mcap.to_str().unwrap()],
        vec!["inspect", dir.join("missing.mcap").to_str().unwrap()],
    ] {
        let (code, _, err) = run(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(
            err.starts_with("error: ") && !err.contains("panicked"),
            "{err}"
        );
    }
    assert!(!dir.join("fixed.mcap").exists(), "no half-written output");
}

/// `dlo plan --json` prints the documented keys, and its exit code tells the three outcomes
/// apart: 0 for a collision-free plan whose replay coincides, 4 when the verification grid
/// finds penetration, 5 when the replay does not coincide (here: it snaps through). The JSON
/// and a readable log are written in every case; the errors name the file.
#[test]
fn plan_prints_documented_json_and_exit_codes() {
    let scratch = crate::common::Scratch::new("dlo-cli-plan");
    let dir = scratch.path();
    let logs = dir.join("logs");
    let logs_s = logs.to_str().unwrap();
    let json = |out: &str| -> serde_json::Value { serde_json::from_str(out).unwrap() };
    let plan_json = |case: &str| run(&["plan", case, "--json", "--log-dir", logs_s]);
    let plan_text = |case: &str| run(&["plan", case, "--log-dir", logs_s]);
    let log_ok = |name: &str| {
        let bytes = std::fs::read(logs.join(format!("{name}.mcap"))).unwrap();
        assert!(bytes.starts_with(b"\x89MCAP0\r\n") && bytes.ends_with(b"\x89MCAP0\r\n"));
    };

    let pillar = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/planning_cases/plan_cable_around_pillar.json"
    );
    let (code, out, err) = plan_json(pillar);
    assert_eq!(code, 0, "{err}");
    let v = json(&out);
    let keys = [
        "status",
        "u_max",
        "u_max_straight",
        "min_clearance",
        "violation",
        "replay",
        "mcap",
        "timing_s",
    ];
    assert_has_keys(&v, "", &keys);
    let keys = [
        "max_deviation_over_l",
        "k_at_max_deviation",
        "u_max",
        "all_stable",
        "coincide",
        "min_clearance",
        "max_contact_force",
        "k_at_max_contact_force",
    ];
    assert_has_keys(&v["replay"], "replay.", &keys);
    assert_has_keys(
        &v["replay"]["steps"][0],
        "replay.steps[0].",
        &["deviation", "clearance", "contact_force"],
    );
    let keys = [
        "start",
        "attempt",
        "status",
        "sampled_u_max",
        "u_max",
        "collision_free",
        "violation",
        "evaluations",
        "tracking_rounds",
        "tracking_rounds_kept",
    ];
    assert_has_keys(&v["starts"][0], "starts[0].", &keys);
    assert!(v["timing_s"]["plan"].as_f64().unwrap() > 0.0);
    assert!(v["timing_s"]["replay"].as_f64().unwrap() > 0.0);
    assert_eq!(v["status"], "planned");
    assert_eq!(v["replay"]["coincide"], true);
    assert!(
        v["mcap"]
            .as_str()
            .unwrap()
            .ends_with("plan_cable_around_pillar.mcap")
    );
    log_ok("plan_cable_around_pillar");
    // The gripper trajectory: in the JSON, one pose per replay step, and the same rows in the
    // CSV next to the log (the header names every column; values round-trip exactly).
    let steps = v["replay"]["steps"].as_array().unwrap().len();
    let poses = v["trajectory"]["poses"].as_array().unwrap();
    assert_eq!(poses.len(), steps);
    assert_has_keys(
        &v["trajectory"],
        "trajectory.",
        &[
            "frame",
            "held",
            "path_length",
            "straight_distance",
            "largest_step",
        ],
    );
    assert_has_keys(
        &poses[0],
        "trajectory.poses[0].",
        &["k", "position", "quaternion", "rotation"],
    );
    let csv_path = v["trajectory_csv"].as_str().unwrap();
    assert!(csv_path.ends_with("plan_cable_around_pillar.trajectory.csv"));
    let csv = std::fs::read_to_string(csv_path).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header.len(), 17);
    assert_eq!(header[0], "k");
    assert!(header[1].starts_with("x [case length unit"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), steps);
    // The same numbers (to 2e-16 relative: serde_json's default float parser can be one unit in
    // the last place off the shortest representation both files print).
    let same = |a: f64, b: &serde_json::Value| {
        let b = b.as_f64().unwrap();
        assert!((a - b).abs() <= 2.3e-16 * b.abs().max(1e-300), "{a} vs {b}");
    };
    for (row, pose) in rows.iter().zip(poses) {
        same(row[0], &pose["k"]);
        for c in 0..3 {
            same(row[1 + c], &pose["position"][c]);
        }
        for c in 0..4 {
            same(row[4 + c], &pose["quaternion"][c]);
        }
    }

    // The paper's scheme as written (21 samples, no margin, no mean energy, no tracking, no
    // refinement, no swept rows) tunnels through the block.
    let mut c: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/planning_cases/plan_paper_planar.json"
        ))
        .unwrap(),
    )
    .unwrap();
    c["name"] = "tunnels".into();
    for (k, val) in [
        ("path_terms", serde_json::json!(3)),
        ("safety_margin", serde_json::json!(0.0)),
        ("sharpness", serde_json::json!([10, 100, 1000])),
        ("starts", serde_json::json!(1)),
        ("k_samples", serde_json::json!(21)),
        ("mean_weight", serde_json::json!(0.0)),
        ("equilibrium_weight", serde_json::json!(0.0)),
        ("sample_refinements", serde_json::json!(0)),
        ("swept_clearance", serde_json::json!(false)),
    ] {
        c["plan"][k] = val;
    }
    let tunnels = dir.join("tunnels.json");
    std::fs::write(&tunnels, c.to_string()).unwrap();
    let (code, out, err) = plan_json(tunnels.to_str().unwrap());
    assert_eq!(code, 4, "{err}");
    let v = json(&out);
    assert_eq!(v["status"], "collision");
    assert!(v["min_clearance"].as_f64().unwrap() < 0.0);
    assert!(err.contains("tunnels.json"), "{err}");
    // `"swept_clearance": false`: no attempt holds the swept rows, though they all tunnel.
    let starts = v["starts"].as_array().unwrap();
    assert!(starts.len() > 1, "{starts:?}");
    for s in starts {
        assert_eq!(s["swept_clearance"], false, "{s}");
        assert_eq!(s["collision_free"], false, "{s}");
    }
    log_ok("tunnels");

    // A buckled arch planned to a turned end: the replay snaps through (tests/integration/planner.rs).
    let snap = dir.join("snap.json");
    std::fs::write(
        &snap,
        r#"{ "name": "snap",
  "rod": { "length": 1.0, "flexural_rigidity": 1.0, "radius": 0.005 },
  "constraints": [ { "type": "orientation", "s": 0.0, "theta": 0.0 } ],
  "plan": {
    "start": { "x": 0.0, "z": 0.8, "theta": 0.0, "shape": { "theta": [0, 0, 1.2, 0, 0, 0, 0, 0, 0, 0] } },
    "goal": { "x": 0.0, "z": 0.8, "theta": 0.8, "shape": { "theta": [0, 0, -1.2, 0, 0, 0, 0, 0, 0, 0] } },
    "k_samples": 21, "fallback_path_terms": [] } }"#,
    )
    .unwrap();
    let (code, out, err) = plan_json(snap.to_str().unwrap());
    assert_eq!(code, 5, "{err}");
    let v = json(&out);
    assert_eq!(v["status"], "planned");
    assert_eq!(v["replay"]["coincide"], false);
    assert!(!v["replay"]["snaps"].as_array().unwrap().is_empty());
    assert!(
        err.contains("snap.json") && err.contains("snap-through"),
        "{err}"
    );
    // The replayed equilibria were checked as the plan, and the report and the message say
    // why they are not one.
    assert_eq!(v["executed_path"], serde_json::Value::Null);
    let why = v["equilibrium_plan"]["reason"].as_str().expect("a reason");
    assert_eq!(v["equilibrium_plan"]["executable"], false);
    assert!(why.contains("snaps through"), "{why}");
    // The message gives their own failure (the first of the report's reason) and counts the
    // retries that failed too; the report lists each, and its reason holds every one.
    let own = why.split("; ").next().unwrap();
    assert!(
        err.contains(&format!(
            "the replayed equilibria are not a plan either: {own}; "
        )),
        "{err}"
    );
    let retries = v["equilibrium_plan"]["retries"]
        .as_array()
        .expect("retries");
    assert!(!retries.is_empty());
    assert!(
        err.contains(&format!("; {} retries failed too (", retries.len())),
        "{err}"
    );
    assert_eq!(v["equilibrium_plan"]["failure"], "snaps_through");
    // Each names the check it failed, which its reason describes, and the message counts
    // them by that kind.
    let describes = |failure: &str| match failure {
        "not_converged" => "replay solves did not converge",
        "snaps_through" => "the replay snaps through",
        "unstable" => "replayed shapes are unstable",
        "ends_elsewhere" => "the replay ends ",
        "enters_obstacle" => "a replayed shape comes ",
        "crosses_itself" => "a replayed shape crosses itself",
        "confirmation" => "the confirmation replay",
        "start_not_converged" => "the start pose's solve did not converge",
        other => panic!("unexpected failure kind {other}"),
    };
    for r in retries {
        let (attempt, reason) = (
            r["attempt"].as_str().unwrap(),
            r["reason"].as_str().unwrap(),
        );
        assert!(
            why.contains(&format!("{attempt}: {reason}")),
            "{r} not in {why}"
        );
        assert!(
            reason.starts_with(describes(r["failure"].as_str().unwrap())),
            "{r}"
        );
    }
    let count = |kind: &str| retries.iter().filter(|r| r["failure"] == kind).count();
    for (kind, named) in [
        ("snaps_through", "snap through"),
        ("not_converged", "stop converging"),
        (
            "ends_elsewhere",
            "end on another equilibrium of the goal pose",
        ),
    ] {
        if count(kind) > 0 {
            assert!(err.contains(&format!("{} {named}", count(kind))), "{err}");
        }
    }
    // The summary lists them one a line.
    let (_, summary, _) = plan_text(snap.to_str().unwrap());
    let r0 = &retries[0];
    assert!(
        summary.contains("  retried, no plan either:\n")
            && summary.contains(&format!(
                "\n    {}: {}\n",
                r0["attempt"].as_str().unwrap(),
                r0["reason"].as_str().unwrap()
            )),
        "{summary}"
    );
    log_ok("snap");
}

/// Exit 3: a solve that runs out of its budget prints its summary (status `iteration_limit`)
/// and says so; exit 1: a log that cannot be created names the file and the system's reason.
#[test]
fn unconverged_solve_and_unwritable_log_exit_codes() {
    let scratch = crate::common::Scratch::new("dlo-cli-codes");
    let dir = scratch.path();
    let shipped = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/planning_cases/pinned_buckling_080.json"
    );
    let mut c: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(shipped).unwrap()).unwrap();
    c["name"] = "budget".into();
    c["solver"]["max_outer"] = 1.into();
    let budget = dir.join("budget.json");
    std::fs::write(&budget, c.to_string()).unwrap();
    let logs = dir.join("logs");
    let (code, out, err) = run(&[
        "shape",
        budget.to_str().unwrap(),
        "--json",
        "--log-dir",
        logs.to_str().unwrap(),
    ]);
    assert_eq!(code, 3, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["status"], "iteration_limit");
    assert!(
        err.contains("budget.json") && err.contains("did not converge"),
        "{err}"
    );
    assert!(logs.join("budget.mcap").exists());

    // A file where the log directory should be.
    let blocker = dir.join("blocker");
    std::fs::write(&blocker, "").unwrap();
    let (code, out, err) = run(&[
        "shape",
        shipped,
        "--log-dir",
        blocker.join("logs").to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(out.is_empty(), "{out}");
    assert!(
        err.contains("pinned_buckling_080.mcap") && err.contains("cannot create the log"),
        "{err}"
    );
    assert!(err.contains("os error"), "the system's reason: {err}");
}

/// Several cases at once: each runs in its own process with its own log, the JSON lines name
/// every file with its exit code and report, and the exit code is the worst case's (here bad
/// input, 2, over success); a folder runs its case files that have the section the command
/// needs.
#[test]
fn many_cases_run_in_parallel_with_the_worst_exit_code() {
    let scratch = crate::common::Scratch::new("dlo-cli-batch");
    let dir = scratch.path();
    let bad = dir.join("bad.json");
    std::fs::write(&bad, r#"{"rod": {"length": -1, "flexural_rigidity": 1}}"#).unwrap();
    let logs = dir.join("logs");
    let paper = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/planning_cases/plan_paper_planar.json"
    );
    let (code, out, err) = run(&[
        "plan",
        paper,
        bad.to_str().unwrap(),
        "--json",
        "--log-dir",
        logs.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("bad.json") && err.contains("rod.length"),
        "{err}"
    );
    let lines: Vec<serde_json::Value> = out
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 2);
    assert_eq!(lines[0]["exit_code"], 0);
    assert_eq!(lines[0]["report"]["status"], "planned");
    assert!(
        lines[0]["file"]
            .as_str()
            .unwrap()
            .ends_with("plan_paper_planar.json")
    );
    assert_eq!(lines[1]["exit_code"], 2);
    assert!(lines[1]["report"].is_null());
    assert!(logs.join("plan_paper_planar.mcap").exists());
    // A folder: only its case files with a `grasp` section run under `dlo margin`.
    let (code, out, err) = run(&[
        "margin",
        concat!(env!("CARGO_MANIFEST_DIR"), "/planning_cases"),
        "--log-dir",
        logs.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("grasp_a_080.json") && out.contains("grasp_b_pinch.json"),
        "{out}"
    );
    assert!(out.contains("2 of 2 cases succeeded"), "{out}");
    assert!(logs.join("grasp_a_080.mcap").exists() && logs.join("grasp_b_pinch.mcap").exists());
}

/// Hostile inputs and outputs get a clean error naming the file or field, a documented exit
/// code and no panic; an input is never written over: empty grasp points and friction
/// coefficients, an absurd search cap, a device for a case file, a picture or a recovered log
/// aimed at its own input; a direction with huge components is normalised, not rejected;
/// stdout on a full device is exit 1, a closed pipe ends the output quietly.
#[test]
fn hostile_inputs_and_outputs_fail_cleanly() {
    let scratch = crate::common::Scratch::new("dlo-cli-hostile");
    let dir = scratch.path();
    let logs = dir.join("logs");
    let logs_s = logs.to_str().unwrap();
    let grasp = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/planning_cases/grasp_a_080.json"
    ))
    .unwrap();
    let with_grasp = |name: &str, section: serde_json::Value| {
        let mut v: serde_json::Value = serde_json::from_str(&grasp).unwrap();
        v["grasp"] = section;
        v["name"] = name.into();
        let p = dir.join(format!("{name}.json"));
        std::fs::write(&p, v.to_string()).unwrap();
        p
    };
    for (name, section, field) in [
        (
            "no_points",
            serde_json::json!({"points": []}),
            "grasp.points",
        ),
        ("no_mu", serde_json::json!({"mu": []}), "grasp.mu"),
        (
            "huge_cap",
            serde_json::json!({"f_max": 1e300}),
            "grasp.f_max",
        ),
    ] {
        let p = with_grasp(name, section);
        let (code, out, err) = run(&["margin", p.to_str().unwrap(), "--log-dir", logs_s]);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(
            err.contains(field) && !err.contains("panicked"),
            "{name}: {err}"
        );
        assert!(out.is_empty());
        if name == "huge_cap" {
            assert!(err.contains("1e300 is more than"), "{err}");
        }
    }
    let p = with_grasp(
        "huge_direction",
        serde_json::json!({"points": [50.0], "mu": [0.5], "directions": [[1e200, 1e200]]}),
    );
    let (code, out, err) = run(&["margin", p.to_str().unwrap(), "--json", "--log-dir", logs_s]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let d = v["direction"][0].as_array().unwrap();
    let h = std::f64::consts::FRAC_1_SQRT_2;
    // [n_z, n_x] = [1e200, 1e200] is the unit vector (x, y, z) = (1, 0, 1)/√2.
    assert!(
        (d[0].as_f64().unwrap() - h).abs() < 1e-15 && (d[2].as_f64().unwrap() - h).abs() < 1e-15
    );

    #[cfg(unix)]
    {
        let (code, _, err) = run(&["shape", "/dev/zero"]);
        assert_eq!(code, 2);
        assert!(err.contains("/dev/zero") && err.contains("device"), "{err}");
        // stdout on a full device.
        let case = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/planning_cases/pinned_buckling_080.json"
        );
        let full = std::fs::File::create("/dev/full").unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_dlo"))
            .args(["shape", case, "--log-dir", logs_s])
            .stdout(full)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1));
        assert!(String::from_utf8_lossy(&out.stderr).contains("stdout"));
        // A closed pipe: the reader goes away before the output is written.
        let mut child = Command::new(env!("CARGO_BIN_EXE_dlo"))
            .args(["shape", case, "--log-dir", logs_s])
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        assert_eq!(out.status.code(), Some(0));
        assert!(!String::from_utf8_lossy(&out.stderr).contains("panicked"));
    }
    // Readers never write over their input.
    let log = logs.join("pinned_buckling_080.mcap");
    let bytes = std::fs::read(&log).unwrap();
    let (code, _, err) = run(&["plot", log.to_str().unwrap(), log.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("overwrite"));
    assert_eq!(std::fs::read(&log).unwrap(), bytes);
    let partial = dir.join("x.mcap.partial");
    std::fs::write(&partial, &bytes).unwrap();
    let fixed = dir.join("x.mcap");
    let (code, _, err) = run(&[
        "recover",
        partial.to_str().unwrap(),
        fixed.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        std::fs::read(&partial).unwrap(),
        bytes,
        "the input was changed"
    );
    let (code, _, err) = run(&["recover", fixed.to_str().unwrap(), fixed.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
}

/// Meshes that bound no solid are rejected naming the mesh, the field and the defect, in
/// `dlo shape` and in `dlo plan` (where a flat or inside-out mesh once surfaced as "no static
/// shape reaches this pose"); a mesh written with per-face vertex copies is accepted.
#[test]
fn meshes_that_bound_no_solid_are_rejected() {
    let scratch = crate::common::Scratch::new("dlo-cli-meshes");
    let dir = scratch.path();
    let root = env!("CARGO_MANIFEST_DIR");
    let cube = std::fs::read_to_string(format!("{root}/planning_cases/meshes/cube.obj")).unwrap();
    let verts: Vec<&str> = cube.lines().filter(|l| l.starts_with("v ")).collect();
    let faces: Vec<&str> = cube.lines().filter(|l| l.starts_with("f ")).collect();
    let obj = |fs: &[String]| format!("{}\n{}\n", verts.join("\n"), fs.join("\n"));
    let flip = |f: &str| {
        let i: Vec<&str> = f.split_whitespace().collect();
        format!("f {} {} {}", i[1], i[3], i[2])
    };
    let all: Vec<String> = faces.iter().map(|f| f.to_string()).collect();
    let flat_verts: Vec<String> = verts
        .iter()
        .map(|v| {
            let c: Vec<&str> = v.split_whitespace().collect();
            format!("v {} {} 0", c[1], c[2])
        })
        .collect();
    // Per-face copies of the vertices (as exporters write them): the same solid.
    let mut copies = String::new();
    for (k, f) in faces.iter().enumerate() {
        for i in f.split_whitespace().skip(1) {
            copies += verts[i.parse::<usize>().unwrap() - 1];
            copies += "\n";
        }
        copies += &format!("f {} {} {}\n", 3 * k + 1, 3 * k + 2, 3 * k + 3);
    }
    let meshes = [
        ("open", obj(&all[..all.len() - 1]), "not closed"),
        (
            "inside_out",
            obj(&faces.iter().map(|f| flip(f)).collect::<Vec<_>>()),
            "inside-out",
        ),
        (
            "one_flipped",
            obj(&[&[flip(faces[0])], &all[1..]].concat()),
            "wound the same way",
        ),
        (
            "doubled",
            obj(&[&all[..], &all[..1]].concat()),
            "more than two triangles",
        ),
        (
            "flattened",
            format!("{}\n{}\n", flat_verts.join("\n"), all.join("\n")),
            "more than two triangles",
        ),
        // A two-sided triangle: closed and consistent, but it encloses nothing.
        (
            "flat",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf 1 3 2\n".to_string(),
            "no volume",
        ),
        (
            "sliver",
            obj(&[&all[..], &["f 1 1 2".to_string()]].concat()),
            "zero area",
        ),
    ];
    let plan = std::fs::read_to_string(format!("{root}/planning_cases/plan_cable_past_mesh.json"))
        .unwrap();
    for (name, text, needle) in &meshes {
        std::fs::write(dir.join(format!("{name}.obj")), text).unwrap();
        let mut v: serde_json::Value = serde_json::from_str(&plan).unwrap();
        v["obstacles"][0]["shape"]["obj"] = format!("{name}.obj").into();
        v["name"] = format!("mesh_{name}").into();
        let p = dir.join(format!("mesh_{name}.json"));
        std::fs::write(&p, v.to_string()).unwrap();
        for cmd in ["shape", "plan"] {
            let (code, out, err) =
                run(&[cmd, p.to_str().unwrap(), "--log-dir", dir.to_str().unwrap()]);
            assert_eq!(code, 2, "{name} ({cmd}): {err}");
            assert!(
                err.contains(&format!("{name}.obj"))
                    && err.contains("obstacles[0].shape.obj")
                    && err.contains(needle),
                "{name} ({cmd}): {err}"
            );
            assert!(
                out.is_empty() && !err.contains("panicked"),
                "{name}: {out}{err}"
            );
        }
    }
    std::fs::write(dir.join("copies.obj"), copies).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&plan).unwrap();
    v["obstacles"][0]["shape"]["obj"] = "copies.obj".into();
    let p = dir.join("mesh_copies.json");
    std::fs::write(&p, v.to_string()).unwrap();
    let (code, _, err) = run(&[
        "shape",
        p.to_str().unwrap(),
        "--log-dir",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "per-face vertex copies: {err}");
}

/// Sizes and magnitudes that would make a run take unbounded time or overflow its arithmetic are
/// refused before any work starts (exit 2, naming the field); duplicate keys inside `plan` and
/// `grasp` are refused like those at the top level; names that cannot name a file are refused
/// at validation; suspicious but legal values run with a warning; an end placed inside an
/// obstacle names the obstacle.
#[test]
fn limits_warnings_and_blocked_poses_are_reported_before_work() {
    let scratch = crate::common::Scratch::new("dlo-cli-limits");
    let dir = scratch.path();
    let root = env!("CARGO_MANIFEST_DIR");
    let read = |n: &str| -> serde_json::Value {
        serde_json::from_str(
            &std::fs::read_to_string(format!("{root}/planning_cases/{n}")).unwrap(),
        )
        .unwrap()
    };
    let write = |name: &str, v: &serde_json::Value| {
        let p = dir.join(format!("{name}.json"));
        std::fs::write(&p, v.to_string()).unwrap();
        p
    };
    let logs = dir.join("logs");
    let logs = logs.to_str().unwrap();
    let set = |base: &str, edit: &dyn Fn(&mut serde_json::Value)| {
        let mut v = read(base);
        edit(&mut v);
        v
    };
    let pinned = "pinned_buckling_080.json";
    let refused: Vec<(&str, &str, serde_json::Value, &str)> = vec![
        (
            "nodes",
            "shape",
            set(pinned, &|v| {
                v["discretisation"] = serde_json::json!({"panels": 2000, "gauss_points": 16})
            }),
            "discretisation.panels",
        ),
        (
            "self_contact_samples",
            "shape",
            set("self_contact_crossed_loop.json", &|v| {
                v["discretisation"]["samples"] = 2000.into()
            }),
            "discretisation.samples",
        ),
        (
            "rigidity",
            "shape",
            set(pinned, &|v| v["rod"]["flexural_rigidity"] = 1e300.into()),
            "rod.flexural_rigidity",
        ),
        (
            "coefficients",
            "shape",
            set(
                pinned,
                &|v| v["shape"] = serde_json::json!({"theta": [1e300, 0, 0, 0, 0, 0, 0, 0, 0, 0]}),
            ),
            "shape.theta[0]",
        ),
        (
            "report_points",
            "shape",
            set(pinned, &|v| v["report_points"] = vec![0.5; 3000].into()),
            "report_points",
        ),
        (
            "outer",
            "shape",
            set(pinned, &|v| {
                v["solver"] = serde_json::json!({"max_outer": 1000000})
            }),
            "solver.max_outer",
        ),
        (
            "long_name",
            "shape",
            set(pinned, &|v| v["name"] = "n".repeat(300).into()),
            "name",
        ),
        (
            "nul_name",
            "shape",
            set(pinned, &|v| v["name"] = "a\u{0}b".into()),
            "name",
        ),
        (
            "safety",
            "plan",
            set("plan_paper_planar.json", &|v| {
                v["plan"]["safety_margin"] = 1.0.into()
            }),
            "plan.safety_margin",
        ),
        (
            "verify_grid",
            "plan",
            set("plan_paper_planar.json", &|v| {
                v["plan"]["verify_k_samples"] = 100001.into();
                v["plan"]["verify_s_samples"] = 10000.into();
            }),
            "plan.verify_k_samples",
        ),
        (
            "directions",
            "margin",
            set("grasp_a_080.json", &|v| {
                v["grasp"]["directions"] = vec![serde_json::json!([1.0, 0.0]); 1000].into()
            }),
            "grasp.directions",
        ),
        (
            "limits",
            "margin",
            set("grasp_a_080.json", &|v| {
                v["grasp"]["points"] = (1..5000)
                    .map(|i| i as f64 / 5000.0 * 100.0)
                    .collect::<Vec<_>>()
                    .into();
                v["grasp"]["directions"] = 360.into();
            }),
            "grasp.points",
        ),
    ];
    for (name, cmd, v, field) in &refused {
        let p = write(name, v);
        let (code, out, err) = run(&[cmd, p.to_str().unwrap(), "--log-dir", logs]);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(
            err.contains(field) && err.contains(&format!("{name}.json")),
            "{name}: {err}"
        );
        assert!(
            out.is_empty() && !err.contains("panicked"),
            "{name}: {out}{err}"
        );
    }
    // Duplicate keys inside sections kept as JSON values.
    let paper =
        std::fs::read_to_string(format!("{root}/planning_cases/plan_paper_planar.json")).unwrap();
    let dup = paper.replacen("\"plan\": {", "\"plan\": {\"starts\": 1, \"starts\": 2,", 1);
    assert_ne!(dup, paper);
    let p = dir.join("dup.json");
    std::fs::write(&p, dup).unwrap();
    let (code, _, err) = run(&["plan", p.to_str().unwrap(), "--log-dir", logs]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("duplicate field `starts`"), "{err}");
    // Degrees where radians are meant: a warning that says what was assumed, then the run.
    let p = write(
        "degrees",
        &set("plan_paper_planar.json", &|v| {
            v["plan"]["goal"]["theta"] = 90.0.into()
        }),
    );
    let (_, _, err) = run(&["plan", p.to_str().unwrap(), "--log-dir", logs]);
    assert!(
        err.contains("warning") && err.contains("plan.goal.theta") && err.contains("1.570796"),
        "{err}"
    );
    // An end inside the paper case's block names the block.
    let p = write(
        "inside",
        &set("plan_paper_planar.json", &|v| {
            v["plan"]["goal"] = serde_json::json!({"x": 0.0, "z": 0.9, "theta": 0.0})
        }),
    );
    let (code, out, err) = run(&["plan", p.to_str().unwrap(), "--log-dir", logs, "--json"]);
    assert_eq!(code, 6, "{err}");
    assert!(
        err.contains("plan.goal") && err.contains("inside obstacle 'block'"),
        "{err}"
    );
    let report: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(report["verdict"], "unreachable", "{out}");
    assert_eq!(report["end"], "goal", "{out}");
}

/// Extreme numbers in an error are written in exponent notation: the message stays short
/// (Rust writes 1e300 plainly with 301 digits).
#[test]
fn extreme_numbers_in_errors_are_written_short() {
    let scratch = crate::common::Scratch::new("dlo-cli-extreme");
    let dir = scratch.path();
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/planning_cases/plan_paper_planar.json"
    ))
    .unwrap();
    type Edit<'a> = &'a dyn Fn(&mut serde_json::Value);
    let cases: [(&str, Edit, &str, &str); 4] = [
        (
            "margin",
            &|v| v["plan"]["safety_margin"] = 1e300.into(),
            "plan.safety_margin",
            "got 1e300",
        ),
        (
            "radius",
            &|v| v["rod"]["radius"] = (-1e-300).into(),
            "rod.radius",
            "got -1e-300",
        ),
        (
            "length",
            &|v| v["rod"]["length"] = (-1e200).into(),
            "rod.length",
            "got -1e200",
        ),
        (
            "stop",
            &|v| v["plan"]["equilibrium_stop"] = 1e30.into(),
            "plan.equilibrium_stop",
            "got 1e30",
        ),
    ];
    for (name, edit, field, value) in cases {
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        edit(&mut v);
        let p = dir.join(format!("{name}.json"));
        std::fs::write(&p, v.to_string()).unwrap();
        let logs = dir.join("logs");
        let (code, out, err) = run(&[
            "plan",
            p.to_str().unwrap(),
            "--log-dir",
            logs.to_str().unwrap(),
        ]);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(out.is_empty());
        assert!(err.contains(field) && err.contains(value), "{name}: {err}");
        assert!(err.len() < 300, "{name}: {} characters: {err}", err.len());
    }
}
