//! What one frame can hold on a context, from the limits it reports (`GL_MAX_TEXTURE_SIZE`,
//! fragment precision, ES level) rather than from any one driver's: `manylight info` states
//! these, and the methods enforce the same numbers.

use serde::Serialize;

use crate::cluster::pack::{
    GridEncoding, DATA_TEXTURE_WIDTH, MAX_INDEXED_LIGHTS, RGBA8_CELL_CAP, RGBA8_OFFSET_LIMIT,
};
use crate::gl::{Caps, EsVersion};

/// The capacities of one frame on a context.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Capacities {
    /// Lights one plain-forward draw loops over (`forward::max_lights`).
    pub forward_lights: u32,
    /// Visible lights tiled and clustered shading index in one frame.
    pub indexed_lights: usize,
    /// Entries of one frame's index list, every cell's list together.
    pub index_entries: usize,
    /// Lights one cell lists (`None`: only the index list bounds it).
    pub cell_lights: Option<u32>,
    /// Texels of the grid texture: the cells plus each cascade's two table texels.
    pub grid_texels: usize,
}

/// The capacities of `caps`' context.
pub fn capacities(caps: &Caps) -> Capacities {
    let rows = caps.max_texture_size.max(1) as usize;
    let texels = rows * DATA_TEXTURE_WIDTH as usize;
    let es2 = caps.es == EsVersion::Es2;
    let index_entries = texels * GridEncoding::for_es(caps.es).indices_per_texel();
    Capacities {
        forward_lights: super::forward::max_lights(caps),
        indexed_lights: MAX_INDEXED_LIGHTS,
        index_entries: if es2 {
            index_entries.min(RGBA8_OFFSET_LIMIT)
        } else {
            index_entries
        },
        // A cell's lights are one loop of the shader, which some drivers end early.
        cell_lights: match (es2, caps.light_loop_budget()) {
            (true, budget) => Some(RGBA8_CELL_CAP.min(budget)),
            (false, u32::MAX) => None,
            (false, budget) => Some(budget),
        },
        grid_texels: texels,
    }
}
