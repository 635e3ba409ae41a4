//! Generated hostile case files: the shipped cases with values replaced (huge, tiny, negative,
//! zero, non-integral, wrong types, empty and long lists, strings with NUL), keys deleted and
//! sections swapped, and raw text cut or spliced. Reading and validating them (`case::parse`,
//! the `plan` section) and evaluating the start shape must never panic; every error names the
//! file; any case that validates has a finite start energy.
//!
//! Runs for `DLO_FUZZ_SECONDS` (default 2 s; `.ci/run` gives it more) in batches of proptest
//! cases from fixed seeds.

use crate::common;
use dlo_planner::case;
use proptest::prelude::*;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

/// Cases read, and cases that validated (printed, to show the generator reaches past parsing).
static CHECKED: AtomicUsize = AtomicUsize::new(0);
static VALID: AtomicUsize = AtomicUsize::new(0);

fn shipped() -> Vec<(PathBuf, Value)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("planning_cases");
    let mut out: Vec<(PathBuf, Value)> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .map(|p| {
            let v = serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
            (p, v)
        })
        .collect();
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

/// A hostile value.
fn hostile() -> impl Strategy<Value = Value> {
    prop_oneof![
        prop_oneof![
            Just(1e300),
            Just(-1e300),
            Just(1e-300),
            Just(0.0),
            Just(-0.0),
            Just(-1.0),
            Just(0.5),
            Just(90.0),
            Just(1e9),
            Just(2001.0),
            Just(f64::MAX),
            Just(f64::MIN_POSITIVE),
        ]
        .prop_map(|x| serde_json::json!(x)),
        prop_oneof![
            Just(u64::MAX),
            Just(0u64),
            Just(1u64),
            Just(33u64),
            Just(100_000u64)
        ]
        .prop_map(|x| serde_json::json!(x)),
        Just(Value::Null),
        Just(Value::Bool(true)),
        Just(serde_json::json!("")),
        Just(serde_json::json!("a\u{0}b/../x")),
        Just(serde_json::json!([])),
        Just(serde_json::json!({})),
        Just(serde_json::json!([1e300, -1e300, 0.0])),
        (0usize..3000).prop_map(|n| serde_json::json!(vec![0.5; n])),
        Just(serde_json::json!({"start": 1e300, "end": -1.0})),
    ]
}

#[derive(Clone, Debug)]
enum Edit {
    /// Replace the `i`-th node (in document order) by a hostile value.
    Replace(usize, Value),
    /// Delete the `i`-th object member.
    Delete(usize),
    /// Copy the `i`-th node over the `j`-th.
    Copy(usize, usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        4 => (any::<usize>(), hostile()).prop_map(|(i, v)| Edit::Replace(i, v)),
        1 => any::<usize>().prop_map(Edit::Delete),
        1 => (any::<usize>(), any::<usize>()).prop_map(|(i, j)| Edit::Copy(i, j)),
    ]
}

fn count(v: &Value) -> usize {
    1 + match v {
        Value::Array(a) => a.iter().map(count).sum(),
        Value::Object(o) => o.values().map(count).sum(),
        _ => 0,
    }
}

/// The `i`-th node in document order (0 is the root).
fn node(v: &mut Value, i: &mut usize) -> Option<*mut Value> {
    if *i == 0 {
        return Some(v as *mut Value);
    }
    *i -= 1;
    match v {
        Value::Array(a) => a.iter_mut().find_map(|x| node(x, i)),
        Value::Object(o) => o.values_mut().find_map(|x| node(x, i)),
        _ => None,
    }
}

fn get(v: &mut Value, i: usize) -> &mut Value {
    let n = count(v);
    let mut k = i % n;
    // SAFETY: the pointer is to a node of `v`, which is borrowed mutably for the result's life.
    unsafe { &mut *node(v, &mut k).unwrap() }
}

fn apply(base: &Value, edits: &[Edit]) -> Value {
    let mut v = base.clone();
    for e in edits {
        match e {
            Edit::Replace(i, x) => *get(&mut v, i.saturating_add(1)) = x.clone(),
            Edit::Delete(i) => {
                let target = get(&mut v, *i);
                if let Value::Object(o) = target
                    && let Some(k) = o.keys().nth(i % o.len().max(1)).cloned()
                {
                    o.remove(&k);
                }
            }
            Edit::Copy(i, j) => {
                let x = get(&mut v, *i).clone();
                *get(&mut v, j.saturating_add(1)) = x;
            }
        }
    }
    v
}

/// Reads, validates and evaluates `text` as a case at `path`; fails on a panic or an error that
/// does not name the file, or (`json`: the text is JSON) that names neither a field nor what
/// is wrong with the file as a whole (a required section missing, not an object).
fn check(text: &str, path: &Path, json: bool) -> Result<(), TestCaseError> {
    CHECKED.fetch_add(1, Relaxed);
    let named = |e: &dyn std::fmt::Display| {
        let m = e.to_string();
        prop_assert!(m.contains(&*path.to_string_lossy()), "file not named: {m}");
        Ok(())
    };
    match case::parse(text, path) {
        Err(e) => {
            named(&e)?;
            if json && !matches!(e, dlo_planner::Error::Invalid { .. }) {
                let m = e.to_string();
                prop_assert!(
                    ["missing field", "a case file is a JSON object"]
                        .iter()
                        .any(|w| m.contains(w)),
                    "JSON of the wrong kind not named by its field: {m}"
                );
            }
        }
        Ok(c) => {
            VALID.fetch_add(1, Relaxed);
            if c.plan.is_some()
                && let Err(e) = dlo_planner::case::plan::plan_section(&c)
            {
                named(&e)?;
            }
            let mut p = c.problem.clone();
            let ev = dlo_planner::statics::evaluate_shape(&mut p, &c.initial);
            let e = ev.energy;
            prop_assert!(
                [
                    e.flexural,
                    e.torsional,
                    e.extensional,
                    e.gravitational,
                    e.work
                ]
                .iter()
                .all(|x| x.is_finite()),
                "a validated case whose start energy is not finite: {e:?}"
            );
        }
    }
    Ok(())
}

fn budget() -> Duration {
    Duration::from_secs_f64(common::fuzz_seconds() / 2.0)
}

fn run_batches<S: Strategy>(
    name: &str,
    strategy: S,
    test: impl Fn(S::Value) -> Result<(), TestCaseError>,
) {
    let start = Instant::now();
    let cases = common::run_batches(name, 7, 32, budget(), strategy, test);
    eprintln!(
        "{name}: {cases} cases in {:.1} s ({} of {} cases read by both tests validated)",
        start.elapsed().as_secs_f64(),
        VALID.load(Relaxed),
        CHECKED.load(Relaxed)
    );
}

#[test]
fn edited_case_files_never_panic_and_errors_name_the_file() {
    let cases = shipped();
    assert!(cases.len() >= 15);
    let strategy = (0..cases.len(), prop::collection::vec(edit(), 1..5));
    run_batches("edited cases", strategy, |(k, edits)| {
        let (path, base) = &cases[k];
        let v = apply(base, &edits);
        check(&v.to_string(), path, true)
    });
}

#[test]
fn cut_and_spliced_case_text_never_panics() {
    let cases: Vec<(PathBuf, String)> = shipped()
        .into_iter()
        .map(|(p, v)| (p, serde_json::to_string_pretty(&v).unwrap()))
        .collect();
    let strategy = (
        0..cases.len(),
        any::<usize>(),
        any::<usize>(),
        prop::collection::vec(any::<char>(), 0..8),
    );
    run_batches("cut cases", strategy, |(k, at, len, ins)| {
        let (path, text) = &cases[k];
        let chars: Vec<char> = text.chars().collect();
        let a = at % (chars.len() + 1);
        let b = (a + len % 64).min(chars.len());
        let mut t: String = chars[..a].iter().collect();
        t.extend(ins);
        t.extend(&chars[b..]);
        check(&t, path, false)
    });
}
