//! The tables a grid keeps for the assignment's hot path, filled by `build.rs` from the grid
//! and holding no reference back to it: which slice a view depth lies in without a logarithm
//! ([`SliceLookup`]), per-cascade constants that turn divisions into multiplications
//! ([`CascadeConstants`]), and each slice's exact depths and extents ([`SliceFrustum`]).
//!
//! **Slices by table.** Along the log2 mapping, slice boundaries are fixed depths. A depth's
//! slice is found from the top bits of its `f64` pattern (exponent and 6 mantissa bits: a
//! bucket spanning a ratio of at most 1 + 1/64) through a table holding each bucket's first
//! slice, then stepping past the boundaries the depth has crossed inside its bucket (a slice
//! spans a ratio of about 1 + 2·tan(fov/2)·footprint·slice_depth / height: 1.1 at 64-pixel
//! cells on 720 rows, where one comparison decides, 1.013 at 8-pixel half-deep cells on 360,
//! where a bucket holds two slices at most). The
//! result is exactly "the last slice whose start is ≤ d"; the boundaries come from
//! `ClusterGrid::slice_depth_range`, so it agrees with `ClusterGrid::view_z_to_cascade_slice`
//! up to its rounding at a boundary, which the caller's widening of the depth range absorbs.
//!
//! ```text
//! bits(d) >> 46 ─ base ─► buckets[b]: first slice g ─► while d ≥ start[g + 1]: g += 1 ─► (k, s)
//! ```

use crate::cluster::headroom::room_for;

/// Bits below the bucket: 52 mantissa bits − 6 kept.
const BUCKET_SHIFT: u32 = 46;

/// Bucket number of a depth: its bit pattern as a signed number, less the low mantissa bits
/// (monotone in `d` for `d` ≥ 0, negative for negative patterns).
fn bucket(d: f64) -> i64 {
    (d.to_bits() as i64) >> BUCKET_SHIFT
}

/// Slice lookup for the log2 depth mapping (see the module docs).
#[derive(Clone, Debug, Default)]
pub(crate) struct SliceLookup {
    /// Bucket number of `buckets[0]`.
    base: i64,
    /// Per bucket: the first slice it reaches and where the next one starts.
    buckets: Vec<Bucket>,
    /// Per global slice: the depth where it starts (0 for the first), then a NaN that no
    /// depth is `≥`, which ends the steps of [`SliceLookup::find`] without a length check.
    start: Vec<f64>,
    /// Per global slice: (cascade, slice within the cascade).
    address: Vec<(u32, u32)>,
}

impl SliceLookup {
    /// Makes this the lookup of a grid's slices, reusing its buffers: `slices` gives each
    /// slice's (cascade, slice within the cascade) and the view depth where it starts, near to
    /// far, and `near` and `far` are the grid's ends. Buckets cover the grid's first split to
    /// its far end: nearer depths all lie in the first slice and farther ones reach the last
    /// through the steps. The buffers keep room for `most_slices` and for buckets from `near`
    /// (the nearest a split can be), so a grid rebuilt finer allocates nothing.
    pub(crate) fn rebuild(
        &mut self,
        slices: impl Iterator<Item = ((u32, u32), f64)>,
        most_slices: usize,
        near: f64,
        far: f64,
    ) {
        let (start, address) = (&mut self.start, &mut self.address);
        start.clear();
        address.clear();
        room_for(start, most_slices + 1);
        room_for(address, most_slices);
        for (slice, z0) in slices {
            start.push(if start.is_empty() { 0.0 } else { z0 });
            address.push(slice);
        }
        let far = far.max(f64::MIN_POSITIVE);
        // Depths before the second slice's start (all in the first slice) clamp to the first
        // bucket, so that bucket must begin in the first slice: it is the bucket of the last
        // depth before that start. (The start's own bucket begins in the second slice when
        // the start is a bucket's first depth, as 1.0 is.)
        let second = start.get(1).copied().unwrap_or(far).min(far);
        let base = bucket(if second > 0.0 {
            second.next_down()
        } else {
            second
        });
        let last = bucket(far).max(base);
        start.push(f64::NAN);
        self.buckets.clear();
        // Capped: a near plane of 10⁻³⁰⁰ would ask for a bucket per 1/64 octave down to it.
        let most_buckets = last - bucket(near.max(f64::MIN_POSITIVE)).min(last) + 1;
        room_for(&mut self.buckets, (most_buckets as usize).min(1 << 14));
        self.buckets.extend((base..=last).map(|b| {
            let d = f64::from_bits((b as u64) << BUCKET_SHIFT);
            let first = start.partition_point(|&z| z <= d) - 1;
            Bucket {
                next_start: start[first + 1],
                first: first as u32,
            }
        }));
        self.base = base;
    }

    /// Its buffers' capacities (a test that a rebuild did not grow them).
    #[cfg(test)]
    pub(crate) fn capacities(&self) -> [usize; 3] {
        [
            self.buckets.capacity(),
            self.start.capacity(),
            self.address.capacity(),
        ]
    }

    /// Empty, as [`SliceLookup::default`], keeping the buffers (for the linear mapping, which
    /// needs no table).
    pub(crate) fn clear(&mut self) {
        self.base = 0;
        self.buckets.clear();
        self.start.clear();
        self.address.clear();
    }

    /// (cascade, slice) of the last slice starting at or before `d` (`d` ≥ 0, not NaN). The
    /// assignment takes ranges ([`SliceLookup::find_range`]).
    #[cfg(test)]
    pub(crate) fn find(&self, d: f64) -> (u32, u32) {
        self.address[self.index(d)]
    }

    /// [`SliceLookup::find`] of `d0` and of `d1 ≥ d0`, the second without a look-up of its
    /// own when `d1` lies in the first's slice (a small light's whole depth range, most often).
    #[inline(always)]
    pub(crate) fn find_range(&self, d0: f64, d1: f64) -> ((u32, u32), (u32, u32)) {
        let g0 = self.index(d0);
        // The slices start in ascending order, and the last entry is NaN (no such start).
        let g1 = if d1 < self.start[g0 + 1] {
            g0
        } else {
            self.index(d1)
        };
        (self.address[g0], self.address[g1])
    }

    /// The number of the last slice starting at or before `d` (`d` ≥ 0, not NaN).
    #[inline(always)]
    fn index(&self, d: f64) -> usize {
        // Negative patterns (−0 included) clamp to the first bucket, +∞ to the last.
        let bucket = (bucket(d) - self.base).clamp(0, self.buckets.len() as i64 - 1);
        let bucket = self.buckets[bucket as usize];
        // The first step without a branch and from the bucket's own entry (one load, not two
        // in a row): on all but the finest grids a bucket holds one boundary at most, and
        // whether a depth lies past it is a coin toss that a branch predictor loses, on the
        // assignment's hot path.
        let mut g = bucket.first as usize + usize::from(d >= bucket.next_start);
        while d >= self.start[g + 1] {
            g += 1;
        }
        g
    }
}

/// One bucket of [`SliceLookup`]: the global slice (slices numbered across cascades) its
/// smallest depth is in, and the depth where the slice after it starts (NaN after the last).
#[derive(Clone, Copy, Debug)]
struct Bucket {
    next_start: f64,
    first: u32,
}

/// Per-cascade constants of the box projection and of the NDC → tile conversion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct CascadeConstants {
    /// `1 / z_near`, or +∞ for the first cascade (which also takes depths in front of its
    /// start): `1 / max(d, z_near) = min(1 / d, inv_near)`.
    pub inv_near: f64,
    /// `1 / z_far`, or 0 for the last cascade (which extends to infinity):
    /// `1 / min(d, z_far) = max(1 / d, inv_far)`.
    pub inv_far: f64,
    /// Half the columns and half the rows: tile coordinate `(ndc + 1) · half`.
    pub half_tiles: [f64; 2],
    /// NDC width of one column and height of one row, `2 / tiles` (divided once here: the
    /// spot-cone test asks for them in every slice).
    pub ndc_step: [f64; 2],
    /// Width of one column and height of one row in view-space slope (perspective) or view
    /// units (orthographic): `2 · extent / tiles`, `extent = 1 / ndc_scale`.
    pub tile_step: [f64; 2],
    /// `1 / ndc_scale` per axis: `tan` of the half field of view (perspective) or the half
    /// width and height (orthographic); column or row `i` starts at `−extent + i · step`.
    pub extent: [f64; 2],
    /// Index of the cascade's first slice among all the grid's slices (for
    /// `ClusterGrid::slice_slabs`).
    pub first_slice: u32,
}

impl CascadeConstants {
    /// View-space slope (perspective) or offset (orthographic) where column (`axis` 0) or row
    /// (`axis` 1) `i` starts; `i = tiles` is where the last one ends.
    #[inline(always)]
    pub(crate) fn tile_edge(&self, axis: usize, i: u32) -> f64 {
        -self.extent[axis] + i as f64 * self.tile_step[axis]
    }
}

/// One slice's exact depths and the view half extents at them (see
/// `ClusterGrid::row_spheres`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SliceFrustum {
    /// The slice's view depths (exact: `ClusterGrid::slice_depth_range`).
    pub(super) depths: (f64, f64),
    pub(super) near: (f64, f64),
    pub(super) far: (f64, f64),
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cluster::grid::{ClusterGrid, GridConfig, GridProjection};

    /// The lookup of `grid`'s slices, as the grid builds it.
    fn lookup_of(grid: &ClusterGrid) -> SliceLookup {
        let mut lookup = SliceLookup::default();
        lookup.rebuild(grid.slice_starts(), 0, grid.near, grid.far);
        lookup
    }

    fn grids() -> Vec<ClusterGrid> {
        let t = 30f64.to_radians().tan();
        let persp = |near, far, w, h| {
            ClusterGrid::new(
                w,
                h,
                GridProjection::Perspective {
                    tan_x: t * w as f64 / h as f64,
                    tan_y: t,
                },
                near,
                far,
                &GridConfig::default(),
            )
        };
        vec![
            persp(0.1, 80.0, 1280, 720),
            persp(1e-4, 1e5, 256, 144),
            persp(0.5, 0.6, 640, 480),
            persp(0.0, 10.0, 64, 64),
        ]
    }

    /// The lookup equals a search over the slice starts, at and around every boundary and
    /// across the whole depth range (0 and beyond the far end included).
    #[test]
    fn lookup_matches_a_search_over_slice_starts() {
        for grid in grids() {
            let lookup = lookup_of(&grid);
            let search =
                |d: f64| lookup.address[lookup.start.partition_point(|&z| z <= d).max(1) - 1];
            let mut depths = vec![-0.0, 0.0, f64::MIN_POSITIVE, grid.far * 1e3, f64::INFINITY];
            for &z in lookup.start[1..].iter().filter(|z| !z.is_nan()) {
                depths.extend([z, z.next_up(), z.next_down(), z * 1.01, z * 0.99]);
            }
            let mut d = 1e-6;
            while d < grid.far * 4.0 {
                depths.push(d);
                d *= 1.001;
            }
            for &d in &depths {
                assert_eq!(lookup.find(d), search(d), "depth {d}");
            }
            // A range's ends as two look-ups give, whether or not they share a slice.
            depths.sort_by(f64::total_cmp);
            for (i, &d0) in depths.iter().enumerate() {
                for &d1 in depths[i..].iter().take(12) {
                    let ends = (search(d0), search(d1));
                    assert_eq!(lookup.find_range(d0, d1), ends, "depths {d0}..{d1}");
                }
            }
        }
    }

    /// Away from boundaries, the lookup agrees with the mapping the shader evaluates.
    #[test]
    fn lookup_agrees_with_the_depth_mapping() {
        for grid in grids() {
            let lookup = lookup_of(&grid);
            let mut d = grid.near.max(1e-6);
            let mut checked = 0;
            while d < grid.far * 2.0 {
                let (lo, hi) = (
                    grid.view_z_to_cascade_slice(d * (1.0 - 1e-9)),
                    grid.view_z_to_cascade_slice(d * (1.0 + 1e-9)),
                );
                if lo == hi {
                    assert_eq!(lookup.find(d), lo, "depth {d}");
                    checked += 1;
                }
                d *= 1.003;
            }
            assert!(checked > 100, "only {checked} depths checked");
        }
    }
}
