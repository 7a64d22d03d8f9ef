//! Percentiles of per-frame figures: what a game sees is its slow frames, not the median.

use serde::Serialize;

/// The distribution of one figure over the timed frames (nearest-rank percentiles).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Spread {
    /// Median.
    pub p50: f64,
    /// 95th percentile.
    pub p95: f64,
    /// 99th percentile (with fewer than 100 frames, the slowest but one per hundred rounds up
    /// to the maximum).
    pub p99: f64,
    /// Largest.
    pub max: f64,
    /// Frames it was taken over.
    pub frames: usize,
}

impl Spread {
    /// The spread of `values`; `None` for none (or any NaN).
    pub fn of(values: impl IntoIterator<Item = f64>) -> Option<Spread> {
        let mut v: Vec<f64> = values.into_iter().collect();
        if v.is_empty() || v.iter().any(|x| x.is_nan()) {
            return None;
        }
        v.sort_by(f64::total_cmp);
        let rank = |q: f64| v[((v.len() as f64 * q).ceil() as usize).clamp(1, v.len()) - 1];
        Some(Spread {
            p50: rank(0.50),
            p95: rank(0.95),
            p99: rank(0.99),
            max: v[v.len() - 1],
            frames: v.len(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::Spread;

    #[test]
    fn nearest_rank_percentiles() {
        let s = Spread::of((1..=200).map(f64::from)).unwrap();
        assert_eq!(
            (s.p50, s.p95, s.p99, s.max, s.frames),
            (100.0, 190.0, 198.0, 200.0, 200)
        );
        let one = Spread::of([7.0]).unwrap();
        assert_eq!((one.p50, one.p99, one.max), (7.0, 7.0, 7.0));
        // One slow frame in twenty shows at p95 and above, not in the median.
        let s = Spread::of((0..20).map(|i| if i == 3 { 50.0 } else { 10.0 })).unwrap();
        assert_eq!((s.p50, s.p95, s.max), (10.0, 10.0, 50.0));
        assert_eq!(Spread::of([]), None);
        assert_eq!(Spread::of([1.0, f64::NAN]), None);
    }
}
