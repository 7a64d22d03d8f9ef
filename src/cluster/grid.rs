//! The dense, cascaded cluster grid (Persson's "practical clustered", Billeter 2015 §3).
//!
//! The view frustum is split in depth into `C` cascades. Perspective cameras space the cascade
//! boundaries geometrically between a first split `d₀` and the far end `d_F` of what the scene
//! can put on screen; orthographic cameras space them linearly. Every cascade has its own x/y
//! resolution, chosen so cells are roughly cubical with an N×N pixel footprint at the
//! cascade's near end, but never smaller than a minimum world size (no swarm of tiny cells
//! near the camera), and its own number of slices, exponential inside the cascade (Olsson 2012
//! Eq. 2: each slice about as deep as it is wide).
//!
//! One mapping serves CPU and GPU: with `f(d) = log2(d)` (perspective) or `f(d) = d`
//! (orthographic), a view depth `d` has the continuous coordinate
//!
//! ```text
//! t = (f(d) − a) · b          cascade k = clamp(⌊t⌋, 0, C−1)
//! slice s = clamp(⌊(t − k) · S_k⌋, 0, S_k − 1)
//! ```
//!
//! so depths in front of `d₀` (between the near plane and the first split) fall into the first
//! slice and depths beyond `d_F` (up to an infinite far plane) into the last. The shader gets
//! `a`, `b` and `C` as uniforms and `(tiles_x, tiles_y, S_k, first cell)` per cascade from the
//! grid texture; all integer quantities come from here, so CPU and GPU never disagree on the
//! layout, only (by float rounding) on which side of a boundary a fragment lies — which the
//! assignment's padding absorbs.
//!
//! Columns: pixel `x` is in column `⌊x · tiles_x / W⌋`, whose NDC range is
//! `[−1 + 2i/tiles_x, −1 + 2(i+1)/tiles_x]`; rows likewise from the bottom (GL window
//! coordinates).

use glam::DMat4;

use super::depth_lookup::{CascadeConstants, SliceLookup};

/// Relative widening of depth ranges against slice boundaries: far more than the CPU table's
/// rounding at a boundary and than the shader's `f32` evaluation of the mapping (10⁻⁵ in log2
/// units).
pub(crate) const SLICE_WIDEN: f64 = 7e-6;

/// Tunables of the grid.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct GridConfig {
    /// Whether the clustered method picks the footprint itself every so often
    /// ([`GridMode::Auto`], the default) or always uses `footprint_px`. [`ClusterGrid::new`]
    /// always builds `footprint_px`: the choice is the method's (see [`super::auto`]).
    pub mode: GridMode,
    /// Number of depth cascades (Billeter uses 12).
    pub cascades: u32,
    /// Target cell footprint in pixels (cells are about this wide and as deep as wide): the
    /// fixed mode's, and where the automatic mode starts.
    pub footprint_px: f64,
    /// Where the first cascade starts (perspective: depths nearer than it share the first
    /// slice); `None`: at the near plane, or 1/4096 of the far end for a tiny near plane. The
    /// automatic mode sets it a little before the nearest surface, so no slice is spent on the
    /// empty space in front of the camera.
    pub first_split: Option<f64>,
    /// Minimum cell width in world units at a cascade's near end; `None`: no minimum, every
    /// cascade has cells of `footprint_px` (the grid starts at the first geometry, see
    /// [`GridConfig::first_split`], so near cascades are not wasted on empty space).
    pub min_cell_size: Option<f64>,
    /// Upper bound on slices per cascade.
    pub max_slices: u32,
    /// Upper bound on columns or rows of a cascade.
    pub max_tiles: u32,
    /// How tightly a light's cells are found (the default is the tight one; the other is kept
    /// to measure what it saves).
    pub coverage: Coverage,
}

/// Who picks the cell footprint.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GridMode {
    /// The clustered method measures candidate footprints against a cost model calibrated on
    /// the device and switches with hysteresis (see [`super::auto`]).
    #[default]
    Auto,
    /// Always `footprint_px` (tests, and users who want one grid).
    Fixed,
}

/// How the assignment bounds the cells a light's sphere reaches.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Coverage {
    /// Per slice, the sphere's cross-section over the slice's depths, and per row of cells the
    /// columns that cross-section reaches inside the row.
    #[default]
    SliceRows,
    /// One screen rectangle per cascade, every slice and row of it (earlier versions): kept
    /// as a yardstick for the bench and the tests.
    CascadeBox,
}

impl Default for GridConfig {
    fn default() -> Self {
        GridConfig {
            mode: GridMode::Auto,
            cascades: 12,
            footprint_px: 64.0,
            first_split: None,
            min_cell_size: None,
            max_slices: 32,
            max_tiles: 256,
            coverage: Coverage::default(),
        }
    }
}

impl GridConfig {
    /// A fixed grid of `footprint_px` with the other settings at their defaults.
    pub fn fixed(footprint_px: f64) -> Self {
        GridConfig {
            mode: GridMode::Fixed,
            footprint_px,
            ..GridConfig::default()
        }
    }

    /// A 2D tiling for tiled forward: one cascade, one slice, square tiles of `tile_px`.
    pub fn tiles(tile_px: f64) -> Self {
        GridConfig {
            mode: GridMode::Fixed,
            cascades: 1,
            footprint_px: tile_px,
            first_split: None,
            min_cell_size: Some(0.0),
            max_slices: 1,
            max_tiles: 1024,
            coverage: Coverage::default(),
        }
    }
}

/// How view depth maps to the grid coordinate `t`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum DepthMapping {
    /// `f(d) = log2(d)`.
    Log2,
    /// `f(d) = d`.
    Linear,
}

/// The projection as the grid needs it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GridProjection {
    /// Perspective: view x/y at depth `d` spans `±d·tan_x`, `±d·tan_y`.
    Perspective {
        /// tan(fov_y / 2) × aspect.
        tan_x: f64,
        /// tan(fov_y / 2).
        tan_y: f64,
    },
    /// Orthographic: view x/y spans `±half_x`, `±half_y`.
    Orthographic {
        /// Half the visible width.
        half_x: f64,
        /// Half the visible height.
        half_y: f64,
    },
}

impl GridProjection {
    /// From a GL projection matrix (perspective or orthographic, symmetric).
    pub fn from_matrix(p: &DMat4) -> GridProjection {
        if p.w_axis.w == 0.0 {
            GridProjection::Perspective {
                tan_x: 1.0 / p.x_axis.x,
                tan_y: 1.0 / p.y_axis.y,
            }
        } else {
            GridProjection::Orthographic {
                half_x: 1.0 / p.x_axis.x,
                half_y: 1.0 / p.y_axis.y,
            }
        }
    }

    /// View-space half extent in x and y at view depth `d`.
    pub fn half_extent(&self, d: f64) -> (f64, f64) {
        match *self {
            GridProjection::Perspective { tan_x, tan_y } => (d * tan_x, d * tan_y),
            GridProjection::Orthographic { half_x, half_y } => (half_x, half_y),
        }
    }
}

/// One depth cascade.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Cascade {
    /// View depth where the cascade starts (its first slice also takes everything nearer for
    /// cascade 0).
    pub z_near: f64,
    /// View depth where it ends (the last cascade's last slice also takes everything farther).
    pub z_far: f64,
    /// Columns.
    pub tiles_x: u32,
    /// Rows.
    pub tiles_y: u32,
    /// Depth slices.
    pub slices: u32,
    /// Index of the cascade's first cell in the grid.
    pub first_cell: u32,
}

impl Cascade {
    /// Cells in this cascade.
    pub fn cells(&self) -> u32 {
        self.tiles_x * self.tiles_y * self.slices
    }
}

/// A cell's address.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CellCoord {
    /// Cascade.
    pub cascade: u32,
    /// Slice within the cascade.
    pub slice: u32,
    /// Column.
    pub x: u32,
    /// Row (from the bottom).
    pub y: u32,
}

/// The grid for one viewport and projection. Recompute only when they change.
#[derive(Clone, Debug)]
pub struct ClusterGrid {
    /// Viewport width in pixels.
    pub width: u32,
    /// Viewport height in pixels.
    pub height: u32,
    /// Projection.
    pub projection: GridProjection,
    /// Near plane distance.
    pub near: f64,
    /// Far end of the grid (finite even for an infinite far plane).
    pub far: f64,
    /// Depth mapping.
    pub mapping: DepthMapping,
    /// `t = (f(d) − a) · b`: offset.
    pub a: f64,
    /// `t = (f(d) − a) · b`: scale.
    pub b: f64,
    /// The cascades, near to far.
    pub cascades: Vec<Cascade>,
    /// Total cells.
    pub total_cells: u32,
    /// How the assignment bounds a light's cells.
    pub coverage: Coverage,
    /// NDC per unit of view-space slope (perspective: `1 / tan`) or of view-space offset
    /// (orthographic: `1 / half extent`), for x and y: multiplied instead of divided by in the
    /// assignment's hot path.
    pub(crate) ndc_scale: [f64; 2],
    /// Bounding sphere (view-space centre, radius) of every cell, built on first use (the
    /// cone-vs-cell test of spot lights); infinite radius for cells reaching infinity.
    cell_spheres: std::sync::OnceLock<Vec<[f64; 4]>>,
    /// The buffer of an earlier grid's spheres, for the next build (see [`ClusterGrid::rebuild`]).
    spare_spheres: SpareSpheres,
    /// Slice of a depth without a logarithm (log2 mapping only).
    slice_lookup: SliceLookup,
    /// Per cascade: constants of the assignment's box projection and tile conversion.
    pub(crate) cascade_constants: Vec<CascadeConstants>,
    /// Per slice (numbered across cascades): the view depths `[z0, z1]` a fragment the shader
    /// puts in that slice can have, the slice's bounds widened by [`SLICE_WIDEN`] for the
    /// shader's `f32` evaluation of the mapping (see [`ClusterGrid::depth_range_to_slices`]),
    /// and their reciprocals `1/z0`, `1/z1` (+∞ for 0, 0 for +∞).
    pub(crate) slice_slabs: Vec<[f64; 4]>,
    /// Perspective: `1 / √(1 + tan²)` for x and y, the length of the side planes' normals
    /// `(1, 0, tan)` taken out (see [`ClusterGrid::sphere_outside_sides`]).
    side_plane_norm: [f64; 2],
}

/// A buffer kept for the next build of a grid's cell spheres (behind a lock because the spheres
/// are built on first use through `&self`, possibly on several threads). A clone starts without.
#[derive(Debug, Default)]
struct SpareSpheres(std::sync::Mutex<Vec<[f64; 4]>>);

impl Clone for SpareSpheres {
    fn clone(&self) -> Self {
        SpareSpheres::default()
    }
}

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
            coverage: config.coverage,
            ndc_scale: [0.0; 2],
            cell_spheres: std::sync::OnceLock::new(),
            spare_spheres: SpareSpheres::default(),
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
        let c = config.cascades.max(1);
        let min_cell = config.min_cell_size.unwrap_or(0.0).max(0.0);
        let split = config.first_split.filter(|d| d.is_finite());
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
            // Slices about as deep as a cell is wide (Olsson 2012, Eq. 2).
            let cell_width = footprint * pixel;
            let slices = match mapping {
                DepthMapping::Log2 => {
                    let rho = 1.0 + 2.0 * half_y / z_near.max(1e-300) / height as f64 * footprint;
                    ((z_far / z_near).ln() / rho.ln()).ceil()
                }
                DepthMapping::Linear => ((z_far - z_near) / cell_width.max(1e-300)).ceil(),
            };
            let slices = if slices.is_finite() { slices as u32 } else { 1 }
                .clamp(1, config.max_slices.max(1));
            let cascade = Cascade {
                z_near,
                z_far,
                tiles_x,
                tiles_y,
                slices,
                first_cell,
            };
            first_cell += cascade.cells();
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
        self.coverage = config.coverage;
        self.ndc_scale = match projection {
            GridProjection::Perspective { tan_x, tan_y } => [1.0 / tan_x, 1.0 / tan_y],
            GridProjection::Orthographic { half_x, half_y } => [1.0 / half_x, 1.0 / half_y],
        };
        // The spheres are of the old cells: dropped, their buffer kept for the next build.
        if let Some(mut spheres) = self.cell_spheres.take() {
            spheres.clear();
            *self
                .spare_spheres
                .0
                .get_mut()
                .unwrap_or_else(|e| e.into_inner()) = spheres;
        }
        self.side_plane_norm = match projection {
            GridProjection::Perspective { tan_x, tan_y } => {
                [tan_x, tan_y].map(|t| 1.0 / (1.0 + t * t).sqrt())
            }
            GridProjection::Orthographic { .. } => [1.0; 2],
        };
        let mut lookup = std::mem::take(&mut self.slice_lookup);
        if mapping == DepthMapping::Log2 {
            lookup.rebuild(self);
        } else {
            lookup.clear();
        }
        self.slice_lookup = lookup;
        let mut constants = std::mem::take(&mut self.cascade_constants);
        CascadeConstants::of_into(self, &mut constants);
        self.cascade_constants = constants;
        let mut slabs = std::mem::take(&mut self.slice_slabs);
        self.build_slice_slabs(&mut slabs);
        self.slice_slabs = slabs;
    }

    fn build_slice_slabs(&self, slabs: &mut Vec<[f64; 4]>) {
        slabs.clear();
        for (k, c) in self.cascades.iter().enumerate() {
            for s in 0..c.slices {
                let (z0, z1) = self.slice_depth_range(k as u32, s);
                let first = k == 0 && s == 0;
                let z0 = if first { 0.0 } else { z0 * (1.0 - SLICE_WIDEN) };
                let z1 = z1 * (1.0 + SLICE_WIDEN);
                slabs.push([z0, z1, 1.0 / z0, 1.0 / z1]);
            }
        }
    }

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

    /// `f(d)` of the depth mapping (`d` clamped to a positive value for the log).
    pub fn map_depth(&self, d: f64) -> f64 {
        match self.mapping {
            DepthMapping::Log2 => d.max(1e-300).log2(),
            DepthMapping::Linear => d,
        }
    }

    /// The continuous grid coordinate `t` of a view depth.
    pub fn depth_to_t(&self, d: f64) -> f64 {
        (self.map_depth(d) - self.a) * self.b
    }

    /// Cascade and slice of a view depth (the mapping the shader evaluates).
    pub fn view_z_to_cascade_slice(&self, d: f64) -> (u32, u32) {
        self.t_to_cascade_slice(self.depth_to_t(d))
    }

    /// First and last (cascade, slice) a depth range `[dmin, dmax]` can touch: the hot path of
    /// the assignment. Under the log2 mapping the slices come from a table (no logarithm; see
    /// `depth_lookup`) and the range is first widened by a relative 7·10⁻⁶ (10⁻⁵ in log2
    /// units), far more than the table's rounding at a boundary and than the shader's `f32`
    /// evaluation of the mapping; so the result never misses a slice that
    /// [`view_z_to_cascade_slice`](Self::view_z_to_cascade_slice) gives a depth inside the
    /// range, and at worst includes one neighbour slice more.
    pub fn depth_range_to_slices(&self, dmin: f64, dmax: f64) -> ((u32, u32), (u32, u32)) {
        match self.mapping {
            DepthMapping::Linear => (
                self.view_z_to_cascade_slice(dmin),
                self.view_z_to_cascade_slice(dmax),
            ),
            DepthMapping::Log2 => (
                self.slice_lookup.find(dmin * (1.0 - SLICE_WIDEN)),
                self.slice_lookup.find(dmax * (1.0 + SLICE_WIDEN)),
            ),
        }
    }

    /// Cascade and slice of a grid coordinate, clamped into the grid.
    pub fn t_to_cascade_slice(&self, t: f64) -> (u32, u32) {
        // Clamping to ≥ 0 first makes the truncating cast a floor (and maps NaN to 0);
        // `f64::floor` is a libm call on baseline x86-64.
        let last = self.cascades.len() as u32 - 1;
        let k = t.clamp(0.0, last as f64) as u32;
        let slices = self.cascades[k as usize].slices;
        let s = ((t - k as f64) * slices as f64).clamp(0.0, (slices - 1) as f64) as u32;
        (k, s)
    }

    /// View-depth range `[z0, z1]` of a slice, with the first slice of the grid starting at the
    /// near plane and the last extending to infinity.
    pub fn slice_depth_range(&self, cascade: u32, slice: u32) -> (f64, f64) {
        let c = &self.cascades[cascade as usize];
        let t0 = cascade as f64 + slice as f64 / c.slices as f64;
        let t1 = cascade as f64 + (slice + 1) as f64 / c.slices as f64;
        let inv = |t: f64| {
            let f = t / self.b + self.a;
            match self.mapping {
                DepthMapping::Log2 => f.exp2(),
                DepthMapping::Linear => f,
            }
        };
        let z0 = if cascade == 0 && slice == 0 {
            self.near
        } else {
            inv(t0)
        };
        let last = cascade as usize == self.cascades.len() - 1 && slice == c.slices - 1;
        let z1 = if last { f64::INFINITY } else { inv(t1) };
        (z0, z1)
    }

    /// Column of a window x coordinate (pixels, from the left) in a cascade.
    pub fn column(&self, cascade: u32, x_px: f64) -> u32 {
        let tx = self.cascades[cascade as usize].tiles_x;
        ((x_px * tx as f64 / self.width as f64).max(0.0) as u32).min(tx - 1)
    }

    /// Row of a window y coordinate (pixels, from the bottom) in a cascade.
    pub fn row(&self, cascade: u32, y_px: f64) -> u32 {
        let ty = self.cascades[cascade as usize].tiles_y;
        ((y_px * ty as f64 / self.height as f64).max(0.0) as u32).min(ty - 1)
    }

    /// Linear index of a cell.
    pub fn cell_index(&self, c: CellCoord) -> u32 {
        let k = &self.cascades[c.cascade as usize];
        k.first_cell + (c.slice * k.tiles_y + c.y) * k.tiles_x + c.x
    }

    /// The cell of a fragment: window position (pixels, y from the bottom) and view depth.
    pub fn cell_of_fragment(&self, x_px: f64, y_px: f64, d: f64) -> CellCoord {
        let (cascade, slice) = self.view_z_to_cascade_slice(d);
        CellCoord {
            cascade,
            slice,
            x: self.column(cascade, x_px),
            y: self.row(cascade, y_px),
        }
    }

    /// View-space bounds of a cell: NDC x and y ranges and the depth range. A point at view
    /// position `(x, y, −d)` is inside when `d ∈ [z0, z1]` and its NDC lies in the ranges.
    pub fn cell_bounds(&self, c: CellCoord) -> CellBounds {
        let k = &self.cascades[c.cascade as usize];
        let ndc = |i: u32, n: u32| -1.0 + 2.0 * i as f64 / n as f64;
        let (z0, z1) = self.slice_depth_range(c.cascade, c.slice);
        CellBounds {
            ndc_x: (ndc(c.x, k.tiles_x), ndc(c.x + 1, k.tiles_x)),
            ndc_y: (ndc(c.y, k.tiles_y), ndc(c.y + 1, k.tiles_y)),
            depth: (z0, z1),
        }
    }
}

/// A cell's extent (see [`ClusterGrid::cell_bounds`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellBounds {
    /// NDC x range.
    pub ndc_x: (f64, f64),
    /// NDC y range.
    pub ndc_y: (f64, f64),
    /// View depth range (`z1` may be infinite).
    pub depth: (f64, f64),
}

#[cfg(test)]
mod tests {
    use super::*;

    fn persp(near: f64, far: f64) -> ClusterGrid {
        persp_with(near, far, &GridConfig::default())
    }

    fn persp_with(near: f64, far: f64, config: &GridConfig) -> ClusterGrid {
        let t = (30f64).to_radians().tan();
        ClusterGrid::new(
            1280,
            720,
            GridProjection::Perspective {
                tan_x: t * 16.0 / 9.0,
                tan_y: t,
            },
            near,
            far,
            config,
        )
    }

    #[test]
    fn depth_ranges_never_miss_a_slice() {
        for g in [persp(1e-4, 1e5), persp(0.1, 80.0), persp(0.5, 0.6)] {
            let mut d = g.near;
            while d < g.far * 2.0 {
                // Around `d`, and on every slice boundary too.
                let (k, s) = g.view_z_to_cascade_slice(d);
                let (z0, _) = g.slice_depth_range(k, s);
                for x in [
                    d,
                    d.next_up(),
                    d.next_down(),
                    z0,
                    z0.next_up(),
                    z0.next_down(),
                ] {
                    let exact = g.view_z_to_cascade_slice(x);
                    let (lo, hi) = g.depth_range_to_slices(x, x);
                    assert!(
                        lo <= exact && exact <= hi,
                        "{x}: {exact:?} not in {lo:?}..{hi:?}"
                    );
                }
                d *= 1.013;
            }
        }
    }

    #[test]
    fn cells_are_contiguous_and_counted() {
        let g = persp(0.1, 80.0);
        let mut next = 0;
        for c in &g.cascades {
            assert_eq!(c.first_cell, next);
            next += c.cells();
            assert!(c.tiles_x >= 1 && c.tiles_y >= 1 && c.slices >= 1);
        }
        assert_eq!(next, g.total_cells);
        assert_eq!(g.cascades.len(), 12);
    }

    #[test]
    fn depth_mapping_is_monotonic_and_covers_near_to_infinity() {
        for g in [persp(1e-4, 1e5), persp(0.1, 80.0), persp(0.5, 0.6)] {
            let mut last = (0, 0);
            let mut d = g.near;
            while d < g.far * 4.0 {
                let cs = g.view_z_to_cascade_slice(d);
                assert!(cs >= last, "not monotonic at {d}");
                let (z0, z1) = g.slice_depth_range(cs.0, cs.1);
                assert!(
                    z0 <= d * (1.0 + 1e-9) && d <= z1 * (1.0 + 1e-9),
                    "{d} outside slice {cs:?} [{z0}, {z1}]"
                );
                last = cs;
                d *= 1.01;
            }
            assert_eq!(g.view_z_to_cascade_slice(g.near * 0.5).0, 0);
            let lastc = g.cascades.len() as u32 - 1;
            assert_eq!(g.view_z_to_cascade_slice(f64::INFINITY).0, lastc);
        }
    }

    #[test]
    fn cells_are_roughly_cubical_or_clamped_to_the_minimum() {
        let g = persp(0.1, 80.0);
        for (k, c) in g.cascades.iter().enumerate() {
            let (z0, z1) = g.slice_depth_range(k as u32, 0);
            let z0 = z0.max(c.z_near);
            let width = 2.0 * z0 * (30f64).to_radians().tan() / c.tiles_y as f64;
            let depth = z1 - z0;
            if c.slices < GridConfig::default().max_slices {
                assert!(
                    depth / width < 2.5 && width / depth < 2.5,
                    "cascade {k}: {width} × {depth}"
                );
            }
        }
        // Without a minimum cell size every cascade has the footprint's tiles; with one, the
        // near cascades are coarser.
        assert!(g
            .cascades
            .iter()
            .all(|c| c.tiles_y == g.cascades[0].tiles_y));
        let coarse = persp_with(
            0.1,
            80.0,
            &GridConfig {
                min_cell_size: Some(80.0 / 64.0),
                ..GridConfig::default()
            },
        );
        assert!(coarse.cascades[0].tiles_y < coarse.cascades[11].tiles_y);
    }

    #[test]
    fn orthographic_uses_linear_slices_and_allows_near_zero() {
        let g = ClusterGrid::new(
            256,
            144,
            GridProjection::Orthographic {
                half_x: 8.0,
                half_y: 4.5,
            },
            0.0,
            20.0,
            &GridConfig::default(),
        );
        assert_eq!(g.mapping, DepthMapping::Linear);
        assert_eq!(g.view_z_to_cascade_slice(0.0), (0, 0));
        let (k, _) = g.view_z_to_cascade_slice(10.0);
        assert_eq!(k, 6);
    }

    #[test]
    fn tiles_config_gives_one_slice_spanning_everything() {
        let t = (30f64).to_radians().tan();
        let g = ClusterGrid::new(
            256,
            144,
            GridProjection::Perspective { tan_x: t, tan_y: t },
            0.1,
            50.0,
            &GridConfig::tiles(16.0),
        );
        assert_eq!(g.cascades.len(), 1);
        assert_eq!(g.cascades[0].slices, 1);
        assert_eq!((g.cascades[0].tiles_x, g.cascades[0].tiles_y), (16, 9));
        assert_eq!(g.slice_depth_range(0, 0), (0.1, f64::INFINITY));
    }

    #[test]
    fn fragment_cells_match_bounds() {
        let g = persp(0.1, 80.0);
        for &(x, y, d) in &[
            (0.5, 0.5, 0.1),
            (1279.5, 719.5, 79.0),
            (640.0, 360.0, 5.0),
            (100.2, 600.7, 30.0),
        ] {
            let c = g.cell_of_fragment(x, y, d);
            let b = g.cell_bounds(c);
            let nx = 2.0 * x / 1280.0 - 1.0;
            let ny = 2.0 * y / 720.0 - 1.0;
            assert!(b.ndc_x.0 <= nx && nx <= b.ndc_x.1);
            assert!(b.ndc_y.0 <= ny && ny <= b.ndc_y.1);
            assert!(b.depth.0 <= d * (1.0 + 1e-12) && d <= b.depth.1 * (1.0 + 1e-12));
        }
    }
}
