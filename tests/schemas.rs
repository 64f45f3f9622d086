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
