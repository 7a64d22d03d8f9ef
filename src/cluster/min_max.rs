//! `f64` minimum and maximum in one instruction each, for the assignment's per-slice and
//! per-row arithmetic.
//!
//! `f64::min` and `f64::max` return the other operand when one is NaN, which costs x86-64
//! five instructions more than a comparison and a select (`minsd`, `maxsd`): before these,
//! the NaN checks were an eighth of the instructions of finding a light's cells. The
//! difference is only in NaN: `a.at_most(b)` is `a.min(b)` whenever `a` is not NaN (a NaN `b`
//! gives `a`, as `f64::min` does), but a NaN `a` stays NaN. So every caller puts first an
//! operand that is never NaN, or one that is NaN only when the other is too, and says why.
//! (Of two equal operands both give the first, the one of `±0` x86-64's `f64::min` gives.)

/// `f64` bounds by comparison and select (see the module docs).
pub(crate) trait MinMax {
    /// `b` where it is less than `self`, else `self` (`self.min(b)` for a `self` not NaN).
    fn at_most(self, b: f64) -> f64;
    /// `b` where it is greater than `self`, else `self` (`self.max(b)` for a `self` not NaN).
    fn at_least(self, b: f64) -> f64;
}

impl MinMax for f64 {
    #[inline(always)]
    fn at_most(self, b: f64) -> f64 {
        if b < self {
            b
        } else {
            self
        }
    }

    #[inline(always)]
    fn at_least(self, b: f64) -> f64 {
        if b > self {
            b
        } else {
            self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::MinMax;

    /// Equal to `f64::min` and `f64::max` wherever the first operand is not NaN, bit for bit
    /// apart from the sign of an equal zero; a NaN first operand stays NaN.
    #[test]
    fn agrees_with_f64_min_and_max_for_a_first_operand_not_nan() {
        let values = [
            f64::NEG_INFINITY, -1e300, -2.5, -1.0, -f64::MIN_POSITIVE, -0.0, 0.0,
            f64::MIN_POSITIVE, 1.0, 2.5, 1e300, f64::INFINITY, f64::NAN,
        ];
        let same = |a: f64, b: f64| a.to_bits() == b.to_bits() || (a == 0.0 && b == 0.0);
        for &a in &values {
            for &b in &values {
                if a.is_nan() {
                    assert!(a.at_most(b).is_nan() && a.at_least(b).is_nan());
                } else {
                    assert!(same(a.at_most(b), a.min(b)), "{a} at most {b}");
                    assert!(same(a.at_least(b), a.max(b)), "{a} at least {b}");
                }
            }
        }
    }
}
