//! Algorithm options come from one typed struct per algorithm: every option `--help` and the
//! schema document is accepted at its documented default, an unknown key is refused with the
//! list of the algorithm's options and their defaults, and a request-balancing option without
//! request balancing is refused by name.

use crate::common;

use std::collections::BTreeMap;
use std::sync::Arc;

use sortsim::algo::{check_options, AlgorithmId};
use sortsim::scene::Scene;
use sortsim::spec::run::RunSpec;

/// Resolves a run of `algo` with `set` and checks its options as a run would; the message of
/// the first refusal (names and values are refused while resolving, before the scene is read;
/// what needs the machine or the scene, by `check_options`).
fn check(algo: AlgorithmId, set: &[(&str, &str)]) -> Result<(), String> {
    let scene = Arc::new(Scene::load(&common::root().join("scenes/spd-teapot.json")).unwrap());
    let (machine, machine_set) = match algo.id() {
        id if id.starts_with("sort-middle") => ("delta.json", &[][..]),
        id => common::sort_last_machine(id),
    };
    let set: BTreeMap<String, String> = machine_set
        .iter()
        .chain(set)
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    let spec = RunSpec {
        schema: None,
        machine: common::root().join("machines").join(machine),
        scene: scene.file().to_path_buf(),
        algo: algo.id().into(),
        procs: 4,
        frames: None,
        seed: 1,
        set,
    };
    let cfg = spec.resolve(Some(scene)).map_err(|e| e.to_string())?;
    check_options(&cfg).map_err(|e| e.to_string())
}

#[test]
fn every_documented_default_is_accepted() {
    for algo in AlgorithmId::ALL {
        let docs = algo.option_docs();
        assert!(docs.iter().any(|d| d.key == "aa"), "{}", algo.id());
        for d in &docs {
            assert!(!d.help.is_empty(), "{} {}: no help", algo.id(), d.key);
            if d.default == "none" {
                continue;
            }
            // The adaptive-only keys need aa=adaptive beside them, the request-balancing
            // ones assign=request.
            let mut set = vec![(d.key.as_str(), d.default.as_str())];
            if d.key.starts_with("aa-") {
                set.push(("aa", "adaptive"));
            }
            if d.key == "split" || d.key == "min-packet" {
                set.push(("assign", "request"));
            }
            check(algo, &set)
                .unwrap_or_else(|e| panic!("{} {}={}: {e}", algo.id(), d.key, d.default));
        }
    }
}

#[test]
fn an_unknown_key_lists_the_options_with_their_defaults() {
    let text = check(AlgorithmId::SortMiddleEllsworth, &[("colour", "red")]).unwrap_err();
    assert!(
        text.contains("sort-middle/ellsworth has no option 'colour'")
            && text.contains("granularity (default 8)")
            && text.contains("two-step (default off)")
            && text.contains("aa (default none)"),
        "{text}"
    );
}

#[test]
fn request_balancing_options_need_request_balancing() {
    let e = check(AlgorithmId::SortLastPc, &[("split", "3")]).unwrap_err();
    assert_eq!(
        e,
        "--set split=3: expected assign=request with it (it applies to request balancing only)"
    );
    check(
        AlgorithmId::SortLastPc,
        &[("assign", "request"), ("split", "3")],
    )
    .unwrap();
    let e = check(AlgorithmId::SortLastSnooping, &[("assign", "request")]).unwrap_err();
    assert!(
        e.contains("only sort-last/df, sort-last/pc and the compositing variants"),
        "{e}"
    );
}

#[test]
fn help_and_schema_list_every_option_of_every_algorithm() {
    let help = AlgorithmId::options_help();
    let schema: serde_json::Value =
        serde_json::from_str(&sortsim::spec::schema::schema_json("options").unwrap()).unwrap();
    for algo in AlgorithmId::ALL {
        assert!(help.contains(&format!("  {}\n", algo.id())));
        let properties = schema["$defs"][algo.id()]["properties"]
            .as_object()
            .unwrap();
        for d in algo.option_docs() {
            assert!(help.contains(&format!("    {} (default {})", d.key, d.default)));
            assert!(properties.contains_key(&d.key), "{} {}", algo.id(), d.key);
        }
        assert_eq!(properties.len(), algo.option_docs().len(), "{}", algo.id());
    }
}
