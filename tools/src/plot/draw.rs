//! Drawing through plotters: grid, series, markers, the Pareto front and the legend box.

use image::RgbImage;
use plotters::prelude::*;

use super::*;

pub(super) fn draw_grid<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    frame: &Frame,
    xa: &Axis,
    ya: &Axis,
    x_lines: &[(f64, bool)],
    y_lines: &[(f64, bool)],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let style = |major: bool| {
        let g = if major { 215 } else { 238 };
        RGBColor(g, g, g).stroke_width(1)
    };
    // Minor lines first so major ones are drawn over them.
    for major in [false, true] {
        for &(v, _) in x_lines.iter().filter(|l| l.1 == major) {
            let x = frame.x(v, xa);
            root.draw(&PathElement::new(
                [(x, frame.top), (x, frame.bottom())],
                style(major),
            ))?;
        }
        for &(v, _) in y_lines.iter().filter(|l| l.1 == major) {
            let y = frame.y(v, ya);
            root.draw(&PathElement::new(
                [(frame.left, y), (frame.right(), y)],
                style(major),
            ))?;
        }
    }
    let axis = RGBColor(60, 60, 60).stroke_width(1);
    for &(v, _) in x_lines.iter().filter(|l| l.1) {
        let (x, y) = (frame.x(v, xa), frame.bottom());
        root.draw(&PathElement::new([(x, y), (x, y + TICK as i32)], axis))?;
    }
    for &(v, _) in y_lines.iter().filter(|l| l.1) {
        let (x, y) = (frame.left, frame.y(v, ya));
        root.draw(&PathElement::new([(x - TICK as i32, y), (x, y)], axis))?;
    }
    // Floors: dashed lines where zero and negative values are drawn.
    let dash = RGBColor(120, 120, 120).stroke_width(1);
    if let Some(f) = ya.floor {
        let y = frame.y(f.log10(), ya);
        for x in (frame.left..frame.right()).step_by(10) {
            root.draw(&PathElement::new(
                [(x, y), ((x + 5).min(frame.right()), y)],
                dash,
            ))?;
        }
    }
    if let Some(f) = xa.floor {
        let x = frame.x(f.log10(), xa);
        for y in (frame.top..frame.bottom()).step_by(10) {
            root.draw(&PathElement::new(
                [(x, y), (x, (y + 5).min(frame.bottom()))],
                dash,
            ))?;
        }
    }
    root.draw(&Rectangle::new(
        [(frame.left, frame.top), (frame.right(), frame.bottom())],
        axis,
    ))?;
    Ok(())
}

/// How much worse hiding a marker (or a label) under the legend is than hiding a few pixels
/// of a line.
pub(super) const MARKER_WEIGHT: usize = 100;

/// The front's legend text: says what the staircase is, so a steep one (configurations
/// about as fast, far apart in error) reads as data rather than a drawing fault.
pub(super) const FRONT_LABEL: &str = "Pareto front (nothing both faster and more exact)";

/// Pixels the legend should not cover, each with the cost of covering it.
pub(super) type Avoid = Vec<((i32, i32), usize)>;

/// Draws the front, the series lines (dashed and wider, then solid) and the markers (hollow,
/// then filled), in that order so markers stay on top and a hollow series stays visible around
/// the filled markers it shares points with; returns the pixels they cover (lines sampled
/// every few pixels) with their weights.
pub(super) fn draw_data<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    chart: &Chart,
    frame: &Frame,
    xa: &Axis,
    ya: &Axis,
    s: u32,
) -> Result<Avoid, DrawingAreaErrorKind<DB::ErrorType>> {
    let to_px = |pts: &[(f64, f64)], sort: bool| {
        let mut v: Vec<(f64, f64)> = pts
            .iter()
            .filter_map(|&(x, y)| Some((xa.space(x)?, ya.space(y)?)))
            .collect();
        if sort {
            v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
        }
        v.into_iter()
            .map(|p| frame.px(p, xa, ya))
            .collect::<Vec<_>>()
    };
    let mut covered = Vec::new();
    if let Some(front) = drawn_front(chart) {
        // A staircase: the boundary of the region the front dominates (minimising both).
        let pts = to_px(front, true);
        let mut path = Vec::new();
        for (i, &p) in pts.iter().enumerate() {
            if i > 0 {
                path.push((p.0, pts[i - 1].1));
            }
            path.push(p);
        }
        covered.extend(sample_path(&path));
        root.draw(&PathElement::new(path, FRONT_COLOR.stroke_width(3)))?;
    }
    // Hollow series' lines first, wider: the solid line they coincide with stays on top.
    for hollow in [true, false] {
        for sr in chart
            .series
            .iter()
            .filter(|sr| sr.line && sr.hollow == hollow)
        {
            let pts = to_px(&sr.points, true);
            covered.extend(sample_path(&pts));
            draw_line(root, &pts, rgb(sr.color), hollow)?;
        }
    }
    for hollow in [true, false] {
        for sr in chart.series.iter().filter(|sr| sr.hollow == hollow) {
            for p in to_px(&sr.points, false) {
                covered.push((p, MARKER_WEIGHT));
                draw_marker(root, p, sr.marker, rgb(sr.color), 2 + s as i32, hollow)?;
            }
        }
    }
    Ok(covered)
}

/// A series line: solid and 2 pixels wide, or `dashed` (8 on, 6 off) and 5 wide, drawn under
/// the solid lines so that one lying on it stays visible along its middle.
pub(super) fn draw_line<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    path: &[(i32, i32)],
    color: RGBColor,
    dashed: bool,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    if !dashed {
        return root.draw(&PathElement::new(path.to_vec(), color.stroke_width(2)));
    }
    let style = color.stroke_width(5);
    for dash in dashes(path, 8.0, 6.0) {
        root.draw(&PathElement::new(dash, style))?;
    }
    Ok(())
}

/// The pieces of a polyline drawn as dashes `on` pixels long with `off`-pixel gaps, the
/// pattern running on across corners.
pub(super) fn dashes(path: &[(i32, i32)], on: f64, off: f64) -> Vec<Vec<(i32, i32)>> {
    let period = on + off;
    let mut out: Vec<Vec<(i32, i32)>> = Vec::new();
    let mut current: Vec<(i32, i32)> = Vec::new();
    // Distance along the path at the start of the current segment.
    let mut at = 0.0;
    for w in path.windows(2) {
        let (a, b) = (
            (w[0].0 as f64, w[0].1 as f64),
            (w[1].0 as f64, w[1].1 as f64),
        );
        let len = (b.0 - a.0).hypot(b.1 - a.1);
        let point = |d: f64| {
            let t = if len > 0.0 { (d - at) / len } else { 0.0 };
            let p = (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
            (p.0.round() as i32, p.1.round() as i32)
        };
        // Walk the pattern's switch points on this segment. A dash still open at its end
        // goes on into the next segment, round the corner.
        let mut d = at;
        while d < at + len {
            let period_start = d - d.rem_euclid(period);
            let dash_end = period_start + on;
            if d < dash_end {
                let next = dash_end.min(at + len);
                if current.is_empty() {
                    current.push(point(d));
                }
                current.push(point(next));
                if next >= dash_end {
                    out.push(std::mem::take(&mut current));
                }
                d = next;
            } else {
                // At least a step on: rounding may put `d` a hair short of the boundary.
                d = (period_start + period).min(at + len).max(d + 1e-9);
            }
        }
        at += len;
    }
    if current.len() > 1 {
        out.push(current);
    }
    out
}

/// Points every few pixels along a polyline, each of weight 1.
pub(super) fn sample_path(path: &[(i32, i32)]) -> Avoid {
    let mut out: Vec<(i32, i32)> = path.to_vec();
    for w in path.windows(2) {
        let (a, b) = (w[0], w[1]);
        let n = ((b.0 - a.0).abs().max((b.1 - a.1).abs()) / 4).max(1);
        out.extend((1..n).map(|k| (a.0 + (b.0 - a.0) * k / n, a.1 + (b.1 - a.1) * k / n)));
    }
    out.into_iter().map(|p| (p, 1)).collect()
}

pub(super) fn rgb(c: (u8, u8, u8)) -> RGBColor {
    RGBColor(c.0, c.1, c.2)
}

/// The corners of a marker's polygon around (x, y) with "radius" `r`; `None` for the shapes
/// that are not polygons (circle, cross, plus).
pub(super) fn marker_polygon(
    marker: Marker,
    (x, y): (i32, i32),
    r: i32,
) -> Option<Vec<(i32, i32)>> {
    // Triangles and the diamond are a pixel larger, so their area is close to the square's.
    let t = r + 1;
    let half_w = (t as f64 * 0.866).round() as i32;
    Some(match marker {
        Marker::Square => vec![
            (x - r, y - r),
            (x + r, y - r),
            (x + r, y + r),
            (x - r, y + r),
        ],
        Marker::Triangle => vec![(x, y - t), (x + half_w, y + t / 2), (x - half_w, y + t / 2)],
        Marker::TriangleDown => vec![(x, y + t), (x + half_w, y - t / 2), (x - half_w, y - t / 2)],
        Marker::Diamond => vec![(x, y - t), (x + t, y), (x, y + t), (x - t, y)],
        Marker::Circle | Marker::Cross | Marker::Plus => return None,
    })
}

/// Extra radius of a hollow marker, so it rings a filled marker at the same point.
pub(super) const HOLLOW_GROW: i32 = 3;

/// Draws a `marker` at (x, y) with radius `r`: filled, or (`hollow`) as a 2-pixel outline
/// [`HOLLOW_GROW`] pixels larger. Crosses and pluses are strokes either way.
pub(super) fn draw_marker<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    (x, y): (i32, i32),
    marker: Marker,
    color: RGBColor,
    r: i32,
    hollow: bool,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let r = if hollow { r + HOLLOW_GROW } else { r };
    let stroke = color.stroke_width(2);
    let fill = if hollow { stroke } else { color.filled() };
    if let Some(mut corners) = marker_polygon(marker, (x, y), r) {
        if !hollow {
            return root.draw(&Polygon::new(corners, fill));
        }
        corners.push(corners[0]);
        return root.draw(&PathElement::new(corners, stroke));
    }
    match marker {
        Marker::Cross => {
            root.draw(&PathElement::new([(x - r, y - r), (x + r, y + r)], stroke))?;
            root.draw(&PathElement::new([(x - r, y + r), (x + r, y - r)], stroke))
        }
        Marker::Plus => {
            let r = r + 1;
            root.draw(&PathElement::new([(x - r, y), (x + r, y)], stroke))?;
            root.draw(&PathElement::new([(x, y - r), (x, y + r)], stroke))
        }
        _ => root.draw(&Circle::new((x, y), r, fill)),
    }
}

/// One legend row: a series (its marker, and its line if it has one) or the Pareto front.
pub(super) struct Entry {
    pub(super) label: String,
    pub(super) color: RGBColor,
    /// A sample line (dashed for a hollow series; thick for the front).
    pub(super) line: bool,
    /// The series' marker; `None` for the front.
    pub(super) marker: Option<Marker>,
    pub(super) hollow: bool,
}

/// Legend entries and their layout.
pub(super) struct Legend {
    pub(super) entries: Vec<Entry>,
    pub(super) w: i32,
    pub(super) h: i32,
    /// Height of a text line.
    line: i32,
}

/// Width of the sample line or marker at the left of a legend row.
pub(super) const SWATCH: i32 = 24;

impl Legend {
    /// The labelled series, then the front when one is drawn; sized for text at scale `s`.
    pub(super) fn new(chart: &Chart, s: u32, face: Face) -> Legend {
        let mut entries: Vec<Entry> = chart
            .series
            .iter()
            .filter(|sr| !sr.label.is_empty())
            .map(|sr| Entry {
                label: sr.label.clone(),
                color: rgb(sr.color),
                line: sr.line,
                marker: Some(sr.marker),
                hollow: sr.hollow,
            })
            .collect();
        if drawn_front(chart).is_some() {
            entries.push(Entry {
                label: FRONT_LABEL.to_string(),
                color: FRONT_COLOR,
                line: true,
                marker: None,
                hollow: false,
            });
        }
        let text_w = entries
            .iter()
            .map(|e| face.width(&e.label, s))
            .max()
            .unwrap_or(0);
        let line = face.line(s) as i32;
        let w = PAD as i32 * 3 + SWATCH + text_w as i32;
        let h = PAD as i32 * 2 + entries.len() as i32 * Self::row(line) - 4;
        Legend {
            entries,
            w,
            h,
            line,
        }
    }

    /// Height of a row for text lines `line` pixels high.
    pub(super) fn row(line: i32) -> i32 {
        line + 4
    }

    /// Top-left corner of the legend: the corner of the plot whose box covers the least
    /// weight of `avoid` pixels (top right on ties). `None` when there is nothing to list.
    pub(super) fn place(&self, frame: &Frame, avoid: &Avoid) -> Option<(i32, i32)> {
        if self.entries.is_empty() {
            return None;
        }
        let inset = 6;
        let (l, t) = (frame.left + inset, frame.top + inset);
        let (r, b) = (
            frame.right() - inset - self.w,
            frame.bottom() - inset - self.h,
        );
        let corners = [(r, t), (l, t), (r, b), (l, b)];
        corners.into_iter().min_by_key(|&(x, y)| {
            let m = 4; // keep markers' edges out from under the box too
            avoid
                .iter()
                .filter(|(p, _)| p.0 >= x - m && p.0 <= x + self.w + m)
                .filter(|(p, _)| p.1 >= y - m && p.1 <= y + self.h + m)
                .map(|(_, weight)| weight)
                .sum::<usize>()
        })
    }

    pub(super) fn draw_box<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, plotters::coord::Shift>,
        (x, y): (i32, i32),
        s: u32,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let corners = [(x, y), (x + self.w, y + self.h)];
        root.draw(&Rectangle::new(corners, WHITE.filled()))?;
        root.draw(&Rectangle::new(
            corners,
            RGBColor(150, 150, 150).stroke_width(1),
        ))?;
        for (k, e) in self.entries.iter().enumerate() {
            let cy = y + PAD as i32 + k as i32 * Self::row(self.line) + self.line / 2;
            let (x0, x1) = (x + PAD as i32, x + PAD as i32 + SWATCH);
            if e.line && e.marker.is_none() {
                let path = [(x0, cy), (x1, cy)];
                root.draw(&PathElement::new(path, e.color.stroke_width(3)))?;
            } else if e.line {
                draw_line(root, &[(x0, cy), (x1, cy)], e.color, e.hollow)?;
            }
            if let Some(marker) = e.marker {
                let at = ((x0 + x1) / 2, cy);
                draw_marker(root, at, marker, e.color, 2 + s as i32, e.hollow)?;
            }
        }
        Ok(())
    }

    /// The labels, right of their swatches.
    pub(super) fn draw_text(&self, img: &mut RgbImage, (x, y): (i32, i32), s: u32, face: Face) {
        for (k, e) in self.entries.iter().enumerate() {
            let tx = x + 2 * PAD as i32 + SWATCH;
            let ty = y + PAD as i32 + k as i32 * Self::row(self.line);
            face.draw(img, (tx, ty), &e.label, s, TEXT, false);
        }
    }
}
