//! Field paths inside `kind`-tagged objects (a scene's `camera`, `motion`, `generator`...).
//!
//! serde reads an internally tagged enum by buffering the object first, so a bad value inside
//! one is reported at the object (`camera`), not at the field (`camera.fov_deg`). `narrow`
//! finds the field from serde's own message: the field it names (unknown or missing), or the
//! one value in the object that is what serde says it did not expect.
//!
//! Owns that narrowing only. Must never change a message or guess: when the value is not
//! unique, the path stays at the object.

use serde_json::Value;

/// The path of the field inside the tagged object at `field` that `message` is about, when
/// `field` is such an object and the field can be told from the message; `None` otherwise.
pub(super) fn narrow(text: &str, field: &str, message: &str) -> Option<String> {
    let document: Value = serde_json::from_str(text).ok()?;
    let object = at_path(&document, field)?.as_object()?;
    if !object.contains_key("kind") {
        return None;
    }
    let join = |rest: &str| {
        if field.is_empty() {
            rest.to_string()
        } else if rest.starts_with('[') {
            format!("{field}{rest}")
        } else {
            format!("{field}.{rest}")
        }
    };
    if let Some(name) = quoted_after(message, "unknown field `")
        .or_else(|| quoted_after(message, "missing field `"))
    {
        return Some(join(name));
    }
    let unexpected = Unexpected::parse(message)?;
    let mut found = Vec::new();
    for (key, value) in object.iter().filter(|(k, _)| k.as_str() != "kind") {
        collect(value, key.clone(), &unexpected, &mut found);
    }
    match found.as_slice() {
        [one] => Some(join(one)),
        _ => None,
    }
}

/// The value serde's message says it did not expect ("invalid type: string \"x\", ...").
enum Unexpected {
    Str(String),
    Number(f64),
    Bool(bool),
    Null,
    Sequence,
    Map,
    Length(usize),
}

impl Unexpected {
    fn parse(message: &str) -> Option<Unexpected> {
        if let Some(rest) = message.strip_prefix("invalid length ") {
            return rest
                .split(',')
                .next()?
                .trim()
                .parse()
                .ok()
                .map(Unexpected::Length);
        }
        let rest = message
            .strip_prefix("invalid type: ")
            .or_else(|| message.strip_prefix("invalid value: "))?;
        let what = rest.rsplit_once(", expected ")?.0;
        if let Some(s) = what.strip_prefix("string ") {
            return serde_json::from_str::<String>(s).ok().map(Unexpected::Str);
        }
        for prefix in ["integer `", "floating point `"] {
            if let Some(n) = what.strip_prefix(prefix) {
                return n.trim_end_matches('`').parse().ok().map(Unexpected::Number);
            }
        }
        match what {
            "boolean `true`" => Some(Unexpected::Bool(true)),
            "boolean `false`" => Some(Unexpected::Bool(false)),
            "null" | "unit value" => Some(Unexpected::Null),
            "sequence" => Some(Unexpected::Sequence),
            "map" => Some(Unexpected::Map),
            _ => None,
        }
    }

    fn matches(&self, value: &Value) -> bool {
        match (self, value) {
            (Unexpected::Str(s), Value::String(v)) => s == v,
            (Unexpected::Number(n), Value::Number(v)) => v.as_f64() == Some(*n),
            (Unexpected::Bool(b), Value::Bool(v)) => b == v,
            (Unexpected::Null, Value::Null) => true,
            (Unexpected::Sequence, Value::Array(_)) => true,
            (Unexpected::Map, Value::Object(_)) => true,
            (Unexpected::Length(n), Value::Array(v)) => v.len() == *n,
            _ => false,
        }
    }
}

/// Every path under `value` (itself included) whose value `unexpected` matches.
fn collect(value: &Value, path: String, unexpected: &Unexpected, found: &mut Vec<String>) {
    if unexpected.matches(value) {
        found.push(path.clone());
    }
    match value {
        Value::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                collect(item, format!("{path}[{i}]"), unexpected, found);
            }
        }
        Value::Object(fields) => {
            for (key, item) in fields {
                collect(item, format!("{path}.{key}"), unexpected, found);
            }
        }
        _ => {}
    }
}

/// The value at a path as serde_path_to_error prints it (`geometry[0].motion`, `.` for the
/// document itself).
fn at_path<'a>(document: &'a Value, path: &str) -> Option<&'a Value> {
    let mut here = document;
    if path.is_empty() || path == "." {
        return Some(here);
    }
    for segment in path.split('.') {
        let (key, indexes) = match segment.find('[') {
            Some(i) => (&segment[..i], &segment[i..]),
            None => (segment, ""),
        };
        if !key.is_empty() {
            here = here.get(key)?;
        }
        for index in indexes.split('[').filter(|s| !s.is_empty()) {
            here = here.get(index.trim_end_matches(']').parse::<usize>().ok()?)?;
        }
    }
    Some(here)
}

/// The text between `prefix` and the next backquote.
fn quoted_after<'a>(message: &'a str, prefix: &str) -> Option<&'a str> {
    let start = message.find(prefix)? + prefix.len();
    let len = message[start..].find('`')?;
    Some(&message[start..start + len])
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = r#"{"camera": {"kind": "perspective", "eye": [0, 0, 3], "fov_deg": "abc"},
        "geometry": [{"motion": {"kind": "tumble", "seed": 1, "axis": [0, 1]}}]}"#;

    #[test]
    fn a_bad_value_in_a_tagged_object_is_found_by_what_serde_did_not_expect() {
        let m = "invalid type: string \"abc\", expected f32";
        assert_eq!(
            narrow(SCENE, "camera", m).as_deref(),
            Some("camera.fov_deg")
        );
        let m = "invalid length 2, expected an array of length 3";
        assert_eq!(
            narrow(SCENE, "geometry[0].motion", m).as_deref(),
            Some("geometry[0].motion.axis")
        );
        let m = "unknown field `fov`, expected one of `eye`, `target`";
        assert_eq!(narrow(SCENE, "camera", m).as_deref(), Some("camera.fov"));
    }

    #[test]
    fn an_ambiguous_value_or_an_untagged_object_keeps_the_path() {
        // Two zeros in `eye`: the path cannot tell which.
        let m = "invalid value: integer `0`, expected a positive number";
        assert_eq!(narrow(SCENE, "camera", m), None);
        assert_eq!(
            narrow(SCENE, "geometry[0]", "invalid type: null, expected x"),
            None
        );
        assert_eq!(narrow("not json", "camera", "missing field `x`"), None);
    }
}
