//! The hot loops run four doubles wide where the processor has AVX2 (`src/kernels/wide.rs`). Both
//! compilations must give the same results bit for bit: the same plan (every number of the JSON
//! report but the timings), the same static shapes, the same grasp margins. `DLO_NO_AVX2` forces
//! the baseline path. On a processor without AVX2 both runs take the baseline path and the test
//! checks nothing more than reproducibility.

use crate::common::strip;
use std::path::Path;
use std::process::Command;

/// `dlo <cmd> <case> --json` with the log in `target/test-logs/wide/<tag>`, as JSON without the
/// timings and the log's path.
fn run(cmd: &str, case: &str, baseline: bool) -> serde_json::Value {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tag = if baseline { "baseline" } else { "wide" };
    let dir = root.join("target/test-logs/wide").join(tag);
    std::fs::create_dir_all(&dir).unwrap();
    let mut c = Command::new(env!("CARGO_BIN_EXE_dlo"));
    c.arg(cmd)
        .arg(root.join("planning_cases").join(case))
        .arg("--json")
        .arg("--log-dir")
        .arg(&dir);
    if baseline {
        c.env("DLO_NO_AVX2", "1");
    } else {
        c.env_remove("DLO_NO_AVX2");
    }
    let out = c.output().unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    let mut v: serde_json::Value =
        serde_json::from_str(&text).unwrap_or_else(|e| panic!("{cmd} {case}: {e}: {text}"));
    strip(&mut v);
    v
}

#[test]
fn wide_and_baseline_kernels_give_identical_results() {
    for (cmd, case) in [
        ("plan", "plan_paper_planar.json"),
        ("plan", "plan_cable_around_pillar.json"),
        ("shape", "extensible_twist_3d.json"),
        ("margin", "grasp_b_pinch.json"),
    ] {
        let wide = run(cmd, case, false);
        let baseline = run(cmd, case, true);
        assert!(
            wide == baseline,
            "{cmd} {case}: the AVX2 and baseline kernels differ:\n{wide}\n{baseline}"
        );
    }
}
