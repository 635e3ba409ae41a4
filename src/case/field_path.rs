//! Reading a case file's JSON so that a value of the wrong kind is reported at its field
//! (`rod.radius`, `obstacles[2].shape`, `plan.goal.position[1]`), not only at a line and
//! column.

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
    fn paths_join_as_written() {
        assert_eq!(join("plan", "goal.x"), "plan.goal.x");
        assert_eq!(join("plan", "[2]"), "plan[2]");
        assert_eq!(join("plan", ""), "plan");
        assert_eq!(join("", "rod.radius"), "rod.radius");
    }
}
