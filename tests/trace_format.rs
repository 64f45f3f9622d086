//! The pixel-trace file format (paper 003, section 2: "compressed pixel records" written
//! before z-buffering): encode/decode round trips exactly, stays compact, and every kind of
//! damage is refused with its own message and never a panic.

use proptest::prelude::*;
use sortsim::raster::FragmentRecord;
use sortsim::scene::Scene;
use sortsim::trace::format::{encode, TraceMeta, HEADER_LEN};
use sortsim::trace::{decode, record_scene, Trace};

fn meta(width: u32, height: u32, primitives: u32) -> TraceMeta {
    TraceMeta {
        width,
        height,
        frame: 3,
        primitives,
        culled: true,
    }
}

/// A small trace with spans, colour changes, depth steps and a lone fragment.
fn sample() -> Trace {
    let mut f = Vec::new();
    for (prim, y, x0, len, z0, dz) in [
        (0u32, 2u32, 1u32, 5u32, 1000u32, 7i64),
        (0, 3, 0, 7, 990, 6),
        (2, 3, 4, 3, 50, -3),
        (1, 0, 9, 1, u32::MAX - 1, 0),
    ] {
        for k in 0..len {
            f.push(FragmentRecord {
                x: x0 + k,
                y,
                z: (z0 as i64 + dz * k as i64) as u32,
                rgb: [k as u8, 200, (prim * 40) as u8],
                prim,
            });
        }
    }
    Trace::new(meta(10, 6, 3), &f).unwrap()
}

fn check(bytes: &[u8], expected: &str) {
    let err = decode(bytes).expect_err("damaged trace must be refused");
    let msg = err.to_string();
    assert!(msg.contains(expected), "expected {expected:?} in {msg:?}");
}

/// Rewrites the checksum so only the intended damage remains.
fn reseal(bytes: &mut [u8]) {
    let n = bytes.len() - 8;
    let sum = sortsim::trace::format::fnv1a64(&bytes[..n]);
    bytes[n..].copy_from_slice(&sum.to_le_bytes());
}

#[test]
fn round_trip_is_exact_for_a_hand_built_trace() {
    let t = sample();
    let back = decode(&encode(&t)).unwrap();
    assert_eq!(back, t);
    assert_eq!(back.meta(), meta(10, 6, 3));
    assert_eq!(back.fragments().count(), 16);
}

#[test]
fn empty_trace_round_trips() {
    let t = Trace::new(meta(4, 4, 0), &[]).unwrap();
    assert_eq!(decode(&encode(&t)).unwrap(), t);
}

#[test]
fn fragments_outside_the_screen_or_database_cannot_make_a_trace() {
    let f = |x, y, prim| FragmentRecord {
        x,
        y,
        z: 1,
        rgb: [0; 3],
        prim,
    };
    let e = Trace::new(meta(10, 6, 3), &[f(10, 0, 0)]).unwrap_err();
    assert!(e.to_string().contains("outside the 10x6 screen"), "{e}");
    let e = Trace::new(meta(10, 6, 3), &[f(0, 0, 3)]).unwrap_err();
    assert!(
        e.to_string().contains("not below the primitive count 3"),
        "{e}"
    );
    let e = Trace::new(meta(0, 6, 3), &[]).unwrap_err();
    assert!(e.to_string().contains("bad screen size 0x6"), "{e}");
}

/// Paper 003 Table 1's Cube trace has 6.46 M fragments; the brief asks for well under 10
/// bytes per fragment. The Zinnia stand-in (0.42 M fragments) is recorded and measured here;
/// the bound is 4 bytes per fragment (measured about 2.2; Cube measures 1.9).
#[test]
fn recorded_stand_in_round_trips_and_is_compact() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = Scene::load(&root.join("scenes/p003-zinnia.json")).unwrap();
    let t = record_scene(&scene, 0).unwrap();
    let bytes = encode(&t);
    let per_fragment = bytes.len() as f64 / t.len() as f64;
    assert!(per_fragment < 4.0, "{per_fragment:.2} bytes per fragment");
    let back = decode(&bytes).unwrap();
    assert!(back == t, "decoded trace differs from the recording");
}

#[test]
fn bad_magic_is_refused() {
    let mut b = encode(&sample());
    b[0] = b'X';
    check(&b, "bad magic: not a sortsim trace");
    check(b"P6\n640 480\n255\n", "bad magic");
}

#[test]
fn other_versions_are_refused() {
    let mut b = encode(&sample());
    b[8] = 7;
    reseal(&mut b);
    check(&b, "unsupported version 7 (this sortsim reads version 1)");
}

#[test]
fn unknown_flags_and_bad_screens_are_refused() {
    let mut b = encode(&sample());
    b[10] = 0x04;
    check(&b, "unknown flags 0x0004");
    let mut b = encode(&sample());
    b[12..16].copy_from_slice(&0u32.to_le_bytes());
    check(&b, "bad screen size 0x6");
}

#[test]
fn a_flipped_byte_is_a_checksum_mismatch() {
    let clean = encode(&sample());
    for at in [
        HEADER_LEN,
        HEADER_LEN + 5,
        clean.len() - 12,
        clean.len() - 1,
    ] {
        let mut b = clean.clone();
        b[at] ^= 0x10;
        check(&b, "checksum mismatch");
    }
}

#[test]
fn truncation_anywhere_is_reported_as_truncation() {
    let clean = encode(&sample());
    for len in [0, 5, HEADER_LEN - 1] {
        check(
            &clean[..len],
            "truncated: the file ends inside the 44-byte header",
        );
    }
    for len in [HEADER_LEN, HEADER_LEN + 3, clean.len() / 2, clean.len() - 1] {
        check(
            &clean[..len],
            "truncated: header says 16 fragments, file ends after",
        );
    }
}

#[test]
fn counts_that_disagree_with_the_body_are_refused() {
    let clean = encode(&sample());
    let mut more = clean.clone();
    more[28..36].copy_from_slice(&20u64.to_le_bytes());
    reseal(&mut more);
    check(
        &more,
        "count mismatch: header says 20 fragments, the file holds 16",
    );
    let mut fewer = clean.clone();
    fewer[28..36].copy_from_slice(&10u64.to_le_bytes());
    reseal(&mut fewer);
    check(&fewer, "count mismatch: header says 10 fragments");
    let mut spans = clean.clone();
    spans[36..44].copy_from_slice(&2u64.to_le_bytes());
    reseal(&mut spans);
    check(&spans, "count mismatch: header says 2 spans");
    let mut huge = clean;
    huge[28..36].copy_from_slice(&u64::MAX.to_le_bytes());
    reseal(&mut huge);
    check(&huge, "count mismatch");
}

#[test]
fn sealed_out_of_range_values_are_refused() {
    let mut b = encode(&sample());
    // Primitive count 2: the sample names primitive 2.
    b[24..28].copy_from_slice(&2u32.to_le_bytes());
    reseal(&mut b);
    check(&b, "primitive 2 is not below the primitive count 2");
    let mut b = encode(&sample());
    b[12..16].copy_from_slice(&8u32.to_le_bytes());
    reseal(&mut b);
    check(&b, "is outside the 8x6 screen");
}

fn fragment_list() -> impl Strategy<Value = (u32, u32, Vec<FragmentRecord>)> {
    (1u32..40, 1u32..30).prop_flat_map(|(w, h)| {
        let frag = (0..w, 0..h, any::<u32>(), any::<[u8; 3]>(), 0u32..50)
            .prop_map(|(x, y, z, rgb, prim)| FragmentRecord { x, y, z, rgb, prim });
        // Runs of consecutive x exercise the span encoding, random points the rest.
        let run = (frag, 1u32..8, -5i64..5).prop_map(move |(f, len, dz)| {
            (0..len)
                .filter(|k| f.x + k < w)
                .map(|k| FragmentRecord {
                    x: f.x + k,
                    z: (f.z as i64 + dz * k as i64).clamp(0, u32::MAX as i64) as u32,
                    ..f
                })
                .collect::<Vec<_>>()
        });
        (
            Just(w),
            Just(h),
            prop::collection::vec(run, 0..40).prop_map(|r| r.concat()),
        )
    })
}

proptest! {
    /// Any fragment list (in any order, with any depths and colours) survives a round trip
    /// unchanged, and any truncation of its file is refused without a panic.
    #[test]
    fn random_fragment_lists_round_trip((w, h, frags) in fragment_list(), cut in 0usize..1000) {
        let t = Trace::new(meta(w, h, 50), &frags).unwrap();
        let bytes = encode(&t);
        let back = decode(&bytes).unwrap();
        prop_assert_eq!(back.fragments().collect::<Vec<_>>(), frags);
        let cut = cut % bytes.len();
        prop_assert!(decode(&bytes[..cut]).is_err());
    }

    /// Arbitrary bytes after a valid header never panic the decoder.
    #[test]
    fn garbage_bodies_never_panic(body in prop::collection::vec(any::<u8>(), 0..200)) {
        let mut b = encode(&sample())[..HEADER_LEN].to_vec();
        b.extend_from_slice(&body);
        let _ = decode(&b);
    }
}

/// A file cut inside the checksum of an empty trace is truncated, not "damaged".
#[test]
fn empty_trace_cut_inside_its_checksum_is_truncated() {
    let t = Trace::new(meta(4, 4, 0), &[]).unwrap();
    let b = encode(&t);
    check(&b[..b.len() - 2], "truncated: header says 0 fragments");
}
