//! Four `f64` lanes for the assignment's per-row arithmetic (`rows.rs`, the spot cone's rows):
//! `wide`'s `f64x4` (two SSE2 or NEON registers; scalar on targets with neither) and
//! [`MinMax`](crate::cluster::min_max::MinMax)'s bounds lane by lane, so that lanes and scalar
//! code give the same bits.
//!
//! On x86 the bounds are one `minpd`/`maxpd` a register: `minpd(x, y)` is `x < y ? x : y`
//! (`y` when either is NaN), which is `MinMax::at_most(y, x)` exactly. `wide`'s `fast_min`
//! is that instruction; a compare and select took five instructions a register, as the compiler
//! does not see a select of bits as a minimum.

pub(super) use wide::f64x4 as F64x4;

/// `x` in every lane.
#[inline(always)]
pub(super) fn splat(x: f64) -> F64x4 {
    F64x4::splat(x)
}

/// `MinMax::at_most` lane by lane: the same comparison and select, or on aarch64 the same
/// `fminnm`.
#[inline(always)]
pub(super) fn at_most(a: F64x4, b: F64x4) -> F64x4 {
    #[cfg(target_arch = "aarch64")]
    return a.min(b);
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    return b.fast_min(a);
    #[cfg(not(any(
        target_arch = "aarch64",
        all(target_arch = "x86_64", target_feature = "sse2")
    )))]
    b.simd_lt(a).select(b, a)
}

/// `MinMax::at_least` lane by lane.
#[inline(always)]
pub(super) fn at_least(a: F64x4, b: F64x4) -> F64x4 {
    #[cfg(target_arch = "aarch64")]
    return a.max(b);
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    return b.fast_max(a);
    #[cfg(not(any(
        target_arch = "aarch64",
        all(target_arch = "x86_64", target_feature = "sse2")
    )))]
    b.simd_gt(a).select(b, a)
}

/// `start`, `start + 1`, `start + 2`, `start + 3`: exact (integers below 2⁵³), in one
/// conversion instead of four.
#[inline(always)]
pub(super) fn counting_from(start: u32) -> F64x4 {
    splat(start as f64) + F64x4::from([0.0, 1.0, 2.0, 3.0])
}
