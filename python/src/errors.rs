//! Errors as Python exceptions: bad input is an `InputError` (a `ValueError`) carrying the
//! field it concerns and the message; an unreadable file is an `OSError`.

use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    dlo_planner,
    InputError,
    PyValueError,
    "Bad input: `field` names the field (e.g. `rod.length`, `path_terms`, `start`; `None` when \
     the input could not be parsed far enough to name one) and `message` says what is wrong."
);

pyo3::create_exception!(
    dlo_planner,
    UnreachableError,
    InputError,
    "No static shape reaches a plan's start or goal (`field`: `start` or `goal`, `plan.start` \
     or `plan.goal` for a case file) under the problem's constraints and obstacles: nothing \
     was planned. `message` names the obstacle the end lies in or the constraint most violated."
);

/// An [`InputError`] for `field` (none when `None`).
pub(crate) fn input_error(field: Option<&str>, message: impl Into<String>) -> PyErr {
    with_field(InputError::new_err, field, message.into())
}

/// An [`UnreachableError`] for the end `field`.
pub(crate) fn unreachable_error(field: &str, message: impl Into<String>) -> PyErr {
    with_field(UnreachableError::new_err, Some(field), message.into())
}

fn with_field(new: fn(String) -> PyErr, field: Option<&str>, message: String) -> PyErr {
    let text = match field {
        Some(f) => format!("{f}: {message}"),
        None => message.clone(),
    };
    let err = new(text);
    Python::attach(|py| {
        let value = err.value(py);
        let _ = value.setattr("field", field);
        let _ = value.setattr("message", message);
    });
    err
}

/// A case file's error: a field's, a parse error's, or an unreadable file's.
pub(crate) fn case_error(e: dlo_planner::Error) -> PyErr {
    use dlo_planner::Error;
    match e {
        Error::Invalid {
            path,
            field,
            message,
        } => input_error(Some(&field), format!("{}: {message}", path.display())),
        Error::Parse { path, message } => {
            input_error(None, format!("{}: {message}", path.display()))
        }
        Error::Io { .. } => PyOSError::new_err(e.to_string()),
        other => input_error(None, other.to_string()),
    }
}

/// A settings error.
pub(crate) fn settings_error(e: dlo_planner::error::SettingsError) -> PyErr {
    input_error(Some(&e.field), e.message)
}

/// A static problem the builder refused: its item (e.g. `constraint 2`) is the field.
pub(crate) fn build_error(e: dlo_planner::statics::builder::BuildError) -> PyErr {
    input_error(Some(&e.item), e.message)
}

/// A plan that cannot be set up.
pub(crate) fn setup_error(e: dlo_planner::planner::PlanSetupError) -> PyErr {
    use dlo_planner::planner::PlanSetupError;
    match e {
        PlanSetupError::Settings(s) => settings_error(s),
        PlanSetupError::Problem(m) => input_error(Some("problem"), m),
        PlanSetupError::End { end, message } => input_error(Some(end), message),
        PlanSetupError::Unreachable { end, message } => unreachable_error(end, message),
    }
}

/// A log or output file that could not be written.
pub(crate) fn output_error(path: &std::path::Path, message: impl std::fmt::Display) -> PyErr {
    PyOSError::new_err(format!("{}: {message}", path.display()))
}
