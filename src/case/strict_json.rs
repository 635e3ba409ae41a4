//! JSON sections kept as values (`plan`, `grasp`) read like the typed ones: a key written twice
//! in an object is an error instead of the last one silently winning.

use serde::de::{Deserializer, Error as _, MapAccess, SeqAccess, Visitor};
use serde_json::{Map, Value};
use std::fmt;

/// A JSON value in which no object has a key twice.
pub struct StrictValue(pub Value);

impl<'de> serde::Deserialize<'de> for StrictValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(StrictVisitor).map(StrictValue)
    }
}

struct StrictVisitor;

impl<'de> Visitor<'de> for StrictVisitor {
    type Value = Value;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("any JSON value")
    }
    fn visit_bool<E>(self, v: bool) -> Result<Value, E> {
        Ok(Value::Bool(v))
    }
    fn visit_i64<E>(self, v: i64) -> Result<Value, E> {
        Ok(v.into())
    }
    fn visit_u64<E>(self, v: u64) -> Result<Value, E> {
        Ok(v.into())
    }
    fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Value, E> {
        serde_json::Number::from_f64(v)
            .map(Value::Number)
            .ok_or_else(|| E::custom("a number that is not finite"))
    }
    fn visit_str<E>(self, v: &str) -> Result<Value, E> {
        Ok(Value::String(v.to_owned()))
    }
    fn visit_string<E>(self, v: String) -> Result<Value, E> {
        Ok(Value::String(v))
    }
    fn visit_unit<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_none<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_some<D: Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        d.deserialize_any(StrictVisitor)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        let mut v = Vec::new();
        while let Some(StrictValue(x)) = seq.next_element()? {
            v.push(x);
        }
        Ok(Value::Array(v))
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        let mut m = Map::new();
        while let Some(k) = map.next_key::<String>()? {
            let StrictValue(v) = map.next_value()?;
            if m.contains_key(&k) {
                return Err(A::Error::custom(format!("duplicate field `{k}`")));
            }
            m.insert(k, v);
        }
        Ok(Value::Object(m))
    }
}

/// `deserialize_with` for an optional section kept as a value.
/// `null` is an absent section.
pub fn optional<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Value>, D::Error> {
    let v = <StrictValue as serde::Deserialize>::deserialize(d)?.0;
    Ok((!v.is_null()).then_some(v))
}

#[cfg(test)]
mod tests {
    #[derive(serde::Deserialize)]
    struct S {
        #[serde(default, deserialize_with = "super::optional")]
        plan: Option<serde_json::Value>,
    }

    #[test]
    fn duplicate_keys_are_rejected_at_any_depth() {
        let ok: S =
            serde_json::from_str(r#"{"plan": {"a": 1, "b": {"c": [1, {"d": 2}]}}}"#).unwrap();
        assert_eq!(ok.plan.unwrap()["b"]["c"][1]["d"], 2);
        for text in [
            r#"{"plan": {"a": 1, "a": 2}}"#,
            r#"{"plan": {"b": {"c": 1, "c": 1}}}"#,
            r#"{"plan": {"b": [{"d": 1, "d": 2}]}}"#,
        ] {
            let e = serde_json::from_str::<S>(text).err().unwrap().to_string();
            assert!(e.contains("duplicate field"), "{text}: {e}");
        }
        for text in ["{}", r#"{"plan": null}"#] {
            let none: S = serde_json::from_str(text).unwrap();
            assert!(none.plan.is_none());
        }
    }
}
