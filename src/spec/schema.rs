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

/// The spec kinds, in the order `schemas/` lists them.
pub const KINDS: [&str; 5] = ["machine", "scene", "run", "sweep", "pattern"];

/// The schema of spec kind `kind` as pretty JSON with a final newline; `None` for an unknown
/// kind.
pub fn schema_json(kind: &str) -> Option<String> {
    let schema = match kind {
        "machine" => schemars::schema_for!(MachineSpec),
        "scene" => schemars::schema_for!(SceneSpec),
        "run" => schemars::schema_for!(RunSpec),
        "sweep" => schemars::schema_for!(SweepSpec),
        "pattern" => schemars::schema_for!(Pattern),
        _ => return None,
    };
    let mut text = serde_json::to_string_pretty(&schema).expect("a schema serializes");
    text.push('\n');
    Some(text)
}

/// The file `schemas/` ships for `kind`.
pub fn file_name(kind: &str) -> String {
    format!("{kind}.schema.json")
}
