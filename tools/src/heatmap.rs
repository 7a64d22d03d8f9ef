//! Per-pixel counts (lights evaluated per pixel) and image differences as false-colour
//! pictures, with a colour legend, so a person can see where the work or the error is.

use crate::sheet::draw_text;
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
/// Difference images: pixels where the two images agree exactly.
const SAME: Rgba<u8> = Rgba([0, 0, 0, 255]);
/// Maps narrower than this are enlarged by an integer factor so the legend fits under them.
const MIN_WIDTH: u32 = 200;
/// Enlargement stops before the map gets taller than this.
const MAX_HEIGHT: u32 = 4096;
const PAD: u32 = 4;
const BAR_H: u32 = 10;
/// Height of a line of the 8×8 label font, with its gap.
const LINE: u32 = 10;

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

/// How a heat map's counts map onto [`colormap`]. A maximum of 0 counts as 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// `count / max`; counts above `max` saturate.
    Linear(u32),
    /// `ln(1 + count) / ln(1 + max)`: equal ratios are equal steps, so counts of a few and of
    /// thousands read on one bar; counts above `max` saturate.
    Log(u32),
}

impl Scale {
    /// The count at the top of the bar (at least 1).
    pub fn max(self) -> u32 {
        match self {
            Scale::Linear(m) | Scale::Log(m) => m.max(1),
        }
    }

    /// Where `count` lies on the bar, in [0, 1].
    pub fn position(self, count: f64) -> f64 {
        let max = self.max() as f64;
        let t = match self {
            Scale::Linear(_) => count / max,
            Scale::Log(_) => count.max(0.0).ln_1p() / max.ln_1p(),
        };
        t.clamp(0.0, 1.0)
    }

    /// The values the bar is labelled with: 0, the middle and the top on a linear bar; 0, the
    /// powers of ten below the top, and the top on a log bar.
    fn ticks(self) -> Vec<u32> {
        let max = self.max();
        match self {
            Scale::Linear(_) => vec![0, max / 2, max],
            Scale::Log(_) => std::iter::once(0)
                .chain(std::iter::successors(Some(1u32), |p| p.checked_mul(10)))
                .take_while(|&v| v < max)
                .chain(std::iter::once(max))
                .collect(),
        }
    }
}

/// The integer factor a `width`×`height` map is enlarged by: enough to reach [`MIN_WIDTH`],
/// but not so much that a tall, thin map grows past [`MAX_HEIGHT`].
fn enlargement(width: u32, height: u32) -> u32 {
    if width > 0 && width < MIN_WIDTH {
        MIN_WIDTH
            .div_ceil(width)
            .min((MAX_HEIGHT / height.max(1)).max(1))
    } else {
        1
    }
}

/// Draws `counts` (row-major, top row first, `width`×`height`) as a heat map: covered pixels
/// in [`colormap`] at their [`Scale::position`], uncovered ones dark grey. Maps under 200
/// pixels wide are enlarged by an integer factor (nearest neighbour). Below the map: a colour
/// bar labelled with the scale's ticks, then `title` wrapped to the image's width, in white
/// 8×8 text on a dark panel. The image is as wide as the map (at least 200 pixels, the map
/// centred when narrower). Panics if a slice's length is not `width`×`height`.
pub fn heatmap(
    counts: &[u32],
    covered: &[bool],
    width: u32,
    height: u32,
    scale: Scale,
    title: &str,
) -> RgbaImage {
    let n = width as usize * height as usize;
    assert_eq!(counts.len(), n, "counts is not width×height");
    assert_eq!(covered.len(), n, "covered is not width×height");
    let k = enlargement(width, height);
    let map = RgbaImage::from_fn(width * k, height * k, |x, y| {
        let i = (y / k * width + x / k) as usize;
        if covered[i] {
            let [r, g, b] = colormap(scale.position(counts[i] as f64));
            Rgba([r, g, b, 255])
        } else {
            BACKGROUND
        }
    });
    let ticks = scale
        .ticks()
        .into_iter()
        .map(|v| (scale.position(v as f64), v.to_string()))
        .collect();
    let bar = Bar {
        ticks,
        zero_swatch: false,
    };
    with_panel(&map, &bar, title)
}

/// Per pixel, the largest absolute RGB channel difference between `image` and `reference`
/// (alpha ignored) as [`colormap`]`(diff / full_scale)`, black where the images agree exactly
/// (even a 1-step difference shows as dark purple); a `full_scale` of 0 counts as 1. Narrow
/// images are enlarged as in [`heatmap`]. Below: a colour bar in 8-bit steps (a black swatch
/// for 0, then 1 to `full_scale`), `what` (say, which method against which reference) and a
/// caption with the amplification (255 / `full_scale`) and the largest difference found.
/// Panics if the sizes differ (a caller bug, as in [`manylight::metrics::diff`]).
pub fn diff_image(
    reference: &RgbaImage,
    image: &RgbaImage,
    full_scale: u8,
    what: &str,
) -> RgbaImage {
    assert_eq!(
        reference.dimensions(),
        image.dimensions(),
        "images differ in size"
    );
    let full = full_scale.max(1);
    let diff = |x, y| {
        let (pa, pb) = (reference.get_pixel(x, y), image.get_pixel(x, y));
        (0..3).map(|c| pa[c].abs_diff(pb[c])).max().unwrap_or(0)
    };
    let (w, h) = reference.dimensions();
    let k = enlargement(w, h);
    let map = RgbaImage::from_fn(w * k, h * k, |x, y| match diff(x / k, y / k) {
        0 => SAME,
        d => {
            let [r, g, b] = colormap(d as f64 / full as f64);
            Rgba([r, g, b, 255])
        }
    });
    let max = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| diff(x, y))
        .max()
        .unwrap_or(0);
    let f = full as f64;
    let bar = Bar {
        ticks: vec![
            (1.0 / f, "1".to_string()),
            (0.5, (full / 2).to_string()),
            (1.0, format!("{full}+")),
        ],
        zero_swatch: true,
    };
    let caption = format!(
        "{what}\nColour: the largest RGB difference at each pixel in 8-bit steps, amplified \
         x{:.0} ({full}/255 or more is full yellow); black: identical. Max error {max}/255.",
        255.0 / f
    );
    with_panel(&map, &bar, &caption)
}

/// A colour bar: labelled positions in [0, 1] along [`colormap`].
struct Bar {
    ticks: Vec<(f64, String)>,
    /// Start with a black square labelled 0: difference images draw "identical" black, which
    /// is not on the colour map.
    zero_swatch: bool,
}

/// `map` with a panel under it: `bar` across the panel, its tick labels (dropping any that
/// would run into a neighbour), then `caption` wrapped to the width. The image is as wide as
/// the map, or [`MIN_WIDTH`] with the map centred when it is narrower; nothing else widens it,
/// so no band is left empty beside the map.
fn with_panel(map: &RgbaImage, bar: &Bar, caption: &str) -> RgbaImage {
    let out_w = map.width().max(MIN_WIDTH);
    let lines = wrap(caption, ((out_w - 2 * PAD) / 8) as usize);
    // Bar, tick marks, tick labels, caption lines, each with a gap.
    let legend_h = PAD + BAR_H + 3 + 8 + PAD + lines.len() as u32 * LINE + PAD;
    let mut img = RgbaImage::from_pixel(out_w, map.height() + legend_h, PANEL);
    let map_x = (out_w - map.width()) / 2;
    image::imageops::replace(&mut img, map, map_x as i64, 0);

    let bar_y = map.height() + PAD;
    let mut bar_x0 = PAD;
    let bar_x1 = out_w - PAD;
    let label_y = bar_y + BAR_H + 3;
    // Right end of the last label drawn, so the next keeps a gap from it.
    let mut drawn_to: Option<u32> = None;
    if bar.zero_swatch {
        let swatch =
            (bar_x0..bar_x0 + BAR_H).flat_map(|x| (bar_y..bar_y + BAR_H).map(move |y| (x, y)));
        for (x, y) in swatch {
            img.put_pixel(x, y, SAME);
        }
        let left = bar_x0 + BAR_H / 2 - 4;
        draw_text(&mut img, left, label_y, "0", LABEL);
        drawn_to = Some(left + 8);
        bar_x0 += BAR_H + 4;
    }
    let span = (bar_x1 - bar_x0 - 1) as f64;
    for x in bar_x0..bar_x1 {
        let [r, g, b] = colormap((x - bar_x0) as f64 / span);
        for y in bar_y..bar_y + BAR_H {
            img.put_pixel(x, y, Rgba([r, g, b, 255]));
        }
    }
    // Labels centred on their ticks, except that the bar's ends align with the bar's edges.
    // The last label is always drawn; an earlier one only where it keeps a character's gap
    // from its neighbours.
    let n = bar.ticks.len();
    let placed: Vec<(u32, u32, u32, &str)> = bar
        .ticks
        .iter()
        .map(|(t, text)| {
            let x = bar_x0 + (t.clamp(0.0, 1.0) * span).round() as u32;
            let w = text.chars().count() as u32 * 8;
            let left = if x == bar_x0 {
                x
            } else if x + 1 == bar_x1 {
                (x + 1).saturating_sub(w)
            } else {
                x.saturating_sub(w / 2)
            };
            (x, left, w, text.as_str())
        })
        .collect();
    let last_left = placed.last().map_or(u32::MAX, |p| p.1);
    for (i, &(x, left, w, text)) in placed.iter().enumerate() {
        let is_last = i + 1 == n;
        let clear_of_previous = drawn_to.is_none_or(|end| left >= end + 8);
        let clear_of_last = left + w + 8 <= last_left;
        if !(is_last || clear_of_previous && clear_of_last) {
            continue;
        }
        for y in bar_y + BAR_H..label_y - 1 {
            img.put_pixel(x, y, LABEL);
        }
        draw_text(&mut img, left, label_y, text, LABEL);
        drawn_to = Some(left + w);
    }
    let mut y = label_y + 8 + PAD;
    for line in &lines {
        draw_text(&mut img, PAD, y, line, LABEL);
        y += LINE;
    }
    img
}

/// `text` broken into lines of at most `width` characters: at its newlines, and between words
/// (a word longer than a line is cut).
fn wrap(text: &str, width: usize) -> Vec<String> {
    let width = width.max(1);
    let mut lines = Vec::new();
    for paragraph in text.split('\n') {
        let mut line = String::new();
        for word in paragraph.split_whitespace() {
            let mut word: Vec<char> = word.chars().collect();
            let line_len = line.chars().count();
            if line_len > 0 && line_len + 1 + word.len() <= width {
                line.push(' ');
                line.extend(&word);
                continue;
            }
            if line_len > 0 {
                lines.push(std::mem::take(&mut line));
            }
            while word.len() > width {
                lines.push(word.drain(..width).collect());
            }
            line = word.into_iter().collect();
        }
        lines.push(line);
    }
    lines
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
            Scale::Linear(10),
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
        // A large map keeps its size; a long title wraps instead of widening the image (which
        // left an empty band beside the map).
        let big = heatmap(&[1; 300], &[true; 300], 300, 1, Scale::Linear(2), "t");
        assert_eq!(big.width(), 300);
        let short = heatmap(&[1; 4], &[true; 4], 2, 2, Scale::Linear(2), "x");
        let long = heatmap(
            &[1; 4],
            &[true; 4],
            2,
            2,
            Scale::Linear(2),
            &"x ".repeat(40),
        );
        assert_eq!((short.width(), long.width()), (MIN_WIDTH, MIN_WIDTH));
        assert!(long.height() >= short.height() + LINE);
        // A thin, tall map is not blown up past MAX_HEIGHT, and is centred in the panel's
        // width; an empty one still gets a legend.
        let thin = heatmap(&[0; 2000], &[true; 2000], 1, 2000, Scale::Linear(0), "");
        assert_eq!((thin.width(), thin.height() > 4000), (MIN_WIDTH, true));
        assert!(thin.height() < MAX_HEIGHT + 100);
        assert_ne!(thin.get_pixel(MIN_WIDTH / 2, 0), &PANEL);
        assert_eq!(
            heatmap(&[], &[], 0, 0, Scale::Linear(5), "").width(),
            MIN_WIDTH
        );
    }

    #[test]
    fn log_scale_covers_the_largest_count_and_spreads_small_ones() {
        let log = Scale::Log(1000);
        assert_eq!(log.position(0.0), 0.0);
        assert_eq!(log.position(1000.0), 1.0);
        assert_eq!(log.position(5000.0), 1.0);
        // A count of 10 in a scale up to 1 000: a third of the way, not 1%.
        assert!((log.position(10.0) - 0.347).abs() < 0.01);
        assert_eq!(log.ticks(), [0, 1, 10, 100, 1000]);
        assert_eq!(Scale::Log(292).ticks(), [0, 1, 10, 100, 292]);
        assert_eq!(Scale::Linear(292).ticks(), [0, 146, 292]);
        assert_eq!(Scale::Log(0).max(), 1);
        // The whole bar is used: the top count gets the top colour.
        let img = heatmap(&[0, 1000], &[true, true], 2, 1, log, "");
        let top = colormap(1.0);
        assert_eq!(img.get_pixel(199, 0), &Rgba([top[0], top[1], top[2], 255]));
    }

    #[test]
    fn wrap_breaks_at_spaces_and_newlines() {
        assert_eq!(wrap("aa bb cc", 5), ["aa bb", "cc"]);
        assert_eq!(wrap("a\nb c", 10), ["a", "b c"]);
        assert_eq!(wrap("abcdefgh", 3), ["abc", "def", "gh"]);
        assert_eq!(wrap("", 3), [""]);
    }

    #[test]
    fn diff_image_marks_differences_where_they_are() {
        let a = RgbaImage::from_pixel(5, 4, Rgba([100, 100, 100, 255]));
        let k = 40; // enlarged to 200 pixels wide
        let same = diff_image(&a, &a, 16, "same");
        assert_eq!(same.width(), 5 * k);
        assert!(same.height() > 4 * k, "no legend under the map");
        let map = |img: &RgbaImage| {
            let (w, h) = (5 * k, 4 * k);
            image::imageops::crop_imm(img, 0, 0, w, h).to_image()
        };
        assert!(map(&same).pixels().all(|p| p == &SAME));
        let mut b = a.clone();
        b.put_pixel(3, 2, Rgba([100, 108, 100, 0])); // green off by 8; alpha ignored
        let d = diff_image(&a, &b, 16, "b vs a");
        let half = colormap(0.5);
        let marked = Rgba([half[0], half[1], half[2], 255]);
        assert_eq!(d.get_pixel(3 * k, 2 * k), &marked);
        assert_eq!(d.get_pixel(4 * k - 1, 3 * k - 1), &marked);
        let others = map(&d)
            .enumerate_pixels()
            .filter(|(x, y, _)| (x / k, y / k) != (3, 2))
            .all(|(_, _, p)| p == &SAME);
        assert!(others);
        // The caption and the bar are drawn, with a black swatch for "identical".
        let lit = |img: &RgbaImage| img.pixels().filter(|p| *p == &LABEL).count();
        assert!(lit(&d) > 0 && lit(&same) > 0, "no legend text");
        let bar_y = 4 * k + PAD + BAR_H / 2;
        assert_eq!(d.get_pixel(PAD + 1, bar_y), &SAME, "no black swatch for 0");
        let top = colormap(1.0);
        assert_eq!(
            d.get_pixel(5 * k - PAD - 1, bar_y),
            &Rgba([top[0], top[1], top[2], 255])
        );
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
        heatmap(
            &counts,
            &covered,
            w,
            h,
            Scale::Log(128),
            "lights/pixel, clustered",
        )
        .save("/tmp/manylight_heatmap.png")
        .unwrap();
    }
}
