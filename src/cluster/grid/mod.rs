//! The dense, cascaded cluster grid (Persson's "practical clustered", Billeter 2015 §3).
//!
//! The view frustum is split in depth into `C` cascades. Perspective cameras space the cascade
//! boundaries geometrically between a first split `d₀` and the far end `d_F` of what the scene
//! can put on screen; orthographic cameras space them linearly. Every cascade has its own x/y
//! resolution, chosen so cells have an N×N pixel footprint at the cascade's near end, but never
//! smaller than a minimum world size when one is set, and its own number of slices,
//! exponential inside the cascade (Olsson 2012 Eq. 2: each slice about as deep as it is wide,
//! or `slice_depth` times that).
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
//!
//! Layout: the grid types here; its settings in `config`, the camera model in `projection`,
//! building in `build`, depth and pixel lookups in `addressing`, culling volumes in `spheres`,
//! the assignment's hot-path tables in `tables`.

mod addressing;
mod build;
mod config;
mod projection;
mod spheres;
mod tables;
#[cfg(test)]
mod tests;

pub use config::{
    Coverage, GridConfig, GridMeasure, GridMode, DEFAULT_ASSIGN_BUDGET, MAX_CASCADES,
};
pub use projection::{DepthMapping, GridProjection, ViewVolume};

pub(crate) use spheres::SliceCells;
pub(crate) use tables::CascadeConstants;
use tables::{SliceFrustum, SliceLookup};

/// Relative widening of depth ranges against slice boundaries: far more than the CPU table's
/// rounding at a boundary and than the shader's `f32` evaluation of the mapping (10⁻⁵ in log2
/// units).
pub(crate) const SLICE_WIDEN: f64 = 7e-6;

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
    /// Cells in this cascade, saturating at `u32::MAX` (which a renderer refuses by name).
    pub fn cells(&self) -> u32 {
        // Saturating: a large frame with raised limits (`max_tiles`, `max_slices`) can make
        // more than 2³² cells, which the renderer then refuses by name instead of wrapping.
        let cells = u64::from(self.tiles_x) * u64::from(self.tiles_y) * u64::from(self.slices);
        cells.min(u64::from(u32::MAX)) as u32
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
    /// Per slice (numbered across cascades): its exact view depths `[z0, z1]` and the view
    /// half extents at each (`z1` infinite for the last slice of an infinite grid): what a
    /// cell's bounding sphere is made from ([`ClusterGrid::row_spheres`]).
    pub(crate) slice_frusta: Vec<SliceFrustum>,
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
