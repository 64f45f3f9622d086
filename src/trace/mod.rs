//! Pixel traces (paper 003, section 2): every fragment a frame generates before z-buffering,
//! recorded once (`record`), stored in a compact versioned binary file (`format`), and
//! replayed (`replay`) to count the merge traffic of object-parallel rendering on n
//! processors without rasterizing again: straightforward merging (direct send, Kubota
//! Denali), PixelFlow's pipeline, and Cox and Hanrahan's distributed snooping.
//!
//! Must never rasterize during replay, never read the clock into an output, and never
//! iterate a hash map: the same trace, assignment and seed give byte-identical reports.
//!
//! # Trace file format, version 1
//! All integers little-endian. `varint` is LEB128 (7 bits per byte, low bits first, at most
//! 10 bytes); `zigzag` maps a signed delta to unsigned (0, -1, 1, -2, ... -> 0, 1, 2, 3, ...).
//!
//! ```text
//! offset size  field
//! 0      8     magic  b"SORTTRC\n"
//! 8      2     version u16 = 1
//! 10     2     flags u16: bit 0 = back faces were culled when recorded; other bits 0
//! 12     4     width u32  (1..=16384)
//! 16     4     height u32 (1..=16384)
//! 20     4     frame u32  (the scene frame recorded)
//! 24     4     primitive count u32 (triangles in the frame's database; ids are 0..count)
//! 28     8     fragment count u64
//! 36     8     span count u64
//! 44     ...   spans, in generation order
//! end-8  8     FNV-1a 64 of every byte before it
//! ```
//!
//! A span is a run of fragments of one primitive on one row at consecutive x (what the
//! rasterizer emits per triangle and scanline; any fragment list splits into such runs).
//! Each span is `zigzag(y - previous span's y)`, `zigzag(x0 - previous span's x0)`,
//! `varint(length >= 1)`, `zigzag(prim - previous span's prim)`, then its fragments. The
//! first fragment of a span is `zigzag(z - previous span's first z)` and 3 raw rgb bytes.
//! Every later fragment is one varint `zigzag(zz) << 1 | c`, where `zz` is the second
//! difference of z (depth is linear along a span, so it is almost always 0) and `c` says
//! that 3 raw rgb bytes follow (the colour changed); otherwise the colour repeats. The
//! "previous span" values start at 0. Flat-shaded fragments cost about one byte, a new
//! span about eight.
//!
//! The reader checks, in this order: the header is complete, the magic, the version, the
//! flags, the screen size; then it decodes the spans (every fragment inside the screen,
//! every primitive id below the primitive count, no run past the fragment count) and
//! compares the checksum. A body that ends early with a bad checksum is reported as
//! truncated; a body that disagrees with the header's counts under a good checksum as a
//! count mismatch; any other damage as a checksum mismatch.

pub mod format;
pub mod record;
pub mod replay;

pub use format::{decode, encode, read_trace, write_trace, FormatError, Trace, TraceError};
pub use record::{record_frame, record_scene};
