//! A spot's cone against four rows of one slice at once ([`ConeSlice::columns_of_rows`]):
//! [`ConeSlice::columns`]'s closed form, lane by lane, without branches between the lanes, so
//! that the rows' roots and divisions share SIMD instructions (as the chords do, `rows.rs`).
//! Every lane does the scalar's operations in the scalar's order, so the columns, and the
//! lists, are the same bit for bit; what the lanes do not cover (narrow rows, a slice whose
//! quadratic has no `t²` term) goes to the scalar code.

use super::{whole_cells, ConeSlice, NARROW_ROW};
use crate::cluster::assign::rows::ROW_LANES;
use crate::cluster::assign::simd::{at_least, at_most, counting_from, splat, F64x4 as F};

// A narrow row's cells fit the lanes.
const _: () = assert!(NARROW_ROW as usize <= ROW_LANES);

/// Every lane's bit.
const ALL: u32 = (1 << ROW_LANES) - 1;

impl ConeSlice<'_> {
    /// [`ConeSlice::columns`] of rows `row .. row + ROW_LANES`, row `row + i` within the
    /// columns `spans[i]`: each lane's columns, `x0 > x1` where the row gets none (also where
    /// its span was already empty).
    #[inline(always)]
    pub fn columns_of_rows(
        &self,
        row: u32,
        spans: [(u32, u32); ROW_LANES],
    ) -> [(u32, u32); ROW_LANES] {
        if self.whole {
            return spans;
        }
        let scalar = |i: usize| {
            let (x0, x1) = spans[i];
            if x0 > x1 {
                return (1, 0);
            }
            self.columns(row + i as u32, x0, x1).unwrap_or((1, 0))
        };
        if self.a == 0.0 {
            // The quadratic degenerates to a line, a branch per lane: rare (an axis at exactly
            // the cone's angle to the rows), left to the scalar code.
            return std::array::from_fn(scalar);
        }
        let wide = self.wide_rows(row, spans);
        std::array::from_fn(|i| {
            let (x0, x1) = spans[i];
            if x0 > x1 {
                (1, 0)
            } else if x1 - x0 < NARROW_ROW {
                scalar(i)
            } else {
                wide[i]
            }
        })
    }

    /// [`ConeSlice::columns`] of a row of at most [`NARROW_ROW`] cells, `x0..=x1`, the first
    /// of them centred at `v0 + x0 · (sx, 0, 0)` from the apex: `ConeSlice::cell_may_touch`
    /// cell by cell, the cells in lanes (without a branch per cell: which cells pass is what a
    /// predictor cannot learn).
    #[inline(always)]
    pub(super) fn narrow_columns(&self, v0: glam::DVec3, x0: u32, x1: u32) -> Option<(u32, u32)> {
        let cone = self.cone;
        let axis = cone.axis;
        let columns = counting_from(x0);
        let (vx, vy, vz) = (
            splat(v0.x) + columns * splat(self.sx),
            splat(v0.y),
            splat(v0.z),
        );
        let v1 = vx * splat(axis.x) + vy * splat(axis.y) + vz * splat(axis.z);
        let bound = splat(self.r) + v1 * splat(cone.sin);
        let cos_sq = splat(cone.cos_sq);
        let off_axis = cos_sq * (vx * vx + vy * vy + vz * vz - v1 * v1);
        let reach = bound * bound;
        let outside = v1.simd_gt(splat(self.r + cone.range + self.slack))
            | v1.simd_lt(splat(-self.r - self.slack))
            | bound.simd_lt(splat(-self.slack))
            | (off_axis - reach).simd_gt(splat(1e-9) * (off_axis.abs() + reach + cos_sq * v1 * v1));
        let touches = !outside.to_bitmask() & ((1 << (x1 - x0 + 1)) - 1);
        (touches != 0).then(|| {
            (
                x0 + touches.trailing_zeros(),
                x0 + 31 - touches.leading_zeros(),
            )
        })
    }

    /// The quadratic's columns of the four rows (`ConeSlice::columns` past its narrow rows,
    /// for a slice with `a ≠ 0`), every lane computed; `x0 > x1` for none.
    #[inline(always)]
    fn wide_rows(&self, row: u32, spans: [(u32, u32); ROW_LANES]) -> [(u32, u32); ROW_LANES] {
        let cone = self.cone;
        let axis = cone.axis;
        let (ox, oz) = (splat(self.origin.x), splat(self.origin.z));
        let rows = counting_from(row);
        let vy = splat(self.origin.y) + rows * splat(self.row_step);
        // `v₀ · axis`, `v₀ − axis · p` and `r + sin · p`, as `DVec3` computes them.
        let p = ox * splat(axis.x) + vy * splat(axis.y) + oz * splat(axis.z);
        let w = [
            ox - splat(axis.x) * p,
            vy - splat(axis.y) * p,
            oz - splat(axis.z) * p,
        ];
        let h0 = splat(self.r) + splat(cone.sin) * p;
        let mut ok = ALL;
        let mut lo = F::from(spans.map(|(x0, _)| x0 as f64));
        let mut hi = F::from(spans.map(|(_, x1)| x1 as f64));
        // −r ≤ v₁ = p + q·t ≤ r + range.
        let below = p + splat(self.r) + splat(self.slack);
        keep_nonnegative(&mut lo, &mut hi, &mut ok, below, self.q, self.inv_q);
        let above = splat(self.r) + splat(cone.range) + splat(self.slack) - p;
        keep_nonnegative(&mut lo, &mut hi, &mut ok, above, -self.q, -self.inv_q);
        let b = splat(2.0)
            * splat(self.sx)
            * (splat(cone.cos_sq) * w[0] - splat(cone.sin) * splat(axis.x) * h0);
        let off_axis = splat(cone.cos_sq) * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        let reach = h0 * h0;
        quadratic_nonpositive(
            self.a,
            b,
            off_axis - reach,
            off_axis + reach,
            &mut lo,
            &mut hi,
            &mut ok,
        );
        // Widened, then the whole cells inside (`ConeSlice::columns`).
        let lo = (lo - splat(1e-6) * (splat(1.0) + lo.abs())).to_array();
        let hi = (hi + splat(1e-6) * (splat(1.0) + hi.abs())).to_array();
        std::array::from_fn(|i| {
            let (x0, x1) = spans[i];
            let cells = (ok & (1 << i) != 0).then(|| whole_cells(lo[i], hi[i], x0, x1));
            cells.flatten().unwrap_or((1, 0))
        })
    }
}

/// `super::keep_nonnegative` in lanes (`b` and `inv_b` the same in every lane): cuts each
/// lane's `[lo, hi]` to where `a + b·t ≥ 0`, and clears its bit of `ok` where nothing is
/// left.
#[inline(always)]
fn keep_nonnegative(lo: &mut F, hi: &mut F, ok: &mut u32, a: F, b: f64, inv_b: f64) {
    if b > 0.0 {
        *lo = at_least(*lo, -a * splat(inv_b));
    } else if b < 0.0 {
        *hi = at_most(*hi, -a * splat(inv_b));
    } else {
        *ok &= (a.simd_ge(splat(0.0)) | a.is_nan()).to_bitmask();
    }
    *ok &= lo.simd_le(*hi).to_bitmask();
}

/// `super::quadratic_nonpositive` in lanes for `a ≠ 0` (the same in every lane): each lane's
/// `[lo, hi]` cut to the hull of where `a·t² + b·t + c ≤ 0`, and its bit of `ok` cleared where
/// that is empty.
#[inline(always)]
fn quadratic_nonpositive(a: f64, b: F, c: F, c_terms: F, lo: &mut F, hi: &mut F, ok: &mut u32) {
    let t = at_least(at_least(lo.abs(), hi.abs()), splat(1.0));
    let c = c - splat(1e-9) * (c_terms.abs() + b.abs() * t + splat(a.abs()) * t * t);
    let disc = b * b - splat(4.0 * a) * c;
    let root = disc.sqrt();
    // `root.copysign(b)`: the root is +0, positive or NaN (a NaN lane is not used below).
    let k = splat(-0.5) * (b + b.is_sign_negative().select(-root, root));
    let (x, y) = (k / splat(a), c / k);
    let zero = k.simd_eq(splat(0.0));
    let r1 = zero.select(splat(0.0), at_most(x, y));
    let r2 = zero.select(splat(0.0), at_least(x, y));
    // Where the roots bound the span: between them (`a > 0`), or the hull of what is left on
    // either side of them.
    let (cut_lo, cut_hi, cut_ok) = if a > 0.0 {
        let (cut_lo, cut_hi) = (at_least(*lo, r1), at_most(*hi, r2));
        (cut_lo, cut_hi, cut_lo.simd_le(cut_hi))
    } else {
        let (left, right) = (lo.simd_le(r1), hi.simd_ge(r2));
        (
            left.select(*lo, at_least(*lo, r2)),
            right.select(*hi, at_most(*hi, r1)),
            left | right,
        )
    };
    // An overflowed discriminant keeps the span; with no real root the sign is `a`'s
    // everywhere; otherwise the roots cut it.
    let finite = disc.is_finite();
    let no_root = finite & disc.simd_lt(splat(0.0));
    let cut = finite & !no_root;
    *lo = cut.select(cut_lo, *lo);
    *hi = cut.select(cut_hi, *hi);
    *ok &= !cut.to_bitmask() | cut_ok.to_bitmask();
    // `a` is finite here (else the slice is whole) and not 0: not negative is positive.
    if a > 0.0 {
        *ok &= !no_root.to_bitmask();
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::spots;
    use super::super::{Cone, ConeSlice};
    use super::{NARROW_ROW, ROW_LANES};
    use crate::cluster::assign::rows::tests::value;
    use crate::cluster::grid::{ClusterGrid, GridConfig, GridProjection, SliceCells};
    use glam::DVec3;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    /// A spot's cone as `Cone::of` makes it, from random parts (the bound is not used here).
    fn cone(rng: &mut Pcg64Mcg) -> Cone {
        let axis = DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        )
        .normalize_or(DVec3::Z);
        // Now and then an axis along the rows, or across them (`q = 0`).
        let axis = match rng.random_range(0..20) {
            0 => DVec3::X,
            1 => DVec3::Y,
            _ => axis,
        };
        let cos: f64 = rng.random_range(0.0175..1.0);
        let apex = DVec3::new(
            value(rng, -50.0..50.0),
            rng.random_range(-50.0..50.0),
            rng.random_range(-80.0..0.0),
        );
        let range = value(rng, 0.01..40.0).abs();
        Cone {
            apex,
            axis,
            cos_sq: cos * cos,
            sin: (1.0 - cos * cos).sqrt(),
            range,
            slack_terms: apex.abs().element_sum() + range,
            bound: (apex, range),
        }
    }

    /// A narrow row's columns tested one by one (`ConeSlice::cell_may_touch`), as before the
    /// lanes.
    fn narrow_cell_by_cell(slice: &ConeSlice, row: u32, x0: u32, x1: u32) -> Option<(u32, u32)> {
        if slice.whole {
            return Some((x0, x1));
        }
        let y = slice.origin.y + row as f64 * slice.row_step;
        let touched = (x0..=x1).filter(|&x| {
            let v = DVec3::new(slice.origin.x + x as f64 * slice.sx, y, slice.origin.z);
            slice.cell_may_touch(v)
        });
        let touched: Vec<u32> = touched.collect();
        Some((*touched.first()?, *touched.last()?))
    }

    /// Rows `row..row + ROW_LANES` of `slice` within `spans`: how many lanes differ from
    /// the scalar closed form, and how many the quadratic cut (some columns kept, not all).
    fn compare(slice: &ConeSlice, row: u32, spans: [(u32, u32); ROW_LANES]) -> (usize, usize) {
        let lanes = slice.columns_of_rows(row, spans);
        let (mut differ, mut cut) = (0, 0);
        for i in 0..ROW_LANES {
            let (x0, x1) = spans[i];
            let one = if x0 > x1 {
                None
            } else if x1 - x0 < NARROW_ROW {
                narrow_cell_by_cell(slice, row + i as u32, x0, x1)
            } else {
                slice.columns(row + i as u32, x0, x1)
            };
            let (a, b) = lanes[i];
            differ += usize::from((a <= b).then_some((a, b)) != one);
            cut += usize::from(
                x0 <= x1 && x1 - x0 >= NARROW_ROW && one.is_some_and(|s| s != (x0, x1)),
            );
        }
        (differ, cut)
    }

    /// Four rows give, lane by lane, the columns the scalar closed form gives each row: the
    /// spots and slices of real grids (every row of every slice, whole and in random spans
    /// of every width), and cones and cells made of random parts, extreme values included.
    #[test]
    fn four_rows_give_the_columns_of_one_row_at_a_time() {
        let mut rng = Pcg64Mcg::seed_from_u64(37);
        let (mut differ, mut cut) = (0, 0);
        let span = |rng: &mut Pcg64Mcg, tiles: u32| {
            let x0 = rng.random_range(0..tiles);
            match rng.random_range(0..6) {
                0 => (x0 + 1, x0),
                1 => (x0, (x0 + rng.random_range(0..3)).min(tiles - 1)),
                2 => (0, tiles - 1),
                _ => (x0, rng.random_range(x0..tiles)),
            }
        };
        for (footprint, far) in [(24.0, 60.0), (11.0, 30.0), (64.0, f64::INFINITY)] {
            let grid = ClusterGrid::new(
                320,
                180,
                GridProjection::test_view(),
                0.1,
                far,
                &GridConfig::fixed(footprint),
            );
            for light in spots(&mut rng, &grid, 300) {
                let Some(cone) = Cone::of(&light, light.cull_radius as f64) else {
                    continue;
                };
                let mut first_slice = 0;
                for (k, c) in grid.cascades.iter().enumerate() {
                    for g in first_slice..first_slice + c.slices {
                        let cells =
                            grid.slice_cells(k as u32, g, (0, c.tiles_x - 1), (0, c.tiles_y - 1));
                        let slice = cone.slice(&cells);
                        for row in 0..c.tiles_y {
                            let spans = std::array::from_fn(|_| span(&mut rng, c.tiles_x));
                            let (d, n) = compare(&slice, row, spans);
                            (differ, cut) = (differ + d, cut + n);
                        }
                    }
                    first_slice += c.slices;
                }
            }
        }
        for _ in 0..40_000 {
            let cone = cone(&mut rng);
            let cells = SliceCells {
                origin: DVec3::new(
                    value(&mut rng, -60.0..0.0),
                    rng.random_range(-40.0..0.0),
                    -rng.random_range(0.05..90.0),
                ),
                step: [rng.random_range(0.01..4.0), rng.random_range(0.01..4.0)],
                radius: value(&mut rng, 0.005..3.0).abs(),
            };
            let spans = std::array::from_fn(|_| span(&mut rng, 120));
            differ += compare(&cone.slice(&cells), rng.random_range(0..200), spans).0;
        }
        assert_eq!(differ, 0, "rows whose lanes and scalar columns differ");
        assert!(cut > 10_000, "only {cut} rows cut by the quadratic");
    }
}
