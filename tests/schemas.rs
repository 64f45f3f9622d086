//! The JSON Schemas under schemas/: each equals what `sortsim schema KIND` generates from the
//! spec types, and every bundled spec names (`$schema`) and validates against its kind's
//! schema.

use std::path::Path;

use sortsim::spec::schema::{file_name, schema_json, KINDS};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn shipped_schemas_equal_the_generated_ones() {
    for kind in KINDS {
        let path = root().join("schemas").join(file_name(kind));
        let shipped =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(
            shipped,
            schema_json(kind).unwrap(),
            "{} is stale: regenerate it with `sortsim schema {kind} > {}`",
            path.display(),
            path.display()
        );
    }
}

/// Every `.json` file directly under `dir`, sorted.
fn specs(dir: &str) -> Vec<std::path::PathBuf> {
    let mut files: Vec<_> = std::fs::read_dir(root().join(dir))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no specs in {dir}");
    files
}

#[test]
fn every_bundled_spec_validates_against_its_schema() {
    for (kind, dir) in [
        ("machine", "machines"),
        ("scene", "scenes"),
        ("sweep", "sweeps"),
        ("pattern", "tests/patterns"),
    ] {
        let schema: serde_json::Value = serde_json::from_str(&schema_json(kind).unwrap()).unwrap();
        let validator = jsonschema::validator_for(&schema).expect("the schema compiles");
        for file in specs(dir) {
            let text = std::fs::read_to_string(&file).unwrap();
            let spec: serde_json::Value = serde_json::from_str(&text).unwrap();
            let expected = Path::new(if dir.contains('/') { "../.." } else { ".." })
                .join("schemas")
                .join(file_name(kind));
            assert_eq!(
                spec.get("$schema").and_then(|s| s.as_str()),
                expected.to_str(),
                "{} names its schema for editors",
                file.display()
            );
            let errors: Vec<String> = validator
                .iter_errors(&spec)
                .map(|e| format!("{} at {}", e, e.instance_path()))
                .collect();
            assert!(errors.is_empty(), "{}: {errors:?}", file.display());
        }
    }
}

#[test]
fn a_spec_the_reader_refuses_is_refused_by_the_schema_too() {
    let schema: serde_json::Value = serde_json::from_str(&schema_json("machine").unwrap()).unwrap();
    let validator = jsonschema::validator_for(&schema).unwrap();
    let bad = root().join("tests/bad_input/machine");
    for name in [
        "unknown-field.json",
        "unknown-topology.json",
        "time-as-number.json",
        "missing-network.json",
    ] {
        let spec: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(bad.join(name)).unwrap()).unwrap();
        assert!(!validator.is_valid(&spec), "{name} passed the schema");
    }
}

/// A value at each bound the loaders enforce, and one just past it: an editor with the schema
/// flags exactly what `sortsim check` refuses.
#[test]
fn the_schemas_carry_the_ranges_the_loaders_enforce() {
    use serde_json::{json, Value};
    // (kind, bundled file, JSON pointer, a value at the bound, a value past it)
    let cases: &[(&str, &str, &str, Value, Value)] = &[
        (
            "scene",
            "scenes/spd-teapot.json",
            "/shading/ambient",
            json!(1.0),
            json!(2),
        ),
        (
            "scene",
            "scenes/spd-teapot.json",
            "/shading/diffuse",
            json!(0.0),
            json!(-0.1),
        ),
        (
            "scene",
            "scenes/spd-teapot.json",
            "/camera/fov_deg",
            json!(179.9),
            json!(180),
        ),
        (
            "scene",
            "scenes/spd-teapot.json",
            "/camera/fov_deg",
            json!(0.1),
            json!(0),
        ),
        (
            "scene",
            "scenes/spd-teapot.json",
            "/camera/near",
            json!(1e-6),
            json!(0),
        ),
        (
            "scene",
            "scenes/spd-teapot.json",
            "/resolution/0",
            json!(16384),
            json!(16385),
        ),
        (
            "scene",
            "scenes/spd-teapot.json",
            "/resolution/1",
            json!(1),
            json!(0),
        ),
        (
            "scene",
            "scenes/spd-teapot.json",
            "/geometry/0/color/2",
            json!(1.0),
            json!(1.5),
        ),
        (
            "scene",
            "scenes/spd-teapot.json",
            "/geometry/0/generator/n",
            json!(200),
            json!(201),
        ),
        (
            "machine",
            "machines/snooping-bus.json",
            "/nodes",
            json!(1 << 20),
            json!(1u64 << 40),
        ),
        (
            "machine",
            "machines/snooping-bus.json",
            "/nodes",
            json!(1),
            json!(0),
        ),
    ];
    for (kind, file, pointer, at_bound, past) in cases {
        let schema: Value = serde_json::from_str(&schema_json(kind).unwrap()).unwrap();
        let validator = jsonschema::validator_for(&schema).unwrap();
        let base: Value =
            serde_json::from_str(&std::fs::read_to_string(root().join(file)).unwrap()).unwrap();
        for (value, accepted) in [(at_bound, true), (past, false)] {
            let mut doc = base.clone();
            *doc.pointer_mut(pointer).expect("the pointer names a field") = value.clone();
            assert_eq!(
                validator.is_valid(&doc),
                accepted,
                "{file} with {pointer} = {value}: the schema"
            );
            let dir = tempfile::tempdir().unwrap();
            let edited = dir.path().join(Path::new(file).file_name().unwrap());
            std::fs::write(&edited, serde_json::to_string(&doc).unwrap()).unwrap();
            let loaded = match *kind {
                "scene" => sortsim::spec::scene::load(&edited).map(|_| ()),
                _ => sortsim::spec::machine::load_machine(&edited).map(|_| ()),
            };
            assert_eq!(
                loaded.is_ok(),
                accepted,
                "{file} with {pointer} = {value}: the loader ({loaded:?})"
            );
        }
    }
}
