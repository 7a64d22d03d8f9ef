//! Where things fall in the grid: the depth mapping from view depth to cascade and slice (and
//! back to a slice's depth range), the table-driven slice lookup of the assignment's hot path,
//! and pixel → column / row → cell index.

use super::{CellBounds, CellCoord, ClusterGrid, DepthMapping, SLICE_WIDEN};

impl ClusterGrid {
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
    /// range, and at worst includes one neighbour slice more. Inlined always: the
    /// assignment's per-light path calls it once a light, and left to the compiler it went
    /// out of line there as that path's code grew.
    #[inline(always)]
    pub fn depth_range_to_slices(&self, dmin: f64, dmax: f64) -> ((u32, u32), (u32, u32)) {
        match self.mapping {
            DepthMapping::Linear => (
                self.view_z_to_cascade_slice(dmin),
                self.view_z_to_cascade_slice(dmax),
            ),
            DepthMapping::Log2 => self
                .slice_lookup
                .find_range(dmin * (1.0 - SLICE_WIDEN), dmax * (1.0 + SLICE_WIDEN)),
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
