//! Algorithm options: `--set key=value` (or a run spec's `set` object) arrives as raw strings
//! in [`Options`]; each algorithm declares its options once, as a typed struct (serde +
//! schemars: the field's doc comment is its help, its serde default the default, its type's
//! `FromStr` what is valid), and [`parse`] turns the strings into that struct. The schema
//! (`sortsim schema options`), `sortsim run --help` and the error for a bad or unknown key all
//! read the same struct.
//!
//! Owns the string-to-struct step and the small option value types. Must never hold an
//! algorithm's defaults outside its struct.

use std::collections::BTreeMap;
use std::fmt;

use schemars::JsonSchema;
use serde::de::DeserializeOwned;

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

/// Raw `key=value` options as given.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Options {
    values: BTreeMap<String, String>,
}

impl Options {
    pub fn new(values: BTreeMap<String, String>) -> Options {
        Options { values }
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

    pub fn pairs(&self) -> impl Iterator<Item = (&String, &String)> {
        self.values.iter()
    }

    pub fn is_given(&self, key: &str) -> bool {
        self.values.contains_key(key)
    }

    /// The value given for `key`, if any.
    pub fn value(&self, key: &str) -> Option<&str> {
        self.values.get(key).map(String::as_str)
    }
}

/// One option as documented by its struct: key, default as the user would type it, help.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OptionDoc {
    pub key: String,
    pub default: String,
    pub help: String,
}

/// The options of `T`, by key, from its schema.
pub fn docs<T: JsonSchema>() -> Vec<OptionDoc> {
    let schema = schemars::schema_for!(T);
    let Some(properties) = schema.get("properties").and_then(|p| p.as_object()) else {
        return Vec::new();
    };
    properties
        .iter()
        .map(|(key, p)| OptionDoc {
            key: key.clone(),
            default: match p.get("default") {
                None | Some(serde_json::Value::Null) => "none".to_string(),
                Some(serde_json::Value::String(s)) => s.clone(),
                Some(v) => v.to_string(),
            },
            help: p
                .get("description")
                .and_then(|d| d.as_str())
                .unwrap_or("")
                .replace('\n', " "),
        })
        .collect()
}

/// The options of an algorithm whose struct is `T` plus the shared anti-aliasing options.
pub fn parse<T: DeserializeOwned + JsonSchema>(
    o: &Options,
    algo: &'static str,
) -> Result<(T, super::aa::AaOptions), OptionError> {
    let own = docs::<T>();
    let aa = docs::<super::aa::AaOptions>();
    if let Some(key) = o
        .values
        .keys()
        .find(|k| !own.iter().chain(&aa).any(|d| &d.key == *k))
    {
        return Err(OptionError::Unknown {
            key: key.clone(),
            algo,
            valid: own
                .iter()
                .chain(&aa)
                .map(|d| format!("{} (default {})", d.key, d.default))
                .collect::<Vec<_>>()
                .join(", "),
        });
    }
    let split = |docs: &[OptionDoc]| -> serde_json::Value {
        o.values
            .iter()
            .filter(|(k, _)| docs.iter().any(|d| &d.key == *k))
            .map(|(k, v)| (k.clone(), serde_json::Value::String(v.clone())))
            .collect::<serde_json::Map<_, _>>()
            .into()
    };
    Ok((deserialize(o, split(&own))?, deserialize(o, split(&aa))?))
}

fn deserialize<T: DeserializeOwned>(o: &Options, map: serde_json::Value) -> Result<T, OptionError> {
    serde_path_to_error::deserialize(map).map_err(|e| {
        let key = e.path().to_string();
        OptionError::Invalid {
            value: o.value(&key).unwrap_or_default().to_string(),
            key,
            message: e.inner().to_string(),
        }
    })
}

/// Implements `Deserialize` (from the option's string, through `FromStr`, whose error is the
/// message) and `Serialize` (as `Display`, so a schema's default reads as typed).
macro_rules! string_option {
    ($t:ty) => {
        impl<'de> serde::Deserialize<'de> for $t {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let s = String::deserialize(d)?;
                s.parse().map_err(serde::de::Error::custom)
            }
        }
        impl serde::Serialize for $t {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.serialize_str(&self.to_string())
            }
        }
    };
}
pub(crate) use string_option;

/// A whole-number option with a lower bound and what it counts, e.g. regions per processor.
macro_rules! count_option {
    ($(#[$doc:meta])* $name:ident, min = $min:expr, what = $what:expr) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub struct $name(pub u32);

        impl std::str::FromStr for $name {
            type Err = String;
            fn from_str(s: &str) -> Result<Self, String> {
                s.parse::<u32>()
                    .ok()
                    .filter(|&v| v >= $min)
                    .map($name)
                    .ok_or_else(|| format!("expected {}", $what))
            }
        }

        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "{}", self.0)
            }
        }

        $crate::algo::options::string_option!($name);

        impl schemars::JsonSchema for $name {
            fn schema_name() -> std::borrow::Cow<'static, str> {
                stringify!($name).into()
            }
            fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
                schemars::json_schema!({
                    "type": "string",
                    "pattern": "^[0-9]+$",
                    "description": format!("{}", $what),
                })
            }
        }
    };
}
pub(crate) use count_option;

/// An option with a fixed set of spellings, e.g. `two-step=on|off|auto`.
macro_rules! choice_option {
    ($(#[$doc:meta])* $name:ident { $($(#[$vdoc:meta])* $variant:ident = $text:literal),+ $(,)? }) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum $name { $($(#[$vdoc])* $variant),+ }

        impl $name {
            pub const ALL: &'static [&'static str] = &[$($text),+];
        }

        impl std::str::FromStr for $name {
            type Err = String;
            fn from_str(s: &str) -> Result<Self, String> {
                match s {
                    $($text => Ok($name::$variant),)+
                    _ => Err(format!("expected one of {}", $name::ALL.join(", "))),
                }
            }
        }

        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(match self { $($name::$variant => $text),+ })
            }
        }

        $crate::algo::options::string_option!($name);

        impl schemars::JsonSchema for $name {
            fn schema_name() -> std::borrow::Cow<'static, str> {
                stringify!($name).into()
            }
            fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
                schemars::json_schema!({ "type": "string", "enum": $name::ALL })
            }
        }
    };
}
pub(crate) use choice_option;

/// A quantity option (a size or a time) whose message names what it is for.
macro_rules! quantity_option {
    ($(#[$doc:meta])* $name:ident($inner:ty), what = $what:expr) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub struct $name(pub $inner);

        impl std::str::FromStr for $name {
            type Err = String;
            fn from_str(s: &str) -> Result<Self, String> {
                s.parse::<$inner>().map($name).map_err(|_| format!("expected {}", $what))
            }
        }

        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "{}", self.0)
            }
        }

        $crate::algo::options::string_option!($name);

        impl schemars::JsonSchema for $name {
            fn schema_name() -> std::borrow::Cow<'static, str> {
                <$inner as schemars::JsonSchema>::schema_name()
            }
            fn json_schema(g: &mut schemars::SchemaGenerator) -> schemars::Schema {
                <$inner as schemars::JsonSchema>::json_schema(g)
            }
        }
    };
}
pub(crate) use quantity_option;

choice_option!(
    /// `on` or `off`.
    OnOff { On = "on", Off = "off" }
);

impl OnOff {
    pub fn is_on(self) -> bool {
        self == OnOff::On
    }
}

/// Lines of `key (default): help` for every option of an algorithm, for `--help`.
pub fn help_lines(docs: &[OptionDoc]) -> String {
    let mut out = String::new();
    for d in docs {
        let _ = fmt::Write::write_fmt(
            &mut out,
            format_args!("    {} (default {}): {}\n", d.key, d.default, d.help),
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    count_option!(
        Widgets,
        min = 1,
        what = "a whole number of widgets, at least 1"
    );
    choice_option!(Mode { Fast = "fast", Slow = "slow" });

    fn fast() -> Mode {
        Mode::Fast
    }
    fn two() -> Widgets {
        Widgets(2)
    }

    /// A test algorithm's options.
    #[derive(serde::Deserialize, schemars::JsonSchema, Debug)]
    #[serde(rename_all = "kebab-case")]
    struct TestOptions {
        /// How many widgets.
        #[serde(default = "two")]
        widgets: Widgets,
        /// How fast.
        #[serde(default = "fast")]
        mode: Mode,
    }

    #[test]
    fn typed_reads_defaults_and_unknown_keys() {
        let o = Options::from_pairs(["widgets=12"]).unwrap();
        let (t, _) = parse::<TestOptions>(&o, "test/algo").unwrap();
        assert_eq!((t.widgets, t.mode), (Widgets(12), Mode::Fast));
        let o = Options::from_pairs(["colour=red"]).unwrap();
        let err = parse::<TestOptions>(&o, "test/algo")
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("--set colour: test/algo has no option 'colour'; valid options: mode (default fast), widgets (default 2), aa (default none)"),
            "{err}"
        );
        let d = docs::<TestOptions>();
        assert_eq!(
            (d[1].key.as_str(), d[1].help.as_str()),
            ("widgets", "How many widgets.")
        );
    }

    #[test]
    fn wrong_values_name_key_value_and_what_is_valid() {
        let o = Options::from_pairs(["widgets=lots"]).unwrap();
        let e = parse::<TestOptions>(&o, "test/algo").unwrap_err();
        assert_eq!(
            e.to_string(),
            "--set widgets=lots: expected a whole number of widgets, at least 1"
        );
        let o = Options::from_pairs(["mode=later"]).unwrap();
        let e = parse::<TestOptions>(&o, "test/algo").unwrap_err();
        assert_eq!(
            e.to_string(),
            "--set mode=later: expected one of fast, slow"
        );
        assert!(Options::from_pairs(["novalue"]).is_err());
    }
}
