//! Many cases at once: `dlo plan|shape|margin` given several case files or a folder runs each
//! case in its own `dlo` process (each with its own log), as many at a time as the machine has
//! cores, and prints one summary table at the end (or one JSON line per case with `--json`).
//! The exit code is the worst case's.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};

/// Exit codes from worst to best: interrupted, output, bad input, unreachable start or goal,
/// not converged, collision, not coincident, success.
const SEVERITY: [u8; 8] = [130, 1, 2, 6, 3, 4, 5, 0];

fn severity(code: u8) -> usize {
    SEVERITY
        .iter()
        .position(|&c| c == code)
        .map_or(0, |i| SEVERITY.len() - i)
}

/// The worst of two exit codes (an unknown code counts as the worst).
pub fn worst(a: u8, b: u8) -> u8 {
    if severity(a) >= severity(b) { a } else { b }
}

/// The case files named by `paths`: files as given, and in each folder its `*.json` files
/// (sorted) that have the `section` the command needs (`None`: every case file).
pub fn expand(paths: &[PathBuf], section: Option<&str>) -> Result<Vec<PathBuf>, String> {
    let mut out = Vec::new();
    for p in paths {
        if !p.is_dir() {
            out.push(p.clone());
            continue;
        }
        let entries =
            std::fs::read_dir(p).map_err(|e| format!("{}: cannot read: {e}", p.display()))?;
        let mut files: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|f| f.is_file() && f.extension().is_some_and(|x| x == "json"))
            .collect();
        files.sort();
        let before = out.len();
        for f in files {
            let keep = match section {
                None => true,
                Some(key) => std::fs::read_to_string(&f)
                    .ok()
                    .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
                    .is_some_and(|v| v.get(key).is_some()),
            };
            if keep {
                out.push(f);
            }
        }
        if out.len() == before {
            return Err(format!(
                "{}: no case files{} in this folder",
                p.display(),
                section.map_or(String::new(), |s| format!(" with a `{s}` section"))
            ));
        }
    }
    Ok(out)
}

/// One case's run.
struct Outcome {
    case: PathBuf,
    code: u8,
    json: Option<serde_json::Value>,
    stderr: String,
    seconds: f64,
}

/// Runs `dlo <command> CASE --json <extra…>` for every case, `jobs` at a time, and reports.
pub fn run(
    command: &str,
    cases: &[PathBuf],
    extra: &[String],
    json: bool,
    jobs: usize,
) -> ExitCode {
    let exe = match std::env::current_exe() {
        Ok(e) => e,
        Err(e) => {
            eprintln!("error: cannot find the dlo executable to run the cases: {e}");
            return ExitCode::from(1);
        }
    };
    let jobs = jobs.max(1);
    // Ctrl-C reaches every case's process, which finishes its own log and exits with 130; this
    // process waits for them and reports.
    let _ = ctrlc::set_handler(|| {});
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..jobs.min(cases.len()) {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                    let Some(case) = cases.get(i) else { break };
                    let o = run_one(&exe, command, case, extra);
                    if !o.stderr.is_empty() {
                        for line in o.stderr.lines() {
                            eprintln!("{}: {line}", case.display());
                        }
                    }
                    results
                        .lock()
                        .unwrap_or_else(|p| p.into_inner())
                        .push((i, o));
                }
            });
        }
    });
    // In the order the cases were given.
    let mut results = results.into_inner().unwrap_or_else(|p| p.into_inner());
    results.sort_by_key(|(i, _)| *i);
    let outcomes: Vec<Outcome> = results.into_iter().map(|(_, o)| o).collect();
    let code = outcomes.iter().fold(0, |acc, o| worst(acc, o.code));
    let text = if json {
        json_lines(&outcomes)
    } else {
        table(command, &outcomes, code)
    };
    super::emit(&text);
    ExitCode::from(code)
}

fn run_one(exe: &Path, command: &str, case: &Path, extra: &[String]) -> Outcome {
    let t0 = std::time::Instant::now();
    let out = Command::new(exe)
        .arg(command)
        .arg(case)
        .arg("--json")
        .args(extra)
        .stdin(Stdio::null())
        .output();
    let seconds = t0.elapsed().as_secs_f64();
    match out {
        Ok(o) => Outcome {
            case: case.to_path_buf(),
            // A child killed by a signal (no code) counts as interrupted.
            code: o
                .status
                .code()
                .map_or(130, |c| u8::try_from(c).unwrap_or(1)),
            json: serde_json::from_slice(&o.stdout).ok(),
            stderr: String::from_utf8_lossy(&o.stderr).trim_end().to_string(),
            seconds,
        },
        Err(e) => Outcome {
            case: case.to_path_buf(),
            code: 1,
            json: None,
            stderr: format!("cannot run: {e}"),
            seconds,
        },
    }
}

/// One JSON object per line: `file`, `exit_code` and the case's report (`null` when it wrote
/// none, e.g. on bad input).
fn json_lines(outcomes: &[Outcome]) -> String {
    let mut o = String::new();
    for r in outcomes {
        let line = serde_json::json!({
            "file": r.case.display().to_string(),
            "exit_code": r.code,
            "report": r.json,
        });
        o.push_str(&line.to_string());
        o.push('\n');
    }
    o
}

fn num(v: &serde_json::Value, path: &[&str]) -> Option<f64> {
    path.iter().try_fold(v, |v, k| v.get(k))?.as_f64()
}

/// The summary table: one row per case with what decides it, and the batch's exit code
/// `worst_code`.
fn table(command: &str, outcomes: &[Outcome], worst_code: u8) -> String {
    use std::fmt::Write;
    let mut o = String::new();
    let head = match command {
        "plan" => "U_max      replay d/L  verdict",
        "shape" => "energy U      stable",
        _ => "F_mub at the first mu",
    };
    let width = outcomes
        .iter()
        .map(|r| r.case.display().to_string().len())
        .max()
        .unwrap_or(4)
        .max(4);
    let _ = writeln!(o, "{:width$}  exit  status          {head}  time", "case");
    for r in outcomes {
        let v = r.json.as_ref();
        let status = match v {
            // A margin report has no status: it is a lower bound where the search was capped.
            Some(v) if command == "margin" => {
                if v["capped"]
                    .as_array()
                    .is_some_and(|c| c.iter().any(|x| x == true))
                {
                    "capped"
                } else {
                    "computed"
                }
            }
            Some(v) => v["status"].as_str().unwrap_or("?"),
            None if r.code == 2 => "bad input",
            None => "no report",
        };
        let detail = match (command, v) {
            (_, None) => String::new(),
            ("plan", Some(v)) => format!(
                "{:<10.4e} {:<11.4} {}",
                num(v, &["u_max"]).unwrap_or(f64::NAN),
                num(v, &["replay", "max_deviation_over_l"]).unwrap_or(f64::NAN),
                if v["replay"]["coincide"] == true {
                    "coincide"
                } else {
                    "do not coincide"
                }
            ),
            ("shape", Some(v)) => format!(
                "{:<13.6e} {}",
                num(v, &["energy", "total"]).unwrap_or(f64::NAN),
                v["stable"]
            ),
            (_, Some(v)) => format!(
                "{:.6e}",
                v["f_mub"]
                    .get(0)
                    .and_then(|f| f.as_f64())
                    .unwrap_or(f64::NAN)
            ),
        };
        let _ = writeln!(
            o,
            "{:width$}  {:>4}  {status:15} {detail}  {:.2} s",
            r.case.display().to_string(),
            r.code,
            r.seconds
        );
    }
    let ok = outcomes.iter().filter(|r| r.code == 0).count();
    let _ = writeln!(
        o,
        "{ok} of {} cases succeeded; exit code {worst_code} (the worst case's)",
        outcomes.len()
    );
    o
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn worst_orders_the_codes() {
        assert_eq!(worst(0, 5), 5);
        assert_eq!(worst(5, 4), 4);
        assert_eq!(worst(2, 3), 2);
        assert_eq!(worst(1, 2), 1);
        assert_eq!(worst(130, 1), 130);
        assert_eq!(worst(0, 0), 0);
    }
}
