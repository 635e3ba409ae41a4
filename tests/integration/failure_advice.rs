//! What `dlo plan` advises when a plan fails: the case file's `plan` fields to change, with
//! values beyond those the run already used (the case's and the defaults').

use crate::common::shipped_variant;
use std::process::Command;

/// `dlo plan` on the shipped paper case changed by `edit`, in a fresh folder: its exit code and
/// standard error.
fn plan_variant(tag: &str, edit: impl FnOnce(&mut serde_json::Value)) -> (Option<i32>, String) {
    let mut text = String::new();
    let _ = shipped_variant("plan_paper_planar.json", |v| {
        edit(v);
        text = v.to_string();
    });
    let scratch = crate::common::Scratch::new(&format!("dlo-advice-{tag}"));
    let dir = scratch.path();
    let file = dir.join("case.json");
    std::fs::write(&file, &text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_dlo"))
        .args(["plan", "--log-dir"])
        .arg(&dir)
        .arg(&file)
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The paper's case with three path terms, no fallback counts, no equilibrium tracking and a
/// coincidence tolerance of 0.5 % of L: its plan's replay departs by about 1.8 % of L (exit 5).
/// The advice names more path terms than the run tried (6 and 8, the planar default it left
/// out), more starts than its 2, and tracking, which was off; each with the value the case
/// had.
#[test]
fn a_departure_advises_settings_beyond_those_run() {
    let (code, stderr) = plan_variant("departs", |v| {
        let p = &mut v["plan"];
        p["path_terms"] = serde_json::json!(3);
        p["fallback_path_terms"] = serde_json::json!([]);
        p["equilibrium_weight"] = serde_json::json!(0);
        p["equilibrium_plans"] = serde_json::json!(false);
        p["coincide_tolerance"] = serde_json::json!(0.005);
    });
    assert_eq!(code, Some(5), "{stderr}");
    for advice in [
        "plan.fallback_path_terms: [6, 8]",
        "plan.starts: 4, now 2",
        "plan.equilibrium_weight: 1e4, now off",
    ] {
        assert!(stderr.contains(advice), "{advice}: {stderr}");
    }
}

/// The same with fallback counts [4] and tracking at weight 1000: the advice adds a count
/// beyond the largest tried and a weight ten times the case's.
#[test]
fn the_advice_goes_beyond_the_cases_own_settings() {
    let (code, stderr) = plan_variant("beyond", |v| {
        let p = &mut v["plan"];
        p["path_terms"] = serde_json::json!(3);
        p["fallback_path_terms"] = serde_json::json!([4]);
        p["equilibrium_weight"] = serde_json::json!(1000);
        p["equilibrium_rounds"] = serde_json::json!(1);
        p["equilibrium_plans"] = serde_json::json!(false);
        p["coincide_tolerance"] = serde_json::json!(0.002);
    });
    assert_eq!(code, Some(5), "{stderr}");
    for advice in [
        "plan.fallback_path_terms: [4, 8]",
        "plan.equilibrium_weight: 1e4, now 1e3",
    ] {
        assert!(stderr.contains(advice), "{advice}: {stderr}");
    }
}
