//! JSON Schemas of the spec files, generated from the same serde types that read them (so a
//! field, a default or an allowed value is declared once), for editors to complete and check
//! specs as they are written. `sortsim schema KIND` prints one; `schemas/` ships them all.
//!
//! Owns the list of spec kinds and their schema text. Must never be a second description of a
//! spec: everything here comes from the types' derives and doc comments.

use crate::net::pattern::Pattern;
use crate::spec::machine::MachineSpec;
use crate::spec::run::RunSpec;
use crate::spec::scene::SceneSpec;
use crate::sweep::spec::SweepSpec;

/// The spec kinds, in the order `schemas/` lists them; `options` is the algorithms' options
/// (a run spec's `set`), one definition per algorithm.
pub const KINDS: [&str; 6] = ["machine", "scene", "run", "sweep", "pattern", "options"];

/// The schema of spec kind `kind` as pretty JSON with a final newline; `None` for an unknown
/// kind.
pub fn schema_json(kind: &str) -> Option<String> {
    let schema = match kind {
        "machine" => schemars::schema_for!(MachineSpec),
        "scene" => schemars::schema_for!(SceneSpec),
        "run" => schemars::schema_for!(RunSpec),
        "sweep" => schemars::schema_for!(SweepSpec),
        "pattern" => schemars::schema_for!(Pattern),
        "options" => return Some(pretty(&options_schema())),
        _ => return None,
    };
    Some(pretty(&schema))
}

/// Every algorithm's options: `$defs` keyed by algorithm id.
fn options_schema() -> serde_json::Value {
    use crate::algo::AlgorithmId;
    // Each algorithm's value types ($refs to "#/$defs/...") move up to the top, beside the
    // algorithms, so every reference resolves from the document's root.
    let mut defs = serde_json::Map::new();
    for a in AlgorithmId::ALL {
        let mut schema = a.options_schema();
        if let Some(obj) = schema.as_object_mut() {
            obj.remove("$schema");
            if let Some(serde_json::Value::Object(types)) = obj.remove("$defs") {
                defs.extend(types);
            }
        }
        defs.insert(a.id().to_string(), schema);
    }
    serde_json::json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "Algorithm options",
        "description": "The options each algorithm takes through --set KEY=VALUE or a run spec's \"set\" object (values are strings there); one definition per algorithm id.",
        "$defs": defs,
    })
}

/// The fields the machine spec allows in the object at `path` (`[]`: the top level; `["network",
/// "node"]`: a node's), sorted; `None` when `path` does not name an object of the schema.
pub fn machine_fields_at(path: &[&str]) -> Option<Vec<String>> {
    let schema = serde_json::to_value(schemars::schema_for!(MachineSpec)).ok()?;
    let mut here = object_schema(&schema, &schema)?;
    for key in path {
        here = object_schema(&schema, here.get("properties")?.get(*key)?)?;
    }
    let mut fields: Vec<String> = here
        .get("properties")?
        .as_object()?
        .keys()
        .cloned()
        .collect();
    fields.sort();
    Some(fields)
}

/// `node` as an object schema: itself, the definition it refers to, or the one alternative of
/// an optional field (`anyOf` a definition and null) that is an object.
fn object_schema<'a>(
    root: &'a serde_json::Value,
    node: &'a serde_json::Value,
) -> Option<&'a serde_json::Value> {
    if node.get("properties").is_some() {
        return Some(node);
    }
    if let Some(name) = node
        .get("$ref")
        .and_then(|r| r.as_str()?.strip_prefix("#/$defs/"))
    {
        return object_schema(root, root.get("$defs")?.get(name)?);
    }
    node.get("anyOf")?
        .as_array()?
        .iter()
        .find_map(|alternative| object_schema(root, alternative))
}

fn pretty(schema: &impl serde::Serialize) -> String {
    let mut text = serde_json::to_string_pretty(schema).expect("a schema serializes");
    text.push('\n');
    text
}

/// The file `schemas/` ships for `kind`.
pub fn file_name(kind: &str) -> String {
    format!("{kind}.schema.json")
}
