//! Serde glue for quantities: specs write `"17MB/s"`, `"60us"`, `"4KiB"`; this file turns
//! those strings into `Bandwidth`, `SimTime` and `Bytes` through `units`' exact parsers.
//!
//! Their JSON Schema (a string matching the unit grammar) lives here too, beside the parser
//! it describes.
//!
//! Must never parse a number itself: all unit arithmetic lives in `units`.

use std::fmt;
use std::marker::PhantomData;
use std::str::FromStr;

use serde::de::{self, Deserialize, Deserializer, Visitor};

use crate::units::{Bandwidth, Bytes, SimTime};

struct FromUnitString<T>(PhantomData<T>, &'static str);

impl<T> Visitor<'_> for FromUnitString<T>
where
    T: FromStr,
    T::Err: fmt::Display,
{
    type Value = T;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(
            f,
            "a {} as a string with a unit, such as {}",
            self.1,
            example(self.1)
        )
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<T, E> {
        v.parse().map_err(E::custom)
    }
}

fn example(kind: &str) -> &'static str {
    match kind {
        "time" => "\"60us\"",
        "size" => "\"4KiB\"",
        _ => "\"17MB/s\"",
    }
}

impl<'de> Deserialize<'de> for SimTime {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_str(FromUnitString(PhantomData, "time"))
    }
}
impl<'de> Deserialize<'de> for Bytes {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_str(FromUnitString(PhantomData, "size"))
    }
}
impl<'de> Deserialize<'de> for Bandwidth {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_str(FromUnitString(PhantomData, "bandwidth"))
    }
}

/// The schema of a quantity string: a number, optional spaces, then one of `units`.
fn unit_schema(description: &str, units: &str, example: &str) -> schemars::Schema {
    schemars::json_schema!({
        "type": "string",
        "description": description,
        "pattern": format!("^ *[0-9]*\\.?[0-9]+ *({units}) *$"),
        "examples": [example],
    })
}

impl schemars::JsonSchema for SimTime {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "Time".into()
    }
    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        unit_schema("A time with its unit.", "ps|ns|us|µs|ms|s", "60us")
    }
}

impl schemars::JsonSchema for Bytes {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "Size".into()
    }
    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        unit_schema(
            "A size with its unit (KB = 1000 B, KiB = 1024 B).",
            "B|KB|kB|MB|GB|KiB|MiB|GiB",
            "4KiB",
        )
    }
}

impl schemars::JsonSchema for Bandwidth {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "Bandwidth".into()
    }
    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        unit_schema(
            "A bandwidth with its unit (bytes or bits per second).",
            "bit/s|bps|kbit/s|Kbit/s|Mbit/s|Gbit/s|B/s|KB/s|kB/s|MB/s|GB/s|KiB/s|MiB/s|GiB/s",
            "17MB/s",
        )
    }
}
