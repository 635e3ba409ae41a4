//! Generated damage to real logs: bytes flipped, overwritten, inserted, deleted and cut off, in
//! any number and place. `inspect`, `recover` and the plot reader must never panic or abort
//! (an abort, such as a huge allocation, kills this test); any change to a finished log must be
//! reported as damage; what `recover` writes is always a finished, undamaged log holding no
//! more messages than the original.
//!
//! Runs for `DLO_FUZZ_SECONDS` (the two generated tests share it; default 2 s, `.ci/run` gives more) in batches of proptest
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
        |edits| {
            let damaged = apply(base, &edits);
            let result = check(base, messages, &damaged);
            if result.is_err() {
                keep_failure(name, base, &damaged);
            }
            result
        },
    );
    eprintln!(
        "{name}: {cases} damaged logs in {:.1} s",
        start.elapsed().as_secs_f64()
    );
}

/// Writes a failing damaged log and its base (which holds run-dependent log times and
/// timings, so a batch number alone does not reproduce it) under `target/test-logs/hostile/`.
/// Proptest shrinks a failure case by case, so the file left is the smallest failing one.
fn keep_failure(name: &str, base: &[u8], damaged: &[u8]) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-logs/hostile");
    let stem = name.replace(' ', "-");
    let base_path = dir.join(format!("{stem}-base.mcap"));
    let failing = dir.join(format!("{stem}-failing.mcap"));
    static TOLD: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);
    if std::fs::write(&base_path, base).is_ok()
        && std::fs::write(&failing, damaged).is_ok()
        && !TOLD.swap(true, std::sync::atomic::Ordering::Relaxed)
    {
        eprintln!(
            "{name}: failing log kept as {} (its base: {})",
            failing.display(),
            base_path.display()
        );
    }
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

/// Offsets of the top-level records of a finished log with `opcode` (walked by their length
/// fields from the start magic to the data end).
fn records_with_opcode(log: &[u8], opcode: u8) -> Vec<usize> {
    let mut at = 8;
    let mut found = Vec::new();
    while at + 9 <= log.len() {
        let op = log[at];
        if op == 0x0F {
            break; // data end
        }
        if op == opcode {
            found.push(at);
        }
        let len = u64::from_le_bytes(log[at + 1..at + 9].try_into().unwrap());
        at += 9 + len as usize;
    }
    found
}

/// A message index between chunks (it starts with a real channel id) whose opcode is changed to
/// that of a message reads as a message of that channel: the reader must stop there, not count
/// it, and every reader must call the log damaged.
#[test]
fn a_message_index_turned_into_a_message_is_damage() {
    let base = log_of("shape", "planning_cases/pinned_buckling_080.json");
    let messages = inspect(&base).unwrap().messages;
    let indexes = records_with_opcode(&base, 0x07);
    assert!(!indexes.is_empty(), "the log has message indexes");
    for at in indexes {
        let mut b = base.clone();
        b[at] = 0x05;
        let ins = inspect(&b).unwrap();
        assert!(ins.messages <= messages, "{} > {messages}", ins.messages);
        assert!(ins.stopped_at.is_some() && ins.damage.is_some());
        let r = recover(&b, std::io::Cursor::new(Vec::new())).unwrap();
        assert!(r.truncated && r.messages <= messages);
    }
}

/// A footer whose CRC became 0 ("not computed") is checked by where it points: a summary
/// offset start moved outside the file, or the summary start moved off its section, is damage.
#[test]
fn a_footer_without_its_crc_is_checked_by_its_offsets() {
    let base = log_of("shape", "planning_cases/pinned_buckling_080.json");
    let crc_at = base.len() - 8 - 4;
    let offsets_at = crc_at - 8;
    let start_at = offsets_at - 8;
    for (at, value) in [(offsets_at, 1u64 << 63), (offsets_at, 9), (start_at, 9)] {
        let mut b = base.clone();
        b[crc_at..crc_at + 4].fill(0);
        b[at..at + 8].copy_from_slice(&value.to_le_bytes());
        assert!(check_finished(&b).is_err(), "field at {at} set to {value}");
        assert!(inspect(&b).unwrap().damage.is_some());
        let r = recover(&b, std::io::Cursor::new(Vec::new())).unwrap();
        assert!(r.truncated);
    }
    // The CRC alone set to 0 leaves a log with the same contents: still a finished log.
    let mut b = base.clone();
    b[crc_at..crc_at + 4].fill(0);
    assert_eq!(check_finished(&b), Ok(()));
}
