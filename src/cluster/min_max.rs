//! `f64` minimum and maximum in one instruction each, for the assignment's per-slice and
//! per-row arithmetic.
//!
//! `f64::min` and `f64::max` return the other operand when one is NaN, which costs x86-64
//! five instructions more than a comparison and a select (`minsd`, `maxsd`): before these,
//! the NaN checks were an eighth of the instructions of finding a light's cells. So on
//! x86-64 (and on every target but aarch64) these are a comparison and a select, and they
//! differ from `f64::min` only in NaN: `a.at_most(b)` is `a.min(b)` whenever `a` is not NaN
//! (a NaN `b` gives `a`, as `f64::min` does), but a NaN `a` stays NaN. aarch64 has
//! `f64::min` and `max` in one instruction each (`fminnm`, `fmaxnm`; a comparison and a
//! select take two), so there they are `f64::min` and `max`, and a NaN `a` gives `b`. Every
//! caller puts first an operand that is never NaN, or one that is NaN only when the other is
//! too, and says why: then both give the same.
//! (Of two zeros x86-64 gives the first, aarch64 orders −0 below +0; no list depends on it:
//! `scripts/check-aarch64` compares the lists made on both.)

/// `f64` bounds in one instruction each (see the module docs).
pub(crate) trait MinMax {
    /// The lesser of `self` and `b`: `self.min(b)` for a `self` not NaN (a NaN `self`: see
    /// the module docs).
    fn at_most(self, b: f64) -> f64;
    /// The greater of `self` and `b`: `self.max(b)` for a `self` not NaN.
    fn at_least(self, b: f64) -> f64;
}

impl MinMax for f64 {
    #[cfg(target_arch = "aarch64")]
    #[inline(always)]
    fn at_most(self, b: f64) -> f64 {
        self.min(b)
    }

    #[cfg(target_arch = "aarch64")]
    #[inline(always)]
    fn at_least(self, b: f64) -> f64 {
        self.max(b)
    }

    #[cfg(not(target_arch = "aarch64"))]
    #[inline(always)]
    fn at_most(self, b: f64) -> f64 {
        if b < self {
            b
        } else {
            self
        }
    }

    #[cfg(not(target_arch = "aarch64"))]
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
    /// apart from the sign of an equal zero; a NaN first operand stays NaN (on aarch64 it
    /// gives the other operand, as `f64::min` does).
    #[test]
    fn agrees_with_f64_min_and_max_for_a_first_operand_not_nan() {
        let values = [
            f64::NEG_INFINITY,
            -1e300,
            -2.5,
            -1.0,
            -f64::MIN_POSITIVE,
            -0.0,
            0.0,
            f64::MIN_POSITIVE,
            1.0,
            2.5,
            1e300,
            f64::INFINITY,
            f64::NAN,
        ];
        let same = |a: f64, b: f64| a.to_bits() == b.to_bits() || (a == 0.0 && b == 0.0);
        for &a in &values {
            for &b in &values {
                if a.is_nan() && cfg!(not(target_arch = "aarch64")) {
                    assert!(a.at_most(b).is_nan() && a.at_least(b).is_nan());
                } else if a.is_nan() {
                    assert!(same(a.at_most(b), b) || b.is_nan(), "NaN at most {b}");
                    assert!(same(a.at_least(b), b) || b.is_nan(), "NaN at least {b}");
                } else {
                    assert!(same(a.at_most(b), a.min(b)), "{a} at most {b}");
                    assert!(same(a.at_least(b), a.max(b)), "{a} at least {b}");
                }
            }
        }
    }
}
