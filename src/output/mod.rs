//! Files a person or a program reads, written safely: atomic writes (never a half-written
//! file), deterministic JSON, charts (`plot`), HTML pages (`page`), what a command cost the
//! host (`cost`), and the closing line every report command prints. Owns these mechanisms for
//! every layer above; must never know what a run, a sweep or a paper is.

pub mod cost;
pub mod page;
pub mod plot;

use std::io::Write;
use std::path::Path;

/// Writes `bytes` to `path` through a temporary file in the same folder and a rename, so a
/// reader (or an interrupted run) never sees a partial file; temporaries of writers killed
/// before their rename are removed once the file is whole again.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_atomic_with(path, |out| out.write_all(bytes))
}

/// Writes what `fill` writes to `path`, atomically as [`write_atomic`] does, streamed through
/// a buffer: a file larger than what its writer keeps in memory (a run's timeline) is never
/// held whole.
pub fn write_atomic_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    if path.is_dir() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "is a folder; give the name of a file to write",
        ));
    }
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir)?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = dir.join(format!(".{name}.tmp{}", std::process::id()));
    let written = std::fs::File::create(&tmp).and_then(|file| {
        let mut out = std::io::BufWriter::new(file);
        fill(&mut out)?;
        let file = out
            .into_inner()
            .map_err(std::io::IntoInnerError::into_error)?;
        file.sync_all()?;
        drop(file);
        std::fs::rename(&tmp, path)
    });
    if let Err(e) = written {
        // Nothing half-written stays behind, whatever failed.
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    remove_stale_temporaries(dir, &name);
    Ok(())
}

/// Deletes the temporary files an earlier writer of `dir/name` left when it was killed
/// between creating and renaming one (their names carry that writer's process id). Best
/// effort: the report is already whole, so a failure here is not an error.
fn remove_stale_temporaries(dir: &Path, name: &str) {
    let prefix = format!(".{name}.tmp");
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.filter_map(Result::ok) {
        if e.file_name().to_string_lossy().starts_with(&prefix) {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

/// Writes `text` to `dir/name` through [`write_atomic`]; a failure names the file (reported as
/// the plot module's `Io` error, which every report writer returns).
pub fn write_text(dir: &Path, name: &str, text: &str) -> Result<(), plot::PlotError> {
    let path = dir.join(name);
    write_atomic(&path, text.as_bytes()).map_err(|source| plot::PlotError::Io { path, source })
}

/// The line every report command ends with: where the report went, what it cost (`detail`,
/// may be empty) and, when the folder has one, the page to open.
pub fn closing_line(dir: &Path, detail: &str) -> String {
    let page = dir.join("index.html");
    if page.is_file() {
        format!(
            "report written to {}{detail}; page: {}\n",
            dir.display(),
            page.display()
        )
    } else {
        format!("report written to {}{detail}\n", dir.display())
    }
}

/// Pretty JSON with a trailing newline; serde_json keeps struct field order, and every map in
/// a report is a BTreeMap or a Vec, so the text is deterministic.
pub fn to_json<T: serde::Serialize>(value: &T) -> String {
    let mut s = serde_json::to_string_pretty(value).expect("report types serialize");
    s.push('\n');
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A streamed write that fails halfway leaves neither the file nor its temporary, and
    /// keeps the whole file an earlier write left; one that succeeds replaces it whole.
    #[test]
    fn a_failed_stream_leaves_nothing_half_written() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("timeline.json");
        let fail_after = |bytes: &'static [u8]| {
            move |out: &mut dyn Write| {
                out.write_all(bytes)?;
                Err(std::io::Error::other("the writer failed"))
            }
        };
        assert!(write_atomic_with(&path, fail_after(b"{\"half\":")).is_err());
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert!(left.is_empty(), "nothing stays behind: {left:?}");

        write_atomic_with(&path, |out| out.write_all(b"whole\n")).unwrap();
        assert!(write_atomic_with(&path, fail_after(b"par")).is_err());
        assert_eq!(std::fs::read(&path).unwrap(), b"whole\n");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
