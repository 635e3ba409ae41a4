//! A log's life on disk: written under a partial name of this process's own beside its final
//! path, finished and moved into place, so that a run killed hard leaves the previous run's
//! finished log whole (and its own finished chunks, for [`super::recover`]), and two runs at
//! once never write one file. The CLI and the Python package write every log this way.

use super::{LogError, McapWriter, SharedWriter, lock};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// Where the file bound for `path` is written until it is complete.
pub fn partial_path(path: &Path) -> PathBuf {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(format!(".{}.partial", std::process::id()));
    path.with_file_name(name)
}

/// Starts the log bound for `path` (its folder too) under [`partial_path`], its header on disk
/// at once; on failure nothing is left behind.
pub fn create(path: &Path) -> Result<SharedWriter, LogError> {
    let tmp = partial_path(path);
    let created = McapWriter::create(&tmp).and_then(|mut w| w.flush().map(|()| w));
    match created {
        Ok(w) => Ok(Arc::new(Mutex::new(w))),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

/// Finishes the log started by [`create`] for `path` and moves it into place (once: later
/// calls do nothing). On failure the partial file is removed and the error says why.
pub fn finish(w: &SharedWriter, path: &Path) -> Result<(), String> {
    let tmp = partial_path(path);
    let mut guard = lock(w);
    let was_open = !guard.is_finished();
    let finished = guard.finish().map_err(|e| crate::error::causes(&e));
    drop(guard);
    let moved = match finished {
        Ok(()) if was_open => std::fs::rename(&tmp, path).map_err(|e| e.to_string()),
        other => other,
    };
    moved.inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })
}

/// Writes `text` to `path` through [`partial_path`] moved into place, so that a failed write
/// leaves no half-written file (and an earlier file stays whole until the new one is).
pub fn write_atomically(path: &Path, text: &str) -> std::io::Result<()> {
    let tmp = partial_path(path);
    std::fs::write(&tmp, text)
        .and_then(|()| std::fs::rename(&tmp, path))
        .inspect_err(|_| {
            let _ = std::fs::remove_file(&tmp);
        })
}
