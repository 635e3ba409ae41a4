//! `dlo recover`, `dlo inspect` and `dlo plot`: reading logs.

use super::*;

/// The largest log read by `inspect`, `recover` and `plot` (bytes).
pub(crate) const MAX_LOG_BYTES: u64 = 4 << 30;

pub(crate) fn read_file(path: &Path) -> Result<Vec<u8>, ExitCode> {
    case::read_capped(path, MAX_LOG_BYTES).map_err(|e| {
        eprintln!("error: {}: cannot read: {e}", path.display());
        ExitCode::from(EXIT_BAD_INPUT)
    })
}

/// Whether two paths name the same file (an existing one, or the same path as written).
pub(crate) fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
}

pub(crate) fn run_recover(broken: &Path, fixed: &Path) -> ExitCode {
    let bytes = match read_file(broken) {
        Ok(b) => b,
        Err(c) => return c,
    };
    if same_file(broken, fixed) {
        eprintln!(
            "error: {}: the recovered log would overwrite its input: give another FIXED.mcap",
            fixed.display()
        );
        return ExitCode::from(EXIT_BAD_INPUT);
    }
    // Written beside the output under a name of this process's own, never the input's.
    let tmp = partial_path(fixed);
    let out = match std::fs::File::create(&tmp) {
        Ok(f) => std::io::BufWriter::new(f),
        Err(e) => {
            eprintln!("error: {}: cannot create: {e}", tmp.display());
            return ExitCode::from(EXIT_OUTPUT);
        }
    };
    match dlo_planner::output::mcap_log::recover::recover(&bytes, out) {
        Ok(r) => {
            if let Err(e) = std::fs::rename(&tmp, fixed) {
                let _ = std::fs::remove_file(&tmp);
                eprintln!("error: {}: cannot write: {e}", fixed.display());
                return ExitCode::from(EXIT_OUTPUT);
            }
            emit(&format!(
                "recovered {} messages from {} into {}{}\n",
                r.messages,
                broken.display(),
                fixed.display(),
                match (&r.stopped_at, &r.damage) {
                    (Some(s), _) => format!(" (the input was cut short: {s})"),
                    (None, Some(d)) =>
                        format!(" (every message was read; the input is damaged: {d})"),
                    (None, None) => " (the input was complete)".into(),
                }
            ));
            ExitCode::SUCCESS
        }
        // Reading is from memory: an I/O error is the output's.
        Err(mcap::McapError::Io(e)) => {
            let _ = std::fs::remove_file(&tmp);
            eprintln!("error: {}: cannot write: {e}", fixed.display());
            ExitCode::from(EXIT_OUTPUT)
        }
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            eprintln!("error: {}: not an MCAP file: {e}", broken.display());
            ExitCode::from(EXIT_BAD_INPUT)
        }
    }
}

pub(crate) fn run_inspect(file: &Path, json: bool) -> ExitCode {
    use std::fmt::Write;
    let bytes = match read_file(file) {
        Ok(b) => b,
        Err(c) => return c,
    };
    let ins = match dlo_planner::output::mcap_log::inspect::inspect(&bytes) {
        Ok(i) => i,
        Err(e) => {
            eprintln!("error: {}: not an MCAP file: {e}", file.display());
            return ExitCode::from(EXIT_BAD_INPUT);
        }
    };
    if json {
        emit(&format!(
            "{}\n",
            serde_json::to_string_pretty(&ins).expect("inspection serialises")
        ));
        return ExitCode::SUCCESS;
    }
    let mut o = String::new();
    let _ = writeln!(
        o,
        "{}: {} messages, {} s to {} s, {}",
        file.display(),
        ins.messages,
        ins.start_time.map_or(0.0, |t| t as f64 * 1e-9),
        ins.end_time.map_or(0.0, |t| t as f64 * 1e-9),
        if ins.indexed {
            "indexed"
        } else {
            "NOT indexed (run `dlo recover`)"
        }
    );
    for (name, t) in &ins.topics {
        let _ = writeln!(
            o,
            "  {name:28} {:26} {:9} {:7} messages  {:8.3} s .. {:8.3} s",
            t.schema,
            t.encoding,
            t.messages,
            t.first_log_time as f64 * 1e-9,
            t.last_log_time as f64 * 1e-9
        );
    }
    if let Some(s) = &ins.stopped_at {
        let _ = writeln!(o, "  the file ends early: {s}");
    } else if let Some(d) = &ins.damage {
        let _ = writeln!(o, "  every message was read, but the file is damaged: {d}");
    }
    emit(&o);
    ExitCode::SUCCESS
}

pub(crate) fn run_plot(file: &Path, out: &Path) -> ExitCode {
    let bytes = match read_file(file) {
        Ok(b) => b,
        Err(c) => return c,
    };
    let frames = match dlo_planner::output::plot::read_frames(&bytes) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("error: {}: {e}", file.display());
            return ExitCode::from(EXIT_BAD_INPUT);
        }
    };
    let title = file
        .file_stem()
        .map_or("plan".into(), |s| s.to_string_lossy().into_owned());
    match dlo_planner::output::plot::plot(&frames, &title, out) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}: {e}", out.display());
            ExitCode::from(EXIT_OUTPUT)
        }
    }
}
