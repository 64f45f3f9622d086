//! Paper 003 section 7.2 (Figures 5 and 6) on the stand-in scenes: trace-driven distributed
//! snooping traffic against the expectation A sum p_d H_d, the reductions against d*A the
//! paper reports, and the Zinnia background-first pathology and its two fixes.
//!
//! The stand-ins match Table 1 in primitives, mean size and depth complexity, with depth
//! order random (independent of database order), which is exactly equation 3's assumption.
//! Table 1 does not say how each scene's depth is spread over the screen; six stand-ins
//! scatter it evenly, and Brooks' and Cube's fall in a share of the screen (their
//! `footprint`) fitted to the reductions section 7.2 gives for them, so those two reductions
//! are checked as fits still holding, not as predictions. Measured values are in the
//! comments next to each tolerance (seed 1, release build).

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::{Mutex, OnceLock};

use sortsim::scene::Scene;
use sortsim::trace::replay::{harmonic, Assign, Replay};
use sortsim::trace::{record_scene, Trace};

/// Records (once per test binary) and prepares a stand-in's frame-0 trace.
fn replay(name: &str) -> &'static Replay<'static> {
    static CACHE: OnceLock<Mutex<BTreeMap<String, &'static Replay<'static>>>> = OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    if let Some(r) = cache.lock().unwrap().get(name) {
        return r;
    }
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenes/p003-{name}.json"));
    let scene = Scene::load(&path).unwrap();
    let trace: &'static Trace = Box::leak(Box::new(record_scene(&scene, 0).unwrap()));
    let r: &'static Replay<'static> = Box::leak(Box::new(Replay::new(trace)));
    cache.lock().unwrap().insert(name.to_string(), r);
    r
}

const ALL: [&str; 8] = [
    "bike", "cube", "zinnia", "roses", "washht", "brooks", "capitol", "rad",
];

/// The stand-ins whose footprint is fitted (scenes/fits/): their depth piles up.
const PILED: [&str; 2] = ["brooks", "cube"];

/// "In all but one of the simulations, expected traffic is close to observed traffic", and
/// observed "grows initially as a function of number of processors before reaching a
/// plateau, while expected traffic is flat" (local z-buffering removes pixels on small
/// machines). With random assignment on 64 processors, observed is within 3% of expected on
/// every evenly scattered stand-in (measured -1.1% Roses to +2.0% Zinnia); never more than
/// 3% above it at any n, and equal to the minimum (active pixels) at n = 1 (exact). Where
/// depth piles up (Brooks 8.5 deep over 40% of the screen, Cube 11.6 over 69%) a
/// processor's own primitives hide each other even on 64 processors, which the expectation
/// ignores: observed is below it (the paper: ignoring local z-buffering "is conservative"),
/// by less than 6% (measured -4.2% Brooks, -2.5% Cube).
#[test]
fn random_assignment_observed_is_close_to_expected() {
    for name in ALL {
        let piled = PILED.contains(&name);
        let stats = replay(name).stats();
        let observed = replay(name).snooping_pixels(Assign::Random, &[1, 4, 16, 64], 1);
        let ratio = observed[3] as f64 / stats.expected;
        eprintln!(
            "{name}: observed/expected at n=64 {ratio:.4}, observed {observed:?}, expected {:.0}",
            stats.expected
        );
        if piled {
            assert!((0.94..1.0).contains(&ratio), "{name}: {ratio:.4}");
        } else {
            assert!((ratio - 1.0).abs() <= 0.03, "{name}: {ratio:.4}");
        }
        assert_eq!(observed[0], stats.active, "{name}: n = 1 is the minimum");
        for (k, &o) in observed.iter().enumerate() {
            assert!(o as f64 <= 1.03 * stats.expected, "{name} [{k}]: {o}");
        }
        assert!(
            observed[0] < observed[1] && observed[1] < observed[3],
            "{name}: rises"
        );
    }
}

/// The plateau: on every stand-in but Zinnia (whose one background primitive dominates),
/// the climb from 16 to 64 processors is under a third of the climb from 1 to 16 (measured
/// 0.03 Rad to 0.11 Bike). Round-robin assignment, as in the paper.
#[test]
fn observed_traffic_rises_then_plateaus() {
    for name in ALL.iter().filter(|&&n| n != "zinnia") {
        let o = replay(name).snooping_pixels(Assign::Scatter, &[1, 16, 64], 1);
        let late = o[2] as f64 - o[1] as f64;
        let early = o[1] as f64 - o[0] as f64;
        eprintln!("{name}: climb 16->64 / climb 1->16 = {:.3}", late / early);
        assert!(early > 0.0 && late < early / 3.0, "{name}: {o:?}");
    }
}

/// d*A over observed traffic on 64 processors, round-robin (the paper's assignment).
fn reduction(name: &str) -> f64 {
    let observed = replay(name).snooping_pixels(Assign::Scatter, &[64], 1)[0];
    let r = replay(name).stats().fragments as f64 / observed as f64;
    eprintln!("{name}: reduction d*A/observed at n=64 = {r:.3}");
    r
}

/// "Traffic is reduced by factors of about 3.3, 4.0, 2.3 and 2.0" (Brooks, Cube, Roses,
/// Wash.ht) and "by less than a factor of two" for Bike, Capitol and Rad.
///
/// - Roses 2.3 and Wash.ht 2.0, predicted by the even scatter: within 10% (measured 2.32
///   and 1.85).
/// - Cube 4.0 and Brooks 3.3, the targets their footprints were fitted to: the shipped fits
///   still hold, within 10% (measured 4.00 and 3.29). Evenly spread, the same pixels give at
///   least d / [(1-a) H_floor(d) + a H_ceil(d)] (equation 4 is the worst case for traffic,
///   so a floor for the reduction: 1.76 for Brooks' d = 3.41), and each fitted reduction
///   stays within 10% of its stand-in's own expectation d*A/ET (measured 3.29 against 3.24,
///   4.00 against 3.91; local z-buffering on 64 processors is the rest).
/// - Bike, Capitol, Rad below 2 for every n >= 4 (measured at 64: 1.63, 1.22, 1.31).
/// - Every high-depth stand-in (d > 3) reduces more than every low-depth one.
#[test]
fn reductions_against_d_times_a_are_in_the_papers_ranges() {
    let within = |name: &str, paper: f64, tol: f64| {
        let r = reduction(name);
        assert!(
            ((r - paper) / paper).abs() <= tol,
            "{name}: {r:.3} vs paper {paper}"
        );
        r
    };
    let roses = within("roses", 2.3, 0.10);
    let washht = within("washht", 2.0, 0.10);
    let cube = within("cube", 4.0, 0.10);
    let brooks = within("brooks", 3.3, 0.10);
    for (name, r) in [("cube", cube), ("brooks", brooks)] {
        let stats = replay(name).stats();
        let own = stats.fragments as f64 / stats.expected;
        eprintln!("{name}: own d*A/ET = {own:.3}");
        assert!(
            ((r - own) / own).abs() <= 0.10,
            "{name}: {r:.3} vs {own:.3}"
        );
        let d = stats.fragments as f64 / stats.area as f64;
        let a = d - d.floor();
        let even = d / ((1.0 - a) * harmonic(d.floor() as u64) + a * harmonic(d.ceil() as u64));
        assert!(r > even, "{name}: {r:.3} against the even floor {even:.3}");
    }
    let mut low = Vec::new();
    for name in ["bike", "capitol", "rad"] {
        for (n, o) in [4, 16, 64].into_iter().zip(replay(name).snooping_pixels(
            Assign::Scatter,
            &[4, 16, 64],
            1,
        )) {
            let r = replay(name).stats().fragments as f64 / o as f64;
            assert!(r < 2.0, "{name} n = {n}: reduction {r:.3}");
        }
        low.push(reduction(name));
    }
    let high_min = [roses, washht, cube, brooks]
        .into_iter()
        .fold(f64::MAX, f64::min);
    let low_max = low.into_iter().fold(0.0, f64::max);
    assert!(high_min > low_max, "{high_min:.3} vs {low_max:.3}");
}

/// "In one simulation (Zinnia), observed exceeds expected traffic ... the largest primitive
/// (the background) appears first in the database"; the cure: "force their assignment to
/// processors later in the broadcast order. Of course, randomizing object assignment can be
/// expected to solve this problem as well."
///
/// - round-robin: observed above expected by more than 4% for n = 16, 32, 64 (measured
///   +5.0%, +5.7%, +6.3%);
/// - background-last: below round-robin at every n >= 4 and within 1% of expected at 64
///   (measured -0.1%);
/// - random: below round-robin at 64 on average over seeds 1..=4 (seed 1 measured +2.0%
///   against +6.3%).
#[test]
fn zinnia_background_first_exceeds_expected_and_is_fixed() {
    let procs = [4, 16, 32, 64];
    let stats = replay("zinnia").stats();
    let expected = stats.expected;
    // The background primitive is the first in the database and the largest.
    let big = replay("zinnia").largest().unwrap();
    assert_eq!(big, replay("zinnia").present()[0]);
    let scatter = replay("zinnia").snooping_pixels(Assign::Scatter, &procs, 1);
    let last = replay("zinnia").snooping_pixels(Assign::BackgroundLast, &procs, 1);
    eprintln!("zinnia expected {expected:.0}, scatter {scatter:?}, background-last {last:?}");
    for k in 1..4 {
        assert!(scatter[k] as f64 > 1.04 * expected, "n = {}", procs[k]);
    }
    for k in 0..4 {
        assert!(last[k] < scatter[k], "n = {}", procs[k]);
    }
    assert!((last[3] as f64 / expected - 1.0).abs() <= 0.01);
    let random: f64 = (1..=4)
        .map(|seed| replay("zinnia").snooping_pixels(Assign::Random, &[64], seed)[0] as f64)
        .sum::<f64>()
        / 4.0;
    eprintln!("zinnia random mean over seeds 1..=4 at n=64: {random:.0}");
    assert!(random < scatter[3] as f64);
}
