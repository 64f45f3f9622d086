//! Algorithm options from `--set key=value` (or a run spec's `set` object): raw strings until
//! an algorithm reads them with a typed getter, which names the key and what is valid when
//! the value is wrong. Keys an algorithm never reads are rejected by `finish`.
//!
//! Must never hold defaults: each algorithm states its own where it reads an option.

use std::cell::RefCell;
use std::collections::{BTreeMap, BTreeSet};
use std::str::FromStr;

#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum OptionError {
    #[error("--set {key}={value}: {message}")]
    Invalid {
        key: String,
        value: String,
        message: String,
    },
    #[error("--set {key}: {algo} has no option '{key}'; valid options: {valid}")]
    Unknown {
        key: String,
        algo: &'static str,
        valid: String,
    },
}

/// `key=value` options, with a record of which keys were read.
#[derive(Clone, Debug, Default)]
pub struct Options {
    values: BTreeMap<String, String>,
    read: RefCell<BTreeSet<String>>,
}

impl Options {
    pub fn new(values: BTreeMap<String, String>) -> Options {
        Options {
            values,
            read: RefCell::default(),
        }
    }

    /// Parses `key=value` pairs as given on the command line.
    pub fn from_pairs<'a>(
        pairs: impl IntoIterator<Item = &'a str>,
    ) -> Result<Options, OptionError> {
        let mut values = BTreeMap::new();
        for pair in pairs {
            let (k, v) = pair.split_once('=').ok_or_else(|| OptionError::Invalid {
                key: pair.to_string(),
                value: String::new(),
                message: "expected key=value".into(),
            })?;
            values.insert(k.trim().to_string(), v.trim().to_string());
        }
        Ok(Options::new(values))
    }

    /// The option `key` parsed as `T`, or `default`; `what` describes valid values.
    pub fn get<T: FromStr>(&self, key: &str, default: T, what: &str) -> Result<T, OptionError> {
        self.read.borrow_mut().insert(key.to_string());
        match self.values.get(key) {
            None => Ok(default),
            Some(v) => v.parse().map_err(|_| OptionError::Invalid {
                key: key.to_string(),
                value: v.clone(),
                message: format!("expected {what}"),
            }),
        }
    }

    /// The option `key`, which must be one of `choices`, or `default`.
    pub fn choice(
        &self,
        key: &str,
        default: &'static str,
        choices: &[&'static str],
    ) -> Result<&'static str, OptionError> {
        self.read.borrow_mut().insert(key.to_string());
        match self.values.get(key) {
            None => Ok(default),
            Some(v) => {
                choices
                    .iter()
                    .copied()
                    .find(|c| c == v)
                    .ok_or_else(|| OptionError::Invalid {
                        key: key.to_string(),
                        value: v.clone(),
                        message: format!("expected one of {}", choices.join(", ")),
                    })
            }
        }
    }

    /// Fails on the first key no getter asked for, listing those that were.
    pub fn finish(&self, algo: &'static str) -> Result<(), OptionError> {
        let read = self.read.borrow();
        match self.values.keys().find(|k| !read.contains(*k)) {
            None => Ok(()),
            Some(k) => Err(OptionError::Unknown {
                key: k.clone(),
                algo,
                valid: read.iter().cloned().collect::<Vec<_>>().join(", "),
            }),
        }
    }

    pub fn pairs(&self) -> impl Iterator<Item = (&String, &String)> {
        self.values.iter()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn typed_reads_and_unknown_keys() {
        let o = Options::from_pairs(["granularity=12", "counts=current", "colour=red"]).unwrap();
        assert_eq!(o.get("granularity", 8u32, "a whole number").unwrap(), 12);
        assert_eq!(
            o.choice("counts", "previous", &["previous", "current"])
                .unwrap(),
            "current"
        );
        assert_eq!(o.get("buffer", 4096u32, "a size").unwrap(), 4096);
        let err = o.finish("sort-middle/ellsworth").unwrap_err().to_string();
        assert_eq!(err, "--set colour: sort-middle/ellsworth has no option 'colour'; valid options: buffer, counts, granularity");
    }

    #[test]
    fn wrong_types_name_key_value_and_what_is_valid() {
        let o = Options::from_pairs(["granularity=lots", "counts=later"]).unwrap();
        let e = o
            .get(
                "granularity",
                8u32,
                "a whole number of regions per processor, at least 1",
            )
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "--set granularity=lots: expected a whole number of regions per processor, at least 1"
        );
        let e = o
            .choice("counts", "previous", &["previous", "current"])
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "--set counts=later: expected one of previous, current"
        );
        assert!(Options::from_pairs(["novalue"]).is_err());
    }
}
