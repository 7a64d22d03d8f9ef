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

/// Pixels the legend should not cover, each with the cost of covering it.
pub(super) type Avoid = Vec<((i32, i32), usize)>;

/// Draws the front, the series lines and the markers (in that order, so markers stay on
/// top); returns the pixels they cover (lines sampled every few pixels) with their weights.
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
    if let Some(front) = &chart.front {
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
    for sr in chart.series.iter().filter(|sr| sr.line) {
        let pts = to_px(&sr.points, true);
        covered.extend(sample_path(&pts));
        root.draw(&PathElement::new(pts, rgb(sr.color).stroke_width(2)))?;
    }
    for (i, sr) in chart.series.iter().enumerate() {
        for p in to_px(&sr.points, false) {
            covered.push((p, MARKER_WEIGHT));
            draw_marker(root, p, i, rgb(sr.color), 2 + s as i32)?;
        }
    }
    Ok(covered)
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

/// Series `i` gets marker shape `i % 5` (circle, square, triangle, diamond, cross), so
/// series stay apart in grey-scale prints too.
pub(super) fn draw_marker<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    (x, y): (i32, i32),
    i: usize,
    color: RGBColor,
    r: i32,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    match i % 5 {
        0 => root.draw(&Circle::new((x, y), r, color.filled())),
        1 => root.draw(&Rectangle::new(
            [(x - r, y - r), (x + r, y + r)],
            color.filled(),
        )),
        2 => root.draw(&TriangleMarker::new((x, y), r + 1, color.filled())),
        3 => root.draw(&Polygon::new(
            vec![
                (x, y - r - 1),
                (x + r + 1, y),
                (x, y + r + 1),
                (x - r - 1, y),
            ],
            color.filled(),
        )),
        _ => root.draw(&Cross::new((x, y), r, color.stroke_width(2))),
    }
}

/// Legend entries and their layout.
pub(super) struct Legend {
    /// (label, series index or `None` for the Pareto front, line?, colour)
    pub(super) entries: Vec<(String, Option<usize>, bool, RGBColor)>,
    pub(super) w: i32,
    pub(super) h: i32,
}

/// Width of the sample line or marker at the left of a legend row.
pub(super) const SWATCH: i32 = 24;

impl Legend {
    pub(super) fn new(chart: &Chart, s: u32) -> Legend {
        let mut entries: Vec<_> = chart
            .series
            .iter()
            .enumerate()
            .filter(|(_, sr)| !sr.label.is_empty())
            .map(|(i, sr)| (sr.label.clone(), Some(i), sr.line, rgb(sr.color)))
            .collect();
        if chart.front.as_ref().is_some_and(|f| !f.is_empty()) {
            entries.push(("Pareto front".to_string(), None, true, FRONT_COLOR));
        }
        let text_w = entries
            .iter()
            .map(|e| text_width(&e.0, s))
            .max()
            .unwrap_or(0);
        let w = PAD as i32 * 3 + SWATCH + text_w as i32;
        let h = PAD as i32 * 2 + entries.len() as i32 * Self::row(s) - 4;
        Legend { entries, w, h }
    }

    pub(super) fn row(s: u32) -> i32 {
        8 * s as i32 + 4
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
        for (k, (_, series, line, color)) in self.entries.iter().enumerate() {
            let cy = y + PAD as i32 + k as i32 * Self::row(s) + 4 * s as i32;
            let (x0, x1) = (x + PAD as i32, x + PAD as i32 + SWATCH);
            if *line {
                let width = if series.is_none() { 3 } else { 2 };
                root.draw(&PathElement::new(
                    [(x0, cy), (x1, cy)],
                    color.stroke_width(width),
                ))?;
            }
            if let Some(i) = series {
                draw_marker(root, ((x0 + x1) / 2, cy), *i, *color, 2 + s as i32)?;
            }
        }
        Ok(())
    }

    pub(super) fn draw_text(&self, img: &mut RgbImage, (x, y): (i32, i32), s: u32) {
        for (k, (label, ..)) in self.entries.iter().enumerate() {
            let tx = x + 2 * PAD as i32 + SWATCH;
            let ty = y + PAD as i32 + k as i32 * Self::row(s);
            draw_str(img, tx, ty, label, s, TEXT, false);
        }
    }
}
