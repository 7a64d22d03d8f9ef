//! Per-pixel counts (lights evaluated per pixel) and image differences as false-colour
//! pictures, with a colour legend, so a person can see where the work or the error is.

use super::sheet::draw_text;
use image::{Rgba, RgbaImage};

/// Viridis sampled at nine evenly spaced points (matplotlib / R `viridis(9)`): perceptually
/// uniform, lightness rising monotonically, readable with colour-vision deficiencies.
const VIRIDIS: [[u8; 3]; 9] = [
    [0x44, 0x01, 0x54],
    [0x47, 0x2D, 0x7B],
    [0x3B, 0x52, 0x8B],
    [0x2C, 0x72, 0x8E],
    [0x21, 0x90, 0x8C],
    [0x27, 0xAD, 0x81],
    [0x5D, 0xC8, 0x63],
    [0xAA, 0xDC, 0x32],
    [0xFD, 0xE7, 0x25],
];

/// Uncovered (background) pixels. Viridis starts at a dark purple, so a covered pixel with a
/// count of 0 still stands apart from this.
const BACKGROUND: Rgba<u8> = Rgba([40, 40, 40, 255]);
/// The legend panel under the map (the contact sheet's background).
const PANEL: Rgba<u8> = Rgba([24, 24, 28, 255]);
const LABEL: Rgba<u8> = Rgba([230, 230, 230, 255]);
/// Maps narrower than this are enlarged by an integer factor so the legend fits under them.
const MIN_WIDTH: u32 = 200;
/// Enlargement stops before the map gets taller than this.
const MAX_HEIGHT: u32 = 4096;
const PAD: u32 = 4;
const BAR_H: u32 = 10;

/// Viridis at `t` in [0, 1] (linear interpolation between nine control points): dark purple
/// at 0, yellow at 1. `t` outside [0, 1] is clamped; NaN gives black.
pub fn colormap(t: f64) -> [u8; 3] {
    if t.is_nan() {
        return [0, 0, 0];
    }
    let f = t.clamp(0.0, 1.0) * (VIRIDIS.len() - 1) as f64;
    let i = (f.floor() as usize).min(VIRIDIS.len() - 2);
    let u = f - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    std::array::from_fn(|c| (a[c] as f64 + (b[c] as f64 - a[c] as f64) * u).round() as u8)
}

/// Draws `counts` (row-major, top row first, `width`×`height`) as a heat map: covered pixels
/// in [`colormap`]`(count / scale_max)` (counts above `scale_max` saturate; a `scale_max` of 0
/// counts as 1), uncovered ones dark grey. Maps under 200 pixels wide are enlarged by an
/// integer factor (nearest neighbour). Below the map: a colour bar labelled 0, `scale_max`/2
/// and `scale_max`, then `title`, in white 8×8 text on a dark panel; the image is widened if
/// the title needs it. Panics if a slice's length is not `width`×`height`.
pub fn heatmap(
    counts: &[u32],
    covered: &[bool],
    width: u32,
    height: u32,
    scale_max: u32,
    title: &str,
) -> RgbaImage {
    let n = width as usize * height as usize;
    assert_eq!(counts.len(), n, "counts is not width×height");
    assert_eq!(covered.len(), n, "covered is not width×height");
    let scale_max = scale_max.max(1);
    // Enlarge narrow maps, but not a tall, thin one into a gigantic image.
    let k = if width > 0 && width < MIN_WIDTH {
        MIN_WIDTH
            .div_ceil(width)
            .min((MAX_HEIGHT / height.max(1)).max(1))
    } else {
        1
    };
    let (map_w, map_h) = (width * k, height * k);
    let title_w = title.chars().count() as u32 * 8 + 2 * PAD;
    let out_w = map_w.max(title_w).max(MIN_WIDTH);
    // Bar, tick marks, tick labels, title, each with a gap.
    let legend_h = PAD + BAR_H + 3 + 8 + PAD + 8 + PAD;
    let mut img = RgbaImage::from_pixel(out_w, map_h + legend_h, PANEL);

    for y in 0..map_h {
        for x in 0..map_w {
            let i = (y / k * width + x / k) as usize;
            let c = if covered[i] {
                let [r, g, b] = colormap(counts[i] as f64 / scale_max as f64);
                Rgba([r, g, b, 255])
            } else {
                BACKGROUND
            };
            img.put_pixel(x, y, c);
        }
    }

    // The bar spans the panel (as wide as the map unless the title widened it) less a margin.
    let (bar_x0, bar_x1) = (PAD, out_w - PAD);
    let bar_y = map_h + PAD;
    for x in bar_x0..bar_x1 {
        let [r, g, b] = colormap((x - bar_x0) as f64 / (bar_x1 - bar_x0 - 1) as f64);
        for y in bar_y..bar_y + BAR_H {
            img.put_pixel(x, y, Rgba([r, g, b, 255]));
        }
    }
    let label_y = bar_y + BAR_H + 3;
    let ticks = [
        (bar_x0, 0u32, 0.0),
        ((bar_x0 + bar_x1 - 1) / 2, scale_max / 2, 0.5),
        (bar_x1 - 1, scale_max, 1.0),
    ];
    for (x, value, align) in ticks {
        for y in bar_y + BAR_H..label_y - 1 {
            img.put_pixel(x, y, LABEL);
        }
        let text = value.to_string();
        let w = text.len() as f64 * 8.0;
        let tx = (x as f64 - w * align).max(0.0) as u32;
        draw_text(&mut img, tx, label_y, &text, LABEL);
    }
    draw_text(&mut img, PAD, label_y + 8 + PAD, title, LABEL);
    img
}

/// Per pixel, the largest absolute RGB channel difference between `a` and `b` (alpha
/// ignored) as [`colormap`]`(diff / full_scale)`, black where the images agree exactly (even
/// a 1-step difference shows as dark purple). A `full_scale` of 0 counts as 1. Panics if the
/// sizes differ (a caller bug, as in [`crate::metrics::diff`]).
pub fn diff_image(a: &RgbaImage, b: &RgbaImage, full_scale: u8) -> RgbaImage {
    assert_eq!(a.dimensions(), b.dimensions(), "images differ in size");
    let full = full_scale.max(1) as f64;
    let mut out = RgbaImage::new(a.width(), a.height());
    for ((pa, pb), po) in a.pixels().zip(b.pixels()).zip(out.pixels_mut()) {
        let d = (0..3).map(|c| pa[c].abs_diff(pb[c])).max().unwrap_or(0);
        let [r, g, bl] = if d == 0 {
            [0, 0, 0]
        } else {
            colormap(d as f64 / full)
        };
        *po = Rgba([r, g, bl, 255]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn luma(c: [u8; 3]) -> f64 {
        0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64
    }

    #[test]
    fn colormap_is_ordered_and_clamped() {
        assert_eq!(colormap(0.0), VIRIDIS[0]);
        assert_eq!(colormap(1.0), VIRIDIS[8]);
        assert_eq!(colormap(-3.0), colormap(0.0));
        assert_eq!(colormap(7.0), colormap(1.0));
        assert_eq!(colormap(f64::NAN), [0, 0, 0]);
        let l: Vec<f64> = (0..=100)
            .map(|i| luma(colormap(i as f64 / 100.0)))
            .collect();
        assert!(
            l.windows(2).all(|w| w[1] >= w[0]),
            "lightness not monotonic"
        );
        assert!(l[100] - l[0] > 150.0);
    }

    #[test]
    fn heatmap_scales_small_maps_and_adds_a_legend() {
        let (w, h) = (64, 36);
        let mut counts = vec![5u32; w * h];
        let mut covered = vec![true; w * h];
        counts[0] = 0; // covered, zero count
        covered[1] = false; // background
        counts[w * h - 1] = 1000; // saturates
        let img = heatmap(
            &counts,
            &covered,
            w as u32,
            h as u32,
            10,
            "lights per pixel",
        );
        let k = 4; // 200 / 64 rounded up
        assert_eq!(img.width(), 64 * k);
        assert!(img.height() > 36 * k, "no legend under the map");
        assert_ne!(img.get_pixel(0, 0), img.get_pixel(k, 0));
        assert_eq!(img.get_pixel(k, 0), &BACKGROUND);
        let top = colormap(1.0);
        assert_eq!(
            img.get_pixel(64 * k - 1, 36 * k - 1),
            &Rgba([top[0], top[1], top[2], 255])
        );
        // Text lit somewhere in the panel.
        let lit = (36 * k..img.height())
            .flat_map(|y| (0..img.width()).map(move |x| (x, y)))
            .any(|(x, y)| img.get_pixel(x, y) == &LABEL);
        assert!(lit, "no legend text");
        // A large map keeps its size; a long title widens the panel.
        let big = heatmap(&[1; 300], &[true; 300], 300, 1, 2, "t");
        assert_eq!(big.width(), 300);
        let long = heatmap(&[1; 4], &[true; 4], 2, 2, 2, &"x".repeat(40));
        assert_eq!(long.width(), 40 * 8 + 2 * PAD);
        // A thin, tall map is not blown up past MAX_HEIGHT; an empty one still gets a legend.
        let thin = heatmap(&[0; 2000], &[true; 2000], 1, 2000, 0, "");
        assert_eq!((thin.width(), thin.height() > 4000), (MIN_WIDTH, true));
        assert!(thin.height() < MAX_HEIGHT + 100);
        assert_eq!(heatmap(&[], &[], 0, 0, 5, "").width(), MIN_WIDTH);
    }

    #[test]
    fn diff_image_marks_differences_where_they_are() {
        let a = RgbaImage::from_pixel(5, 4, Rgba([100, 100, 100, 255]));
        let same = diff_image(&a, &a, 16);
        assert_eq!(same.dimensions(), (5, 4));
        assert!(same.pixels().all(|p| p == &Rgba([0, 0, 0, 255])));
        let mut b = a.clone();
        b.put_pixel(3, 2, Rgba([100, 108, 100, 0])); // green off by 8; alpha ignored
        let d = diff_image(&a, &b, 16);
        let half = colormap(0.5);
        assert_eq!(d.get_pixel(3, 2), &Rgba([half[0], half[1], half[2], 255]));
        let others = d.enumerate_pixels().filter(|(x, y, _)| (*x, *y) != (3, 2));
        assert!(others
            .map(|(_, _, p)| p)
            .all(|p| p == &Rgba([0, 0, 0, 255])));
    }

    #[test]
    #[ignore = "writes /tmp/manylight_heatmap.png for a person to look at"]
    fn write_example_heatmap() {
        let (w, h) = (64u32, 36u32);
        let mut counts = Vec::new();
        let mut covered = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let (dx, dy) = (x as f64 - 40.0, y as f64 - 15.0);
                covered.push(y > 4);
                counts.push((120.0 * (-(dx * dx + dy * dy) / 150.0).exp()) as u32);
            }
        }
        heatmap(&counts, &covered, w, h, 128, "lights/pixel, clustered")
            .save("/tmp/manylight_heatmap.png")
            .unwrap();
    }
}
