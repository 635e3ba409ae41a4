//! Writing to stdout and describing errors.

/// Set when stdout could not be written (other than a closed pipe): the run then exits with 1.
pub(crate) static STDOUT_FAILED: std::sync::atomic::AtomicBool =
    std::sync::atomic::AtomicBool::new(false);

/// Writes to stdout. A closed pipe (e.g. `dlo shape … | head`) ends the output quietly; any
/// other failure (a full device) is reported and makes the exit code 1.
pub(crate) fn emit(text: &str) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    let written = out.write_all(text.as_bytes()).and_then(|()| out.flush());
    if let Err(e) = written
        && e.kind() != std::io::ErrorKind::BrokenPipe
        && !STDOUT_FAILED.swap(true, std::sync::atomic::Ordering::SeqCst)
    {
        eprintln!("error: stdout: cannot write: {e}");
    }
}

pub(crate) use dlo_planner::error::causes;
