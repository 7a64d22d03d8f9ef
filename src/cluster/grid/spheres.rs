//! Cell bounding volumes for culling: the frustum side-plane test of a light's sphere and the
//! bounding sphere of a cell (the spot-cone test), from a per-slice table.

use super::tables::SliceFrustum;
use super::ClusterGrid;
use crate::cluster::min_max::MinMax;

impl ClusterGrid {
    /// True when the view-space sphere (`center`, `radius`) lies wholly outside one of the
    /// view frustum's four side planes, so it touches no cell (the assignment's first cull).
    #[inline]
    pub fn sphere_outside_sides(&self, center: glam::DVec3, radius: f64) -> bool {
        self.projection
            .sphere_outside_sides(center, radius, self.side_plane_norm)
    }

    /// The bounding spheres of the cells of row `y` of slice `slice` (numbered across
    /// cascades) of cascade `cascade`, one column at a time: what the spot-cone test's cell
    /// radius is taken from ([`ClusterGrid::slice_cells`]), computed when asked from a per-slice table
    /// (a table of every cell's sphere, rebuilt with the grid whenever a moving camera changed
    /// its depth range, cost more than the whole assignment it served), with the row's and
    /// the slice's share worked out once per row.
    #[inline]
    pub(crate) fn row_spheres(&self, cascade: u32, slice: u32, y: u32) -> RowSpheres {
        let [step_x, step_y] = self.cascade_constants[cascade as usize].ndc_step;
        let f = &self.slice_frusta[slice as usize];
        let (z0, z1) = f.depths;
        let (ny0, ny1) = (-1.0 + y as f64 * step_y, -1.0 + (y + 1) as f64 * step_y);
        // The centre of the eight corners: the mean of the NDC bounds times the mean half
        // extent (x, y), the middle depth (z).
        let cy = 0.25 * (ny0 + ny1) * (f.near.1 + f.far.1);
        let half_depth = 0.5 * (z1 - z0);
        // The farthest corner, per depth end: the farther of the two NDC bounds in x and in y
        // (the squared distance separates into the three axes).
        let y_and_z = |hy: f64| {
            (ny0 * hy - cy).powi(2).at_least((ny1 * hy - cy).powi(2)) + half_depth * half_depth
        };
        RowSpheres {
            #[cfg(test)]
            infinite: z1.is_infinite(),
            #[cfg(test)]
            cy,
            #[cfg(test)]
            cz: -0.5 * (z0 + z1),
            near_x: f.near.0,
            far_x: f.far.0,
            mean_x: 0.5 * (f.near.0 + f.far.0),
            near_rest: y_and_z(f.near.1),
            far_rest: y_and_z(f.far.1),
            step_x,
        }
    }

    /// Every slice's [`SliceFrustum`], in order, into `out` (cleared first).
    pub(super) fn build_slice_frusta(&self, out: &mut Vec<SliceFrustum>) {
        out.clear();
        for (k, c) in self.cascades.iter().enumerate() {
            for slice in 0..c.slices {
                let (z0, z1) = self.slice_depth_range(k as u32, slice);
                out.push(SliceFrustum {
                    depths: (z0, z1),
                    near: self.projection.half_extent(z0),
                    far: self.projection.half_extent(z1),
                });
            }
        }
    }
}

/// The bounding spheres of one row of cells (see [`ClusterGrid::row_spheres`]). The
/// assignment reads only their radii ([`ClusterGrid::slice_cells`]); the centres are for the
/// tests (`RowSpheres::cell`).
pub(crate) struct RowSpheres {
    #[cfg(test)]
    infinite: bool,
    #[cfg(test)]
    cy: f64,
    #[cfg(test)]
    cz: f64,
    /// View half width at the slice's near and far depths, and their mean.
    near_x: f64,
    far_x: f64,
    mean_x: f64,
    /// Per depth end: the farthest corner's squared distance in y plus that in z.
    near_rest: f64,
    far_rest: f64,
    /// NDC width of a column.
    step_x: f64,
}

impl RowSpheres {
    /// The bounding sphere `[x, y, z, radius]` (view space) of the row's cell in column `x`:
    /// the centre of its eight corners and the farthest corner; an infinite radius for a cell
    /// reaching infinity.
    #[cfg(test)]
    pub(crate) fn cell(&self, x: u32) -> [f64; 4] {
        if self.infinite {
            return [0.0, 0.0, 0.0, f64::INFINITY];
        }
        let (cx, radius_sq) = self.centre_x_and_radius_sq(x);
        [cx, self.cy, self.cz, radius_sq.sqrt()]
    }

    /// The view x of the centre of the row's cell in column `x`, and its squared radius.
    #[cfg(test)]
    fn centre_x_and_radius_sq(&self, x: u32) -> (f64, f64) {
        let (cx, x_terms) = self.column_terms(x);
        (cx, self.radius_sq(x_terms))
    }

    /// The view x of the centre of the cells in column `x` and, per depth end, the farthest
    /// corner's squared distance in x: the same in every row of the slice.
    #[inline(always)]
    fn column_terms(&self, x: u32) -> (f64, [f64; 2]) {
        let nx0 = -1.0 + x as f64 * self.step_x;
        let nx1 = -1.0 + (x + 1) as f64 * self.step_x;
        let cx = 0.5 * (nx0 + nx1) * self.mean_x;
        let farthest_x = |hx: f64| (nx0 * hx - cx).powi(2).at_least((nx1 * hx - cx).powi(2));
        (cx, [farthest_x(self.near_x), farthest_x(self.far_x)])
    }

    /// The squared radius of this row's cell in the column with `column_terms` `[near, far]`.
    #[inline(always)]
    fn radius_sq(&self, [near, far]: [f64; 2]) -> f64 {
        (near + self.near_rest).at_least(far + self.far_rest)
    }
}

/// The cells of one slice as the spot-cone test sees them (see [`ClusterGrid::slice_cells`]):
/// the centre of the cell in column `x`, row `y` is `origin + (x·step[0], y·step[1], 0)`, and
/// every cell of the columns and rows asked for lies within `radius` of its centre (infinite
/// for cells reaching infinity).
pub(crate) struct SliceCells {
    pub origin: glam::DVec3,
    pub step: [f64; 2],
    pub radius: f64,
}

impl ClusterGrid {
    /// The cells of slice `slice` (numbered across cascades) of cascade `cascade`, with a
    /// radius that bounds every cell of `columns` × `rows` (inclusive ranges).
    #[inline]
    pub(crate) fn slice_cells(
        &self,
        cascade: u32,
        slice: u32,
        columns: (u32, u32),
        rows: (u32, u32),
    ) -> SliceCells {
        let [step_x, step_y] = self.cascade_constants[cascade as usize].ndc_step;
        let f = &self.slice_frusta[slice as usize];
        let (z0, z1) = f.depths;
        let mean = [0.5 * (f.near.0 + f.far.0), 0.5 * (f.near.1 + f.far.1)];
        let radius = if z1.is_infinite() {
            f64::INFINITY
        } else {
            // A cell's squared radius is a sum of per-axis terms, each a maximum of squares of
            // functions affine in the column or row (see `RowSpheres::cell`): convex over the
            // rectangle, so largest at one of its corners.
            // The columns' terms are the rows' too: worked out once (the sizes are finite
            // here, so no bound is NaN).
            let first_row = self.row_spheres(cascade, slice, rows.0);
            let last_row = self.row_spheres(cascade, slice, rows.1);
            let (_, left) = first_row.column_terms(columns.0);
            let (_, right) = first_row.column_terms(columns.1);
            let mut largest: f64 = 0.0;
            for spheres in [&first_row, &last_row] {
                for x_terms in [left, right] {
                    largest = largest.at_least(spheres.radius_sq(x_terms));
                }
            }
            largest.sqrt()
        };
        SliceCells {
            origin: glam::DVec3::new(
                (-1.0 + 0.5 * step_x) * mean[0],
                (-1.0 + 0.5 * step_y) * mean[1],
                -0.5 * (z0 + z1),
            ),
            step: [step_x * mean[0], step_y * mean[1]],
            radius,
        }
    }
}
