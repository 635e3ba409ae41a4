//! Golden reports: the JSON report of every shipped case — `dlo shape` for each case file,
//! `dlo plan` for those with a `plan` section, `dlo margin` for those with a `grasp` section —
//! with its timings and file paths removed, compared exactly with `tests/golden/`. A change
//! meant to keep behaviour keeps them identical; a change meant to alter it regenerates them
//!
//!     DLO_UPDATE_GOLDEN=1 cargo test --release --test integration golden::
//!
//! and the diff of `tests/golden/` is reviewed with it.

use crate::common::strip;
use std::path::{Path, PathBuf};
use std::process::Command;

#[test]
fn shipped_reports_match_the_golden_files() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let golden = root.join("tests/golden");
    let logs = root.join("target/test-logs/golden");
    let update = std::env::var_os("DLO_UPDATE_GOLDEN").is_some();
    let mut cases: Vec<PathBuf> = std::fs::read_dir(root.join("planning_cases"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    cases.sort();
    let mut changed = Vec::new();
    let mut compared = 0;
    for case in &cases {
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(case).unwrap()).unwrap();
        let name = case.file_stem().unwrap().to_str().unwrap();
        let mut commands = vec!["shape"];
        if v.get("plan").is_some() {
            commands.push("plan");
        }
        if v.get("grasp").is_some() {
            commands.push("margin");
        }
        for cmd in commands {
            let out = Command::new(env!("CARGO_BIN_EXE_dlo"))
                .arg(cmd)
                .arg(case)
                .arg("--json")
                .arg("--log-dir")
                .arg(&logs)
                .output()
                .unwrap();
            let mut report: serde_json::Value =
                serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
                    panic!(
                        "{cmd} {name}: {e}: {}",
                        String::from_utf8_lossy(&out.stderr)
                    )
                });
            strip(&mut report);
            let text = serde_json::to_string_pretty(&report).unwrap() + "\n";
            let file = golden.join(format!("{name}.{cmd}.json"));
            if update {
                std::fs::create_dir_all(&golden).unwrap();
                std::fs::write(&file, &text).unwrap();
                continue;
            }
            let want = std::fs::read_to_string(&file).unwrap_or_else(|e| {
                panic!("{}: {e} (regenerate: DLO_UPDATE_GOLDEN=1)", file.display())
            });
            compared += 1;
            if want != text {
                changed.push(format!("{cmd} {name}"));
            }
        }
    }
    assert!(
        changed.is_empty(),
        "reports differ from tests/golden/: {changed:?} (a change meant to alter them: DLO_UPDATE_GOLDEN=1 cargo test --release --test integration golden::, and review the diff)"
    );
    assert!(update || compared >= 26, "{compared} reports compared");
}
