//! Axes: ranges in drawing space (log10 on log axes), zero floors and tick choice.

use super::*;

/// Ticks on one axis: (position in drawing space, label) and unlabelled minor positions.
pub(super) type Ticks = (Vec<(f64, String)>, Vec<f64>);

/// One axis: the range in drawing space (the value itself, or log10 of it on a log axis).
pub(super) struct Axis {
    pub(super) log: bool,
    /// Value zero and negative values are drawn at; only set on a log axis that has some.
    pub(super) floor: Option<f64>,
    pub(super) lo: f64,
    pub(super) hi: f64,
}

impl Axis {
    pub(super) fn new(values: impl Iterator<Item = f64>, log: bool, floor: Option<f64>) -> Axis {
        let values: Vec<f64> = values.filter(|v| v.is_finite()).collect();
        let floor = if log && values.iter().any(|&v| v <= 0.0) {
            let min_pos = values.iter().copied().filter(|&v| v > 0.0).reduce(f64::min);
            let auto = min_pos.map_or(LOG_FLOOR, |m| 10f64.powf(m.log10().floor() - 1.0));
            Some(floor.filter(|f| f.is_finite() && *f > 0.0).unwrap_or(auto))
        } else {
            None
        };
        let mut axis = Axis {
            log,
            floor,
            lo: 0.0,
            hi: 1.0,
        };
        let space: Vec<f64> = values.iter().filter_map(|&v| axis.space(v)).collect();
        if let (Some(lo), Some(hi)) = (
            space.iter().copied().reduce(f64::min),
            space.iter().copied().reduce(f64::max),
        ) {
            let (mut lo, mut hi) = (lo, hi);
            if hi - lo <= 1e-12 * hi.abs().max(lo.abs()).max(1e-300) {
                // One distinct value: half a decade, or 10% of the value, either side.
                let half = if log || lo == 0.0 {
                    0.5
                } else {
                    lo.abs() * 0.1
                };
                (lo, hi) = (lo - half, hi + half);
            }
            let margin = (hi - lo) * 0.05;
            (axis.lo, axis.hi) = (lo - margin, hi + margin);
        }
        axis
    }

    /// A data value in drawing space; `None` for non-finite values.
    pub(super) fn space(&self, v: f64) -> Option<f64> {
        if !v.is_finite() {
            None
        } else if !self.log {
            Some(v)
        } else if v > 0.0 {
            Some(v.log10())
        } else {
            Some(self.floor.unwrap_or(LOG_FLOOR).log10())
        }
    }

    /// At most `max` labelled ticks on an axis `len_px` long; a floor tick ("0") replaces
    /// any tick closer to it than `glyph_px` and a half, and those below it (which would
    /// read as values under zero).
    pub(super) fn ticks(&self, max: usize, len_px: u32, glyph_px: u32) -> Ticks {
        let (mut major, mut minor) = if self.log {
            log_ticks(self.lo, self.hi, max)
        } else {
            let v = nice_ticks(self.lo, self.hi, max);
            let step = if v.len() > 1 { v[1] - v[0] } else { 1.0 };
            (
                v.iter().map(|&t| (t, fmt_linear(t, step))).collect(),
                vec![],
            )
        };
        if let Some(floor) = self.floor {
            let f = floor.log10();
            let min_gap = (self.hi - self.lo) * 1.5 * glyph_px as f64 / len_px.max(1) as f64;
            major.retain(|(t, _)| *t - f >= min_gap);
            minor.retain(|&t| t > f);
            major.push((f, "0".to_string()));
        }
        (major, minor)
    }

    /// Grid lines: (position, major?).
    pub(super) fn lines(&self, ticks: &Ticks) -> Vec<(f64, bool)> {
        let major = ticks.0.iter().map(|t| (t.0, true));
        major.chain(ticks.1.iter().map(|&t| (t, false))).collect()
    }
}

/// The most x ticks whose labels (in `face` at scale `s`) do not collide on a plot `pw`
/// pixels wide.
pub(super) fn x_ticks_that_fit(xa: &Axis, pw: u32, s: u32, face: Face) -> Ticks {
    let glyph = face.line(s);
    let mut max = (pw / (glyph * 4 + 12)).max(2) as usize;
    loop {
        let ticks = xa.ticks(max, pw, glyph);
        let mut pos: Vec<(f64, u32)> = ticks
            .0
            .iter()
            .map(|(v, l)| (*v, face.width(l, s)))
            .collect();
        pos.sort_by(|a, b| a.0.total_cmp(&b.0));
        let px_per_unit = pw as f64 / (xa.hi - xa.lo);
        let fits = pos.windows(2).all(|w| {
            let gap = (w[1].0 - w[0].0) * px_per_unit;
            gap >= (w[0].1 + w[1].1) as f64 / 2.0 + glyph as f64
        });
        if fits || max <= 2 {
            return ticks;
        }
        max -= 1;
    }
}

/// Multiples of a 1-2-5 step in [lo, hi], at most `max` of them (but at least one step).
pub(super) fn nice_ticks(lo: f64, hi: f64, max: usize) -> Vec<f64> {
    let raw = (hi - lo) / max.max(1) as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|&st| st >= raw * (1.0 - 1e-9))
        .unwrap_or(10.0 * mag);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// Log-axis ticks in log10 space. Three decades or more: every decade (or every k-th when
/// there are too many, the skipped decades becoming minor lines), with 2..9 × decade minor
/// lines. Fewer: 1, 2 and 5 × decade when at least two of those fit, else every decade, else
/// (an axis too short for either) a linear 1-2-5 sequence of values.
pub(super) fn log_ticks(lo: f64, hi: f64, max: usize) -> Ticks {
    let (d0, d1) = ((lo - 1e-9).ceil() as i32, (hi + 1e-9).floor() as i32);
    let inside = |v: f64| v >= lo - 1e-9 && v <= hi + 1e-9;
    let mult = |ms: &[f64]| -> Vec<(f64, f64, i32)> {
        (lo.floor() as i32..=hi.ceil() as i32)
            .flat_map(|e| ms.iter().map(move |&m| (m, e)))
            .map(|(m, e)| ((m * 10f64.powi(e)).log10(), m, e))
            .filter(|t| inside(t.0))
            .collect()
    };
    let minor_all: Vec<f64> = mult(&[2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
        .iter()
        .map(|t| t.0)
        .collect();
    let n = (d1 - d0 + 1).max(0) as usize;
    let one_two_five = mult(&[1.0, 2.0, 5.0]);
    if n < 3 && one_two_five.len() >= 2 && one_two_five.len() <= max.max(2) {
        let major = one_two_five.iter().map(|&(v, m, e)| (v, fmt_pow(m, e)));
        return (major.collect(), minor_all);
    }
    if n >= 2 {
        let k = n.div_ceil(max.max(1)).max(1) as i32;
        let major: Vec<_> = (d0..=d1)
            .filter(|e| e.rem_euclid(k) == 0)
            .map(|e| (e as f64, fmt_pow(1.0, e)))
            .collect();
        let minor = if k == 1 {
            minor_all
        } else {
            (d0..=d1)
                .filter(|e| e.rem_euclid(k) != 0)
                .map(f64::from)
                .collect()
        };
        return (major, minor);
    }
    let (a, b) = (10f64.powf(lo), 10f64.powf(hi));
    let vals: Vec<f64> = nice_ticks(a, b, max)
        .into_iter()
        .filter(|&v| v > 0.0)
        .collect();
    let step = if vals.len() > 1 { vals[1] - vals[0] } else { a };
    let major = vals
        .iter()
        .map(|&v| (v.log10(), fmt_linear(v, step)))
        .collect();
    (major, vec![])
}

/// `m`×10^`e` as a short label: plain decimals from 0.001 to 99999, `2e-5` style outside.
pub(super) fn fmt_pow(m: f64, e: i32) -> String {
    if (-3..=4).contains(&e) {
        format!("{:.*}", (-e).max(0) as usize, m * 10f64.powi(e))
    } else {
        format!("{m}e{e}")
    }
}

/// A tick value on a linear axis with spacing `step`: as many decimals as the step needs, or
/// scientific notation with just enough digits for very large or small values.
pub(super) fn fmt_linear(v: f64, step: f64) -> String {
    if v.abs() < step * 1e-6 {
        return "0".to_string();
    }
    let step_exp = step.abs().log10().floor() as i32;
    if v.abs() >= 1e6 || step < 1e-4 {
        let digits = (v.abs().log10().floor() as i32 - step_exp).max(0) as usize;
        let s = format!("{:.*e}", digits, v);
        // "1.50e3" → "1.5e3"
        match s.split_once('e') {
            Some((m, e)) if m.contains('.') => {
                format!("{}e{}", m.trim_end_matches('0').trim_end_matches('.'), e)
            }
            _ => s,
        }
    } else {
        format!("{:.*}", (-step_exp).max(0) as usize, v)
    }
}
