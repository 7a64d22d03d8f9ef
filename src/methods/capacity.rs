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
    let nothing = Capacities {
        forward_lights: 0,
        indexed_lights: 0,
        index_entries: 0,
        cell_lights: Some(0),
        grid_texels: 0,
    };
    if super::forward::data_textures_unfit(caps).is_some() {
        // No method that reads the data textures runs: nothing fits.
        return nothing;
    }
    if let super::Support::Unsupported(_) = super::culled_support::culled_support(caps) {
        // Tiled and clustered do not run (no fragment highp on ES 2.0): no list fits.
        return Capacities {
            forward_lights: super::forward::max_lights(caps),
            ..nothing
        };
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gl::context::context_or_skip;
    use crate::gl::Device;
    use crate::methods::{Support, METHODS};

    /// A context whose `GL_MAX_TEXTURE_SIZE` is below the data textures' width (ES 2.0 allows
    /// 64; ES 3.0 requires 2 048) runs no method: each says why, naming the limit (deferred
    /// too: its transparent objects are drawn forward).
    #[test]
    fn data_textures_past_the_texture_limit_leave_no_method() {
        let Some(ctx) = context_or_skip(EsVersion::Es3) else {
            return;
        };
        let mut dev = Device::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
        for (limit, fits) in [
            (DATA_TEXTURE_WIDTH as i32 - 1, false),
            (64, false),
            (1024, true),
        ] {
            dev.caps_mut().max_texture_size = limit;
            for m in METHODS {
                match (m.supported)(dev.caps()) {
                    Support::Unsupported(why) if !fits => {
                        assert!(why.contains("GL_MAX_TEXTURE_SIZE"), "{}: {why}", m.name)
                    }
                    Support::Unsupported(why) => panic!("{} at {limit}: {why}", m.name),
                    _ => assert!(fits, "{} runs at {limit}", m.name),
                }
            }
            let forward_lights = capacities(dev.caps()).forward_lights;
            assert_eq!(forward_lights > 0, fits, "{limit}");
        }
    }

    /// Without fragment highp (a Mali-400) tiled and clustered do not run, so no list fits:
    /// `info` said 65 536 visible lights there. Forward keeps its capacity.
    #[test]
    fn without_fragment_highp_only_forward_has_a_capacity() {
        let Some(ctx) = context_or_skip(EsVersion::Es2) else {
            return;
        };
        let mut dev = Device::new(ctx.load_gl().unwrap(), EsVersion::Es2).unwrap();
        let with = capacities(dev.caps());
        assert!(
            with.indexed_lights > 0 && with.index_entries > 0,
            "{with:?}"
        );
        dev.caps_mut().fragment_highp = crate::gl::caps::Precision::default();
        let without = capacities(dev.caps());
        assert_eq!(
            (
                without.indexed_lights,
                without.index_entries,
                without.cell_lights
            ),
            (0, 0, Some(0))
        );
        assert_eq!(without.grid_texels, 0);
        assert!(without.forward_lights > 0, "{without:?}");
    }
}
