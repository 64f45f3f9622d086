//! Serde glue for quantities: specs write `"17MB/s"`, `"60us"`, `"4KiB"`; this file turns
//! those strings into `Bandwidth`, `SimTime` and `Bytes` through `units`' exact parsers.
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
