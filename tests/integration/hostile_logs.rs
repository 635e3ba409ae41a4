//! Generated damage to real logs: bytes flipped, overwritten, inserted, deleted and cut off, in
//! any number and place. `inspect`, `recover` and the plot reader must never panic or abort
//! (an abort, such as a huge allocation, kills this test); any change to a finished log must be
//! reported as damage; what `recover` writes is always a finished, undamaged log holding no
//! more messages than the original.
//!
//! Runs for `DLO_FUZZ_SECONDS` (the two generated tests share it; default 8 s, `.ci/run` gives more) in batches of proptest
//! cases from fixed seeds, so a failure names the batch that reproduces it.

use crate::common;
use dlo_planner::output::mcap_log::inspect::inspect;
use dlo_planner::output::mcap_log::reader::check_finished;
use dlo_planner::output::mcap_log::recover::recover;
use proptest::prelude::*;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// A real log: `dlo` run on a shipped case into a folder of this test's own.
fn log_of(command: &str, case: &str) -> Vec<u8> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = root.join("target/test-logs/hostile").join(command);
    std::fs::create_dir_all(&dir).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_dlo"))
        .args([command, root.join(case).to_str().unwrap(), "--log-dir"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stem = Path::new(case).file_stem().unwrap();
    std::fs::read(dir.join(stem).with_extension("mcap")).unwrap()
}

#[derive(Clone, Debug)]
enum Edit {
    Flip(usize, u8),
    Set(usize, u8),
    Insert(usize, Vec<u8>),
    Delete(usize, usize),
    Truncate(usize),
    /// An 8-byte little-endian length written over the file: the field a corrupted record
    /// header most often holds.
    Length(usize, u64),
}

fn edit() -> impl Strategy<Value = Edit> {
    let at = any::<usize>();
    prop_oneof![
        (at, 1u8..=255).prop_map(|(i, b)| Edit::Flip(i, b)),
        (at, any::<u8>()).prop_map(|(i, b)| Edit::Set(i, b)),
        (at, prop::collection::vec(any::<u8>(), 1..64)).prop_map(|(i, v)| Edit::Insert(i, v)),
        (at, 1usize..256).prop_map(|(i, n)| Edit::Delete(i, n)),
        at.prop_map(Edit::Truncate),
        (
            at,
            prop_oneof![Just(u64::MAX), Just(1 << 40), Just(1 << 31), any::<u64>()]
        )
            .prop_map(|(i, n)| Edit::Length(i, n)),
    ]
}

fn apply(base: &[u8], edits: &[Edit]) -> Vec<u8> {
    let mut b = base.to_vec();
    for e in edits {
        let n = b.len().max(1);
        match e {
            Edit::Flip(i, x) => {
                if !b.is_empty() {
                    b[i % n] ^= x;
                }
            }
            Edit::Set(i, x) => {
                if !b.is_empty() {
                    b[i % n] = *x;
                }
            }
            Edit::Insert(i, v) => {
                let at = i % (b.len() + 1);
                b.splice(at..at, v.iter().copied());
            }
            Edit::Delete(i, k) => {
                let at = i % n;
                let end = (at + k).min(b.len());
                b.drain(at.min(end)..end);
            }
            Edit::Truncate(i) => b.truncate(i % n),
            Edit::Length(i, v) => {
                if b.len() >= 8 {
                    let at = i % (b.len() - 7);
                    b[at..at + 8].copy_from_slice(&v.to_le_bytes());
                }
            }
        }
    }
    b
}

/// The properties above for one damaged copy of `base` (which holds `messages` messages).
fn check(base: &[u8], messages: u64, damaged: &[u8]) -> Result<(), TestCaseError> {
    let changed = damaged != base;
    if let Ok(ins) = inspect(damaged) {
        prop_assert!(ins.messages <= messages);
        prop_assert!(
            !changed || ins.damage.is_some() || ins.stopped_at.is_some(),
            "a changed log inspected as undamaged"
        );
    }
    let mut out = std::io::Cursor::new(Vec::new());
    if let Ok(r) = recover(damaged, &mut out) {
        prop_assert!(r.messages <= messages);
        prop_assert!(
            !changed || r.truncated,
            "a changed log recovered as complete"
        );
        let fixed = out.into_inner();
        prop_assert_eq!(check_finished(&fixed), Ok(()));
        let again = inspect(&fixed).unwrap();
        prop_assert_eq!(again.messages, r.messages);
    }
    let _ = dlo_planner::output::plot::read_frames(damaged);
    prop_assert_eq!(check_finished(damaged).is_ok(), !changed);
    Ok(())
}

/// Runs batches of generated damage to `base` until `budget` has passed.
fn fuzz(name: &str, base: &[u8], budget: Duration) {
    let messages = inspect(base).unwrap().messages;
    assert_eq!(
        check_finished(base),
        Ok(()),
        "{name}: the base log is finished"
    );
    let start = Instant::now();
    let cases = common::run_batches(
        name,
        0,
        64,
        budget,
        prop::collection::vec(edit(), 1..6),
        |edits| check(base, messages, &apply(base, &edits)),
    );
    eprintln!(
        "{name}: {cases} damaged logs in {:.1} s",
        start.elapsed().as_secs_f64()
    );
}

fn budget() -> Duration {
    Duration::from_secs_f64(common::fuzz_seconds() / 2.0)
}

#[test]
fn damaged_shape_logs_are_reported_and_never_crash_a_reader() {
    let base = log_of("shape", "planning_cases/pinned_buckling_080.json");
    fuzz("shape log", &base, budget());
}

#[test]
fn damaged_plan_logs_are_reported_and_never_crash_a_reader() {
    let base = log_of("plan", "planning_cases/plan_paper_planar.json");
    fuzz("plan log", &base, budget());
}

/// Every single-byte change of a small finished log is found by the full check, and recover
/// never calls it complete.
#[test]
fn every_single_byte_flip_of_a_log_is_found() {
    let base = log_of("shape", "planning_cases/pinned_buckling_080.json");
    for i in 0..base.len() {
        let mut b = base.clone();
        b[i] ^= 0x01;
        assert!(check_finished(&b).is_err(), "flip at byte {i} not found");
        let r = recover(&b, std::io::Cursor::new(Vec::new()));
        assert!(
            r.map_or(true, |r| r.truncated),
            "flip at byte {i} recovered as complete"
        );
    }
}
