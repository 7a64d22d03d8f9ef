//! Cell bounding volumes for culling: the frustum side-plane test of a light's sphere and the
//! bounding sphere of a cell (the spot-cone test), from a per-slice table.

use super::{ClusterGrid, GridProjection};

/// One slice's exact depths and the view half extents at them (see
/// [`ClusterGrid::cell_sphere`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SliceFrustum {
    depths: (f64, f64),
    near: (f64, f64),
    far: (f64, f64),
}

impl ClusterGrid {
    /// True when the view-space sphere (`center`, `radius`) lies wholly outside one of the
    /// view frustum's four side planes, so it touches no cell (the assignment's first cull).
    pub fn sphere_outside_sides(&self, center: glam::DVec3, radius: f64) -> bool {
        // By symmetry the nearer of the two planes of an axis decides: |x| against the right.
        match self.projection {
            GridProjection::Perspective { tan_x, tan_y } => {
                let d = -center.z;
                (center.x.abs() - tan_x * d) * self.side_plane_norm[0] > radius
                    || (center.y.abs() - tan_y * d) * self.side_plane_norm[1] > radius
            }
            GridProjection::Orthographic { half_x, half_y } => {
                center.x.abs() - half_x > radius || center.y.abs() - half_y > radius
            }
        }
    }

    /// The bounding sphere `[x, y, z, radius]` (view space) of the cell in column `x` and row
    /// `y` of slice `slice` (numbered across cascades) of cascade `cascade`: the centre of its
    /// eight corners and the farthest corner; an infinite radius for a cell reaching infinity.
    /// Computed when asked (the cone-vs-cell test of spot lights) from a per-slice table: a
    /// table of every cell's sphere, rebuilt with the grid whenever a moving camera changed
    /// its depth range, cost more than the whole assignment it served.
    #[inline]
    pub(crate) fn cell_sphere(&self, cascade: u32, slice: u32, x: u32, y: u32) -> [f64; 4] {
        let c = &self.cascades[cascade as usize];
        let f = &self.slice_frusta[slice as usize];
        if f.depths.1.is_infinite() {
            return [0.0, 0.0, 0.0, f64::INFINITY];
        }
        let ndc = |i: u32, n: u32| -1.0 + 2.0 * i as f64 / n as f64;
        bounding_sphere(
            (ndc(x, c.tiles_x), ndc(x + 1, c.tiles_x)),
            (ndc(y, c.tiles_y), ndc(y + 1, c.tiles_y)),
            f.depths,
            f.near,
            f.far,
        )
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

/// The bounding sphere `[x, y, z, radius]` of the cell between NDC `columns` and `rows` and
/// view depths `depths`, whose view half extents are `near` at the first depth and `far` at
/// the second: the centre of its eight corners and the farthest corner.
fn bounding_sphere(
    columns: (f64, f64),
    rows: (f64, f64),
    depths: (f64, f64),
    near: (f64, f64),
    far: (f64, f64),
) -> [f64; 4] {
    let mut corners = [glam::DVec3::ZERO; 8];
    for (i, corner) in corners.iter_mut().enumerate() {
        let (z, (hx, hy)) = if i & 4 != 0 {
            (depths.1, far)
        } else {
            (depths.0, near)
        };
        let nx = if i & 1 != 0 { columns.1 } else { columns.0 };
        let ny = if i & 2 != 0 { rows.1 } else { rows.0 };
        *corner = glam::DVec3::new(nx * hx, ny * hy, -z);
    }
    let center = corners.iter().sum::<glam::DVec3>() / 8.0;
    // One root of the largest squared distance (the root is monotonic and correctly rounded,
    // so this is the largest distance exactly).
    let farthest = corners
        .iter()
        .map(|p| p.distance_squared(center))
        .fold(0.0, f64::max);
    [center.x, center.y, center.z, farthest.sqrt()]
}
