//! A spot light's cone as the assignment tests it against cells (see [`super::cells`]): the
//! bounding sphere of the part of the light's sphere inside the cone, and the cone-vs-cell
//! test that trims each row of cells to those the cone may touch, solved for the whole row at
//! once (one quadratic) rather than cell by cell.

mod lanes;

use crate::cluster::grid::SliceCells;
use crate::cluster::min_max::MinMax;
use crate::cluster::view_light::GpuLight;

/// A spot light's cone, for the cone-vs-cell test (Wronski's "cull that cone"), and the
/// bounding sphere of the part of the light's sphere inside the cone.
pub(crate) struct Cone {
    apex: glam::DVec3,
    axis: glam::DVec3,
    /// cos² and sin of the (padded) outer half-angle.
    cos_sq: f64,
    sin: f64,
    /// The light's (padded) radius.
    range: f64,
    /// The apex's size (the sum of its coordinates' magnitudes, no root) plus `range`: the
    /// cone's share of every slice's slack.
    slack_terms: f64,
    /// Bounding sphere (centre, radius) of the spherical sector the light reaches.
    pub bound: (glam::DVec3, f64),
}

impl Cone {
    /// The cone of a spot light of (padded) radius `range`; `None` for point lights, cones
    /// too wide to be worth testing, and axes without a direction (zero, or a non-finite
    /// component): those are bounded by the light's whole sphere.
    #[inline(always)]
    pub fn of(light: &GpuLight, range: f64) -> Option<Cone> {
        // 1 − cos(outer) = offset / scale (see `spot_terms_from_half_sines`; the edge where the
        // light ends, past the outer angle for a cone sharper than its smallest width): no
        // trigonometry per light. Cones of 89° and wider are not worth testing.
        if light.spot_scale == 0.0 {
            return None;
        }
        // Normalised only once the light is known to be a spot: point lights skip the root
        // and the division.
        let axis = light.direction.as_dvec3().normalize_or_zero();
        if axis == glam::DVec3::ZERO {
            return None;
        }
        let cos_outer = 1.0 - light.spot_offset as f64 / light.spot_scale as f64;
        // Pad the angle a little: the shader evaluates the cone edge in f32.
        let cos = cos_outer - 2e-4;
        if cos.is_nan() || cos < 0.0175 {
            return None;
        }
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let apex = light.position.as_dvec3();
        // The sector {apex + t·u : u·axis ≥ cos, 0 ≤ t ≤ range}. Up to 45°, the sphere through
        // the apex and the rim circle (centre range / (2 cos) along the axis) holds it; wider,
        // the sphere on the rim circle (centre range·cos along the axis, radius range·sin)
        // does, the apex and the cap's tip lying inside it.
        let (along, radius) = if cos >= std::f64::consts::FRAC_1_SQRT_2 {
            let h = range / (2.0 * cos);
            (h, h)
        } else {
            (range * cos, range * sin)
        };
        Some(Cone {
            apex,
            axis,
            cos_sq: cos * cos,
            sin,
            range,
            slack_terms: apex.abs().element_sum() + range,
            bound: (apex + axis * along, radius),
        })
    }

    /// The cone against the cells of one slice (see [`ConeSlice::columns`]).
    #[inline]
    pub fn slice(&self, cells: &SliceCells) -> ConeSlice<'_> {
        let r = cells.radius;
        let [sx, sy] = cells.step;
        let ax = self.axis.x;
        // Along a row `t` counts columns: v(t) = v₀ + t·(sx, 0, 0) from the apex.
        let q = sx * ax;
        ConeSlice {
            whole: !(r.is_finite() && cells.origin.is_finite() && sx.is_finite() && sy.is_finite()),
            origin: cells.origin - self.apex,
            row_step: sy,
            r,
            sx,
            q,
            inv_q: 1.0 / q,
            a: sx * sx * (self.cos_sq - ax * ax),
            // Sizes by sums of coordinate magnitudes (≥ lengths, at most √3 times: no roots).
            slack: 1e-12 * (cells.origin.abs().element_sum() + self.slack_terms + r),
            cone: self,
        }
    }

    /// False only when the cell's bounding sphere is certainly outside the cone (up to the
    /// light's range): the test [`ConeSlice::columns`] solves for a whole row at once, kept
    /// as its yardstick in the tests.
    #[cfg(test)]
    pub(crate) fn may_touch(&self, &[x, y, z, radius]: &[f64; 4]) -> bool {
        let v = glam::DVec3::new(x, y, z) - self.apex;
        let v1 = v.dot(self.axis);
        if v1 > radius + self.range || v1 < -radius {
            return false;
        }
        // Distance of the sphere's centre outside the cone: cos·√(|v|² − v1²) − v1·sin; the
        // cell is outside when that exceeds its radius. Squared (both sides are then ≥ 0) so
        // the hot loop has no square root.
        let bound = radius + v1 * self.sin;
        bound >= 0.0 && self.cos_sq * (v.length_squared() - v1 * v1) <= bound * bound
    }
}

/// A cone against the cells of one slice: what [`ConeSlice::columns`] needs for every row,
/// worked out once per slice.
pub(crate) struct ConeSlice<'a> {
    cone: &'a Cone,
    /// Not finite (a slice reaching infinity): every cell is kept.
    whole: bool,
    /// Centre of the cell in column 0, row 0, from the apex; view y between rows.
    origin: glam::DVec3,
    row_step: f64,
    /// Radius bounding every cell, view x between columns, its part along the axis (and
    /// reciprocal), and the quadratic's leading coefficient (the same in every row).
    r: f64,
    sx: f64,
    q: f64,
    inv_q: f64,
    a: f64,
    /// Absolute slack of the linear conditions (rounding of the axial distance).
    slack: f64,
}

impl ConeSlice<'_> {
    /// The first and last of the columns `x0..=x1` of row `row` whose cells the cone may
    /// touch, or `None`: a superset of the cells whose bounding sphere of radius `r` (every
    /// cell's, see [`SliceCells`]) passes the cell-by-cell cone test (`Cone::may_touch`, kept
    /// for the tests), in closed form instead of cell by cell.
    ///
    /// Along the row the centre is `v(t) = v₀ + t·(sx, 0, 0)` from the apex (`t` the column),
    /// and with `v₁ = v·axis` and `w = v − v₁·axis` (the part off the axis) a cell passes where
    /// `−r ≤ v₁ ≤ r + range` (two linear conditions in `t`) and `cos·|w| ≤ r + sin·v₁`: the
    /// distance outside the cone is convex in `t`, so the cells passing are one interval, and
    /// squared the condition is the quadratic `a·t² + b·t + c ≤ 0` whose roots bound it. It is
    /// widened by a millionth of a cell so that rounding never removes a cell.
    #[inline(always)]
    pub fn columns(&self, row: u32, x0: u32, x1: u32) -> Option<(u32, u32)> {
        if self.whole {
            return Some((x0, x1));
        }
        let cone = self.cone;
        let mut v0 = self.origin;
        v0.y += row as f64 * self.row_step;
        if x1 - x0 < NARROW_ROW {
            // A few cells: each tested on its own is cheaper than the row's quadratic, all in
            // one set of lanes.
            return self.narrow_columns(v0, x0, x1);
        }
        let p = v0.dot(cone.axis);
        let w0 = v0 - cone.axis * p;
        let h0 = self.r + cone.sin * p;
        // −r ≤ v₁ = p + q·t ≤ r + range.
        let span = (x0 as f64, x1 as f64);
        let span = keep_nonnegative(span, p + self.r + self.slack, self.q, self.inv_q)?;
        let above = self.r + cone.range + self.slack - p;
        let span = keep_nonnegative(span, above, -self.q, -self.inv_q)?;
        let b = 2.0 * self.sx * (cone.cos_sq * w0.x - cone.sin * cone.axis.x * h0);
        let (off_axis, reach) = (cone.cos_sq * w0.length_squared(), h0 * h0);
        let (lo, hi) = quadratic_nonpositive(self.a, b, off_axis - reach, off_axis + reach, span)?;
        // Widened, then the whole cells inside (by conversions: `ceil` and `floor` are library
        // calls on a baseline x86-64 target).
        let margin = |t: f64| 1e-6 * (1.0 + t.abs());
        whole_cells(lo - margin(lo), hi + margin(hi), x0, x1)
    }

    /// False only when the sphere of radius `r` (every cell's bound) at `v` from the apex is
    /// certainly outside the cone: the conditions [`ConeSlice::columns`] solves for a row,
    /// loosened as it loosens them (the linear ones by the slack, the quadratic one by a
    /// billionth of its terms). NaN keeps the cell. What a narrow row's lanes
    /// (`ConeSlice::narrow_columns`) do cell by cell, kept as their yardstick in the tests.
    #[cfg(test)]
    fn cell_may_touch(&self, v: glam::DVec3) -> bool {
        let cone = self.cone;
        let v1 = v.dot(cone.axis);
        let bound = self.r + v1 * cone.sin;
        let (off_axis, reach) = (cone.cos_sq * (v.length_squared() - v1 * v1), bound * bound);
        // `|`, not `||`: the four tests cost less than the branches between them.
        let outside = (v1 > self.r + cone.range + self.slack)
            | (v1 < -self.r - self.slack)
            | (bound < -self.slack)
            | (off_axis - reach > 1e-9 * (off_axis.abs() + reach + cone.cos_sq * v1 * v1));
        !outside
    }
}

/// The columns of `x0..=x1` wholly or partly inside the (widened) interval `[lo, hi]` of
/// column coordinates, or `None`; a NaN end keeps them all.
#[inline(always)]
fn whole_cells(lo: f64, hi: f64, x0: u32, x1: u32) -> Option<(u32, u32)> {
    if !(hi >= x0 as f64 && lo <= x1 as f64) {
        // Also for NaN, which keeps the whole span.
        return (lo.is_nan() || hi.is_nan()).then_some((x0, x1));
    }
    // `as u32` truncates, and saturates below 0; `hi ≥ x0 ≥ 0` here.
    let truncated = lo as u32;
    let first = (truncated + u32::from((truncated as f64) < lo)).max(x0);
    let last = (hi as u32).min(x1);
    (first <= last).then_some((first, last))
}

/// Rows of fewer than this many columns plus one test their cells one by one
/// (`ConeSlice::narrow_columns`) instead of solving the row's quadratic.
const NARROW_ROW: u32 = 3;

/// The part of `span` (`lo ≤ hi`) where `a + b·t ≥ 0`, or `None` when there is none;
/// `inv_b` is `1 / b` (a row's reciprocal is worked out once per slice). A span's ends are
/// never NaN (column numbers, or a span cut by these two functions), so they go first in its
/// bounds ([`MinMax`]): a NaN bound leaves them.
#[inline(always)]
fn keep_nonnegative((lo, hi): (f64, f64), a: f64, b: f64, inv_b: f64) -> Option<(f64, f64)> {
    let (lo, hi) = if b > 0.0 {
        (lo.at_least(-a * inv_b), hi)
    } else if b < 0.0 {
        (lo, hi.at_most(-a * inv_b))
    } else if a >= 0.0 || a.is_nan() {
        // Also for NaN (an overflowed coefficient): keep the span.
        (lo, hi)
    } else {
        return None;
    };
    (lo <= hi).then_some((lo, hi))
}

/// The smallest interval holding every `t` of `span` where `a·t² + b·t + c ≤ 0` (with a
/// tolerance: the inequality is loosened by a billionth of its terms' size over the span —
/// `c_terms` is the size of what `c` was computed from, before any cancellation — so a
/// rounding error in the coefficients cannot make a touching row look empty), or `None`.
#[inline(always)]
fn quadratic_nonpositive(
    a: f64,
    b: f64,
    c: f64,
    c_terms: f64,
    (lo, hi): (f64, f64),
) -> Option<(f64, f64)> {
    let t = lo.abs().at_least(hi.abs()).at_least(1.0);
    let c = c - 1e-9 * (c_terms.abs() + b.abs() * t + a.abs() * t * t);
    if a == 0.0 {
        // b·t + c ≤ 0.
        return keep_nonnegative((lo, hi), -c, -b, -1.0 / b);
    }
    let disc = b * b - 4.0 * a * c;
    if !disc.is_finite() {
        // Overflowed: keep everything.
        return Some((lo, hi));
    }
    if disc < 0.0 {
        // No real root: one sign everywhere, that of `a`.
        return (a < 0.0).then_some((lo, hi));
    }
    // The two roots without cancellation (Numerical Recipes §5.6).
    let k = -0.5 * (b + disc.sqrt().copysign(b));
    let (r1, r2) = if k == 0.0 {
        (0.0, 0.0)
    } else {
        // Never NaN: `a`, `c` and `k` are finite (else the discriminant is not), `a` and `k`
        // not zero.
        let (x, y) = (k / a, c / k);
        (x.at_most(y), x.at_least(y))
    };
    if a > 0.0 {
        let (lo, hi) = (lo.at_least(r1), hi.at_most(r2));
        return (lo <= hi).then_some((lo, hi));
    }
    // Non-positive outside the roots: the hull of what is left of the span on either side.
    let left = (lo <= r1).then_some((lo, hi.at_most(r1)));
    let right = (hi >= r2).then_some((lo.at_least(r2), hi));
    match (left, right) {
        (Some((l, _)), Some((_, h))) => Some((l, h)),
        (one, other) => one.or(other),
    }
}

#[cfg(test)]
mod tests {
    use glam::{DVec3, Vec3};
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    use super::Cone;
    use crate::cluster::grid::{ClusterGrid, GridConfig, GridProjection};
    use crate::cluster::view_light::GpuLight;
    use crate::scene::Light;

    /// Random spots in and around the view of `grid`: every size of cone, from a few cells
    /// to most of the view, pointing every way (some at or away from the eye).
    pub(super) fn spots(rng: &mut Pcg64Mcg, grid: &ClusterGrid, n: usize) -> Vec<GpuLight> {
        (0..n)
            .map(|_| {
                let d = rng
                    .random_range(grid.near.max(0.05).ln()..grid.far.ln())
                    .exp();
                let (hx, hy) = grid.projection.half_extent(d);
                let p = DVec3::new(
                    rng.random_range(-1.3..1.3) * hx,
                    rng.random_range(-1.3..1.3) * hy,
                    -d,
                );
                let dir = DVec3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                let dir = if dir.length() < 1e-3 { DVec3::Z } else { dir };
                let outer = rng.random_range(1.0..120.0);
                let r = hy * rng.random_range(0.05..1.5);
                let light = Light::spot(
                    p,
                    r as f32,
                    Vec3::ONE,
                    1.0,
                    crate::scene::Cone {
                        direction: dir,
                        inner_deg: outer * 0.5,
                        outer_deg: outer,
                    },
                );
                GpuLight::from_light(&light, &glam::DMat4::IDENTITY)
            })
            .collect()
    }

    /// Every cell of every row that the cell-by-cell test passes (with the cell's own sphere)
    /// lies inside the closed-form span, and the span is not much wider than those cells.
    #[test]
    fn row_spans_hold_every_cell_the_cell_test_passes() {
        let projection = GridProjection::test_view();
        let mut rng = Pcg64Mcg::seed_from_u64(17);
        let (mut passed, mut spanned, mut rows, mut narrow_rows) = (0u64, 0u64, 0u64, 0u64);
        for (footprint, far) in [(24.0, 60.0), (11.0, 30.0), (64.0, f64::INFINITY)] {
            let grid = ClusterGrid::new(
                320,
                180,
                projection,
                0.1,
                far,
                &GridConfig::fixed(footprint),
            );
            for light in spots(&mut rng, &grid, 120) {
                let range = light.cull_radius as f64;
                let Some(cone) = Cone::of(&light, range) else {
                    continue;
                };
                let mut first_slice = 0;
                for (k, c) in grid.cascades.iter().enumerate() {
                    let (columns, all_rows) = ((0, c.tiles_x - 1), (0, c.tiles_y - 1));
                    for slice in first_slice..first_slice + c.slices {
                        let cells = grid.slice_cells(k as u32, slice, columns, all_rows);
                        let cone_slice = cone.slice(&cells);
                        for y in 0..c.tiles_y {
                            let spheres = grid.row_spheres(k as u32, slice, y);
                            let touched: Vec<u32> = (0..c.tiles_x)
                                .filter(|&x| cone.may_touch(&spheres.cell(x)))
                                .collect();
                            let span = cone_slice.columns(y, 0, c.tiles_x - 1);
                            if let (Some(&a), Some(&b)) = (touched.first(), touched.last()) {
                                let (lo, hi) = span.unwrap_or_else(|| {
                                    panic!("{light:?}: row {y} of slice {slice} lost {touched:?}")
                                });
                                assert!(lo <= a && b <= hi, "{light:?}: {touched:?} ⊄ {lo}..={hi}");
                                passed += (b - a + 1) as u64;
                                rows += 1;
                            }
                            // Windows of one to three columns (tested cell by cell): every
                            // touched cell inside one is kept, and nothing outside it.
                            for x0 in 0..c.tiles_x {
                                for x1 in x0..(x0 + 3).min(c.tiles_x) {
                                    let inside: Vec<u32> = touched
                                        .iter()
                                        .copied()
                                        .filter(|x| (x0..=x1).contains(x))
                                        .collect();
                                    let narrow = cone_slice.columns(y, x0, x1);
                                    if let Some((lo, hi)) = narrow {
                                        assert!(x0 <= lo && lo <= hi && hi <= x1);
                                    }
                                    if let (Some(&a), Some(&b)) = (inside.first(), inside.last()) {
                                        let (lo, hi) = narrow.unwrap_or_else(|| {
                                            panic!(
                                                "{light:?}: row {y} lost {inside:?} in {x0}..={x1}"
                                            )
                                        });
                                        assert!(lo <= a && b <= hi, "{light:?}: {inside:?}");
                                        narrow_rows += 1;
                                    }
                                }
                            }
                            spanned += span.map_or(0, |(lo, hi)| (hi - lo + 1) as u64);
                        }
                    }
                    first_slice += c.slices;
                }
            }
        }
        assert!(rows > 2_000, "only {rows} rows touched");
        assert!(
            narrow_rows > 5_000,
            "only {narrow_rows} narrow windows touched"
        );
        // The span takes one radius for the whole slice (its largest cell's): a little wider.
        assert!(
            (spanned as f64) < passed as f64 * 1.15,
            "{spanned} cells spanned against {passed}"
        );
    }
}
