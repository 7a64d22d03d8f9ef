//! Building a grid: [`ClusterGrid::new`] and the in-place [`ClusterGrid::rebuild`], which lay
//! out the cascades, slices and tiles and fill the per-frame lookup tables (slice table, box
//! projection constants, widened slice slabs).

use super::tables::{CascadeConstants, SliceLookup};
use super::{Cascade, ClusterGrid, DepthMapping, GridConfig, GridProjection, SLICE_WIDEN};
use crate::cluster::headroom::room_for;

impl ClusterGrid {
    /// Builds the grid. `depth_range` is the span of view depths the scene can occupy
    /// (already clipped to [near, far] by the caller; it bounds the grid for infinite or huge
    /// far planes).
    pub fn new(
        width: u32,
        height: u32,
        projection: GridProjection,
        near: f64,
        far: f64,
        config: &GridConfig,
    ) -> ClusterGrid {
        let mut grid = ClusterGrid {
            width: 0,
            height: 0,
            projection,
            near: 0.0,
            far: 0.0,
            mapping: DepthMapping::Linear,
            a: 0.0,
            b: 0.0,
            cascades: Vec::new(),
            total_cells: 0,
            coverage: config.measure.coverage,
            ndc_scale: [0.0; 2],
            slice_frusta: Vec::new(),
            side_plane_norm: [0.0; 2],
            slice_lookup: SliceLookup::default(),
            cascade_constants: Vec::new(),
            slice_slabs: Vec::new(),
        };
        grid.rebuild(width, height, projection, near, far, config);
        grid
    }

    /// Makes this grid what [`ClusterGrid::new`] builds from these arguments, in place: its
    /// buffers are reused, so a grid rebuilt every frame (a moving camera changes its depth
    /// range) allocates nothing once they have grown.
    pub fn rebuild(
        &mut self,
        width: u32,
        height: u32,
        projection: GridProjection,
        near: f64,
        far: f64,
        config: &GridConfig,
    ) {
        let width = width.max(1);
        let height = height.max(1);
        let near = near.max(0.0);
        let far = if far.is_finite() && far > near {
            far
        } else {
            near + 1.0
        };
        let c = config.cascades.clamp(1, super::MAX_CASCADES);
        let min_cell = config.measure.min_cell_size.unwrap_or(0.0).max(0.0);
        let split = config.first_split.filter(|d| d.is_finite());
        let slice_depth = if config.slice_depth.is_finite() {
            config.slice_depth.clamp(1.0 / 16.0, 16.0)
        } else {
            1.0
        };
        let (mapping, d0) = match projection {
            // The first split is moved back from a tiny near plane (Olsson's remedy) but
            // never past 1/4096 of the far end: a 1e-4 near plane does not make 12 cascades
            // of microscopic cells.
            GridProjection::Perspective { .. } => (
                DepthMapping::Log2,
                split.unwrap_or(far / 4096.0).max(near).min(far * 0.5),
            ),
            GridProjection::Orthographic { .. } => (
                DepthMapping::Linear,
                split.map_or(near, |d| d.max(near).min(near + (far - near) * 0.5)),
            ),
        };
        let (fa, ff) = match mapping {
            DepthMapping::Log2 => (d0.log2(), far.log2()),
            DepthMapping::Linear => (d0, far),
        };
        let a = fa;
        let b = c as f64 / (ff - fa).max(1e-12);
        let inverse = |f: f64| match mapping {
            DepthMapping::Log2 => f.exp2(),
            DepthMapping::Linear => f,
        };
        let mut cascades = std::mem::take(&mut self.cascades);
        cascades.clear();
        let mut first_cell = 0u32;
        for k in 0..c {
            let z_near = inverse(fa + (ff - fa) * k as f64 / c as f64);
            let z_far = inverse(fa + (ff - fa) * (k + 1) as f64 / c as f64);
            // World size of one pixel (vertically) at the cascade's near end.
            let (_, half_y) = projection.half_extent(z_near.max(near).max(1e-30));
            let pixel = 2.0 * half_y / height as f64;
            let footprint = config
                .footprint_px
                .max(1.0)
                .max(min_cell / pixel.max(1e-300));
            let tiles =
                |px: u32| ((px as f64 / footprint).ceil() as u32).clamp(1, config.max_tiles.max(1));
            let (tiles_x, tiles_y) = (tiles(width), tiles(height));
            // Slices `slice_depth` times as deep as a cell is wide (1: Olsson 2012, Eq. 2).
            let slice = footprint * pixel * slice_depth;
            let slices = match mapping {
                DepthMapping::Log2 => {
                    let rho = 1.0
                        + 2.0 * half_y / z_near.max(1e-300) / height as f64
                            * footprint
                            * slice_depth;
                    ((z_far / z_near).ln() / rho.ln()).ceil()
                }
                DepthMapping::Linear => ((z_far - z_near) / slice.max(1e-300)).ceil(),
            };
            // At most 255: the grid texture's cascade table stores a slice count in a byte.
            let slices = if slices.is_finite() { slices as u32 } else { 1 }
                .clamp(1, config.max_slices.clamp(1, 255));
            let cascade = Cascade {
                z_near,
                z_far,
                tiles_x,
                tiles_y,
                slices,
                first_cell,
            };
            first_cell = first_cell.saturating_add(cascade.cells());
            cascades.push(cascade);
        }
        self.width = width;
        self.height = height;
        self.projection = projection;
        self.near = near;
        self.far = far;
        self.mapping = mapping;
        self.a = a;
        self.b = b;
        self.cascades = cascades;
        self.total_cells = first_cell;
        self.coverage = config.measure.coverage;
        self.ndc_scale = match projection {
            GridProjection::Perspective { tan_x, tan_y } => [1.0 / tan_x, 1.0 / tan_y],
            GridProjection::Orthographic { half_x, half_y } => [1.0 / half_x, 1.0 / half_y],
        };
        self.side_plane_norm = projection.side_plane_norms();
        // Per-slice arrays with room for the most slices these settings allow (a few
        // kilobytes): the automatic grid rebuilds a grid for finer and coarser footprints,
        // and a finer one than any before would otherwise grow them in a later frame.
        let most_slices = (c * config.max_slices.clamp(1, 255)) as usize;
        let mut lookup = std::mem::take(&mut self.slice_lookup);
        if mapping == DepthMapping::Log2 {
            lookup.rebuild(self.slice_starts(), most_slices, self.near, self.far);
        } else {
            lookup.clear();
        }
        self.slice_lookup = lookup;
        let mut constants = std::mem::take(&mut self.cascade_constants);
        self.build_cascade_constants(&mut constants);
        self.cascade_constants = constants;
        let mut frusta = std::mem::take(&mut self.slice_frusta);
        room_for(&mut frusta, most_slices);
        self.build_slice_frusta(&mut frusta);
        self.slice_frusta = frusta;
        let mut slabs = std::mem::take(&mut self.slice_slabs);
        room_for(&mut slabs, most_slices);
        self.build_slice_slabs(&mut slabs);
        self.slice_slabs = slabs;
    }

    /// Every slice's (cascade, slice within the cascade) and the view depth where it starts,
    /// near to far: what the slice lookup is built from.
    pub(super) fn slice_starts(&self) -> impl Iterator<Item = ((u32, u32), f64)> + '_ {
        self.cascades
            .iter()
            .enumerate()
            .flat_map(move |(k, cascade)| {
                let k = k as u32;
                (0..cascade.slices).map(move |s| ((k, s), self.slice_depth_range(k, s).0))
            })
    }

    /// The constants of every cascade, into `out` (cleared first).
    fn build_cascade_constants(&self, out: &mut Vec<CascadeConstants>) {
        let last = self.cascades.len() - 1;
        let mut first_slice = 0;
        out.clear();
        out.extend(self.cascades.iter().enumerate().map(|(k, c)| {
            let constants = CascadeConstants {
                inv_near: if k == 0 {
                    f64::INFINITY
                } else {
                    1.0 / c.z_near
                },
                inv_far: if k == last { 0.0 } else { 1.0 / c.z_far },
                half_tiles: [0.5 * c.tiles_x as f64, 0.5 * c.tiles_y as f64],
                ndc_step: [2.0 / c.tiles_x as f64, 2.0 / c.tiles_y as f64],
                tile_step: [
                    2.0 * (1.0 / self.ndc_scale[0]) / c.tiles_x as f64,
                    2.0 * (1.0 / self.ndc_scale[1]) / c.tiles_y as f64,
                ],
                extent: self.ndc_scale.map(|s| 1.0 / s),
                first_slice,
            };
            first_slice += c.slices;
            constants
        }));
    }

    /// The slabs of [`ClusterGrid::slice_slabs`] from the slices' exact depths (the frusta,
    /// built first).
    fn build_slice_slabs(&self, slabs: &mut Vec<[f64; 4]>) {
        slabs.clear();
        slabs.extend(self.slice_frusta.iter().enumerate().map(|(g, f)| {
            let (z0, z1) = f.depths;
            let z0 = if g == 0 {
                0.0
            } else {
                z0 * (1.0 - SLICE_WIDEN)
            };
            let z1 = z1 * (1.0 + SLICE_WIDEN);
            [z0, z1, 1.0 / z0, 1.0 / z1]
        }));
    }
}
