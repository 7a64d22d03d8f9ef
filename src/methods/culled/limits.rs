//! Stage limits: what one frame may hold on this context (the cell cap, the index list, the
//! grid and the lights the textures can address), from its capacities and the options.

use crate::cluster::assign::{AssignLimits, MAX_UNTRIMMED_INDICES};
use crate::cluster::grid::{ClusterGrid, GridConfig};
use crate::cluster::pack::DATA_TEXTURE_WIDTH;
use crate::cluster::pack::{grid_fits_table, grid_texels, MAX_INDEXED_LIGHTS};
use crate::gl::Device;
use crate::methods::capacity::capacities;
use crate::methods::FrameContext;
use crate::scene::Short;
use crate::Error;

/// The assignment's limits: the context's cell and index-list capacities, lowered by
/// `MeasureOptions::cell_cap` and `max_indices`.
pub(super) fn assign_limits(ctx: &FrameContext) -> AssignLimits {
    let capacity = capacities(ctx.dev.caps());
    let cell_cap = ctx
        .options
        .measure
        .cell_cap
        .unwrap_or(u32::MAX)
        .min(capacity.cell_lights.unwrap_or(u32::MAX));
    let mut max_indices = capacity.index_entries;
    if let Some(m) = ctx.options.measure.max_indices {
        max_indices = max_indices.min(m);
    }
    AssignLimits {
        cell_cap,
        max_indices,
        max_threads: ctx.options.max_assign_threads,
        ..AssignLimits::default()
    }
}

/// Refuses, before any assignment, a grid the grid texture cannot hold (it would only fail at
/// the upload, after allocating its lists) or whose table cannot address its cells.
pub(super) fn check_grid(
    dev: &Device,
    grid: &ClusterGrid,
    config: &GridConfig,
) -> Result<(), Error> {
    let footprint_px = config.footprint_px;
    let max_rows = dev.caps().max_texture_size.max(1) as usize;
    let texels = grid_texels(grid);
    if texels > max_rows * DATA_TEXTURE_WIDTH as usize {
        // Where the caps bound the grid, a finer footprint adds no cells (every size said
        // the same count), and where slices are at theirs deeper ones remove none.
        let max_slices = config.max_slices.clamp(1, 255);
        let capped =
            (grid.cascades.iter()).any(|c| c.tiles_x.max(c.tiles_y) >= config.max_tiles.max(1));
        let slices_capped = grid.cascades.iter().all(|c| c.slices >= max_slices);
        let caps = if capped {
            format!(
                " (at the caps of {} tiles a side and {max_slices} slices a cascade: \
                 grid.max_tiles, grid.max_slices)",
                config.max_tiles
            )
        } else {
            String::new()
        };
        let slices = if slices_capped {
            ""
        } else {
            "deeper slices (grid.slice_depth), "
        };
        return Err(Error::Limit(format!(
            "a {} px cell footprint (grid.footprint_px) makes {} grid cells{caps}; \
             this context's grid texture holds {}: use a larger footprint, {slices}or the \
             automatic grid",
            Short(footprint_px),
            grid.total_cells,
            max_rows * DATA_TEXTURE_WIDTH as usize - (texels - grid.total_cells as usize)
        )));
    }
    // The table's 24-bit first cells: a limit only where the texture holds more cells
    // (16 384 rows of 1 024 texels hold 2²⁴ texels, table included).
    if let Some(what) = grid_fits_table(grid) {
        return Err(Error::Limit(format!(
            "a {} px cell footprint (grid.footprint_px) with these limits \
             (grid.max_tiles, grid.max_slices) makes {what}: use a larger footprint or the \
             automatic grid",
            Short(footprint_px)
        )));
    }
    Ok(())
}

/// The error of a frame whose cells' lists would hold more references before the cell cap than
/// an assignment builds (many lights overlapping on a fine fixed grid).
pub(super) fn too_many_references(
    method: &str,
    cells: u32,
    references: usize,
    automatic: bool,
) -> Error {
    let knob = match method {
        "tiled" => "a larger tile_px",
        _ if automatic => "deeper slices (grid.slice_depth), the auto method (deferred past this)",
        _ => "a larger grid.footprint_px, deeper slices (grid.slice_depth) or the automatic grid",
    };
    Error::Limit(format!(
        "{method}: the frame's {cells} cells would list at least {references} light references before \
         the cell cap trims them, more than the {MAX_UNTRIMMED_INDICES} an assignment builds \
         (the lights overlap too much for cells this fine): {knob}, or fewer overlapping lights"
    ))
}

/// The error of a frame whose light lists (or the runs they are built from) needed `bytes` in
/// one buffer, which the allocator refused: an error, where growing it would abort.
pub(super) fn lists_unallocated(method: &str, bytes: u64) -> Error {
    Error::Limit(format!(
        "{method}: the frame's light lists need a buffer of {} MiB, which this process cannot \
         allocate now: fewer or smaller lights in view, larger cells (grid.footprint_px, \
         tile_px), or forward",
        bytes.div_ceil(1 << 20)
    ))
}

/// The error of a frame with more visible lights than the index list can number.
pub(super) fn too_many_visible(visible: usize) -> Error {
    Error::Limit(format!(
        "{visible} lights are visible in this frame; tiled and clustered shading index at most \
         {MAX_INDEXED_LIGHTS}: the auto method (deferred past that, on ES 3.0) or forward \
         renders more"
    ))
}
