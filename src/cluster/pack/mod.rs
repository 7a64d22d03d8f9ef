//! The texel layouts of the data textures the shaders read, all [`DATA_TEXTURE_WIDTH`] texels
//! wide: the light records (`lights.rs`), and the cluster grid and its light index list
//! (`grid.rs`).

mod grid;
mod lights;

pub use grid::{
    grid_fits_table, grid_texels, pack_grid, pack_grid_into, pack_indices, pack_indices_into,
    unpack_cell, unpack_index, GridEncoding, PackedTexels, MAX_INDEXED_LIGHTS, MAX_TABLE_CELLS,
    RGBA8_CELL_CAP, RGBA8_OFFSET_LIMIT, TABLE_TEXELS_PER_CASCADE,
};
pub use lights::{
    fp16_radiance, pack_lights, pack_lights_into, unpack_light, LightEncoding, LightLayout,
    PackedLights, DATA_TEXTURE_WIDTH, FP16_MAX_RADIANCE,
};
pub(crate) use lights::{scaled_alike_within, shader_spot_terms};
