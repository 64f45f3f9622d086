//! Keeps STYLE.md's habit true for `net/`: every source file opens with a `//!` comment
//! saying what it owns and what it must never do.

use std::path::Path;

fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn every_net_file_opens_with_a_doc_saying_what_it_owns_and_must_never_do() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    rust_files(&root.join("src/net"), &mut files);
    for name in ["benches/net.rs", "tests/net_docs.rs"] {
        files.push(root.join(name));
    }
    assert!(files.len() >= 17, "{files:?}");
    for path in files {
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(
            text.starts_with("//! "),
            "{} has no //! opening",
            path.display()
        );
        let doc: String = text
            .lines()
            .take_while(|l| l.starts_with("//!"))
            .collect::<Vec<_>>()
            .join(" ");
        let says_never = doc.contains("never") || doc.contains("Never");
        assert!(
            says_never || path.ends_with("net_docs.rs"),
            "{}: the opening doc should say what it must never do",
            path.display()
        );
    }
}
