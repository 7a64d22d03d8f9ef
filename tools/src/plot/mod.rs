//! Charts for the benchmark report: scatter and line series on linear or log axes, with an
//! optional Pareto front, rendered to an `RgbImage`.
//!
//! Text. Plotters' legend sizes its box with the font's own estimate rather than asking the
//! backend, and a `DrawingBackend` wrapper cannot be written here (the trait's signatures name
//! types plotters does not re-export). So plotters rasterises the shapes (grid, series,
//! markers, legend box) and this module does the layout and mapping itself and draws every
//! label (title, axis descriptions, tick labels, legend) afterwards: in a TrueType font found
//! on the system (plotters' `ab_glyph` feature draws it), or with the font8x8 glyphs scaled by
//! an integer factor where no font file is found (see `text.rs`).

use image::{Rgb, RgbImage};
use plotters::prelude::*;

mod axis;
mod draw;
#[cfg(test)]
mod tests;
mod text;

use axis::*;
use draw::*;
use text::*;

/// Where zero and negative values are drawn on a log axis when the data has no positive value
/// to place the floor under. Otherwise the floor is one decade below the smallest positive
/// value (or [`Chart::y_floor`] on the y axis).
pub const LOG_FLOOR: f64 = 1e-6;

/// One set of points in a chart.
#[derive(Clone, Debug, Default)]
pub struct Series {
    /// Legend text (an empty label leaves the series out of the legend).
    pub label: String,
    /// Data points (x, y); non-finite coordinates are skipped.
    pub points: Vec<(f64, f64)>,
    /// Colour of markers and line, e.g. from [`palette`].
    pub color: (u8, u8, u8),
    /// Marker shape, e.g. from [`style`].
    pub marker: Marker,
    /// Connect the points in x order.
    pub line: bool,
    /// Draw the markers as larger outlines under the filled ones (and the line wider and
    /// dashed under the solid ones), for a series whose points often coincide with another's:
    /// both stay visible, this one around the other.
    pub hollow: bool,
    /// A short text beside each point (empty: none), as many as `points` or none at all.
    pub point_labels: Vec<String>,
}

/// The shape of a series' markers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Marker {
    /// A disc.
    #[default]
    Circle,
    /// A square.
    Square,
    /// A triangle pointing up.
    Triangle,
    /// A square on its corner.
    Diamond,
    /// An ×.
    Cross,
    /// A triangle pointing down.
    TriangleDown,
    /// A +.
    Plus,
}

impl Marker {
    /// Every shape, in the order [`style`] hands them out.
    pub const ALL: [Marker; 7] = [
        Marker::Circle,
        Marker::Square,
        Marker::Triangle,
        Marker::Diamond,
        Marker::Cross,
        Marker::TriangleDown,
        Marker::Plus,
    ];
}

/// A 2-D chart. Log axes draw zero and negative values at a floor (see [`LOG_FLOOR`] and
/// `y_floor`): the floor is marked by a dashed line whose tick reads "0" (and "exact" on the
/// y axis), so an exact result stays visible instead of vanishing off a log scale.
#[derive(Clone, Debug, Default)]
pub struct Chart {
    /// Title above the plot.
    pub title: String,
    /// Description of the x axis.
    pub x_label: String,
    /// Description of the y axis (drawn rotated, reading upwards).
    pub y_label: String,
    /// Logarithmic x axis.
    pub x_log: bool,
    /// Logarithmic y axis.
    pub y_log: bool,
    /// The data.
    pub series: Vec<Series>,
    /// Points drawn as a thick dark staircase labelled as the Pareto front (any order); a front of
    /// fewer than two distinct points is no front and is neither drawn nor listed.
    pub front: Option<Vec<(f64, f64)>>,
    /// On a log y axis, where zero and negative y values are drawn; it should lie below the
    /// smallest positive y. `None`: one decade below the smallest positive y.
    pub y_floor: Option<f64>,
}

/// Indices of the points not dominated by another when minimising both x and y, sorted by x
/// (then y, then index). A point is dominated if another is no worse in both coordinates and
/// better in one, so exact duplicates on the front are all kept. Points with a NaN are never
/// on the front.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len())
        .filter(|&i| !points[i].0.is_nan() && !points[i].1.is_nan())
        .collect();
    order.sort_by(|&a, &b| {
        let (pa, pb) = (points[a], points[b]);
        pa.0.total_cmp(&pb.0)
            .then(pa.1.total_cmp(&pb.1))
            .then(a.cmp(&b))
    });
    // Sweep in x order: a point is on the front iff its y beats every y seen so far, or it
    // repeats the last front point exactly.
    let mut front: Vec<usize> = Vec::new();
    for i in order {
        let p = points[i];
        let keep = match front.last() {
            None => true,
            Some(&last) => p.1 < points[last].1 || p == points[last],
        };
        if keep {
            front.push(i);
        }
    }
    front
}

/// Series colour `i`: the Okabe–Ito palette (distinguishable with the common colour-vision
/// deficiencies), without its black, which is kept for the Pareto front; repeats after 7.
pub fn palette(i: usize) -> (u8, u8, u8) {
    const COLORS: [(u8, u8, u8); 7] = [
        (0, 114, 178),   // blue
        (213, 94, 0),    // vermillion
        (0, 158, 115),   // bluish green
        (230, 159, 0),   // orange
        (204, 121, 167), // reddish purple
        (86, 180, 233),  // sky blue
        (240, 228, 66),  // yellow
    ];
    COLORS[i % COLORS.len()]
}

/// Colour and marker number `i`: [`palette`]`(i)` with [`Marker::ALL`]`[i % 7]`, so series
/// stay apart in grey-scale prints too. A caller that gives each thing drawn (a method, say)
/// a fixed `i` gets the same look for it in every chart.
pub fn style(i: usize) -> ((u8, u8, u8), Marker) {
    (palette(i), Marker::ALL[i % Marker::ALL.len()])
}

/// Gap in pixels between text, axes and the image edge.
const PAD: u32 = 6;
/// Length of a tick mark outside the plot frame.
const TICK: u32 = 5;
const TEXT: Rgb<u8> = Rgb([25, 25, 25]);
const FRONT_COLOR: RGBColor = RGBColor(30, 30, 30);

/// The front as drawn: `None` unless it has at least two distinct finite points (one point,
/// or copies of one, is no line and no trade-off to show).
fn drawn_front(chart: &Chart) -> Option<&[(f64, f64)]> {
    let front = chart.front.as_deref()?;
    let mut finite = front.iter().filter(|p| p.0.is_finite() && p.1.is_finite());
    let first = finite.next()?;
    finite.any(|p| p != first).then_some(front)
}

/// Renders `chart` into a `width`×`height` image. Text is at scale 2 (title 3) on images at
/// least 480×300, 1 (title 2) below that, in the system's TrueType font (lines of 11, 18 and
/// 25 pixels at scales 1 to 3) or else the 8×8 bitmap font scaled; long titles shrink to fit. Fails only if the
/// image is too small to hold the axes or plotters reports an error.
pub fn render(chart: &Chart, width: u32, height: u32) -> Result<RgbImage, String> {
    render_with(chart, width, height, Face::system())
}

/// [`render`] with the text in `face`.
fn render_with(chart: &Chart, width: u32, height: u32, face: Face) -> Result<RgbImage, String> {
    let s = if width >= 480 && height >= 300 { 2 } else { 1 };
    let title_s = face.fit_scale(&chart.title, s + 1, width.saturating_sub(2 * PAD));
    let xdesc_s = face.fit_scale(&chart.x_label, s, width.saturating_sub(2 * PAD));
    let ydesc_s = face.fit_scale(&chart.y_label, s, height.saturating_sub(2 * PAD));

    let all = || {
        let front = chart.front.iter().flatten();
        chart.series.iter().flat_map(|s| &s.points).chain(front)
    };
    let xa = Axis::new(all().map(|p| p.0), chart.x_log, None);
    let ya = Axis::new(all().map(|p| p.1), chart.y_log, chart.y_floor);

    // Vertical layout first: the plot height fixes the y ticks, whose label width fixes the
    // left margin, which fixes the plot width and so the x ticks.
    let glyph = face.line(s);
    let title_h = if chart.title.is_empty() {
        0
    } else {
        face.line(title_s) + PAD
    };
    // The top y tick label is centred on the frame and pokes above it by half a line.
    let top = PAD + title_h + glyph / 2;
    let xdesc_h = if chart.x_label.is_empty() {
        0
    } else {
        face.line(xdesc_s) + PAD
    };
    let bottom = TICK + PAD / 2 + glyph + PAD + xdesc_h;
    let ph = height
        .checked_sub(top + bottom)
        .filter(|&h| h >= 16)
        .ok_or_else(|| format!("{width}x{height} is too small for a chart"))?;
    let y_ticks = ya.ticks((ph / (3 * glyph)).max(2) as usize, ph, glyph);
    let ylabel_w = y_ticks.0.iter().map(|t| face.width(&t.1, s)).max();
    let ydesc_w = if chart.y_label.is_empty() {
        0
    } else {
        face.line(ydesc_s) + PAD
    };
    let left = PAD + ydesc_w + ylabel_w.unwrap_or(0) + PAD / 2 + TICK;
    let right = PAD + 2 * glyph; // room for half of the last x tick label
    let pw = width
        .checked_sub(left + right)
        .filter(|&w| w >= 16)
        .ok_or_else(|| format!("{width}x{height} is too small for a chart"))?;
    let x_ticks = x_ticks_that_fit(&xa, pw, s, face);
    let frame = Frame {
        left: left as i32,
        top: top as i32,
        w: pw as i32,
        h: ph as i32,
    };

    let legend = Legend::new(chart, s, face);
    let mut buf = vec![255u8; width as usize * height as usize * 3];
    let legend_at;
    {
        let root = BitMapBackend::with_buffer(&mut buf, (width, height)).into_drawing_area();
        let (x_lines, y_lines) = (xa.lines(&x_ticks), ya.lines(&y_ticks));
        draw_grid(&root, &frame, &xa, &ya, &x_lines, &y_lines).map_err(perr)?;
        let paths = draw_data(&root, chart, &frame, &xa, &ya, s).map_err(perr)?;
        let mut avoid = paths;
        if ya.floor.is_some() {
            // Keep the legend off the "exact" label drawn above the y floor line.
            let (x, y) = exact_label_at(&frame, &xa, &ya, s, face);
            let w = face.width(EXACT, s) as i32;
            let half = glyph as i32 / 2;
            avoid.extend(
                (0..=w)
                    .step_by(8)
                    .map(|i| ((x + i, y + half), MARKER_WEIGHT)),
            );
        }
        legend_at = legend.place(&frame, &avoid);
        if let Some(at) = legend_at {
            legend.draw_box(&root, at, s).map_err(perr)?;
        }
        root.present().map_err(perr)?;
    }
    let mut img = RgbImage::from_raw(width, height, buf).ok_or("plot buffer size mismatch")?;

    // Tick labels: x centred under its tick, y right-aligned and centred on its tick, both
    // kept inside the image.
    for (v, label) in &x_ticks.0 {
        let lw = face.width(label, s) as i32;
        let x = (frame.x(*v, &xa) - lw / 2).clamp(0, (width as i32 - lw).max(0));
        let y = frame.top + frame.h + (TICK + PAD / 2) as i32;
        face.draw(&mut img, (x, y), label, s, TEXT, false);
    }
    for (v, label) in &y_ticks.0 {
        let x = frame.left - (TICK + PAD / 2 + face.width(label, s)) as i32;
        let y = (frame.y(*v, &ya) - glyph as i32 / 2).clamp(0, (height - glyph) as i32);
        face.draw(&mut img, (x, y), label, s, TEXT, false);
    }
    if ya.floor.is_some() {
        let at = exact_label_at(&frame, &xa, &ya, s, face);
        face.draw(&mut img, at, EXACT, s, Rgb([90, 90, 90]), false);
    }
    let centre_x = |text: &str, scale| {
        let w = face.width(text, scale) as i32;
        (frame.left + frame.w / 2 - w / 2).clamp(0, (width as i32 - w).max(0))
    };
    let title_x = (width as i32 - face.width(&chart.title, title_s) as i32).max(0) / 2;
    let black = Rgb([0, 0, 0]);
    face.draw(
        &mut img,
        (title_x, PAD as i32),
        &chart.title,
        title_s,
        black,
        false,
    );
    let xdesc_y = (height - PAD - face.line(xdesc_s)) as i32;
    let xdesc_x = centre_x(&chart.x_label, xdesc_s);
    let xdesc_at = (xdesc_x, xdesc_y);
    face.draw(&mut img, xdesc_at, &chart.x_label, xdesc_s, TEXT, false);
    let ydesc_len = face.width(&chart.y_label, ydesc_s) as i32;
    let ydesc_y = (frame.top + frame.h / 2 + ydesc_len / 2).clamp(0, height as i32 - 1);
    let ydesc_at = (PAD as i32, ydesc_y);
    face.draw(&mut img, ydesc_at, &chart.y_label, ydesc_s, TEXT, true);
    draw_point_labels(&mut img, chart, &frame, (&xa, &ya), s, face);
    if let Some(at) = legend_at {
        legend.draw_text(&mut img, at, s, face);
    }
    Ok(img)
}

/// Each series' point labels, right of their points in the series' colour, kept inside the
/// image; a label that would overlap one already drawn is left out (the tables have them all).
fn draw_point_labels(
    img: &mut RgbImage,
    chart: &Chart,
    frame: &Frame,
    (xa, ya): (&Axis, &Axis),
    s: u32,
    face: Face,
) {
    let (width, height) = (img.width() as i32, img.height() as i32);
    let mut drawn: Vec<(i32, i32, i32, i32)> = Vec::new();
    for sr in &chart.series {
        let (r, g, b) = sr.color;
        for (p, label) in sr.points.iter().zip(&sr.point_labels) {
            let (Some(x), Some(y)) = (xa.space(p.0), ya.space(p.1)) else {
                continue;
            };
            if label.is_empty() {
                continue;
            }
            let (x, y) = frame.px((x, y), xa, ya);
            let w = face.width(label, s) as i32;
            let at_x = (x + 6 + s as i32).clamp(0, (width - w).max(0));
            let h = face.line(s) as i32;
            let at_y = (y - h / 2).clamp(0, (height - h).max(0));
            let rect = (at_x, at_y, at_x + w, at_y + h);
            let overlaps = |o: &(i32, i32, i32, i32)| {
                rect.0 < o.2 && o.0 < rect.2 && rect.1 < o.3 && o.1 < rect.3
            };
            if drawn.iter().any(overlaps) {
                continue;
            }
            drawn.push(rect);
            face.draw(img, (at_x, at_y), label, s, Rgb([r, g, b]), false);
        }
    }
}

fn perr<E: std::fmt::Display>(e: E) -> String {
    format!("plotting failed: {e}")
}

/// The plotting rectangle in pixels, and the map from drawing space into it.
struct Frame {
    left: i32,
    top: i32,
    w: i32,
    h: i32,
}

impl Frame {
    fn x(&self, v: f64, a: &Axis) -> i32 {
        self.left + ((v - a.lo) / (a.hi - a.lo) * (self.w - 1) as f64).round() as i32
    }
    fn y(&self, v: f64, a: &Axis) -> i32 {
        self.top + ((a.hi - v) / (a.hi - a.lo) * (self.h - 1) as f64).round() as i32
    }
    fn px(&self, p: (f64, f64), xa: &Axis, ya: &Axis) -> (i32, i32) {
        (self.x(p.0, xa), self.y(p.1, ya))
    }
    fn right(&self) -> i32 {
        self.left + self.w - 1
    }
    fn bottom(&self) -> i32 {
        self.top + self.h - 1
    }
}

/// The note on the y floor line of a log axis.
const EXACT: &str = "exact";

/// Top-left of the "exact" note: just above the y floor line, at the left of the plot or
/// right of the x floor line.
fn exact_label_at(frame: &Frame, xa: &Axis, ya: &Axis, s: u32, face: Face) -> (i32, i32) {
    let floor = ya.floor.map_or(ya.lo, f64::log10);
    let x = xa.floor.map_or(frame.left, |f| frame.x(f.log10(), xa));
    (x + 4, frame.y(floor, ya) - face.line(s) as i32 - 3)
}
