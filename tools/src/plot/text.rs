//! Chart text: a TrueType font found on the system when there is one (drawn by plotters'
//! `ab_glyph` font support), else the font8x8 glyphs at an integer scale.

use std::sync::OnceLock;

use font8x8::UnicodeFonts;
use image::{Rgb, RgbImage};
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle, FontTransform};

/// Fonts tried in order; the first that loads is used. DejaVu Sans is the Debian/Ubuntu
/// `fonts-dejavu-core` package (and Fedora's, Arch's); Liberation Sans and the macOS,
/// Windows and Android sans fonts follow. No font file ships with the crate.
const FONT_FILES: &[&str] = &[
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu-sans-fonts/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/liberation-sans/LiberationSans-Regular.ttf",
    "/System/Library/Fonts/Supplemental/Arial.ttf",
    "/Library/Fonts/Arial.ttf",
    "C:\\Windows\\Fonts\\arial.ttf",
    "/system/fonts/Roboto-Regular.ttf",
];

/// The name the system font is registered under with plotters.
const FAMILY: &str = "manylight-sans";

/// TrueType line height (ascent + descent, in pixels) is `TRUETYPE_BASE + TRUETYPE_PX` per
/// unit of scale: 11, 18 and 25 pixels at scales 1 to 3. More than the bitmap font's 8 per
/// unit, as its glyphs fill their cell while a TrueType font leaves room for accents and
/// descenders; the base keeps scale 1 (small charts) readable.
const TRUETYPE_BASE: u32 = 4;
/// See [`TRUETYPE_BASE`].
const TRUETYPE_PX: u32 = 7;

/// Where the baseline lies in a TrueType line, as a fraction of its height from the top: the
/// ascent share of DejaVu Sans (0.80) and Liberation Sans (0.81); close enough for others.
const ASCENT: f64 = 0.8;

/// How chart text is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Face {
    /// The font8x8 glyphs scaled by an integer factor: always there.
    Bitmap,
    /// The system font of [`FONT_FILES`], registered with plotters.
    TrueType,
}

impl Face {
    /// TrueType when one of [`FONT_FILES`] loads (tried once per process), else bitmap.
    pub(super) fn system() -> Face {
        static LOADED: OnceLock<bool> = OnceLock::new();
        if *LOADED.get_or_init(load_system_font) {
            Face::TrueType
        } else {
            Face::Bitmap
        }
    }

    /// Height in pixels of one line of text at `scale`.
    pub(super) fn line(self, scale: u32) -> u32 {
        match self {
            Face::Bitmap => 8 * scale,
            Face::TrueType => TRUETYPE_BASE + TRUETYPE_PX * scale,
        }
    }

    /// Width in pixels of `text` drawn at `scale`.
    pub(super) fn width(self, text: &str, scale: u32) -> u32 {
        let bitmap = text.chars().count() as u32 * 8 * scale;
        match self {
            Face::Bitmap => bitmap,
            // The estimate sums the glyph advances and truncates: one pixel of slack.
            Face::TrueType => font(self.line(scale))
                .box_size(text)
                .map_or(bitmap, |(w, _)| w + 1),
        }
    }

    /// The largest scale up to `want` (at least 1) at which `text` fits in `room` pixels.
    pub(super) fn fit_scale(self, text: &str, want: u32, room: u32) -> u32 {
        (1..=want.max(1))
            .rev()
            .find(|&sc| self.width(text, sc) <= room)
            .unwrap_or(1)
    }

    /// Draws `text` at `scale`, clipped to the image. Horizontal text has the top-left corner
    /// of its line box at (x, y); `up` text is turned a quarter turn anticlockwise (it reads
    /// bottom to top) with its bottom-left corner at (x, y).
    pub(super) fn draw(
        self,
        img: &mut RgbImage,
        (x, y): (i32, i32),
        text: &str,
        scale: u32,
        color: Rgb<u8>,
        up: bool,
    ) {
        if self == Face::TrueType && draw_truetype(img, (x, y), text, scale, color, up) {
            return;
        }
        draw_bitmap(img, x, y, text, scale, color, up);
    }
}

/// Reads the first font of [`FONT_FILES`] that plotters accepts and registers it as
/// [`FAMILY`]; false when none does.
fn load_system_font() -> bool {
    FONT_FILES.iter().any(|path| {
        let Ok(bytes) = std::fs::read(path) else {
            return false;
        };
        // plotters keeps fonts for the life of the process and wants `&'static` bytes; this
        // runs once, so leaking the one file read is the simplest way to give it that.
        let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
        register_font(FAMILY, FontStyle::Normal, bytes).is_ok()
    })
}

/// The registered system font with a line `px` pixels high.
fn font(px: u32) -> FontDesc<'static> {
    FontDesc::new(FontFamily::Name(FAMILY), px as f64, FontStyle::Normal)
}

/// Draws `text` in the system font (anti-aliased, blended into the image); false if plotters
/// could not draw it, so the caller falls back to the bitmap font.
fn draw_truetype(
    img: &mut RgbImage,
    (x, y): (i32, i32),
    text: &str,
    scale: u32,
    color: Rgb<u8>,
    up: bool,
) -> bool {
    let px = Face::TrueType.line(scale);
    // plotters' ab_glyph font puts the baseline half a line below the position it is given;
    // move it to ASCENT of the line below the top of the line box.
    let shift = ((ASCENT - 0.5) * px as f64).round() as i32;
    let color = RGBColor(color[0], color[1], color[2]);
    let (style, pos) = if up {
        // A 270° turn maps the text's (right, down) onto (up, right).
        let style = font(px).transform(FontTransform::Rotate270).color(&color);
        (style, (x + shift, y - 1))
    } else {
        (font(px).color(&color), (x, y + shift))
    };
    let (w, h) = img.dimensions();
    let root = BitMapBackend::with_buffer(img, (w, h)).into_drawing_area();
    root.draw_text(text, &style, pos).is_ok()
}

/// The 8×8 glyph for `ch`: ASCII, Latin-1 (µ, ×, °) or Greek, else `?`.
pub(super) fn glyph(ch: char) -> [u8; 8] {
    font8x8::BASIC_FONTS
        .get(ch)
        .or_else(|| font8x8::LATIN_FONTS.get(ch))
        .or_else(|| font8x8::GREEK_FONTS.get(ch))
        .or_else(|| font8x8::BASIC_FONTS.get('?'))
        .unwrap_or([0; 8])
}

/// Draws `text` with font8x8 glyphs scaled by `scale`, clipped to the image; positions as
/// in [`Face::draw`].
fn draw_bitmap(
    img: &mut RgbImage,
    x: i32,
    y: i32,
    text: &str,
    scale: u32,
    color: Rgb<u8>,
    up: bool,
) {
    let sc = scale as i32;
    let (w, h) = (img.width() as i32, img.height() as i32);
    for (i, ch) in text.chars().enumerate() {
        for (row, bits) in glyph(ch).iter().enumerate() {
            for col in 0..8 {
                if bits & (1 << col) == 0 {
                    continue;
                }
                for (dx, dy) in (0..sc).flat_map(|a| (0..sc).map(move |b| (a, b))) {
                    // (gx, gy): the pixel in unrotated text coordinates.
                    let gx = (i as i32 * 8 + col) * sc + dx;
                    let gy = row as i32 * sc + dy;
                    let (px, py) = if up {
                        (x + gy, y - 1 - gx)
                    } else {
                        (x + gx, y + gy)
                    };
                    if px >= 0 && py >= 0 && px < w && py < h {
                        img.put_pixel(px as u32, py as u32, color);
                    }
                }
            }
        }
    }
}
