//! Image comparison: the numbers every correctness claim is stated in.

pub mod counts;
pub mod cpu_reference;
pub mod spread;

use serde::Serialize;

/// Differences between two images of the same size, per channel (RGB; alpha ignored), in
/// 8-bit steps.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ImageDiff {
    /// Largest absolute channel difference (0–255).
    pub max_abs: u8,
    /// Root mean square channel difference (0–255 scale).
    pub rmse: f64,
    /// Peak signal-to-noise ratio in dB (infinite for identical images).
    pub psnr_db: f64,
    /// Fraction of pixels with any channel differing by more than 1.
    pub over_1: f64,
    /// Fraction of pixels with any channel differing by more than 2.
    pub over_2: f64,
}

/// Compares two RGBA8 images. Panics if the sizes differ (a caller bug, not bad input).
pub fn diff(a: &image::RgbaImage, b: &image::RgbaImage) -> ImageDiff {
    assert_eq!(a.dimensions(), b.dimensions(), "images differ in size");
    let (mut max_abs, mut sq, mut over1, mut over2) = (0u8, 0f64, 0usize, 0usize);
    for (pa, pb) in a.pixels().zip(b.pixels()) {
        let mut pix_max = 0u8;
        for c in 0..3 {
            let d = pa[c].abs_diff(pb[c]);
            pix_max = pix_max.max(d);
            sq += (d as f64).powi(2);
        }
        max_abs = max_abs.max(pix_max);
        over1 += (pix_max > 1) as usize;
        over2 += (pix_max > 2) as usize;
    }
    let n = (a.width() as usize * a.height() as usize).max(1);
    let mse = sq / (n * 3) as f64;
    ImageDiff {
        max_abs,
        rmse: mse.sqrt(),
        psnr_db: if mse == 0.0 {
            f64::INFINITY
        } else {
            10.0 * (255.0f64 * 255.0 / mse).log10()
        },
        over_1: over1 as f64 / n as f64,
        over_2: over2 as f64 / n as f64,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_difference_gives_known_numbers() {
        let a = image::RgbaImage::from_pixel(4, 4, image::Rgba([100, 100, 100, 255]));
        let mut b = a.clone();
        b.put_pixel(0, 0, image::Rgba([110, 100, 100, 255])); // one channel off by 10
        let d = diff(&a, &b);
        assert_eq!(d.max_abs, 10);
        let mse: f64 = 100.0 / 48.0;
        assert!((d.rmse - mse.sqrt()).abs() < 1e-12);
        assert!((d.psnr_db - 10.0 * (65025.0 / mse).log10()).abs() < 1e-9);
        assert_eq!(d.over_2, 1.0 / 16.0);
        assert_eq!(diff(&a, &a).psnr_db, f64::INFINITY);
    }

    #[test]
    fn a_uniform_offset_of_one_step_gives_the_textbook_psnr() {
        let a = image::RgbaImage::from_pixel(8, 8, image::Rgba([10, 20, 30, 255]));
        let b = image::RgbaImage::from_pixel(8, 8, image::Rgba([11, 21, 31, 255]));
        let d = diff(&a, &b);
        assert_eq!((d.max_abs, d.rmse), (1, 1.0));
        // 20·log10(255 / 1).
        assert!((d.psnr_db - 48.130_803_608_679_1).abs() < 1e-9);
        assert_eq!((d.over_1, d.over_2), (0.0, 0.0));
    }
}
