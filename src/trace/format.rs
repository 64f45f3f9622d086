//! The trace file format (version 1, specified in the `trace` module doc and traces/FORMAT.md):
//! the in-memory [`Trace`] (fragments as compact parallel arrays), its encoder and its
//! validating decoder.
//!
//! Must never panic on any input bytes, never allocate more than the file's size justifies,
//! and never hand out a `Trace` whose fragments lie outside its screen or name a primitive
//! outside its database.

use std::path::{Path, PathBuf};

use crate::raster::screen::MAX_VIEWPORT;
use crate::raster::FragmentRecord;

/// The first 8 bytes of every trace file.
pub const MAGIC: [u8; 8] = *b"SORTTRC\n";
/// The only version this sortsim writes and reads.
pub const VERSION: u16 = 1;
/// Flag bit 0: back faces were culled when the trace was recorded.
pub const FLAG_CULLED: u16 = 1;
/// Bytes before the first span.
pub const HEADER_LEN: usize = 44;
/// Bytes of the trailing checksum.
pub const CHECKSUM_LEN: usize = 8;

/// What a trace says about where it came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TraceMeta {
    pub width: u32,
    pub height: u32,
    /// The scene frame recorded.
    pub frame: u32,
    /// Triangles in the frame's database: every primitive id is below this.
    pub primitives: u32,
    /// Back faces were culled when recording.
    pub culled: bool,
}

/// One frame's fragments in generation order, as parallel arrays.
///
/// Invariant: every fragment lies inside `width x height` and names a primitive below
/// `primitives` (checked by [`Trace::new`] and by the decoder).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Trace {
    meta: TraceMeta,
    /// `y * width + x` per fragment.
    pixel: Vec<u32>,
    z: Vec<u32>,
    prim: Vec<u32>,
    rgb: Vec<[u8; 3]>,
}

/// What is wrong with a trace's bytes (or, for [`Trace::new`], with a fragment list).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum FormatError {
    #[error("truncated: the file ends inside the {HEADER_LEN}-byte header (after {len} bytes)")]
    HeaderTruncated { len: usize },
    #[error("bad magic: not a sortsim trace (a trace starts with the bytes \"SORTTRC\\n\")")]
    BadMagic,
    #[error("unsupported version {found} (this sortsim reads version {VERSION})")]
    UnsupportedVersion { found: u16 },
    #[error("unknown flags 0x{flags:04x} (version 1 defines only bit 0, back-face culling)")]
    UnknownFlags { flags: u16 },
    #[error("bad screen size {width}x{height} (valid: 1..={MAX_VIEWPORT} pixels each way)")]
    BadScreen { width: u32, height: u32 },
    #[error("truncated: header says {expected} fragments, file ends after {got}")]
    Truncated { expected: u64, got: u64 },
    #[error("checksum mismatch: the file stores {stored:016x} but its contents hash to {computed:016x} (the file is damaged)")]
    ChecksumMismatch { stored: u64, computed: u64 },
    #[error("count mismatch: header says {header} {what}, the file holds {found}")]
    CountMismatch {
        what: &'static str,
        header: u64,
        found: u64,
    },
    #[error("fragment {index}: {message}")]
    Malformed { index: u64, message: String },
}

/// A [`FormatError`] or an I/O failure, naming the file.
#[derive(Debug, thiserror::Error)]
#[error("{}: {}", file.display(), kind)]
pub struct TraceError {
    pub file: PathBuf,
    pub kind: TraceErrorKind,
}

#[derive(Debug, thiserror::Error)]
pub enum TraceErrorKind {
    #[error(transparent)]
    Format(#[from] FormatError),
    #[error("cannot read: {0}")]
    Read(std::io::Error),
    #[error("cannot write: {0}")]
    Write(std::io::Error),
}

impl Trace {
    /// Builds a trace from fragments in generation order, checking the invariant.
    pub fn new(meta: TraceMeta, fragments: &[FragmentRecord]) -> Result<Trace, FormatError> {
        check_screen(meta.width, meta.height)?;
        let mut t = Trace::empty(meta, fragments.len());
        for (i, f) in fragments.iter().enumerate() {
            t.push(i as u64, f.x, f.y, f.z, f.rgb, f.prim)?;
        }
        Ok(t)
    }

    pub fn meta(&self) -> TraceMeta {
        self.meta
    }

    /// Screen area A in pixels.
    pub fn area(&self) -> usize {
        self.meta.width as usize * self.meta.height as usize
    }

    pub fn len(&self) -> usize {
        self.pixel.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pixel.is_empty()
    }

    /// Pixel index `y * width + x` of every fragment.
    pub fn pixels(&self) -> &[u32] {
        &self.pixel
    }

    pub fn depths(&self) -> &[u32] {
        &self.z
    }

    pub fn prims(&self) -> &[u32] {
        &self.prim
    }

    pub fn colors(&self) -> &[[u8; 3]] {
        &self.rgb
    }

    /// Fragment `i` as the rasterizer recorded it.
    pub fn fragment(&self, i: usize) -> FragmentRecord {
        let w = self.meta.width;
        FragmentRecord {
            x: self.pixel[i] % w,
            y: self.pixel[i] / w,
            z: self.z[i],
            rgb: self.rgb[i],
            prim: self.prim[i],
        }
    }

    pub fn fragments(&self) -> impl Iterator<Item = FragmentRecord> + '_ {
        (0..self.len()).map(|i| self.fragment(i))
    }

    fn empty(meta: TraceMeta, capacity: usize) -> Trace {
        Trace {
            meta,
            pixel: Vec::with_capacity(capacity),
            z: Vec::with_capacity(capacity),
            prim: Vec::with_capacity(capacity),
            rgb: Vec::with_capacity(capacity),
        }
    }

    fn push(
        &mut self,
        index: u64,
        x: u32,
        y: u32,
        z: u32,
        rgb: [u8; 3],
        prim: u32,
    ) -> Result<(), FormatError> {
        let m = self.meta;
        if x >= m.width || y >= m.height {
            return Err(FormatError::Malformed {
                index,
                message: format!(
                    "pixel ({x}, {y}) is outside the {}x{} screen",
                    m.width, m.height
                ),
            });
        }
        if prim >= m.primitives {
            return Err(FormatError::Malformed {
                index,
                message: format!(
                    "primitive {prim} is not below the primitive count {}",
                    m.primitives
                ),
            });
        }
        self.pixel.push(y * m.width + x);
        self.z.push(z);
        self.prim.push(prim);
        self.rgb.push(rgb);
        Ok(())
    }
}

fn check_screen(width: u32, height: u32) -> Result<(), FormatError> {
    let ok = |v: u32| (1..=MAX_VIEWPORT).contains(&v);
    if ok(width) && ok(height) {
        Ok(())
    } else {
        Err(FormatError::BadScreen { width, height })
    }
}

/// FNV-1a 64: the checksum over every byte before it.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

fn zigzag(v: i64) -> u64 {
    ((v << 1) ^ (v >> 63)) as u64
}

fn unzigzag(u: u64) -> i64 {
    ((u >> 1) as i64) ^ -((u & 1) as i64)
}

fn put_varint(out: &mut Vec<u8>, mut v: u64) {
    while v >= 0x80 {
        out.push(v as u8 | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

/// Runs of one primitive on one row at consecutive x, as `(first fragment, length)`.
fn spans(t: &Trace) -> Vec<(usize, usize)> {
    let mut out: Vec<(usize, usize)> = Vec::new();
    for i in 0..t.len() {
        let continues = i > 0
            && t.prim[i] == t.prim[i - 1]
            && t.pixel[i] == t.pixel[i - 1].wrapping_add(1)
            && t.pixel[i] % t.meta.width != 0;
        match out.last_mut() {
            Some((_, len)) if continues => *len += 1,
            _ => out.push((i, 1)),
        }
    }
    out
}

/// The file bytes of `trace`.
pub fn encode(trace: &Trace) -> Vec<u8> {
    let runs = spans(trace);
    let m = trace.meta;
    let mut out = Vec::with_capacity(HEADER_LEN + 2 * trace.len() + 8 * runs.len() + 8);
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    let flags = if m.culled { FLAG_CULLED } else { 0 };
    out.extend_from_slice(&flags.to_le_bytes());
    for v in [m.width, m.height, m.frame, m.primitives] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&(trace.len() as u64).to_le_bytes());
    out.extend_from_slice(&(runs.len() as u64).to_le_bytes());
    let (mut py, mut px, mut pprim, mut pz) = (0i64, 0i64, 0i64, 0i64);
    for (start, len) in runs {
        let f = trace.fragment(start);
        put_varint(&mut out, zigzag(f.y as i64 - py));
        put_varint(&mut out, zigzag(f.x as i64 - px));
        put_varint(&mut out, len as u64);
        put_varint(&mut out, zigzag(f.prim as i64 - pprim));
        put_varint(&mut out, zigzag(f.z as i64 - pz));
        out.extend_from_slice(&f.rgb);
        (py, px, pprim, pz) = (f.y as i64, f.x as i64, f.prim as i64, f.z as i64);
        let mut dz = 0i64;
        for i in start + 1..start + len {
            let step = trace.z[i] as i64 - trace.z[i - 1] as i64;
            let changed = trace.rgb[i] != trace.rgb[i - 1];
            put_varint(&mut out, zigzag(step - dz) << 1 | changed as u64);
            if changed {
                out.extend_from_slice(&trace.rgb[i]);
            }
            dz = step;
        }
    }
    let sum = fnv1a64(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    out
}

/// Reads a span body; knows nothing of the checksum.
struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
}

/// Why the span body did not decode.
enum BodyError {
    /// The bytes ended after this many whole fragments.
    RanOut(u64),
    /// More fragments or spans than the header announced, or bytes left over.
    Counts(FormatError),
    /// A value out of range.
    Invalid(FormatError),
}

impl Cursor<'_> {
    fn byte(&mut self, done: u64) -> Result<u8, BodyError> {
        let b = *self.bytes.get(self.at).ok_or(BodyError::RanOut(done))?;
        self.at += 1;
        Ok(b)
    }

    fn varint(&mut self, done: u64) -> Result<u64, BodyError> {
        let mut v = 0u64;
        for shift in (0..70).step_by(7) {
            let b = self.byte(done)?;
            if shift == 63 && b > 1 {
                break;
            }
            v |= ((b & 0x7f) as u64) << shift;
            if b & 0x80 == 0 {
                return Ok(v);
            }
        }
        Err(BodyError::Invalid(FormatError::Malformed {
            index: done,
            message: "malformed varint (more than 64 bits)".into(),
        }))
    }

    fn rgb(&mut self, done: u64) -> Result<[u8; 3], BodyError> {
        Ok([self.byte(done)?, self.byte(done)?, self.byte(done)?])
    }
}

/// The fixed-size header fields after the magic.
struct Header {
    meta: TraceMeta,
    fragments: u64,
    spans: u64,
}

fn header(bytes: &[u8]) -> Result<Header, FormatError> {
    if bytes.len() < MAGIC.len() || bytes[..MAGIC.len()] != MAGIC {
        if bytes.len() < MAGIC.len() && MAGIC.starts_with(bytes) {
            return Err(FormatError::HeaderTruncated { len: bytes.len() });
        }
        return Err(FormatError::BadMagic);
    }
    if bytes.len() < HEADER_LEN {
        return Err(FormatError::HeaderTruncated { len: bytes.len() });
    }
    let u16_at = |o: usize| u16::from_le_bytes([bytes[o], bytes[o + 1]]);
    let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().expect("4 bytes"));
    let u64_at = |o: usize| u64::from_le_bytes(bytes[o..o + 8].try_into().expect("8 bytes"));
    let version = u16_at(8);
    if version != VERSION {
        return Err(FormatError::UnsupportedVersion { found: version });
    }
    let flags = u16_at(10);
    if flags & !FLAG_CULLED != 0 {
        return Err(FormatError::UnknownFlags { flags });
    }
    let (width, height) = (u32_at(12), u32_at(16));
    check_screen(width, height)?;
    Ok(Header {
        meta: TraceMeta {
            width,
            height,
            frame: u32_at(20),
            primitives: u32_at(24),
            culled: flags & FLAG_CULLED != 0,
        },
        fragments: u64_at(28),
        spans: u64_at(36),
    })
}

/// Decodes the spans of `body` (the bytes between header and checksum).
fn body(h: &Header, body: &[u8]) -> Result<Trace, BodyError> {
    // Every fragment takes at least one byte: never reserve more than the body can hold.
    let cap = h.fragments.min(body.len() as u64) as usize;
    let mut t = Trace::empty(h.meta, cap);
    let mut c = Cursor { bytes: body, at: 0 };
    let (mut py, mut px, mut pprim, mut pz) = (0i64, 0i64, 0i64, 0i64);
    let invalid = |index: u64, message: &str| {
        BodyError::Invalid(FormatError::Malformed {
            index,
            message: message.to_string(),
        })
    };
    let mut spans = 0u64;
    while c.at < body.len() {
        let done = t.len() as u64;
        if spans == h.spans {
            return Err(BodyError::Counts(FormatError::CountMismatch {
                what: "spans",
                header: h.spans,
                found: spans + 1,
            }));
        }
        let y = py + unzigzag(c.varint(done)?);
        let x = px + unzigzag(c.varint(done)?);
        let len = c.varint(done)?;
        let prim = pprim + unzigzag(c.varint(done)?);
        let mut z = pz + unzigzag(c.varint(done)?);
        let mut rgb = c.rgb(done)?;
        if len == 0 {
            return Err(invalid(done, "span of length 0"));
        }
        if len > h.fragments - done {
            return Err(BodyError::Counts(FormatError::CountMismatch {
                what: "fragments",
                header: h.fragments,
                found: done + len,
            }));
        }
        let in_u32 = |v: i64| u32::try_from(v).ok();
        let (Some(yu), Some(xu), Some(pu)) = (in_u32(y), in_u32(x), in_u32(prim)) else {
            return Err(invalid(done, "span position or primitive out of range"));
        };
        (py, px, pprim, pz) = (y, x, prim, z);
        let mut dz = 0i64;
        for k in 0..len {
            let index = done + k;
            if k > 0 {
                let v = c.varint(index)?;
                dz += unzigzag(v >> 1);
                z += dz;
                if v & 1 == 1 {
                    rgb = c.rgb(index)?;
                }
            }
            let Some(zu) = in_u32(z) else {
                return Err(invalid(index, "depth leaves the u32 range"));
            };
            let xk = xu.checked_add(k as u32).filter(|_| k < u32::MAX as u64);
            let Some(xk) = xk else {
                return Err(invalid(index, "span runs past x = 2^32"));
            };
            t.push(index, xk, yu, zu, rgb, pu)
                .map_err(BodyError::Invalid)?;
        }
        spans += 1;
    }
    let counts = |what, header, found| {
        BodyError::Counts(FormatError::CountMismatch {
            what,
            header,
            found,
        })
    };
    if t.len() as u64 != h.fragments {
        return Err(if t.len() as u64 > h.fragments {
            counts("fragments", h.fragments, t.len() as u64)
        } else {
            BodyError::RanOut(t.len() as u64)
        });
    }
    if spans != h.spans {
        return Err(counts("spans", h.spans, spans));
    }
    Ok(t)
}

/// Decodes and validates a whole trace file's bytes.
pub fn decode(bytes: &[u8]) -> Result<Trace, FormatError> {
    let h = header(bytes)?;
    let end = bytes.len().saturating_sub(CHECKSUM_LEN).max(HEADER_LEN);
    let stored = (bytes.len() >= HEADER_LEN + CHECKSUM_LEN)
        .then(|| u64::from_le_bytes(bytes[end..].try_into().expect("8 checksum bytes")));
    let computed = fnv1a64(&bytes[..end]);
    let decoded = body(&h, &bytes[HEADER_LEN..end]);
    let sound = stored == Some(computed);
    match (decoded, sound) {
        (Ok(t), true) => Ok(t),
        // The file ends inside the checksum of an otherwise complete trace.
        (Ok(t), false) if stored.is_none() => Err(FormatError::Truncated {
            expected: h.fragments,
            got: t.len() as u64,
        }),
        (Err(BodyError::RanOut(got)), false) => Err(FormatError::Truncated {
            expected: h.fragments,
            got,
        }),
        (Err(BodyError::RanOut(got)), true) => Err(FormatError::CountMismatch {
            what: "fragments",
            header: h.fragments,
            found: got,
        }),
        (Err(BodyError::Counts(e) | BodyError::Invalid(e)), true) => Err(e),
        (_, false) => Err(FormatError::ChecksumMismatch {
            stored: stored.unwrap_or(0),
            computed,
        }),
    }
}

/// Reads and validates a trace file.
pub fn read_trace(path: &Path) -> Result<Trace, TraceError> {
    let err = |kind| TraceError {
        file: path.to_path_buf(),
        kind,
    };
    let bytes = crate::spec::read_input_bytes(path).map_err(|e| err(TraceErrorKind::Read(e)))?;
    decode(&bytes).map_err(|e| err(e.into()))
}

/// Writes `trace` to `path` (atomically: a temporary file, then a rename).
pub fn write_trace(path: &Path, trace: &Trace) -> Result<u64, TraceError> {
    let bytes = encode(trace);
    crate::output::write_atomic(path, &bytes).map_err(|e| TraceError {
        file: path.to_path_buf(),
        kind: TraceErrorKind::Write(e),
    })?;
    Ok(bytes.len() as u64)
}
