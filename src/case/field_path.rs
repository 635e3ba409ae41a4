//! Reading a case file's JSON so that a value of the wrong kind is reported at its field
//! (`rod.radius`, `obstacles[2].shape.radius`, `plan.goal.position[1]`), not only at a line and
//! column, and the errors of a case file's text ([`file_error`]).

use serde::{Deserialize, Deserializer};

/// `T` read by `de`; on failure, the path of the field it failed at (empty at the top level)
/// and the deserialiser's own error.
pub(crate) fn read<'de, T, D>(de: D) -> Result<T, (String, D::Error)>
where
    T: Deserialize<'de>,
    D: Deserializer<'de>,
{
    serde_path_to_error::deserialize(de).map_err(|e| {
        let path = e.path().to_string();
        // The top level prints as `.`.
        let path = if path == "." { String::new() } else { path };
        (path, e.into_inner())
    })
}

/// `T` read from `value`, the value of the section or field `prefix` (`grasp`, `goal`; empty:
/// the section itself); on failure, the path of the field it failed at, `prefix` included, and
/// serde's message.
pub(crate) fn read_in<T: serde::de::DeserializeOwned>(
    prefix: &str,
    value: serde_json::Value,
) -> Result<T, (String, String)> {
    read(value).map_err(|(field, e)| (join(prefix, &field), e.to_string()))
}

/// The field `path` inside the section `prefix` (`plan` and `goal.x` give `plan.goal.x`);
/// either may be empty.
pub(crate) fn join(prefix: &str, path: &str) -> String {
    match (prefix.is_empty(), path.is_empty()) {
        (_, true) => prefix.to_owned(),
        (true, false) => path.to_owned(),
        (false, false) if path.starts_with('[') => format!("{prefix}{path}"),
        (false, false) => format!("{prefix}.{path}"),
    }
}

/// The value at `path` (as [`read`] gives it: `obstacles[2].shape`) inside `root`.
pub(crate) fn at<'v>(root: &'v serde_json::Value, path: &str) -> Option<&'v serde_json::Value> {
    let mut v = root;
    for part in path.split('.') {
        let (key, indices) = part.split_once('[').map_or((part, ""), |(k, i)| (k, i));
        if !key.is_empty() {
            v = v.get(key)?;
        }
        for index in indices.split('[').filter(|i| !i.is_empty()) {
            v = v.get(index.strip_suffix(']')?.parse::<usize>().ok()?)?;
        }
    }
    Some(v)
}

/// The error of a case file's `text` (at `path`) that failed at the field `field` (empty: the
/// top level) with `e`: a value of the wrong kind, at its field (its message keeps the line and
/// column); text that is not JSON, or JSON that is not an object, as a whole.
pub(crate) fn file_error(
    text: &str,
    path: &std::path::Path,
    field: String,
    e: serde_json::Error,
) -> crate::error::Error {
    use crate::error::Error;
    let field = tagged_field(text, &field, &e).unwrap_or(field);
    // A case is a JSON object. Valid JSON of another kind fails as data, and serde's
    // message for an array ("expected struct CaseFile with 16 elements") names nothing
    // a user wrote.
    let first = text.trim_start().chars().next();
    let mut data = e.classify() == serde_json::error::Category::Data;
    let mut message = e.to_string();
    // In text that is JSON, serde_json reports two kinds of value as syntax errors: a
    // name (`"basis": "paper"`) given as a value of another kind ("expected value"),
    // and a list with more items than its field takes ("trailing characters"). They
    // are data.
    if !data && !field.is_empty() && serde_json::from_str::<serde_json::Value>(text).is_ok() {
        data = true;
        let what = if message.starts_with("expected value") {
            "expected a name (a string), got a value of another kind"
        } else if message.starts_with("trailing characters") {
            "more items than this field takes"
        } else {
            "a value of the wrong kind"
        };
        message = format!("{what} at line {} column {}", e.line(), e.column());
    }
    let object = first.is_none_or(|c| c == '{');
    if !object && data {
        message = format!(
            "a case file is a JSON object (`{{ \"rod\": …, … }}`); this one starts with `{}`",
            first.unwrap_or_default()
        );
    }
    // A value of the wrong kind is reported at its field (the message keeps the line
    // and column); a file that is not JSON, or not an object, as a whole.
    if object && data && !field.is_empty() {
        Error::invalid(path, field, message)
    } else {
        Error::Parse {
            path: path.to_path_buf(),
            message,
        }
    }
}

/// The field inside a constraint or an obstacle's shape that `e` is about, where `field` names
/// the entry (`constraints[0]`, `obstacles[2].shape`): an entry tagged by its `type` is read
/// whole, so serde's error names the entry only. The field is the key whose value alone, with
/// the entry's `type`, gives the same error where the `type` alone does not (a value of the
/// wrong kind, an unknown key); `None` where no key does (a missing field) or `field` is not
/// such an entry.
fn tagged_field(text: &str, field: &str, e: &serde_json::Error) -> Option<String> {
    type Check = fn(serde_json::Value) -> Result<(), serde_json::Error>;
    let check: Check = if field.starts_with("constraints[") && !field.contains('.') {
        |v| serde_json::from_value::<super::ConstraintSpec>(v).map(|_| ())
    } else if field.starts_with("obstacles[") && field.ends_with("].shape") {
        |v| serde_json::from_value::<super::ShapeKind>(v).map(|_| ())
    } else {
        return None;
    };
    let root: serde_json::Value = serde_json::from_str(text).ok()?;
    let entry = at(&root, field)?.as_object()?;
    let tag = entry.get("type")?;
    // serde_json's message without its position (errors from a value have none).
    let message = e.to_string();
    let message = message
        .rsplit_once(" at line ")
        .map_or(message.as_str(), |(m, _)| m);
    let gives = |v: serde_json::Value| check(v).is_err_and(|e| e.to_string() == message);
    // An error the tag alone gives (a missing field) is no key's.
    if gives(serde_json::json!({ "type": tag })) {
        return None;
    }
    entry
        .iter()
        .filter(|(k, _)| *k != "type")
        .find(|(k, v)| gives(serde_json::json!({ "type": tag, *k: v })))
        .map(|(k, _)| format!("{field}.{k}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Inner {
        #[allow(dead_code)]
        x: f64,
    }

    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Outer {
        #[allow(dead_code)]
        items: Vec<Inner>,
    }

    #[test]
    fn a_wrong_value_is_reported_at_its_field() {
        let v = serde_json::json!({"items": [{"x": 1.0}, {"x": "one"}]});
        let (path, e) = read::<Outer, _>(v).unwrap_err();
        assert_eq!(path, "items[1].x");
        assert!(
            e.to_string().contains("invalid type: string \"one\""),
            "{e}"
        );
        let (path, _) = read::<Outer, _>(serde_json::json!({"items": 3})).unwrap_err();
        assert_eq!(path, "items");
        let (path, _) = read::<Outer, _>(serde_json::json!("items")).unwrap_err();
        assert_eq!(path, "");
    }

    #[test]
    fn a_path_finds_its_value() {
        let v = serde_json::json!({"obstacles": [{}, {"shape": {"type": "ball"}}], "m": [[1, 2]]});
        assert_eq!(
            at(&v, "obstacles[1].shape.type"),
            Some(&serde_json::json!("ball"))
        );
        assert_eq!(at(&v, "m[0][1]"), Some(&serde_json::json!(2)));
        assert_eq!(at(&v, "obstacles[2]"), None);
        assert_eq!(at(&v, "m[x]"), None);
    }

    #[test]
    fn paths_join_as_written() {
        assert_eq!(join("plan", "goal.x"), "plan.goal.x");
        assert_eq!(join("plan", "[2]"), "plan[2]");
        assert_eq!(join("plan", ""), "plan");
        assert_eq!(join("", "rod.radius"), "rod.radius");
    }
}
