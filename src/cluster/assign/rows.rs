//! The per-row chord of the slice refinement (`cells.rs`), four rows at a time: the same
//! arithmetic as one row at a time, lane by lane, in `wide`'s four `f64` lanes (`simd.rs`: two
//! SSE2 registers on x86-64's baseline, two NEON registers on aarch64), without branches
//! between the lanes. Every lane does exactly the scalar operations in the scalar order, so
//! the columns, and the lists, are the same bit for bit.
//!
//! Bounds are taken by comparison and select ([`MinMax`]), the operand first that is NaN only
//! when the other is too: `t · za` (NaN only for `t = 0` and an infinite `za`, and then
//! `zb ≥ za` is infinite too), `low · inv_a` (`inv_a ≥ inv_b ≥ 0`, both finite). A gap that comes
//! out NaN where `f64::max` gave a number gives the same columns: either is "the whole
//! cross-section" (where `f64::max` gave a number, it was ≤ 0; the tests check the lanes
//! against `f64`'s bounds, slabs reaching infinity included).

use super::simd::{at_least, at_most, counting_from, splat, F64x4};
use crate::cluster::min_max::MinMax;

/// Rows whose chords one call of [`RowChords::columns`] works out.
pub(super) const ROW_LANES: usize = 4;

/// What every row of one slice shares (see `ScreenExtent::for_each_row_run`).
pub(super) struct RowChords {
    /// Perspective (rows are bands of slopes) or orthographic (bands of offsets).
    pub perspective: bool,
    /// The slab's clipped depths `za ≤ zb` and their reciprocals `inv_a ≥ inv_b`.
    pub za: f64,
    pub zb: f64,
    pub inv_a: f64,
    pub inv_b: f64,
    /// The sphere's centre (view x, y) and its cross-section's squared radius `ρ²`.
    pub cx: f64,
    pub cy: f64,
    pub rho_sq: f64,
    /// Row `i` starts at `−extent_y + i · step_y` (`CascadeConstants::tile_edge`).
    pub extent_y: f64,
    pub step_y: f64,
    /// NDC scale of x, half the columns, and the last column.
    pub scale_x: f64,
    pub half_tiles_x: f64,
    pub last_column: u32,
    /// The cross-section's columns: every chord's bound, and a row holding the centre's.
    pub columns: (u32, u32),
}

impl RowChords {
    /// Columns `(x0, x1)` of rows `row .. row + ROW_LANES`; `x0 > x1` where a row gets none.
    #[inline(always)]
    pub(super) fn columns(&self, row: u32) -> [(u32, u32); ROW_LANES] {
        let rows = counting_from(row);
        let t0 = splat(-self.extent_y) + rows * splat(self.step_y);
        let t1 = t0 + splat(self.step_y);
        let (za, zb, cy) = (splat(self.za), splat(self.zb), splat(self.cy));
        // The band's nearest approach to the centre over the slab (a lower bound).
        let gap = if self.perspective {
            let below = at_most(t0 * za, t0 * zb) - cy;
            let above = cy - at_least(t1 * za, t1 * zb);
            at_least(below, above)
        } else {
            at_least(t0 - cy, cy - t1)
        };
        let half_sq = splat(self.rho_sq) - gap * gap;
        // A negative `half_sq` gives NaN here, and its lane no columns below.
        let half = half_sq.sqrt();
        let (low, high) = (splat(self.cx) - half, splat(self.cx) + half);
        let (lo, hi) = if self.perspective {
            let (inv_a, inv_b) = (splat(self.inv_a), splat(self.inv_b));
            (
                at_most(low * inv_a, low * inv_b),
                at_least(high * inv_a, high * inv_b),
            )
        } else {
            (low, high)
        };
        let (lo, hi) = (lo * splat(self.scale_x), hi * splat(self.scale_x));
        // `ndc_to_tiles`: `as u32` saturates (NaN and negatives to 0) and the last column
        // caps it; clamping in f64 first (0 first: NaN gives 0) gives the same tile.
        let last = splat(self.last_column as f64);
        let tile = |ndc: F64x4| {
            at_most(
                at_least(splat(0.0), (ndc + splat(1.0)) * splat(self.half_tiles_x)),
                last,
            )
            .to_array()
        };
        let (x0, x1) = (tile(lo), tile(hi));
        // The band holds the centre (or the gap is NaN): the whole cross-section's columns.
        let whole = (gap.is_nan() | gap.simd_le(splat(0.0))).to_bitmask();
        let hits = (half_sq.simd_ge(splat(0.0))
            & lo.simd_le(hi)
            & hi.simd_ge(splat(-1.0))
            & lo.simd_le(splat(1.0)))
        .to_bitmask();
        let (c0, c1) = self.columns;
        std::array::from_fn(|i| {
            if whole & (1 << i) != 0 {
                (c0, c1)
            } else if hits & (1 << i) != 0 {
                ((x0[i] as u32).max(c0), (x1[i] as u32).min(c1))
            } else {
                (1, 0)
            }
        })
    }
}

impl RowChords {
    /// Columns `(x0, x1)` of one row, `x0 > x1` where it gets none: lane 0 of
    /// [`RowChords::columns`] without the other three (a slice's last rows).
    #[inline(always)]
    pub(super) fn one(&self, row: u32) -> (u32, u32) {
        let t0 = -self.extent_y + row as f64 * self.step_y;
        let t1 = t0 + self.step_y;
        let gap = if self.perspective {
            let below = (t0 * self.za).at_most(t0 * self.zb) - self.cy;
            let above = self.cy - (t1 * self.za).at_least(t1 * self.zb);
            below.at_least(above)
        } else {
            (t0 - self.cy).at_least(self.cy - t1)
        };
        if gap.is_nan() || gap <= 0.0 {
            return self.columns;
        }
        let half_sq = self.rho_sq - gap * gap;
        if half_sq < 0.0 {
            return (1, 0);
        }
        let half = half_sq.sqrt();
        let (low, high) = (self.cx - half, self.cx + half);
        let (lo, hi) = if self.perspective {
            (
                (low * self.inv_a).at_most(low * self.inv_b),
                (high * self.inv_a).at_least(high * self.inv_b),
            )
        } else {
            (low, high)
        };
        let (lo, hi) = (lo * self.scale_x, hi * self.scale_x);
        if !((lo <= hi) & (hi >= -1.0) & (lo <= 1.0)) {
            return (1, 0);
        }
        let tile = |ndc: f64| (((ndc + 1.0) * self.half_tiles_x) as u32).min(self.last_column);
        (tile(lo).max(self.columns.0), tile(hi).min(self.columns.1))
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    /// One row at a time, as the refinement did before the lanes (the oracle of both):
    /// `None` for no columns.
    fn one_row(c: &RowChords, row: u32) -> Option<(u32, u32)> {
        let t0 = -c.extent_y + row as f64 * c.step_y;
        let t1 = t0 + c.step_y;
        let gap = if c.perspective {
            let below = (t0 * c.za).min(t0 * c.zb) - c.cy;
            let above = c.cy - (t1 * c.za).max(t1 * c.zb);
            below.max(above)
        } else {
            (t0 - c.cy).max(c.cy - t1)
        };
        if gap.is_nan() || gap <= 0.0 {
            return Some(c.columns);
        }
        let half_sq = c.rho_sq - gap * gap;
        if half_sq < 0.0 {
            return None;
        }
        let half = half_sq.sqrt();
        let (low, high) = (c.cx - half, c.cx + half);
        let (lo, hi) = if c.perspective {
            (
                (low * c.inv_a).min(low * c.inv_b),
                (high * c.inv_a).max(high * c.inv_b),
            )
        } else {
            (low, high)
        };
        let (lo, hi) = (lo * c.scale_x, hi * c.scale_x);
        if !((lo <= hi) & (hi >= -1.0) & (lo <= 1.0)) {
            return None;
        }
        let to_tile = |ndc: f64| (((ndc + 1.0) * c.half_tiles_x) as u32).min(c.last_column);
        let (x0, x1) = (to_tile(lo).max(c.columns.0), to_tile(hi).min(c.columns.1));
        (x0 <= x1).then_some((x0, x1))
    }

    /// A value from `range`, now and then an extreme one (also the spot cone lanes' test's).
    pub(in crate::cluster::assign) fn value(
        rng: &mut Pcg64Mcg,
        range: std::ops::Range<f64>,
    ) -> f64 {
        match rng.random_range(0..40) {
            0 => f64::NAN,
            1 => f64::INFINITY,
            2 => f64::NEG_INFINITY,
            3 => 0.0,
            4 => 1e300,
            _ => rng.random_range(range),
        }
    }

    #[test]
    fn four_lanes_and_one_give_the_columns_of_one_row_at_a_time() {
        let mut rng = Pcg64Mcg::seed_from_u64(31);
        let mut differ = 0;
        for case in 0..20_000 {
            let tiles_x: u32 = rng.random_range(1..300);
            let tiles_y: u32 = rng.random_range(1..200);
            let c0 = rng.random_range(0..tiles_x);
            let c1 = rng.random_range(c0..tiles_x);
            let extent_y = rng.random_range(0.1..3.0);
            // Now and then a slab reaching infinity (the last slice), or wholly there (a
            // light past an infinite far plane): products of zero and infinity are NaN.
            let za = match case % 97 {
                0 => f64::INFINITY,
                _ => rng.random_range(0.01..100.0),
            };
            let inv_a = 1.0 / za;
            let zb = match case % 7 {
                0 => f64::INFINITY,
                _ => za + rng.random_range(0.0..10.0),
            };
            let chords = RowChords {
                perspective: case % 4 != 0,
                za,
                zb,
                inv_a,
                inv_b: (1.0 / zb).min(inv_a),
                cx: value(&mut rng, -50.0..50.0),
                cy: value(&mut rng, -50.0..50.0),
                rho_sq: value(&mut rng, -400.0..400.0).abs(),
                extent_y,
                step_y: 2.0 * extent_y / tiles_y as f64,
                scale_x: rng.random_range(0.1..3.0),
                half_tiles_x: tiles_x as f64 / 2.0,
                last_column: tiles_x - 1,
                columns: (c0, c1),
            };
            let row = rng.random_range(0..tiles_y);
            for (i, &(x0, x1)) in chords.columns(row).iter().enumerate() {
                let expected = one_row(&chords, row + i as u32);
                let lanes = (x0 <= x1).then_some((x0, x1));
                let (x0, x1) = chords.one(row + i as u32);
                let one = (x0 <= x1).then_some((x0, x1));
                differ += usize::from(lanes != expected) + usize::from(one != expected);
            }
        }
        assert_eq!(differ, 0, "rows whose lanes and scalar columns differ");
    }
}
