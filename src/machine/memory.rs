//! A node's memory pool: a capacity, tagged allocations and frees, and high-water marks per
//! tag and per node.
//!
//! Owns memory accounting only; it never stores the data itself. Over capacity is an error
//! naming node, tag, requested and available bytes; an algorithm that models a degradation
//! (adaptive supersampling) asks `available` first and decides for itself.

use std::collections::BTreeMap;

use crate::units::Bytes;

#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum MemError {
    #[error("node {node}: allocating {requested} for '{tag}' exceeds its memory: {available} of {capacity} available")]
    OverCapacity {
        node: u32,
        tag: &'static str,
        requested: Bytes,
        available: Bytes,
        capacity: Bytes,
    },
    #[error(
        "node {node}: freeing {requested} of '{tag}' but only {held} is allocated under that tag"
    )]
    FreeTooMuch {
        node: u32,
        tag: &'static str,
        requested: Bytes,
        held: Bytes,
    },
}

/// High-water marks of one pool.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PoolStats {
    pub capacity: Bytes,
    pub high_water: Bytes,
    /// Per tag, in tag order (deterministic).
    pub high_water_by_tag: BTreeMap<&'static str, Bytes>,
}

#[derive(Clone, Debug)]
pub struct MemoryPool {
    node: u32,
    capacity: Bytes,
    used: Bytes,
    high_water: Bytes,
    by_tag: BTreeMap<&'static str, TagUse>,
}

#[derive(Clone, Copy, Debug, Default)]
struct TagUse {
    held: Bytes,
    high_water: Bytes,
}

impl MemoryPool {
    pub fn new(node: u32, capacity: Bytes) -> MemoryPool {
        MemoryPool {
            node,
            capacity,
            used: Bytes::ZERO,
            high_water: Bytes::ZERO,
            by_tag: BTreeMap::new(),
        }
    }

    pub fn available(&self) -> Bytes {
        self.capacity.saturating_sub(self.used)
    }

    pub fn used(&self) -> Bytes {
        self.used
    }

    pub fn alloc(&mut self, tag: &'static str, bytes: Bytes) -> Result<(), MemError> {
        if bytes > self.available() {
            return Err(MemError::OverCapacity {
                node: self.node,
                tag,
                requested: bytes,
                available: self.available(),
                capacity: self.capacity,
            });
        }
        self.used += bytes;
        self.high_water = self.high_water.max(self.used);
        let t = self.by_tag.entry(tag).or_default();
        t.held += bytes;
        t.high_water = t.high_water.max(t.held);
        Ok(())
    }

    pub fn free(&mut self, tag: &'static str, bytes: Bytes) -> Result<(), MemError> {
        let t = self.by_tag.entry(tag).or_default();
        if bytes > t.held {
            return Err(MemError::FreeTooMuch {
                node: self.node,
                tag,
                requested: bytes,
                held: t.held,
            });
        }
        t.held = t.held - bytes;
        self.used = self.used - bytes;
        Ok(())
    }

    pub fn stats(&self) -> PoolStats {
        PoolStats {
            capacity: self.capacity,
            high_water: self.high_water,
            high_water_by_tag: self
                .by_tag
                .iter()
                .map(|(&tag, t)| (tag, t.high_water))
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tracks_high_water_per_tag_and_node() {
        let mut pool = MemoryPool::new(3, Bytes::new(100));
        pool.alloc("framebuffer", Bytes::new(60)).unwrap();
        pool.alloc("messages", Bytes::new(30)).unwrap();
        pool.free("messages", Bytes::new(30)).unwrap();
        pool.alloc("messages", Bytes::new(10)).unwrap();
        let s = pool.stats();
        assert_eq!(s.high_water, Bytes::new(90));
        assert_eq!(s.high_water_by_tag["messages"], Bytes::new(30));
        assert_eq!(s.high_water_by_tag["framebuffer"], Bytes::new(60));
        assert_eq!(pool.available(), Bytes::new(30));
    }

    #[test]
    fn over_capacity_names_node_tag_and_bytes() {
        let mut pool = MemoryPool::new(7, Bytes::new(100));
        pool.alloc("zbuffer", Bytes::new(80)).unwrap();
        let err = pool.alloc("subpixels", Bytes::new(21)).unwrap_err();
        assert_eq!(
            err.to_string(),
            "node 7: allocating 21B for 'subpixels' exceeds its memory: 20B of 100B available"
        );
        assert_eq!(
            pool.used(),
            Bytes::new(80),
            "a failed allocation changes nothing"
        );
        assert!(pool.free("zbuffer", Bytes::new(81)).is_err());
    }
}
