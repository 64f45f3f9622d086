//! Images out of the rasterizer: PNG encoding of a framebuffer and a deterministic hash of
//! its pixels for tests and reports.
//!
//! Must never pick a file name, create a directory or hash with a seeded hasher
//! (`RandomState`): the hash is FNV-1a, identical on every run and platform.

use std::io::Write;
use std::path::Path;

use super::target::Framebuffer;

/// Why a PNG could not be written.
#[derive(Debug, thiserror::Error)]
pub enum PngError {
    #[error("cannot write {path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("PNG encoding failed: {0}")]
    Encode(#[from] png::EncodingError),
}

/// Encodes the framebuffer's colours as an 8-bit RGB PNG into `out`.
pub fn encode_png<W: Write>(fb: &Framebuffer, out: W) -> Result<(), PngError> {
    let mut enc = png::Encoder::new(out, fb.width(), fb.height());
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut w = enc.write_header()?;
    w.write_image_data(fb.colors().as_flattened())?;
    w.finish()?;
    Ok(())
}

/// Writes the framebuffer as a PNG file at `path` (created or truncated).
pub fn write_png(fb: &Framebuffer, path: &Path) -> Result<(), PngError> {
    let io = |source| PngError::Io {
        path: path.display().to_string(),
        source,
    };
    let file = std::fs::File::create(path).map_err(io)?;
    let mut buf = std::io::BufWriter::new(file);
    encode_png(fb, &mut buf)?;
    buf.flush().map_err(io)
}

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const FNV_PRIME: u64 = 0x0000_0100_0000_01b3;

/// FNV-1a over arbitrary bytes, continuing from `state`.
pub fn fnv1a(state: u64, bytes: &[u8]) -> u64 {
    bytes
        .iter()
        .fold(state, |h, &b| (h ^ u64::from(b)).wrapping_mul(FNV_PRIME))
}

/// FNV-1a over width, height (little endian) and the row-major RGB bytes.
pub fn image_hash(width: u32, height: u32, rgb: &[[u8; 3]]) -> u64 {
    let h = fnv1a(FNV_OFFSET, &width.to_le_bytes());
    let h = fnv1a(h, &height.to_le_bytes());
    fnv1a(h, rgb.as_flattened())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a_matches_published_vectors() {
        assert_eq!(fnv1a(FNV_OFFSET, b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(FNV_OFFSET, b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a(FNV_OFFSET, b"foobar"), 0x8594_4171_f739_67e8);
    }

    #[test]
    fn image_hash_depends_on_shape_and_pixels() {
        let px = [[1u8, 2, 3], [4, 5, 6]];
        assert_ne!(image_hash(2, 1, &px), image_hash(1, 2, &px));
        assert_ne!(
            image_hash(2, 1, &px),
            image_hash(2, 1, &[[1, 2, 3], [4, 5, 7]])
        );
    }
}
