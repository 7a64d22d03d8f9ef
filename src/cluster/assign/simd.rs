//! Four `f64` lanes for the assignment's per-row arithmetic (`rows.rs`, the spot cone's rows):
//! `wide`'s `f64x4` (two SSE2 or NEON registers; scalar on targets with neither) and
//! [`MinMax`](crate::cluster::min_max::MinMax)'s bounds lane by lane, so that lanes and scalar
//! code give the same bits.

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
    #[cfg(not(target_arch = "aarch64"))]
    b.simd_lt(a).select(b, a)
}

/// `MinMax::at_least` lane by lane.
#[inline(always)]
pub(super) fn at_least(a: F64x4, b: F64x4) -> F64x4 {
    #[cfg(target_arch = "aarch64")]
    return a.max(b);
    #[cfg(not(target_arch = "aarch64"))]
    b.simd_gt(a).select(b, a)
}
