//! The README and the pages under docs/ test themselves: every `console` block is run by
//! trycmd from an empty folder (the data root is this checkout, as for an installed sortsim)
//! and what it prints is compared with what the page shows; every image a page shows was made
//! by a command on the page (`<!-- made by: FILE -->` after it: the file the commands wrote
//! must be the image, byte for byte) or says it is a measurement (`<!-- measured: ... -->`).
//! `TRYCMD=overwrite cargo test --release --test readme` re-records the pages and images.

use std::path::{Path, PathBuf};

fn manifest_dir() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// README.md and every page under docs/.
fn pages() -> Vec<PathBuf> {
    let mut pages = vec![manifest_dir().join("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(manifest_dir().join("docs"))
        .expect("docs/ exists")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    docs.sort();
    pages.extend(docs);
    pages
}

/// (image as the page links it, the file its commands wrote) for every `made by` image, and
/// panics on an image with neither note.
fn made_images(page: &Path) -> Vec<(PathBuf, String)> {
    let text = std::fs::read_to_string(page).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let mut images = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let Some(start) = line.find("](") else {
            continue;
        };
        if !line.trim_start().starts_with("![") {
            continue;
        }
        let link = &line[start + 2..line.rfind(')').expect("an image link closes")];
        let note = lines.get(i + 1).copied().unwrap_or("");
        if let Some(file) = note
            .strip_prefix("<!-- made by: ")
            .and_then(|n| n.strip_suffix(" -->"))
        {
            images.push((page.parent().unwrap().join(link), file.to_string()));
        } else {
            assert!(
                note.starts_with("<!-- measured: "),
                "{}: the image {link} says neither which command made it nor that it is a measurement",
                page.display()
            );
        }
    }
    images
}

/// `TRYCMD=overwrite`: trycmd has rewritten the copies' outputs; the pages and the images their
/// commands drew are copied back over the originals (a model change that moves answers on
/// purpose re-records them this way, and the diff shows what moved). The pages are copied as
/// they were when the test began, so edits made while it runs are overwritten; trycmd writes
/// what it saw in place of `[..]` and `...`, which must be put back by hand.
fn rerecord(scratch: &Path) {
    for page in pages() {
        std::fs::copy(scratch.join(page.file_name().unwrap()), &page).unwrap();
        for (image, made) in made_images(&page) {
            std::fs::copy(scratch.join(&made), &image)
                .unwrap_or_else(|e| panic!("{}: {made} was not written: {e}", page.display()));
        }
    }
}

#[test]
fn every_command_in_the_readme_and_docs_prints_what_the_page_shows() {
    let scratch = tempfile::tempdir().expect("temporary folder");
    let home = scratch.path().join("home");
    let cases = trycmd::TestCases::new();
    cases
        .register_bin("sortsim", PathBuf::from(env!("CARGO_BIN_EXE_sortsim")))
        .env("SORTSIM_ROOT", manifest_dir().to_str().expect("UTF-8 path"))
        .env("HOME", home.to_str().unwrap());
    // The pages are copied into the empty folder their commands run in.
    for page in pages() {
        let copy = scratch.path().join(page.file_name().unwrap());
        std::fs::copy(&page, &copy).unwrap();
        cases.case(&copy);
    }
    // trycmd runs a page's commands in the process's folder; this test binary holds this one
    // test, so no other test sees the change.
    let before = std::env::current_dir().unwrap();
    std::env::set_current_dir(scratch.path()).unwrap();
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| cases.run()));
    std::env::set_current_dir(before).unwrap();
    if let Err(panic) = outcome {
        std::panic::resume_unwind(panic);
    }
    if std::env::var_os("TRYCMD").is_some_and(|v| v == "overwrite") {
        rerecord(scratch.path());
    }
    for page in &pages() {
        for (image, made) in made_images(page) {
            let written = scratch.path().join(made.clone());
            let shown =
                std::fs::read(&image).unwrap_or_else(|e| panic!("{}: {e}", image.display()));
            let written = std::fs::read(&written)
                .unwrap_or_else(|e| panic!("{}: {made} was not written: {e}", page.display()));
            assert!(
                shown == written,
                "{}: {} is not what the page's commands draw ({made}); copy the new one over it",
                page.display(),
                image.display()
            );
        }
    }
}
