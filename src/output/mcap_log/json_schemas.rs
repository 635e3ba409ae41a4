//! The JSON schemas of the logs' JSON channels, written in the subset Foxglove's JSON-schema
//! reader turns into message definitions (so that the Plot panel and the message-path
//! autocompletion see the fields): every object lists its `properties`; every field has one
//! `type` among `boolean`, `string`, `number`, `integer`, `object` and `array`; an array's
//! `items` are scalars or objects, never arrays. A field without a value is left out of a
//! message (the writer drops `null`s), never written as `null`. Rotation matrices (arrays of
//! arrays, which that reader cannot describe) stay in the messages but not in the schemas:
//! the Raw Messages panel shows them, and the Euler angles next to them are plottable.

use serde_json::{Value, json};
use std::sync::LazyLock;

fn number_array() -> Value {
    json!({"type": "array", "items": {"type": "number"}})
}

fn energy() -> Value {
    json!({"type": "object", "properties": {
        "total": {"type": "number"}, "flexural": {"type": "number"},
        "torsional": {"type": "number"}, "extensional": {"type": "number"},
        "gravitational": {"type": "number"}, "work": {"type": "number"},
        "internal": {"type": "number"}}})
}

fn reaction() -> Value {
    json!({"type": "object", "properties": {
        "constraint": {"type": "string"},
        "s": {"type": "number", "description": "arc length of the constraint (absent for a constraint without one point, e.g. an obstacle's)"},
        "force": number_array(),
        "moment": number_array(),
        "angle_torques": number_array()}})
}

fn pose() -> Value {
    json!({"type": "object", "properties": {
        "s": {"type": "number"},
        "position": number_array(),
        "euler_zyz": number_array()}})
}

/// `/metrics/*`: one shape's energy, clearance and (replay) deviation, stability and
/// violation. `clearance` (no obstacles), `deviation`, `stable` and `violation` (replayed
/// shapes only) are left out of a message where they have no value.
pub static METRICS: LazyLock<Value> = LazyLock::new(|| {
    let mut e = energy();
    e["properties"]
        .as_object_mut()
        .expect("properties")
        .remove("internal");
    json!({
        "type": "object",
        "properties": {
            "k": {"type": "number", "description": "path parameter; log time is t0 + 10 k s"},
            "energy": e,
            "clearance": {"type": "number", "description": "smallest surface gap to an obstacle (absent without obstacles)"},
            "deviation": {"type": "number", "description": "replay: largest distance to the plan's shape (case units)"},
            "stable": {"type": "boolean", "description": "replay: second-order stability (absent when not decided)"},
            "violation": {"type": "number", "description": "replay: constraint violation of the solve (units of L)"}
        }
    })
});

/// `/optimiser/progress`: one outer iteration of the path optimisation.
pub static PROGRESS: LazyLock<Value> = LazyLock::new(|| {
    json!({"type": "object", "properties": {
        "start": {"type": "integer"}, "stage": {"type": "integer", "description": "sharpness stage"},
        "outer": {"type": "integer", "description": "outer iteration of the multiplier method"},
        "smoothed_max": {"type": "number"}, "sampled_max": {"type": "number"},
        "k_worst": {"type": "number"}, "violation": {"type": "number"},
        "rho": {"type": "number", "description": "penalty"}}})
});

/// `/reactions/feasible`: the reactions of one replayed shape.
pub static REACTIONS: LazyLock<Value> = LazyLock::new(|| {
    json!({"type": "object", "properties": {
        "k": {"type": "number"},
        "reactions": {"type": "array", "items": reaction()}}})
});

/// `/metrics/shape`: `dlo shape`'s report (see `docs/cli.md`), rotation matrices and the
/// angles' frame left out of the schema.
pub static SHAPE_REPORT: LazyLock<Value> = LazyLock::new(|| {
    json!({"type": "object", "properties": {
        "case": {"type": "string"}, "status": {"type": "string"},
        "energy": energy(),
        "reactions": {"type": "array", "items": reaction()},
        "balance": {"type": "object", "properties": {
            "force_residual": number_array(), "moment_residual": number_array(),
            "relative": {"type": "number"}}},
        "self_contacts": {"type": "array", "items": {"type": "object", "properties": {
            "s": number_array(), "force": number_array()}}},
        "max_violation": {"type": "number"},
        "kkt_residual": {"type": "number"},
        "stable": {"type": "boolean"},
        "stability": {"type": "string"},
        "min_reduced_eigenvalue": {"type": "number"},
        "neutral_modes": {"type": "integer"},
        "gauge_modes": {"type": "integer"},
        "end_pose": pose(),
        "points": {"type": "array", "items": pose()},
        "coefficients": {"type": "object", "properties": {
            "phi": number_array(), "theta": number_array(), "psi": number_array(),
            "eps": number_array()}},
        "outer_iterations": {"type": "integer"},
        "timing_s": {"type": "number"}}})
});

/// `/grasp/limits`: one point and direction of a margin computation.
pub static GRASP_LIMIT: LazyLock<Value> = LazyLock::new(|| {
    json!({"type": "object", "properties": {
        "s_a": {"type": "number", "description": "point of action (case units)"},
        "direction": number_array(),
        "f_contact_lost": {"type": "number", "description": "where a contact is lost (absent: held up to f_max)"},
        "finger_lost": {"type": "string", "description": "the finger that lets go first (absent: none)"},
        "f_limit": {"type": "array", "items": {"type": "number"}, "description": "F(s_a, n) per friction coefficient"},
        "unconverged": {"type": "integer"}}})
});

/// `value` serialised with every `null` member of an object left out, at any depth (`null`s
/// inside arrays stay: leaving them out would move the entries after them). A view, not a copy:
/// the writer serialises every JSON message through it.
pub struct WithoutNulls<'a>(pub &'a Value);

impl serde::Serialize for WithoutNulls<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::{SerializeMap, SerializeSeq};
        match self.0 {
            Value::Object(m) => {
                let mut map = s.serialize_map(None)?;
                for (k, v) in m.iter().filter(|(_, v)| !v.is_null()) {
                    map.serialize_entry(k, &WithoutNulls(v))?;
                }
                map.end()
            }
            Value::Array(a) => {
                let mut seq = s.serialize_seq(Some(a.len()))?;
                for v in a {
                    seq.serialize_element(&WithoutNulls(v))?;
                }
                seq.end()
            }
            v => v.serialize(s),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Foxglove's JSON-schema reader, rule for rule (`parseJsonSchema` of Foxglove Studio's
    /// MCAP support, the same in Lichtblick): the message definitions it builds, or its error.
    fn foxglove_reads(schema: &Value, path: &str) -> Result<usize, String> {
        if schema["type"] != "object" {
            return Err(format!("{path}: expected \"type\": \"object\""));
        }
        let props = schema["properties"]
            .as_object()
            .ok_or(format!("{path}: no properties"))?;
        let mut fields = 0;
        for (name, f) in props {
            let p = format!("{path}.{name}");
            fields += match f["type"].as_str() {
                Some("boolean" | "string" | "number" | "integer") => 1,
                Some("object") => foxglove_reads(f, &p)?,
                Some("array") => match f["items"]["type"].as_str() {
                    Some("boolean" | "string" | "number" | "integer") => 1,
                    Some("object") => foxglove_reads(&f["items"], &p)?,
                    t => return Err(format!("{p}: unsupported item type {t:?}")),
                },
                _ => return Err(format!("{p}: unsupported type {}", f["type"])),
            };
        }
        Ok(fields)
    }

    #[test]
    fn every_schema_is_one_foxglove_reads() {
        for (name, s, fields) in [
            ("metrics", &*METRICS, 11),
            ("progress", &*PROGRESS, 8),
            ("reactions", &*REACTIONS, 6),
            ("shape report", &*SHAPE_REPORT, 38),
            ("grasp limit", &*GRASP_LIMIT, 6),
        ] {
            assert_eq!(foxglove_reads(s, name), Ok(fields), "{name}");
        }
        // The rules reject what the viewer rejects.
        assert!(foxglove_reads(&json!({"type": "object"}), "bare").is_err());
        let nested = json!({"type": "object", "properties": {"r": {"type": "array", "items": number_array()}}});
        assert!(foxglove_reads(&nested, "nested").is_err());
        let union = json!({"type": "object", "properties": {"c": {"type": ["number", "null"]}}});
        assert!(foxglove_reads(&union, "union").is_err());
    }

    #[test]
    fn nulls_leave_objects_and_stay_in_arrays() {
        let v = json!({"a": null, "b": {"c": null, "d": 1}, "e": [null, {"f": null}]});
        let written = serde_json::to_value(WithoutNulls(&v)).expect("serialises");
        assert_eq!(written, json!({"b": {"d": 1}, "e": [null, {}]}));
    }
}
