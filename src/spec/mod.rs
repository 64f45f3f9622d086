//! Spec files: serde types for machines, scenes, runs and sweeps, and the one loader that
//! turns a JSON file into a validated value or a `SpecError` naming file, line/column or field
//! path, and what would be valid.
//!
//! Owns deserialization of user input. Must never simulate anything, and never let a
//! malformed spec reach the rest of the crate: everything past `spec` is validated.

pub mod check;
pub mod machine;
mod quantity;
pub mod range;
pub mod run;
pub mod scene;
pub mod schema;
mod tagged;

use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;

/// A spec file that cannot be used, with everything a person needs to fix it.
#[derive(Debug, thiserror::Error)]
pub enum SpecError {
    #[error("{}: cannot read: {source}", file.display())]
    Io {
        file: PathBuf,
        source: std::io::Error,
    },
    #[error("{}:{line}:{column}: malformed JSON: {message}", file.display())]
    Syntax {
        file: PathBuf,
        line: usize,
        column: usize,
        message: String,
    },
    #[error("{}:{line}:{column}: at `{field}`: {message}", file.display())]
    Field {
        file: PathBuf,
        field: String,
        line: usize,
        column: usize,
        message: String,
    },
    #[error("{}: {}{message}", file.display(), at(field))]
    Invalid {
        file: PathBuf,
        field: String,
        message: String,
    },
}

/// "at `path`: " for a field, nothing for the document as a whole.
fn at(field: &str) -> String {
    if field.is_empty() {
        String::new()
    } else {
        format!("at `{field}`: ")
    }
}

impl SpecError {
    /// A value that parsed but is not allowed; `field` is a path such as `network.dims[1]`.
    pub fn invalid(file: &Path, field: impl Into<String>, message: impl Into<String>) -> SpecError {
        SpecError::Invalid {
            file: file.to_path_buf(),
            field: field.into(),
            message: message.into(),
        }
    }

    /// The field path the error points at, if any.
    pub fn field(&self) -> Option<&str> {
        match self {
            SpecError::Field { field, .. } | SpecError::Invalid { field, .. } => Some(field),
            _ => None,
        }
    }
}

/// Reads and deserializes a JSON spec. Malformed JSON is reported as file:line:column; an
/// unknown field, a missing field or a bad value as its path (serde's message lists the valid
/// fields or variants).
pub fn load_json<T: DeserializeOwned>(path: &Path) -> Result<T, SpecError> {
    let text = read_input(path).map_err(|source| SpecError::Io {
        file: path.to_path_buf(),
        source,
    })?;
    parse_json(path, &text)
}

/// The bytes of an input file. Only a regular file is read: a device such as /dev/zero, a pipe
/// or a folder would be read without end or not at all.
pub fn read_input_bytes(path: &Path) -> std::io::Result<Vec<u8>> {
    if !std::fs::metadata(path)?.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file (a device, pipe or folder cannot be an input)",
        ));
    }
    std::fs::read(path)
}

/// The text of an input file (UTF-8), read as [`read_input_bytes`] does.
pub fn read_input(path: &Path) -> std::io::Result<String> {
    String::from_utf8(read_input_bytes(path)?)
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))
}

/// As `load_json`, for text already in memory; `path` is only used in messages.
pub fn parse_json<T: DeserializeOwned>(path: &Path, text: &str) -> Result<T, SpecError> {
    let mut de = serde_json::Deserializer::from_str(text);
    let value =
        serde_path_to_error::deserialize(&mut de).map_err(|e| from_path_error(path, text, e))?;
    de.end().map_err(|e| syntax_error(path, &e))?;
    Ok(value)
}

fn from_path_error(
    path: &Path,
    text: &str,
    err: serde_path_to_error::Error<serde_json::Error>,
) -> SpecError {
    let field = err.path().to_string();
    let inner = err.into_inner();
    match inner.classify() {
        serde_json::error::Category::Data => {
            let message = strip_position(&inner.to_string());
            SpecError::Field {
                file: path.to_path_buf(),
                field: tagged::narrow(text, &field, &message).unwrap_or(field),
                line: inner.line(),
                column: inner.column(),
                message,
            }
        }
        _ => syntax_error(path, &inner),
    }
}

fn syntax_error(path: &Path, err: &serde_json::Error) -> SpecError {
    SpecError::Syntax {
        file: path.to_path_buf(),
        line: err.line(),
        column: err.column(),
        message: strip_position(&err.to_string()),
    }
}

/// serde_json appends " at line L column C"; the position is already in our own prefix.
fn strip_position(message: &str) -> String {
    match message.rfind(" at line ") {
        Some(i) => message[..i].to_string(),
        None => message.to_string(),
    }
}

/// The kinds of spec `sortsim check` recognises.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpecKind {
    Machine,
    Scene,
    Run,
    Sweep,
    Pattern,
    /// A `sortsim calibrate` spec (`targets` and `parameters`), checked by `calibrate::check`.
    Calibration,
    /// A paper's rows (`papers/NNN.json`: `paper` and `rows`), checked by `paper::data`.
    Paper,
}

impl SpecKind {
    /// Guesses a spec's kind from its top-level keys, so `check` needs no flag.
    pub fn detect(path: &Path) -> Result<SpecKind, SpecError> {
        let value: serde_json::Value = load_json(path)?;
        let has = |key: &str| value.get(key).is_some();
        if has("targets") && has("parameters") {
            Ok(SpecKind::Calibration)
        } else if has("paper") && has("rows") {
            Ok(SpecKind::Paper)
        } else if has("network") || has("cpu") || has("memory") {
            Ok(SpecKind::Machine)
        } else if has("geometry") || has("resolution") {
            Ok(SpecKind::Scene)
        } else if has("vary")
            || has("algos")
            || has("machines")
            || has("scenes")
            || value.get("procs").is_some_and(|p| p.is_array())
        {
            Ok(SpecKind::Sweep)
        } else if has("algo") {
            Ok(SpecKind::Run)
        } else if has("messages") {
            Ok(SpecKind::Pattern)
        } else {
            Err(SpecError::invalid(
                path,
                "",
                "cannot tell what kind of spec this is: a machine has `network`, a scene has `geometry`, a run has `algo`, a sweep has lists (`procs: [...]`, `vary`), a network pattern has `messages`, a calibration has `targets` and `parameters`, a paper's rows have `paper` and `rows`; a trace starts with the bytes \"SORTTRC\\n\"",
            ))
        }
    }
}
