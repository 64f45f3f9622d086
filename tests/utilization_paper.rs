//! Paper 002 (Ellsworth), Figure 4, on the PLB head stand-in: the utilization simulator's
//! curves have the paper's shape. Each tolerance is written next to its assertion with the
//! reason it is what it is.
//!
//! Must never pin exact utilization values: the stand-in is not the PLB head, only its
//! shape is the claim.

use std::path::Path;
use std::sync::OnceLock;

use sortsim::algo::sort_middle::utilization::{simulate, Config, CountsMode, Outcome};
use sortsim::scene::Scene;
use sortsim::spec::machine::load_machine;

const PROCS: [u32; 10] = [1, 2, 4, 8, 16, 32, 64, 128, 256, 512];
const GRANULARITIES: [u32; 5] = [1, 2, 4, 8, 12];
const BALANCED: [CountsMode; 2] = [CountsMode::Current, CountsMode::Previous];

/// One simulation shared by every test: the PLB head stand-in, every 4th frame of its 80
/// (frames 1, 5, ..., 77, so that each sampled frame has its own previous frame), costs
/// from the Delta spec.
fn plb() -> &'static Outcome {
    static OUTCOME: OnceLock<Outcome> = OnceLock::new();
    OUTCOME.get_or_init(|| {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let scene = Scene::load(&root.join("scenes/plb-head-standin.json")).unwrap();
        let machine = load_machine(&root.join("machines/delta.json")).unwrap();
        let frames: Vec<u32> = (1..80).step_by(4).collect();
        let cfg = Config::new(&PROCS, &GRANULARITIES, &frames).unwrap();
        simulate(&scene, &machine, &cfg).unwrap()
    })
}

fn u(n: u32, g: u32, mode: CountsMode) -> f64 {
    plb()
        .cell(n, g, mode)
        .unwrap_or_else(|| panic!("no cell N={n} g={g} {mode:?}"))
        .utilization
}

#[test]
fn one_processor_is_always_fully_utilized() {
    for g in GRANULARITIES {
        for mode in CountsMode::ALL {
            assert_eq!(u(1, g, mode), 1.0, "g={g} {mode:?}");
        }
    }
}

#[test]
fn utilization_rises_with_the_granularity_ratio() {
    for mode in BALANCED {
        for n in PROCS.into_iter().filter(|&n| n >= 8) {
            // Figure 4: "the utilization increases as the granularity ratio increases". A
            // step may dip by up to 3 points: a new ratio is a new grid (other region shapes
            // and boundaries), and the packing balances estimates, not the accurate times.
            for w in GRANULARITIES.windows(2) {
                let (a, b) = (u(n, w[0], mode), u(n, w[1], mode));
                assert!(
                    b >= a - 0.03,
                    "N={n} {mode:?}: g={} {a:.3} -> g={} {b:.3}",
                    w[0],
                    w[1]
                );
            }
            // Over the whole range the rise is large: one region per processor leaves most
            // processors idle once N >= 8 (the head covers a fraction of the screen).
            let (lo, hi) = (u(n, 1, mode), u(n, 12, mode));
            assert!(hi >= lo + 0.2, "N={n} {mode:?}: g=1 {lo:.3}, g=12 {hi:.3}");
        }
        // With 2 and 4 processors every curve but g=1's is near the top of the chart.
        for n in [2, 4] {
            for g in GRANULARITIES.into_iter().filter(|&g| g >= 2) {
                assert!(
                    u(n, g, mode) >= 0.9,
                    "N={n} g={g} {mode:?}: {:.3}",
                    u(n, g, mode)
                );
            }
        }
    }
}

#[test]
fn utilization_falls_as_processors_are_added() {
    for mode in BALANCED {
        for g in GRANULARITIES {
            // Figure 4: "a decrease in utilization as the number of processors increases".
            // One doubling may gain up to 3 points (the same grid-change effect as above).
            for w in PROCS.windows(2) {
                let (a, b) = (u(w[0], g, mode), u(w[1], g, mode));
                assert!(
                    b <= a + 0.03,
                    "g={g} {mode:?}: N={} {a:.3} -> N={} {b:.3}",
                    w[0],
                    w[1]
                );
            }
            // And from 8 to 512 processors it falls by at least 5 points at every ratio.
            let (small, large) = (u(8, g, mode), u(512, g, mode));
            assert!(
                large <= small - 0.05,
                "g={g} {mode:?}: N=8 {small:.3}, N=512 {large:.3}"
            );
        }
    }
}

#[test]
fn previous_frame_counts_cost_little_at_512_processors() {
    for g in [4, 8, 12] {
        let (current, previous) = (
            u(512, g, CountsMode::Current),
            u(512, g, CountsMode::Previous),
        );
        // Paper 002: "For 512 processors, the drop in utilization ranges only up to 7
        // percent" (12 on another model). The PLB stand-in turns 4.5 degrees a frame as the
        // benchmark does, and its drop stays within the paper's 7 points; previous-frame
        // counts should not beat the current frame's by more than noise (1 point).
        assert!(
            current - previous <= 0.07,
            "g={g}: current {current:.3}, previous {previous:.3}"
        );
        assert!(
            current - previous >= -0.01,
            "g={g}: current {current:.3}, previous {previous:.3}"
        );
    }
}

#[test]
fn bin_packing_is_never_worse_than_the_interleaved_pattern() {
    for n in PROCS {
        for g in GRANULARITIES {
            let interleaved = u(n, g, CountsMode::Interleaved);
            for mode in BALANCED {
                // Greedy packing balances estimates, so on a frame it can lose to r mod N by
                // luck; averaged over the sequence it must not, beyond half a point (where
                // both are above 95%).
                assert!(
                    u(n, g, mode) >= interleaved - 0.005,
                    "N={n} g={g} {mode:?}: {:.3} < {interleaved:.3}",
                    u(n, g, mode)
                );
            }
        }
    }
    // Where balancing matters it wins by far: 512 processors, 12 regions each.
    assert!(u(512, 12, CountsMode::Current) >= u(512, 12, CountsMode::Interleaved) + 0.2);
}

#[test]
fn the_performance_model_normalizes_each_processor_count_to_a_mean_of_one() {
    for n in PROCS {
        let cells: Vec<_> = plb()
            .cells
            .iter()
            .filter(|c| c.procs == n && c.counts == CountsMode::Previous)
            .collect();
        let mean = cells.iter().map(|c| c.relative_time).sum::<f64>() / cells.len() as f64;
        assert!(
            (mean - 1.0).abs() < 1e-9,
            "N={n}: mean relative time {mean}"
        );
        assert!(cells
            .iter()
            .all(|c| c.total_s() > 0.0 && c.overlap_factor >= 1.0));
    }
}
