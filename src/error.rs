//! The library's error type.

use std::path::PathBuf;

/// Errors of the library. Messages name the file, the field and what is wrong.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be read.
    #[error("{path}: cannot read: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The case file is not valid JSON for the case schema.
    #[error("{path}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// serde's message, with line and column.
        message: String,
    },
    /// A field holds a value that is not allowed.
    #[error("{path}: field `{field}`: {message}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// Dotted path of the field, e.g. `rod.length`.
        field: String,
        /// What is wrong.
        message: String,
    },
}

impl Error {
    /// Shorthand for [`Error::Invalid`].
    pub fn invalid(
        path: &std::path::Path,
        field: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Error::Invalid {
            path: path.to_path_buf(),
            field: field.into(),
            message: message.into(),
        }
    }
}

/// A setting out of its range: the field (its name in the settings struct and in a case file's
/// section, e.g. `path_terms` or `sharpness[2]`) and why.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{field}: {message}")]
pub struct SettingsError {
    /// The field.
    pub field: String,
    /// What is wrong.
    pub message: String,
}

impl SettingsError {
    /// The error for `field`.
    pub fn new(field: impl Into<String>, message: impl Into<String>) -> Self {
        SettingsError {
            field: field.into(),
            message: message.into(),
        }
    }

    /// `x` if it is finite, else the error for `field`.
    pub fn finite(field: &str, x: f64) -> Result<f64, SettingsError> {
        if x.is_finite() {
            Ok(x)
        } else {
            Err(SettingsError::new(
                field,
                format!("must be finite, got {}", Num(x)),
            ))
        }
    }

    /// `x` if it is finite and positive, else the error for `field`.
    pub fn positive(field: &str, x: f64) -> Result<f64, SettingsError> {
        if SettingsError::finite(field, x)? > 0.0 {
            Ok(x)
        } else {
            Err(SettingsError::new(
                field,
                format!("must be positive, got {}", Num(x)),
            ))
        }
    }
}

/// A number as an error message writes it: plainly, or in exponent notation where the plain
/// form would be long (Rust writes 1e300 with 301 digits).
#[derive(Clone, Copy, Debug)]
pub struct Num(pub f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if a == 0.0 || !a.is_finite() || (1e-4..1e15).contains(&a) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

/// An error and its chain of causes, `outer: inner: …` (the MCAP crate wraps I/O errors in a
/// generic message whose cause says what went wrong).
pub fn causes(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        text.push_str(&format!(": {s}"));
        source = s.source();
    }
    text
}
