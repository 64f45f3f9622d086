//! Quantities with units: simulated time, byte counts and bandwidths, and counts of things
//! as people write them (`count`: "1 frame", "3 frames").
//!
//! Owns the one place where unit strings from specs ("17MB/s", "60us", "4KiB") become exact
//! integers, and where bytes over a bandwidth become picoseconds (u128 rational arithmetic,
//! rounded up once). Nothing outside this file converts between units by hand.
//!
//! Must never use floating point on a path that produces a `SimTime` or a `Bytes`: floats
//! appear only in `as_secs_f64`-style accessors used for reports.

use std::fmt;
use std::ops::{Add, AddAssign, Mul, Sub};

/// Picoseconds per second.
pub const PS_PER_S: u64 = 1_000_000_000_000;

/// A simulated instant or duration: an exact count of picoseconds (u64 covers 213 days).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct SimTime(u64);

impl SimTime {
    pub const ZERO: SimTime = SimTime(0);
    pub const MAX: SimTime = SimTime(u64::MAX);

    pub const fn from_ps(ps: u64) -> SimTime {
        SimTime(ps)
    }
    pub const fn from_ns(ns: u64) -> SimTime {
        SimTime(ns * 1_000)
    }
    pub const fn from_us(us: u64) -> SimTime {
        SimTime(us * 1_000_000)
    }
    pub const fn from_ms(ms: u64) -> SimTime {
        SimTime(ms * 1_000_000_000)
    }
    pub const fn ps(self) -> u64 {
        self.0
    }
    /// Seconds as a float, for reports only.
    pub fn as_secs_f64(self) -> f64 {
        self.0 as f64 / PS_PER_S as f64
    }
    /// Microseconds as a float, for reports and timelines only.
    pub fn as_us_f64(self) -> f64 {
        self.0 as f64 / 1e6
    }
    pub fn saturating_sub(self, other: SimTime) -> SimTime {
        SimTime(self.0.saturating_sub(other.0))
    }
    pub fn saturating_add(self, other: SimTime) -> SimTime {
        SimTime(self.0.saturating_add(other.0))
    }
    pub fn checked_add(self, other: SimTime) -> Option<SimTime> {
        self.0.checked_add(other.0).map(SimTime)
    }
    /// The earlier of two instants that may be absent: the next event of two sources.
    /// (Written as a match: gathering them in an array to take the least is read back in wide
    /// loads that wait for the narrow stores that built it, on every event of a network.)
    #[inline]
    pub fn earliest(a: Option<SimTime>, b: Option<SimTime>) -> Option<SimTime> {
        match (a, b) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }
    /// `self * n`, saturating at `SimTime::MAX`.
    pub fn times(self, n: u64) -> SimTime {
        SimTime(self.0.saturating_mul(n))
    }
}

impl Add for SimTime {
    type Output = SimTime;
    fn add(self, rhs: SimTime) -> SimTime {
        SimTime(
            self.0
                .checked_add(rhs.0)
                .expect("simulated time overflowed u64 picoseconds"),
        )
    }
}
impl AddAssign for SimTime {
    fn add_assign(&mut self, rhs: SimTime) {
        *self = *self + rhs;
    }
}
impl Sub for SimTime {
    type Output = SimTime;
    fn sub(self, rhs: SimTime) -> SimTime {
        SimTime(
            self.0
                .checked_sub(rhs.0)
                .expect("simulated time went negative"),
        )
    }
}
impl std::iter::Sum for SimTime {
    fn sum<I: Iterator<Item = SimTime>>(iter: I) -> SimTime {
        iter.fold(SimTime::ZERO, |a, b| a + b)
    }
}

impl fmt::Display for SimTime {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let ps = self.0;
        let (div, unit) = match ps {
            0..1_000 => (1, "ps"),
            1_000..1_000_000 => (1_000, "ns"),
            1_000_000..1_000_000_000 => (1_000_000, "us"),
            1_000_000_000..PS_PER_S => (1_000_000_000, "ms"),
            _ => (PS_PER_S, "s"),
        };
        if ps % div == 0 {
            write!(f, "{}{}", ps / div, unit)
        } else {
            // Six decimals at most, without the zeros that say nothing (168.66us, 1.5ms); a
            // time that rounds to a whole number keeps them, so it does not read as exact.
            let fraction = format!("{:.6}", ps as f64 / div as f64);
            let trimmed = fraction.trim_end_matches('0');
            let shown = if trimmed.ends_with('.') {
                &fraction
            } else {
                trimmed
            };
            write!(f, "{shown}{unit}")
        }
    }
}

/// A byte count.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Bytes(pub u64);

impl Bytes {
    pub const ZERO: Bytes = Bytes(0);
    pub const fn new(n: u64) -> Bytes {
        Bytes(n)
    }
    pub const fn get(self) -> u64 {
        self.0
    }
    pub fn saturating_sub(self, other: Bytes) -> Bytes {
        Bytes(self.0.saturating_sub(other.0))
    }
}
impl Add for Bytes {
    type Output = Bytes;
    fn add(self, rhs: Bytes) -> Bytes {
        Bytes(
            self.0
                .checked_add(rhs.0)
                .expect("byte count overflowed u64"),
        )
    }
}
impl AddAssign for Bytes {
    fn add_assign(&mut self, rhs: Bytes) {
        *self = *self + rhs;
    }
}
impl Sub for Bytes {
    type Output = Bytes;
    fn sub(self, rhs: Bytes) -> Bytes {
        Bytes(self.0.checked_sub(rhs.0).expect("byte count went negative"))
    }
}
impl Mul<u64> for Bytes {
    type Output = Bytes;
    fn mul(self, rhs: u64) -> Bytes {
        Bytes(self.0.checked_mul(rhs).expect("byte count overflowed u64"))
    }
}
impl std::iter::Sum for Bytes {
    fn sum<I: Iterator<Item = Bytes>>(iter: I) -> Bytes {
        iter.fold(Bytes::ZERO, |a, b| a + b)
    }
}
impl fmt::Display for Bytes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}B", self.0)
    }
}

/// A data rate, held exactly as bits per second (every unit sortsim parses is a whole
/// number of bits per second, so no rate is ever rounded).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Bandwidth {
    bits_per_s: u64,
}

impl Bandwidth {
    /// `None` for zero: a link that moves nothing is not a link.
    pub fn from_bits_per_s(bits_per_s: u64) -> Option<Bandwidth> {
        (bits_per_s > 0).then_some(Bandwidth { bits_per_s })
    }
    pub fn from_bytes_per_s(bytes_per_s: u64) -> Option<Bandwidth> {
        bytes_per_s
            .checked_mul(8)
            .and_then(Bandwidth::from_bits_per_s)
    }
    pub fn bits_per_s(self) -> u64 {
        self.bits_per_s
    }
    /// Bytes per second as a float, for reports only.
    pub fn bytes_per_s_f64(self) -> f64 {
        self.bits_per_s as f64 / 8.0
    }
    /// Time to move `bytes` at this rate: ceil(bytes * 8 * 1e12 / bits_per_s) picoseconds,
    /// computed in u128 and rounded once, up (a transfer never finishes early).
    pub fn transfer_time(self, bytes: Bytes) -> SimTime {
        SimTime(ceil_div(
            bytes.0 as u128 * 8 * PS_PER_S as u128,
            self.bits_per_s as u128,
        ))
    }
    /// Exact bit-picoseconds numerator of `transfer_time`: bytes * 8e12. Transport models that
    /// share a link keep remaining work in this unit so that no rounding accumulates.
    pub fn work_of(bytes: Bytes) -> u128 {
        bytes.0 as u128 * 8 * PS_PER_S as u128
    }
}

/// Exact and short: the largest SI prefix that divides the rate (`17MB/s`, `150kB/s`,
/// `235439B/s`), so the text parses back to the same rate.
impl fmt::Display for Bandwidth {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (value, unit) = if self.bits_per_s % 8 == 0 {
            (self.bits_per_s / 8, "B/s")
        } else {
            (self.bits_per_s, "bit/s")
        };
        let (scaled, prefix) = [(1_000_000_000, "G"), (1_000_000, "M"), (1_000, "k")]
            .into_iter()
            .find(|&(p, _)| value >= p && value % p == 0)
            .map_or((value, ""), |(p, name)| (value / p, name));
        write!(f, "{scaled}{prefix}{unit}")
    }
}

/// ceil(num / den) for u128, saturating into u64.
/// `n` things, the noun in the plural unless `n` is 1: `count(1, "frame")` is "1 frame",
/// `count(3, "frame")` "3 frames". Every count a person reads is written through this.
pub fn count(n: impl Into<u64>, noun: &str) -> String {
    let n = n.into();
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

pub fn ceil_div(num: u128, den: u128) -> u64 {
    let q = num.div_ceil(den);
    u64::try_from(q).unwrap_or(u64::MAX)
}

/// What went wrong parsing a quantity; the message lists the valid units.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum UnitError {
    #[error("empty {kind}; expected a number followed by a unit ({valid})")]
    Empty {
        kind: &'static str,
        valid: &'static str,
    },
    #[error(
        "'{text}' is not a valid {kind}: {why}; expected a number followed by a unit ({valid})"
    )]
    Invalid {
        text: String,
        kind: &'static str,
        why: &'static str,
        valid: &'static str,
    },
    #[error("'{text}' has unknown unit '{unit}' for a {kind}; valid units: {valid}")]
    UnknownUnit {
        text: String,
        unit: String,
        kind: &'static str,
        valid: &'static str,
    },
}

const TIME_UNITS: &str = "ps, ns, us, ms, s";
const BYTE_UNITS: &str = "B, KB, MB, GB (powers of 10), KiB, MiB, GiB (powers of 2)";
const RATE_UNITS: &str =
    "bit/s, kbit/s, Mbit/s, Gbit/s, B/s, KB/s, MB/s, GB/s, KiB/s, MiB/s, GiB/s";

impl std::str::FromStr for SimTime {
    type Err = UnitError;
    fn from_str(s: &str) -> Result<SimTime, UnitError> {
        let q = Quantity::parse(s, "time", TIME_UNITS)?;
        let ps_per_unit: u128 = match q.unit {
            "ps" => 1,
            "ns" => 1_000,
            "us" | "µs" => 1_000_000,
            "ms" => 1_000_000_000,
            "s" => PS_PER_S as u128,
            _ => return Err(q.unknown_unit()),
        };
        q.scaled(ps_per_unit, "finer than one picosecond")
            .map(SimTime)
    }
}

impl std::str::FromStr for Bytes {
    type Err = UnitError;
    fn from_str(s: &str) -> Result<Bytes, UnitError> {
        let q = Quantity::parse(s, "size", BYTE_UNITS)?;
        let per_unit = byte_multiplier(q.unit).ok_or_else(|| q.unknown_unit())?;
        q.scaled(per_unit, "not a whole number of bytes").map(Bytes)
    }
}

impl std::str::FromStr for Bandwidth {
    type Err = UnitError;
    fn from_str(s: &str) -> Result<Bandwidth, UnitError> {
        let q = Quantity::parse(s, "bandwidth", RATE_UNITS)?;
        let bits_per_unit: u128 = match q.unit {
            "bit/s" | "bps" => 1,
            "kbit/s" | "Kbit/s" => 1_000,
            "Mbit/s" => 1_000_000,
            "Gbit/s" => 1_000_000_000,
            unit => match unit.strip_suffix("/s").and_then(byte_multiplier) {
                Some(bytes) => bytes * 8,
                None => return Err(q.unknown_unit()),
            },
        };
        let bits = q.scaled(bits_per_unit, "not a whole number of bits per second")?;
        Bandwidth::from_bits_per_s(bits).ok_or(UnitError::Invalid {
            text: s.to_string(),
            kind: "bandwidth",
            why: "a bandwidth must be greater than zero",
            valid: RATE_UNITS,
        })
    }
}

fn byte_multiplier(unit: &str) -> Option<u128> {
    Some(match unit {
        "B" => 1,
        "KB" | "kB" => 1_000,
        "MB" => 1_000_000,
        "GB" => 1_000_000_000,
        "KiB" => 1 << 10,
        "MiB" => 1 << 20,
        "GiB" => 1 << 30,
        _ => return None,
    })
}

/// A decimal number and its unit, split from a string like "1.5ms". The number is kept
/// exactly as `mantissa / 10^decimals`.
struct Quantity<'a> {
    text: &'a str,
    mantissa: u128,
    decimals: u32,
    unit: &'a str,
    kind: &'static str,
    valid: &'static str,
}

impl<'a> Quantity<'a> {
    fn parse(text: &'a str, kind: &'static str, valid: &'static str) -> Result<Self, UnitError> {
        let invalid = |why| UnitError::Invalid {
            text: text.to_string(),
            kind,
            why,
            valid,
        };
        let trimmed = text.trim();
        if trimmed.is_empty() {
            return Err(UnitError::Empty { kind, valid });
        }
        if trimmed.starts_with('-') {
            return Err(invalid("it is negative"));
        }
        let split = trimmed
            .find(|c: char| !(c.is_ascii_digit() || c == '.'))
            .unwrap_or(trimmed.len());
        let (number, unit) = (&trimmed[..split], trimmed[split..].trim_start());
        if number.is_empty() {
            return Err(invalid("it has no number"));
        }
        if unit.is_empty() {
            return Err(invalid("it has no unit"));
        }
        let (int_part, frac_part) = number.split_once('.').unwrap_or((number, ""));
        if int_part.is_empty() && frac_part.is_empty() || frac_part.contains('.') {
            return Err(invalid("the number is malformed"));
        }
        let mut mantissa: u128 = 0;
        for d in int_part.bytes().chain(frac_part.bytes()) {
            mantissa = mantissa
                .checked_mul(10)
                .and_then(|m| m.checked_add((d - b'0') as u128))
                .ok_or_else(|| invalid("it is too large"))?;
        }
        let decimals =
            u32::try_from(frac_part.len()).map_err(|_| invalid("it has too many decimals"))?;
        if decimals > 30 {
            return Err(invalid("it has too many decimals"));
        }
        Ok(Quantity {
            text,
            mantissa,
            decimals,
            unit,
            kind,
            valid,
        })
    }

    /// mantissa * per_unit / 10^decimals, which must be an integer that fits in u64.
    fn scaled(&self, per_unit: u128, inexact_why: &'static str) -> Result<u64, UnitError> {
        let invalid = |why| UnitError::Invalid {
            text: self.text.to_string(),
            kind: self.kind,
            why,
            valid: self.valid,
        };
        let num = self
            .mantissa
            .checked_mul(per_unit)
            .ok_or_else(|| invalid("it is too large"))?;
        let den = 10u128.pow(self.decimals);
        if num % den != 0 {
            return Err(invalid(inexact_why));
        }
        u64::try_from(num / den).map_err(|_| invalid("it is too large"))
    }

    fn unknown_unit(&self) -> UnitError {
        UnitError::UnknownUnit {
            text: self.text.to_string(),
            unit: self.unit.to_string(),
            kind: self.kind,
            valid: self.valid,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn time(s: &str) -> u64 {
        s.parse::<SimTime>().unwrap().ps()
    }
    fn bytes(s: &str) -> u64 {
        s.parse::<Bytes>().unwrap().get()
    }
    fn bits(s: &str) -> u64 {
        s.parse::<Bandwidth>().unwrap().bits_per_s()
    }

    #[test]
    fn parses_the_issue_examples_exactly() {
        assert_eq!(bits("17MB/s"), 136_000_000);
        assert_eq!(bits("20Mbit/s"), 20_000_000);
        assert_eq!(bits("1.2GB/s"), 9_600_000_000);
        assert_eq!(time("60us"), 60_000_000);
        assert_eq!(time("75ns"), 75_000);
        assert_eq!(time("1.5ms"), 1_500_000_000);
        assert_eq!(bytes("4KiB"), 4096);
        assert_eq!(bytes("4MB"), 4_000_000);
        assert_eq!(bytes("4MiB"), 4 << 20);
        assert_eq!(time("3ps"), 3);
        assert_eq!(time(" 2 s "), 2 * PS_PER_S);
    }

    #[test]
    fn rejects_bad_quantities_listing_valid_units() {
        for bad in [
            "",
            "  ",
            "-5us",
            "NaN",
            "nan s",
            "inf s",
            "5",
            "us",
            "5 parsecs",
            "1..2ms",
            ".ms",
        ] {
            let err = bad.parse::<SimTime>().unwrap_err().to_string();
            assert!(err.contains("ps, ns, us, ms, s"), "{bad:?}: {err}");
        }
        let err = "99999999999999999999999999s"
            .parse::<SimTime>()
            .unwrap_err()
            .to_string();
        assert!(err.contains("too large"), "{err}");
        let err = "0.5ps".parse::<SimTime>().unwrap_err().to_string();
        assert!(err.contains("finer than one picosecond"), "{err}");
        let err = "0MB/s".parse::<Bandwidth>().unwrap_err().to_string();
        assert!(err.contains("greater than zero"), "{err}");
        let err = "3 furlongs/s".parse::<Bandwidth>().unwrap_err().to_string();
        assert!(err.contains("Mbit/s") && err.contains("MiB/s"), "{err}");
        let err = "1.5B".parse::<Bytes>().unwrap_err().to_string();
        assert!(err.contains("whole number of bytes"), "{err}");
    }

    #[test]
    fn transfer_time_rounds_once_up() {
        let bw: Bandwidth = "17MB/s".parse().unwrap();
        // 4096 B at 17e6 B/s = 240.941176...us -> rounded up to the next picosecond.
        assert_eq!(bw.transfer_time(Bytes(4096)).ps(), 240_941_177);
        assert_eq!(bw.transfer_time(Bytes(17_000_000)).ps(), PS_PER_S);
        assert_eq!(bw.transfer_time(Bytes::ZERO), SimTime::ZERO);
        let slow = Bandwidth::from_bits_per_s(3).unwrap();
        assert_eq!(
            slow.transfer_time(Bytes(1)).ps(),
            (8 * PS_PER_S).div_ceil(3)
        );
    }

    #[test]
    fn display_is_compact() {
        assert_eq!(SimTime::from_us(60).to_string(), "60us");
        assert_eq!(SimTime::from_ps(1_500_000_000).to_string(), "1.5ms");
        assert_eq!(SimTime::from_ps(168_660_000).to_string(), "168.66us");
        assert_eq!(SimTime::from_ps(1_234_567).to_string(), "1.234567us");
        // Below the sixth decimal a time is rounded, never shown as a whole number it is not.
        assert_eq!(SimTime::from_ps(2_000_000_000_001).to_string(), "2.000000s");
        for (given, shown) in [
            ("17MB/s", "17MB/s"),
            ("17000000B/s", "17MB/s"),
            ("150000B/s", "150kB/s"),
            ("235439B/s", "235439B/s"),
            ("1.2GB/s", "1200MB/s"),
            ("4.2GB/s", "4200MB/s"),
            ("2GB/s", "2GB/s"),
        ] {
            let rate: Bandwidth = given.parse().unwrap();
            assert_eq!(rate.to_string(), shown, "{given}");
            assert_eq!(
                shown.parse::<Bandwidth>().unwrap(),
                rate,
                "{shown} parses back"
            );
        }
    }
}
