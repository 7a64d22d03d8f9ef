//! Cell bounding volumes for culling: the frustum side-plane test of a light's sphere and the
//! lazily built bounding sphere of every cell (the spot-cone test), with the buffer a rebuilt
//! grid keeps for them.

use super::{CellCoord, ClusterGrid, GridProjection};

/// A buffer kept for the next build of a grid's cell spheres (behind a lock because the spheres
/// are built on first use through `&self`, possibly on several threads). A clone starts without.
#[derive(Debug, Default)]
pub(super) struct SpareSpheres(pub(super) std::sync::Mutex<Vec<[f64; 4]>>);

impl Clone for SpareSpheres {
    fn clone(&self) -> Self {
        SpareSpheres::default()
    }
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

    /// Bounding spheres `[x, y, z, radius]` of every cell, in cell order (built on first use).
    pub fn cell_spheres(&self) -> &[[f64; 4]] {
        self.cell_spheres.get_or_init(|| {
            let mut spheres = std::mem::take(
                &mut *self
                    .spare_spheres
                    .0
                    .lock()
                    .unwrap_or_else(|e| e.into_inner()),
            );
            self.build_cell_spheres(&mut spheres);
            spheres
        })
    }

    fn build_cell_spheres(&self, out: &mut Vec<[f64; 4]>) {
        out.clear();
        out.reserve(self.total_cells as usize);
        for (k, c) in self.cascades.iter().enumerate() {
            for slice in 0..c.slices {
                for y in 0..c.tiles_y {
                    for x in 0..c.tiles_x {
                        let coord = CellCoord {
                            cascade: k as u32,
                            slice,
                            x,
                            y,
                        };
                        out.push(self.bounding_sphere(coord));
                    }
                }
            }
        }
    }

    fn bounding_sphere(&self, cell: CellCoord) -> [f64; 4] {
        let b = self.cell_bounds(cell);
        if b.depth.1.is_infinite() {
            return [0.0, 0.0, 0.0, f64::INFINITY];
        }
        let mut corners = [glam::DVec3::ZERO; 8];
        for (i, corner) in corners.iter_mut().enumerate() {
            let z = if i & 4 != 0 { b.depth.1 } else { b.depth.0 };
            let (hx, hy) = self.projection.half_extent(z);
            let nx = if i & 1 != 0 { b.ndc_x.1 } else { b.ndc_x.0 };
            let ny = if i & 2 != 0 { b.ndc_y.1 } else { b.ndc_y.0 };
            *corner = glam::DVec3::new(nx * hx, ny * hy, -z);
        }
        let center = corners.iter().sum::<glam::DVec3>() / 8.0;
        let radius = corners
            .iter()
            .map(|p| p.distance(center))
            .fold(0.0, f64::max);
        [center.x, center.y, center.z, radius]
    }
}
