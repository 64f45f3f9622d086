//! The one range syntax of sortsim's flags and spec files, as Rust writes ranges: `A..B` runs
//! from A to B-1, `A..=B` from A to B. `--frames`, a sweep's `frames`, `--procs` and
//! `--granularity` all read ranges here.
//!
//! Owns parsing a range and the wording of a malformed or empty one; never decides what a
//! range may hold (frames in a scene, processors on a machine: the callers check that).

use std::ops::RangeInclusive;

/// How a range is written, for help texts and error messages.
pub const SYNTAX: &str = "A..B (A to B-1) or A..=B (A to B), A and B whole numbers";

/// A range, `A..B` or `A..=B`, as the whole numbers it holds; `None` when `text` has no `..`
/// (a single value, for the caller to read). An empty range (`5..5`, `5..=4`) is an error.
pub fn parse(text: &str) -> Option<Result<RangeInclusive<u32>, String>> {
    let (a, rest) = text.split_once("..")?;
    let (inclusive, b) = match rest.strip_prefix('=') {
        Some(b) => (true, b),
        None => (false, rest),
    };
    let number = |s: &str| {
        s.trim()
            .parse::<u32>()
            .map_err(|_| format!("'{text}' is not a range: write {SYNTAX}"))
    };
    Some((|| {
        let (a, b) = (number(a)?, number(b)?);
        let last = if inclusive { Some(b) } else { b.checked_sub(1) };
        match last {
            Some(last) if last >= a => Ok(a..=last),
            _ => Err(format!(
                "'{text}' is an empty range: {} ({SYNTAX})",
                if inclusive {
                    format!("{a} > {b}")
                } else {
                    format!("{b} is excluded and {a} >= {b}")
                }
            )),
        }
    })())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_mean_what_they_mean_in_rust() {
        assert_eq!(parse("0..4"), Some(Ok(0..=3)));
        assert_eq!(parse("0..=4"), Some(Ok(0..=4)));
        assert_eq!(parse("7..=7"), Some(Ok(7..=7)));
        assert_eq!(parse(" 2 ..= 9 "), Some(Ok(2..=9)));
        assert_eq!(parse("12"), None);
    }

    #[test]
    fn empty_and_malformed_ranges_name_the_syntax() {
        for bad in [
            "5..5", "5..=4", "0..0", "a..3", "1..x", "..3", "1..", "1...3",
        ] {
            let e = parse(bad).expect("has ..").unwrap_err();
            assert!(e.contains("A..=B"), "{bad}: {e}");
        }
    }
}
