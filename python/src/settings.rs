//! Settings from Python dicts with the case file's names: each key is set on the defaults in
//! turn, so that an error names the key it concerns.

use crate::errors::input_error;
use pyo3::prelude::*;
use serde::Serialize;
use serde::de::DeserializeOwned;

/// A Python value as JSON (through Python's `json`, refusing NaN and infinities).
pub(crate) fn to_json(value: &Bound<'_, PyAny>, what: &str) -> PyResult<serde_json::Value> {
    let py = value.py();
    let kwargs = pyo3::types::PyDict::new(py);
    kwargs.set_item("allow_nan", false)?;
    let text: String = py
        .import("json")?
        .call_method("dumps", (value,), Some(&kwargs))
        .map_err(|e| input_error(Some(what), format!("not JSON data: {e}")))?
        .extract()?;
    serde_json::from_str(&text).map_err(|e| input_error(Some(what), e.to_string()))
}

/// `T::default()` with the entries of `given` (a dict, or `None` for the defaults) set on it.
pub(crate) fn merged<T: Default + Serialize + DeserializeOwned>(
    given: Option<&Bound<'_, PyAny>>,
    what: &str,
) -> PyResult<T> {
    let Some(given) = given.filter(|g| !g.is_none()) else {
        return Ok(T::default());
    };
    let serde_json::Value::Object(entries) = to_json(given, what)? else {
        return Err(input_error(Some(what), "must be a dict"));
    };
    let mut settings = serde_json::to_value(T::default()).expect("settings serialise");
    let known: Vec<String> = settings
        .as_object()
        .map(|o| o.keys().cloned().collect())
        .unwrap_or_default();
    for (key, value) in entries {
        let Some(slot) = settings.get_mut(&key) else {
            return Err(input_error(
                Some(&key),
                format!("unknown {what} setting; known: {}", known.join(", ")),
            ));
        };
        *slot = value;
        serde_json::from_value::<T>(settings.clone())
            .map_err(|e| input_error(Some(&key), e.to_string()))?;
    }
    Ok(serde_json::from_value(settings).expect("checked key by key"))
}
