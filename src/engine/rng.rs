//! Named random streams: every random draw in a run comes from a ChaCha stream derived from
//! the run's seed and a stream name, so adding a stream never shifts another.
//!
//! Must never touch OS randomness or global state.

use rand::SeedableRng;
use rand_chacha::ChaCha12Rng;

/// The stream `name` of the run seeded with `seed`. The name is hashed (FNV-1a, fixed across
/// platforms and releases) into ChaCha's 64-bit stream number.
pub fn rng_stream(seed: u64, name: &str) -> ChaCha12Rng {
    let mut rng = ChaCha12Rng::seed_from_u64(seed);
    rng.set_stream(fnv1a(name.as_bytes()));
    rng
}

fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngCore;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let a1 = rng_stream(7, "assign").next_u64();
        let a2 = rng_stream(7, "assign").next_u64();
        let b = rng_stream(7, "phold/3").next_u64();
        let c = rng_stream(8, "assign").next_u64();
        assert_eq!(a1, a2);
        assert_ne!(a1, b);
        assert_ne!(a1, c);
        // Pinned: a change of generator, seeding or name hash would silently change every run.
        assert_eq!(fnv1a(b"assign"), 0x8fa7_71bd_787e_d1ec);
        assert_eq!(a1, 0xb37f_d1fc_5f77_46fa);
    }
}
