//! The scene bad-input corpus (tests/bad_input/scene/): every spec listed in EXPECTED.txt is
//! refused by `Scene::load` with one message naming the file and containing the expected
//! fragment, without a panic; and a frame index out of range is refused with the valid range.

use std::path::{Path, PathBuf};

use sortsim::scene::{Scene, SceneError};

fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_input/scene")
}

/// (spec file, fragment) pairs; every .json file in the folder must be listed and vice versa.
fn corpus() -> Vec<(PathBuf, String)> {
    let dir = corpus_dir();
    let text = std::fs::read_to_string(dir.join("EXPECTED.txt")).unwrap();
    let cases: Vec<(PathBuf, String)> = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let (file, fragment) = l.split_once(": ").expect("lines are `file: fragment`");
            (dir.join(file), fragment.to_string())
        })
        .collect();
    let mut listed: Vec<PathBuf> = cases.iter().map(|(f, _)| f.clone()).collect();
    let mut present: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    listed.sort();
    present.sort();
    assert_eq!(
        listed, present,
        "every corpus spec has an expectation and every expectation a spec"
    );
    cases
}

fn check(file: &Path, fragment: &str) {
    let err = match Scene::load(file) {
        Ok(_) => panic!(
            "{}: loaded, but should be refused with {fragment:?}",
            file.display()
        ),
        Err(e) => e.to_string(),
    };
    eprintln!("{err}");
    assert!(
        err.contains(fragment),
        "{}: expected {fragment:?} in: {err}",
        file.display()
    );
    let spec_name = file.file_name().unwrap().to_string_lossy();
    let names_a_file = err.contains(&*spec_name) || err.contains(".obj");
    assert!(names_a_file, "the message names the file: {err}");
    assert_eq!(err.lines().count(), 1, "one line: {err}");
}

#[test]
fn every_bad_scene_spec_is_refused_with_its_message() {
    let cases = corpus();
    assert!(cases.len() >= 10);
    for (file, fragment) in cases {
        check(&file, &fragment);
    }
}

#[test]
fn frame_index_out_of_range_names_the_valid_range() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/p000-letter-b.json");
    let scene = Scene::load(&file).unwrap();
    assert_eq!(scene.frame_count(), 20);
    assert!(scene.frame(19).is_ok());
    let err = scene.frame(20).unwrap_err();
    assert!(
        matches!(
            err,
            SceneError::FrameOutOfRange {
                frame: 20,
                count: 20,
                ..
            }
        ),
        "{err:?}"
    );
    let msg = err.to_string();
    assert!(
        msg.contains("p000-letter-b.json")
            && msg.contains("frame 20 is out of range")
            && msg.contains("valid 0..=19"),
        "{msg}"
    );
}
