//! A run's files: the log written under a partial name, finished and moved into place (also on
//! Ctrl-C and SIGTERM), and other outputs written atomically.

use super::*;

/// The log being written and its final path, finished and moved into place by the Ctrl-C
/// (and SIGTERM) handler.
pub(crate) static ACTIVE_LOG: OnceLock<(SharedWriter, PathBuf)> = OnceLock::new();

/// Set while a plan runs: the first Ctrl-C (or SIGTERM) then asks the planner to stop
/// ([`STOP`]) instead of ending the process, so that the run ends as `interrupted` and
/// finishes its log on its own; a second one ends it at once.
pub(crate) static COOPERATIVE: std::sync::atomic::AtomicBool =
    std::sync::atomic::AtomicBool::new(false);

/// Set by the first Ctrl-C of a plan; the plan's observer reads it.
pub(crate) static STOP: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

pub(crate) use dlo_planner::output::mcap_log::file::partial_path;

/// Opens the log bound for `dir/<name>.mcap` (under [`partial_path`], its header on disk at
/// once) and arms the Ctrl-C and SIGTERM handler to finish it.
pub(crate) fn open_log(dir: &Path, name: &str) -> Result<(SharedWriter, PathBuf), ExitCode> {
    let path = dir.join(format!("{name}.mcap"));
    let shared = dlo_planner::output::mcap_log::file::create(&path).map_err(|e| {
        eprintln!(
            "error: {}: cannot create the log: {}",
            path.display(),
            causes(&e)
        );
        ExitCode::from(EXIT_OUTPUT)
    })?;
    if ACTIVE_LOG.set((shared.clone(), path.clone())).is_ok() {
        let _ = ctrlc::set_handler(|| {
            use std::sync::atomic::Ordering::SeqCst;
            if COOPERATIVE.load(SeqCst) && !STOP.swap(true, SeqCst) {
                return;
            }
            if let Some((w, path)) = ACTIVE_LOG.get() {
                let mut w = dlo_planner::output::mcap_log::lock(w);
                if w.finish().is_ok() {
                    let _ = std::fs::rename(partial_path(path), path);
                }
            }
            eprintln!("interrupted: the log was finished and is readable");
            std::process::exit(EXIT_INTERRUPTED);
        });
    }
    Ok((shared, path))
}

/// Finishes a log and moves it into place; reports failure as exit code 1 and then leaves no
/// half-written file.
pub(crate) fn close_log(w: &SharedWriter, path: &Path) -> Result<(), ExitCode> {
    dlo_planner::output::mcap_log::file::finish(w, path).map_err(|e| {
        eprintln!("error: {}: cannot finish the log: {e}", path.display());
        ExitCode::from(EXIT_OUTPUT)
    })
}

/// Writes `text` to `path` atomically (see [`dlo_planner::output::mcap_log::file`]).
pub(crate) fn write_atomically(path: &Path, text: &str) -> Result<(), ExitCode> {
    dlo_planner::output::mcap_log::file::write_atomically(path, text).map_err(|e| {
        eprintln!("error: {}: cannot write: {e}", path.display());
        ExitCode::from(EXIT_OUTPUT)
    })
}
