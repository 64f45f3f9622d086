//! Image error against a reference: the mean absolute error over the rgb channels, in levels
//! 0..255, and the share of pixels with any channel more than one level away.
//!
//! Owns the metric and nothing else. Must never render, round the reference (it compares
//! against the exact box-filtered mean), or depend on anything but the two images.

/// How far an 8-bit image is from a reference.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ImageError {
    /// Mean over pixels and the three channels of |image - reference|, in levels.
    pub mae_levels: f64,
    /// Largest |image - reference| of any channel, in levels.
    pub max_abs_levels: f64,
    /// Pixels with any channel more than one level away, over all pixels (0..=1).
    pub off_by_more_than_one_share: f64,
}

#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("the image has {image} pixels but the reference has {reference}")]
pub struct SizeMismatch {
    pub image: usize,
    pub reference: usize,
}

/// Compares `image` with `reference`, pixel for pixel (both row-major, same size).
pub fn image_error(image: &[[u8; 3]], reference: &[[f64; 3]]) -> Result<ImageError, SizeMismatch> {
    if image.len() != reference.len() {
        return Err(SizeMismatch {
            image: image.len(),
            reference: reference.len(),
        });
    }
    let (mut sum, mut max, mut off) = (0.0f64, 0.0f64, 0usize);
    for (px, r) in image.iter().zip(reference) {
        let d = [0, 1, 2].map(|k| (f64::from(px[k]) - r[k]).abs());
        sum += d[0] + d[1] + d[2];
        max = d.iter().copied().fold(max, f64::max);
        off += usize::from(d.iter().any(|&v| v > 1.0));
    }
    let pixels = image.len().max(1) as f64;
    Ok(ImageError {
        mae_levels: sum / (3.0 * pixels),
        max_abs_levels: max,
        off_by_more_than_one_share: off as f64 / pixels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_images_have_no_error() {
        let img = [[10u8, 20, 30], [255, 0, 7]];
        let r = img.map(|p| p.map(f64::from));
        assert_eq!(image_error(&img, &r).unwrap(), ImageError::default());
    }

    #[test]
    fn hand_made_images_give_exact_values() {
        // Pixel 0: off by (1, 0, 0.5): within one level. Pixel 1: off by (0, 3, 0): counted.
        // Pixel 2 and 3 exact. MAE = (1 + 0.5 + 3) / 12 = 0.375.
        let img = [[11u8, 20, 30], [0, 3, 0], [5, 5, 5], [255, 255, 255]];
        let r = [
            [10.0, 20.0, 29.5],
            [0.0, 0.0, 0.0],
            [5.0, 5.0, 5.0],
            [255.0, 255.0, 255.0],
        ];
        let e = image_error(&img, &r).unwrap();
        assert_eq!(e.mae_levels, 0.375);
        assert_eq!(e.max_abs_levels, 3.0);
        assert_eq!(e.off_by_more_than_one_share, 0.25);
    }

    #[test]
    fn one_level_exactly_is_not_off() {
        let e = image_error(&[[1, 1, 1]], &[[0.0, 2.0, 1.0]]).unwrap();
        assert_eq!(e.off_by_more_than_one_share, 0.0);
        let e = image_error(&[[1, 1, 1]], &[[0.0, 2.0, 2.25]]).unwrap();
        assert_eq!(e.off_by_more_than_one_share, 1.0);
        assert_eq!(e.mae_levels, 3.25 / 3.0);
    }

    #[test]
    fn sizes_must_match() {
        assert_eq!(
            image_error(&[[0; 3]], &[]).unwrap_err(),
            SizeMismatch {
                image: 1,
                reference: 0
            }
        );
    }
}
