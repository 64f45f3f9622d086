//! Fixed-size polygon buffers, one per destination: triangles accumulate until a buffer is
//! full, then it is handed back to be sent; `flush` empties every buffer at the end of the
//! transformation, sending one (possibly empty) message to each destination so that it knows
//! the sender is done (paper 002: "each processor sends a minimum of one message to each
//! other processor").
//!
//! Owns buffer bookkeeping and message sizes. Must never send anything itself.

use crate::raster::ScreenTriangle;
use crate::units::Bytes;

/// Header bytes of every polygon message (frame number, count, flags).
pub const HEADER_BYTES: u64 = 16;

/// Bytes of one triangle in a polygon message.
pub const TRIANGLE_BYTES: u64 = ScreenTriangle::PAYLOAD_BYTES as u64;

/// Bytes of one triangle in a first-step (two-step) message: the triangle and its final
/// destination.
pub const ROUTED_TRIANGLE_BYTES: u64 = TRIANGLE_BYTES + 4;

/// The size of a message carrying `n` items of `item_bytes` each.
pub fn message_bytes(n: usize, item_bytes: u64) -> Bytes {
    Bytes::new(HEADER_BYTES + n as u64 * item_bytes)
}

/// One buffer per destination, each holding at most `capacity` items.
pub struct Buffers<T> {
    capacity: usize,
    slots: Vec<Vec<T>>,
}

impl<T> Buffers<T> {
    /// Buffers of `buffer_bytes` for `destinations` destinations; at least one item fits.
    pub fn new(destinations: usize, buffer_bytes: Bytes, item_bytes: u64) -> Buffers<T> {
        let capacity =
            (buffer_bytes.get().saturating_sub(HEADER_BYTES) / item_bytes).max(1) as usize;
        // Host vectors grow on demand: a 512-processor run would otherwise hold 512 x 512
        // full buffers at once (the simulated machine is charged for them regardless).
        Buffers {
            capacity,
            slots: (0..destinations).map(|_| Vec::new()).collect(),
        }
    }

    /// Adds `item` for `dst`; returns the buffer's contents when this filled it.
    pub fn push(&mut self, dst: usize, item: T) -> Option<Vec<T>> {
        let slot = &mut self.slots[dst];
        slot.push(item);
        (slot.len() == self.capacity).then(|| std::mem::take(slot))
    }

    /// Empties the buffer of `dst`.
    pub fn take(&mut self, dst: usize) -> Vec<T> {
        std::mem::take(&mut self.slots[dst])
    }

    pub fn capacity(&self) -> usize {
        self.capacity
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_4kb_buffer_holds_what_fits_after_the_header() {
        let mut b: Buffers<u32> = Buffers::new(2, Bytes::new(4096), TRIANGLE_BYTES);
        assert_eq!(
            b.capacity(),
            ((4096 - HEADER_BYTES) / TRIANGLE_BYTES) as usize
        );
        for i in 0..b.capacity() as u32 - 1 {
            assert!(b.push(1, i).is_none());
        }
        let full = b.push(1, 99).expect("the last item fills it");
        assert_eq!(full.len(), b.capacity());
        assert!(message_bytes(full.len(), TRIANGLE_BYTES).get() <= 4096);
        assert!(b.take(1).is_empty() && b.take(0).is_empty());
    }
}
