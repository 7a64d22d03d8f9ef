//! Per-pixel light counts read back from a frame rendered in a count mode (see
//! [`crate::renderer::Renderer::render_light_counts`]): the light evaluations a method makes,
//! or the lights that really reach each pixel.

/// Per-pixel light counts of one frame (opaque surfaces; see
/// [`Renderer::render_light_counts`](crate::renderer::Renderer::render_light_counts)).
#[derive(Clone, Debug, PartialEq)]
pub struct LightCounts {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Count per pixel, row-major, top row first (0 where nothing is drawn).
    pub counts: Vec<u32>,
    /// Whether a surface covers the pixel.
    pub covered: Vec<bool>,
}

impl LightCounts {
    /// Decodes a count frame: the count in the red, green and blue bytes (low to high, see
    /// `encodeCount` in `glsl/surface.glsl`), alpha marking covered pixels (the target is
    /// cleared to 0).
    pub fn decode(image: &image::RgbaImage) -> LightCounts {
        LightCounts {
            width: image.width(),
            height: image.height(),
            counts: image
                .pixels()
                .map(|p| p[0] as u32 | (p[1] as u32) << 8 | (p[2] as u32) << 16)
                .collect(),
            covered: image.pixels().map(|p| p[3] > 127).collect(),
        }
    }

    /// [`LightCounts::decode`] into buffers allocated fallibly: a frame whose counts the
    /// machine cannot hold is an error naming its size.
    pub(crate) fn try_decode(image: &image::RgbaImage) -> Result<LightCounts, crate::GlError> {
        use crate::gl::alloc::zeroed;
        let (width, height) = image.dimensions();
        let mut counts: Vec<u32> = zeroed(width, height, 1, "light counts")?;
        let mut covered: Vec<bool> = zeroed(width, height, 1, "light coverage")?;
        for ((count, cover), p) in counts.iter_mut().zip(&mut covered).zip(image.pixels()) {
            *count = p[0] as u32 | (p[1] as u32) << 8 | (p[2] as u32) << 16;
            *cover = p[3] > 127;
        }
        Ok(LightCounts {
            width,
            height,
            counts,
            covered,
        })
    }

    /// Sum over covered pixels.
    pub fn total(&self) -> u64 {
        self.counts.iter().map(|&n| n as u64).sum()
    }

    /// Covered pixels.
    pub fn covered_pixels(&self) -> usize {
        self.covered.iter().filter(|&&c| c).count()
    }

    /// Mean per covered pixel (0 when nothing is covered).
    pub fn mean(&self) -> f64 {
        let n = self.covered_pixels();
        if n == 0 {
            0.0
        } else {
            self.total() as f64 / n as f64
        }
    }

    /// Largest count.
    pub fn max(&self) -> u32 {
        self.counts.iter().copied().max().unwrap_or(0)
    }

    /// Count at pixel (x, y), top row first; `None` outside the image.
    pub fn at(&self, x: u32, y: u32) -> Option<u32> {
        if x >= self.width {
            return None;
        }
        let i = (y as usize).checked_mul(self.width as usize)? + x as usize;
        self.counts.get(i).copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decoding_reads_24_bit_counts_and_coverage() {
        let mut img = image::RgbaImage::new(3, 1);
        img.put_pixel(0, 0, image::Rgba([0x34, 0x12, 0x01, 255]));
        img.put_pixel(1, 0, image::Rgba([0, 0, 0, 255]));
        img.put_pixel(2, 0, image::Rgba([0, 0, 0, 0]));
        let c = LightCounts::decode(&img);
        assert_eq!(c.counts, vec![0x01_1234, 0, 0]);
        assert_eq!(c.covered, vec![true, true, false]);
        assert_eq!(
            (c.total(), c.covered_pixels(), c.max()),
            (0x01_1234, 2, 0x01_1234)
        );
        assert_eq!(c.mean(), 0x01_1234 as f64 / 2.0);
        assert_eq!(c.at(0, 0), Some(0x01_1234));
        assert_eq!(c.at(2, 0), Some(0));
        // Past the row's end is outside, not the next row's first pixel.
        assert_eq!(
            (c.at(3, 0), c.at(0, 1), c.at(0, u32::MAX)),
            (None, None, None)
        );
        assert_eq!(LightCounts::try_decode(&img).unwrap(), c);
    }
}
