//! Logs written from Python exactly as the CLI writes them: under a partial name, finished and
//! moved into place (`dlo_planner::output::mcap_log::file`).

use crate::errors::output_error;
use dlo_planner::error::causes;
use dlo_planner::output::mcap_log::{SharedWriter, file};
use dlo_planner::statics::StaticProblem;
use pyo3::prelude::*;
use std::path::{Path, PathBuf};

/// Starts `dir/<name>.mcap`.
pub(crate) fn open(dir: &Path, name: &str) -> PyResult<(SharedWriter, PathBuf)> {
    let path = dir.join(format!("{name}.mcap"));
    let w = file::create(&path).map_err(|e| output_error(&path, causes(&e)))?;
    Ok((w, path))
}

/// Finishes a log started by [`open`].
pub(crate) fn close(w: &SharedWriter, path: &Path) -> PyResult<()> {
    file::finish(w, path).map_err(|e| output_error(path, format!("cannot finish the log: {e}")))
}

/// Logs one static shape as `dlo shape` does; returns the log's path.
pub(crate) fn log_static(
    dir: &Path,
    name: &str,
    p: &StaticProblem,
    a: &[f64],
    metrics: &serde_json::Value,
) -> PyResult<PathBuf> {
    let (w, path) = open(dir, name)?;
    let logged =
        dlo_planner::output::mcap_log::log_static(&w, &p.model, &p.obstacles(), a, metrics);
    if let Err(e) = logged {
        let _ = close(&w, &path);
        return Err(output_error(&path, causes(&e)));
    }
    close(&w, &path)?;
    Ok(path)
}

/// Writes `text` to `path` atomically.
pub(crate) fn write(path: &Path, text: &str) -> PyResult<()> {
    file::write_atomically(path, text).map_err(|e| output_error(path, e))
}
