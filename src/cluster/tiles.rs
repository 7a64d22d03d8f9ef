//! 2D screen tiles for tiled forward: the same grid and assignment machinery with one cascade
//! and one depth slice spanning the whole frustum, so a tile's light list holds every light
//! whose sphere crosses the tile's frustum column at any depth (Olsson & Assarsson 2011).

use super::grid::{ClusterGrid, GridConfig, GridProjection};

/// Default tile size in pixels.
pub const TILE_PX: f64 = 32.0;

/// A tile grid over a `width × height` viewport.
pub fn tile_grid(
    width: u32,
    height: u32,
    projection: GridProjection,
    near: f64,
    far: f64,
    tile_px: f64,
) -> ClusterGrid {
    ClusterGrid::new(
        width,
        height,
        projection,
        near,
        far,
        &GridConfig::tiles(tile_px),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_the_viewport_with_one_slice() {
        let g = tile_grid(
            1000,
            500,
            GridProjection::Perspective {
                tan_x: 1.0,
                tan_y: 0.5,
            },
            0.1,
            100.0,
            TILE_PX,
        );
        let c = &g.cascades[0];
        assert_eq!((c.tiles_x, c.tiles_y, c.slices), (32, 16, 1));
        assert_eq!(g.total_cells, 32 * 16);
        assert_eq!(g.column(0, 999.9), 31);
    }
}
