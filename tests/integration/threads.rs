//! A plan splits its sampled shapes over `plan.threads` threads; each sample is evaluated into
//! its own slots and the samples are added up in order afterwards, so the report is the same
//! bit for bit on any number of threads: shipped planar and 3D cases, self-contact, and the
//! paper's objective (no travel term, where clear samples' shapes are left out), and swept
//! clearance rows.

use crate::common::strip;
use std::path::Path;
use std::process::Command;

fn report(case: &Path, threads: u32) -> serde_json::Value {
    let logs = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-logs/threads");
    let out = Command::new(env!("CARGO_BIN_EXE_dlo"))
        .arg("plan")
        .arg(case)
        .args(["--json", "--threads", &threads.to_string(), "--log-dir"])
        .arg(&logs)
        .output()
        .unwrap();
    let mut v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{}: {e}: {}",
            case.display(),
            String::from_utf8_lossy(&out.stderr)
        )
    });
    strip(&mut v);
    v
}

#[test]
fn plans_are_the_same_on_one_two_and_three_threads() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = root.join("target/test-logs/threads");
    std::fs::create_dir_all(&dir).unwrap();
    // The paper's case with its objective alone (clear samples' shapes left out), and with
    // swept rows.
    let variant = |name: &str, key: &str, value: serde_json::Value| {
        let paper = root.join("planning_cases/plan_paper_planar.json");
        let mut v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(paper).unwrap()).unwrap();
        v["name"] = name.into();
        v["plan"][key] = value;
        let file = dir.join(format!("{name}.json"));
        std::fs::write(&file, v.to_string()).unwrap();
        file
    };
    let cases = [
        root.join("planning_cases/plan_paper_planar.json"),
        root.join("planning_cases/plan_cable_under_bar.json"),
        root.join("planning_cases/plan_loop_flip.json"),
        variant("threads_paper_objective", "travel_weight", 0.0.into()),
        variant("threads_swept", "swept_clearance", true.into()),
    ];
    for case in &cases {
        let one = report(case, 1);
        assert!(one["u_max"].is_number(), "{}: {one}", case.display());
        for threads in [2, 3] {
            assert!(
                report(case, threads) == one,
                "{}: the report on {threads} threads differs from one thread's",
                case.display()
            );
        }
    }
}

/// `DLO_THREADS` sets the default; a value that is not a number in 1..=256 is bad input (exit
/// 2, naming the variable), before anything is planned or written.
#[test]
fn a_bad_dlo_threads_is_bad_input() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let logs = root.join("target/test-logs/threads_env");
    for bad in ["0", "x", "300"] {
        let out = Command::new(env!("CARGO_BIN_EXE_dlo"))
            .args(["plan", "planning_cases/plan_paper_planar.json", "--log-dir"])
            .arg(&logs)
            .current_dir(root)
            .env("DLO_THREADS", bad)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{bad}: {err}");
        assert!(
            err.contains("DLO_THREADS") && !err.contains("panicked"),
            "{err}"
        );
        assert!(!logs.join("plan_paper_planar.mcap").exists());
    }
}
